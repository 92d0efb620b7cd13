"""The runtime executes Figure 5 exactly: state sequences, iteration numbers, newData, send/receive order,
snapshot isolation, refused undeclared writes, faults and recovery, FIFOs, timeouts, deterministic traces."""

from __future__ import annotations

import math
import re
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.model.elements import Duration
from earl.runtime.events import Recorder
from earl.runtime.simulation import Simulation

SPECS = Path(__file__).parent / "runtime_specs"
MS = 1_000_000


class Events(Recorder):
    """Everything the engines report, in order."""

    def __init__(self) -> None:
        self.states: list[tuple[int, str, str | None, str]] = []
        self.messages: list[tuple[int, str, Any]] = []
        self.stops: list[tuple[int, str, str, int, str]] = []

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        self.states.append((time, subsystem, source, destination))

    def message_sent(self, time: int, link: str, value: Any) -> None:
        self.messages.append((time, link, value))

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        self.stops.append((time, subsystem, behaviour, iterations, reason))


def copy_spec(name: str, tmp_path: Path, replacements: dict[str, str] | None = None) -> Path:
    target = tmp_path / name
    shutil.copytree(SPECS / name, target)
    spec = target / "system.earl"
    text = spec.read_text()
    for old, new in (replacements or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    spec.write_text(text)
    return spec


def simulate(spec: Path, **options: Any) -> tuple[Simulation, Events]:
    events = Events()
    parameters = options.pop("parameters", None)
    system = earl.load(spec, parameters)
    return earl.simulate(system, parameters=parameters, recorders=[events], **options), events


# ---------------------------------------------------------------------- Figure 5, step by step
def test_counter_runs_its_fsm_and_stops_counting_at_the_limit() -> None:
    sim, events = simulate(SPECS / "counter")
    sim.advance_to(0.05)
    assert [(t, s, a, b) for t, s, a, b in events.states if s == "counter/a.cs"] == [
        (0, "counter/a.cs", None, "counting"),
        (20 * MS, "counter/a.cs", "counting", "finished"),
    ]
    # counting/bb ran three iterations (t = 0, 10, 20 ms) before its terminal condition held
    assert events.stops == [(20 * MS, "counter/a.cs", "counting", 3, "terminal")]
    cs = sim.state_of("counter/a.cs")
    assert cs.memory["count"] == 3
    assert cs.memory["sent"] == 3  # rest/pf of finished/bb copied it
    assert cs.iteration == 3  # finished/bb ran at 30, 40, 50 ms; the number restarts at 0 in a new state
    assert sim.state_of("counter/a.relay/ve").iteration == 6


def test_messages_are_sent_after_the_transition_function_and_received_at_the_next_iteration() -> None:
    sim, events = simulate(SPECS / "counter")
    sim.advance_to(0.0)
    # at t = 0 every subsystem runs once, in declaration order: cs, relay, display
    assert events.messages == [
        (0, "counter/a:cs,relay", 1),  # cs incremented count to 1 in stage 1, stage 2 sent it
        (0, "counter/a:relay,display", 0),  # the relay forwards what it had before receiving (nothing yet)
        (0, "counter/a:relay,cs", 0),
        (0, "counter/a:display,relay", 0),  # the display's echo wakes the relay waiting for it
    ]
    relay = sim.state_of("counter/a.relay/ve")
    assert relay.inputs == {"command": 1, "echo": 0}
    assert relay.new_data == {"command": True, "echo": True}
    cs = sim.state_of("counter/a.cs")
    # the cs received before the relay sent anything: its echo buffer is not new
    assert cs.new_data == {"echo": False}
    sim.advance_to(0.010)
    assert sim.state_of("counter/a.cs").new_data == {"echo": True}
    assert sim.state_of("counter/a.cs").inputs == {"echo": 0}


def test_new_data_is_false_when_nothing_arrived_since_the_last_receive() -> None:
    sim, _ = simulate(SPECS / "counter")
    sim.advance_to(0.06)
    relay = sim.state_of("counter/a.relay/ve")
    # the cs stopped sending after its count reached the limit
    assert relay.new_data["command"] is False
    assert relay.inputs["command"] == 3


def test_an_obligatory_buffer_not_filled_in_time_times_out_and_predicates_see_it(tmp_path: Path) -> None:
    # the display runs every 20 ms, so every other echo the relay waits for (3 ms) never comes
    spec = copy_spec("counter", tmp_path, {"display/re {\n        period 10 ms": "display/re {\n        period 20 ms"})
    sim, events = simulate(spec)
    sim.advance_to(0.0131)
    relay = sim.state_of("counter/a.relay/ve")
    assert relay.state == "lost"
    relay_changes = [(t, a, b) for t, s, a, b in events.states if s == "counter/a.relay/ve"]
    assert relay_changes == [(0, None, "run"), (13 * MS, "run", "lost")]
    sim.advance_to(0.0201)
    relay = sim.state_of("counter/a.relay/ve")
    assert relay.state == "run"  # the echo came at 20 ms: not timed out, back to run
    assert relay.timed_out == {"command": False, "echo": False}
    assert relay.memory["lost"] == 1
    sim.advance_to(0.0331)
    assert sim.state_of("counter/a.relay/ve").memory["lost"] == 1
    assert sim.state_of("counter/a.relay/ve").state == "lost"


# ---------------------------------------------------------------------- stages (Eq. 7-8)
def test_functions_of_one_stage_see_one_snapshot() -> None:
    sim, _ = simulate(SPECS / "probe")
    sim.advance_to(0.0)
    memory = sim.state_of("probe/a.cs").memory
    # swapA wrote x = y + 1 = 21 and swapB y = x = 10 from the same snapshot (x=10, y=20)
    assert (memory["x"], memory["y"]) == (21, 10)
    sim.advance_to(0.001)
    memory = sim.state_of("probe/a.cs").memory
    assert (memory["x"], memory["y"]) == (11, 21)


@pytest.mark.parametrize(
    ("mode", "kind", "message"),
    [
        (1, "exception", "RuntimeError: the probe trips on purpose"),
        (2, "undeclared-write", "does not declare that it writes `recoveries`; it writes: trips"),
        (3, "type", "trips/mo must be a whole number (int), not the string 'many'"),
        (4, "undeclared-read", "`trip/pf` does not declare that it reads `recoveries`; it reads: trips"),
        (5, "type", "trips/mo must be a whole number (int)"),
    ],
)
def test_a_failing_function_makes_the_error_condition_true_and_the_fsm_recovers(
    mode: int, kind: str, message: str
) -> None:
    sim, events = simulate(SPECS / "probe", parameters={"MODE": mode})
    sim.advance_to(0.004)
    [fault] = sim.faults
    assert fault.kind == kind
    assert message in fault.message
    # seconds, as sim.time and context.time are; the exact nanoseconds beside them
    assert (
        fault.time == pytest.approx(0.002)
        and fault.time_ns == 2 * MS
        and fault.state == "work"
        and fault.function == "trip"
    )
    if kind in ("exception", "undeclared-read"):
        # the traceback starts in the user's code and shows the line that failed
        assert "stages.py" in fault.traceback and "earl/runtime" not in fault.traceback
    if kind == "exception":
        assert "the probe trips on purpose" in fault.traceback
    if kind in ("undeclared-write", "type"):
        assert fault.traceback == ""  # found after the call returned: the message names function and write
    if kind == "type":  # earl refused what the function wrote: the function raised nothing
        assert fault.message.startswith("`trip/pf` wrote a value of the wrong type: "), fault.message
    assert [(t, a, b) for t, _, a, b in events.states] == [
        (0, None, "work"),
        (2 * MS, "work", "recover"),
        (3 * MS, "recover", "work"),
    ]
    assert events.stops[0] == (2 * MS, "probe/a.cs", "work", 3, "error")
    memory = sim.state_of("probe/a.cs").memory
    # the failed call wrote nothing: neither the undeclared 99 nor the string; recover/pf ran once
    assert memory["recoveries"] == 1
    assert memory["trips"] == 3


def test_when_no_transition_holds_the_subsystem_stays_and_the_fault_is_recorded_once(tmp_path: Path) -> None:
    spec = copy_spec(
        "probe",
        tmp_path,
        {"tc = not true/pp": "tc = true/pp", "work -> recover when true/pp": "work -> recover when not true/pp"},
    )
    sim, _ = simulate(spec)
    sim.advance_to(0.005)
    assert sim.state_of("probe/a.cs").state == "work"
    assert [f.kind for f in sim.faults] == ["no-transition"]
    assert "stays in the state" in sim.faults[0].message
    assert sim.state_of("probe/a.cs").iteration == 6  # the behaviour went on, its number not reset


def test_a_function_that_returns_a_value_is_told_once_that_it_is_ignored(tmp_path: Path) -> None:
    """`return {"x": 1}` writes nothing: a fault says so at the function's first return, naming its spec line
    and how outputs are written; its writes through `outputs` still count and the FSM goes on as before."""
    spec = copy_spec("probe", tmp_path)
    stages = spec.parent / "probing" / "stages.py"
    stages.write_text(
        stages.read_text().replace(
            "def swap_b(inputs, outputs, context):\n    outputs.y = inputs.x\n",
            'def swap_b(inputs, outputs, context):\n    outputs.y = inputs.x\n    return {"y": 0}\n',
        )
    )
    sim, _ = simulate(spec)
    sim.advance_to(0.005)
    [fault] = sim.faults
    assert fault.kind == "return-value" and fault.function == "swapB" and fault.time == 0
    assert fault.message.startswith("`swapB/pf` (system.earl:21) returned a dict ({'y': 0}), which is ignored")
    assert "`outputs.y = …`" in fault.message and "returns None" in fault.message
    assert fault.traceback == ""
    assert sim.state_of("probe/a.cs").memory["y"] != 0  # what it wrote through `outputs` was kept
    assert [f.kind for f in sim.faults] == ["return-value"]  # never the error condition's `recover`
    sim.close()


# ---------------------------------------------------------------------- FIFOs
@pytest.mark.parametrize(
    ("policy", "seen", "faults"),
    [
        ("dropOldest", (0, 1, 3, 6, 9), 0),
        ("dropNewest", (0, 1, 2, 3, 5), 0),
        ("fault", (0, 1, 3, 6, 9), 4),
    ],
)
def test_a_fifo_input_buffer_keeps_its_capacity_by_its_overflow_policy(
    tmp_path: Path, policy: str, seen: tuple[int, ...], faults: int
) -> None:
    spec = copy_spec("fifo", tmp_path, {"overflow dropOldest": f"overflow {policy}"})
    sim, _ = simulate(spec)
    sim.advance_to(0.0125)
    assert sim.state_of("pipe/a.consumer/ve").memory["seen"] == seen
    overflows = [f.message for f in sim.faults if f.kind == "overflow"]
    assert len(overflows) == faults
    if overflows:  # each says what was dropped since the last receive, and the total so far
        assert [m.split(": ", 1)[1] for m in overflows[:2]] == [
            "1 dropped since the last receive, 1 in all",
            "2 dropped since the last receive, 3 in all",
        ]


# ---------------------------------------------------------------------- determinism and traces
def test_the_same_spec_and_seed_give_a_byte_identical_trace(tmp_path: Path) -> None:
    traces = []
    for name, seed in (("a", 7), ("b", 7), ("c", 8)):
        path = tmp_path / f"{name}.mcap"
        sim, _ = simulate(SPECS / "counter", seed=seed, trace=path, record_memory=["all"])
        sim.advance_to(0.2)
        sim.close()
        traces.append(path.read_bytes())
    assert traces[0] == traces[1]
    assert traces[0] != traces[2]  # the display's noise comes from the seeded stream


def test_each_link_gets_a_message_writer_only_from_the_recorders_that_record_it(tmp_path: Path) -> None:
    """The engine asks for a writer per link once: a recorder without `message_sent` gives none, the trace
    none for a link it does not record, and a link nobody records is then never reported."""
    from earl.runtime import RecordingWarning
    from earl.runtime.trace import TraceWriter

    with pytest.warns(RecordingWarning, match="`nothing-matches` matches no link"):
        sim, events = simulate(SPECS / "counter", trace=tmp_path / "links.mcap", record_links=["nothing-matches"])
    links = sorted(sim.network.link_types)
    assert links
    assert all(Recorder().message_writer(link) is None for link in links)
    trace = sim.trace
    assert isinstance(trace, TraceWriter)
    assert all(trace.message_writer(link) is None for link in links)
    sim.advance_to(0.05)
    sim.close()
    # the test's recorder has message_sent: it saw every message, the trace none
    assert events.messages and {link for _, link, _ in events.messages} <= set(links)
    from mcap.reader import make_reader

    with (tmp_path / "links.mcap").open("rb") as stream:
        topics = {channel.topic for _, channel, _ in make_reader(stream).iter_messages()}
    assert topics and not any(topic.startswith("/link/") for topic in topics)


def test_a_trace_written_by_its_own_process_is_the_trace_written_in_process(tmp_path: Path) -> None:
    """A file trace is written by a second process (trace_process.py); a stream, in this one: same bytes."""
    import io

    in_process = io.BytesIO()
    for output in (tmp_path / "background.mcap", in_process):
        sim, _ = simulate(SPECS / "counter", seed=3, trace=output, record_memory=["all"])
        sim.advance_to(0.2)
        sim.close()
    assert (tmp_path / "background.mcap").read_bytes() == in_process.getvalue()


def test_a_trace_that_cannot_be_written_stops_with_one_sentence(tmp_path: Path) -> None:
    """A full disk (/dev/full) is reported as a TraceWriteError, during the run or when it closes."""
    from earl.runtime.trace import TraceWriteError

    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    sim, _ = simulate(SPECS / "counter", trace="/dev/full", record_memory=["all"])
    with pytest.raises(TraceWriteError, match=r"cannot write the trace /dev/full: No space left on device"):
        sim.advance_to(0.2)
        sim.close()


def test_state_of_an_unknown_subsystem_suggests_the_right_name() -> None:
    sim, _ = simulate(SPECS / "counter")
    with pytest.raises(KeyError, match=r"counter/a\.relay/ve"):
        sim.state_of("counter/a.relay")


def test_state_of_a_family_s_base_name_names_its_members() -> None:
    """`manip/a.motorController/ve` is no subsystem: its members are; the closest name by spelling was one of
    them picked at random (`[3]` of three)."""
    sim = earl.simulate(earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place"), environment=None)
    try:
        with pytest.raises(KeyError) as raised:
            sim.state_of("manip/a.motorController/ve")
        assert str(raised.value) == (
            "`manip/a.motorController/ve` is a family of subsystems, each run on its own: name a member, "
            "`manip/a.motorController[1]/ve` … `manip/a.motorController[6]/ve`"
        )
    finally:
        sim.close()


def test_the_real_time_scheduler_paces_by_the_wall_clock_and_measures_lateness() -> None:
    sim, events = simulate(SPECS / "counter", realtime=True)
    sim.advance_to(0.05)
    sim.close()
    lateness = sim.scheduler.lateness["counter/a.cs"]
    assert len(lateness.samples) == 5  # 10, …, 50 ms: the clock starts once the instant 0 has run
    assert all(sample >= 0 for sample in lateness.samples)
    assert [(t, b) for t, s, _, b in events.states if s == "counter/a.cs"] == [(0, "counting"), (20 * MS, "finished")]


def test_a_real_time_start_is_not_late_by_its_one_time_costs() -> None:
    """The example's 17 subsystems at 2 ms: generating their code and the first calls at t = 0 took up
    to 22 ms, and every subsystem recorded a `deadline` fault in the first instant."""
    sim = earl.simulate(earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place"), realtime=True)
    try:
        sim.advance_to(0.3)
        assert [f for f in sim.faults if f.time == 0] == []
    finally:
        sim.close()


LONE_WAITER = """\
system lone

waiter/a {
    cs {
        period 1 ms

        ping/ib: int

        misses/m: int = 0

        missed/pp = timeout(ping/ib)
        false/pp = false

        count/pf(misses/mi -> misses/mo) = python "waiting:count"

        wait/bb {
            tf = {count/pf}
            tc = missed/pp
        }

        fsm {
            initial wait
            state wait: wait/bb { obligatory ping/ib  timeout 3 ms }

            wait -> wait when missed/pp
        }
    }
}

r/r {
    waiter/a
}
"""


def lone_waiter(tmp_path: Path, spec: str) -> tuple[Simulation, Events]:
    """`spec` (LONE_WAITER or a variant) with its counting function, ready to run."""
    (tmp_path / "system.earl").write_text(spec)
    (tmp_path / "waiting.py").write_text(
        "def count(inputs, outputs, context):\n    outputs.misses = inputs.misses + 1\n"
    )
    events = Events()
    # nothing sends `ping`: a rule of the manual the checker enforces, not the subject here
    return earl.simulate(earl.load(tmp_path / "system.earl"), recorders=[events], check=False), events


EVERY_THIRD = """\
system everyThird

a/a {
    cs {
        period 10 ms
        count/m: int = 0
        val/ob: int
        false/pp = false
        inc/pf(count/mi -> count/mo) = python "third:inc"
        send/pf(count/mi -> val/ob) = python "third:send"
        run/bb {
            tf = {inc/pf} then {send/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

b/a {
    cs {
        val/ib: int
        got/m: int = 0
        false/pp = false
        take/pf(val/ib -> got/mo) = python "third:take"
        run/bb {
            tf = {take/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb { obligatory val/ib  timeout 1 s }
        }
    }
}

link a,b: a/a.cs.val -> b/a.cs.val

r/r {
    a/a
    b/a
}
"""


class _Still:
    """An environment that does nothing: with one, every event goes through the scheduler's queue."""

    def advance(self, seconds: float) -> None:
        pass


def test_a_subsystem_woken_by_a_sender_running_alone_takes_each_message_when_it_arrives(tmp_path: Path) -> None:
    """The sender runs in the scheduler's tight loop (`_run_alone`); the receiver it wakes must run at
    once, in the sender's instant, and not after the sender has run on to the end of `advance_to`."""
    (tmp_path / "system.earl").write_text(EVERY_THIRD)
    (tmp_path / "third.py").write_text(
        "TAKEN = []\n"
        "def inc(i, o, c):\n    o.count = i.count + 1\n"
        "def send(i, o, c):\n    if i.count % 3 == 1:\n        o.val = i.count\n"
        "def take(i, o, c):\n    o.got = i.val\n    TAKEN.append((round(c.time, 6), i.val))\n"
    )
    runs = []
    for environment, chunks in ((None, [0.2]), (_Still(), [0.2]), (None, [0.05, 0.1, 0.15, 0.2])):
        sim = earl.simulate(earl.load(tmp_path / "system.earl"), environment=environment)
        try:
            taken = sys.modules["third"].TAKEN
            taken.clear()
            for until in chunks:
                sim.advance_to(until)
            runs.append(list(taken))
        finally:
            sim.close()
    wanted = [(0.0, 0), (0.0, 1), (0.03, 4), (0.06, 7), (0.09, 10), (0.12, 13), (0.15, 16), (0.18, 19)]
    assert runs == [wanted, wanted, wanted]


def test_a_lone_subsystem_that_waits_for_a_buffer_times_out_on_time(tmp_path: Path) -> None:
    # One engine alone runs in the scheduler's tight loop (`_run_alone`); a wait must leave it
    # for the timeout event exactly as the general loop does: start, wait 3 ms, start again.
    sim, events = lone_waiter(tmp_path, LONE_WAITER)
    try:
        sim.advance_to(0.0100)
        waiter = sim.state_of("waiter/a.cs")
        # iterations start at 0, 3, 6 and 9 ms; each waits 3 ms and times out
        assert waiter.memory["misses"] == 4
        assert [t for t, _, _, _ in events.states][1:] == [3 * MS, 6 * MS, 9 * MS]
        assert waiter.timed_out == {"ping": True}
    finally:
        sim.close()


def test_stale_reads_the_set_of_buffers_whose_remote_sender_is_gone(tmp_path: Path) -> None:
    # The transport marks a buffer stale by adding it to the engine's `stale` set (in place); the
    # compiled predicates read that very set. In one process nothing is ever stale.
    spec = LONE_WAITER.replace("missed/pp = timeout(ping/ib)", "missed/pp = stale(ping/ib)").replace(
        "state wait: wait/bb { obligatory ping/ib  timeout 3 ms }", "state wait: wait/bb"
    )
    sim, events = lone_waiter(tmp_path, spec)
    try:
        sim.advance_to(0.0025)
        assert [b for _, _, _, b in events.states] == ["wait"]  # never stale: no transition
        engine = sim.network.by_name["waiter/a.cs"]
        engine.stale.add("ping")
        sim.advance_to(0.0035)
        assert [(t, b) for t, _, _, b in events.states][1:] == [(3 * MS, "wait")]
        assert sim.state_of("waiter/a.cs").timed_out == {"ping": True}  # a stale buffer also times out
        # a message that comes while the buffer is still stale (before its sender's liveliness is known):
        # the buffer has new data, so it did not time out
        engine.channels["ping"].deliver(1.0)
        sim.advance_to(0.0045)
        waiter = sim.state_of("waiter/a.cs")
        assert waiter.new_data == {"ping": True} and waiter.timed_out == {"ping": False}
    finally:
        sim.close()


@pytest.mark.parametrize("check", [True, False])
def test_the_python_api_refuses_a_parameter_the_system_does_not_declare(check: bool) -> None:
    """As `earl run --param` does (EARL-R001): a misspelt name must not leave the default in place,
    with the checker switched off too."""
    system = earl.load(SPECS / "counter")
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(system, parameters={"LIMTI": 3}, check=check)
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-R001" and "`LIMTI`" in diagnostic.message
    assert diagnostic.hint == "did you mean `LIMIT`?"


def test_parameters_given_to_load_are_the_system_s_own() -> None:
    """`earl.load(path, {"N": 3})`, as the README shows it: the model, its run and its text have N = 3."""
    example = Path(__file__).parent.parent / "examples" / "pick_and_place"
    system = earl.load(example, {"N": 3})
    assert "param N: int = 3" in system.to_earl()
    sim = earl.simulate(system, environment=None)
    try:
        assert [name for name in sim.subsystems if "/a.motorController[" in name] == [
            f"manip/a.motorController[{k}]/ve" for k in (1, 2, 3)
        ]
    finally:
        sim.close()


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("abc", 'its value is "abc"'),
        (1.5, "its value is 1.5"),
        (True, "its value is true"),
        (None, "its value is None"),
        (float("nan"), "its value is NaN"),
        (10**30, "its value (a whole number of 31 digits) does not fit it"),
    ],
)
def test_the_python_api_refuses_a_parameter_value_of_the_wrong_type(value: Any, fragment: str) -> None:
    """As `--param` does (EARL-R005): `LIMIT` is an `int`, 64 bits at most."""
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(SPECS / "counter"), parameters={"LIMIT": value})
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-R005" and "parameter `LIMIT` is `int` but" in diagnostic.message
    assert fragment in diagnostic.message


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda system: earl.simulate(str(SPECS / "counter")), "a simulation runs a System, as earl.load(path)"),
        (lambda system: earl.simulate(system, trace=5), "trace takes a file name or a binary stream, not int"),
        (lambda system: earl.simulate(system, record_memory="counter/a.cs"), "record_memory takes a list of names"),
        (lambda system: earl.simulate(system, agents="counter/a"), "agents takes a list of names"),
    ],
    ids=["path", "trace", "record_memory", "agents"],
)
def test_the_python_api_says_what_an_argument_takes(call: Any, fragment: str) -> None:
    with pytest.raises(TypeError, match=re.escape(fragment)):
        call(earl.load(SPECS / "counter"))


