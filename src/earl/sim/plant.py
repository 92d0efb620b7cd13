"""`MujocoPlant`: a MuJoCo model stepped in lockstep with a run's virtual time.

Real effectors write actuator inputs by name (`set_input("motor3", 1.2)`, a winding
current in amperes for the arm's drives); real receptors read quantised encoders,
poses and contacts.  The runtime calls `advance(time)` before the subsystems due at
`time` run, so every subsystem sees the world as it is at its own instant.

    plant = MujocoPlant.from_xml(workcell_mjcf(6, ...), seed=1)
    plant.set_input("motor2", 1.5)
    plant.advance(0.010)
    plant.encoder("motor2")      # motor shaft position, rad, to the encoder's resolution

An encoder is declared in the MJCF as `<numeric name="earl.encoder.ACTUATOR"
data="GEAR COUNTS"/>`: it reports the actuated joint's position times the gear ratio
(the motor shaft), rounded down to whole counts of `COUNTS` per revolution.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from earl.diagnostics import Diagnostic, EarlError, Severity, did_you_mean
from earl.model.location import SourceLocation

if TYPE_CHECKING:
    from earl.model.elements import System

ENCODER_PREFIX = "earl.encoder."

FloatArray = NDArray[np.float64]
_FrameHook = Callable[["MujocoPlant"], None]


class PlantError(ValueError):
    """A name that the model does not have, or a time that has already passed."""


@dataclass(frozen=True)
class XmlOrigin:
    """Where a model's XML came from: what messages call it (a file name), and its text, to find a line in."""

    name: str
    text: str | None = None

    def line_of(self, name: str, attribute: str = "name") -> str:
        """`NAME, line N` for the element whose `name="…"` (or other `attribute`) is `name`, any value if `name`
        is empty; just `NAME` if the text does not show it (an included file, or no text)."""
        value = re.escape(name) if name else "[^\"']*"
        found = re.search(rf"""\b{attribute}\s*=\s*["']{value}["']""", self.text or "")
        if found is None or self.text is None:
            return self.name
        return f"{self.name}, line {1 + self.text.count(chr(10), 0, found.start())}"


@dataclass(frozen=True)
class Encoder:
    """An incremental encoder on an actuator's motor shaft."""

    actuator: str
    joint_address: int
    gear_ratio: float
    counts_per_revolution: int
    #: motor radians per count
    resolution: float = field(init=False)
    # counts per joint radian: read runs every millisecond for every drive
    _counts_per_joint_radian: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        resolution = 2.0 * math.pi / self.counts_per_revolution
        object.__setattr__(self, "resolution", resolution)
        object.__setattr__(self, "_counts_per_joint_radian", self.gear_ratio / resolution)

    def read(self, joint_position: float) -> float:
        """The motor position the encoder reports: whole counts, never more than the true position."""
        return math.floor(joint_position * self._counts_per_joint_radian + 1e-9) * self.resolution


@dataclass(frozen=True)
class Pose:
    """A position in metres and a unit quaternion (w, x, y, z), in the world frame."""

    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]


