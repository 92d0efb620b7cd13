"""Primitive predicates computed by Python: `big/pp(x/mi) = python "module:function"`.

The spec below is also tests/runtime_specs/thresholds/system.earl, so the other readers' tests
(SysML export, the document) read it too.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import earl
from earl.check import check
from earl.diagnostics import EarlError, Severity

SPEC = """\
system thresholds

param LIMIT: int = 3

counter/a {
    cs {
        period 1 ms

        x/m: int = 0

        // computed by Python from the memory it declares
        big/pp(x/mi) = python "limits:big"
        false/pp = false

        increment/pf(x/mi -> x/mo) = python "limits:increment"

        count/bb {
            tf = {increment/pf}
            tc = big/pp
        }

        done/bb {
            tf = {}
            tc = false/pp
        }

        fsm {
            initial count
            state count: count/bb
            state done: done/bb

            count -> done when big/pp
        }
    }
}

r/r {
    counter/a
}
"""

CODE = """\
def big(inputs, context):
    return inputs.x >= context.parameters["LIMIT"]


def increment(inputs, outputs, context):
    outputs.x = inputs.x + 1
"""


def test_the_spec_file_is_this_spec() -> None:
    folder = Path(__file__).parent / "runtime_specs" / "thresholds"
    assert (folder / "system.earl").read_text() == SPEC
    assert (folder / "limits.py").read_text() == CODE


def write(tmp_path: Path, code: str = CODE) -> Path:
    spec = tmp_path / "system.earl"
    spec.write_text(SPEC)
    (tmp_path / "limits.py").write_text(code)
    return spec


def test_a_python_primitive_predicate_reads_back_and_is_canonical(tmp_path: Path) -> None:
    system = earl.load(write(tmp_path))
    predicate = system.agent("counter").control_subsystem.primitive_predicate("big")  # type: ignore[union-attr]
    assert predicate is not None and predicate.implementation is not None
    assert predicate.implementation.path == "limits:big"
    assert [r.name for r in predicate.reads] == ["x"]
    assert system.to_earl() == SPEC
    assert earl.loads(system.to_earl(), str(tmp_path / "system.earl")) == system


def test_the_checker_treats_it_as_a_condition_it_cannot_see_into_and_never_imports_it(tmp_path: Path) -> None:
    spec = write(tmp_path, "raise SystemExit('imported')\n")
    errors = [d for d in check(earl.load(spec)) if d.severity is Severity.ERROR]
    assert errors == []


def test_the_runtime_calls_it_with_its_declared_reads(tmp_path: Path) -> None:
    sim = earl.simulate(earl.load(write(tmp_path)))
    sim.advance_to(0.0015)
    assert sim.state_of("counter/a.cs").state == "count"
    sim.advance_to(0.0025)
    # x reached LIMIT (3) in the third iteration, at 2 ms: big/pp held and the FSM moved on
    assert sim.state_of("counter/a.cs").state == "done"
    assert sim.state_of("counter/a.cs").memory["x"] == 3
    assert sim.faults == []


def test_a_predicate_whose_code_is_missing_is_reported_at_its_line(tmp_path: Path) -> None:
    spec = write(tmp_path, CODE.replace("def big(", "def large("))
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.load(spec))
    [diagnostic] = raised.value.diagnostics
    assert diagnostic.code == "EARL-X004"
    assert "`big/pp`" in diagnostic.message
    assert diagnostic.location is not None and diagnostic.location.line == 12
    assert "def big(inputs, context) -> bool" in (diagnostic.hint or "")


def test_a_predicate_that_raises_is_a_fault_and_counts_as_false(tmp_path: Path) -> None:
    spec = write(tmp_path, CODE.replace("return inputs.x >=", "return inputs.y >="))
    sim = earl.simulate(earl.load(spec))
    sim.advance_to(0.005)
    assert sim.state_of("counter/a.cs").state == "count"
    assert sim.faults and sim.faults[0].kind == "predicate"
    assert "does not declare that it reads `y`" in sim.faults[0].message


def test_a_predicate_is_asked_once_per_decision_however_many_conditions_name_it(tmp_path: Path) -> None:
    """`big/pp` is the terminal condition and the transition's condition: one call per iteration, and a
    predicate with state (a debounce, a random draw) decides as it answered."""
    code = CODE.replace(
        'def big(inputs, context):\n    return inputs.x >= context.parameters["LIMIT"]\n',
        "CALLS = []\n\n\ndef big(inputs, context):\n    CALLS.append(context.time)\n"
        "    return len(CALLS) == 3  # true once, on its third call\n",
    )
    sim = earl.simulate(earl.load(write(tmp_path, code)))
    try:
        sim.advance_to(0.0045)
        import limits  # type: ignore[import-not-found]

        assert limits.CALLS == [0.0, 0.001, 0.002]  # each iteration once; after the third, state `done`
        assert sim.state_of("counter/a.cs").state == "done"
    finally:
        sim.close()
        sys.modules.pop("limits", None)


def test_a_predicate_that_raises_is_one_fault_per_decision(tmp_path: Path) -> None:
    spec = write(tmp_path, CODE.replace("return inputs.x >=", "return inputs.y >="))
    sim = earl.simulate(earl.load(spec))
    try:
        sim.advance_to(0.0005)  # one iteration
        assert [f.kind for f in sim.faults] == ["predicate"]
    finally:
        sim.close()


def test_a_predicate_that_raises_in_the_error_and_the_terminal_condition_is_one_fault(tmp_path: Path) -> None:
    """The error condition asks it first and records the fault; the terminal condition, in the same decision,
    finds it failed and counts it false without a second fault."""
    spec = write(tmp_path, CODE.replace("return inputs.x >=", "return inputs.y >="))
    text = spec.read_text()
    spec.write_text(
        text.replace("            tc = big/pp\n", "            tc = big/pp\n            ec = big/pp and false/pp\n", 1)
    )
    sim = earl.simulate(earl.load(spec))
    try:
        sim.advance_to(0.0025)  # three iterations, three decisions
        assert [f.kind for f in sim.faults] == ["predicate"] * 3
        assert all("error condition" in f.message for f in sim.faults)
        assert sim.state_of("counter/a.cs").state == "count"
    finally:
        sim.close()


def test_the_document_and_the_sysml_export_name_its_code(tmp_path: Path) -> None:
    """Table 4 and the SysML constraint say which code computes the predicate; the export calls the
    library's opaque `EARL::python` (which exists), with the predicate's reads as arguments."""
    from earl.cli.main import main

    spec = write(tmp_path)
    sys.modules.pop("limits", None)  # imported by the runs above
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 0
    assert '`python "limits:big"(`[`x/mi`]' in (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    assert main(["export", "sysml", str(spec), "-o", str(tmp_path / "thresholds.sysml")]) == 0
    exported = (tmp_path / "thresholds.sysml").read_text(encoding="utf-8")
    constraint = exported[exported.index("constraint <'big/pp'>") :]
    constraint = constraint[: constraint.index("}")]
    assert 'Computed by python "limits:big".' in constraint
    assert "EARL::python(" in constraint
    assert "calc def python {" in (tmp_path / "EARL.sysml").read_text(encoding="utf-8")
    assert "limits" not in sys.modules


@pytest.mark.parametrize(
    ("result", "said"),
    [
        ('"no"', "returned a str ('no')"),
        ('float("nan")', "returned a float (nan)"),
        ("None", "returned None"),
        ("1", "returned an int (1)"),
    ],
)
def test_a_predicate_that_returns_no_boolean_is_a_fault_and_the_condition_counts_as_false(
    tmp_path: Path, result: str, said: str
) -> None:
    """`return "no"` or NaN would be true and None false if taken by truthiness, silently."""
    code = CODE.replace('return inputs.x >= context.parameters["LIMIT"]', f"return {result}")
    sim = earl.simulate(earl.load(write(tmp_path, code)))
    try:
        sim.advance_to(0.0025)  # three iterations, three decisions
        assert sim.state_of("counter/a.cs").state == "count"
        assert [f.kind for f in sim.faults] == ["predicate"] * 3  # once per decision, not per condition
        assert sim.faults[0].message == (
            f"evaluating the terminal condition of `count/bb`: `big/pp` {said}, not a Boolean, so the condition "
            "counts as false (a predicate computed by Python returns True or False)"
        )
    finally:
        sim.close()
        sys.modules.pop("limits", None)


@pytest.mark.parametrize("numpy_boolean", ["numpy.bool_", "numpy.array"])
def test_a_predicate_may_return_a_numpy_boolean(tmp_path: Path, numpy_boolean: str) -> None:
    """NumPy's Boolean, alone or as an array of no dimension (what `numpy.all(…)` of a 0-d array gives)."""
    code = "import numpy\n\n" + CODE.replace(
        'return inputs.x >= context.parameters["LIMIT"]',
        f'return {numpy_boolean}(inputs.x >= context.parameters["LIMIT"])',
    )
    sim = earl.simulate(earl.load(write(tmp_path, code)))
    try:
        sim.advance_to(0.0025)
        assert sim.state_of("counter/a.cs").state == "done"
        assert sim.faults == []
    finally:
        sim.close()
        sys.modules.pop("limits", None)


