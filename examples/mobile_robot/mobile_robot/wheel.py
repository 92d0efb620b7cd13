"""`wheelController[W]/ve`: a PI regulator of the wheel's angular velocity (Eq. (2)-(3) of the manual,
on velocity), reading the encoder every 2 ms; a driver fault or a lost encoder disables the wheel."""

from __future__ import annotations

import math
from typing import Any

from mobile_robot.world import COUNTS_PER_REVOLUTION, SUPPLY

#: the integral term may hold at most this many volts: no wind-up while the supply saturates
INTEGRAL_LIMIT = SUPPLY


def _angle(encoder: Any) -> float:
    return encoder.ticks * math.tau / COUNTS_PER_REVOLUTION


def regulate(inputs: Any, outputs: Any, context: Any) -> None:
    parameters = context.parameters
    angle = _angle(inputs.encoder)
    speed = (angle - inputs.position) / context.period  # since the last iteration, a period ago
    command = inputs.command
    if command.brake:
        integral, voltage = 0.0, 0.0
    else:
        error = command.angularVelocity - speed
        integral = inputs.integral + error * context.period
        limit = INTEGRAL_LIMIT / parameters["KI"]
        integral = max(-limit, min(limit, integral))
        voltage = max(-SUPPLY, min(SUPPLY, parameters["KP"] * error + parameters["KI"] * integral))
    outputs.position = angle
    outputs.speed = speed
    outputs.integral = integral
    outputs.voltage = voltage
    outputs.fault = inputs.encoder.driverFault


def disable(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.position = _angle(inputs.encoder)
    outputs.speed = 0.0
    outputs.integral = 0.0
    outputs.voltage = 0.0
    outputs.fault = True


def output_voltage(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.motorVoltage = {"voltage": inputs.voltage, "enable": not inputs.fault}


def output_state(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.state = {"angularVelocity": inputs.speed, "position": inputs.position, "fault": inputs.fault}
