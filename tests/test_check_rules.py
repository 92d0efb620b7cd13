"""Every rule of `earl check`: a small spec that breaks it, pointing at the spot, and one that keeps it.

Each case starts from BASE, a tiny system that passes every rule (two purely computational
agents joined by one link), and changes it by replacing text.  The expected line and column
are those of the token the finding must point at, counted in the changed text.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pytest

import earl
from earl.check import check, context_for
from earl.check.registry import RULES
from earl.check.rules_doc import ENFORCED_BY_THE_LANGUAGE
from earl.diagnostics import Diagnostic, EarlError, Severity
from earl.model.elements import System
from earl.model.text import expression_text

EXAMPLE = Path(__file__).parent.parent / "examples" / "pick_and_place" / "system.earl"

# Line numbers matter below: BASE is 46 lines long (its periods share the `cs {` lines to keep them), and text appended with `add` starts at line 48.
BASE = """\
system base

a1/a {
    cs { period 1 ms
        out/ob: double
        x/m: double = 0.0
        go/pp = x/mi > 1.0
        compute/pf(x/mi -> x/mo)
        emit/pf(x/mi -> out/ob)
        run/bb {
            tf = {compute/pf} then {emit/pf}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}

a2/a {
    cs { period 1 ms
        inp/ib: double
        y/m: double = 0.0
        got/pp = newData(inp/ib)
        take/pf(inp/ib -> y/mo)
        run/bb {
            tf = {take/pf}
            tc = got/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when got/pp
        }
    }
}

link a1,a2: a1/a.cs.out -> a2/a.cs.inp

r/r {
    a1/a
    a2/a
    link a1,a2
}
"""


def edit(*replacements: tuple[str, str], text: str = BASE) -> str:
    """`text` with each `old` (which must occur exactly once) replaced by `new`."""
    for old, new in replacements:
        assert text.count(old) == 1, f"{old!r} occurs {text.count(old)} times"
        text = text.replace(old, new)
    return text


def add(extra: str, text: str = BASE) -> str:
    """`text` followed by a blank line and `extra`; after BASE, the first line of `extra` is line 48."""
    return f"{text}\n{extra}"


# An agent that acts: cs → ve → re (CE).  Added after BASE, `a3/a {` is line 48.
EFFECTOR_AGENT = """\
a3/a {
    cs {
        cmd/ob: double
    }
    m/ve {
        cmd/ib: double
        drive/ob: double
    }
    d/re {
        drive/ib: double
    }
    link cs,m: cs.cmd -> m/ve.cmd
    link m,d: m/ve.drive -> d/re.drive
}
"""

# An agent that perceives: rr → vr → cs (CR).  Added after BASE, `a4/a {` is line 48.
RECEPTOR_AGENT = """\
a4/a {
    cs {
        data/ib: double
    }
    s/vr {
        raw/ib: double
        data/ob: double
    }
    cam/rr {
        raw/ob: double
    }
    link cam,s: cam/rr.raw -> s/vr.raw
    link s,cs: s/vr.data -> cs.data
}
"""

# A second state in a1 that the first can go to, for the FSM rules.
TWO_STATES = (
    "            state run: run/bb\n            run -> run when go/pp\n",
    "            state run: run/bb\n            state other: run/bb\n"
    "            run -> run when go/pp\n            run -> other when go/pp\n            other -> run when go/pp\n",
)


@dataclass(frozen=True)
class Case:
    code: str
    failing: str
    line: int
    column: int
    fragment: str  # a part of the message that names what is wrong
    passing: str


def ping_pong(a2_period: bool) -> str:
    """BASE with a link back from a2 to a1, each waiting for the other's message, a1 without a period and a2
    with one or without: each message wakes the other at once (EARL-W018) when neither has one."""
    return edit(
        ("    cs { period 1 ms\n        out/ob: double", "    cs {\n        back/ib: double\n        out/ob: double"),
        (
            "            state run: run/bb\n            run -> run when go/pp",
            "            state run: run/bb { obligatory back/ib }\n            run -> run when go/pp",
        ),
        (
            "    cs { period 1 ms\n        inp/ib: double\n",
            ("    cs { period 1 ms\n" if a2_period else "    cs {\n")
            + "        inp/ib: double\n        ret/ob: double\n",
        ),
        ("        take/pf(inp/ib -> y/mo)\n", "        take/pf(inp/ib -> y/mo)\n        give/pf(y/mi -> ret/ob)\n"),
        ("            tf = {take/pf}\n", "            tf = {take/pf} then {give/pf}\n"),
        (
            "            state run: run/bb\n            run -> run when got/pp",
            "            state run: run/bb { obligatory inp/ib }\n            run -> run when got/pp",
        ),
        (
            "link a1,a2: a1/a.cs.out -> a2/a.cs.inp\n",
            "link a1,a2: a1/a.cs.out -> a2/a.cs.inp\nlink a2,a1: a2/a.cs.ret -> a1/a.cs.back\n",
        ),
        ("    link a1,a2\n}", "    link a1,a2\n    link a2,a1\n}"),
    )


def optional_speed(terminal_condition: str) -> str:
    """BASE with the link's messages a struct of one optional field, and a2's `tc` reading it."""
    return add(
        "struct Cmd {\n    speed: double?\n}\n",
        edit(
            ("out/ob: double", "out/ob: Cmd"),
            ("inp/ib: double", "inp/ib: Cmd"),
            (
                "        got/pp = newData(inp/ib)\n",
                "        got/pp = newData(inp/ib)\n        fast/pp = inp/ib.speed > 1.0\n",
            ),
            ("tc = got/pp", f"tc = {terminal_condition}"),
        ),
    )


def predicate_chain(length: int) -> str:
    """BASE with a1's `tc` a chain of `length` predicates, each naming the next (one level deeper each)."""
    chain = "".join(f"        q{i}/pp = x/mi > 0.0 and q{i + 1}/pp\n" for i in range(length))
    return edit(
        ("        go/pp = x/mi > 1.0\n", f"        go/pp = x/mi > 1.0\n{chain}        q{length}/pp = x/mi > 0.0\n"),
        ("tc = go/pp", "tc = q0/pp"),
    )


CASES: list[Case] = [
    Case(
        "EARL-E001",
        BASE[: BASE.index("r/r {")],
        1,
        8,
        "system `base` has no Robot",
        BASE,
    ),
    Case(
        "EARL-E002",
        edit(("r/r {\n    a1/a\n    a2/a\n    link a1,a2\n}", "r/r {\n}")),
        42,
        1,
        "robot `r/r` contains no Agent",
        BASE,
    ),
    Case(
        "EARL-E003",
        add("r2/r {\n    a1/a\n}\n"),
        49,
        5,
        "agent `a1/a` belongs to robot `r/r` and to robot `r2/r`",
        add("r2/r {\n    a3/a\n}\n" + EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E004",
        edit(("    a2/a\n    link a1,a2\n}\n", "    link a1,a2\n}\n\nr2/r {\n    a2/a\n}\n")),
        44,
        5,
        "robot `r/r` refers to link `a1,a2`, but `a2/a` is not one of its agents",
        BASE,
    ),
    Case(
        "EARL-E005",
        add("a3/a {\n    m/ve {\n        cmd/ib: double\n        drive/ob: double\n    }\n}\n"),
        48,
        1,
        "agent `a3/a` has no Control Subsystem",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E006",
        add(
            edit(
                ("    d/re {\n        drive/ib: double\n    }\n", ""),
                ("    link m,d: m/ve.drive -> d/re.drive\n", ""),
                text=EFFECTOR_AGENT,
            )
        ),
        48,
        1,
        "agent `a3/a` has a Virtual Effector but no Real Effector",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E007",
        add(
            edit(
                ("    cam/rr {\n        raw/ob: double\n    }\n", ""),
                ("    link cam,s: cam/rr.raw -> s/vr.raw\n", ""),
                text=RECEPTOR_AGENT,
            )
        ),
        48,
        1,
        "agent `a4/a` has a Virtual Receptor but no Real Receptor",
        add(RECEPTOR_AGENT),
    ),
    Case(
        "EARL-E008",
        add(
            edit(
                ("        drive/ib: double\n", ""),
                ("    link m,d: m/ve.drive -> d/re.drive\n", ""),
                text=EFFECTOR_AGENT,
            )
        ),
        56,
        5,
        "Real Effector `a3/a.d/re` has no Input Buffer",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E010",
        edit(("inp/ib: double", "inp/ib: int")),
        40,
        1,
        "link `a1,a2` sends `double` into an Input Buffer of type `int`",
        BASE,
    ),
    Case(
        "EARL-E011",
        add("a3/a {\n    cs {\n        out/ob: double\n    }\n}\n\nlink a3,a2: a3/a.cs.out -> a2/a.cs.inp\n"),
        54,
        1,
        "`a2/a.cs.inp/ib` is fed by link `a1,a2` and by link `a3,a2`",
        add(
            "a3/a {\n    cs {\n        out/ob: double\n    }\n}\n\nlink a3,a1: a3/a.cs.out -> a1/a.cs.inp\n",
            text=edit(
                ("        out/ob: double\n        x/m", "        out/ob: double\n        inp/ib: double\n        x/m")
            ),
        ),
    ),
    Case(
        "EARL-E012",
        add(
            edit(
                ("    link m,d: m/ve.drive -> d/re.drive\n", "    link cs,d: cs.cmd -> d/re.drive\n"),
                text=EFFECTOR_AGENT,
            )
        ),
        60,
        5,
        "a link from a Control Subsystem to a Real Effector is not permitted inside an agent (link `cs,d`)",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E013",
        add(EFFECTOR_AGENT + "\nlink a1,a3: a1/a.cs.out -> a3/a.m/ve.cmd\n"),
        63,
        1,
        "inter-agent link `a1,a3` ends at `a3/a.m/ve`, not at a Control Subsystem",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E013",
        add(
            "link a1,a1: a1/a.cs.out -> a1/a.cs.inp\n",
            text=edit(
                ("        out/ob: double\n        x/m", "        out/ob: double\n        inp/ib: double\n        x/m")
            ),
        ),
        49,
        1,
        "link `a1,a1` starts and ends in `a1/a`",
        BASE,
    ),
    Case(
        "EARL-E014",
        add(edit(("    link cs,m: cs.cmd -> m/ve.cmd\n", ""), text=EFFECTOR_AGENT)),
        56,
        5,
        "`a3/a.d/re` is not on a chain cs → ve → re",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-E015",
        add(edit(("    link s,cs: s/vr.data -> cs.data\n", ""), text=RECEPTOR_AGENT)),
        56,
        5,
        "`a4/a.cam/rr` is not on a chain rr → vr → cs",
        add(RECEPTOR_AGENT),
    ),
    Case(
        "EARL-E030",
        edit(("go/pp = x/mi > 1.0", "go/pp = x/mi + 1.0")),
        7,
        17,
        "primitive predicate `go/pp` is a number, not a Boolean",
        BASE,
    ),
    Case(
        "EARL-E030",
        edit(("tc = go/pp\n", "tc = go/pp or x/mi\n")),
        12,
        27,
        "an operand of `or` must be a boolean, but `x/mi` is a number",
        edit(("tc = go/pp\n", "tc = go/pp or x/mi > 3.0\n")),
    ),
    Case(
        "EARL-E040",
        edit(("tf = {compute/pf} then {emit/pf}", "tf = {compute/pf, emit/pf}")),
        11,
        31,
        "`emit/pf` writes `out/ob` in stage 1 of `run/bb`",
        BASE,
    ),
    Case(
        "EARL-E040",
        edit(("tf = {take/pf}", "tf = {take/pf} then {take/pf}")),
        29,
        34,
        "`take/pf` reads `inp/ib` in the last stage of `run/bb` in `a2/a.cs`",
        BASE,
    ),
    Case(
        "EARL-E041",
        edit(
            (
                "        emit/pf(x/mi -> out/ob)\n",
                "        emit/pf(x/mi -> out/ob)\n        stage pf = {emit/pf}\n        stage pfo = {compute/pf}\n",
            )
        ),
        13,
        19,
        "`compute/pf` is in a stage of `run/bb` that takes its functions from `pf`, which does not contain it",
        edit(
            (
                "        emit/pf(x/mi -> out/ob)\n",
                "        emit/pf(x/mi -> out/ob)\n        stage pf = {compute/pf}\n        stage pfo = {emit/pf}\n",
            )
        ),
    ),
    Case(
        "EARL-E041",
        edit(
            ("        emit/pf(x/mi -> out/ob)\n", "        emit/pf(x/mi -> out/ob)\n        stage pfo = {emit/pf}\n"),
            ("tf = {compute/pf} then {emit/pf}", "tf = {compute/pf} then {emit/pf} then {emit/pf}"),
        ),
        12,
        13,
        "`run/bb` has 3 stages but `cs` declares 1 stage sets",
        edit(
            (
                "        emit/pf(x/mi -> out/ob)\n",
                "        emit/pf(x/mi -> out/ob)\n        stage pf = {compute/pf}\n        stage pfo = {emit/pf}\n",
            )
        ),
    ),
    Case(
        "EARL-E042",
        edit(
            (
                "        compute/pf(x/mi -> x/mo)\n",
                "        compute/pf(x/mi -> x/mo)\n        compute2/pf(x/mi -> x/mo)\n",
            ),
            ("tf = {compute/pf}", "tf = {compute/pf, compute2/pf}"),
        ),
        12,
        31,
        "`compute/pf` and `compute2/pf` both write `x/m` in stage 1 of `run/bb`",
        edit(
            (
                "        compute/pf(x/mi -> x/mo)\n",
                "        compute/pf(x/mi -> x/mo)\n        compute2/pf(x/mi -> z/mo)\n",
            ),
            ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        z/m: double = 0.0\n"),
            ("tf = {compute/pf}", "tf = {compute/pf, compute2/pf}"),
        ),
    ),
    Case(
        "EARL-E060",
        edit(TWO_STATES),
        19,
        13,
        "transitions `run,run/t` and `run,other/t` of a1/a.cs can both hold, e.g. when go/pp = true",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when go/pp priority 1\n")),
    ),
    Case(
        "EARL-I063",
        edit(
            ("        got/pp = newData(inp/ib)\n", "        got/pp = newData(inp/ib)\n        false/pp = false\n"),
            ("tc = got/pp", "tc = false/pp"),
        ),
        29,
        9,
        "`run/bb` never ends: its terminal and error conditions can never hold, so state `run` of a2/a.cs is never left",
        BASE,
    ),
    Case(
        "EARL-W001",
        add("a3/a {\n    cs {\n    }\n}\n"),
        48,
        1,
        "agent `a3/a` is of type C (zombie)",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-W010",
        edit(("link a1,a2: a1/a", "link a2,a1: a1/a"), ("    link a1,a2\n}", "    link a2,a1\n}")),
        40,
        1,
        "link `a2,a1` is not named after its ends; §2.5 suggests `a1,a2`",
        BASE,
    ),
    Case(
        "EARL-W010",
        add(edit(("link cs,m: cs.cmd", "link cs,d: cs.cmd"), text=EFFECTOR_AGENT)),
        59,
        5,
        "link `cs,d` is not named after its ends; §2.5 suggests `cs,m`",
        add(EFFECTOR_AGENT),
    ),
    Case(
        "EARL-W020",
        edit(
            (
                "state run: run/bb\n            run -> run when go/pp",
                "state run: run/bb\n            state lost: run/bb\n            run -> run when go/pp",
            )
        ),
        17,
        13,
        "state `lost` of a1/a.cs is unreachable from the initial state `run`",
        edit(TWO_STATES),
    ),
    Case(
        "EARL-W021",
        edit(("            run -> run when go/pp\n", "")),
        16,
        13,
        "state `run` of a1/a.cs has no way out: `run/bb` can stop, but no transition leaves it",
        BASE,
    ),
    Case(
        "EARL-W030",
        edit(("        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0\n        unused/pp = x/mi > 2.0\n")),
        8,
        9,
        "primitive predicate `unused/pp` is never used",
        BASE,
    ),
    Case(
        "EARL-W040",
        edit(("        out/ob: double\n", "        out/ob: double\n        spare/ob: double\n")),
        6,
        9,
        "output buffer `a1/a.cs.spare/ob` is never written by a function of any behaviour",
        BASE,
    ),
    Case(
        "EARL-W041",
        edit(("x/m: double = 0.0", "x/m: double")),
        11,
        19,
        "`compute/pf` reads `x/mi` in the first iteration of `run/bb`",
        BASE,
    ),
    Case(
        "EARL-W042",
        edit(
            ("        emit/pf(x/mi -> out/ob)\n", "        emit/pf(x/mi -> out/ob)\n        spare/pf(x/mi -> x/mo)\n")
        ),
        10,
        9,
        "partial transition function `spare/pf` is not used by any behaviour",
        BASE,
    ),
    Case(
        "EARL-W061",
        edit(("run -> run when go/pp", "run -> run when go/pp and x/mi > 2.0")),
        16,
        13,
        "`run/bb` can stop while no transition out of `run` holds (a1/a.cs), e.g. when go/pp = true, x/mi <= 2.0",
        BASE,
    ),
    Case(
        "EARL-W062",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when go/pp and not go/pp\n")),
        19,
        13,
        "transition `run,other/t` of a1/a.cs can never be taken: its condition never holds",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when go/pp and x/mi > 2.0 priority 1\n")),
    ),
    Case(
        "EARL-W062",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when go/pp priority 1\n")),
        18,
        13,
        "transition `run,run/t` of a1/a.cs can never be taken: whenever its condition holds, `run,other/t` "
        "holds too and is tried first",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when go/pp and x/mi > 2.0 priority 1\n")),
    ),
    Case(
        "EARL-W062",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when not go/pp\n")),
        19,
        13,
        "transition `run,other/t` of a1/a.cs can never be taken: its condition never holds when `run/bb` stops",
        edit(TWO_STATES, ("run -> other when go/pp\n", "run -> other when x/mi > 2.0 priority 1\n")),
    ),
    Case(
        "EARL-E043",
        edit(("        x/m: double = 0.0\n", '        x/m: double = "zero"\n')),
        6,
        23,
        "the initial value of `x/m` must be a number (double), not the string",
        BASE,
    ),
    Case(
        "EARL-E043",
        edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        v/m: double[3] = [1.0, 2.0]\n")),
        7,
        26,
        "the initial value of `v/m` must have 3 elements (double[3]), not 2",
        edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        v/m: double[3] = [1.0, 2.0, 3]\n")),
    ),
    Case(
        "EARL-E043",
        edit(("        x/m: double = 0.0\n", '        x/m: double = -"zero"\n')),
        6,
        23,
        "an initial value must be a constant: `-` needs a number",
        edit(("        x/m: double = 0.0\n", "        x/m: double = -(-2)\n")),
    ),
    Case(
        "EARL-E043",
        edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        k/m: int = -true\n")),
        7,
        20,
        "`-` needs a number",  # Python's -True is -1: it passed, and the SysML export wrote `-true`
        edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        k/m: int = -1\n")),
    ),
    Case(
        "EARL-E043",
        edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        k/m: int = 1.0\n")),
        7,
        20,
        # a parameter refuses it (`param K: int = 1.0`, EARL-R005): the memory took it as 1, silently
        "the initial value of `k/m` must be a whole number (int), not the real number 1.0",
        edit(("        x/m: double = 0.0\n", "        x/m: double = 1\n        k/m: int = 1\n")),
    ),
    Case(
        "EARL-E045",
        edit(("        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0 and not late/pp\n        late/pp = go/pp\n")),
        7,
        9,
        "primitive predicate `go/pp` of a1/a.cs is defined through itself (go/pp -> late/pp -> go/pp)",
        edit(
            (
                "        go/pp = x/mi > 1.0\n",
                "        go/pp = x/mi > 1.0 and not late/pp\n        late/pp = x/mi > 2.0\n",
            )
        ),
    ),
    Case(
        "EARL-W011",
        edit(("        inp/ib: double\n", "        inp/ib: double\n        spare/ib: double\n")),
        25,
        9,
        "`a2/a.cs.spare/ib` is fed by no link: it never receives a message",
        BASE,
    ),
    Case(
        "EARL-E016",
        edit(
            ("        inp/ib: double\n", "        inp/ib: double\n        spare/ib: double\n"),
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory spare/ib }\n            run -> run when got/pp",
            ),
        ),
        35,
        44,
        "state `run` of a2/a.cs waits for ever: `spare/ib` is obligatory, no link feeds it, and the state has no `timeout`",
        edit(
            ("        inp/ib: double\n", "        inp/ib: double\n        spare/ib: double\n"),
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory spare/ib  timeout 5 ms }\n            run -> run when got/pp",
            ),
        ),
    ),
    Case(
        "EARL-W043",
        edit(
            (
                "        fsm {\n            initial run\n            state run: run/bb\n            run -> run when got/pp\n        }\n",
                "",
            )
        ),
        23,
        5,
        "a2/a.cs has no `fsm`: it never runs a behaviour, and `earl run` refuses it",
        BASE,
    ),
    Case(
        "EARL-W044",
        edit(
            (
                "        got/pp = newData(inp/ib)\n",
                "        got/pp = newData(inp/ib)\n        lost/pp = timeout(inp/ib) or got/pp\n",
            ),
            ("tc = got/pp", "tc = lost/pp"),
        ),
        27,
        19,
        "`timeout(inp/ib)` in `lost/pp` is never true: `inp/ib` is obligatory in no state of a2/a.cs",
        edit(
            (
                "        got/pp = newData(inp/ib)\n",
                "        got/pp = newData(inp/ib)\n        lost/pp = timeout(inp/ib) or got/pp\n",
            ),
            ("tc = got/pp", "tc = lost/pp"),
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib  timeout 5 ms }\n            run -> run when got/pp",
            ),
        ),
    ),
    Case(
        "EARL-W046",
        optional_speed("got/pp and fast/pp"),
        27,
        19,
        "the terminal condition of `run/bb` (through `fast/pp`) reads `inp/ib.speed` even when no message that "
        "carries the optional field `speed` has arrived",
        optional_speed("newData(inp/ib.speed) and fast/pp"),
    ),
    Case(
        "EARL-E047",
        predicate_chain(160),
        19,
        9,
        "primitive predicate `q11/pp` of a1/a.cs is 151 levels deep written out through the predicates it names: "
        "at most 150",
        predicate_chain(148),
    ),
    Case(
        "EARL-E017",
        edit(("    cs { period 1 ms\n        inp/ib", "    cs {\n        inp/ib")),
        34,
        13,
        "a2/a.cs has no `period` and state `run` waits for no obligatory buffer, so nothing paces it",
        edit(
            ("    cs { period 1 ms\n        inp/ib", "    cs {\n        inp/ib"),
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib }\n            run -> run when got/pp",
            ),
        ),
    ),
    Case(
        "EARL-W045",
        edit(("    cs { period 1 ms\n        out/ob", "    cs { period 1.0000005 ms\n        out/ob")),
        4,
        10,
        "the period of a1/a.cs, `period 1.0000005 ms`, is 1000000.5 ns: earl keeps time in whole nanoseconds, so "
        "it runs as 1000001 ns",
        edit(("    cs { period 1 ms\n        out/ob", "    cs { period 1.000001 ms\n        out/ob")),
    ),
    Case(
        "EARL-W018",
        ping_pong(a2_period=False),
        17,
        13,
        "subsystems without a `period` wait for each other in a cycle, each message starting the next iteration "
        "at once: a1/a.cs in state `run` → a2/a.cs in state `run` → a1/a.cs in state `run`",
        ping_pong(a2_period=True),
    ),
    Case(
        "EARL-W022",
        edit(
            ("        inp/ib: double\n", "        inp/ib: double\n        spare/ib: double\n"),
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib  optional inp/ib }\n            run -> run when got/pp",
            ),
        ),
        35,
        61,
        "state `run` of a2/a.cs lists `inp/ib` as obligatory and as optional",
        edit(
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib  timeout 5 ms }\n            run -> run when got/pp",
            ),
        ),
    ),
    Case(
        "EARL-W022",
        edit(
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib, inp/ib }\n            run -> run when got/pp",
            ),
        ),
        34,
        52,
        "state `run` of a2/a.cs lists `inp/ib` twice as obligatory",
        edit(
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { obligatory inp/ib }\n            run -> run when got/pp",
            ),
        ),
    ),
    Case(
        "EARL-W022",
        edit(
            (
                "            state run: run/bb\n            run -> run when got/pp",
                "            state run: run/bb { optional inp/ib  timeout 5 ms }\n            run -> run when got/pp",
            ),
        ),
        34,
        13,
        "state `run` of a2/a.cs has a `timeout` but no obligatory buffer to wait for",
        BASE,
    ),
    Case(
        "EARL-W047",
        edit(("        take/pf(inp/ib -> y/mo)\n", "        take/pf(inp/ib, inp/ib -> y/mo)\n")),
        27,
        25,
        "`take/pf` of a2/a.cs reads `inp/ib` twice",
        BASE,
    ),
    Case(
        "EARL-W047",
        edit(
            ("            tf = {compute/pf} then {emit/pf}", "            tf = {compute/pf, compute/pf} then {emit/pf}")
        ),
        11,
        31,
        "stage 1 of `run/bb` of a1/a.cs runs `compute/pf` twice",
        BASE,
    ),
    Case(
        "EARL-W047",
        edit(
            (
                "            tf = {compute/pf} then {emit/pf}",
                "            tf = {compute/pf} then {compute/pf, emit/pf}",
            )
        ),
        11,
        37,
        "`compute/pf` is in stage 1 and again in stage 2 of `run/bb` of a1/a.cs",
        BASE,
    ),
    Case(
        "EARL-W047",
        edit(
            (
                "        emit/pf(x/mi -> out/ob)\n",
                "        emit/pf(x/mi -> out/ob)\n        stage pf = {compute/pf, emit/pf}\n        stage pfo = {emit/pf}\n",
            )
        ),
        11,
        22,
        "`emit/pf` is in stage set `pf` and again in stage set `pfo` of a1/a.cs",
        BASE,
    ),
    Case(
        "EARL-W047",
        edit(("    a2/a\n    link a1,a2\n", "    a2/a\n    a1/a\n    link a1,a2\n")),
        45,
        5,
        "robot `r/r` holds `a1/a` twice",
        BASE,
    ),
    Case(
        "EARL-E044",
        edit(("        take/pf(inp/ib -> y/mo)\n", '        take/pf(inp/ib -> y/mo) = python "take"\n')),
        27,
        9,
        'the implementation of `take/pf`, `python "take"`, does not name a function',
        edit(("        take/pf(inp/ib -> y/mo)\n", '        take/pf(inp/ib -> y/mo) = python "robot.relay:take"\n')),
    ),
    Case(
        "EARL-E064",
        edit(
            TWO_STATES,
            (
                "other -> run when go/pp\n",
                "other -> run when go/pp\n            assume go/pp\n            assume not go/pp\n",
            ),
        ),
        21,
        13,
        "the `assume` formulas of a1/a.cs can never hold",
        edit(
            TWO_STATES,
            ("other -> run when go/pp\n", "other -> run when go/pp\n            assume not (go/pp and x/mi < 1.0)\n"),
        ),
    ),
]


