"""Sub-formulas made of constants alone, folded: once expansion has put family indices and parameters in,
`2 == 2` or `J + 1 < 3` is a truth the checker can read without a subsystem's values (the FSM analysis
folds them away; the type check skips what a constant guard never lets be read)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from earl.model.expressions import (
    Arithmetic,
    BooleanOperation,
    Comparison,
    ConstantError,
    Expression,
    Literal,
    Negate,
    Not,
    evaluate_constant,
)

Constant = bool | int | float | str

ORDERINGS: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
    "==": lambda a, b: a == b,
    "!=": lambda a, b: a != b,
}


def constant_value(expression: Expression) -> Constant | None:
    """The value of a sub-formula of constants; None when it reads anything of the subsystem."""
    if isinstance(expression, (Literal, Negate, Arithmetic)):
        try:
            return evaluate_constant(expression, {})
        except ConstantError:
            return None
    if isinstance(expression, Not):
        operand = constant_value(expression.operand)
        return (not operand) if isinstance(operand, bool) else None
    if isinstance(expression, BooleanOperation):
        values = [constant_value(operand) for operand in expression.operands]
        if not all(isinstance(value, bool) for value in values):
            return None
        return all(values) if expression.operator == "and" else any(values)
    if isinstance(expression, Comparison):
        left, right = constant_value(expression.left), constant_value(expression.right)
        if left is None or right is None or isinstance(left, bool) != isinstance(right, bool):
            return None
        if isinstance(left, str) != isinstance(right, str):
            return None
        if expression.operator not in ("==", "!=") and (isinstance(left, (str, bool))):
            return None
        if expression.operator not in ORDERINGS:
            return None
        return bool(ORDERINGS[expression.operator](left, right))
    return None


__all__ = ["ORDERINGS", "Constant", "constant_value"]
