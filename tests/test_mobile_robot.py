"""The second example runs: the mobile robot patrols its route around a post, stops for a wheel fault and
resumes, in the planar world of examples/mobile_robot/mobile_robot/world.py (every subsystem kind of
the manual at work: cs, ve, re, vr and rr, and an agent of no robot)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

import earl
from earl.model.expand import expand

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "mobile_robot"
sys.path.insert(0, str(EXAMPLE))

from mobile_robot import base, scan_filter, world  # noqa: E402
from mobile_robot.environment import make_environment, make_environment_wheel_fault  # noqa: E402


class _Record(dict[str, Any]):
    def __getattr__(self, name: str) -> Any:
        return self[name]


def _record(value: Any) -> Any:
    if isinstance(value, dict):
        return _Record({key: _record(item) for key, item in value.items()})
    return value


def test_the_base_patrols_its_route_going_around_the_post_without_touching_anything() -> None:
    simulation = earl.simulate(earl.load(EXAMPLE / "system.earl"), seed=3)
    try:
        simulation.advance_to(70.0)
        statistics = simulation.statistics.subsystems["base/a.cs"]
        assert simulation.state_of("coordinator/a.cs").state == "done"
        assert simulation.faults == []
        # the post was in the way, and the FSM does not chatter passing it: it went drive -> avoidObstacle
        # -> drive 10 times in 8 s, each time driveToGoal/pf turned straight back at the post (or it sat at
        # the edge of the scan filter's view)
        assert 1 <= statistics.transitions.get("drive,avoidObstacle", 0) <= 2
        assert simulation.environment.least_clearance > 0.1
        pose = simulation.state_of("base/a.cs").memory["pose"]
        assert math.hypot(pose["x"], pose["y"]) < 0.15  # home, by its own odometry
        assert math.hypot(simulation.environment.x, simulation.environment.y) < 0.25  # and in the world
    finally:
        simulation.close()


def test_a_wheel_fault_stops_the_base_and_the_coordinator_has_it_resume() -> None:
    system = earl.load(EXAMPLE / "system.earl")
    environment = make_environment_wheel_fault(expand(system, {}), 0)
    simulation = earl.simulate(system, environment=environment)
    try:
        simulation.advance_to(80.0)
        base_transitions = simulation.statistics.subsystems["base/a.cs"].transitions
        coordinator = simulation.statistics.subsystems["coordinator/a.cs"].transitions
        assert base_transitions["drive,emergencyStop"] == 1 and base_transitions["emergencyStop,idle"] == 1
        assert coordinator["monitor,recover"] == 1 and coordinator["recover,dispatch"] == 1
        assert simulation.statistics.subsystems["base/a.wheelController[1]/ve"].transitions["fault,regulate"] == 1
        assert simulation.state_of("coordinator/a.cs").state == "done"
    finally:
        simulation.close()


def test_earl_run_prints_the_patrol_line_with_four_wheels_too() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "run", str(EXAMPLE), "--param", "WHEELS=4"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1].startswith("mobile-robot: patrolled=true coordinator=done"), result.stdout


def test_a_wheel_turns_at_the_speed_its_voltage_holds_against_back_emf_and_friction() -> None:
    room = world.Room()
    floor = world.World(room, 2, 0.08, 0.42, (0.0, 0.0, 0.0))
    floor.set_voltage(1, 3.0)
    floor.set_voltage(2, 3.0)
    floor.advance(2.0)
    expected = world.MOTOR_CONSTANT * 3.0 / (world.RESISTANCE * world.FRICTION + world.MOTOR_CONSTANT**2)
    assert floor.wheels[0].speed == pytest.approx(expected, rel=1e-3)
    assert floor.y == pytest.approx(0.0, abs=1e-9) and floor.x > 0.0  # equal wheels: straight ahead
    assert floor.encoder(1) == math.floor(floor.wheels[0].angle * world.COUNTS_PER_REVOLUTION / math.tau)


def test_the_lidar_sees_a_post_ahead_and_the_walls_around() -> None:
    room = world.Room(low=(-2.0, -3.0), high=(4.0, 3.0), obstacles=[world.Obstacle(2.0, 0.0, 0.5)])
    ranges = world.World(room, 2, 0.08, 0.42, (0.0, 0.0, 0.0)).scan()
    beam = world.BEAMS // 2  # straight ahead: the beams start straight behind
    assert ranges[beam] == pytest.approx(1.5)
    assert ranges[0] == pytest.approx(2.0)  # the wall behind
    assert ranges[beam + world.BEAMS // 4] == pytest.approx(3.0)  # the wall to the left


def test_the_scan_filter_reports_the_nearest_obstacle_ahead_and_the_free_distance_per_sector() -> None:
    beams = 8
    ranges = [5.0] * beams
    ranges[4] = 1.0  # straight ahead (the beams start straight behind)
    ranges[0] = 0.3  # behind: in sector 5 of 8, not in the way
    scan = _record(
        {"stamp": 0, "angleMin": -math.pi, "angleIncrement": math.tau / beams, "rangeMax": 8.0, "ranges": ranges}
    )
    outputs = SimpleNamespace()
    context = SimpleNamespace(parameters={"SECTORS": 8, "MEDIAN_WINDOW": 1})
    scan_filter.detect(SimpleNamespace(scan=scan, history=[]), outputs, context)
    report = outputs.report
    assert report["nearestDistance"] == 1.0 and report["nearestBearing"] == pytest.approx(0.0)
    assert report["sectorDistance"][0] == 1.0 and report["sectorDistance"][4] == 0.3
    assert report["validBeams"] == beams


def test_odometry_undoes_the_inverse_kinematics() -> None:
    parameters = {"WHEEL_RADIUS": 0.08, "TRACK_WIDTH": 0.42, "WHEELS": 2}
    commands = SimpleNamespace(wheelCommand={})
    twist = _record({"linear": 0.3, "angular": -0.4})
    base.output_wheel_commands(
        SimpleNamespace(desiredTwist=twist, braking=False, resetWheelFaults=False),
        commands,
        SimpleNamespace(parameters=parameters),
    )
    states = {w: _record({"angularVelocity": c["angularVelocity"]}) for w, c in commands.wheelCommand.items()}
    wheel_state = SimpleNamespace(items=states.items)
    moved = SimpleNamespace()
    pose = _record({"x": 0.0, "y": 0.0, "theta": 0.0})
    base.localise(
        SimpleNamespace(wheelState=wheel_state, pose=pose), moved, SimpleNamespace(parameters=parameters, period=0.025)
    )
    assert moved.velocity["linear"] == pytest.approx(0.3) and moved.velocity["angular"] == pytest.approx(-0.4)


def test_the_environment_reads_the_wheels_and_geometry_from_the_spec() -> None:
    system = earl.load(EXAMPLE / "system.earl", {"WHEELS": 4})
    floor = make_environment(expand(system, {}), 5)
    assert len(floor.wheels) == 4 and floor.wheel_radius == 0.08 and floor.track_width == 0.42
    assert make_environment(expand(system, {}), 5).room.obstacles == floor.room.obstacles
    assert make_environment(expand(system, {}), 6).room.obstacles != floor.room.obstacles


def test_a_run_of_the_base_alone_reports_the_world_and_says_the_coordinator_is_elsewhere() -> None:
    """As the base's process of examples/mobile_robot/deploy.toml does: the report had failed for want of
    the coordinator's subsystem."""
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "run", str(EXAMPLE), "--agents", "base", "--duration", "1s"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "the report" not in result.stdout + result.stderr
    lines = result.stdout.splitlines()
    assert lines[-2] == "coordinator/a runs in another process: its summary says whether the patrol is done"
    assert lines[-1].startswith("mobile-robot: patrolled=unknown coordinator=elsewhere least_clearance_m="), lines
    assert lines[-1].endswith("sim_time_s=1.000")
