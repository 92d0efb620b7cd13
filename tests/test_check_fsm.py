"""The FSM analysis against brute force: on random FSMs, the BDDs find exactly what trying every
assignment of the primitive predicates finds, and every assignment they show really does what the
message says.  As `fsm.selectState()` runs: the transitions leaving a state are tried only when its
behaviour stops, in priority order."""

from __future__ import annotations

import itertools
import random
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.check import check, context_for
from earl.diagnostics import Diagnostic
from earl.model.elements import FSM, Subsystem, Transition
from earl.model.expressions import BooleanOperation, Expression, Literal, Not, Read
from earl.model.kinds import Kind

PREDICATES = 5


def random_fsm(seed: int) -> str:
    """One control subsystem: four states, three transitions out of each, conditions of one to three
    literals, priorities on some, one `assume`; the behaviours stop on one of two predicates or never."""
    chooser = random.Random(seed)
    names = [f"p{i}" for i in range(1, PREDICATES + 1)]

    def literal() -> str:
        name = chooser.choice(names)
        return f"{name}/pp" if chooser.random() < 0.6 else f"not {name}/pp"

    lines = ["system random", "", "r/r { a/a }", "", "a/a {", "    cs {"]
    lines += [f"        x{i}/ib: boolean" for i in range(1, PREDICATES + 1)]
    lines += [f"        p{i}/pp = x{i}/ib" for i in range(1, PREDICATES + 1)]
    for state in range(1, 5):
        stop = "false" if chooser.random() < 0.15 else " or ".join(literal() for _ in range(2))
        lines += [f"        b{state}/bb {{", "            tf = {}", f"            tc = {stop}", "        }"]
    lines += ["        fsm {", "            initial s1"]
    lines += [f"            state s{state}: b{state}/bb" for state in range(1, 5)]
    for state in range(1, 5):
        for destination in chooser.sample(range(1, 5), 3):
            condition = " and ".join(literal() for _ in range(chooser.randint(1, 3)))
            priority = f" priority {chooser.randint(1, 2)}" if chooser.random() < 0.4 else ""
            lines.append(f"            s{state} -> s{destination} when {condition}{priority}")
    first, second = chooser.sample(names, 2)
    lines += [f"            assume not ({first}/pp and {second}/pp)", "        }", "    }", "}", ""]
    return "\n".join(lines)


def value(expression: Expression, assignment: Mapping[str, bool]) -> bool:
    if isinstance(expression, Literal) and isinstance(expression.value, bool):
        return expression.value
    if isinstance(expression, Not):
        return not value(expression.operand, assignment)
    if isinstance(expression, BooleanOperation):
        results = [value(operand, assignment) for operand in expression.operands]
        return all(results) if expression.operator == "and" else any(results)
    assert isinstance(expression, Read) and expression.target.kind is Kind.PRIMITIVE_PREDICATE
    return assignment[expression.target.name]


def brute_force(subsystem: Subsystem, fsm: FSM) -> dict[str, set[str]]:
    """What the analysis must report, from all 2^5 assignments."""
    assignments = [
        dict(zip([f"p{i}" for i in range(1, PREDICATES + 1)], values, strict=True))
        for values in itertools.product((False, True), repeat=PREDICATES)
    ]
    allowed = [a for a in assignments if all(value(x.expression, a) for x in fsm.assumptions)]
    found: dict[str, set[str]] = {code: set() for code in ("EARL-E060", "EARL-W061", "EARL-W062", "EARL-I063")}
    ending: dict[str, bool] = {}
    for state in fsm.states:
        behaviour = subsystem.basic_behaviour(state.behaviour)
        assert behaviour is not None

        def stops(a: dict[str, bool]) -> bool:
            return value(behaviour.terminal_condition.expression, a)  # noqa: B023

        ending[state.name] = any(stops(a) for a in allowed)
        if not ending[state.name]:
            found["EARL-I063"].add(state.name)
            continue
        leaving = [t for t in fsm.transitions if t.source == state.name]
        stopping = [a for a in allowed if stops(a)]  # transitions are tried only when the behaviour stops

        def distinct(first: Transition, second: Transition) -> bool:
            return (first.priority is not None or second.priority is not None) and first.priority != second.priority

        def rank(t: Transition) -> tuple[bool, int]:
            return (t.priority is None, t.priority or 0)

        for t in leaving:
            before = [u for u in leaving if distinct(u, t) and rank(u) < rank(t)]
            taken = any(
                value(t.condition.expression, a) and not any(value(u.condition.expression, a) for u in before)
                for a in stopping
            )
            if not taken:
                found["EARL-W062"].add(t.name)
        for first, second in itertools.combinations(leaving, 2):
            # both the first to hold: a transition of higher priority holding is taken instead
            higher = [u for u in leaving if distinct(u, first) and rank(u) < rank(first)]
            both = any(
                value(first.condition.expression, a)
                and value(second.condition.expression, a)
                and not any(value(u.condition.expression, a) for u in higher)
                for a in stopping
            )
            if not distinct(first, second) and both:
                found["EARL-E060"].add(f"{first.name}|{second.name}")
        if any(stops(a) and not any(value(t.condition.expression, a) for t in leaving) for a in allowed):
            found["EARL-W061"].add(state.name)
    return found


PATTERNS = {
    "EARL-E060": re.compile(r"transitions `([^`]+)/t` and `([^`]+)/t`"),
    "EARL-W061": re.compile(r"no transition out of `([^`]+)`"),
    "EARL-W062": re.compile(r"transition `([^`]+)/t`"),
    "EARL-I063": re.compile(r"so state `([^`]+)`"),
}


def reported(diagnostics: list[Diagnostic]) -> dict[str, set[str]]:
    found: dict[str, set[str]] = {code: set() for code in PATTERNS}
    for diagnostic in diagnostics:
        if diagnostic.code in PATTERNS:
            match = PATTERNS[diagnostic.code].search(diagnostic.message)
            assert match is not None, diagnostic.message
            found[diagnostic.code].add("|".join(match.groups()))
    return found


