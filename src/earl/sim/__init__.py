"""Plant adapters: bind Real Effectors and Real Receptors to a physics engine (MuJoCo).

    from earl.sim import MujocoPlant
    from earl.sim.arm import workcell_mjcf

`earl.sim.plant` steps a model in lockstep with virtual time and reads quantised
encoders; `earl.sim.arm` writes the project's N-joint arm as MJCF; `earl.sim.render`
takes pictures offscreen.  See docs/simulation.md.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path

#: MuJoCo was imported before earl.sim could choose its OpenGL backend (render.py says so when it matters)
MUJOCO_IMPORTED_FIRST = "mujoco" in sys.modules

#: the module of MuJoCo that picks its OpenGL backend, when it is first imported, from `MUJOCO_GL`
_GL_CONTEXT = "mujoco.rendering.classic.gl_context"
#: the backend earl.sim chose and has not turned on yet (see `use_offscreen_backend`)
_deferred_backend: str | None = None


def _knows_gl_context() -> bool:
    """Whether this MuJoCo picks its backend in `_GL_CONTEXT`, found without importing MuJoCo."""
    spec = importlib.util.find_spec("mujoco")
    origin = spec.origin if spec is not None else None
    return origin is not None and (Path(origin).parent / "rendering" / "classic" / "gl_context.py").is_file()


# Without a display the only backends that work are EGL and OSMesa, and EGL is the faster one.
# Importing it (PyOpenGL) costs a tenth of a second that a run without pictures never needs:
# MuJoCo is imported with rendering off, and `use_offscreen_backend` turns EGL on before the
# first picture. The environment is left as it was, so that other processes choose for themselves.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY") and not MUJOCO_IMPORTED_FIRST:
    if _knows_gl_context():
        os.environ["MUJOCO_GL"] = "disable"
        try:
            import mujoco
        finally:
            del os.environ["MUJOCO_GL"]
        _deferred_backend = "egl"
    else:
        os.environ["MUJOCO_GL"] = "egl"

#: the backend `MUJOCO_GL` named that MuJoCo could not load, and why (None: no such failure). Physics
#: needs no OpenGL: MuJoCo is then imported with rendering off, and only pictures are refused.
UNUSABLE_BACKEND: tuple[str, str] | None = None
if "MUJOCO_GL" in os.environ and "mujoco" not in sys.modules:
    try:
        import mujoco
    except Exception as error:  # PyOpenGL raises AttributeError, ImportError … for a missing library
        requested = os.environ["MUJOCO_GL"]
        UNUSABLE_BACKEND = (requested, f"{type(error).__name__}: {error}")
        for name in [name for name in sys.modules if name == "mujoco" or name.startswith(("mujoco.", "OpenGL"))]:
            del sys.modules[name]
        os.environ["MUJOCO_GL"] = "disable"
        try:
            import mujoco  # noqa: F401
        finally:
            os.environ["MUJOCO_GL"] = requested


def use_offscreen_backend() -> None:
    """Turn on the OpenGL backend earl.sim chose, before MuJoCo first renders (render.py calls it)."""
    global _deferred_backend
    if _deferred_backend is None:
        return
    os.environ["MUJOCO_GL"], _deferred_backend = _deferred_backend, None
    # MuJoCo's renderer reads the context class from this module when it makes a context
    importlib.reload(importlib.import_module(_GL_CONTEXT))


from earl.sim.plant import Encoder, MujocoPlant, PlantError, Pose  # noqa: E402  (after choosing the GL backend)

__all__ = ["Encoder", "MujocoPlant", "PlantError", "Pose", "use_offscreen_backend"]
