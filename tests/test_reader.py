"""The fast reader changes nothing: same tokens, same elements, same spans as Lark's own way.

The reader (earl/lang/parser.py) runs Lark's LALR tables and contextual scanners in one loop
(driver.py) with callbacks that build elements as it reduces (reductions.py).  These tests
hold it to Lark's behaviour: the spans it measures equal the positions Lark's tree parser
propagates, and Lark's own parser and lexer loops give the same model.
"""

from __future__ import annotations

import dataclasses
import re
import sys
from pathlib import Path
from typing import Any

import pytest
from lark import Tree
from lark.lexer import ContextualLexer

import earl
from earl.diagnostics import SourceMap
from earl.lang import parser as reader
from earl.lang.driver import Driver, NotWellFormed
from earl.lang.transformer import ParsedFile
from earl.model.expand import expand
from earl.model.expressions import Star
from earl.model.text import reference_text

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from generate import generate  # noqa: E402

sys.path.remove(str(ROOT / "benchmarks"))


def _texts() -> list[tuple[str, str]]:
    texts = [(str(p.relative_to(ROOT)), p.read_text(encoding="utf-8")) for p in sorted(ROOT.glob("examples/*/*.earl"))]
    reference = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    texts += [(f"language.md#{i}", block) for i, block in enumerate(re.findall(r"```earl\n(.*?)```", reference, re.S))]
    texts.append(("generated", generate(3)))
    return texts


TEXTS = _texts()

#: Grammar rules whose tree is exactly one element of the model, with that element's class.
ELEMENT_RULES = {
    "agent": "Agent",
    "robot": "Robot",
    "subsystem": "Subsystem",
    "input_buffer": "InputBuffer",
    "output_buffer": "OutputBuffer",
    "memory": "Memory",
    "primitive_predicate": "PrimitivePredicate",
    "partial_transition_function": "PartialTransitionFunction",
    "basic_behaviour": "BasicBehaviour",
    "fsm": "FSM",
    "state": "State",
    "transition": "Transition",
    "assumption": "Assumption",
    "link": "Link",
    "struct_decl": "StructType",
    "parameter": "Parameter",
}


def _elements(value: Any, found: dict[str, list[tuple[int, int, int, int]]]) -> None:
    """The span of every element of the rules above, by class name (subsystems of every kind as one)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        names = {type(value).__name__} | {base.__name__ for base in type(value).__mro__}
        for name in set(ELEMENT_RULES.values()) & names:
            location = value.location
            found.setdefault(name, []).append((location.line, location.column, location.end_line, location.end_column))
        for field in dataclasses.fields(value):
            if field.name not in ("location", "comments"):
                _elements(getattr(value, field.name), found)
    elif isinstance(value, list | tuple):
        for item in value:
            _elements(item, found)


def _parse(text: str) -> ParsedFile:
    return reader.parse_text(text, "spec.earl", SourceMap())


@pytest.mark.parametrize(("name", "text"), TEXTS, ids=[name for name, _ in TEXTS])
def test_element_spans_equal_the_positions_of_lark_trees(name: str, text: str) -> None:
    tree = reader._parser().parse(text)
    expected: dict[str, list[tuple[int, int, int, int]]] = {}
    for rule, element in ELEMENT_RULES.items():
        for subtree in tree.iter_subtrees_topdown():
            if isinstance(subtree, Tree) and subtree.data == rule:
                meta = subtree.meta
                expected.setdefault(element, []).append((meta.line, meta.column, meta.end_line, meta.end_column))
    found: dict[str, list[tuple[int, int, int, int]]] = {}
    _elements(_parse(text).declarations, found)
    assert expected, name
    for element, spans in expected.items():
        assert sorted(found.get(element, [])) == sorted(spans), element


@pytest.mark.parametrize(("name", "text"), TEXTS, ids=[name for name, _ in TEXTS])
def test_the_loop_with_lark_s_own_tree_callbacks_builds_lark_s_tree(name: str, text: str) -> None:
    """The loop is Lark's parse, whatever its callbacks build: with the tree parser's, Lark's tree."""
    tree_parser = reader._parser()
    assert Driver(tree_parser).read(text) == tree_parser.parse(text)