def witness(message: str) -> dict[str, bool]:
    """The assignment a message shows (`… e.g. when p1/pp = true, p3/pp = false`); unnamed ones are free."""
    assignment = {f"p{i}": False for i in range(1, PREDICATES + 1)}
    shown = message.split("e.g. when ", 1)[1]
    if shown != "always":
        for part in shown.split(", "):
            name, _, truth = part.rpartition(" = ")
            assignment[name.removesuffix("/pp")] = truth == "true"
    return assignment


@pytest.mark.parametrize("seed", range(25))
def test_the_bdd_analysis_finds_what_brute_force_finds(seed: int) -> None:
    system = earl.loads(random_fsm(seed), "random.earl")
    subsystem = next(s for _, s in context_for(system).subsystems())
    assert subsystem.fsm is not None
    diagnostics = check(system)
    assert reported(diagnostics) == brute_force(subsystem, subsystem.fsm)
    transitions = {t.name: t for t in subsystem.fsm.transitions}
    assumptions = subsystem.fsm.assumptions
    for diagnostic in diagnostics:
        if diagnostic.code == "EARL-E060":
            match = PATTERNS["EARL-E060"].search(diagnostic.message)
            assert match is not None
            assignment = witness(diagnostic.message)
            assert all(value(a.expression, assignment) for a in assumptions)
            assert all(value(transitions[name].condition.expression, assignment) for name in match.groups())
            source = subsystem.fsm.state_named(transitions[match.group(1)].source)
            stopping = subsystem.basic_behaviour(source.behaviour) if source else None
            assert stopping is not None and value(stopping.terminal_condition.expression, assignment)
        if diagnostic.code == "EARL-W061":
            match = PATTERNS["EARL-W061"].search(diagnostic.message)
            assert match is not None
            state = subsystem.fsm.state_named(match.group(1))
            behaviour = subsystem.basic_behaviour(state.behaviour) if state else None
            assert behaviour is not None
            assignment = witness(diagnostic.message)
            assert all(value(a.expression, assignment) for a in assumptions)
            assert value(behaviour.terminal_condition.expression, assignment)
            leaving = [t for t in subsystem.fsm.transitions if t.source == match.group(1)]
            assert not any(value(t.condition.expression, assignment) for t in leaving)


def test_the_random_fsms_exercise_every_finding() -> None:
    """The seeds above are not all quiet: together they produce each kind of finding."""
    seen: set[str] = set()
    for seed in range(25):
        seen.update(d.code for d in check(earl.loads(random_fsm(seed), "random.earl")) if d.code in PATTERNS)
    assert seen == set(PATTERNS)


def test_equal_priorities_still_overlap() -> None:
    text = random_fsm(0)
    base = "\n".join(line for line in text.splitlines() if not line.strip().startswith("s1 ->"))
    both = base.replace(
        "            state s4: b4/bb\n",
        "            state s4: b4/bb\n            s1 -> s2 when p1/pp priority 1\n            s1 -> s3 when p1/pp priority 1\n",
    )
    overlaps = [d for d in check(earl.loads(both, "random.earl")) if d.code == "EARL-E060" and "`s1,s2/t`" in d.message]
    assert len(overlaps) == 1
    assert "e.g. when p1/pp = true" in overlaps[0].message
    apart = both.replace("s1 -> s3 when p1/pp priority 1", "s1 -> s3 when p1/pp priority 2")
    assert not [d for d in check(earl.loads(apart, "random.earl")) if d.code == "EARL-E060" and "`s1," in d.message]


PROBE = """\
system probe

struct S {
    a: double
    b: boolean
    mode: string
    opt: double?
}

r/r { x/a }

x/a {
    cs {
        period 10 ms
        v/ib: double
        s/ib: S
        m/m: double = 0.0
        go/pp = newData(v/ib)
        hot/pp = v/ib > 3.0
        cold/pp = not hot/pp
        false/pp = false
        work/pf(v/ib, s/ib -> m/mo)
        run/bb {
            tf = {work/pf}
            tc = TC
        }
        sink/bb {
            tf = {work/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
            state a: sink/bb
            state b: sink/bb
            run -> a when FIRST
            run -> b when SECOND
        }
    }
}
"""


def probe(first: str, second: str, stop: str = "go/pp") -> dict[str, list[str]]:
    """The FSM findings for `run -> a when FIRST` and `run -> b when SECOND`, the behaviour stopping on `stop`."""
    text = PROBE.replace("TC", stop).replace("FIRST", first).replace("SECOND", second)
    found: dict[str, list[str]] = {}
    for diagnostic in check(earl.loads(text, "probe.earl")):
        if diagnostic.code in ("EARL-E060", "EARL-W061", "EARL-W062", "EARL-I063", "EARL-E064"):
            found.setdefault(diagnostic.code, []).append(diagnostic.message)
    found.pop("EARL-I063")  # the sinks
    return found


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("v/ib > 5.0", "v/ib < 3.0"),
        ("v/ib > 3.0", "v/ib <= 3.0"),
        ("v/ib >= 3.0", "3.0 > v/ib"),
        ("v/ib == 2.0", "v/ib != 2.0"),
        ('s/ib.mode == "stop"', 's/ib.mode == "go"'),
        ("hot/pp", "cold/pp"),
        ("s/ib.b", "s/ib.b == false"),
        ("s/ib.b", "s/ib.b != true"),
        ("newData(s/ib.opt)", "not newData(s/ib)"),
        ("newData(v/ib)", "timeout(v/ib)"),
    ],
)
def test_conditions_that_exclude_each_other_through_what_they_compare_do_not_overlap(first: str, second: str) -> None:
    assert "EARL-E060" not in probe(first, second, stop="true")


