"""Real time: an iteration whose start the wait of the one before it put off past its period's instant is
late from that instant, and an overrun (docs/semantics.md, "When subsystems run")."""

from __future__ import annotations

from pathlib import Path

import earl

# `sender` sends every 20 ms; `d` has a period of 2 ms and waits up to 10 ms for the message: an iteration
# that starts at 2 ms waits until its timeout at 12 ms, so the next one, due at 4 ms, starts 8 ms late.
SPEC = """\
system late

r/r {
    sender/a
    d/a
    link sender,d
}

sender/a {
    cs {
        period 20 ms
        out/ob: int
        n/m: int = 0
        false/pp = false
        count/pf(n/mi -> n/mo) = python "late:count"
        send/pf(n/mi -> out/ob) = python "late:send"
        run/bb {
            tf = {count/pf} then {send/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

d/a {
    cs {
        period 2 ms
        in/ib: int
        v/m: int = 0
        false/pp = false
        take/pf(in/ib -> v/mo) = python "late:take"
        run/bb {
            tf = {take/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb { obligatory in/ib  timeout 10 ms }
        }
    }
}

link sender,d: sender/a.cs.out -> d/a.cs.in
"""

CODE = """\
def count(inputs, outputs, context):
    outputs.n = inputs.n + 1


def send(inputs, outputs, context):
    outputs.out = inputs.n


def take(inputs, outputs, context):
    outputs.v = inputs["in"]
"""


def test_an_iteration_put_off_by_the_wait_before_it_is_late_from_its_period_and_an_overrun(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(SPEC)
    (tmp_path / "late.py").write_text(CODE)
    simulation = earl.simulate(earl.load(tmp_path), realtime=True)
    try:
        simulation.advance_to(0.2)
        lateness = simulation.scheduler.lateness["d/a.cs"]
        faults = [fault for fault in simulation.faults if fault.subsystem == "d/a.cs"]
    finally:
        simulation.close()
    # after each wait the next iteration starts 6 or 8 ms after its period's instant: ~20 of them in 0.2 s
    put_off = [late for late in lateness.samples if late >= 5_000_000]
    assert len(put_off) >= 15, sorted(lateness.samples)[-20:]
    assert lateness.overruns >= len(put_off)
    (deadline,) = [fault for fault in faults if fault.kind == "deadline"]  # the first overrun, recorded
    # at 12 ms, unless the wall clock made an earlier iteration more than a period late on a loaded machine
    if deadline.time == 0.012:
        assert (
            "due at 0.004000 s by its period (2 ms): the iteration before it waited for its obligatory buffers "
            "until 8 ms after that" in deadline.message
        )