def findings(text: str, code: str | None = None) -> list[Diagnostic]:
    diagnostics = check(earl.loads(text, "spec.earl"))
    return [d for d in diagnostics if code is None or d.code == code]


def test_base_spec_is_clean() -> None:
    assert BASE.count("\n") == 46  # the line numbers of the cases count on it
    assert findings(BASE) == []


def test_every_rule_has_a_failing_and_a_passing_case() -> None:
    assert {case.code for case in CASES} == set(RULES)


@pytest.mark.parametrize("case", CASES, ids=lambda case: f"{case.code}:{case.fragment[:30]}")
def test_rule_points_at_the_finding(case: Case) -> None:
    found = findings(case.failing, case.code)
    assert found, f"{case.code} not reported; got {[str(d) for d in findings(case.failing)]}"
    at_spot = [
        d for d in found if d.location is not None and (d.location.line, d.location.column) == (case.line, case.column)
    ]
    assert at_spot, f"{case.code} reported at {[str(d.location) for d in found]}, not {case.line}:{case.column}"
    assert any(case.fragment in d.message for d in at_spot), [d.message for d in at_spot]
    rule = RULES[case.code]
    for diagnostic in found:
        assert diagnostic.severity is rule.severity
        assert diagnostic.location is not None and diagnostic.location.file == "spec.earl"


