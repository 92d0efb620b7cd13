"""Lark's parse errors, told as one plain sentence with a hint (Lark's LALR error-reporting idea).

The parser stops at the first token it cannot use.  What it had read until then
(its value stack) and what it would have accepted (its parse table) are enough to
name the usual slips: a misspelt keyword, a transition without `->`, a duration
without its unit, an element without its kind, a `{` never closed.
"""

from __future__ import annotations

import dataclasses
import re
from functools import lru_cache
from typing import Any

from lark import Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from earl.diagnostics import Diagnostic, Severity, did_you_mean
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.location import SourceLocation
from earl.model.types import INTEGER_RANGES

#: How each terminal of the grammar is named to a person (keywords and punctuation are quoted).
TERMINAL_TEXT: dict[str, str] = {
    "NAME": "a name",
    "NUMBER": "a number",
    "INT": "a whole number",
    "STRING": "a string in double quotes",
    "OPTIONAL": "`?`",
    "ROBOT_KIND": "`r` (Robot)",
    "AGENT_KIND": "`a` (Agent)",
    "SUBSYSTEM_KIND": "a subsystem kind (`ve`, `re`, `vr`, `rr`)",
    "CS": "`cs`",
    "IB": "`ib` (Input Buffer)",
    "OB": "`ob` (Output Buffer)",
    "M": "`m` (Internal Memory)",
    "MI": "`mi` (memory read)",
    "MO": "`mo` (memory written)",
    "PP": "`pp` (Primitive Predicate)",
    "PF": "`pf` (Partial Transition Function)",
    "BB": "`bb` (Basic Behaviour)",
    "TIME_UNIT": "a time unit (`s`, `ms`, `us`)",
    "COMPARISON_OPERATOR": "a comparison (`==`, `<`, …)",
    "ANY_STATE": "`*`",
    "$END": "the end of the file",
}

#: The terminals an expression may start with; when all are expected they are named as one.
_EXPRESSION_START = {"NAME", "NUMBER", "LPAR"}
_EXPRESSION_TERMINALS = {"NAME", "NUMBER", "STRING", "LPAR", "LSQB", "MINUS", "NOT", "TRUE", "FALSE", "ANY", "ALL"}

#: Hints for what was expected, keyed by a terminal that identifies the construct.
HINTS: dict[str, str] = {
    "TIME_UNIT": "write a duration with its unit, e.g. `period 2 ms`",
    "AGENT_KIND": "an Agent is named with `/a`, e.g. `manip/a`",
    "ROBOT_KIND": "a Robot is named with `/r`, e.g. `manipulationRobot/r`",
    "INITIAL": "an `fsm` starts with its initial state: `fsm { initial idle  state idle: idle/bb … }`",
    "TC": "a Basic Behaviour is written `name/bb { tf = {move/pf} then {send/pf} tc = CONDITION }`",
    "WHEN": "a transition is written `source -> destination when CONDITION`",
    "TF": "a Basic Behaviour is written `name/bb { tf = {move/pf} then {send/pf} tc = CONDITION }`",
    "IN": "a family is declared `name[K in 1..N]/kind`",
    "PYTHON": 'an implementation is written `= python "module:function"`',
}

#: How a declaration of each kind is written, for a slip right after its kind suffix.
DECLARATION_FORMS: dict[str, str] = {
    "PP": 'a Primitive Predicate is written `name/pp = CONDITION`, or `name/pp(reads) = python "module:function"`',
    "M": "an Internal Memory is written `name/m: Type` or `name/m: Type = INITIAL`",
    "IB": "an Input Buffer is written `name/ib: Type`, optionally followed by `fifo N`",
    "OB": "an Output Buffer is written `name/ob: Type`",
    "PF": 'a Partial Transition Function is written `name/pf(reads -> writes)`, optionally `= python "module:function"`',
    "BB": "a Basic Behaviour is written `name/bb { tf = {move/pf} tc = CONDITION }`",
    "AGENT_KIND": "an Agent is written `name/a { cs { … } … }`",
    "ROBOT_KIND": "a Robot is written `name/r { agent/a  link a,b }`",
    "SUBSYSTEM_KIND": "a subsystem is written `name/ve { … }` (or `re`, `vr`, `rr`)",
}

#: What may be declared where: the keyword that identifies each kind of block, and the forms.
_BLOCK_FORMS: list[tuple[str, str]] = [
    (
        "PERIOD",
        "elements are named with their kind: `cmd/ib: T`, `out/ob: T`, `x/m: T`, `ready/pp = …`, "
        "`move/pf(…)`, `idle/bb { … }`",
    ),
    ("CS", "subsystems are `cs { … }` or `name/ve { … }` (also `re`, `vr`, `rr`)"),
    ("STRUCT", "declarations are named with their kind: `manip/a { … }` for an Agent, `r1/r { … }` for a Robot"),
]

_CLOSING = {"LBRACE": "}", "LPAR": ")", "LSQB": "]"}
_OPENING = {"RBRACE": "LBRACE", "RPAR": "LPAR", "RSQB": "LSQB"}
_CLOSING_TO_OPENING = {"RBRACE": "{", "RPAR": "(", "RSQB": "["}

#: Keywords that only the top level of a file holds: meeting one inside a block hints at a missing `}`.
_TOP_LEVEL_ONLY = {"system", "import", "struct", "type"}

#: Characters people type from other languages, and what EARL writes instead.
_CHARACTER_HINTS: dict[str, str] = {
    ";": "EARL needs no `;` between statements; remove it",
    "'": 'strings are written in double quotes, e.g. "module:function"',
    "#": "comments start with `//`",
    "\u2192": "write the arrow as `->`",
    "&": "write `and`",
    "|": "write `or`",
    "!": "write `not`, or `!=` for “not equal”",
}


@lru_cache(maxsize=1)
def _literal_terminals() -> dict[str, str]:
    """Terminal name → its literal text, for every terminal that is a fixed string (`->`, `{`, `period`)."""
    from earl.lang.parser import _parser  # the parser imports this module; resolve the cycle lazily

    return {t.name: t.pattern.value for t in _parser().terminals if t.pattern.type == "str"}


