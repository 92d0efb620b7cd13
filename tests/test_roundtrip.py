"""The formatter and the reader agree: printing a model and reading it back gives the same model.

Generated models (tests/strategies.py) check `parse(format(m)) == m` and that
formatting is idempotent; examples check comments and the parentheses of expressions.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings

from earl.cli.main import main
from earl.diagnostics import SourceMap
from earl.lang.loader import merge
from earl.lang.parser import keyword_terminals, parse_text
from earl.model import (
    Agent,
    Arithmetic,
    BooleanOperation,
    Comparison,
    ControlSubsystem,
    Expression,
    Literal,
    Name,
    Negate,
    Not,
    PrimitivePredicate,
    Robot,
    System,
)
from earl.model.expressions import ElementReference, Read
from earl.model.kinds import Kind
from earl.model.location import Comments
from earl.model.text import expression_text, literal_text
from strategies import (
    KEYWORDS,
    comment_carriers,
    commented_systems,
    expression_systems,
    expressions,
    systems,
)

# Whole models are large and drawing them costs far more than reading them (four fifths of the
# time); 75 each keep this file under a minute on two shared cores.
MODELS = settings(max_examples=75, deadline=None, suppress_health_check=[HealthCheck.too_slow])
EXPRESSIONS = settings(max_examples=400, deadline=None)


def parse(text: str) -> System:
    """The syntax of one file as a System, names unresolved (what `earl fmt` reads)."""
    sources = SourceMap()
    return merge(parse_text(text, "<generated>", sources), [], sources, library=True)


def structure(value: Any) -> Any:
    """The compared content of a model with every value's type, so `1`, `1.0` and `true` differ.

    Dataclass equality says `Literal(1) == Literal(True) == Literal(1.0)`; a formatter that
    printed one for another would pass `==` but not this.
    """
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (
            type(value).__name__,
            tuple((f.name, structure(getattr(value, f.name))) for f in dataclasses.fields(value) if f.compare),
        )
    if isinstance(value, list | tuple):
        return (type(value).__name__, tuple(structure(item) for item in value))
    return (type(value).__name__, value)


def assert_same_model(read: System, written: System) -> None:
    assert read == written
    assert structure(read) == structure(written)


# ---------------------------------------------------------------------- properties
@MODELS
@given(systems())
def test_a_formatted_model_reads_back_as_the_same_model(system: System) -> None:
    text = system.to_earl()
    assert_same_model(parse(text), system)


@MODELS
@given(systems())
def test_formatting_is_idempotent(system: System) -> None:
    text = system.to_earl()
    assert parse(text).to_earl() == text


@EXPRESSIONS
@given(expressions(max_leaves=20))
def test_an_expression_reads_back_as_the_same_tree(expression: Expression) -> None:
    system = expression_systems(expression)
    read = parse(system.to_earl())
    assert_same_model(read, system)
    assert expression_text(read.agents[0].subsystems[0].primitive_predicates[0].expression) == expression_text(
        expression
    )


@MODELS
@given(commented_systems())
def test_comments_stay_with_their_elements(system: System) -> None:
    text = system.to_earl()
    read = parse(text)
    assert_same_model(read, system)
    assert read.comments.leading == system.comments.leading
    assert read.comments.closing == system.comments.closing
    for written, kept in zip(comment_carriers(system), comment_carriers(read), strict=True):
        assert (kept.comments.leading, kept.comments.trailing, kept.comments.after) == (
            written.comments.leading,
            written.comments.trailing,
            written.comments.after,
        ), type(written).__name__
    # a robot's members and a basic behaviour's clauses keep theirs in a table of their owner's
    for written, kept in zip(system.order, read.order, strict=True):
        if isinstance(written, Robot):  # the reader makes a member's entry whether or not it has comments
            said = {key: comments for key, comments in kept.member_comments.items() if comments != Comments()}
            assert said == written.member_comments
        for subsystem, again in zip(getattr(written, "subsystems", []), getattr(kept, "subsystems", []), strict=True):
            for behaviour, read_back in zip(subsystem.basic_behaviours, again.basic_behaviours, strict=True):
                assert read_back.clause_comments == behaviour.clause_comments
    assert read.to_earl() == text


def test_the_strategies_avoid_every_keyword_of_the_grammar() -> None:
    assert set(keyword_terminals().values()) == KEYWORDS


# ---------------------------------------------------------------------- examples: parentheses
def p(name: str) -> Read:
    return Read(ElementReference(name, Kind.PRIMITIVE_PREDICATE))


a, b, c = Name("a"), Name("b"), Name("c")


@pytest.mark.parametrize(
    ("expression", "text"),
    [
        (Not(BooleanOperation("and", (p("a"), p("b")))), "not (a/pp and b/pp)"),
        (Comparison("==", Not(p("a")), p("b")), "(not a/pp) == b/pp"),
        (Not(Comparison("==", p("a"), p("b"))), "not a/pp == b/pp"),
        (Not(Not(p("a"))), "not not a/pp"),
        (Arithmetic("-", a, Arithmetic("-", b, c)), "a - (b - c)"),
        (Arithmetic("-", Arithmetic("-", a, b), c), "a - b - c"),
        (Arithmetic("*", Arithmetic("+", a, b), c), "(a + b) * c"),
        (Arithmetic("+", a, Arithmetic("*", b, c)), "a + b * c"),
        (Negate(Literal(1)), "-(1)"),
        (Literal(-1), "-1"),
        (Negate(Literal(-1)), "-(-1)"),
        (Negate(a), "-a"),
        (Negate(Negate(a)), "-(-a)"),
        (Negate(Arithmetic("*", a, b)), "-(a * b)"),
        (Arithmetic("*", Negate(a), b), "-a * b"),
        (Arithmetic("-", a, Literal(-1)), "a - -1"),
        (Arithmetic("-", a, Negate(b)), "a - -b"),
        (BooleanOperation("or", (BooleanOperation("or", (p("a"), p("b"))), p("c"))), "(a/pp or b/pp) or c/pp"),
        (BooleanOperation("and", (p("a"), BooleanOperation("or", (p("b"), p("c"))))), "a/pp and (b/pp or c/pp)"),
        (BooleanOperation("or", (p("a"), BooleanOperation("and", (p("b"), p("c"))))), "a/pp or b/pp and c/pp"),
        (Comparison("<", Comparison("<", a, b), c), "(a < b) < c"),
        (Comparison("==", Arithmetic("+", a, b), Negate(c)), "a + b == -c"),
        (Arithmetic("+", a, Not(b)), "a + (not b)"),
    ],
)
def test_the_expression_printer_uses_the_fewest_correct_parentheses(expression: Expression, text: str) -> None:
    assert expression_text(expression) == text
    read = parse(expression_systems(expression).to_earl())
    assert read.agents[0].subsystems[0].primitive_predicates[0].expression == expression


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (1.5e-07, "1.5e-07"),
        (1e16, "1e+16"),
        (float("inf"), "1e999"),
        (float("-inf"), "-1e999"),
        ('say "hi"\\\n', '"say \\"hi\\"\\\\\\n"'),
        ("ünïcödé 🤖", '"ünïcödé 🤖"'),
    ],
)
def test_literals_are_written_so_they_read_back(value: float | str, text: str) -> None:
    assert literal_text(value) == text
    read = parse(expression_systems(Literal(value)).to_earl())
    assert read.agents[0].subsystems[0].primitive_predicates[0].expression == Literal(value)


def test_a_number_the_language_cannot_write_is_refused() -> None:
    with pytest.raises(ValueError, match="nan"):
        literal_text(float("nan"))


def test_keyword_names_of_primitive_predicates_are_kept() -> None:
    control = ControlSubsystem(
        primitive_predicates=[PrimitivePredicate("false", Literal(False)), PrimitivePredicate("true", p("false"))]
    )
    agent = Agent("a", subsystems=[control])
    system = System("s", agents=[agent], order=[agent])
    text = system.to_earl()
    assert "false/pp = false\n" in text
    assert "true/pp = false/pp\n" in text
    assert parse(text) == system


# ---------------------------------------------------------------------- examples: comments
COMMENTED = """\
// header: what this system is
system demo // the name
param N: int = 3   // joints

