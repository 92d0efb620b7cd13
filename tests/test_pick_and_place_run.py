"""The manual's example, end to end: `earl run` semantics against MuJoCo (issue: the example runs).

These run the real spec, the real runtime and the real physics; each full run simulates the
whole task (about 13 s of virtual time).
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.runtime.events import Recorder

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "pick_and_place"
MS = 1_000_000
#: manip/a.cs runs every 2 ms
CS_PERIOD = 2 * MS


class Watch(Recorder):
    def __init__(self) -> None:
        self.states: list[tuple[int, str, str]] = []
        self.stop_commands: list[int] = []

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        self.states.append((time, subsystem, destination))

    def message_sent(self, time: int, link: str, value: Any) -> None:
        if link == "task,manip" and value["emergencyStopCommand"]:
            self.stop_commands.append(time)


def run(n: int, seed: int = 0, environment: str | None = None, **options: Any) -> tuple[earl.Simulation, Watch]:
    watch = Watch()
    system = earl.load(EXAMPLE, {"N": n})
    extra: dict[str, Any] = {} if environment is None else {"environment": environment}
    sim = earl.simulate(system, parameters={"N": n}, seed=seed, recorders=[watch], **extra, **options)
    return sim, watch


@pytest.mark.parametrize("n", [6, 3, 7])
def test_the_arm_picks_the_box_and_places_it_within_10_mm_of_the_target(n: int) -> None:
    sim, watch = run(n)
    sim.advance_to(13.0)
    placement = sim.environment.placement()  # type: ignore[attr-defined]
    sim.close()
    assert placement.placed, placement
    assert placement.error_mm <= 10.0
    task_states = [state for _, subsystem, state in watch.states if subsystem == "task/a.cs"]
    assert task_states == ["approach", "grasp", "lift", "carry", "place", "release", "retreat", "done"]
    assert not [f for f in sim.faults if f.subsystem.startswith("manip/a")], sim.faults[:3]


def currents(sim: earl.Simulation, n: int) -> list[float]:
    return [sim.state_of(f"manip/a.motor[{k}]/re").memory["appliedCurrent"] for k in range(1, n + 1)]


def zero_within(sim: earl.Simulation, n: int, raised: int, until: float) -> int:
    """Step 1 ms at a time; the first instant every drive's current is zero (and stays so)."""
    first_zero: int | None = None
    time = raised
    while time <= until * 1e9:
        sim.advance_to(time / 1e9)
        if all(current == 0.0 for current in currents(sim, n)):
            first_zero = time if first_zero is None else first_zero
        else:
            first_zero = None
        time += MS
    assert first_zero is not None, currents(sim, n)
    return first_zero


def test_an_emergency_stop_from_the_task_zeroes_every_current_within_two_cs_periods() -> None:
    sim, watch = run(6, environment="pick_and_place.environment:make_environment_operator_stop")
    sim.advance_to(2.9)
    assert max(abs(c) for c in currents(sim, 6)) > 0.01  # the arm is working before the stop
    sim.advance_to(3.02)
    raised = watch.stop_commands[0]
    assert 3000 * MS <= raised <= 3010 * MS
    first_zero = zero_within(sim, 6, raised, 3.3)
    assert first_zero - raised <= 2 * CS_PERIOD
    assert sim.state_of("manip/a.cs").state == "emergencyStop"
    sim.advance_to(3.5)
    assert sim.state_of("manip/a.cs").state == "emergencyStop"
    assert currents(sim, 6) == [0.0] * 6
    sim.close()


def test_a_driver_fault_reported_by_one_motor_controller_stops_every_drive() -> None:
    sim, watch = run(6, environment="pick_and_place.environment:make_environment_driver_fault")
    sim.advance_to(3.02)
    raised = next(
        t for t, s, state in watch.states if s == "manip/a.motorController[2]/ve" and state == "emergencyStop"
    )
    first_zero = zero_within(sim, 6, raised, 3.3)
    assert first_zero - raised <= 2 * CS_PERIOD
    sim.advance_to(3.5)
    assert sim.state_of("manip/a.cs").state == "emergencyStop"
    assert currents(sim, 6) == [0.0] * 6
    sim.close()


def test_two_runs_with_the_same_seed_write_identical_traces(tmp_path: Path) -> None:
    traces = []
    for name in ("first", "second"):
        path = tmp_path / f"{name}.mcap"
        sim, _ = run(6, seed=3, trace=path, record_memory=["manip/a.cs"])
        sim.advance_to(1.5)
        sim.close()
        traces.append(path.read_bytes())
    assert len(traces[0]) > 10_000
    assert traces[0] == traces[1]


