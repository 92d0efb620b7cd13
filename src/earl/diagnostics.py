"""Diagnostics: one located, plain-language message per problem, printed like rustc's.

error[EARL-S003]: expected `->` after the source state `idle`
  --> pick.earl:41:14
   |
41 |         idle jointMove when newJointPos/pp
   |              ^^^^^^^^^
   = hint: a transition is written `source -> destination when CONDITION`
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

from earl.model.location import SourceLocation


class Severity(StrEnum):
    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


@dataclass
class Diagnostic:
    severity: Severity
    message: str
    location: SourceLocation | None = None
    code: str | None = None
    hint: str | None = None

    def __str__(self) -> str:
        """`file:3:5: error[EARL-R018]: message`, and the hint on a line of its own, as `earl check` says them:
        an uncaught `EarlError` (which says its first diagnostic so) must say how to fix what it names."""
        return self.headline() + (f"\n  = hint: {self.hint}" if self.hint else "")

    def headline(self) -> str:
        """The diagnostic without its hint: `file:3:5: error[EARL-R018]: message`."""
        where = f"{self.location}: " if self.location else ""
        code = f"[{self.code}]" if self.code else ""
        return f"{where}{self.severity.value}{code}: {self.message}"


class EarlError(Exception):
    """Raised when a specification cannot be read into a model; carries every diagnostic found."""

    def __init__(self, diagnostics: Sequence[Diagnostic], sources: SourceMap | None = None) -> None:
        self.diagnostics = list(diagnostics)
        self.sources = sources or SourceMap()
        first = self.diagnostics[0] if self.diagnostics else None
        said = first.headline() if first else "invalid specification"
        if len(self.diagnostics) > 1:
            # an uncaught error prints only this: the rest are in `.diagnostics`
            said += f" (and {len(self.diagnostics) - 1} more in .diagnostics)"
        if first is not None and first.hint:
            said += f"\n  = hint: {first.hint}"
        super().__init__(said)


@dataclass
class SourceMap:
    """The text of every file read, so a diagnostic can quote the line it points at."""

    texts: dict[str, str] = field(default_factory=dict)
    #: each file's lines, split once: a large spec with many findings would be split for each
    _lines: dict[str, list[str]] = field(default_factory=dict, repr=False, compare=False)

    def add(self, name: str, text: str) -> None:
        self.texts[name] = text
        self._lines.pop(name, None)

    def line(self, name: str, number: int) -> str | None:
        lines = self._lines.get(name)
        if lines is None:
            text = self.texts.get(name)
            if text is None:
                return None
            # lines as the reader counts them: `str.splitlines` would also break at U+2028, U+0085 …
            # inside a comment or a string, and quote the wrong line after it
            lines = self._lines[name] = [line.removesuffix("\r") for line in text.split("\n")]
        if 1 <= number <= len(lines):
            return lines[number - 1]
        return "" if number == len(lines) + 1 else None


def did_you_mean(name: str, candidates: Iterable[str]) -> str | None:
    """A hint naming the closest candidate, for misspelt names."""
    names = sorted(set(candidates))
    # a slip of case only (`PLAN` for `plan`) is the closest of all, though difflib sees no letter alike
    same_but_case = [candidate for candidate in names if candidate.casefold() == name.casefold()]
    if same_but_case and name not in names:
        return f"did you mean `{same_but_case[0]}`?"
    matches = difflib.get_close_matches(name, names, n=1, cutoff=0.6)
    return f"did you mean `{matches[0]}`?" if matches else None


#: columns of a source line shown at most; a longer line is cut around the spot, as rustc does
SHOWN_COLUMNS = 100
#: columns shown before the spot in a cut line
CONTEXT_COLUMNS = 30


def _window(source: str, start: int, width: int) -> tuple[str, int, int]:
    """The part of a long line around `start` (0-based), with `…` where it was cut; where the caret
    starts in it, and how wide it is."""
    if len(source) <= SHOWN_COLUMNS:
        return source, start, width
    first = max(0, min(start - CONTEXT_COLUMNS, len(source) - SHOWN_COLUMNS))
    last = first + SHOWN_COLUMNS
    shown = ("…" if first else "") + source[first:last] + ("…" if last < len(source) else "")
    offset = start - first + (1 if first else 0)
    return shown, offset, max(1, min(width, last - start))


#: control characters as escapes: a message or hint quoting the spec's text (a string value, a file name
#: with a newline) stays on its line, and cannot print what looks like another diagnostic
_ESCAPED_CONTROLS = (
    {code: f"\\x{code:02x}" for code in [*range(32), *range(0x7F, 0xA0)]}  # C0, DEL and C1 (CSI is 0x9b)
    | {10: "\\n", 13: "\\r", 9: "\\t"}
)


def escape_controls(text: str) -> str:
    """`text` with its control characters written as escapes: what the spec or its code wrote (a message,
    a file name, a source line) can neither start a line of its own nor drive the terminal."""
    return text.translate(_ESCAPED_CONTROLS)


def render(diagnostic: Diagnostic, sources: SourceMap) -> str:
    """The diagnostic as plain text with the source line and a caret under the spot."""
    code = f"[{diagnostic.code}]" if diagnostic.code else ""
    lines = [f"{diagnostic.severity.value}{code}: {escape_controls(diagnostic.message)}"]
    location = diagnostic.location
    if location is not None:
        number = str(location.line)
        gutter = " " * len(number)
        lines.append(f"{gutter}--> {escape_controls(str(location))}")
        source = sources.line(location.file, location.line)
        if source is not None:
            # a tab is one column wide as the caret counts; other controls are escaped after the caret is placed
            source = source.replace("\t", " ")
            if location.end_line == location.line and location.end_column > location.column:
                width = location.end_column - location.column
            else:
                width = 1
            width = max(1, min(width, max(1, len(source) - location.column + 1)))
            source, offset, width = _window(source, location.column - 1, width)
            lines.append(f"{gutter} |")
            lines.append(f"{number} | {_shown_source(source)}")
            lines.append(f"{gutter} | {' ' * offset}{'^' * width}")
    if diagnostic.hint:
        gutter = " " * (len(str(location.line)) if location else 0)
        lines.append(f"{gutter} = hint: {escape_controls(diagnostic.hint)}")
    return "\n".join(lines)


def _shown_source(source: str) -> str:
    """A source line as printed: a control character shown as `?`, one column like the character it
    replaces, so that the caret below still points at the spot."""
    return "".join("?" if ord(character) in _ESCAPED_CONTROLS else character for character in source)
