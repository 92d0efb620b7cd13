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
from typing import Literal

from earl.check.context import CheckContext
from earl.check.registry import Finding, rule
from earl.check.rules_behaviour import _conditions, followable_definitions
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
    Quantifier,
    Read,
    children,
)
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.text import expression_text, reference_text
from earl.model.types import ArrayType, StructType

#: a field path of an input buffer: its name and the accessors' texts (`("cmd", ".target")`)
Path = tuple[str, ...]


#: how a read's value is used: compared for order, computed with or read into (`value`), taken as a
#: Boolean (`boolean`: an absent field reads as false, so `not` of it as true), or compared for equality
#: (`equality`: an absent field equals no value, which is what it should be)
Use = Literal["value", "boolean", "equality"]


@dataclass(frozen=True)
class _Unguarded:
    read: Read
    needed: Path  # the optional field that must be present
    faults: bool  # reading it absent raises; otherwise the absent Boolean reads as false
    predicate: str | None  # the primitive predicate whose definition holds the read, if any


class _Reader:
    """The reads of optional fields that a subsystem's conditions may make while the field is absent.

    A predicate is followed into its definition where a condition names it, with that condition's
    guards; each (predicate, guards) once, and never into itself (EARL-E045) nor into one too deep to
    follow (EARL-E047), so that neither `p/pp = p/pp and p/pp` nor a chain of thousands is walked."""

    def __init__(self, context: CheckContext, subsystem: Subsystem) -> None:
        self.context = context
        self.subsystem = subsystem
        self.definitions = followable_definitions(subsystem)
        self._present: dict[tuple[str, bool], frozenset[Path]] = {}
        self._opened: set[str] = set()  # predicates whose definitions are being followed
        self._followed: set[tuple[str, frozenset[Path], Use]] = set()

    # ---------------------------------------------------------------- what a formula proves present
    def present_if(self, expression: Expression, holds: bool) -> frozenset[Path]:
        """The fields every message in question carries whenever `expression` is `holds`."""
        if isinstance(expression, Not):
            return self.present_if(expression.operand, not holds)
        if isinstance(expression, Call) and expression.function == "newData" and holds:
            [argument] = expression.arguments or (None,)
            if isinstance(argument, Read) and argument.target.kind is Kind.INPUT_BUFFER and argument.path:
                return frozenset(_prefixes(_path_of(argument)))
            return frozenset()
        if isinstance(expression, Read) and expression.target.kind is Kind.PRIMITIVE_PREDICATE:
            name = expression.target.name
            definition = self.definitions.get(name)
            if definition is None or name in self._opened:
                return frozenset()
            key = (name, holds)
            if key not in self._present:
                self._opened.add(name)
                try:
                    self._present[key] = self.present_if(definition, holds)
                finally:
                    self._opened.discard(name)
            return self._present[key]
        if isinstance(expression, BooleanOperation):
            parts = [self.present_if(operand, holds) for operand in expression.operands]
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
        self, expression: Expression, present: frozenset[Path], predicate: str | None = None, use: Use = "boolean"
    ) -> Iterator[_Unguarded]:
        """Reads of optional fields `expression` may make while they are absent, given the fields `present`;
        `use`: how the value of `expression` itself is used."""
        if isinstance(expression, BooleanOperation):
            known = present
            for operand in expression.operands:
                yield from self.unguarded(operand, known, predicate, "boolean")
                # the next operand runs only when this one did not decide: true before `and`, false before `or`
                known = known | self.present_if(operand, expression.operator == "and")
            return
        if isinstance(expression, Not):
            yield from self.unguarded(expression.operand, present, predicate, "boolean")
            return
        if isinstance(expression, Comparison):
            side_use: Use = "equality" if expression.operator in ("==", "!=") else "value"
            for side in (expression.left, expression.right):
                yield from self.unguarded(side, present, predicate, side_use)
            return
        if isinstance(expression, Call):
            # `newData(x/ib.a.b)` is false, not a fault, when `a` is absent; `timeout` and `stale` read no field
            for argument in expression.arguments:
                for accessor in argument.path if isinstance(argument, Read) else ():
                    if isinstance(accessor, IndexAccess):
                        yield from self.unguarded(accessor.index, present, predicate, "value")
            return
        if isinstance(expression, Read):
            yield from self._read(expression, present, predicate, use)
            return
        if isinstance(expression, Quantifier):
            yield from self.unguarded(expression.body, present, predicate, "boolean")
            return
        for child in children(expression):  # arithmetic, `-`, lists: their operands are values
            yield from self.unguarded(child, present, predicate, "value")

    def _read(self, read: Read, present: frozenset[Path], predicate: str | None, use: Use) -> Iterator[_Unguarded]:
        for accessor in read.path:
            if isinstance(accessor, IndexAccess):
                yield from self.unguarded(accessor.index, present, predicate, "value")
        if read.target.kind is Kind.PRIMITIVE_PREDICATE:
            name = read.target.name
            definition = self.definitions.get(name)
            if definition is None or read.path or name in self._opened or (name, present, use) in self._followed:
                return
            # evaluated where it is named: the caller's guards hold inside it, and its value is used as the
            # caller uses it (`p/pp == false` of an absent Boolean holds no more than the field's own would)
            self._followed.add((name, present, use))
            self._opened.add(name)
            try:
                yield from self.unguarded(definition, present, name, use)
            finally:
                self._opened.discard(name)
            return
        if read.target.kind is not Kind.INPUT_BUFFER:
            return  # memory has no `newData`: nothing could guard it
        needed = self._needed(read, use)
        if needed is not None and needed[0] not in present:
            yield _Unguarded(read, needed[0], needed[1], predicate)

    def _needed(self, read: Read, use: Use) -> tuple[Path, bool] | None:
        """The deepest optional field that must be present for `read` to read a value, and whether reading it
        absent raises (None: nothing must be present)."""
        buffer = self.context.input_buffer(self.subsystem, read.target)
        if buffer is None:
            return None
        current = self.context.structural(buffer.data_type)
        path = _path_of(read)
        needed: Path | None = None
        faults = False
        last = len(read.path) - 1
        for position, accessor in enumerate(read.path):
            if isinstance(accessor, FieldAccess):
                if not isinstance(current, StructType):
                    break
                field = current.field_named(accessor.name)
                if field is None:
                    break
                if field.optional and use != "equality":  # `==` and `!=` read an absent field as absent
                    needed = path[: position + 2]
                    # read into, compared for order or computed with: raises; taken as a Boolean: false
                    faults = faults or position < last or use == "value"
                current = self.context.structural(field.data_type)
            elif isinstance(current, ArrayType):
                current = self.context.structural(current.element)
            else:
                break
        return None if needed is None else (needed, faults)


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
    into it then faults and counts as false, and an optional Boolean taken as a condition reads as false
    (`not` of it as true). Guard the read with `newData(x/ib.field) and …`, as Table 4 does; `==` and `!=`
    need no guard: an absent field equals no value, and so does a field inside it (`cmd/ib.target.x == 1.0`
    is false while `target` is absent). Assumptions are not evaluated at run time and are not checked."""

    reported: set[object] = set()  # each read once, named with the first condition that reaches it
    for _agent, subsystem in context.distinct_subsystems():
        reader = _Reader(context, subsystem)
        for role, expression, location in _conditions(subsystem):
            if role.startswith(("primitive predicate", "an assumption")):
                continue  # a predicate is read where a condition names it, with that condition's guards
            for found in reader.unguarded(expression, frozenset()):
                where = found.read.location or location
                # a model built in Python has no locations: its reads are told apart by what they read
                key = where if where is not None else (subsystem.name, found.predicate, expression_text(found.read))
                if key not in reported:
                    reported.add(key)
                    yield _finding(found, role, where)


def _finding(found: _Unguarded, role: str, location: SourceLocation | None) -> Finding:
    inside = f" (through `{found.predicate}/pp`)" if found.predicate else ""
    field = "".join(found.needed[1:]).removeprefix(".")
    outcome = (
        "reading an absent field faults, and the condition counts as false"
        if found.faults
        else "an absent field reads as false (and `not` of it as true)"
    )
    return Finding(
        f"{role}{inside} reads `{expression_text(found.read)}` even when no message that carries the optional "
        f"field `{field}` has arrived: {outcome}",
        location,
        f"guard it: `newData({''.join(found.needed)}) and …`, as Table 4 does, or make the field non-optional",
    )
