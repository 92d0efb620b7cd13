"""Names and expressions written back in the manual's notation.

Used by messages, diagrams and the formatter alike, so an element is spelled the
same everywhere: `motorControllerState[K]/ib.emergencyStop`, `idle,jointMove/t`.
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

from earl.model.expressions import (
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ElementReference,
    Expression,
    FieldAccess,
    IndexAccess,
    ListLiteral,
    Literal,
    Name,
    Negate,
    Not,
    Quantifier,
    Read,
    Star,
)
from earl.model.kinds import Kind

if TYPE_CHECKING:
    from earl.model.elements import Agent, Family, Link, Robot, Subsystem

# Binding strength, loosest first; a child binding more loosely than its parent needs parentheses.
_OR, _AND, _NOT, _COMPARE, _SUM, _PRODUCT, _UNARY, _ATOM = range(8)


def _precedence(expression: Expression) -> int:
    if isinstance(expression, BooleanOperation):
        return _OR if expression.operator == "or" else _AND
    if isinstance(expression, Not):
        return _NOT
    if isinstance(expression, Comparison):
        return _COMPARE
    if isinstance(expression, Arithmetic):
        return _PRODUCT if expression.operator == "*" else _SUM
    if isinstance(expression, Negate):
        return _UNARY
    if (
        isinstance(expression, Literal)
        and isinstance(expression.value, int | float)
        and not isinstance(expression.value, bool)
        and expression.value < 0
    ):
        return _UNARY  # `-1` reads like a negation
    return _ATOM


def literal_text(value: bool | int | float | str) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float) and not math.isfinite(value):
        if math.isnan(value):
            raise ValueError("nan has no EARL literal: no number in the language reads as nan")
        # The reader turns a number too large for a float into infinity, so this reads back as it.
        return "1e999" if value > 0 else "-1e999"
    if not isinstance(value, int | float):
        # `PythonImplementation(my_function)`: its repr (`<function idle at 0x…>`) is no text the reader reads
        raise TypeError(f"no EARL literal is {type(value).__name__} {value!r:.60}")
    return repr(value)


def index_text(index: Expression | Star) -> str:
    return "*" if isinstance(index, Star) else expression_text(index)


def reference_text(reference: ElementReference) -> str:
    indices = "".join(f"[{index_text(index)}]" for index in reference.indices)
    if reference.kind.value == "cs":
        return "cs"
    return f"{reference.name}{indices}/{reference.kind.value}"


def family_text(name: str, family: Family | None) -> str:
    if family is None:
        return name
    return f"{name}[{family.index} in {expression_text(family.first)}..{expression_text(family.last)}]"


def link_name_text(link: Link) -> str:
    parts = []
    for part in link.name:
        if part.index is None:
            parts.append(part.name)
        elif link.family is not None and part.declares_family:
            parts.append(family_text(part.name, link.family))
        else:
            parts.append(f"{part.name}[{expression_text(part.index)}]")
    return ",".join(parts)


def expression_text(expression: Expression) -> str:
    """Canonical text with the fewest parentheses that keep the tree as it is."""
    if isinstance(expression, Literal):
        return literal_text(expression.value)
    if isinstance(expression, ListLiteral):
        return "[" + ", ".join(expression_text(item) for item in expression.items) + "]"
    if isinstance(expression, Name):
        return expression.name
    if isinstance(expression, Read):
        text = reference_text(expression.target)
        for accessor in expression.path:
            if isinstance(accessor, FieldAccess):
                text += f".{accessor.name}"
            elif isinstance(accessor, IndexAccess):
                text += f"[{expression_text(accessor.index)}]"
        return text
    if isinstance(expression, Call):
        return f"{expression.function}(" + ", ".join(expression_text(a) for a in expression.arguments) + ")"
    if isinstance(expression, Quantifier):
        return (
            f"{expression.quantifier}({expression.index} in {expression_text(expression.first)}"
            f"..{expression_text(expression.last)}: {expression_text(expression.body)})"
        )
    if isinstance(expression, Not):
        return "not " + _operand(expression.operand, _NOT, strict=False)
    if isinstance(expression, Negate):
        operand = expression.operand
        # `-(1)` keeps a negated literal apart from the literal -1.
        if isinstance(operand, Literal) or _precedence(operand) < _ATOM:
            return f"-({expression_text(operand)})"
        return "-" + expression_text(operand)
    if isinstance(expression, BooleanOperation):
        own = _precedence(expression)
        return f" {expression.operator} ".join(_operand(o, own, strict=True) for o in expression.operands)
    if isinstance(expression, Comparison):
        left = _operand(expression.left, _COMPARE, strict=True)
        right = _operand(expression.right, _COMPARE, strict=True)
        return f"{left} {expression.operator} {right}"
    if isinstance(expression, Arithmetic):
        own = _precedence(expression)
        left = _operand(expression.left, own, strict=False)
        right = _operand(expression.right, own, strict=True)
        return f"{left} {expression.operator} {right}"
    raise TypeError(f"not an expression: {expression!r}")


def _operand(expression: Expression, parent: int, *, strict: bool) -> str:
    """Text of a child, parenthesised when it binds more loosely (or equally, when `strict`)."""
    own = _precedence(expression)
    text = expression_text(expression)
    if own < parent or (strict and own == parent):
        return f"({text})"
    return text


def instance_name(name: str, index: int | None) -> str:
    """`motorController[3]`: a member of a family by its index; an element declared alone by its name."""
    return name if index is None else f"{name}[{index}]"


def subsystem_name(agent: Agent, subsystem: Subsystem) -> str:
    """`manip/a.cs`, `manip/a.motorController[3]/ve`: the dot notation of manual §2.2, for the checker's and
    the run's messages and the names a run gives its subsystems alike."""
    own = (
        "cs"
        if subsystem.kind is Kind.CONTROL_SUBSYSTEM
        else f"{_member_or_family(subsystem.name, subsystem.index, subsystem.family)}/{subsystem.kind.value}"
    )
    return f"{_member_or_family(agent.name, agent.index, agent.family)}/a.{own}"


def robot_member_keys(robot: Robot) -> list[str]:
    """`a/a`, `link b,a`, …: the keys of `Robot.member_comments`, one per member as written (agents, then
    links); a member written twice (EARL-W047) has keys of its own, `a/a (2)`, so neither takes the other's
    comments."""
    keys: list[str] = []
    seen: dict[str, int] = {}
    written = [reference_text(agent) for agent in robot.agents] + [f"link {link.name}" for link in robot.links]
    for text in written:
        seen[text] = seen.get(text, 0) + 1
        keys.append(text if seen[text] == 1 else f"{text} ({seen[text]})")
    return keys


def agent_name(agent: Agent) -> str:
    """`manip/a`, `worker[3]/a` for a member, `worker[K]/a` for a family as declared."""
    return f"{_member_or_family(agent.name, agent.index, agent.family)}/a"


def _member_or_family(name: str, index: int | None, family: Family | None) -> str:
    """`motorController[3]` for a member; `motorController[K]` for a family as declared (a message about the
    declaration is about every member), not `motorController`, which names none."""
    if index is None and family is not None:
        return f"{name}[{family.index}]"
    return instance_name(name, index)