class MujocoPlant:
    """One MuJoCo model and its state, advanced to each instant the runtime asks for."""

    def __init__(
        self, model: mujoco.MjModel, seed: int = 0, keyframe: str | None = None, *, origin: XmlOrigin | None = None
    ) -> None:
        """`origin`: the XML the model was read from, for messages that point at its lines (`from_file` and
        `from_xml` give it)."""
        self.model = model
        self.origin = origin or XmlOrigin("the model's XML")
        self.data = mujoco.MjData(model)
        # views on the data's own buffers, made once (each `data.ctrl` makes a new view)
        self._ctrl = self.data.ctrl
        self._qpos = self.data.qpos
        self._actuators = {model.actuator(i).name: i for i in range(model.nu)}
        self._timestep = float(model.opt.timestep)
        # per actuator (low, high) as Python floats: set_input runs every millisecond for every drive
        self._ranges = [
            (float(low), float(high)) if model.actuator_ctrllimited[i] else (-math.inf, math.inf)
            for i, (low, high) in enumerate(model.actuator_ctrlrange)
        ]
        self.seed = seed
        #: for whatever the environment randomises; the physics itself is deterministic
        self.random = np.random.default_rng(seed)
        if keyframe is not None:
            key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, keyframe)
            if key < 0:
                raise PlantError(f"the model has no keyframe named `{keyframe}`")
            mujoco.mj_resetDataKeyframe(model, self.data, key)
        mujoco.mj_forward(model, self.data)
        self.encoders = self._read_encoders()
        self._sensors = {model.sensor(i).name: i for i in range(model.nsensor)}
        #: what the environment said each real effector or receptor acts on (`map_actuator`, `map_sensor`)
        self._maps: list[_Map] = []
        #: (subsystem name as `context.subsystem`, kind) -> the name resolved from its map, once
        self._resolved: dict[tuple[str, str], str] = {}
        self._faults: dict[str, float] = {}
        self._steps = 0
        #: the step the sensor readings were last computed at (mj_forward has run at 0)
        self._sensed_at = 0
        self._closers: list[Callable[[], None]] = []
        self._frame_hooks: list[tuple[float, _FrameHook]] = []
        self._next_frame: list[float] = []

    @classmethod
    def from_xml(cls, xml: str, seed: int = 0, keyframe: str | None = None) -> MujocoPlant:
        """Build from MJCF text (errors from MuJoCo are reported as `PlantError`).

        Files the text includes are looked for in the current directory; `from_file` finds them
        next to the XML file, and its errors name that file."""
        if not xml.strip():
            raise PlantError("MuJoCo could not read the model: the XML given to MujocoPlant.from_xml is empty")
        origin = XmlOrigin("the XML given to MujocoPlant.from_xml", xml)
        try:
            model = mujoco.MjModel.from_xml_string(xml)
        except ValueError as error:
            said = load_error(origin.name, str(error))
            raise PlantError(f"{said} (MujocoPlant.from_file reads a file and names it here)") from None
        return cls(model, seed, keyframe, origin=origin)

    @classmethod
    def from_file(cls, path: str | Path, seed: int = 0, keyframe: str | None = None) -> MujocoPlant:
        """Build from an MJCF file: a relative `path` is taken from the current directory, the files
        it includes (`<include>`, meshes) from the file's own directory."""
        if not Path(path).is_file():
            kind = "is a directory, not an XML file" if Path(path).is_dir() else "does not exist"
            where = (
                ""
                if Path(path).is_absolute()
                else f" (a relative path is taken from the current directory, {Path.cwd()})"
            )
            raise PlantError(f"MuJoCo could not read the model: {path} {kind}{where}")
        try:
            model = mujoco.MjModel.from_xml_path(str(path))
        except ValueError as error:
            raise PlantError(load_error(str(path), str(error))) from None
        return cls(model, seed, keyframe, origin=XmlOrigin(str(path), Path(path).read_text(errors="replace")))

    # ------------------------------------------------------------ time

    @property
    def time(self) -> float:
        """Simulated time, seconds."""
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        return self._timestep

    def advance(self, time: float) -> None:
        """Step the physics until simulated time reaches `time`, never beyond it.

        The plant takes every step that ends by `time`: at a time that is not a whole number of
        steps it stays up to a step behind, never ahead, so that no subsystem sees the world as it
        will be after its own instant (`bind` refuses a timestep that does not divide a real
        effector's or receptor's period). The number of steps is computed from the step count, not
        by adding up floats, so that equal calls give equal states however the calls are split.
        """
        # a millionth of a step: 0.003 / 0.001 is 2.9999999999999996, and is 3 steps
        target = math.floor(time / self.timestep + 1e-6)
        if target < self._steps:
            raise PlantError(f"cannot go back in time: the plant is at {self.time:.6f} s, asked for {time:.6f} s")
        while self._steps < target:
            mujoco.mj_step(self.model, self.data)
            self._steps += 1
            if self._frame_hooks:
                self._call_frame_hooks()

    # ------------------------------------------------------------ actuators

    def _actuator(self, name: str) -> int:
        try:
            return self._actuators[name]
        except KeyError:
            names = ", ".join(self.actuator_names())
            raise PlantError(f"the model has no actuator named `{name}` (it has: {names})") from None

    def actuator_names(self) -> list[str]:
        return [self.model.actuator(i).name for i in range(self.model.nu)]

    # ------------------------------------------------------------ the system it serves

    def bind(self, system: System) -> None:
        """Refuse, before the first iteration, a system whose real effectors and receptors the model cannot
        serve (the runtime calls it with the system as it runs; docs/simulation.md says what is checked):
        the timestep must divide their periods, so that the plant is stepped to each of their instants
        exactly; and the model must have the actuator (encoder, sensor) each is mapped to (`map_actuator`).

        No convention of names is checked (`motor[2]/re` on `motor2` would refuse a family numbered
        otherwise, `motor[K in 0..N-1]/re` on `motor1…`): only the maps, by the lookup `actuator_of` makes
        during the run, with the parameters each subsystem is given then. A name its code writes itself
        (`set_input("motor3", …)`) is not checked."""
        problems = self._unmet_periods(_real_families(system)) + self._unmet_maps(system)
        if problems:
            raise EarlError(problems)

    # ------------------------------------------------------------ what each real effector and receptor acts on

    def map_actuator(self, subsystem: str, actuator: str, *, encoder: bool = False) -> None:
        """Say which actuator the real effector (or any subsystem) `subsystem` acts on, so that a missing one is refused before
        the run (`bind`) instead of failing in every iteration; its functions ask `actuator_of(context)`.

        `subsystem` is named as the run names it, a family with its index: `arm/a.motor[K]/re`;
        `actuator` is the model's name, with the subsystem's parameters in braces: `motor{K}`
        (`context.parameters`: the family's index, its own `param`s, the agent's and the system's).
        `encoder=True`: it reads that actuator's encoder too, which the model must declare."""
        self._add_map(_Map(subsystem, "actuator", actuator))
        if encoder:
            self._add_map(_Map(subsystem, "encoder", actuator))

    def map_sensor(self, subsystem: str, sensor: str) -> None:
        """Say which of the model's `<sensor>`s the real receptor (or any subsystem) `subsystem` reads, as
        `map_actuator` does for an actuator; its functions ask `sensor_of(context)` and read `sensor(name)`."""
        self._add_map(_Map(subsystem, "sensor", sensor))

    def actuator_of(self, context: Any) -> str:
        """The actuator `map_actuator` gave the running subsystem (`context`, as its functions get it)."""
        return self._name_of(context.subsystem, context.parameters, "actuator")

    def sensor_of(self, context: Any) -> str:
        """The sensor `map_sensor` gave the running subsystem."""
        return self._name_of(context.subsystem, context.parameters, "sensor")

    def _add_map(self, new: _Map) -> None:
        if not isinstance(new.template, str) or not isinstance(new.subsystem, str):
            raise PlantError(
                f"map_{new.kind}(subsystem, {new.kind}) takes two strings, e.g. ('arm/a.motor[K]/re', 'motor{{K}}')"
            )
        self._maps = [old for old in self._maps if (old.subsystem, old.kind) != (new.subsystem, new.kind)] + [new]
        self._resolved.clear()

    def _map_of(self, subsystem: str, parameters: Mapping[str, Any], kind: str) -> _Map | None:
        """The map of `kind` that names the subsystem: the first declared, when several do."""
        return next((m for m in self._maps if m.kind == kind and m.matches(subsystem, parameters)), None)

    def _name_of(self, subsystem: str, parameters: Mapping[str, Any], kind: str) -> str:
        """The model's name a subsystem acts on, from its map: the one lookup of the run and of `bind`."""
        name = self._resolved.get((subsystem, kind))
        if name is None:
            found = self._map_of(subsystem, parameters, kind)
            if found is None:
                raise PlantError(
                    f"no {kind} is mapped for `{subsystem}`: the environment says which one it acts on with "
                    f"plant.map_{'sensor' if kind == 'sensor' else 'actuator'}('{_family_of(subsystem)}', …)"
                )
            name = self._resolved[(subsystem, kind)] = found.name_for(subsystem, parameters)
        return name

    def _known(self, kind: str) -> list[str]:
        if kind == "sensor":
            return list(self._sensors)
        return list(self.encoders) if kind == "encoder" else self.actuator_names()

    def _unmet_maps(self, system: System) -> list[Diagnostic]:
        """Each map's subsystems whose actuator (encoder, sensor) the model lacks, found by `_name_of`, the
        lookup their functions make during the run, with the parameters they are given then; and each map
        that names no subsystem of the system but one close to a name it has. A map for a member of a family
        that this run's parameters leave out (`motor[6]/re` of `motor[K in 1..N]/re` with N = 3) is no
        slip: nothing looks it up, as nothing would with N = 6."""
        members = _members(system, real_only=False)
        self._resolved.clear()
        problems: list[Diagnostic] = []
        said: set[str] = set()  # a map that names no subsystem is said once, not for its actuator and encoder
        unwritten: set[tuple[str, str]] = set()  # so is a name that cannot be written (`encoder=True` maps it twice)
        for found in self._maps:
            mapped = [member for member in members if found.matches(member.shown, member.parameters)]
            if found.subsystem in said:
                continue
            if not mapped:
                # a map for a subsystem of another system may do no harm; one close to a name of this one is a slip
                if any(found.names_beyond(member.shown, member.parameters) for member in members):
                    continue
                names = list(dict.fromkeys([member.family for member in members] + [m.shown for m in members]))
                if did_you_mean(found.subsystem, names) is not None:
                    said.add(found.subsystem)
                    problems.append(self._maps_nothing(found, names))
                continue
            wrong = [letter for letter in found.letters() if letter not in mapped[0].indices]
            if wrong:
                said.add(found.subsystem)
                problems.append(self._not_an_index(found, mapped[0], wrong[0]))
                continue
            missing: list[tuple[_Member, str]] = []
            taken: set[str] = set()  # found by other members: no suggestion for a missing one
            for member in mapped:
                if self._map_of(member.shown, member.parameters, found.kind) is not found:
                    continue  # an earlier map names it: the lookup takes that one, and it is checked there
                try:
                    name = self._name_of(member.shown, member.parameters, found.kind)
                except PlantError as error:
                    if (found.subsystem, found.template) not in unwritten:
                        unwritten.add((found.subsystem, found.template))
                        problems.append(Diagnostic(Severity.ERROR, str(error), member.location, code="EARL-X021"))
                    break
                if name not in self._known(found.kind):
                    missing.append((member, name))
                else:
                    taken.add(name)
            if missing:
                problems.append(self._lacks(found, missing, taken))
        return problems

    def _lacks(self, found: _Map, missing: list[tuple[_Member, str]], taken: set[str]) -> Diagnostic:
        known = self._known(found.kind)
        names = ", ".join(f"`{name}`" for _, name in missing)
        who = ", ".join(f"`{member.shown}`" for member, _ in missing)
        what = "an encoder" if found.kind == "encoder" else f"{found.kind}"
        where = self.origin.name
        exist = ", ".join(known) or "none"
        said = (
            f"{who} {'act' if len(missing) > 1 else 'acts'} on the {found.kind} {names} "
            f"(map_{found.kind if found.kind != 'encoder' else 'actuator'}('{found.subsystem}', '{found.template}'"
            f"{', encoder=True' if found.kind == 'encoder' else ''})), but {where} has no {what} named so; "
            f"its {found.kind}s: {exist}"
        )
        if found.kind == "encoder":
            said = (
                f"{who} {'read' if len(missing) > 1 else 'reads'} the encoder of {names} (map_actuator("
                f"'{found.subsystem}', '{found.template}', encoder=True)), but {where} declares none for "
                f"{'them' if len(missing) > 1 else 'it'}; the encoders it declares: {exist}"
            )
        suggestion = did_you_mean(missing[0][1], [name for name in known if name not in taken])
        hint = (
            f'add <numeric name="{ENCODER_PREFIX}{missing[0][1]}" data="GEAR COUNTS"/> to its <custom> section'
            if found.kind == "encoder"
            else suggestion
            or f"add it to the model's <{'sensor' if found.kind == 'sensor' else 'actuator'}> section, or correct the map"
        )
        return Diagnostic(Severity.ERROR, said, missing[0][0].location, code="EARL-X021", hint=hint)

    def _maps_nothing(self, found: _Map, names: list[str]) -> Diagnostic:
        families = [name for name in names if "[" not in name or not name.rsplit("[", 1)[1][0].isdigit()]
        return Diagnostic(
            Severity.ERROR,
            f"the environment maps `{found.subsystem}` to `{found.template}`, but the system has "
            f"no subsystem of that name (it has: {', '.join(families) or 'none'})",
            None,
            code="EARL-X021",
            hint=did_you_mean(found.subsystem, names),
        )

    def _not_an_index(self, found: _Map, member: _Member, letter: str) -> Diagnostic:
        return Diagnostic(
            Severity.ERROR,
            f"the environment maps `{found.subsystem}` to `{found.template}`, but `{letter}` is no "
            f"index of the family `{member.family}` (it is a parameter, {letter} = {member.parameters[letter]}): "
            f"the map would name `{member.shown}` alone",
            member.location,
            code="EARL-X021",
            hint=f"name the family by its index, `{member.family}`, or one member by its number, `{member.shown}`",
        )

    def _unmet_periods(self, families: dict[str, list[_Member]]) -> list[Diagnostic]:
        """The real effectors and receptors whose period is no whole number of the model's steps: the plant
        would be up to a step behind their instants (it never steps beyond an instant)."""
        step = round(self.timestep * 1e9)  # nanoseconds, as the run keeps time
        unmet = {
            family: members[0].period
            for family, members in families.items()
            if members[0].period is not None and (members[0].period % step if step else 1)
        }
        if not unmet:
            return []
        periods = [member.period for members in families.values() for member in members if member.period]
        first = families[next(iter(unmet))][0]
        listed = ", ".join(f"`{family}` ({_shown_time(period)})" for family, period in unmet.items())
        return [
            Diagnostic(
                Severity.ERROR,
                f"the model's timestep, {_shown_time(step)} ({self.origin.line_of('', 'timestep')}), does not "
                "divide the period of "
                f"{listed}: the plant is stepped {_shown_time(step)} at a time, so at their instants it would be up "
                "to a step behind",
                first.location,
                code="EARL-X021",
                hint="choose a timestep that divides the period of every real effector and receptor, e.g. "
                f'<option timestep="{_divisor_below(math.gcd(*periods), step) / 1e9:g}"/>',
            )
        ]

    def set_input(self, actuator: str, value: float) -> float:
        """Set an actuator's input (a winding current for a `motor` with gear = kt·G); returns what is applied.

        A limited actuator (`ctrlrange`) saturates at its range, as a current-limited driver does;
        a driver in fault applies nothing.
        """
        index = self._actuator(actuator)
        applied = float(value)
        if not math.isfinite(applied) or (self._faults and self.driver_fault(actuator)):
            applied = 0.0
        low, high = self._ranges[index]
        applied = min(max(applied, low), high)
        self._ctrl[index] = applied
        return applied

    def applied_input(self, actuator: str) -> float:
        return float(self.data.ctrl[self._actuator(actuator)])

    def joint_torque(self, actuator: str) -> float:
        """The torque (or force) the actuator applies at its joint now: gear × its input (kt·G·i for a drive)."""
        index = self._actuator(actuator)
        return float(self.data.actuator_force[index] * self.model.actuator_gear[index, 0])

    # ------------------------------------------------------------ faults

    def inject_fault(self, actuator: str, at_time: float) -> None:
        """From `at_time` on, the actuator's driver reports a fault and applies no current."""
        self._actuator(actuator)
        self._faults[actuator] = at_time

    def driver_fault(self, actuator: str) -> bool:
        start = self._faults.get(actuator)
        return start is not None and self.time >= start - 0.5 * self.timestep

    # ------------------------------------------------------------ sensors

    def _read_encoders(self) -> dict[str, Encoder]:
        """The encoders the model declares, each checked: a wrong number would fail in every reading
        (a division by zero counts) or read nonsense, far from the line that is wrong."""
        encoders: dict[str, Encoder] = {}
        for i in range(self.model.nnumeric):
            name = self.model.numeric(i).name
            if not name.startswith(ENCODER_PREFIX):
                continue
            actuator = name[len(ENCODER_PREFIX) :]
            data = [float(number) for number in self.model.numeric(i).data]
            shown = " ".join(f"{number:g}" for number in data)
            where = f'{self.origin.line_of(name)}: the encoder <numeric name="{name}" data="{shown}"/>'
            if actuator not in self._actuators:
                names = ", ".join(self.actuator_names()) or "none"
                hint = did_you_mean(actuator, self._actuators)
                raise PlantError(
                    f"{where} names no actuator of the model: an encoder is `{ENCODER_PREFIX}ACTUATOR` "
                    f"(the actuators: {names}){'; ' + hint if hint else ''}"
                )
            if len(data) != 2:
                raise PlantError(f'{where} has {len(data)} numbers: write data="GEAR COUNTS", e.g. data="100 4096"')
            gear_ratio, counts = data
            if not math.isfinite(gear_ratio) or gear_ratio == 0:
                raise PlantError(
                    f"{where} has the gear ratio {gear_ratio:g}: GEAR, its first number, is the motor shaft's "
                    'turns per turn of the joint, a number other than 0 (e.g. data="100 4096")'
                )
            if not (math.isfinite(counts) and counts >= 1 and counts == int(counts)):
                raise PlantError(
                    f"{where} has {counts:g} counts per revolution: COUNTS, its second number, is a whole "
                    'number, 1 or more (e.g. data="100 4096")'
                )
            index = self._actuators[actuator]
            joint = int(self.model.actuator_trnid[index, 0])
            if int(self.model.actuator_trntype[index]) != mujoco.mjtTrn.mjTRN_JOINT or int(
                self.model.jnt_type[joint]
            ) not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                raise PlantError(
                    f"{where} is on an actuator that drives no hinge or slide joint: an encoder reads the angle "
                    f"or position of the joint its actuator drives (`joint=` of `{actuator}`)"
                )
            encoders[actuator] = Encoder(actuator, int(self.model.jnt_qposadr[joint]), gear_ratio, int(counts))
        return encoders

    def encoder(self, actuator: str) -> float:
        """The motor shaft position the actuator's encoder reports, rad (quantised)."""
        try:
            encoder = self.encoders[actuator]
        except KeyError:
            raise PlantError(
                f"no encoder is declared for `{actuator}` (declared: {', '.join(self.encoders) or 'none'})"
            ) from None
        return encoder.read(float(self._qpos[encoder.joint_address]))

    def sensor(self, name: str) -> tuple[float, ...]:
        """The reading of the model's `<sensor>` named `name` now, its numbers as a tuple (one for a jointpos)."""
        try:
            index = self._sensors[name]
        except KeyError:
            raise PlantError(
                f"the model has no sensor named `{name}` (it has: {', '.join(self._sensors) or 'none'})"
            ) from None
        if self._sensed_at != self._steps:
            # mj_step computes the sensors before it integrates: they would be a step behind the state
            mujoco.mj_forward(self.model, self.data)
            self._sensed_at = self._steps
        start = int(self.model.sensor_adr[index])
        return tuple(float(v) for v in self.data.sensordata[start : start + int(self.model.sensor_dim[index])])

    def joint_position(self, joint: str) -> float:
        """The true joint position (for tests and plots; a controller reads encoders)."""
        return float(self.data.joint(self._joint(joint)).qpos[0])

    def joint_velocity(self, joint: str) -> float:
        return float(self.data.joint(self._joint(joint)).qvel[0])

    def _joint(self, name: str) -> int:
        index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if index < 0:
            raise PlantError(f"the model has no joint named `{name}`")
        return int(index)

    def body_pose(self, body: str) -> Pose:
        index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, body)
        if index < 0:
            raise PlantError(f"the model has no body named `{body}`")
        return _pose(self.data.xpos[index], self.data.xquat[index])

    def site_pose(self, site: str) -> Pose:
        index = self._site(site)
        quaternion = np.empty(4)
        mujoco.mju_mat2Quat(quaternion, self.data.site_xmat[index])
        return _pose(self.data.site_xpos[index], quaternion)

    def site_jacobian(self, site: str) -> tuple[FloatArray, FloatArray]:
        """Translational and rotational Jacobians (3 × nv each) of a site, at the current state."""
        jacp = np.zeros((3, self.model.nv))
        jacr = np.zeros((3, self.model.nv))
        mujoco.mj_jacSite(self.model, self.data, jacp, jacr, self._site(site))
        return jacp, jacr

    def _site(self, name: str) -> int:
        index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name)
        if index < 0:
            raise PlantError(f"the model has no site named `{name}`")
        return int(index)

    def contacts_between(self, body_a: str, body_b: str) -> int:
        """How many contacts touch the two bodies now."""
        a = self.model.body(body_a).id
        b = self.model.body(body_b).id
        count = 0
        for i in range(self.data.ncon):
            contact = self.data.contact[i]
            pair = {int(self.model.geom_bodyid[contact.geom1]), int(self.model.geom_bodyid[contact.geom2])}
            count += pair == {a, b}
        return count

    # ------------------------------------------------------------ frames

    def every(self, interval: float, hook: _FrameHook) -> None:
        """Call `hook(plant)` every `interval` seconds of simulated time (e.g. to record video frames)."""
        if interval <= 0:
            raise PlantError(f"a frame interval must be positive, got {interval} s")
        self._frame_hooks.append((interval, hook))
        self._next_frame.append(self.time)

    def _call_frame_hooks(self) -> None:
        for i, (interval, hook) in enumerate(self._frame_hooks):
            if self.time + 0.5 * self.timestep >= self._next_frame[i]:
                self._next_frame[i] += interval
                hook(self)

    def on_close(self, closer: Callable[[], None]) -> None:
        """Run `closer` when the plant is closed (a renderer to release, a video to finish)."""
        self._closers.append(closer)

    def close(self) -> None:
        """Finish what was attached to the plant (renderers, recordings), once."""
        closers, self._closers = self._closers, []
        for closer in closers:
            closer()


