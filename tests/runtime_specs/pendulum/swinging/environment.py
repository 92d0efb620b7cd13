from pathlib import Path
from typing import Any

from earl.sim import MujocoPlant

# next to this package, whatever directory `earl run` is started from
MODEL = Path(__file__).resolve().parent.parent / "pendulum.xml"


def make(system: Any, seed: int) -> MujocoPlant:
    plant = MujocoPlant.from_file(MODEL, seed=seed, keyframe="start")
    # motor[2]/re drives the model's `motor2` and reads its encoder (checked before the run)
    plant.map_actuator("arm/a.motor[K]/re", "motor{K}", encoder=True)
    return plant
