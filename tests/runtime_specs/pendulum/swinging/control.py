from typing import Any

GOAL = (0.0, 0.0)  # joint positions, rad: hanging straight down
STIFFNESS = (4.0, 2.0)  # A per rad, shoulder and elbow
DAMPING = (0.7, 0.15)  # A per rad/s


def regulate(inputs: Any, outputs: Any, context: Any) -> None:
    velocity = [(now - before) / context.period for now, before in zip(inputs.angle, inputs.previous, strict=True)]
    outputs.effort = [
        stiffness * (goal - now) - damping * speed
        for stiffness, damping, goal, now, speed in zip(STIFFNESS, DAMPING, GOAL, inputs.angle, velocity, strict=True)
    ]
    outputs.previous = list(inputs.angle)


def command(inputs: Any, outputs: Any, context: Any) -> None:
    for k, current in enumerate(inputs.effort, start=1):
        outputs.current[k] = current