def test_the_benchmark_s_loop_alone_walks_every_text_and_builds_nothing() -> None:
    """bench_parse's "loop alone" (the model's share is what a read costs beyond it) must walk the
    whole text the reader walks: a text the loop cannot read raises, so a short walk cannot pass."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from bench_parse import loop_alone
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    loop = loop_alone()
    for name, text in TEXTS:
        assert loop.read(text) is None, name
    with pytest.raises(NotWellFormed):
        loop.read(TEXTS[0][1] + "\n}")


def _not_well_formed(text: str) -> Any:
    """The loop giving up at once: the reader then parses with Lark's own loop."""
    raise NotWellFormed(0)


def _comments(parsed: ParsedFile) -> list[tuple[int, int, list[str], str | None]]:
    return sorted(
        (e.location.line, e.location.column, list(e.comments.leading), e.comments.trailing)
        for e in reader._statements(parsed.declarations)
    )


def _assert_lark_s_loops_read_the_same(text: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The reader's one loop (driver.py) against Lark's own parser and lexer loops: model, spans, comments."""
    element_parser = reader._element_parser()
    fast = _parse(text)
    monkeypatch.setattr(element_parser.driver, "read", _not_well_formed)  # the fallback: Lark's own loops
    assert type(element_parser.lark.parser.lexer) is ContextualLexer
    slow = _parse(text)
    assert fast.declarations == slow.declarations
    spans_fast: dict[str, list[tuple[int, int, int, int]]] = {}
    spans_slow: dict[str, list[tuple[int, int, int, int]]] = {}
    _elements(fast.declarations, spans_fast)
    _elements(slow.declarations, spans_slow)
    assert spans_fast == spans_slow and spans_fast
    assert _comments(fast) == _comments(slow)
    assert (fast.header_comments, fast.closing_comments) == (slow.header_comments, slow.closing_comments)


@pytest.mark.parametrize(("name", "text"), TEXTS, ids=[name for name, _ in TEXTS])
def test_lark_own_loops_read_the_same_model(name: str, text: str, monkeypatch: pytest.MonkeyPatch) -> None:
    _assert_lark_s_loops_read_the_same(text, monkeypatch)


@pytest.mark.parametrize(
    "text",
    [
        "system s\r\n\r\na/a {\r\n    cs { period 2 ms }\r\n}\r\n",  # Windows line ends
        "system s\n\na/a {\n    cs { period 2 ms }\n}\n   \n\t\n",  # blank lines and tabs at the end
        "system s\na/a { cs { period 2 ms } } // the last line, a comment, no newline",
        "\n\n   system s\n\n\n\na/a {\n\n\n    cs { period 2 ms }\n}",  # whitespace first, no final newline
    ],
)
def test_the_loop_reads_whitespace_and_comments_anywhere_as_lark_does(
    text: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    _assert_lark_s_loops_read_the_same(text, monkeypatch)


def test_a_text_the_loop_cannot_read_gets_lark_s_error_from_the_same_spot() -> None:
    """Each malformed spec fails in the loop first; the error the user sees comes from Lark's own parse."""
    element_parser = reader._element_parser()
    for text, code, line, column in [
        ("system s\n\na/a {\n    cs {\n        period 2\n    }\n}\n", "EARL-S008", 5, 16),  # no action for `}`
        ("system s\n\na/a {\n    cs { period 2 ms } §\n}\n", "EARL-S001", 4, 24),  # no terminal matches `§`
    ]:
        with pytest.raises(NotWellFormed):
            element_parser.driver.read(text)
        with pytest.raises(earl.EarlError) as caught:
            _parse(text)
        diagnostic = caught.value.diagnostics[0]
        assert diagnostic.location is not None
        assert (diagnostic.code, diagnostic.location.line, diagnostic.location.column) == (code, line, column)
    assert _parse("system t\n\na/a {\n    cs {\n        period 2 ms\n    }\n}\n").system_name == "t"


def test_a_syntax_error_is_explained_by_lark_and_the_reader_recovers() -> None:
    with pytest.raises(earl.EarlError) as caught:
        _parse("system s\n\na/a {\n    cs {\n        period 2\n    }\n}\n")
    assert caught.value.diagnostics[0].code == "EARL-S008"
    # The element parser's state is reset: the next file reads normally, from its own first line.
    parsed = _parse("system t\n\na/a {\n    cs {\n        period 2 ms\n    }\n}\n")
    assert parsed.system_name == "t"
    assert parsed.declarations[0].location.line == 3


def test_a_real_parameter_computed_from_a_family_index_is_in_scope_with_one_value_per_member() -> None:
    """`param GAIN: double = 0.5 * ID` (ID itself `= K`): a predicate and an initial value may use it;
    expanded, each member has its own value; a member whose value does not fit the type is refused."""
    text = """\
system gains

arm/a {
    joint[K in 1..2]/ve {
        period 1 ms
        param ID: int = K
        param GAIN: double = 0.5 * ID
        param OFFSET: double = 0.25 * K
        x/ib: double
        m/m: double = GAIN
        far/pp = x/ib > GAIN and x/ib < OFFSET
    }
}
"""
    from earl.model.expand import expand

    expanded = expand(earl.loads(text, "gains.earl"))
    members = [s for s in expanded.agents[0].subsystems]
    assert [(s.index, s.memories[0].initial_value.value) for s in members] == [(1, 0.5), (2, 1.0)]  # type: ignore[union-attr]
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text.replace("param OFFSET: double = 0.25 * K", "param OFFSET: string = K"), "gains.earl")
    (problem,) = refused.value.diagnostics
    assert problem.code == "EARL-R005" and "where K = 1" in problem.message
    # a whole number, a Boolean or a string computed from a real that differs per member
    for declared in ("param H: int = GAIN * 2", "param B: boolean = GAIN"):
        with pytest.raises(earl.EarlError) as refused:
            earl.loads(
                text.replace(
                    "        param OFFSET: double = 0.25 * K\n",
                    f"        param OFFSET: double = 0.25 * K\n        {declared}\n",
                ),
                "gains.earl",
            )
        (problem,) = refused.value.diagnostics
        assert problem.code == "EARL-R005" and "computed from `GAIN`, a `double`" in problem.message


