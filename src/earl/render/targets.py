"""`--target manip/a.cs.jointMove/bb`: finding the element a diagram is about.

A target is written in the manual's dot notation: an agent (`manip/a`), a
subsystem (`manip/a.cs`, `manip/a.motorController/ve`), or a Basic Behaviour
(`manip/a.cs.jointMove/bb`, optionally followed by `.tf` or `.tf.execute()`).
A family is named without an index, with its index variable
(`motorController[K]/ve`) or with `[*]`; with `--expand`, a member is named by its number
(`motorController[3]/ve`) or a parameter whose value it is (`motorController[N]/ve`).
Without `--expand` a target naming a member of each family on its way (or such a parameter) is
drawn alone, from the expansion (`names_a_member` says so); one that names a family anywhere on
its way (`manip[2]/a.motorController[K]/ve`) is drawn as the declared family.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from earl.model.elements import Agent, BasicBehaviour, Family, Subsystem, System
from earl.model.expand import family_members, parameter_values
from earl.model.expressions import ConstantError
from earl.render.names import agent_name, qualified_subsystem_name

_SEGMENT = re.compile(r"^(?P<name>[A-Za-z_]\w*)(?:\[(?P<index>[^\]]*)\])?(?:/(?P<kind>[a-z]+))?$")


class TargetError(Exception):
    """A `--target` that names nothing; the message lists what could be named instead."""


@dataclass(frozen=True)
class Segment:
    name: str
    index: str | None
    kind: str | None


def _segments(text: str) -> list[Segment]:
    cleaned = text.strip()
    for suffix in (".tf.execute()", ".tf"):
        if cleaned.endswith(suffix):
            cleaned = cleaned[: -len(suffix)]
    result = []
    for part in cleaned.split("."):
        match = _SEGMENT.match(part)
        if match is None:
            raise TargetError(f"`{text}` is not a target: `{part}` should look like `name/kind`, e.g. `manip/a.cs`")
        result.append(Segment(match["name"], match["index"], match["kind"]))
    return result


Environment = Mapping[str, bool | int | float | str]


def _number(written: str) -> int | None:
    """A member's number as written, read as a number (`02` is member 2) by both matchers alike."""
    # ASCII digits: `\d` (and `int`) also take `٢` and `２`, which no spec writes for a member
    return int(written) if re.fullmatch(r"-?[0-9]+", written) else None


def _matches(
    segment: Segment, name: str, family: Family | None, index: int | None, kind: str, environment: Environment
) -> bool:
    if segment.name != name or (segment.kind is not None and segment.kind != kind):
        return False
    if index is not None:  # a member of an expanded family answers to its number, or a parameter that is it
        written = None if segment.index is None else segment.index.strip()
        if written is not None and written in environment:
            written = str(environment[written])
        return written is not None and _number(written) == index
    if family is None:
        return segment.index is None
    # a family drawn once answers to its name, its index variable, or any member's number; not to another
    # letter or text (`[J]` of `motorController[K]`, `[foo]`), which names nothing of it
    number = None if segment.index is None else segment.index.strip()
    if number is None or number in (family.index, "*"):  # `[*]`: EARL's every member
        return True
    if number in environment:  # a parameter, `[N]`: the member it is
        number = str(environment[number])
    member = _number(number)
    if member is None:
        return False
    try:
        return member in family_members(family, environment)
    except ConstantError:  # its range needs an agent's own parameters: the name alone decides
        return True


def _environment(system: System) -> Environment:
    try:
        return parameter_values(system.parameters, {})
    except ConstantError:
        return {}


def _choices(names: Sequence[str]) -> str:
    shown = ", ".join(f"`{n}`" for n in names[:12])
    return shown + (f" and {len(names) - 12} more" if len(names) > 12 else "")


def find_agent(system: System, text: str) -> Agent:
    segments = _segments(text)
    first = segments[0]
    if first.kind is None and len(segments) == 1:
        first = Segment(first.name, first.index, "a")
    environment = _environment(system)
    found = [a for a in system.agents if _matches(first, a.name, a.family, a.index, "a", environment)]
    if len(found) != 1 or len(segments) != 1:
        raise TargetError(f"no agent `{text}`; the agents are {_choices([agent_name(a) for a in system.agents])}")
    return found[0]


def _subsystem_in(agent: Agent, segment: Segment, environment: Environment) -> Subsystem | None:
    for subsystem in agent.subsystems:
        kind = subsystem.kind.value
        if segment.name == "cs" and segment.kind in (None, "cs") and kind == "cs":
            return subsystem
        if segment.kind is not None and _matches(
            segment, subsystem.name, subsystem.family, subsystem.index, kind, environment
        ):
            return subsystem
    return None


