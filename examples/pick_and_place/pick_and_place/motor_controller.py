"""`motorController[K]/ve` and `fingerController/ve`: the hardware side of a motor position regulator.

A motor controller forwards the winding current its control subsystem computed to
its drive — never more than the drive's current limit — and reports the motor
position the drive's encoder measured.  When ordered to, or when the driver reports
a fault, it switches the driver to its emergency stop state: no current, and the
stop reported upwards, for good.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from earl.sim import arm


def _limit(context: Any) -> float:
    parameters = context.parameters
    if "joint" in parameters:
        return _joint_limit(int(parameters["N"]), int(parameters["joint"]))
    return arm.FINGER_DRIVE.current_limit


@functools.cache
def _joint_limit(n: int, joint: int) -> float:
    return arm.drive(n, joint).current_limit


def _forward(command: Any, reading: Any, outputs: Any, context: Any) -> None:
    current = float(command.desiredWindingCurrent)
    limit = _limit(context)
    outputs.windingCurrent = 0.0 if not math.isfinite(current) else min(max(current, -limit), limit)
    outputs.currentMotorPos = float(reading.motorPos)


def regulate(inputs: Any, outputs: Any, context: Any) -> None:
    """Forward the ordered winding current (limited) and take the encoder's motor position."""
    _forward(inputs.motorControllerCommand, inputs.encoderReading, outputs, context)


def regulate_finger(inputs: Any, outputs: Any, context: Any) -> None:
    """The same for the gripper's finger drive, whose command buffer is named fingerCommand."""
    _forward(inputs.fingerCommand, inputs.encoderReading, outputs, context)


def stop_driver(inputs: Any, outputs: Any, context: Any) -> None:
    """Emergency stop: no current; keep reporting the motor position and the stop."""
    outputs.windingCurrent = 0.0
    outputs.currentMotorPos = float(inputs.encoderReading.motorPos)
    outputs.emergencyStop = True


def output_motor_command(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.motorCommand = {"windingCurrent": float(inputs.windingCurrent)}


def output_state(inputs: Any, outputs: Any, context: Any) -> None:
    """motorControllerState/ob (a joint's controller) or fingerState/ob (the gripper's)."""
    state = {"currentMotorPos": float(inputs.currentMotorPos), "emergencyStop": bool(inputs.emergencyStop)}
    if "joint" not in context.parameters:  # the gripper's controller belongs to no joint
        outputs.fingerState = state
    else:
        outputs.motorControllerState = state