def test_an_undeclared_false_pp_says_how_to_declare_it_or_to_write_the_constant() -> None:
    text = """\
system f

a/a {
    cs {
        period 1 ms
        x/m: int = 0
        f/pf(x/mi -> x/mo)
        run/bb {
            tf = {f/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}
"""
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "f.earl")
    (problem,) = refused.value.diagnostics
    assert problem.code == "EARL-R022"
    assert problem.hint == "declare `false/pp = false`, or write the constant itself: `false`"


def test_a_reversed_link_end_is_said_to_be_reversed_before_a_similar_name_is_suggested() -> None:
    """`eyes` is an Output Buffer of the destination, and it has an Input Buffer `eye`: the link runs the
    wrong way, which says more than "did you mean eye?"."""
    text = """\
system r

a/a {
    cs {
        out/ob: double
    }
    d/vr {
        eye/ib: double
        eyes/ob: double
    }
    link cs,d: cs.out -> d/vr.eyes
}
"""
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "r.earl")
    (problem,) = [d for d in refused.value.diagnostics if d.code == "EARL-R054"]
    assert problem.hint == "`eyes` is an Output Buffer there; a link runs from an Output Buffer to an Input Buffer"


_ROBOT_OF_WORKERS = """\
system crew

param N: int = 3

r1/r {
    MEMBERS
}

worker[K in 1..N]/a {
    cs {
        period 1 ms
    }
}
"""


def test_a_robot_without_the_member_of_a_family_is_told_to_write_one_or_all() -> None:
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(_ROBOT_OF_WORKERS.replace("MEMBERS", "worker/a"), "crew.earl")
    (problem,) = refused.value.diagnostics
    assert (problem.code, problem.location.line if problem.location else None) == ("EARL-R024", 6)
    assert problem.hint == "write `worker[1]/a`, or `worker[*]/a` for every member"


