"""The environment of `earl run examples/pick_and_place`: the workcell in MuJoCo.

`make_environment(system, seed)` is named in run.toml.  It builds the arm with the
spec's N joints (earl.sim.arm), puts the box near its nominal place (moved by up to
2 mm, drawn from the seed) and parks the arm above it.  The runtime calls
`advance(time)` before the subsystems due at `time` run, and `close()` at the end.

Pictures: with `EARL_SIM_OUTPUT=DIR` in the environment, the run writes DIR/final.png when
it closes; with `EARL_SIM_VIDEO=1` as well, it records a video (MP4 with ffmpeg, else an
animated GIF) — slow where OpenGL is software, so not by default.
Where MuJoCo cannot render, the reason is kept in `render_messages` and the run goes on.

Two more factories stage the emergency stops of issue 5's tests:
`make_environment_operator_stop` (the operator presses the stop button at 3 s, which
task/a turns into an emergency-stop command) and `make_environment_driver_fault`
(joint 2's driver reports a fault at 3 s, which its motor controller reports).
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from earl.sim import MujocoPlant, arm
from pick_and_place import scene
from pick_and_place.task import park_configuration

OUTPUT_VARIABLE = "EARL_SIM_OUTPUT"
#: `EARL_SIM_VIDEO=1` records the video too; software OpenGL draws a frame slowly, so it is off by default
VIDEO_VARIABLE = "EARL_SIM_VIDEO"
VIDEO_FPS = 12.5
VIDEO_SIZE = (480, 360)
PICTURE_SIZE = (960, 720)
#: when the staged emergency stops happen, seconds of simulated time
STOP_TIME = 3.0
FAULTY_JOINT = 2


@dataclass(frozen=True)
class Placement:
    """Where the box ended up against the place target."""

    error_mm: float
    resting: bool
    released: bool

    @property
    def placed(self) -> bool:
        return self.resting and self.released and self.error_mm <= scene.PLACE_TOLERANCE * 1000.0


class PickAndPlaceEnvironment:
    """The plant, plus what the example needs around it: placement, staged faults, pictures."""

    def __init__(
        self,
        n: int,
        seed: int = 0,
        *,
        output: str | Path | None = None,
        operator_stop_at: float | None = None,
        driver_fault: tuple[int, float] | None = None,
        start: list[float] | None = None,
    ) -> None:
        self.n = n
        random = np.random.default_rng(seed)
        jitter = random.uniform(-scene.BOX_JITTER, scene.BOX_JITTER, size=2)
        self.box_start = (scene.BOX_XY[0] + float(jitter[0]), scene.BOX_XY[1] + float(jitter[1]))
        # the arm starts parked above the box, unless a test asks for another posture
        initial = park_configuration(n) if start is None else list(start)
        xml = arm.workcell_mjcf(n, self.box_start, scene.TARGET_XY, initial)
        self.plant = MujocoPlant.from_xml(xml, seed=seed, keyframe="initial")
        # what each drive acts on (arm.actuator_name: joint k's motor is `motork`), checked by `bind` before the
        # run and asked by the drives' functions (motor.py) during it
        self.plant.map_actuator("manip/a.motor[K]/re", "motor{joint}", encoder=True)
        self.plant.map_actuator("grip/a.fingerDrive/re", arm.FINGER_ACTUATOR, encoder=True)
        self.operator_stop_at = operator_stop_at
        if driver_fault is not None:
            joint, at = driver_fault
            self.plant.inject_fault(arm.actuator_name(joint), at)
        self.output = Path(output) if output is not None else None
        self.render_messages: list[str] = []
        self.pictures: list[Path] = []
        self._video: Any = None
        self._camera: Any = None
        if self.output is not None and os.environ.get(VIDEO_VARIABLE) == "1":
            self._start_video()
        self._started = time.perf_counter()
        self.wall_time: float | None = None

    # ------------------------------------------------------------ the runtime's side

    def bind(self, system: Any) -> None:
        """The workcell checks, before the first iteration, that it has every drive (and encoder) the spec's
        motors are mapped to, and a timestep that divides their period."""
        self.plant.bind(system)

    def advance(self, time: float) -> None:
        self.plant.advance(time)

    def close(self) -> None:
        if self.wall_time is not None:
            return
        self.wall_time = time.perf_counter() - self._started
        if self.output is not None:
            self._finish_pictures()
        self.plant.close()

    # ------------------------------------------------------------ what the example's code asks

    def operator_stop_requested(self) -> bool:
        return self.operator_stop_at is not None and self.plant.time >= self.operator_stop_at

    def placement(self) -> Placement:
        pose = self.plant.body_pose(arm.BOX_BODY)
        target = self.plant.model.site(arm.TARGET_SITE).pos
        error = math.hypot(pose.position[0] - float(target[0]), pose.position[1] - float(target[1]))
        resting = abs(pose.position[2] - arm.BOX_HALF_SIZE) < 0.003
        touching = self.plant.contacts_between(arm.BOX_BODY, "finger_left") + self.plant.contacts_between(
            arm.BOX_BODY, "finger_right"
        )
        return Placement(error * 1000.0, resting, touching == 0)

    # ------------------------------------------------------------ pictures

    def _start_video(self) -> None:
        from earl.sim.render import PlantCamera, RenderUnavailable, VideoRecorder

        try:
            self._camera = PlantCamera(self.plant, *VIDEO_SIZE, camera="overview", shadows=False)
            self._video = VideoRecorder(self._camera, self.plant, VIDEO_FPS)
        except RenderUnavailable as error:
            self.render_messages.append(f"no pictures: {error}")

    def _finish_pictures(self) -> None:
        from earl.sim.render import PlantCamera, RenderUnavailable

        assert self.output is not None
        try:
            still = PlantCamera(self.plant, *PICTURE_SIZE, camera="overview")
            self.pictures.append(still.save_png(self.output / "final.png"))
            if self._video is not None and self._video.frames:
                self.pictures.append(self._video.save(self.output / "run"))
        except (RenderUnavailable, OSError, ValueError) as error:
            self.render_messages.append(f"pictures incomplete: {error}")


def joints_of(system: Any) -> int:
    """N, from the (expanded) system the runtime passes: the value of its parameter `N`."""
    for parameter in getattr(system, "parameters", []):
        if parameter.name == "N":
            value = getattr(parameter.value, "value", None)
            if isinstance(value, int):
                return value
    raise ValueError("the spec has no integer parameter `N` (the number of the manipulator's joints)")


def _output() -> str | None:
    return os.environ.get(OUTPUT_VARIABLE) or None


def make_environment(system: Any, seed: int) -> PickAndPlaceEnvironment:
    """The factory of run.toml: the workcell for the spec's N."""
    return PickAndPlaceEnvironment(joints_of(system), seed, output=_output())


def make_environment_operator_stop(system: Any, seed: int) -> PickAndPlaceEnvironment:
    """As make_environment, and the operator presses the stop button at STOP_TIME."""
    return PickAndPlaceEnvironment(joints_of(system), seed, output=_output(), operator_stop_at=STOP_TIME)


def make_environment_driver_fault(system: Any, seed: int) -> PickAndPlaceEnvironment:
    """As make_environment, and joint FAULTY_JOINT's driver faults at STOP_TIME."""
    return PickAndPlaceEnvironment(joints_of(system), seed, output=_output(), driver_fault=(FAULTY_JOINT, STOP_TIME))