def test_state_of_something_that_is_no_subsystem_name_is_a_key_error_that_says_how_they_look() -> None:
    simulation = earl.simulate(earl.load(SPECS / "counter"))
    with pytest.raises(KeyError, match=re.escape("subsystems are named like `counter/a.cs`")):
        simulation.state_of(None)  # type: ignore[arg-type]
    simulation.close()


def test_a_whole_number_beyond_64_bits_is_refused_for_an_int_parameter_on_the_command_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from earl.cli.main import main

    assert main(["run", str(SPECS / "counter"), "--param", "LIMIT=" + "9" * 25, "--duration", "10ms"]) == 1
    assert "EARL-R005" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("time", "error"), [(float("nan"), ValueError), (float("inf"), ValueError), (2e9, ValueError), ("1s", TypeError)]
)
def test_advance_to_takes_a_finite_number_of_seconds(time: Any, error: type[Exception]) -> None:
    sim = earl.simulate(earl.load(SPECS / "counter"), seed=1)
    with pytest.raises(error, match="advance_to takes"):
        sim.advance_to(time)
    sim.advance_to(0.01)  # the run is intact
    assert sim.time == pytest.approx(0.01)
    sim.close()


def test_advance_to_a_time_reached_does_nothing_and_a_negative_one_is_refused() -> None:
    sim = earl.simulate(earl.load(SPECS / "counter"), seed=1)
    try:
        sim.advance_to(0.03)
        with pytest.raises(ValueError, match=r"advance_to takes a run time from 0 on, not -1\.0"):
            sim.advance_to(-1.0)
        sim.advance_to(0.01)  # reached already: nothing to do
        assert sim.time == pytest.approx(0.03)
        sim.advance_to(0.05)
        assert sim.time == pytest.approx(0.05)
    finally:
        sim.close()


