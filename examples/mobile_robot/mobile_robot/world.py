"""The floor the mobile robot drives on: a walled room with round obstacles, two DC-motor wheels and
a 2-D lidar, integrated in lockstep with run time.

A differential-drive base on a flat floor needs no contact solver: each wheel is a DC motor
(armature voltage → current → torque, back-EMF and viscous friction) whose shaft turns the
wheel without slip, and the base moves as the two wheel speeds say.  The lidar casts its beams
against the room's walls and the obstacles.  Everything is NumPy and deterministic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: encoder counts per wheel revolution (a 16-bit magnetic encoder on the wheel shaft)
COUNTS_PER_REVOLUTION = 65536
#: the motor: armature resistance (ohm), torque and back-EMF constant (N m/A = V s/rad), rotor and
#: wheel inertia seen at the wheel (kg m^2), viscous friction (N m s/rad), supply voltage (V)
RESISTANCE = 1.2
MOTOR_CONSTANT = 0.5
INERTIA = 0.02
FRICTION = 0.02
SUPPLY = 12.0
#: the integration step, seconds: well under the motor's electrical-mechanical time constant
STEP = 0.0005
#: the base's footprint: a disc of this radius, metres (a collision is the disc touching anything)
BODY_RADIUS = 0.2
#: the lidar: beams per revolution, and the longest range it reports, metres
BEAMS = 180
RANGE_MAX = 8.0


@dataclass(frozen=True)
class Obstacle:
    """A round post on the floor: centre and radius, metres."""

    x: float
    y: float
    radius: float


@dataclass
class Room:
    """The walls (an axis-aligned rectangle, metres) and what stands inside."""

    low: tuple[float, float] = (-2.0, -2.0)
    high: tuple[float, float] = (8.0, 8.0)
    obstacles: list[Obstacle] = field(default_factory=list)


@dataclass
class Wheel:
    voltage: float = 0.0
    speed: float = 0.0  # rad/s
    angle: float = 0.0  # rad, integrated
    fault: bool = False


class World:
    """The room, the base in it, and time."""

    def __init__(
        self, room: Room, wheels: int, wheel_radius: float, track_width: float, pose: tuple[float, float, float]
    ) -> None:
        self.room = room
        self.wheels = [Wheel() for _ in range(wheels)]
        self.wheel_radius = wheel_radius
        self.track_width = track_width
        self.x, self.y, self.theta = pose
        self.time = 0.0
        #: the least distance between the base's footprint and anything, over the whole run
        self.least_clearance = self.clearance()
        self.distance_driven = 0.0
        #: (wheel from 1, from, until): the wheel's driver reports a fault in that span of run time
        self.fault_windows: list[tuple[int, float, float]] = []

    # ------------------------------------------------------------ physics
    def advance(self, time: float) -> None:
        while self.time < time - 1e-12:
            step = min(STEP, time - self.time)
            self._step(step)
            self.time += step

    def _step(self, dt: float) -> None:
        for number, wheel in enumerate(self.wheels, start=1):
            wheel.fault = any(w == number and start <= self.time < end for w, start, end in self.fault_windows)
            voltage = 0.0 if wheel.fault else max(-SUPPLY, min(SUPPLY, wheel.voltage))
            current = (voltage - MOTOR_CONSTANT * wheel.speed) / RESISTANCE
            torque = MOTOR_CONSTANT * current - FRICTION * wheel.speed
            wheel.speed += torque / INERTIA * dt
            wheel.angle += wheel.speed * dt
        left = self._side_speed(left=True)
        right = self._side_speed(left=False)
        linear = self.wheel_radius * (left + right) / 2.0
        angular = self.wheel_radius * (right - left) / self.track_width
        self.theta = math.remainder(self.theta + angular * dt, math.tau)
        self.x += linear * math.cos(self.theta) * dt
        self.y += linear * math.sin(self.theta) * dt
        self.distance_driven += abs(linear) * dt
        self.least_clearance = min(self.least_clearance, self.clearance())

    def _side_speed(self, left: bool) -> float:
        """Wheel 1 is on the left, wheel 2 on the right; with four, odd wheels left, even right."""
        speeds = [w.speed for index, w in enumerate(self.wheels, start=1) if (index % 2 == 1) == left]
        return sum(speeds) / len(speeds)

    def clearance(self) -> float:
        """Metres between the base's footprint and the nearest wall or obstacle (negative: overlapping)."""
        walls = min(
            self.x - self.room.low[0], self.room.high[0] - self.x, self.y - self.room.low[1], self.room.high[1] - self.y
        )
        posts = [math.hypot(self.x - o.x, self.y - o.y) - o.radius for o in self.room.obstacles]
        return min([walls, *posts]) - BODY_RADIUS

    # ------------------------------------------------------------ what the drives and the lidar touch
    def set_voltage(self, wheel: int, voltage: float) -> float:
        """The armature voltage of wheel `wheel` (from 1), within the supply; the voltage applied."""
        applied = max(-SUPPLY, min(SUPPLY, voltage))
        self.wheels[wheel - 1].voltage = applied
        return applied

    def encoder(self, wheel: int) -> int:
        return math.floor(self.wheels[wheel - 1].angle * COUNTS_PER_REVOLUTION / math.tau)

    def driver_fault(self, wheel: int) -> bool:
        return self.wheels[wheel - 1].fault

    def scan(self) -> np.ndarray:
        """One revolution of the lidar at the base's centre: a range per beam, counter-clockwise from
        straight behind (`-pi`), RANGE_MAX where a beam hits nothing nearer."""
        angles = self.theta + (-math.pi + np.arange(BEAMS) * (math.tau / BEAMS))
        dx, dy = np.cos(angles), np.sin(angles)
        with np.errstate(divide="ignore", invalid="ignore"):
            tx = np.where(dx > 0, (self.room.high[0] - self.x) / dx, (self.room.low[0] - self.x) / dx)
            ty = np.where(dy > 0, (self.room.high[1] - self.y) / dy, (self.room.low[1] - self.y) / dy)
        ranges = np.minimum(np.where(np.isfinite(tx), tx, np.inf), np.where(np.isfinite(ty), ty, np.inf))
        for post in self.room.obstacles:
            # |p + t d - c| = r: t^2 - 2 t (d.(c - p)) + |c - p|^2 - r^2 = 0, the nearer root ahead
            cx, cy = post.x - self.x, post.y - self.y
            along = dx * cx + dy * cy
            discriminant = along**2 - (cx * cx + cy * cy - post.radius**2)
            hit = (discriminant >= 0) & (along > 0)
            distance = np.where(hit, along - np.sqrt(np.maximum(discriminant, 0.0)), np.inf)
            ranges = np.minimum(ranges, np.where(distance > 0, distance, np.inf))
        return np.minimum(ranges, RANGE_MAX)
