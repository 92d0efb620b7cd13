"""Messages received on Zenoh's threads, handed to the scheduler (docs/distributed.md, "Scheduling").

The engines, their channels and the recorders belong to whichever thread holds the
inbox's `owner` lock: the scheduler's own thread holds it whenever it is not asleep.
A Zenoh callback that finds the owner free (the scheduler sleeps until its next
instant) takes it and has the scheduler serve the message at once on Zenoh's thread:
deliver it and run whatever is due now, such as the subsystem that was waiting for it.
That saves the switch to the scheduler's thread, the largest part of a remote link's
latency after Zenoh's own.  A callback that finds the owner busy appends (action,
value) to a deque, safe across threads, and signals the scheduler, which drains the
inbox before each event and while it waits.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from typing import Any

#: called with the run time (ns) and the item's value, by the thread that holds the owner lock
Action = Callable[[int, Any], None]
#: the scheduler's way of running an action at once, called with the owner lock held
Serve = Callable[[Action, Any], None]


class Inbox:
    """A thread-safe hand-over from Zenoh callbacks to the scheduler."""

    __slots__ = ("_items", "_serve", "_signal", "owner")

    def __init__(self) -> None:
        self._items: deque[tuple[Action, Any]] = deque()
        # A bare lock as a binary semaphore, held while nothing is signalled: waking a sleeper is
        # one release and sleeping one acquire, both in C, where threading.Event runs a Condition
        # in Python (a waiter lock allocated per wait) on both sides of every message.
        self._signal = threading.Lock()
        self._signal.acquire()
        #: held by the thread that runs the scheduler's work; released by the scheduler while it sleeps
        self.owner = threading.Lock()
        self._serve: Serve | None = None

    def serve_with(self, serve: Serve | None) -> None:
        """Let callbacks that find the owner free run `serve(action, value)`; None: hand over only.

        Going back to None waits (a few seconds at most) for a callback that is serving to end,
        so that nothing runs the scheduler's work after its owner closed the run."""
        self._serve = serve
        if serve is None and self.owner.acquire(timeout=5.0):
            self.owner.release()

    def put(self, action: Action, value: Any) -> None:
        """From any thread: run `action(time, value)` now if the scheduler sleeps, else at its next drain."""
        if self._serve is not None and self.owner.acquire(blocking=False):
            try:
                serve = self._serve  # read again under the lock: the run may have ended meanwhile
                if serve is not None:
                    serve(action, value)
                    return
            finally:
                self.owner.release()
        items = self._items
        idle = not items
        items.append((action, value))
        # only a consumer that found the inbox empty can be asleep: waking it once is enough
        if idle:
            self.wake()

    def wake(self) -> None:
        """End the scheduler's current wait (it then looks at its event queue again)."""
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
        """With the owner lock held: run every action that arrived, in arrival order."""
        self._signal.acquire(blocking=False)  # a signal for what is drained now must not wake the next wait
        items = self._items
        while items:
            action, value = items.popleft()
            action(time, value)
