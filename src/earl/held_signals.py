"""Stop signals held back while a compiled module initialises, and raised again once it is imported.

A Python signal handler runs at the next point where the interpreter looks for signals. While a
Cython module initialises (dd's CUDD bindings, which `earl check` and `earl run` import when they
first analyse an FSM), that point can be inside an import the module makes and whose failure it
clears without a word (`backports_abc`), or inside code whose exception it reports as "Exception
ignored … Cython module failed to patch module" and goes on: the KeyboardInterrupt of a Ctrl-C was
lost there, and the command went on to exit 0. Meanwhile a stop signal is only noted; once the
module is imported it is raised again, for whichever handler is in place then (the `earl` program's,
Python's KeyboardInterrupt, a library user's own).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

#: the signals that stop earl (docs/language.md, "Errors and exit codes"); SIGHUP is not on Windows
HELD = tuple(
    number for number in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", None)) if number is not None
)


@contextlib.contextmanager
def stop_signals_held() -> Iterator[None]:
    """Meanwhile a stop signal with a handler of Python code is noted, not handled; afterwards each one
    noted is raised again, in order, for the handler in place before. Handlers run in the main thread
    only: elsewhere nothing is held (a signal interrupts the main thread, not this import)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came: list[int] = []

    def note(number: int, _frame: FrameType | None) -> None:
        came.append(number)

    before = {}
    for number in HELD:
        handler = signal.getsignal(number)
        if callable(handler):  # SIG_DFL and SIG_IGN run no Python code, which is where a signal gets lost
            before[number] = handler
            signal.signal(number, note)
    try:
        yield
    finally:
        for number, handler in before.items():
            if signal.getsignal(number) is note:  # not one the held code put in place itself
                signal.signal(number, handler)
        for number in came:
            signal.raise_signal(number)  # its handler runs here (a KeyboardInterrupt is raised from here)
