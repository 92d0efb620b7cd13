"""Expressions: the `fun` of Predicates and Primitive Predicates (manual §2.2, Table 4).

An expression is a small immutable tree.  The same classes describe constant
expressions (parameter values, family ranges, array sizes) and the Boolean
formulas of primitive predicates, initial conditions and terminal conditions.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

from earl.model.frozen import quick_init
from earl.model.kinds import Kind
from earl.model.location import SourceLocation, location_field


@quick_init
@dataclass(frozen=True, slots=True)
class Star:
    """The `[*]` index: every member of a family (`motorControllerState[*]/ib`)."""

    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class ElementReference:
    """A name in the manual's notation: `manipulatorCommand/ib`, `windingCurrent[K]/mo`.

    `indices` select members of an indexed family; they are expressions over
    parameters and index variables, or `Star` for all members.  `kind` is a `Kind`,
    or its text (`"ib"`), which becomes that Kind.
    """

    name: str
    kind: Kind
    indices: tuple[Expression | Star, ...] = ()
    location: SourceLocation | None = location_field()

    def __post_init__(self) -> None:
        # `ElementReference("cmd", "ib")`: a kind given as the text the manual writes after the slash is that
        # Kind. Kept as text it compared equal to the Kind (a StrEnum) in some places and not in others
        # (`kind is Kind.INPUT_BUFFER`, `kind.value`): the checker and the run took it, `to_earl` refused
        # it. A text that is no kind (`"ibb"`) stays as given, for the type check to name.
        if self.kind.__class__ is not Kind and isinstance(self.kind, str):
            kind = Kind._value2member_map_.get(self.kind)
            if kind is not None:
                object.__setattr__(self, "kind", kind)
        if isinstance(self.indices, list):  # given in Python: a tuple as the reader makes it, equal to it and hashable
            object.__setattr__(self, "indices", tuple(self.indices))

    @property
    def is_family_wide(self) -> bool:
        return any(isinstance(index, Star) for index in self.indices)


@quick_init
@dataclass(frozen=True, slots=True)
class Literal:
    """`true`, `false`, an integer, a real number or a string."""

    value: bool | int | float | str
    location: SourceLocation | None = location_field()

    # `true` and `1`, `0` and `false`, `1` and `1.0` are different literals, of different types, but Python
    # takes `True == 1` and `1 == 1.0`: two models differing only there compared equal (and hashed alike)
    def __eq__(self, other: object) -> bool:
        if other.__class__ is not Literal:
            return NotImplemented
        value = other.value  # type: ignore[attr-defined]
        return self.value.__class__ is value.__class__ and (self.value is value or self.value == value)

    def __hash__(self) -> int:
        return hash((self.value.__class__, self.value))


@quick_init
@dataclass(frozen=True, slots=True)
class ListLiteral:
    """`[0.0, 0.0, 1.0]`: the initial value of an array."""

    items: tuple[Expression, ...]
    location: SourceLocation | None = location_field()

    def __post_init__(self) -> None:
        if isinstance(self.items, list):  # given in Python: a tuple as the reader makes it, equal to it and hashable
            object.__setattr__(self, "items", tuple(self.items))


@quick_init
@dataclass(frozen=True, slots=True)
class Name:
    """A parameter (`N`) or a family index variable (`K`)."""

    name: str
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class FieldAccess:
    name: str
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class IndexAccess:
    index: Expression
    location: SourceLocation | None = location_field()


Accessor = FieldAccess | IndexAccess


@quick_init
@dataclass(frozen=True, slots=True)
class Read:
    """The value of a buffer, memory or primitive predicate, possibly a part of it.

    `manipulatorCommand/ib.emergencyStopCommand` reads a field of the message in an
    Input Buffer; `currentJointPos/mi[2]` an element of a memory; `emergencyStop/pp`
    the value of a primitive predicate.
    """

    target: ElementReference
    path: tuple[Accessor, ...] = ()
    location: SourceLocation | None = location_field()

    def __post_init__(self) -> None:
        if isinstance(self.path, list):  # given in Python: a tuple as the reader makes it, equal to it and hashable
            object.__setattr__(self, "path", tuple(self.path))


@quick_init
@dataclass(frozen=True, slots=True)
class Call:
    """A built-in function: `newData(manipulatorCommand/ib.jointPosSetpoint)`, `timeout(x/ib)`, `stale(x/ib)`."""

    function: str
    arguments: tuple[Expression, ...]
    location: SourceLocation | None = location_field()

    def __post_init__(self) -> None:
        # given in Python: a tuple as the reader makes it, equal to it and hashable
        if isinstance(self.arguments, list):
            object.__setattr__(self, "arguments", tuple(self.arguments))


@quick_init
@dataclass(frozen=True, slots=True)
class Not:
    operand: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class Negate:
    operand: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class BooleanOperation:
    """`a and b and c` or `a or b`: one operator over two or more operands."""

    operator: str  # "and" | "or"
    operands: tuple[Expression, ...]
    location: SourceLocation | None = location_field()
    #: in an expanded system, the `any`/`all` this operation unrolls (one operand per index value), so
    #: that a message can speak of what was written; no part of the operation's meaning
    unrolled: Quantifier | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if isinstance(self.operands, list):  # given in Python: a tuple as the reader makes it, equal to it and hashable
            object.__setattr__(self, "operands", tuple(self.operands))


@quick_init
@dataclass(frozen=True, slots=True)
class Comparison:
    operator: str  # "==" "!=" "<" "<=" ">" ">="
    left: Expression
    right: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class Arithmetic:
    operator: str  # "+" "-" "*"
    left: Expression
    right: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class Quantifier:
    """`any(K in 1..N: motorControllerState[K]/ib.emergencyStop)`: the manual's `∨ … ∨`."""

    quantifier: str  # "any" | "all"
    index: str
    first: Expression
    last: Expression
    body: Expression
    location: SourceLocation | None = location_field()


