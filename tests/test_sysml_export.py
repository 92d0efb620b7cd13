"""`earl export sysml`: the golden file, every model element found in the export, names, expressions, the CLI.

The element walk reads the export with the independent SysML v2 parser (tests/test_sysml_parse.py)
and looks every element of the expanded model up by its EARL name, the short name it must carry.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.check import context_for
from earl.cli.main import main
from earl.export.sysml import export_sysml, library_text
from earl.export.sysml_expressions import ExpressionWriter, literal
from earl.export.sysml_names import Namespace, is_basic_name, name_text, quoted, readable
from earl.model import (
    Agent,
    Arithmetic,
    BooleanOperation,
    Comparison,
    ElementReference,
    FieldAccess,
    IndexAccess,
    Kind,
    Literal,
    Negate,
    Not,
    Read,
    System,
)
from test_sysml_parse import FLAGSHIP, GOLDEN, ROOT, parse_tree, syntax_errors

SMALL = GOLDEN / "small.earl"
SMALL_EXPECTED = GOLDEN / "small.sysml"


# ---------------------------------------------------------------------- golden file
def test_the_small_spec_exports_as_the_golden_file() -> None:
    text = export_sysml(earl.load(SMALL))
    if os.environ.get("EARL_UPDATE_GOLDEN"):
        SMALL_EXPECTED.write_text(text, encoding="utf-8")
    assert text == SMALL_EXPECTED.read_text(encoding="utf-8"), (
        "the export of tests/golden/sysml/small.earl changed; if the change is wanted, run "
        "EARL_UPDATE_GOLDEN=1 pytest tests/test_sysml_export.py and review the diff"
    )


def test_the_golden_file_parses() -> None:
    assert not syntax_errors(SMALL_EXPECTED.read_text(encoding="utf-8"))


def test_the_export_does_not_depend_on_the_working_directory(monkeypatch: pytest.MonkeyPatch) -> None:
    first = export_sysml(earl.load(SMALL))
    monkeypatch.chdir(GOLDEN)
    assert export_sysml(earl.load("small.earl")) == first


# ---------------------------------------------------------------------- every element is there
_ELEMENT = re.compile(r"(Usage|Definition|Package|TransitionUsage|Membership)Context$")
_REDEFINED = re.compile(r":>>((?:[A-Za-z_]\w*)|(?:'[^']*'))")


def _unquote(text: str) -> str:
    return text[1:-1].replace("\\'", "'").replace("\\\\", "\\") if text.startswith("'") else text


def _identification(context: Any) -> tuple[list[str], bool]:
    """The names an element declares (its short name and its name), or else the feature it redefines."""
    from sysmlpy.antlr.SysMLv2Parser import SysMLv2Parser

    stack = list(context.getChildren())
    while stack:
        child = stack.pop(0)
        if isinstance(child, (SysMLv2Parser.IdentificationContext, SysMLv2Parser.FeatureIdentificationContext)):
            return [_unquote(n.getText()) for n in child.getTypedRuleContexts(SysMLv2Parser.NameContext)], False
        if hasattr(child, "getChildren") and not _ELEMENT.search(type(child).__name__):
            if "Body" in type(child).__name__:
                continue
            stack[:0] = list(child.getChildren())
    found = _REDEFINED.match(re.sub(r"^[a-z]+", "", context.getText()))
    return ([_unquote(found.group(1))] if found else []), True


def _paths(context: Any, path: tuple[frozenset[str], ...] = ()) -> Iterator[tuple[frozenset[str], ...]]:
    """Every element of the tree as the names of it and of each element around it."""
    if not hasattr(context, "getChildren"):
        return
    if _ELEMENT.search(type(context).__name__) and "Membership" not in type(context).__name__:
        declared, redefined = _identification(context)
        names = frozenset(declared)
        # The grammar nests a usage in a context of its kind: an unnamed one is met twice, and counted once.
        if names and not (redefined and path and path[-1] == names):
            path = (*path, names)
            yield path
    for child in context.getChildren():
        yield from _paths(child, path)


def _index(text: str) -> set[tuple[str, ...]]:
    """Every path of names, each step by any of its names, for lookups."""
    errors = syntax_errors(text)
    assert not errors, errors
    result: set[tuple[str, ...]] = set()
    for path in _paths(parse_tree(text)):
        choices: list[tuple[str, ...]] = [()]
        for step in path:
            choices = [(*prefix, name) for prefix in choices for name in step]
        result.update(choices)
    return result


def _member(name: str, index: int | None, kind: str) -> str:
    return f"{name if index is None else f'{name}[{index}]'}/{kind}"


def _expected(system: System) -> Iterator[tuple[str, ...]]:
    """Every element of the expanded model, as the path of EARL names the export must have."""
    package = system.name
    top = (package, system.name)
    for definition in system.types:
        yield (package, definition.name)
        for field in getattr(definition, "fields", []):
            yield (package, definition.name, field.name)
    for parameter in system.parameters:
        yield (*top, parameter.name)
    for robot in system.robots:
        yield (*top, f"{robot.name}/r")
    for link in system.links:
        yield (*top, link.name_text)
    for agent in system.agents:
        yield from _agent_paths(top, agent)


def _agent_paths(top: tuple[str, ...], agent: Agent) -> Iterator[tuple[str, ...]]:
    own = (*top, _member(agent.name, agent.index, "a"))
    yield own
    yield (*own, "agentType")
    for parameter in agent.parameters:
        yield (*own, parameter.name)
    for link in agent.links:
        yield (*own, link.name_text)
    for subsystem in agent.subsystems:
        sub = (
            *own,
            "cs"
            if subsystem.kind is Kind.CONTROL_SUBSYSTEM
            else _member(subsystem.name, subsystem.index, subsystem.kind.value),
        )
        yield sub
        for parameter in subsystem.parameters:
            yield (*sub, parameter.name)
        for buffer in subsystem.input_buffers:
            yield (*sub, _member(buffer.name, buffer.index, "ib"), "msg")
        for output in subsystem.output_buffers:
            yield (*sub, _member(output.name, output.index, "ob"), "msg")
        for memory in subsystem.memories:
            yield (*sub, _member(memory.name, memory.index, "m"), "data")
        for predicate in subsystem.primitive_predicates:
            yield (*sub, f"{predicate.name}/pp")
        for function in subsystem.partial_transition_functions:
            yield (*sub, f"{function.name}/pf")
        for stage_set in subsystem.stage_sets:
            yield (*sub, f"stage {stage_set.name}")
        for behaviour in subsystem.basic_behaviours:
            yield (*sub, f"{behaviour.name}/bb", "tf")
            yield (*sub, f"{behaviour.name}/bb", "terminalCondition")
            if behaviour.error_condition is not None:
                yield (*sub, f"{behaviour.name}/bb", "errorCondition")
        if subsystem.fsm is not None:
            fsm = (*sub, "fsm")
            for state in subsystem.fsm.states:
                # `start` and `done` are what every state body inherits: such a state is `start_2`, without a
                # short name, which would hide the inherited feature as well
                yield (*fsm, f"{state.name}_2" if state.name in ("start", "done") else state.name)
            for transition in subsystem.fsm.transitions:
                yield (*fsm, f"{transition.source},{transition.destination}/t")
            for number in range(1, len(subsystem.fsm.assumptions) + 1):
                yield (*fsm, f"assumption{number}")


@pytest.mark.parametrize("path", [FLAGSHIP, SMALL], ids=lambda p: p.name)
def test_every_element_of_the_model_is_in_the_export(path: Path) -> None:
    system = earl.load(path)
    expanded = context_for(system).system
    found = _index(export_sysml(system))
    expected = list(_expected(expanded))
    missing = [" :: ".join(p) for p in expected if p not in found]
    assert not missing, f"{len(missing)} of {len(expected)} elements are not in the export: {missing[:10]}"
    assert len(expected) > 100


def test_the_element_walk_can_fail() -> None:
    """A path that is not in the export is reported missing."""
    found = _index(export_sysml(earl.load(SMALL)))
    assert ("conveyor", "conveyor", "line/a", "cs", "order/ib", "msg") in found
    assert ("conveyor", "conveyor", "line/a", "cs", "nothing/ib", "msg") not in found
    assert ("conveyor", "conveyor", "line/a", "belt[3]/ve") not in found  # N = 2


# ---------------------------------------------------------------------- what the export says
def test_families_are_expanded_with_the_given_parameters() -> None:
    text = export_sysml(earl.load(FLAGSHIP, {"N": 3}), {"N": 3})
    assert "motorController3_ve" in text and "motorController4_ve" not in text
    assert "attribute N : EARL::int = 3 {" in text
    assert "<'motorController[3]/ve'>" in text


def test_agent_types_are_the_checkers_table_1() -> None:
    system = earl.load(ROOT / "examples" / "mobile_robot")
    context = context_for(system)
    text = export_sysml(system)
    for agent in context.system.agents:
        row = context.agent_type(agent)
        own = re.escape(f"<'{_member(agent.name, agent.index, 'a')}'>")
        block = re.search(own + r".*?attribute :>> agentType = EARL::AgentType::(\w+);", text, re.DOTALL)
        assert block is not None and block.group(1) == row.name


def test_transitions_keep_priorities_and_guards() -> None:
    text = export_sysml(earl.load(FLAGSHIP))
    assert "transition <'idle,jointMove/t'> idle_jointMove_t" in text
    guard = re.search(r"idle_jointMove_t\s+first idle\s+if ([^\n]*)\n\s+then jointMove \{([^}]*\}[^}]*)\}", text)
    assert guard is not None
    assert guard.group(1) == "newJointPos_pp and not emergencyStop_pp"
    assert "@EARL::TransitionPriority { priority = 2; }" in guard.group(2)
    # `* -> emergencyStop` is one transition per other state
    assert text.count("Declared as `* -> emergencyStop`") == 3


def test_a_two_stage_transition_function_is_a_fork_and_a_join_per_stage() -> None:
    text = export_sysml(earl.load(FLAGSHIP))
    block = re.search(r"<'jointMove/bb'>.*?action :>> tf \{(.*?)\n\s+\}", text, re.DOTALL)
    assert block is not None
    lines = [line.strip() for line in block.group(1).strip().splitlines()]
    assert lines[:4] == [
        "first start then stage1Fork;",
        "fork stage1Fork;",
        "then calculatePosition_pf;",
        "then jointMove_pf;",
    ]
    assert "join stage1Join;" in lines and "first stage1Join then stage2Fork;" in lines
    assert lines[-1] == "first stage2Join then done;"


def test_memory_buffers_and_links_carry_the_spec_types() -> None:
    text = export_sysml(earl.load(SMALL))
    assert "attribute :>> data : Speeds[2] ordered nonunique := (0.0, 0.0);" in text
    assert "in item :>> msg : Order;" in text
    assert "attribute :>> capacity = 4;" in text and "EARL::OverflowPolicy::dropOldest" in text
    assert re.search(
        r"flow <'supervisor,line'> supervisor_line : EARL::InterAgentLink :> links of Order\s+"
        r"from supervisor_a\.cs\.order_ob\.msg\s+to line_a\.cs\.order_ib\.msg",
        text,
    )


# ---------------------------------------------------------------------- names
def test_names() -> None:
    assert readable("manip/a") == "manip_a"
    assert readable("motorController[3]/ve") == "motorController3_ve"
    assert readable("task,manip") == "task_manip"
    assert readable("idle,jointMove/t") == "idle_jointMove_t"
    assert not is_basic_name("part") and name_text("part") == "'part'"
    assert name_text("then") == "'then'" and name_text("idle") == "idle"
    assert quoted("it's") == "'it\\'s'"
    namespace = Namespace(("ib",))
    assert [namespace.claim("ib"), namespace.claim("x"), namespace.claim("x")] == ["ib_2", "x", "x_2"]


def test_a_state_named_like_a_keyword_is_quoted() -> None:
    text = (
        SMALL.read_text(encoding="utf-8")
        .replace("initial stop", "initial then")
        .replace("state stop: stop/bb", "state then: stop/bb")
        .replace("* -> stop", "* -> then")
        .replace("stop -> run", "then -> run")
    )
    exported = export_sysml(earl.loads(text, "keywords.earl"))
    assert "state 'then' : EARL::FSMState" in exported
    assert "entry; then 'then';" in exported
    assert not syntax_errors(exported)


# ---------------------------------------------------------------------- expressions
def _writer() -> ExpressionWriter:
    return ExpressionWriter(lambda reference: readable(f"{reference.name}/{reference.kind.value}"))


def _read(name: str, kind: Kind, *path: Any) -> Read:
    return Read(ElementReference(name, kind), tuple(path))


def test_not_and_comparisons_get_sysml_parentheses() -> None:
    a, b = _read("a", Kind.PRIMITIVE_PREDICATE), _read("b", Kind.PRIMITIVE_PREDICATE)
    x = _read("x", Kind.INPUT_BUFFER, FieldAccess("speed"))
    writer = _writer()
    # EARL's `not x <= 2.5` is `not (x <= 2.5)`; SysML's `not` binds tighter than `<=`.
    assert writer.text(Not(Comparison("<=", x, Literal(2.5)))) == "not (x_ib.msg.speed <= 2.5)"
    assert writer.text(BooleanOperation("or", (a, BooleanOperation("and", (a, b))))) == "a_pp or (a_pp and b_pp)"
    assert writer.text(Not(a)) == "not a_pp"
    assert (
        writer.text(Comparison("==", Comparison("<", x, Literal(1)), Literal(True))) == "(x_ib.msg.speed < 1) == true"
    )


def test_the_operand_of_a_unary_operator_is_a_primary_expression() -> None:
    """KerML's `UnaryExpression: operator operand=ExtentExpression` takes a primary expression: `not not b`
    and `--x` are refused by the OMG pilot's grammar, `not (not b)` and `-(-x)` are what EARL means."""
    b = _read("b", Kind.MEMORY_INPUT)
    x = _read("x", Kind.MEMORY_INPUT)
    writer = _writer()
    assert writer.text(Not(Not(b))) == "not (not b_mi.data)"
    assert writer.text(Comparison(">", Negate(Negate(x)), Literal(0.0))) == "-(-x_mi.data) > 0.0"
    assert writer.text(Negate(Literal(-1.0))) == "-(-1.0)"
    assert writer.text(Negate(Arithmetic("-", x, Literal(1.0)))) == "-(x_mi.data - 1.0)"
    assert writer.text(Not(Comparison("==", b, Literal(True)))) == "not (b_mi.data == true)"
    # a unary operand of a binary operator stays bare: the grammar's operands are unary expressions there
    assert writer.text(Arithmetic("-", x, Literal(-1.0))) == "x_mi.data - -1.0"
    assert writer.text(Arithmetic("*", Negate(x), x)) == "-x_mi.data * x_mi.data"
    assert writer.text(BooleanOperation("and", (Not(b), b))) == "not b_mi.data and b_mi.data"