def _describe(terminal: str, keywords: dict[str, str]) -> str:
    if terminal in TERMINAL_TEXT:
        return TERMINAL_TEXT[terminal]
    literal = keywords.get(terminal) or _literal_terminals().get(terminal)
    if literal is not None:
        return f"`{literal}`"
    return terminal.lower()


def _found(token: Token) -> str:
    if token.type == "$END":
        return "the end of the file"
    return f"`{token}`"


def translate(error: UnexpectedInput, path: str, text: str, keywords: dict[str, str]) -> Diagnostic:
    """One diagnostic for a Lark error: where, what was expected, and a hint."""
    if isinstance(error, UnexpectedCharacters):
        return _unexpected_character(error, path, text)
    if isinstance(error, (UnexpectedToken, UnexpectedEOF)):
        return _unexpected_token(error, path, text, keywords)
    return Diagnostic(Severity.ERROR, str(error).splitlines()[0], None, code="EARL-S000")


def _unexpected_character(error: UnexpectedCharacters, path: str, text: str) -> Diagnostic:
    position = error.pos_in_stream
    character = text[position] if position is not None and 0 <= position < len(text) else str(error.char)
    line, column = error.line, error.column
    location = SourceLocation(path, line, column, line, column + 1)
    if character == '"':
        return Diagnostic(
            Severity.ERROR,
            "this string is not closed on its line",
            location,
            code="EARL-S002",
            hint='strings are written in double quotes on one line, e.g. "pick_and_place.manip:joint_move"',
        )
    shown = f"`{character}`" if character.isprintable() and not character.isspace() else f"U+{ord(character):04X}"
    hint = _CHARACTER_HINTS.get(character)
    if hint is None and character.isalpha():
        hint = "names are ASCII letters, digits and `_`"
    return Diagnostic(
        Severity.ERROR,
        f"unexpected character {shown}",
        location,
        code="EARL-S001",
        hint=hint or "names are letters, digits and `_`; comments start with `//`",
    )


#: The clauses a declaration holds once, by keyword: what holds one, and how to mend a second.
SAID_ONCE: dict[str, tuple[str, str]] = {
    "period": ("a subsystem runs at one period", "keep one `period`"),
    "timeout": ("a state waits for its obligatory buffers for one timeout", "keep one `timeout`"),
    "initial": (
        "an FSM has one initial state",
        "keep one `initial`; the other states are declared `state NAME: behaviour/bb`",
    ),
    "tf": (
        "a Basic Behaviour has one transition function",
        "keep one `tf`, its stages in order: `tf = {first/pf} then {second/pf}`",
    ),
    "tc": (
        "a Basic Behaviour has one terminal condition",
        "keep one `tc`; when either condition ends the behaviour, join them with `or`",
    ),
    "ec": (
        "a Basic Behaviour has one error condition",
        "keep one `ec`; when either condition is an error, join them with `or`",
    ),
    "fifo": ("an Input Buffer has one capacity", "keep one `fifo CAPACITY`"),
    "overflow": ("a FIFO has one overflow policy", "keep one `overflow POLICY`"),
    "priority": ("a transition has one priority", "keep one `priority N`"),
    "when": ("a transition has one condition", "keep one `when`; join the conditions with `and` or `or`"),
}


def said_twice(keyword: str, where: str, first_line: int, location: SourceLocation) -> Diagnostic:
    """EARL-S009 at the second of a clause said once; `where` names its holder (" in `cs`"), or is ""."""
    reason, hint = SAID_ONCE[keyword]
    return Diagnostic(
        Severity.ERROR,
        f"a second `{keyword}`{where} (the first is on line {first_line}): {reason}",
        location,
        code="EARL-S009",
        hint=hint,
    )


class _Context:
    """What the parser had read when it stopped, and what it would have accepted."""

    def __init__(self, error: UnexpectedToken | UnexpectedEOF, keywords: dict[str, str], text: str = "") -> None:
        self.keywords = keywords
        self.text = text
        parser = getattr(error, "interactive_parser", None)
        state = getattr(parser, "parser_state", None)
        self.values: list[Any] = list(getattr(state, "value_stack", None) or [])
        self.expected = self._expected(error, parser)
        self.before: set[str] = set()
        states = getattr(state, "state_stack", None) or []
        if state is not None and len(states) >= 2:
            table = state.parse_conf.states.get(states[-2], {})
            self.before = {t for t in table if t == t.upper()}

    @staticmethod
    def _expected(error: UnexpectedToken | UnexpectedEOF, parser: Any) -> list[str]:
        found: set[str] = set()
        if parser is not None:
            try:
                # The lexer's own list leaves out keywords (they are lexed as names); the parser knows them.
                found = set(parser.accepts())
            except Exception:
                found = set()
        if not found:
            found = set(error.expected or ())
        return sorted(t for t in found if t not in ("COMMENT", "WS"))

    @property
    def previous(self) -> Token | None:
        """The token read just before the error, when the parser had not yet folded it into a rule."""
        if self.values and isinstance(self.values[-1], Token):
            return self.values[-1]
        return None

    def value(self, back: int) -> Any:
        return self.values[-back] if len(self.values) >= back else None

    def last_end(self) -> tuple[int, int] | None:
        """Line and column just after the last thing read."""
        for value in reversed(self.values):
            if isinstance(value, Token) and value.end_line is not None:
                return value.end_line, value.end_column or 1
            if isinstance(value, Tree) and not value.meta.empty:
                return value.meta.end_line, value.meta.end_column
        return None

    def open_brackets(self) -> list[Token]:
        """The `{`, `(` and `[` read but not closed, outermost first."""
        opened: list[Token] = []
        for value in self.values:
            if not isinstance(value, Token):
                continue
            if value.type in _CLOSING:
                opened.append(value)
            elif value.type in _OPENING and opened and opened[-1].type == _OPENING[value.type]:
                opened.pop()
        return opened

    def after_arrow(self) -> bool:
        """Whether an `->` was read since the innermost `(` still open: the write list of a header."""
        opened = self.open_brackets()
        if not opened or opened[-1].type != "LPAR":
            return False
        inside = self.values[max(i for i, v in enumerate(self.values) if v is opened[-1]) + 1 :]
        return any(isinstance(value, Token) and str(value) == "->" for value in inside)

    def describe(self, terminals: list[str]) -> list[str]:
        """What the terminals are called, keywords and punctuation first, then kinds of token."""
        terminals = list(terminals)
        described: list[str] = []
        if set(terminals) >= _EXPRESSION_START:
            described.append("an expression")
            terminals = [t for t in terminals if t not in _EXPRESSION_TERMINALS]
        texts = sorted({_describe(t, self.keywords) for t in terminals}, key=lambda d: (not d.startswith("`"), d))
        return described + texts

    def keyword(self, terminal: str) -> str | None:
        return self.keywords.get(terminal) or _literal_terminals().get(terminal)