@pytest.mark.parametrize(
    ("first", "second", "example"),
    [
        ("v/ib > 3.0 and v/ib < 5.0", "v/ib > 4.0", "4.0 < v/ib < 5.0"),
        ('s/ib.mode == "stop"', 's/ib.mode != "go"', 's/ib.mode != "go" = true, s/ib.mode == "stop" = true'),
        ("hot/pp", "v/ib > 4.0", "hot/pp = true, v/ib > 4.0"),
    ],
)
def test_conditions_that_can_hold_together_still_overlap_with_an_example_in_the_spec_s_words(
    first: str, second: str, example: str
) -> None:
    [message] = probe(first, second, stop="true")["EARL-E060"]
    assert message.endswith(f"e.g. when {example}"), message


def test_transitions_are_tried_only_when_the_behaviour_stops() -> None:
    # `not go/pp` and `hot/pp` overlap, but never when `run/bb` stops (on go/pp)
    found = probe("hot/pp", "not go/pp")
    assert "EARL-E060" not in found
    assert found["EARL-W062"] == [
        "transition `run,b/t` of x/a.cs can never be taken: its condition never holds when `run/bb` stops"
    ]
    # a terminal condition that cannot hold: the behaviour never ends, and nothing else is said
    assert probe("hot/pp", "go/pp", stop="v/ib > 5.0 and v/ib < 3.0") == {}


def test_a_transition_always_preceded_by_one_of_higher_priority_is_never_taken() -> None:
    found = probe("go/pp priority 1", "go/pp and hot/pp priority 2")
    assert found == {
        "EARL-W062": [
            "transition `run,b/t` of x/a.cs can never be taken: whenever its condition holds, `run,a/t` holds "
            "too and is tried first"
        ]
    }


def test_assumptions_that_contradict_each_other_are_an_error_not_a_silence() -> None:
    text = PROBE.replace("TC", "go/pp").replace("FIRST", "go/pp").replace("SECOND", "go/pp")
    text = text.replace(
        "            run -> b when go/pp\n", "            run -> b when go/pp\n            assume go/pp and not go/pp\n"
    )
    codes = [d.code for d in check(earl.loads(text, "probe.earl")) if d.code.startswith("EARL-E")]
    assert codes == ["EARL-E064"]


def test_contradicting_assumptions_are_pointed_at_and_innocent_ones_are_not() -> None:
    # only the two comparisons of `v/ib` contradict each other: the caret and the message are theirs
    assumptions = (
        "            assume not s/ib.b or v/ib > 0.0\n"
        '            assume s/ib.mode == "a"\n'
        "            assume v/ib > 3.0\n"
        "            assume v/ib < 2.0\n"
    )
    text = PROBE.replace("TC", "go/pp").replace("FIRST", "go/pp").replace("SECOND", "hot/pp")
    text = text.replace("            run -> b when hot/pp\n", "            run -> b when hot/pp\n" + assumptions)
    [contradiction] = [d for d in check(earl.loads(text, "probe.earl")) if d.code == "EARL-E064"]
    assert contradiction.location is not None
    assert (contradiction.location.line, contradiction.location.column) == (40, 13)
    assert contradiction.message == (
        "the `assume` formulas of x/a.cs can never hold: `v/ib > 3.0` (line 40) and `v/ib < 2.0` (line 41) "
        "cannot hold at once, so they would hide every overlap of its transitions"
    )
    assert contradiction.hint == "an assumption states what always holds of the inputs; correct one of these"


def test_an_assumption_that_contradicts_itself_is_named_alone() -> None:
    text = PROBE.replace("TC", "go/pp").replace("FIRST", "go/pp").replace("SECOND", "hot/pp")
    text = text.replace(
        "            run -> b when hot/pp\n",
        "            run -> b when hot/pp\n            assume go/pp\n            assume hot/pp and not hot/pp\n",
    )
    [contradiction] = [d for d in check(earl.loads(text, "probe.earl")) if d.code == "EARL-E064"]
    assert contradiction.location is not None and contradiction.location.line == 39
    assert "`hot/pp and not hot/pp` (line 39) holds in no situation" in contradiction.message
    assert contradiction.hint is not None and contradiction.hint.endswith("correct it")


IN_ONE_STATE = """\
system a3

r/r { a/a }

a/a {
    cs {
        period 10 ms
        y/ib: double
        g/m: double = 0.0
        f/pf(y/ib -> g/mo)
        run/bb {
            tf = {f/pf}
            tc = true
        }
        fsm {
            initial s1
            state s1: run/bb { obligatory y/ib timeout 1 ms }
            state s2: run/bb
            s1 -> s2 when true
            s2 -> s1 when y/ib > 0.0
            s2 -> s2 when y/ib > 1.0
            assume timeout(y/ib)
        }
    }
}
"""


def test_an_assumption_that_cannot_hold_in_one_state_is_said_there_and_hides_nothing() -> None:
    """`assume timeout(y/ib)` holds where `y/ib` is waited for, never in `s2`, which does not wait for it: the
    check passed, said that `run/bb` (`tc = true`) never ends in `s2`, and hid the overlap of its transitions."""
    diagnostics = check(earl.loads(IN_ONE_STATE, "a3.earl"))
    codes = [d.code for d in diagnostics if d.code.startswith(("EARL-E06", "EARL-W06", "EARL-I06"))]
    assert codes == ["EARL-E064", "EARL-W061", "EARL-E060"]
    [contradiction] = [d for d in diagnostics if d.code == "EARL-E064"]
    assert contradiction.message == (
        "the `assume` formulas of a/a.cs cannot hold in state `s2`: `timeout(y/ib)` (line 22) holds in no "
        "situation there, as `y/ib`, which `s2` does not wait for, never times out; `s2` is checked without it"
    )
    assert contradiction.location is not None
    assert (contradiction.location.line, contradiction.location.column) == (18, 13)
    assert (
        contradiction.hint is not None
        and "let `s2` wait for `y/ib` (`obligatory y/ib timeout …`)" in contradiction.hint
    )
    # waited for in every state, the assumption can hold everywhere: nothing said
    waited = IN_ONE_STATE.replace("state s2: run/bb\n", "state s2: run/bb { obligatory y/ib timeout 1 ms }\n")
    assert [d.code for d in check(earl.loads(waited, "a3.earl")) if d.code == "EARL-E064"] == []


