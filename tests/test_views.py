"""What a partial transition function sees (docs/runtime.md): `outputs` taken and checked when the
call returns, read back with `outputs["x"]`, families, names that could collide with the views' own
bookkeeping, and the quick type tests the compiled iteration writes inline (earl/runtime/iteration.py)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.runtime.values import Reals

SPEC = """\
system views

param MODE: int = 0

viewer/a {
    cs {
        period 1 ms

        sent/m: int = 7
        clear/m: int = 0
        level/m: double = 0.5
        joints/m: double[3] = [0.0, 0.0, 0.0]
        current[K in 1..2]/m: double = 0.0
        seen/m: double = 0.0
        faulted/m: boolean = false

        false/pp = false

        write/pf(sent/mi, level/mi, current[*]/mi -> sent/mo, clear/mo, level/mo, joints/mo, current[*]/mo, seen/mo) = python "viewing:write"

        run/bb {
            tf = {write/pf}
            tc = false/pp
        }

        fsm {
            initial run
            state run: run/bb
        }
    }
}

r/r {
    viewer/a
}
"""

CODE = """\
import math

LOG = []


def write(inputs, outputs, context):
    mode = context.parameters["MODE"]
    before = outputs["level"]  # memory's value before the stage: nothing written yet
    outputs.level = before + 1.0
    LOG.append((before, outputs["level"], outputs.level, outputs["sent/mo"]))
    outputs.sent = inputs.sent + 1
    outputs.clear = outputs["clear"] + 2
    outputs.current[2] = 1.5
    outputs.seen = outputs.current[2]
    if mode == 0:
        outputs.joints = [1, 2.5, 3]  # ints where doubles are declared: converted
    elif mode == 1:
        outputs.joints = (0.1, math.nan, 0.3)
    elif mode == 2:
        outputs.joints = [True, 0.0, 0.0]
    elif mode == 3:
        outputs.joints = [0.1, 0.2]
    elif mode == 4:
        outputs.current = [1.0, 2.0]
    elif mode == 5:
        import numpy
        outputs.joints = numpy.array([0.5, 0.25, 0.125])
    elif mode == 6:
        outputs.level = math.nan
    elif mode == 7:
        inputs.sent = 100  # inputs are read-only: the call fails, and writes nothing
    elif mode == 8:
        inputs.current[1] = 2.0  # a member of a family read, likewise
    elif mode == 9:
        outputs["current[1]"] = 3.0  # a member by its name, as `inputs["x[2]"]` reads one
        LOG.append(outputs["current[1]"])
    elif mode == 10:
        list(inputs)  # no collection of names: said so, not as a read of an undeclared `0`
    elif mode == 11:
        len(inputs)
    elif mode == 12:
        "sent" in outputs
    elif mode == 13:
        for _ in outputs:
            pass
    elif mode == 14 and not (inputs and outputs):  # truth is no count: a view is true
        raise AssertionError("a view is false")
