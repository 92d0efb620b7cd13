"""The model: built in Python, read from text, expanded into instances; independent of every reader."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.model import (
    FSM,
    Agent,
    BasicBehaviour,
    BooleanOperation,
    ControlSubsystem,
    ElementReference,
    Family,
    Field,
    InputBuffer,
    Kind,
    Link,
    LinkEnd,
    LinkNamePart,
    Literal,
    Name,
    Not,
    OutputBuffer,
    Parameter,
    PrimitivePredicate,
    PrimitiveType,
    Read,
    RealEffector,
    Robot,
    State,
    StructType,
    System,
    Transition,
    TransitionFunction,
    TypeReference,
    VirtualEffector,
)
from earl.model.elements import Predicate
from earl.model.expand import expand
from earl.model.text import expression_text

EXAMPLE = Path(__file__).parent.parent / "examples" / "pick_and_place" / "system.earl"


def test_the_model_imports_no_parser_renderer_or_runtime() -> None:
    code = (
        "import sys, earl.model, earl.model.expand;"
        "bad = [m for m in sys.modules if m == 'lark' or m.startswith(('lark.', 'earl.lang', 'earl.cli'))];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout + result.stderr


def _built_in_python() -> System:
    def pp(name: str) -> Read:
        return Read(ElementReference(name, Kind.PRIMITIVE_PREDICATE))

    command = ElementReference("command", Kind.INPUT_BUFFER)
    cs = ControlSubsystem(
        input_buffers=[InputBuffer("command", TypeReference("Command"))],
        output_buffers=[OutputBuffer("drive", PrimitiveType("double"), Family("K", Literal(1), Name("N")))],
        primitive_predicates=[
            PrimitivePredicate("stop", Read(command, (earl.model.FieldAccess("stop"),))),
            PrimitivePredicate("false", Literal(False)),
        ],
        basic_behaviours=[
            BasicBehaviour("run", TransitionFunction([]), Predicate(pp("stop"))),
            BasicBehaviour("halt", TransitionFunction([]), Predicate(pp("false"))),
        ],
        fsm=FSM(
            "run",
            states=[State("run", "run"), State("halt", "halt")],
            transitions=[Transition("run", "halt", Predicate(pp("stop")), priority=1)],
        ),
    )
    drive = VirtualEffector(
        "drive",
        Family("K", Literal(1), Name("N")),
        input_buffers=[InputBuffer("setpoint", PrimitiveType("double"))],
        output_buffers=[OutputBuffer("current", PrimitiveType("double"))],
    )
    motor = RealEffector(
        "motor", Family("K", Literal(1), Name("N")), input_buffers=[InputBuffer("current", PrimitiveType("double"))]
    )
    link = Link(
        (LinkNamePart("cs"), LinkNamePart("drive", Name("K"), declares_family=True)),
        LinkEnd(
            None,
            ElementReference("cs", Kind.CONTROL_SUBSYSTEM),
            ElementReference("drive", Kind.OUTPUT_BUFFER, (Name("K"),)),
        ),
        LinkEnd(
            None,
            ElementReference("drive", Kind.VIRTUAL_EFFECTOR, (Name("K"),)),
            ElementReference("setpoint", Kind.INPUT_BUFFER),
        ),
        Family("K", Literal(1), Name("N")),
    )
    agent = Agent("arm", subsystems=[cs, drive, motor], links=[link])
    return System(
        "built",
        parameters=[Parameter("N", PrimitiveType("int"), Literal(2))],
        types=[StructType("Command", [Field("stop", PrimitiveType("boolean"))])],
        agents=[agent],
        robots=[Robot("robot", agents=[ElementReference("arm", Kind.AGENT)])],
    )


def test_a_model_built_in_python_prints_as_text_that_reads_back_equal() -> None:
    system = _built_in_python()
    text = system.to_earl()
    assert "drive[K in 1..N]/ve {" in text
    assert "link cs,drive[K in 1..N]: cs.drive[K] -> drive[K]/ve.setpoint" in text
    again = earl.loads(text)
    assert again == system
    assert again.to_earl() == text


def test_equality_ignores_locations_but_not_content() -> None:
    first = earl.loads("system a\nparam N: int = 1\n")
    second = earl.loads("system a\n\n\n   param N: int = 1\n")
    third = earl.loads("system a\nparam N: int = 2\n")
    assert first == second
    assert first != third
    assert first.parameters[0].location is not None
    assert first.parameters[0].location.line == 2
    assert second.parameters[0].location.line == 4


def test_every_element_of_the_flagship_keeps_its_source_location() -> None:
    system = earl.load(EXAMPLE)
    missing = []
    for agent in system.agents:
        elements: list[object] = [agent, *agent.subsystems, *agent.links]
        for subsystem in agent.subsystems:
            elements += [
                *subsystem.input_buffers,
                *subsystem.output_buffers,
                *subsystem.memories,
                *subsystem.primitive_predicates,
                *subsystem.partial_transition_functions,
                *subsystem.basic_behaviours,
            ]
            if subsystem.fsm is not None:
                elements += [subsystem.fsm, *subsystem.fsm.states, *subsystem.fsm.transitions]
        missing += [e for e in elements if getattr(e, "location", None) is None]
    assert missing == []
    idle = system.agent("manip").control_subsystem.fsm.state_named("idle")  # type: ignore[union-attr]
    assert idle is not None and idle.location is not None
    assert idle.location.file.endswith("system.earl")
    assert "state idle: idle/bb" in EXAMPLE.read_text().splitlines()[idle.location.line - 1]


@pytest.mark.parametrize("joints", [3, 6, 7])
def test_families_expand_to_one_instance_per_member(joints: int) -> None:
    system = earl.load(EXAMPLE, {"N": joints})
    expanded = expand(system, {"N": joints})
    manip = expanded.agent("manip")
    assert manip is not None
    controllers = manip.subsystems_of(Kind.VIRTUAL_EFFECTOR)
    assert [c.index for c in controllers] == list(range(1, joints + 1))
    assert all(c.family is not None for c in controllers)  # the family is kept for rendering
    assert len(manip.subsystems_of(Kind.REAL_EFFECTOR)) == joints
    assert len(manip.links) == 4 * joints
    cs = manip.control_subsystem
    assert cs is not None
    assert [b.index for b in cs.input_buffers if b.name == "motorControllerState"] == list(range(1, joints + 1))
    # any(K in 1..N: …) is unrolled into an `or` over every member
    emergency = cs.primitive_predicate("emergencyStop")
    assert emergency is not None
    text = expression_text(emergency.expression)
    assert text.count("motorControllerState[") == joints
    assert f"motorControllerState[{joints}]/ib.emergencyStop" in text
    # [*] in a function's declared writes names every member
    output = cs.partial_transition_function("outputMotorCon")
    assert output is not None
    assert len([w for w in output.writes if w.kind is Kind.OUTPUT_BUFFER]) == joints
    # `* -> emergencyStop` becomes one transition from every other state
    assert cs.fsm is not None
    sources = sorted(t.source or "" for t in cs.fsm.transitions if t.destination == "emergencyStop")
    assert sources == ["idle", "jointMove", "operationalMove"]
    # the declared model is untouched: still one family declaration
    declared = system.agent("manip")
    assert declared is not None
    assert len(declared.subsystems_of(Kind.VIRTUAL_EFFECTOR)) == 1


def test_parameters_become_values_in_expanded_types_and_params() -> None:
    system = earl.load(EXAMPLE, {"N": 4})
    expanded = expand(system, {"N": 4})
    joint_position = expanded.type_named("JointPosition")
    assert joint_position is not None
    assert expression_text(joint_position.data_type.size) == "4"  # type: ignore[union-attr, arg-type]
    manip = expanded.agent("manip")
    assert manip is not None
    joints = [s.parameters[0].value for s in manip.subsystems_of(Kind.VIRTUAL_EFFECTOR)]
    assert joints == [Literal(1), Literal(2), Literal(3), Literal(4)]


def test_an_empty_any_is_false_and_a_single_member_any_is_its_body() -> None:
    text = """system s
