"""Executable EARL semantics: subsystem engines (Figure 5), links, schedulers, traces.

The runtime is the only part of earl that imports user code.  See docs/semantics.md
for what one iteration does and docs/runtime.md for the contract with user code.
"""

from earl.runtime.events import Fault
from earl.runtime.simulation import Simulation, SubsystemState, simulate
from earl.runtime.values import Record

__all__ = ["Fault", "Record", "Simulation", "SubsystemState", "simulate"]
