"""Printing diagnostics to a terminal: plain text when piped, coloured on a terminal (Rich)."""

from __future__ import annotations

import sys
from collections.abc import Sequence

from rich.console import Console
from rich.text import Text

from earl.diagnostics import Diagnostic, Severity, SourceMap, render

_STYLES = {Severity.ERROR: "bold red", Severity.WARNING: "bold yellow", Severity.NOTE: "bold cyan"}


def error_console() -> Console:
    return Console(file=sys.stderr, highlight=False, soft_wrap=True)


def _counts(diagnostics: Sequence[Diagnostic]) -> str:
    errors = sum(1 for d in diagnostics if d.severity is Severity.ERROR)
    warnings = sum(1 for d in diagnostics if d.severity is Severity.WARNING)
    notes = len(diagnostics) - errors - warnings
    parts = []
    for count, word in ((errors, "error"), (warnings, "warning"), (notes, "note")):
        if count:
            parts.append(f"{count} {word}{'s' if count != 1 else ''}")
    return ", ".join(parts)


def _by_file(diagnostics: Sequence[Diagnostic]) -> dict[str | None, list[Diagnostic]]:
    """Diagnostics grouped by file, files in the order they first appear, each group in its own order."""
    groups: dict[str | None, list[Diagnostic]] = {}
    for diagnostic in diagnostics:
        groups.setdefault(diagnostic.location.file if diagnostic.location else None, []).append(diagnostic)
    return groups


def print_diagnostics(diagnostics: Sequence[Diagnostic], sources: SourceMap, console: Console | None = None) -> None:
    """Each diagnostic with its source line and caret; when they come from more than one file (a spec
    and the files it imports), under one heading per file."""
    console = console or error_console()
    groups = _by_file(diagnostics)
    headed = len(groups) > 1
    for file, group in groups.items():
        if headed:
            console.print(Text(f"── {file or 'the specification as a whole'}: {_counts(group)}", style="bold"))
            console.print()
        for diagnostic in group:
            text = render(diagnostic, sources)
            head, _, rest = text.partition("\n")
            line = Text(head, style=_STYLES[diagnostic.severity])
            console.print(line)
            if rest:
                console.print(Text(rest))
            console.print()
    errors = sum(1 for d in diagnostics if d.severity is Severity.ERROR)
    warnings = sum(1 for d in diagnostics if d.severity is Severity.WARNING)
    if errors or warnings:
        parts = []
        if errors:
            parts.append(f"{errors} error{'s' if errors != 1 else ''}")
        if warnings:
            parts.append(f"{warnings} warning{'s' if warnings != 1 else ''}")
        console.print(Text(", ".join(parts), style="bold"))
