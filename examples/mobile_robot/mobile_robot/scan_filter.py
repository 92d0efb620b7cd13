"""`scanFilter/vr`: drops invalid beams, takes the median of each beam over the last MEDIAN_WINDOW
scans, and reduces the scan to the nearest obstacle ahead and the free distance per sector."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: the nearest obstacle is looked for within this angle either side of straight ahead (radians): what
#: stands beside or behind the base is not in its way
AHEAD = math.radians(70.0)
#: returns nearer than this are the lidar's own housing, not obstacles (metres)
MINIMUM_RANGE = 0.05


def remember(inputs: Any, outputs: Any, context: Any) -> None:
    keep = context.parameters["MEDIAN_WINDOW"] - 1
    history = [*inputs.history, inputs.scan]
    outputs.history = history[-keep:] if keep > 0 else []


def detect(inputs: Any, outputs: Any, context: Any) -> None:
    scan = inputs.scan
    sectors = context.parameters["SECTORS"]
    ranges = np.asarray(scan.ranges, dtype=float)
    same = [np.asarray(old.ranges, dtype=float) for old in inputs.history if len(old.ranges) == len(ranges)]
    if same:
        ranges = np.median(np.vstack([ranges, *same]), axis=0)
    bearings = scan.angleMin + np.arange(len(ranges)) * scan.angleIncrement
    valid = np.isfinite(ranges) & (ranges > MINIMUM_RANGE) & (ranges < scan.rangeMax)
    ahead = valid & (np.abs(bearings) <= AHEAD)
    if ahead.any():
        nearest = int(np.argmin(np.where(ahead, ranges, np.inf)))
        nearest_distance, nearest_bearing = float(ranges[nearest]), float(bearings[nearest])
    else:  # nothing in the way (or no scan yet): as far as the lidar sees
        nearest_distance, nearest_bearing = float(scan.rangeMax) if valid.size else math.inf, 0.0
    # sector 1 is centred straight ahead, the others follow counter-clockwise
    width = math.tau / sectors
    sector_of = np.floor(np.mod(bearings + width / 2.0, math.tau) / width).astype(int)
    free = [float(np.min(ranges[valid & (sector_of == sector)], initial=scan.rangeMax)) for sector in range(sectors)]
    outputs.report = {
        "nearestDistance": nearest_distance,
        "nearestBearing": nearest_bearing,
        "sectorDistance": free,
        "validBeams": int(valid.sum()),
    }


def output_obstacles(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.obstacles = inputs.report