def test_a_predicate_that_raises_inside_another_is_named_and_its_traceback_kept(tmp_path: Path) -> None:
    """`either/pp = false/pp or big/pp`: the exception of big's code is big's, not the compiled predicate's
    that asked for it, and the fault keeps the traceback of the code, as a partial transition function's does."""
    spec = write(tmp_path, CODE.replace('return inputs.x >= context.parameters["LIMIT"]', "return 1 / 0"))
    text = spec.read_text().replace(
        "        false/pp = false\n", "        false/pp = false\n        either/pp = false/pp or big/pp\n"
    )
    spec.write_text(text.replace("tc = big/pp", "tc = either/pp"))
    sim = earl.simulate(earl.load(spec))
    try:
        sim.advance_to(0.0005)  # one iteration
        [fault] = sim.faults
        assert fault.message == (
            "evaluating the terminal condition of `count/bb` raised ZeroDivisionError: division by zero in `big/pp`"
        )
        assert fault.traceback.startswith("Traceback (most recent call last):\n")
        assert "limits.py" in fault.traceback and "return 1 / 0" in fault.traceback
        assert fault.traceback.endswith("ZeroDivisionError: division by zero\n")
        assert "earl/runtime" not in fault.traceback
    finally:
        sim.close()
        sys.modules.pop("limits", None)