def _unexpected_token(
    error: UnexpectedToken | UnexpectedEOF, path: str, text: str, keywords: dict[str, str]
) -> Diagnostic:
    token: Token = error.token if isinstance(error, UnexpectedToken) else Token("$END", "")
    context = _Context(error, keywords, text)
    end = context.last_end()

    def after_previous() -> SourceLocation:
        if end is None:
            return SourceLocation(path, 1, 1, 1, 2)
        return SourceLocation(path, end[0], end[1], end[0], end[1] + 1)

    start = getattr(token, "start_pos", None)
    if token.type == "SLASH" and start is not None and text.startswith("/*", start):
        return Diagnostic(
            Severity.ERROR,
            "`/*` does not start a comment: EARL has line comments only",
            _token_location(path, token),
            code="EARL-S006",
            hint="write `//` at the start of each line of the comment",
        )
    if token.type == "$END" or not token.line:
        location = after_previous()
    elif (
        end is not None
        and token.line > end[0]
        and token.type not in ("NUMBER", "INT", "STRING")
        and _last_character(text, end) not in ("{", "}")
    ):
        # What is missing belongs at the end of the line before, not before the next statement. After
        # `{` or `}` the line before is complete: the statement found is the one in the wrong place.
        location = after_previous()
    else:
        column = token.column or 1
        location = SourceLocation(
            path, token.line, column, token.end_line or token.line, token.end_column or column + 1
        )

    for special in (
        _stray_closing,
        _division,
        _repeated_clause,
        _misplaced_keyword,
        _missing_arrow,
        _end_of_file,
        _bad_kind,
        _duration,
        _line_ends_early,
    ):
        diagnostic = special(token, context, location, path)
        if diagnostic is not None:
            return diagnostic
    diagnostic = _expected_message(token, context, location)
    line = token.line
    opens_its_line = token.type in _STRAY_BRACKETS and end is not None and line is not None and line > end[0]
    unhinted = diagnostic.hint in (None, _SEE_THE_DOCS) or (diagnostic.hint or "").startswith("is a `")
    if line is not None and opens_its_line and unhinted:
        # Nothing more specific is known of the line before (`tf` then `{…}` is told that `=` is
        # missing): the bracket that opens its line is the stray thing, pointed at itself, and
        # "is a `}` missing?" misled.
        column = token.column or 1
        return dataclasses.replace(
            diagnostic,
            location=SourceLocation(path, line, column, token.end_line or line, token.end_column or column + 1),
            hint=f"this `{token}` belongs to nothing before it: remove it, or move it to its declaration",
        )
    return diagnostic


#: the hint of an unexpected token when nothing more is known
_SEE_THE_DOCS = "see docs/language.md for what may be written here"

#: brackets that cannot begin a declaration: one opening a line where it is unexpected is stray
_STRAY_BRACKETS = frozenset({"LBRACE", "LSQB", "RSQB", "LPAR", "RPAR"})


def _last_character(text: str, end: tuple[int, int]) -> str:
    """The character that ends what was read (`end` is just after it: line and column from 1)."""
    lines = text.split("\n")
    line = lines[end[0] - 1] if 0 < end[0] <= len(lines) else ""
    return line[end[1] - 2] if 2 <= end[1] <= len(line) + 1 else ""


def _token_location(path: str, token: Token) -> SourceLocation:
    line = token.line or 1
    column = token.column or 1
    return SourceLocation(path, line, column, token.end_line or line, token.end_column or column + 1)


