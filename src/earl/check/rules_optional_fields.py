"""A condition reads an optional field only when a message that carries it has arrived (manual Table 4).

An optional field (`jointPosSetpoint: JointPosition?`) may be absent from a message. A
condition that compares it, computes with it or reads further into it then raises at run
time: the condition faults and counts as false (docs/semantics.md). The manual's own guard is
`newData(manipulatorCommand/ib.msg.jointPosSetpoint)`: a new message arrived that carries the
field. Conditions are evaluated as written, left to right, and stop as soon as the outcome is
known, so `newData(cmd/ib.target) and cmd/ib.target > 3.0` never reads an absent field.

What proves a field present is worked out from the formula alone, through the primitive
predicates it names; a guard that holds for reasons outside the formula (every sender fills the
field) is not seen: make such a field non-optional.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from earl.check.context import CheckContext
from earl.check.registry import Finding, rule
from earl.check.rules_behaviour import _conditions
from earl.diagnostics import Severity
from earl.model.elements import Subsystem
from earl.model.expressions import (
    BooleanOperation,
    Call,
    Comparison,
    Expression,
    FieldAccess,
    IndexAccess,
    Not,
    Read,
    children,
)
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.text import expression_text, reference_text
from earl.model.types import ArrayType, StructType

#: a field path of an input buffer: its name and the accessors' texts (`("cmd", ".target")`)
Path = tuple[str, ...]

#: how deep predicates naming predicates are followed (deeper ones prove nothing present)
_MOST_DEPTH = 32


@dataclass(frozen=True)
class _Unguarded:
    read: Read
    needed: Path  # the optional field that must be present
    predicate: str | None  # the primitive predicate whose definition holds the read, if any


class _Reader:
    """The reads of optional fields that a subsystem's conditions may make while the field is absent."""

    def __init__(self, context: CheckContext, subsystem: Subsystem) -> None:
        self.context = context
        self.subsystem = subsystem
        self.definitions = {p.name: p.expression for p in subsystem.primitive_predicates if p.implementation is None}

    # ---------------------------------------------------------------- what a formula proves present
    def present_if(self, expression: Expression, holds: bool, depth: int = 0) -> frozenset[Path]:
        """The fields every message in question carries whenever `expression` is `holds`."""
        if depth > _MOST_DEPTH:
            return frozenset()
        if isinstance(expression, Not):
            return self.present_if(expression.operand, not holds, depth + 1)
        if isinstance(expression, Call) and expression.function == "newData" and holds:
            [argument] = expression.arguments or (None,)
            if isinstance(argument, Read) and argument.target.kind is Kind.INPUT_BUFFER and argument.path:
                return frozenset(_prefixes(_path_of(argument)))
            return frozenset()
        if isinstance(expression, Read) and expression.target.kind is Kind.PRIMITIVE_PREDICATE:
            definition = self.definitions.get(expression.target.name)
            return frozenset() if definition is None else self.present_if(definition, holds, depth + 1)
        if isinstance(expression, BooleanOperation):
            parts = [self.present_if(operand, holds, depth + 1) for operand in expression.operands]
            if not parts:
                return frozenset()
            # `a and b` holds when both do; `a or b` fails when both do: the facts of every part add up.
            # Otherwise one part is enough, and only what all of them prove is known.
            adds_up = (expression.operator == "and") == holds
            if adds_up:
                return frozenset().union(*parts)
            return frozenset.intersection(*parts)
        return frozenset()

    # ---------------------------------------------------------------- the reads, in evaluation order
    def unguarded(
        self, expression: Expression, present: frozenset[Path], predicate: str | None = None, depth: int = 0
    ) -> Iterator[_Unguarded]:
        """Reads of optional fields `expression` may make while they are absent, given the fields `present`."""
        if depth > _MOST_DEPTH:
            return
        if isinstance(expression, BooleanOperation):
            known = present
            for operand in expression.operands:
                yield from self.unguarded(operand, known, predicate, depth + 1)
                # the next operand runs only when this one did not decide: true before `and`, false before `or`
                known = known | self.present_if(operand, expression.operator == "and")
            return
        if isinstance(expression, Comparison) and expression.operator in ("==", "!="):
            # an absent field compares as unequal to every value: only reading *into* it raises
            for side in (expression.left, expression.right):
                if isinstance(side, Read):
                    yield from self._read(side, present, predicate, whole_value_needed=False)
                else:
                    yield from self.unguarded(side, present, predicate, depth + 1)
            return
        if isinstance(expression, Call):
            # `newData(x/ib.a.b)` is false, not a fault, when `a` is absent; `timeout` and `stale` read no field
            for argument in expression.arguments:
                for accessor in argument.path if isinstance(argument, Read) else ():
                    if isinstance(accessor, IndexAccess):
                        yield from self.unguarded(accessor.index, present, predicate, depth + 1)
            return
        if isinstance(expression, Read):
            yield from self._read(expression, present, predicate, whole_value_needed=True, depth=depth)
            return
        for child in children(expression):
            yield from self.unguarded(child, present, predicate, depth + 1)

    def _read(
        self,
        read: Read,
        present: frozenset[Path],
        predicate: str | None,
        whole_value_needed: bool,
        depth: int = 0,
    ) -> Iterator[_Unguarded]:
        for accessor in read.path:
            if isinstance(accessor, IndexAccess):
                yield from self.unguarded(accessor.index, present, predicate, depth + 1)
        if read.target.kind is Kind.PRIMITIVE_PREDICATE:
            definition = self.definitions.get(read.target.name)
            if definition is not None and not read.path:
                # evaluated where it is named: the caller's guards hold inside it
                yield from self.unguarded(definition, present, read.target.name, depth + 1)
            return
        if read.target.kind is not Kind.INPUT_BUFFER:
            return  # memory has no `newData`: nothing could guard it
        needed = self._needed(read, whole_value_needed)
        if needed is not None and needed not in present:
            yield _Unguarded(read, needed, predicate)

    def _needed(self, read: Read, whole_value_needed: bool) -> Path | None:
        """The deepest optional field that must be present for `read` not to raise (None: nothing must)."""
        buffer = self.context.input_buffer(self.subsystem, read.target)
        if buffer is None:
            return None
        current = self.context.structural(buffer.data_type)
        path = _path_of(read)
        needed: Path | None = None
        last = len(read.path) - 1
        for position, accessor in enumerate(read.path):
            if isinstance(accessor, FieldAccess):
                if not isinstance(current, StructType):
                    return needed
                field = current.field_named(accessor.name)
                if field is None:
                    return needed
                if field.optional and (position < last or whole_value_needed):
                    needed = path[: position + 2]
                current = self.context.structural(field.data_type)
            elif isinstance(current, ArrayType):
                current = self.context.structural(current.element)
            else:
                return needed
        return needed