param N: int = 1
a/a {
    cs {
        x[K in 1..N]/ib: boolean
        one/pp = any(K in 1..N: x[K]/ib)
        none/pp = any(K in 1..0: x[K]/ib)
        every/pp = all(K in 2..1: x[K]/ib)
    }
}
"""
    expanded = expand(earl.loads(text))
    cs = expanded.agents[0].control_subsystem
    assert cs is not None
    values = {p.name: p.expression for p in cs.primitive_predicates}
    assert expression_text(values["one"]) == "x[1]/ib"
    assert values["none"] == Literal(False)
    assert values["every"] == Literal(True)


def test_boolean_operations_keep_their_operands_in_order() -> None:
    expression = BooleanOperation("and", (Not(Name("a")), Name("b")))
    assert expression_text(expression) == "not a and b"


def test_spans_cover_what_was_written_parentheses_included() -> None:
    # The reader measures spans while it parses; they must match the text exactly (carets, SARIF).
    text = (
        "system s\n\nr/r {\n    a/a\n}\n\na/a {\n    cs {\n        x/ib: boolean\n"
        "        p/pp = not (x/ib and x/ib)\n        q/pp = (x/ib)\n    }\n}\n"
    )
    cs = earl.loads(text, "spans.earl").agent("a").control_subsystem
    p, q = cs.primitive_predicates
    assert p.location is not None and (p.location.line, p.location.column, p.location.end_column) == (10, 9, 35)
    negation = p.expression
    assert isinstance(negation, Not) and negation.location is not None
    assert (negation.location.column, negation.location.end_column) == (16, 35)  # `not (…)`, the `)` too
    inner = negation.operand
    assert inner.location is not None and (inner.location.column, inner.location.end_column) == (21, 34)
    assert q.location is not None and (q.location.column, q.location.end_column) == (9, 22)
    assert q.expression.location is not None and q.expression.location.column == 17  # inside the parentheses


def test_check_resolves_a_system_built_or_edited_in_python() -> None:
    """What the reader would refuse in a file, `earl.check.check` reports for a model built in Python:
    names that resolve to nothing, a period time could not follow, a priority that is no number."""
    from pathlib import Path

    from earl.check import check
    from earl.model.elements import Duration, Predicate, Transition
    from earl.model.expressions import Literal

    def codes(edit: Any) -> list[str]:
        system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
        cs = system.agent("counter").control_subsystem
        assert cs is not None and cs.fsm is not None
        edit(cs)
        return sorted({d.code or "" for d in check(system) if d.severity.name == "ERROR"})

    assert codes(lambda cs: None) == []
    assert codes(lambda cs: cs.fsm.transitions.append(Transition("counting", "nowhere", Predicate(Literal(True))))) == [
        "EARL-R032"
    ]
    assert codes(lambda cs: setattr(cs.fsm, "initial", "nope")) == ["EARL-R031"]
    assert codes(lambda cs: setattr(cs, "period", Duration(-2, "ms"))) == ["EARL-S012"]
    with pytest.raises(earl.ModelTypeError, match=r"\.period: expected Duration \| None, got float 0\.002"):
        codes(lambda cs: setattr(cs, "period", 0.002))
    assert codes(lambda cs: setattr(cs.fsm.transitions[0], "priority", "1")) == ["EARL-R033"]


def test_earl_check_is_reached_from_import_earl_alone() -> None:
    """The docs write `earl.check.check(system)`; a fresh `import earl` must reach it (loaded on first use)."""
    code = (
        "import sys, earl\n"
        "assert 'earl.check' not in sys.modules\n"
        "print(len(earl.check.check(earl.load(sys.argv[1]))) >= 0)\n"
    )
    example = Path(__file__).parent.parent / "examples" / "pick_and_place"
    result = subprocess.run([sys.executable, "-c", code, str(example)], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "True"


def test_an_override_of_an_imported_parameter_is_not_printed_as_if_it_held() -> None:
    """`to_earl()` prints the root file; an override of a parameter of an imported file would be lost
    on reading the text back, so it is refused; an override of the root file's own parameter prints."""
    examples = Path(__file__).parent.parent / "examples"
    with pytest.raises(ValueError, match=r"`SECTORS`, given another value, is declared in .*types\.earl"):
        earl.load(examples / "mobile_robot", {"SECTORS": 16}).to_earl()
    edited = earl.load(examples / "mobile_robot")
    assert edited.to_earl()  # as read: printed, with its import
    next(p for p in edited.parameters if p.name == "SECTORS").value = Literal(16)
    with pytest.raises(ValueError, match="`SECTORS`, given another value"):
        edited.to_earl()
    assert "param N: int = 3" in earl.load(examples / "pick_and_place", {"N": 3}).to_earl()


