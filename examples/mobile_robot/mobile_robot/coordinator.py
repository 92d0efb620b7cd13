"""`coordinator/a.cs`: holds the route, sends the base one waypoint at a time, and asks a base that
stopped for an emergency to resume (as a fleet manager would)."""

from __future__ import annotations

from typing import Any

#: the patrol: the corners of a square around the room's middle (metres, radians), then home
ROUTE = (
    {"x": 5.0, "y": 0.0, "theta": 0.0},
    {"x": 5.0, "y": 5.0, "theta": 0.0},
    {"x": 0.0, "y": 3.0, "theta": 0.0},
    {"x": 0.0, "y": 0.0, "theta": 0.0},
)
MAX_SPEED = 0.4


def load_route(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.route = ROUTE
    outputs.waypointIndex = 1
    outputs.finalWaypoint = len(ROUTE) == 1


def select_waypoint(inputs: Any, outputs: Any, context: Any) -> None:
    """The next waypoint once the base reached the last one sent; the same one after a recovery."""
    index = inputs.waypointIndex
    if inputs.status.goalReached and index < len(inputs.route):
        index += 1
    outputs.waypointIndex = index
    outputs.finalWaypoint = index == len(inputs.route)
    outputs.command = {
        "target": inputs.route[index - 1],
        "maxSpeed": MAX_SPEED,
        "cancel": False,
        "emergencyStop": False,
    }


def compose_resume(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.command = {"target": None, "maxSpeed": MAX_SPEED, "cancel": False, "emergencyStop": False}


def send_command(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.goal = inputs.command
