"""The rule registry: every rule of `earl check`, with its code, title and the manual text it enforces.

A rule is a function that receives the `CheckContext` and yields `Finding`s; the
decorator records its code, severity, title and reference.  docs/rules.md is
generated from this registry (`python -m earl.check.rules_doc`), and a test fails
when the page is stale.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from earl.diagnostics import Severity
from earl.model.location import SourceLocation

if TYPE_CHECKING:
    from earl.check.context import CheckContext


@dataclass(frozen=True)
class Finding:
    """One violation a rule found: the rule adds its code and severity."""

    message: str
    location: SourceLocation | None
    hint: str | None = None


RuleFunction = Callable[["CheckContext"], Iterable[Finding]]


@dataclass(frozen=True)
class Rule:
    code: str
    severity: Severity
    title: str
    reference: str  # the manual's section, equation, table or figure
    check: RuleFunction

    @property
    def explanation(self) -> str:
        """The rule function's docstring: why the rule exists, for docs/rules.md."""
        return " ".join((self.check.__doc__ or "").split())


RULES: dict[str, Rule] = {}


def rules_by_code() -> list[Rule]:
    return sorted(RULES.values(), key=lambda rule: rule.code)


_PREFIX = {Severity.ERROR: "EARL-E", Severity.WARNING: "EARL-W", Severity.NOTE: "EARL-I"}


def rule(code: str, severity: Severity, title: str, reference: str) -> Callable[[RuleFunction], RuleFunction]:
    """Register a rule; `code` is its stable identifier (`EARL-E012`)."""
    if not code.startswith(_PREFIX[severity]):
        raise ValueError(f"{code}: a {severity.value} code starts with {_PREFIX[severity]}")

    def register(function: RuleFunction) -> RuleFunction:
        if code in RULES:
            raise ValueError(f"rule code {code} is registered twice")
        RULES[code] = Rule(code, severity, title, reference, function)
        return function

    return register