def test_a_value_of_the_wrong_type_in_a_model_built_in_python_is_named_where_it_is() -> None:
    """`tc = Literal(True)` where a Predicate belongs, `data_type="boolean"`, a state naming its behaviour
    by an ElementReference: the printer and the checker say which value, not `'Literal' object has no
    attribute 'expression'` from deep inside."""
    from earl.check import check
    from earl.model.expressions import ElementReference, Literal
    from earl.model.kinds import Kind
    from earl.model.validate import ModelTypeError

    def counter() -> Any:
        system = earl.load(Path(__file__).parent / "runtime_specs" / "counter")
        return system, system.agent("counter").control_subsystem

    system, cs = counter()
    cs.basic_behaviours[0].terminal_condition = Literal(True)
    with pytest.raises(ModelTypeError, match=r"\.basic_behaviours\[0\]\.terminal_condition: expected Predicate"):
        system.to_earl()
    system, cs = counter()
    cs.memories[0].data_type = "int"
    with pytest.raises(ModelTypeError, match=r'\.memories\[0\]\.data_type: .*write `PrimitiveType\("int"\)`'):
        system.to_earl()
    system, cs = counter()
    cs.fsm.states[0].behaviour = ElementReference("count", Kind.BASIC_BEHAVIOUR)
    with pytest.raises(ModelTypeError, match=r"\.fsm\.states\[0\]\.behaviour: expected str, got ElementReference"):
        check(system)
    system, cs = counter()
    cs.fsm.initial = None  # printed, it would read `initial None`: another spec
    with pytest.raises(ModelTypeError, match=r"\.fsm\.initial: expected str, got NoneType"):
        system.to_earl()
    system, _ = counter()
    system.links.append("x")  # would be left out of the text without a word
    with pytest.raises(ModelTypeError, match=r"system\.links\[0\]: expected Link, got str"):
        system.to_earl()
    system, _ = counter()
    assert system.to_earl() and not [d for d in check(system) if d.severity.name == "ERROR"]