FAMILY_SPEC = """\
system tally

param N: int = 3

counter/a {
    cs {
        period 1 ms

        x[K in 1..N]/m: int = K
        step/m: int = 0

        // every member of the family, as a function's reads take it
        full/pp(x[*]/mi, step/mi) = python "tallies:full"

        increment/pf(step/mi -> step/mo) = python "tallies:increment"

        count/bb {
            tf = {increment/pf}
            tc = full/pp
        }

        fsm {
            initial count
            state count: count/bb

            count -> count when full/pp
        }
    }
}

r/r {
    counter/a
}
"""

FAMILY_CODE = """\
SEEN = []


def full(inputs, context):
    SEEN.append((inputs.x.indices(), list(inputs.x), inputs.x[2]))
    return sum(inputs.x) + inputs.step >= 8


def increment(inputs, outputs, context):
    outputs.step = inputs.step + 1
"""


def test_a_python_predicate_reads_every_member_of_a_family(tmp_path: Path) -> None:
    """`full/pp(x[*]/mi, …)` was EARL-R026 ("`[*]` … cannot be a value in an expression"); its reads are a
    list, as a function's: checked, written back, expanded to every member and given to the code as one."""
    from earl.model.expand import expand
    from earl.model.expressions import Read
    from earl.model.text import reference_text

    spec = tmp_path / "system.earl"
    spec.write_text(FAMILY_SPEC)
    (tmp_path / "tallies.py").write_text(FAMILY_CODE)
    system = earl.load(spec)
    assert [d for d in check(system) if d.severity is Severity.ERROR] == []
    assert system.to_earl() == FAMILY_SPEC
    expanded = expand(system).agent("counter").control_subsystem.primitive_predicate("full")  # type: ignore[union-attr]
    assert expanded is not None
    members = ["x[1]/mi", "x[2]/mi", "x[3]/mi", "step/mi"]
    assert [reference_text(r) for r in expanded.reads] == members
    arguments = expanded.expression.arguments  # type: ignore[attr-defined]
    assert [reference_text(a.target) for a in arguments if isinstance(a, Read)] == members
    sys.modules.pop("tallies", None)
    sim = earl.simulate(system)
    try:
        sim.advance_to(0.0025)
        import tallies  # type: ignore[import-not-found]

        # the family by its indices, iterated in their order, and one member by its index
        assert tallies.SEEN[0] == ([1, 2, 3], [1, 2, 3], 2)
        assert len(tallies.SEEN) == 3  # once per iteration: 0, 1 and 2 ms
        assert sim.state_of("counter/a.cs").memory["step"] == 3
        assert sim.faults == []
    finally:
        sim.close()
        sys.modules.pop("tallies", None)


