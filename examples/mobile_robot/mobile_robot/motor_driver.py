"""`wheelDrive[W]/re`: the motor driver of wheel W applies the armature voltage its controller sent and
samples the wheel's encoder counter and fault pin (the world's)."""

from __future__ import annotations

from typing import Any


def _world(context: Any) -> Any:
    world = context.environment
    if world is None or not hasattr(world, "set_voltage"):
        raise RuntimeError(
            f"{context.subsystem} drives a simulated wheel and needs the mobile robot's world: run with "
            '`environment = "mobile_robot.environment:make_environment"` (examples/mobile_robot/run.toml)'
        )
    return world


def drive(inputs: Any, outputs: Any, context: Any) -> None:
    world = _world(context)
    wheel = context.parameters["wheel"]
    command = inputs.motorVoltage
    world.set_voltage(wheel, command.voltage if command.enable else 0.0)
    outputs.ticks = world.encoder(wheel)
    outputs.driverFault = world.driver_fault(wheel)


def output_encoder(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.encoder = {"ticks": inputs.ticks, "driverFault": inputs.driverFault}
