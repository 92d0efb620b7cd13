"""One subsystem at run time: Figure 5 of the manual, to the letter (docs/semantics.md).

`bb.execute()` is one iteration, `iterate()` here, compiled per FSM state by
earl/runtime/compiled_iteration.py from the methods below:

    1. tf.execute(): the stages in order, the functions of a stage on one snapshot
       (Eq. 4–8), compiled per behaviour by earl/runtime/iteration.py
    2. tf.pf.ob.send(): every output buffer written this iteration
    3. iterationNumber += 1
    4. tf.pf.ib.receive()
    5. ec.fun, then tc.fun; when either holds, fsm.selectState() enters the next
       state's behaviour (iterationNumber = 0)

When the state has an obligatory input buffer that is still empty after step 3,
`iterate()` stops there and the scheduler waits for the message (or the timeout)
before it calls `receive()` and `decide()`.

A scheduler (virtual or real time) decides when each iteration runs.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from earl.model.location import SourceLocation
from earl.runtime.binding import UserFunction
from earl.runtime.channels import Channel
from earl.runtime.compiled_iteration import Completion, Iterate, compile_completion, compile_iteration
from earl.runtime.events import Fault, Recorder, TransitionName
from earl.runtime.iteration import Call, Execute
from earl.runtime.predicates import CompiledPredicate, absent_read
from earl.runtime.values import ValueTypeError
from earl.runtime.views import Context, Inputs, Outputs, UndeclaredAccess, explain


@dataclass
class FunctionRuntime:
    """A bound partial transition function with the views it is called with."""

    name: str
    function: UserFunction
    inputs: Inputs
    outputs: Outputs
    #: the spec line declaring it, named when it misbehaves in a way the spec line explains (a result returned)
    location: SourceLocation | None = None


@dataclass
class BehaviourRuntime:
    name: str
    stages: list[list[FunctionRuntime]]
    terminal_condition: CompiledPredicate
    error_condition: CompiledPredicate | None
    #: the output buffers some function of this behaviour may write (in send order)
    outputs: list[str] = field(default_factory=list)
    #: its terminal condition is the constant false and it has no error condition
    never_ends: bool = False
    #: `tf.execute()` compiled for the engine that runs it (earl/runtime/iteration.py)
    execute: Execute | None = None


@dataclass
class TransitionRuntime:
    #: `idle,jointMove`; its `declared` is `*,jointMove` for a transition a `*` line stands for
    name: TransitionName
    destination: str
    condition: CompiledPredicate

    @property
    def condition_named(self) -> str:
        """`the condition of `idle,stop/t``, or of `*,stop/t` (from `idle`) as the checker says a `*` line's."""
        name = self.name
        declared = getattr(name, "declared", name)
        if declared != name:
            return f"the condition of `{declared}/t` (from `{name.split(',', 1)[0]}`)"
        return f"the condition of `{name}/t`"


@dataclass
class StateRuntime:
    name: str
    behaviour: BehaviourRuntime
    obligatory: list[str]
    timeout: int | None  # nanoseconds
    #: leaving transitions, highest priority first, then in declaration order
    transitions: list[TransitionRuntime]
    #: one whole iteration in this state, compiled at its first use
    iterate: Iterate | None = None
    #: receive and decide after a wait for the obligatory buffers, compiled at its first use
    complete: Completion | None = None
    #: the queues of the obligatory input buffers' channels, found at the first wait
    obligatory_queues: tuple[Any, ...] | None = None
    #: where the spec declares the state, named when its waits never let run time pass
    location: SourceLocation | None = None


class Sink(Protocol):
    """What a send hands a message to: a local input buffer's `Channel`, or a remote link's publisher."""

    def deliver(self, value: Any) -> None: ...


@dataclass
class Destination:
    """Where an output buffer's messages go: an input buffer's channel, and the engine that owns it.

    A link whose input buffer runs in another process has no local engine (`None`) and a
    transport's sink for a channel (docs/distributed.md).
    """

    link: str
    channel: Channel | Sink
    engine: SubsystemEngine | None
    buffer: str


