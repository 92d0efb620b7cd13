"""Where `earl fmt` writes blank lines of its own: between the groups of a body.

The formatter prints each body group by group, with one blank line between two groups; the reader
keeps a blank line a person left inside a group (as a "" first in the next element's leading
comments), and only there, since between two groups `earl fmt` writes one anyway. Both read the
groups from here, so what the one writes the other reads back as it was.

A clause is named by its key in the owner's `clause_comments` (`period`, `initial`, `tf`, `tc`, `ec`).
"""

from __future__ import annotations

from earl.model.elements import FSM, Agent, BasicBehaviour, Link, Parameter, Subsystem
from earl.model.types import TypeAlias

#: the top-level declarations of one kind that `earl fmt` writes line after line, as a group
_ONE_LINERS = (Parameter, TypeAlias, Link)


def _present(groups: list[list[object]]) -> list[list[object]]:
    return [group for group in groups if group]


def subsystem_groups(subsystem: Subsystem) -> list[list[object]]:
    """The parts of a subsystem in the order of manual §2.2; each basic behaviour and the FSM alone."""
    alone: list[list[object]] = [[behaviour] for behaviour in subsystem.basic_behaviours]
    return _present(
        [
            [*(["period"] if subsystem.period is not None else []), *subsystem.parameters],
            [*subsystem.input_buffers, *subsystem.output_buffers],
            list(subsystem.memories),
            list(subsystem.primitive_predicates),
            list(subsystem.partial_transition_functions),
            list(subsystem.stage_sets),
            *alone,
            [subsystem.fsm] if subsystem.fsm is not None else [],
        ]
    )


def agent_groups(agent: Agent) -> list[list[object]]:
    """An agent's parameters, each of its subsystems alone, its links."""
    alone: list[list[object]] = [[subsystem] for subsystem in agent.subsystems]
    return _present([list(agent.parameters), *alone, list(agent.links)])


def fsm_groups(fsm: FSM) -> list[list[object]]:
    """The initial state with the states, the transitions, the assumptions."""
    return _present([["initial", *fsm.states], list(fsm.transitions), list(fsm.assumptions)])


def behaviour_groups(behaviour: BasicBehaviour) -> list[list[object]]:
    """A basic behaviour's clauses, one group."""
    return [["tf", "tc", *(["ec"] if behaviour.error_condition is not None else [])]]


def apart(previous: object | None, declaration: object) -> bool:
    """Whether `earl fmt` writes a blank line between two top-level declarations (imports aside): always,
    but between two parameters, two type aliases or two links, the second without comments above it."""
    return not (
        type(declaration) is type(previous)
        and isinstance(declaration, _ONE_LINERS)
        and not declaration.comments.leading  # type: ignore[attr-defined]
    )
