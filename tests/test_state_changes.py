"""What a state change records: which declared transition was taken (a `* -> S` line is told from `R -> S`),
and when (the instant the decision was made, after any wait of its iteration); docs/semantics.md, "The trace"."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import jsonschema
from mcap.reader import make_reader

import earl
from earl.runtime.events import Recorder

MS = 1_000_000
EARL = [sys.executable, "-m", "earl.cli.main"]

# n counts the iterations: at n == 1 `s0 -> s1` holds, at n == 3 only `* -> s1` (from s0 too)
STAR = """\
system star

r/r {
    a/a
}

a/a {
    cs {
        period 10 ms
        n/m: int = 0
        true/pp = true
        odd/pp = n/mi == 1
        even/pp = n/mi == 3
        inc/pf(n/mi -> n/mo) = python "counting:inc"
        go/bb {
            tf = {inc/pf}
            tc = true/pp
        }
        fsm {
            initial s0
            state s0: go/bb
            state s1: go/bb

            s0 -> s1 when odd/pp
            * -> s1 when even/pp
            s1 -> s0 when true/pp
        }
    }
}
"""

COUNTING = """\
def inc(inputs, outputs, context):
    outputs.n = inputs.n + 1
"""


class Changes(Recorder):
    def __init__(self) -> None:
        self.changes: list[tuple[int, str | None, str, Any]] = []

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        self.changes.append((time, source, destination, transition))


def star_spec(tmp_path: Path) -> Path:
    (tmp_path / "system.earl").write_text(STAR)
    (tmp_path / "counting.py").write_text(COUNTING)
    return tmp_path


def test_the_trace_says_which_declared_transition_was_taken_and_stays_valid_against_its_schema(
    tmp_path: Path,
) -> None:
    trace = tmp_path / "run.mcap"
    result = subprocess.run(
        [*EARL, "run", str(star_spec(tmp_path)), "--duration", "40ms", "--trace", str(trace)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    changes = []
    with trace.open("rb") as stream:
        for schema, _channel, message in make_reader(stream).iter_messages(topics=["/a/a.cs/fsm"]):
            data = json.loads(message.data)
            assert schema is not None
            jsonschema.validate(data, json.loads(schema.data))
            changes.append((message.log_time, data))
    assert changes == [
        (0, {"to": "s0"}),
        (0, {"from": "s0", "to": "s1", "transition": "s0,s1"}),  # `s0 -> s1`, which names itself
        (10 * MS, {"from": "s1", "to": "s0", "transition": "s1,s0"}),
        (20 * MS, {"from": "s0", "to": "s1", "transition": "s0,s1", "declared": "*,s1"}),  # the `*` line
        (30 * MS, {"from": "s1", "to": "s0", "transition": "s1,s0"}),
    ]  # at 40 ms n == 5: neither holds, and s0 stays


def test_a_recorder_is_given_the_name_it_always_was_which_also_says_the_declared_one(tmp_path: Path) -> None:
    changes = Changes()
    simulation = earl.simulate(earl.load(star_spec(tmp_path)), recorders=[changes])
    try:
        simulation.advance_to(0.025)
    finally:
        simulation.close()
    names = [transition for _, _, _, transition in changes.changes]
    assert names == [None, "s0,s1", "s1,s0", "s0,s1"]
    assert [getattr(name, "declared", None) for name in names] == [None, "s0,s1", "s1,s0", "*,s1"]
    assert all(type(str(name)) is str for name in names[1:])


# a state of `period 10 ms` whose buffer group waits 3 ms for a message that never comes
WAITING = """\
system waiting

r/r {
    a/a
}

a/a {
    cs {
        period 10 ms
        in/ib: int
        n/m: int = 0
        lost/pp = timeout(in/ib)
        true/pp = true
        inc/pf(n/mi -> n/mo) = python "counting:inc"
        go/bb {
            tf = {inc/pf}
            tc = lost/pp
        }
        other/bb {
            tf = {inc/pf}
            tc = true/pp
        }
        fsm {
            initial wait
            state wait: go/bb { obligatory in/ib  timeout 3 ms }
            state gone: other/bb

            wait -> gone when lost/pp
        }
    }
}
"""


def test_a_state_change_after_a_wait_is_stamped_when_the_wait_ended(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(WAITING)
    (tmp_path / "counting.py").write_text(COUNTING)
    changes = Changes()
    simulation = earl.simulate(earl.load(tmp_path), recorders=[changes])
    try:
        simulation.advance_to(0.015)
        iterations = simulation.state_of("a/a.cs").memory["n"]
    finally:
        simulation.close()
    # the iteration starts at 0, times out at 3 ms and decides then; the next state's first iteration comes
    # one period after the deciding iteration's start, at 10 ms
    assert [(time, source, destination) for time, source, destination, _ in changes.changes] == [
        (0, None, "wait"),
        (3 * MS, "wait", "gone"),
    ]
    assert iterations == 2  # at 0 and at 10 ms


def test_a_fault_in_the_condition_of_a_star_transition_names_it_as_declared(tmp_path: Path) -> None:
    spec = star_spec(tmp_path)
    text = (spec / "system.earl").read_text()
    text = text.replace("        n/m: int = 0\n", "        n/m: int = 0\n        v/m: double[3] = [0.0, 0.0, 0.0]\n")
    text = text.replace("even/pp = n/mi == 3", "even/pp = v/mi[5] > 1.0")
    (spec / "system.earl").write_text(text)
    simulation = earl.simulate(earl.load(spec), check=False)  # `earl check` refuses the index (EARL-E030)
    try:
        simulation.advance_to(0.02)  # at 20 ms, n == 3 in s0: `s0 -> s1` does not hold, the `*` line is tried
        faults = [(fault.time_ns, fault.kind, fault.message) for fault in simulation.faults]
    finally:
        simulation.close()
    assert faults[0] == (
        20 * MS,
        "predicate",
        "evaluating the condition of `*,s1/t` (from `s0`) in `even/pp`: `v/mi` has no element 5 (it has 3 elements)",
    )
