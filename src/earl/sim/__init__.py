"""Plant adapters: bind Real Effectors and Real Receptors to a physics engine (MuJoCo).

    from earl.sim import MujocoPlant
    from earl.sim.arm import workcell_mjcf

`earl.sim.plant` steps a model in lockstep with virtual time and reads quantised
encoders; `earl.sim.arm` writes the project's N-joint arm as MJCF; `earl.sim.render`
takes pictures offscreen.  See docs/simulation.md.
"""

from __future__ import annotations

import os
import sys

#: MuJoCo was imported before earl.sim could choose its OpenGL backend (render.py says so when it matters)
MUJOCO_IMPORTED_FIRST = "mujoco" in sys.modules

# MuJoCo picks its OpenGL backend when it is first imported; without a display the
# only backends that work are EGL and OSMesa, and EGL is the faster one.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY") and not MUJOCO_IMPORTED_FIRST:
    os.environ["MUJOCO_GL"] = "egl"

from earl.sim.plant import Encoder, MujocoPlant, PlantError, Pose  # noqa: E402  (after choosing the GL backend)

__all__ = ["Encoder", "MujocoPlant", "PlantError", "Pose"]
