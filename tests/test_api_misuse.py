"""The Python API refuses what the language cannot say, and arguments of the wrong kind, in plain words.

A model built in Python never meets the grammar: an operator EARL does not have (`xor`, `=>`, `/`),
an overflow policy it does not know, must be refused by the resolver as the reader refuses their
text, not crash the checker or go into the run's generated code."""

from __future__ import annotations

import dataclasses
import functools
import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import earl
from earl import (
    Arithmetic,
    BooleanOperation,
    Comparison,
    ElementReference,
    Family,
    InputBuffer,
    Kind,
    LinkNamePart,
    Literal,
    Name,
    Predicate,
    PrimitiveType,
    Quantifier,
    Queue,
    Read,
)
from earl.check import check
from earl.diagnostics import EarlError
from earl.model.location import Comments

TEXT = """\
system demo
a/a {
    cs {
        period 10 ms
        x/m: double = 0.0
        never/pp = false
        idle/bb {
            tf = {}
            tc = never/pp
        }
        fsm {
            initial run
            state run: idle/bb
            state other: idle/bb
            run -> other when never/pp
        }
    }
}
r/r {
    a/a
}
"""

X = Read(ElementReference("x", Kind.MEMORY_INPUT))
NEVER = Read(ElementReference("never", Kind.PRIMITIVE_PREDICATE))


@pytest.mark.parametrize(
    ("condition", "message", "hint"),
    [
        (
            Comparison("=>", X, Literal(3.0)),
            "`=>` is no comparison operator of EARL (in the condition of transition `run,other/t` of `a/a.cs`)",
            "did you mean `>`?",
        ),
        (BooleanOperation("xor", (NEVER, Literal(True))), "`xor` is no Boolean operator of EARL", "did you mean `or`?"),
        (
            Comparison(">", Arithmetic("/", X, Literal(2.0)), Literal(1.0)),
            "`/` is no arithmetic operator of EARL",
            "EARL has `+`, `-`, `*`",
        ),
        (Quantifier("some", "K", Literal(1), Literal(2), NEVER), "`some` is no quantifier of EARL", None),
        # to_earl wrote the operand alone, which read back as no operation
        (BooleanOperation("and", (NEVER,)), "`and` over 1 operand; it takes two or more", None),
        (BooleanOperation("or", ()), "`or` over 0 operands; it takes two or more", None),
    ],
)
def test_an_operator_the_language_does_not_have_is_r047(condition: Any, message: str, hint: str | None) -> None:
    system = earl.loads(TEXT)
    assert system.agents[0].subsystems[0].fsm is not None
    system.agents[0].subsystems[0].fsm.transitions[0].condition = Predicate(condition)
    [diagnostic] = check(system)
    assert diagnostic.code == "EARL-R047" and diagnostic.message.startswith(message)
    if hint is not None:
        assert diagnostic.hint == hint
    with pytest.raises(EarlError) as raised:
        earl.simulate(system)
    assert raised.value.diagnostics[0].code == "EARL-R047"


def test_an_unchecked_run_refuses_an_unknown_operator_instead_of_generating_code_with_it() -> None:
    system = earl.loads(TEXT)
    assert system.agents[0].subsystems[0].fsm is not None
    system.agents[0].subsystems[0].fsm.transitions[0].condition = Predicate(BooleanOperation("xor", (NEVER, NEVER)))
    with pytest.raises(EarlError, match="`xor` is no Boolean operator of EARL"):
        earl.simulate(system, check=False)


def test_an_unknown_overflow_policy_is_r018() -> None:
    system = earl.loads(TEXT)
    subsystem = system.agents[0].subsystems[0]
    subsystem.input_buffers.append(InputBuffer("inp", PrimitiveType("double"), queue=Queue(Literal(3), "dropAll")))
    [diagnostic] = [d for d in check(system) if d.code == "EARL-R018"]
    assert diagnostic.message == "`inp/ib` has the overflow policy 'dropAll' (in `a/a.cs`)"


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: earl.loads(TEXT, {"N": 3}), "the second argument of loads is the name messages give the text"),
        (lambda: earl.loads(TEXT.encode()), "decode the bytes first"),
        (lambda: earl.loads(None), "loads takes the text of a specification (a str), not NoneType"),
        (lambda: earl.loads("system x", path=5), "loads names the text by a str or a Path, not int 5"),
        (lambda: earl.loads(TEXT, parameters={3: 4}), "a parameter is named by a str"),
        (lambda: earl.load("x.earl", "N=3"), "parameters takes a mapping of parameter names to values"),
        (lambda: earl.load(5), "load takes a file name (a str or a Path), not int 5"),
        (lambda: earl.save("x", "x.earl"), "save writes a System, as earl.load(path) returns it, not str"),
        (lambda: check("x"), "check takes a System, as earl.load(path) returns it, not str"),  # type: ignore[arg-type]
        (lambda: earl.simulate(earl.loads(TEXT), parameters={3: 4}), "a parameter is named by a str"),
    ],
)
def test_arguments_of_the_wrong_kind_are_a_type_error_that_says_what_is_taken(
    call: Callable[[], object], message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError) as raised:
        call()
    assert message in str(raised.value)
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize(
    ("name", "hint"),
    [
        ("my arm", "e.g. `my_arm`"),
        ("a1/a", "write the name without its kind: `a1`"),
        ("", "a name is a letter or `_`, then letters, digits and `_`"),
        ("1a", "e.g. `_1a`"),
        ("système", "e.g. `syst_me`"),
    ],
)
def test_a_name_the_language_could_not_read_back_is_r006(name: str, hint: str) -> None:
    """`to_earl()` wrote such names as they are, and the text did not load; the run went ahead."""
    system = earl.loads(TEXT)
    system.agents[0].name = name
    system.robots[0].agents[0] = ElementReference(name, Kind.AGENT)
    [diagnostic] = [d for d in check(system) if d.code == "EARL-R006"]
    assert diagnostic.message == f"{name!r} is no EARL name (an agent)"
    assert diagnostic.hint is not None and hint in diagnostic.hint
    with pytest.raises(EarlError):
        earl.simulate(system)


