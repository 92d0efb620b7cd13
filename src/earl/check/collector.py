"""Pausing Python's cyclic garbage collector while a large model is built and checked.

Expanding a spec of ten thousand agents allocates millions of small objects and frees almost
none, which is the pattern that makes the collector's full passes (each visits every live
object) run again and again: measured on benchmarks/generate_families.py at 5,000 agents, they
were 60 % of the expansion time.  The model's objects form no reference cycles that need
collecting during a check, so the collector is paused for its duration and resumed (and left to
catch up on its own schedule) afterwards.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def collector_paused() -> Iterator[None]:
    """Within the block, no automatic cyclic collection; the previous setting is restored after."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
