"""The `earl` command: thin, it parses arguments, calls the library and prints.

Exit codes (documented in docs/language.md, "Errors and exit codes"):
    0  the specification is valid (or the command succeeded)
    1  the specification is invalid (or, with `fmt --check`, not canonical)
    2  usage error: a missing file, an unknown option, a bad value
    130  interrupted (Ctrl-C), at any point: one line, never a traceback (earl/_program.py)
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import gc
import importlib
import sys
from collections.abc import Sequence

from earl import __version__, _program, collector

#: every command, in the order `earl --help` lists them, and the module that implements it
COMMANDS = {
    "check": "earl.cli.check_command",
    "diagram": "earl.cli.diagram_command",
    "doc": "earl.cli.doc_command",
    "export": "earl.cli.export_command",
    "fmt": "earl.cli.fmt_command",
    "launch": "earl.cli.launch_command",
    "rules": "earl.cli.rules_command",
    "run": "earl.cli.run_command",
    "trace": "earl.cli.trace_command",
}
#: commands a module above registers besides its own (`earl plot` is `earl trace plot`)
ALIASES = {"plot": "trace"}

EXIT_OK = 0
EXIT_INVALID = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

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

exit codes: 0 valid, 1 invalid specification, 2 usage error (missing file, bad option), 130 interrupted
(Ctrl-C); each command's --help says its own
docs: docs/language.md (the language), docs/rules.md (the checks), docs/semantics.md (how a run
behaves), docs/runtime.md (user code), docs/distributed.md, docs/diagrams.md, docs/sysml.md
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"earl: error: {message}\n(run `{self.prog} --help` for the options)\n")
        raise SystemExit(EXIT_USAGE)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command line, or with `only` just that command's (see `main`)."""
    parser = _Parser(
        prog="earl",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"earl {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, module in COMMANDS.items():
        if only is None or name == only:
            importlib.import_module(module).register(commands)
    return parser


def _command_named(argv: Sequence[str]) -> str | None:
    """The command `argv` names, when it is the first word that is not an option (`earl run …`)."""
    for word in argv:
        if not word.startswith("-"):
            word = ALIASES.get(word, word)
            return word if word in COMMANDS else None
        if word in ("-h", "--help", "--version"):
            return None
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """The command `argv` (default: the program's arguments) names, run; its exit code. Ctrl-C at any
    point is exit 130 with one line (a command that stops in order says its own)."""
    try:
        _program.take_over()
        code = _main(argv)
    except KeyboardInterrupt:  # while the command's modules are imported, its arguments parsed
        code = EXIT_INTERRUPTED
    except Exception as error:
        if not (caused_by_an_interrupt(error) or _program.stop_received()):
            raise
        code = EXIT_INTERRUPTED
    else:
        if not _program.stop_received() or code == EXIT_INTERRUPTED:
            return code
        # a stop signal came and some compiled code swallowed its KeyboardInterrupt: the command went on
    with contextlib.suppress(OSError):
        sys.stderr.write("earl: interrupted\n")
    return EXIT_INTERRUPTED


def caused_by_an_interrupt(error: BaseException) -> bool:
    """Whether a KeyboardInterrupt is what `error` wraps. CPython 3.11 turns one raised while a class is
    made (in a descriptor's `__set_name__`, as Lark's classes have while `lark` is imported) into a
    RuntimeError "Error calling __set_name__", with the KeyboardInterrupt as its cause: a Ctrl-C or a
    stopped `earl run` at that moment of the start is an interrupt all the same, not a traceback.
    Only causes count: an error raised while an interrupt was being handled (its context) is an error."""
    seen: set[int] = set()
    cause: BaseException | None = error
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__
    return False


def _main(argv: Sequence[str] | None) -> int:
    words = sys.argv[1:] if argv is None else list(argv)
    for stream in (sys.stdout, sys.stderr):
        # a file name of undecodable bytes (`spec\udcfe.earl`) is printed escaped, never a traceback
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            with contextlib.suppress(Exception):
                reconfigure(errors="backslashreplace")
    # Only the command being run is imported: the others pull in the renderer, the SysML
    # exporter and more, which would add half a second to every `earl run`.
    parser = build_parser(_command_named(words))
    arguments = parser.parse_args(words)
    if arguments.command is None:
        parser.print_help()
        return EXIT_USAGE
    try:
        result: int = arguments.run(arguments)
    except KeyboardInterrupt:
        with contextlib.suppress(OSError):
            sys.stderr.write("earl: interrupted\n")
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (`earl check … | head`): not an error of ours.
        _stdout_to_devnull()
        return EXIT_OK
    except OSError as error:
        if error.errno not in _OUTPUT_FULL:
            raise
        # the output cannot be written (`> /dev/full`, a full disk): one line, not a traceback
        _stdout_to_devnull()
        with contextlib.suppress(OSError):
            sys.stderr.write(f"earl: cannot write the output: {error.strerror}\n")
        return 1
    return result


#: errors of a write to an output that has no room left
_OUTPUT_FULL = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO})


def _stdout_to_devnull() -> None:
    """Whatever is still buffered for standard output goes nowhere, so that the exit does not fail again."""
    import os

    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


#: True in the `earl` program, a process that ends with its command (not when a test calls `main`)
AS_PROGRAM = False


def script() -> int:
    """The `earl` program: `main`, then an exit that does not scan the heap again.

    What a command builds while the collector is paused (the model read, expanded and
    checked) is frozen when the pause ends (`earl.collector`), so that no collection visits
    it again: about 8% of `earl check` on the 5 MB benchmark spec.
    Python's own exit collects garbage over every object still alive (the parsed model, NumPy,
    MuJoCo, Lark's tables: a tenth of a second after `earl run`). The garbage is collected
    here once, so that every finalizer runs as before, and what is still alive is frozen, so
    that the exit's own collections skip it; it is freed as the modules are torn down.
    Only the program does this: a caller of `main` (a test) keeps its collector as it was.
    """
    global AS_PROGRAM
    code = EXIT_INTERRUPTED
    try:
        AS_PROGRAM = True
        collector.FREEZE_ON_RESUME = True  # what a command builds lives until the process ends
        code = main()
        _end_lingering_threads(code)
        gc.collect()
        gc.freeze()
    except KeyboardInterrupt:  # as the command ends: it is done, or said why it stopped
        with contextlib.suppress(OSError):
            sys.stderr.write("earl: interrupted\n")
        code = EXIT_INTERRUPTED
    _program.hand_back(code)  # and while the interpreter ends
    return code


#: seconds threads left running by the spec's code get to end before the program ends without them
THREAD_GRACE = 2.0


def _end_lingering_threads(code: int) -> None:
    """A thread that the spec's code started and never ended (not a daemon) would keep the program
    from ever exiting once the command is done; it gets a moment, then the program ends without it."""
    import os
    import threading
    import time

    deadline = time.monotonic() + THREAD_GRACE
    lingering = [t for t in threading.enumerate() if t is not threading.main_thread() and not t.daemon]
    for thread in lingering:
        thread.join(max(0.0, deadline - time.monotonic()))
    alive = [t.name for t in lingering if t.is_alive()]
    if not alive:
        return
    with contextlib.suppress(OSError):
        sys.stderr.write(f"earl: threads still running at the end ({', '.join(alive)}) are stopped with the program\n")
    with contextlib.suppress(OSError):
        sys.stdout.flush()
    with contextlib.suppress(OSError):
        sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(script())
