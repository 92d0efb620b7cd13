"""`earl doc SPEC -o site/`: the spec as a browsable document with the manual's diagrams and tables."""

from __future__ import annotations

import argparse
from typing import Any

from earl.check import check
from earl.cli.common import UsageError, named_path, parse_parameters, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError, Severity, SourceMap
from earl.lang.loader import load
from earl.render.build import Subject
from earl.render.document import write_site
from earl.render.graphviz import GraphvizError, dot_program

EPILOG = """\
writes (diagrams an earlier run wrote and this one did not draw are removed; other files stay,
and an index.html or index.md that earl doc did not write stops it):
  SITE/index.html       one static page: inline CSS, no script, works offline
  SITE/index.md         the same document in Markdown
  SITE/diagrams/*.svg   every diagram, referenced by both

examples:
  earl doc examples/pick_and_place -o site/
  earl doc examples/pick_and_place -o site-n3/ --param N=3 --expand

exit codes: 0 written, 1 the spec cannot be read or `earl check` found errors (the document is still
written and shows them), 2 usage error (missing file, Graphviz missing, output not writable), 130 interrupted (Ctrl-C)
"""


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "doc",
        help="write the spec as an HTML and Markdown document with the manual's diagrams and tables",
        description="Write SPEC as a document that reads like §3 of the EARL manual: the system with the Table 1 "
        "type of every agent, per agent its structure and data types, per subsystem Tables 3-6, its FSM and the "
        "activity of every basic behaviour, and the results of `earl check`, all cross-linked. Reading a spec "
        "never runs code it names.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument("-o", "--output", required=True, metavar="SITE", help="the directory to write")
    parser.add_argument("--expand", action="store_true", help="draw and tabulate every member of each family")
    parser.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="set a system parameter (repeatable)"
    )
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    try:
        path = spec_path(arguments.spec)
        parameters = parse_parameters(arguments.param)
        output = named_path(arguments.output, "-o", "site/", "directory")
        if output.exists() and not output.is_dir():
            raise UsageError(f"{arguments.output} exists and is not a directory")
        dot_program()  # before reading anything: without Graphviz there is no document to write
    except UsageError as error:
        return usage_error(str(error))
    except GraphvizError as error:
        return usage_error(str(error))
    try:
        system = load(path, parameters)
    except EarlError as error:
        print_diagnostics(error.diagnostics, error.sources)
        return 1
    diagnostics = check(system, parameters)
    try:
        result = write_site(Subject(system, arguments.expand, parameters), diagnostics, output)
    except GraphvizError as error:
        return usage_error(str(error))
    except OSError as error:
        return usage_error(f"cannot write {arguments.output}: {error.strerror or error}")
    errors = sum(1 for d in diagnostics if d.severity is Severity.ERROR)
    print(f"{result.html} ({len(result.diagrams)} diagrams in {result.html.parent / 'diagrams'}), {result.markdown}")
    if errors:
        print_diagnostics([d for d in diagnostics if d.severity is Severity.ERROR], _sources(system.sources))
        print(f"earl check found {errors} error{'s' if errors != 1 else ''}; the document shows them")
        return 1
    return 0


def _sources(sources: object) -> SourceMap:
    return sources if isinstance(sources, SourceMap) else SourceMap()
