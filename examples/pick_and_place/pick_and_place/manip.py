"""`manip/a.cs`: the partial transition functions of the manipulator's control subsystem (§3.2).

Each function follows the runtime's contract (docs/runtime.md): `inputs` holds what
it declares it reads, `outputs` takes what it declares it writes.

- calculate_position — encoder readings → joint positions and the gripper's pose;
- joint_move — joint-space quintic interpolation, and the winding currents realising it;
- operational_move — operational-space interpolation, inverse kinematics by damped
  least squares, and the winding currents;
- passive_regulation — the winding currents that hold the arm still against gravity;
- emergency_stop — copies an emergency stop towards every motor controller;
- output_manip_state, output_motor_con — Figure 14a and 14b.

All winding currents come from one regulator per joint (Eq. (2)–(3), regulator.py),
so switching between behaviours never makes the current jump.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pick_and_place.kinematics import Pose, RobotModel, Vector, robot_model
from pick_and_place.regulator import Gains, RegulatorState, regulate
from pick_and_place.store import state_of
from pick_and_place.trajectory import CartesianTrajectory, JointTrajectory

#: peak joint speed of a joint-space move, rad/s
JOINT_SPEED = 0.8
#: peak speed of the grasp point in an operational-space move, m/s
CARTESIAN_SPEED = 0.3
ANGULAR_SPEED = 1.0
#: damped-least-squares steps per iteration: the reference moves little in 2 ms, so one step keeps up
IK_STEPS = 1
#: a move is finished when every joint is this close to its goal (rad) ...
JOINT_TOLERANCE = 0.004
#: ... or this long after its trajectory ended, whatever the error (s)
SETTLE_TIMEOUT = 0.8


def _joints(context: Any) -> int:
    return int(context.parameters["N"])


def _measured_motor_positions(inputs: Any, n: int) -> Vector:
    states = inputs.motorControllerState
    return np.array([float(states[k].currentMotorPos) for k in range(1, n + 1)])


def _no_reading_yet(context: Any) -> bool:
    """The first iteration of the run, the only one that has no motor position to work from.

    An iteration computes before it receives (Figure 5b), so the first one sees input buffers that
    received nothing and hold zeros, not readings.  From the second on every motor controller has
    reported: a controller reports only once its drive's first encoder reading has arrived (its
    `start` state), and idle waits for all of them (obligatory).
    """
    return context.iteration == 0 and context.time == 0.0


def _write_currents(outputs: Any, currents: Vector) -> None:
    for k, current in enumerate(currents, start=1):
        outputs.windingCurrent[k] = float(current)


class _Controller:
    """The regulator and reference of one manipulator control subsystem, kept across iterations."""

    def __init__(self, model: RobotModel, measured: Vector) -> None:
        self.model = model
        q = model.motor_to_joint(measured)
        self.gains = Gains.design(model.joint_inertia(q), model.torque_per_ampere, model.gear)
        self.regulator = RegulatorState(integral=np.zeros(model.n))
        self.reference = q
        self.reference_velocity = np.zeros(model.n)
        self.move_start = 0.0
        self.joint_trajectory: JointTrajectory | None = None
        self.cartesian_trajectory: CartesianTrajectory | None = None
        self.goal = q

    def currents(self, measured: Vector, acceleration: Vector, period: float) -> Vector:
        """Eq. (2)–(3) on every joint, with the feed-forward of the robot model."""
        model = self.model
        torque = model.inverse_dynamics(self.reference, self.reference_velocity, acceleration)
        return regulate(
            self.gains,
            self.regulator,
            model.joint_to_motor(self.reference),
            model.joint_to_motor(self.reference_velocity),
            measured,
            torque / model.torque_per_ampere,
            period,
            model.current_limit,
        )

    def finished(self, measured: Vector, elapsed: float, duration: float, converged: bool = True) -> bool:
        """The trajectory has ended and the arm is at its goal — or it has had SETTLE_TIMEOUT to get there."""
        if elapsed < duration:
            return False
        if elapsed >= duration + SETTLE_TIMEOUT:
            return True
        error = np.max(np.abs(self.goal - self.model.motor_to_joint(measured)))
        return converged and bool(error < JOINT_TOLERANCE)


def _controller(context: Any, measured: Vector) -> _Controller | None:
    memory = state_of(context)
    controller: _Controller | None = memory.get("controller")
    if controller is None and not _no_reading_yet(context):
        controller = memory["controller"] = _Controller(robot_model(_joints(context)), measured)
    return controller


# ---------------------------------------------------------------- the functions of stage pf


def calculate_position(inputs: Any, outputs: Any, context: Any) -> None:
    """currentJointPos and currentOperationalPos from the motor controllers' encoder readings.

    Before the first reading nothing is written: memory keeps its initial value, which is not reported.
    The robot model is built then all the same: the first iteration is the one a real-time run makes
    before its clock starts, and building it (MuJoCo compiling the robot's XML) takes milliseconds.
    """
    model = robot_model(_joints(context))
    if _no_reading_yet(context):
        return
    q = model.motor_to_joint(_measured_motor_positions(inputs, model.n))
    pose = model.forward(q)
    outputs.currentJointPos = q
    outputs.currentOperationalPos = {"position": pose.position, "orientation": pose.orientation}


def joint_move(inputs: Any, outputs: Any, context: Any) -> None:
    """Figure 13: interpolate in joint space towards jointPosSetpoint and regulate the motors onto it."""
    n = _joints(context)
    measured = _measured_motor_positions(inputs, n)
    controller = _controller(context, measured)
    if controller is None:
        _write_currents(outputs, np.zeros(n))
        outputs.motionFinished = False
        return
    if context.iteration == 0 or controller.joint_trajectory is None:
        setpoint = inputs.manipulatorCommand.jointPosSetpoint
        goal = controller.reference if setpoint is None else np.asarray(setpoint, dtype=float)
        goal = np.clip(goal, controller.model.lower, controller.model.upper)
        controller.joint_trajectory = JointTrajectory.between(controller.reference, goal, JOINT_SPEED)
        controller.cartesian_trajectory = None
        controller.goal = goal
        controller.move_start = context.time
    trajectory = controller.joint_trajectory
    elapsed = context.time - controller.move_start
    controller.reference, controller.reference_velocity, acceleration = trajectory.sample(elapsed)
    _write_currents(outputs, controller.currents(measured, acceleration, context.period))
    outputs.motionFinished = controller.finished(measured, elapsed, trajectory.duration)


def operational_move(inputs: Any, outputs: Any, context: Any) -> None:
    """Interpolate the gripper's pose towards operationalPosSetpoint; inverse kinematics gives the joints."""
    n = _joints(context)
    measured = _measured_motor_positions(inputs, n)
    controller = _controller(context, measured)
    if controller is None:
        _write_currents(outputs, np.zeros(n))
        outputs.motionFinished = False
        return
    model = controller.model
    if context.iteration == 0 or controller.cartesian_trajectory is None:
        setpoint = inputs.manipulatorCommand.operationalPosSetpoint
        start = model.forward(controller.reference)
        if setpoint is None:
            goal = (start.position, start.orientation)
        else:
            goal = (np.asarray(setpoint.position, dtype=float), np.asarray(setpoint.orientation, dtype=float))
        controller.cartesian_trajectory = CartesianTrajectory.between(
            (start.position, start.orientation), goal, CARTESIAN_SPEED, ANGULAR_SPEED
        )
        controller.joint_trajectory = None
        controller.move_start = context.time
    trajectory = controller.cartesian_trajectory
    elapsed = context.time - controller.move_start
    position, orientation = trajectory.sample(elapsed)
    previous = controller.reference
    reference = model.inverse_kinematics(Pose(position, orientation), previous, iterations=IK_STEPS)
    controller.reference = reference
    controller.reference_velocity = (reference - previous) / context.period
    # the goal, for `finished`, is where the reference ends up once the line is done
    controller.goal = reference
    _write_currents(outputs, controller.currents(measured, np.zeros(n), context.period))
    # the inverse kinematics has converged when its steps have become negligible
    converged = bool(np.max(np.abs(reference - previous)) < 1e-6)
    outputs.motionFinished = controller.finished(measured, elapsed, trajectory.duration, converged)


def passive_regulation(inputs: Any, outputs: Any, context: Any) -> None:
    """Hold the arm where its reference is (where the last move ended, or where it started)."""
    n = _joints(context)
    measured = _measured_motor_positions(inputs, n)
    controller = _controller(context, measured)
    if controller is None:
        _write_currents(outputs, np.zeros(n))
        return
    if context.iteration == 0:
        controller.joint_trajectory = None
        controller.cartesian_trajectory = None
    controller.reference_velocity = np.zeros(n)
    _write_currents(outputs, controller.currents(measured, np.zeros(n), context.period))


def emergency_stop(inputs: Any, outputs: Any, context: Any) -> None:
    """Copy an emergency stop — ordered by the task or reported by any drive — to every motor controller."""
    states = inputs.motorControllerState
    stop = bool(inputs.manipulatorCommand.emergencyStopCommand) or any(bool(s.emergencyStop) for _, s in states.items())
    if stop:
        for k, _ in states.items():
            outputs.emergencyStopCommand[k] = True


# ---------------------------------------------------------------- the functions of stage pfo


def output_manip_state(inputs: Any, outputs: Any, context: Any) -> None:
    """Figure 14a: compose manipulatorState/ob from memory; nothing before the first reading (no pose is known)."""
    if _no_reading_yet(context):
        return
    stops = inputs.emergencyStopCommand
    outputs.manipulatorState = {
        "currentJointPos": inputs.currentJointPos,
        "currentOperationalPos": inputs.currentOperationalPos,
        "motionFinished": bool(inputs.motionFinished),
        "emergencyStop": any(bool(s) for s in stops),
    }


def output_motor_con(inputs: Any, outputs: Any, context: Any) -> None:
    """Figure 14b: one MotorControllerCommand per drive; a stopped drive is sent no current."""
    currents = inputs.windingCurrent
    stops = inputs.emergencyStopCommand
    for k in range(1, len(currents) + 1):
        stop = bool(stops[k])
        current = float(currents[k])
        outputs.motorControllerCommand[k] = {
            "desiredWindingCurrent": 0.0 if stop or not math.isfinite(current) else current,
            "emergencyStopCommand": stop,
        }
