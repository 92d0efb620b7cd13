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

from collections.abc import Iterator
from typing import Any

from lark import Token
from lark.lexer import ContextualLexer, PatternStr, UnlessCallback

_new_string = str.__new__


class _Prepared:
    """What the loop needs of one of Lark's per-state lexers, looked up once."""

    __slots__ = ("callbacks", "ignore", "keywords", "matchers", "newline")

    def __init__(self, lexer: Any) -> None:
        scanner = lexer.scanner  # built lazily by Lark; builds its callbacks too
        self.matchers = tuple(expression.match for expression in scanner._mres)
        self.ignore = lexer.ignore_types
        self.newline = lexer.newline_types
        self.keywords: dict[str, dict[str, str]] = {}
        self.callbacks: dict[str, Any] = {}
        for type_, callback in lexer.callback.items():
            if isinstance(callback, UnlessCallback) and all(
                isinstance(t.pattern, PatternStr) and not t.pattern.flags for t in callback.scanner.terminals
            ):
                # A name that is exactly a keyword's text is that keyword (Lark's `_create_unless`).
                self.keywords[type_] = {t.pattern.value: t.name for t in callback.scanner.terminals}
            else:
                self.callbacks[type_] = callback


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
            table = self._by_lexer[id(basic)] = _Prepared(basic)
        self._prepared[state] = table
        return table

    def lex(self, lexer_state: Any, parser_state: Any) -> Iterator[Token]:
        prepared = self._prepared
        line_counter = lexer_state.line_ctr
        text: str = lexer_state.text.text
        end: int = lexer_state.text.end
        position: int = line_counter.char_pos
        line: int = line_counter.line
        line_start: int = line_counter.line_start_pos
        states: list[int] = parser_state.state_stack  # the same list for the whole parse
        while position < end:
            state = states[-1]
            table = prepared.get(state) or self._prepare(state)
            match = None
            for matcher in table.matchers:
                match = matcher(text, position, end)
                if match is not None:
                    break
            if match is None:
                # Let Lark's own loop meet the character it cannot read and raise its error.
                line_counter.char_pos, line_counter.line = position, line
                line_counter.line_start_pos = line_start
                line_counter.column = position - line_start + 1
                yield from ContextualLexer.lex(self, lexer_state, parser_state)
                return
            value = match.group()
            type_: str = match.lastgroup  # type: ignore[assignment]
            column = position - line_start + 1
            next_position = position + len(value)
            end_line = line
            if type_ in table.newline:
                newlines = value.count("\n")
                if newlines:
                    end_line = line + newlines
                    line_start = position + value.rindex("\n") + 1
            if type_ in table.ignore:
                if type_ in table.callbacks:
                    token = _token(type_, value, position, line, column, end_line, next_position - line_start + 1)
                    token.end_pos = next_position
                    table.callbacks[type_](token)
                position, line = next_position, end_line
                continue
            keywords = table.keywords.get(type_)
            if keywords is not None:
                type_ = keywords.get(value, type_)
            token = _token(type_, value, position, line, column, end_line, next_position - line_start + 1)
            token.end_pos = next_position
            callback = table.callbacks.get(type_)
            position, line = next_position, end_line
            # Lark's own loop state, kept current for an error raised while this token is parsed.
            line_counter.char_pos, line_counter.line = position, line
            line_counter.line_start_pos = line_start
            line_counter.column = position - line_start + 1
            lexer_state.last_token = token
            yield token if callback is None else callback(token)


def _token(type_: str, value: str, position: int, line: int, column: int, end_line: int, end_column: int) -> Token:
    # Token's own constructor goes through two Python-level calls; its slots are public.
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
