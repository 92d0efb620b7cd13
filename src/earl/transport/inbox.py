"""Messages received on Zenoh's threads, handed over to the scheduler's thread.

The engines, their channels and the recorders belong to the scheduler's thread alone;
Zenoh calls back on its own threads.  A callback therefore only appends (action,
value) to a deque, which is safe across threads, and sets an event that wakes the
scheduler if it sleeps until its next instant.  The scheduler drains the inbox before
each event and while it waits, so a remote message wakes a subsystem that waits for
an obligatory buffer as soon as it arrives (docs/distributed.md, "Scheduling").
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from typing import Any

#: called in the scheduler's thread with the run time (ns) and the item's value
Action = Callable[[int, Any], None]


class Inbox:
    """A thread-safe hand-over queue from Zenoh callbacks to the scheduler."""

    __slots__ = ("_items", "_signal")

    def __init__(self) -> None:
        self._items: deque[tuple[Action, Any]] = deque()
        # A bare lock as a binary semaphore, held while nothing is signalled: waking a sleeper is
        # one release and sleeping one acquire, both in C, where threading.Event runs a Condition
        # in Python (a waiter lock allocated per wait) on both sides of every message.
        self._signal = threading.Lock()
        self._signal.acquire()

    def put(self, action: Action, value: Any) -> None:
        """From any thread: run `action(time, value)` in the scheduler's thread at its next drain."""
        items = self._items
        idle = not items
        items.append((action, value))
        # only a consumer that found the inbox empty can be asleep: waking it once is enough
        if idle:
            try:  # noqa: SIM105 (a try costs nothing when nothing is raised; contextlib.suppress costs a call)
                self._signal.release()
            except RuntimeError:  # signalled already by another thread
                pass

    @property
    def pending(self) -> bool:
        return bool(self._items)

    def wait(self, seconds: float) -> None:
        """Sleep at most `seconds`, less if something arrives."""
        if not self._items:
            self._signal.acquire(timeout=seconds)  # taken: the signal is consumed; timed out: nothing came

    def drain(self, time: int) -> None:
        """In the scheduler's thread: run every action that arrived, in arrival order."""
        self._signal.acquire(blocking=False)  # a signal for what is drained now must not wake the next wait
        items = self._items
        while items:
            action, value = items.popleft()
            action(time, value)
