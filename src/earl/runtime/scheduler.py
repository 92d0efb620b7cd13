"""When each subsystem runs: virtual time (default, deterministic) or real time (`--realtime`).

Both schedulers share one event queue.  An event is (time, subsystem order, sequence):
subsystems due at the same instant run in the spec's declaration order, so the same
spec and seed always run the same way.  Time is integer nanoseconds, never a float
that drifts.

Each iteration of a subsystem (docs/semantics.md):

    START   at t: steps 1-3 of the iteration; if every obligatory buffer of the state
            has a message, receive and decide at once (`SubsystemEngine.iterate`); else wait — a message arriving wakes it (RESUME),
            or the state's timeout expires (TIMEOUT) and `timeout(x/ib)` becomes true
    then    receive(), decide(); the next START is one period after this START, or at
            once if the wait made the iteration longer than its period (an overrun).

In virtual time a wait simply advances simulated time; the real-time scheduler
sleeps until each event is due on the wall clock and measures how late it starts.
"""

from __future__ import annotations

import heapq
import threading
import time as wall
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from earl.runtime.builder import Network
from earl.runtime.engine import SubsystemEngine
from earl.runtime.events import Recorder

_START, _RESUME, _TIMEOUT = 0, 1, 2

#: iterations a subsystem without a `period` may start in one instant (no run time passing), beyond one
#: for each message its FIFOs hold, before the run ends as a zero-time loop (docs/semantics.md, "When
#: subsystems run"): subsystems that wake each other at once would otherwise never let run time pass
ZERO_TIME_ITERATIONS = 10_000


class ZeroTimeLoop(RuntimeError):
    """Subsystems without a `period` woke each other at once, for ever, in one instant: run time cannot pass."""


@dataclass
class Lateness:
    """How late iterations started on the wall clock (real time only), in nanoseconds."""

    samples: list[int] = field(default_factory=list)
    overruns: int = 0


class Inbox(Protocol):
    """Messages from other processes, received on another thread (docs/distributed.md, "Scheduling")."""

    #: held by the thread that runs the scheduler's work; the scheduler releases it while it sleeps
    owner: threading.Lock

    @property
    def pending(self) -> bool: ...

    def wait(self, seconds: float) -> None:
        """Sleep at most `seconds`; return early when something arrives."""

    def wake(self) -> None:
        """End a `wait` now."""

    def drain(self, time: int) -> None:
        """Deliver what arrived, at run time `time` (the owner lock held)."""

    def serve_with(self, serve: Callable[[Callable[[int, Any], None], Any], None] | None) -> None:
        """Let the thread that receives a message run `serve(action, value)` when the owner lock is free."""