def test_a_behaviour_the_assumptions_keep_from_stopping_is_not_said_to_never_end() -> None:
    """`tc = go/pp` with `assume not go/pp`: its terminal condition can hold, the assumption is the reason it
    does not; EARL-I063 said the condition could never hold. The transitions out are what it makes dead."""
    text = IN_ONE_STATE.replace("tc = true", "tc = go/pp").replace(
        "        run/bb {", "        go/pp = y/ib > 5.0\n        run/bb {"
    )
    text = text.replace("assume timeout(y/ib)", "assume not go/pp")
    diagnostics = check(earl.loads(text, "a3.earl"))
    assert [d.code for d in diagnostics if d.code == "EARL-I063"] == []
    dead = [d.message for d in diagnostics if d.code == "EARL-W062"]
    assert dead[0] == (
        "transition `s1,s2/t` of a/a.cs can never be taken: the `assume` formulas rule out that `run/bb` stops "
        "in `s1` (`not go/pp` (line 23))"
    )
    # a terminal condition that cannot hold of itself still is the note
    never = text.replace("tc = go/pp", "tc = go/pp and y/ib < 1.0")
    notes = [d.message for d in check(earl.loads(never, "a3.earl")) if d.code == "EARL-I063"]
    assert notes[0].startswith("`run/bb` never ends: its terminal and error conditions can never hold")


FAMILY = """\
system fam

r/r { w[1]/a  w[2]/a  boss/a }

w[K in 1..2]/a {
    cs {
        period 10 ms
        in/ib: double
        m/m: double = 0.0
        go/pp = newData(in/ib)
        first/pp = K == 1
        false/pp = false
        work/pf(in/ib -> m/mo)
        run/bb {
            tf = {work/pf}
            tc = go/pp
        }
        sink/bb {
            tf = {work/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
            state a: sink/bb
            state b: sink/bb
            run -> a when go/pp
            run -> b when go/pp and not first/pp
        }
    }
}

boss/a {
    cs {
        period 10 ms
        out[K in 1..2]/ob: double
    }
}

link boss,w[K in 1..2]: boss/a.cs.out[K] -> w[K]/a.cs.in
"""


def test_a_member_of_a_family_is_analysed_with_its_own_index() -> None:
    found = {d.code: d.message for d in check(earl.loads(FAMILY, "fam.earl")) if d.code in ("EARL-E060", "EARL-W062")}
    assert found == {
        "EARL-E060": "transitions `run,a/t` and `run,b/t` of w[2]/a.cs can both hold, e.g. when go/pp = true",
        "EARL-W062": "transition `run,b/t` of w[1]/a.cs can never be taken: its condition never holds",
    }
    same = FAMILY.replace("first/pp = K == 1", "first/pp = in/ib > 1.0")
    [overlap] = [d.message for d in check(earl.loads(same, "fam.earl")) if d.code == "EARL-E060"]
    assert "of w[1..2]/a.cs can both hold" in overlap  # one analysis, said once for both members


def test_a_condition_over_a_large_family_is_one_boolean_to_the_analysis() -> None:
    """`any(K in 1..N: …)` with N = 1,000 joints: 1,001 atoms in one `or` would make a BDD as deep as N
    (dd's operations recurse once per variable: N = 2,500 exceeded Python's recursion limit)."""
    example = Path(__file__).parent.parent / "examples" / "pick_and_place"
    diagnostics = check(earl.load(example, {"N": 1000}))
    assert [d for d in diagnostics if d.severity.value == "error"] == []


def probe_text(
    first: str, second: str, stop: str = "true", extra: str = "", fsm_extra: str = ""
) -> dict[str, list[str]]:
    """`probe`, with more declarations in the subsystem (`extra`) and more lines in the FSM (`fsm_extra`)."""
    text = PROBE.replace("TC", stop).replace("FIRST", first).replace("SECOND", second)
    text = text.replace("        false/pp = false\n", "        false/pp = false\n" + extra)
    text = text.replace("            run -> b when", fsm_extra + "            run -> b when")
    found: dict[str, list[str]] = {}
    for diagnostic in check(earl.loads(text, "probe.earl")):
        if diagnostic.code in ("EARL-E060", "EARL-W061", "EARL-W062", "EARL-E064", "EARL-W020"):
            found.setdefault(diagnostic.code, []).append(diagnostic.message)
    return found


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("arr/ib[N - 1] > 1.0", "arr/ib[2] <= 1.0"),
        ("arr/ib[1 + 1] > 1.0", "arr/ib[2] <= 1.0"),
        ("any(J in 1..1: arr/ib[J + 1] > 1.0)", "arr/ib[N - 1] <= 1.0"),
        ("flags/ib[N - 1]", "not flags/ib[2]"),
    ],
)
def test_an_index_made_of_constants_reads_the_element_its_value_names(first: str, second: str) -> None:
    """`arr/ib[N - 1]` with N = 3 is `arr/ib[2]`: as two values, the two conditions were said to overlap
    (E060) and to leave the behaviour stuck (W061)."""
    extra = "        param N: int = 3\n        arr/ib: double[N]\n        flags/ib: boolean[N]\n"
    assert probe_text(first, second, extra=extra) == {}


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("d/ib", "d/ib"),  # a number where a Boolean belongs
        ('s/ib.mode < "b"', 's/ib.mode >= "b"'),  # strings ordered
        ("bad/pp", "not bad/pp and v/ib > 1.0"),  # through a predicate's definition
    ],
)
def test_a_condition_with_a_type_error_is_said_once_not_again_by_the_fsm_analysis(first: str, second: str) -> None:
    """`when d/ib` on a `double` is EARL-E030; the analysis took `d/ib` for a Boolean of its own and
    reported an overlap "when d/ib = true" (E060) and a stuck state (W061) the author never wrote."""
    extra = '        d/ib: double\n        bad/pp = s/ib.mode < "b"\n'
    text = PROBE.replace("TC", "true").replace("FIRST", first).replace("SECOND", second)
    text = text.replace("        false/pp = false\n", "        false/pp = false\n" + extra)
    codes = [d.code for d in check(earl.loads(text, "probe.earl"))]
    assert "EARL-E030" in codes
    assert not {"EARL-E060", "EARL-W061", "EARL-W062", "EARL-W020"} & set(codes)


