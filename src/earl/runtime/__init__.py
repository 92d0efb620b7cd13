"""Executable EARL semantics: subsystem engines (Figure 5), links, schedulers, traces.

The runtime is the only part of earl that imports user code.  See docs/semantics.md
for what one iteration does and docs/runtime.md for the contract with user code.

The names below are imported when first used: the trace's own process
(`trace_process.py`) imports `earl.runtime.trace` without the engine, the
scheduler and the builder.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from earl.runtime.events import Fault
    from earl.runtime.scheduler import ZeroTimeLoop
    from earl.runtime.simulation import RecordingWarning, Simulation, SubsystemState, UnknownSubsystem, simulate
    from earl.runtime.values import Record, plain

__all__ = [
    "Fault",
    "Record",
    "RecordingWarning",
    "Simulation",
    "SubsystemState",
    "UnknownSubsystem",
    "ZeroTimeLoop",
    "plain",
    "simulate",
]

_HOMES = {
    "Fault": "earl.runtime.events",
    "Record": "earl.runtime.values",
    "RecordingWarning": "earl.runtime.simulation",
    "Simulation": "earl.runtime.simulation",
    "UnknownSubsystem": "earl.runtime.simulation",
    "SubsystemState": "earl.runtime.simulation",
    "simulate": "earl.runtime.simulation",
    "ZeroTimeLoop": "earl.runtime.scheduler",
    "plain": "earl.runtime.values",
}


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'earl.runtime' has no attribute {name!r}")
    return getattr(importlib.import_module(home), name)
