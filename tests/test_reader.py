"""The fast reader changes nothing: same tokens, same elements, same spans as Lark's own way.

The reader (earl/lang/parser.py) runs Lark's LALR parser with callbacks that build elements
as it reduces (reductions.py) and a tighter loop around Lark's contextual scanners
(lexing.py).  These tests hold it to Lark's behaviour: the spans it measures equal the
positions Lark's tree parser propagates, and Lark's own lexer loop gives the same model.
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
from earl.lang.lexing import FastContextualLexer
from earl.lang.transformer import ParsedFile

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
def test_lark_own_lexer_loop_reads_the_same_model(name: str, text: str) -> None:
    lexer = reader._element_parser().lark.parser.lexer
    fast = _parse(text)
    lexer.__class__ = ContextualLexer
    try:
        slow = _parse(text)
    finally:
        lexer.__class__ = FastContextualLexer
    assert fast.declarations == slow.declarations
    spans_fast: dict[str, list[tuple[int, int, int, int]]] = {}
    spans_slow: dict[str, list[tuple[int, int, int, int]]] = {}
    _elements(fast.declarations, spans_fast)
    _elements(slow.declarations, spans_slow)
    assert spans_fast == spans_slow


def test_a_syntax_error_is_explained_by_lark_and_the_reader_recovers() -> None:
    with pytest.raises(earl.EarlError) as caught:
        _parse("system s\n\na/a {\n    cs {\n        period 2\n    }\n}\n")
    assert caught.value.diagnostics[0].code == "EARL-S008"
    # The element parser's state is reset: the next file reads normally, from its own first line.
    parsed = _parse("system t\n\na/a {\n    cs {\n        period 2 ms\n    }\n}\n")
    assert parsed.system_name == "t"
    assert parsed.declarations[0].location.line == 3
