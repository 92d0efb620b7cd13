"""Builds model elements while Lark's LALR parser reduces, without a parse tree in between.

Lark can apply a transformer during an LALR parse (its `transformer=` option), but then
it gives the transformer no positions, and building a tree only to walk it again costs
more than the parse itself.  This module replaces the callbacks Lark made for every
rule of `earl.lark` with ones that do what Lark's tree builder would have done — drop
the anonymous tokens (`{`, `->`, keywords), splice the children of `_inlined` rules,
pass the single child of a `?rule` through — and in addition measure the span of text
each rule covered, the way `propagate_positions` does, and hand both to the
`ElementBuilder` method named after the rule.

The grammar stays the only description of the language: which symbols a callback keeps
comes from the rules Lark compiled from `earl.lark`.
"""

from __future__ import annotations

from collections.abc import Callable
from operator import itemgetter
from typing import Any

from lark import Token
from lark.grammar import Rule

#: (line, column, end line, end column) of the text a rule covered; None for an empty rule.
Span = tuple[int, int, int, int]


#: the callback of a rule whose one child is its value (`?sum: product`); a parser loop that
#: knows it may leave the value where it is on the stack
PASS_THROUGH: Callable[[list[Any]], Any] = itemgetter(0)


class Inline(list[Any]):
    """The children of an `_inlined` rule, spliced into its parent's children."""

    __slots__ = ()


class SpanTable:
    """The span of every value on the parser's stack that is not a token, keyed by identity.

    A value's entry is removed when its parent rule is reduced, so the table holds only
    what is still on the stack, never the whole file.
    """

    def __init__(self) -> None:
        self.spans: dict[int, Span | None] = {}

    def clear(self) -> None:
        self.spans.clear()

    def span(self, raw: list[Any]) -> Span | None:
        """From the first position among `raw` to the last, as Lark's `propagate_positions` measures."""
        spans = self.spans
        start: tuple[int, int] | None = None
        for value in raw:
            if type(value) is Token:
                start = (value.line, value.column)  # type: ignore[assignment]
                break
            found = spans.get(id(value))
            if found is not None:
                start = (found[0], found[1])
                break
        if start is None:
            return None
        for value in reversed(raw):
            if type(value) is Token:
                return (start[0], start[1], value.end_line, value.end_column)  # type: ignore[return-value]
            found = spans.get(id(value))
            if found is not None:
                return (start[0], start[1], found[2], found[3])
        return None  # pragma: no cover - a start was found, so an end is too


class _IdentityRule(Rule):
    """A rule of this parser's own table, equal only to itself."""

    __slots__ = ()
    __hash__ = object.__hash__
    __eq__ = object.__eq__
    __ne__ = object.__ne__


def install(parser: Any, builder: Any, table: SpanTable) -> None:
    """Replace Lark's tree-building callback of every rule by one that calls `builder`.

    `parser` is Lark's LALR parser object (holding `callbacks` and `parse_table`).  The new
    table of callbacks is keyed by the very rule objects of the parse table: a grammar
    loaded from Lark's cache has equal but distinct copies, and every lookup would then
    fall back to comparing rules in Python.
    """
    old: dict[Any, Callable[[list[Any]], Any]] = parser.callbacks
    callbacks: dict[Any, Callable[[list[Any]], Any]] = {k: v for k, v in old.items() if isinstance(k, str)}
    for actions in parser.parse_table.states.values():
        for _action, argument in actions.values():
            if isinstance(argument, Rule) and not isinstance(argument, _IdentityRule):
                original = old[argument]
                # The parser looks its rule up at every reduction; Lark's Rule hashes and
                # compares in Python, an identity rule in C.  The layout is the same.
                argument.__class__ = _IdentityRule
                callbacks.setdefault(argument, original)
    missing: list[str] = []
    for rule in list(callbacks):
        if isinstance(rule, str):
            continue  # a terminal's lexer callback, not a rule
        callback = _callback(rule, builder, table)
        if callback is None:
            missing.append(rule.alias or rule.origin.name)
            continue
        callbacks[rule] = callback
    if missing:
        raise RuntimeError(f"ElementBuilder has no method for the grammar rules {sorted(set(missing))}")
    parser.callbacks = callbacks


