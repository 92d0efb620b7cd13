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


def print_diagnostics(diagnostics: Sequence[Diagnostic], sources: SourceMap, console: Console | None = None) -> None:
    console = console or error_console()
    for diagnostic in diagnostics:
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
