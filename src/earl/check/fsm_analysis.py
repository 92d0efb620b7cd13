"""FSM analysis: overlapping, dead and missing transition conditions, decided with binary decision diagrams.

Each primitive predicate is a free Boolean variable (a predicate defined by a
constant, like the manual's `false/pp`, is that constant); any other Boolean
sub-formula that is not built from `and`, `or`, `not` (a comparison, a call of
`newData`) is a variable of its own.  The `assume` formulas of the FSM constrain
the variables.  With these, for every state of every FSM:

- two leaving transitions whose conditions can hold together, without distinct
  priorities, make the FSM nondeterministic (error, with one assignment);
- a behaviour that can stop (`tc or ec`) while no leaving transition holds is stuck
  (warning, with one assignment);
- a condition that can never hold is a dead transition (warning);
- a behaviour whose `tc` and `ec` can never hold never ends (note: fine for a sink state).

The BDDs come from `dd` (a maintained BDD package; its pure-Python backend needs no
compiler), not from a hand-made solver.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any

from earl.check.context import CheckContext, subsystem_name
from earl.check.registry import Finding, rule
from earl.diagnostics import Severity
from earl.model.elements import FSM, Subsystem, Transition
from earl.model.expressions import BooleanOperation, Expression, Literal, Not, Read, evaluate_constant, walk
from earl.model.kinds import Kind
from earl.model.text import expression_text


def _import_dd_without_networkx() -> ModuleType:
    """`dd.autoref`, imported while `import networkx` fails.

    dd imports networkx only to draw BDDs as graphs, which earl never does, and falls back
    quietly when it is missing; importing it takes a quarter of a second of every `earl check`
    and `earl run`. Only dd's own import sees it missing: the entry is removed again, so user
    code that imports networkx later gets it as usual.
    """
    absent = "networkx" not in sys.modules
    if absent:
        sys.modules["networkx"] = None  # type: ignore[assignment]  # makes `import networkx` raise ImportError
    try:
        return importlib.import_module("dd.autoref")
    finally:
        if absent and "networkx" in sys.modules and sys.modules["networkx"] is None:
            del sys.modules["networkx"]


if TYPE_CHECKING:
    from dd.autoref import BDD, Function
else:
    _autoref = _import_dd_without_networkx()
    BDD, Function = _autoref.BDD, _autoref.Function


@dataclass(frozen=True)
class Analysis:
    """The findings of one FSM, keyed by rule code."""

    findings: dict[str, list[Finding]]


class _Encoder:
    def __init__(self, subsystem: Subsystem) -> None:
        self.bdd = BDD()
        self.subsystem = subsystem
        self.names: dict[str, str] = {}  # BDD variable → the text a person reads
        self.by_text: dict[str, str] = {}
        self.constants: dict[str, bool] = {}
        for predicate in subsystem.primitive_predicates:
            if not any(isinstance(node, Read) for node in walk(predicate.expression)):
                try:
                    value = evaluate_constant(predicate.expression, {})
                except ValueError:
                    continue
                if isinstance(value, bool):
                    self.constants[predicate.name] = value

    def variable(self, text: str) -> Function:
        name = self.by_text.get(text)
        if name is None:
            name = self.by_text[text] = f"v{len(self.by_text)}"
            self.names[name] = text
            self.bdd.declare(name)
        return self.bdd.var(name)

    def encode(self, expression: Expression) -> Function:
        if isinstance(expression, Literal) and isinstance(expression.value, bool):
            return self.bdd.true if expression.value else self.bdd.false
        if isinstance(expression, Not):
            return ~self.encode(expression.operand)
        if isinstance(expression, BooleanOperation):
            operands = [self.encode(o) for o in expression.operands]
            result = operands[0]
            for operand in operands[1:]:
                result = (result & operand) if expression.operator == "and" else (result | operand)
            return result
        if isinstance(expression, Read) and expression.target.kind is Kind.PRIMITIVE_PREDICATE and not expression.path:
            constant = self.constants.get(expression.target.name)
            if constant is not None:
                return self.bdd.true if constant else self.bdd.false
        return self.variable(expression_text(expression))

    def example(self, formula: Function) -> str:
        assignment: dict[str, Any] = self.bdd.pick(formula) or {}
        if not assignment:
            return "always"
        parts = [
            f"{self.names[name]} = {'true' if value else 'false'}"
            for name, value in sorted(assignment.items(), key=lambda item: self.names[item[0]])
        ]
        return ", ".join(parts)


def _distinct_priorities(first: Transition, second: Transition) -> bool:
    if first.priority is None and second.priority is None:
        return False
    return first.priority != second.priority


def analyse(subsystem: Subsystem, fsm: FSM, owner: str) -> Analysis:
    encoder = _Encoder(subsystem)
    bdd = encoder.bdd
    findings: dict[str, list[Finding]] = {
        code: [] for code in ("EARL-E060", "EARL-W061", "EARL-W062", "EARL-I063", "EARL-W021", "EARL-W020")
    }
    assumed = bdd.true
    for assumption in fsm.assumptions:
        assumed &= encoder.encode(assumption.expression)
    conditions = {id(t): encoder.encode(t.condition.expression) for t in fsm.transitions}
    ending: dict[str, bool] = {}
    for state in fsm.states:
        behaviour = subsystem.basic_behaviour(state.behaviour)
        if behaviour is None:
            continue
        stop = encoder.encode(behaviour.terminal_condition.expression)
        if behaviour.error_condition is not None:
            stop |= encoder.encode(behaviour.error_condition.expression)
        can_stop = (stop & assumed) != bdd.false
        ending[state.name] = can_stop
        leaving = [t for t in fsm.transitions if t.source == state.name]
        if not can_stop:
            findings["EARL-I063"].append(
                Finding(
                    f"`{behaviour.name}/bb` never ends: its terminal and error conditions can never hold, so state `{state.name}` of {owner} is never left",
                    behaviour.location,
                    "fine for a deliberate sink state such as an emergency stop",
                )
            )
            continue
        if not leaving:
            findings["EARL-W021"].append(
                Finding(
                    f"state `{state.name}` of {owner} has no way out: `{behaviour.name}/bb` can stop, but no transition leaves it",
                    state.location,
                    f"add a transition `{state.name} -> …`, or make its terminal condition `false/pp` if it is a sink state",
                )
            )
            continue
        for transition in leaving:
            if (conditions[id(transition)] & assumed) == bdd.false:
                findings["EARL-W062"].append(
                    Finding(
                        f"transition `{transition.name}/t` of {owner} can never be taken: its condition never holds",
                        transition.location,
                        "check the condition and the `assume` formulas",
                    )
                )
        for position, first in enumerate(leaving):
            for second in leaving[position + 1 :]:
                if _distinct_priorities(first, second):
                    continue
                both = conditions[id(first)] & conditions[id(second)] & assumed
                if both != bdd.false:
                    findings["EARL-E060"].append(
                        Finding(
                            f"transitions `{first.name}/t` and `{second.name}/t` of {owner} can both hold, e.g. when {encoder.example(both)}",
                            second.location,
                            "give them distinct priorities (`priority 1` is evaluated first) or declare an `assume` that rules this out",
                        )
                    )
        none_holds = bdd.true
        for transition in leaving:
            none_holds &= ~conditions[id(transition)]
        stuck = stop & none_holds & assumed
        if stuck != bdd.false:
            findings["EARL-W061"].append(
                Finding(
                    f"`{behaviour.name}/bb` can stop while no transition out of `{state.name}` holds ({owner}), e.g. when {encoder.example(stuck)}",
                    state.location,
                    "add a transition for this case, or narrow the terminal condition",
                )
            )
    # Reachability through transitions that can be taken from behaviours that can end.
    reachable = {fsm.initial}
    frontier = [fsm.initial]
    while frontier:
        source = frontier.pop()
        if not ending.get(source, False):
            continue
        for transition in fsm.transitions:
            possible = transition.source == source and (conditions[id(transition)] & assumed) != bdd.false
            if possible and transition.destination not in reachable:
                reachable.add(transition.destination)
                frontier.append(transition.destination)
    for state in fsm.states:
        if state.name not in reachable:
            findings["EARL-W020"].append(
                Finding(
                    f"state `{state.name}` of {owner} is unreachable from the initial state `{fsm.initial}`",
                    state.location,
                    f"add a transition into `{state.name}`, or remove the state",
                )
            )
    return Analysis(findings)


def _fsm_key(subsystem: Subsystem) -> tuple[object, ...]:
    """Family members usually have identical FSMs: analyse each distinct one once."""
    fsm = subsystem.fsm
    assert fsm is not None
    parts: list[object] = [id(subsystem.location), fsm.initial]
    parts += [(p.name, expression_text(p.expression)) for p in subsystem.primitive_predicates]
    parts += [(s.name, s.behaviour) for s in fsm.states]
    parts += [(t.source, t.destination, t.priority, expression_text(t.condition.expression)) for t in fsm.transitions]
    parts += [expression_text(a.expression) for a in fsm.assumptions]
    for behaviour in subsystem.basic_behaviours:
        parts.append(expression_text(behaviour.terminal_condition.expression))
        parts.append(
            None if behaviour.error_condition is None else expression_text(behaviour.error_condition.expression)
        )
    return tuple(parts)


def analyses(context: CheckContext) -> dict[str, list[Finding]]:
    """Every FSM of the system analysed once; cached on the context for the rules below."""
    cached = getattr(context, "_fsm_analyses", None)
    if cached is not None:
        return cached  # type: ignore[no-any-return]
    result: dict[str, list[Finding]] = {}
    seen: set[tuple[object, ...]] = set()
    for agent, subsystem in context.distinct_subsystems():
        if subsystem.fsm is None:
            continue
        key = _fsm_key(subsystem)
        if key in seen:
            continue
        seen.add(key)
        owner = subsystem_name(agent, subsystem)
        if subsystem.family is not None or agent.family is not None:
            owner = f"{owner} (and the other members of its family)"
        for code, found in analyse(subsystem, subsystem.fsm, owner).findings.items():
            result.setdefault(code, []).extend(found)
    context._fsm_analyses = result  # type: ignore[attr-defined]
    return result


def _from_analysis(code: str) -> Any:
    def check(context: CheckContext) -> Iterator[Finding]:
        seen: set[object] = set()
        for finding in analyses(context).get(code, []):
            key = (finding.location, finding.message.split(" of ")[0])
            if key not in seen:
                seen.add(key)
                yield finding

    return check


def _register(code: str, severity: Severity, title: str, reference: str, doc: str) -> None:
    function = _from_analysis(code)
    function.__doc__ = doc
    # SARIF names a rule by an identifier, as the other rules' function names are.
    function.__name__ = "_".join(title.split())
    rule(code, severity, title, reference)(function)


_register(
    "EARL-E060",
    Severity.ERROR,
    "transitions leaving a state do not overlap",
    "§2.2, Figure 5a, Table 5",
    "`fsm.selectState()` must pick one next state. Two transitions leaving one state whose initial conditions "
    "can hold at once (under the FSM's `assume` formulas) need distinct priorities, or an assumption that "
    "excludes the overlap. The manual's own Table 5 overlaps: `jointMove,jointMove/t` and `jointMove,idle/t` "
    "both hold when a new joint position arrives without an emergency stop.",
)
_register(
    "EARL-W061",
    Severity.WARNING,
    "a behaviour never stops without a way out",
    "§2.2, Figure 5",
    "When a behaviour's terminal or error condition holds, the FSM selects a leaving transition; if none "
    "holds the subsystem is stuck (FABRIC fails; earl records a fault, docs/semantics.md).",
)
_register(
    "EARL-W062",
    Severity.WARNING,
    "every transition can be taken",
    "§2.2, Table 5",
    "A transition whose initial condition can never hold (under the assumptions) is dead specification.",
)
_register(
    "EARL-I063",
    Severity.NOTE,
    "behaviours that never end",
    "§2.2, Table 5",
    "A behaviour whose terminal and error conditions can never hold runs forever, like the manual's "
    "`emergencyStop/bb` with `false/pp`: fine for a deliberate sink state, a mistake elsewhere.",
)
_register(
    "EARL-W020",
    Severity.WARNING,
    "every state is reachable",
    "§2.2, Figure 5a",
    "A state no chain of possible transitions leads to from the initial state never runs.",
)
_register(
    "EARL-W021",
    Severity.WARNING,
    "a state that can end has a way out",
    "§2.2, Figure 5a",
    "A state whose behaviour can stop but that no transition leaves leaves the FSM with no next state.",
)
