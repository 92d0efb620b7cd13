"""Subsystems without a `period` that wake each other at once, for ever: run time never passes.

`earl check` warns of such a cycle (EARL-W018); at run time a subsystem that starts more than
ZERO_TIME_ITERATIONS iterations in one instant ends the run (a `zero-time-loop` fault); and a stop
signal ends a run whose instant never ends (docs/semantics.md, "When subsystems run", "Faults")."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import earl
from earl.check import check
from earl.runtime import ZeroTimeLoop
from earl.runtime.scheduler import ZERO_TIME_ITERATIONS

SPECS = Path(__file__).parent / "runtime_specs"
EARL = [sys.executable, "-m", "earl.cli.main"]


def earl_cli(*arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*EARL, *arguments], capture_output=True, text=True, timeout=120, check=False)


def ping_copy(tmp_path: Path, *replacements: tuple[str, str]) -> Path:
    """The ping spec in `tmp_path`, each (old, new) of `replacements` made at the first place of `old`."""
    target = tmp_path / "ping"
    shutil.copytree(SPECS / "ping", target)
    spec = target / "system.earl"
    text = spec.read_text()
    for old, new in replacements:
        assert old in text, old
        text = text.replace(old, new, 1)
    spec.write_text(text)
    return spec


def w018(spec: Path) -> list[str]:
    return [str(d.location) + " " + d.message for d in check(earl.load(spec)) if d.code == "EARL-W018"]


# ---------------------------------------------------------------------------------------------- the check


def test_check_warns_of_period_less_subsystems_waking_each_other_in_a_cycle() -> None:
    result = earl_cli("check", str(SPECS / "ping"))
    assert result.returncode == 0, result.stdout + result.stderr  # a warning: the spec is valid
    said = result.stdout + result.stderr
    assert "warning[EARL-W018]" in said
    assert "a/a.cs in state `s0` → b/a.cs in state `s0` → a/a.cs in state `s0`" in said
    assert "system.earl:31:13" in said  # the state the cycle is told from
    assert "give one of them a `period`" in said


def test_a_timeout_does_not_break_the_cycle_but_a_period_does(tmp_path: Path) -> None:
    # a message that comes ends the wait at once, timeout or not
    in_time = ("{ obligatory in/ib }\n", "{ obligatory in/ib timeout 5 ms }\n")
    timed = ping_copy(tmp_path / "timed", in_time, in_time)
    assert len(w018(timed)) == 1
    # with a period on b, b paces a: no cycle left (b waits for its period, not only for a)
    paced = ping_copy(tmp_path / "paced", ("b/a {\n    cs {\n", "b/a {\n    cs {\n        period 1 ms\n"))
    assert w018(paced) == []


def test_a_cycle_one_of_whose_states_also_waits_for_a_paced_sender_is_not_warned_of(tmp_path: Path) -> None:
    """a waits for b *and* for c, which has a period: c paces the cycle, so run time passes."""
    spec = ping_copy(
        tmp_path,
        ("    b/a\n", "    b/a\n    c/a\n    link c,a\n"),
        ("a/a {\n    cs {\n        in/ib: int\n", "a/a {\n    cs {\n        in/ib: int\n        tick/ib: int\n"),
        ("state s0: go/bb { obligatory in/ib }\n", "state s0: go/bb { obligatory in/ib, tick/ib }\n"),
        (
            "link a,b:",
            "c/a {\n    cs {\n        out/ob: int\n        n/m: int = 0\n        false/pp = false\n"
            '        count/pf(n/mi -> n/mo) = python "pinging:count"\n'
            '        send/pf(n/mi -> out/ob) = python "pinging:send"\n'
            "        go/bb {\n            tf = {count/pf} then {send/pf}\n            tc = false/pp\n        }\n"
            "        fsm {\n            initial s0\n            state s0: go/bb\n        }\n"
            "        period 1 ms\n    }\n}\n\nlink c,a: c/a.cs.out -> a/a.cs.tick\nlink a,b:",
        ),
    )
    assert not [d for d in check(earl.load(spec)) if d.severity.name == "ERROR"]
    assert w018(spec) == []
    simulation = earl.simulate(earl.load(spec))  # and indeed run time passes
    try:
        simulation.advance_to(0.01)
        assert simulation.faults == []
        assert simulation.state_of("a/a.cs").iteration >= 9
    finally:
        simulation.close()


AGENT_CYCLE = """\
system inside

r/r {
    a/a
}

