"""Slips a newcomer makes, each told by what it is rather than by a guess at a missing bracket.

The cases come from a hunt through a conveyor-sorter spec changed one line at a time: `=`
written for `==`, `initial idle/bb`, a comma after a state's behaviour. The parser stops inside
a block that is still open however the file goes on, so "is a `}` missing?" is only said when
the file really holds more `{` than `}`.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import earl
from earl.diagnostics import Diagnostic, EarlError

_HEAD = "system s\n\nr/r {\n    a/a\n}\n\na/a {\n    cs {\n        period 1 ms\n"
_TAIL = "    }\n}\n"
_BEHAVIOUR = "        b/bb {\n            tf = {}\n            tc = true\n        }\n"


def _spec(body: str) -> str:
    """A spec whose `a/a.cs` holds `t/m`, `b/bb` and `body` (the body's first line is line 15)."""
    return _HEAD + "        t/m: int = 0\n" + _BEHAVIOUR + body + _TAIL


def _error(text: str) -> Diagnostic:
    with pytest.raises(EarlError) as caught:
        earl.loads(text, "spec.earl")
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.location is not None
    return diagnostic


def _where(diagnostic: Diagnostic) -> tuple[int, int]:
    assert diagnostic.location is not None
    return diagnostic.location.line, diagnostic.location.column


@pytest.mark.parametrize(
    ("body", "meant"),
    [
        ("        x/pp = t/mi > 1 and t/mi = 3\n", "x/pp = t/mi > 1 and t/mi == 3"),
        (
            "        fsm {\n            initial idle\n            state idle: b/bb\n"
            "            idle -> idle when t/mi = 0\n        }\n",
            "idle -> idle when t/mi == 0",
        ),
        (
            "        c/bb {\n            tf = {}\n            tc = t/mi = 1\n        }\n",
            "tc = t/mi == 1",
        ),
    ],
    ids=["predicate", "transition", "terminal condition"],
)
def test_an_equals_sign_where_a_comparison_is_meant_is_told_to_be_doubled(body: str, meant: str) -> None:
    diagnostic = _error(_spec(body))
    assert diagnostic.code == "EARL-S006"
    assert diagnostic.hint == f"to compare, write `==`: `{meant}`"
    assert "missing" not in diagnostic.message


def test_a_missing_closing_brace_is_still_pointed_at() -> None:
    """A `{` the file never closes: named with its line, at the end of the file or where it stops."""
    text = _HEAD + "        b/bb {\n            tf = {}\n            tc = true\n" + _TAIL
    diagnostic = _error(text + "\n")
    assert diagnostic.message == "the file ends before the `{` on line 7 is closed"
    unclosed = _HEAD + "        b/bb {\n            tf = {}\n            tc = true\n        fsm {\n" + _TAIL
    diagnostic = _error(unclosed)
    assert diagnostic.hint == "is a `}` missing? the `{` on line 10, column 14 is still open"


@pytest.mark.parametrize(
    "body",
    ["        x/pp = t/mi > 1 )\n", "        stage s = {b/bb} {b/bb}\n"],
    ids=["a stray bracket", "a second set"],
)
def test_a_brace_hint_is_not_given_when_the_braces_are_balanced(body: str) -> None:
    """Both said "is a `}` missing? the `{` on line 8 is still open": the `{` of `cs`, closed two lines on."""
    diagnostic = _error(_spec(body))
    assert diagnostic.code == "EARL-S006"
    assert "missing" not in (diagnostic.hint or "")


def test_initial_names_a_state_not_its_behaviour() -> None:
    diagnostic = _error(_spec("        fsm {\n            initial idle/bb\n            state idle: b/bb\n        }\n"))
    assert _where(diagnostic) == (16, 25)
    assert diagnostic.hint == "`initial` names a state, not its behaviour: write `initial idle`"


def test_a_comma_after_a_states_behaviour_shows_how_a_state_is_written() -> None:
    body = (
        "        fsm {\n            initial idle\n            state idle: b/bb, optional { optional x/ib }\n        }\n"
    )
    diagnostic = _error(_spec(body))
    assert _where(diagnostic) == (17, 29)
    assert diagnostic.hint == (
        "a state has one behaviour, and its buffers follow it in braces, with no comma: "
        "`state idle: b/bb { obligatory a/ib  optional b/ib  timeout 20 ms }`"
    )


@pytest.mark.parametrize(
    ("group", "meant", "column"),
    [
        (
            "{ obligatory x/ib, optional y/ib, timeout 20 ms }",
            "{ obligatory x/ib  optional y/ib  timeout 20 ms }",
            49,
        ),
        ("{ optional x/ib, y/ib, timeout 20 ms }", "{ optional x/ib, y/ib  timeout 20 ms }", 53),
    ],
    ids=["optional after a comma", "timeout after a comma"],
)
def test_commas_between_the_parts_of_a_buffer_group_are_shown_away(group: str, meant: str, column: int) -> None:
    buffers = "        x/ib: double\n        y/ib: double\n"
    body = buffers + f"        fsm {{\n            initial idle\n            state idle: b/bb {group}\n        }}\n"
    diagnostic = _error(_spec(body))
    assert diagnostic.code == "EARL-S007"
    assert _where(diagnostic) == (19, column)
    assert diagnostic.hint == (
        f"the parts of a buffer group are separated by spaces or new lines, not commas: `{meant}`"
    )


def test_the_sorter_slips_from_the_command_line(tmp_path: Path) -> None:
    """The real command on a spec of several blocks: one located sentence and the hint, exit 1."""
    spec = tmp_path / "slip.earl"
    spec.write_text(_spec("        x/pp = t/mi = 3\n"))
    done = subprocess.run(
        [sys.executable, "-m", "earl", "check", str(spec)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 1
    assert "slip.earl:15:21" in done.stderr + done.stdout
    assert "= hint: to compare, write `==`: `x/pp = t/mi == 3`" in done.stderr + done.stdout
    assert "missing" not in done.stderr + done.stdout


@pytest.mark.parametrize(
    ("declaration", "column", "hint"),
    [
        ("param H: double = N/2.0", 20, "multiply instead: write `N * 0.5` for `N / 2.0`"),
        ("param H: double = 0.3 * N / 4", 27, "multiply instead: write `N * 0.25` for `N / 4`"),
        ("param H: double = (N + 1) / 2", 27, "multiply instead: write `(N + 1) * 0.5` for `(N + 1) / 2`"),
        (
            "param H: double = N / M",
            21,
            "EARL cannot compute `1 / M`: give it as a parameter of its own (`param INV_M: double = …`, then "
            "`N * INV_M`), or compute it in the Python code that uses it",
        ),
        (
            "param H: double = 1.0 / M",
            23,
            "EARL cannot compute `1 / M`: give it as a parameter of its own (`param INV_M: double = …`, then "
            "`INV_M`), or compute it in the Python code that uses it",
        ),
        ("param H: double = N / (M)", 21, "multiply instead, e.g. `N * 0.5` for `N / 2`"),
        (
            "param H: int = N / 2",
            18,
            "`H` is an `int` and `N * 0.5` is a `double`, even when whole: give `H` its own value and compute "
            "`N` from it (`param H: int = …`, then `param N: int = 2 * H`), or declare `H` a `double` and "
            "write `N * 0.5`",
        ),
        (
            "type V = double[N / 2]",
            19,
            "an array size is a whole number and `N * 0.5` is a `double`, even when whole: there is no whole "
            "division, so declare the smaller number as a parameter and compute the larger from it "
            "(`param HALF: int = 3`, then `param N: int = 2 * HALF`)",
        ),
    ],
    ids=["double", "product", "parenthesised", "by a name", "an inverse", "by a group", "int", "array size"],
)
def test_a_division_is_told_there_is_none_and_how_to_write_it(declaration: str, column: int, hint: str) -> None:
    """`N / 2` was "`2` is not a kind of element" (the slash read as a kind's), `(N + 1) / 2` a division."""
    diagnostic = _error(f"system s\nparam N: int = 6\nparam M: int = 3\n{declaration}\n")
    assert diagnostic.code == "EARL-S006"
    assert _where(diagnostic) == (4, column)
    assert diagnostic.message.startswith("there is no division: the `/` after `")
    assert diagnostic.hint == hint


def test_the_advice_for_an_int_parameter_is_one_that_checks(tmp_path: Path) -> None:
    """`0.5 * N` for an `int` is EARL-R005; what the hint proposes instead is accepted."""
    spec = tmp_path / "half.earl"
    spec.write_text("system s\nparam H: int = 3\nparam N: int = 2 * H\n")
    assert [p.name for p in earl.load(spec).parameters] == ["H", "N"]
    spec.write_text("system s\nparam N: int = 6\nparam H: int = N * 0.5\n")
    with pytest.raises(EarlError) as caught:
        earl.load(spec)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "EARL-R005"
    assert diagnostic.hint == (
        "a `double` stays a `double` even when it is whole (and there is no whole division): give `H` its own "
        "value (`param H: int = 3`) and compute the others from it by multiplying, or declare `H` a `double`"
    )


def test_a_kind_in_capitals_is_no_division() -> None:
    """`v/IB` after an element's name is its kind in the wrong case; `N / M` after a parameter a division."""
    diagnostic = _error(_spec("        v/ib: double\n        x/pp = v/IB > 3.0\n"))
    assert diagnostic.code == "EARL-S005"
    assert diagnostic.hint == "kinds are written in lowercase: `v/ib`"


@pytest.mark.parametrize("divisor", ["0", "M", "(2)"])
def test_an_int_divided_by_no_number_is_told_without_a_product(divisor: str) -> None:
    """`N / 0` raised inside the message's making (an unbound name); by a name or a group there is no
    product to show."""
    diagnostic = _error(f"system s\nparam N: int = 6\nparam M: int = 3\nparam H: int = N / {divisor}\n")
    assert diagnostic.code == "EARL-S006"
    assert diagnostic.hint == (
        "`H` is an `int` and a product with a `double` is a `double`, even when whole: give `H` its own value "
        "(`param H: int = …`) and compute the others from it by multiplying, or declare `H` a `double`"
    )


@pytest.mark.parametrize(
    ("body", "hint"),
    [
        (
            "        fsm {\n            initial idle\n            state idle: b { optional t/mi }\n        }\n",
            "a state names its behaviour with its kind: `state idle: b/bb`",
        ),
        (
            "        c/bb {\n            tf = {}, {}\n            tc = true\n        }\n",
            "the stages of a `tf` follow one another with `then`: `tf = {} then {}`; "
            "the functions of one stage share its braces: `{a/pf, b/pf}`",
        ),
        (
            "        fsm {\n            initial idle\n            state idle: b/bb\n"
            "            idle -> idle priority 2 when t/mi > 3\n        }\n",
            "`when CONDITION` comes before `priority`: `idle -> idle when t/mi > 3 priority 2`",
        ),
    ],
    ids=["a state's behaviour without its kind", "stages apart with a comma", "priority before when"],
)
def test_more_slips_are_told_how_they_are_written(body: str, hint: str) -> None:
    """Each had the generic hint, or none (`state s: b {` said only "expected `/` or `[` after `b`")."""
    assert _error(_spec(body)).hint == hint


def test_a_struct_field_with_a_default_value_is_told_there_is_none() -> None:
    diagnostic = _error("system s\n\nstruct Push {\n    abort: boolean = false\n}\n")
    assert _where(diagnostic) == (4, 20)
    assert diagnostic.hint == (
        "a struct's fields have no default value: a memory of the struct gets its first value in the first stage "
        "of the initial state's behaviour"
    )


def test_a_whole_real_written_for_an_int_parameter_is_told_to_drop_the_point() -> None:
    with pytest.raises(EarlError) as caught:
        earl.loads("system s\nparam H: int = 3.0\n", "s.earl")
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "EARL-R005"
    assert diagnostic.hint == "write `3`: an integer type holds whole numbers, written without a decimal point"
