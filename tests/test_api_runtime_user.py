"""What a user of the Python API meets at run time: user code named from a notebook or a saved script,
values read from a run, and what errors say (docs/python-api.md)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.diagnostics import EarlError, did_you_mean

ROOT = Path(__file__).resolve().parents[1]

SPEC = """\
system c
c/a {
    cs {
        period 10 ms
        count/m: int = 0
        never/pp = false
        increment/pf(count/mi -> count/mo) = python "IMPLEMENTATION"
        go/bb {
            tf = {increment/pf}
            tc = never/pp
        }
        fsm {
            initial go
            state go: go/bb
        }
    }
}
r/r {
    c/a
}
"""


def spec(implementation: str) -> str:
    return SPEC.replace("IMPLEMENTATION", implementation)


def environment() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}


def refusal(implementation: str) -> earl.Diagnostic:
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.loads(spec(implementation)))
    [diagnostic] = raised.value.diagnostics
    return diagnostic


# ---------------------------------------------------------------- naming user code


def test_a_function_missing_from_main_in_python_c_is_x004_saying_to_define_it_in_the_session() -> None:
    """`python -c` (as the REPL and a notebook's kernel) has a `__main__` without `__file__`: the hint
    said where to define the function by that file, and failed with an AttributeError instead."""
    code = f"import earl\ntry:\n    earl.simulate(earl.loads({spec('__main__:advance')!r}))\n"
    code += "except earl.EarlError as e:\n    print(e.diagnostics[0].code, e.diagnostics[0].hint)\n"
    done = subprocess.run(
        [sys.executable, "-c", code], env=environment(), capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(
        "EARL-X004 `__main__` is this interactive session (a notebook, the REPL, `python -c`)"
    )
    assert "define `def advance(inputs, outputs, context) -> None` in it" in done.stdout


def test_a_function_missing_from_a_namespace_package_says_it_can_define_none(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "nspkg_for_test").mkdir()  # no __init__.py: a namespace package, whose __file__ is None
    monkeypatch.syspath_prepend(str(tmp_path))
    diagnostic = refusal("nspkg_for_test:advance")
    assert diagnostic.code == "EARL-X004"
    assert diagnostic.hint is not None and "in `None`" not in diagnostic.hint
    assert diagnostic.hint.startswith("`nspkg_for_test` is a directory without `__init__.py`")
    assert 'python "nspkg_for_test.MODULE:FUNCTION"' in diagnostic.hint


def test_a_function_named_with_the_wrong_case_gets_a_did_you_mean(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "casecode_for_test.py").write_text("def plan(inputs, outputs, context):\n    pass\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    diagnostic = refusal("casecode_for_test:PLAN")
    assert (diagnostic.code, diagnostic.hint) == ("EARL-X004", "did you mean `plan`?")
    assert did_you_mean("Idle", ["idle", "IDLE", "other"]) == "did you mean `IDLE`?"  # sorted: the first alike


def test_a_model_naming_main_saved_warns_and_its_run_by_earl_says_where_the_functions_went(tmp_path: Path) -> None:
    """The docs' own example names `__main__:increment`; saved and run with `earl run`, `__main__` is earl's
    program, and the hint said to define the function in earl's own `__main__.py`."""
    system = earl.loads(spec("__main__:increment"))
    target = tmp_path / "system.earl"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        earl.save(system, target)
    [warning] = caught
    assert warning.filename == __file__  # at the line that saved, not inside earl
    assert "names functions of `__main__` (`increment`), which exist only while the script" in str(warning.message)
    assert target.read_text(encoding="utf-8") == system.to_earl()  # written all the same
    done = subprocess.run(
        [sys.executable, "-m", "earl", "run", str(target), "--duration", "0.05"],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode != 0
    assert "error[EARL-X004]: `increment/pf` of c/a.cs names `__main__:increment`, but `__main__` is the program" in (
        done.stderr
    )
    assert (
        'hint: move `increment` into a module beside the spec (e.g. `functions.py`) and name it `python "functions:'
        in (done.stderr)
    )
    assert "earl/__main__.py" not in done.stderr
    # a name that earl's own `__main__` has (`script`, the command itself) is never bound to it
    target.write_text(spec("__main__:script"), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "earl", "run", str(target), "--duration", "0.05"],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert "error[EARL-X004]: `increment/pf` of c/a.cs names `__main__:script`, but `__main__` is the program" in (
        done.stderr
    )


def test_earl_fmt_rewrites_a_spec_naming_main_without_a_warning(tmp_path: Path) -> None:
    target = tmp_path / "system.earl"
    target.write_text(spec("__main__:increment").replace("    period", "  period"), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-W", "error", "-m", "earl", "fmt", "--write", str(target)],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr and "    period 10 ms" in target.read_text(encoding="utf-8")


# ---------------------------------------------------------------- values read from a run

RECORDS = """\
system records
struct Reading {
    values: double[2]
    items: int
    keys: int
    get: int
    copy: int
    update: boolean
    replace: int
    count: int
}
a/a {
    cs {
        period 10 ms
        reading/m: Reading
        total/m: double = 0.0
        never/pp = false
        produce/pf( -> reading/mo) = python "recordcode_for_test:produce"
        consume/pf(reading/mi -> total/mo) = python "recordcode_for_test:consume"
        go/bb {
            tf = {produce/pf, consume/pf}
            tc = never/pp
        }
        fsm {
            initial go
            state go: go/bb
        }
    }
}
r/r {
    a/a
}
"""

RECORD_CODE = """\
def produce(inputs, outputs, context):
    outputs.reading = {"values": [1.0, 2.0], "items": 3, "keys": 4, "get": 5, "copy": 6, "update": True,
                       "replace": 7, "count": 8}


def consume(inputs, outputs, context):
    r = inputs.reading
    outputs.total = sum(r.values) + r.items + r.keys + r.get + r.copy + r.replace + r.count + r.update
"""


def test_struct_fields_named_like_dict_methods_are_read_as_the_fields_and_traced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`msg.values` was dict's method, so `sum(msg.values)` was a fault; the trace (JSON in this process
    for a BytesIO, msgpack to the writer's process for a file) packs a field named `items` too."""
    import io

    from earl.runtime import Record
    from earl.runtime.trace_reader import _messages

    (tmp_path / "recordcode_for_test.py").write_text(RECORD_CODE)
    monkeypatch.syspath_prepend(str(tmp_path))
    memory_trace = io.BytesIO()
    for trace in (tmp_path / "run.mcap", memory_trace):
        with earl.simulate(earl.loads(RECORDS), trace=trace, record_memory=["all"]) as simulation:
            simulation.advance_to(0.05)
            assert simulation.faults == []
            state = simulation.state_of("a/a.cs")
        reading = state.memory["reading"]
        assert state.memory["total"] == 1.0 + 2.0 + 3 + 4 + 5 + 6 + 7 + 8 + 1
        assert (reading.values, reading.items, reading.update, reading.replace) == ((1.0, 2.0), 3, True, 7)
        assert dict.items(reading) == {**reading}.items() and "items=3" in repr(reading)
        assert Record.replace(reading, items=9).items == 9
    memory_trace.seek(0)
    path = tmp_path / "from_memory.mcap"
    path.write_bytes(memory_trace.getvalue())
    for written in (tmp_path / "run.mcap", path):
        memories = [value for topic, _, _, value in _messages(written) if topic == "/a/a.cs/memory"]
        assert memories and memories[-1]["reading"]["items"] == 3


def test_a_struct_with_a_field_named_items_crosses_a_link_between_processes() -> None:
    from earl.model.types import TypeReference
    from earl.runtime.values import TypeSystem
    from earl.transport.codec import LinkCodec

    system = earl.loads(RECORDS)
    types = TypeSystem(system)
    codec = LinkCodec(types, TypeReference("Reading"), "reading")
    sent = types.coerce(
        {"values": [1.0, 2.0], "items": 3, "keys": 4, "get": 5, "copy": 6, "update": True, "replace": 7, "count": 8},
        TypeReference("Reading"),
    )
    received = codec.decode(codec.encode(sent))
    assert received == sent and received.items == 3


def test_values_read_from_a_run_copy_deepcopy_and_pickle_to_equal_values(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import copy
    import pickle

    (tmp_path / "recordcode_for_test.py").write_text(RECORD_CODE)
    monkeypatch.syspath_prepend(str(tmp_path))
    with earl.simulate(earl.loads(RECORDS)) as simulation:
        simulation.advance_to(0.03)
        state = simulation.state_of("a/a.cs")
    reading = state.memory["reading"]
    assert copy.copy(reading) == reading and copy.deepcopy(reading) == reading
    assert copy.deepcopy(state) == state and copy.deepcopy(state.memory) == state.memory
    assert type(copy.deepcopy(reading)) is type(reading)
    again = pickle.loads(pickle.dumps(state))
    assert again == state and again.memory["reading"].values == (1.0, 2.0)
    assert type(again.memory["reading"]).__name__ == "Reading"
    # unpickled in another process, where no run made the struct's class
    code = "import pickle, sys; r = pickle.loads(sys.stdin.buffer.read()); print(r.items, r.values, r)"
    done = subprocess.run(
        [sys.executable, "-c", code],
        input=pickle.dumps(reading),
        env=environment(),
        capture_output=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.decode().startswith("3 (1.0, 2.0) Reading(values=(1.0, 2.0), items=3")


# ---------------------------------------------------------------- what errors say


def test_an_uncaught_earl_error_and_a_diagnostic_say_their_code_and_hint() -> None:
    """An overflow policy `'drop'` never said which policies are valid: the hint was left out of str()."""
    system = earl.loads(spec("nowhere:f"))
    system.agents[0].subsystems[0].input_buffers.append(
        earl.InputBuffer("inp", earl.PrimitiveType("int"), queue=earl.Queue(earl.Literal(3), "drop"))
    )
    hint = "  = hint: a FIFO's overflow policy is one of dropOldest, dropNewest, fault"
    [diagnostic] = [d for d in earl.check.check(system) if d.severity is earl.Severity.ERROR]
    assert str(diagnostic).splitlines() == [
        "error[EARL-R018]: `inp/ib` has the overflow policy 'drop' (in `c/a.cs`)",
        hint,
    ]
    with pytest.raises(EarlError) as raised:
        earl.simulate(system)
    assert str(raised.value).splitlines() == [str(diagnostic).splitlines()[0], hint]
    with pytest.raises(EarlError) as raised:
        earl.loads("system s\nx/a {\n}\nx/a {\n}\n", "two.earl")
    assert str(raised.value).startswith("two.earl:4:1: error[EARL-R002]: ")


# ---------------------------------------------------------------- check=False


UNCHECKED = """\
system c
c/a {
    cs {
        period 10 ms
        count/m: int = 0
        done/pp = count/mi >= 3
        never/pp = false
        increment/pf(count/mi -> count/mo) = python "unchecked_code_for_test:increment"
        counting/bb {
            tf = {increment/pf}
            tc = done/pp
        }
        resting/bb {
            tf = {}
            tc = never/pp
        }
        fsm {
            initial counting
            state counting: counting/bb
            state finished: resting/bb
            counting -> finished when done/pp
        }
    }
}
r/r {
    c/a
}
"""


def _cs(system: earl.System) -> earl.ControlSubsystem:
    subsystem = system.agents[0].subsystems[0]
    assert isinstance(subsystem, earl.ControlSubsystem)
    return subsystem


def _fsm(system: earl.System) -> earl.FSM:
    fsm = _cs(system).fsm
    assert fsm is not None
    return fsm


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda s: setattr(_fsm(s), "initial", "nowhere"), "its FSM starts in the state `nowhere`"),
        (
            lambda s: setattr(_fsm(s).states[1], "behaviour", "nosuch"),
            "state `finished` runs the behaviour `nosuch/bb`",
        ),
        (
            lambda s: setattr(_fsm(s).transitions[0], "destination", "nosuch"),
            "a transition of its FSM names the state `nosuch`",
        ),
        (
            lambda s: setattr(
                _cs(s).partial_transition_functions[0],
                "reads",
                [earl.ElementReference("nosuch", earl.Kind.MEMORY_INPUT)],
            ),
            "`increment/pf` reads `nosuch/mi`",
        ),
        (
            lambda s: setattr(
                _cs(s).basic_behaviours[0],
                "terminal_condition",
                earl.Predicate(earl.Read(earl.ElementReference("nosuch", earl.Kind.PRIMITIVE_PREDICATE))),
            ),
            "the `tc` of `counting/bb` reads `nosuch/pp`",
        ),
        (
            lambda s: (
                _cs(s)
                .basic_behaviours[1]
                .transition_function.stages.append(
                    [earl.ElementReference("missing", earl.Kind.PARTIAL_TRANSITION_FUNCTION)]
                )
            ),
            "`resting/bb` calls `missing/pf`",
        ),
    ],
)
def test_a_run_without_the_checker_refuses_an_undeclared_name_before_it_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, edit: Any, message: str
) -> None:
    """It was a KeyError from inside the run (engine.py, generated code), a fault at every iteration, or
    for an initial state that is no state, a run doing nothing without a word."""
    (tmp_path / "unchecked_code_for_test.py").write_text(
        "def increment(inputs, outputs, context):\n    outputs.count = inputs.count + 1\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    system = earl.loads(UNCHECKED)
    with earl.simulate(system, check=False) as simulation:  # as loaded, it runs
        simulation.advance_to(0.1)
        assert simulation.state_of("c/a.cs").state == "finished"
    edit(system)
    with pytest.raises(EarlError) as raised:
        earl.simulate(system, check=False)
    [diagnostic] = raised.value.diagnostics
    assert diagnostic.code == "EARL-X015"
    assert diagnostic.message == f"c/a.cs cannot run: {message}, which it does not declare"


def test_a_value_of_the_wrong_type_run_without_the_checker_is_named_at_its_path() -> None:
    from earl.model.validate import ModelTypeError

    system = earl.loads(UNCHECKED)
    _cs(system).memories[0].data_type = "int"  # type: ignore[assignment]
    with pytest.raises(ModelTypeError, match=r"^system\.agents\[0\]\.subsystems\[0\]\.memories\[0\]\.data_type: "):
        earl.simulate(system, check=False)


# ---------------------------------------------------------------- earl.save


def test_save_to_a_directory_writes_its_system_earl_as_load_reads_it(tmp_path: Path) -> None:
    system = earl.loads(UNCHECKED)
    earl.save(system, tmp_path)
    assert (tmp_path / "system.earl").read_text(encoding="utf-8") == system.to_earl()
    assert earl.load(tmp_path) == earl.load(tmp_path / "system.earl")


def test_save_says_which_path_it_cannot_write_not_a_temporary_file(tmp_path: Path) -> None:
    """A missing directory named the temporary file `.earl-xxxx.tmp`; `""` said `[Errno 22]` without a path."""
    system = earl.loads(UNCHECKED)
    missing = tmp_path / "nope" / "system.earl"
    with pytest.raises(FileNotFoundError) as raised:
        earl.save(system, missing)
    assert raised.value.filename == str(missing) and ".tmp" not in str(raised.value)
    assert f"the directory `{missing.parent}` does not exist" in str(raised.value)
    with pytest.raises(ValueError, match="save takes a file name, not an empty string"):
        earl.save(system, "")
    with pytest.raises(OSError) as device:
        earl.save(system, "/dev/null")
    assert device.value.filename == "/dev/null" and "not a regular file" in str(device.value)
    (tmp_path / "locked").mkdir(mode=0o500)
    if os.geteuid() != 0:  # root writes anywhere
        with pytest.raises(PermissionError) as refused:
            earl.save(system, tmp_path / "locked" / "x.earl")
        assert refused.value.filename == str(tmp_path / "locked" / "x.earl")
        assert f"cannot write in the directory `{tmp_path / 'locked'}`" in str(refused.value)


def test_a_traced_run_closes_the_pipes_to_its_writer(tmp_path: Path) -> None:
    """Under `python -X dev`, every traced run left the writer's standard error open: a ResourceWarning."""
    code = textwrap.dedent(
        f"""
        import gc, earl
        for _ in range(3):
            with earl.simulate(earl.loads({UNCHECKED.replace("unchecked_code_for_test:", "code:")!r}),
                               trace={str(tmp_path / "run.mcap")!r}) as simulation:
                simulation.advance_to(0.05)
            gc.collect()
        del simulation
        gc.collect()
        print("done")
        """
    )
    (tmp_path / "code.py").write_text(
        "def increment(inputs, outputs, context):\n    outputs.count = inputs.count + 1\n"
    )
    done = subprocess.run(
        [sys.executable, "-X", "dev", "-c", code],
        cwd=tmp_path,
        env={**environment(), "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(tmp_path)])},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0 and done.stdout == "done\n", done.stderr
    assert "ResourceWarning" not in done.stderr, done.stderr


def test_a_should_stop_that_raises_leaves_a_run_that_goes_on(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`should_stop` is asked between instants; its exception marked the run "stopped inside an instant",
    refusing every later advance."""
    (tmp_path / "unchecked_code_for_test.py").write_text(
        "def increment(inputs, outputs, context):\n    outputs.count = inputs.count + 1\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    asked: list[float] = []

    def should_stop() -> bool:
        asked.append(simulation.time)
        if len(asked) == 2:
            raise ZeroDivisionError("division by zero")
        return False

    with earl.simulate(earl.loads(UNCHECKED), check=False) as simulation:
        with pytest.raises(ZeroDivisionError) as raised:
            simulation.advance_to(0.1, should_stop=should_stop)
        assert raised.value.__traceback__ is not None and "_StopQuestionFailed" not in repr(raised.value)
        stopped_at = simulation.time
        assert stopped_at < 0.1
        simulation.advance_to(0.1)
        assert simulation.time == pytest.approx(0.1)
        assert simulation.state_of("c/a.cs").state == "finished"
        assert simulation.state_of("c/a.cs").memory == {"count": 3}


# ---------------------------------------------------------------- reading a trace, writing the document


def test_the_page_s_example_of_reading_a_trace_and_writing_the_document_runs_and_prints_what_it_says(
    tmp_path: Path,
) -> None:
    import re
    import shutil

    page = (ROOT / "docs" / "python-api.md").read_text(encoding="utf-8")
    section = page.split("## Reading a trace, writing the document", 1)[1].split("\n## ", 1)[0]
    [code] = re.findall(r"^```python\n(.*?)^```", section, re.DOTALL | re.MULTILINE)
    shutil.copytree(ROOT / "tests" / "runtime_specs" / "counter", tmp_path / "tests" / "runtime_specs" / "counter")
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, env=environment(), capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    promised = [line.split("  # ", 1)[1].split(" (", 1)[0] for line in code.splitlines() if "print(" in line]
    assert done.stdout.splitlines() == promised
    assert "*Generated by earl " in (tmp_path / "counter-doc" / "index.md").read_text(encoding="utf-8")
    assert list((tmp_path / "counter-doc" / "diagrams").glob("*.svg"))


def test_a_trace_is_read_from_a_path_or_a_stream_and_what_cannot_be_read_is_said(tmp_path: Path) -> None:
    import io

    system = earl.load(ROOT / "tests" / "runtime_specs" / "counter")
    with earl.simulate(system, seed=1, trace=tmp_path / "run.mcap") as simulation:
        simulation.advance_to(0.05)
    on_disk = earl.read_trace(str(tmp_path / "run.mcap")).summary()
    data = (tmp_path / "run.mcap").read_bytes()
    stream = io.BytesIO(data)
    stream.seek(5)  # read whole, whatever its position
    with earl.read_trace(stream) as trace:
        assert trace.summary() == on_disk
        copy = trace.path
        assert copy.is_file()
        with pytest.raises(earl.TraceError, match=r"has no values for `counter/a\.cs\.nosuch`"):
            trace.signals(["counter/a.cs.nosuch"])
        with pytest.raises(TypeError, match="not a single string"):
            trace.signals("counter/a.cs.count")  # type: ignore[arg-type]
        with pytest.raises(ValueError, match="malformed"):
            trace.signals(["counter/a.cs.count[x"])
    assert not copy.exists()  # the copy of a stream is removed
    with open(tmp_path / "run.mcap", "rb") as opened:  # a file object: named by its name in messages
        assert earl.read_trace(opened).summary() == on_disk
    with pytest.raises(earl.TraceError) as raised:
        earl.read_trace(io.BytesIO(b"not a trace")).summary()
    assert str(raised.value).startswith("the trace stream is not a readable MCAP trace")
    with pytest.raises(TypeError, match="binary file object"):
        earl.read_trace(io.StringIO("x")).summary()
    with pytest.raises(FileNotFoundError, match="no such trace file"):  # as open says it, at once
        earl.read_trace(tmp_path / "missing.mcap")


def test_write_doc_writes_the_site_into_a_directory_named_by_a_str(tmp_path: Path) -> None:
    """`write_site` failed with a str path; there was no way to write the `earl doc` site from Python."""
    from earl.render.build import Subject
    from earl.render.document import NotOurs, write_site

    system = earl.load(ROOT / "tests" / "runtime_specs" / "counter")
    result = earl.write_doc(system, str(tmp_path / "site"))
    assert result.html == tmp_path / "site" / "index.html" and result.html.is_file()
    assert all(path.is_file() for path in result.diagrams) and result.diagrams
    again = write_site(Subject(system), [], str(tmp_path / "other"))  # the lower level takes a str too
    assert again.markdown.is_file()
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "index.html").write_text("<p>my own page</p>")
    with pytest.raises(NotOurs):
        earl.write_doc(system, tmp_path / "mine")
    (tmp_path / "file").write_text("")
    with pytest.raises(NotADirectoryError):
        earl.write_doc(system, tmp_path / "file")
    with pytest.raises(TypeError, match="write_doc documents a System"):
        earl.write_doc("system.earl", tmp_path)  # type: ignore[arg-type]


def test_a_struct_with_a_field_named_items_goes_to_json_through_plain(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """json.dumps calls a mapping's items() by name, which the field hides; earl.runtime.plain gives the value
    as plain dicts and lists all the way down, which json takes."""
    import json

    from earl.runtime import plain

    (tmp_path / "recordcode_for_test.py").write_text(RECORD_CODE)
    monkeypatch.syspath_prepend(str(tmp_path))
    with earl.simulate(earl.loads(RECORDS)) as simulation:
        simulation.advance_to(0.02)
        reading = simulation.state_of("a/a.cs").memory["reading"]
    with pytest.raises(TypeError):
        json.dumps(reading)  # the reason plain exists: `items` is the field, 3
    as_data = json.loads(json.dumps(plain(reading)))
    assert as_data == {
        "values": [1.0, 2.0],
        "items": 3,
        "keys": 4,
        "get": 5,
        "copy": 6,
        "update": True,
        "replace": 7,
        "count": 8,
    }
    assert type(plain(reading)) is dict and type(plain(reading)["values"]) is list


ABSENT_UNDER_GET = """\
system absent
struct Inner {
    x: double
}
struct Bag {
    get: boolean
    inner: Inner?
}
a/a {
    cs {
        period 10 ms
        bag/m: Bag
        big/pp = bag/mi.inner.x > 5.0
        go/bb {
            tf = {}
            tc = big/pp
        }
        fsm {
            initial go
            state go: go/bb
        }
    }
}
r/r {
    a/a
}
"""


def test_a_fault_through_an_absent_field_is_said_so_in_a_struct_with_a_field_named_get() -> None:
    """The message finder called the Record's get, which a field named `get` hides: the fault fell back to
    Python's "'NoneType' object is not subscriptable"."""
    with earl.simulate(earl.loads(ABSENT_UNDER_GET), check=False) as simulation:
        simulation.advance_to(0.0)
        messages = [fault.message for fault in simulation.faults]
    assert messages and "`bag/mi.inner` was absent" in messages[0], messages


def test_read_trace_of_a_directory_or_of_no_file_is_said_at_once(tmp_path: Path) -> None:
    with pytest.raises(IsADirectoryError, match="a directory, not a trace"):
        earl.read_trace(tmp_path)
    with pytest.raises(FileNotFoundError, match="no such trace file"):
        earl.read_trace(tmp_path / "run.mcap")