def test_a_data_type_given_as_a_string_in_python_is_said_where_it_is_declared() -> None:
    from earl.check import check

    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    buffer = system.agent("manip").control_subsystem.input_buffers[0]  # type: ignore[union-attr]
    buffer.data_type = "ManipulatorCommand"  # type: ignore[assignment]
    first = check(system)[0]
    assert first.code == "EARL-R012" and first.message == "`ManipulatorCommand` is not a data type"
    assert first.hint == 'write `PrimitiveType("ManipulatorCommand")` or `TypeReference("ManipulatorCommand")`'
    assert first.location == buffer.location


def test_cycles_are_found_in_one_walk_each_once_from_where_the_walk_returns() -> None:
    from earl.model.graphs import cycles

    graph = {"a": ["b", "c"], "b": ["a"], "c": ["a", "d"], "d": [], "e": ["e"]}
    assert list(cycles(graph, graph.__getitem__)) == [["a", "b"], ["a", "c"], ["e"]]
    chain = {f"n{i}": [f"n{i + 1}"] for i in range(20_000)} | {"n20000": ["n0"]}
    [cycle] = cycles(chain, chain.__getitem__)  # no recursion, and no walk from each node in turn
    assert len(cycle) == 20_001 and cycle[0] == "n0"


def test_the_digest_of_a_system_follows_equality_and_is_the_same_in_every_process() -> None:
    from earl.model.digest import model_digest

    spec = Path(__file__).parent.parent / "examples" / "pick_and_place" / "system.earl"
    system = earl.load(spec)
    digest = model_digest(expand(system, {}))
    assert len(digest) == 16 and int(digest, 16) >= 0
    # comments, locations and where the text was read from are no part of the system
    again = earl.loads("// a copy\n" + system.to_earl().replace("//", "// said otherwise:"), "elsewhere/system.earl")
    assert again == system and model_digest(expand(again, {})) == digest
    # numbers compare by value, as `==` does: `period 2.0 ms` is `period 2 ms`
    text = system.to_earl()
    same = earl.loads(text.replace("period 2 ms", "period 2.0 ms"))
    assert "period 2.0 ms" in same.to_earl() and same == system and model_digest(expand(same, {})) == digest
    # another parameter value, a changed period, a changed condition: another system
    assert model_digest(expand(system, {"N": 7})) != digest
    text = system.to_earl()
    for old, new in [("period 2 ms", "period 3 ms"), ("emergencyStopCommand or any", "emergencyStopCommand and any")]:
        assert old in text
        assert model_digest(expand(earl.loads(text.replace(old, new, 1)), {})) != digest, old
    # sets and dicts have no order (and str hashes differ between processes): the same digest in another one
    program = (
        "import sys, earl\nfrom earl.model.expand import expand\nfrom earl.model.digest import model_digest\n"
        "print(model_digest(expand(earl.load(sys.argv[1]), {})), model_digest({'b': {1, 'x'}, 'a': frozenset('yz')}))"
    )
    outputs = {
        subprocess.run(
            [sys.executable, "-c", program, str(spec)],
            capture_output=True,
            text=True,
            check=True,
            env={**__import__("os").environ, "PYTHONHASHSEED": seed},
        ).stdout
        for seed in ("1", "2")
    }
    assert outputs == {f"{digest} {model_digest({'a': frozenset('zy'), 'b': {'x', 1}})}\n"}