"""


def run(tmp_path: Path, mode: int) -> tuple[Any, list[Any]]:
    (tmp_path / "system.earl").write_text(SPEC)
    (tmp_path / "viewing.py").write_text(CODE)
    sim = earl.simulate(earl.load(tmp_path / "system.earl"), parameters={"MODE": mode})
    sim.advance_to(0.0015)
    import viewing  # type: ignore[import-not-found]  # on sys.path once the run bound it

    log = list(viewing.LOG)
    sim.close()
    return sim, log


@pytest.fixture(autouse=True)
def _forget_module() -> Any:
    import sys

    yield
    sys.modules.pop("viewing", None)


def test_writes_are_taken_when_the_call_returns_and_read_back_by_item(tmp_path: Path) -> None:
    sim, log = run(tmp_path, 0)
    assert sim.faults == []
    memory = sim.state_of("viewer/a.cs").memory
    # names a view keeps for itself elsewhere (`sent`, `clear`) are plain names of the spec here
    assert memory["sent"] == 9 and memory["clear"] == 4
    assert memory["level"] == 2.5
    assert memory["joints"] == (1.0, 2.5, 3.0) and all(type(j) is float for j in memory["joints"])
    assert memory["current[1]"] == 0.0 and memory["current[2]"] == 1.5
    assert memory["seen"] == 1.5
    # outputs["level"]: memory's value before anything was written, then what was written
    assert log[0] == (0.5, 1.5, 1.5, 7) and log[1] == (1.5, 2.5, 2.5, 8)


@pytest.mark.parametrize(
    ("mode", "kind", "message"),
    [
        (1, "type", "joints/mo[1] is NaN"),
        (2, "type", "joints/mo[0] must be a number (double), not"),
        (3, "type", "joints/mo must have 3 elements"),
        (4, "undeclared-write", "`current` is a family: write one member"),
        (6, "type", "level/mo is NaN"),
        (7, "undeclared-write", "`write/pf` assigned `inputs.sent`; inputs are read-only"),
        (8, "undeclared-write", "assigned `inputs.current[1]`; inputs are read-only"),
        (
            10,
            "exception",
            "`write/pf` raised TypeError: inputs cannot be iterated, counted or searched (`for`, `len`, `in`); ",
        ),
        (10, "exception", 'read a declared name: `inputs.current` or `inputs["current"]` (it reads: current, level'),
        (11, "exception", "inputs cannot be iterated, counted or searched"),
        (12, "exception", "outputs cannot be iterated, counted or searched"),
        (13, "exception", 'write a declared name: `outputs.sent = …` or `outputs["sent"] = …` (it writes: sent,'),
    ],
)
def test_a_value_the_quick_test_rejects_gets_the_precise_message(
    tmp_path: Path, mode: int, kind: str, message: str
) -> None:
    sim, _ = run(tmp_path, mode)
    assert sim.faults, "the bad write was not refused"
    fault = sim.faults[0]
    assert (fault.kind, fault.function) == (kind, "write")
    assert message in fault.message
    memory = sim.state_of("viewer/a.cs").memory
    # a call that failed wrote nothing, not even what it wrote before the bad value
    assert memory["sent"] == 7 and memory["level"] == 0.5 and memory["joints"] == (0.0, 0.0, 0.0)


def test_a_numpy_array_is_accepted_and_stored_as_reals(tmp_path: Path) -> None:
    sim, _ = run(tmp_path, 5)
    assert sim.faults == []
    joints = sim.state_of("viewer/a.cs").memory["joints"]
    assert joints == (0.5, 0.25, 0.125) and type(joints) is Reals  # a tuple of floats, checked
    assert not any(math.isnan(j) for j in joints)


def test_a_struct_field_reads_as_an_attribute_even_one_named_like_a_dict_method() -> None:
    from earl.model.types import TypeReference
    from earl.runtime.values import TypeSystem

    system = earl.loads(
        "system s\n\nstruct Reading {\n    motorPos: double\n    items: int\n    note: string?\n}\n", "types.earl"
    )
    types = TypeSystem(system)
    reading = types.coercer(TypeReference("Reading"), "reading/ib")({"motorPos": 0.5, "items": 3})
    assert reading.motorPos == 0.5 and reading.note is None
    assert reading["items"] == 3 and reading.items == 3  # the field, not dict's method (`dict.items(reading)`)
    with pytest.raises(AttributeError, match="has no field `speed`"):
        _ = reading.speed
    with pytest.raises(TypeError, match="cannot be changed in place"):
        reading.motorPos = 1.0
    assert reading.replace(motorPos=1.0).motorPos == 1.0
    default = types.default(TypeReference("Reading"))
    assert default.motorPos == 0.0 and type(default) is type(reading)


SHARED_NAMES_SPEC = """\
system shared

twin/a {
    cs {
        period 1 ms

        level/ib: double
        level/ob: double
        level/m: double = 1.0
        seen/m: double = 0.0

        false/pp = false

        both/pf(level/ib, level/mi -> level/mo, level/ob, seen/mo) = python "sharing:both"

        run/bb {
            tf = {both/pf}
            tc = false/pp
        }

        fsm {
            initial run
            state run: run/bb
        }
    }

    echo/ve {
        period 1 ms

        level/ib: double
        level/ob: double

        false/pp = false

        copy/pf(level/ib -> level/ob) = python "sharing:copy"

        run/bb {
            tf = {copy/pf}
            tc = false/pp
        }

        fsm {
            initial run
            state run: run/bb
        }
    }

    link cs,echo: cs.level -> echo/ve.level
    link echo,cs: echo/ve.level -> cs.level
}

r/r {
    twin/a
}
"""

SHARED_NAMES_CODE = """\
def both(inputs, outputs, context):
    # an input buffer, a memory and an output buffer all named `level`: the attribute is the first
    # declared of each direction, the others are reached by their full names
    outputs.level = inputs["level/mi"] + 1.0
    outputs["level/ob"] = inputs["level/mi"] * 10.0
    outputs.seen = inputs["level/ib"]


