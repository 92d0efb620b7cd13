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
    """The winding currents for one iteration; updates `state`.

    Written joint by joint over Python floats, as the manual writes it: on six joints that
    takes a third of the time of the same arithmetic as NumPy array operations, each of
    which costs more to dispatch than to compute.
    """
    motor = measured.tolist()
    if state.previous is None or state.velocity.shape != measured.shape:
        velocity = [0.0] * len(motor)
    else:
        alpha = period / (period + VELOCITY_FILTER)
        velocity = [
            v + alpha * ((m - p) / period - v)  # low-passed finite difference of the encoder
            for v, m, p in zip(state.velocity.tolist(), motor, state.previous.tolist(), strict=True)
        ]
    integrals: list[float] = []
    currents: list[float] = []
    for kp, ki, kd, target, target_velocity, position, speed, integral, forward, most in zip(
        gains.proportional.tolist(),
        gains.integral.tolist(),
        gains.derivative.tolist(),
        desired.tolist(),
        desired_velocity.tolist(),
        motor,
        velocity,
        state.integral.tolist(),
        feedforward.tolist(),
        limit.tolist(),
        strict=True,
    ):
        error = target - position  # Eq. (3)
        grown = integral + error * period
        current = kp * error + ki * grown + kd * (target_velocity - speed) + forward  # Eq. (2) and the two additions
        # anti-windup: the integral stays put while the current is saturated in the direction the error pushes
        winding_up = abs(current) > most and _sign(current) == _sign(error)
        integrals.append(integral if winding_up else grown)
        currents.append(min(max(current, -most), most))
    state.velocity = np.array(velocity)
    state.previous = measured.copy()
    state.integral = np.array(integrals)
    return np.array(currents)


def _sign(value: float) -> int:
    """np.sign for one float: -1, 0 or 1."""
    return (value > 0.0) - (value < 0.0)