@pytest.mark.parametrize("value", ["true", "1.0"])
def test_a_memory_whose_initial_value_does_not_fit_is_said_at_its_line(tmp_path: Path, value: str) -> None:
    """`earl check` refuses it (EARL-E043); unchecked, the run names the memory's line, not the subsystem's.
    A real number for an `int` is refused as for a parameter: `1.0` became 1, silently."""
    spec = copy_spec("counter", tmp_path, {"count/m: int = 0": f"count/m: int = {value}"})
    line = 1 + spec.read_text()[: spec.read_text().index(f"count/m: int = {value}")].count("\n")
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(spec), check=False)
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X010" and "the initial value of count/m must be" in diagnostic.message
    assert diagnostic.location is not None and diagnostic.location.line == line


def test_a_condition_that_fails_names_the_primitive_predicate_at_fault(tmp_path: Path) -> None:
    spec = copy_spec(
        "counter",
        tmp_path,
        {
            "        count/m: int = 0\n": "        count/m: int = 0\n        v/m: double[3] = [0.0, 0.0, 0.0]\n",
            "done/pp = count/mi >= LIMIT": "done/pp = count/mi >= LIMIT or v/mi[5] > 1.0",
        },
    )
    sim = earl.simulate(earl.load(spec), check=False)  # `earl check` refuses it (EARL-E030)
    try:
        sim.advance_to(0.005)
        assert sim.faults[0].message == (
            "evaluating the terminal condition of `counting/bb` in `done/pp`: `v/mi` has no element 5 (it has 3 elements)"
        )
    finally:
        sim.close()


