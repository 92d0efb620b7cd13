"""Conditions reading a message whose optional field is absent (docs/language.md, "Built-in functions"):
`==` and `!=` hold as for an absent field, whose fields are absent too; other operators fault, and the
fault says in EARL's words what was absent."""

from __future__ import annotations

from pathlib import Path

import earl
from earl.check import check

# `s` sends a Cmd whose optional `inner` and `v` are absent and whose `values` is empty, at t = 0
SPEC = """\
system absent

struct Inner {
    x: double
}

struct Cmd {
    inner: Inner?
    values: double[]
    v: double?
    id: int
}

r/r {
    s/a
    e/a
    f/a
    link s,e
    link s,f
}

s/a {
    cs {
        period 10 ms
        cmd/ob: Cmd
        n/m: int = 0
        false/pp = false
        inc/pf(n/mi -> n/mo) = python "absent:inc"
        out/pf(n/mi -> cmd/ob) = python "absent:out"
        run/bb {
            tf = {inc/pf} then {out/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

e/a {
    cs {
        period 10 ms
        cmd/ib: Cmd
        came/pp = newData(cmd/ib)
        false/pp = false
        eqX/pp = cmd/ib.inner.x == 1.0
        neX/pp = cmd/ib.inner.x != 1.0
        wait/bb {
            tf = {}
            tc = came/pp
        }
        stay/bb {
            tf = {}
            tc = false/pp
        }
        fsm {
            initial idle
            state idle: wait/bb
            state equal: stay/bb
            state unequal: stay/bb

            idle -> equal when eqX/pp priority 1
            idle -> unequal when neX/pp priority 2
        }
    }
}

f/a {
    cs {
        period 10 ms
        cmd/ib: Cmd
        came/pp = newData(cmd/ib)
        false/pp = false
        intoAbsent/pp = cmd/ib.inner.x > 0.5
        absentValue/pp = cmd/ib.v > 1.0
        beyondEnd/pp = cmd/ib.values[0] > 0.0
        wait/bb {
            tf = {}
            tc = came/pp
        }
        stay/bb {
            tf = {}
            tc = false/pp
        }
        fsm {
            initial idle
            state idle: wait/bb
            state other: stay/bb

            idle -> other when intoAbsent/pp priority 1
            idle -> other when absentValue/pp priority 2
            idle -> other when beyondEnd/pp priority 3
        }
    }
}

link s,e: s/a.cs.cmd -> e/a.cs.cmd
link s,f: s/a.cs.cmd -> f/a.cs.cmd
"""

CODE = """\
def inc(inputs, outputs, context):
    outputs.n = inputs.n + 1


def out(inputs, outputs, context):
    outputs.cmd = {"inner": None, "values": [], "v": None, "id": inputs.n}
"""


def spec(tmp_path: Path) -> Path:
    (tmp_path / "system.earl").write_text(SPEC)
    (tmp_path / "absent.py").write_text(CODE)
    return tmp_path


def test_equality_through_an_absent_optional_field_is_that_of_an_absent_field(tmp_path: Path) -> None:
    simulation = earl.simulate(earl.load(spec(tmp_path)))
    try:
        simulation.advance_to(0.0)
        # `cmd/ib.inner.x == 1.0` is false and `!=` true while `inner` is absent; neither faults
        assert simulation.state_of("e/a.cs").state == "unequal"
        assert [fault for fault in simulation.faults if fault.subsystem == "e/a.cs"] == []
    finally:
        simulation.close()


def test_other_operators_fault_saying_what_was_absent_in_earl_s_words(tmp_path: Path) -> None:
    simulation = earl.simulate(earl.load(spec(tmp_path)))
    try:
        simulation.advance_to(0.0)
        messages = [fault.message for fault in simulation.faults if fault.subsystem == "f/a.cs"]
    finally:
        simulation.close()
    assert messages[:3] == [
        "evaluating the condition of `idle,other/t` in `intoAbsent/pp`: `cmd/ib.inner` was absent "
        "(guard the read: `newData(cmd/ib.inner) and …`, EARL-W046)",
        "evaluating the condition of `idle,other/t` in `absentValue/pp`: `cmd/ib.v` was absent "
        "(guard the read: `newData(cmd/ib.v) and …`, EARL-W046)",
        "evaluating the condition of `idle,other/t` in `beyondEnd/pp`: `cmd/ib.values` has no element 0 "
        "(it has 0 elements)",
    ]
    assert not any("NoneType" in message or "index out of range" in message for message in messages)


def test_the_check_warns_of_the_reads_that_fault_and_not_of_equality(tmp_path: Path) -> None:
    warned = [d.message for d in check(earl.load(spec(tmp_path))) if d.code == "EARL-W046"]
    assert any("`intoAbsent/pp`" in message for message in warned)
    assert any("`absentValue/pp`" in message for message in warned)
    assert not any("eqX/pp" in message or "neX/pp" in message for message in warned), warned
