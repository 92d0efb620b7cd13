"""The pick-and-place example's behaviour code, function by function, without the runtime.

The functions are called as the runtime calls them (docs/runtime.md): `inputs`,
`outputs` and `context` objects, here small stand-ins that follow the same contract
(attribute access, 1-based families, refusal of undeclared writes).  The stand-ins
are also used by tests/test_sim_closed_loop.py.
"""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples" / "pick_and_place"))

from pick_and_place import grip, manip, motor_controller, scene, task
from pick_and_place.kinematics import Pose, robot_model, tool_down_orientation
from pick_and_place.regulator import Gains, RegulatorState, regulate
from pick_and_place.trajectory import CartesianTrajectory, JointTrajectory, duration_for, quintic

from earl.sim import arm

# ---------------------------------------------------------------- stand-ins for the runtime's views


class Msg(dict[str, Any]):
    """A struct value: attribute access to its fields, as the runtime's Record."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def msg(value: Any) -> Any:
    """Written values (dicts, arrays) as a receiver sees them: structs with attributes, tuples."""
    if isinstance(value, dict):
        return Msg({k: msg(v) for k, v in value.items()})
    if isinstance(value, (list, tuple, np.ndarray)):
        return tuple(float(v) if isinstance(v, (float, np.floating)) else msg(v) for v in value)
    return value


class Family:
    """`inputs.motorControllerState[K]`, K = 1..N."""

    def __init__(self, members: dict[int, Any]) -> None:
        self._members = dict(sorted(members.items()))

    def __getitem__(self, index: int) -> Any:
        return self._members[index]

    def __len__(self) -> int:
        return len(self._members)

    def __iter__(self) -> Iterator[Any]:
        return iter(self._members.values())

    def items(self) -> list[tuple[int, Any]]:
        return list(self._members.items())


class Inputs:
    def __init__(self, **fields: Any) -> None:
        self._fields = {
            k: Family(v) if isinstance(v, dict) and all(isinstance(i, int) for i in v) else v for k, v in fields.items()
        }

    def __getattr__(self, name: str) -> Any:
        try:
            return self.__dict__["_fields"][name]
        except KeyError:
            raise AttributeError(f"undeclared read `{name}`") from None


class FamilyWrites:
    def __init__(self, outputs: Outputs, name: str, indices: range) -> None:
        self._outputs, self._name, self._indices = outputs, name, indices

    def __setitem__(self, index: int, value: Any) -> None:
        if index not in self._indices:
            raise AttributeError(f"undeclared write `{self._name}[{index}]`")
        self._outputs.written.setdefault(self._name, {})[index] = value


class Outputs:
    """Declared writes only; `written` holds what the function wrote in this call."""

    def __init__(self, *names: str, families: dict[str, int] | None = None) -> None:
        object.__setattr__(self, "_names", set(names))
        object.__setattr__(self, "_families", {k: range(1, n + 1) for k, n in (families or {}).items()})
        object.__setattr__(self, "written", {})

    def __setattr__(self, name: str, value: Any) -> None:
        if name not in self._names:
            raise AttributeError(f"undeclared write `{name}`")
        self.written[name] = value

    def __getattr__(self, name: str) -> Any:
        families = self.__dict__["_families"]
        if name in families:
            return FamilyWrites(self, name, families[name])
        raise AttributeError(f"undeclared `{name}`")

    def __dir__(self) -> list[str]:
        return sorted(self._names | set(self._families))


def context(**fields: Any) -> SimpleNamespace:
    base: dict[str, Any] = {
        "time": 0.0,
        "iteration": 0,
        "period": 0.002,
        "parameters": {"N": 6},
        "environment": None,
        "subsystem": "test",
        "random": np.random.default_rng(0),
        "state": "",
        "behaviour": "",
    }
    base.update(fields)
    return SimpleNamespace(**base)


def controller_states(motor_positions: list[float], stops: list[bool] | None = None) -> dict[int, Msg]:
    stops = stops or [False] * len(motor_positions)
    return {
        k: Msg(currentMotorPos=p, emergencyStop=s)
        for k, (p, s) in enumerate(zip(motor_positions, stops, strict=True), 1)
    }


def command(joints: list[float] | None = None, pose: Any = None, stop: bool = False) -> Msg:
    return Msg(jointPosSetpoint=joints, operationalPosSetpoint=pose, emergencyStopCommand=stop)


# ---------------------------------------------------------------- trajectories


def test_quintic_starts_and_ends_at_rest() -> None:
    assert quintic(0.0) == (0.0, 0.0, 0.0)
    assert quintic(1.0) == (1.0, 0.0, 0.0)
    s, ds, _ = quintic(0.5)
    assert s == pytest.approx(0.5) and ds == pytest.approx(15 / 8)  # the peak speed
    values = [quintic(t)[0] for t in np.linspace(0, 1, 101)]
    assert all(b >= a for a, b in itertools.pairwise(values))


def test_move_duration_keeps_the_peak_speed_under_the_limit() -> None:
    trajectory = JointTrajectory.between(np.zeros(2), np.array([1.0, -0.5]), peak_speed=0.8)
    assert trajectory.duration == pytest.approx(15 / 8 * 1.0 / 0.8)
    speeds = [np.max(np.abs(trajectory.sample(t)[1])) for t in np.linspace(0, trajectory.duration, 201)]
    assert max(speeds) == pytest.approx(0.8, rel=1e-3)
    assert duration_for(0.0, 1.0) > 0


def test_joint_trajectory_velocity_is_the_derivative_of_its_position() -> None:
    trajectory = JointTrajectory.between(np.array([0.2, 0.0]), np.array([-0.4, 1.0]), 1.0)
    t, h = 0.37 * trajectory.duration, 1e-6
    (p0, v, a), (p1, v1, _) = trajectory.sample(t), trajectory.sample(t + h)
    assert np.allclose((p1 - p0) / h, v, atol=1e-4)
    assert np.allclose((v1 - v) / h, a, atol=1e-3)
    assert np.allclose(trajectory.sample(trajectory.duration + 1.0)[0], [-0.4, 1.0])


def test_cartesian_trajectory_is_a_line_and_a_great_circle() -> None:
    start = (np.array([0.4, 0.0, 0.2]), tool_down_orientation(0.0))
    goal = (np.array([0.1, 0.4, 0.2]), tool_down_orientation(math.pi / 2))
    trajectory = CartesianTrajectory.between(start, goal, peak_speed=0.3, peak_angular_speed=1.0)
    middle_position, middle_orientation = trajectory.sample(trajectory.duration / 2)
    assert np.allclose(middle_position, [0.25, 0.2, 0.2])
    assert abs(float(np.dot(middle_orientation, tool_down_orientation(math.pi / 4)))) == pytest.approx(1.0)
    end_position, end_orientation = trajectory.sample(trajectory.duration)
    assert np.allclose(end_position, goal[0]) and abs(float(np.dot(end_orientation, goal[1]))) == pytest.approx(1.0)


# ---------------------------------------------------------------- kinematics


@pytest.mark.parametrize("n", [3, 6, 7])
def test_inverse_kinematics_converges_to_reachable_poses(n: int) -> None:
    model = robot_model(n)
    q = np.array(arm.tool_down_configuration(n, scene.PARK))
    for x, y, z in [(0.45, 0.0, 0.03), (0.10, 0.42, 0.16), (0.30, -0.25, 0.10)]:
        target = Pose(np.array([x, y, z]), tool_down_orientation(math.atan2(y, x)))
        solution = q
        for _ in range(60):
            solution = model.inverse_kinematics(target, solution)
        error = model.pose_error(target, solution)
        assert np.linalg.norm(error[:3]) < 1e-5, (n, x, y, z)
        assert np.linalg.norm(error[3:]) < 1e-4


@pytest.mark.parametrize("n", [3, 6])
def test_jacobian_with_the_levelling_wrist_matches_finite_differences(n: int) -> None:
    model = robot_model(n)
    q = np.array(arm.tool_down_configuration(n, (0.35, 0.1, 0.1))) + 0.05
    jac = model.jacobian(q)
    h = 1e-7
    for k in range(n):
        step = np.zeros(n)
        step[k] = h
        moved = (model.forward(q + step).position - model.forward(q).position) / h
        assert np.allclose(moved, jac[:3, k], atol=1e-5)


def test_gravity_feed_forward_matches_the_plant_at_rest() -> None:
    """The controller's own model (robot only) gives the torque that holds the plant's arm still."""
    from earl.sim import MujocoPlant

    n = 6
    q = arm.tool_down_configuration(n, scene.PARK)
    plant = MujocoPlant.from_xml(arm.workcell_mjcf(n, (0.8, 0.5), scene.TARGET_XY, q), keyframe="initial")
    torque = robot_model(n).inverse_dynamics(np.array(q), np.zeros(n), np.zeros(n))
    for k in range(1, n + 1):
        plant.set_input(arm.actuator_name(k), torque[k - 1] / arm.drive(n, k).torque_per_ampere)
    plant.advance(0.2)
    drift = [abs(plant.joint_position(arm.joint_name(k)) - q[k - 1]) for k in range(1, n + 1)]
    assert max(drift) < 2e-3


# ---------------------------------------------------------------- Eq. (2)–(3)


def _gains(p: float, i: float, d: float) -> Gains:
    return Gains(np.array([p]), np.array([i]), np.array([d]))


def test_regulator_is_eq_2_and_3() -> None:
    state = RegulatorState(integral=np.zeros(1))
    gains = _gains(2.0, 10.0, 0.0)
    zero = np.zeros(1)
    limit = np.array([100.0])
    first = regulate(gains, state, np.array([1.0]), zero, np.array([0.25]), zero, 0.002, limit)
    # e = 0.75 (Eq. 3); current = Kp e + Ki ∫e = 2·0.75 + 10·0.75·0.002 (Eq. 2)
    assert first[0] == pytest.approx(1.5 + 0.015)
    second = regulate(gains, state, np.array([1.0]), zero, np.array([0.25]), zero, 0.002, limit)
    assert second[0] == pytest.approx(1.5 + 0.03)


def test_regulator_saturates_without_winding_up() -> None:
    state = RegulatorState(integral=np.zeros(1))
    gains = _gains(10.0, 100.0, 0.0)
    zero = np.zeros(1)
    for _ in range(100):
        current = regulate(gains, state, np.array([1.0]), zero, zero, zero, 0.002, np.array([3.0]))
    assert current[0] == 3.0
    assert state.integral[0] == pytest.approx(0.0)  # nothing integrated while saturated that way
    # once the error reverses, the current leaves the limit at once
    current = regulate(gains, state, np.array([0.0]), zero, np.array([0.1]), zero, 0.002, np.array([3.0]))
    assert current[0] < 0


def test_derivative_term_damps_the_measured_motor_velocity() -> None:
    state = RegulatorState(integral=np.zeros(1))
    gains = _gains(0.0, 0.0, 1.0)
    zero = np.zeros(1)
    regulate(gains, state, zero, zero, np.array([0.0]), zero, 0.001, np.array([100.0]))
    current = regulate(gains, state, zero, zero, np.array([0.01]), zero, 0.001, np.array([100.0]))
    assert current[0] < 0  # moving forward: the term pushes back


def test_gains_place_every_joint_at_the_natural_frequency() -> None:
    from pick_and_place.regulator import NATURAL_FREQUENCY

    model = robot_model(6)
    q = np.array(arm.tool_down_configuration(6, scene.PARK))
    inertia = model.joint_inertia(q)
    gains = Gains.design(inertia, model.torque_per_ampere, model.gear)
    # joint stiffness = Kp · kt · G² (A per motor radian → N·m per joint radian)
    stiffness = gains.proportional * model.torque_per_ampere * model.gear
    assert np.allclose(np.sqrt(stiffness / inertia), NATURAL_FREQUENCY)


# ---------------------------------------------------------------- manip/a.cs


def test_calculate_position_turns_motor_positions_into_joints_and_pose() -> None:
    n = 6
    q = arm.tool_down_configuration(n, (0.45, 0.0, 0.06))
    motor = [qk * d.gear_ratio for qk, d in zip(q, arm.drives(n), strict=True)]
    outputs = Outputs("currentJointPos", "currentOperationalPos")
    manip.calculate_position(Inputs(motorControllerState=controller_states(motor)), outputs, context(time=0.002))
    assert np.allclose(outputs.written["currentJointPos"], q)
    assert np.allclose(outputs.written["currentOperationalPos"]["position"], [0.45, 0.0, 0.06], atol=1e-9)


def test_nothing_is_measured_or_reported_in_the_first_iteration_of_the_run() -> None:
    """It runs before anything was received (Figure 5b): its buffers hold zeros, which are no reading."""
    first = context(time=0.0, iteration=0)
    position = Outputs("currentJointPos", "currentOperationalPos")
    manip.calculate_position(Inputs(motorControllerState=controller_states([0.0] * 6)), position, first)
    assert position.written == {}
    state = Outputs("manipulatorState")
    pose = Msg(position=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 0.0))
    manip.output_manip_state(
        Inputs(currentJointPos=(0.0,) * 6, currentOperationalPos=pose, motionFinished=True, emergencyStopCommand={}),
        state,
        first,
    )
    assert state.written == {}


def test_emergency_stop_is_copied_to_every_motor_controller() -> None:
    for stops, ordered in [([False, True, False], False), ([False, False, False], True)]:
        outputs = Outputs(families={"emergencyStopCommand": 3})
        inputs = Inputs(
            manipulatorCommand=command(stop=ordered), motorControllerState=controller_states([1.0] * 3, stops)
        )
        manip.emergency_stop(inputs, outputs, context(parameters={"N": 3}))
        assert outputs.written["emergencyStopCommand"] == {1: True, 2: True, 3: True}
    quiet = Outputs(families={"emergencyStopCommand": 3})
    manip.emergency_stop(
        Inputs(manipulatorCommand=command(), motorControllerState=controller_states([1.0] * 3)), quiet, context()
    )
    assert quiet.written == {}


def test_output_motor_con_sends_no_current_to_a_stopped_drive() -> None:
    outputs = Outputs(families={"motorControllerCommand": 2})
    inputs = Inputs(windingCurrent={1: 1.5, 2: -2.0}, emergencyStopCommand={1: False, 2: True})
    manip.output_motor_con(inputs, outputs, context(parameters={"N": 2}))
    assert outputs.written["motorControllerCommand"] == {
        1: {"desiredWindingCurrent": 1.5, "emergencyStopCommand": False},
        2: {"desiredWindingCurrent": 0.0, "emergencyStopCommand": True},
    }


def test_output_manip_state_composes_figure_14a() -> None:
    outputs = Outputs("manipulatorState")
    pose = Msg(position=(0.1, 0.2, 0.3), orientation=(1.0, 0.0, 0.0, 0.0))
    inputs = Inputs(
        currentJointPos=(0.1, 0.2, 0.3),
        currentOperationalPos=pose,
        motionFinished=True,
        emergencyStopCommand={1: False, 2: False, 3: True},
    )
    manip.output_manip_state(inputs, outputs, context(time=0.002))
    state = outputs.written["manipulatorState"]
    assert state["emergencyStop"] is True and state["motionFinished"] is True
    assert state["currentOperationalPos"] == pose


def test_no_current_before_the_first_encoder_reading() -> None:
    outputs = Outputs("motionFinished", families={"windingCurrent": 6})
    inputs = Inputs(
        manipulatorCommand=command(joints=[0.0] * 6),
        motorControllerState=controller_states([0.0] * 6),
        currentJointPos=(0.0,) * 6,
    )
    manip.joint_move(inputs, outputs, context(subsystem="no-data"))
    assert outputs.written["windingCurrent"] == {k: 0.0 for k in range(1, 7)}
    assert outputs.written["motionFinished"] is False


# ---------------------------------------------------------------- motor controllers


def test_motor_controller_forwards_current_within_its_drives_limit() -> None:
    outputs = Outputs("windingCurrent", "currentMotorPos")
    inputs = Inputs(
        motorControllerCommand=Msg(desiredWindingCurrent=50.0, emergencyStopCommand=False),
        encoderReading=Msg(motorPos=12.5, driverFault=False),
    )
    motor_controller.regulate(inputs, outputs, context(parameters={"N": 6, "joint": 2}))
    assert outputs.written == {"windingCurrent": arm.drive(6, 2).current_limit, "currentMotorPos": 12.5}


def test_stopped_driver_gets_no_current_and_reports_the_stop() -> None:
    outputs = Outputs("windingCurrent", "currentMotorPos", "emergencyStop")
    motor_controller.stop_driver(Inputs(encoderReading=Msg(motorPos=3.0, driverFault=True)), outputs, context())
    assert outputs.written == {"windingCurrent": 0.0, "currentMotorPos": 3.0, "emergencyStop": True}


def test_output_state_writes_the_buffer_its_subsystem_declares() -> None:
    inputs = Inputs(currentMotorPos=1.0, emergencyStop=False)
    # a joint's motor controller has the parameter `joint`; the gripper's finger controller has not
    for name, parameters in (("motorControllerState", {"N": 6, "joint": 2}), ("fingerState", {})):
        outputs = Outputs(name)
        motor_controller.output_state(inputs, outputs, context(parameters=parameters))
        assert outputs.written == {name: {"currentMotorPos": 1.0, "emergencyStop": False}}


# ---------------------------------------------------------------- grip/a.cs


def test_gripper_closes_with_the_current_limit_and_reports_a_grasp_when_stopped_short() -> None:
    memory = context(subsystem="grip-test", period=0.01, parameters={})
    motor = arm.FINGER_DRIVE.gear_ratio * 0.02  # 4 cm open: stopped on a 4 cm box
    names = ("desiredFingerPos", "currentFingerPos", "windingCurrent", "motionFinished", "objectGrasped")
    results = []
    for iteration in range(20):
        memory.iteration, memory.time = iteration, iteration * 0.01
        outputs = Outputs(*names)
        inputs = Inputs(
            gripperCommand=Msg(desiredFingerPos=0.0), fingerState=Msg(currentMotorPos=motor, emergencyStop=False)
        )
        grip.move_fingers(inputs, outputs, memory)
        results.append(outputs.written)
    assert results[0]["windingCurrent"] == -arm.FINGER_DRIVE.current_limit
    assert results[0]["currentFingerPos"] == pytest.approx(0.04)
    assert not results[0]["objectGrasped"] and not results[0]["motionFinished"]
    assert results[-1]["objectGrasped"] and results[-1]["motionFinished"]


# ---------------------------------------------------------------- task/a.cs

_TASK_WRITES = ("manipulatorSetpoint", "gripperSetpoint", "commandIssued", "phaseComplete")


def _manipulator_state(position: tuple[float, float, float], finished: bool = True, stop: bool = False) -> Msg:
    return Msg(
        currentJointPos=(0.0,) * 6,
        currentOperationalPos=Msg(position=position, orientation=(0.0, 0.0, 1.0, 0.0)),
        motionFinished=finished,
        emergencyStop=stop,
    )


def _gripper_status(opening: float, finished: bool = True, grasped: bool = False) -> Msg:
    return Msg(currentFingerPos=opening, motionFinished=finished, objectGrasped=grasped)


def test_approach_issues_its_set_points_once_then_waits_for_the_arm_and_fingers() -> None:
    grasp_point = (*scene.BOX_XY, scene.GRASP_HEIGHT)
    outputs = Outputs(*_TASK_WRITES)
    inputs = Inputs(
        manipulatorState=_manipulator_state(scene.PARK), gripperStatus=_gripper_status(0.08), commandIssued=False
    )
    task.approach(inputs, outputs, context(iteration=0))
    setpoint = outputs.written["manipulatorSetpoint"]
    assert setpoint["jointPosSetpoint"] is None
    assert np.allclose(setpoint["operationalPosSetpoint"]["position"], grasp_point)
    assert outputs.written["gripperSetpoint"] == {"desiredFingerPos": scene.OPEN}
    assert outputs.written["commandIssued"] is True and outputs.written["phaseComplete"] is False
    # still where it started although it reports motionFinished: not done
    later = Outputs(*_TASK_WRITES)
    task.approach(inputs, later, context(iteration=5))
    assert later.written == {"commandIssued": False, "phaseComplete": False}
    arrived = Inputs(
        manipulatorState=_manipulator_state(grasp_point), gripperStatus=_gripper_status(0.08), commandIssued=False
    )
    done = Outputs(*_TASK_WRITES)
    task.approach(arrived, done, context(iteration=50))
    assert done.written["phaseComplete"] is True


def test_grasp_waits_for_the_fingers_to_stop_on_the_box() -> None:
    def run(status: Msg) -> bool:
        outputs = Outputs(*_TASK_WRITES)
        inputs = Inputs(manipulatorState=_manipulator_state((0, 0, 0)), gripperStatus=status, commandIssued=False)
        task.grasp(inputs, outputs, context(iteration=10))
        return bool(outputs.written["phaseComplete"])

    assert not run(_gripper_status(0.08, finished=True))  # the old status: still open
    assert run(_gripper_status(0.04, finished=True, grasped=True))
    assert run(_gripper_status(0.0, finished=True))  # a miss: closed completely


def test_only_a_manipulator_change_is_sent_to_the_manipulator() -> None:
    gripper_only = Inputs(manipulatorSetpoint=command(), commandIssued=True)
    outputs = Outputs("manipulatorCommand")
    task.send_manipulator_command(gripper_only, outputs, context())
    assert outputs.written == {}
    moved = Inputs(manipulatorSetpoint=command(joints=[0.0] * 6), commandIssued=True)
    task.send_manipulator_command(moved, outputs, context())
    assert "manipulatorCommand" in outputs.written
    silent = Outputs("manipulatorCommand")
    task.send_manipulator_command(
        Inputs(manipulatorSetpoint=command(joints=[0.0] * 6), commandIssued=False), silent, context()
    )
    assert silent.written == {}


def test_abort_confirms_the_emergency_stop_once() -> None:
    first = Outputs("manipulatorSetpoint", "commandIssued")
    inputs = Inputs(manipulatorState=_manipulator_state((0, 0, 0), stop=True))
    task.abort(inputs, first, context(iteration=0))
    assert first.written["manipulatorSetpoint"]["emergencyStopCommand"] is True
    assert first.written["commandIssued"] is True
    second = Outputs("manipulatorSetpoint", "commandIssued")
    task.abort(inputs, second, context(iteration=1))
    assert second.written == {"commandIssued": False}


def test_the_operators_stop_button_becomes_an_emergency_stop_command() -> None:
    button = SimpleNamespace(operator_stop_requested=lambda: True)
    outputs = Outputs(*_TASK_WRITES)
    inputs = Inputs(
        manipulatorState=_manipulator_state(scene.PARK), gripperStatus=_gripper_status(0.08), commandIssued=False
    )
    task.lift(inputs, outputs, context(iteration=7, environment=button))
    assert outputs.written["manipulatorSetpoint"]["emergencyStopCommand"] is True
    assert outputs.written["commandIssued"] is True


def test_every_function_the_spec_names_exists_with_three_parameters() -> None:
    import importlib
    import inspect
    import re

    spec = (Path(__file__).resolve().parent.parent / "examples" / "pick_and_place" / "system.earl").read_text()
    names = re.findall(r'python "(pick_and_place\.[a-z_]+):([a-z_]+)"', spec)
    assert len(names) >= 30
    for module_name, function_name in names:
        function = getattr(importlib.import_module(module_name), function_name)
        assert list(inspect.signature(function).parameters) == ["inputs", "outputs", "context"], function_name


# ---------------------------------------------------------------- the environment and the report


def test_the_environment_takes_n_from_the_expanded_spec_and_the_box_from_the_seed() -> None:
    from pick_and_place.environment import PickAndPlaceEnvironment, joints_of, make_environment

    import earl
    from earl.model.expand import expand

    system = earl.load(Path(__file__).resolve().parent.parent / "examples" / "pick_and_place" / "system.earl")
    environment = make_environment(expand(system, {"N": 3}), 5)
    assert environment.n == 3 and environment.plant.model.nu == 4
    assert joints_of(expand(system, {})) == 6
    same = PickAndPlaceEnvironment(3, 5)
    other = PickAndPlaceEnvironment(3, 6)
    assert environment.box_start == same.box_start != other.box_start
    assert max(abs(a - b) for a, b in zip(environment.box_start, scene.BOX_XY, strict=True)) <= scene.BOX_JITTER
    with pytest.raises(ValueError, match="no integer parameter `N`"):
        joints_of(SimpleNamespace(parameters=[]))


def test_an_environment_built_for_another_arm_is_said_by_every_drive_not_run_silently() -> None:
    from pick_and_place.environment import PickAndPlaceEnvironment

    import earl

    system = earl.load(Path(__file__).resolve().parent.parent / "examples" / "pick_and_place" / "system.earl", {"N": 3})
    simulation = earl.simulate(system, environment=PickAndPlaceEnvironment(6, 0))
    try:
        simulation.advance_to(0.004)
        drives = {fault.subsystem for fault in simulation.faults}
        assert drives == {f"manip/a.motor[{joint}]/re" for joint in (1, 2, 3)} | {"grip/a.fingerDrive/re"}
        raised = [fault for fault in simulation.faults if fault.kind == "exception"]
        assert raised and all("arm of N=3 joints, but the environment was built for N=6" in f.message for f in raised)
    finally:
        simulation.close()


def test_placement_measures_the_box_against_the_target() -> None:
    from pick_and_place.environment import PickAndPlaceEnvironment

    environment = PickAndPlaceEnvironment(6, 0)
    placement = environment.placement()
    expected = math.dist(environment.box_start, scene.TARGET_XY) * 1000.0
    assert placement.error_mm == pytest.approx(expected, abs=0.5)
    assert placement.resting and placement.released and not placement.placed


def test_the_report_ends_with_the_pick_and_place_line() -> None:
    import re

    from pick_and_place.environment import PickAndPlaceEnvironment
    from pick_and_place.report import summary

    environment = PickAndPlaceEnvironment(6, 0)
    environment.plant.advance(0.01)
    environment.close()
    text = summary(SimpleNamespace(environment=environment, time=0.01))
    last = text.splitlines()[-1]
    assert re.fullmatch(
        r"pick-and-place: placed=(true|false) error_mm=\d+\.\d+ sim_time_s=\d+\.\d+ wall_time_s=\d+\.\d+", last
    ), last
    assert "placed=false" in last


def test_pictures_of_a_run_or_the_reason_why_not(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from pick_and_place import environment as environment_module

    from earl.sim import render

    monkeypatch.setattr(environment_module, "VIDEO_SIZE", (64, 48))
    monkeypatch.setattr(environment_module, "PICTURE_SIZE", (64, 48))
    monkeypatch.setattr(environment_module, "VIDEO_FPS", 100.0)
    still = environment_module.PickAndPlaceEnvironment(3, 0, output=tmp_path / "still")
    still.advance(0.01)
    still.close()
    if not still.render_messages:  # without EARL_SIM_VIDEO=1: the picture of the end only
        assert [p.name for p in still.pictures] == ["final.png"]
    monkeypatch.setenv("EARL_SIM_VIDEO", "1")
    environment = environment_module.PickAndPlaceEnvironment(3, 0, output=tmp_path)
    environment.advance(0.03)
    environment.close()
    if environment.render_messages:  # no OpenGL here: the reason is given, the run went on
        assert "MuJoCo cannot render offscreen" in environment.render_messages[0]
    else:
        assert {p.name for p in environment.pictures} >= {"final.png"}
        assert any(p.suffix in {".gif", ".mp4"} for p in environment.pictures)

    def no_context(*args: object, **kwargs: object) -> None:
        raise RuntimeError("no EGL display")

    monkeypatch.setattr(render.mujoco, "Renderer", no_context)
    blind = environment_module.PickAndPlaceEnvironment(3, 0, output=tmp_path / "blind")
    blind.advance(0.01)
    blind.close()
    assert blind.pictures == []
    assert blind.render_messages[0].startswith("no pictures: MuJoCo cannot render offscreen here")
    assert "no EGL display" in blind.render_messages[0]