def test_a_negative_element_index_is_a_fault_not_an_element_from_the_end(tmp_path: Path) -> None:
    spec = copy_spec(
        "counter",
        tmp_path,
        {
            "        count/m: int = 0\n": "        count/m: int = 0\n        v/m: double[3] = [0.0, 0.0, 9.0]\n",
            "done/pp = count/mi >= LIMIT": "done/pp = count/mi >= LIMIT or v/mi[0 - 1] > 1.0",
        },
    )
    sim = earl.simulate(earl.load(spec), check=False)  # `earl check` refuses it (EARL-E030)
    try:
        sim.advance_to(0.005)
        assert sim.state_of("counter/a.cs").state == "counting"  # `v/mi[2]` (9.0) was not read
        assert "element -1 does not exist (elements count from 0) in `done/pp`" in sim.faults[0].message
    finally:
        sim.close()


@pytest.mark.parametrize("index", ["true", "1.5", "0.5 + 0.5"])
def test_an_index_that_is_not_a_whole_number_is_a_fault_not_an_element(tmp_path: Path, index: str) -> None:
    """`v/mi[true]` read element 1 (Python takes True for 1), silently; `earl check` refuses it (EARL-E030),
    a run that skips the check reports it."""
    spec = copy_spec(
        "counter",
        tmp_path,
        {
            "        count/m: int = 0\n": "        count/m: int = 0\n        v/m: double[3] = [0.0, 9.0, 0.0]\n",
            "done/pp = count/mi >= LIMIT": f"done/pp = count/mi >= LIMIT or v/mi[{index}] > 1.0",
        },
    )
    sim = earl.simulate(earl.load(spec), check=False)
    try:
        sim.advance_to(0.005)
        assert sim.state_of("counter/a.cs").state == "counting"  # `v/mi[1]` (9.0) was not read
        assert "an index must be a whole number, not" in sim.faults[0].message
    finally:
        sim.close()


