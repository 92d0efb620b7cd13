"""Ctrl-C while the `earl` program starts or ends: one line and exit 130, never a traceback.

The `earl` command (`earl …`, `python -m earl …`, `python -m earl.cli.main …`) imports this
package before any of its own code runs: reading `earl/__init__.py` and the model takes a tenth
of a second, during which Python's own handler would raise KeyboardInterrupt inside an import and
print its traceback. In the program (and only there: a library user's handlers are theirs) this
module's handler is in place from the package's first line until `earl.cli.main.main` takes over,
and again once the command is done, while the interpreter ends. Importing this module puts it in
place (`guard`): `earl/__init__.py` imports it first.
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


def guard() -> None:
    """`interrupted` for Ctrl-C, in the program only, and only where Ctrl-C would interrupt it: a SIGINT
    that the shell had the program ignore (`trap '' INT`, a job started with `&` by a non-interactive
    shell, `nohup`) stays ignored."""
    global PROGRAM
    PROGRAM = is_program() and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    if PROGRAM:
        with contextlib.suppress(ValueError, OSError):  # not the main thread: Python's handler stays
            signal.signal(signal.SIGINT, interrupted)


def take_over() -> None:
    """The command runs: Ctrl-C raises KeyboardInterrupt again, which the command handles."""
    with contextlib.suppress(ValueError, OSError):
        if signal.getsignal(signal.SIGINT) is interrupted:
            signal.signal(signal.SIGINT, signal.default_int_handler)


def hand_back(code: int) -> None:
    """The command is done with exit code `code`: what it printed is flushed, and in the program Ctrl-C
    while the interpreter ends is `interrupted` (Python would print a KeyboardInterrupt from its threads'
    shutdown)."""
    if code == EXIT_INTERRUPTED and PROGRAM:
        _forget_the_interrupt()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a reader gone, a full disk: said already, or not to be
            stream.flush()
    if PROGRAM:
        with contextlib.suppress(ValueError, OSError):
            signal.signal(signal.SIGINT, interrupted)


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
