"""`task/a.cs`: the pick-and-place sequence, one behaviour per phase (§3.1).

Each phase's function runs in stage pf.  In its first iteration it computes the
phase's set-points and sets `commandIssued`; stage pfo then sends them.  In the
following iterations it watches `manipulatorState` and `gripperStatus` and sets
`phaseComplete` when the phase is done, which the FSM turns into the next phase:

    approach  open the fingers; move the grasp point straight down around the box
    grasp     close the fingers until they stop on the box
    lift      raise the box to the carrying height
    carry     move above the place target
    place     lower the box onto the table
    release   open the fingers
    retreat   rise clear of the box, then a joint-space move back to the parking posture

A motion counts as done when manip/a reports motionFinished *and* its position is
at the phase's target; the second test covers the few milliseconds before manip/a
has seen a new command, when it still reports the previous motion as finished.

The operator's stop button (`operator_stop_requested()` on the environment, when it
has one) makes any phase send an emergency stop to manip/a.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from earl.sim import arm
from pick_and_place import scene
from pick_and_place.kinematics import tool_down_orientation

#: a Cartesian target is reached within this distance, metres
POSITION_TOLERANCE = 0.004
#: a joint target is reached within this angle, radians
JOINT_TOLERANCE = 0.01

_NO_MOTION = {"jointPosSetpoint": None, "operationalPosSetpoint": None, "emergencyStopCommand": False}


def _operational(position: tuple[float, float, float], yaw: float) -> dict[str, Any]:
    pose = {"position": list(position), "orientation": list(tool_down_orientation(yaw))}
    return {"jointPosSetpoint": None, "operationalPosSetpoint": pose, "emergencyStopCommand": False}


def _joint(q: list[float]) -> dict[str, Any]:
    return {"jointPosSetpoint": list(q), "operationalPosSetpoint": None, "emergencyStopCommand": False}


def _at_position(state: Any, target: tuple[float, float, float]) -> bool:
    position = np.asarray(state.currentOperationalPos.position, dtype=float)
    return bool(np.linalg.norm(position - np.asarray(target)) < POSITION_TOLERANCE)


def _at_joints(state: Any, target: list[float]) -> bool:
    q = np.asarray(state.currentJointPos, dtype=float)
    return bool(np.max(np.abs(q - np.asarray(target))) < JOINT_TOLERANCE)


def _moved_to(inputs: Any, target: tuple[float, float, float]) -> bool:
    state = inputs.manipulatorState
    return bool(state.motionFinished) and not inputs.commandIssued and _at_position(state, target)


def _operator_stop(context: Any) -> bool:
    requested = getattr(context.environment, "operator_stop_requested", None)
    return bool(requested()) if callable(requested) else False


def _phase(
    inputs: Any,
    outputs: Any,
    context: Any,
    manipulator: dict[str, Any] | None,
    gripper: float | None,
    complete: bool,
) -> None:
    """Issue the phase's set-points in its first iteration; afterwards report whether it is complete."""
    if _operator_stop(context) and not inputs.manipulatorState.emergencyStop:
        outputs.manipulatorSetpoint = {**_NO_MOTION, "emergencyStopCommand": True}
        outputs.commandIssued = True
        outputs.phaseComplete = False
        return
    if context.iteration == 0:
        outputs.manipulatorSetpoint = manipulator if manipulator is not None else _NO_MOTION
        if gripper is not None:
            outputs.gripperSetpoint = {"desiredFingerPos": gripper}
        outputs.commandIssued = True
        outputs.phaseComplete = False
        return
    outputs.commandIssued = False
    outputs.phaseComplete = complete


def _box_yaw() -> float:
    return scene.yaw_towards(*scene.BOX_XY)


def _target_yaw() -> float:
    return scene.yaw_towards(*scene.TARGET_XY)


def _grasp_point() -> tuple[float, float, float]:
    return (*scene.BOX_XY, scene.GRASP_HEIGHT)


