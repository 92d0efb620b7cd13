"""`earl check`: every rule of the manual, and an FSM analysis, over a resolved system.

    >>> from earl.check import check
    >>> diagnostics = check(earl.load("examples/pick_and_place"))

Checking reads the model only: it never imports or runs code a spec names.
"""

from __future__ import annotations

from collections.abc import Mapping

from earl.check import fsm_analysis, rules_behaviour, rules_communication, rules_optional_fields, rules_structure
from earl.check.context import CheckContext
from earl.check.merging import Said, merge_family_members
from earl.check.registry import RULES, Finding, Rule
from earl.collector import paused as collector_paused
from earl.diagnostics import Diagnostic, Severity, did_you_mean
from earl.lang.resolver import resolve
from earl.model.elements import System
from earl.model.expand import expand
from earl.model.types import PARAMETER_TYPES, parameter_value_problem, refuse_wrong_parameters
from earl.model.validate import explaining

# The rule modules register themselves on import; they are listed here so that none is forgotten.
RULE_MODULES = (rules_structure, rules_communication, rules_behaviour, rules_optional_fields, fsm_analysis)

_ORDER = {Severity.ERROR: 0, Severity.WARNING: 1, Severity.NOTE: 2}


def context_for(system: System, parameters: Mapping[str, bool | int | float | str] | None = None) -> CheckContext:
    return CheckContext(system, expand(system, parameters or {}))


def check(system: System, parameters: Mapping[str, bool | int | float | str] | None = None) -> list[Diagnostic]:
    """Every finding of every rule, ordered by file (the spec's own first), line and column.

    A parameter the system does not declare is EARL-R001, as `load(path, parameters)` reports it:
    a misspelt `N` must not leave the default in place without a word."""
    if not isinstance(system, System):
        raise TypeError(
            f"check takes a System, as earl.load(path) returns it, not {type(system).__name__} {system!r:.60}"
        )
    refuse_wrong_parameters(parameters)
    unknown = unknown_parameters(system, parameters or {}) + wrong_parameter_values(system, parameters or {})
    if unknown:
        return unknown
    # a value of the wrong type, built in Python, fails somewhere inside: said at its path instead
    with collector_paused(), explaining(system):
        # A system built or edited in Python never met the reader: its names are resolved here, as
        # `load` resolves a file's (a transition to a state that does not exist, a duplicate agent …).
        unresolved = [d for d in resolve(system, parameters or {}) if d.severity is Severity.ERROR]
        if unresolved:
            return unresolved
        return check_context(context_for(system, parameters))


def unknown_parameters(system: System, parameters: Mapping[str, object]) -> list[Diagnostic]:
    """EARL-R001 for each name in `parameters` that is not a system parameter of `system`."""
    known = [p.name for p in system.parameters]
    return [
        Diagnostic(
            Severity.ERROR,
            f"there is no system parameter `{name}` to set",
            None,
            "EARL-R001",
            did_you_mean(name, known) or f"system parameters: {', '.join(known) or 'none'}",
        )
        for name in parameters
        if name not in known
    ]


def wrong_parameter_values(system: System, parameters: Mapping[str, object]) -> list[Diagnostic]:
    """EARL-R005 for each value in `parameters` that its system parameter's type does not take, as
    `load(path, parameters)` and `--param` report it (`"abc"` for an `int`, 10**30 beyond 64 bits)."""
    declared = {p.name: getattr(p.data_type, "name", "") for p in system.parameters}
    found = []
    for name, value in parameters.items():
        type_name = declared.get(name)
        if type_name not in PARAMETER_TYPES:
            continue  # unknown (EARL-R001), or a parameter whose own type is wrong (EARL-R003)
        wrong = parameter_value_problem(type_name, value)
        if wrong is not None:
            found.append(
                Diagnostic(Severity.ERROR, f"parameter `{name}` is `{type_name}` but {wrong}", None, "EARL-R005")
            )
    return found


def check_context(context: CheckContext) -> list[Diagnostic]:
    """Every finding of every rule over an already expanded system (`context_for`)."""
    with collector_paused():
        found = [
            Said(rule.code, finding.message, finding.location, finding.hint)
            for rule in RULES.values()
            for finding in rule.check(context)
        ]
    diagnostics = [
        Diagnostic(RULES[said.code].severity, said.message, said.location, said.code, said.hint)
        for said in merge_family_members(found)
    ]
    root = context.declared.source_file
    diagnostics.sort(
        key=lambda d: (
            # the spec itself first, then the files it imports
            d.location is None or d.location.file != root,
            d.location.file if d.location else "",
            d.location.line if d.location else 0,
            d.location.column if d.location else 0,
            _ORDER[d.severity],
        )
    )
    return diagnostics


__all__ = ["RULES", "CheckContext", "Finding", "Rule", "check", "check_context", "collector_paused", "context_for"]
