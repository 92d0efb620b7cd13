"""EARL-W046: a condition reads an optional field only when a message that carries it has arrived.

Conditions run left to right and stop once their outcome is known, so what an earlier operand
proves (`newData(c/ib.t)` held, or failed under `not`) guards the later ones; the last test runs
the system to show that the reads the rule reports are exactly those that fault."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

import earl
from earl.check import check
from earl.model.expressions import Call, ElementReference, FieldAccess, Literal, Read
from earl.model.kinds import Kind
from earl.runtime.names import reference_key
from earl.runtime.predicates import compile_predicate

SPEC = """\
system optional

struct Inner {
    y: double?
    z: double
}

struct Cmd {
    t: Inner?
    mode: string?
    speed: double
}

r/r { x/a }

x/a {
    cs {
        period 10 ms
        c[K in 1..2]/ib: Cmd
        m/m: Cmd
        f/pf(c[*]/ib -> m/mo) = python "optcode:f"
        has/pp = newData(c[1]/ib.t)
        PREDICATES
        run/bb {
            tf = {f/pf}
            tc = CONDITION
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when true
        }
    }
}
"""


def warned(condition: str, predicates: str = "") -> list[str]:
    text = SPEC.replace("CONDITION", condition).replace("        PREDICATES\n", textwrap.indent(predicates, " " * 8))
    return [d.message for d in check(earl.loads(text, "optional.earl")) if d.code == "EARL-W046"]


@pytest.mark.parametrize(
    "condition",
    [
        "newData(c[1]/ib.t) and c[1]/ib.t.z > 3.0",
        "not newData(c[1]/ib.t) or c[1]/ib.t.z > 3.0",
        "not (not newData(c[1]/ib.t)) and c[1]/ib.t.z > 3.0",
        "has/pp and c[1]/ib.t.z > 3.0",  # the guard is a predicate's definition
        "newData(c[1]/ib.t.z) and c[1]/ib.t.z > 3.0",  # a field inside `t` is new only when `t` is there
        "((newData(c[1]/ib.t) and c[1]/ib.speed > 1.0) or (newData(c[1]/ib.t) and c[1]/ib.speed < 0.0)) and c[1]/ib.t.z > 3.0",
        'c[1]/ib.mode == "stop"',  # an absent field equals no value: nothing raises
        "c[1]/ib.t != c[2]/ib.t",
        "c[1]/ib.t.z == 1.0",  # a field inside an absent one is absent too: `==` is false, nothing raises
        "timeout(c[1]/ib.t) or newData(c[1]/ib.t)",  # neither reads the field
        "newData(c[1]/ib.t.y) and c[1]/ib.t.y > 1.0",
        "m/mi.t.z > 1.0",  # memory has no `newData`: nothing could guard it
        "c[1]/ib.speed > 1.0",
    ],
)
def test_reads_that_cannot_meet_an_absent_field_are_not_reported(condition: str) -> None:
    assert warned(condition) == []


@pytest.mark.parametrize(
    ("condition", "field", "guard"),
    [
        ("c[1]/ib.t.z > 3.0", "t", "c[1]/ib.t"),
        ("c[1]/ib.t.z > 3.0 and newData(c[1]/ib.t)", "t", "c[1]/ib.t"),  # the guard comes too late
        ("newData(c[1]/ib.t) or c[1]/ib.t.z > 3.0", "t", "c[1]/ib.t"),  # read exactly when it is not new
        ("(newData(c[1]/ib.t) or c[1]/ib.speed > 1.0) and c[1]/ib.t.z > 3.0", "t", "c[1]/ib.t"),
        ("newData(c[2]/ib.t) and c[1]/ib.t.z > 3.0", "t", "c[1]/ib.t"),  # another member's message
        ("newData(c[1]/ib.t) and c[1]/ib.t.y > 1.0", "t.y", "c[1]/ib.t.y"),  # `y` is optional in turn
        ("c[1]/ib.speed * 2.0 > 1.0 or -c[1]/ib.t.z > 1.0", "t", "c[1]/ib.t"),
    ],
)
def test_reads_that_may_meet_an_absent_field_are_reported_with_the_guard_to_write(
    condition: str, field: str, guard: str
) -> None:
    [message] = warned(condition)
    assert f"the optional field `{field}` has arrived" in message
    diagnostics = check(earl.loads(SPEC.replace("CONDITION", condition).replace("        PREDICATES\n", ""), "o.earl"))
    [diagnostic] = [d for d in diagnostics if d.code == "EARL-W046"]
    assert diagnostic.hint is not None and f"`newData({guard}) and …`" in diagnostic.hint


def test_a_read_inside_a_predicate_is_judged_where_a_condition_names_it_and_said_once() -> None:
    predicates = (
        "far/pp = c[1]/ib.t.z > 3.0\nnear/pp = not far/pp\nodd/pp = not odd/pp\nunused/pp = c[2]/ib.t.z > 1.0\n"
    )
    assert warned("has/pp and (far/pp or near/pp)", predicates) == []
    [message] = warned("far/pp or near/pp or odd/pp", predicates)  # one read, reached twice
    assert message.startswith("the terminal condition of `run/bb` (through `far/pp`) reads `c[1]/ib.t.z`")


def test_the_reads_reported_are_the_reads_that_fault_at_run_time(tmp_path: Path) -> None:
    (tmp_path / "optcode.py").write_text("def f(i, o, c):\n    pass\n")
    for condition, faults in (("c[1]/ib.t.z > 3.0", True), ("newData(c[1]/ib.t) and c[1]/ib.t.z > 3.0", False)):
        spec = tmp_path / "system.earl"
        spec.write_text(SPEC.replace("CONDITION", condition).replace("        PREDICATES\n", ""))
        assert bool(warned(condition)) is faults
        simulation = earl.simulate(earl.load(spec), environment=None)
        simulation.advance_to(0.05)
        simulation.close()
        assert bool(simulation.faults) is faults, simulation.faults


@pytest.mark.parametrize(
    ("message", "carried"),
    [
        ({"t": None}, False),  # `t` absent: no fault, and not new
        ({"t": {"y": None, "z": 1.0}}, True),
        ({"t": {"y": None, "z": None}}, False),
    ],
)
def test_new_data_of_a_field_inside_an_absent_field_is_false_not_a_fault(
    message: dict[str, object], carried: bool
) -> None:
    """`newData(c[1]/ib.t.z)`: a new message that carries `t.z`; one without `t` does not carry it."""
    target = ElementReference("c", Kind.INPUT_BUFFER, (Literal(1),))
    new_data = Call("newData", (Read(target, (FieldAccess("t"), FieldAccess("z"))),))
    predicate = compile_predicate(new_data, "x/a.cs probe")
    key = reference_key(target)
    assert predicate({key: message}, {key: True}, {}, {}, {}) is carried
    assert predicate({key: message}, {key: False}, {}, {}, {}) is False


def test_predicates_named_twice_or_through_themselves_are_followed_once() -> None:
    """`odd/pp = odd/pp and odd/pp` made the rule expand without end (earl check hung); a chain whose
    every predicate names the next twice doubled the walk at each link."""
    import time

    doubled = "".join(f"d{i}/pp = d{i + 1}/pp and d{i + 1}/pp\n" for i in range(40)) + "d40/pp = c[1]/ib.t.z > 3.0\n"
    started = time.monotonic()
    assert warned("odd/pp", "odd/pp = odd/pp and odd/pp\n") == []
    [message] = warned("d0/pp", doubled)
    assert time.monotonic() - started < 10
    assert "(through `d40/pp`) reads `c[1]/ib.t.z`" in message


def test_a_read_deep_inside_predicates_and_nots_is_still_found() -> None:
    chain = "".join(f"p{i}/pp = c[2]/ib.speed < 1.0 and p{i + 1}/pp\n" for i in range(1, 21))
    chain += "p21/pp = c[1]/ib.t.z > 3.0\n"
    assert len(warned("p1/pp", chain)) == 1
    assert len(warned("not (" * 34 + "c[1]/ib.t.z > 3.0" + ")" * 34)) == 1


def test_an_optional_boolean_taken_as_a_condition_reads_as_false_and_the_warning_says_so() -> None:
    text = SPEC.replace("    speed: double\n", "    speed: double\n    flag: boolean?\n")
    for condition in ("c[1]/ib.flag", "not c[1]/ib.flag", "c[1]/ib.flag or c[2]/ib.speed < 1.0"):
        system = earl.loads(text.replace("CONDITION", condition).replace("        PREDICATES\n", ""), "o.earl")
        [message] = [d.message for d in check(system) if d.code == "EARL-W046"]
        assert message.endswith("an absent field reads as false (and `not` of it as true)")
    assert [
        d
        for d in check(
            earl.loads(text.replace("CONDITION", "c[1]/ib.flag == true").replace("        PREDICATES\n", ""), "o.earl")
        )
        if d.code == "EARL-W046"
    ] == []


def test_a_predicate_compared_for_equality_is_judged_as_the_field_itself_would_be() -> None:
    """`p/pp == false` of an absent Boolean does not hold, as `c[1]/ib.flag == false` does not: no warning
    that it reads as false, where `not p/pp` does read as true."""
    text = SPEC.replace("    speed: double\n", "    speed: double\n    flag: boolean?\n")
    predicates = "        p/pp = c[1]/ib.flag\n"
    found = {}
    for condition in ("p/pp == false", "p/pp != true", "not p/pp"):
        system = earl.loads(text.replace("CONDITION", condition).replace("        PREDICATES\n", predicates), "o.earl")
        found[condition] = [d.message for d in check(system) if d.code == "EARL-W046"]
    assert found["p/pp == false"] == found["p/pp != true"] == []
    assert len(found["not p/pp"]) == 1