class Scheduler:
    """Runs a network of subsystem engines; `advance_to(t)` runs everything due until `t`."""

    def __init__(
        self,
        network: Network,
        recorder: Recorder,
        environment: object = None,
        *,
        realtime: bool = False,
        record_memory: set[str] | None = None,
        clock: Callable[[], int] = wall.perf_counter_ns,
        inbox: Inbox | None = None,
    ) -> None:
        self.network = network
        self.recorder = recorder
        self.environment = environment
        self.realtime = realtime
        self.record_memory = record_memory or set()
        self.clock = clock
        self.now = 0
        self._queue: list[tuple[int, int, int, int, SubsystemEngine, int]] = []
        self._sequence = 0
        self._tokens: dict[str, int] = {}
        self._resume_pending: set[str] = set()
        self._advance: Callable[[float], Any] | None = getattr(environment, "advance", None)
        self._environment_time = -1
        self._wall_start = 0
        #: whether the wall clock runs yet: it starts once the first instant (t = 0) has run, whose
        #: one-time costs (the first call of every function, the environment's first step) are no lateness
        self._clock_running = False
        self.lateness: dict[str, Lateness] = {}
        self.started = False
        #: messages from other processes; only real-time runs have one
        self.inbox = inbox
        # what a message served on the receiving thread needs of the current `advance_to`
        self._until = 0
        self._should_stop: Callable[[], bool] | None = None
        #: the run time the scheduler's thread sleeps until, -1 while it is awake (owner lock held)
        self._sleeping_until = -1
        #: whether the scheduler's thread holds the inbox's owner lock
        self._owning = False
        #: what went wrong while serving a message on the receiving thread, raised in the scheduler's
        self._failure: BaseException | None = None
        #: per subsystem without a period: the instant of its last iteration and how many it started then
        self._instant_starts: dict[str, list[int]] = {}
        #: real time: the run time an iteration was due by its period, for one whose start the wait of the
        #: iteration before it put off (its lateness counts from then, and it is an overrun)
        self._put_off: dict[str, int] = {}

    # ------------------------------------------------------------------ start
    def start(self) -> None:
        for engine in self.network.engines:
            engine.on_delivery = self._delivered
            self._tokens[engine.name] = 0
            initial = self.network.initial_states.get(engine.name)
            if initial is None or initial not in engine.states:
                continue
            if self.realtime:
                engine.prepare()  # before the wall clock starts: see `SubsystemEngine.prepare`
            engine.start(initial, 0)
            self._push(0, engine, _START)
        self._wall_start = self.clock()
        self.started = True

    def _push(self, time: int, engine: SubsystemEngine, kind: int, token: int = 0) -> None:
        self._sequence += 1
        heapq.heappush(self._queue, (time, engine.order, self._sequence, kind, engine, token))

    # ------------------------------------------------------------------ running
    def advance_to(self, until: int, should_stop: Callable[[], bool] | None = None) -> None:
        """Run every event due at or before `until` (ns); `now` is `until` afterwards."""
        if not self.started:
            self.start()
        if self.inbox is not None:
            self._advance_with_inbox(until, self.inbox, should_stop)
            return
        queue = self._queue
        pop = heapq.heappop
        push = heapq.heappush
        advance = self._advance
        realtime = self.realtime
        tokens = self._tokens
        record_memory = self.record_memory
        while queue and queue[0][0] <= until:
            # a stop is made between two instants, never inside one (docs/semantics.md)
            if should_stop is not None and queue[0][0] > self.now and should_stop():
                return
            if realtime:
                due = queue[0][0]
                if advance is not None and due > self._environment_time:
                    self._environment_time = due  # stepped before the wait, whose time it may use
                    advance(due * 1e-9)
                if due > 0 and not self._clock_running:
                    self._start_clock()
                # a stop asked while waiting for the next instant is made at once: no instant is running
                if not self._sleep_until_due(due, should_stop if due > self.now else None):
                    return
            time, _, _, kind, engine, token = pop(queue)
            self.now = time
            if advance is not None and time > self._environment_time:
                self._environment_time = time
                advance(time * 1e-9)
            if realtime and kind == _START:
                self._record_lateness(time, engine)
            if kind == _START:
                if engine.period is None:
                    self._count_iteration_in_instant(engine, time)
                # `_start` and `_push` written out: this is the path of nearly every event
                if not engine.iterate(time):
                    self._wait(engine, time)
                    continue
                if record_memory and engine.name in record_memory:
                    self.recorder.memory_snapshot(time, engine.name, engine.memory)
                period = engine.period
                following = time + period if period is not None and period > 0 else time
                if advance is None and not realtime:
                    # The engine alone is due before anything else: run it on without the queue
                    # (same order as through the queue, only cheaper).
                    alone = self._run_alone(engine, following, until, should_stop)
                    if alone is None:
                        continue
                    following = alone
                self._sequence += 1
                push(queue, (following, engine.order, self._sequence, _START, engine, 0))
            elif kind == _RESUME:
                if engine.waiting and token == tokens[engine.name]:
                    self._push(self._finish(engine, time, timed_out=False), engine, _START)
            elif engine.waiting and token == tokens[engine.name]:  # _TIMEOUT
                self._push(self._finish(engine, time, timed_out=True), engine, _START)
        if realtime and until > self.now:
            # real time reaches `until` on the wall clock too, not only the events before it: a stop while
            # waiting says the run time the wall clock had reached
            if not self._clock_running:
                self._start_clock()
            if not self._sleep_until_due(until, should_stop):
                self.now = max(self.now, min(self.clock() - self._wall_start, until))
                return
        self.now = max(self.now, until)
        if advance is not None and self.now > self._environment_time:
            self._environment_time = self.now
            advance(self.now * 1e-9)

    def _advance_with_inbox(self, until: int, inbox: Inbox, should_stop: Callable[[], bool] | None) -> None:
        """Real time with messages from other processes: wait on the wall clock for the next event *or* a
        message, whichever comes first, so that a remote message wakes a subsystem waiting for it at once.
        Unlike the local loop it waits until `until` itself, since the next event may be a message.

        While this thread sleeps, a message may be served on the thread that received it (`_serve`),
        which can change the event queue: the loop therefore looks at the queue afresh after every wait."""
        self._until, self._should_stop = until, should_stop
        queue = self._queue
        pop = heapq.heappop
        clock = self.clock
        inbox.owner.acquire()
        self._owning = True
        if self._advance is None:
            # Only a process without an environment serves messages on the receiving thread: a
            # plant's offscreen renderer (EGL, OSMesa) works only on the thread that created it.
            inbox.serve_with(self._serve)
        try:
            while True:
                if self._failure is not None:
                    failure, self._failure = self._failure, None
                    raise failure
                if should_stop is not None and not (queue and queue[0][0] <= self.now) and should_stop():
                    return  # between two instants
                if inbox.pending:
                    # a message arriving now is handled at the wall-clock instant it was received
                    self.now = max(self.now, min(clock() - self._wall_start, until))
                    inbox.drain(self.now)
                due = queue[0][0] if queue and queue[0][0] <= until else until
                if due > 0 and not self._clock_running:
                    self._start_clock()
                if clock() - self._wall_start < due:
                    self._sleep_until(due, inbox)
                    continue
                if not queue or queue[0][0] > until:
                    break
                time, _, _, kind, engine, token = pop(queue)
                self._run_event(time, kind, engine, token)
            self.now = max(self.now, until)
            if self._advance is not None and self.now > self._environment_time:
                self._environment_time = self.now
                self._advance(self.now * 1e-9)
        finally:
            if self._owning:
                self._owning = False
                inbox.owner.release()

    def close(self) -> None:
        """No message is served on a receiving thread any more (and none is being served on return)."""
        if self.inbox is not None:
            self.inbox.serve_with(None)

    def _run_event(self, time: int, kind: int, engine: SubsystemEngine, token: int) -> None:
        """One event of a real-time run with an inbox, on whichever thread holds the owner lock."""
        self.now = time
        advance = self._advance
        if advance is not None and time > self._environment_time:
            self._environment_time = time
            advance(time * 1e-9)
        if kind == _START:
            self._record_lateness(time, engine)
            following = self._start(engine, time)
            if following is not None:
                self._push(following, engine, _START)
        elif engine.waiting and token == self._tokens[engine.name]:
            self._push(self._finish(engine, time, timed_out=kind == _TIMEOUT), engine, _START)

    def _serve(self, action: Callable[[int, Any], None], value: Any) -> None:
        """On the thread that received a message, while the scheduler's thread sleeps (the owner lock
        held): deliver it at the wall-clock instant of its arrival and run every event due by then —
        typically the subsystem that waited for it, whose answer thus leaves without a thread switch."""
        inbox = self.inbox
        assert inbox is not None
        try:
            arrived = min(self.clock() - self._wall_start, self._until)
            if arrived > self.now:
                self.now = arrived
            time = self.now
            if inbox.pending:
                inbox.drain(time)  # what came before, first
            action(time, value)
            queue = self._queue
            while queue and queue[0][0] <= time:  # the whole instant: a stop is made between instants
                event_time, _, _, kind, engine, token = heapq.heappop(queue)
                if kind == _RESUME and engine.waiting and not (queue and queue[0][0] <= time):
                    # the subsystem this message woke, with nothing else due: its receive and decide, and
                    # its next iteration if that is due at once, run without going through the queue
                    if token == self._tokens[engine.name]:
                        following: int | None = self._finish(engine, event_time, timed_out=False)
                        if following is not None and following <= time:
                            self.now = following
                            self._record_lateness(following, engine)
                            following = self._start(engine, following)
                        if following is not None:
                            self._push(following, engine, _START)
                    continue
                self._run_event(event_time, kind, engine, token)
            if queue and queue[0][0] < self._sleeping_until:
                self._wake_sleeper()  # it sleeps until a later event than the one now first
        except BaseException as failure:  # raised again in the scheduler's thread, where the run is
            self._failure = failure
            self._wake_sleeper()

    def _wake_sleeper(self) -> None:
        inbox = self.inbox
        assert inbox is not None
        self._sleeping_until = -1  # read by the sleeper: its deadline is no longer the one to keep
        inbox.wake()

    def _sleep_until(self, time: int, inbox: Inbox) -> None:
        """Wait until run time `time` on the wall clock, or until a message is pending or served.

        The owner lock is free meanwhile, so that a message can be served on its receiving thread."""
        due = self._wall_start + time
        # while the owner lock is still held: the recorders belong to its holder
        self.recorder.idle((due - self.clock()) * 1e-9)
        self._sleeping_until = time
        self._owning = False
        inbox.owner.release()
        try:
            while self._sleeping_until == time:
                if inbox.pending:
                    return
                remaining = due - self.clock()
                if remaining <= 0:
                    return
                if remaining > 300_000:
                    should_stop = self._should_stop
                    if should_stop is not None and should_stop():
                        return  # the loop that called makes the stop: no instant is running
                    # in steps of at most 50 ms, so that a stop request (a flag a signal handler set) is seen
                    inbox.wait(min(remaining - 200_000, 50_000_000) * 1e-9)
                else:
                    # the last stretch is polled, as a timed wait overshoots; yielding the GIL on each turn
                    # lets a Zenoh callback deliver meanwhile instead of waiting out the switch interval
                    wall.sleep(0)
        finally:
            inbox.owner.acquire()
            self._owning = True
            self._sleeping_until = -1

    def _start(self, engine: SubsystemEngine, time: int) -> int | None:
        """One iteration from START; the time of the next START, or None while the engine waits."""
        if engine.period is None:
            self._count_iteration_in_instant(engine, time)
        if engine.iterate(time):
            if self.record_memory and engine.name in self.record_memory:
                self.recorder.memory_snapshot(time, engine.name, engine.memory)
            period = engine.period
            if period is None:
                return time
            following = time + period
            return following if following > time else time
        self._wait(engine, time)
        return None

    def _wait(self, engine: SubsystemEngine, time: int) -> None:
        """The engine waits for its obligatory buffers, until its state's timeout at most."""
        state = engine.state
        assert state is not None
        engine.waiting = True
        token = self._tokens[engine.name] = self._tokens[engine.name] + 1
        if state.timeout is not None:
            self._push(time + state.timeout, engine, _TIMEOUT, token)
        return None

    def _asked(self, should_stop: Callable[[], bool], engine: SubsystemEngine, following: int) -> bool:
        """`should_stop()`, asked between two iterations of `engine` run alone, off the queue: if it raises,
        the next iteration is put back on the queue first, so that the run is whole and can go on."""
        try:
            return should_stop()
        except BaseException:
            self._push(following, engine, _START)
            raise

    def _run_alone(
        self, engine: SubsystemEngine, following: int, until: int, should_stop: Callable[[], bool] | None = None
    ) -> int | None:
        """Iterations of one engine due at `following`, … up to `until` (ns) while nothing else is due.

        The loop of a system with one subsystem (and of a fast one among slow ones), so it is
        `_start` written out for the common case: a period, no memory to record after each
        iteration.  What is due next is looked at after every iteration: a message the engine sent
        may have woken a subsystem waiting for it (`_delivered` queues it at that instant), and
        that one runs before the engine's next iteration.
        """
        queue = self._queue
        period = engine.period
        if period is None or period <= 0 or (self.record_memory and engine.name in self.record_memory):
            next_start: int | None = following
            while next_start is not None and next_start <= until and not (queue and queue[0][0] <= next_start):
                if should_stop is not None and self._asked(should_stop, engine, next_start):
                    break
                self.now = next_start
                next_start = self._start(engine, next_start)
            return next_start
        while following <= until and not (queue and queue[0][0] <= following):
            if should_stop is not None and self._asked(should_stop, engine, following):
                break  # the next iteration goes back to the queue, where the stop is made
            self.now = following
            # looked up each time: the engine's `iterate` changes with its state
            if not engine.iterate(following):
                self._wait(engine, following)
                return None
            following += period
        return following

    def _count_iteration_in_instant(self, engine: SubsystemEngine, time: int) -> None:
        """An iteration of a subsystem without a period starts at `time`. Only such a subsystem can start
        two in one instant (a FIFO's messages, taken one per iteration, or a message that came at once);
        one that starts more than ZERO_TIME_ITERATIONS ends the run (ZeroTimeLoop)."""
        seen = self._instant_starts.get(engine.name)
        if seen is None or seen[0] != time:
            self._instant_starts[engine.name] = [time, 1]
            return
        seen[1] += 1
        if seen[1] > ZERO_TIME_ITERATIONS and seen[1] > ZERO_TIME_ITERATIONS + _fifo_capacity(engine):
            self._end_zero_time_loop(engine, time)

    def _end_zero_time_loop(self, engine: SubsystemEngine, time: int) -> None:
        """Record the loop as a fault of `engine` and end the run: every subsystem that started more than one
        iteration in this instant is part of it (each wakes the next at once)."""
        looping = [
            other
            for other in self.network.engines
            if (seen := self._instant_starts.get(other.name)) is not None and seen[0] == time and seen[1] > 1
        ]
        self._instant_starts[engine.name][1] -= 1  # the iteration refused does not run
        named = [_where_it_waits(other, self._instant_starts[other.name][1]) for other in looping]
        subsystems = named[0] if len(named) == 1 else ", ".join(named[:-1]) + " and " + named[-1]
        message = (
            f"{subsystems} at {time / 1e9:.6f} s, with no run time passing: "
            f"{'it has' if len(looping) == 1 else 'they have'} no `period`, and each message sent started "
            "the next iteration at once, for ever; give one of them a `period` (earl check: EARL-W018)"
        )
        engine.report_fault(time, "zero-time-loop", message)
        raise ZeroTimeLoop(message)

    def _delivered(self, engine: SubsystemEngine) -> None:
        """A message reached a waiting engine: wake it now if its obligatory buffers are all filled."""
        if engine.name in self._resume_pending or not engine.obligatory_ready():
            return
        self._resume_pending.add(engine.name)
        self._push(self.now, engine, _RESUME, self._tokens[engine.name])

    def _finish(self, engine: SubsystemEngine, time: int, *, timed_out: bool) -> int:
        """Receive and decide; the time of the engine's next START."""
        if engine.waiting:
            engine.waiting = False
            self._resume_pending.discard(engine.name)
            self._tokens[engine.name] += 1
        if timed_out:
            engine.receive(time, timed_out=True)
            engine.decide(time)
        else:
            engine.complete(time)
        if self.record_memory and engine.name in self.record_memory:
            self.recorder.memory_snapshot(time, engine.name, engine.memory)
        period = engine.period
        if period is None:
            return time
        following = engine.iteration_start + period
        if following >= time:
            return following
        if self.realtime:
            self._put_off[engine.name] = following  # the wait overran the period: the next starts late
        return time

    def _sleep_until_due(self, time: int, should_stop: Callable[[], bool] | None) -> bool:
        """Wait until run time `time` on the wall clock: sleep most of the way, in steps of at most 50 ms
        so that a stop request is seen (a signal handler only sets a flag), then spin the last 0.2 ms, as
        a sleep alone wakes up to a scheduler tick late. False when `should_stop()` came true first."""
        due = self._wall_start + time
        if due - self.clock() > 300_000:
            self.recorder.idle((due - self.clock()) * 1e-9)
        while True:
            remaining = due - self.clock()
            if remaining <= 300_000:
                break
            if should_stop is not None and should_stop():
                return False
            wall.sleep(min(remaining - 200_000, 50_000_000) * 1e-9)
        while self.clock() < due:
            pass
        return True

    def _start_clock(self) -> None:
        """Run time 0 is now on the wall clock: the first instant has run (`_clock_running`)."""
        self._wall_start = self.clock()
        self._clock_running = True

    def _record_lateness(self, time: int, engine: SubsystemEngine) -> None:
        """How late the iteration due at `time` starts on the wall clock, counted from when its period said it
        was due: an overrun when more than a period late, or when the wait of the iteration before it for its
        obligatory buffers went past that instant (docs/semantics.md, "When subsystems run")."""
        put_off = self._put_off.pop(engine.name, None) if self._put_off else None
        if not self._clock_running:
            return  # the first instant, run before the clock starts
        due = time if put_off is None else put_off
        late = self.clock() - (self._wall_start + due)
        record = self.lateness.get(engine.name)
        if record is None:
            record = self.lateness[engine.name] = Lateness()
        record.samples.append(late)
        period = engine.period
        if period is not None and (late > period or put_off is not None):
            record.overruns += 1
            if record.overruns == 1:
                why = (
                    f"more than its period ({period / 1e6:g} ms)"
                    if put_off is None
                    else f"due at {put_off / 1e9:.6f} s by its period ({period / 1e6:g} ms): the iteration before it "
                    f"waited for its obligatory buffers until {(time - put_off) / 1e6:g} ms after that"
                )
                engine.report_fault(
                    time,
                    "deadline",
                    f"an iteration started {late / 1e6:.3f} ms late, {why}; further overruns are only counted",
                )

    @property
    def next_event_time(self) -> int | None:
        return self._queue[0][0] if self._queue else None


def _fifo_capacity(engine: SubsystemEngine) -> int:
    """The messages the FIFOs of `engine`'s input buffers hold at most: one iteration each, in zero time."""
    return sum(channel.capacity or 0 for channel in engine.channels.values())


def _where_it_waits(engine: SubsystemEngine, iterations: int) -> str:
    """`a/a.cs` (10,000 iterations in state `s0`, system.earl:27): the subsystem, and the state it loops in
    where the spec says it."""
    state = engine.state
    if state is None:
        return f"`{engine.name}` ({iterations:,} iterations)"
    location = state.location
    where = f", {Path(location.file).name}:{location.line}" if location is not None else ""
    return f"`{engine.name}` ({iterations:,} iterations in state `{state.name}`{where})"