def copy(inputs, outputs, context):
    outputs.level = inputs.level
"""


def test_a_memory_and_an_output_buffer_of_one_name_are_written_by_attribute_and_by_full_name(
    tmp_path: Path,
) -> None:
    (tmp_path / "system.earl").write_text(SHARED_NAMES_SPEC)
    (tmp_path / "sharing.py").write_text(SHARED_NAMES_CODE)
    # a ve without its re breaks a rule of the manual, not of the runtime: the checker is not the subject here
    sim = earl.simulate(earl.load(tmp_path / "system.earl"), check=False)
    try:
        sim.advance_to(0.0035)
        assert sim.faults == []
        cs = sim.state_of("twin/a.cs")
        # iterations at 0, 1, 2 and 3 ms: memory 1 -> 2 -> 3 -> 4 -> 5; each sends ten times what it read
        assert cs.memory["level"] == 5.0
        # cs's 10 (0 ms) is relayed by the echo at 1 ms, received by cs after its 2 ms iteration, read at 3 ms
        assert cs.memory["seen"] == 10.0
        assert sim.state_of("twin/a.echo/ve").inputs["level"] == 40.0
    finally:
        sim.close()


def test_a_view_is_true_though_it_cannot_be_counted(tmp_path: Path) -> None:
    sim, _ = run(tmp_path, 14)
    assert sim.faults == []


def test_a_member_of_a_family_is_written_and_read_back_by_its_name(tmp_path: Path) -> None:
    sim, log = run(tmp_path, 9)
    assert sim.faults == []
    assert sim.state_of("viewer/a.cs").memory["current[1]"] == 3.0
    assert log[-1] == 3.0


def test_an_output_buffer_read_back_before_it_is_written_is_a_fault_not_none(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(SHARED_NAMES_SPEC)
    (tmp_path / "sharing.py").write_text(
        SHARED_NAMES_CODE.replace("    outputs.level = inputs.level\n", "    outputs.level = outputs['level'] or 1.0\n")
    )
    sim = earl.simulate(earl.load(tmp_path / "system.earl"), check=False)
    try:
        sim.advance_to(0.0005)
        fault = next(f for f in sim.faults if f.subsystem == "twin/a.echo/ve")
        assert fault.kind == "undeclared-read", sim.faults
        assert "reads back the output buffer `level` before writing it" in fault.message
    finally:
        sim.close()
        import sys

        sys.modules.pop("sharing", None)


def test_a_checked_array_of_reals_passes_again_at_once_but_only_at_its_size() -> None:
    """Reals remember that earl checked them: written again they pass with one comparison, yet the
    size is still tested, and a plain tuple, list or NumPy array is checked element by element."""
    from earl.runtime.values import QuickTest

    refused: list[Any] = []

    def slow(value: Any) -> Any:
        refused.append(value)
        return "refused"

    check = QuickTest("real_array", size=3).compile(slow)
    checked = check((1.0, 2.0, 3.0))
    assert type(checked) is Reals and checked == (1.0, 2.0, 3.0)
    assert check(checked) is checked  # the same object, not tested again
    assert type(check([1.0, 2.0, 3.0])) is Reals
    assert check(Reals((1.0, 2.0))) == "refused"  # a checked double[2] is no double[3]
    assert check((1.0, float("nan"), 3.0)) == "refused" and check((1, 2.0, 3.0)) == "refused"
    assert len(refused) == 3


@pytest.mark.parametrize("size", [0, 1, 6, 16, 17, 40])
def test_every_element_of_an_array_of_reals_is_tested_at_every_size(size: int) -> None:
    """Short arrays have their element tests written out one by one, longer ones test them in one
    call (`UNROLLED_ELEMENTS`); both refuse a non-float or a NaN wherever it sits, the last element too."""
    from earl.runtime.values import UNROLLED_ELEMENTS, QuickTest

    assert 6 <= UNROLLED_ELEMENTS < 17  # the sizes above cover both forms
    check = QuickTest("real_array", size=size).compile(lambda value: "refused")
    good = [0.5 * index for index in range(size)]
    assert type(check(good)) is Reals and check(good) == tuple(good)
    assert type(check(tuple(good))) is Reals
    for position in range(size):
        for bad in (1, True, "1.0", None, float("nan")):
            value = list(good)
            value[position] = bad
            assert check(value) == "refused", (position, bad)
    assert check([*good, 1.0]) == "refused"  # one element too many


@pytest.mark.parametrize(
    ("value", "type_name", "message"),
    [
        (300, "uint8", "x/mo = 300 does not fit uint8 (0..255)"),
        (10**400, "int", "x/mo = (a whole number of 401 digits) does not fit int"),
        (10**5000, "int64", "(a whole number of 5001 digits)"),  # beyond what Python will print
        (-(10**300), "uint8", "x/mo = -(a whole number of 301 digits) does not fit uint8"),
        (10**400, "double", "x/mo = (a whole number of 401 digits) is too large for a double"),
        ("y" * 10_000, "int", "not the string 'yyyy"),
        ("/dev/tty\udcff", "string", "x/mo is not text: it holds the lone surrogate U+DCFF at index 8"),
    ],
    ids=["uint8", "int", "int64 beyond printing", "negative uint8", "double", "long string", "lone surrogate"],
)
def test_a_value_of_any_size_is_refused_in_a_short_message(value: Any, type_name: str, message: str) -> None:
    from earl.model.elements import System
    from earl.model.types import PrimitiveType
    from earl.runtime.values import TypeSystem, ValueTypeError

    coerce = TypeSystem(System("s")).coercer(PrimitiveType(type_name), "x/mo")
    with pytest.raises(ValueTypeError) as refused:
        coerce(value)
    assert message in str(refused.value)
    assert len(str(refused.value)) < 200


def test_an_array_of_reals_the_specs_code_makes_from_the_runtimes_own_class_is_checked() -> None:
    """`type(inputs.position)(…)` makes the runtime's class of checked arrays: its elements are checked too,
    so that NaN cannot pass as an array the runtime checked before."""
    from earl.runtime.values import Reals, ValueTypeError

    assert Reals([1, 2.5]) == (1.0, 2.5) and type(Reals([1])[0]) is float
    for wrong in ([1.0, float("nan")], ["a"], [True], [None]):
        with pytest.raises(ValueTypeError):
            Reals(wrong)


def test_a_null_leaf_of_a_trace_is_a_leaf_the_reader_tells_apart_by_the_schema() -> None:
    """JSON writes an infinite real and an absent optional field as null: both are leaves (a gap in a
    plot, not a signal that seems never recorded), and the channel's schema says which one it is. A
    memory family's member is one property (`log[2]`)."""
    from earl.runtime.trace_reader import _is_padding, _null_is_absent
    from earl.runtime.values import iter_leaves

    leaves = list(iter_leaves({"position": [1.0, None], "stop": False, "note": "text"}))
    assert leaves == [("position[0]", 1.0), ("position[1]", None), ("stop", False), ("note", "text")]
    reals = {"type": "array", "items": {"type": "number"}}
    schema = {
        "type": "object",
        "properties": {
            "position": reals,
            "log[2]": {"type": "number"},
            "spare": {"anyOf": [{"type": "number"}, {"type": "null"}]},
            "pose": {"anyOf": [{"type": "object", "properties": {"x": {"type": "number"}}}, {"type": "null"}]},
        },
    }
    assert not _null_is_absent(schema, "position[1]") and not _null_is_absent(schema, "log[2]")
    assert not _null_is_absent(schema, "pose.x")
    assert _null_is_absent(schema, "spare") and _null_is_absent(schema, "pose") and _null_is_absent(None, "x")
    # as earl writes them now, for Foxglove: an optional field is its type, left out of `required`, and a
    # memory family an array whose elements before its first member are null (`prefixItems`)
    pose = {"type": "object", "properties": {"x": {"type": "number"}}, "required": ["x"]}
    family = {"type": "array", "items": {"type": "number"}, "prefixItems": [{"type": "null"}]}
    schema = {
        "type": "object",
        "properties": {"spare": {"type": "number"}, "pose": pose, "log": family, "gain": {"type": "number"}},
        "required": ["log", "gain"],
    }
    assert _null_is_absent(schema, "spare") and _null_is_absent(schema, "pose")
    assert not _null_is_absent(schema, "pose.x") and not _null_is_absent(schema, "log[2]")
    assert not _null_is_absent(schema, "gain")
    assert _is_padding(schema, "log[0]") and not _is_padding(schema, "log[1]") and not _is_padding(schema, "gain")


