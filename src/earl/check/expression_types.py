"""The type of an expression, to tell whether a predicate really is Boolean (manual §2.2)."""

from __future__ import annotations

from dataclasses import dataclass

from earl.check.constants import constant_value
from earl.check.context import CheckContext
from earl.model.elements import InputBuffer, Memory, Subsystem
from earl.model.expressions import (
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ConstantError,
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
    children,
    evaluate_constant,
)
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.text import expression_text
from earl.model.types import INTEGER_RANGES, ArrayType, PrimitiveType, StructType, type_text

BOOLEAN = "boolean"
NUMBER = "number"
STRING = "string"
OTHER = "other"  # a struct, an array or bytes: only comparable for equality
UNKNOWN = "unknown"  # the resolver reported the problem already

_NUMERIC = {
    "int8",
    "int16",
    "int32",
    "int64",
    "uint8",
    "uint16",
    "uint32",
    "uint64",
    "int",
    "float32",
    "float64",
    "double",
}


@dataclass
class TypeProblem:
    message: str
    location: SourceLocation | None
    hint: str | None = None


class ExpressionTyper:
    """Infers `boolean`, `number`, `string` or `other` bottom-up and records misuse."""

    def __init__(self, context: CheckContext, subsystem: Subsystem) -> None:
        self.context = context
        self.subsystem = subsystem
        self.problems: list[TypeProblem] = []
        # an index said out of range once: the unrolled bodies of a quantifier repeat each index's place
        self._indices_said: set[SourceLocation | None] = set()
        # an index of the wrong type said once, likewise
        self._index_types_said: set[SourceLocation | None] = set()
        # above 0 while typing operands that are never evaluated: `J == 2 or v/ib[J + 1]` with J = 2 reads no
        # element 3, since `or` stops at its constant true operand (their types are still checked)
        self._unreachable = 0

    def type_of(self, expression: Expression) -> str:
        if isinstance(expression, Literal):
            value = expression.value
            if isinstance(value, bool):
                return BOOLEAN
            return STRING if isinstance(value, str) else NUMBER
        if isinstance(expression, ListLiteral):
            return OTHER
        if isinstance(expression, Name):
            return UNKNOWN
        if isinstance(expression, Read):
            return self._read(expression)
        if isinstance(expression, Call):
            for argument in expression.arguments:  # `newData(x/ib.samples[i])`: its indices are indices too
                if isinstance(argument, Read):
                    self._check_index_types(argument)
            return BOOLEAN
        if isinstance(expression, Quantifier):
            self._expect(expression.body, BOOLEAN, f"the body of `{expression.quantifier}(…)`")
            return BOOLEAN
        if isinstance(expression, Not):
            self._expect(expression.operand, BOOLEAN, "the operand of `not`")
            return BOOLEAN
        if isinstance(expression, BooleanOperation):
            quantifier = expression.unrolled
            if quantifier is not None:
                # each body reads with its own K: an index out of range may be in any of them
                self._check_indices_in(expression)
                # `any(K in 1..N: …)` unrolled: every operand is the body for one K; said once, as written
                self._expect(
                    expression.operands[0],
                    BOOLEAN,
                    f"the body of `{quantifier.quantifier}({quantifier.index} in …: …)`",
                    shown=expression_text(quantifier.body),
                )
                return BOOLEAN
            stopped = 0
            for operand in expression.operands:
                self._expect(operand, BOOLEAN, f"an operand of `{expression.operator}`")
                if not stopped and _stops(expression.operator, operand):
                    stopped = 1
                    self._unreachable += 1
            self._unreachable -= stopped
            return BOOLEAN
        if isinstance(expression, Negate):
            self._expect(expression.operand, NUMBER, "the operand of `-`")
            return NUMBER
        if isinstance(expression, Arithmetic):
            self._expect(expression.left, NUMBER, f"the left operand of `{expression.operator}`")
            self._expect(expression.right, NUMBER, f"the right operand of `{expression.operator}`")
            return NUMBER
        if isinstance(expression, Comparison):
            left, right = self.type_of(expression.left), self.type_of(expression.right)
            if UNKNOWN not in (left, right):
                described = f"{self._what(expression.left, left)} with {self._what(expression.right, right)}"
                if expression.operator in ("==", "!="):
                    if left != right or (left == OTHER and not self._same_structure(expression.left, expression.right)):
                        self.problems.append(
                            TypeProblem(f"`{expression_text(expression)}` compares {described}", expression.location)
                        )
                elif left != NUMBER or right != NUMBER:
                    self.problems.append(
                        TypeProblem(
                            f"`{expression.operator}` orders numbers, but `{expression_text(expression)}` compares {described}",
                            expression.location,
                        )
                    )
            return BOOLEAN
        return UNKNOWN

    def integer_range(self, expression: Expression) -> tuple[int, int] | None:
        """The whole numbers a read of an integer type may hold (`uint8`: 0 to 255); None for any other
        expression. Values are checked against their type where they are written."""
        if not isinstance(expression, Read):
            return None
        structure = self._structure(expression)
        if isinstance(structure, PrimitiveType):
            return INTEGER_RANGES.get(structure.name)
        return None

    def _expect(self, expression: Expression, expected: str, role: str, shown: str | None = None) -> None:
        actual = self.type_of(expression)
        if actual not in (expected, UNKNOWN):
            self.problems.append(
                TypeProblem(
                    f"{role} must be a {expected}, but `{shown or expression_text(expression)}` is a {actual}",
                    expression.location,
                )
            )

    def _what(self, expression: Expression, category: str) -> str:
        """`a number`, `a struct `Goal``, `an array `double[3]``: what a side of a comparison is."""
        if category != OTHER:
            return f"a {category}"
        structure = self._structure(expression) if isinstance(expression, Read) else None
        if isinstance(structure, StructType):
            return f"a struct `{structure.name}`"
        if isinstance(structure, ArrayType):
            return f"an array `{type_text(structure)}`"
        if isinstance(structure, PrimitiveType):
            return f"a `{structure.name}` value"
        return "a list" if isinstance(expression, ListLiteral) else "a struct or an array"

    def _same_structure(self, left: Expression, right: Expression) -> bool:
        """Two structs, arrays or bytes values of one type (or whose types are not known here)."""
        first = self._structure(left) if isinstance(left, Read) else None
        second = self._structure(right) if isinstance(right, Read) else None
        if first is None or second is None:
            return True
        return self.context.same_type(first, second)  # type: ignore[arg-type]

    def _check_indices_in(self, expression: Expression) -> None:
        """A constant index outside a fixed-size array anywhere in `expression`, said with the innermost
        unrolled quantifier around it: its place alone is that of every body."""
        if self._unreachable:
            return
        stack: list[tuple[Expression, str]] = [(expression, "")]
        while stack:
            node, within = stack.pop()
            quantifier = node.unrolled if isinstance(node, BooleanOperation) else None
            if quantifier is not None:
                within = f" (in the body of `{quantifier.quantifier}({quantifier.index} in …: …)`)"
            if isinstance(node, Read):
                self._structure(node, check_indices=True, within=within)
            if isinstance(node, BooleanOperation):
                # a body's own guard, made constant by its index (`J == N or …`), ends its evaluation
                evaluated: list[Expression] = []
                for operand in node.operands:
                    evaluated.append(operand)
                    if _stops(node.operator, operand):
                        break
                stack.extend((child, within) for child in reversed(evaluated))
                continue
            # the first body first: the first value out of range is the one said
            stack.extend((child, within) for child in reversed(list(children(node))))

    def _structure(
        self, read: Read, check_indices: bool = False, within: str = ""
    ) -> PrimitiveType | ArrayType | StructType | None:
        """The type a read of a buffer or memory yields, aliases followed; None when not known. With
        `check_indices`, a constant index outside a fixed-size array on the way is a problem (`within`
        says where, when the place alone does not)."""
        target = read.target
        element: InputBuffer | Memory | None
        if target.kind is Kind.INPUT_BUFFER:
            element = self.context.input_buffer(self.subsystem, target)
        elif target.kind in (Kind.MEMORY_INPUT, Kind.MEMORY):
            element = self.context.memory(self.subsystem, target)
        else:
            return None
        if element is None:
            return None
        current = self.context.structural(element.data_type)
        for accessor in read.path:
            if isinstance(accessor, FieldAccess) and isinstance(current, StructType):
                field = current.field_named(accessor.name)
                if field is None:
                    return None
                current = self.context.structural(field.data_type)
            elif not isinstance(accessor, FieldAccess) and isinstance(current, ArrayType):
                if check_indices:
                    self._check_index(read, accessor, current, within)
                current = self.context.structural(current.element)
            else:
                return None
        return current  # type: ignore[return-value]

    def _read(self, read: Read) -> str:
        if read.target.kind is Kind.PRIMITIVE_PREDICATE:
            return BOOLEAN
        self._check_index_types(read)
        current = self._structure(read, check_indices=not self._unreachable)
        if current is None:
            return UNKNOWN
        if isinstance(current, PrimitiveType):
            if current.name == "boolean":
                return BOOLEAN
            if current.name in _NUMERIC:
                return NUMBER
            if current.name == "string":
                return STRING
        return OTHER

    def _check_index_types(self, read: Read) -> None:
        """Every index of `read` is a whole number: `v/ib[1.5]`, `v/ib[true]` or `v/ib[d/ib]` of a `double`
        names no element (a Boolean would even read element 1 in Python, silently)."""
        for accessor in read.path:
            if not isinstance(accessor, IndexAccess):
                continue
            location = accessor.location or accessor.index.location or read.location
            if location in self._index_types_said:
                continue  # the unrolled bodies of a quantifier repeat each index's place
            wrong = self._not_whole(accessor.index)
            if wrong is None:
                continue
            self._index_types_said.add(location)
            value = constant_value(accessor.index)
            self.problems.append(
                TypeProblem(
                    f"the index of `{expression_text(read)}` must be a whole number, but {wrong}",
                    location,
                    f"write `{int(value)}`: elements are counted in whole numbers"
                    if isinstance(value, float) and value.is_integer()
                    else "index with a whole number (`v/ib[2]`), an `int` parameter or quantifier index, "
                    "or a buffer or memory of an integer type (`int32`, `uint8`, …)",
                )
            )

    def _not_whole(self, index: Expression) -> str | None:
        """Why `index` is not a whole number (`` `1.5` is a real number ``), or None when it is one or its
        type is not known here. EARL's arithmetic is `+ - *`: whole numbers give whole numbers."""
        shown = f"`{expression_text(index)}`"
        value = constant_value(index)
        if value is not None:
            if isinstance(value, bool):
                return f"{shown} is a Boolean"
            if isinstance(value, str):
                return f"{shown} is a string"
            return None if isinstance(value, int) else f"{shown} is a real number"
        if isinstance(index, Negate):
            return self._not_whole(index.operand)
        if isinstance(index, Arithmetic):
            return self._not_whole(index.left) or self._not_whole(index.right)
        category = self.type_of(index)
        structure = self._structure(index) if isinstance(index, Read) else None
        if isinstance(structure, PrimitiveType) and structure.name not in INTEGER_RANGES:
            return f"{shown} is a `{structure.name}`"
        if category == BOOLEAN:
            return f"{shown} is a Boolean"
        if category == STRING:
            return f"{shown} is a string"
        if category == OTHER:
            return f"{shown} is {self._what(index, category)}"
        return None

    def _check_index(self, read: Read, accessor: object, array: ArrayType, within: str = "") -> None:
        """A constant index outside a fixed-size array: `ranges/ib[8]` of a `double[8]` (elements 0 to 7)
        would fail every time the condition is evaluated, and count as false."""
        index = getattr(accessor, "index", None)
        size = array.size
        if index is None or not isinstance(size, Literal):
            return
        try:  # `v/mi[1 + 3]`, `v/mi[K - 1]` with K put in by the expansion: constants too
            position = evaluate_constant(index, {})
        except ConstantError:
            return
        length = size.value
        if isinstance(position, bool) or not isinstance(position, int) or not isinstance(length, int):
            return
        location = getattr(accessor, "location", None) or read.location
        if not 0 <= position < length and location not in self._indices_said:
            self._indices_said.add(location)
            self.problems.append(
                TypeProblem(
                    f"`{expression_text(read)}` reads element {position} of a `{type_text(array)}`, whose elements "
                    f"are 0 to {length - 1}{within}",
                    location,
                )
            )


__all__ = ["BOOLEAN", "ExpressionTyper", "TypeProblem"]


def _stops(boolean_operator: str, operand: Expression) -> bool:
    """Whether `operand`, a constant, ends the evaluation of the `and`/`or` it is an operand of."""
    return constant_value(operand) is (boolean_operator == "or")