@pytest.mark.parametrize("case", CASES, ids=lambda case: f"{case.code}:{case.fragment[:30]}")
def test_rule_keeps_quiet_on_the_passing_spec(case: Case) -> None:
    assert [str(d) for d in findings(case.passing, case.code)] == []


def test_findings_are_ordered_by_position() -> None:
    text = add(EFFECTOR_AGENT.replace("    link cs,m: cs.cmd -> m/ve.cmd\n", ""), text=edit(TWO_STATES))
    positions = [(d.location.line, d.location.column) for d in findings(text) if d.location is not None]
    assert len(positions) >= 2
    assert positions == sorted(positions)


# ---------------------------------------------------------------- rules the language enforces
#
# Some of the manual's rules are refused while a spec is read (docs/rules.md, "Rules the language
# itself enforces"): the failing spec stops `earl check` with a reading code at the spot, and BASE,
# which keeps every one of them, reads cleanly (test_base_spec_is_clean).

FSM_BODY = "            initial run\n            state run: run/bb\n            run -> run when go/pp\n"

READING_CASES: list[tuple[str, str, str, int, int, str]] = [
    # (the manual's rule, code, failing spec, line, column, part of the message)
    (
        "exactly one Control Subsystem per Agent",
        "EARL-R002",
        edit(("a1/a {\n    cs {", "a1/a {\n    cs {\n    }\n    cs {")),
        6,
        5,
        "the Control Subsystem `cs` of `a1/a` is declared twice",
    ),
    (
        "the initial state exists",
        "EARL-R031",
        edit((FSM_BODY, FSM_BODY.replace("initial run", "initial walk"))),
        15,
        21,
        "the initial state `walk` is not a state of this FSM",
    ),
    (
        "every state has one basic behaviour",
        "EARL-R030",
        edit((FSM_BODY, FSM_BODY.replace("state run: run/bb", "state run: walk/bb"))),
        16,
        24,
        "state `run` names `walk/bb`, which `a1/a.cs` does not declare",
    ),
    (
        "every state has only one basic behaviour",
        "EARL-S006",
        edit((FSM_BODY, FSM_BODY.replace("state run: run/bb", "state run: run/bb, run/bb"))),
        16,
        30,
        "found `,`",
    ),
    (
        "transitions name existing states",
        "EARL-R032",
        edit(("run -> run when go/pp", "run -> walk when go/pp")),
        17,
        20,  # `walk` itself
        "transition `run,walk/t` names the state `walk`, which this FSM does not declare",
    ),
    (
        "predicates read only their own subsystem's memory",
        "EARL-R022",
        edit(("go/pp = x/mi > 1.0", "go/pp = y/mi > 1.0")),  # y/m belongs to a2/a.cs
        7,
        17,
        "`a1/a.cs` has no Internal Memory `y`",
    ),
    (
        "predicates read buffers and memory, never an Output Buffer",
        "EARL-R021",
        edit(("go/pp = x/mi > 1.0", "go/pp = out/ob > 1.0")),
        7,
        17,
        "`out/ob` cannot be read by a predicate",
    ),
    (
        "newData applies only to Input Buffers",
        "EARL-R042",
        edit(("got/pp = newData(inp/ib)", "got/pp = newData(y/mi)")),
        26,
        26,
        "`newData(…)` applies to an Input Buffer",
    ),
    (
        "a partial transition function reads `ib` and `mi`",
        "EARL-R021",
        edit(("emit/pf(x/mi -> out/ob)", "emit/pf(x/mo -> out/ob)")),
        9,
        17,
        "`x/mo` cannot be read by a Partial Transition Function",
    ),
    (
        "a partial transition function writes `mo` and `ob`",
        "EARL-R021",
        edit(("take/pf(inp/ib -> y/mo)", "take/pf(inp/ib -> inp/ib)")),
        27,
        27,
        "`inp/ib` cannot be written by a Partial Transition Function",
    ),
    (
        "links run from an Output Buffer to an Input Buffer",
        "EARL-R054",
        edit(("link a1,a2: a1/a.cs.out -> a2/a.cs.inp", "link a1,a2: a2/a.cs.inp -> a1/a.cs.out")),
        40,
        21,
        "`a2/a.cs` has no Output Buffer `inp`",
    ),
    (
        "kind suffixes name a kind of element",
        "EARL-S005",
        edit(("x/m: double = 0.0", "x/mm: double = 0.0")),
        6,
        11,
        "`mm` is not a kind of element that can stand here",
    ),
    (
        "a reference's kind suffix matches the element it names",
        "EARL-R022",
        edit(("tc = go/pp\n", "tc = go/ib\n")),
        12,
        18,
        "`a1/a.cs` has no Input Buffer `go`",
    ),
]