Expression = (
    Literal | ListLiteral | Name | Read | Call | Not | Negate | BooleanOperation | Comparison | Arithmetic | Quantifier
)

#: The built-in functions a predicate may call, with the number of arguments.
BUILTIN_FUNCTIONS: dict[str, int] = {
    # true when a new message arrived at the last receive (manual Table 4)
    "newData": 1,
    # true when an obligatory input buffer was not filled before its timeout
    "timeout": 1,
    # true while the agent that feeds the input buffer from another process is gone (docs/distributed.md)
    "stale": 1,
}

#: The call that stands for a primitive predicate computed by Python code (see PrimitivePredicate).
PYTHON_PREDICATE = "python"

COMPARISON_OPERATORS = ("==", "!=", "<=", ">=", "<", ">")
ARITHMETIC_OPERATORS = ("+", "-", "*")


def children(expression: Expression) -> Iterator[Expression]:
    """The direct sub-expressions, in source order."""
    if isinstance(expression, ListLiteral):
        yield from expression.items
    elif isinstance(expression, Read):
        yield from _reference_indices(expression.target)
        for accessor in expression.path:
            if isinstance(accessor, IndexAccess):
                yield accessor.index
    elif isinstance(expression, Call):
        yield from expression.arguments
    elif isinstance(expression, (Not, Negate)):
        yield expression.operand
    elif isinstance(expression, BooleanOperation):
        yield from expression.operands
    elif isinstance(expression, (Comparison, Arithmetic)):
        yield expression.left
        yield expression.right
    elif isinstance(expression, Quantifier):
        yield expression.first
        yield expression.last
        yield expression.body


def _reference_indices(reference: ElementReference) -> Iterator[Expression]:
    for index in reference.indices:
        if not isinstance(index, Star):
            yield index


def walk(expression: Expression) -> Iterator[Expression]:
    """Every node of an expression, parents before children (iterative: specs may nest deeply)."""
    stack = [expression]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(reversed(list(children(node))))


def reads(expression: Expression) -> Iterator[Read]:
    for node in walk(expression):
        if isinstance(node, Read):
            yield node


class ConstantError(ValueError):
    """A constant expression could not be evaluated; `location` says where."""

    def __init__(self, message: str, location: SourceLocation | None) -> None:
        super().__init__(message)
        self.location = location


def evaluate_constant(
    expression: Expression, names: Mapping[str, bool | int | float | str]
) -> bool | int | float | str:
    """The value of an expression made only of literals, parameters and arithmetic."""
    if isinstance(expression, Literal):
        return expression.value
    if isinstance(expression, Name):
        if expression.name not in names:
            raise ConstantError(f"`{expression.name}` is not a parameter or index in scope here", expression.location)
        return names[expression.name]
    if isinstance(expression, Negate):
        value = evaluate_constant(expression.operand, names)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConstantError("`-` needs a number", expression.location)
        return -value
    if isinstance(expression, Arithmetic):
        left = evaluate_constant(expression.left, names)
        right = evaluate_constant(expression.right, names)
        if isinstance(left, (bool, str)) or isinstance(right, (bool, str)):
            raise ConstantError(f"`{expression.operator}` needs numbers", expression.location)
        if expression.operator == "+":
            return left + right
        if expression.operator == "-":
            return left - right
        return left * right
    raise ConstantError("only numbers, parameters and `+ - *` may appear in a constant", expression.location)


def evaluate_integer(expression: Expression, names: Mapping[str, bool | int | float | str]) -> int:
    value = evaluate_constant(expression, names)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConstantError(f"expected a whole number here, got {value!r}", expression.location)
    return value
