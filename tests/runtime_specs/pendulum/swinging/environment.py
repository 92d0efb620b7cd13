from pathlib import Path
from typing import Any

from earl.sim import MujocoPlant

# next to this package, whatever directory `earl run` is started from
MODEL = Path(__file__).resolve().parent.parent / "pendulum.xml"


def make(system: Any, seed: int) -> MujocoPlant:
    return MujocoPlant.from_file(MODEL, seed=seed, keyframe="start")