@pytest.mark.parametrize(
    ("rule", "code", "failing", "line", "column", "fragment"), READING_CASES, ids=[c[0] for c in READING_CASES]
)
def test_rules_the_language_enforces_stop_reading_at_the_spot(
    rule: str, code: str, failing: str, line: int, column: int, fragment: str
) -> None:
    with pytest.raises(EarlError) as raised:
        earl.loads(failing, "spec.earl")
    at_spot = [
        d
        for d in raised.value.diagnostics
        if d.code == code and d.location is not None and (d.location.line, d.location.column) == (line, column)
    ]
    assert at_spot, [f"{d.code} {d.location} {d.message}" for d in raised.value.diagnostics]
    assert any(fragment in d.message for d in at_spot), [d.message for d in at_spot]
    assert all(d.severity is Severity.ERROR for d in at_spot)


def test_a_name_misspelt_in_several_places_is_one_error_saying_where_the_others_are() -> None:
    """`hi/pp` for `high/pp` in a `tc` and two conditions was three EARL-R022 errors for one slip."""
    text = edit(
        ("        go/pp = x/mi > 1.0\n", "        high/pp = x/mi > 1.0\n        go/pp = high/pp\n"),
        ("            tc = go/pp\n", "            tc = hi/pp\n"),
        ("run -> run when go/pp", "run -> run when hi/pp or not hi/pp"),
    )
    with pytest.raises(EarlError) as raised:
        earl.loads(text, "spec.earl")
    [unknown] = [d for d in raised.value.diagnostics if d.code == "EARL-R022"]
    assert unknown.message == "`a1/a.cs` has no Primitive Predicate `hi` (and 2 more uses, at line 18)"
    assert unknown.location is not None and (unknown.location.line, unknown.hint) == (13, "did you mean `high`?")


def test_every_rule_the_language_enforces_has_a_reading_case() -> None:
    """docs/rules.md names the reading codes that enforce the manual; each has a failing case above."""
    documented = {code for _, how in ENFORCED_BY_THE_LANGUAGE for code in re.findall(r"EARL-[SR]\d{3}", how)}
    tested = {case[1] for case in READING_CASES}
    assert documented - {"EARL-S011"} <= tested  # a second `fsm`: see test_a_second_fsm_is_refused


def test_an_unfed_buffer_listed_twice_waits_for_ever_once() -> None:
    # the repeat is EARL-W022's to say; EARL-E016 tells of the buffer, not of each mention
    text = edit(
        ("link a1,a2: a1/a.cs.out -> a2/a.cs.inp\n", ""),
        ("    link a1,a2\n", ""),
        (
            "            state run: run/bb\n            run -> run when got/pp",
            "            state run: run/bb { obligatory inp/ib, inp/ib }\n            run -> run when got/pp",
        ),
    )
    waits = findings(text, "EARL-E016")
    assert [(d.location.line, d.location.column) for d in waits if d.location is not None] == [(34, 44)]
    assert [d.message for d in findings(text, "EARL-W022")] == [
        "state `run` of a2/a.cs lists `inp/ib` twice as obligatory"
    ]


def test_a_second_fsm_is_refused() -> None:
    """A Subsystem has one FSM (Figure 3): a second `fsm` block is refused where it starts."""
    block = "        fsm {\n" + FSM_BODY + "        }\n"
    with pytest.raises(EarlError) as raised:
        earl.loads(edit((block, block + block)), "spec.earl")
    assert [(d.code, d.location.line if d.location else None) for d in raised.value.diagnostics] == [("EARL-S011", 19)]


# ---------------------------------------------------------------- EARL-E040: how to fix it


def test_a_one_stage_function_writing_an_output_is_told_how_to_split() -> None:
    """`tf = {control/pf}` writing an Output Buffer is refused (Eq. 4–6 put outputs in stage 2), and the
    hint spells out the fix; applying it literally makes the spec clean."""
    text = edit(("tf = {compute/pf} then {emit/pf}", "tf = {emit/pf}"), ("        compute/pf(x/mi -> x/mo)\n", ""))
    (finding,) = findings(text, "EARL-E040")
    assert finding.message.startswith(
        "`emit/pf` writes `out/ob` in stage 1 of `run/bb` in `a1/a.cs`: a transition function of one stage"
    )
    assert finding.hint is not None
    assert "let `emit/pf` write memory instead (`-> out/mo`, declared as `/m`)" in finding.hint
    assert "`tf = {emit/pf} then {send/pf}` with `send/pf(… /mi -> out/ob)`" in finding.hint
    fixed = edit(
        ("        emit/pf(x/mi -> out/ob)\n", "        emit/pf(x/mi -> out/mo)\n        send/pf(out/mi -> out/ob)\n"),
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        out/m: double = 0.0\n"),
        ("tf = {emit/pf}", "tf = {emit/pf} then {send/pf}"),
        text=text,
    )
    assert findings(fixed) == []


def test_an_early_stage_output_names_every_buffer_once() -> None:
    text = edit(
        ("        out/ob: double\n", "        out/ob: double\n        extra/ob: double\n"),
        ("emit/pf(x/mi -> out/ob)", "emit/pf(x/mi -> out/ob, extra/ob)"),
        ("tf = {compute/pf} then {emit/pf}", "tf = {emit/pf} then {compute/pf}"),
    )
    found = [d for d in findings(text, "EARL-E040") if "writes `out/ob`" in d.message]
    assert len(found) == 1
    assert "writes `out/ob`, `extra/ob` in stage 1 of `run/bb`" in found[0].message
    assert found[0].hint == "`emit/pf` reads only memory: move it into the last stage (stage 2)"


# ---------------------------------------------------------------- the manual's example


def example_text() -> str:
    return EXAMPLE.read_text(encoding="utf-8")


def test_the_example_has_no_errors_or_warnings() -> None:
    diagnostics = check(earl.load(EXAMPLE))
    assert [str(d) for d in diagnostics if d.severity is not Severity.NOTE] == []


def test_the_example_notes_exactly_its_false_pp_behaviours() -> None:
    """Every behaviour whose only condition is `tc = false/pp` never ends (a sink state), and no other."""
    system = earl.load(EXAMPLE)
    sinks = {
        behaviour.location.line
        for agent in system.agents
        for subsystem in agent.subsystems
        for behaviour in subsystem.basic_behaviours
        if behaviour.location is not None
        and behaviour.error_condition is None
        and expression_text(behaviour.terminal_condition.expression) == "false/pp"
    }
    notes = [d for d in check(system) if d.code == "EARL-I063"]
    assert len(sinks) == 8
    assert {d.location.line for d in notes if d.location is not None} == sinks
    assert all(d.severity is Severity.NOTE for d in notes)
    assert any("`emergencyStop/bb` never ends" in d.message and "manip/a.cs" in d.message for d in notes)


def without_priorities_and_assumptions(text: str) -> str:
    text = re.sub(r" priority \d+", "", text)
    return re.sub(r"(?m)^\s*assume .*\n", "", text)


def assignment(message: str) -> dict[str, bool]:
    """The example assignment a finding shows: `… e.g. when a/pp = true, b/pp = false`."""
    shown = message.split("e.g. when ", 1)[1]
    pairs = [part.rsplit(" = ", 1) for part in shown.split(", ")]
    assert all(value in ("true", "false") for _, value in pairs), shown
    return {name: value == "true" for name, value in pairs}


def test_table_5_without_priorities_and_assumption_overlaps() -> None:
    original = example_text()
    assert re.search(r" priority \d", original) and re.search(r"(?m)^\s*assume ", original)
    text = without_priorities_and_assumptions(original)
    assert not re.search(r" priority \d|^\s*assume ", text, re.MULTILINE)
    overlaps = findings(text, "EARL-E060")
    wanted = [d for d in overlaps if "`jointMove,jointMove/t` and `jointMove,idle/t`" in d.message]
    assert len(wanted) == 1, [d.message for d in overlaps]
    finding = wanted[0]
    assert "manip/a.cs" in finding.message
    values = assignment(finding.message)
    assert values["newJointPos/pp"] is True
    assert values["emergencyStop/pp"] is False
    line = text.splitlines().index("            jointMove -> idle when not emergencyStop/pp") + 1
    assert finding.location is not None and finding.location.line == line
    assert finding.hint is not None and "priorit" in finding.hint


def test_the_assumption_alone_separates_the_two_new_set_points() -> None:
    """Without priorities but with the `assume`, idle's two moves no longer overlap; jointMove's still do."""
    text = re.sub(r" priority \d+", "", example_text())
    messages = [d.message for d in findings(text, "EARL-E060")]
    assert not any("`idle,jointMove/t` and `idle,operationalMove/t`" in m for m in messages)
    assert any("`jointMove,jointMove/t` and `jointMove,idle/t`" in m for m in messages)
    without = [d.message for d in findings(without_priorities_and_assumptions(example_text()), "EARL-E060")]
    assert any("`idle,jointMove/t` and `idle,operationalMove/t`" in m for m in without)


def test_a_stuck_state_shows_an_assignment_that_sticks() -> None:
    text = edit(
        ("            jointMove -> idle when not emergencyStop/pp priority 3\n", ""),
        text=example_text(),
    )
    stuck = findings(text, "EARL-W061")
    assert len(stuck) == 1
    message = stuck[0].message
    assert "`jointMove/bb` can stop while no transition out of `jointMove` holds (manip/a.cs)" in message
    values = assignment(message)
    # tc = motionFinished or emergencyStop, and neither `* -> emergencyStop` nor jointMove -> jointMove holds
    assert values["emergencyStop/pp"] is False
    assert values["motionFinished/pp"] is True
    assert values["newJointPos/pp"] is False


# ---------------------------------------------------------------- Table 1


def test_table_1_types_of_the_example() -> None:
    system = earl.load(EXAMPLE)
    context = context_for(system)
    declared = {agent.name: context.agent_type(agent).name for agent in system.agents}
    expanded = {agent.name: context.agent_type(agent).name for agent in context.system.agents}
    assert declared == expanded == {"task": "CT", "manip": "CET", "grip": "CET"}


