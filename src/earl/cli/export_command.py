"""`earl export sysml SPEC -o FILE.sysml`: a specification as SysML v2 text, for SysML v2 tools."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from earl.check import check
from earl.cli.common import (
    UsageError,
    named_path,
    parse_parameters,
    refuse_to_overwrite_inputs,
    spec_path,
    usage_error,
)
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError, Severity, SourceMap
from earl.export.sysml import LIBRARY_FILE, export_sysml, library_text
from earl.lang.loader import load


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "export",
        help="write a specification in another modelling language (SysML v2)",
        description="Write SPEC as SysML v2 textual notation: agents and subsystems as parts, buffers as ports, "
        "links as flows, each FSM as a state machine, every indexed family expanded. The text imports EARL, the "
        f"library of the manual's concepts ({LIBRARY_FILE}); with -o it is written beside the output. The "
        "specification must pass `earl check` first. Exporting never runs code a spec names. See docs/sysml.md.",
        epilog="exit codes: 0 written, 1 invalid specification, 2 usage error (missing file, bad option, "
        "output not writable), 130 interrupted (Ctrl-C)",
    )
    parser.add_argument("language", choices=["sysml"], help="the language to write: sysml (SysML v2 text)")
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument("-o", "--output", metavar="FILE", help="write to FILE (default: standard output)")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a system parameter before families are expanded, e.g. --param N=3 (repeatable)",
    )
    parser.add_argument(
        "--no-library", action="store_true", help=f"with -o, do not write {LIBRARY_FILE} beside the output"
    )
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    try:
        path = spec_path(arguments.spec)
        parameters = parse_parameters(arguments.param)
        output = None if arguments.output is None else named_path(arguments.output, "-o", "model.sysml")
        if output is not None and not output.parent.is_dir():
            raise UsageError(f"cannot write {output}: no such directory {output.parent}")
        if output is not None and output.is_dir():
            raise UsageError(f"cannot write {output}: it is a directory; name the .sysml file")
    except UsageError as error:
        return usage_error(str(error))
    try:
        system = load(path, parameters)
    except EarlError as error:
        print_diagnostics(error.diagnostics, error.sources)
        return 1
    errors = [d for d in check(system, parameters) if d.severity is Severity.ERROR]
    if errors:
        sources = system.sources if isinstance(system.sources, SourceMap) else SourceMap()
        print_diagnostics(errors, sources)
        sys.stderr.write(f"{path}: not exported: the specification breaks the rules above (see `earl check`)\n")
        return 1
    text = export_sysml(system, parameters)
    if output is None:
        sys.stdout.write(text)
        return 0
    # compared without case too: on a file system that ignores it (macOS, Windows) `earl.sysml` is the library
    library_place = (output.parent / LIBRARY_FILE).resolve()
    if not arguments.no_library and (
        library_place == output.resolve() or str(library_place).lower() == str(output.resolve()).lower()
    ):
        return usage_error(
            f"-o {output} is where the library {LIBRARY_FILE} goes, beside the export: name the export otherwise "
            f"(e.g. -o {output.parent / (system.name + '.sysml')}), or leave the library out with --no-library"
        )
    try:
        refuse_to_overwrite_inputs(output, system.sources)
        if not arguments.no_library:
            refuse_to_overwrite_inputs(output.parent / LIBRARY_FILE, system.sources)
    except UsageError as error:
        return usage_error(str(error))
    written = []
    try:
        # the library first: a model that names `EARL::…` is of no use without it, so when it cannot be
        # written, neither is the model, and nothing is left half done
        if not arguments.no_library:
            library = output.parent / LIBRARY_FILE
            library.write_text(library_text(), encoding="utf-8")
            written.append(library)
        output.write_text(text, encoding="utf-8")
        written.insert(0, output)
    except OSError as error:
        done = f" ({' and '.join(str(p) for p in written)} written)" if written else ""
        return usage_error(f"cannot write {error.filename or output}: {error.strerror}{done}")
    sys.stderr.write(f"{path}: wrote {' and '.join(str(p) for p in written)}\n")
    return 0
