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
        where = f"{self.location}: " if self.location else ""
        return f"{where}{self.severity.value}: {self.message}"


class EarlError(Exception):
    """Raised when a specification cannot be read into a model; carries every diagnostic found."""

    def __init__(self, diagnostics: Sequence[Diagnostic], sources: SourceMap | None = None) -> None:
        self.diagnostics = list(diagnostics)
        self.sources = sources or SourceMap()
        first = self.diagnostics[0] if self.diagnostics else None
        super().__init__(str(first) if first else "invalid specification")


@dataclass
class SourceMap:
    """The text of every file read, so a diagnostic can quote the line it points at."""

    texts: dict[str, str] = field(default_factory=dict)

    def add(self, name: str, text: str) -> None:
        self.texts[name] = text

    def line(self, name: str, number: int) -> str | None:
        text = self.texts.get(name)
        if text is None:
            return None
        lines = text.splitlines()
        if 1 <= number <= len(lines):
            return lines[number - 1]
        return "" if number == len(lines) + 1 else None


def did_you_mean(name: str, candidates: Iterable[str]) -> str | None:
    """A hint naming the closest candidate, for misspelt names."""
    matches = difflib.get_close_matches(name, sorted(set(candidates)), n=1, cutoff=0.6)
    return f"did you mean `{matches[0]}`?" if matches else None


def render(diagnostic: Diagnostic, sources: SourceMap) -> str:
    """The diagnostic as plain text with the source line and a caret under the spot."""
    code = f"[{diagnostic.code}]" if diagnostic.code else ""
    lines = [f"{diagnostic.severity.value}{code}: {diagnostic.message}"]
    location = diagnostic.location
    if location is not None:
        number = str(location.line)
        gutter = " " * len(number)
        lines.append(f"{gutter}--> {location}")
        source = sources.line(location.file, location.line)
        if source is not None:
            source = source.replace("\t", " ")
            if location.end_line == location.line and location.end_column > location.column:
                width = location.end_column - location.column
            else:
                width = 1
            width = max(1, min(width, max(1, len(source) - location.column + 1)))
            lines.append(f"{gutter} |")
            lines.append(f"{number} | {source}")
            lines.append(f"{gutter} | {' ' * (location.column - 1)}{'^' * width}")
    if diagnostic.hint:
        gutter = " " * (len(str(location.line)) if location else 0)
        lines.append(f"{gutter} = hint: {diagnostic.hint}")
    return "\n".join(lines)
