"""Lark's parse errors, told as one plain sentence with a hint (Lark's LALR error-reporting idea)."""

from __future__ import annotations

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from earl.diagnostics import Diagnostic, Severity, did_you_mean
from earl.model.location import SourceLocation

#: How each terminal of the grammar is named to a person.
TERMINAL_TEXT: dict[str, str] = {
    "NAME": "a name",
    "NUMBER": "a number",
    "INT": "a whole number",
    "STRING": "a string in double quotes",
    "LBRACE": "`{`",
    "RBRACE": "`}`",
    "LPAR": "`(`",
    "RPAR": "`)`",
    "LSQB": "`[`",
    "RSQB": "`]`",
    "COLON": "`:`",
    "COMMA": "`,`",
    "DOT": "`.`",
    "EQUAL": "`=`",
    "SLASH": "`/`",
    "STAR": "`*`",
    "PLUS": "`+`",
    "MINUS": "`-`",
    "QMARK": "`?`",
    "OPTIONAL": "`?`",
    "__ANON_0": "`->`",
    "ROBOT_KIND": "`r`",
    "AGENT_KIND": "`a`",
    "SUBSYSTEM_KIND": "a subsystem kind (`ve`, `re`, `vr`, `rr`)",
    "IB": "`ib`",
    "OB": "`ob`",
    "M": "`m`",
    "MI": "`mi`",
    "MO": "`mo`",
    "PP": "`pp`",
    "PF": "`pf`",
    "BB": "`bb`",
    "TIME_UNIT": "a time unit (`s`, `ms`, `us`)",
    "COMPARISON_OPERATOR": "a comparison",
    "TRUE": "`true`",
    "FALSE": "`false`",
    "ANY": "`any`",
    "ALL": "`all`",
    "$END": "the end of the file",
}

#: Hints for what was expected, keyed by a terminal that identifies the construct.
HINTS: dict[str, str] = {
    "TIME_UNIT": "write a duration with its unit, e.g. `period 2 ms`",
    "AGENT_KIND": "an Agent is named with `/a`, e.g. `manip/a`",
    "ROBOT_KIND": "a Robot is named with `/r`, e.g. `manipulationRobot/r`",
}

_PAIRS = {"RBRACE": "{", "RPAR": "(", "RSQB": "["}


def _describe(terminal: str, keywords: dict[str, str]) -> str:
    if terminal in TERMINAL_TEXT:
        return TERMINAL_TEXT[terminal]
    if terminal in keywords:
        return f"`{keywords[terminal]}`"
    return terminal.lower()


def _found(token: Token) -> str:
    if token.type == "$END":
        return "the end of the file"
    return f"`{token}`"


def translate(error: UnexpectedInput, path: str, text: str, keywords: dict[str, str]) -> Diagnostic:
    """One diagnostic for a Lark error: where, what was expected, and a hint."""
    if isinstance(error, UnexpectedCharacters):
        line, column = error.line, error.column
        character = text.splitlines()[line - 1][column - 1] if line - 1 < len(text.splitlines()) else "?"
        location = SourceLocation(path, line, column, line, column + 1)
        if character == '"':
            return Diagnostic(
                Severity.ERROR,
                "this string is not closed on its line",
                location,
                code="EARL-S002",
                hint='strings are written in double quotes on one line, e.g. "pick_and_place.manip:joint_move"',
            )
        return Diagnostic(
            Severity.ERROR,
            f"unexpected character `{character}`",
            location,
            code="EARL-S001",
            hint="names are letters, digits and `_`; comments start with `//`",
        )
    if isinstance(error, (UnexpectedToken, UnexpectedEOF)):
        token: Token = error.token if isinstance(error, UnexpectedToken) else Token("$END", "")
        expected = sorted(error.expected) if error.expected else []
        expected = [t for t in expected if t not in ("COMMENT", "WS")]
        previous = _previous_token(error)
        if token.type == "$END" or not token.line:
            lines = text.splitlines() or [""]
            line = len(lines)
            column = len(lines[-1]) + 1
            location = SourceLocation(path, line, column, line, column + 1)
        else:
            column = token.column or 1
            location = SourceLocation(
                path, token.line, column, token.end_line or token.line, token.end_column or column + 1
            )
        return _expected_message(token, expected, previous, location, keywords)
    return Diagnostic(Severity.ERROR, str(error).splitlines()[0], None, code="EARL-S000")


def _previous_token(error: UnexpectedInput) -> Token | None:
    parser = getattr(error, "interactive_parser", None)
    if parser is None:
        return None
    stack = parser.parser_state.value_stack
    for value in reversed(stack):
        if isinstance(value, Token):
            return value
        break
    return None


def _expected_message(
    token: Token, expected: list[str], previous: Token | None, location: SourceLocation, keywords: dict[str, str]
) -> Diagnostic:
    described = [_describe(t, keywords) for t in expected]
    after = f" after `{previous}`" if previous is not None and str(previous).strip() else ""
    hint: str | None = None

    # A source state followed by anything but an arrow: the commonest slip in an FSM.
    if "__ANON_0" in expected and previous is not None and previous.type in ("NAME", "STAR") and len(expected) <= 3:
        return Diagnostic(
            Severity.ERROR,
            f"expected `->` after the source state `{previous}`",
            location,
            code="EARL-S003",
            hint="a transition is written `source -> destination when CONDITION`",
        )
    if token.type == "$END":
        closing = [t for t in expected if t in _PAIRS]
        message = f"the file ends{after} but {' or '.join(described[:4])} was expected"
        if closing:
            hint = f"a `{_PAIRS[closing[0]]}` is not closed"
        return Diagnostic(Severity.ERROR, message, location, code="EARL-S004", hint=hint)

    for terminal in expected:
        if terminal in HINTS:
            hint = HINTS[terminal]
            break
    if token.type == "NAME" and hint is None:
        candidates = [keywords[t] for t in expected if t in keywords]
        hint = did_you_mean(str(token), candidates)
    if token.type == "NAME" and previous is not None and previous.type == "SLASH":
        kinds = [d for d in described]
        return Diagnostic(
            Severity.ERROR,
            f"`{token}` is not a kind of element that can stand here; expected {_join(kinds)}",
            location,
            code="EARL-S005",
            hint=hint or "the kind after `/` says what an element is: `a`, `cs`, `ve`, `ib`, `pp`, …",
        )
    if len(described) > 8:
        return Diagnostic(
            Severity.ERROR,
            f"unexpected {_found(token)}{after}",
            location,
            code="EARL-S006",
            hint=hint or "see docs/language.md for what may be written here",
        )
    return Diagnostic(
        Severity.ERROR,
        f"expected {_join(described)}{after}, found {_found(token)}",
        location,
        code="EARL-S006",
        hint=hint,
    )


def _join(items: list[str]) -> str:
    if not items:
        return "something else"
    if len(items) == 1:
        return items[0]
    return ", ".join(items[:-1]) + " or " + items[-1]