def test_the_digest_walks_a_model_nested_deeper_than_pythons_recursion_limit() -> None:
    from earl.model.digest import model_digest

    deep: object = Literal(True)
    for _ in range(sys.getrecursionlimit() * 2):
        deep = Not(deep)  # type: ignore[arg-type]
    assert model_digest(deep) != model_digest(Not(Literal(True)))


def test_an_agent_and_a_robot_are_found_by_their_name_bare_or_with_their_kind() -> None:
    import earl

    system = earl.load(Path(__file__).parent.parent / "examples" / "pick_and_place")
    assert system.agent("manip/a") is system.agent("manip") is not None
    assert system.agent("manip/r") is None and system.agent("nobody/a") is None
    robot = system.robots[0]
    assert system.robot(f"{robot.name}/r") is system.robot(robot.name) is robot


def test_a_list_where_a_class_declares_a_tuple_or_the_reverse_is_the_same_model_as_read_back() -> None:
    """Every part of earl reads a list or a tuple alike, but a model built with the other one never equalled
    itself read back from its text (`load(save(m)) != m`), and a frozen expression holding a list could
    not be hashed."""
    from earl.model import Call, ListLiteral, Star

    x = ElementReference("x", Kind.INPUT_BUFFER)
    assert BooleanOperation("and", [Literal(True), Literal(False)]) == BooleanOperation(
        "and", (Literal(True), Literal(False))
    )
    assert ListLiteral([Literal(1.0)]) == ListLiteral((Literal(1.0),))
    assert hash(Call("newData", [Read(x)])) == hash(Call("newData", (Read(x),)))
    assert Read(x, [earl.FieldAccess("f")]) == Read(x, (earl.FieldAccess("f"),))
    assert ElementReference("x", "mo", [Star()]) == ElementReference("x", Kind.MEMORY_OUTPUT, (Star(),))
    system = earl.load(EXAMPLE)
    read_back = earl.loads(system.to_earl())
    assert system == read_back
    system.agents = tuple(system.agents)  # type: ignore[assignment]
    system.links[0].name = list(system.links[0].name)  # type: ignore[assignment]
    control = system.agents[0].control_subsystem
    assert control is not None
    behaviour = control.basic_behaviours[0]
    behaviour.transition_function.stages = tuple(tuple(stage) for stage in behaviour.transition_function.stages)  # type: ignore[assignment]
    control.partial_transition_functions[0].reads = tuple(control.partial_transition_functions[0].reads)  # type: ignore[assignment]
    assert system == read_back and read_back == system
    assert earl.loads(system.to_earl()) == system
    # what differs still differs
    behaviour.transition_function.stages = [*behaviour.transition_function.stages, []]
    assert system != read_back


def test_literals_of_different_types_are_different_though_python_takes_true_for_1() -> None:
    """`Literal(True) == Literal(1)` held (Python's `True == 1`): a Boolean predicate and a number one, which
    check tells apart, were the same model, and one could stand for the other in a cache."""
    for left, right in [(True, 1), (0, False), (1, 1.0), (1.0, True)]:
        assert Literal(left) != Literal(right)
        assert len({Literal(left), Literal(right)}) == 2
    assert Literal(2) == Literal(2) and hash(Literal("a")) == hash(Literal("a"))
    system = earl.load(EXAMPLE)
    text = system.to_earl()
    assert "= false\n" in text
    other = earl.loads(text.replace("= false\n", "= 0\n", 1))
    assert other != system
