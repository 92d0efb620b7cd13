"""The closing line of `earl run examples/mobile_robot` (`report` in run.toml)."""

from __future__ import annotations

from typing import Any

COORDINATOR = "coordinator/a.cs"


def summary(simulation: Any) -> str:
    """`mobile-robot: patrolled=<true|false> coordinator=<state> least_clearance_m=… driven_m=… sim_time_s=…`.

    In a process of a split run (examples/mobile_robot/deploy.toml) that does not run the coordinator,
    whose state says whether the patrol is done: `patrolled=unknown coordinator=elsewhere …`, after a
    line saying where to look (the summary stays the last line)."""
    world = simulation.environment
    measured = (
        f"least_clearance_m={world.least_clearance:.3f} driven_m={world.distance_driven:.2f} "
        f"sim_time_s={simulation.time:.3f}"
    )
    if COORDINATOR not in simulation.subsystems:
        return (
            "coordinator/a runs in another process: its summary says whether the patrol is done\n"
            f"mobile-robot: patrolled=unknown coordinator=elsewhere {measured}"
        )
    coordinator = simulation.state_of(COORDINATOR).state
    patrolled = coordinator == "done" and world.least_clearance > 0.0
    return f"mobile-robot: patrolled={'true' if patrolled else 'false'} coordinator={coordinator} {measured}"
