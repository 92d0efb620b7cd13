"""Whether a signal's path (`push[2].abort`, `perBin[1]`) is one the trace's schemas have.

A signal the messages never gave a value is either a value the run never sent (an optional field,
an array sent empty) or a path its element does not have: a misspelt field, an index past a fixed
array's end, a member a family does not have. The channels' schemas say which, as the spec does for
`earl run --plot` (earl/runtime/plot.py), so that a slip is refused rather than drawn without.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from earl.diagnostics import did_you_mean

#: `[2]`, `[*]`, `[K]` or `.name`
_STEP = re.compile(r"\[([0-9]+|\*|[A-Za-z_]\w*)\]|\.([A-Za-z_]\w*)")


def path_problem(
    inner: str,
    memory: tuple[Any, dict[str, int]] | None,
    buffers: dict[str, Any],
    declared: list[str] | None,
    has_leaves: Callable[[str], bool],
) -> str | None:
    """What is wrong with `inner` (a signal's name inside its subsystem, `push[2].abortt`) by the
    trace's schemas, or None when they show nothing wrong (or cannot tell).

    `memory` is the subsystem's memory schema with its families' first indices (None when its memory
    is not recorded); `buffers` the schema of each recorded output buffer (`push[2]`, `beltSpeed`) by
    the link leaving it; `declared` every output buffer the subsystem declares, recorded or not (the
    FSM channel's metadata `outputs`; None in a trace written before it said); `has_leaves(prefix)` whether the
    messages held a value under `prefix` (a field the schema leaves out, an array of arrays, is known
    only from them)."""
    steps = [(match.group(1), match.group(2)) for match in _STEP.finditer(inner)]
    element = _element(inner)
    if "".join(match.group(0) for match in _STEP.finditer(inner)) != inner[len(element) :]:
        return None  # not a path of steps: the syntax check says so before
    schema, families = memory if memory is not None else (None, {})
    properties = schema.get("properties") if isinstance(schema, dict) else None
    if isinstance(properties, dict) and element in properties:
        current = properties[element]
        if element in families:
            if not steps:
                return None  # a family named whole: said elsewhere
            first = families[element]
            last = current.get("maxItems") if isinstance(current, dict) else None
            index, _ = steps.pop(0)
            if index is None or not _is_member(index, first, last):
                return _no_member(element, index, list(range(first, last)) if isinstance(last, int) else [first])
            current = current.get("items") if isinstance(current, dict) else None
            return _walk(current, f"{element}[{index}]", steps, has_leaves)
        return _walk(current, element, steps, has_leaves)
    recorded = {name: found for name, found in buffers.items() if _element(name) == element}
    named = [name for name in declared or recorded if _element(name) == element]
    if not named:
        return None  # no value of the trace: said elsewhere, with the elements the trace has
    if element in named:
        return _walk(_unwrapped(recorded.get(element)), element, steps, has_leaves)
    if not steps:
        return None  # a family named whole: said elsewhere
    index, _ = steps.pop(0)
    # the members share one type: a member that never sent is checked by another's schema
    sibling = _unwrapped(next(iter(recorded.values()), None))
    if index == "*":
        return _walk(sibling, f"{element}[*]", steps, has_leaves)
    indices = sorted(int(name[len(element) + 1 : -1]) for name in named)
    if index is None or not index.isdigit():
        return _no_member(element, index, indices, recorded=declared is None)
    if int(index) not in indices:
        # which members a family has is known only from the trace's metadata (a trace written
        # before it said has the members whose links were recorded and sent)
        return None if declared is None else _no_member(element, index, indices)
    member = f"{element}[{index}]"
    return _walk(_unwrapped(recorded[member]) if member in recorded else sibling, member, steps, has_leaves)


def declared_buffer(inner: str, declared: list[str]) -> str | None:
    """The output buffer of `declared` (the FSM channel's `outputs`) that `inner` (`push[2].abort`,
    `push[*].abort`, `beltSpeed`) is a value of: `push[2]`, `push[*]`, `beltSpeed`; None when it names none."""
    element = _element(inner)
    if element in declared:
        return element
    member = re.match(r"\[([0-9]+|\*)\]", inner[len(element) :])
    if member is None:
        return None
    named = f"{element}[{member.group(1)}]"
    if member.group(1) == "*":
        return named if any(_element(name) == element for name in declared) else None
    return named if named in declared else None


def _element(name: str) -> str:
    """The element a buffer's name starts with: `push` of `push[2]`."""
    return re.split(r"[.\[]", name, maxsplit=1)[0]


def _is_member(index: str, first: int, last: Any) -> bool:
    """Whether `index` (`*`, `2`, `K`) names members of a family whose first index is `first` and
    whose array is `last` long (None: not known)."""
    if index == "*":
        return True
    if not index.isdigit():
        return False
    return int(index) >= first and (not isinstance(last, int) or int(index) < last)


def _no_member(element: str, index: str | None, indices: list[int], recorded: bool = False) -> str:
    """What a signal that names no member of the family `element` is told."""
    if index is None:
        return f"`{element}` is a family; name a member, `{element}[{indices[0]}]`, or every one, `{element}[*]`"
    span = f"{indices[0]}..{indices[-1]}" if indices == list(range(indices[0], indices[-1] + 1)) else str(indices)
    has = f"the trace has members {span} of `{element}`" if recorded else f"`{element}` has members {span}"
    if not index.isdigit():
        return f"`{element}[{index}]` names no member: a member is named by its index ({has}), or `[*]` for every one"
    return f"{has}, not {index}"


def _unwrapped(schema: Any) -> Any:
    """The schema of what an output buffer sent: a message that is not a struct is `{"value": …}`."""
    if isinstance(schema, dict) and "title" not in schema:
        properties = schema.get("properties")
        if isinstance(properties, dict) and list(properties) == ["value"]:
            return properties["value"]
    return schema


def _walk(
    schema: Any, named: str, steps: list[tuple[str | None, str | None]], has_leaves: Callable[[str], bool]
) -> str | None:
    """`path_problem`'s steps after the element (`named` so far) through `schema`."""
    current = schema
    for index, field in steps:
        current = _present(current)
        if not isinstance(current, dict):
            return None  # a part the schema leaves out: the messages alone say what it is
        kind = current.get("type")
        if field is not None:
            properties = current.get("properties")
            if kind == "array":
                return (
                    f"`{named}` has no field `{field}` where the signal names it: it is an array; name an element, "
                    f"`{named}[0]`, or every one, `{named}[*]`"
                )
            if kind != "object" or not isinstance(properties, dict):
                return f"`{named}` has no field `{field}` where the signal names it: it is {_kind(kind)}"
            if field not in properties:
                if has_leaves(f"{named}.{field}"):
                    return None  # a field the schema leaves out (an array of arrays), in the messages
                hint = did_you_mean(field, properties)
                listed = ", ".join(f"`{name}`" for name in properties) or "none in the trace"
                return f"`{named}` has no field `{field}` where the signal names it; " + (hint or f"it has {listed}")
            current = properties[field]
            named += f".{field}"
        else:
            assert index is not None
            if kind != "array":
                return f"`{named}` is not an array where the signal indexes it: it is {_kind(kind)}"
            size = current.get("maxItems")
            if not index.isdigit() and index != "*":
                return f"`{named}[{index}]`: an element of an array is named by a number from 0, or `[*]` for every one"
            if index.isdigit() and isinstance(size, int) and current.get("minItems") == size and int(index) >= size:
                return f"`{named}` has elements 0 to {size - 1} where the signal indexes it, not {index}"
            current = current.get("items")
            named += f"[{index}]"
    return None


def _kind(kind: Any) -> str:
    """A JSON schema's `type` in words."""
    return {
        "object": "a struct",
        "array": "an array",
        "number": "a number",
        "integer": "a whole number",
        "boolean": "a Boolean",
        "string": "text",
    }.get(str(kind), "no struct")


def _present(schema: Any) -> Any:
    """An optional field's schema when present (`anyOf: [T, null]`, as earlier traces wrote it, gives T)."""
    if isinstance(schema, dict) and isinstance(schema.get("anyOf"), list):
        present = [option for option in schema["anyOf"] if isinstance(option, dict) and option.get("type") != "null"]
        if len(present) == 1:
            return present[0]
    return schema