def typed_agent(effectors: bool, receptors: bool, transmission: bool) -> str:
    """A system whose agent `x/a` has exactly the activities asked for."""
    cs = ["cmd/ob: double"] * effectors + ["data/ib: double"] * receptors + ["tx/ob: double"] * transmission
    parts = ["    cs {", *(f"        {line}" for line in cs), "    }"]
    if effectors:
        parts += ["    m/ve {", "        cmd/ib: double", "        drive/ob: double", "    }"]
        parts += ["    d/re {", "        drive/ib: double", "    }"]
        parts += ["    link cs,m: cs.cmd -> m/ve.cmd", "    link m,d: m/ve.drive -> d/re.drive"]
    if receptors:
        parts += ["    s/vr {", "        raw/ib: double", "        data/ob: double", "    }"]
        parts += ["    cam/rr {", "        raw/ob: double", "    }"]
        parts += ["    link cam,s: cam/rr.raw -> s/vr.raw", "    link s,cs: s/vr.data -> cs.data"]
    text = "system types\n\nx/a {\n" + "\n".join(parts) + "\n}\n"
    members = "x/a"
    if transmission:
        text += "\np/a {\n    cs {\n        rx/ib: double\n    }\n}\n\nlink x,p: x/a.cs.tx -> p/a.cs.rx\n"
        members += " p/a"
    return text + f"\nr/r {{ {members} }}\n"


TABLE_1 = [
    ("C", False, False, False),
    ("CT", False, False, True),
    ("CE", True, False, False),
    ("CR", False, True, False),
    ("CET", True, False, True),
    ("CRT", False, True, True),
    ("CER", True, True, False),
    ("CERT", True, True, True),
]


@pytest.mark.parametrize(("name", "effectors", "receptors", "transmission"), TABLE_1)
def test_table_1_agent_type(name: str, effectors: bool, receptors: bool, transmission: bool) -> None:
    system: System = earl.loads(typed_agent(effectors, receptors, transmission))
    context = context_for(system)
    agent = system.agent("x")
    assert agent is not None
    row = context.agent_type(agent)
    assert (row.name, row.effectors, row.receptors, row.transmission) == (name, effectors, receptors, transmission)
    if transmission:
        partner = system.agent("p")
        assert partner is not None
        assert context.agent_type(partner).name == "CT"  # receiving counts as communicating too
    diagnostics = check(system)
    assert [d.code for d in diagnostics if d.severity is Severity.ERROR] == []
    zombies = [d for d in diagnostics if d.code == "EARL-W001"]
    assert bool(zombies) == (name == "C")


def test_table_1_counts_every_member_of_an_agent_family() -> None:
    text = edit(
        ("a2/a {", "a2[K in 1..2]/a {"),
        ("link a1,a2: a1/a.cs.out -> a2/a.cs.inp", "link a1,a2[K in 1..2]: a1/a.cs.out -> a2[K]/a.cs.inp"),
        ("    a2/a\n    link a1,a2\n", "    a2[1]/a\n    a2[2]/a\n"),
    )
    system = earl.loads(text)
    context = context_for(system)
    assert [context.agent_type(agent).name for agent in context.system.agents] == ["CT", "CT", "CT"]
    family = system.agent("a2")
    assert family is not None
    assert context.agent_type(family).name == "CT"
    assert findings(text) == []


# ---------------------------------------------------------------- members of a family


FAMILY_AGENT = """\
a3[I in 1..3]/a {
    cs { period 1 ms
        cmd[K in 1..2]/ob: double
        c[K in 1..2]/m: double = 0.0
        plan/pf(c[*]/mi -> c[*]/mo)
        send/pf(c[*]/mi -> cmd[*]/ob)
        run/bb {
            tf = {plan/pf} then {send/pf}
            tc = false
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
    m[K in 1..2]/ve { period 1 ms
        param which: int = K
        cmd/ib: double
        drive/ob: double
        w[J in 1..2]/m: double = 0.0
        f/pf(cmd/ib -> w[which]/mo)
        g/pf(cmd/ib -> w[2]/mo)
        out/pf(w[*]/mi -> drive/ob)
        run/bb {
            tf = {f/pf, g/pf} then {out/pf}
            tc = false
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
    d[K in 1..2]/re {
        drive/ib: double
    }
    link cs,m[K in 1..2]: cs.cmd[K] -> m[K]/ve.cmd
    link m[K in 1..2],d[K]: m[K]/ve.drive -> d[K]/re.drive
}
"""


def test_a_problem_of_one_family_member_is_found_once() -> None:
    """`f/pf` and `g/pf` collide only in `m[2]/ve` (where `which` = 2), in every member of the agent
    family; members whose inside is the same are checked once, and the one that differs is not lost."""
    text = add(FAMILY_AGENT)
    (collision,) = findings(text, "EARL-E042")
    assert "`f/pf` and `g/pf` both write `w[2]/m` in stage 1 of `run/bb` (a3[1]/a.m[2]/ve)" in collision.message
    assert collision.location is not None and (collision.location.line, collision.location.column) == (72, 25)
    # (the drives `d[K]/re` have no FSM: they are there as link ends)
    assert [d.code for d in findings(text) if d.severity is not Severity.NOTE and d.code != "EARL-W043"] == [
        "EARL-E042"
    ]


def test_members_that_name_no_index_are_one_subsystem_to_the_rules() -> None:
    context = context_for(earl.loads(add(FAMILY_AGENT)))
    members = [(agent.name, agent.index, s.name, s.index) for agent, s in context.subsystems()]
    distinct = [(agent.name, agent.index, s.name, s.index) for agent, s in context.distinct_subsystems()]
    assert len(members) == 2 + 3 * 5
    # a1.cs, a2.cs; then a3's cs (names no index), m[1] and m[2] (they name K through `which`), d (no body)
    assert distinct == [
        ("a1", None, "cs", None),
        ("a2", None, "cs", None),
        ("a3", 1, "cs", None),
        ("a3", 1, "m", 1),
        ("a3", 1, "m", 2),
        ("a3", 1, "d", 1),
    ]


WORKERS = """\
system workers

param N: int = 3

r/r { sup/a }

worker[K in 1..N]/a {
    cs { period 1 ms
        i/ib: double
        x/m: double = 0.0
        take/pf(i/ib -> x/mo)
        b/bb {
            tf = {take/pf}
            tc = false
        }
        fsm {
            initial one
            state one: b/bb { obligatory i/ib }
        }
    }
}

sup/a {
    cs { period 1 ms
        o/ob: double
        x/m: double = 0.0
        send/pf(x/mi -> o/ob)
        b/bb {
            tf = {send/pf}
            tc = false
        }
        fsm {
            initial one
            state one: b/bb
        }
    }
}

link sup,worker: sup/a.cs.o -> worker[FED]/a.cs.i
"""


@pytest.mark.parametrize(("fed", "unfed"), [(1, "worker[2..3]"), (2, "worker[1, 3]"), (3, "worker[1..2]")])
def test_members_of_an_agent_family_linked_differently_are_checked_each(fed: int, unfed: str) -> None:
    """Only one worker is fed: the others wait for ever on `i/ib`, wherever the fed one is in the family
    (the members were one subsystem to the rules, checked as the first: linking `worker[1]` hid the rest)."""
    text = WORKERS.replace("FED", str(fed))
    assert [d.message for d in findings(text, "EARL-E016")] == [
        f"state `one` of {unfed}/a.cs waits for ever: `i/ib` is obligatory, no link feeds it, and the state has "
        "no `timeout`"
    ]
    assert [d.message for d in findings(text, "EARL-W011")] == [
        f"`{unfed}/a.cs.i/ib` is fed by no link: it never receives a message"
    ]


def test_a_buffer_fed_only_by_an_output_buffer_nothing_writes_waits_for_ever() -> None:
    """`sup`'s `send/pf` writes its memory, not `o/ob`: `o/ob` is never sent (EARL-W040), so `worker[1]`,
    the one it feeds, waits for ever as surely as its unlinked siblings; the message names the sender."""
    text = WORKERS.replace("FED", "1").replace("send/pf(x/mi -> o/ob)", "send/pf(x/mi -> x/mo)")
    [never_sent, unlinked] = findings(text, "EARL-E016")
    assert never_sent.message == (
        "state `one` of worker[1]/a.cs waits for ever: `i/ib` is obligatory, fed only by `sup/a.cs.o/ob`, which no "
        "function of any behaviour writes, so it is never sent, and the state has no `timeout`"
    )
    assert never_sent.hint is not None and never_sent.hint.startswith(
        "add `o/ob` to the writes of a function of sup/a.cs"
    )
    assert unlinked.message.startswith("state `one` of worker[2..3]/a.cs waits for ever: `i/ib` is obligatory, no link")
    assert findings(WORKERS.replace("FED", "1"), "EARL-E016")[0].message.startswith("state `one` of worker[2..3]/a.cs")


def test_members_of_a_subsystem_family_linked_differently_are_checked_each() -> None:
    text = add(
        "a4/a {\n    cs {\n        o/ob: double\n    }\n"
        "    d[K in 1..3]/ve {\n        in/ib: double\n        out/ob: double\n        x/m: double = 0.0\n"
        "        take/pf(in/ib -> x/mo)\n        b/bb {\n            tf = {take/pf}\n            tc = false\n        }\n"
        "        fsm {\n            initial one\n            state one: b/bb { obligatory in/ib }\n        }\n    }\n"
        "    link cs,d: cs.o -> d[1]/ve.in\n}\n"
    )
    assert [d.message for d in findings(text, "EARL-E016")] == [
        # `cs` has no behaviour that writes `o/ob`: `d[1]` is linked but never receives either
        "state `one` of a4/a.d[1]/ve waits for ever: `in/ib` is obligatory, fed only by `a4/a.cs.o/ob`, which no "
        "function of any behaviour writes, so it is never sent, and the state has no `timeout`",
        "state `one` of a4/a.d[2..3]/ve waits for ever: `in/ib` is obligatory, no link feeds it, and the state "
        "has no `timeout`",
    ]
    assert [d.message for d in findings(text, "EARL-W011")] == [
        "`a4/a.d[2..3]/ve.in/ib` is fed by no link: it never receives a message"
    ]


def test_every_zombie_member_of_an_agent_family_is_named() -> None:
    """Only `worker[3]/a` is linked: the other four are zombies, named together (not `worker[1]/a` alone)."""
    text = WORKERS.replace("param N: int = 3", "param N: int = 5").replace("FED", "3")
    assert [d.message for d in findings(text, "EARL-W001")] == [
        "agent `worker[1, 2, 4, 5]/a` is of type C (zombie): no effectors, receptors or inter-agent links"
    ]
    linked_first = WORKERS.replace("FED", "1")
    assert [d.message for d in findings(linked_first, "EARL-W001")] == [
        "agent `worker[2..3]/a` is of type C (zombie): no effectors, receptors or inter-agent links"
    ]


def test_members_linked_alike_are_still_one_subsystem_to_the_rules() -> None:
    """Every worker fed, each by a link of its own: one subsystem to the rules, not one per member."""
    text = WORKERS.replace("o/ob: double", "o[K in 1..N]/ob: double").replace("-> o/ob)", "-> o[*]/ob)")
    text = text.replace(
        "link sup,worker: sup/a.cs.o -> worker[FED]/a.cs.i",
        "link sup,worker[K in 1..N]: sup/a.cs.o[K] -> worker[K]/a.cs.i",
    )
    context = context_for(earl.loads(text, "spec.earl"))
    distinct = [(agent.name, agent.index) for agent, _ in context.distinct_subsystems()]
    assert distinct == [("worker", 1), ("sup", None)]
    groups = [[(agent.name, agent.index) for agent, _ in members] for members in context.distinct_subsystem_groups()]
    assert groups == [[("worker", 1), ("worker", 2), ("worker", 3)], [("sup", None)]]
    assert findings(text, "EARL-E016") == []


