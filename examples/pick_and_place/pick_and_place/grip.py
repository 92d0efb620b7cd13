"""`grip/a.cs`: the two-finger gripper's control subsystem.

The fingers are driven by one motor through a lead screw; the opening between the
pads is 2 × motor position / lead-screw ratio.  A proportional regulator on the
opening gives the winding current, limited to the drive's current limit: when the
fingers close on the box they stop, the error stays, and the current saturates —
the grasp force is the limit times the drive's force per ampere (24 N).  The
fingers count as stopped when the opening changed less than `STALL_SPEED` for
`STALL_ITERATIONS` iterations; stopped short of a closing set-point means an
object is grasped.
"""

from __future__ import annotations

from typing import Any

from earl.sim import arm
from pick_and_place.store import state_of

#: amperes per metre of opening error
PROPORTIONAL_GAIN = 150.0
#: a move is finished within this distance of the set-point, metres
POSITION_TOLERANCE = 0.0015
#: below this speed of the opening (m/s) the fingers are stopped
STALL_SPEED = 0.003
STALL_ITERATIONS = 3
#: the fingers count as under way once they moved this far (m), or after this long (s)
START_DISTANCE = 0.002
START_TIME = 0.15
#: stopped at least this far short of a closing set-point: an object is in the way, metres
BLOCKED_MARGIN = 0.003


def finger_opening(motor_position: float) -> float:
    """Metres between the finger pads for a finger-drive motor position in radians."""
    return 2.0 * motor_position / arm.FINGER_DRIVE.gear_ratio


def _current(desired: float, opening: float) -> float:
    limit = arm.FINGER_DRIVE.current_limit
    return min(max(PROPORTIONAL_GAIN * (desired - opening), -limit), limit)


def _stopped(context: Any, opening: float) -> bool:
    """Slow for STALL_ITERATIONS iterations, after having moved (or after START_TIME to get going)."""
    memory = state_of(context)
    if context.iteration == 0:
        memory["start"] = opening
        memory["slow"] = 0
    previous = memory.get("opening")
    slow = previous is not None and abs(opening - previous) / context.period < STALL_SPEED
    memory["slow"] = memory.get("slow", 0) + 1 if slow else 0
    memory["opening"] = opening
    started = (
        abs(opening - memory.get("start", opening)) > START_DISTANCE or context.iteration * context.period >= START_TIME
    )
    return started and int(memory["slow"]) >= STALL_ITERATIONS


def move_fingers(inputs: Any, outputs: Any, context: Any) -> None:
    """Drive the fingers towards desiredFingerPos; say when they got there, or stopped on an object."""
    desired = min(max(float(inputs.gripperCommand.desiredFingerPos), 0.0), arm.MAX_OPENING)
    opening = finger_opening(float(inputs.fingerState.currentMotorPos))
    stopped = _stopped(context, opening)
    blocked = stopped and opening > desired + BLOCKED_MARGIN
    outputs.desiredFingerPos = desired
    outputs.currentFingerPos = opening
    outputs.windingCurrent = _current(desired, opening)
    outputs.motionFinished = context.iteration >= STALL_ITERATIONS and (
        abs(desired - opening) < POSITION_TOLERANCE or stopped
    )
    outputs.objectGrasped = blocked


def hold_fingers(inputs: Any, outputs: Any, context: Any) -> None:
    """Keep regulating towards the last set-point (a grasp keeps squeezing)."""
    desired = float(inputs.desiredFingerPos)
    opening = finger_opening(float(inputs.fingerState.currentMotorPos))
    _stopped(context, opening)
    outputs.currentFingerPos = opening
    outputs.windingCurrent = _current(desired, opening)
    outputs.objectGrasped = opening > desired + BLOCKED_MARGIN


def output_status(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.gripperStatus = {
        "currentFingerPos": float(inputs.currentFingerPos),
        "motionFinished": bool(inputs.motionFinished),
        "objectGrasped": bool(inputs.objectGrasped),
    }


def output_finger_command(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.fingerCommand = {"desiredWindingCurrent": float(inputs.windingCurrent), "emergencyStopCommand": False}
