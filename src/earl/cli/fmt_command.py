"""`earl fmt FILE…`: print, check or rewrite specifications in canonical form."""

from __future__ import annotations

import argparse
import difflib
import re
import sys
from typing import Any

from earl.cli.common import UsageError, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError
from earl.lang.loader import parse_file_as_read, parse_source, save
from earl.model.validate import ModelNameError


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "fmt",
        help="print a specification in canonical form",
        description="Print each FILE in canonical form: four-space indentation, one declaration per line, "
        "the parts of every subsystem in the manual's order, a blank line between two groups of them. Comments "
        "are kept, and so is one blank line where one or more were left between two members of a group.",
        epilog="exit codes: 0 done (or canonical with --check), 1 invalid, not canonical, or a file that could not "
        "be put in canonical form or rewritten (it is left as it was), 2 usage error, 130 interrupted (Ctrl-C)",
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
            # formatting needs the syntax only, so a library file works too
            system, data = parse_file_as_read(path)
        except EarlError as error:
            print_diagnostics(error.diagnostics, error.sources)
            status = 1
            continue
        # as the bytes are: `\r\n` or `\r` line ends are not canonical (universal newlines would hide them)
        original = data.decode("utf-8", errors="replace")
        try:
            canonical = system.to_earl()
        except ModelNameError:  # a name to_earl would not write; said where the file declares it
            sys.stderr.write(f"earl fmt: {_unwritable_name(system, str(path))}; the file is left as it is\n")
            status = 1
            continue
        problem = _reads_back_differently(system, canonical, str(path))
        if problem is not None:
            sys.stderr.write(
                f"earl fmt: {path}: cannot be put in canonical form: {problem}; the file is left as it is\n"
            )
            status = 1
            continue
        if arguments.check:
            if original != canonical:
                sys.stderr.write(f"{path}: not canonical (run `earl fmt --write {path}`)\n")
                status = 1
        elif arguments.write:
            if original != canonical:
                try:
                    save(system, path, warn_of_main=False)
                except OSError as error:  # a read-only directory, a full disk, a device: the file is as it was
                    sys.stderr.write(f"earl fmt: cannot rewrite {path}: {error.strerror or error}\n")
                    status = 1
                    continue
                sys.stderr.write(f"{path}: reformatted\n")
        elif arguments.diff:
            diff = difflib.unified_diff(
                _lines(original),
                _lines(canonical),
                str(path),
                f"{path} (canonical)",
            )
            for line in diff:
                # a last line without its newline is marked as `diff` and `patch` expect
                sys.stdout.write(line if line.endswith("\n") else line + "\n\\ No newline at end of file\n")
        else:
            sys.stdout.write(canonical)
    return status


def _unwritable_name(system: Any, path: str) -> str:
    """Where the name `to_earl` refused is declared and why, as one line."""
    from earl.lang.resolver import unreadable_names

    name, what, location, _ = unreadable_names(system)[0]
    return (
        f"{location or path}: cannot be put in canonical form: `{name}` ({what}) would not read back where "
        "canonical form writes it (a name that is also a keyword): rename it"
    )


def _reads_back_differently(system: Any, canonical: str, path: str) -> str | None:
    """Why the canonical text would not read back as the same specification, or None.

    Canonical order moves declarations, and a name that is also a keyword (`timeout/ib`,
    `state/pp`) can read differently in its new place: such a text is never written."""
    try:
        again = parse_source(canonical, path)
    except EarlError as error:
        first = error.diagnostics[0]
        line = f" at line {first.location.line}" if first.location is not None else ""
        return (
            f"its canonical text would not read back ({first.message}{line}); a name that is also a keyword "
            "(`timeout`, `state`, `period`, …) reads differently where canonical order puts it: rename it"
        )
    if again != system:
        return "its canonical text would read back as a different specification"
    return None


def _lines(text: str) -> list[str]:
    """The lines as `diff` and `patch` count them: ended by `\\n` only (a `\\r`, a form feed or U+2028
    inside a line is part of it; `str.splitlines` would end lines there)."""
    return re.findall(r"[^\n]*\n|[^\n]+$", text)
