"""Element names as the diagrams and the document print them, and keys to find elements by reference.

A declared family is drawn once with its index variable (`motorController[K]/ve`,
`K ∈ 1..N`, as the manual's Figure 10); a member of an expanded family carries
its number (`motorController[3]/ve`).  The notation itself (`name/kind`,
expressions) comes from `earl.model.text`, so every reader spells an element alike.
"""

from __future__ import annotations

import hashlib
import re
from typing import Protocol, TypeVar

from earl.model.elements import Agent, Family, Link, Subsystem
from earl.model.expressions import ElementReference, Literal
from earl.model.kinds import Kind
from earl.model.text import expression_text


class Indexed(Protocol):
    """Anything that can be declared as a family: buffers, memory, subsystems, agents."""

    @property
    def name(self) -> str: ...

    @property
    def family(self) -> Family | None: ...

    @property
    def index(self) -> int | None: ...


def indexed_name(element: Indexed) -> str:
    """`windingCurrent[K]` for a declared family, `windingCurrent[3]` for a member, else the name."""
    if element.index is not None:
        return f"{element.name}[{element.index}]"
    if element.family is not None:
        return f"{element.name}[{element.family.index}]"
    return element.name


def family_note(element: Indexed) -> str | None:
    """`K ∈ 1..N` for a declared family drawn once; None for a member or a single element."""
    family = element.family
    if family is None or element.index is not None:
        return None
    return f"{family.index} ∈ {expression_text(family.first)}..{expression_text(family.last)}"


def agent_name(agent: Agent) -> str:
    return f"{indexed_name(agent)}/a"


def subsystem_name(subsystem: Subsystem) -> str:
    """`cs` or `motorController[K]/ve`: the name within its agent."""
    if subsystem.kind is Kind.CONTROL_SUBSYSTEM:
        return "cs"
    return f"{indexed_name(subsystem)}/{subsystem.kind.value}"


def qualified_subsystem_name(agent: Agent, subsystem: Subsystem) -> str:
    """`manip/a.cs`: the manual's dot notation (§2.2)."""
    return f"{agent_name(agent)}.{subsystem_name(subsystem)}"


def element_name(element: Indexed, kind: Kind) -> str:
    return f"{indexed_name(element)}/{kind.value}"


def link_label(link: Link) -> str:
    """`cs,motorController[K]`: the link's name with its index, without the family's range."""
    return ",".join(
        part.name if part.index is None else f"{part.name}[{expression_text(part.index)}]" for part in link.name
    )


# ---------------------------------------------------------------------- finding elements by reference
Key = tuple[str, Kind, int | None]


def normal_kind(kind: Kind) -> Kind:
    """Memory is declared `/m` and referenced as `/mi` or `/mo`: all three name one element."""
    return Kind.MEMORY if kind in (Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT) else kind


def element_key(element: Indexed, kind: Kind) -> Key:
    return element.name, normal_kind(kind), element.index


def reference_keys(reference: ElementReference) -> list[Key]:
    """The keys a reference may denote, most specific first.

    `windingCurrent[3]/mo` names member 3 in an expanded system and, in a declared
    one where families are drawn once, the family itself; `windingCurrent[K]/mo`
    and `windingCurrent[*]/mo` name the family.
    """
    kind = normal_kind(reference.kind)
    keys: list[Key] = []
    if reference.indices:
        index = reference.indices[0]
        if isinstance(index, Literal) and isinstance(index.value, int) and not isinstance(index.value, bool):
            keys.append((reference.name, kind, index.value))
    keys.append((reference.name, kind, None))
    return keys


T = TypeVar("T")


def lookup(table: dict[Key, T], reference: ElementReference) -> T | None:
    for key in reference_keys(reference):
        if key in table:
            return table[key]
    return None


# ---------------------------------------------------------------------- anchors and file names
# `_` is kept: names may hold it, and `arm_a` must not become the slug of `arm/a`.
_UNSAFE = re.compile(r"[^A-Za-z0-9_]+")
#: file systems refuse names over 255 bytes; a diagram's file name is its slug and a suffix
_LONGEST = 120


def slug(*parts: str) -> str:
    """A stable identifier for HTML anchors and file names: `manip-a-cs-jointMove-bb`.

    Distinct elements get distinct slugs: EARL names are letters, digits and `_`, and the
    characters that join them (`/`, `,`, `.`, `[`) become `-`. A slug too long for a file name
    keeps its start and ends with a digest of the whole."""
    text = "-".join(_UNSAFE.sub("-", part).strip("-") for part in parts if part) or "x"
    if len(text) > _LONGEST:
        digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:12]
        text = f"{text[: _LONGEST - 13]}-{digest}"
    return text