def _callback(rule: Any, builder: Any, table: SpanTable) -> Callable[[list[Any]], Any] | None:
    name = rule.alias or rule.options.template_source or rule.origin.name
    keep_all = bool(rule.options.keep_all_tokens)
    kept: list[tuple[int, bool]] = []  # (position in the expansion, splice it?)
    for position, symbol in enumerate(rule.expansion):
        if symbol.is_term:
            if keep_all or not symbol.filter_out:
                kept.append((position, False))
        else:
            kept.append((position, symbol.name.startswith("_")))
    inline = rule.origin.name.startswith("_")
    expand_single = bool(rule.options.expand1) and not rule.alias  # as Lark's tree builder decides
    spans = table.spans
    measure = table.span

    if expand_single and len(rule.expansion) == 1 and kept and not kept[0][1]:
        # `?sum: product`: the one child is the result, span and all.
        return PASS_THROUGH

    method: Callable[[Span | None, list[Any]], Any] | None = None
    always_single = expand_single and len(kept) == 1 and not kept[0][1]
    if not inline and not always_single:
        method = getattr(builder, name, None)
        if method is None:
            return None

    splice = any(s for _, s in kept)
    positions = tuple(p for p, _ in kept)
    every = positions == tuple(range(len(rule.expansion)))

    first_position, first_spliced = kept[0] if kept else (0, False)
    rest = kept[1:]

    def children_of(raw: list[Any]) -> list[Any]:
        if not splice:
            # Lark hands each reduction a fresh slice of its stack: when every symbol is kept,
            # that slice is already the list of children.
            return raw if every else [raw[p] for p in positions]
        # `x*` compiles to a left-recursive rule: extend its list in place, or a long
        # list would be copied once per element.
        children: list[Any] = raw[first_position] if first_spliced else [raw[first_position]]
        for position, spliced in rest:
            if spliced:
                children.extend(raw[position])
            else:
                children.append(raw[position])
        return children

    def reduce(raw: list[Any]) -> Any:
        if not raw:
            return method(None, []) if method is not None else Inline()
        # The span, from the first and last values when both have one (nearly always).
        first = raw[0]
        last = raw[-1]
        start: Any = first if type(first) is Token else spans.pop(id(first), None)
        finish: Any = start if last is first else last if type(last) is Token else spans.pop(id(last), None)
        span: Any  # Span | None; Lark types a token's positions as optional
        inner: Any = raw  # the values whose spans may still be in the table
        if start is None or finish is None:
            # Put back what was taken (one of them has no span); `measure` looks further in.
            if type(first) is not Token:
                spans[id(first)] = start
            if type(last) is not Token:
                spans[id(last)] = finish
            span = measure(raw)
        else:
            inner = raw[1:-1] if len(raw) > 2 else ()  # the first and the last were taken out above
            if type(start) is Token:
                if type(finish) is Token:
                    span = (start.line, start.column, finish.end_line, finish.end_column)
                else:
                    span = (start.line, start.column, finish[2], finish[3])
            elif type(finish) is Token:
                span = (start[0], start[1], finish.end_line, finish.end_column)
            else:
                span = (start[0], start[1], finish[2], finish[3])
        children = children_of(raw)
        if expand_single and len(children) == 1:
            # `?atom: "(" expression ")"` passes its child through; like Lark's "container", the
            # child's span then covers the parentheses too, for the span of whatever holds it.
            only = children[0]
            if type(only) is not Token:
                spans[id(only)] = span
            return only
        for value in inner:
            if type(value) is not Token:
                spans.pop(id(value), None)
        result: Any = (
            (Inline(children) if type(children) is not Inline else children)
            if method is None
            else method(span, children)
        )
        if type(result) is not Token:
            spans[id(result)] = span
        return result

    return reduce


__all__ = ["PASS_THROUGH", "Inline", "Span", "SpanTable", "install"]
