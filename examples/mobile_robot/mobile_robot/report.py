"""The closing line of `earl run examples/mobile_robot` (`report` in run.toml)."""

from __future__ import annotations

from typing import Any


def summary(simulation: Any) -> str:
    """`mobile-robot: patrolled=<true|false> coordinator=<state> least_clearance_m=… driven_m=… sim_time_s=…`."""
    world = simulation.environment
    coordinator = simulation.state_of("coordinator/a.cs").state
    patrolled = coordinator == "done" and world.least_clearance > 0.0
    return (
        f"mobile-robot: patrolled={'true' if patrolled else 'false'} coordinator={coordinator} "
        f"least_clearance_m={world.least_clearance:.3f} driven_m={world.distance_driven:.2f} "
        f"sim_time_s={simulation.time:.3f}"
    )
