"""An N-joint arm with a two-finger gripper, written as MJCF for this project (docs/simulation.md).

The same generator gives two documents:

- `robot_mjcf(n)` — the robot alone (arm, gripper, drives): what a manufacturer ships
  and what a controller may build its own kinematic and dynamic model from;
- `workcell_mjcf(n, ...)` — the robot on a table with a box to pick and a place target:
  the plant the real effectors act on.

Every joint is driven by a DC motor behind a gear train (`Drive`): MuJoCo's `motor`
actuator with `gear = motor constant × gear ratio` turns a winding current in
amperes into joint torque, and `ctrlrange` is the current limit.  The rotor's
inertia and the gear train's viscous friction appear at the joint, multiplied by
the square of the gear ratio, as `armature` and `damping`.  Each drive's encoder
(counts per motor revolution) is recorded in a `<custom>` numeric, which
`earl.sim.MujocoPlant` reads to quantise the motor position it reports.

Joint layouts by N (yaw turns about the vertical, pitch about the horizontal axis
across the arm, roll about the link itself):

    N=3  yaw pitch pitch              + a levelling wrist (a parallelogram linkage)
    N=4  yaw pitch pitch roll         + a levelling wrist
    N=5  yaw pitch pitch pitch roll
    N=6  yaw pitch pitch roll pitch roll
    N=7  yaw pitch roll pitch roll pitch roll

With fewer than five joints the gripper cannot be turned to point down by a
motor, so two passive joints, tied to the shoulder and the elbow by equality
constraints, keep it level as a palletising robot's parallelogram does.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

MIN_JOINTS = 3
MAX_JOINTS = 7

#: Height of the shoulder's pitch axis above the table, metres.
SHOULDER_HEIGHT = 0.30
#: Shoulder pitch axis to elbow pitch axis, metres.
UPPER_ARM = 0.35
#: Elbow pitch axis to wrist pitch axis, metres.
FOREARM = 0.30
#: Wrist pitch axis to the grasp point between the finger pads, metres.
TOOL = 0.13
#: Length of each finger pad along the tool axis, metres.
FINGER_LENGTH = 0.04
#: Widest opening between the finger pads, metres.
MAX_OPENING = 0.09
#: MuJoCo's step, s (its default): one step per 2 ms drive period; implicitfast with armature and stiff
#: contacts is stable at it, and the placement moves by 0.004 mm against a 1 ms step
TIMESTEP = 0.002
#: The opening in the workcell's initial keyframe, metres.
INITIAL_OPENING = 0.08

_YAW, _PITCH, _ROLL = "yaw", "pitch", "roll"

_LAYOUTS: dict[int, tuple[str, ...]] = {
    3: (_YAW, _PITCH, _PITCH),
    4: (_YAW, _PITCH, _PITCH, _ROLL),
    5: (_YAW, _PITCH, _PITCH, _PITCH, _ROLL),
    6: (_YAW, _PITCH, _PITCH, _ROLL, _PITCH, _ROLL),
    7: (_YAW, _PITCH, _ROLL, _PITCH, _ROLL, _PITCH, _ROLL),
}


@dataclass(frozen=True)
class Drive:
    """One drive's datasheet: a DC motor behind a gear train, with an incremental encoder.

    For the finger drive the "gear ratio" is the lead screw's: motor radians per metre
    that each finger travels.
    """

    name: str
    #: torque per ampere of winding current at the motor shaft, N·m/A
    motor_constant: float
    #: motor radians per joint radian (or per metre of finger travel)
    gear_ratio: float
    #: the driver's winding current limit, A
    current_limit: float
    #: encoder counts per motor revolution (quadrature decoded)
    encoder_counts: int
    #: rotor inertia, kg·m²
    rotor_inertia: float
    #: viscous friction of motor and gear train at the motor shaft, N·m·s/rad
    viscous_friction: float

    @property
    def torque_per_ampere(self) -> float:
        """Joint torque (or finger force) per ampere: motor constant × gear ratio."""
        return self.motor_constant * self.gear_ratio

    @property
    def armature(self) -> float:
        """The rotor's inertia seen at the joint."""
        return self.rotor_inertia * self.gear_ratio**2

    @property
    def damping(self) -> float:
        """The gear train's viscous friction seen at the joint."""
        return self.viscous_friction * self.gear_ratio**2

    @property
    def encoder_resolution(self) -> float:
        """The smallest change of motor position the encoder reports, rad."""
        return 2.0 * math.pi / self.encoder_counts


