"""Pausing Python's cyclic garbage collector while a large model is read, expanded and checked.

Reading a spec allocates hundreds of thousands of small objects and frees almost none;
expanding ten thousand agents allocates millions. That is the pattern that makes the
collector's passes (each visits every object still young, and its full passes every live
object) run again and again for cycles that are not there: a fifth of the time of reading a
large file, and 60 % of the expansion time of benchmarks/generate_families.py at 5,000 agents.
The model's objects form no reference cycles that need collecting meanwhile, so the collector
is paused for the duration, and resumed afterwards.

Resumed, it would still owe one pass over everything built while it was paused, and more as
those objects age through its generations: about a second after reading the 5 MB benchmark
spec. A program whose objects all live until it ends (the `earl` command, not a caller of the
Python API) sets `FREEZE_ON_RESUME`: what was built is then frozen (`gc.freeze`) before the
collector resumes, and no pass visits it again.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager

#: set by the `earl` program (earl/cli/main.py): freeze what a paused block built when it ends
FREEZE_ON_RESUME = False


@contextmanager
def paused() -> Iterator[None]:
    """Within the block, no automatic cyclic collection; the previous setting is restored after."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if FREEZE_ON_RESUME:
            gc.freeze()
        if enabled:
            gc.enable()


__all__ = ["FREEZE_ON_RESUME", "paused"]
