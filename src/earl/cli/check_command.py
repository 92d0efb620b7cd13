"""`earl check SPEC`: read a specification and report every problem, pointing at the line."""

from __future__ import annotations

import argparse
import json
from typing import Any

from earl.cli.common import UsageError, parse_parameter, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import Diagnostic, EarlError
from earl.lang.loader import load


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "check",
        help="check a specification against the rules of the EARL manual",
        description="Read SPEC (a .earl file, or a directory holding system.earl), resolve every name and "
        "report each problem with its file, line and column. Reading a spec never runs code it names.",
        epilog="exit codes: 0 valid, 1 invalid specification, 2 usage error",
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
        "--format", choices=["human", "json"], default="human", help="how to print problems (default: human)"
    )
    parser.add_argument("--verbose", "-v", action="store_true", help="also summarise what the spec contains")
    parser.set_defaults(run=run)


def _json(diagnostics: list[Diagnostic]) -> str:
    return json.dumps(
        [
            {
                "code": d.code,
                "severity": d.severity.value,
                "message": d.message,
                "hint": d.hint,
                "file": d.location.file if d.location else None,
                "line": d.location.line if d.location else None,
                "column": d.location.column if d.location else None,
                "end_line": d.location.end_line if d.location else None,
                "end_column": d.location.end_column if d.location else None,
            }
            for d in diagnostics
        ],
        indent=2,
    )


def run(arguments: argparse.Namespace) -> int:
    try:
        path = spec_path(arguments.spec)
        parameters = dict(parse_parameter(p) for p in arguments.param)
    except UsageError as error:
        return usage_error(str(error))
    try:
        system = load(path, parameters)
    except EarlError as error:
        if arguments.format == "json":
            print(_json(error.diagnostics))
        else:
            print_diagnostics(error.diagnostics, error.sources)
        return 1
    if arguments.format == "json":
        print(_json([]))
        return 0
    agents = len(system.agents)
    subsystems = sum(len(a.subsystems) for a in system.agents)
    print(f"{path}: ok — system `{system.name}`, {agents} agent(s), {subsystems} subsystem declaration(s)")
    if arguments.verbose:
        for agent in system.agents:
            kinds = ", ".join(("cs" if s.kind.value == "cs" else f"{s.name}/{s.kind.value}") for s in agent.subsystems)
            print(f"  {agent.name}/a: {kinds}")
    return 0