#: Base yaw: a mid-size motor with a harmonic gear.
BASE_DRIVE = Drive("base", 0.060, 100.0, 5.0, 4096, 1.2e-5, 1.5e-4)
#: Shoulder and elbow carry the arm against gravity.
LARGE_DRIVE = Drive("large", 0.075, 120.0, 6.0, 4096, 1.4e-5, 1.5e-4)
#: Wrist pitch and the roll joints.
SMALL_DRIVE = Drive("small", 0.030, 100.0, 3.0, 2048, 3.0e-6, 5.0e-5)
#: The gripper's lead-screw drive: 1000 motor radians per metre of finger travel.
FINGER_DRIVE = Drive("finger", 0.012, 1000.0, 2.0, 1024, 6.0e-7, 2.0e-4)


def check_joint_count(n: int) -> None:
    """Refuse an N the generator has no layout for, in plain words."""
    if not MIN_JOINTS <= n <= MAX_JOINTS:
        raise ValueError(
            f"the simulated arm has {MIN_JOINTS} to {MAX_JOINTS} joints; the spec asks for N = {n} "
            f"(set it with `--param N=6`)"
        )


def joint_layout(n: int) -> tuple[str, ...]:
    """The kind of each joint 1..N: "yaw", "pitch" or "roll"."""
    check_joint_count(n)
    return _LAYOUTS[n]


@functools.cache
def drives(n: int) -> tuple[Drive, ...]:
    """The drive of each joint 1..N: the base; large drives up to the elbow, which carry the arm; small after it."""
    layout = joint_layout(n)
    result = [BASE_DRIVE]
    pitches = 0
    for kind in layout[1:]:
        pitches += kind == _PITCH
        result.append(LARGE_DRIVE if pitches <= 2 and not (kind == _ROLL and pitches == 2) else SMALL_DRIVE)
    return tuple(result)


def drive(n: int, joint: int) -> Drive:
    """The drive of joint `joint` (1-based, as the spec's K)."""
    return drives(n)[joint - 1]


def joint_name(k: int) -> str:
    return f"joint{k}"


def actuator_name(k: int) -> str:
    return f"motor{k}"


FINGER_JOINT = "finger_left"
FINGER_ACTUATOR = "fingerDrive"
GRASP_SITE = "grasp"
BOX_BODY = "box"
TARGET_SITE = "place_target"


def pitch_joints(n: int) -> list[int]:
    """The 1-based indices of the pitch joints: shoulder, elbow and (N ≥ 5) wrist."""
    return [k + 1 for k, kind in enumerate(joint_layout(n)) if kind == _PITCH]


