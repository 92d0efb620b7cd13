"""A quicker loop around Lark's contextual lexer: same scanners, same tokens, less work per token.

Lark's `ContextualLexer` compiles, for every parser state, one regular expression of
the terminals that state accepts (so `a` after `manip/` is the Agent kind while `a`
elsewhere is a name).  Its loop then spends most of its time around those matches: a
method call or two per token, a generic line counter, and a second regular-expression
match on every name to see whether it is a keyword.  This loop uses Lark's own compiled
scanners and keyword tables unchanged, and does the rest inline: the tokens it yields are
the ones Lark's loop would yield.  When no terminal matches, it hands over to Lark's loop
at the same position, so errors are Lark's own.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from lark import Token
from lark.lexer import ContextualLexer, PatternStr, UnlessCallback

_new_string = str.__new__

#: What the loop needs of one of Lark's per-state lexers: its match function, the terminals
#: that may hold a newline, the ignored terminals, keyword tables and other callbacks.
_Prepared = tuple[Callable[..., Any], frozenset[str], frozenset[str], dict[str, dict[str, str]], dict[str, Any]]


def _prepare(lexer: Any) -> _Prepared:
    scanner = lexer.scanner  # built lazily by Lark; builds its callbacks too
    matchers = tuple(expression.match for expression in scanner._mres)
    keywords: dict[str, dict[str, str]] = {}
    callbacks: dict[str, Any] = {}
    for type_, callback in lexer.callback.items():
        if isinstance(callback, UnlessCallback) and all(
            isinstance(t.pattern, PatternStr) and not t.pattern.flags for t in callback.scanner.terminals
        ):
            # A name that is exactly a keyword's text is that keyword (Lark's `_create_unless`).
            keywords[type_] = {t.pattern.value: t.name for t in callback.scanner.terminals}
        else:
            callbacks[type_] = callback
    if len(matchers) == 1:
        match = matchers[0]
    else:  # Python's `re` takes at most 100 groups, so Lark may split a scanner in several

        def match(text: str, position: int, end: int) -> Any:
            for matcher in matchers:
                found = matcher(text, position, end)
                if found is not None:
                    return found
            return None

    return (match, frozenset(lexer.newline_types), frozenset(lexer.ignore_types), keywords, callbacks)


class FastContextualLexer(ContextualLexer):
    """Lark's contextual lexer with a tighter `lex` loop (installed on an existing instance)."""

    _prepared: dict[int, _Prepared]
    _by_lexer: dict[int, _Prepared]

    @classmethod
    def adopt(cls, lexer: ContextualLexer) -> None:
        lexer.__class__ = cls
        lexer._prepared = {}  # type: ignore[attr-defined]
        lexer._by_lexer = {}  # type: ignore[attr-defined]

    def _prepare(self, state: int) -> _Prepared:
        # Lark compiles a state's scanner on first use; so does this, once per distinct scanner.
        basic = self.lexers[state]
        table = self._by_lexer.get(id(basic))
        if table is None:
            table = self._by_lexer[id(basic)] = _prepare(basic)
        self._prepared[state] = table
        return table

    def lex(self, lexer_state: Any, parser_state: Any) -> Iterator[Token]:
        prepared = self._prepared
        text: str = lexer_state.text.text
        end: int = lexer_state.text.end
        line_counter = lexer_state.line_ctr
        position: int = line_counter.char_pos
        line: int = line_counter.line
        line_start: int = line_counter.line_start_pos
        states: list[int] = parser_state.state_stack  # the same list for the whole parse
        new = _new_string
        token_class = Token
        while position < end:
            state = states[-1]
            table = prepared.get(state)
            if table is None:
                table = self._prepare(state)
            match_at, newline, ignore, keywords, callbacks = table
            match = match_at(text, position, end)
            if match is None:
                # Let Lark's own loop meet the character it cannot read and raise its error.
                line_counter.char_pos, line_counter.line = position, line
                line_counter.line_start_pos = line_start
                line_counter.column = position - line_start + 1
                yield from ContextualLexer.lex(self, lexer_state, parser_state)
                return
            value: str = match.group()
            type_: str = match.lastgroup  # type: ignore[assignment]
            start, start_line, column = position, line, position - line_start + 1
            position += len(value)
            if type_ in newline:
                newlines = value.count("\n")
                if newlines:
                    line += newlines
                    line_start = start + value.rindex("\n") + 1
            if type_ in ignore:
                if type_ in callbacks:
                    ignored = _make(type_, value, start, start_line, column, line, position - line_start + 1)
                    ignored.end_pos = position
                    callbacks[type_](ignored)
                continue
            if type_ in keywords:
                type_ = keywords[type_].get(value, type_)
            # Token's own constructor goes through two Python-level calls; its slots are public.
            token = new(token_class, value)
            token.type = type_
            token.value = value
            token.start_pos = start
            token.line = start_line
            token.column = column
            token.end_line = line
            token.end_column = position - line_start + 1
            token.end_pos = position
            yield token if type_ not in callbacks else callbacks[type_](token)
        line_counter.char_pos, line_counter.line = position, line
        line_counter.line_start_pos = line_start
        line_counter.column = position - line_start + 1


def _make(type_: str, value: str, position: int, line: int, column: int, end_line: int, end_column: int) -> Token:
    token: Token = _new_string(Token, value)
    token.type = type_
    token.value = value
    token.start_pos = position
    token.line = line
    token.column = column
    token.end_line = end_line
    token.end_column = end_column
    return token


__all__ = ["FastContextualLexer"]
