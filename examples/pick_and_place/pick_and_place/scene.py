"""The workcell as the task agent knows it: where the box is, where it goes, how high to carry it.

The task agent has no camera: like a machine in a fixture-based cell it knows the
layout.  The environment builds the same layout (moving the box by up to
`BOX_JITTER` metres, drawn from the run's seed) so that the task never sees
a perfect world.
"""

from __future__ import annotations

import math

from earl.sim import arm

#: the box's centre on the table, metres
BOX_XY = (0.45, 0.0)
#: the place target's centre on the table, metres
TARGET_XY = (0.10, 0.42)
#: the largest offset of the box from BOX_XY, per axis, metres
BOX_JITTER = 0.002
#: height of the grasp point when the fingers hold the box (1 cm above its centre)
GRASP_HEIGHT = arm.BOX_HALF_SIZE + 0.01
#: carried this high, the box clears the table by about 11 cm
CARRY_HEIGHT = 0.16
#: released this high, the box drops about 2 mm onto the table
PLACE_HEIGHT = GRASP_HEIGHT + 0.002
#: the arm starts, and ends, with the grasp point here: above the box
PARK = (0.45, 0.0, 0.26)
#: finger openings, metres between the pads
OPEN = 0.08
CLOSED = 0.0
#: placed: the box rests within this distance of the target
PLACE_TOLERANCE = 0.010


def yaw_towards(x: float, y: float) -> float:
    return math.atan2(y, x)
