"""Reading a trace back from Python: what `earl trace summary` and `earl plot` read, as values.

    >>> trace = earl.read_trace("counter.mcap")          # or the io.BytesIO a run wrote to
    >>> trace.summary().subsystems["counter/a.cs"].final_state
    'finished'
    >>> [series] = trace.signals(["counter/a.cs.count"]).series
    >>> series.times[:2], series.values[:2]

A trace in memory (`earl.simulate(…, trace=io.BytesIO())`) is read from a temporary copy on disk, since
the reader works on files; the copy is removed when the Trace is closed or collected, and messages name
the stream, never the copy.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
import weakref
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, TypeVar

from earl.runtime.signal_syntax import signal_text_problem
from earl.runtime.trace_reader import Signals, TraceError, TraceSummary, read_signals, summarise

_Result = TypeVar("_Result")


class Trace:
    """An earl trace (MCAP), from a path or a binary file object; `TraceError` says why one cannot be read."""

    def __init__(self, source: str | os.PathLike[str] | IO[bytes]) -> None:
        if isinstance(source, (str, os.PathLike)):
            if isinstance(source, str) and not source.strip():
                raise ValueError("read_trace takes the trace's file name, not an empty string")
            self.path = Path(source)
            self.name = str(source)
            # said at once, as `open` says it, rather than at the first read (the CLI's usage errors)
            if self.path.is_dir():
                raise IsADirectoryError(
                    errno.EISDIR,
                    "a directory, not a trace: name the .mcap file (trace= of a run writes one)",
                    self.name,
                )
            if not self.path.exists():
                raise FileNotFoundError(errno.ENOENT, "no such trace file", self.name)
            return
        read = getattr(source, "read", None)
        if not callable(read):
            raise TypeError(
                f"read_trace takes a file name or a binary file object (io.BytesIO), not {type(source).__name__}"
            )
        data = _contents(source)
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError("read_trace reads a binary file object (open(…, 'rb'), io.BytesIO), not a text one")
        self.name = str(getattr(source, "name", "") or "the trace stream")
        descriptor, copy = tempfile.mkstemp(prefix=".earl-trace-", suffix=".mcap")
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
        self.path = Path(copy)
        self._remove = weakref.finalize(self, _remove_quietly, copy)

    def summary(self) -> TraceSummary:
        """What `earl trace summary` shows: end time (ns), each subsystem's time in each state, transitions,
        iterations and faults, the faults, the number of link messages and the run's settings."""
        return self._reading(lambda: summarise(self.path))

    def signals(self, names: list[str]) -> Signals:
        """The signals `earl plot --signal` draws (`counter/a.cs.count`, `manip/a.cs.cmd.pos[0]`, `x[*]/…` for
        every member): each `Series` has its `times` (s) and `values`; `bands` holds each subsystem's states."""
        if isinstance(names, str):
            raise TypeError(f"signals takes a list of signal names, e.g. [{names!r:.60}], not a single string")
        names = list(names)
        if not names:
            raise ValueError("signals takes at least one signal name, e.g. ['counter/a.cs.count']")
        for name in names:
            if not isinstance(name, str):
                raise TypeError(f"a signal is named by a str, not {type(name).__name__} {name!r:.60}")
            problem = signal_text_problem(name)
            if problem is not None:
                raise ValueError(problem)
        return self._reading(lambda: read_signals(self.path, names))

    def close(self) -> None:
        """Remove the copy of a trace read from a stream (a trace read from a path has none)."""
        remove = getattr(self, "_remove", None)
        if remove is not None:
            remove()

    def __enter__(self) -> Trace:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Trace({self.name!r})"

    def _reading(self, read: Callable[[], _Result]) -> _Result:
        if not hasattr(self, "_remove"):
            return read()
        try:
            return read()
        except TraceError as error:  # said of the stream, not of the temporary copy
            raise TraceError(str(error).replace(str(self.path), self.name)) from None


def _contents(source: Any) -> Any:
    """All of a file object's bytes: a BytesIO's whole value whatever its position (a run leaves it at its
    end), else read from its start when it can seek there."""
    value = getattr(source, "getvalue", None)
    if callable(value):
        return value()
    seek = getattr(source, "seek", None)
    if callable(seek) and getattr(source, "seekable", lambda: False)():
        seek(0)
    return source.read()


def _remove_quietly(path: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)


def read_trace(source: str | os.PathLike[str] | IO[bytes]) -> Trace:
    """The trace at `source`, a path or a binary file object (the `io.BytesIO` a run wrote to)."""
    return Trace(source)
