"""One diagnostic for a problem that every member of an indexed family shares.

Rules look at the expanded system, so a wrong `link motor[K in 1..N],cs` declared once is found
once per member: N findings at the same place, whose messages differ only in
the index (`motor[1],cs` … `motor[6],cs`).  A person wrote it once and fixes it once, so the
check says it once, with the indices that differ written as a range: `motor[1..6],cs`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

from earl.model.location import SourceLocation

_INDEX = re.compile(r"\[(\d+)\]")


@dataclass(frozen=True)
class Said:
    """What a rule found, with the rule's code; `message` may name a family member's index."""

    code: str
    message: str
    location: SourceLocation | None
    hint: str | None


def merge_family_members(findings: Iterable[Said]) -> list[Said]:
    """The findings in their first order, those of one rule at one place whose messages differ only in
    indices merged into one (with the first one's hint: a rule's hint does not name a member)."""
    groups: dict[tuple[str, SourceLocation | None, str], list[Said]] = {}
    for said in findings:
        shape = _INDEX.sub("[]", said.message)
        groups.setdefault((said.code, said.location, shape), []).append(said)
    merged: list[Said] = []
    for group in groups.values():
        first = group[0]
        messages = list(dict.fromkeys(said.message for said in group))  # the same text twice is said once
        if len(messages) == 1:
            merged.append(first)
            continue
        indices = [[int(found) for found in _INDEX.findall(message)] for message in messages]
        ranges = [f"[{_written(sorted(set(column)))}]" for column in zip(*indices, strict=True)]
        pieces = _INDEX.split(first.message)[::2]  # the text around the indices
        message = "".join(piece + index for piece, index in zip(pieces, [*ranges, ""], strict=True))
        merged.append(Said(first.code, message, first.location, first.hint))
    return merged


def _written(values: list[int]) -> str:
    """`1..6` for a run of consecutive indices, `1, 3, 4` otherwise, `2` for one."""
    if len(values) == 1:
        return str(values[0])
    if values[-1] - values[0] == len(values) - 1:
        return f"{values[0]}..{values[-1]}"
    return ", ".join(str(value) for value in values)


__all__ = ["Said", "merge_family_members"]