def tool_down_configuration(n: int, position: tuple[float, float, float], elbow_up: bool = True) -> list[float]:
    """Joint positions that put the grasp point at `position` with the gripper pointing down.

    The arm's geometry is planar once the base has turned towards the target, so this
    is the two-link solution in closed form.  The gripper's frame is then
    Rz(yaw)·Ry(π): its x axis, along which the fingers close, points back towards the
    base.  Raises ValueError when the point is out of reach.
    """
    layout = joint_layout(n)
    x, y, z = position
    yaw = math.atan2(y, x)
    reach = math.hypot(x, y)
    height = z + TOOL - SHOULDER_HEIGHT
    squared = reach**2 + height**2
    cos_elbow = (squared - UPPER_ARM**2 - FOREARM**2) / (2.0 * UPPER_ARM * FOREARM)
    if not -1.0 <= cos_elbow <= 1.0:
        raise ValueError(f"the point ({x:.3f}, {y:.3f}, {z:.3f}) m is out of the arm's reach")
    elbow = math.acos(cos_elbow) * (1.0 if elbow_up else -1.0)
    shoulder = math.atan2(reach, height) - math.atan2(FOREARM * math.sin(elbow), UPPER_ARM + FOREARM * math.cos(elbow))
    q = [0.0] * n
    q[0] = yaw
    pitches = [k - 1 for k, kind in enumerate(layout, start=1) if kind == _PITCH]
    q[pitches[0]] = shoulder
    q[pitches[1]] = elbow
    if len(pitches) > 2:
        q[pitches[2]] = math.pi - shoulder - elbow
    return q


# ---------------------------------------------------------------- MJCF text


def _f(value: float) -> str:
    return f"{value:.6g}"


def _vec(*values: float) -> str:
    return " ".join(_f(v) for v in values)


_AXES = {_YAW: "0 0 1", _PITCH: "0 1 0", _ROLL: "0 0 1"}
_LIMITS = {_YAW: 2.9, _PITCH: 2.6, _ROLL: 2.9}


def _chain_positions(layout: tuple[str, ...]) -> list[float]:
    """Height of each joint along the upright arm (every joint at zero), from the base."""
    heights = []
    pitch_count = 0
    for k, kind in enumerate(layout):
        if k == 0:
            heights.append(0.0)
        elif kind == _PITCH:
            pitch_count += 1
            heights.append(SHOULDER_HEIGHT + [0.0, UPPER_ARM, UPPER_ARM + FOREARM][pitch_count - 1])
        else:
            # a roll joint sits a little beyond the pitch joint before it
            heights.append(heights[-1] + 0.08 if pitch_count < 3 else heights[-1] + 0.03)
    return heights


def _robot_body(n: int, indent: str) -> str:
    layout = joint_layout(n)
    heights = _chain_positions(layout)
    wrist = SHOULDER_HEIGHT + UPPER_ARM + FOREARM
    levelling = n < 5
    # With a levelling wrist the arm's own links end at the elbow; an N = 4 roll joint sits
    # below the levelling wrist and turns the gripper about the vertical.
    arm_joints = 3 if levelling else n
    lines: list[str] = []
    depth = 0
    previous = 0.0
    for k in range(1, arm_joints + 1):
        height = heights[k - 1]
        pad = indent + "  " * depth
        lines.append(f'{pad}<body name="link{k}" pos="0 0 {_f(height - previous)}">')
        lines.append(_joint_line(n, k, pad + "  "))
        following = heights[k] if k < arm_joints else wrist
        length = max(following - height, 0.02)
        radius = 0.05 if k == 1 else 0.045 if height < SHOULDER_HEIGHT + UPPER_ARM else 0.035
        colour = "0.85 0.45 0.1 1" if k % 2 else "0.3 0.3 0.32 1"
        lines.append(
            f'{pad}  <geom class="link" type="capsule" fromto="0 0 0 0 0 {_f(length)}" size="{_f(radius)}"'
            f' rgba="{colour}"/>'
        )
        previous = height
        depth += 1
    pad = indent + "  " * depth
    if levelling:
        lines.append(f'{pad}<body name="level" pos="0 0 {_f(wrist - previous)}">')
        lines.append(f'{pad}  <joint name="level_shoulder" axis="0 1 0" armature="0.005" damping="0.2"/>')
        lines.append(f'{pad}  <joint name="level_elbow" axis="0 1 0" armature="0.005" damping="0.2"/>')
        lines.append(f'{pad}  <geom class="link" type="sphere" size="0.04" rgba="0.3 0.3 0.32 1"/>')
        lines.append(f'{pad}  <body name="flange" euler="0 {_f(math.pi)} 0">')
        inner = pad + "    "
        if n == 4:
            lines.append(_joint_line(n, 4, inner))
        lines.extend(_gripper(inner))
        lines.append(f"{pad}  </body>")
        lines.append(f"{pad}</body>")
    else:
        lines.append(f'{pad}<body name="flange" pos="0 0 {_f(wrist - previous)}">')
        lines.extend(_gripper(pad + "  "))
        lines.append(f"{pad}</body>")
    for d in reversed(range(depth)):
        lines.append(indent + "  " * d + "</body>")
    return "\n".join(lines)


