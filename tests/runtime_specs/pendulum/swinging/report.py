from typing import Any


def summary(simulation: Any) -> str:
    plant = simulation.environment
    shoulder, elbow = plant.joint_position("shoulder"), plant.joint_position("elbow")
    return f"pendulum: shoulder={shoulder:.3f} rad elbow={elbow:.3f} rad at {plant.time:.3f} s"