class SubsystemEngine:
    """The run-time state of one subsystem: buffers, memory, the FSM and the running behaviour."""

    def __init__(
        self,
        name: str,
        order: int,
        period: int | None,
        context: Context,
        recorder: Recorder,
    ) -> None:
        self.name = name
        #: position in the deterministic order in which subsystems due at one instant run
        self.order = order
        self.period = period
        self.context = context
        context._engine = self
        self.recorder = recorder
        self.inputs: dict[str, Any] = {}
        self.new_data: dict[str, bool] = {}
        self.timed_out: dict[str, bool] = {}
        self.channels: dict[str, Channel] = {}
        self.memory: dict[str, Any] = {}
        self.destinations: dict[str, list[Destination]] = {}
        self.predicates: dict[str, CompiledPredicate] = {}
        #: what each predicate computed by Python returned (or raised) since the input buffers last took
        #: what arrived: one call per predicate per decision, however many conditions name it; and the
        #: values of predicates that conditions would otherwise compute many times over
        self.predicate_values: dict[str, bool | BaseException] = {}
        #: whether `predicate_values` is used at all (emptied before each decision then)
        self.keeps_predicate_values = False
        self.states: dict[str, StateRuntime] = {}
        self.state: StateRuntime | None = None
        self.iteration = 0
        self.total_iterations = 0
        self.faults = 0
        #: partial transition functions already told that what they return is ignored (once each)
        self._returned: set[str] = set()
        self._error_in_iteration = False
        self._stuck = False
        self._timeouts_set = False
        #: input buffers whose remote sender is gone (docs/distributed.md): `stale(x/ib)` and
        #: `timeout(x/ib)` read true; changed in place only (predicates hold this very set)
        self.stale: set[str] = set()
        #: set by the scheduler: called when a message reaches an obligatory buffer this engine waits for
        self.on_delivery: Callable[[SubsystemEngine], None] | None = None
        self.waiting = False
        self.iteration_start = 0
        #: one whole iteration in the current state (earl/runtime/compiled_iteration.py); set by `start`
        self.iterate: Iterate = self._not_started

    def _not_started(self, time: int) -> bool:
        raise RuntimeError(f"{self.name} has not started: its FSM has no state yet")

    # ------------------------------------------------------------------ set-up
    def start(self, initial: str, time: int) -> None:
        """`fsm.run()` begins in the initial state `ifs`."""
        self.state = self.states[initial]
        self.iterate = self._iteration_of(self.state)
        self.iteration = 0
        # no transition led here: `*,idle` would name an any-source transition the spec may not have
        self.recorder.state_changed(time, self.name, None, initial, None)
        self.recorder.behaviour_started(time, self.name, initial, self.state.behaviour.name)

    def prepare(self) -> None:
        """Generate every state's code now rather than at its first iteration: a real-time run does it
        before its clock starts, so that no first iteration starts late by the time it took."""
        for state in self.states.values():
            if state.iterate is None:
                state.iterate = compile_iteration(self, state)
            if state.complete is None and state.obligatory:
                state.complete = compile_completion(self, state)

    # ------------------------------------------------------------------ Figure 5b, steps 1-5
    def _iteration_of(self, state: StateRuntime) -> Iterate:
        """`iterate(time)` while in `state`: one whole iteration (steps 1-5), compiled at its first use.

        It returns False after step 3 when an obligatory input buffer is empty: the scheduler then
        waits for it (or its timeout) and calls `receive` and `decide` itself.
        """
        if state.iterate is not None:
            return state.iterate

        def first(time: int) -> bool:
            # compiled when first run rather than when built: the scheduler and the transport have
            # set up links, recorders and waits by then
            state.iterate = compile_iteration(self, state)
            if self.state is state:
                self.iterate = state.iterate
            return state.iterate(time)

        return first

    def _function_fault(self, time: int, function: str, raised: BaseException) -> None:
        error = explain(raised)
        if isinstance(error, UndeclaredAccess):
            kind = "undeclared-write" if error.write else "undeclared-read"
        elif isinstance(error, ValueTypeError):
            kind = "type"
        else:
            kind = "exception"
        trace = _user_traceback(raised)
        if kind == "type":  # raised by earl as the function wrote: the function itself raised nothing
            said = f"`{function}/pf` wrote a value of the wrong type: {error}"
        else:
            said = f"`{function}/pf` raised {exception_text(error)}"
        self.report_fault(time, kind, said, function, trace)
        # Faults section of docs/semantics.md: the behaviour's error condition becomes true
        self._error_in_iteration = True

    def _function_returned(self, time: int, call: Call, value: object) -> None:
        """A partial transition function returned something other than None: what it returns is ignored (docs/
        runtime.md), so a function written as `return {"x": 1}` writes nothing. Said once per function: the same
        code returns the same kind of thing at every call, and its writes through `outputs` still count."""
        name = call.name
        if name in self._returned:
            return
        self._returned.add(name)
        location = call.location
        # the file's name: a whole path would bury what the message says
        where = f" ({Path(location.file).name}:{location.line})" if location is not None else ""
        written = call.outputs.__dir__()
        example = f"outputs.{written[0]} = …" if written else "outputs.NAME = …"
        self.report_fault(
            time,
            "return-value",
            f"`{name}/pf`{where} returned {shown(value)}, which is ignored: a partial transition function "
            f"writes its outputs through its second parameter (`{example}`) and returns None",
            name,
        )

    def report_fault(self, time: int, kind: str, message: str, function: str = "", trace: str = "") -> None:
        self.faults += 1
        state = self.state
        self.recorder.fault(
            Fault.at(
                time,
                self.name,
                kind,
                message,
                state=state.name if state else "",
                behaviour=state.behaviour.name if state else "",
                function=function,
                traceback=trace,
            )
        )

    def complete(self, time: int) -> None:
        """Steps 4 and 5 after a wait that ended with every obligatory input buffer filled."""
        state = self.state
        assert state is not None
        complete = state.complete
        if complete is None:
            complete = state.complete = compile_completion(self, state)
        complete(time)

    # ------------------------------------------------------------------ Figure 5b, step 4
    def obligatory_ready(self) -> bool:
        """Every obligatory input buffer of the state has a message (asked at each delivery while waiting)."""
        state = self.state
        assert state is not None
        queues = state.obligatory_queues
        if queues is None:
            queues = state.obligatory_queues = tuple(self.channels[key].queue for key in state.obligatory)
        return all(queues)

    def receive(self, time: int, timed_out: bool = False) -> None:
        """`tf.pf.ib.receive()`: every input buffer takes what arrived; obligatory ones not filled time out."""
        state = self.state
        assert state is not None
        self.predicate_values.clear()
        inputs = self.inputs
        new_data = self.new_data
        for key, channel in self.channels.items():
            queue = channel.queue
            if queue:
                inputs[key] = queue.popleft()
                new_data[key] = True
                # a FIFO can only have overflowed when something arrived
                if channel.overflowed:
                    channel.overflowed = False
                    since, channel.reported = channel.dropped - channel.reported, channel.dropped
                    self.report_fault(
                        time,
                        "overflow",
                        f"the FIFO of `{key}/ib` overflowed: {since} dropped since the last receive, "
                        f"{channel.dropped} in all",
                    )
            elif new_data[key]:
                new_data[key] = False
        if state.obligatory or self._timeouts_set:
            flags = self.timed_out
            obligatory = state.obligatory
            any_set = False
            for key in flags:
                flag = flags[key] = timed_out and key in obligatory and not new_data[key]
                any_set = any_set or flag
            self._timeouts_set = any_set
        if self.stale:
            # a stale buffer also reads as timed out until its sender returns; `stale(x/ib)` tells it apart.
            # One that took a message now did not time out (a message can come before the sender's
            # liveliness is known): `timeout(x/ib)` never holds with `newData(x/ib)`.
            for key in self.stale:
                self.timed_out[key] = not new_data[key]
            self._timeouts_set = True

    # ------------------------------------------------------------------ Figure 5b, step 5 and Figure 5a
    def _evaluate(self, time: int, predicate: CompiledPredicate, what: str | TransitionRuntime) -> bool:
        """`predicate`'s value, false when it fails (a fault naming `what`: a transition's condition is named
        only then)."""
        try:
            return bool(predicate(self.inputs, self.new_data, self.timed_out, self.memory, self.predicates))
        except (KeyboardInterrupt, SystemExit):
            raise
        except PredicateFailedBefore:
            return False
        except BaseException as raised:  # a Python predicate's own exception class may derive from BaseException
            said = what.condition_named if isinstance(what, TransitionRuntime) else what
            self._condition_failed(time, said, raised)
            return False

    def _condition_failed(self, time: int, what: str, raised: BaseException) -> None:
        """A condition could not be evaluated: a `predicate` fault, and the condition counts as false."""
        trace = ""
        if isinstance(raised, PredicateFault):  # a Python predicate's own failure, which names it
            said = f"evaluating {what}{raised.said}"
            trace = raised.trace
        else:
            inside = _predicate_raising(raised)
            where = f" in `{inside}`" if inside and inside not in what else ""
            absent = absent_read(raised)  # in EARL's words rather than Python's, when it can be said
            if absent is not None:
                said = f"evaluating {what}{where}: {absent}"
            else:
                said = f"evaluating {what} raised {exception_text(explain(raised))}{where}"
        self.report_fault(time, "predicate", said, trace=trace)
        self._failure_recorded(raised)

    def _failure_recorded(self, raised: BaseException) -> None:
        """A Python predicate that raised is asked again in the same decision (a `tc` and a transition naming
        it) as false, without a second fault for the one failure."""
        values = self.predicate_values
        for name, value in values.items():
            if value is raised:
                values[name] = PredicateFailedBefore(name)

    def decide(self, time: int) -> None:
        """Test `ec` then `tc`; when either holds, `fsm.selectState()`."""
        state = self.state
        assert state is not None
        behaviour = state.behaviour
        error = self._error_in_iteration
        if not error and behaviour.never_ends:
            return  # `tc = false/pp` and no `ec`: nothing to evaluate (a deliberate sink state)
        if not error and behaviour.error_condition is not None:
            error = self._evaluate(time, behaviour.error_condition, f"the error condition of `{behaviour.name}/bb`")
        if error:
            reason = "error"
        else:
            # inline rather than through _evaluate: its message is built only when something fails
            try:
                terminal = behaviour.terminal_condition(
                    self.inputs, self.new_data, self.timed_out, self.memory, self.predicates
                )
            except (KeyboardInterrupt, SystemExit):
                raise
            except PredicateFailedBefore:
                terminal = False
            except BaseException as raised:
                self._condition_failed(time, f"the terminal condition of `{behaviour.name}/bb`", raised)
                terminal = False
            if not terminal:
                return
            reason = "terminal"
        for transition in state.transitions:
            if self._evaluate(time, transition.condition, transition):
                self._enter(time, transition, reason)
                return
        if not self._stuck:
            # docs/semantics.md, "No transition holds": stay, go on iterating, try again after each iteration
            self._stuck = True
            self.report_fault(
                time,
                "no-transition",
                f"`{behaviour.name}/bb` stopped ({reason} condition) in state `{state.name}` but no transition "
                "out of it holds; the subsystem stays in the state and tries again after every iteration",
            )

    def _enter(self, time: int, transition: TransitionRuntime, reason: str) -> None:
        state = self.state
        assert state is not None
        self.recorder.behaviour_stopped(time, self.name, state.name, state.behaviour.name, self.iteration, reason)
        self.recorder.state_changed(time, self.name, state.name, transition.destination, transition.name)
        self.state = self.states[transition.destination]
        self.iterate = self._iteration_of(self.state)
        self.iteration = 0
        self._stuck = False
        self.recorder.behaviour_started(time, self.name, self.state.name, self.state.behaviour.name)

    def snapshot(self) -> dict[str, Any]:
        return dict(self.memory)


