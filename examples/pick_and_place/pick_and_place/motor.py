"""`motor[K]/re` and `fingerDrive/re`: the drives, bound to the MuJoCo plant of the run.

A drive applies the winding current its controller sent (the plant's actuator turns
it into torque: motor constant × current × gear ratio, within the current limit)
and reads its encoder: the motor shaft position in whole counts, and whether the
driver reports a fault.
"""

from __future__ import annotations

from typing import Any


class NoPlant(RuntimeError):
    """A drive ran without the physics it drives."""


def _plant(context: Any) -> Any:
    environment = context.environment
    if environment is None or not hasattr(environment, "plant"):
        raise NoPlant(
            f"{context.subsystem} drives a simulated motor and needs the MuJoCo environment: run with "
            '`environment = "pick_and_place.environment:make_environment"` (examples/pick_and_place/run.toml)'
        )
    joints = context.parameters.get("N")
    built_for = getattr(environment, "n", joints)
    if joints is not None and built_for != joints:
        # a hand-made environment for another arm: its other joints would hang unpowered and the run
        # would fail to place the box with no word of why
        raise NoPlant(
            f"{context.subsystem} drives joint motors of an arm of N={joints} joints, but the environment "
            f"was built for N={built_for}: build it from the system this run runs "
            "(pick_and_place.environment.make_environment(expanded_system, seed)) or pass N to "
            "PickAndPlaceEnvironment"
        )
    return environment.plant


def apply_current(inputs: Any, outputs: Any, context: Any) -> None:
    """The actuator is the one the environment mapped this drive to (`map_actuator`), which `bind` checked."""
    plant = _plant(context)
    outputs.appliedCurrent = plant.set_input(plant.actuator_of(context), float(inputs.motorCommand.windingCurrent))


def read_encoder(inputs: Any, outputs: Any, context: Any) -> None:
    plant = _plant(context)
    actuator = plant.actuator_of(context)
    outputs.encoderReading = {"motorPos": plant.encoder(actuator), "driverFault": plant.driver_fault(actuator)}


# the finger's drive is mapped to the gripper's actuator: the same functions serve it
apply_finger_current = apply_current
read_finger_encoder = read_encoder