def test_advance_by_takes_a_duration_and_should_stop_a_function() -> None:
    sim = earl.simulate(earl.load(SPECS / "counter"), seed=1)
    try:
        with pytest.raises(ValueError, match="advance_by takes a duration of 0 s or more"):
            sim.advance_by(-0.01)
        with pytest.raises(TypeError, match="should_stop takes a function"):
            sim.advance_to(0.01, should_stop="x")  # type: ignore[arg-type]
        sim.advance_by(0.02, should_stop=lambda: False)
        assert sim.time == pytest.approx(0.02)
        sim.advance_by(0.02, should_stop=lambda: True)  # between two instants: at once
        assert sim.time == pytest.approx(0.02)
    finally:
        sim.close()


def test_a_memory_family_starts_each_member_from_its_own_index(tmp_path: Path) -> None:
    spec = copy_spec(
        "counter",
        tmp_path,
        {
            "        count/m: int = 0\n": "        count/m: int = 0\n        history[J in 1..3]/m: double = 2 * J + 0.5\n"
        },
    )
    system = earl.load(spec)
    from earl.check import check

    assert [d for d in check(system) if d.severity.value == "error"] == []
    sim = earl.simulate(system)
    try:
        sim.advance_to(0.001)
        memory = sim.state_of("counter/a.cs").memory
        assert [memory[f"history[{j}]"] for j in (1, 2, 3)] == [2.5, 4.5, 6.5]
    finally:
        sim.close()