class PredicateFault(Exception):
    """What a primitive predicate computed by Python raises when it raised or gave no Boolean: it names the
    predicate, which the condition's fault then reports. `_predicate_raising` cannot find it: the frames
    of a Python predicate are no compiled predicate's, so an exception of its code would be blamed on the
    compiled predicate that asked for it (`sensorLost/pp = … or tooFar/pp`)."""

    def __init__(self, predicate: str, said: str, trace: str = "") -> None:
        super().__init__(f"`{predicate}/pp`{said}")
        self.predicate = predicate
        #: the fault's message after `evaluating the terminal condition of `b/bb``
        self.said = said
        #: the traceback of the predicate's code, from its own frames down, when it raised
        self.trace = trace

    @classmethod
    def raised(cls, predicate: str, error: BaseException) -> PredicateFault:
        """The fault of a predicate whose code raised `error`."""
        return cls(predicate, f" raised {exception_text(explain(error))} in `{predicate}/pp`", _user_traceback(error))


class PredicateFailedBefore(Exception):
    """What a Python primitive predicate raises when asked again in the decision where it raised and its
    fault was recorded: the condition is false again, without a second fault for one failure (an `ec`
    and a `tc` naming one predicate made two)."""


def _predicate_raising(error: BaseException) -> str | None:
    """`stopRequested/pp`: the innermost compiled primitive predicate the error passed through (its code is
    named `<earl predicate SUBSYSTEM NAME/pp>`), so that a condition's fault names the predicate at fault."""
    found = None
    trace = error.__traceback__
    while trace is not None:
        filename = trace.tb_frame.f_code.co_filename
        if filename.startswith("<earl predicate ") and filename.endswith("/pp>"):
            found = filename[:-1].rsplit(" ", 1)[-1]
        trace = trace.tb_next
    return found