def test_an_output_buffer_read_as_an_attribute_before_it_is_written_is_told_to_keep_a_variable(
    tmp_path: Path,
) -> None:
    """`outputs.level` read before it is written: for an output buffer, `outputs["level"]` would be a
    fault too, so the advice is a variable, not that."""
    (tmp_path / "system.earl").write_text(SHARED_NAMES_SPEC)
    (tmp_path / "sharing.py").write_text(
        SHARED_NAMES_CODE.replace("    outputs.level = inputs.level\n", "    outputs.level = outputs.level or 1.0\n")
    )
    sim = earl.simulate(earl.load(tmp_path / "system.earl"), check=False)
    try:
        sim.advance_to(0.0005)
        fault = next(f for f in sim.faults if f.subsystem == "twin/a.echo/ve")
        assert "read `outputs.level` before writing it; an output buffer holds nothing" in fault.message
        assert 'outputs["level"]' not in fault.message
    finally:
        sim.close()
        import sys

        sys.modules.pop("sharing", None)


FLOAT32_MAX = 3.4028234663852886e38


def test_a_float32_holds_what_single_precision_holds_in_every_form_of_value() -> None:
    """Values are kept at double precision, but a finite value beyond float32's range is refused, as an
    integer out of range is: scalars, struct fields and arrays (short and long, and a double[] array the
    runtime checked before), through the quick tests and the full check alike; an infinity passes."""
    from earl.model.expressions import Literal
    from earl.model.types import ArrayType, PrimitiveType, TypeReference
    from earl.runtime.values import TypeSystem, ValueTypeError

    system = earl.loads("system s\nstruct Pose {\n    x: float32\n    y: double\n}\n")
    types = TypeSystem(system)
    scalar = types.coercer(PrimitiveType("float32"), "x/mo")
    pose = types.coercer(TypeReference("Pose"), "p/mo")
    short = types.coercer(ArrayType(PrimitiveType("float32"), Literal(3)), "a/mo")
    long = types.coercer(ArrayType(PrimitiveType("float32"), Literal(20)), "b/mo")
    doubles = types.coercer(ArrayType(PrimitiveType("double"), Literal(3)), "d/mo")
    big = FLOAT32_MAX * 2
    assert scalar(FLOAT32_MAX) == FLOAT32_MAX and scalar(-1.5) == -1.5 and scalar(3) == 3.0
    assert scalar(math.inf) == math.inf and pose({"x": -math.inf, "y": 1e300})["x"] == -math.inf
    # FLT_MAX as printed rounds to FLT_MAX: a float32, though a hair above the double FLT_MAX is
    assert scalar(3.4028235e38) == 3.4028235e38 and short([3.4028235e38] * 3) == (3.4028235e38,) * 3
    assert short([1.0, math.inf, -FLOAT32_MAX]) == (1.0, math.inf, -FLOAT32_MAX)
    refusals = [
        (scalar, big, "x/mo = 6.805646932770577e+38 does not fit float32 (at most ±3.4028235e+38"),
        (scalar, -(10**39), "does not fit float32"),
        (pose, {"x": big, "y": 0.0}, "p/mo.x = 6.805646932770577e+38 does not fit float32"),
        (short, [0.0, 0.0, big], "a/mo[2] = 6.805646932770577e+38 does not fit float32"),
        (long, [0.0] * 19 + [-big], "does not fit float32"),
        (short, doubles([1.0, big, 0.0]), "a/mo[1] = 6.805646932770577e+38 does not fit float32"),
    ]
    for coerce, value, message in refusals:
        with pytest.raises(ValueTypeError) as refused:
            coerce(value)
        assert message in str(refused.value)
    assert doubles([big, 0.0, 0.0]) == (big, 0.0, 0.0)  # a double holds it


def test_a_float32_initial_value_or_parameter_beyond_its_range_is_refused_by_the_checker() -> None:
    text = "system s\nr/a {\n    cs {\n        period 1 ms\n        x/m: float32 = 1e300\n        y/m: float32 = -3e38\n    }\n}\n"
    found = [(d.code, d.location.line if d.location else 0) for d in earl.check.check(earl.loads(text))]
    assert ("EARL-E043", 5) in found and ("EARL-E043", 6) not in found, found
    assert earl.loads("system s\nparam F: float32 = 3.4028235e38\n").parameters[0].name == "F"
    with pytest.raises(earl.EarlError) as huge:
        earl.loads("system s\nparam H: double = 1" + "0" * 400 + "\n")
    assert "is too large for a double" in str(huge.value)
    with pytest.raises(earl.EarlError) as refused:
        earl.loads("system s\nparam G: float32 = 1e39\n")
    assert "parameter `G` is `float32` but its value 1e+39 does not fit it (at most ±3.4028235e+38" in str(
        refused.value
    )
