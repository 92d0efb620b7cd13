"""The written form of a signal (`manip/a.cs.windingCurrent[1]`), checked before it is looked up.

A signal is names joined by `/` and `.`, each name followed by any number of indices in brackets:

    signal := NAME step*          step := "/" NAME | "." NAME | "[" index "]"
    index  := digits | "*" | NAME (a family's index variable, said by the lookup to be no member)

Names are the spec's (`[A-Za-z_][A-Za-z0-9_]*`). Whether the names are those of a subsystem and its
memory or output buffer is the lookup's question; this module says only where the text itself goes
wrong, so that `x[` is named a malformed signal rather than a subsystem the trace lacks.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from earl.diagnostics import escape_controls

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_INDEX = re.compile(r"[0-9]+|\*|[A-Za-z_][A-Za-z0-9_]*")


@dataclass(frozen=True)
class MalformedSignal:
    """Where a signal's text goes wrong (`at`, counted from 0) and what is wrong there."""

    signal: str
    at: int
    problem: str

    def __str__(self) -> str:
        """The spot and what is wrong there, then the signal again with a caret under the spot."""
        shown = escape_controls(self.signal)
        column = len(escape_controls(self.signal[: self.at]))
        said = f"`{shown}` is malformed at character {column + 1}: {self.problem}\n  {shown}\n  {' ' * column}^"
        hint = foxglove_hint(self.signal)
        return said if hint is None else f"{said}\n{hint}"


#: a Foxglove message path of a trace's topic, as docs/semantics.md shows them: `"/manip/a.cs/memory".x[1]`
_FOXGLOVE_PATH = re.compile(r'"?/(?P<topic>[^"]*)"?(?P<path>(?:\.[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9:]*\])?)*)\Z')


def foxglove_hint(signal: str) -> str | None:
    """For a Foxglove message path pasted as a signal, how earl names what it plots; None for other text.

    A memory topic's path is the subsystem's memory: `"/manip/a.cs/memory".windingCurrent[1]` is
    `manip/a.cs.windingCurrent[1]`. A link's topic is named by the link, where a signal names the
    output buffer it leaves, which only the trace knows."""
    found = _FOXGLOVE_PATH.match(signal)
    if found is None or not signal.startswith(('"/', "/")):
        return None
    topic, path = found.group("topic"), found.group("path").replace("[:]", "[*]")
    if topic.endswith("/memory") and path:
        spelled = f"{topic.removesuffix('/memory')}{path}"
        return f"this is a Foxglove message path; earl names that value `{escape_controls(spelled)}`"
    if topic.startswith("link/"):
        return (
            "this is a Foxglove message path; earl names a value a link carries by the output buffer it leaves, "
            "`agent/a.subsystem.buffer.field` (the link's channel names it, `source`; `earl plot TRACE "
            "--signal agent/a.subsystem` lists them)"
        )
    if topic.endswith("/fsm"):
        return (
            "this is a Foxglove message path; earl plot draws a subsystem's states as the shaded bands of its signals"
        )
    return None


def signal_text_problem(signal: str) -> str | None:
    """What is wrong with a signal as given on the command line or in run.toml, said after the option
    that gave it (`--signal …`), or None: one that is empty, or not written as a signal is."""
    if not signal.strip():
        return "names no signal: write one as `agent/a.subsystem.memory`, e.g. manip/a.cs.count"
    malformed = signal_syntax_error(signal)
    return None if malformed is None else str(malformed)


def signal_syntax_error(signal: str) -> MalformedSignal | None:
    """The first place where `signal` is not written as a signal is, or None when it is."""
    at = 0
    while True:
        name = _NAME.match(signal, at)
        if name is None:
            where = (
                f"after `{signal[at - 1]}`, where a name belongs"
                if at
                else "where the first name belongs: a signal starts with its agent's name, as in `manip/a.cs.count`"
            )
            return MalformedSignal(signal, at, f"{_found(signal, at)} {where}")
        last, at = name.group(), name.end()  # the name that brackets after it index, for the examples
        while at < len(signal) and signal[at] == "[":
            index = _INDEX.match(signal, at + 1)
            if index is None:
                return MalformedSignal(
                    signal,
                    at + 1,
                    f"{_found(signal, at + 1)} where an index belongs: a whole number, as in `{last}[1]`, "
                    f"or `*` for every member or element, `{last}[*]`",
                )
            if not signal.startswith("]", index.end()):
                return MalformedSignal(
                    signal, index.end(), f"{_found(signal, index.end())} where the `]` closing `[` belongs"
                )
            at = index.end() + 1
        if at == len(signal):
            return None
        if signal[at] not in "./":
            return MalformedSignal(
                signal,
                at,
                f"{_found(signal, at)} after `{signal[name.start() : at]}`: a signal's names are joined by `.` and `/`, "
                "and indexed in brackets, `[1]`",
            )
        at += 1


def _found(signal: str, at: int) -> str:
    """What stands at `at`, in words: the end, a space, or the character itself."""
    if at >= len(signal):
        return "the signal ends"
    character = signal[at]
    if character.isspace():
        return "a space" if character == " " else f"`{escape_controls(character)}` (white space)"
    return f"`{escape_controls(character)}`"