def test_every_kind_of_declared_name_is_checked() -> None:
    system = earl.loads(TEXT)
    subsystem = system.agents[0].subsystems[0]
    subsystem.memories[0].name = "x y"
    assert subsystem.fsm is not None
    subsystem.fsm.states[1].name = "other state"
    system.name = "my system"
    said = [d.message for d in check(system) if d.code == "EARL-R006"]
    assert said == [
        "'my system' is no EARL name (the system)",
        "'x y' is no EARL name (a memory of a/a.cs)",
        "'other state' is no EARL name (a state of the FSM of a/a.cs)",
    ]


@pytest.mark.parametrize(
    ("options", "error", "message"),
    [
        ({"check": "no"}, TypeError, "check takes True or False, not str 'no'"),
        ({"check": None}, TypeError, "check takes True or False, not NoneType None"),
        ({"realtime": "yes"}, TypeError, "realtime takes True or False, not str 'yes'"),
        ({"trace": "missing/run.mcap"}, FileNotFoundError, "the directory `missing` does not exist"),
        ({"record_outputs": ["zz/a.cs.out"]}, ValueError, "record_outputs: `zz/a.cs.out` is no output buffer"),
        (  # it was iterated by character: "`a` is no output buffer"
            {"record_outputs": "a/a.cs.out"},
            TypeError,
            "record_outputs takes a list of names, e.g. ['a/a.cs.out'], not a single string",
        ),
    ],
)
def test_simulation_options_of_the_wrong_kind_are_refused_before_the_run(
    options: dict[str, Any], error: type[Exception], message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(error) as raised:
        earl.simulate(earl.loads(TEXT), environment=None, **options)
    assert message in str(raised.value)


def test_a_link_pattern_matching_nothing_is_a_warning_and_an_unknown_subsystem_a_plain_key_error() -> None:
    from earl.runtime import RecordingWarning, UnknownSubsystem

    with pytest.warns(RecordingWarning, match="record_links: `nomatch\\*` matches no link"):
        simulation = earl.simulate(earl.loads(TEXT), environment=None, record_links=["nomatch*"])
    with simulation, pytest.raises(UnknownSubsystem) as raised:
        simulation.state_of("a/a.c")
    assert isinstance(raised.value, KeyError)
    assert str(raised.value) == "no subsystem `a/a.c` in this run. did you mean `a/a.cs`?"


def test_a_finding_in_an_element_built_in_python_says_which_declaration_it_is_about() -> None:
    """Such elements have no location: `a FIFO holds at least one message, not 0` did not say whose, and then
    said only the subsystem, not which of its declarations."""
    from earl import ArrayType, Memory

    system = earl.loads(TEXT)
    subsystem = system.agents[0].subsystems[0]
    subsystem.input_buffers.append(InputBuffer("inp", PrimitiveType("double"), queue=Queue(Literal(0))))
    subsystem.memories.append(Memory("y", PrimitiveType("real")))
    subsystem.memories.append(Memory("z", ArrayType(PrimitiveType("double"), Literal(-1))))
    said = {(d.code, d.message, d.hint) for d in check(system)}
    assert said == {
        (
            "EARL-R012",
            "unknown primitive type `real` (in `y/m` of `a/a.cs`)",
            "the primitive types: boolean, int8, int16, int32, int64, uint8, uint16, uint32, uint64, int, float32, "
            "float64, double, string, bytes; a struct or alias is a `TypeReference`",
        ),
        ("EARL-R013", "an array size must not be negative, here it is -1 (in `z/m` of `a/a.cs`)", None),
        ("EARL-R018", "a FIFO holds at least one message, not 0 (in `inp/ib` of `a/a.cs`)", None),
    }


FAMILY = """\
system fam
w[I in 1..2]/a {
    cs {
        period 10 ms
        out[J in 1..2]/ob: double
        go/pp = true
        run/bb {
            tf = {}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}
boss/a {
    cs {
        period 10 ms
        in[I in 1..2]/ib: double
        go/pp = true
        run/bb {
            tf = {}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}
link w[I in 1..2],boss: w[I]/a.cs.out[1] -> boss/a.cs.in[I]
r/r {
    w[1]/a
    w[2]/a
    boss/a
}
"""


def test_what_the_checks_of_arguments_still_take(tmp_path: Path) -> None:
    """Values the checks above must not refuse: a Path naming text, NumPy's Booleans and 0/1 for flags,
    a member of an output-buffer family in record_outputs."""
    import numpy

    path = tmp_path / "demo.earl"
    path.write_text(TEXT)
    with pytest.raises(EarlError) as raised:
        earl.loads("system 1", path)
    assert raised.value.diagnostics[0].location is not None
    assert raised.value.diagnostics[0].location.file == str(path)
    for flag in (numpy.bool_(False), 0):
        earl.simulate(earl.loads(TEXT), environment=None, realtime=flag, check=numpy.bool_(True)).close()
    with earl.simulate(
        earl.loads(FAMILY), environment=None, trace=tmp_path / "t.mcap", record_outputs=["w[1]/a.cs.out[1]"]
    ) as simulation:
        assert simulation.trace is not None and simulation.trace.links_also_recorded


@pytest.mark.parametrize(
    ("signal", "outputs"),
    [
        ("w[1]/a.cs.out[1]", ["w[1]/a.cs.out[1]"]),
        ("w[2]/a.cs.out[*]", ["w[2]/a.cs.out[1]", "w[2]/a.cs.out[2]"]),
    ],
)
def test_a_plotted_member_of_an_output_family_is_recorded_by_its_member_name(signal: str, outputs: list[str]) -> None:
    """`--plot --signal 'w[1]/a.cs.out[1]'` asked the run for `w[1]/a.cs.out`, which no link leaves."""
    from earl.model.expand import expand
    from earl.runtime.plot import what_to_record

    assert what_to_record(expand(earl.loads(FAMILY), {}), [signal]) == ([], outputs)


def test_a_signal_index_of_digits_that_are_not_ascii_is_refused() -> None:
    """`\\d` took `٢` (and `int` reads it as 2): the signal was recorded as member 2, where no spec writes it."""
    from earl.model.expand import expand
    from earl.runtime.plot import what_to_record

    with pytest.raises(ValueError, match=re.escape("`out` is a family of output buffers; name a member")):
        what_to_record(expand(earl.loads(FAMILY), {}), ["w[1]/a.cs.out[٢]"])
    pick_and_place = expand(earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place"), {})
    with pytest.raises(ValueError, match=re.escape("`[٢]` is not a path of `[index]` and `.field` steps")):
        what_to_record(pick_and_place, ["manip/a.cs.currentJointPos[٢]"])


def test_a_family_of_outputs_named_whole_is_every_member_to_record_and_a_member_to_plot(tmp_path: Path) -> None:
    from earl.model.expand import expand
    from earl.runtime.plot import what_to_record

    with pytest.raises(ValueError, match=r"`out` is a family of output buffers; name a member, `w\[1\]/a.cs.out\[1\]`"):
        what_to_record(expand(earl.loads(FAMILY), {}), ["w[1]/a.cs.out"])
    with earl.simulate(
        earl.loads(FAMILY), environment=None, trace=tmp_path / "t.mcap", record_outputs=["w[1]/a.cs.out"]
    ) as simulation:
        assert simulation.trace is not None and simulation.trace.links_also_recorded == {"w[1],boss"}


def test_a_recorder_without_idle_still_records_a_real_time_run() -> None:
    """`idle` came later than the other methods: a recorder that does not derive from `Recorder` may lack it."""

    class Counting:
        def __init__(self) -> None:
            self.changes = 0

        def state_changed(self, *arguments: object) -> None:
            self.changes += 1

        def behaviour_started(self, *arguments: object) -> None: ...
        def behaviour_stopped(self, *arguments: object) -> None: ...
        def message_sent(self, *arguments: object) -> None: ...
        def message_writer(self, link: str) -> None: ...
        def memory_snapshot(self, *arguments: object) -> None: ...
        def fault(self, *arguments: object) -> None: ...
        def iteration_done(self, *arguments: object) -> None: ...

    counting = Counting()
    with earl.simulate(earl.loads(TEXT), environment=None, realtime=True, recorders=[counting]) as simulation:  # type: ignore[list-item]
        simulation.advance_to(0.05)
    assert counting.changes >= 1


def test_a_kind_written_as_its_text_is_the_kind_at_run_time_as_for_the_checker() -> None:
    """`ElementReference("command", "ib")`: Kind is a StrEnum, so the resolver and the checker take "ib" for
    Kind.INPUT_BUFFER; the run took the read for one of memory and failed in its generated code (KeyError)."""
    spec = Path(__file__).parent / "runtime_specs" / "counter"
    written = earl.load(spec)
    as_text = earl.load(spec)
    relay = next(s for a in as_text.agents for s in a.subsystems if s.name == "relay")
    store = next(f for f in relay.partial_transition_functions if f.name == "store")
    store.reads[0] = ElementReference("command", "ib")  # type: ignore[arg-type]
    assert not [d for d in check(as_text) if d.severity.name == "ERROR"]
    runs = []
    for system in (written, as_text):
        simulation = earl.simulate(system)
        simulation.advance_to(0.2)
        runs.append({name: simulation.state_of(name).memory for name in simulation.network.by_name})
        simulation.close()
    assert runs[0] == runs[1]


@pytest.mark.parametrize("period", ["2 ms", 0.002, 2, 0])
def test_a_period_that_is_no_duration_is_named_by_to_earl_not_left_out(period: object) -> None:
    """The printer wrote only the body items it knew: `period = "2 ms"` vanished from the text, which then
    read back as a subsystem without a period (EARL-E017, far from the mistake)."""
    from earl.model.validate import ModelTypeError

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents[0].control_subsystem.period = period  # type: ignore[assignment,union-attr]
    with pytest.raises(ModelTypeError, match=r"system\.agents\[0\]\.subsystems\[0\]\.period: expected Duration"):
        system.to_earl()


def test_a_subsystem_built_twice_in_python_is_said_of_its_agent_not_of_the_subsystem_before_it() -> None:
    from earl import ControlSubsystem, VirtualEffector

    system = earl.loads(TEXT)
    agent = system.agents[0]
    agent.subsystems.append(VirtualEffector("drive"))
    agent.subsystems.append(VirtualEffector("drive"))
    agent.subsystems.append(ControlSubsystem())
    said = [d.message for d in check(system) if d.code == "EARL-R002"]
    # said of the agent (the message names it), not "(in `a/a.drive/ve`)", the subsystem declared before
    assert said == [
        "`drive/ve` of `a/a` is declared twice",
        "the Control Subsystem `cs` of `a/a` is declared twice (first declared at line 3)",
    ]


def test_a_nan_that_no_text_can_say_is_named_where_it_is_by_to_earl() -> None:
    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents[0].control_subsystems[0].memories[0].initial_value = Literal(float("nan"))
    with pytest.raises(
        ValueError, match=r"^system\.agents\[0\]\.subsystems\[0\]\.memories\[0\]\.initial_value\.value: nan"
    ):
        system.to_earl()


def test_what_draws_exports_or_expands_a_model_built_in_python_names_a_wrong_value_as_check_does(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`timeout = 0.05`, `reads = ["command/ib"]`, `initial_value = 0`: diagrams, the notebook's display,
    export_sysml and expand failed inside earl (`'float' object has no attribute 'value'`) where check and
    to_earl named the value; they now raise the same ModelTypeError, at the same path."""
    from earl.export import export_sysml
    from earl.model.expand import expand
    from earl.model.validate import ModelTypeError
    from earl.render import build_diagram
    from earl.render.jupyter import svg_for

    spec = Path(__file__).parent / "runtime_specs" / "counter"
    timeout = r"system\.agents\[0\]\.subsystems\[1\]\.fsm\.states\[\d\]\.timeout: expected Duration"
    system = earl.load(spec)
    relay = system.agents[0].subsystems[1]
    next(s for s in relay.fsm.states if s.timeout is not None).timeout = 0.05  # type: ignore[union-attr,assignment]
    for draw in (
        lambda: build_diagram(system, "fsm", "counter/a.relay/ve"),
        lambda: build_diagram(system, "agent", "counter/a"),
        lambda: export_sysml(system),
    ):
        with pytest.raises(ModelTypeError, match=timeout):
            draw()
    assert svg_for(relay) is None  # IPython then shows the text; the reason is one line, not a traceback
    assert "earl: virtualEffector.fsm.states" in capsys.readouterr().err
    system = earl.load(spec)
    system.agents[0].subsystems[1].partial_transition_functions[0].reads = ["command/ib"]  # type: ignore[list-item]
    with pytest.raises(ModelTypeError, match=r"partial_transition_functions\[0\]\.reads\[0\]: expected Element"):
        export_sysml(system)
    system = earl.load(spec)
    system.agents[0].subsystems[0].memories[0].initial_value = 0  # type: ignore[assignment]
    with pytest.raises(ModelTypeError, match=r"memories\[0\]\.initial_value: .*write `Literal\(0\)`"):
        expand(system)


def test_a_function_given_for_the_python_implementation_is_refused_by_to_earl_at_its_path() -> None:
    """`PythonImplementation(my_function)` for `PythonImplementation("module:function")`: to_earl wrote
    `= python <function idle at 0x…>`, a text that does not read back."""
    from earl import PythonImplementation
    from earl.model.validate import ModelTypeError

    def increment(*arguments: object) -> None: ...

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents[0].subsystems[0].partial_transition_functions[0].implementation = PythonImplementation(
        increment  # type: ignore[arg-type]
    )
    said = r'implementation\.path: expected str, got function .*: name the function as text, `".*:.*increment"`'
    with pytest.raises(ModelTypeError, match=said):
        system.to_earl()


@pytest.mark.parametrize("name", ["period", "fsm", "state", "true", "link"])
def test_a_keyword_given_as_a_name_in_python_is_said_by_check_and_refused_by_to_earl(name: str) -> None:
    """`Memory("period", …)` passed check and ran, but `to_earl()` and `earl.save` wrote `period/m: int`,
    which the reader does not read back. A keyword the reader reads as a name there (`python/m`) stays."""
    from earl import Memory
    from earl.model.validate import ModelNameError

    spec = Path(__file__).parent / "runtime_specs" / "counter"
    system = earl.load(spec)
    system.agents[0].subsystems[0].memories.append(Memory(name, PrimitiveType("int")))
    [said] = [d for d in check(system) if d.code == "EARL-R006"]
    assert said.message.startswith(f"`{name}` is a keyword of EARL where it is declared (a memory of counter/a.cs)")
    with pytest.raises(ModelNameError, match=rf"system\.agents\[0\]\.subsystems\[0\]\.memories\[2\]\.name: '{name}'"):
        system.to_earl()
    system = earl.load(spec)
    system.agents[0].subsystems[0].memories.append(Memory("python", PrimitiveType("int")))
    assert earl.loads(system.to_earl()) == system
    # beside one that does not read back, the one that does is not blamed (the parser stops at `period`)
    system.agents[0].subsystems[0].memories.append(Memory("period", PrimitiveType("int")))
    assert [d.message.split("`")[1] for d in check(system) if d.code == "EARL-R006"] == ["period"]
    # the first memory: the parser stops a blank line below the line it says (`fifo` after the buffers)
    system = earl.load(spec)
    system.agents[0].subsystems[0].memories.insert(0, Memory("fifo", PrimitiveType("int")))
    with pytest.raises(ModelNameError, match=r"memories\[0\]\.name: 'fifo'"):
        system.to_earl()
    system = earl.load(spec)
    system.name = "système"
    with pytest.raises(ModelNameError, match=r"'système' \(the system\) is no EARL name"):
        system.to_earl()
    system = earl.load(spec)
    system.name = "my system"
    with pytest.raises(ModelNameError, match=r"system\.name: 'my system' \(the system\) is no EARL name"):
        system.to_earl()


def test_a_predicate_given_as_earl_text_is_told_to_be_built_not_made_a_string_literal() -> None:
    """`expression = "count/mi >= 3"` was told to write `Literal('count/mi >= 3')`, which is a string,
    not a Boolean (EARL-E030); the hint builds the comparison instead."""
    from earl.model.validate import ModelTypeError

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents[0].subsystems[0].primitive_predicates[0].expression = "count/mi >= 3"  # type: ignore[assignment]
    built = 'Comparison(">=", Read(ElementReference("count", Kind.MEMORY_INPUT)), Literal(3))'
    with pytest.raises(ModelTypeError, match=re.escape(f"build the expression, e.g. `{built}`")):
        system.to_earl()
    system.agents[0].subsystems[0].primitive_predicates[0].expression = "done or busy/pp"  # type: ignore[assignment]
    with pytest.raises(ModelTypeError, match=r"build the expression, e.g. `Comparison\("):
        check(system)
    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents[0].subsystems[0].memories[0].initial_value = "ready"  # type: ignore[assignment]
    with pytest.raises(ModelTypeError, match=r"initial_value: .*write `Literal\('ready'\)`"):
        system.to_earl()


def test_a_name_not_found_in_python_says_the_declaration_and_attribute_it_is_in() -> None:
    """`reads[0] = ElementReference("cmdd", …)` said only ``EARL-R022 `counter/a.relay/ve` has no Input Buffer
    `cmdd` ``, and `data_type = None` only the subsystem: a model built in Python has no line to point at."""
    from earl import Memory

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    relay = system.agents[0].subsystems[1]
    store = next(f for f in relay.partial_transition_functions if f.name == "store")
    store.reads[0] = ElementReference("commandd", Kind.INPUT_BUFFER)
    relay.memories.append(Memory("extra", None))  # type: ignore[arg-type]
    said = {d.message for d in check(system)}
    assert (
        "`counter/a.relay/ve` has no Input Buffer `commandd` (in reads[0] of `store/pf` of `counter/a.relay/ve`)"
        in said
    )
    assert "NoneType is not a data type (in `extra/m` of `counter/a.relay/ve`)" in said


def test_a_kind_given_as_its_text_becomes_the_kind_so_to_earl_writes_it_as_check_and_the_run_take_it() -> None:
    """`ElementReference("command", "ib")` was taken by check, export and the run, but to_earl refused it
    (`kind: expected Kind, got str 'ib'`); a text that is no kind is still named, with the kinds."""
    from earl.model.validate import ModelTypeError

    reference = ElementReference("command", "ib")  # type: ignore[arg-type]
    assert reference.kind is Kind.INPUT_BUFFER and reference == ElementReference("command", Kind.INPUT_BUFFER)
    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    store = system.agents[0].subsystems[1].partial_transition_functions[0]
    store.reads[0] = reference
    assert earl.loads(system.to_earl()) == earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    store.reads[0] = ElementReference("command", "ibb")  # type: ignore[arg-type]
    with pytest.raises(
        ModelTypeError, match=r"reads\[0\]\.kind: expected Kind, got str 'ibb': .*its text, one of r, a"
    ):
        system.to_earl()


def test_a_spec_whose_names_are_keywords_as_read_is_not_printed_again_to_see_that_they_read_back(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """`false/pp` and the control subsystem `cs` are in nearly every spec: a name read from text was read,
    so reading a spec does not print it and parse it again for them (it doubled the time of every load)."""
    import earl.lang.formatter

    def refused(system: object) -> str:
        raise AssertionError("printed while read")

    monkeypatch.setattr(earl.lang.formatter, "format_system", refused)
    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    assert not [d for d in check(system) if d.code == "EARL-R006"]


@pytest.mark.parametrize(("where", "name"), [("memory", "period"), ("agent", "link")])
def test_an_element_read_from_text_and_renamed_to_a_keyword_in_python_is_said_and_refused(
    where: str, name: str
) -> None:
    """A name with a location was taken as read, so a loaded memory renamed `period` in Python passed check and
    `to_earl()` wrote `period/m: …`, which does not read back; it is asked as a new name is, and a name as read
    (`false/pp`, a state called `state`) is still not."""
    from earl.model.validate import ModelNameError

    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    manip = system.agents[1]
    element: Any = manip.subsystems[0].memories[0] if where == "memory" else manip
    assert element.location is not None
    element.name = name
    [said] = [d for d in check(system) if d.code == "EARL-R006"]
    assert said.message.startswith(f"`{name}` is a keyword of EARL where it is declared")
    assert said.location == element.location
    with pytest.raises(ModelNameError, match=f"'{name}'.* is a keyword of EARL where it stands"):
        system.to_earl()
    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    system.agents[1].subsystems[0].fsm.states[1].name = "state"  # `state state: …` reads back
    assert not [d for d in check(system) if d.code == "EARL-R006"]
    assert "state state: jointMove/bb" in system.to_earl()


def test_a_tuple_where_the_model_declares_a_list_is_drawn_and_exported() -> None:
    """`system.agents = tuple(…)` checked, printed and ran, but drawing and the SysML export refused it
    (expected a list, got tuple) once they checked the model's types first."""
    from earl.export.sysml import export_sysml
    from earl.render.build import build_diagram

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    system.agents = tuple(system.agents)  # type: ignore[assignment]
    subsystem = system.agents[0].subsystems[0]
    subsystem.memories = tuple(subsystem.memories)  # type: ignore[assignment]
    assert "counter/a" in build_diagram(system, "system").dot
    assert "counter" in export_sysml(system)


class _NoTime:
    def advance(self) -> None: ...


class _BindsNothing:
    def bind(self) -> None: ...


class _ClosesWithWhat:
    def close(self, viewer: object) -> None: ...


class _TimeByName:
    def advance(self, *, time: float) -> None: ...


def _passing_the_count(advance: Callable[[Any, float, int], None]) -> Callable[[Any, float], None]:
    """A decorator whose wrapper earl calls with the time; `functools.wraps` makes it look like `advance`."""

    @functools.wraps(advance)
    def wrapper(self: Any, time: float) -> None:
        advance(self, time, len(self.counts))

    return wrapper


class _Decorated:
    def __init__(self) -> None:
        self.counts: list[int] = []

    @_passing_the_count
    def advance(self, time: float, count: int) -> None:
        self.counts.append(count)


class _ClosingWidth:
    """`close` is data here, the gripper's closing width: earl calls no `close` then, and runs."""

    def __init__(self) -> None:
        self.close = 0.02
        self.times: list[float] = []

    def advance(self, time: float) -> None:
        self.times.append(time)


class _OpensAViewer:
    def __init__(self, advance: object) -> None:
        self.closed = 0
        self.advance = advance

    def close(self) -> None:
        self.closed += 1


def test_a_decorated_advance_is_checked_as_the_wrapper_earl_calls() -> None:
    environment = _Decorated()
    with earl.simulate(earl.loads(TEXT), environment=environment) as simulation:
        simulation.advance_to(0.02)
    assert environment.counts[:3] == [0, 1, 2]


def test_an_environment_whose_close_is_data_runs_and_is_not_called() -> None:
    environment = _ClosingWidth()
    with earl.simulate(earl.loads(TEXT), environment=environment) as simulation:
        simulation.advance_to(0.02)
    assert environment.times[-1] == pytest.approx(0.02) and environment.close == 0.02


@pytest.mark.parametrize("advance", [lambda: None, 0.001], ids=["no time", "no method"])
def test_an_environment_whose_advance_is_refused_is_closed(advance: object) -> None:
    """What it opened (a viewer) is closed when the run is refused, as when its `bind` refuses."""
    environment = _OpensAViewer(advance)
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.loads(TEXT), environment=environment)
    assert [d.code for d in refused.value.diagnostics] == ["EARL-X020"]
    assert environment.closed == 1


class _Fits:
    """Methods as earl calls them, with defaults and *args: all of these fit."""

    def __init__(self) -> None:
        self.times: list[float] = []

    def bind(self, system: object, strict: bool = True) -> None: ...

    def advance(self, *times: float) -> None:
        self.times.extend(times)

    def close(self, reason: str = "") -> None: ...


@pytest.mark.parametrize(
    ("environment", "said"),
    [
        (_NoTime(), "the environment's `advance()` cannot be called as earl calls it, advance(time): too many"),
        (_BindsNothing(), "the environment's `bind()` cannot be called as earl calls it, bind(system): too many"),
        (_ClosesWithWhat(), "the environment's `close(viewer)` cannot be called as earl calls it, close(): missing"),
        # keyword-only, shown as written: `advance(time)` would look callable as earl calls it
        (_TimeByName(), "the environment's `advance(*, time)` cannot be called as earl calls it, advance(time): too"),
    ],
)
def test_an_environment_object_whose_methods_earl_cannot_call_is_refused_before_the_run(
    environment: object, said: str
) -> None:
    """Not a TypeError traceback at the first instant (advance), or once the run is over (close)."""
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.loads(TEXT), environment=environment)
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X020"
    assert diagnostic.message.startswith(said)
    assert diagnostic.hint is not None and diagnostic.hint.startswith("define it as `def ")


def test_an_environment_object_whose_methods_fit_runs() -> None:
    environment = _Fits()
    with earl.simulate(earl.loads(TEXT), environment=environment) as simulation:
        simulation.advance_to(0.02)
    assert environment.times[-1] == pytest.approx(0.02)


def _counter_with(tmp_path: Path, memories: str, *replacements: tuple[str, str]) -> Path:
    """The runtime's counter spec with `memories` declared just before its control subsystem's FSM."""
    spec = tmp_path / "counter"
    text = (Path(__file__).parent / "runtime_specs" / "counter" / "system.earl").read_text(encoding="utf-8")
    text = text.replace("\n        fsm {", f"\n{memories}        fsm {{", 1)
    for old, new in replacements:
        assert old in text, old
        text = text.replace(old, new)
    spec.mkdir()
    (spec / "system.earl").write_text(text, encoding="utf-8")
    return spec


def _earl(*arguments: str | Path) -> subprocess.CompletedProcess[str]:
    source = str(Path(__file__).parent.parent / "src")
    return subprocess.run(
        [sys.executable, "-m", "earl", *map(str, arguments)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": source},
    )


def test_a_family_index_named_state_is_a_name_as_written_and_fmt_says_what_does_not_read_back(
    tmp_path: Path,
) -> None:
    """The words `param`, `type`, `struct` and `state` before a name were skipped for every kind of name, so
    the family index of `seen[state in 1..2]/m` was read as `in`, taken for a name renamed in Python, and blamed
    for what did not read back (`and/m` after `sent/m: int = 0`): check refused it with EARL-R006 and
    `earl fmt --check` ended in a ModelNameError traceback. Check says ok, as before, and fmt names `and`."""
    spec = _counter_with(tmp_path, "        and/m: int = 0\n        seen[state in 1..2]/m: int = 0\n")
    checked = _earl("check", spec)
    assert checked.returncode == 0 and "ok" in checked.stdout, checked.stdout + checked.stderr
    formatted = _earl("fmt", "--check", spec)
    assert formatted.returncode == 1 and "Traceback" not in formatted.stderr, formatted.stderr
    [said] = formatted.stderr.splitlines()
    assert "cannot be put in canonical form" in said and "after `and`" in said and "the file is left as it is" in said
    assert not [d for d in check(earl.load(spec)) if d.code == "EARL-R006"]


def test_a_name_after_its_keyword_on_another_line_or_a_keyword_named_index_is_read_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Only a parameter, type, struct or state follows its keyword, and a line end or a comment may part them
    (`state // the last one` ⏎ `timeout: …`); each was taken for a name renamed in Python, so the spec was
    printed and parsed again while read."""
    import earl.lang.formatter

    def refused(system: object) -> str:
        raise AssertionError("printed while read")

    spec = _counter_with(
        tmp_path,
        "        seen[state in 1..2]/m: int = 0\n        kept[param in 1..2]/m: int = 0\n",
        ("state finished: finished/bb", "state // the last one\n            timeout: finished/bb"),
        ("counting -> finished when", "counting -> timeout when"),
        ("param LIMIT: int = 3", "param\n    period: int = 3\n\nparam LIMIT: int = 3"),
    )
    monkeypatch.setattr(earl.lang.formatter, "format_system", refused)
    system = earl.load(spec)
    assert not [d for d in check(system) if d.code == "EARL-R006"]
    monkeypatch.undo()
    assert earl.loads(system.to_earl(), "again.earl") == system


def _renamed(system: Any, path: str, name: str) -> None:
    """`system.<path> = name`, for a path as EARL-R006 says it; a link's name part is frozen, so replaced."""
    from dataclasses import replace

    *steps, last = path.removeprefix("system.").split(".")
    holder: Any = None
    owner: Any = system
    for step in steps:
        attribute, _, index = step.partition("[")
        holder, owner = owner, getattr(owner, attribute)
        if index:
            owner = owner[int(index.rstrip("]"))]
    if isinstance(owner, LinkNamePart):  # `links[1].name[0]`: the link holds a tuple of them
        holder.name = tuple(replace(part, name=name) if part is owner else part for part in holder.name)
    elif isinstance(owner, Family):  # frozen, as the link's `family`
        holder.family = replace(owner, index=name)
    else:
        setattr(owner, last, name)


@pytest.mark.parametrize(
    ("path", "name", "what"),
    [
        ("agents[0].subsystems[0].parameters[0].name", "my gain", "a parameter of counter/a.cs"),
        ("agents[0].subsystems[0].stage_sets[0].name", "my stage", "a stage set of counter/a.cs"),
        ("agents[0].links[1].name[0].name", "my link", "a part of the name of a link of `counter/a`"),
        ("agents[0].links[1].name[1].name", "relay-display", "a part of the name of a link of `counter/a`"),
        ("agents[0].links[0].family.index", "my K", "the family index of a link of `counter/a`"),
        ("agents[0].links[0].family.index", "any", "the family index of a link of `counter/a`"),
        ("agents[0].links[0].family.index", "true", "the family index of a link of `counter/a`"),
    ],
)
def test_a_subsystem_parameter_stage_set_or_link_renamed_in_python_is_said_and_refused(
    tmp_path: Path, path: str, name: str, what: str
) -> None:
    """A subsystem's parameter, a stage set, a part of a link's name and a link family's index were not among the
    names EARL-R006 asks: renamed `my gain` in Python, check said nothing and `to_earl()` wrote
    `param my gain: int = 2`, which does not read back."""
    from earl.model.validate import ModelNameError

    spec = _counter_with(
        tmp_path,
        "        param G: int = 2\n        stage first = {rest/pf}\n",
        ("link cs,relay: cs.count", "link cs,relay[K in 1..1]: cs.count"),
    )
    system = earl.load(spec)
    assert not [d for d in check(system) if d.code == "EARL-R006"]
    _renamed(system, f"system.{path}", name)
    [said] = [d for d in check(system) if d.code == "EARL-R006"]
    assert f"({what})" in said.message and said.location is not None
    with pytest.raises(ModelNameError, match=re.escape(f"system.{path}: '{name}' ({what})")):
        system.to_earl()


def test_a_system_link_renamed_in_python_is_said() -> None:
    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    _renamed(system, "system.links[0].name[1].name", "the manipulator")
    [said] = [d for d in check(system) if d.code == "EARL-R006"]
    assert said.message == "'the manipulator' is no EARL name (a part of the name of a link of the system)"


def test_stage_sets_and_links_named_as_keywords_in_the_text_are_read_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`stage stage = …` and `link state, fifo: …` read back as written: reading them does not print the spec
    and parse it again (a link's name is its first word only when written with a `:`)."""
    import earl.lang.formatter

    def refused(system: object) -> str:
        raise AssertionError("printed while read")

    spec = _counter_with(
        tmp_path,
        "        stage stage = {rest/pf}\n",
        ("link relay,display:", "link state, // a comment\n        fifo :"),
        ("link display,relay: display/re.echo", "link display/re.echo"),
        ("link cs,relay: cs.count", "link cs,relay[stage in 1..1]: cs.count"),
    )
    monkeypatch.setattr(earl.lang.formatter, "format_system", refused)
    system = earl.load(spec)
    assert not [d for d in check(system) if d.code == "EARL-R006"]
    monkeypatch.undo()
    assert earl.loads(system.to_earl(), "again.earl") == system


@pytest.mark.parametrize("index", ["my K", "any", "not", "true", "J"])
def test_the_index_of_any_built_in_python_is_said_when_it_would_not_read_back(index: str) -> None:
    """`Quantifier("any", "my K", …)` passed check and `to_earl()` wrote `any(my K in 1..N: …)`, which does not
    read back; `any(true in 1..2: true …)` reads back with a Boolean literal where the index was."""
    from dataclasses import replace

    from earl.model.validate import ModelNameError

    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    [predicate] = [p for p in system.agents[1].subsystems[0].primitive_predicates if p.name == "emergencyStop"]
    assert isinstance(predicate.expression, BooleanOperation)
    written, quantifier = predicate.expression.operands
    assert isinstance(quantifier, Quantifier) and isinstance(quantifier.body, Read)
    target = replace(quantifier.body.target, indices=(Name(index),))
    renamed = replace(quantifier, index=index, body=replace(quantifier.body, target=target))
    predicate.expression = replace(predicate.expression, operands=(written, renamed))
    said = [d for d in check(system) if d.code == "EARL-R006"]
    if index == "J":  # a name: it reads back as written
        assert not said
        assert earl.loads(system.to_earl()) == system
        return
    expected = (
        f"{index!r} is no EARL name (the index of `any`/`all`)"
        if " " in index
        else f"`{index}` is a keyword of EARL where it is declared (the index of `any`/`all`): the text would not "
        "read back"
    )
    assert [d.message for d in said] == [expected]
    assert said[0].location == quantifier.location
    at = system.agents[1].subsystems[0].primitive_predicates.index(predicate)
    path = f"system.agents[1].subsystems[0].primitive_predicates[{at}].expression.operands[1].index"
    with pytest.raises(ModelNameError, match=re.escape(f"{path}: '{index}' (the index of `any`/`all`)")):
        system.to_earl()


@pytest.mark.parametrize(
    ("where", "comments", "path"),
    [
        ("agent", Comments(closing=["/* x */"]), r"system\.agents\[0\]\.comments\.closing\[0\]: '/\* x \*/'"),
        ("agent", Comments(leading=["just words"]), r"system\.agents\[0\]\.comments\.leading\[0\]: 'just words'"),
        ("memory", Comments(trailing="// one\n// two"), r"\.subsystems\[0\]\.memories\[0\]\.comments\.trailing: "),
        ("memory", Comments(after="# hash"), r"\.memories\[0\]\.comments\.after: '# hash'"),
    ],
)
def test_a_comment_the_language_cannot_hold_is_refused_where_it_is(where: str, comments: Comments, path: str) -> None:
    """`Comments(closing=["/* x */"])` was written as is, and the text did not read back: EARL has `//`
    comments only, one line each."""
    from earl.model.validate import ModelCommentError

    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    element: Any = system.agents[0] if where == "agent" else system.agents[0].subsystems[0].memories[0]
    element.comments = comments
    [said] = [d for d in check(system) if d.code == "EARL-R007"]
    assert re.search(path, said.message) and "is no EARL comment" in said.message
    with pytest.raises(ModelCommentError, match=path + r".* is no EARL comment"):
        system.to_earl()


def test_spaces_around_a_comment_set_in_python_are_dropped_so_it_reads_back() -> None:
    """`Comments(closing=[" // b "])` was written one space deeper than its block's body, and read back
    as `// b`; blank comments ("", spaces) stay blank lines."""
    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    agent = system.agents[0]
    agent.comments = Comments(leading=["  // a "], trailing=" // t ", closing=[" // b ", "  ", "// b2"], after="\t// c")
    text = system.to_earl()
    assert "\n    // b\n\n    // b2\n}  // c\n" in text
    read = earl.loads(text)
    assert read == system
    said = read.agents[0].comments
    assert (said.leading, said.trailing, said.closing, said.after) == (["// a"], "// t", ["// b", "", "// b2"], "// c")
    assert read.to_earl() == text


def _edited_counter(edit: Callable[[Any], None]) -> Any:
    system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
    edit(system)
    return system


def _relay_state(system: Any) -> Any:
    return next(s for s in system.agents[0].subsystems[1].fsm.states if s.timeout is not None)


@pytest.mark.parametrize(
    ("edit", "path"),
    [
        # docs/python-api.md's own example: check returned a diagnostic and simulate raised EarlError
        (lambda s: setattr(_relay_state(s), "timeout", 0.05), r"fsm\.states\[\d\]\.timeout: expected Duration"),
        # check said `is '20' ms, not a number`, but to_earl wrote `timeout "20" ms`, which does not load
        (
            lambda s: setattr(_relay_state(s), "timeout", earl.Duration("20", "ms")),  # type: ignore[arg-type]
            r"fsm\.states\[\d\]\.timeout\.value: expected int \| float, got str '20'",
        ),
        # check passed it, to_earl wrote `?`, and the reload held True
        (
            lambda s: s.types.append(
                earl.StructType("T", [earl.Field("x", earl.PrimitiveType("int"), optional="yes")])
            ),  # type: ignore[arg-type]
            r"system\.types\[\d\]\.fields\[0\]\.optional: expected bool, got str 'yes'",
        ),
    ],
)
def test_a_value_of_a_wrong_type_is_a_model_type_error_of_check_to_earl_and_simulate_alike(
    edit: Callable[[Any], None], path: str
) -> None:
    for use in (check, lambda system: system.to_earl(), earl.simulate):
        with pytest.raises(earl.ModelTypeError, match=path):
            use(_edited_counter(edit))


def test_to_earl_refuses_a_priority_check_refuses_rather_than_write_text_that_does_not_load() -> None:
    def edit(system: Any) -> None:
        system.agents[0].subsystems[0].fsm.transitions[0].priority = True

    assert [d.code for d in check(_edited_counter(edit)) if d.severity is earl.Severity.ERROR] == ["EARL-R033"]
    with pytest.raises(earl.ModelTypeError, match=r"transitions\[0\]\.priority: expected int \| None, got bool"):
        _edited_counter(edit).to_earl()


LINKED = """\
system linked

param W: int = 2

struct Tick {
    count: int
}

counter[K in 1..W]/a {
    cs {
        period 10 ms
        tick/ob: Tick
    }
}

display/a {
    cs {
        period 10 ms
        tick[K in 1..W]/ib: Tick
    }
}

link counter[K in 1..W],display: counter[K]/a.cs.tick -> display/a.cs.tick[K]

fleet/r {
    counter[*]/a
    display/a
    link counter[K in 1..W],display
}
"""


def _errors_of(system: Any) -> list[tuple[str | None, str]]:
    return [(d.code, d.message) for d in check(system) if d.severity is earl.Severity.ERROR]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda s: setattr(s.robots[0], "agents", [ElementReference("display", Kind.ROBOT)]),
            "an agent of robot `fleet/r` is `display/r`, of kind `/r` (Robot); it must be `/a` (Agent)",
        ),
        (
            lambda s: setattr(s.robots[0], "links", [ElementReference("counter[K in 1..W],display", Kind.AGENT)]),
            "a link of robot `fleet/r` is `counter[K in 1..W],display/a`, of kind `/a` (Agent); it must be `/aa`",
        ),
        (
            lambda s: setattr(
                s.links[0], "source", dataclasses.replace(s.links[0].source, agent=ElementReference("counter", "r"))
            ),
            "the source agent of link `counter[K in 1..W],display` is `counter/r`, of kind `/r` (Robot)",
        ),
        (
            lambda s: setattr(
                s.links[0],
                "destination",
                dataclasses.replace(s.links[0].destination, buffer=ElementReference("tick", "mi")),
            ),
            "the destination buffer of link `counter[K in 1..W],display` is `tick/mi`",
        ),
    ],
)
def test_a_robot_member_or_link_end_of_the_wrong_kind_is_r021_not_text_that_does_not_load(
    edit: Callable[[Any], None], message: str
) -> None:
    system = earl.loads(LINKED)
    assert _errors_of(system) == []
    edit(system)
    [(code, said)] = _errors_of(system)
    assert code == "EARL-R021" and said.startswith(message), said


