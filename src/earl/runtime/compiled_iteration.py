"""One whole iteration of one subsystem in one FSM state, compiled into one Python function.

`bb.execute()` of Figure 5b is five steps (docs/semantics.md): `tf.execute()`, send the
output buffers written, count the iteration, receive the input buffers, and test the
error and terminal conditions. `SubsystemEngine` keeps each step as a method, for the
rare paths (a wait for an obligatory buffer, a timeout, a fault). This module writes the
common path of one state out as straight-line code, as `iteration.py` does for
`tf.execute()`: which output buffer goes to which input buffer, which links are recorded,
which input buffers the state waits for and what its terminal condition is are all known
once the state is entered, and a subsystem iterates hundreds of times a second.

What the generated `iterate(time)` does, in the order of the engine's methods:

1. `execute(time)`, the state's compiled `tf.execute()`;
2. every buffer it wrote goes to each of its links: an input buffer that keeps its latest
   message is written in place, any other through its channel's `deliver`; the link's
   recorder (the trace) gets it if it records that link; a subsystem waiting for it is told;
3. the iteration is counted; if an obligatory input buffer is still empty, it returns False
   (the scheduler waits; `receive` and `decide` are then the engine's own);
4. each input buffer takes what arrived (the engine's `receive` when a timeout or a stale
   link is involved, or a FIFO that reports overflows);
5. the terminal condition is evaluated; the engine's `decide` runs only when it holds, when
   the behaviour has an error condition, or after a fault, and does the rest (Figure 5a).

Names from the spec enter the generated text only as string literals written by `repr`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from earl.runtime.channels import Channel
from earl.runtime.codegen import generated_function
from earl.runtime.iteration import compile_execute

if TYPE_CHECKING:
    from earl.runtime.engine import StateRuntime, SubsystemEngine

#: `iterate(time)`: one iteration; False when it stopped to wait for an obligatory input buffer
Iterate = Callable[[int], bool]
#: `complete(time)`: receive and decide, after a wait that ended with every obligatory buffer filled
Completion = Callable[[int], None]


def compile_iteration(engine: SubsystemEngine, state: StateRuntime) -> Iterate:
    """The iteration of `engine` while it is in `state`."""
    behaviour = state.behaviour
    if behaviour.execute is None:
        behaviour.execute = compile_execute(
            behaviour.stages, engine.memory, engine.context, engine._function_fault, engine._function_returned
        )
    namespace = {**_steps_4_and_5(engine, state), "execute": behaviour.execute}
    lines = [
        "def iterate(time):",
        "    engine.iteration_start = time",
        "    engine._error_in_iteration = False",
        "    sent = execute(time)",
    ]
    lines += _sends(engine, namespace)
    lines += ["    engine.iteration += 1", "    engine.total_iterations += 1"]
    lines += _obligatory(engine, state, namespace)
    if _keeps_predicate_values(engine):
        lines.append("    engine.predicate_values.clear()")  # the memory changed
    lines += _receives(engine, namespace)
    lines += _decision(behaviour.never_ends, behaviour.error_condition is not None)
    lines.append("    return True")
    return generated_function("iterate", lines, namespace)  # type: ignore[return-value]


def compile_completion(engine: SubsystemEngine, state: StateRuntime) -> Completion:
    """Steps 4 and 5 of `engine` in `state`, once the obligatory input buffers it waited for are all filled.

    The scheduler calls it when the last of them arrives (not when the wait timed out: then the
    engine's own `receive` sets the timeout flags). A control subsystem that waits for its drives'
    readings every period (`manip/a.cs`) ends every iteration here.
    """
    behaviour = state.behaviour
    namespace = _steps_4_and_5(engine, state)
    lines = ["def complete(time):"]
    if _keeps_predicate_values(engine):
        lines.append("    engine.predicate_values.clear()")
    lines += _receives(engine, namespace)
    lines += _decision(behaviour.never_ends, behaviour.error_condition is not None)
    return generated_function("complete", lines, namespace)  # type: ignore[return-value]


def _keeps_predicate_values(engine: SubsystemEngine) -> bool:
    """Whether some predicate values of `engine` are kept for one decision: those computed by Python, and those
    a condition would otherwise compute many times over (earl.runtime.predicates.repeatedly_evaluated)."""
    return engine.keeps_predicate_values


def _steps_4_and_5(engine: SubsystemEngine, state: StateRuntime) -> dict[str, Any]:
    """What receiving and deciding read: the engine's dictionaries, its own methods for the rare paths."""
    return {
        "engine": engine,
        "inputs": engine.inputs,
        "new_data": engine.new_data,
        "timed_out": engine.timed_out,
        "memory": engine.memory,
        "predicates": engine.predicates,
        "stale": engine.stale,
        "receive": engine.receive,
        "decide": engine.decide,
        "terminal_condition": state.behaviour.terminal_condition,
        "Exception": Exception,
    }


def _sends(engine: SubsystemEngine, namespace: dict[str, Any]) -> list[str]:
    """Step 2: each written output buffer to its links, in the order the functions wrote them."""
    branches: list[str] = []
    route = 0
    for key, destinations in engine.destinations.items():
        body: list[str] = []
        for destination in destinations:
            n = route
            route += 1
            channel = destination.channel
            if isinstance(channel, Channel) and channel.capacity is None:
                # the latest message only: a message not yet received is replaced by the newer one
                namespace[f"queue_{n}"] = channel.queue
                body += [f"q = queue_{n}", "if q:", "    q[0] = value", "else:", "    q.append(value)"]
            else:  # a FIFO, or a link to another process
                namespace[f"deliver_{n}"] = channel.deliver
                body.append(f"deliver_{n}(value)")
            writer = engine.recorder.message_writer(destination.link)
            if writer is not None:
                namespace[f"record_{n}"] = writer
                body.append(f"record_{n}(time, value)")
            if destination.engine is not None:
                namespace[f"receiver_{n}"] = destination.engine
                body += [
                    f"if receiver_{n}.waiting and receiver_{n}.on_delivery is not None:",
                    f"    receiver_{n}.on_delivery(receiver_{n})",
                ]
        if body:
            keyword = "if" if not branches else "elif"
            branches.append(f"            {keyword} key == {key!r}:")
            branches += [f"                {line}" for line in body]
    if not branches:
        return []
    return ["    if sent:", "        for key, value in sent.items():", *branches]


def _obligatory(engine: SubsystemEngine, state: StateRuntime, namespace: dict[str, Any]) -> list[str]:
    """Step 3's end: stop here while an obligatory input buffer is empty."""
    if not state.obligatory:
        return []
    tests = []
    for position, key in enumerate(state.obligatory):
        namespace[f"obligatory_{position}"] = engine.channels[key].queue
        tests.append(f"not obligatory_{position}")
    return [f"    if {' or '.join(tests)}:", "        return False"]


def _receives(engine: SubsystemEngine, namespace: dict[str, Any]) -> list[str]:
    """Step 4, `receive()` written out for the input buffers of this engine."""
    channels = engine.channels
    if not channels:
        return ["    if engine._timeouts_set or stale:", "        receive(time)"]
    if any(channel.capacity is not None and channel.overflow == "fault" for channel in channels.values()):
        return ["    receive(time)"]  # a FIFO whose overflow is a fault: the engine reports it
    lines = ["    if engine._timeouts_set or stale:", "        receive(time)", "    else:"]
    for position, (key, channel) in enumerate(channels.items()):
        namespace[f"arrived_{position}"] = channel.queue
        lines += [
            f"        q = arrived_{position}",
            "        if q:",
            f"            inputs[{key!r}] = q.popleft()",
            f"            new_data[{key!r}] = True",
            f"        elif new_data[{key!r}]:",
            f"            new_data[{key!r}] = False",
        ]
    return lines


def _decision(never_ends: bool, has_error_condition: bool) -> list[str]:
    """Step 5: only a terminal condition that holds (or a fault, or an error condition) needs `decide()`."""
    lines = ["    if engine._error_in_iteration:", "        decide(time)"]
    if never_ends:
        return lines
    if has_error_condition:
        return [*lines, "    else:", "        decide(time)"]
    # evaluated again by decide() when it holds or raised: a predicate has no side effects, and
    # decide() reports the failure
    return [
        *lines,
        "    else:",
        "        try:",
        "            terminal = terminal_condition(inputs, new_data, timed_out, memory, predicates)",
        "        except (KeyboardInterrupt, SystemExit):",
        "            raise",
        "        except BaseException:",
        "            terminal = True",
        "        if terminal:",
        "            decide(time)",
    ]