@dataclass(frozen=True)
class _Member:
    """A real effector or receptor, as a message about its period names it."""

    shown: str
    location: SourceLocation | None
    #: nanoseconds; None: it runs when a message wakes it
    period: int | None
    #: its family as the run names it (`arm/a.motor[K]/re`), or its own name
    family: str = ""
    #: `context.parameters` of its functions
    parameters: Mapping[str, Any] = field(default_factory=dict)
    #: the indices of its family and its agent's family (`K` of `motor[K in 1..N]/re`)
    indices: frozenset[str] = frozenset()


@dataclass(frozen=True)
class _Map:
    """`map_actuator('arm/a.motor[K]/re', 'motor{K}')`: the subsystems it names and the model's name of each."""

    subsystem: str
    #: "actuator", "encoder" or "sensor"
    kind: str
    template: str

    def letters(self) -> list[str]:
        """The names in brackets (`K` of `arm/a.motor[K]/re`), each replaced by its parameter's value to match."""
        return re.findall(r"\[([A-Za-z_]\w*)\]", self.subsystem)

    def matches(self, subsystem: str, parameters: Mapping[str, Any]) -> bool:
        """`arm/a.motor[K]/re` names `arm/a.motor[2]/re` when its K is 2 (each `[NAME]` by its parameter)."""

        def index(found: re.Match[str]) -> str:
            value = parameters.get(found[1])
            return found[0] if value is None else f"[{value}]"

        return re.sub(r"\[([A-Za-z_]\w*)\]", index, self.subsystem) == subsystem

    def names_beyond(self, subsystem: str, parameters: Mapping[str, Any]) -> bool:
        """`arm/a.motor[6]/re` names a member of the family of `arm/a.motor[2]/re`, by a number that may be
        outside the family's range in this run (each `[NAME]` by its parameter, as `matches`)."""
        # ASCII digits: `\d` takes `٢` too, which names no member (a slip, said as a map that maps nothing)
        if not re.search(r"\[[0-9]+\]", self.subsystem):
            return False

        def index(found: re.Match[str]) -> str:
            value = parameters.get(found[1])
            return found[0] if value is None else f"[{value}]"

        named = re.escape(re.sub(r"\[([A-Za-z_]\w*)\]", index, self.subsystem))
        return re.fullmatch(re.sub(r"\\\[[0-9]+\\\]", r"\\[[0-9]+\\]", named), subsystem) is not None

    def name_for(self, subsystem: str, parameters: Mapping[str, Any]) -> str:
        try:
            return self.template.format_map(parameters)
        except (KeyError, IndexError, ValueError, AttributeError, TypeError) as error:
            # what str.format raises for what is in braces (`{Q}`, `{K[0]}`, `{K.x}`, a lone `{`)
            shown = ", ".join(parameters) or "none"
            reason = f"it has no parameter `{error.args[0]}`" if isinstance(error, KeyError) else str(error)
            raise PlantError(
                f"the {'actuator' if self.kind == 'encoder' else self.kind} `{self.template}` mapped for "
                f"`{subsystem}` cannot be written from its parameters ({reason}); in braces go the names of its "
                f"parameters: {shown}"
            ) from None


