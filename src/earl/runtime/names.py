"""How the runtime names concrete elements: `manip/a.motorController[3]/ve`, `windingCurrent[3]`.

The same text names a subsystem in the CLI (`--record-memory manip/a.cs`), in the
Python API (`sim.state_of("manip/a.cs")`) and in trace topics.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from earl.model.elements import Agent
from earl.model.expressions import ElementReference, Literal
from earl.model.text import instance_name as indexed  # `windingCurrent[3]`: spelled as the checker spells it

__all__ = ["agent_name", "family_example", "indexed", "named_members", "reference_index", "reference_key"]


def agent_name(agent: Agent) -> str:
    return f"{indexed(agent.name, agent.index)}/a"


def reference_key(reference: ElementReference) -> str:
    """`windingCurrent[3]/mo` → `windingCurrent[3]`: buffers and memory are keyed without their kind."""
    if not reference.indices:
        return reference.name
    index = reference.indices[0]
    if not isinstance(index, Literal) or not isinstance(index.value, int):
        raise ValueError(f"`{reference.name}` is not a concrete member (expand the system first)")
    return indexed(reference.name, index.value)


def reference_index(reference: ElementReference) -> int | None:
    if not reference.indices:
        return None
    index = reference.indices[0]
    return index.value if isinstance(index, Literal) and isinstance(index.value, int) else None


#: a name with its index, if any: `pusher[*]`, `motorController[3]`, `cs`
_INDEXED = re.compile(r"([A-Za-z_]\w*)(?:\[([^\]]*)\])?")


def named_members(written: str, names: Iterable[str]) -> list[str]:
    """The names among `names` (`pusher[1]/a.cs`, …) that `written` stands for, in their order: itself
    when it is one; else every member of each family it names whole, as `earl diagram --target` and a
    robot name one: with `[*]`, with an index variable (`pusher[K]/a.cs`) or without an index
    (`pusher/a.cs`). A member is named by its number (`pusher[2]/a.cs`). None: it names nothing."""
    listed = list(names)
    if written in listed:
        return [written]
    parts: list[str] = []
    position = 0
    for match in _INDEXED.finditer(written):
        parts.append(re.escape(written[position : match.start()]))
        name, index = match.group(1), match.group(2)
        if index is None:
            parts.append(re.escape(name) + r"(?:\[[0-9]+\])?")
        elif index.strip().isascii() and index.strip().isdigit():
            parts.append(rf"{re.escape(name)}\[{int(index)}\]")
        elif index.strip() == "*" or re.fullmatch(r"[A-Za-z_]\w*", index.strip()):
            parts.append(re.escape(name) + r"\[[0-9]+\]")
        else:
            return []
        position = match.end()
    parts.append(re.escape(written[position:]))
    pattern = re.compile("".join(parts))
    return [name for name in listed if pattern.fullmatch(name)]


def family_example(names: Iterable[str]) -> str | None:
    """`` `pusher[1]/a.cs`, or every member, `pusher[*]/a.cs` `` for the first member of a family among
    `names`, to show how members are named; None when none is one."""
    member = next((name for name in names if "[" in name), None)
    if member is None:
        return None
    family = re.sub(r"\[[0-9]+\]", "[*]", member)
    return f"`{member}`, or every member, `{family}`"