def test_a_python_predicates_family_read_without_an_index_is_told_to_write_star() -> None:
    with pytest.raises(EarlError) as refused:
        earl.loads(FAMILY_SPEC.replace("full/pp(x[*]/mi", "full/pp(x/mi"), "tally.earl")
    (problem,) = refused.value.diagnostics
    assert problem.code == "EARL-R024"
    assert problem.hint == "write `x[1]/mi`, or `x[*]/mi` for every member"


def _with_big(tmp_path: Path, predicate: earl.PrimitivePredicate) -> earl.System:
    system = earl.load(write(tmp_path))
    subsystem = system.agent("counter").control_subsystem  # type: ignore[union-attr]
    assert subsystem is not None
    subsystem.primitive_predicates[0] = predicate
    return system


X_READ = earl.ElementReference("x", earl.Kind.MEMORY_INPUT)


@pytest.mark.parametrize(
    "predicate",
    [
        # the code is set but the expression is an ordinary one: the check read `false`, the run the code
        earl.PrimitivePredicate(
            "big", earl.Literal(False), reads=[X_READ], implementation=earl.PythonImplementation("limits:big")
        ),
        # `python()` without the reads it declares: the reload has `python(x/mi)`
        earl.PrimitivePredicate(
            "big", earl.Call("python", ()), reads=[X_READ], implementation=earl.PythonImplementation("limits:big")
        ),
        # reads said in the expression only: the text writes `big/pp()`
        earl.PrimitivePredicate(
            "big", earl.Call("python", (earl.Read(X_READ),)), implementation=earl.PythonImplementation("limits:big")
        ),
    ],
)
def test_a_predicate_built_in_python_whose_code_expression_and_reads_disagree_is_r048(
    tmp_path: Path, predicate: earl.PrimitivePredicate
) -> None:
    system = _with_big(tmp_path, predicate)
    errors = [d for d in check(system) if d.severity is Severity.ERROR]
    assert [d.code for d in errors] == ["EARL-R048"]
    assert "`big/pp` of `counter/a.cs` is computed by Python" in errors[0].message
    assert "PrimitivePredicate.python('big', reads, 'limits:big')" in (errors[0].hint or "")
    with pytest.raises(EarlError):
        earl.simulate(system)


def test_a_predicate_built_with_primitive_predicate_python_is_the_one_read_from_text(tmp_path: Path) -> None:
    built = earl.PrimitivePredicate.python("big", [X_READ], "limits:big")
    system = _with_big(tmp_path, built)
    assert system == earl.load(tmp_path / "system.earl")
    assert [d for d in check(system) if d.severity is Severity.ERROR] == []
    assert earl.loads(system.to_earl()) == system
