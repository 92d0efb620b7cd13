"""`tf.execute()` of one basic behaviour, compiled into one straight-line Python function.

The transition function runs its stages in order; the partial transition functions of a
stage run as if in parallel, on one snapshot of buffers and memory (Eq. 4–8 of the manual,
docs/semantics.md). What that means for one call:

1. copy the declared reads into the function's `inputs`;
2. call `function(inputs, outputs, context)`; what it returns is ignored (anything but None is a
   `return-value` fault, said once per function: its writes go through `outputs`);
3. check what it set on `outputs` against its declared writes and their types;
4. a stage of one function writes memory at once; a stage of several collects the writes and
   applies them when the stage ends, so that no function sees another's;
5. a function that raised writes nothing, and the fault is reported (the behaviour's error
   condition becomes true).

The function is generated, not a loop over the stages, because it is the innermost work of
every iteration of every subsystem: the loop's own bookkeeping (unpacking, branching on the
stage's size, looking up each written name) cost as much as the light functions it called.
Names from the spec enter the generated text only as string literals written by `repr`;
every function, view and dictionary is passed in as a numbered variable.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

from earl.model.location import SourceLocation
from earl.runtime.binding import UserFunction
from earl.runtime.codegen import generated_function
from earl.runtime.values import QUICK_TEST_NAMES, QuickTest
from earl.runtime.views import Context, Inputs, Outputs

#: `execute(time)`: runs the stages; returns what the iteration sends, by output buffer, or None
Execute = Callable[[int], "dict[str, Any] | None"]


class Call(Protocol):
    """One partial transition function as a stage holds it."""

    @property
    def name(self) -> str: ...
    @property
    def function(self) -> UserFunction: ...
    @property
    def inputs(self) -> Inputs: ...
    @property
    def outputs(self) -> Outputs: ...
    @property
    def location(self) -> SourceLocation | None: ...


def compile_execute(
    stages: Sequence[Sequence[Call]],
    memory: dict[str, Any],
    context: Context,
    fault: Callable[[int, str, Exception], None],
    returned: Callable[[int, Call, object], None],
) -> Execute:
    """The behaviour's `tf.execute()`; `fault(time, function, error)` is told of a call that raised, and
    `returned(time, call, value)` of one that returned something other than None (which is ignored)."""
    namespace: dict[str, Any] = {
        "memory": memory,
        "context": context,
        "fault": fault,
        "returned": returned,
        "Exception": Exception,
        "MISSING": _MISSING,
        # what the quick tests use, and the builtins, as closure variables (see below)
        **QUICK_TEST_NAMES,
        **{builtin.__name__: builtin for builtin in (next, iter)},
    }
    # `sent` is made only when something is sent; a stage's own dictionary is made once and reused
    lines = ["def execute(time):", "    sent = None"]
    number = 0
    for position, stage in enumerate(stages):
        single = len(stage) == 1
        # one function alone in its stage writes memory at once: there is nobody to isolate
        target = "memory" if single else f"stage_{position}"
        if not single:
            namespace[target] = {}
        for call in stage:
            n = number
            number += 1
            lines += _call(n, call, target, namespace)
        if not single:
            # the stage's writes become visible only now: no function saw another's (Eq. 7-8)
            lines += [f"    if {target}:", f"        memory.update({target})", f"        {target}.clear()"]
    lines.append("    return sent")
    return generated_function("execute", lines, namespace)  # type: ignore[return-value]


class _Missing:
    """Not written by the call (None is a value a function may write)."""


_MISSING = _Missing()


def _call(n: int, call: Call, target: str, namespace: dict[str, Any]) -> list[str]:
    """The lines of one call: refresh, call, take and check what it set, then apply it (or the fault)."""
    outputs = call.outputs
    writes = outputs._earl_single_writes()
    namespace.update(
        {
            f"function_{n}": call.function,
            f"inputs_{n}": call.inputs,
            f"outputs_{n}": outputs,
            f"set_{n}": outputs.__dict__,
            f"refuse_{n}": outputs._earl_refuse,
            f"clear_{n}": outputs._earl_clear,
            f"written_{n}": outputs._earl_memory_written,
            f"sends_{n}": outputs._earl_sent,
            f"name_{n}": call.name,
            f"call_{n}": call,
        }
    )
    values = [f"value_{n}_{position}" for position in range(len(writes))]
    # step 1, written out: each declared read copied into the view (what Inputs._earl_refresh does)
    lines = []
    for name, store, key in call.inputs._earl_singles:
        lines.append(f"    reads_{n}[{name!r}] = {_store_name(store, namespace)}[{key!r}]")
    namespace[f"reads_{n}"] = call.inputs.__dict__
    lines += [
        "    try:",
        f"        result_{n} = function_{n}(inputs_{n}, outputs_{n}, context)",
    ]
    if writes:
        lines.append(f"        if set_{n}:")
        # what the call set, each by its declared name; anything left over was not declared
        for value, (attribute, _) in zip(values, writes, strict=True):
            lines.append(f"            {value} = set_{n}.pop({attribute!r}, MISSING)")
        lines += [f"            if set_{n}:", f"                refuse_{n}(next(iter(set_{n})))"]
        for position, (value, (_, write)) in enumerate(zip(values, writes, strict=True)):
            coerce = f"coerce_{n}_{position}"
            namespace[coerce] = write.coerce
            lines += [f"            if {value} is not MISSING:"]
            lines += [f"                {line}" for line in _checked(value, coerce, write.quick)]
        lines += ["        else:", f"            {' = '.join(values)} = MISSING"]
    else:
        lines += [f"        if set_{n}:", f"            refuse_{n}(next(iter(set_{n})))"]
    lines += [
        # any exception of the function is its fault (a BaseException subclass too), but an interruption
        # or sys.exit() ends the run
        "    except (KeyboardInterrupt, SystemExit):",
        "        raise",
        "    except BaseException as error:",
        f"        clear_{n}()",
        f"        fault(time, name_{n}, error)",
        "    else:",
        # a function that returns its outputs (`return {"x": 1}`) expects them written: it is told, once
        f"        if result_{n} is not None:",
        f"            returned(time, call_{n}, result_{n})",
        # writes by family member or by `outputs["x/mo"]` first, so that a later attribute write wins
        f"        if written_{n}:",
        f"            {target}.update(written_{n})",
        f"            written_{n}.clear()",
        f"        if sends_{n}:",
        "            if sent is None:",
        "                sent = {}",
        f"            sent.update(sends_{n})",
        f"            sends_{n}.clear()",
    ]
    for value, (_, write) in zip(values, writes, strict=True):
        lines.append(f"        if {value} is not MISSING:")
        if write.is_memory:
            lines.append(f"            {target}[{write.key!r}] = {value}")
        else:
            lines += [
                "            if sent is None:",
                "                sent = {}",
                f"            sent[{write.key!r}] = {value}",
            ]
    return lines


def _store_name(store: dict[str, Any], namespace: dict[str, Any]) -> str:
    """The variable holding one dictionary the reads come from (the engine's input buffers, its memory)."""
    for name, known in namespace.items():
        if name.startswith("store_") and known is store:
            return name
    name = f"store_{sum(1 for known in namespace if known.startswith('store_'))}"
    namespace[name] = store
    return name


def _checked(value: str, coerce: str, quick: QuickTest | None) -> list[str]:
    """Lines leaving `value` checked: the type's quick test inline, its full coercer only when it fails."""
    return [f"{value} = {coerce}({value})"] if quick is None else quick.lines(value, coerce)
