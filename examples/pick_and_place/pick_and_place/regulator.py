"""The motor position regulator of the manual's Eq. (2)–(3), one per joint, in motor units.

    windingCurrent = Kp·e(t) + Ki·∫₀ᵗ e(t′) dt′                         (2)
    e = desiredMotorPos − currentMotorPos                               (3)

Positions are at the motor shaft (joint angle × gear ratio), currents in amperes.
Two terms are added to the manual's PI law, both standard for a geared arm and both
documented in docs/simulation.md: a derivative term on the motor velocity error
(the arm's own friction is too small to damp a PI loop), and a model-based
feed-forward current (gravity and the reference motion's inertia, from the
controller's own robot model), so that the integral only corrects what the model
gets wrong — the payload, for instance.  The integral stops growing while the
current is saturated in the direction the error pushes (anti-windup).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Vector = NDArray[np.float64]

#: closed-loop natural frequency of every joint, rad/s (about 5 Hz)
NATURAL_FREQUENCY = 32.0
DAMPING_RATIO = 0.9
#: the integral's corner frequency as a fraction of the natural frequency
INTEGRAL_FRACTION = 0.25
#: time constant of the low-pass filter on the encoder-differenced velocity, s
VELOCITY_FILTER = 0.004


@dataclass(frozen=True)
class Gains:
    """Per joint, in motor units: A/rad, A/(rad·s), A·s/rad."""

    proportional: Vector
    integral: Vector
    derivative: Vector

    @classmethod
    def design(cls, inertia: Vector, torque_per_ampere: Vector, gear: Vector) -> Gains:
        """Place each joint's poles from its inertia (rotor included) and its drive's constants.

        At the joint a stiffness K = J·ω² needs K / (kt·G²) amperes per motor radian,
        because a motor radian is 1/G joint radians and an ampere gives kt·G N·m.
        """
        scale = 1.0 / (torque_per_ampere * gear)
        stiffness = inertia * NATURAL_FREQUENCY**2
        damping = 2.0 * DAMPING_RATIO * inertia * NATURAL_FREQUENCY
        return cls(
            proportional=stiffness * scale,
            integral=stiffness * NATURAL_FREQUENCY * INTEGRAL_FRACTION * scale,
            derivative=damping * scale,
        )


@dataclass
class RegulatorState:
    """What Eq. (2) remembers between iterations: the integral, and the last position for the velocity."""

    integral: Vector
    previous: Vector | None = None
    velocity: Vector = field(default_factory=lambda: np.zeros(0))


def regulate(
    gains: Gains,
    state: RegulatorState,
    desired: Vector,
    desired_velocity: Vector,
    measured: Vector,
    feedforward: Vector,
    period: float,
    limit: Vector,
) -> Vector:
    """The winding currents for one iteration; updates `state`."""
    error = desired - measured  # Eq. (3)
    if state.previous is None or state.velocity.shape != measured.shape:
        state.velocity = np.zeros_like(measured)
    else:
        raw = (measured - state.previous) / period
        alpha = period / (period + VELOCITY_FILTER)
        state.velocity = state.velocity + alpha * (raw - state.velocity)
    state.previous = measured.copy()
    integral = state.integral + error * period
    current = (
        gains.proportional * error  # Eq. (2), the proportional term
        + gains.integral * integral  # Eq. (2), the integral term
        + gains.derivative * (desired_velocity - state.velocity)
        + feedforward
    )
    saturated = np.abs(current) > limit
    winding_up = saturated & (np.sign(current) == np.sign(error))
    state.integral = np.where(winding_up, state.integral, integral)
    # np.minimum/np.maximum rather than np.clip, whose argument handling costs more than the clip on six joints
    clipped: Vector = np.minimum(np.maximum(current, -limit), limit)
    return clipped
