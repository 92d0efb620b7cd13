"""Lark's LALR parse of a well-formed spec in one loop: its contextual lexer and its parse table.

Lark parses in two layers: a generator yields each token from the contextual lexer (which
picks, for every parser state, a scanner of only the terminals that state accepts, so that
`a` after `manip/` is the Agent kind while `a` elsewhere is a name), and the parser state's
`feed_token` method shifts it, reducing on the way. Per token that is a generator resumption,
a method call, attribute chains (`rule.expansion`, `rule.origin.name`), a second regular
expression on every name to see whether it is a keyword, and, before most tokens, a whole
trip round the lexer loop for the whitespace in front of it.

`Driver.read` does the same work in one function, from the same tables: the parse table
Lark computed from `earl.lark`, the callbacks `reductions.install` put in it, and the
scanners and keyword tables of Lark's contextual lexer. Each scanner is Lark's own with
Lark's `WS` pattern allowed in front, so the whitespace before a token is read by the same
call as the token. The grammar stays the only description of the language.

The loop knows only the way forward. At the first character no terminal matches, or the
first token the table has no action for, it raises `NotWellFormed`, and the reader parses
the text again with Lark's own loops, whose errors (and their explanations in
`syntax_errors.py`) stay the only ones a user sees.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from lark import Lark, Token
from lark.lexer import PatternStr, UnlessCallback
from lark.parsers.lalr_analysis import Shift

from earl.lang.reductions import PASS_THROUGH

_new_string = str.__new__

#: What the loop needs of one of Lark's per-state lexers: its match function, the terminals
#: that may hold a newline, the ignored terminals, keyword tables and other callbacks.
Scanner = tuple[
    Callable[[str, int, int], Any], frozenset[str], frozenset[str], dict[str, dict[str, str]], dict[str, Any]
]


class NotWellFormed(Exception):
    """The text is not a spec this loop can read; Lark's own parse says why."""


def _scanner(lexer: Any, whitespace: str) -> Scanner:
    """One of Lark's per-state lexers as the loop uses it."""
    scanner = lexer.scanner  # built lazily by Lark; builds its callbacks too
    matchers: list[Callable[[str, int, int], Any]] = [
        re.compile(f"(?:{whitespace})?(?:{expression.pattern})", expression.flags).match for expression in scanner._mres
    ]
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
    match: Callable[[str, int, int], Any]
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


class Driver:
    """The loop for one `Lark` LALR parser with a contextual lexer, whose callbacks build the result."""

    def __init__(self, lark: Lark, start: str = "start") -> None:
        parser = lark.parser.parser.parser  # Lark's LALR `_Parser`: the parse table and callbacks
        self._lexers: dict[int, Any] = lark.parser.lexer.lexers  # per parser state, Lark compiles lazily
        table = parser.parse_table
        self._states: dict[int, dict[str, tuple[Any, Any]]] = table.states
        self._start_state: int = table.start_states[start]
        self._end_state: int = table.end_states[start]
        callbacks: dict[Any, Callable[[Any], Any]] = parser.callbacks
        #: what a shifted token of these types becomes on the stack (Lark's terminal callbacks)
        self._shift_callbacks = {key: value for key, value in callbacks.items() if isinstance(key, str)}
        #: per rule: how many values it pops, the nonterminal it pushes, the callback that builds it
        self._rules: dict[Any, tuple[int, str, Callable[[list[Any]], Any]]] = {}
        for actions in self._states.values():
            for action, argument in actions.values():
                if action is not Shift and argument not in self._rules:
                    size, callback = len(argument.expansion), callbacks[argument]
                    if callback is PASS_THROUGH and size != 1:  # the loop's shortcut is for one child only
                        raise ValueError(f"the rule {argument} passes its first child through, but has {size}")
                    self._rules[argument] = (size, argument.origin.name, callback)
        self._whitespace: str = lark.get_terminal("WS").pattern.to_regexp()
        self._scanners: dict[int, Scanner] = {}
        self._by_lexer: dict[int, Scanner] = {}  # states that accept the same terminals share a lexer

    def _scanner_of(self, state: int) -> Scanner:
        lexer = self._lexers[state]
        scanner = self._by_lexer.get(id(lexer))
        if scanner is None:
            scanner = self._by_lexer[id(lexer)] = _scanner(lexer, self._whitespace)
        self._scanners[state] = scanner
        return scanner

    def read(self, text: str) -> Any:
        """The value the start rule's callback built, or `NotWellFormed`."""
        states = self._states
        rules = self._rules
        shift_callbacks = self._shift_callbacks
        scanners = self._scanners
        scanner_of = self._scanner_of
        end_state = self._end_state
        new = _new_string
        token_class = Token
        shift = Shift
        pass_through = PASS_THROUGH
        state = self._start_state
        state_stack: list[int] = [state]
        value_stack: list[Any] = []
        position = 0
        line = 1
        line_start = 0
        end = len(text)
        at_end = False
        token: Any = None
        type_ = "$END"
        while True:
            if position < end:
                scanner = scanners.get(state)
                if scanner is None:
                    scanner = scanner_of(state)
                match_at, newline, ignore, keywords, lexer_callbacks = scanner
                match = match_at(text, position, end)
                if match is None:
                    raise NotWellFormed(position)
                type_ = match.lastgroup
                start = match.start(type_)
                if start != position:  # the whitespace before the token
                    newlines = text.count("\n", position, start)
                    if newlines:
                        line += newlines
                        line_start = text.rindex("\n", position, start) + 1
                value: str = match.group(type_)
                start_line, column = line, start - line_start + 1
                position = match.end()
                if type_ in newline:
                    newlines = value.count("\n")
                    if newlines:
                        line += newlines
                        line_start = start + value.rindex("\n") + 1
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
                if type_ in lexer_callbacks:
                    token = lexer_callbacks[type_](token)
                    type_ = token.type
                if type_ in ignore:
                    continue
            else:
                at_end, type_ = True, "$END"
            # reduce as long as the table says so; then shift the token, or accept at the end
            while True:
                action = states[state].get(type_)
                if action is None:
                    raise NotWellFormed(position)
                kind, argument = action
                if kind is shift:
                    if at_end:
                        raise NotWellFormed(position)
                    state = argument
                    state_stack.append(state)
                    value_stack.append(token if type_ not in shift_callbacks else shift_callbacks[type_](token))
                    break
                size, origin, callback = rules[argument]
                if callback is pass_through:  # `?sum: product`: the value stays, only the state changes
                    state = states[state_stack[-2]][origin][1]
                    state_stack[-1] = state
                else:
                    if size:
                        children = value_stack[-size:]
                        del state_stack[-size:]
                        del value_stack[-size:]
                    else:
                        children = []
                    value_stack.append(callback(children))
                    state = states[state_stack[-1]][origin][1]
                    state_stack.append(state)
                if at_end and state == end_state:
                    return value_stack[-1]


__all__ = ["Driver", "NotWellFormed"]
