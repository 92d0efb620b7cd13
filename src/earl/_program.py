"""Ctrl-C while the `earl` program starts or ends: one line and exit 130, never a traceback.

The `earl` command (`earl …`, `python -m earl …`, `python -m earl.cli.main …`) imports this
package before any of its own code runs: reading `earl/__init__.py` and the model takes a tenth
of a second, during which Python's own handler would raise KeyboardInterrupt inside an import and
print its traceback. In the program (and only there: a library user's handlers are theirs) this
module's handler is in place from the package's first line until `earl.cli.main.main` takes over,
and again once the command is done, while the interpreter ends. Importing this module puts it in
place (`guard`): `earl/__init__.py` imports it first.

`earl run` and `earl launch` end as Ctrl-C does on SIGTERM and SIGHUP too (docs/semantics.md,
docs/distributed.md): for them the same holds of those two signals from the first line, not only once
the command has put its own handler in place, so that a `timeout` or a service manager that stops
one as it starts does not end it by the signal (143 in a shell).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys

#: what `python -m MODULE` runs as the `earl` program
PROGRAM_MODULES = frozenset({"earl", "earl.cli.main"})
#: names of the console script `earl` (pip writes `earl`; on Windows `earl.exe` runs `earl-script.py`)
SCRIPT_NAMES = frozenset({"earl", "earl.exe", "earl-script.py"})


def is_program() -> bool:
    """Whether this interpreter runs the `earl` command (rather than a program that uses the library).
    Asked as the package is first imported: `python -m` changes `sys.argv[0]` afterwards."""
    if not sys.argv:
        return False
    if sys.argv[0] == "-m":  # `python -m …`: runpy imports the package before it runs the module
        words = list(getattr(sys, "orig_argv", []))
        for position, word in enumerate(words[1:], start=1):
            if word == "-m":
                return position + 1 < len(words) and words[position + 1] in PROGRAM_MODULES
            if word.startswith("-m"):
                return word[2:] in PROGRAM_MODULES
        return False
    return os.path.basename(sys.argv[0]) in SCRIPT_NAMES


def interrupted(*_: object) -> None:
    """Ctrl-C with no command to stop in order: nothing was done yet, or all of it is."""
    with contextlib.suppress(OSError):
        os.write(2, b"earl: interrupted\n")
    os._exit(130)


#: whether this interpreter runs the `earl` command (`guard` decides it)
PROGRAM = False
#: the commands that a SIGTERM or SIGHUP ends as Ctrl-C does (the run's `STOP_SIGNALS`)
STOPPED_LIKE_CTRL_C = frozenset({"run", "launch"})
#: SIGTERM and SIGHUP (not on Windows), when the command is one of STOPPED_LIKE_CTRL_C and the program
#: was not started to ignore them (`nohup` ignores SIGHUP, `trap '' TERM` SIGTERM): `guard` decides it
OTHER_STOPS: tuple[int, ...] = ()


def command_named(words: list[str]) -> str | None:
    """The command the program's arguments name: the first word that is not an option (as
    `earl.cli.main` reads it); None for `earl --help` and the like."""
    for word in words:
        if word in ("-h", "--help", "--version"):
            return None
        if not word.startswith("-"):
            return word
    return None


def guard() -> None:
    """`interrupted` for Ctrl-C, in the program only, and only where Ctrl-C would interrupt it: a SIGINT
    that the shell had the program ignore (`trap '' INT`, a job started with `&` by a non-interactive
    shell, `nohup`) stays ignored. So too for SIGTERM and SIGHUP in `earl run` and `earl launch`."""
    global PROGRAM, OTHER_STOPS
    program = is_program()
    PROGRAM = program and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    if program and command_named(sys.argv[1:]) in STOPPED_LIKE_CTRL_C:
        numbers = (getattr(signal, name, None) for name in ("SIGTERM", "SIGHUP"))
        OTHER_STOPS = tuple(n for n in numbers if n is not None and signal.getsignal(n) == signal.SIG_DFL)
    with contextlib.suppress(ValueError, OSError):  # not the main thread: Python's handlers stay
        for number in _guarded():
            signal.signal(number, interrupted)


def _guarded() -> tuple[int, ...]:
    """The stop signals the program answers with `interrupted` while no command handles them."""
    return ((signal.SIGINT,) if PROGRAM else ()) + OTHER_STOPS


#: the stop signal that `raise_interrupt` turned into a KeyboardInterrupt, 0 while none came. Compiled code
#: that imports a module may swallow the interrupt or say it in other words (a Cython module's
#: initialisation clears it; pybind11's, as MuJoCo's, turns it into "ImportError: generic_type: …"), so the
#: command asks this rather than trusting that the KeyboardInterrupt reached it (`stop_received`).
STOP_RECEIVED = 0


def raise_interrupt(number: int, frame: object) -> None:
    """Python's own Ctrl-C handler, which also remembers that a stop signal came."""
    global STOP_RECEIVED
    STOP_RECEIVED = number
    raise KeyboardInterrupt


def stop_received() -> bool:
    """Whether a stop signal came while the command had not put its own handler in place: whatever failed
    meanwhile failed because of it (never true outside the `earl` program)."""
    return STOP_RECEIVED != 0


def take_over() -> None:
    """The command runs: Ctrl-C raises KeyboardInterrupt again, which the command handles; so does a SIGTERM
    or SIGHUP of `earl run` or `earl launch`, until the command puts its own handler in place."""
    with contextlib.suppress(ValueError, OSError):
        if signal.getsignal(signal.SIGINT) is interrupted:
            signal.signal(signal.SIGINT, raise_interrupt)
        for number in OTHER_STOPS:
            if signal.getsignal(number) is interrupted:
                signal.signal(number, raise_interrupt)


def hand_back(code: int) -> None:
    """The command is done with exit code `code`: what it printed is flushed, and in the program Ctrl-C
    while the interpreter ends is `interrupted` (Python would print a KeyboardInterrupt from its threads'
    shutdown)."""
    if code == EXIT_INTERRUPTED and PROGRAM:
        _forget_the_interrupt()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a reader gone, a full disk: said already, or not to be
            stream.flush()
    with contextlib.suppress(ValueError, OSError):
        for number in _guarded():
            signal.signal(number, interrupted)


#: the exit code of a command that Ctrl-C stopped
EXIT_INTERRUPTED = 130


def _forget_the_interrupt() -> None:
    """CPython remembers a KeyboardInterrupt that went up through C code running Python source (the
    initialisation of a Cython module such as `dd`'s, which `earl check` imports) even once it is caught,
    and `python -m earl` then ends by SIGINT itself instead of with exit code 130. Running one line of
    source down that path (`PyRun_SimpleString`) resets what it remembers."""
    if sys.implementation.name != "cpython":
        return
    with contextlib.suppress(Exception):
        import ctypes

        ctypes.pythonapi.PyRun_SimpleStringFlags(b"pass", None)


guard()
