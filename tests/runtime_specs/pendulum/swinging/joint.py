from typing import Any

GEAR_RATIO = 100.0  # motor shaft radians per joint radian (the encoders' first number)


def take(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.drive = inputs.command
    outputs.position = inputs.encoder / GEAR_RATIO


def pass_on(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.current = inputs.drive
    outputs.angle = inputs.position
