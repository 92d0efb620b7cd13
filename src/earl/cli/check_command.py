"""`earl check SPEC`: every way a specification breaks the manual, pointing at the line."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from rich.console import Console
from rich.status import Status
from rich.table import Table

from earl.check import CheckContext, check_context, collector_paused, context_for
from earl.check.report import as_json, as_sarif
from earl.cli.common import UsageError, parse_parameters, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import Diagnostic, EarlError, Severity
from earl.lang.loader import load
from earl.model.elements import System


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "check",
        help="check a specification against the rules of the EARL manual",
        description="Read SPEC (a .earl file, or a directory holding system.earl), resolve every name, apply "
        "every rule of the EARL manual (docs/rules.md) and analyse each FSM for overlapping, dead and missing "
        "transition conditions. Each problem is reported with its file, line and column. Reading a spec never "
        "runs code it names.",
        epilog="exit codes: 0 valid (warnings and notes allowed; see --strict), 1 errors found, 2 usage error,\n"
        "130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a system parameter, e.g. --param N=3 (repeatable)",
    )
    parser.add_argument(
        "--format",
        choices=["human", "json", "sarif"],
        default="human",
        help="human (default): grouped by file with the source line; json: a list of objects; sarif: SARIF 2.1.0",
    )
    parser.add_argument("--strict", action="store_true", help="fail (exit 1) on warnings too")
    parser.add_argument(
        "--verbose", "-v", action="store_true", help="also list every agent with its Table 1 type and subsystems"
    )
    parser.set_defaults(run=run)


def _print(diagnostics: list[Diagnostic], arguments: argparse.Namespace, sources: Any) -> None:
    if arguments.format == "json":
        print(as_json(diagnostics))
    elif arguments.format == "sarif":
        print(as_sarif(diagnostics))
    else:
        shown = diagnostics if arguments.verbose else [d for d in diagnostics if d.severity is not Severity.NOTE]
        print_diagnostics(shown, sources)


def _summary(system: System, context: CheckContext) -> None:
    table = Table(title=f"system {system.name}", title_justify="left")
    table.add_column("agent")
    table.add_column("type (Table 1)")
    table.add_column("subsystems")
    for agent in context.system.agents:
        row = context.agent_type(agent)
        counts: dict[str, int] = {}
        for subsystem in agent.subsystems:
            counts[subsystem.kind.value] = counts.get(subsystem.kind.value, 0) + 1
        name = agent.name if agent.index is None else f"{agent.name}[{agent.index}]"
        table.add_row(f"{name}/a", f"{row.name} — {row.description}", ", ".join(f"{n} {k}" for k, n in counts.items()))
    Console(highlight=False).print(table)


class _Phases:
    """Which phase of `earl check` runs, said by a spinner on a terminal (`status`), or nowhere (None)."""

    def __init__(self, status: Status | None) -> None:
        self._status = status

    def update(self, text: str) -> None:
        if self._status is not None:
            self._status.update(text, spinner="dots")  # a new spinner is drawn at once, not at the next tick

    def stop(self) -> None:
        if self._status is not None:
            self._status.stop()


@contextmanager
def _phases(console: Console) -> Iterator[_Phases]:
    """On a terminal, a spinner saying which phase runs: a spec of 100,000 subsystems takes seconds in
    each. Nowhere else: a pipe or a file gets only the findings."""
    if not console.is_terminal:
        yield _Phases(None)
        return
    with console.status("") as status:
        phases = _Phases(status)
        phases.update("reading the specification …")
        yield phases


def run(arguments: argparse.Namespace) -> int:
    try:
        path = spec_path(arguments.spec)
        parameters = parse_parameters(arguments.param)
    except UsageError as error:
        return usage_error(str(error))
    # Reading and checking a large spec allocates millions of objects that all stay alive until the
    # end: the collector's passes over them would cost more than the work (earl/collector.py).
    with collector_paused(), _phases(Console(stderr=True)) as phase:
        try:
            system = load(path, parameters)
        except EarlError as error:
            phase.stop()
            _print(error.diagnostics, arguments, error.sources)
            return 1
        phase.update("expanding the indexed families …")
        context = context_for(system, parameters)
        phase.update(f"applying the rules to {sum(len(a.subsystems) for a in context.system.agents):,} subsystems …")
        diagnostics = check_context(context)
    errors = sum(1 for d in diagnostics if d.severity is Severity.ERROR)
    warnings = sum(1 for d in diagnostics if d.severity is Severity.WARNING)
    _print(diagnostics, arguments, system.sources)
    failed = errors > 0 or (arguments.strict and warnings > 0)
    if arguments.format == "human":
        if arguments.verbose:
            _summary(system, context)
        if not failed:
            notes = len(diagnostics) - errors - warnings
            parts = [f"{warnings} warning{'s' if warnings != 1 else ''}"] if warnings else []
            if notes:
                parts.append(
                    f"{notes} note{'s' if notes != 1 else ''}{'' if arguments.verbose else ', shown with --verbose'}"
                )
            extra = f" ({'; '.join(parts)})" if parts else ""
            print(f"{path}: ok — system `{system.name}` follows the rules of the EARL manual{extra}")
    return 1 if failed else 0
