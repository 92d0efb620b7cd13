"""Sub-formulas made of constants alone, folded: once expansion has put family indices and parameters in,
`2 == 2` or `J + 1 < 3` is a truth the checker can read without a subsystem's values (the FSM analysis
folds them away; the type check skips what a constant guard never lets be read)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

from earl.model.expressions import (
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ConstantError,
    Expression,
    IndexAccess,
    Literal,
    Negate,
    Not,
    Read,
    Star,
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


def indices_folded(expression: Expression) -> Expression:
    """`expression` with every index made of constants written as its value: `arr/ib[3 - 1]` (`N - 1`
    with N = 3) and `arr/ib[1 + 1]` read what `arr/ib[2]` reads, and the checker must see one value, not
    three (docs/language.md: constants, family indices and parameters are folded). The expression
    itself when nothing changes."""
    if isinstance(expression, Read):
        indices = tuple(
            index if isinstance(index, Star) else _index_folded(index) for index in expression.target.indices
        )
        path = tuple(
            IndexAccess(_index_folded(accessor.index), accessor.location)
            if isinstance(accessor, IndexAccess)
            else accessor
            for accessor in expression.path
        )
        if indices == expression.target.indices and path == expression.path:
            return expression
        target = dataclasses.replace(expression.target, indices=indices)
        return Read(target, path, expression.location)
    if isinstance(expression, Comparison):
        left, right = indices_folded(expression.left), indices_folded(expression.right)
        if left is expression.left and right is expression.right:
            return expression
        return Comparison(expression.operator, left, right, expression.location)
    if isinstance(expression, Call):
        arguments = tuple(indices_folded(argument) for argument in expression.arguments)
        if all(new is old for new, old in zip(arguments, expression.arguments, strict=True)):
            return expression
        return Call(expression.function, arguments, expression.location)
    if isinstance(expression, (Not, Negate)):
        operand = indices_folded(expression.operand)
        return expression if operand is expression.operand else dataclasses.replace(expression, operand=operand)
    if isinstance(expression, BooleanOperation):
        operands = tuple(indices_folded(operand) for operand in expression.operands)
        if all(new is old for new, old in zip(operands, expression.operands, strict=True)):
            return expression
        return dataclasses.replace(expression, operands=operands)
    if isinstance(expression, Arithmetic):
        left, right = indices_folded(expression.left), indices_folded(expression.right)
        if left is expression.left and right is expression.right:
            return expression
        return Arithmetic(expression.operator, left, right, expression.location)
    return expression


def _index_folded(index: Expression) -> Expression:
    if isinstance(index, Literal):
        return index
    value = constant_value(index)
    if isinstance(value, int) and not isinstance(value, bool):
        return Literal(value, index.location)
    return indices_folded(index)


__all__ = ["ORDERINGS", "Constant", "constant_value", "indices_folded"]
