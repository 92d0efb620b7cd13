"""`base/a.cs`: odometry, goal following, obstacle avoidance and the emergency stop of the base.

Each function is one partial transition function of the spec; the FSM (system.earl) chooses which
run: `drive` steers to the goal, `avoidObstacle` turns away from what is near ahead while creeping on,
`emergencyStop` brakes until the coordinator asks to resume.
"""

from __future__ import annotations

import math
from typing import Any

#: the goal counts as reached within this distance (metres)
GOAL_TOLERANCE = 0.15
#: steering: turn rate per radian of heading error (1/s), and the highest turn rate (rad/s)
HEADING_GAIN = 2.0
MAX_TURN = 1.5
#: slowing down: metres per second per metre of remaining distance
APPROACH_GAIN = 0.8
#: while avoiding: forward speed (m/s) and turn rate (rad/s)
AVOID_SPEED = 0.12
AVOID_TURN = 0.9


def _twist(linear: float, angular: float) -> dict[str, float]:
    return {"linear": linear, "angular": angular}


def _sides(inputs: Any) -> tuple[float, float]:
    """The mean wheel speed of each side (rad/s): wheel 1 left, 2 right; with four, odd left, even right."""
    left = [state.angularVelocity for index, state in inputs.wheelState.items() if index % 2 == 1]
    right = [state.angularVelocity for index, state in inputs.wheelState.items() if index % 2 == 0]
    return sum(left) / len(left), sum(right) / len(right)


def initialise(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.pose = {"x": 0.0, "y": 0.0, "theta": 0.0}
    outputs.velocity = _twist(0.0, 0.0)
    outputs.currentGoal = {"x": 0.0, "y": 0.0, "theta": 0.0}


def localise(inputs: Any, outputs: Any, context: Any) -> None:
    """Odometry: the wheel speeds over the last period, integrated at the mid-point heading."""
    radius = context.parameters["WHEEL_RADIUS"]
    left, right = _sides(inputs)
    linear = radius * (left + right) / 2.0
    angular = radius * (right - left) / context.parameters["TRACK_WIDTH"]
    pose = inputs.pose
    step = context.period
    heading = pose.theta + angular * step / 2.0
    outputs.pose = {
        "x": pose.x + linear * math.cos(heading) * step,
        "y": pose.y + linear * math.sin(heading) * step,
        "theta": math.remainder(pose.theta + angular * step, math.tau),
    }
    outputs.velocity = _twist(linear, angular)


def drive_to_goal(inputs: Any, outputs: Any, context: Any) -> None:
    goal = inputs.goal
    target = goal.target if goal.target is not None else inputs.currentGoal
    outputs.currentGoal = target
    pose = inputs.pose
    dx, dy = target.x - pose.x, target.y - pose.y
    distance = math.hypot(dx, dy)
    if distance < GOAL_TOLERANCE:
        outputs.desiredTwist = _twist(0.0, 0.0)
        outputs.goalReached = True
        return
    error = math.remainder(math.atan2(dy, dx) - pose.theta, math.tau)
    angular = max(-MAX_TURN, min(MAX_TURN, HEADING_GAIN * error))
    # full speed only when facing the goal: turn on the spot first
    linear = min(goal.maxSpeed, APPROACH_GAIN * distance) * max(0.0, math.cos(error)) ** 2
    outputs.desiredTwist = _twist(linear, angular)
    outputs.goalReached = False


def avoid(inputs: Any, outputs: Any, context: Any) -> None:
    """Turn away from an obstacle near ahead and creep on; once none is, go straight on past it.

    It also says whether the way to the goal is clear (goalWayClear/m, which pathClear/pp reads): with
    the post on the straight line to the goal, leaving as soon as nothing was near ahead made driveToGoal
    turn straight back at it, and the FSM went drive -> avoidObstacle -> drive ten times in 8 s."""
    obstacles, pose, goal = inputs.obstacles, inputs.pose, inputs.currentGoal
    parameters = context.parameters
    near = parameters["AVOID_DISTANCE"] + parameters["CLEARANCE_MARGIN"]
    if obstacles.nearestDistance < near:
        away = -1.0 if obstacles.nearestBearing >= 0.0 else 1.0
        outputs.desiredTwist = _twist(AVOID_SPEED, away * AVOID_TURN)
    else:
        outputs.desiredTwist = _twist(AVOID_SPEED, 0.0)
    # the scan filter's sector (0 straight ahead, counter-clockwise) that the goal's direction lies in
    sectors = parameters["SECTORS"]
    width = math.tau / sectors
    bearing = math.atan2(goal.y - pose.y, goal.x - pose.x) - pose.theta
    sector = math.floor((bearing + width / 2.0) % math.tau / width) % sectors
    distance = math.hypot(goal.x - pose.x, goal.y - pose.y)
    outputs.goalWayClear = obstacles.sectorDistance[sector] > min(near, distance)


def hold(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.desiredTwist = _twist(0.0, 0.0)
    outputs.braking = False
    outputs.resetWheelFaults = False


def brake(inputs: Any, outputs: Any, context: Any) -> None:
    goal = inputs.goal
    outputs.desiredTwist = _twist(0.0, 0.0)
    outputs.braking = True
    # the coordinator's "resume" (neither a stop nor a cancel) clears a latched driver fault too
    outputs.resetWheelFaults = not goal.emergencyStop and not goal.cancel


def output_wheel_commands(inputs: Any, outputs: Any, context: Any) -> None:
    """Inverse kinematics of the differential drive: the twist as one angular velocity per wheel."""
    radius = context.parameters["WHEEL_RADIUS"]
    half_track = context.parameters["TRACK_WIDTH"] / 2.0
    twist = inputs.desiredTwist
    left = (twist.linear - twist.angular * half_track) / radius
    right = (twist.linear + twist.angular * half_track) / radius
    for wheel in range(1, context.parameters["WHEELS"] + 1):
        outputs.wheelCommand[wheel] = {
            "angularVelocity": left if wheel % 2 == 1 else right,
            "brake": inputs.braking,
            "resetFault": inputs.resetWheelFaults,
        }


def output_status(inputs: Any, outputs: Any, context: Any) -> None:
    reached = inputs.goalReached
    outputs.status = {
        "pose": inputs.pose,
        "velocity": inputs.velocity,
        "activeGoal": None if reached else inputs.currentGoal,
        "goalReached": reached,
        "emergencyStop": inputs.braking,
        # the control subsystem's second stage reads memory only (Eq. 6): the obstacles are not among it
        "nearestObstacle": math.inf,
        "mode": context.state,
    }
