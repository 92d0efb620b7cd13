"""How the runtime names concrete elements: `manip/a.motorController[3]/ve`, `windingCurrent[3]`.

The same text names a subsystem in the CLI (`--record-memory manip/a.cs`), in the
Python API (`sim.state_of("manip/a.cs")`) and in trace topics.
"""

from __future__ import annotations

from earl.model.elements import Agent
from earl.model.expressions import ElementReference, Literal
from earl.model.text import instance_name as indexed  # `windingCurrent[3]`: spelled as the checker spells it

__all__ = ["agent_name", "indexed", "reference_index", "reference_key"]


def agent_name(agent: Agent) -> str:
    return f"{indexed(agent.name, agent.index)}/a"


def reference_key(reference: ElementReference) -> str:
    """`windingCurrent[3]/mo` → `windingCurrent[3]`: buffers and memory are keyed without their kind."""
    if not reference.indices:
        return reference.name
    index = reference.indices[0]
    if not isinstance(index, Literal) or not isinstance(index.value, int):
        raise ValueError(f"`{reference.name}` is not a concrete member (expand the system first)")
    return indexed(reference.name, index.value)


def reference_index(reference: ElementReference) -> int | None:
    if not reference.indices:
        return None
    index = reference.indices[0]
    return index.value if isinstance(index, Literal) and isinstance(index.value, int) else None