def _real_families(system: System) -> dict[str, list[_Member]]:
    """The real effectors and receptors, by family (`arm/a.motor[K]/re`; one that is no family by its own name)."""
    families: dict[str, list[_Member]] = {}
    for member in _members(system, real_only=True):
        families.setdefault(member.family, []).append(member)
    return families


def _members(system: System, *, real_only: bool) -> list[_Member]:
    """The subsystems of the (expanded) system, each with the parameters its functions get: the real effectors
    and receptors alone for the periods the plant must divide; every subsystem for the maps, since any of them
    is given `context.environment` and may ask `actuator_of` or `sensor_of`."""
    from earl.model.kinds import Kind
    from earl.model.text import subsystem_name
    from earl.runtime.parameters import agent_parameters, subsystem_parameters

    members: list[_Member] = []
    for agent in system.agents:
        inherited = agent_parameters(system, agent)
        for subsystem in agent.subsystems:
            if real_only and subsystem.kind not in (Kind.REAL_EFFECTOR, Kind.REAL_RECEPTOR):
                continue
            shown = subsystem_name(agent, subsystem)
            index = "" if subsystem.index is None else str(subsystem.index)
            family = shown
            if index and subsystem.family is not None:  # `arm/a.motor[2]/re` is a member of `arm/a.motor[K]/re`
                family = shown.rsplit("[", 1)[0] + f"[{subsystem.family.index}]/{subsystem.kind}"
            period = None if subsystem.period is None else round(subsystem.period.seconds * 1e9)
            parameters = subsystem_parameters(inherited, subsystem)
            indices = frozenset(f.index for f in (agent.family, subsystem.family) if f is not None)
            members.append(_Member(shown, subsystem.location, period, family, parameters, indices))
    return members