# ---------------------------------------------------------------- EARL-W041 beyond the initial state


def position_of(text: str, line_text: str, token: str) -> tuple[int, int]:
    """(line, column) of `token` on the only line that contains `line_text`."""
    (number,) = [n for n, line in enumerate(text.splitlines(), start=1) if line_text in line]
    return number, text.splitlines()[number - 1].index(token) + 1


UNWRITTEN = edit(
    TWO_STATES,
    ("state other: run/bb", "state other: other/bb"),
    ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        z/m: double\n"),
    (
        "        emit/pf(x/mi -> out/ob)\n",
        "        emit/pf(x/mi -> out/ob)\n        fill/pf(x/mi -> z/mo)\n        useZ/pf(z/mi -> x/mo)\n"
        "        other/bb {\n            tf = {useZ/pf} then {emit/pf}\n            tc = go/pp\n        }\n",
    ),
)


def test_memory_unwritten_on_the_way_to_a_state_is_reported_there() -> None:
    (finding,) = findings(UNWRITTEN, "EARL-W041")
    assert finding.location is not None
    assert (finding.location.line, finding.location.column) == position_of(UNWRITTEN, "tf = {useZ/pf}", "useZ")
    assert finding.message == (
        "`useZ/pf` reads `z/mi` in the first iteration of `other/bb` (state `other` of a1/a.cs, entered by "
        "run → other where nothing writes it) before anything wrote it"
    )
    # written by the behaviour of the state before: nothing to report
    written = edit(("tf = {compute/pf} then {emit/pf}", "tf = {compute/pf, fill/pf} then {emit/pf}"), text=UNWRITTEN)
    assert findings(written, "EARL-W041") == []


def test_a_condition_reading_unwritten_memory_is_reported() -> None:
    text = edit(
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        z/m: double\n"),
        ("        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0\n        zset/pp = z/mi > 0.0\n"),
        ("tc = go/pp\n", "tc = go/pp or zset/pp\n"),
    )
    (finding,) = findings(text, "EARL-W041")
    assert finding.location is not None
    assert (finding.location.line, finding.location.column) == position_of(text, "tc = go/pp or zset/pp", "zset")
    assert "the condition of `run/bb` reads `z/mi` (through `zset/pp`)" in finding.message
    assert "(the initial state of a1/a.cs)" in finding.message
    fixed = edit(("z/m: double\n", "z/m: double = 0.0\n"), text=text)
    assert findings(fixed, "EARL-W041") == []


def test_a_condition_reading_unwritten_memory_itself_says_no_through() -> None:
    """`tc = go/pp or z/mi > 0.0` reads `z/mi` directly: the message said "reads `z/mi` (through `z/mi`)"."""
    text = edit(
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        z/m: double\n"),
        ("tc = go/pp\n", "tc = go/pp or z/mi > 0.0\n"),
    )
    (finding,) = findings(text, "EARL-W041")
    assert finding.message == (
        "the condition of `run/bb` reads `z/mi` after the first iteration (the initial state of a1/a.cs), "
        "before anything wrote it"
    )


def test_an_inter_agent_link_from_a_receptor_is_said_once_at_the_end_it_starts_at() -> None:
    """From `cam/rr` into another agent's `cs`: E012 and E013 both reported it, and E013 said the link
    "ends at" `a4/a.cam/rr`, its source."""
    text = add(RECEPTOR_AGENT + "\nlink a4,a2: a4/a.cam/rr.raw -> a2/a.cs.inp\n")
    said = [(d.code, d.message) for d in findings(text) if d.code in ("EARL-E012", "EARL-E013")]
    assert said == [
        ("EARL-E013", "inter-agent link `a4,a2` starts at `a4/a.cam/rr`, not at a Control Subsystem"),
    ]


def test_a_subsystem_declared_twice_is_reported_once_not_again_by_each_link_to_it() -> None:
    twice = BASE.replace("a1/a {\n    cs {", "a1/a {\n    cs {\n    }\n    cs {")
    with pytest.raises(EarlError) as raised:
        earl.loads(twice, "spec.earl")
    assert [d.code for d in raised.value.diagnostics] == ["EARL-R002"]


def test_a_problem_every_member_of_a_link_family_shares_is_said_once_with_the_indices_as_a_range() -> None:
    declared = "    link motor[K in 1..N],motorController[K]: motor[K]/re.encoderReading -> motorController[K]/ve.encoderReading\n"
    wrong = "    link motor[K in 1..N],cs: motor[K]/re.encoderReading -> cs.motorControllerState[K]\n"
    text = EXAMPLE.read_text(encoding="utf-8")
    assert declared in text
    system = earl.loads(text.replace(declared, wrong), str(EXAMPLE))
    found = [d for d in check(system) if d.code == "EARL-E012"]
    assert [d.message for d in found] == [
        "a link from a Real Effector to a Control Subsystem is not permitted inside an agent (link `motor[1..6],cs`)"
    ]
    fed_twice = [d.message for d in check(system) if d.code == "EARL-E011"]
    assert fed_twice == [
        "`manip/a.cs.motorControllerState[1..6]/ib` is fed by link `motor[1..6],cs` and by link "
        "`motorController[1..6],cs`"
    ]


def test_merging_keeps_apart_other_places_and_writes_scattered_indices_as_a_list() -> None:
    from earl.check.merging import Said, merge_family_members
    from earl.model.location import SourceLocation

    here, there = SourceLocation("s.earl", 3, 5, 3, 9), SourceLocation("s.earl", 4, 5, 4, 9)
    found = [
        Said("EARL-E010", "`m[1]/ve` is wrong", here, "fix it"),
        Said("EARL-E010", "`m[3]/ve` is wrong", here, "fix it"),
        Said("EARL-E010", "`m[3]/ve` is wrong", here, "fix it"),
        Said("EARL-E010", "`m[4]/ve` is wrong", here, "fix it"),
        Said("EARL-E010", "`m[2]/ve` is wrong", there, "fix it"),
        Said("EARL-E011", "`m[5]/ve` is wrong", here, None),
    ]
    assert [(s.code, s.message, s.location) for s in merge_family_members(found)] == [
        ("EARL-E010", "`m[1, 3, 4]/ve` is wrong", here),
        ("EARL-E010", "`m[2]/ve` is wrong", there),
        ("EARL-E011", "`m[5]/ve` is wrong", here),
    ]


def test_equality_of_structs_and_arrays_needs_one_type_and_names_them() -> None:
    types = "struct S {\n    a: double\n    arr: double[3]\n}\n\nstruct T {\n    a: double\n}\n\n"
    text = BASE.replace("system base\n\n", "system base\n\n" + types).replace(
        "        inp/ib: double\n", "        inp/ib: double\n        s/ib: S\n        t/ib: T\n        u/ib: S\n"
    )

    def said(condition: str) -> list[str]:
        spec = text.replace("got/pp = newData(inp/ib)", f"got/pp = newData(inp/ib) and {condition}")
        return [d.message for d in findings(spec, "EARL-E030")]

    assert said("s/ib == t/ib") == ["`s/ib == t/ib` compares a struct `S` with a struct `T`"]
    assert said("s/ib.arr != t/ib") == ["`s/ib.arr != t/ib` compares an array `double[3]` with a struct `T`"]
    assert said("s/ib == 3.0") == ["`s/ib == 3.0` compares a struct `S` with a number"]
    assert said("s/ib == u/ib") == []


def test_the_hint_for_outputs_in_an_early_stage_says_what_fits_the_function() -> None:
    # `emit/pf` reads only memory: it is a second-stage function already
    [finding] = findings(edit(("tf = {compute/pf} then {emit/pf}", "tf = {compute/pf, emit/pf}")), "EARL-E040")
    assert finding.hint == "`emit/pf` reads only memory: make it the second stage, `tf = {compute/pf} then {emit/pf}`"
    # a family of output buffers is named as the spec writes it, not member by member
    text = EXAMPLE.read_text(encoding="utf-8")
    before = "tf = {calculatePosition/pf, jointMove/pf} then {outputManipState/pf, outputMotorCon/pf}"
    assert before in text
    wrong = text.replace(
        before, "tf = {calculatePosition/pf, jointMove/pf, outputMotorCon/pf} then {outputManipState/pf}"
    )
    said = [d for d in check(earl.loads(wrong, str(EXAMPLE))) if d.code == "EARL-E040"]
    assert [d.message.split(" in stage")[0] for d in said] == [
        "`outputMotorCon/pf` writes `motorControllerCommand[*]/ob`"
    ]
    assert said[0].hint == "`outputMotorCon/pf` reads only memory: move it into the last stage (stage 2)"


def test_a_predicate_only_unused_predicates_use_is_unused_too() -> None:
    """`p2/pp = p1/pp and …` with `p2/pp` unused: `p1/pp` is dead too, and W030 said only `p2/pp`."""
    text = edit(
        (
            "        go/pp = x/mi > 1.0\n",
            "        go/pp = x/mi > 1.0\n        p1/pp = x/mi > 2.0\n        p2/pp = p1/pp and x/mi < 5.0\n"
            "        p3/pp = p1/pp or p2/pp\n",
        )
    )
    said = findings(text, "EARL-W030")
    assert [(d.message, d.location.line if d.location else None) for d in said] == [
        ("primitive predicate `p1/pp` is used only by `p2/pp` and `p3/pp`, which are never used in a condition", 8),
        ("primitive predicate `p2/pp` is used only by `p3/pp`, which is never used in a condition", 9),
        ("primitive predicate `p3/pp` is never used", 10),
    ]
    assert said[0].hint == "use one of them in a terminal, error or initial condition, or remove them together"
    # one of them used by a condition: every predicate it is defined through is used
    assert findings(text.replace("tc = go/pp", "tc = p3/pp"), "EARL-W030") == []


def test_a_real_number_for_an_integer_memory_is_refused_with_the_whole_number_to_write() -> None:
    text = edit(("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        k/m: int32[2] = [1, 2.0]\n"))
    [finding] = findings(text, "EARL-E043")
    assert finding.message == "the initial value of `k/m`[1] must be a whole number (int32), not the real number 2.0"
    [whole] = findings(edit(("x/m: double = 0.0", "x/m: double = 0.0\n        k/m: uint8 = 3.0")), "EARL-E043")
    assert whole.hint == "write `3`: an integer type holds whole numbers, written without a decimal point"