def test_a_transition_the_assumptions_rule_out_is_said_so_and_its_state_is_not_told_to_add_one() -> None:
    """`v/ib > 20.0` under `assume v/ib < 10.0`: W062 said "its condition never holds", as of a
    contradiction in itself, and W020 said "add a transition into `b`" though one is there."""
    text = PROBE.replace("TC", "true").replace("FIRST", "not (v/ib > 20.0)").replace("SECOND", "v/ib > 20.0")
    text = text.replace("            run -> b when", "            assume v/ib < 10.0\n            run -> b when")
    said = {d.code: d for d in check(earl.loads(text, "probe.earl")) if d.code in ("EARL-W062", "EARL-W020")}
    assert said["EARL-W062"].message == (
        "transition `run,b/t` of x/a.cs can never be taken: its condition never holds under the `assume` "
        "formulas (`v/ib < 10.0` (line 37))"
    )
    assert said["EARL-W020"].hint is not None and said["EARL-W020"].hint.startswith(
        "`run,b/t` can never be taken: check its condition"
    )


def test_an_example_says_a_compared_value_as_the_range_it_lies_in() -> None:
    """Sixty bands `v/ib > K and v/ib <= K + 1` made W061's example 120 comparisons' truths, sorted as text
    (`v/ib <= 10.0 = false` before `v/ib <= 2.0`): now the band itself."""
    bands = "".join(f"            run -> a when v/ib > {k}.0 and v/ib <= {k + 1}.0\n" for k in range(2, 60))
    found = probe_text("v/ib <= 1.0", "v/ib > 60.0", fsm_extra=bands)
    assert [m.split("e.g. when ")[1] for m in found["EARL-W061"]] == ["1.0 < v/ib <= 2.0"]


@pytest.mark.parametrize(
    ("facts", "said"),
    [
        ([(">", 1.0, True), ("<=", 2.0, True), (">", 0.0, True)], "1.0 < v <= 2.0"),
        ([(">", 1.0, False), ("<", 0.0, False)], "0.0 <= v <= 1.0"),
        ([(">=", 3, True), ("<=", 3, True)], "v == 3"),
        ([("==", 2.0, False), ("<", 5.0, True), (">", 1.0, True)], "1.0 < v < 5.0, v != 2.0"),
        ([("!=", 7.0, False)], "v == 7.0"),
        ([("<", 1e999, True)], "v < 1e999"),
        ([(">", 2.0, True), ("<", 1.0, True)], None),  # no number: the comparisons were left unrelated
    ],
)
def test_the_range_of_a_value_is_said_from_its_comparisons_truths(
    facts: list[tuple[str, float, bool]], said: str | None
) -> None:
    from earl.check.fsm_analysis import _range_text

    assert _range_text("v", facts) == said  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("first", "second", "found"),
    [
        ("v/ib > w/ib", "w/ib >= v/ib", set()),  # one the negation of the other, mirrored
        ("v/ib == w/ib", "w/ib != v/ib", set()),
        ("v/ib < w/ib", "w/ib < v/ib", {"EARL-W061"}),  # never both; neither when equal
        ("v/ib < w/ib or v/ib == w/ib", "v/ib > w/ib", set()),
        ("v/ib <= w/ib", "w/ib <= v/ib", {"EARL-E060"}),  # both when equal
        ("v/ib == w/ib", "v/ib < w/ib or w/ib < v/ib", set()),
    ],
)
def test_comparisons_of_two_values_are_related_however_they_are_written(
    first: str, second: str, found: set[str]
) -> None:
    """`v/ib > x/mi` and `x/mi >= v/ib` were two unrelated Booleans: a false overlap and a false stuck state."""
    assert set(probe_text(first, second, extra="        w/ib: double\n")) == found


def test_two_predicates_computed_by_python_are_two_booleans_whatever_they_read() -> None:
    extra = '        pa/pp(v/ib) = python "m:f"\n        pb/pp(v/ib) = python "m:g"\n'
    found = probe_text("pa/pp", "not pb/pp", extra=extra)
    assert "EARL-E060" in found and "EARL-W061" in found
    assert "EARL-W062" not in probe_text("pa/pp and not pb/pp", "pb/pp", extra=extra)


def test_the_same_comparison_written_many_times_is_still_one_comparison() -> None:
    many = "".join("            assume v/ib > 5.0 or true\n" for _ in range(70))
    assert "EARL-E060" not in probe_text("v/ib > 5.0", "v/ib < 3.0", fsm_extra=many)


def test_two_long_quantifiers_alike_in_their_first_words_are_two_booleans() -> None:
    extra = "        q[K in 1..100]/ib: boolean\n"
    found = probe_text(
        "not any(K in 1..70: q[K]/ib) and any(K in 1..80: q[K]/ib)", "not any(K in 1..80: q[K]/ib)", extra=extra
    )
    assert "EARL-W062" not in found and "EARL-W020" not in found


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("v/ib > 1e16", "v/ib <= 1e16"),
        ("n/ib > 9007199254740992", "n/ib <= 9007199254740992"),
        ("v/ib > 1" + "0" * 400, "v/ib < -1" + "0" * 400),  # beyond every double but infinity; an int never
        ("v/ib < 1e999", "v/ib > 2.0"),
    ],
)
def test_comparisons_with_large_constants_are_decided_exactly(first: str, second: str) -> None:
    found = probe_text(first, second, extra="        n/ib: int\n")
    assert "EARL-W062" not in found and "EARL-W020" not in found


