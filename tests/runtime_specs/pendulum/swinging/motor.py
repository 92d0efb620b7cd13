from typing import Any


def drive(inputs: Any, outputs: Any, context: Any) -> None:
    plant = context.environment
    actuator = plant.actuator_of(context)  # motor[2]/re: `motor2`, as the environment mapped it
    plant.set_input(actuator, inputs.current)  # amperes, limited to the actuator's ctrlrange
    outputs.reading = plant.encoder(actuator)  # motor shaft, rad, in whole encoder counts


def report(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.angle = inputs.reading