def _family_of(subsystem: str) -> str:
    """`arm/a.motor[2]/re` → `arm/a.motor[K]/re`, for a message that shows how a map names it."""
    return re.sub(r"\[\d+\](?=/\w+$)", "[K]", subsystem)


def _shown_time(nanoseconds: int) -> str:
    for unit, size in (("s", 10**9), ("ms", 10**6), ("µs", 10**3)):
        if nanoseconds >= size:
            return f"{nanoseconds / size:g} {unit}"
    return f"{nanoseconds} ns"


def _divisor_below(period: int, step: int) -> int:
    """The longest step, no longer than `step`, that divides `period` (nanoseconds): what to suggest instead."""
    # a million tries: the periods' common divisor in nanoseconds is a round number unless written to the nanosecond
    return next((period // n for n in range(1, min(period, 10**6) + 1) if period % n == 0 and period // n <= step), 1)


def _pose(position: FloatArray, quaternion: FloatArray) -> Pose:
    p = (float(position[0]), float(position[1]), float(position[2]))
    q = (float(quaternion[0]), float(quaternion[1]), float(quaternion[2]), float(quaternion[3]))
    return Pose(p, q)


#: what TinyXML2, MuJoCo's XML reader, means by the errors a hand-written model most often has
_XML_ERRORS = {
    "XML_ERROR_MISMATCHED_ELEMENT": "is closed by an end tag of another name",
    "XML_ERROR_PARSING_ELEMENT": "has a malformed tag",
    "XML_ERROR_PARSING_ATTRIBUTE": "has a malformed attribute",
    "XML_ERROR_PARSING_TEXT": "has text outside any element (is it XML?)",
    "XML_ERROR_PARSING_COMMENT": "has a comment that is not closed (`-->`)",
    "XML_ERROR_PARSING": "is cut short or malformed: an element is not closed",
    "XML_ERROR_EMPTY_DOCUMENT": "is empty",
}
_TINYXML = re.compile(
    r"XML parse error \d+:\s*Error=(\w+) ErrorID=\d+ \(0x[0-9a-fA-F]+\) Line number=(\d+)(?::\s*(.*))?", re.S
)
#: the last line of MuJoCo's own errors: `Element 'joint', line 6` or `Element name 'motor2', id 1, line 16`
_ELEMENT = re.compile(r"Element (name )?'([^']*)'(?:, id \d+)?, line (\d+)")
_PREFIXES = re.compile(r"^(?:(?:XML Error|Error|ParseXML):\s*)+")


def load_error(origin: str, error: str) -> str:
    """MuJoCo's error on reading a model, on one line that names the XML (`origin`) and the line.

    MuJoCo writes its errors over several lines (TinyXML2's for XML that is not well formed, its own
    for a schema or model mistake); a diagnostic is one line, on which they would read `\\n`."""
    tinyxml = _TINYXML.match(error.strip())
    if tinyxml is not None:
        kind, line, detail = tinyxml[1], tinyxml[2], (tinyxml[3] or "").strip()
        element = re.fullmatch(r"XMLElement name=(\S+)", detail)
        subject = f"the element `<{element[1]}>` that starts there" if element else "the XML"
        what = _XML_ERRORS.get(kind, "is not well formed")
        return f"MuJoCo could not read {origin}, line {line}: {subject} {what} ({kind})"
    lines = [line.strip() for line in error.strip().splitlines() if line.strip()]
    where = ""
    if lines and (element := _ELEMENT.fullmatch(lines[-1])) is not None:
        named, name, line = element[1], element[2], element[3]
        where = f", line {line} ({'the element named' if named else 'element'} `{name if named else '<' + name + '>'}`)"
        lines.pop()
    said = "; ".join(_PREFIXES.sub("", line) for line in lines) or "no reason given"
    return f"MuJoCo could not read {origin}{where}: {said}"
