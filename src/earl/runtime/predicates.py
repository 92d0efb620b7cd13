"""Predicates compiled to Python: the `fun` operation of Primitive Predicates and conditions (Table 4–5).

A predicate is evaluated every iteration of every subsystem, so it is turned once
into a Python function over the subsystem's current values instead of walking the
expression tree each time.  The source is generated from the *model* (names become
string keys, literals their `repr`), never from text a user wrote, so nothing but the
expression's own operators can run.

A compiled predicate is called as `predicate(inputs, new_data, timed_out, memory, predicates)`:
the subsystem's dictionaries of input-buffer values, newData flags, timeout flags,
memory values, and its compiled primitive predicates by name. `stale(x/ib)` reads the
subsystem's set of stale input buffers, given when the predicate is compiled.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from collections.abc import Set as AbstractSet
from typing import Any

from earl.model.expressions import (
    ARITHMETIC_OPERATORS,
    COMPARISON_OPERATORS,
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
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
    walk,
)
from earl.model.kinds import Kind
from earl.runtime.names import reference_key

CompiledPredicate = Callable[
    [Mapping[str, Any], Mapping[str, bool], Mapping[str, bool], Mapping[str, Any], Mapping[str, Any]], Any
]

_ARGUMENTS = "ib, nd, to, mem, pp"


class PredicateCompileError(ValueError):
    """The expression cannot be run (it was not expanded, or names something the runtime lacks)."""


def compile_predicate(
    expression: Expression, description: str, stale: AbstractSet[str] = frozenset()
) -> CompiledPredicate:
    """A function computing `expression`; `description` names it in tracebacks (`manip/a.cs emergencyStop/pp`).

    `stale` is the subsystem's set of input buffers whose remote sender is gone, which
    `stale(x/ib)` reads; the transport changes the set in place while the run goes on.
    """
    source = f"lambda {_ARGUMENTS}: {_source(expression)}"
    code = compile(source, f"<earl predicate {description}>", "eval")
    names = {"__builtins__": {}, "stale": stale, "_element": _element, "_carries": _carries, "_carried": _carried}
    # read back from a failing frame's globals, to say in EARL's words what was absent (`absent_read`)
    names[_EXPRESSION] = expression
    function: CompiledPredicate = eval(code, names)
    return function


#: the name under which a compiled predicate's globals hold its expression
_EXPRESSION = "__earl_expression__"


#: a named predicate that one condition, evaluated in full, would evaluate more often than this is
#: computed once per decision instead (`repeatedly_evaluated`)
REPEATED_EVALUATIONS = 8


def repeatedly_evaluated(definitions: Mapping[str, Expression], conditions: Iterable[Expression]) -> set[str]:
    """The predicates (keys of `definitions`) that some condition would evaluate more than REPEATED_EVALUATIONS
    times: a predicate each level of which names the next twice (`p1 = p2 and p2`, `p2 = p3 and p3`, …) doubles
    its work at each level, and compiled predicates call each other.  The engine keeps these for the decision."""
    named: dict[str, list[str]] = {name: _named(expression) for name, expression in definitions.items()}
    order = _definitions_first(named)
    found: set[str] = set()
    for condition in conditions:
        # how many times a full evaluation of `condition` reaches each predicate: from the condition down
        reached: dict[str, int] = {}
        for name in _named(condition):
            reached[name] = reached.get(name, 0) + 1
        for name in reversed(order):  # every predicate after all that name it
            times = reached.get(name, 0)
            if not times:
                continue
            if times > REPEATED_EVALUATIONS:
                found.add(name)
                times = 1  # kept: its own parts are evaluated once
            for part in named[name]:
                reached[part] = reached.get(part, 0) + times
    return found


def _named(expression: Expression) -> list[str]:
    """The primitive predicates `expression` names, once per mention."""
    return [
        reference_key(node.target)
        for node in walk(expression)
        if isinstance(node, Read) and node.target.kind == Kind.PRIMITIVE_PREDICATE
    ]


def _definitions_first(named: Mapping[str, list[str]]) -> list[str]:
    """The predicates ordered so that each comes after every predicate it names (a cycle, which the checker
    refuses, is cut where it closes)."""
    order: list[str] = []
    placed: set[str] = set()
    for root in named:
        stack: list[tuple[str, bool]] = [(root, False)]
        while stack:
            name, parts_done = stack.pop()
            if parts_done:
                order.append(name)
                continue
            if name in placed or name not in named:
                continue
            placed.add(name)
            stack.append((name, True))
            stack.extend((part, False) for part in named[name] if part not in placed)
    return order


def kept_for_the_decision(predicate: CompiledPredicate, name: str, values: dict[str, Any]) -> CompiledPredicate:
    """`predicate`, computed at most once per decision: its value is kept in `values` (the engine's dictionary of
    predicate values, emptied when the input buffers take what arrived and when the memory changes)."""

    def kept(ib: Any, nd: Any, to: Any, mem: Any, pp: Any) -> Any:
        known = values.get(name)
        if known is None:  # an exception is not kept: it ends the whole condition's evaluation at once
            known = values[name] = bool(predicate(ib, nd, to, mem, pp))
        return known

    return kept


def _element(index: int) -> int:
    """An array index of a condition computed at run time: elements count from 0, and none is negative.
    A Boolean or a real number is no index (`earl check` refuses them, EARL-E030; a model built in Python
    may skip the check): Python would read `True` as element 1."""
    if isinstance(index, bool) or not isinstance(index, int):
        raise TypeError(f"an index must be a whole number, not {index!r}")
    if index < 0:
        raise IndexError(f"element {index} does not exist (elements count from 0)")
    return index


def _carries(value: Any, *steps: str | int) -> bool:
    """Whether a message holds what `steps` (field names, element indices) lead to: `newData(x/ib.a.b)` is
    false, not a fault, when the optional field `a` is absent, or when an array is shorter than an index."""
    for step in steps:
        if value is None or (isinstance(step, int) and step >= len(value)):
            return False
        value = value[step]
    return value is not None


def _carried(value: Any, *steps: str | int) -> Any:
    """What `steps` lead to in a message, or None (absent) when an optional field on the way is absent: an
    operand of `==` or `!=`, where an absent field equals no value, a field inside it no more than it."""
    for step in steps:
        if value is None:
            return None
        value = value[step]
    return value


def absent_read(error: BaseException) -> str | None:
    """`` `cmd/ib.inner` was absent ``: what a compiled predicate's `error` (a TypeError or IndexError, Python's
    words for it) comes from, read from the innermost compiled predicate it passed through and the values that
    predicate was given; None when it is not a read of something absent."""
    if not isinstance(error, (TypeError, IndexError)):
        return None
    frame = None
    trace = error.__traceback__
    while trace is not None:
        if _EXPRESSION in trace.tb_frame.f_globals:
            frame = trace.tb_frame
        trace = trace.tb_next
    if frame is None:
        return None
    expression = frame.f_globals[_EXPRESSION]
    values = {"ib": frame.f_locals.get("ib"), "mem": frame.f_locals.get("mem")}
    try:
        for read, use in _reads(expression, "boolean"):
            said = _absent_on_the_way(read, use, values, error)
            if said is not None:
                return said
    except Exception:  # only an explanation: Python's own words are said instead
        return None
    return None


def _reads(expression: Expression, use: str) -> Iterable[tuple[Read, str]]:
    """The reads of buffers and memory in `expression`, in the order they are written, with how each value is
    used: `equality` (an operand of `==`, `!=`), `value` (ordered, computed with), `boolean`."""
    if isinstance(expression, Read):
        if expression.target.kind != Kind.PRIMITIVE_PREDICATE:
            for accessor in expression.path:
                if isinstance(accessor, IndexAccess):
                    yield from _reads(accessor.index, "value")
            yield expression, use
        return
    if isinstance(expression, Call):
        for argument in expression.arguments:  # newData(x/ib.a.b) reads nothing that can fault but its indices
            for accessor in argument.path if isinstance(argument, Read) else ():
                if isinstance(accessor, IndexAccess):
                    yield from _reads(accessor.index, "value")
        return
    if isinstance(expression, Comparison):
        side = "equality" if expression.operator in ("==", "!=") else "value"
        yield from _reads(expression.left, side)
        yield from _reads(expression.right, side)
        return
    if isinstance(expression, (BooleanOperation, Not)):
        for child in children(expression):
            yield from _reads(child, "boolean")
        return
    for child in children(expression):
        yield from _reads(child, "value")


def _absent_on_the_way(read: Read, use: str, values: Mapping[str, Any], error: BaseException) -> str | None:
    """What of `read` was absent (or beyond an array's end), given the values its predicate was given."""
    target = read.target
    source = values.get("ib" if target.kind == Kind.INPUT_BUFFER else "mem")
    if not isinstance(source, Mapping):
        return None
    value = source.get(reference_key(target))
    said = f"{reference_key(target)}/{'ib' if target.kind == Kind.INPUT_BUFFER else 'mi'}"
    for accessor in read.path:
        if isinstance(accessor, FieldAccess):
            if value is None:
                # a field read into an absent one: raised unless compared for equality (`_carried`)
                return None if use == "equality" or not isinstance(error, TypeError) else _absent(said)
            if not isinstance(value, Mapping):
                return None
            # dict's own get: a struct's field named `get` is the field, not the method (runtime.md)
            value = dict.get(value, accessor.name) if isinstance(value, dict) else value.get(accessor.name)
            said += f".{accessor.name}"
            continue
        if value is None:
            return None if use == "equality" or not isinstance(error, TypeError) else _absent(said)
        index = _literal_index(accessor)
        if index is not None and isinstance(value, (list, tuple)) and index >= len(value):
            if isinstance(error, IndexError):
                count = len(value)
                return f"`{said}` has no element {index} (it has {count} element{'' if count == 1 else 's'})"
            return None
        if index is None or not isinstance(value, (list, tuple)):
            return None
        value = value[index]
        said += f"[{index}]"
    if value is None and use == "value" and isinstance(error, TypeError):
        return _absent(said)
    return None


def _absent(said: str) -> str:
    """`` `cmd/ib.inner` was absent ``, with the guard that reads an input buffer's field only when it came."""
    guard = f" (guard the read: `newData({said}) and …`, EARL-W046)" if "/ib." in said else ""
    return f"`{said}` was absent{guard}"


def _literal_index(accessor: IndexAccess) -> int | None:
    index = accessor.index
    if isinstance(index, Literal) and type(index.value) is int and index.value >= 0:
        return index.value
    return None


def predicate_source(expression: Expression) -> str:
    """The generated Python for `expression` (shown by tests and in fault reports)."""
    return _source(expression)


def _literal(value: object) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return "1e999" if value > 0 else "-1e999"
    return repr(value)


def _source(expression: Expression) -> str:
    if isinstance(expression, Literal):
        return _literal(expression.value)
    if isinstance(expression, ListLiteral):
        return "(" + "".join(f"{_source(item)}, " for item in expression.items) + ")"
    if isinstance(expression, Read):
        return _read(expression)
    if isinstance(expression, Call):
        return _call(expression)
    if isinstance(expression, Not):
        return f"(not {_source(expression.operand)})"
    if isinstance(expression, Negate):
        return f"(-{_source(expression.operand)})"
    if isinstance(expression, BooleanOperation):
        if expression.operator not in ("and", "or"):
            raise PredicateCompileError(f"`{expression.operator}` is no Boolean operator of EARL (`and`, `or`)")
        joiner = f" {expression.operator} "
        return "(" + joiner.join(_source(operand) for operand in expression.operands) + ")"
    if isinstance(expression, (Comparison, Arithmetic)):
        known = COMPARISON_OPERATORS if isinstance(expression, Comparison) else ARITHMETIC_OPERATORS
        if expression.operator not in known:
            # a model built in Python and run unchecked: the operator would go into the generated code as it is
            raise PredicateCompileError(f"`{expression.operator}` is no operator of EARL ({', '.join(known)})")
        if isinstance(expression, Comparison) and expression.operator in ("==", "!="):
            # an absent field equals no value, and so does a field inside an absent one
            left, right = _equality_operand(expression.left), _equality_operand(expression.right)
            return f"({left} {expression.operator} {right})"
        return f"({_source(expression.left)} {expression.operator} {_source(expression.right)})"
    if isinstance(expression, Name):
        raise PredicateCompileError(f"`{expression.name}` is not a parameter or index with a known value")
    if isinstance(expression, Quantifier):
        raise PredicateCompileError("a quantifier must be expanded before it runs")
    raise PredicateCompileError(f"cannot run the expression {expression!r}")


def _equality_operand(expression: Expression) -> str:
    """An operand of `==` or `!=`: a read that goes on past a field, which may be an absent optional one, is
    absent itself then (`_carried`); any other operand as everywhere."""
    if not isinstance(expression, Read) or expression.target.kind == Kind.PRIMITIVE_PREDICATE:
        return _source(expression)
    if not any(isinstance(accessor, FieldAccess) for accessor in expression.path[:-1]):
        return _source(expression)  # no field on the way: nothing on it can be absent
    return f"_carried({_base(expression)}, {_steps(expression)})"


def _read(read: Read) -> str:
    target = read.target
    key = repr(reference_key(target))
    if target.kind == Kind.PRIMITIVE_PREDICATE:
        if read.path:
            raise PredicateCompileError(f"`{target.name}/pp` is a Boolean: it has no fields or elements")
        return f"pp[{key}]({_ARGUMENTS})"
    return _base(read) + _path(read)


def _base(read: Read) -> str:
    """The buffer or memory `read` reads, without its fields and elements."""
    target = read.target
    key = repr(reference_key(target))
    if target.kind == Kind.INPUT_BUFFER:
        return f"ib[{key}]"
    if target.kind in (Kind.MEMORY_INPUT, Kind.MEMORY):
        return f"mem[{key}]"
    raise PredicateCompileError(f"a predicate cannot read `{target.name}/{target.kind.value}`")


def _path(read: Read) -> str:
    parts = []
    for accessor in read.path:
        if isinstance(accessor, FieldAccess):
            parts.append(f"[{accessor.name!r}]")
        elif isinstance(accessor, IndexAccess):
            index = accessor.index
            if isinstance(index, Literal) and type(index.value) is int and index.value >= 0:  # not a bool
                parts.append(f"[{_source(index)}]")
            else:  # Python would read a negative index from the end: an element the spec has not
                parts.append(f"[_element({_source(index)})]")
    return "".join(parts)


def _steps(read: Read) -> str:
    """The accessors of `read` as arguments of `_carries`: field names, and element indices (none negative)."""
    steps = []
    for accessor in read.path:
        if isinstance(accessor, FieldAccess):
            steps.append(repr(accessor.name))
        else:
            steps.append(f"_element({_source(accessor.index)})")
    return ", ".join(steps)


def _call(call: Call) -> str:
    if len(call.arguments) != 1 or not isinstance(call.arguments[0], Read):
        raise PredicateCompileError(f"`{call.function}` takes one input buffer")
    argument = call.arguments[0]
    if argument.target.kind != Kind.INPUT_BUFFER:
        raise PredicateCompileError(f"`{call.function}` takes an input buffer (`/ib`)")
    key = repr(reference_key(argument.target))
    if call.function == "newData":
        if not argument.path:
            return f"nd[{key}]"
        # Table 4's newData(manipulatorCommand/ib.msg.jointPosSetpoint): a new message that carries the field
        return f"(nd[{key}] and _carries(ib[{key}], {_steps(argument)}))"
    if call.function == "timeout":
        return f"to[{key}]"
    if call.function == "stale":
        return f"({key} in stale)"
    raise PredicateCompileError(f"unknown function `{call.function}`")