def _joint_line(n: int, k: int, pad: str) -> str:
    kind = joint_layout(n)[k - 1]
    d = drive(n, k)
    return (
        f'{pad}<joint name="{joint_name(k)}" axis="{_AXES[kind]}" range="{_vec(-_LIMITS[kind], _LIMITS[kind])}" '
        f'armature="{_f(d.armature)}" damping="{_f(d.damping)}"/>'
    )


def _gripper(pad: str) -> list[str]:
    """Palm and two fingers along the tool axis (+z of the flange); fingers close along x."""
    base = 0.0
    palm = base + 0.06
    finger_top = palm + 0.012
    site = TOOL
    pad_center = site - finger_top
    half = FINGER_LENGTH / 2
    travel = MAX_OPENING / 2
    return [
        f'{pad}<geom class="link" type="cylinder" fromto="0 0 {_f(base)} 0 0 {_f(palm - 0.012)}" size="0.03"'
        ' rgba="0.3 0.3 0.32 1"/>',
        f'{pad}<geom class="grip" name="palm" type="box" pos="0 0 {_f(palm)}" size="0.06 0.018 0.012"'
        ' rgba="0.2 0.2 0.22 1"/>',
        f'{pad}<site name="{GRASP_SITE}" pos="0 0 {_f(site)}" size="0.006" rgba="0 1 0 0.6"/>',
        f'{pad}<body name="finger_left" pos="0 0 {_f(finger_top)}">',
        f'{pad}  <joint name="{FINGER_JOINT}" type="slide" axis="1 0 0" range="0 {_f(travel)}"'
        f' armature="{_f(FINGER_DRIVE.armature)}" damping="{_f(FINGER_DRIVE.damping)}"/>',
        f'{pad}  <geom class="grip" name="pad_left" type="box" pos="0.006 0 {_f(pad_center)}"'
        f' size="0.006 0.014 {_f(half + 0.004)}" rgba="0.1 0.1 0.1 1"/>',
        f"{pad}</body>",
        f'{pad}<body name="finger_right" pos="0 0 {_f(finger_top)}">',
        f'{pad}  <joint name="finger_right" type="slide" axis="-1 0 0" range="0 {_f(travel)}"'
        f' armature="{_f(FINGER_DRIVE.armature)}" damping="{_f(FINGER_DRIVE.damping)}"/>',
        f'{pad}  <geom class="grip" name="pad_right" type="box" pos="-0.006 0 {_f(pad_center)}"'
        f' size="0.006 0.014 {_f(half + 0.004)}" rgba="0.1 0.1 0.1 1"/>',
        f"{pad}</body>",
    ]


def _actuators_and_encoders(n: int) -> str:
    lines = ["  <actuator>"]
    for k in range(1, n + 1):
        d = drive(n, k)
        lines.append(
            f'    <motor name="{actuator_name(k)}" joint="{joint_name(k)}" gear="{_f(d.torque_per_ampere)}"'
            f' ctrllimited="true" ctrlrange="{_vec(-d.current_limit, d.current_limit)}"/>'
        )
    f = FINGER_DRIVE
    lines.append(
        f'    <motor name="{FINGER_ACTUATOR}" joint="{FINGER_JOINT}" gear="{_f(f.torque_per_ampere)}"'
        f' ctrllimited="true" ctrlrange="{_vec(-f.current_limit, f.current_limit)}"/>'
    )
    lines.append("  </actuator>")
    lines.append("  <custom>")
    for k in range(1, n + 1):
        d = drive(n, k)
        lines.append(
            f'    <numeric name="earl.encoder.{actuator_name(k)}" data="{_f(d.gear_ratio)} {d.encoder_counts}"/>'
        )
    lines.append(f'    <numeric name="earl.encoder.{FINGER_ACTUATOR}" data="{_f(f.gear_ratio)} {f.encoder_counts}"/>')
    lines.append("  </custom>")
    return "\n".join(lines)