def test_a_robot_holds_every_member_of_an_agent_family_with_star() -> None:
    # what the hint of EARL-R024 says is read: the model, the resolver and the expansion already took it
    system = earl.loads(_ROBOT_OF_WORKERS.replace("MEMBERS", "worker[*]/a"), "crew.earl")
    (robot,) = system.robots
    (reference,) = robot.agents
    assert isinstance(reference.indices[0], Star)
    assert "    worker[*]/a\n" in system.to_earl()
    members = [reference_text(member) for member in expand(system).robots[0].agents]
    assert members == ["worker[1]/a", "worker[2]/a", "worker[3]/a"]


_ROBOT_WITH_A_LINK_FAMILY = """\
system robotLinks

param N: int = 2

alpha/a {
    cs {
        period 10 ms
        out[K in 1..N]/ob: double
    }
}

worker[K in 1..N]/a {
    cs {
        period 10 ms
        in/ib: double
    }
}

link alpha,worker[K in 1..N]: alpha/a.cs.out[K] -> worker[K]/a.cs.in

oneRobot/r {
    alpha/a
    worker[*]/a
    LINK
}
"""


def test_a_robot_names_a_link_family_as_it_is_declared_and_holds_every_member() -> None:
    # the robot's reference was read as `alpha,worker[K]` and refused (EARL-R057) with the hint to write what
    # was written
    system = earl.loads(_ROBOT_WITH_A_LINK_FAMILY.replace("LINK", "link alpha,worker[K in 1..N]"), "links.earl")
    assert [reference.name for reference in system.robots[0].links] == ["alpha,worker[K in 1..N]"]
    assert "    link alpha,worker[K in 1..N]\n" in system.to_earl()
    assert [reference.name for reference in expand(system).robots[0].links] == ["alpha,worker[1]", "alpha,worker[2]"]
    # a single link named with a parameter is its one member, named with the parameter's value
    single = _ROBOT_WITH_A_LINK_FAMILY.replace(
        "link alpha,worker[K in 1..N]: alpha/a.cs.out[K] -> worker[K]/a.cs.in",
        "link alpha,worker[N]: alpha/a.cs.out[N] -> worker[N]/a.cs.in",
    ).replace("LINK", "link alpha,worker[N]")
    assert [reference.name for reference in expand(earl.loads(single, "one.earl")).robots[0].links] == [
        "alpha,worker[2]"
    ]
    # a member alone is told to name the family whole
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(_ROBOT_WITH_A_LINK_FAMILY.replace("LINK", "link alpha,worker[1]"), "links.earl")
    (problem,) = refused.value.diagnostics
    assert problem.code == "EARL-R057"
    assert problem.hint == "a robot names a link family whole, as it is declared: `link alpha,worker[K in 1..N]`"
    # a robot that names the family but not its agents is told so for its members (EARL-E004)
    from earl.check import check

    outside = _ROBOT_WITH_A_LINK_FAMILY.replace("LINK", "link alpha,worker[K in 1..N]").replace("    worker[*]/a\n", "")
    said = [d.message for d in check(earl.loads(outside, "links.earl")) if d.code == "EARL-E004"]
    assert said == [
        "robot `oneRobot/r` refers to link `alpha,worker[1..2]`, but `worker[1..2]/a` is not one of its agents"
    ]


def test_a_quantifier_index_that_hides_the_family_s_or_an_outer_one_is_r015() -> None:
    # inside `d[K in 1..N]/ve`, `any(K in 1..N: …)` made every `K` of its body the quantifier's, silently
    text = """\
system sh

param N: int = 2

a/a {
    cs {
        period 1 ms
        c[K in 1..N]/ob: double
    }
    d[K in 1..N]/ve {
        period 1 ms
        v[J in 1..N]/ib: double
        p/pp = any(K in 1..N: v[K]/ib > 0.0)
        q/pp = any(J in 1..N: any(J in 1..N: v[J]/ib > 0.0))
        r/pp = any(I in 1..N: v[I]/ib > 0.0)
    }
    link cs,d[K in 1..N]: cs.c[K] -> d[K]/ve.v[1]
}
"""
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "sh.earl")
    said = [
        (d.code, d.message, d.location.line, d.location.column)
        for d in refused.value.diagnostics
        if d.location is not None
    ]
    assert said == [
        ("EARL-R015", "the index `K` is already in use here", 13, 16),
        ("EARL-R015", "the index `J` is already in use here", 14, 31),
    ]