def all_subsystems(system: System) -> list[tuple[Agent, Subsystem]]:
    return [(agent, subsystem) for agent in system.agents for subsystem in agent.subsystems]


def only_fsm(system: System) -> tuple[Agent, Subsystem]:
    """The subsystem whose FSM is drawn when no --target is given: the only one that has an FSM."""
    found = [(a, s) for a, s in all_subsystems(system) if s.fsm is not None]
    if len(found) == 1:
        return found[0]
    if not found:
        raise TargetError("no subsystem has an FSM to draw")
    raise TargetError(
        "the fsm view needs --target naming a subsystem, e.g. "
        + ", ".join(qualified_subsystem_name(a, s) for a, s in found[:12])
    )


def find_subsystem(system: System, text: str) -> tuple[Agent, Subsystem]:
    segments = _segments(text)
    choices = [qualified_subsystem_name(a, s) for a, s in all_subsystems(system)]
    if len(segments) != 2:
        raise TargetError(f"`{text}` does not name a subsystem; the subsystems are {_choices(choices)}")
    try:
        agent = find_agent(system, segments[0].name + _index(segments[0]) + "/" + (segments[0].kind or "a"))
    except TargetError:
        raise TargetError(f"no subsystem `{text}`; the subsystems are {_choices(choices)}") from None
    subsystem = _subsystem_in(agent, segments[1], _environment(system))
    if subsystem is None:
        raise TargetError(f"no subsystem `{text}`; the subsystems are {_choices(choices)}")
    return agent, subsystem


def find_behaviour(system: System, text: str) -> tuple[Agent, Subsystem, BasicBehaviour]:
    segments = _segments(text)
    choices = [
        f"{qualified_subsystem_name(a, s)}.{b.name}/bb" for a, s in all_subsystems(system) for b in s.basic_behaviours
    ]
    if len(segments) != 3 or segments[2].kind not in (None, "bb"):
        raise TargetError(f"`{text}` does not name a basic behaviour; they are {_choices(choices)}")
    head = ".".join(f"{s.name}{_index(s)}" + (f"/{s.kind}" if s.kind else "") for s in segments[:2])
    try:
        agent, subsystem = find_subsystem(system, head)
    except TargetError:
        raise TargetError(f"no basic behaviour `{text}`; they are {_choices(choices)}") from None
    behaviour = subsystem.basic_behaviour(segments[2].name)
    if behaviour is None:
        own = [f"{b.name}/bb" for b in subsystem.basic_behaviours]
        where = qualified_subsystem_name(agent, subsystem)
        has = f"it has {_choices(own)}" if own else "it has none"
        raise TargetError(f"{where} has no basic behaviour `{segments[2].name}/bb`; {has}")
    return agent, subsystem, behaviour


def _index(segment: Segment) -> str:
    return "" if segment.index is None else f"[{segment.index}]"


def names_a_member(system: System, view: str, text: str) -> bool:
    """Whether `text` names one member of every family the declared `system` draws once that it passes
    through (`manip/a.motorController[2]/ve`, `worker[N]/a`, `manip[2]/a.motorController[3]/ve`), rather than a
    family (`[K]`, `[*]`, no index) or an element declared alone. A target that names a family anywhere
    (`manip[2]/a.motorController[K]/ve`, `manip/a.motorController[2]/ve` when `manip` is a family) is drawn
    as its declared family: a family's drawing is the same for each of its members."""
    try:
        segments = _segments(text)
        if view in ("agent", "types"):
            agent = find_agent(system, text)
            return _is_member(segments[0], agent.family) is True
        if view == "fsm":
            agent, subsystem = find_subsystem(system, text)
        elif view == "activity":
            agent, subsystem, _ = find_behaviour(system, text)
        else:
            return False
    except TargetError:
        return False  # said when the view looks for it
    named = [_is_member(segments[0], agent.family)]
    if len(segments) > 1 and subsystem.kind.value != "cs":
        named.append(_is_member(segments[1], subsystem.family))
    families = [member for member in named if member is not None]
    return bool(families) and all(families)


def _is_member(segment: Segment, family: Family | None) -> bool | None:
    """For a segment that matched `family`: whether it names one member (True) or the family itself (False);
    None when there is no family to name a member of."""
    if family is None:
        return None
    return segment.index is not None and segment.index.strip() not in (family.index, "*")