def _stray_closing(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """A `}` (or `)`, `]`) when no bracket is open: one too many, or one `{` missing above."""
    if token.type not in _OPENING or context.open_brackets():
        return None
    return Diagnostic(
        Severity.ERROR,
        f"this `{token}` closes nothing: every bracket before it is already closed",
        _token_location(path, token),
        code="EARL-S006",
        hint=f"remove it, or add the `{_CLOSING_TO_OPENING[token.type]}` it was meant to close",
    )


#: After these tokens something must follow; a statement that stops after one at the end of a
#: line swallows the next line as its continuation, and the parser only stops later.
_NEEDS_CONTINUATION = {
    "COLON": "a data type",
    "EQUAL": "a value",
    "OR": "an expression",
    "AND": "an expression",
    "NOT": "an expression",
    "PLUS": "an expression",
    "MINUS": "an expression",
    "STAR": "an expression",
    "COMPARISON_OPERATOR": "an expression",
    "COMMA": "another element",
    "WHEN": "a condition",
}


def _line_ends_early(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """`x/pp = a or` with nothing after `or`: the next line was read as the rest of it."""
    if token.type == "$END" or not token.line:
        return None
    line = token.line
    earlier = [v for v in context.values if isinstance(v, Token) and v.line and v.line < line]
    if not earlier:
        return None
    dangling = earlier[-1]
    wanted = _NEEDS_CONTINUATION.get(dangling.type)
    dangling_line = dangling.line or 0
    if wanted is None or dangling is context.previous:
        return None
    # Everything read after the dangling token must sit on later lines: it is the next statement.
    after = context.values[context.values.index(dangling) + 1 :]
    starts = [_start_line(v) for v in after]
    if not starts or any(start is None or start <= dangling_line for start in starts):
        return None
    return Diagnostic(
        Severity.ERROR,
        f"expected {wanted} after `{dangling}` at the end of line {dangling.line}",
        _token_location(path, dangling),
        code="EARL-S006",
        hint=f"line {dangling.line} stops after `{dangling}`, so line {starts[0]} was read as its continuation",
    )


def _start_line(value: Any) -> int | None:
    if isinstance(value, Token):
        return value.line
    if isinstance(value, Tree) and not value.meta.empty:
        return int(value.meta.line)
    return None


#: The rules of the block clauses said once, by the keyword that starts them (their keyword is not kept in the tree).
_CLAUSE_RULES = {
    "initial_state": "initial",
    "transition_function": "tf",
    "terminal_condition": "tc",
    "error_condition": "ec",
}


def _repeated_clause(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """A second `tc`, `initial`, `priority`, …: the grammar takes each once, so the parser stops at it.

    The repeated keyword is the token the parser stopped at (`tc = a  tc = b`), or the name just
    before it (`initial two`: `initial` read as a state's name). The first one is still on the
    stack: as its keyword, as the clause it began, or inside the statement just before.
    """
    previous = context.previous
    if str(token) in SAID_ONCE and token.type != "$END":
        repeated = token
    elif previous is not None and previous.type == "NAME" and str(previous) in SAID_ONCE:
        repeated = previous
    else:
        return None
    keyword = str(repeated)
    block = _innermost_block(context.values)
    statements = [value for value in block if value is not repeated]
    first_line: int | None = None
    for value in statements:
        if isinstance(value, Token) and value.type != "NAME" and str(value) == keyword:
            first_line = value.line
        elif isinstance(value, Tree) and _CLAUSE_RULES.get(str(value.data)) == keyword and not value.meta.empty:
            first_line = value.meta.line
        if first_line is not None:
            break
    if first_line is None and statements:
        first_line = _clause_line_in_statement(statements[-1], keyword)
    if first_line is None:
        return None
    return said_twice(keyword, "", first_line, _token_location(path, repeated))


def _innermost_block(values: list[Any]) -> list[Any]:
    """What was read after the innermost `{` still open, the statements of a repetition one by one."""
    start = 0
    depth = 0
    for index in range(len(values) - 1, -1, -1):
        value = values[index]
        if isinstance(value, Token) and value.type == "RBRACE":
            depth += 1
        elif isinstance(value, Token) and value.type == "LBRACE":
            if depth == 0:
                start = index + 1
                break
            depth -= 1
    flat: list[Any] = []
    for value in values[start:]:
        # `(a | b)*` is collected in a tree of its own (`__fsm_star_8`) until its block closes
        if isinstance(value, Tree) and str(value.data).startswith("__"):
            flat.extend(value.children)
        else:
            flat.append(value)
    return flat


def _clause_line_in_statement(statement: Any, keyword: str) -> int | None:
    """The line of `keyword`'s clause in the statement just read, when it has one."""
    if not isinstance(statement, Tree):
        return None
    children = statement.children
    if statement.data == "input_buffer":
        queue = next((c for c in children if isinstance(c, Tree) and c.data == "queue"), None)
        if queue is None or queue.meta.empty:
            return None
        if keyword == "fifo":
            return int(queue.meta.line)
        policy = queue.children[1] if len(queue.children) > 1 else None
        return policy.line if keyword == "overflow" and isinstance(policy, Token) else None
    if statement.data == "transition" and len(children) >= 3:
        condition = children[2]
        if keyword == "when":
            return _start_line(condition)
        priority = children[3] if len(children) > 3 else None
        return priority.line if keyword == "priority" and isinstance(priority, Token) else None
    return None


def _misplaced_keyword(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """`peroid 2 ms`, `strcut S {…}`, a second `system`: a name where a keyword was meant."""
    previous = context.previous
    if previous is None or previous.type != "NAME" or not context.before:
        return None
    name = str(previous)
    acceptable = {context.keyword(t): t for t in context.before if t in context.keywords}
    acceptable.pop(None, None)
    if name in context.keywords.values() and name not in acceptable:
        if name == "system":
            hint = "`system NAME` is written once, as the first line of the root file"
        elif name in _BUFFER_GROUP_PARTS and _in_buffer_group(context) and _is_token(context.value(2), "COMMA"):
            hint = _buffer_group_commas_hint(context)
        elif name in _TOP_LEVEL_ONLY and context.open_brackets():
            hint = _unclosed_hint(context, context.open_brackets()) or f"`{name}` is written at the top level of a file"
        else:
            hint = None
        return Diagnostic(
            Severity.ERROR, f"`{name}` cannot be written here", _token_location(path, previous), "EARL-S007", hint
        )
    # A name followed by `/` or `[` is an element; anything else after it suggests a keyword was meant.
    if token.type in ("SLASH", "LSQB"):
        return None
    suggestion = did_you_mean(name, [k for k in acceptable if k is not None])
    if suggestion is None:
        return None
    return Diagnostic(
        Severity.ERROR, f"unknown keyword `{name}`", _token_location(path, previous), "EARL-S007", suggestion
    )


#: The keywords that begin the parts of a state's buffer group.
_BUFFER_GROUP_PARTS = {"obligatory", "optional", "timeout"}


def _is_token(value: Any, terminal: str) -> bool:
    return isinstance(value, Token) and value.type == terminal


def _group_brace(context: _Context) -> Token | None:
    """The innermost `{` still open."""
    opened = context.open_brackets()
    return opened[-1] if opened and opened[-1].type == "LBRACE" else None


def _in_buffer_group(context: _Context) -> bool:
    """Whether the innermost `{` still open is a state's buffer group: `state s: b/bb {`."""
    brace = _group_brace(context)
    if brace is None:
        return False
    index = next(i for i, value in enumerate(context.values) if value is brace)
    behaviour = context.values[index - 1] if index >= 1 else None
    return (
        isinstance(behaviour, Tree)
        and behaviour.data == "element_ref"
        and _is_token(context.values[index - 2] if index >= 2 else None, "COLON")
    )


def _buffer_group_commas_hint(context: _Context) -> str:
    """`{ obligatory a/ib, optional b/ib }`: the group as it is meant, its parts apart without commas."""
    hint = "the parts of a buffer group are separated by spaces or new lines, not commas"
    group = _group_brace(context)
    start = group.start_pos if group is not None else None
    end = context.text.find("}", start) if start is not None else -1
    if start is None or end < 0 or "\n" in context.text[start:end]:
        return f"{hint}: `{{ obligatory a/ib  optional b/ib  timeout 20 ms }}`"
    meant = _COMMA_BEFORE_PART.sub(r"  \1", context.text[start : end + 1])
    return f"{hint}: `{meant}`"


#: a comma before a part of a buffer group (the commas inside a part's list of buffers stay)
_COMMA_BEFORE_PART = re.compile(r"\s*,\s*(obligatory|optional|timeout)\b")


def _missing_arrow(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    arrow = next((t for t in context.expected if context.keyword(t) == "->"), None)
    if arrow is None:
        return None
    previous = context.previous
    in_fsm = "ANY_STATE" in context.before or "STATE" in context.before or not context.before
    if previous is not None and previous.type == "NAME" and in_fsm and len(context.expected) <= 3:
        # A source state followed by anything but an arrow: the commonest slip in an FSM.
        return Diagnostic(
            Severity.ERROR,
            f"expected `->` after the source state `{previous}`",
            location,
            code="EARL-S003",
            hint="a transition is written `source -> destination when CONDITION`",
        )
    top = context.value(1)
    if isinstance(top, Tree) and top.data == "link_end":
        return Diagnostic(
            Severity.ERROR,
            f"expected `->` between the two ends of the link, found {_found(token)}",
            location,
            code="EARL-S003",
            hint="a link runs from an Output Buffer to an Input Buffer: `link a,b: a/a.cs.out -> b/a.cs.in`",
        )
    if any(isinstance(v, Token) and v.type == "PF" for v in context.values):
        if "COMMA" in context.expected and token.type == "NAME":
            return Diagnostic(
                Severity.ERROR,
                f"expected `,` or `->` before `{token}`",
                location,
                code="EARL-S003",
                hint="separate what `/pf` reads with `,` and end the list with `->`: `move/pf(a/ib, b/mi -> c/mo)`",
            )
        return Diagnostic(
            Severity.ERROR,
            f"expected `->` between what `/pf` reads and what it writes, found {_found(token)}",
            location,
            code="EARL-S003",
            hint="write `name/pf(reads -> writes)`, e.g. `move/pf(cmd/ib -> pos/mo)`; either side may be empty",
        )
    return None


def _unclosed_hint(context: _Context, opened: list[Token]) -> str | None:
    """ "Is a `}` missing?" — only when the file holds more of the innermost open bracket than it closes.

    The parser stops inside a block that is still open however the file goes on, so an open
    bracket on its stack says nothing by itself: `x/mi = 3` in a `{ … }` that closes further down
    is no missing `}`.
    """
    if not opened:
        return None
    innermost = opened[-1]
    opening = str(innermost)
    counts = _bracket_counts(context.text)
    if context.text and counts.get(opening, 0) <= counts.get(_CLOSING[innermost.type], 0):
        return None
    return (
        f"is a `{_CLOSING[innermost.type]}` missing? "
        f"the `{innermost}` on line {innermost.line}, column {innermost.column} is still open"
    )


def _bracket_counts(text: str) -> dict[str, int]:
    """How many of each bracket the text holds, outside strings and comments."""
    counts: dict[str, int] = {}
    for match in _BRACKETS_STRINGS_COMMENTS.finditer(text):
        bracket = match.group(1)
        if bracket:
            counts[bracket] = counts.get(bracket, 0) + 1
    return counts


#: a bracket (group 1), or a string or comment whose brackets do not count
_BRACKETS_STRINGS_COMMENTS = re.compile(r'([{}()\[\]])|"(?:[^"\\\n]|\\.)*"?|//[^\n]*')


def _end_of_file(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    if token.type != "$END":
        return None
    opened = context.open_brackets()
    if opened:
        innermost = opened[-1]
        closing = _CLOSING[innermost.type]
        return Diagnostic(
            Severity.ERROR,
            f"the file ends before the `{innermost}` on line {innermost.line} is closed",
            location,
            code="EARL-S004",
            hint=f"add the missing `{closing}`" + ("" if len(opened) == 1 else f" ({len(opened)} brackets are open)"),
        )
    previous = context.previous
    after = f" after `{previous}`" if previous is not None and str(previous).strip() else ""
    described = context.describe(context.expected)
    hint = next((HINTS[t] for t in context.expected if t in HINTS), None) or _after_keyword_hint(context)
    return Diagnostic(
        Severity.ERROR,
        f"the file ends{after} but {_join(described[:6], 'or')} was expected",
        location,
        code="EARL-S004",
        hint=hint,
    )


def _division(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """`N / 2`, `(N + 1) / 2`: EARL has no division, its slash introduces a kind.

    After a value, where an operator may follow, the slash itself is refused (`(N + 1) / 2`,
    `v/ib / 2`). After a bare name the slash is taken for a kind's (`N/ib`), and the parser stops
    at what follows it: a number, `(` or `-` is never a kind, nor is a name with capitals or digits.
    """
    slash: Token | None = None
    if token.type == "SLASH" and any(t in context.expected for t in ("STAR", "PLUS", "MINUS")):
        slash = token
    elif (
        _is_token(context.previous, "SLASH")
        and "MI" in context.expected
        and _is_token(context.value(2), "NAME")
        and not _in_header(context)
        and (
            token.type in ("NUMBER", "INT", "LPAR", "MINUS")
            or (token.type == "NAME" and not str(token).islower() and _divides(str(context.value(2)), str(token)))
        )
    ):
        slash = context.previous
    if slash is None or slash.start_pos is None:
        return None
    text = context.text
    dividend = _operand_before(text, slash.start_pos)
    divisor = _DIVISOR.match(text, slash.end_pos or slash.start_pos + 1)
    product = f"{dividend} * 0.5"
    instead = f"multiply instead, e.g. `{product}` for `{dividend} / 2`"
    number = divisor.group(1) if divisor is not None and divisor.group(1) is not None else None
    if number is not None and float(number) == 0:
        number = None  # `N / 0` has no product to show
    if divisor is not None and divisor.group(2) is not None:
        # `1.0 / N`: no expression computes an inverse of a parameter
        inverse = f"INV_{divisor.group(2).upper()}"
        use = inverse if dividend in ("1", "1.0") else f"{dividend} * {inverse}"
        instead = (
            f"EARL cannot compute `1 / {divisor.group(2)}`: give it as a parameter of its own "
            f"(`param {inverse}: double = …`, then `{use}`), or compute it in the Python code that uses it"
        )
    elif number is not None:
        product = f"{dividend} * {1 / float(number)!r}"
        instead = f"multiply instead: write `{product}` for `{dividend} / {number}`"
    whole = _whole_number_context(context)
    if whole is None:
        hint = instead
    else:
        what, name = whole
        times = number or "2"
        # divided by a name or a group there is no product to show
        product = "a product with a `double`" if number is None else f"`{product}`"
        if name is not None and times.isdigit() and dividend.isidentifier() and number is not None:
            hint = (
                f"{what} and {product} is a `double`, even when whole: give `{name}` its own value and "
                f"compute `{dividend}` from it (`param {name}: int = …`, then `param {dividend}: int = {times} * {name}`)"
                f", or declare `{name}` a `double` and write {product}"
            )
        elif name is not None:
            hint = (
                f"{what} and {product} is a `double`, even when whole: give `{name}` its own value "
                f"(`param {name}: int = …`) and compute the others from it by multiplying, "
                f"or declare `{name}` a `double`"
            )
        else:
            hint = (
                f"{what} and {product} is a `double`, even when whole: there is no whole division, so declare "
                "the smaller number as a parameter and compute the larger from it "
                "(`param HALF: int = 3`, then `param N: int = 2 * HALF`)"
            )
    return Diagnostic(
        Severity.ERROR,
        f"there is no division: the `/` after `{dividend}` would introduce a kind, as in `x/ib`",
        _token_location(path, slash),
        code="EARL-S006",
        hint=hint,
    )


#: the kinds as written after a slash: `cmd/IB` is a kind in the wrong case, not a division by `IB`
_KIND_WORDS = frozenset(kind.value for kind in Kind) | {"mi", "mo"}


def _divides(before: str, after: str) -> bool:
    """`N/M` is a division by the parameter `M`; `cmd/IB` the kind `ib` in capitals (parameters are
    named in capitals, elements not)."""
    return after.lower() not in _KIND_WORDS or before.isupper()


#: what follows a slash meant for division: a number (group 1), a parameter's name (group 2), or anything else
_DIVISOR = re.compile(r"[ \t]*(?:(\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)\b|([A-Za-z_][A-Za-z0-9_]*)\b(?!\s*[/\[])|\S)")


def _operand_before(text: str, end: int) -> str:
    """The name or parenthesised group that ends just before `end`, or `x` when it is neither."""
    before = text[:end].rstrip()
    if before.endswith(")"):
        depth = 0
        for index in range(len(before) - 1, -1, -1):
            depth += {")": 1, "(": -1}.get(before[index], 0)
            if depth == 0:
                group = before[index:]
                return group if "\n" not in group else "x"
        return "x"
    # a name, a read (`v/ib.pose.x`, `v/mi[1]`) or a number, written without spaces
    found = re.search(r"[A-Za-z0-9_.\[\]/]+$", before)
    if found is None or "//" in found.group(0):
        return "x"
    operand = found.group(0).rsplit("..", 1)[-1]  # `1..N / 2`: the range's last bound
    unclosed: list[int] = []
    for index, character in enumerate(operand):
        if character == "[":
            unclosed.append(index)
        elif character == "]" and unclosed:
            unclosed.pop()
    if unclosed:  # `double[N / 2]`: the size, not the type
        operand = operand[unclosed[-1] + 1 :]
    return operand or "x"


def _in_header(context: _Context) -> bool:
    """Whether the innermost bracket still open is the `(` of a `/pf` or `/pp` header: its list of reads."""
    opened = context.open_brackets()
    if not opened or opened[-1].type != "LPAR":
        return False
    index = next(i for i, value in enumerate(context.values) if value is opened[-1])
    return index >= 1 and (_is_token(context.values[index - 1], "PF") or _is_token(context.values[index - 1], "PP"))


#: the rules a data type is read as: a `[` after one opens an array's size
_DATA_TYPE_RULES = ("named_type", "fixed_array", "variable_array")


def _whole_number_context(context: _Context) -> tuple[str, str | None] | None:
    """What the expression being read must be when it is a whole number, and the name it declares.

    `param H: int = …` gives ("`H` is an `int`", "H"); an array size, a family's range and a FIFO
    capacity give what they are, and no name.
    """
    values = context.values
    depth = 0
    for index in range(len(values) - 1, -1, -1):
        value = values[index]
        if not isinstance(value, Token):
            continue
        if value.type in _OPENING:
            depth += 1
            continue
        if value.type in _CLOSING:
            if depth:
                depth -= 1
                continue
            typed = values[index - 1] if index >= 1 else None
            if value.type == "LSQB" and isinstance(typed, Tree) and typed.data in _DATA_TYPE_RULES:
                return "an array size is a whole number", None
            if value.type != "LSQB":
                return None
            continue
        if value.type == "FIFO":
            return "a FIFO capacity is a whole number", None
        if value.type == "IN" or str(value) == "..":
            return "a family's range is of whole numbers", None
        if value.type == "EQUAL":
            typed = values[index - 1] if index >= 1 else None
            if not (isinstance(typed, Tree) and typed.data == "named_type"):
                return None
            type_name = str(typed.children[0])
            if type_name not in INTEGER_RANGES:
                return None
            declared = values[index - 3] if index >= 3 else None
            name = declared if _is_token(declared, "NAME") else None
            if name is None and isinstance(declared, Token) and declared.type == "M":
                element = values[index - 5] if index >= 5 else None
                if isinstance(element, Tree) and element.children:
                    return f"`{element.children[0]}` is an `{type_name}`", None
            if name is None:
                return None
            return f"`{name}` is an `{type_name}`", str(name)
    return None


def _bad_kind(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """`manip/x`: the word after `/` is not a kind that can stand here."""
    previous = context.previous
    if previous is None or previous.type != "SLASH" or token.type not in ("NAME", "NUMBER", "INT"):
        return None
    kinds = context.describe(context.expected)
    hint = next((HINTS[t] for t in context.expected if t in HINTS), None)
    if str(token) == Kind.MEMORY.value and "MI" in context.expected:
        name = context.value(2)
        named = f"{name}" if isinstance(name, Token) and name.type == "NAME" else "x"
        # after the `->` of a partial transition function's header the memory is written, before it read
        written = "MO" in context.expected and context.after_arrow()
        use = f"write it: `{named}/mo`" if written else f"read it: `{named}/mi`"
        hint = f"memory is declared `{named}/m`, read as `{named}/mi` and written as `{named}/mo`; here, {use}"
    if hint is None and str(token).lower() in _KIND_WORDS and not str(token).islower():
        hint = f"kinds are written in lowercase: `{context.value(2)}/{str(token).lower()}`"  # `cmd/IB`
    if str(token) in (Kind.AGENT.value, Kind.ROBOT.value) and context.open_brackets():
        title = KIND_TITLES[Kind(str(token))]
        unclosed = _unclosed_hint(context, context.open_brackets())
        hint = f"an {title} is declared at the top level" + (f"; {unclosed}" if unclosed else "")
    return Diagnostic(
        Severity.ERROR,
        f"`{token}` is not a kind of element that can stand here; expected {_join(kinds, 'or')}",
        location,
        code="EARL-S005",
        hint=hint or "the kind after `/` says what an element is: `a`, `ve`, `ib`, `ob`, `m`, `pp`, `pf`, `bb`, …",
    )


def _duration(token: Token, context: _Context, location: SourceLocation, path: str) -> Diagnostic | None:
    """`period 2` or `period 2 min`: a number without one of the three units."""
    previous = context.previous
    if "TIME_UNIT" not in context.expected or previous is None or previous.type != "NUMBER":
        return None
    if token.type == "NAME" and token.line == previous.line:
        return Diagnostic(
            Severity.ERROR,
            f"`{token}` is not a time unit; write `s`, `ms` or `us`",
            location,
            code="EARL-S008",
            hint=f"e.g. `{previous} ms`",
        )
    return Diagnostic(
        Severity.ERROR,
        f"the duration `{previous}` has no unit",
        _token_location(path, previous),
        code="EARL-S008",
        hint=f"write it with its unit: `{previous} s`, `{previous} ms` or `{previous} us`",
    )


def _expected_message(token: Token, context: _Context, location: SourceLocation) -> Diagnostic:
    expected = context.expected
    previous = context.previous
    described = context.describe(expected)
    after = f" after `{previous}`" if previous is not None and str(previous).strip() else ""
    hint: str | None = _slip_hint(token, context)

    if hint is None and token.type == "NAME":
        hint = did_you_mean(str(token), [k for t in expected if (k := context.keyword(t)) and k.isidentifier()])
    if hint is None and previous is not None and previous.type in DECLARATION_FORMS:
        before_slash = context.value(3)
        if (isinstance(before_slash, Tree) and before_slash.data == "declared_name") or (
            isinstance(before_slash, Token) and before_slash.type in ("TRUE", "FALSE")
        ):
            hint = DECLARATION_FORMS[previous.type]
    if hint is None:
        hint = next((HINTS[t] for t in expected if t in HINTS), None)
    if hint is None and previous is not None and previous.type == "NAME" and "SLASH" in expected:
        # `cmd: T` or `manip { … }`: an element written without its kind.
        hint = next((form for marker, form in _BLOCK_FORMS if marker in context.before), None)
        if hint is not None:
            return Diagnostic(
                Severity.ERROR,
                f"expected `/` and a kind after `{previous}`, found {_found(token)}",
                location,
                code="EARL-S006",
                hint=hint,
            )
    if hint is None:
        hint = _after_keyword_hint(context)
    if hint is None and token.type in ("NUMBER", "INT") and "NAME" in expected and "NUMBER" not in expected:
        hint = "names start with a letter or `_`"
    if hint is None and token.type == "NAME" and str(token) in _TOP_LEVEL_ONLY:
        hint = _unclosed_hint(context, context.open_brackets())
    if hint is None and any(t in _OPENING for t in expected) and token.type in _OPENING:
        hint = _unclosed_hint(context, context.open_brackets())
    if hint is None and any(t in _OPENING for t in expected) and context.open_brackets():
        innermost = context.open_brackets()[-1]
        if _OPENING.get(next(t for t in expected if t in _OPENING)) == innermost.type:
            hint = _unclosed_hint(context, [innermost])
    if hint is None and previous is not None and previous.type == "CS" and token.type == "SLASH":
        hint = "the Control Subsystem is written `cs { … }`, without a kind"
    top = context.value(1)
    second = context.value(2)
    if token.type == "COMPARISON_OPERATOR" and (
        (isinstance(top, Tree) and top.data == "comparison")
        or (isinstance(second, Token) and second.type == "COMPARISON_OPERATOR")
    ):
        hint = "comparisons do not chain: write `a < b and b < c`"
    if len(described) > 8:
        return Diagnostic(
            Severity.ERROR,
            f"unexpected {_found(token)}{after}",
            location,
            code="EARL-S006",
            hint=hint or _SEE_THE_DOCS,
        )
    return Diagnostic(
        Severity.ERROR,
        f"expected {_join(described, 'or')}{after}, found {_found(token)}",
        location,
        code="EARL-S006",
        hint=hint,
    )


def _slip_hint(token: Token, context: _Context) -> str | None:
    """A hint for a slip recognised by what was read just before the token the parser stopped at."""
    previous = context.previous
    if token.type == "EQUAL" and "COMPARISON_OPERATOR" in context.expected:
        # `tc = x/mi = 3`: an expression may go on with a comparison, and `=` only gives a value
        return f"to compare, write `==`: `{_line_with(context.text, token, '==')}`"
    before = context.value(2)
    if (
        token.type in ("SLASH", "LSQB")
        and previous is not None
        and previous.type == "NAME"
        and isinstance(before, Token)
        and before.type == "INITIAL"
    ):
        return f"`initial` names a state, not its behaviour: write `initial {previous}`"
    if (
        previous is not None
        and previous.type == "NAME"
        and "SLASH" in context.expected
        and _is_token(context.value(2), "COLON")
        and _is_token(context.value(4), "STATE")
    ):
        # `state pushing: pushing { … }`: the behaviour without its kind
        return f"a state names its behaviour with its kind: `state {context.value(3)}: {previous}/bb`"
    if token.type == "COMMA" and "THEN" in context.expected:
        # `tf = {a/pf}, {b/pf}`
        return (
            f"the stages of a `tf` follow one another with `then`: `{_line_with(context.text, token, ' then')}`; "
            "the functions of one stage share its braces: `{a/pf, b/pf}`"
        )
    if token.type == "PRIORITY" and context.expected == ["WHEN"]:
        # `a -> b priority 2 when c/pp`
        line = _line_with(context.text, token, str(token))
        meant = _PRIORITY_BEFORE_WHEN.sub(r"when \2 priority \1", line)
        return (
            f"`when CONDITION` comes before `priority`: `{meant if meant != line else 'a -> b when c/pp priority 1'}`"
        )
    brace = _group_brace(context)
    if token.type == "EQUAL" and brace is not None:
        index = next(i for i, value in enumerate(context.values) if value is brace)
        if index >= 2 and _is_token(context.values[index - 2], "STRUCT"):
            return (
                "a struct's fields have no default value: a memory of the struct gets its first value in the "
                "first stage of the initial state's behaviour"
            )
    read = context.value(1)
    if token.type == "COMMA" and isinstance(read, Tree) and read.data == "element_ref":
        state, name = context.value(4), context.value(3)
        if isinstance(state, Token) and state.type == "STATE":
            parts = read.children
            behaviour = "/".join(map(str, parts)) if all(isinstance(p, Token) for p in parts) else "b/bb"
            return (
                "a state has one behaviour, and its buffers follow it in braces, with no comma: "
                f"`state {name}: {behaviour} {{ obligatory a/ib  optional b/ib  timeout 20 ms }}`"
            )
    return None


#: `priority N when CONDITION` to the end of a line: the two clauses the other way round
_PRIORITY_BEFORE_WHEN = re.compile(r"priority\s+(\d+)\s+when\s+(.+)$")


def _line_with(text: str, token: Token, replacement: str) -> str:
    """The source line of `token` with the token replaced, trimmed: the line as it was meant."""
    start, end = token.start_pos, token.end_pos
    if start is None or end is None or not text:
        return replacement
    line_start = text.rfind("\n", 0, start) + 1
    line_end = text.find("\n", end)
    line_end = len(text) if line_end < 0 else line_end
    return (text[line_start:start] + replacement + text[end:line_end]).strip()


def _after_keyword_hint(context: _Context) -> str | None:
    """How the innermost statement still open is written, when a keyword began it."""
    values = context.values
    for index in range(len(values) - 1, -1, -1):
        value = values[index]
        if not isinstance(value, Token):
            continue
        if value.type in _KEYWORD_FORMS:
            return _KEYWORD_FORMS[value.type]
        if value.type == "LBRACE":
            opener = values[index - 2] if index >= 2 else None
            if not (isinstance(opener, Token) and opener.type == "STRUCT"):
                return None
    return None


_KEYWORD_FORMS: dict[str, str] = {
    "PARAM": "a parameter is written `param N: int = 6`",
    "SYSTEM": "the system is named on the first line: `system pickAndPlace`",
    "IMPORT": 'the file to import is written in double quotes: `import "types.earl"`',
    "STRUCT": "a struct is written `struct Name { field: Type  other: Type? }`",
    "TYPE": "a type alias is written `type Name = double[6]`",
    "LINK": "a link is written `link NAME: FROM -> TO`, e.g. `link task,manip: task/a.cs.cmd -> manip/a.cs.cmd`",
    "PRIORITY": "a priority is a whole number, e.g. `priority 1`",
    "ANY": "a quantifier is written `any(K in 1..N: CONDITION)`",
    "ALL": "a quantifier is written `all(K in 1..N: CONDITION)`",
    "TF": "a transition function is written `tf = {first/pf, …} then {second/pf, …}`",
    "TIMEOUT": "a timeout is a duration, e.g. `timeout 5 ms`",
    "PERIOD": "a period is a duration, e.g. `period 2 ms`",
}


def _join(items: list[str], conjunction: str) -> str:
    if not items:
        return "something else"
    if len(items) == 1:
        return items[0]
    return ", ".join(items[:-1]) + f" {conjunction} " + items[-1]