def test_a_robot_member_whose_kind_is_no_kind_is_a_model_type_error() -> None:
    system = earl.loads(LINKED)
    system.robots[0].agents = [ElementReference("display", "agent")]  # type: ignore[arg-type]
    with pytest.raises(earl.ModelTypeError, match=r"^system\.robots\[0\]\.agents\[0\]\.kind: expected Kind"):
        check(system)


def test_a_robot_naming_a_link_family_with_an_index_is_r057_as_the_index_would_be_dropped() -> None:
    system = earl.loads(LINKED)
    system.robots[0].links = [ElementReference("counter[K in 1..W],display", Kind.INTER_AGENT_LINK, (earl.Star(),))]
    [(code, said)] = _errors_of(system)
    assert code == "EARL-R057" and "names the link `counter[K in 1..W],display` with indices" in said
    # as documented in python-api.md: the family named whole, as it is declared
    system.robots[0].links = [ElementReference("counter[K in 1..W],display", Kind.INTER_AGENT_LINK)]
    assert _errors_of(system) == [] and earl.loads(system.to_earl()) == system


@pytest.mark.parametrize("parts", [(), ("counter", "display", "x")])
def test_a_link_name_of_other_than_one_or_two_parts_is_r058(parts: tuple[str, ...]) -> None:
    system = earl.loads(LINKED)
    system.links[0].name = tuple(LinkNamePart(part) for part in parts)
    system.robots[0].links = []  # which named it
    [(code, said)] = _errors_of(system)
    assert code == "EARL-R058" and f"has {len(parts)} parts to its name" in said