a/a {
    cs {
        in/ib: int
        out/ob: int
        n/m: int = 0
        false/pp = false
        inc/pf(in/ib -> n/mo) = python "pinging:inc"
        send/pf(n/mi -> out/ob) = python "pinging:send"
        go/bb {
            tf = {inc/pf} then {send/pf}
            tc = false/pp
        }
        fsm {
            initial s0
            state s0: go/bb { obligatory in/ib }
        }
    }
    m/ve {
        in/ib: int
        out/ob: int
        drive/ob: int
        n/m: int = 0
        false/pp = false
        inc/pf(in/ib -> n/mo) = python "pinging:inc"
        send/pf(n/mi -> out/ob, drive/ob) = python "pinging:send"
        go/bb {
            tf = {inc/pf} then {send/pf}
            tc = false/pp
        }
        fsm {
            initial s0
            state s0: go/bb { obligatory in/ib }
        }
    }
    d/re {
        drive/ib: int
    }
    link cs,m: cs.out -> m/ve.in
    link m,cs: m/ve.out -> cs.in
    link m,d: m/ve.drive -> d/re.drive
}
"""


def test_a_control_subsystem_and_its_virtual_effector_can_be_such_a_cycle(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(AGENT_CYCLE)
    diagnostics = check(earl.load(tmp_path))
    assert [d for d in diagnostics if d.severity.name == "ERROR"] == []
    (found,) = [d.message for d in diagnostics if d.code == "EARL-W018"]
    assert "a/a.cs in state `s0` → a/a.m/ve in state `s0` → a/a.cs in state `s0`" in found


# ---------------------------------------------------------------------------------------------- the run


def test_a_zero_time_loop_ends_the_run_with_one_located_line_and_a_readable_trace(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    started = time.monotonic()
    result = earl_cli("run", str(SPECS / "ping"), "--duration", "0.001s", "--trace", str(trace))
    assert time.monotonic() - started < 60  # it used to run for ever at t = 0
    assert result.returncode == 1, result.stderr
    said = " ".join(result.stderr.split())  # Rich wraps the line at 80 columns off a terminal
    assert "Traceback" not in said
    assert (
        f"earl run: `a/a.cs` ({ZERO_TIME_ITERATIONS:,} iterations in state `s0`, system.earl:31) and `b/a.cs` "
        f"({ZERO_TIME_ITERATIONS:,} iterations in state `s0`, system.earl:55) at 0.000000 s, with no run time "
        "passing" in said
    )
    assert "EARL-W018" in said and said.endswith("the run stopped there")
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "1 zero-time-loop" in summary.stdout


def test_from_python_a_zero_time_loop_raises_and_the_simulation_cannot_go_on() -> None:
    simulation = earl.simulate(earl.load(SPECS / "ping"))
    try:
        with pytest.raises(ZeroTimeLoop, match="with no run time passing"):
            simulation.advance_to(0.001)
        (fault,) = simulation.faults
        assert (fault.kind, fault.subsystem, fault.time) == ("zero-time-loop", "a/a.cs", 0)
        assert simulation.state_of("b/a.cs").iteration == ZERO_TIME_ITERATIONS
        with pytest.raises(RuntimeError, match="stopped inside an instant"):
            simulation.advance_to(0.002)
    finally:
        simulation.close()


def test_a_subsystem_without_a_period_fed_by_a_paced_one_runs_on(tmp_path: Path) -> None:
    """The guard counts iterations in one instant only: b answers a, which has a period, once per period."""
    spec = ping_copy(tmp_path, ("a/a {\n    cs {\n", "a/a {\n    cs {\n        period 1 ms\n"))
    simulation = earl.simulate(earl.load(spec))
    try:
        simulation.advance_to(0.1)
        assert simulation.faults == []
        assert simulation.state_of("b/a.cs").iteration > 90
    finally:
        simulation.close()


# ---------------------------------------------------------------------------------------------- stopping

HANGING = """\
import time


def spin(inputs, outputs, context):
    if context.iteration == 3:
        while True:  # a function that never returns: its instant never ends
            time.sleep(0.05)
    outputs.n = inputs.n + 1
"""

HANGING_SPEC = """\
system hang

r/r {
    a/a
}

a/a {
    cs {
        n/m: int = 0
        false/pp = false
        spin/pf(n/mi -> n/mo) = python "hanging:spin"
        go/bb {
            tf = {spin/pf}
            tc = false/pp
        }
        fsm {
            initial s0
            state s0: go/bb
        }
        period 1 ms
    }
}
"""


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT])
def test_one_stop_signal_ends_a_run_whose_instant_never_ends(tmp_path: Path, stop: int) -> None:
    """The stop waits for the instant to end, 2 s at most (a repeated SIGTERM is the same request, so it
    alone could never stop a function that never returns)."""
    (tmp_path / "system.earl").write_text(HANGING_SPEC)
    (tmp_path / "hanging.py").write_text(HANGING)
    trace = tmp_path / "run.mcap"
    process = subprocess.Popen(
        [*EARL, "run", str(tmp_path), "--duration", "1s", "--trace", str(trace)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while not trace.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        time.sleep(1.5)  # the function hangs by then, at 3 ms of run time
        sent = time.monotonic()
        process.send_signal(stop)
        _, stderr = process.communicate(timeout=30)
        took = time.monotonic() - sent
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    assert "the instant running has not ended; stopping inside it" in stderr
    assert "interrupted at 0.003 s; the trace is closed" in stderr
    assert "Traceback" not in stderr
    assert 1.9 < took < 15
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