def test_timeout_of_a_field_is_timeout_of_its_buffer_and_never_holds_with_new_data() -> None:
    assert "EARL-E060" not in probe_text("timeout(s/ib.opt)", "not timeout(s/ib)")
    assert "EARL-E060" not in probe_text("newData(s/ib.opt)", "timeout(s/ib)")


def test_overlaps_of_transitions_a_higher_priority_always_preempts_are_no_ambiguity() -> None:
    found = probe_text("go/pp", "go/pp", stop="go/pp", fsm_extra="            run -> run when go/pp priority 1\n")
    assert "EARL-E060" not in found
    assert len(found["EARL-W062"]) == 2  # both are never taken


def test_a_transition_covered_by_several_before_it_names_them_all() -> None:
    found = probe_text(
        "v/ib > 5.0 priority 1", "v/ib <= 5.0 priority 2", fsm_extra="            run -> run when true priority 3\n"
    )
    assert found["EARL-W062"] == [
        "transition `run,run/t` of x/a.cs can never be taken: whenever its condition holds, one of `run,a/t`, "
        "`run,b/t` holds too and is tried first"
    ]


def test_a_predicate_defined_through_itself_is_e045_and_switches_nothing_off() -> None:
    """`odd/pp = not odd/pp` tied as `v ≡ ¬v` made every formula false: a real overlap went unreported."""
    extra = "        odd/pp = not odd/pp\n        p/pp = not q/pp\n        q/pp = p/pp and go/pp\n"
    found = probe_text("go/pp", "go/pp or odd/pp or p/pp", extra=extra)
    assert found["EARL-E060"] == ["transitions `run,a/t` and `run,b/t` of x/a.cs can both hold, e.g. when go/pp = true"]
    text = PROBE.replace("TC", "true").replace("FIRST", "go/pp").replace("SECOND", "not go/pp")
    text = text.replace("        false/pp = false\n", "        false/pp = false\n" + extra)
    cycles = [d.message for d in check(earl.loads(text, "probe.earl")) if d.code == "EARL-E045"]
    assert cycles == [
        "primitive predicate `odd/pp` of x/a.cs is defined through itself (odd/pp -> odd/pp), so it has no value",
        "primitive predicate `p/pp` of x/a.cs is defined through itself (p/pp -> q/pp -> p/pp), so it has no value",
    ]


OBLIGATORY = """\
        watch/bb {
            tf = {work/pf}
            tc = true
        }
"""


def test_what_receiving_in_a_state_makes_true_is_known_to_the_analysis() -> None:
    """A state that waits for `v/ib` (with a timeout) ends each iteration with `newData(v/ib)` or
    `timeout(v/ib)`; a state that does not wait for it never sees it time out; without a timeout it
    always has new data. Obligatory sensor plus timeout was an E060 and a W061 before."""
    obligatory = "{ obligatory v/ib  timeout 50 ms }"
    text = PROBE.replace("TC", "true").replace("FIRST", "newData(v/ib)").replace("SECOND", "timeout(v/ib)")
    text = text.replace("state run: run/bb", f"state run: run/bb {obligatory}")
    codes = [d.code for d in check(earl.loads(text, "probe.earl"))]
    assert "EARL-W061" not in codes and "EARL-E060" not in codes
    optional = (
        PROBE.replace("TC", "true")
        .replace("FIRST", "newData(v/ib) or timeout(v/ib)")
        .replace("SECOND", "not newData(v/ib)")
    )
    assert "EARL-E060" not in [d.code for d in check(earl.loads(optional, "probe.earl"))]
    forever = PROBE.replace("TC", "true").replace("FIRST", "newData(v/ib)").replace("SECOND", "false")
    forever = forever.replace("state run: run/bb", "state run: run/bb { obligatory v/ib }")
    assert "EARL-W061" not in [d.code for d in check(earl.loads(forever, "probe.earl"))]


def test_a_buffer_fed_by_another_agent_may_time_out_anywhere_and_the_message_says_when() -> None:
    """Over Zenoh a stale sender makes its buffer read as timed out in every state: the overlap is real
    there, and the message says that it happens only then."""
    text = (
        PROBE.replace("TC", "true")
        .replace("FIRST", "newData(v/ib) or timeout(v/ib)")
        .replace("SECOND", "not newData(v/ib)")
    )
    text = text.replace(
        "r/r { x/a }",
        "r/r { x/a }\n\ny/a {\n    cs {\n        period 10 ms\n        out/ob: double\n    }\n}\n\nlink y,x: y/a.cs.out -> x/a.cs.v\n",
    )
    [message] = [d.message for d in check(earl.loads(text, "probe.earl")) if d.code == "EARL-E060"]
    assert message.endswith(
        "(only while a sending agent in another process is stale: its buffer then reads as timed out in every state)"
    )


def test_only_the_member_of_a_family_another_agent_feeds_may_see_its_buffer_go_stale() -> None:
    """`x[1]/a` is fed from `y/a` and `x[2]/a` by nothing: one analysis would say the overlap of both
    or of neither; each member is analysed as it is linked."""
    text = (
        PROBE.replace("TC", "true")
        .replace("FIRST", "newData(v/ib) or timeout(v/ib)")
        .replace("SECOND", "not newData(v/ib)")
        .replace("x/a {", "x[K in 1..2]/a {")
    )
    text = text.replace(
        "r/r { x/a }",
        "r/r { x[1]/a x[2]/a }\n\ny/a {\n    cs {\n        period 10 ms\n        out/ob: double\n    }\n}\n\n"
        "link y,x: y/a.cs.out -> x[1]/a.cs.v\n",
    )
    [message] = [d.message for d in check(earl.loads(text, "probe.earl")) if d.code == "EARL-E060"]
    assert "of x[1]/a.cs can both hold" in message
    assert message.endswith(
        "(only while a sending agent in another process is stale: its buffer then reads as timed out in every state)"
    )