@pytest.mark.parametrize(
    ("path", "wrong", "hint"),
    [
        (
            "1mod:f",
            "names the module `1mod`, which `import` cannot name: `1mod` is not a Python identifier",
            "single dots",
        ),
        ("a..b:f", "names the module `a..b`, which `import` cannot name: a dot has no name on one side", "single dots"),
        ("a/b:f", "names the module `a/b`, which `import` cannot name: `a/b` is not a Python identifier", '"a.b:f"'),
        ("robot/relay.py:take", "names the module `robot/relay.py`", '`python "robot.relay:take"`'),
        ("a.b:f-g", "names the function `f-g`, which is not a Python identifier", "the name it is defined with"),
        ("a:f:g", "names the function `f:g`, which is not a Python identifier", "the name it is defined with"),
    ],
)
def test_an_implementation_that_could_never_be_imported_is_refused(path: str, wrong: str, hint: str) -> None:
    """E044 asked only for both parts: `"1mod:f"`, `"a..b:f"`, `"a/b:f"` passed, and failed at run time."""
    text = edit(("        take/pf(inp/ib -> y/mo)\n", f'        take/pf(inp/ib -> y/mo) = python "{path}"\n'))
    [finding] = findings(text, "EARL-E044")
    assert finding.message.startswith(f'the implementation of `take/pf`, `python "{path}"`, {wrong}')
    assert finding.hint is not None and hint in finding.hint
    # what the runtime imports passes: dotted identifiers, spaces around the parts (`module.function` is E044: the colon is the separator)
    for importable in ("robot.relay:take", " robot.relay : take ", "_m2.über:ñ"):
        fixed = text.replace(f'python "{path}"', f'python "{importable}"')
        assert findings(fixed, "EARL-E044") == [], importable


def test_a_constant_index_outside_a_fixed_array_is_refused() -> None:
    text = edit(
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        v/m: double[3] = [0.0, 0.0, 0.0]\n"),
        ("        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0 or v/mi[5] > 1.0\n"),
    )
    [finding] = findings(text, "EARL-E030")
    assert finding.message == "`v/mi[5]` reads element 5 of a `double[3]`, whose elements are 0 to 2"
    assert findings(text.replace("v/mi[5]", "v/mi[2]"), "EARL-E030") == []
    [negative] = findings(text.replace("v/mi[5]", "v/mi[1 - 2]"), "EARL-E030")
    assert negative.message == "`v/mi[1 - 2]` reads element -1 of a `double[3]`, whose elements are 0 to 2"


@pytest.mark.parametrize(
    ("index", "wrong", "hint"),
    [
        ("d/mi", "`d/mi` is a `double`", "an `int` parameter or quantifier index"),
        ("b/mi", "`b/mi` is a `boolean`", "an `int` parameter or quantifier index"),
        ("true", "`true` is a Boolean", "an `int` parameter or quantifier index"),
        ('"x"', '`"x"` is a string', "an `int` parameter or quantifier index"),
        ("1.5", "`1.5` is a real number", "an `int` parameter or quantifier index"),
        ("1.0", "`1.0` is a real number", "write `1`: elements are counted in whole numbers"),
        ("i/mi + d/mi", "`d/mi` is a `double`", "an `int` parameter or quantifier index"),
    ],
)
def test_an_index_that_is_not_a_whole_number_is_refused(index: str, wrong: str, hint: str) -> None:
    """`v/mi[true]` read element 1 at run time, `v/mi[1.5]` failed every time: both passed the check."""
    memories = (
        "        v/m: double[3] = [0.0, 0.0, 0.0]\n        d/m: double = 0.0\n"
        "        b/m: boolean = false\n        i/m: int32 = 0\n"
    )
    text = edit(
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n" + memories),
        ("        go/pp = x/mi > 1.0\n", f"        go/pp = x/mi > 1.0 or v/mi[{index}] > 1.0\n"),
    )
    [finding] = findings(text, "EARL-E030")
    assert finding.message == f"the index of `v/mi[{index}]` must be a whole number, but {wrong}"
    assert finding.location is not None
    assert (finding.location.line, finding.location.column) == position_of(text, "go/pp =", f"[{index}]")
    assert finding.hint is not None and hint in finding.hint
    # whole numbers: a literal, an integer memory, arithmetic of them, a quantifier's index
    for whole in ("1", "i/mi", "i/mi + 1", "0 - i/mi", "2 * i/mi"):
        assert findings(text.replace(f"v/mi[{index}]", f"v/mi[{whole}]"), "EARL-E030") == [], whole
    quantified = text.replace(f"v/mi[{index}] > 1.0", "any(K in 0..2: v/mi[K] > 1.0)")
    assert findings(quantified, "EARL-E030") == []


def test_a_constant_index_a_quantifier_puts_in_is_checked_for_every_value() -> None:
    """`all(J in 1..N: v/mi[J] > 0.0)` of a `double[N]`: J = N is one past the last element (they count
    from 0). The check looked only at the first body of the unrolled quantifier (J = 1)."""
    text = BASE.replace("system base\n", "system base\n\nparam N: int = 3\n").replace(
        "        x/m: double = 0.0\n",
        "        x/m: double = 0.0\n        v/m: double[N] = [1.0, 1.0, 1.0]\n",
    )
    text = text.replace(
        "        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0 and all(J in 1..N: v/mi[J] > 0.0)\n"
    )
    [finding] = findings(text, "EARL-E030")
    assert finding.message == (
        "`v/mi[3]` reads element 3 of a `double[3]`, whose elements are 0 to 2 (in the body of `all(J in …: …)`)"
    )
    assert finding.location is not None
    assert (finding.location.line, finding.location.column) == position_of(text, "all(J in", "[J]")
    # every value of the range out of bounds, inside a quantifier inside another: said once, at its place
    nested = text.replace("all(J in 1..N: v/mi[J] > 0.0)", "any(I in 1..2: all(J in 1..5: v/mi[J] > 0.0))")
    assert [d.message for d in findings(nested, "EARL-E030")] == [
        "`v/mi[3]` reads element 3 of a `double[3]`, whose elements are 0 to 2 (in the body of `all(J in …: …)`)"
    ]
    assert findings(text.replace("v/mi[J]", "v/mi[J - 1]"), "EARL-E030") == []
    # an element read only when a guard on the index lets it (`or` stops at a true operand, `and` at a false
    # one) is never read out of range: each neighbour of a sorted array, the first and the last body alike
    for guarded in (
        "all(J in 0..N - 1: J == N - 1 or v/mi[J] <= v/mi[J + 1])",
        "all(J in 0..N - 1: J == 0 or v/mi[J - 1] <= v/mi[J])",
        "all(J in 0..N - 1: not (J > 0) or v/mi[J - 1] <= v/mi[J])",
        "any(J in 0..N: J < N and v/mi[J] > 0.0)",
    ):
        assert findings(text.replace("all(J in 1..N: v/mi[J] > 0.0)", guarded), "EARL-E030") == [], guarded
    # a guard that lets the read through where it is out of range does not hide it
    wrong = text.replace("all(J in 1..N: v/mi[J] > 0.0)", "all(J in 0..N - 1: J == 1 or v/mi[J - 1] <= v/mi[J])")
    assert [d.message for d in findings(wrong, "EARL-E030")] == [
        "`v/mi[0 - 1]` reads element -1 of a `double[3]`, whose elements are 0 to 2 (in the body of `all(J in …: …)`)"
    ]


def test_a_transition_condition_reading_unwritten_memory_is_reported() -> None:
    text = edit(
        ("        x/m: double = 0.0\n", "        x/m: double = 0.0\n        z/m: double\n"),
        ("        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0\n        zset/pp = z/mi > 0.0\n"),
        ("            run -> run when go/pp\n", "            run -> run when go/pp and zset/pp\n"),
    )
    [finding] = findings(text, "EARL-W041")
    assert finding.message.startswith("the condition of transition `run,run/t` reads `z/mi` (through `zset/pp`)")
    assert findings(edit(("z/m: double\n", "z/m: double = 0.0\n"), text=text), "EARL-W041") == []


def test_a_quantifier_whose_body_is_not_boolean_is_said_once_as_written() -> None:
    text = BASE.replace("system base\n", "system base\n\nparam N: int = 3\n").replace(
        "        go/pp = x/mi > 1.0\n", "        go/pp = x/mi > 1.0\n        odd/pp = any(K in 1..N: K)\n"
    )
    assert [d.message for d in findings(text, "EARL-E030")] == [
        "the body of `any(K in …: …)` must be a boolean, but `K` is a number"
    ]


def test_a_family_of_receptors_off_the_chain_is_said_once_with_its_range() -> None:
    """Every member is off the chain: one finding names them all (`cam[1..2]/rr`), not the first alone."""
    text = add(
        "a4/a {\n    cs {\n        data/ib: double\n    }\n    s/vr {\n        raw/ib: double\n        data/ob: double\n"
        "    }\n    cam[K in 1..2]/rr {\n        raw/ob: double\n    }\n    link s,cs: s/vr.data -> cs.data\n}\n"
    )
    found = findings(text, "EARL-E015")
    assert [d.message for d in found] == ["`a4/a.cam[1..2]/rr` is not on a chain rr → vr → cs"]


def test_a_link_family_named_otherwise_is_said_as_a_family() -> None:
    """`link m[K in 1..2],drive: …` into `d[K]/re`: said once, as the family is written, with the index
    kept in the suggestion (`m[K],d[K]`), not as its first member (`m[1],drive` → `m,d`)."""
    text = add(FAMILY_AGENT.replace("link m[K in 1..2],d[K]:", "link m[K in 1..2],drive:"))
    found = [d.message for d in findings(text, "EARL-W010") if "drive" in d.message]
    assert found == ["link `m[K],drive` is not named after its ends; §2.5 suggests `m[K],d[K]`"]


LINKED_FAMILIES = """\
a4/a {
    cs {
        c/ob: double
    }
    mc[K in 1..2]/ve {
        c/ib: double
    }
    s[K in 1..2]/rr {
        o/ob: double
    }
    v[K in 1..2]/vr {
        i[J in 1..2]/ib: double
    }
    LINK
}
"""


@pytest.mark.parametrize(
    ("declared", "ends", "suggested"),
    [
        ("link foo", "cs.c -> mc[2]/ve.c", "cs,mc[2]"),
        ("link x[K in 1..2]", "s[K]/rr.o -> v[1]/vr.i[K]", "s[K],v[1]"),
    ],
)
def test_the_suggested_link_name_is_the_one_a_link_without_a_name_gets(
    declared: str, ends: str, suggested: str
) -> None:
    """`link foo: cs.c -> mc[2]/ve.c` was told `cs,mc`, and `s[K]/rr -> v[1]/vr` `s[K],v`, while a link declared
    without a name is named `cs,mc[2]` (what `earl fmt` writes): the suggestion is that name."""
    text = add(LINKED_FAMILIES.replace("LINK", f"{declared}: {ends}"))
    [finding] = findings(text, "EARL-W010")
    assert finding.message.endswith(f"§2.5 suggests `{suggested}`")
    if "[K in" not in declared:  # a family is declared in its name: it has no name without one
        unnamed = earl.loads(add(LINKED_FAMILIES.replace("LINK", f"link {ends}")), "spec.earl")
        [agent] = [agent for agent in unnamed.agents if agent.name == "a4"]
        assert agent.links[0].name_text == suggested


