"""The `earl` command: thin, it parses arguments, calls the library and prints.

Exit codes (documented in README and docs/cli.md):
    0  the specification is valid (or the command succeeded)
    1  the specification is invalid (or, with `fmt --check`, not canonical)
    2  usage error: a missing file, an unknown option, a bad value
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from earl import __version__
from earl.cli import (
    check_command,
    diagram_command,
    doc_command,
    export_command,
    fmt_command,
    launch_command,
    rules_command,
    run_command,
    trace_command,
)

EXIT_OK = 0
EXIT_INVALID = 1
EXIT_USAGE = 2

DESCRIPTION = """\
earl reads robot control systems written in EARL, the Embodied Agent-Based Robot
Control Systems Modelling Language (Warsaw University of Technology), as plain-text
`.earl` specifications: agents, subsystems, buffers, memory, predicates, behaviours
and finite state machines, named as the manual names them (`manip/a`, `jointMove/bb`).
"""

EPILOG = """\
examples:
  earl check examples/pick_and_place/system.earl      check a spec against the manual
  earl check examples/pick_and_place --param N=3      with a system parameter changed
  earl fmt examples/pick_and_place/system.earl        print it in canonical form
  earl fmt --check examples/**/*.earl                 fail (exit 1) if any is not canonical
  earl doc examples/pick_and_place -o site/           the manual's diagrams and tables as a document
  earl run examples/pick_and_place --trace run.mcap   run it against MuJoCo, record a trace
  earl trace summary run.mcap                         time in each state, transitions, faults

exit codes: 0 valid, 1 invalid specification, 2 usage error (missing file, bad option)
docs: docs/language.md (the language), docs/rules.md (the checks), docs/semantics.md (how a run
behaves), docs/runtime.md (user code), docs/distributed.md, docs/diagrams.md, docs/sysml.md
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"earl: error: {message}\n(run `{self.prog} --help` for the options)\n")
        raise SystemExit(EXIT_USAGE)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="earl",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"earl {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    check_command.register(commands)
    diagram_command.register(commands)
    doc_command.register(commands)
    export_command.register(commands)
    fmt_command.register(commands)
    launch_command.register(commands)
    rules_command.register(commands)
    run_command.register(commands)
    trace_command.register(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    arguments = parser.parse_args(argv)
    if arguments.command is None:
        parser.print_help()
        return EXIT_USAGE
    try:
        result: int = arguments.run(arguments)
    except KeyboardInterrupt:
        sys.stderr.write("earl: interrupted\n")
        return 130
    except BrokenPipeError:
        # The reader went away (`earl check … | head`): not an error of ours.
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_OK
    return result


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
