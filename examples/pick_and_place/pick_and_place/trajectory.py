"""Interpolation between set-points: a quintic time scaling in joint space and in operational space.

The quintic s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ starts and ends with zero velocity and zero
acceleration, so a move never asks the drives for a step in current.  A move's
duration is the shortest one that keeps the peak speed (15/8 · distance / T) under
the given limit, and never shorter than `MINIMUM_DURATION`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

Vector = NDArray[np.float64]

MINIMUM_DURATION = 0.3
PEAK_SPEED_FACTOR = 15.0 / 8.0


def quintic(tau: float) -> tuple[float, float, float]:
    """s, ds/dτ, d²s/dτ² of the quintic time scaling at τ ∈ [0, 1] (clamped outside)."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t2 = tau * tau
    t3 = t2 * tau
    return (
        10.0 * t3 - 15.0 * t3 * tau + 6.0 * t3 * t2,
        30.0 * t2 - 60.0 * t3 + 30.0 * t3 * tau,
        60.0 * tau - 180.0 * t2 + 120.0 * t3,
    )


def duration_for(distance: float, peak_speed: float) -> float:
    """The time a quintic move over `distance` needs to stay under `peak_speed`."""
    if peak_speed <= 0:
        raise ValueError(f"a peak speed must be positive, got {peak_speed}")
    return max(MINIMUM_DURATION, PEAK_SPEED_FACTOR * abs(distance) / peak_speed)


@dataclass(frozen=True)
class JointTrajectory:
    """From `start` to `goal` (radians per joint) in `duration` seconds."""

    start: Vector
    goal: Vector
    duration: float

    @classmethod
    def between(cls, start: Vector, goal: Vector, peak_speed: float) -> JointTrajectory:
        start = np.asarray(start, dtype=float)
        goal = np.asarray(goal, dtype=float)
        return cls(start, goal, duration_for(float(np.max(np.abs(goal - start), initial=0.0)), peak_speed))

    def sample(self, t: float) -> tuple[Vector, Vector, Vector]:
        """Position, velocity and acceleration of the reference at time `t` since the start."""
        s, ds, dds = quintic(t / self.duration)
        delta = self.goal - self.start
        return (
            self.start + s * delta,
            delta * (ds / self.duration),
            delta * (dds / self.duration**2),
        )


@dataclass(frozen=True)
class CartesianTrajectory:
    """A straight line for the position and a great-circle arc (slerp) for the orientation."""

    start_position: Vector
    start_orientation: Vector
    goal_position: Vector
    goal_orientation: Vector
    duration: float

    @classmethod
    def between(
        cls,
        start: tuple[Vector, Vector],
        goal: tuple[Vector, Vector],
        peak_speed: float,
        peak_angular_speed: float,
    ) -> CartesianTrajectory:
        p0, q0 = (np.asarray(v, dtype=float) for v in start)
        p1, q1 = (np.asarray(v, dtype=float) for v in goal)
        q0 = q0 / np.linalg.norm(q0)
        q1 = q1 / np.linalg.norm(q1)
        if float(np.dot(q0, q1)) < 0.0:  # the same rotation, the shorter way round
            q1 = -q1
        angle = 2.0 * float(np.arccos(min(1.0, abs(float(np.dot(q0, q1))))))
        duration = max(
            duration_for(float(np.linalg.norm(p1 - p0)), peak_speed), duration_for(angle, peak_angular_speed)
        )
        return cls(p0, q0, p1, q1, duration)

    def sample(self, t: float) -> tuple[Vector, Vector]:
        """Position and orientation (w, x, y, z) of the reference at time `t` since the start."""
        s, _, _ = quintic(t / self.duration)
        position = self.start_position + s * (self.goal_position - self.start_position)
        return position, slerp(self.start_orientation, self.goal_orientation, s)


#: multiplies a unit quaternion (w, x, y, z) into its conjugate, the inverse rotation
_CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])


def slerp(q0: Vector, q1: Vector, s: float) -> Vector:
    """The rotation a fraction `s` of the way from q0 to q1, at constant angular speed."""
    conjugate = q0 * _CONJUGATE
    difference = np.empty(4)
    mujoco.mju_mulQuat(difference, q1, conjugate)
    rotation = np.empty(3)
    mujoco.mju_quat2Vel(rotation, difference, 1.0)
    partial = np.empty(4)
    # math.sqrt of a dot product: np.linalg.norm costs more than the rest of this function on a 3-vector
    length = math.sqrt(float(rotation @ rotation))
    angle = length * s
    axis = rotation / length if angle > 0 else np.array([1.0, 0.0, 0.0])
    mujoco.mju_axisAngle2Quat(partial, axis, angle)
    result = np.empty(4)
    mujoco.mju_mulQuat(result, partial, q0)
    return result
