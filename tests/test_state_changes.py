"""What a state change records: when (the instant the decision was made, after any wait of its
iteration); docs/semantics.md, "The trace"."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import earl
from earl.runtime.events import Recorder

MS = 1_000_000

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