def test_a_link_whose_name_a_family_member_has_too_is_declared_twice() -> None:
    # `link cs,mc[2]` beside the family `cs,mc[K in 1..N]`: two links named `cs,mc[2]` once expanded
    text = """\
system twice

param N: int = 3

a/a {
    cs {
        period 1 ms
        c[K in 1..N]/ob: double
        special/ob: double
    }
    mc[K in 1..N]/ve {
        period 1 ms
        c/ib: double
        boost/ib: double
    }
    link cs,mc[K in 1..N]: cs.c[K] -> mc[K]/ve.c
    link cs,mc[2]: cs.special -> mc[2]/ve.boost
    link cs,mc[N + 1]: cs.special -> mc[1]/ve.boost
}
"""
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "twice.earl")
    said = [(d.code, d.message, d.location.line) for d in refused.value.diagnostics if d.location is not None]
    assert said == [
        (
            "EARL-R002",
            "link `cs,mc[2]` (a member of the family `cs,mc[K in 1..N]`) is declared twice (first declared at line 16)",
            17,
        )
    ]


def test_a_quantifier_index_named_as_a_parameter_is_said_so() -> None:
    text = (
        "system p\n\nparam I: int = 1\nparam N: int = 2\n\na/a {\n    cs {\n        period 1 ms\n"
        "        d[K in 1..N]/ib: double\n        p/pp = any(I in 1..N: d[I]/ib > 0.0)\n    }\n}\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "p.earl")
    (problem,) = refused.value.diagnostics
    assert (problem.code, problem.message) == ("EARL-R015", "the index `I` has the name of a parameter in use here")
    assert problem.hint == "give `any` another index letter: inside it, `I` would no longer be the parameter"


def test_a_link_end_of_the_wrong_kind_is_told_the_kind_declared() -> None:
    text = (
        "system lamp\n\nlamp/a {\n    cs {\n        period 1 ms\n        voltage/ob: double\n    }\n"
        "    driver/ve {\n        period 1 ms\n        voltage/ib: double\n    }\n"
        "    link cs,driver: cs.voltage -> driver/re.voltage\n}\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "lamp.earl")
    (problem,) = refused.value.diagnostics
    assert (problem.code, problem.message) == ("EARL-R053", "`lamp/a` has no subsystem `driver/re`")
    assert problem.hint == "`driver` is its Virtual Effector: write `driver/ve`"


def test_a_family_end_of_the_wrong_kind_is_told_with_its_indices() -> None:
    text = (
        "system lamp\n\nparam N: int = 2\n\nlamp/a {\n    cs {\n        period 1 ms\n        v[K in 1..N]/ob: double\n    }\n"
        "    driver[K in 1..N]/ve {\n        period 1 ms\n        voltage/ib: double\n    }\n"
        "    link cs,driver[K in 1..N]: cs.v[K] -> driver[K]/re.voltage\n}\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "lamp.earl")
    (problem,) = refused.value.diagnostics
    assert problem.hint == "`driver` is its Virtual Effector: write `driver[K]/ve`"


def test_a_quantifier_index_named_as_a_parameter_computed_per_member_is_said_so() -> None:
    # `param me: int = K` ranges as an index does; it is still a parameter
    text = (
        "system p\n\nparam N: int = 2\n\nw[K in 1..N]/a {\n    param me: int = K\n\n    cs {\n        period 1 ms\n"
        "        d[J in 1..N]/ib: double\n        p/pp = any(me in 1..N: d[me]/ib > 0.0)\n    }\n}\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "p.earl")
    (problem,) = [d for d in refused.value.diagnostics if d.code == "EARL-R015"]
    assert problem.message == "the index `me` has the name of a parameter in use here"


def test_a_robot_member_may_be_named_with_a_parameter_of_the_system() -> None:
    # `worker[N]/a` was EARL-R020, "`N` is not a parameter", though `param N` is declared
    system = earl.loads(_ROBOT_OF_WORKERS.replace("MEMBERS", "worker[N]/a"), "crew.earl")
    assert [reference_text(member) for member in expand(system).robots[0].agents] == ["worker[3]/a"]
    assert "    worker[N]/a\n" in system.to_earl()