def test_indices_move_from_zero_based_to_one_based() -> None:
    values = _read("v", Kind.MEMORY_INPUT, IndexAccess(Literal(0)))
    assert _writer().text(values) == "v_mi.data#(1)"
    grid = _read("g", Kind.INPUT_BUFFER, FieldAccess("cells"), IndexAccess(Literal(2)), IndexAccess(Literal(0)))
    assert _writer().text(grid) == "g_ib.msg.cells#(3).elements#(1)"


def test_literals() -> None:
    assert literal(True) == "true" and literal(3) == "3" and literal(0.5) == "0.5"
    assert literal('belt "A"\n') == '"belt \\"A\\"\\n"'
    assert literal(float("inf")) == "1e999"


# ---------------------------------------------------------------------- the library
def test_every_library_definition_names_its_source_in_the_manual() -> None:
    text = library_text()
    definitions = re.findall(
        r"^\s*(?:abstract )?\w+ def (\w+)[^{;]*\{\s*doc\s*/\*(.*?)\*/", text, re.DOTALL | re.MULTILINE
    )
    assert len(definitions) >= 30
    for name, doc in definitions:
        assert re.search(r"§\d|Table \d|earl", doc), f"{name}: its doc names no section of the manual"
    for concept in (
        "System",
        "Robot",
        "Agent",
        "ControlSubsystem",
        "VirtualEffector",
        "RealEffector",
        "VirtualReceptor",
        "RealReceptor",
        "InputBuffer",
        "OutputBuffer",
        "InternalMemory",
        "FSM",
        "FSMState",
        "BasicBehaviour",
        "TransitionFunction",
        "PartialTransitionFunction",
        "PrimitivePredicate",
        "Predicate",
        "Link",
        "AgentType",
        "agentTypeOf",
    ):
        assert any(name == concept for name, _ in definitions), concept
    assert "equation1" in text and "table1" in text