@pytest.mark.parametrize(
    ("duration", "fragment"),
    [
        (Duration(0.0001, "us"), "period is 0.0001 us; it must be at least 1 ns"),
        (Duration(1, "min"), "period is in `min`; the units are s, ms, us"),
    ],
)
def test_a_period_built_in_python_that_time_could_not_follow_is_refused(duration: Duration, fragment: str) -> None:
    """The reader refuses `period 0.0001 us` (EARL-S012); a model built or edited in Python never met the
    reader, and a period that rounds to 0 ns would hold the run at one instant for ever."""
    system = earl.load(SPECS / "counter")
    system.agent("counter").control_subsystem.period = duration  # type: ignore[union-attr]
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(system, check=False)
    assert [(d.code, fragment in d.message) for d in refused.value.diagnostics] == [("EARL-X014", True)]


def test_code_that_cannot_be_bound_is_said_once_for_a_family_of_subsystems(tmp_path: Path) -> None:
    spec = tmp_path / "system.earl"
    spec.write_text(
        """\
system fam

a/a {
    cs {
        period 1 ms
    }
    m[K in 1..3]/ve {
        period 1 ms
        x/m: int = 0
        f/pf(x/mi -> x/mo) = python "helpers:missing"
        run/bb {
            tf = {f/pf}
            tc = false
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}
"""
    )
    (tmp_path / "helpers.py").write_text("def present(inputs, outputs, context):\n    pass\n")
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(spec), check=False)
    assert [d.code for d in refused.value.diagnostics if d.code != "EARL-X011"] == ["EARL-X004"]  # (cs: no fsm)


def test_a_module_that_cannot_be_imported_is_said_once_at_the_first_line_naming_it(tmp_path: Path) -> None:
    """Five functions of one broken file are one error, at the first line naming it (a predicate, bound before
    the functions, names it further down), and the file is imported once: its failing code runs once."""
    spec = tmp_path / "system.earl"
    spec.write_text(
        """\
system broken

a/a {
    cs {
        period 1 ms
        x/m: int = 0
        f/pf(x/mi -> x/mo) = python "helpers:f"
        g/pf(x/mi -> x/mo) = python "helpers:g"
        done/pp(x/mi) = python "helpers:done"
        run/bb {
            tf = {f/pf} then {g/pf}
            tc = done/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}
"""
    )
    (tmp_path / "helpers.py").write_text(
        "from pathlib import Path\n\n"
        "with open(Path(__file__).with_name('imports.txt'), 'a') as log:\n    log.write('imported\\n')\n"
        "raise RuntimeError('half-written')\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(spec), check=False)
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X003"
    assert diagnostic.message.startswith("importing `helpers` for `f/pf` of a/a.cs failed: RuntimeError: half-written")
    assert diagnostic.location is not None and diagnostic.location.line == 7
    assert diagnostic.hint == "`helpers` is named at lines 8, 9 too: this error stands for those"
    assert (tmp_path / "imports.txt").read_text() == "imported\n"


def test_a_module_named_without_its_function_is_said_so_not_read_as_module_dot_function() -> None:
    """`environment = "counting.cs"` (the `:FACTORY` forgotten) was read as the function `cs` of `counting`,
    and refused as `counting` having no function `cs`: only the colon separates module and function."""
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(SPECS / "counter"), environment="counting.cs")
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X001"
    assert diagnostic.message == "`counting.cs` does not name a function: write `module:function`"
    assert diagnostic.hint is not None
    assert diagnostic.hint.startswith(
        '`counting.cs` is a module: name its function after a colon, `"counting.cs:FACTORY"`'
    )
    assert "(it defines `" in diagnostic.hint


