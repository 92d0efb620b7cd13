"""EARL expressions (predicates, conditions, initial values) as SysML v2 expressions.

The two notations differ in three places that matter:

- `not` is a unary operator in SysML v2 and binds tighter than any binary one,
  where EARL's `not a == b` means `not (a == b)`: operands are parenthesised by
  SysML's own precedence, never copied from the EARL text; the operand of a
  unary operator must be a primary expression (`not (not a)`, `-(-x)`);
- a read of a buffer or memory goes through the library's `msg` and `data`
  features (`manipulatorCommand_ib.msg.emergencyStopCommand`, manual §2.2);
- EARL indexes arrays from 0 and SysML's `#(i)` from 1;
- an array that is one value (an element of an array of arrays, an optional array
  field) is exported as an attribute definition holding `elements`, read through it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from earl.export.sysml_names import name_text
from earl.model.expressions import (
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ConstantError,
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
    evaluate_integer,
)
from earl.model.kinds import Kind
from earl.model.text import expression_text
from earl.model.types import ArrayType, DataType, Field, StructType, TypeAlias, TypeDefinition, TypeReference

#: How a reference to a buffer, memory or primitive predicate is written: the SysML name of its target.
Resolver = Callable[[ElementReference], str]
#: The data type of the buffer or memory a reference names (None: not known).
TypeOf = Callable[[ElementReference], DataType | None]
#: A data type of the specification by its name.
TypeNamed = Callable[[str], TypeDefinition | None]

# SysML v2 operator precedence, loosest first (KerML 8.2.5.8): or, and, equality, relational,
# additive, multiplicative, unary, then primary expressions.
_OR, _AND, _EQUALITY, _RELATIONAL, _ADDITIVE, _MULTIPLICATIVE, _UNARY, _PRIMARY = range(8)


def literal(value: bool | int | float | str) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            raise ValueError("nan has no SysML literal")
        if math.isinf(value):
            # SysML has no infinity literal; a decimal too large for any real type reads as one.
            return "1e999" if value > 0 else "-1e999"
        return repr(value)
    escaped = value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    escaped = escaped.replace("\r", "\\r").replace("\b", "\\b").replace("\f", "\\f")
    return f'"{escaped}"'


class ExpressionWriter:
    """Writes the expressions of one subsystem, whose element names `resolve` knows."""

    def __init__(self, resolve: Resolver, type_of: TypeOf | None = None, type_named: TypeNamed | None = None) -> None:
        self.resolve = resolve
        self.type_of = type_of
        self.type_named = type_named

    def text(self, expression: Expression) -> str:
        return self._write(expression)[0]

    # Each case returns the text and its precedence, so that a parent can parenthesise it.
    def _write(self, expression: Expression) -> tuple[str, int]:
        if isinstance(expression, Literal):
            text = literal(expression.value)
            return text, _UNARY if text.startswith("-") else _PRIMARY
        if isinstance(expression, ListLiteral):
            return "(" + ", ".join(self.text(item) for item in expression.items) + ")", _PRIMARY
        if isinstance(expression, Name):
            # Expansion replaces parameters and indices by their values; a name left over is kept as written.
            return name_text(expression.name), _PRIMARY
        if isinstance(expression, Read):
            return self._read(expression), _PRIMARY
        if isinstance(expression, Call):
            return self._call(expression), _PRIMARY
        # KerML's `UnaryExpression: operator operand=ExtentExpression` takes a primary expression (or
        # `all …`): a unary operand of a unary operator is parenthesised, `not (not a)`, `-(-x)`, never `--x`.
        if isinstance(expression, Not):
            return "not " + self._operand(expression.operand, _PRIMARY), _UNARY
        if isinstance(expression, Negate):
            return "-" + self._operand(expression.operand, _PRIMARY), _UNARY
        if isinstance(expression, BooleanOperation):
            own = _OR if expression.operator == "or" else _AND
            parts = [self._operand(operand, own, strict=True) for operand in expression.operands]
            return f" {expression.operator} ".join(parts), own
        if isinstance(expression, Comparison):
            own = _EQUALITY if expression.operator in ("==", "!=") else _RELATIONAL
            left = self._operand(expression.left, own, strict=True)
            right = self._operand(expression.right, own, strict=True)
            return f"{left} {expression.operator} {right}", own
        if isinstance(expression, Arithmetic):
            own = _MULTIPLICATIVE if expression.operator == "*" else _ADDITIVE
            left = self._operand(expression.left, own)
            right = self._operand(expression.right, own, strict=True)
            return f"{left} {expression.operator} {right}", own
        if isinstance(expression, Quantifier):
            # `expand` unrolls every quantifier; one met here belongs to a system that was not expanded.
            raise ValueError(f"quantifier `{expression_text(expression)}` must be expanded before export")
        raise TypeError(f"not an expression: {expression!r}")

    def _operand(self, expression: Expression, parent: int, *, strict: bool = False) -> str:
        text, own = self._write(expression)
        needed = own < parent or (strict and own == parent)
        # Clearer than the bare precedence: `a or (b and c)`, `(a < b) == c`; `x > 1 and y < 2` stays bare.
        nested_logic = isinstance(expression, BooleanOperation) or (
            isinstance(expression, Comparison) and parent in (_EQUALITY, _RELATIONAL)
        )
        return f"({text})" if needed or nested_logic else text

    def _read(self, read: Read, whole: bool = True) -> str:
        """`whole`: the value read is used as a value, so an array held as one value is read as its `elements`."""
        target = read.target
        text = self.resolve(target)
        if target.kind is Kind.INPUT_BUFFER:
            text += ".msg"
        elif target.kind in (Kind.MEMORY, Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT):
            text += ".data"
        # The type of what is read so far, and whether it is an array held as one value (docs/sysml.md:
        # an element of an array of arrays, an optional array field), whose elements are its `elements`.
        current = self.type_of(target) if self.type_of is not None else None
        held = False
        previous: object = None
        for accessor in read.path:
            if isinstance(accessor, FieldAccess):
                text += "." + name_text(accessor.name)
                field = self._field(current, accessor.name)
                current = field.data_type if field is not None else None
                held = field is not None and field.optional and self._array(current) is not None
            elif isinstance(accessor, IndexAccess):
                if current is None:
                    # Types unknown: only an element of an array of arrays is held as one value.
                    held = isinstance(previous, IndexAccess)
                text += (".elements" if held else "") + f"#({self._position(accessor.index)})"
                array = self._array(current)
                current = array.element if array is not None else None
                held = current is not None and self._array(current) is not None
            previous = accessor
        return text + (".elements" if whole and held else "")

    def _resolved(self, data_type: DataType | None) -> DataType | TypeDefinition | None:
        """`data_type` with the spec's aliases followed to what they name."""
        seen: set[str] = set()
        while isinstance(data_type, TypeReference) and self.type_named is not None and data_type.name not in seen:
            seen.add(data_type.name)
            definition = self.type_named(data_type.name)
            if isinstance(definition, TypeAlias):
                data_type = definition.data_type
            else:
                return definition
        return None if isinstance(data_type, TypeReference) else data_type

    def _array(self, data_type: DataType | None) -> ArrayType | None:
        resolved = self._resolved(data_type)
        return resolved if isinstance(resolved, ArrayType) else None

    def _field(self, data_type: DataType | None, name: str) -> Field | None:
        resolved = self._resolved(data_type)
        return resolved.field_named(name) if isinstance(resolved, StructType) else None

    def _position(self, index: Expression) -> str:
        """EARL's 0-based index as SysML's 1-based position."""
        try:
            return str(evaluate_integer(index, {}) + 1)
        except ConstantError:
            return f"{self._operand(index, _ADDITIVE)} + 1"

    def _call(self, call: Call) -> str:
        arguments = []
        for argument in call.arguments:
            if call.function in ("timeout", "stale") and isinstance(argument, Read) and not argument.path:
                # timeout() and stale() are about the buffer itself, not its message.
                arguments.append(self.resolve(argument.target))
            elif isinstance(argument, Read):
                # newData(x/ib.field) is about the field, which may be absent, not about its elements.
                arguments.append(self._read(argument, whole=False))
            else:
                arguments.append(self.text(argument))
        return f"EARL::{call.function}(" + ", ".join(arguments) + ")"