def approach(inputs: Any, outputs: Any, context: Any) -> None:
    """Open the fingers and move the grasp point down around the box."""
    fingers_open = float(inputs.gripperStatus.currentFingerPos) > scene.OPEN - 0.005
    done = _moved_to(inputs, _grasp_point()) and fingers_open
    _phase(inputs, outputs, context, _operational(_grasp_point(), _box_yaw()), scene.OPEN, done)


def grasp(inputs: Any, outputs: Any, context: Any) -> None:
    """Close the fingers; done when they have stopped on the box (or, a miss, closed completely)."""
    status = inputs.gripperStatus
    missed = bool(status.motionFinished) and float(status.currentFingerPos) < scene.CLOSED + 0.003
    done = not inputs.commandIssued and context.iteration >= 2 and (bool(status.objectGrasped) or missed)
    _phase(inputs, outputs, context, None, scene.CLOSED, done)


def lift(inputs: Any, outputs: Any, context: Any) -> None:
    target = (*scene.BOX_XY, scene.CARRY_HEIGHT)
    _phase(inputs, outputs, context, _operational(target, _box_yaw()), None, _moved_to(inputs, target))


def carry(inputs: Any, outputs: Any, context: Any) -> None:
    target = (*scene.TARGET_XY, scene.CARRY_HEIGHT)
    _phase(inputs, outputs, context, _operational(target, _target_yaw()), None, _moved_to(inputs, target))


def place(inputs: Any, outputs: Any, context: Any) -> None:
    target = (*scene.TARGET_XY, scene.PLACE_HEIGHT)
    _phase(inputs, outputs, context, _operational(target, _target_yaw()), None, _moved_to(inputs, target))


def release(inputs: Any, outputs: Any, context: Any) -> None:
    status = inputs.gripperStatus
    opened = bool(status.motionFinished) and float(status.currentFingerPos) > scene.OPEN - 0.005
    done = not inputs.commandIssued and context.iteration >= 2 and opened
    _phase(inputs, outputs, context, None, scene.OPEN, done)


def park_configuration(n: int) -> list[float]:
    """The parking posture: the grasp point at scene.PARK, pointing down."""
    return arm.tool_down_configuration(n, scene.PARK)


def retreat(inputs: Any, outputs: Any, context: Any) -> None:
    """Rise straight up from the box, then move in joint space to the parking posture."""
    n = int(context.parameters["N"])
    above = (*scene.TARGET_XY, scene.CARRY_HEIGHT)
    park = park_configuration(n)
    state = inputs.manipulatorState
    if context.iteration > 0 and not _operator_stop(context) and _moved_to(inputs, above):
        # the first motion is done: the second one, once
        outputs.manipulatorSetpoint = _joint(park)
        outputs.commandIssued = True
        outputs.phaseComplete = False
        return
    parked = bool(state.motionFinished) and not inputs.commandIssued and _at_joints(state, park)
    _phase(inputs, outputs, context, _operational(above, _target_yaw()), None, parked)


def hold(inputs: Any, outputs: Any, context: Any) -> None:
    """The task is done: nothing more to do."""
    outputs.phaseComplete = False


def abort(inputs: Any, outputs: Any, context: Any) -> None:
    """manip/a stopped: confirm the emergency stop once, then issue nothing."""
    if context.iteration == 0:
        outputs.manipulatorSetpoint = {**_NO_MOTION, "emergencyStopCommand": True}
        outputs.commandIssued = True
    else:
        outputs.commandIssued = False


def send_manipulator_command(inputs: Any, outputs: Any, context: Any) -> None:
    """Send the manipulator set-point issued in this iteration (a gripper-only change sends nothing here)."""
    setpoint = inputs.manipulatorSetpoint
    if not inputs.commandIssued:
        return
    carries = (
        setpoint.jointPosSetpoint is not None
        or setpoint.operationalPosSetpoint is not None
        or bool(setpoint.emergencyStopCommand)
    )
    if carries:
        outputs.manipulatorCommand = setpoint


def send_gripper_command(inputs: Any, outputs: Any, context: Any) -> None:
    if inputs.commandIssued:
        outputs.gripperCommand = inputs.gripperSetpoint