@pytest.mark.parametrize(
    ("first", "second"),
    [("v/ib > 3.0", "v/ib <= 3.0"), ("v/ib > 3.0 and v/ib < 1e999", "v/ib <= 3.0 or v/ib == 1e999")],
)
def test_an_infinite_constant_is_a_value_on_the_line_not_the_end_of_the_analysis(first: str, second: str) -> None:
    extra = "        finite/pp = v/ib < 1e999\n"
    found = probe_text(first, second, extra=extra, fsm_extra="            assume finite/pp or not finite/pp\n")
    assert "EARL-E060" not in found and "EARL-W061" not in found


def test_repeats_of_a_comparison_do_not_count_towards_the_limit_of_different_comparisons() -> None:
    """Each occurrence counted: 131 occurrences of 2 comparisons passed the 128 cap and unrelated them."""
    extra = "        w[K in 1..70]/ib: boolean\n        busy/pp = any(K in 1..64: v/ib > 3.0 and w[K]/ib) or any(K in 1..64: v/ib > 3.0 or w[K]/ib)\n"
    found = probe_text(
        "v/ib > 3.0", "v/ib <= 3.0", extra=extra, fsm_extra="            assume busy/pp or not busy/pp\n"
    )
    assert "EARL-E060" not in found and "EARL-W061" not in found


def test_two_transitions_into_one_state_may_overlap_and_a_star_is_named_as_written() -> None:
    found = probe_text("go/pp", "v/ib > 3.0", stop="true", fsm_extra="            * -> a when v/ib > 4.0\n")
    assert found["EARL-E060"] == [
        "transitions `run,a/t` and `run,b/t` of x/a.cs can both hold, e.g. when go/pp = true, v/ib > 3.0",
        "transitions `*,a/t` (from `run`) and `run,b/t` of x/a.cs can both hold, e.g. when v/ib > 4.0",
    ]
    always = probe_text("true", "true", stop="true")
    assert always["EARL-E060"] == ["transitions `run,a/t` and `run,b/t` of x/a.cs can both hold, whatever the inputs"]


def test_new_data_of_a_field_every_message_holds_is_new_data_of_the_message() -> None:
    """`newData(s/ib.a)` of a field that is not optional holds exactly with `newData(s/ib)`; of an
    optional one, only when the message holds it."""
    assert probe_text("newData(s/ib.a)", "not newData(s/ib)") == {}
    found = probe_text("newData(s/ib.opt)", "not newData(s/ib)")
    assert found["EARL-W061"] == [
        "`run/bb` can stop while no transition out of `run` holds (x/a.cs), e.g. when newData(s/ib) = true, "
        "newData(s/ib.opt) = false"
    ]


@pytest.mark.parametrize(
    ("first", "second"),
    [("hot/pp", "not (3.0 < v/ib)"), ("v/ib > 0.0", "not (v/ib > -0.0)"), ("v/ib > 2.0 + 1.0", "not (v/ib > 3.0)")],
)
def test_one_comparison_written_two_ways_is_related_both_ways(first: str, second: str) -> None:
    """Kept once per (operator, constant), the second text of one comparison lost its regions: a false E060."""
    assert probe_text(first, second) == {}


def test_each_value_s_comparisons_sit_side_by_side_in_the_bdd_by_their_constants() -> None:
    """The order of first use interleaved the values' comparisons, and a BDD then carries every value's
    region at once (8 values of 10 comparisons, 40 prioritised transitions: a minute). Each predicate
    follows the comparison it is defined by."""
    extra = (
        "        w/ib: double\n"
        "        v2/pp = v/ib > 2.0\n        w1/pp = w/ib < 1.0\n        v1/pp = v/ib > 1.0\n"
        "        w3/pp = w/ib < 3.0\n        both/pp = v1/pp and w3/pp\n"
    )
    encoder = _probe_encoded(extra, "v2/pp and w1/pp", "both/pp")
    encoder.order_variables()
    levels = encoder.bdd.var_levels
    order = [encoder.names[name] for name in sorted(levels, key=levels.__getitem__)]
    assert order == [
        "v/ib > 1.0", "v1/pp", "v/ib > 2.0", "v2/pp",
        "w/ib < 1.0", "w1/pp", "w/ib < 3.0", "w3/pp", "both/pp",
    ]  # fmt: skip


def test_members_of_two_families_are_interleaved_by_index_while_the_bdds_are_built() -> None:
    """With every `a[K]/ib` above every `b[K]/ib` (the order of first use), `any(K in 1..N: a[K]/ib and
    b[K]/ib)` has 2^N nodes: N = 20 took a minute, N = 24 minutes. The members are placed by index as they
    are declared, so the BDD built is small, and `order_variables` keeps them so."""
    members = 14
    extra = (
        f"        a[K in 1..{members}]/ib: boolean\n        b[K in 1..{members}]/ib: boolean\n"
        f"        anyA/pp = any(K in 1..{members}: a[K]/ib)\n        anyB/pp = any(K in 1..{members}: b[K]/ib)\n"
        f"        pair/pp = any(K in 1..{members}: a[K]/ib and b[K]/ib)\n"
    )
    encoder = _probe_encoded(extra, "anyA/pp or anyB/pp", "pair/pp")
    built = encoder.definitions_met  # `pair/pp` is its variable, tied to its definition here
    assert max(formula.dag_size for formula in built) < 4 * members  # 2^N in the order of first use
    encoder.order_variables()
    levels = encoder.bdd.var_levels
    order = [encoder.names[name] for name in sorted(levels, key=levels.__getitem__)]
    read = [name for name in order if name.startswith(("a[", "b["))]
    assert read == [f"{family}[{k}]/ib" for k in range(1, members + 1) for family in "ab"]
    assert max(formula.dag_size for formula in built) < 4 * members


