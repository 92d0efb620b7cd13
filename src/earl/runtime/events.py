"""What a run reports as it goes: state changes, behaviours, messages, memory, faults.

The engine reports to a `Recorder`; the MCAP trace writer is one, the run summary
another.  Times are integer nanoseconds of run time (simulated or wall).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class Fault:
    """Something went wrong in a subsystem; the run goes on (docs/semantics.md, "Faults")."""

    time: int
    subsystem: str
    kind: str  # "exception" | "undeclared-write" | "type" | "predicate" | "no-transition" | "overflow" | "deadline"
    message: str
    state: str = ""
    behaviour: str = ""
    function: str = ""
    traceback: str = ""


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
    """Receives the events of a run; this base class ignores them all."""

    #: whether `message_sent` should be called at all (messages are the most frequent event)
    wants_messages: bool = True

    def state_changed(self, time: int, subsystem: str, source: str | None, destination: str, transition: str) -> None:
        pass

    def behaviour_started(self, time: int, subsystem: str, state: str, behaviour: str) -> None:
        pass

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        pass

    def message_sent(self, time: int, link: str, value: Any) -> None:
        pass

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        pass

    def fault(self, fault: Fault) -> None:
        pass

    def iteration_done(self, time: int, subsystem: str) -> None:
        pass


class Recorders(Recorder):
    """Several recorders as one."""

    def __init__(self, recorders: list[Recorder]) -> None:
        self.recorders = recorders
        # messages are the most frequent event: call only the recorders that look at them
        self._message_recorders = [r for r in recorders if type(r).message_sent is not Recorder.message_sent]
        #: read by the engine at every send: a plain attribute, kept up to date by `add`
        self.wants_messages = bool(self._message_recorders)
        self._route_messages()

    def add(self, recorder: Recorder) -> None:
        self.recorders.append(recorder)
        if type(recorder).message_sent is not Recorder.message_sent:
            self._message_recorders.append(recorder)
            self.wants_messages = True
            self._route_messages()

    def _route_messages(self) -> None:
        # One recorder looks at messages (the trace, typically): the engine calls it directly, one
        # call less for each of the thousands of messages a second a run sends.
        if len(self._message_recorders) == 1:
            self.message_sent = self._message_recorders[0].message_sent  # type: ignore[method-assign]
        else:
            self.__dict__.pop("message_sent", None)

    def state_changed(self, time: int, subsystem: str, source: str | None, destination: str, transition: str) -> None:
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
        for recorder in self._message_recorders:
            recorder.message_sent(time, link, value)

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        for recorder in self.recorders:
            recorder.memory_snapshot(time, subsystem, memory)

    def fault(self, fault: Fault) -> None:
        for recorder in self.recorders:
            recorder.fault(fault)


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

    def state_changed(self, time: int, subsystem: str, source: str | None, destination: str, transition: str) -> None:
        statistics = self._of(subsystem)
        if source is not None:
            statistics.state_time[source] = statistics.state_time.get(source, 0) + time - statistics.entered
            statistics.transitions[transition] = statistics.transitions.get(transition, 0) + 1
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
