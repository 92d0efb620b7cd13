"""What a run reports as it goes: state changes, behaviours, messages, memory, faults.

The engine reports to a `Recorder`; the MCAP trace writer is one, the run summary
another.  Times are integer nanoseconds of run time (simulated or wall), but for a `Fault`, which the
Python API hands out (`Simulation.faults`): its `time` is seconds, as the API's other times are, and
its `time_ns` the exact nanoseconds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

#: records one message of one link: `write(time, value)`
MessageWriter = Callable[[int, Any], None]


class TransitionName(str):
    """A transition's name, `idle,stop`, as recorders are given it, that also says how the spec declares
    it: `declared` is `*,stop` for one of the transitions a `* -> stop` line stands for, and the name itself
    otherwise. A str, so that a recorder written before it sees the name it always did."""

    declared: str

    def __new__(cls, name: str, declared: str | None = None) -> TransitionName:
        made = super().__new__(cls, name)
        made.declared = name if declared is None else declared
        return made


@dataclass
class Fault:
    """Something went wrong in a subsystem; the run goes on (docs/semantics.md, "Faults";
    docs/python-api.md, "Faults", says each field)."""

    #: seconds of run time, as `Simulation.time` counts it: the `context.time` of the iteration it happened in
    time: float
    #: the subsystem it happened in, `sorter/a.cs`
    subsystem: str
    #: "exception" | "undeclared-write" | "undeclared-read" | "type" | "return-value" | "predicate" |
    #: "no-transition" | "overflow" | "deadline" | "zero-time-loop" (which ends the run)
    kind: str
    message: str
    #: the FSM state and its behaviour the subsystem was in ("" before its FSM started)
    state: str = ""
    behaviour: str = ""
    #: the partial transition function (or Python predicate) at fault, `classify` ("" for none)
    function: str = ""
    #: the traceback of the spec's own code that raised, earl's frames left out ("" for none)
    traceback: str = ""
    #: the same instant as `time` in whole nanoseconds, exact: what the trace stamps the fault with
    #: (the run's events count nanoseconds, as the trace does); from `time` when not given
    time_ns: int = field(default=-1, repr=False)

    def __post_init__(self) -> None:
        if self.time_ns < 0:
            self.time_ns = round(self.time * 1_000_000_000)

    @classmethod
    def at(cls, time_ns: int, subsystem: str, kind: str, message: str, **rest: str) -> Fault:
        """A fault at `time_ns` nanoseconds of run time (how the engine counts it)."""
        # as a function's `context.time` is computed: the fault of a function has the time it was called at
        return cls(float(time_ns * 1e-9), subsystem, kind, message, time_ns=time_ns, **rest)


@dataclass
class SubsystemStatistics:
    """Per subsystem: iterations, time in each state, transitions taken, faults (for the summary table)."""

    iterations: int = 0
    state_time: dict[str, int] = field(default_factory=dict)
    transitions: dict[str, int] = field(default_factory=dict)
    faults: int = 0
    state: str = ""
    entered: int = 0


class Recorder:
    """Receives the events of a run; this base class ignores them all.

    `state_changed` gives the transition's name (`idle,move`), a `TransitionName` whose `declared` is
    `*,move` when a `* -> move` line was taken; the entry into the initial state, when the FSM starts,
    has neither a source state nor a transition (None, None)."""

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        pass

    def behaviour_started(self, time: int, subsystem: str, state: str, behaviour: str) -> None:
        pass

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        pass

    def message_sent(self, time: int, link: str, value: Any) -> None:
        pass

    def message_writer(self, link: str) -> MessageWriter | None:
        """What records each message sent on `link`, or None if nothing would.

        The engine asks once per link, when it compiles the iteration that sends on it, and then
        calls the writer for every message: messages are the most frequent event of a run, and
        a link that nobody records then costs nothing per message. This default calls
        `message_sent`, if the recorder has one of its own.
        """
        if type(self).message_sent is Recorder.message_sent:
            return None
        sent = self.message_sent
        return lambda time, value: sent(time, link, value)

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        pass

    def fault(self, fault: Fault) -> None:
        pass

    def iteration_done(self, time: int, subsystem: str) -> None:
        pass

    def idle(self, seconds: float) -> None:
        """The run is about to wait `seconds` of wall-clock time for its next event (real time only):
        a moment to hand over what is held back, so that a process killed while it waits loses little."""


class Recorders(Recorder):
    """Several recorders as one."""

    def __init__(self, recorders: list[Recorder]) -> None:
        self.recorders = recorders

    def add(self, recorder: Recorder) -> None:
        """Another recorder; add it before the run starts (the engines ask for message writers then)."""
        self.recorders.append(recorder)

    def message_writer(self, link: str) -> MessageWriter | None:
        writers = [w for w in (r.message_writer(link) for r in self.recorders) if w is not None]
        if len(writers) <= 1:
            return writers[0] if writers else None

        def write(time: int, value: Any) -> None:
            for writer in writers:
                writer(time, value)

        return write

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        for recorder in self.recorders:
            recorder.state_changed(time, subsystem, source, destination, transition)

    def behaviour_started(self, time: int, subsystem: str, state: str, behaviour: str) -> None:
        for recorder in self.recorders:
            recorder.behaviour_started(time, subsystem, state, behaviour)

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        for recorder in self.recorders:
            recorder.behaviour_stopped(time, subsystem, state, behaviour, iterations, reason)

    def message_sent(self, time: int, link: str, value: Any) -> None:
        for recorder in self.recorders:
            recorder.message_sent(time, link, value)

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        for recorder in self.recorders:
            recorder.memory_snapshot(time, subsystem, memory)

    def fault(self, fault: Fault) -> None:
        for recorder in self.recorders:
            recorder.fault(fault)

    def idle(self, seconds: float) -> None:
        for recorder in self.recorders:
            idle = getattr(recorder, "idle", None)  # a recorder written before `idle` existed has none
            if idle is not None:
                idle(seconds)


class StatisticsRecorder(Recorder):
    """Counts what the closing summary table shows."""

    def __init__(self) -> None:
        self.subsystems: dict[str, SubsystemStatistics] = {}
        self.faults: list[Fault] = []

    def _of(self, subsystem: str) -> SubsystemStatistics:
        found = self.subsystems.get(subsystem)
        if found is None:
            found = self.subsystems[subsystem] = SubsystemStatistics()
        return found

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        statistics = self._of(subsystem)
        if source is not None:
            statistics.state_time[source] = statistics.state_time.get(source, 0) + time - statistics.entered
            name = transition or "?"
            statistics.transitions[name] = statistics.transitions.get(name, 0) + 1
        statistics.state = destination
        statistics.entered = time

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        self._of(subsystem).iterations += iterations

    def fault(self, fault: Fault) -> None:
        self._of(fault.subsystem).faults += 1
        self.faults.append(fault)

    def close(self, time: int) -> None:
        """Account the time of the states the subsystems are in at the end."""
        for statistics in self.subsystems.values():
            if statistics.state:
                statistics.state_time[statistics.state] = (
                    statistics.state_time.get(statistics.state, 0) + time - statistics.entered
                )
                statistics.entered = time
