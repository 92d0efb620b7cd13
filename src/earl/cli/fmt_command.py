"""`earl fmt FILE…`: print, check or rewrite specifications in canonical form."""

from __future__ import annotations

import argparse
import difflib
import sys
from typing import Any

from earl.cli.common import UsageError, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError
from earl.lang.loader import parse_file, save


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "fmt",
        help="print a specification in canonical form",
        description="Print each FILE in canonical form: four-space indentation, one declaration per line, "
        "the parts of every subsystem in the manual's order. Comments are kept.",
        epilog="exit codes: 0 done (or canonical with --check), 1 invalid, not canonical, or a file that could not "
        "be rewritten (it is left as it was), 2 usage error",
    )
    parser.add_argument("files", metavar="FILE", nargs="+", help=".earl files")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true", help="print nothing; exit 1 when a file is not canonical")
    mode.add_argument("--write", "-w", action="store_true", help="rewrite the files in place")
    mode.add_argument("--diff", action="store_true", help="show what would change, as a unified diff")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    try:
        paths = [spec_path(f) for f in arguments.files]
    except UsageError as error:
        return usage_error(str(error))
    status = 0
    for path in paths:
        try:
            system = parse_file(path)  # formatting needs the syntax only, so a library file works too
        except EarlError as error:
            print_diagnostics(error.diagnostics, error.sources)
            status = 1
            continue
        # as the bytes are: `\r\n` or `\r` line ends are not canonical (universal newlines would hide them)
        original = path.read_bytes().decode("utf-8", errors="replace")
        canonical = system.to_earl()
        if arguments.check:
            if original != canonical:
                sys.stderr.write(f"{path}: not canonical (run `earl fmt --write {path}`)\n")
                status = 1
        elif arguments.write:
            if original != canonical:
                try:
                    save(system, path)
                except OSError as error:  # a read-only directory, a full disk, a device: the file is as it was
                    sys.stderr.write(f"earl fmt: cannot rewrite {path}: {error.strerror or error}\n")
                    status = 1
                    continue
                sys.stderr.write(f"{path}: reformatted\n")
        elif arguments.diff:
            diff = difflib.unified_diff(
                original.splitlines(keepends=True),
                canonical.splitlines(keepends=True),
                str(path),
                f"{path} (canonical)",
            )
            sys.stdout.writelines(diff)
        else:
            sys.stdout.write(canonical)
    return status