@pytest.mark.parametrize("seed", range(3))
def test_many_prioritised_transitions_over_many_comparisons_are_analysed_as_in_the_order_of_first_use(
    seed: int,
) -> None:
    """The variable order changes how large the BDDs grow, never what the analysis finds."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    try:
        from bench_check import comparisons_spec
    finally:
        sys.path.pop(0)
    from earl.check import fsm_analysis

    system = earl.loads(comparisons_spec(4, 5, 12, seed), "compare.earl")

    def findings() -> list[tuple[str | None, str]]:
        # the example after "e.g. when" is the BDD's first satisfying assignment, which the order may change
        return [(d.code, d.message.split(", e.g. when")[0]) for d in check(system)]

    ordered = findings()
    original = fsm_analysis._Encoder.order_variables
    fsm_analysis._Encoder.order_variables = lambda self: None  # type: ignore[method-assign]
    try:
        first_use = findings()
    finally:
        fsm_analysis._Encoder.order_variables = original  # type: ignore[method-assign]
    assert {code for code, _ in ordered} & {"EARL-E060", "EARL-W062", "EARL-W061"}
    assert sorted(ordered) == sorted(first_use)


def test_a_star_that_stands_for_one_transition_is_still_named_as_written() -> None:
    """In an FSM of two states `* -> a` is the one transition `run,a`: it was named so, beside the line
    `run -> a` it was said to be covered by."""
    text = (
        "system star2\nr/r { x/a }\nx/a {\n    cs {\n        period 10 ms\n        v/ib: double\n"
        "        hot/pp = v/ib > 3.0\n        run/bb {\n            tf = {}\n            tc = true\n        }\n"
        "        fsm {\n            initial run\n            state run: run/bb\n            state a: run/bb\n"
        "            run -> a when hot/pp priority 1\n            * -> a when hot/pp priority 2\n"
        "            a -> run when true\n        }\n    }\n}\n"
    )
    messages = [d.message for d in check(earl.loads(text, "star2.earl")) if d.code == "EARL-W062"]
    assert messages == ["transition `*,a/t` of x/a.cs can never be taken from any state"]


@pytest.mark.parametrize("seed", range(3))
def test_the_pure_python_bdds_find_what_cudd_finds_word_for_word(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """dd's wheel brings CUDD on this platform; where it does not, earl falls back on dd.autoref. The
    examples are each the first path of a BDD in earl's own variable order: the same with both."""
    import dd.autoref

    from earl.check import fsm_analysis

    texts = [random_fsm(seed), PROBE.replace("TC", "true").replace("FIRST", "v/ib > 3.0").replace("SECOND", "go/pp")]
    expected = [[d.message for d in check(earl.loads(text, "x.earl"))] for text in texts]
    assert any("e.g. when" in message for messages in expected for message in messages)
    monkeypatch.setattr(fsm_analysis, "BDD", dd.autoref.BDD)
    assert [[d.message for d in check(earl.loads(text, "x.earl"))] for text in texts] == expected


@pytest.mark.parametrize(
    ("first", "second", "overlap", "dead"),
    [
        ("n/ib > 3 and n/ib < 4", "true", None, "run,a"),  # no whole number between 3 and 4
        ("n/ib > 3.5", "n/ib < 4", None, None),  # 3 < 3.5: no number in both
        ("n/ib >= 3", "n/ib <= 3", "n/ib == 3", None),  # 3 is in both
        ("u/ib < 0", "true", None, "run,a"),  # a uint8 is never negative
        ("u/ib > 255", "true", None, "run,a"),  # nor above 255
        ("u/ib > 200", "u/ib > 254", "u/ib > 254", None),  # 255
        ("v/ib > 3.0 and v/ib < 4.0", "v/ib > 3.5", "3.5 < v/ib < 4.0", None),
    ],
)
def test_a_value_of_an_integer_type_holds_only_whole_numbers_of_its_range(
    first: str, second: str, overlap: str | None, dead: str | None
) -> None:
    found = probe_text(first, second, extra="        n/ib: int\n        u/ib: uint8\n")
    assert [m.rsplit("e.g. when ", 1)[-1] for m in found.get("EARL-E060", [])] == ([overlap] if overlap else [])
    assert [m.split("`")[1] for m in found.get("EARL-W062", [])] == ([f"{dead}/t"] if dead else [])


def test_a_transition_never_taken_is_told_apart_from_another_between_the_same_states() -> None:
    """`n -> t when ready/pp` and `n -> t when not ready/pp` are both `n,t/t`: W062 said "transition
    `n,t/t` … can never be taken" without saying which; it gives its number among them and its line, as
    the document's Table 5 writes them."""
    spec = Path(__file__).parent / "doc_specs" / "edge" / "system.earl"
    line = spec.read_text(encoding="utf-8").splitlines().index("            n -> t when not ready/pp") + 1
    messages = [d.message for d in check(earl.load(spec)) if d.code == "EARL-W062"]
    assert messages == [
        f"transition `n,t/t` #2 (line {line}) of solo/a.cs can never be taken: its condition never holds when "
        "`nothing/bb` stops"
    ]


def _probe_encoded(extra: str, first: str, second: str) -> Any:
    """PROBE's subsystem with `extra` declarations and its two transitions' conditions encoded (not yet ordered)."""
    from earl.check.fsm_analysis import _Encoder

    system = earl.loads(
        PROBE.replace("TC", "true")
        .replace("FIRST", first)
        .replace("SECOND", second)
        .replace("        false/pp = false\n", "        false/pp = false\n" + extra),
        "probe.earl",
    )
    context = context_for(system)
    subsystem = next(s for _, s in context.subsystems())
    assert subsystem.fsm is not None
    encoder = _Encoder(context, subsystem)
    for transition in subsystem.fsm.transitions:
        encoder.encode(transition.condition.expression)
    return encoder