@pytest.mark.parametrize("check", [True, False])
def test_a_dot_for_the_colon_of_an_implementation_is_refused_with_the_colon_suggested(
    tmp_path: Path, check: bool
) -> None:
    spec = copy_spec("counter", tmp_path)
    text = spec.read_text()
    dotted = re.sub(r'python "counting\.cs:(\w+)"', r'python "counting.cs.\1"', text, count=1)
    assert dotted != text
    spec.write_text(dotted)
    line = 1 + dotted.split("\n").index(next(row for row in dotted.split("\n") if 'python "counting.cs.' in row))
    function = re.search(r'python "counting\.cs\.(\w+)"', dotted).group(1)  # type: ignore[union-attr]
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(spec), check=check)
    [diagnostic] = [d for d in refused.value.diagnostics if d.severity == earl.Severity.ERROR]
    # the checker finds it first (without importing anything); unchecked, the binding refuses it alike
    assert diagnostic.code == ("EARL-E044" if check else "EARL-X001")
    assert diagnostic.location is not None and diagnostic.location.line == line
    assert f'did you mean `python "counting.cs:{function}"`?' in (diagnostic.hint or "") or (
        f'did you mean `"counting.cs:{function}"`?' in (diagnostic.hint or "")
    )


PLANT = """\
class Plant:
    def __init__(self, system, seed):
        self.seed = seed
        self.times = []

    def advance(self, time):
        self.times.append(time)


class Fixed:
    def __init__(self, xml):
        pass


async def later(system, seed):
    return Plant(system, seed)
"""


def test_a_class_taking_system_and_seed_is_an_environment_factory(tmp_path: Path) -> None:
    """`FACTORY(system, seed) -> object` is what a class is, called: its instance is the environment."""
    spec = copy_spec("counter", tmp_path)
    (spec.parent / "plant.py").write_text(PLANT)
    sim = earl.simulate(earl.load(spec), environment="plant:Plant", seed=4)
    try:
        sim.advance_to(0.002)
        plant = sim.environment
        assert type(plant).__name__ == "Plant" and plant.seed == 4  # type: ignore[attr-defined]
        assert plant.times  # type: ignore[attr-defined]
    finally:
        sim.close()
        sys.modules.pop("plant", None)


@pytest.mark.parametrize(
    ("factory", "message", "hint"),
    [
        (
            "plant:Fixed",
            "the environment calls `plant:Fixed` with 2 arguments, but it is defined as `Fixed(xml)`",
            "give `Fixed` an `__init__(self, system, seed)` (see docs/runtime.md)",
        ),
        (
            "plant:later",
            "the environment names `plant:later`, which is a coroutine function (`async def`), not a function",
            "write it as `def later(system, seed) -> object` (or as a class whose `__init__` takes them): earl "
            "calls it once, before the run, and the object it returns is the environment",
        ),
    ],
)
def test_an_environment_factory_that_cannot_make_the_environment_is_told_how_to_be_written(
    tmp_path: Path, factory: str, message: str, hint: str
) -> None:
    spec = copy_spec("counter", tmp_path)
    (spec.parent / "plant.py").write_text(PLANT)
    try:
        with pytest.raises(earl.EarlError) as refused:
            earl.simulate(earl.load(spec), environment=factory)
    finally:
        sys.modules.pop("plant", None)
    [diagnostic] = refused.value.diagnostics
    assert (diagnostic.code, diagnostic.message, diagnostic.hint) == ("EARL-X005", message, hint)


def test_a_class_named_as_a_partial_transition_function_is_refused_with_a_hint_about_functions(
    tmp_path: Path,
) -> None:
    spec = copy_spec("counter", tmp_path)
    code = spec.parent / "counting" / "cs.py"
    code.write_text(code.read_text() + "\n\nclass Counter:\n    def __init__(self, a, b, c):\n        pass\n")
    text = spec.read_text()
    spec.write_text(re.sub(r'python "counting\.cs:increment"', 'python "counting.cs:Counter"', text))
    with pytest.raises(earl.EarlError) as refused:
        earl.simulate(earl.load(spec))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X005" and "which is a class, not a function" in diagnostic.message
    assert diagnostic.hint == (
        "write it as `def Counter(inputs, outputs, context) -> None`: the runtime calls it and uses what it wrote "
        "through `outputs` at once"
    )


