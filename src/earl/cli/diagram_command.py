"""`earl diagram SPEC --view fsm --target manip/a.cs -o fsm.svg`: one of the manual's diagrams, drawn from the spec."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from earl.cli.common import (
    UsageError,
    named_path,
    parse_parameters,
    refuse_to_overwrite_inputs,
    spec_path,
    usage_error,
)
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError
from earl.lang.loader import load
from earl.render.build import MERMAID_VIEWS, VIEWS, Subject, diagram_of
from earl.render.graphviz import GraphvizError
from earl.render.mermaid import mermaid_of
from earl.render.targets import TargetError

FORMATS = ("svg", "png", "dot", "mermaid")
_SUFFIXES = {".svg": "svg", ".png": "png", ".dot": "dot", ".gv": "dot", ".mmd": "mermaid", ".mermaid": "mermaid"}

EPILOG = """\
views:
  system    agents as blocks and the inter-agent links with their data types (Figure 8)
  agent     one agent: subsystems, buffers as small squares, memory, links (Figure 10)
  fsm       one subsystem's FSM: states, behaviours, conditions, priorities (Figure 12)
  activity  one basic behaviour's transition function, stage by stage (Figure 15)
  types     data types and their fields (Figures 9 and 11)

examples:
  earl diagram examples/pick_and_place --view system -o system.svg
  earl diagram examples/pick_and_place --view agent --target manip/a -o manip.png
  earl diagram examples/pick_and_place --view fsm --target manip/a.cs --format mermaid
  earl diagram examples/pick_and_place --view activity --target manip/a.cs.jointMove/bb -o act.svg
  earl diagram examples/pick_and_place --view agent --target manip/a --expand --param N=3 -o manip3.svg

exit codes: 0 drawn, 1 the spec cannot be read, 2 usage error (bad target, an empty or unwritable -o, Graphviz missing),
130 interrupted (Ctrl-C)
"""


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "diagram",
        help="draw one of the manual's SysML diagrams of a specification (Graphviz or Mermaid)",
        description="Draw a SysML-style diagram of SPEC as the EARL manual draws it by hand: SVG or PNG through "
        "Graphviz's `dot`, the DOT text itself, or Mermaid text (system and fsm views). Indexed families are drawn "
        "once with their index (motorController[K]/ve, K ∈ 1..N) unless --expand is given; a --target naming one "
        "member (motorController[2]/ve) draws that member, one naming a family anywhere on its way "
        "(manip[2]/a.motorController[K]/ve) draws the declared family. Reading a spec never "
        "runs code it names.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument("--view", required=True, choices=VIEWS, help="which diagram to draw")
    parser.add_argument(
        "--target",
        metavar="ELEMENT",
        help="what to draw, in the manual's dot notation: an agent (manip/a) for agent and types, a subsystem "
        "(manip/a.cs) for fsm, a basic behaviour (manip/a.cs.jointMove/bb) for activity; a family by its name "
        "(motorController[K]/ve), one member by its number (motorController[2]/ve)",
    )
    parser.add_argument("-o", "--output", metavar="FILE", help="write here (.svg, .png, .dot, .mmd); default: stdout")
    parser.add_argument("--format", choices=FORMATS, help="output format; default: from the output's suffix, else svg")
    parser.add_argument("--expand", action="store_true", help="draw every member of each indexed family")
    parser.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="set a system parameter (repeatable)"
    )
    parser.set_defaults(run=run)


def output_format(arguments: argparse.Namespace) -> str:
    suffix = Path(arguments.output).suffix.lower() if arguments.output else ""
    implied = _SUFFIXES.get(suffix)
    if arguments.format is not None:
        if implied is not None and implied != arguments.format:
            raise UsageError(f"--format {arguments.format} does not match the output file `{arguments.output}`")
        return str(arguments.format)
    if arguments.output and implied is None:
        raise UsageError(f"cannot tell the format of `{arguments.output}`; name a .svg, .png, .dot or .mmd file")
    return implied or "svg"


def run(arguments: argparse.Namespace) -> int:
    try:
        path = spec_path(arguments.spec)
        parameters = parse_parameters(arguments.param)
        if arguments.output is not None:  # an empty -o is refused, not taken for standard output
            named_path(arguments.output, "-o", "system.svg")
        if arguments.target is not None and not arguments.target.strip():
            raise UsageError("--target names no element: name one, e.g. --target manip/a.cs")
        chosen = output_format(arguments)
        if chosen == "mermaid" and arguments.view not in MERMAID_VIEWS:
            raise UsageError(
                f"Mermaid text exists for the {' and '.join(MERMAID_VIEWS)} views, not for {arguments.view}"
            )
    except UsageError as error:
        return usage_error(str(error))
    try:
        system = load(path, parameters)
    except EarlError as error:
        print_diagnostics(error.diagnostics, error.sources)
        return 1
    subject = Subject(system, arguments.expand, parameters)
    try:
        if chosen == "mermaid":
            data = mermaid_of(subject, arguments.view, arguments.target).encode("utf-8")
        else:
            diagram = diagram_of(subject, arguments.view, arguments.target)
            data = diagram.dot.encode("utf-8") if chosen == "dot" else diagram.render(chosen)
    except (TargetError, GraphvizError) as error:
        return usage_error(str(error))
    if arguments.output:
        try:
            refuse_to_overwrite_inputs(Path(arguments.output), system.sources)
        except UsageError as error:
            return usage_error(str(error))
        try:
            Path(arguments.output).write_bytes(data)
        except OSError as error:
            return usage_error(f"cannot write {arguments.output}: {error.strerror}")
    else:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
    return 0