def _path_of(read: Read) -> Path:
    parts = [reference_text(read.target)]
    for accessor in read.path:
        parts.append(
            f".{accessor.name}" if isinstance(accessor, FieldAccess) else f"[{expression_text(accessor.index)}]"
        )
    return tuple(parts)


def _prefixes(path: Path) -> Iterator[Path]:
    for end in range(2, len(path) + 1):
        yield path[:end]


@rule(
    "EARL-W046", Severity.WARNING, "a condition reads an optional field only when a message carries it", "§2.2, Table 4"
)
def optional_fields_read_only_when_present(context: CheckContext) -> Iterator[Finding]:
    """An optional field may be absent; a condition that compares it (`<`, `>`), computes with it or reads
    into it then faults and counts as false. Guard the read with `newData(x/ib.field) and …`, as Table 4
    does; `==` and `!=` need no guard (an absent field equals no value). Assumptions are not evaluated
    at run time and are not checked."""

    reported: set[SourceLocation | None] = set()  # each read once, named with the first condition that reaches it
    for _agent, subsystem in context.distinct_subsystems():
        reader = _Reader(context, subsystem)
        for role, expression, location in _conditions(subsystem):
            if role.startswith(("primitive predicate", "an assumption")):
                continue  # a predicate is read where a condition names it, with that condition's guards
            for found in reader.unguarded(expression, frozenset()):
                where = found.read.location or location
                if where not in reported:
                    reported.add(where)
                    yield _finding(found, role, where)


def _finding(found: _Unguarded, role: str, location: SourceLocation | None) -> Finding:
    inside = f" (through `{found.predicate}/pp`)" if found.predicate else ""
    return Finding(
        f"{role}{inside} reads `{expression_text(found.read)}` even when no message that carries the optional "
        f"field `{''.join(found.needed[1:]).removeprefix('.')}` has arrived: reading an absent field faults, "
        "and the condition counts as false",
        location,
        f"guard it: `newData({''.join(found.needed)}) and …`, as Table 4 does, or make the field non-optional",
    )
