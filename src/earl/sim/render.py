"""Pictures of a plant through MuJoCo's offscreen renderer: PNG images and short videos.

MuJoCo renders without a display through EGL or OSMesa, chosen by the `MUJOCO_GL`
environment variable; `earl.sim` chooses `egl` when it is unset and there is no display,
and turns it on before the first picture (`use_offscreen_backend`), so that a run without
pictures never loads OpenGL.  Where no OpenGL context can be made,
`RenderUnavailable` says so in one sentence with what to install; callers report it
and carry on, because a picture is never what a run is for.

A video is written as MP4 when an `ffmpeg` program is on the PATH, and otherwise as
an animated GIF (through Pillow), so a machine without ffmpeg still gets one.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray
from PIL import Image

from earl.sim import use_offscreen_backend
from earl.sim.plant import MujocoPlant

Frame = NDArray[np.uint8]


class RenderUnavailable(RuntimeError):
    """No OpenGL context for offscreen rendering on this machine."""


def _advice() -> str:
    import earl.sim

    backend = os.environ.get("MUJOCO_GL", "(unset)")
    if earl.sim.UNUSABLE_BACKEND is not None:
        requested, why = earl.sim.UNUSABLE_BACKEND
        if requested not in ("egl", "osmesa", "glfw"):
            return (
                f"MUJOCO_GL={requested} names no OpenGL backend of MuJoCo (egl, osmesa, glfw): the physics runs "
                "without one; for pictures set MUJOCO_GL=egl or osmesa, or unset it"
            )
        return (
            f"MuJoCo could not load the OpenGL backend MUJOCO_GL={requested} ({why}): the physics runs without it; "
            "for pictures install its libraries (Debian: libegl1 libgl1 for egl, libosmesa6 for osmesa) or unset MUJOCO_GL"
        )
    if earl.sim.MUJOCO_IMPORTED_FIRST and backend == "(unset)":
        return (
            "MuJoCo cannot render offscreen here: it was imported before earl.sim and chose a windowed "
            "backend; set MUJOCO_GL=egl (or osmesa) in the environment, or import earl.sim first"
        )
    return (
        f"MuJoCo cannot render offscreen here (MUJOCO_GL={backend}); install the EGL or OSMesa "
        "libraries (Debian: libegl1 libgl1, or libosmesa6) and set MUJOCO_GL=egl or MUJOCO_GL=osmesa"
    )


class PlantCamera:
    """Renders one plant from one of its cameras (or a free view) at a fixed size."""

    def __init__(
        self, plant: MujocoPlant, width: int = 640, height: int = 480, camera: str | None = None, shadows: bool = True
    ) -> None:
        import earl.sim

        if earl.sim.UNUSABLE_BACKEND is not None:
            raise RenderUnavailable(_advice())
        use_offscreen_backend()
        model = plant.model
        # MuJoCo's offscreen buffer must hold the image; grow it rather than fail.
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
        try:
            self._renderer = mujoco.Renderer(model, height, width)
        except Exception as error:  # the GL backends raise many kinds: all mean "no context"
            raise RenderUnavailable(f"{_advice()} ({type(error).__name__}: {error})") from None
        # Software OpenGL (llvmpipe) spends most of a frame on shadows: a video can do without.
        self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = shadows
        self._plant = plant
        self._camera = camera if camera is not None else -1
        if camera is not None and mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
            raise RenderUnavailable(f"the model has no camera named `{camera}`")
        plant.on_close(self.close)

    def frame(self) -> Frame:
        """The current scene as an RGB image (height × width × 3)."""
        self._renderer.update_scene(self._plant.data, camera=self._camera)
        image: Frame = self._renderer.render().copy()
        return image

    def save_png(self, path: str | Path) -> Path:
        return save_png(self.frame(), path)

    def close(self) -> None:
        renderer = getattr(self, "_renderer", None)
        if renderer is not None:
            renderer.close()
            self._renderer = None


def save_png(image: Frame, path: str | Path) -> Path:
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(image).save(target, format="PNG")
    return target


class VideoRecorder:
    """Collects frames at `fps` of simulated time while the plant advances; `save` writes the video."""

    def __init__(self, camera: PlantCamera, plant: MujocoPlant, fps: float = 25.0) -> None:
        self.fps = fps
        self.frames: list[Frame] = []
        self._camera = camera
        plant.every(1.0 / fps, self._capture)

    def _capture(self, plant: MujocoPlant) -> None:
        self.frames.append(self._camera.frame())

    def save(self, path: str | Path) -> Path:
        """Write the frames: MP4 through ffmpeg when it is installed, else an animated GIF.

        Returns the file written (its suffix says which); raises ValueError with no frames.
        """
        if not self.frames:
            raise ValueError("no frames were recorded: the plant never advanced while recording")
        target = Path(path)
        target.parent.mkdir(parents=True, exist_ok=True)
        ffmpeg = shutil.which("ffmpeg")
        if ffmpeg is not None:
            return _write_mp4(ffmpeg, self.frames, self.fps, target.with_suffix(".mp4"))
        return _write_gif(self.frames, self.fps, target.with_suffix(".gif"))


def _write_gif(frames: list[Frame], fps: float, target: Path) -> Path:
    images = [Image.fromarray(f).quantize(colors=128, method=Image.Quantize.MEDIANCUT) for f in frames]
    images[0].save(target, save_all=True, append_images=images[1:], duration=round(1000.0 / fps), loop=0)
    return target


def _write_mp4(ffmpeg: str, frames: list[Frame], fps: float, target: Path) -> Path:
    height, width, _ = frames[0].shape
    command = [
        ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
        "-s", f"{width}x{height}", "-r", f"{fps:g}", "-i", "-",
        "-pix_fmt", "yuv420p", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", str(target),
    ]  # fmt: skip
    subprocess.run(command, input=b"".join(f.tobytes() for f in frames), check=True)
    return target