// Types shared by both agents.

// The command.
struct Cmd {
    stop: boolean // stop now
    // where to go
    pos: double[N]?
}
manip/a { // the manipulator
    // its control subsystem
    cs {
        period 2 ms
        cmd/ib: Cmd   // from the task agent
        // done when the command stopped
        done/pp = cmd/ib.stop
        fsm {
            initial idle
            // the only state
            state idle: idle/bb
            * -> idle when done/pp  // always
        }
    }
}
// the end

// really the end
"""

COMMENTED_CANONICAL = """\
// header: what this system is
// the name
system demo

param N: int = 3  // joints

// Types shared by both agents.

// The command.
struct Cmd {
    stop: boolean  // stop now
    // where to go
    pos: double[N]?
}

manip/a {  // the manipulator
    // its control subsystem
    cs {
        period 2 ms

        cmd/ib: Cmd  // from the task agent

        // done when the command stopped
        done/pp = cmd/ib.stop

        fsm {
            initial idle
            // the only state
            state idle: idle/bb

            * -> idle when done/pp  // always
        }
    }
}

// the end

// really the end
"""


def test_fmt_keeps_leading_trailing_header_and_closing_comments(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "commented.earl"
    spec.write_text(COMMENTED, encoding="utf-8")
    assert main(["fmt", str(spec)]) == 0
    assert capsys.readouterr().out == COMMENTED_CANONICAL
    spec.write_text(COMMENTED_CANONICAL, encoding="utf-8")
    assert main(["fmt", "--check", str(spec)]) == 0


def test_comment_text_loses_trailing_space_and_carriage_returns() -> None:
    text = "system demo\r\n// above   \r\nparam N: int = 1 // after\t\r\n"
    assert parse(text).to_earl() == "system demo\n\n// above\nparam N: int = 1  // after\n"


def test_a_library_file_keeps_its_first_comment_above_its_first_declaration() -> None:
    text = "// shared types\n\nstruct A {}\n"
    system = parse(text)
    assert system.name == ""
    assert system.types[0].comments.leading == ["// shared types", ""]
    assert system.to_earl() == text


def test_declarations_reordered_in_python_after_reading_are_saved_in_their_new_order() -> None:
    """The order read from the file keeps how kinds interleave (a link between two agents stays there), but
    within a list the list's order is the one saved: reversing `system.agents` was undone by `to_earl()`."""
    text = (
        "system s\n\nparam N: int = 1\n\nstruct T {}\n\n"
        + "".join(f"{name}/a {{\n    cs {{\n        period 1 ms\n    }}\n}}\n\n" for name in ("a", "b"))
        + "link a,b: a/a.cs.x -> b/a.cs.x\n\nc/a {\n    cs {\n        period 1 ms\n    }\n}\n"
    )
    system = parse(text)
    assert system.to_earl() == text
    system.agents.reverse()
    written = system.to_earl()
    assert [agent.name for agent in parse(written).agents] == ["c", "b", "a"]
    assert written.index("b/a") < written.index("link a,b") < written.index("a/a {")
    assert parse(written) == system
