"""A period or timeout that is not a whole number of nanoseconds is rounded, and `earl check` says so (EARL-W045)
with what the run will use."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import earl

SPEC = """\
system per

r/r {
    a/a
}

a/a {
    cs {
        period 0.0015 us
        in/ib: int
        n/m: int = 0
        false/pp = false
        inc/pf(n/mi -> n/mo) = python "per:inc"
        go/bb {
            tf = {inc/pf}
            tc = false/pp
        }
        fsm {
            initial s0
            state s0: go/bb { obligatory in/ib  timeout 0.0025 us }
        }
    }
}
"""


def test_check_warns_at_the_line_of_each_rounded_duration_with_what_the_run_uses(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(SPEC)
    (tmp_path / "per.py").write_text("def inc(inputs, outputs, context):\n    outputs.n = inputs.n + 1\n")
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "check", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr  # warnings: the spec is valid
    said = result.stdout + result.stderr
    assert "warning[EARL-W045]: the period of a/a.cs, `period 0.0015 us`, is 1.5 ns" in said
    assert "system.earl:9:9" in said  # at `period`
    assert "warning[EARL-W045]: the timeout of state `s0` of a/a.cs, `timeout 0.0025 us`, is 2.5 ns" in said
    said_period, said_timeout = (int(n) for n in re.findall(r"so it runs as (\d+) ns", said))
    assert "hint: write a whole number of nanoseconds: `period 0.002 us` (2 ns)" in said
    simulation = earl.simulate(earl.load(tmp_path))
    try:
        engine = simulation.network.by_name["a/a.cs"]
        assert (engine.period, engine.states["s0"].timeout) == (said_period, said_timeout) == (2, 2)  # 2.5 to even
    finally:
        simulation.close()