def test_a_run_time_beyond_any_float_is_refused_as_out_of_range_not_overflowed() -> None:
    """`10**400` is an int Python cannot make a float: compared, not converted, it is refused like infinity,
    and the message quotes it short."""
    simulation = earl.simulate(earl.load(SPECS / "counter"))
    try:
        for call, seconds, message in [
            (simulation.advance_to, 10**400, "at most 1e+09 s, not (a whole number of 401 digits)"),
            (simulation.advance_to, -(10**400), "from 0 on, not -(a whole number of 401 digits)"),
            (simulation.advance_to, -math.inf, "finite run time"),
            (simulation.advance_by, 10**5000, "advance_by takes a finite duration that ends the run by 1e+09 s"),
            (simulation.advance_by, math.nan, "advance_by takes a finite duration"),
        ]:
            with pytest.raises(ValueError) as refused:
                call(seconds)
            assert message in str(refused.value)
        simulation.advance_to(0.002)  # the refusals left it able to run
        assert simulation.time == 0.002
    finally:
        simulation.close()


def test_the_entry_into_the_initial_state_names_no_transition(tmp_path: Path) -> None:
    """`*,counting` read as an any-source transition the spec does not have: the first record of each FSM
    topic has no `from` and `transition` (left out, as the schema leaves them out of `required`), later
    ones the transition taken; the summary counts only those."""
    import json

    from mcap.reader import make_reader

    from earl.runtime.trace_reader import summarise

    sim, _ = simulate(SPECS / "counter", trace=tmp_path / "run.mcap")
    sim.advance_to(0.05)
    sim.close()
    with (tmp_path / "run.mcap").open("rb") as stream:
        changes = [
            json.loads(message.data)
            for _, channel, message in make_reader(stream).iter_messages()
            if channel.topic == "/counter/a.cs/fsm"
        ]
    assert changes[0] == {"to": "counting"}
    assert changes[1:] == [{"from": "counting", "to": "finished", "transition": "counting,finished"}]
    assert summarise(tmp_path / "run.mcap").subsystems["counter/a.cs"].transitions == {"counting,finished": 1}


DAG_LEVELS = 24


def predicate_dag(tmp_path: Path) -> Path:
    """A predicate each level of which names the next twice: written out, the condition is 2**24 leaves long."""
    levels = "\n".join(f"        p{k}/pp = p{k + 1}/pp and p{k + 1}/pp" for k in range(1, DAG_LEVELS))
    (tmp_path / "system.earl").write_text(
        f"""system dag
x/a {{
    cs {{
        period 1 ms
        n/m: int = 0
        p{DAG_LEVELS}/pp = n/mi >= 0
{levels}
        count/pf(n/mi -> n/mo) = python "dagcode:count"
        run/bb {{
            tf = {{count/pf}}
            tc = p1/pp
        }}
        again/bb {{
            tf = {{count/pf}}
            tc = p1/pp
        }}
        fsm {{
            initial run
            state run: run/bb
            state again: again/bb
            run -> again when p1/pp
            again -> run when p1/pp or p2/pp
        }}
    }}
}}
r/r {{
    x/a
}}
"""
    )
    (tmp_path / "dagcode.py").write_text("def count(i, o, c):\n    o.n = i.n + 1\n")
    return tmp_path


def test_a_predicate_that_names_another_twice_at_each_level_is_computed_once_per_decision(tmp_path: Path) -> None:
    from earl.runtime.predicates import REPEATED_EVALUATIONS

    sim = earl.simulate(earl.load(predicate_dag(tmp_path)))
    try:
        engine = sim.network.by_name["x/a.cs"]
        calls = dict.fromkeys(engine.predicates, 0)

        def counted(name: str, predicate: Any) -> Any:
            def call(*arguments: Any) -> Any:
                calls[name] += 1
                return predicate(*arguments)

            return call

        for name, predicate in list(engine.predicates.items()):
            engine.predicates[name] = counted(name, predicate)
        sim.advance_to(0.0095)  # ten decisions, each of which holds: every state's tc and its transition
        states = [sim.state_of("x/a.cs").state]
        assert states == ["run"] and sim.state_of("x/a.cs").memory["n"] == 10
        # each decision evaluates at most three conditions (tc, and a transition naming p1/pp and p2/pp): without
        # keeping values the deepest predicate would be computed 2**23 times per condition, 2.5 * 10**8 in all
        assert max(calls.values()) <= 10 * 3 * REPEATED_EVALUATIONS, calls
        assert calls[f"p{DAG_LEVELS}"] <= 10 * REPEATED_EVALUATIONS, calls
    finally:
        sim.close()


def test_only_predicates_a_condition_would_compute_many_times_over_are_kept() -> None:
    from earl.model.expressions import BooleanOperation, ElementReference, Read
    from earl.model.kinds import Kind
    from earl.runtime.predicates import REPEATED_EVALUATIONS, repeatedly_evaluated

    def named(name: str) -> Read:
        return Read(ElementReference(name, Kind.PRIMITIVE_PREDICATE), ())

    # p1 names p2 twice, p2 names p3 twice, …: p_k is reached 2**(k-1) times from p1
    definitions: dict[str, Any] = {
        f"p{k}": BooleanOperation("and", (named(f"p{k + 1}"), named(f"p{k + 1}"))) for k in range(1, 8)
    }
    definitions["p8"] = named("leaf")
    assert repeatedly_evaluated(definitions, [named("p1")]) == {"p5"}  # 16 times; p6 then only twice
    assert repeatedly_evaluated(definitions, [named("p4")]) == {"p8"}  # 16 times
    assert repeatedly_evaluated(definitions, [named("p5")]) == set()  # p8 8 times: no more than the limit
    # a predicate named by many conditions is computed once per condition: not kept
    assert repeatedly_evaluated(definitions, [named("p8")] * 20) == set()
    assert REPEATED_EVALUATIONS == 8