def test_a_link_family_named_in_one_word_is_told_a_name_with_its_index() -> None:
    """`link drives[K in 1..2]: … -> d[K]/re.drive`: the suggestion keeps the index on the end that is a family
    member (`m[K],d[K]`), here taken by the family beside it, so the free name carries it too."""
    text = add(FAMILY_AGENT.replace("link m[K in 1..2],d[K]:", "link drives[K in 1..2]:"))
    found = [d.message for d in findings(text, "EARL-W010") if "drives" in d.message]
    assert found == ["link `drives[K]` is not named after its ends; §2.5 suggests `m[K],d[K]`"]
    both = add(
        FAMILY_AGENT.replace("        drive/ib: double\n", "        drive/ib: double\n        gain/ib: double\n")
        .replace("        cmd/ib: double\n", "        cmd/ib: double\n        gain/ob: double\n")
        .replace(
            "    link m[K in 1..2],d[K]: m[K]/ve.drive -> d[K]/re.drive\n",
            "    link m[K in 1..2],d[K]: m[K]/ve.drive -> d[K]/re.drive\n"
            "    link gains[K in 1..2]: m[K]/ve.gain -> d[K]/re.gain\n",
        )
    )
    found = [d.message for d in findings(both, "EARL-W010") if "gains" in d.message]
    assert found == [
        "link `gains[K]` is not named after its ends; §2.5 suggests `m[K],d[K]`, but another link between them has "
        "that name: name it `m[K],dGain[K]`"
    ]


TWO_LINKS = edit(
    ("        out/ob: double\n", "        out/ob: double\n        pose/ob: double\n"),
    ("emit/pf(x/mi -> out/ob)", "emit/pf(x/mi -> out/ob, pose/ob)"),
    ("        inp/ib: double\n", "        inp/ib: double\n        pose/ib: double\n"),
    ("take/pf(inp/ib -> y/mo)", "take/pf(inp/ib, pose/ib -> y/mo)"),
    (
        "link a1,a2: a1/a.cs.out -> a2/a.cs.inp\n",
        "link a1,a2: a1/a.cs.out -> a2/a.cs.inp\nSECOND: a1/a.cs.pose -> a2/a.cs.pose\n",
    ),
)


@pytest.mark.parametrize("second", ["link a1,a22", "link a1,a2Pose"])
def test_two_links_between_the_same_agents_can_both_be_named_after_their_ends(second: str) -> None:
    """`a1,a2` is the first link's (names are unique, EARL-R002): the pair's names with what tells the second
    apart after the destination's name keeps the good practice of §2.5, and the system checks clean."""
    text = TWO_LINKS.replace("SECOND", second).replace("    link a1,a2\n", f"    link a1,a2\n    {second}\n")
    assert findings(text) == []


def test_the_second_link_between_two_agents_is_told_a_name_that_is_free() -> None:
    [finding] = findings(TWO_LINKS.replace("SECOND", "link poses"), "EARL-W010")
    assert finding.message == (
        "link `poses` is not named after its ends; §2.5 suggests `a1,a2`, but another link between them has that "
        "name: name it `a1,a2Pose`"
    )
    assert finding.hint is not None and "EARL-R002" in finding.hint


def test_a_suffix_after_the_destination_is_no_name_for_a_link_alone_between_its_ends() -> None:
    alone = edit(("link a1,a2: a1/a.cs.out", "link a1,a22: a1/a.cs.out"), ("    link a1,a2\n", "    link a1,a22\n"))
    assert [d.message for d in findings(alone, "EARL-W010")] == [
        "link `a1,a22` is not named after its ends; §2.5 suggests `a1,a2`"
    ]


def test_two_links_inside_an_agent_are_named_alike() -> None:
    """Inside an agent the ends are subsystems: `v,cs` and `v,cs2` from one virtual receptor into `cs`."""
    agent = (
        "a4/a {\n    cs {\n        c/ib: double\n        d/ib: double\n    }\n"
        "    v/vr {\n        i/ib: double\n        o/ob: double\n        p/ob: double\n    }\n"
        "    r/rr {\n        o/ob: double\n    }\n"
        "    link r,v: r/rr.o -> v/vr.i\n    link v,cs: v/vr.o -> cs.c\n    link SECOND: v/vr.p -> cs.d\n}\n"
    )
    assert findings(add(agent.replace("SECOND", "v,cs2")), "EARL-W010") == []
    [finding] = findings(add(agent.replace("SECOND", "data")), "EARL-W010")
    assert finding.message.endswith(
        "§2.5 suggests `v,cs`, but another link between them has that name: name it `v,csD`"
    )


def test_a_predicate_s_depth_is_that_of_its_expression_with_each_named_predicate_written_out() -> None:
    """`p = q and x > 0` with `q = x > 1` is `(x > 1) and (x > 0)` written out: 3 levels (the regression
    hunt found the named predicate's level counted twice, refusing chains of 76 that ran before)."""
    from earl.check.rules_behaviour import predicate_depths

    text = edit(
        (
            "        go/pp = x/mi > 1.0\n",
            "        go/pp = x/mi > 1.0\n        p/pp = q/pp and x/mi > 0.0\n        q/pp = x/mi > 1.0\n        r/pp = not p/pp\n",
        ),
    )
    context = context_for(earl.loads(text, "depth.earl"))
    subsystem = next(s for a, s in context.subsystems() if a.name == "a1")
    depths = predicate_depths(subsystem)
    assert (depths["q"], depths["p"], depths["r"], depths["go"]) == (2, 3, 4, 2)


def test_a_list_is_said_twice_as_written_not_once_expanded() -> None:
    """`f/pf(x[K]/ib, x[1]/ib -> …)` in `mc[K in 1..N]/ve` names two buffers; in member 1 they are one, which
    no edit of the declaration can say once: no W047. The same `x[K]/ib` twice is a slip in every member."""
    text = """\
system w47

param N: int = 2

a/a {
    cs {
        period 10 ms
        o[K in 1..N]/ob: double
    }
    mc[K in 1..N]/ve {
        period 10 ms
        x[J in 1..N]/ib: double
        y/m: double = 0.0
        f/pf(x[K]/ib, x[1]/ib -> y/mo)
        g/pf(x[K]/ib, x[K]/ib -> y/mo)
        b/bb {
            tf = {f/pf}
            tc = true
        }
        fsm {
            initial s
            state s: b/bb
        }
    }
    link cs,mc[K in 1..N]: cs.o[K] -> mc[K]/ve.x[1]
}
"""
    assert [d.message for d in findings(text, "EARL-W047")] == ["`g/pf` of a/a.mc[K]/ve reads `x[K]/ib` twice"]


def test_a_family_as_declared_is_named_with_its_index_in_messages() -> None:
    """`worker/a.cs has no fsm`, `agent worker/a has a Virtual Effector …`: a family named without its index
    names no subsystem and no agent; as declared it is `worker[K]/a`."""
    text = (
        "system f\n\nparam N: int = 3\n\nworker[K in 1..N]/a {\n    cs {\n        period 1 ms\n    }\n"
        "    d[J in 1..2]/ve {\n        period 1 ms\n    }\n}\n"
    )
    said = {d.message for d in findings(text) if d.code in ("EARL-E006", "EARL-E008", "EARL-W043")}
    assert said == {
        "agent `worker[K]/a` has a Virtual Effector but no Real Effector",
        "Virtual Effector `worker[K]/a.d[J]/ve` has no Input Buffer",
        "Virtual Effector `worker[K]/a.d[J]/ve` has no Output Buffer",
        "worker[K]/a.cs has no `fsm`: it never runs a behaviour, and `earl run` refuses it",
        "worker[K]/a.d[J]/ve has no `fsm`: it never runs a behaviour, and `earl run` refuses it",
    }


# ---------------------------------------------------------------- hints that lead to no other error


def _hinted(text: str, code: str) -> str:
    [finding] = findings(text, code)
    assert finding.hint is not None
    return finding.hint


def test_e017_suggests_waiting_for_a_buffer_a_link_feeds_and_only_a_period_when_none_is() -> None:
    """The hint named the first input buffer, `idle/ib`, which no link feeds: taken, it made EARL-E016."""
    unpaced = edit(("    cs { period 1 ms\n        inp/ib", "    cs {\n        idle/ib: double\n        inp/ib"))
    hint = _hinted(unpaced, "EARL-E017")
    assert hint.endswith("`state run: run/bb { obligatory inp/ib }`")
    taken = edit(
        (
            "state run: run/bb\n            run -> run when got/pp",
            "state run: run/bb { obligatory inp/ib }\n            run -> run when got/pp",
        ),
        text=unpaced,
    )
    assert [d.code for d in findings(taken) if d.severity is Severity.ERROR] == []
    unlinked = edit(("link a1,a2: a1/a.cs.out -> a2/a.cs.inp\n", ""), ("    link a1,a2\n", ""), text=unpaced)
    hint = _hinted(unlinked, "EARL-E017")
    assert "obligatory" not in hint and hint.startswith("give the subsystem a `period`")


def test_w043_with_no_behaviour_suggests_declaring_one_with_the_fsm() -> None:
    """With no behaviour, the hint's `fsm { initial b  state b: b/bb }` named a `b/bb` nobody declared: EARL-R030."""
    text = add("a3/a {\n    cs {\n        period 1 ms\n    }\n}\n")
    hint = _hinted(text, "EARL-W043")
    snippets = re.findall(r"`([^`]+)`", hint)
    assert len(snippets) == 2
    taken = text.replace(
        "        period 1 ms\n    }", "        period 1 ms\n        " + "\n        ".join(snippets) + "\n    }"
    )
    said = findings(taken)
    assert [d.code for d in said if d.severity is Severity.ERROR] == []
    assert not [d for d in said if d.code == "EARL-W043"]


def test_w044_on_a_buffer_family_suggests_waiting_for_the_family_as_a_group_names_it() -> None:
    """`timeout(rep[J]/ib)` in `any(J …)`: the hint's `obligatory rep/ib` was EARL-R024 (a family needs its index)."""
    text = edit(
        ("        inp/ib: double\n", "        inp/ib: double\n        rep[J in 1..2]/ib: double\n"),
        (
            "        got/pp = newData(inp/ib)\n",
            "        got/pp = newData(inp/ib)\n        lost/pp = any(J in 1..2: timeout(rep[J]/ib))\n",
        ),
        ("tc = got/pp", "tc = got/pp or lost/pp"),
    )
    hint = _hinted(text, "EARL-W044")
    [group] = re.findall(r"\{ (obligatory [^}]+) \}", hint)
    assert group == "obligatory rep[*]/ib timeout 50 ms"
    taken = edit(
        (
            "state run: run/bb\n            run -> run when got/pp",
            f"state run: run/bb {{ {group} }}\n            run -> run when got/pp",
        ),
        text=text,
    )
    said = findings(taken)
    assert not [d for d in said if d.severity is Severity.ERROR or d.code == "EARL-W044"]
