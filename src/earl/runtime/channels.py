"""The receiving end of a Link: what an Input Buffer gets at its next `receive()` (§2.2).

By default a buffer keeps the latest message: several messages between two receives
leave only the last, and `newData()` is true once.  An Input Buffer declared with
`fifo N` keeps up to N messages and takes the oldest at each receive; what happens
when it is full is its overflow policy (`dropOldest`, `dropNewest`, `fault`).
"""

from __future__ import annotations

from collections import deque
from typing import Any


class Channel:
    """Messages that arrived for one Input Buffer and were not yet received."""

    __slots__ = ("capacity", "dropped", "overflow", "overflowed", "queue", "reported")

    def __init__(self, capacity: int | None = None, overflow: str = "dropOldest") -> None:
        self.capacity = capacity
        self.overflow = overflow
        self.queue: deque[Any] = deque()
        self.dropped = 0
        #: `dropped` when the receiver last reported an overflow: what was dropped since is the news
        self.reported = 0
        #: set when a `fault`-policy FIFO overflowed; the receiver reports it and clears it
        self.overflowed = False

    def deliver(self, value: Any) -> None:
        queue = self.queue
        if self.capacity is None:
            # latest value: a message not yet received is replaced by the newer one
            if queue:
                queue[0] = value
            else:
                queue.append(value)
            return
        if len(queue) < self.capacity:
            queue.append(value)
            return
        self.dropped += 1
        if self.overflow == "dropNewest":
            return
        if self.overflow == "fault":
            self.overflowed = True
        queue.popleft()
        queue.append(value)

    @property
    def pending(self) -> bool:
        return bool(self.queue)

    def take(self) -> Any:
        return self.queue.popleft()
