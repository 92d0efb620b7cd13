"""What a subsystem names but does not declare, said before it runs (EARL-X015).

A spec read from a file, or any model run with the checker (`earl.simulate`'s default), never gets
here with such a name: the reader and `check` refuse it first. A model built or edited in Python and
run with `check=False` may: a state whose behaviour is not declared, a transition to no state, a
function that reads memory the subsystem lacks. Each would fail deep inside the run (a KeyError in the
middle of an instant) or, for an initial state that is no state, run nothing without a word; found
here, from the declarations alone, each is one located error instead.
"""

from __future__ import annotations

from collections.abc import Iterable

from earl.diagnostics import Diagnostic, Severity, did_you_mean
from earl.model.elements import Subsystem
from earl.model.expressions import ElementReference, Expression, Read, walk
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.runtime.names import indexed, reference_key

CODE = "EARL-X015"
HINT = (
    "declare it or name one that is: `earl.check.check(system)` says every such problem (the run was told check=False)"
)


def undeclared(subsystem: Subsystem, owner: str) -> list[Diagnostic]:
    """A diagnostic for each name `subsystem` (of the expanded system, named `owner` in messages) uses but
    does not declare."""
    found: list[Diagnostic] = []

    def missing(what: str, name: str, known: Iterable[str], location: SourceLocation | None) -> None:
        hint = did_you_mean(name, known) or HINT
        found.append(
            Diagnostic(
                Severity.ERROR,
                f"{owner} cannot run: {what} `{name}`, which it does not declare",
                location or subsystem.location,
                code=CODE,
                hint=hint,
            )
        )

    memory = {indexed(m.name, m.index) for m in subsystem.memories}
    inputs = {indexed(b.name, b.index) for b in subsystem.input_buffers}
    outputs = {indexed(b.name, b.index) for b in subsystem.output_buffers}
    predicates = {p.name for p in subsystem.primitive_predicates}
    functions = {f.name for f in subsystem.partial_transition_functions}
    behaviours = {b.name for b in subsystem.basic_behaviours}

    def accessed(reference: ElementReference, what: str, location: SourceLocation | None) -> None:
        key = reference_key(reference)
        if reference.kind == Kind.INPUT_BUFFER:
            declared, suffix = inputs, "ib"
        elif reference.kind == Kind.OUTPUT_BUFFER:
            declared, suffix = outputs, "ob"
        else:
            declared, suffix = memory, str(reference.kind)
        if key not in declared:
            missing(what, f"{key}/{suffix}", [f"{name}/{suffix}" for name in declared], location)

    def conditions(expression: Expression | None, what: str, location: SourceLocation | None) -> None:
        if expression is None:
            return
        for node in walk(expression):
            if isinstance(node, Read) and node.target.kind == Kind.PRIMITIVE_PREDICATE:
                key = reference_key(node.target)
                if key not in predicates:
                    missing(what, f"{key}/pp", [f"{name}/pp" for name in predicates], location)
            elif isinstance(node, Read) and node.target.kind in (Kind.INPUT_BUFFER, Kind.MEMORY_INPUT):
                accessed(node.target, what, location)

    for function in subsystem.partial_transition_functions:
        for reference in function.reads:
            accessed(reference, f"`{function.name}/pf` reads", function.location)
        for reference in function.writes:
            accessed(reference, f"`{function.name}/pf` writes", function.location)
    for predicate in subsystem.primitive_predicates:
        conditions(predicate.expression, f"`{predicate.name}/pp` reads", predicate.location)
    for behaviour in subsystem.basic_behaviours:
        for stage in behaviour.transition_function.stages:
            for reference in stage:
                if reference.name not in functions:
                    missing(
                        f"`{behaviour.name}/bb` calls",
                        f"{reference.name}/pf",
                        [f"{f}/pf" for f in functions],
                        behaviour.location,
                    )
        conditions(
            behaviour.terminal_condition.expression, f"the `tc` of `{behaviour.name}/bb` reads", behaviour.location
        )
        if behaviour.error_condition is not None:
            conditions(
                behaviour.error_condition.expression, f"the `ec` of `{behaviour.name}/bb` reads", behaviour.location
            )
    fsm = subsystem.fsm
    if fsm is None:
        return found  # EARL-X011, said by the builder
    states = {state.name for state in fsm.states}
    if fsm.initial not in states:
        missing("its FSM starts in the state", fsm.initial, states, fsm.initial_location or fsm.location)
    for state in fsm.states:
        if state.behaviour not in behaviours:
            missing(
                f"state `{state.name}` runs the behaviour",
                f"{state.behaviour}/bb",
                [f"{b}/bb" for b in behaviours],
                state.behaviour_location or state.location,
            )
        for reference in [*state.obligatory, *state.optional]:
            accessed(reference, f"state `{state.name}` waits for", state.location)
    for transition in fsm.transitions:
        for end in (transition.source, transition.destination):
            if end is not None and end not in states:
                missing("a transition of its FSM names the state", end, states, transition.location)
        conditions(transition.condition.expression, "a transition's condition reads", transition.location)
    return found