def _equalities(n: int) -> str:
    lines = [
        "  <equality>",
        f'    <joint joint1="finger_right" joint2="{FINGER_JOINT}" polycoef="0 1 0 0 0" solref="0.004 1"/>',
    ]
    if n < 5:
        shoulder, elbow = pitch_joints(n)[:2]
        lines.append(
            f'    <joint joint1="level_shoulder" joint2="{joint_name(shoulder)}" polycoef="0 -1 0 0 0" solref="0.004 1"/>'
        )
        lines.append(
            f'    <joint joint1="level_elbow" joint2="{joint_name(elbow)}" polycoef="0 -1 0 0 0" solref="0.004 1"/>'
        )
    lines.append("  </equality>")
    return "\n".join(lines)


_DEFAULTS = """  <default>
    <default class="link">
      <geom contype="0" conaffinity="0" density="700"/>
    </default>
    <default class="grip">
      <geom contype="1" conaffinity="1" condim="4" friction="1.2 0.02 0.001" density="900"
            solref="0.004 1" solimp="0.95 0.99 0.001"/>
    </default>
  </default>"""

_OPTIONS = (
    '  <option timestep="{timestep}" integrator="implicitfast" cone="elliptic" impratio="10"/>\n'
    '  <compiler angle="radian" autolimits="true"/>'
)


def robot_mjcf(n: int, timestep: float = TIMESTEP) -> str:
    """The robot alone: arm, gripper and drives, mounted at the origin."""
    check_joint_count(n)
    return "\n".join(
        [
            f'<mujoco model="earl-arm-{n}">',
            _OPTIONS.format(timestep=_f(timestep)),
            _DEFAULTS,
            "  <worldbody>",
            '    <body name="base" pos="0 0 0">',
            '      <geom class="link" type="cylinder" size="0.07 0.02" pos="0 0 0.02" rgba="0.3 0.3 0.32 1"/>',
            _robot_body(n, "      "),
            "    </body>",
            "  </worldbody>",
            '  <contact><exclude body1="finger_left" body2="finger_right"/></contact>',
            _equalities(n),
            _actuators_and_encoders(n),
            "</mujoco>",
        ]
    )


_LOOKS = (
    '  <visual><headlight ambient="0.3 0.3 0.3" diffuse="0.35 0.35 0.35"/></visual>\n'
    "  <asset>\n"
    '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.62 0.72 0.85" rgb2="0.18 0.2 0.26"'
    ' width="128" height="128"/>\n'
    '    <texture name="floor" type="2d" builtin="checker" rgb1="0.5 0.53 0.56" rgb2="0.42 0.45 0.48"'
    ' width="128" height="128"/>\n'
    '    <material name="floor" texture="floor" texrepeat="6 6"/>\n'
    "  </asset>\n"
)
#: The overview camera: in front, between the box and the place target, looking at the work area.
_CAMERA = (1.12, 0.86, 0.9)
_CAMERA_TARGET = (0.2, 0.12, 0.2)


def _look_at(eye: tuple[float, float, float], target: tuple[float, float, float]) -> tuple[float, ...]:
    """MJCF `xyaxes` of a camera at `eye` looking at `target` with the world's z up."""
    forward = [t - e for t, e in zip(target, eye, strict=True)]
    norm = math.sqrt(sum(f * f for f in forward))
    forward = [f / norm for f in forward]
    right = [forward[1], -forward[0], 0.0]  # forward × z
    norm = math.hypot(right[0], right[1])
    right = [r / norm for r in right]
    up = [
        right[1] * forward[2] - right[2] * forward[1],
        right[2] * forward[0] - right[0] * forward[2],
        right[0] * forward[1] - right[1] * forward[0],
    ]
    return (*right, *up)