def test_an_opengl_backend_mujoco_cannot_load_stops_only_the_pictures(tmp_path: Path) -> None:
    """`MUJOCO_GL` naming a backend MuJoCo cannot load failed `import mujoco` itself, and with it the run."""
    import os
    import subprocess
    import sys

    picture = tmp_path / "end.png"
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "run", str(EXAMPLE), "--duration", "0.3s", "--no-progress"],
        env={**os.environ, "MUJOCO_GL": "nothing", "EARL_SIM_OUTPUT": str(picture)},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    said = " ".join((result.stdout + result.stderr).split())
    assert "MUJOCO_GL=nothing names no OpenGL backend of MuJoCo" in said
    assert "pick-and-place: placed=" in said


class Messages(Recorder):
    def __init__(self) -> None:
        self.sent: list[tuple[int, str, Any]] = []

    def message_sent(self, time: int, link: str, value: Any) -> None:
        self.sent.append((time, link, value))


def test_the_first_state_reported_is_measured_and_the_fingers_are_not_driven_before_they_are() -> None:
    """The first iterations ran on input buffers that had received nothing: manip/a reported joints all 0
    and the grasp point at z = 1.08 m (the arm is at 0.26 m) for 0–4 ms, and grip/a read an opening of 0
    (the fingers are at 0.08 m), drove them at its 2 A limit and they opened to 0.0824 m."""
    messages = Messages()
    sim = earl.simulate(earl.load(EXAMPLE), recorders=[messages])
    plant = sim.environment.plant  # type: ignore[attr-defined]
    grasp_point = plant.site_pose("grasp").position
    sim.advance_to(0.3)
    sim.close()
    states = [value for _, link, value in messages.sent if link == "manip,task"]
    first = states[0]
    assert abs(first["currentOperationalPos"]["position"][2] - grasp_point[2]) < 0.002, first
    assert abs(first["currentJointPos"][1] - 0.66) < 0.01 and abs(first["currentJointPos"][2] - 1.58) < 0.01
    statuses = [value for _, link, value in messages.sent if link == "grip,task"]
    assert statuses and all(abs(s["currentFingerPos"] - 0.08) < 0.001 for s in statuses), statuses[:3]
    finger_currents = [
        value["desiredWindingCurrent"] for _, link, value in messages.sent if "cs,fingerController" in link
    ]
    assert max(abs(c) for c in finger_currents) < 0.1, finger_currents[:3]
    # no motor position is reported before its drive's first reading
    reported = [value for _, link, value in messages.sent if link == "manip/a:motorController[2],cs"]
    assert reported and all(value["currentMotorPos"] > 1.0 for value in reported)


def test_the_grasp_is_reported_without_a_break_from_grasp_to_release() -> None:
    """task/a re-sent the closed set-point with every arm phase; grip/a took each as a new move, in which
    it reports no grasp: objectGrasped dropped for 150 ms at lift, carry and place with the box held."""
    messages = Messages()
    sim = earl.simulate(earl.load(EXAMPLE), recorders=[messages])
    sim.advance_to(8.0)
    sim.close()
    commands = [value["desiredFingerPos"] for _, link, value in messages.sent if link == "task,grip"]
    assert commands == [0.08, 0.0, 0.08]  # approach, grasp, release: each once
    grasped = [(t, value["objectGrasped"]) for t, link, value in messages.sent if link == "grip,task"]
    changes = [(t, now) for (_, before), (t, now) in itertools.pairwise(grasped) if now != before]
    assert [now for _, now in changes] == [True, False], changes  # grasped once, released once
    assert changes[1][0] - changes[0][0] > 4.0 * 1e9  # held through lift, carry and place


def test_manip_builds_its_robot_model_in_the_first_instant_which_real_time_runs_before_its_clock() -> None:
    """Building the model (MuJoCo compiling the robot's XML) takes milliseconds: done at the first reading
    (2 ms), after a real-time run's clock had started, it made every drive start its second iteration
    2.7-7 ms late, an overrun of their 2 ms period reported as a deadline fault at t=0.002 s."""
    simulation = earl.simulate(earl.load(EXAMPLE / "system.earl"))
    from pick_and_place.kinematics import robot_model  # importable once the run has bound the spec's code

    robot_model.cache_clear()
    try:
        simulation.advance_to(0.0)  # the first instant: no reading has arrived yet
        assert robot_model.cache_info().currsize == 1
    finally:
        simulation.close()


def test_a_real_time_run_of_the_example_does_not_start_with_an_overrun() -> None:
    """The first instant after the clock starts (2 ms) is not late by a period. On a loaded machine any
    instant may be, so the best of three runs is taken: before the fix every run's was 2.7-7 ms late."""
    first: list[int] = []
    for _ in range(3):
        simulation = earl.simulate(earl.load(EXAMPLE / "system.earl"), realtime=True)
        from pick_and_place.kinematics import robot_model

        robot_model.cache_clear()  # as in a fresh process: the model is built in this run
        try:
            simulation.advance_to(0.004)
            first.append(max(record.samples[0] for record in simulation.scheduler.lateness.values()))
        finally:
            simulation.close()
        if first[-1] < 2_000_000:
            break
    assert min(first) < 2_000_000, f"the first instant started {min(first) / 1e6:.3f} ms late at best"
