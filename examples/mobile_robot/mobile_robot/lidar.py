"""`lidar/rr`: reads a revolution of the lidar (the world's) and publishes it as a LaserScan."""

from __future__ import annotations

import math
from typing import Any

from mobile_robot.world import BEAMS, RANGE_MAX


def acquire(inputs: Any, outputs: Any, context: Any) -> None:
    world = context.environment
    if world is None or not hasattr(world, "scan"):
        raise RuntimeError(f"{context.subsystem} reads a simulated lidar and needs the mobile robot's world (run.toml)")
    outputs.rawScan = {
        "stamp": round(context.time * 1e9),
        "angleMin": -math.pi,
        "angleIncrement": math.tau / BEAMS,
        "rangeMax": RANGE_MAX,
        "ranges": world.scan(),
    }


def publish_scan(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.scan = inputs.rawScan
