"""The parameters a subsystem's functions see as `context.parameters`: the system's, its agent's
(with the agent family's index), its own (with its family's index), later ones winning.

One function, so that what an environment resolves before the run (`MujocoPlant.bind` formats
`motor{K}` with them) is what the subsystem's functions are given during it."""

from __future__ import annotations

from typing import Any

from earl.model.elements import Agent, Subsystem, System
from earl.model.expressions import Literal


def parameter_value(expression: Any) -> Any:
    return expression.value if isinstance(expression, Literal) else expression


def agent_parameters(system: System, agent: Agent) -> dict[str, Any]:
    """The parameters every subsystem of `agent` (of the expanded `system`) sees."""
    parameters = {p.name: parameter_value(p.value) for p in system.parameters}
    if agent.family is not None and agent.index is not None:
        parameters[agent.family.index] = agent.index
    parameters.update({p.name: parameter_value(p.value) for p in agent.parameters})
    return parameters


def subsystem_parameters(inherited: dict[str, Any], subsystem: Subsystem) -> dict[str, Any]:
    """`context.parameters` of `subsystem`: its agent's (`inherited`), its family's index, its own."""
    parameters = dict(inherited)
    if subsystem.family is not None and subsystem.index is not None:
        parameters[subsystem.family.index] = subsystem.index
    parameters.update({p.name: parameter_value(p.value) for p in subsystem.parameters})
    return parameters