#: The box to pick: a 4 cm cube of 100 g.
BOX_HALF_SIZE = 0.02
BOX_MASS = 0.1


def workcell_mjcf(
    n: int,
    box_position: tuple[float, float],
    target_position: tuple[float, float],
    initial_configuration: list[float] | None = None,
    timestep: float = TIMESTEP,
) -> str:
    """The robot on a table, a box to pick at `box_position` and a place target (x, y on the table)."""
    robot = robot_mjcf(n, timestep)
    head, _, rest = robot.partition("  <worldbody>\n")
    body, _, tail = rest.partition("  </worldbody>\n")
    bx, by = box_position
    tx, ty = target_position
    scene = [
        '    <light pos="0.3 -0.6 1.8" dir="-0.2 0.4 -1" diffuse="0.8 0.8 0.8"/>',
        '    <light pos="-0.5 0.5 2.0" dir="0.3 -0.2 -1" diffuse="0.4 0.4 0.4"/>',
        f'    <camera name="overview" pos="{_vec(*_CAMERA)}" xyaxes="{_vec(*_look_at(_CAMERA, _CAMERA_TARGET))}"/>',
        '    <geom name="floor" type="plane" pos="0 0 -0.75" size="3 3 0.1" material="floor" contype="0" conaffinity="0"/>',
        '    <geom name="table" type="box" pos="0.25 0.15 -0.02" size="0.55 0.55 0.02" rgba="0.75 0.65 0.5 1"'
        ' friction="0.8 0.02 0.001" solref="0.004 1"/>',
        f'    <site name="{TARGET_SITE}" type="cylinder" pos="{_vec(tx, ty, 0.0005)}" size="0.03 0.0005"'
        ' rgba="0.1 0.7 0.2 0.6"/>',
        f'    <body name="{BOX_BODY}" pos="{_vec(bx, by, BOX_HALF_SIZE)}">',
        "      <freejoint/>",
        f'      <geom name="box" type="box" size="{_vec(BOX_HALF_SIZE, BOX_HALF_SIZE, BOX_HALF_SIZE)}" mass="{_f(BOX_MASS)}"'
        ' rgba="0.8 0.15 0.15 1" condim="4" friction="1.0 0.02 0.001" solref="0.004 1" solimp="0.95 0.99 0.001"/>',
        "    </body>",
    ]
    keyframe = ""
    if initial_configuration is not None:
        keyframe = _keyframe(n, initial_configuration, (bx, by))
    # The box comes after the robot so that the keyframe's qpos lists the robot's joints first.
    return "".join(
        [
            head,
            _LOOKS,
            "  <worldbody>\n",
            body,
            "\n".join(scene),
            "\n",
            "  </worldbody>\n",
            tail.replace("</mujoco>", keyframe + "</mujoco>"),
        ]
    )


def _keyframe(n: int, q: list[float], box: tuple[float, float]) -> str:
    """`qpos` of the "initial" keyframe: the joints, the levelling wrist, open fingers, the box at rest."""
    values: list[float] = list(q)
    if n < 5:
        shoulder, elbow = pitch_joints(n)[:2]
        insert_at = n if joint_layout(n)[-1] != _ROLL else n - 1
        level = [-q[shoulder - 1], -q[elbow - 1]]
        values = values[:insert_at] + level + values[insert_at:]
    travel = INITIAL_OPENING / 2
    values += [travel, travel, box[0], box[1], BOX_HALF_SIZE, 1.0, 0.0, 0.0, 0.0]
    return f'  <keyframe><key name="initial" qpos="{_vec(*values)}"/></keyframe>\n'