def test_a_system_without_a_name_is_r006() -> None:
    system = earl.loads(LINKED)
    system.name = ""
    assert _errors_of(system) == [
        (
            "EARL-R006",
            "the system has no name: the text would start without its `system` line, which a specification needs",
        )
    ]


def test_a_control_subsystem_named_otherwise_than_cs_is_r008_and_not_saved_as_cs() -> None:
    """`ControlSubsystem("main", …)` checked clean, and was saved as `cs`: a link naming `cs` was refused by check
    (`task/a` has no subsystem `cs`) and one naming `main` did not read back."""
    system = earl.loads(LINKED)
    system.agents[1].subsystems[0].name = "main"
    assert _errors_of(system) == [
        (
            "EARL-R008",
            "the Control Subsystem of `display/a` is named 'main'; an agent's Control Subsystem is called `cs` (§2.2)"
            " and is saved so",
        )
    ]
    with pytest.raises(earl.ModelNameError, match=r"^system\.agents\[1\]\.subsystems\[0\]\.name: 'main'"):
        system.to_earl()


def test_an_import_added_in_python_is_said_not_to_be_read(tmp_path: Path) -> None:
    """`System(imports=[Import("types.earl")])`: check and the run said only `unknown data type `Tick``, whatever
    the working directory, while the saved text loaded (and read back with the file's declarations)."""
    (tmp_path / "types.earl").write_text("struct Tick {\n    count: int\n}\n")
    system = earl.loads(LINKED)
    system.types.clear()
    system.imports.append(earl.Import("types.earl"))
    errors = _errors_of(system)
    assert errors[0] == (
        "EARL-R009",
        'system.imports[0]: `import "types.earl"` in a model built in Python is not read: what that file declares'
        " is not in this model, which check and the run see as it is",
    )
    [said] = [d for d in check(system) if d.code == "EARL-R009"]
    assert "earl.load" in (said.hint or "")
    # as the hint says: saved and loaded, the import is read next to the file
    earl.save(system, tmp_path / "system.earl")
    assert _errors_of(earl.load(tmp_path / "system.earl")) == []