# ---------------------------------------------------------------------- the command
def test_the_command_writes_the_export_and_the_library(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    output = tmp_path / "small.sysml"
    assert main(["export", "sysml", str(SMALL), "-o", str(output)]) == 0
    assert output.read_text(encoding="utf-8") == export_sysml(earl.load(SMALL))
    assert (tmp_path / "EARL.sysml").read_text(encoding="utf-8") == library_text()
    assert "wrote" in capsys.readouterr().err


def test_the_command_prints_to_standard_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # with N = 3 the spec's two initial setpoints no longer fit `double[N]` (EARL-E043): zero ones do
    three = tmp_path / "small.earl"
    three.write_text(
        SMALL.read_text(encoding="utf-8").replace("setpoints/m: Speeds = [0.0, 0.0]", "setpoints/m: Speeds")
    )
    assert main(["export", "sysml", str(three), "--param", "N=3"]) == 0
    assert "belt3_ve" in capsys.readouterr().out
    assert main(["export", "sysml", str(SMALL), "--param", "N=3"]) == 1
    assert "EARL-E043" in capsys.readouterr().err


def test_the_command_refuses_an_invalid_spec(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    broken = tmp_path / "broken.earl"
    broken.write_text(SMALL.read_text(encoding="utf-8").replace("tf = {plan/pf} then {send/pf}", "tf = {nope/pf}"))
    output = tmp_path / "out.sysml"
    assert main(["export", "sysml", str(broken), "-o", str(output)]) == 1
    assert "nope/pf" in capsys.readouterr().err
    assert not output.exists()
    rules = tmp_path / "rules.earl"
    rules.write_text(SMALL.read_text(encoding="utf-8").replace("    supervisor/a\n", ""))
    assert main(["export", "sysml", str(rules)]) == 1
    assert "not exported" in capsys.readouterr().err


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["export", "sysml", "missing.earl"], "no such file"),
        (["export", "sysml", str(SMALL), "-o", "/nonexistent/dir/x.sysml"], "no such directory"),
        (["export", "sysml", str(SMALL), "--param", "N"], "NAME=VALUE"),
        (["export", "uml", str(SMALL)], "invalid choice"),
        (["export", "sysml", str(SMALL), "-o", "/tmp/EARL.sysml"], "is where the library EARL.sysml goes"),
        (["export", "sysml", str(SMALL), "-o", "/tmp/earl.sysml"], "is where the library EARL.sysml goes"),
    ],
)
def test_the_command_reports_usage_errors(
    arguments: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        status = main(arguments)
    except SystemExit as exit_:
        status = int(exit_.code or 0)
    assert status == 2
    assert message in capsys.readouterr().err


def test_exporting_never_imports_code_the_spec_names(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    marker = tmp_path / "imported"
    package = tmp_path / "conveyor"
    package.mkdir()
    (package / "__init__.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    (package / "supervisor.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    (package / "line.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["export", "sysml", str(SMALL), "-o", str(tmp_path / "out.sysml")]) == 0
    assert not marker.exists()
    assert "conveyor" not in sys.modules


def test_export_writes_no_model_when_the_library_cannot_be_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "EARL.sysml").mkdir()  # the library's place is taken by a directory
    assert main(["export", "sysml", str(SMALL), "-o", str(tmp_path / "small.sysml")]) == 2
    assert "cannot write" in capsys.readouterr().err
    assert not (tmp_path / "small.sysml").exists()  # a model naming EARL::… without the library is no use


def test_a_name_renamed_for_a_library_feature_gets_no_short_name_that_would_hide_it(tmp_path: Path) -> None:
    """`param agents` is renamed `agents_2`; a short name `<'agents'>` would be found, by name
    resolution, where the library's `agents` is meant. A system `EARL` does not take the library's
    package name."""
    from earl.export.sysml import export_sysml

    text = SMALL.read_text(encoding="utf-8")
    system_line = next(line for line in text.splitlines() if line.startswith("system "))
    spec = tmp_path / "names.earl"
    spec.write_text(text.replace(system_line, "system EARL\n\nparam agents: int = 1", 1), encoding="utf-8")
    exported = export_sysml(earl.load(spec))
    assert "attribute agents_2 : EARL::int = 1 {" in exported
    assert "<'agents'>" not in exported
    assert "package EARL_system {" in exported
    spec.write_text(text.replace(system_line, "system ScalarValues", 1), encoding="utf-8")
    assert "package ScalarValues_system {" in export_sysml(earl.load(spec))


def test_a_system_built_in_python_is_resolved_before_it_is_written() -> None:
    """An alias that names itself, added in Python, sent the writer into endless recursion: the reader's
    R011 is raised instead, as for a file."""
    from earl.export.sysml import export_sysml
    from earl.model.types import ArrayType, TypeAlias, TypeReference

    system = earl.loads("system s\n")
    system.types.append(TypeAlias("A", ArrayType(TypeReference("A"), None)))
    with pytest.raises(earl.EarlError) as refused:
        export_sysml(system)
    assert [d.code for d in refused.value.diagnostics] == ["EARL-R011"]


def test_a_comment_that_closes_a_block_is_in_the_element_s_doc() -> None:
    text = (
        "system closing\n\nstruct Limits {\n    v: double\n    // the last word on the limits\n}\n\n"
        "x/a {\n    cs {\n        period 10 ms\n        // the subsystem's last word\n    }\n    // the agent's last word\n}\n"
    )
    exported = export_sysml(earl.loads(text, "closing.earl"))
    for said in ("the last word on the limits", "the subsystem's last word", "the agent's last word"):
        assert said in exported
    assert exported.index("the agent's last word") < exported.index("the subsystem's last word")
    # what ends the file is about no element: an editor's mode line is no doc of the system
    assert "vim" not in export_sysml(earl.loads(text + "// vim: set ft=earl:\n", "closing.earl"))


def test_a_comment_after_a_block_s_closing_brace_is_in_that_element_s_doc() -> None:
    """`}  // the agent's end` went to the next declaration's doc (the robot's here); it is about the block it
    follows, however the block is laid out."""
    for agent in (
        "x/a {\n    cs {\n        period 10 ms\n    }\n}  // the agent's end\n",
        "x/a { cs { period 10 ms } }  // the agent's end\n",
    ):
        text = f"system closing\n\n{agent}\nr/r {{\n    x/a\n}}\n"
        exported = export_sysml(earl.loads(text, "closing.earl"))
        agent_doc = re.search(r"part <'x/a'> x_a : EARL::Agent :> agents \{\s*doc\s*/\*(.*?)\*/", exported, re.DOTALL)
        assert agent_doc is not None and "the agent's end" in agent_doc.group(1), exported
        assert exported.count("the agent's end") == 1


_OPTIONAL_ARRAYS = """system opt

type Row = double[3]

struct Cmd {
    target: double[3]?
    path: double[]?
    must: double[3]
    row: Row?
    rows: Row[2]
}

r1/r {
    a1/a
}

a1/a {
    cs {
        period 10 ms
        cmd/ib: Cmd
        hi/pp = newData(cmd/ib.target) and cmd/ib.target[0] > 1.0 and cmd/ib.rows[1][0] > 0.0
        same/pp = cmd/ib.target == [1.0, 2.0, 3.0] and cmd/ib.rows[1] != [0.0, 0.0, 0.0]
        b1/bb {
            tf = {}
            tc = hi/pp or same/pp
        }
        fsm {
            initial one
            state one: b1/bb
        }
    }
}
"""


def test_an_optional_array_field_is_absent_or_one_whole_array() -> None:
    """`double[3]?` is absent or exactly three values: `[0..3]` admitted one or two, and `double[]?` as `[*]`
    could not tell an absent array from an empty one. It is one value of a definition holding the array."""
    exported = export_sysml(earl.loads(_OPTIONAL_ARRAYS, "opt.earl"))
    assert "attribute target : 'double[3]'[0..1];" in exported
    assert "attribute path : 'double[]'[0..1];" in exported
    assert "attribute must : EARL::double[3] ordered nonunique;" in exported
    assert re.search(
        r"attribute def 'double\[3\]' \{[^}]*attribute elements : EARL::double\[3\] ordered nonunique;", exported
    )
    assert re.search(
        r"attribute def 'double\[\]' \{[^}]*attribute elements : EARL::double\[\*\] ordered nonunique;", exported
    )
    # an alias of an array, as one value, is not named as the alias itself (`'Row'` is `Row` in SysML)
    assert "attribute row : 'Row value'[0..1];" in exported
    assert "attribute rows : 'Row value'[2] ordered nonunique;" in exported
    assert "attribute def 'Row'" not in exported
    # reads go through `elements`; newData is about the field itself
    assert "EARL::newData(cmd_ib.msg.target) and cmd_ib.msg.target.elements#(1) > 1.0" in exported
    assert "cmd_ib.msg.rows#(2).elements#(1) > 0.0" in exported
    assert (
        "cmd_ib.msg.target.elements == (1.0, 2.0, 3.0) and cmd_ib.msg.rows#(2).elements != (0.0, 0.0, 0.0)" in exported
    )
    assert not syntax_errors(exported)


_TWO_WAYS = """system dup

r1/r {
    a1/a
}

a1/a {
    cs {
        period 10 ms
        c/m: int = 0
        lo/pp = c/mi < 3
        hi/pp = c/mi > 5
        b1/bb {
            tf = {}
            tc = lo/pp or hi/pp
        }
        fsm {
            initial one
            state one: b1/bb
            state two: b1/bb
            one -> two when lo/pp priority 1
            one -> two when hi/pp priority 2
            * -> one when hi/pp priority 3
            two -> one when lo/pp priority 1
        }
    }
}
"""


def test_transitions_are_written_in_the_order_they_are_tried_and_named_by_earl_names_only() -> None:
    """`* -> one … priority 3` declared before `two -> one … priority 1` was written first, though the text's
    order carries the priority; the second `one -> two` got the short name `<'one,two/t_2'>`, no EARL name.
    Names follow the declarations, as the document's Table 5 numbers them (the `*` one, declared first, is
    `two_one_t`), so that a changed priority renames nothing."""
    exported = export_sysml(earl.loads(_TWO_WAYS, "dup.earl"))
    transitions = re.findall(r"transition (.*)\n\s+first (\w+)\n\s+if (\w+)\n", exported)
    assert transitions == [
        ("<'one,two/t'> one_two_t", "one", "lo_pp"),
        ("two_one_t_2", "two", "lo_pp"),
        ("one_two_t_2", "one", "hi_pp"),
        ("<'two,one/t'> two_one_t", "two", "hi_pp"),
    ]
    assert "/t_2" not in exported
    assert not syntax_errors(exported)


def test_a_link_named_as_a_library_feature_gets_no_short_name() -> None:
    """The export wrote `flow <'links'> links_2`: a short name `links` would be found where the library's
    `links` is meant."""
    text = SMALL.read_text(encoding="utf-8").replace("link supervisor,line", "link links")
    assert "link links:" in text
    exported = export_sysml(earl.loads(text, "small.earl"))
    assert re.search(r"flow links_2 : EARL::InterAgentLink :> links", exported)
    assert "<'links'>" not in exported


def test_a_comment_on_a_struct_field_is_the_field_s_doc() -> None:
    """`value: double // the value` lost its comment, though every `// comment` is its element's doc."""
    text = (
        "system fields\n\nstruct Reading {\n    // how far, in metres\n    distance: double\n"
        "    value: double // the value <v> & stuff\n    extra: double[2]?\n}\n"
    )
    exported = export_sysml(earl.loads(text, "fields.earl"))
    value = re.search(r"attribute value : EARL::double \{\s*doc\s*/\*(.*?)\*/\s*\}", exported, re.DOTALL)
    assert value is not None and "the value <v> & stuff" in value.group(1) and "fields.earl:6" in value.group(1)
    distance = re.search(r"attribute distance : EARL::double \{\s*doc\s*/\*(.*?)\*/\s*\}", exported, re.DOTALL)
    assert distance is not None and "how far, in metres" in distance.group(1)
    assert "attribute extra : 'double[2]'[0..1];" in exported  # a field without a comment stays one line
    assert not syntax_errors(exported)


def test_comments_at_a_robot_s_members_are_in_the_robot_s_doc() -> None:
    """They are kept at the members now (`earl fmt`); a member is a reference in SysML too, so its comments
    are the robot's doc, as they were when the reader gave them to the robot."""
    text = (
        "system c\n\nr/r {\n    // the arm\n    a/a  // trailing\n    b/a\n    link b,a  // the feed\n}\n\n"
        "a/a {\n    cs {\n        period 1 ms\n\n        i/ib: double\n    }\n}\n\n"
        "b/a {\n    cs {\n        period 1 ms\n\n        o/ob: double\n    }\n}\n\n"
        "link b,a: b/a.cs.o -> a/a.cs.i\n"
    )
    exported = export_sysml(earl.loads(text, "c.earl"))
    robot = re.search(r"part <'r/r'> r_r : EARL::Robot :> robots \{\s*doc\s*/\*(.*?)\*/", exported, re.DOTALL)
    assert robot is not None
    assert all(said in robot.group(1) for said in ("the arm", "trailing", "the feed"))


_OWN_SUFFIXES = """system s

x/a {
    cs {
        period 1 ms
        param period_2: int = 1
        param period: int = 2
        f/pp = true
        b/bb {
            tf = {}
            tc = f/pp
        }
        fsm {
            initial start
            state start: b/bb
            state start_2: b/bb
            state done_2: b/bb
            state done: b/bb

            start -> start_2 when f/pp
            start_2 -> done when f/pp
        }
    }
}

r/r {
    x/a
}
"""


def test_a_name_a_person_wrote_is_never_renamed_to_make_room_for_a_generated_one() -> None:
    """A state `start` (a name every state body inherits) was exported as `start_2`, and the person's own
    `start_2` then became `start_2_2`: only the clashing name gets a suffix, one that no name of the spec has."""
    exported = export_sysml(earl.loads(_OWN_SUFFIXES, "own.earl"))
    states = re.findall(r"state (\w+) : EARL::FSMState", exported)
    assert states == ["start_3", "start_2", "done_2", "done_3"]
    assert "entry; then start_3;" in exported
    assert re.search(r"first start_3\s+if f_pp\s+then start_2 \{", exported)
    assert re.search(r"first start_2\s+if f_pp\s+then done_3 \{", exported)
    # a parameter named as the library's `period` feature, beside one named `period_2`
    assert "attribute period_2 : EARL::int = 1" in exported and "attribute period_3 : EARL::int = 2" in exported
    assert not syntax_errors(exported)


def test_a_suffix_skips_the_names_to_come() -> None:
    namespace = Namespace(("start",), users=("start_2", "start_3"))
    assert namespace.claim("start") == "start_4"
    assert namespace.claim("start_2") == "start_2"
    assert namespace.claim("start_3") == "start_3"
    assert namespace.claim("start_2") == "start_2_2"  # a name written twice still gets one


def test_states_named_start_or_done_do_not_hide_what_every_state_body_inherits() -> None:
    """A state body has the features `start` and `done` (an action's first and last snapshots): a state named
    `start` hid one, and `entry; then start;` could be read as the library's."""
    spec = Path(__file__).parent.parent / "examples" / "mobile_robot" / "system.earl"
    assert "state start:" in spec.read_text(encoding="utf-8")
    exported = export_sysml(earl.load(spec))
    assert "entry; then start_2;" in exported and "state start_2 : EARL::FSMState" in exported
    assert not re.search(r"\bstate start\b", exported)
    assert not syntax_errors(exported)


#: a comment on every kind of element the export writes (`K01` … `K39`)
_EVERY_KIND = """// K01 system
system every

// K02 system param
param N: int = 2

// K03 alias
type Metres = double

// K04 struct
struct Reading {
    // K05 field
    value: double
}

// K06 robot
r/r {
    // K07 robot member
    a/a
    b/a
    // K39 robot link member
    link b,a
}

// K08 agent
a/a {
    // K09 agent param
    param G: double = 1.0
    // K10 cs
    cs {
        // K11 period
        period 1 ms
        // K12 subsystem param
        param KP: double = 2.0
        // K13 ib
        x/ib: Reading
        // K14 ob
        y/ob: double
        z/ib: double  // K37 trailing comment
        // K15 memory
        m/m: double = 0.0
        // K16 pp
        p/pp = x/ib.value > 1.0
        // K17 pf
        f/pf(x/ib -> m/mo)
        // K18 stage
        stage pf = {f/pf}
        // K19 bb
        b/bb {
            // K20 tf
            tf = {f/pf}
            // K21 tc
            tc = p/pp
            // K22 ec
            ec = not p/pp
        }
        // K23 fsm
        fsm {
            // K24 initial
            initial s
            // K25 state
            state s: b/bb {
                // K26 obligatory
                obligatory x/ib
                // K27 timeout
                timeout 4 ms
            }
            state t: b/bb
            // K28 transition without priority
            s -> t when p/pp
            // K29 transition with priority
            t -> s when p/pp priority 1
            // K30 from any state
            * -> s when not p/pp priority 2
            // K31 assume
            assume x/ib.value > -1.0
        }
    }
    // K32 ve
    v/ve {
        period 1 ms
        c/ib: double
        o/ob: double
    }
    // K33 re
    e/re {
        period 1 ms
        c/ib: double
    }
    // K34 vr
    w/vr {
        period 1 ms
        c/ib: double
        c/ob: double
    }
    // K35 rr
    q/rr {
        period 1 ms
        c/ob: double
    }
    // K36 link in an agent
    link cs,v: cs.y -> v/ve.c
    link v,e: v/ve.o -> e/re.c
    link q,w: q/rr.c -> w/vr.c
    link w,cs: w/vr.c -> cs.z
}

b/a {
    cs {
        period 1 ms
        o/ob: Reading
    }
}

// K38 link between agents
link b,a: b/a.cs.o -> a/a.cs.x
"""

#: a comment at a clause, or at a robot's member, is in the doc of the element that owns it
_OWNER = {"K07": "K06", "K39": "K06", "K11": "K10", "K20": "K19", "K21": "K19", "K22": "K19", "K24": "K23"}
_OWNER |= {"K26": "K25", "K27": "K25"}


def _docs(exported: str) -> list[str]:
    """Every doc comment of the export, its lines joined as one text."""
    return [
        " ".join(line.strip().removeprefix("*").strip() for line in body.splitlines())
        for body in re.findall(r"\bdoc\s*/\*(.*?)\*/", exported, re.DOTALL)
    ]


def _declared_at(marker: str) -> int:
    """The line of the element a `// K… ` comment is about: the next line, or its own for an end-of-line comment."""
    lines = _EVERY_KIND.splitlines()
    number = next(n for n, line in enumerate(lines, start=1) if f"// {marker} " in line)
    return number + 1 if lines[number - 1].lstrip().startswith("//") else number


def test_every_kind_of_element_keeps_its_comment_and_where_it_was_written() -> None:
    """A transition without a priority, a `param` and a `stage` set lost their comments (and the transition its
    line), though docs/sysml.md promises every `// comment` as its element's doc with the file and line. The spec
    comments every kind of element the export writes, and the clauses whose comments the model keeps."""
    exported = export_sysml(earl.loads(_EVERY_KIND, "every.earl"))
    docs = _docs(exported)
    markers = sorted(set(re.findall(r"// (K\d\d) ", _EVERY_KIND)))
    assert len(markers) == 39
    assert "K01 system" in docs[0]  # the system's comment is the package's doc
    for marker in markers[1:]:
        holding = [doc for doc in docs if f"{marker} " in doc]
        assert holding, f"{marker}'s comment is in no doc"
        line = _declared_at(_OWNER.get(marker, marker))
        assert all(f"From every.earl:{line}." in doc for doc in holding), (marker, holding)
    assert "At `tc`: K21 tc" in exported and "At `timeout`: K27 timeout" in exported
    # a transition without a priority has a doc too, and no priority
    without = re.search(r"transition <'s,t/t'> s_t_t\s+first s\s+if p_pp\s+then t \{(.*?)\n\s*\}", exported, re.DOTALL)
    assert without is not None and "From every.earl:" in without.group(1) and "Priority" not in without.group(1)
    assert not syntax_errors(exported)


def test_a_doc_joins_a_comment_s_lines_and_leaves_out_a_section_above_a_blank_line() -> None:
    """Each line of a comment was wrapped apart (`…  An imported` / `file` / `holds …`), and an imported
    file's header, parted by a blank line from its first declaration, became that declaration's doc."""
    text = (
        "system s\n\n// Section: the parameters of the line, which the next block of comments is about and\n"
        "// this one heads.\n\n// The count of belts on the line, which the controller drives one\n"
        "// after another.\n// - at least one\n// - at most four\nparam N: int = 2\n"
    )
    exported = export_sysml(earl.loads(text, "s.earl"))
    doc = exported[exported.index("attribute N") :]
    doc = doc[: doc.index("*/")]
    assert "Section" not in doc
    assert "The count of belts on the line, which the controller drives one after another." in " ".join(
        line.strip(" *") for line in doc.splitlines()
    )
    assert "* - at least one\n" in doc and "* - at most four\n" in doc  # a list keeps its items