def shown(value: object) -> str:
    """`a dict ({'position': [0.3, 0.3]})`: what a function returned, kept short, whatever its `__repr__` does."""
    if value is None:
        return "None"
    try:
        text = repr(value)
    except BaseException:  # the spec's own class, misbehaving: its type is enough
        text = ""
    if len(text) > 60:
        text = text[:57] + "..."
    kind = type(value).__name__
    article = "an" if kind[:1].lower() in "aeiou" else "a"
    return f"{article} {kind} ({text})" if text else f"{article} {kind}"


def exception_text(error: BaseException) -> str:
    """`OSError: no such device`: the class and message of an exception of the spec's code, even when its
    `__str__` raises or returns no string (the fault must be recorded whatever the class does)."""
    try:
        message = str(error)
    except BaseException:  # anything at all: this is the spec's code misbehaving
        message = "(its message cannot be shown: its __str__ failed)"
    return f"{type(error).__name__}: {message}"


def _user_traceback(error: BaseException) -> str:
    """The traceback of a function's error from its own code down, without the runtime's frames.

    A value of the wrong type or an undeclared name set on `outputs` is found by the runtime
    after the call returned: such an error has no frame of user code, and gets no traceback
    (its message names the function and the write).
    """
    try:
        frames = traceback.extract_tb(error.__traceback__)
        user = [frame for frame in frames if not _is_runtime_frame(frame.filename)]
        if not user:
            return ""
        lines = ["Traceback (most recent call last):\n", *traceback.format_list(user)]
        return "".join(lines + traceback.format_exception_only(type(error), error))
    except Exception:  # an exception class of the spec's code that breaks `__traceback__`: no traceback then
        return ""


def _is_runtime_frame(filename: str) -> bool:
    return filename == "<string>" or filename.startswith(_RUNTIME_DIRECTORY)


#: earl's runtime package: its frames (and the generated `execute`) are not the user's
_RUNTIME_DIRECTORY = str(Path(__file__).resolve().parent)
