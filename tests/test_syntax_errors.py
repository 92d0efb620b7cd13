"""Malformed specifications: each error is reported once, where it was written, in one plain sentence.

Every case asserts the exact line and column of the first diagnostic, its code and a fragment
of its message; name-resolution cases assert the hint too (did-you-mean for misspelt names).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

import earl
from earl.cli.main import main
from earl.diagnostics import Diagnostic, EarlError

_HEAD = "system s\n\nr/r {\n    a/a\n}\n\n"


def _in_cs(body: str) -> str:
    """A spec whose agent `a/a` has a control subsystem holding `body` (its first line is line 9)."""
    return _HEAD + "a/a {\n    cs {\n" + body + "    }\n}\n"


@dataclass(frozen=True)
class Malformed:
    name: str
    text: str
    line: int
    column: int
    code: str
    fragment: str
    hint: str | None = None


SYNTAX = [
    Malformed(
        "missing_arrow_in_transition",
        _in_cs(
            "        period 1 ms\n        x/pp = true\n        b/bb {\n            tf = {}\n            tc = x/pp\n        }\n        fsm {\n            initial idle\n            state idle: b/bb\n            idle busy when x/pp\n        }\n"
        ),
        18,
        18,
        "EARL-S003",
        "expected `->` after the source state `idle`",
    ),
    Malformed(
        "period_without_unit",
        _in_cs("        period 2\n"),
        9,
        16,
        "EARL-S008",
        "the duration `2` has no unit",
    ),
    Malformed(
        "period_with_wrong_unit",
        _in_cs("        period 2 min\n"),
        9,
        18,
        "EARL-S008",
        "`min` is not a time unit; write `s`, `ms` or `us`",
    ),
    Malformed(
        "misspelt_period",
        _in_cs("        peroid 2 ms\n"),
        9,
        9,
        "EARL-S007",
        "unknown keyword `peroid`",
    ),
    Malformed(
        "misspelt_struct",
        "system s\n\nstrcut Pose {\n    x: double\n}\n",
        3,
        1,
        "EARL-S007",
        "unknown keyword `strcut`",
    ),
    Malformed(
        "unknown_kind",
        "system s\n\nmanip/x {\n}\n",
        3,
        7,
        "EARL-S005",
        "`x` is not a kind of element that can stand here; expected `a` (Agent)",
    ),
    Malformed(
        "agent_without_kind",
        "system s\n\nmanip {\n    cs {\n    }\n}\n",
        3,
        7,
        "EARL-S006",
        "expected `/` and a kind after `manip`, found `{`",
    ),
    Malformed(
        "buffer_without_kind",
        _in_cs("        command: double\n"),
        9,
        16,
        "EARL-S006",
        "expected `/` and a kind after `command`, found `:`",
    ),
    Malformed(
        "unclosed_brace_at_eof",
        "system s\n\na/a {\n    cs {\n        period 1 ms\n",
        5,
        20,
        "EARL-S004",
        "the file ends before the `{` on line 4 is closed",
    ),
    Malformed(
        "second_system",
        "system s\nsystem t\n",
        2,
        1,
        "EARL-S007",
        "`system` cannot be written here",
    ),
    Malformed(
        "semicolon",
        _in_cs("        period 1 ms;\n"),
        9,
        20,
        "EARL-S001",
        "unexpected character `;`",
    ),
    Malformed(
        "single_quote_string",
        _in_cs("        f/pf(-> ) = python 'm:f'\n"),
        9,
        28,
        "EARL-S001",
        "unexpected character `'`",
    ),
    Malformed(
        "hash_comment",
        "system s\n# a comment\n",
        2,
        1,
        "EARL-S001",
        "unexpected character `#`",
    ),
    Malformed(
        "unicode_arrow",
        _in_cs("        f/pf(x/ib → y/mo)\n"),
        9,
        19,
        "EARL-S001",
        "unexpected character `→`",
    ),
    Malformed(
        "ampersand",
        _in_cs("        x/pp = true && false\n"),
        9,
        21,
        "EARL-S001",
        "unexpected character `&`",
    ),
    Malformed(
        "chained_comparison",
        _in_cs("        x/pp = 1 < 2 < 3\n"),
        9,
        22,
        "EARL-S006",
        "unexpected `<`",
    ),
    Malformed(
        "division",
        _in_cs("        v/ib: double\n        x/pp = v/ib / 2 > 1.0\n"),
        10,
        21,
        "EARL-S006",
        "there is no division: the `/` after `v/ib` would introduce a kind",
        "multiply instead: write `v/ib * 0.5` for `v/ib / 2`",
    ),
    Malformed(
        "memory_read_without_its_direction",
        _in_cs("        moving/m: boolean = false\n        x/pp = moving/m\n"),
        10,
        23,
        "EARL-S005",
        "`m` is not a kind of element that can stand here",
        "memory is declared `moving/m`, read as `moving/mi` and written as `moving/mo`; here, read it: `moving/mi`",
    ),
    Malformed(
        "memory_written_without_its_direction",
        _in_cs('        effort/m: double\n        relax/pf(-> effort/m) = python "m:f"\n'),
        10,
        28,
        "EARL-S005",
        "`m` is not a kind of element that can stand here",
        "memory is declared `effort/m`, read as `effort/mi` and written as `effort/mo`; here, write it: `effort/mo`",
    ),
    Malformed(
        "memory_read_in_a_header_without_its_direction",
        _in_cs('        effort/m: double\n        relax/pf(effort/m -> effort/mo) = python "m:f"\n'),
        10,
        25,
        "EARL-S005",
        "`m` is not a kind of element that can stand here",
        "memory is declared `effort/m`, read as `effort/mi` and written as `effort/mo`; here, read it: `effort/mi`",
    ),
    Malformed(
        "pf_without_arrow",
        _in_cs("        f/pf(x/ib, y/mo)\n"),
        9,
        24,
        "EARL-S003",
        "expected `->` between what `/pf` reads and what it writes, found `)`",
    ),
    Malformed(
        "link_without_arrow",
        "system s\n\nlink a,b: a/a.cs.out b/a.cs.in\n",
        3,
        22,
        "EARL-S003",
        "expected `->` between the two ends of the link, found `b`",
    ),
    Malformed(
        "cs_with_kind",
        "system s\n\na/a {\n    cs/ve {\n    }\n}\n",
        4,
        7,
        "EARL-S006",
        "expected `{` after `cs`, found `/`",
    ),
    Malformed(
        "bb_without_tc",
        _in_cs("        b/bb {\n            tf = {}\n        }\n"),
        11,
        9,
        "EARL-S006",
        "expected `tc` or `then`, found `}`",
    ),
    Malformed(
        "bb_without_tf",
        _in_cs("        b/bb {\n            tc = true\n        }\n"),
        10,
        13,
        "EARL-S006",
        "expected `tf` after `{`, found `tc`",
    ),
    Malformed(
        "ec_before_tc",
        _in_cs("        b/bb {\n            tf = {f/pf}\n            ec = true\n            tc = true\n        }\n"),
        11,
        13,
        "EARL-S006",
        "expected `tc` or `then`, found `ec`",
    ),
    Malformed(
        "fsm_without_initial",
        _in_cs("        fsm {\n            state idle: b/bb\n        }\n"),
        10,
        13,
        "EARL-S006",
        "expected `initial` after `{`, found `state`",
    ),
    Malformed(
        "state_names_pf",
        _in_cs("        fsm {\n            initial idle\n            state idle: b/pf\n        }\n"),
        11,
        25,
        "EARL-S014",
        "state `idle` must name a Basic Behaviour (`/bb`), not `/pf`",
    ),
    Malformed(
        "two_fsms",
        _in_cs("        fsm {\n            initial a\n        }\n        fsm {\n            initial b\n        }\n"),
        12,
        9,
        "EARL-S011",
        "`cs` declares a second `fsm`; a Subsystem has exactly one FSM",
    ),
    # A clause said once, written twice: refused at the second (EARL-S009), never "the last one wins".
    Malformed(
        "second_period",
        _in_cs("        period 1 ms\n        period 5 ms\n"),
        10,
        9,
        "EARL-S009",
        "a second `period` in `cs` (the first is on line 9): a subsystem runs at one period",
        "keep one `period`",
    ),
    Malformed(
        "second_state_timeout",
        _in_cs(
            "        fsm {\n            initial a\n            state a: b/bb { timeout 2 ms timeout 3 ms }\n        }\n"
        ),
        11,
        42,
        "EARL-S009",
        "a second `timeout` in state `a` (the first is on line 11)",
        "keep one `timeout`",
    ),
    Malformed(
        "second_initial",
        _in_cs("        fsm {\n            initial a\n            state a: b/bb\n            initial b\n        }\n"),
        12,
        13,
        "EARL-S009",
        "a second `initial` (the first is on line 10): an FSM has one initial state",
        "keep one `initial`",
    ),
    Malformed(
        "second_tf",
        _in_cs("        b/bb {\n            tf = {}\n            tf = {}\n            tc = true\n        }\n"),
        11,
        13,
        "EARL-S009",
        "a second `tf` (the first is on line 10): a Basic Behaviour has one transition function",
        "keep one `tf`",
    ),
    Malformed(
        "second_tc",
        _in_cs("        b/bb {\n            tf = {}\n            tc = true\n            tc = false\n        }\n"),
        12,
        13,
        "EARL-S009",
        "a second `tc` (the first is on line 11): a Basic Behaviour has one terminal condition",
        "keep one `tc`",
    ),
    Malformed(
        "second_ec",
        _in_cs(
            "        b/bb {\n            tf = {}\n            tc = true\n            ec = false\n"
            "            ec = true\n        }\n"
        ),
        13,
        13,
        "EARL-S009",
        "a second `ec` (the first is on line 12): a Basic Behaviour has one error condition",
        "keep one `ec`",
    ),
    Malformed(
        "second_fifo",
        _in_cs("        x/ib: int fifo 2 fifo 3\n"),
        9,
        26,
        "EARL-S009",
        "a second `fifo` (the first is on line 9): an Input Buffer has one capacity",
    ),
    Malformed(
        "second_overflow",
        _in_cs("        x/ib: int fifo 2 overflow dropOldest overflow fault\n"),
        9,
        46,
        "EARL-S009",
        "a second `overflow` (the first is on line 9): a FIFO has one overflow policy",
    ),
    Malformed(
        "second_priority",
        _in_cs("        fsm {\n            initial a\n            a -> a when true priority 1 priority 2\n        }\n"),
        11,
        41,
        "EARL-S009",
        "a second `priority` (the first is on line 11): a transition has one priority",
    ),
    Malformed(
        "second_when",
        _in_cs("        fsm {\n            initial a\n            a -> a when true when false\n        }\n"),
        11,
        30,
        "EARL-S009",
        "a second `when` (the first is on line 11): a transition has one condition",
        "join the conditions with `and` or `or`",
    ),
    Malformed(
        "negative_period",
        _in_cs("        period 0 ms\n"),
        9,
        16,
        "EARL-S012",
        "a duration must be positive, not 0",
    ),
    Malformed(
        "unknown_overflow",
        _in_cs("        x/ib: double fifo 4 overflow dropAll\n"),
        9,
        38,
        "EARL-S013",
        "unknown overflow policy `dropAll`",
    ),
    Malformed(
        "family_predicate",
        _in_cs("        p[K in 1..3]/pp = true\n"),
        9,
        11,
        "EARL-S016",
        "a Primitive Predicate cannot be an indexed family",
    ),
    Malformed(
        "link_family_two_indices",
        "system s\n\na/a {\n    link cs,m[K in 1..2]: cs.x[K] -> m[J in 1..2]/ve.y\n}\n",
        4,
        42,
        "EARL-S006",
        "expected `]`, found `in`",
    ),
    Malformed(
        "link_name_two_families",
        "system s\n\na/a {\n    link m[K in 1..2],n[J in 1..2]: m[K]/ve.x -> n[K]/ve.y\n}\n",
        4,
        25,
        "EARL-S010",
        "a link family declares one index; the other part of its name uses it",
    ),
    Malformed(
        "name_starts_with_digit",
        _in_cs("        1x/m: double\n"),
        9,
        9,
        "EARL-S006",
        "expected `false`, `fsm`, `param`, `period`, `stage`, `true`, `}` or a ",
    ),
    Malformed(
        "missing_type_after_colon",
        _in_cs("        x/m:\n        y/m: double\n"),
        9,
        12,
        "EARL-S006",
        "expected a data type after `:` at the end of line 9",
    ),
    Malformed(
        "missing_equals_in_pp",
        _in_cs("        x/pp true\n"),
        9,
        14,
        "EARL-S006",
        "expected `(` or `=` after `pp`, found `true`",
    ),
    Malformed(
        "param_without_value",
        "system s\n\nparam N: int\n",
        3,
        13,
        "EARL-S004",
        "the file ends but `=` or `[` was expected",
    ),
    Malformed(
        "import_without_quotes",
        "system s\nimport types.earl\n",
        2,
        8,
        "EARL-S006",
        "expected a string in double quotes after `import`, found `types`",
    ),
    Malformed(
        "unclosed_paren_expression",
        _in_cs("        x/pp = (true and false\n        y/pp = true\n"),
        9,
        31,
        "EARL-S006",
        "expected `)`, found `y`",
    ),
    Malformed(
        "unclosed_string",
        _in_cs('        f/pf(->) = python "m:f\n'),
        9,
        27,
        "EARL-S002",
        "this string is not closed on its line",
    ),
    Malformed(
        "priority_not_number",
        _in_cs("        fsm {\n            initial a\n            a -> b when true priority high\n        }\n"),
        11,
        39,
        "EARL-S006",
        "expected a whole number after `priority`, found `high`",
    ),
    Malformed(
        "transition_without_when",
        _in_cs("        fsm {\n            initial a\n            a -> b\n        }\n"),
        11,
        19,
        "EARL-S006",
        "expected `when` after `b`, found `}`",
    ),
    Malformed(
        "agent_inside_agent",
        "system s\n\na/a {\n    b/a {\n    }\n}\n",
        4,
        7,
        "EARL-S005",
        "`a` is not a kind of element that can stand here; expected a subsystem",
    ),
    Malformed(
        "struct_inside_agent",
        "system s\n\na/a {\n    cs {\n    }\n\nstruct P {\n    x: double\n}\n",
        7,
        1,
        "EARL-S007",
        "`struct` cannot be written here",
    ),
    Malformed(
        "stray_closing_brace",
        "system s\n\na/a {\n}\n}\n",
        5,
        1,
        "EARL-S006",
        "this `}` closes nothing: every bracket before it is already closed",
    ),
    Malformed(
        "expression_too_deep",
        _in_cs(
            "        x/pp = not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not not true\n"
        ),
        9,
        92,
        "EARL-S015",
        "this expression is nested more than 100 levels deep",
    ),
    Malformed(
        "array_too_deep",
        "system s\n\ntype T = int[1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1][1]\n",
        3,
        10,
        "EARL-S017",
        "this array type has more than 32 dimensions",
    ),
    # a bracket opening a line is stray: pointed at itself, not at the end of the line before it
    Malformed(
        "stray_brace_at_a_line_start",
        "system s\n\nx/a {\n    cs {\n        v/ib: int\n\n        { w/m: int = 0\n    }\n}\n",
        7,
        9,
        "EARL-S006",
        "unexpected `{` after `int`",
        "this `{` belongs to nothing before it",
    ),
    Malformed(
        "stray_bracket_at_a_line_start",
        "system s\n\nx/a {\n    cs {\n        v/ib: int\n        ] w/m: int = 0\n    }\n}\n",
        6,
        9,
        "EARL-S006",
        "unexpected `]` after `int`",
        "this `]` belongs to nothing before it",
    ),
    Malformed(
        "brace_on_the_next_line_of_a_tf_without_its_equals",
        "system s\nx/a {\n    cs {\n        work/pf(->)\n        b/bb {\n            tf\n            {work/pf}\n"
        "            tc = true\n        }\n    }\n}\n",
        6,
        15,
        "EARL-S006",
        "expected `=` after `tf`, found `{`",
        "a transition function is written `tf = {first/pf",
    ),
    Malformed(
        "comment_between_any_state_and_arrow",
        "system s\nx/a {\n    cs {\n        fsm {\n            initial r\n            state r: b/bb\n"
        "            *  // from every state\n                -> r when\n        }\n    }\n}\n",
        8,
        26,
        "EARL-S006",
        "expected an expression",
    ),
    # a string's escapes are JSON's: what JSON refuses is pointed at, never a traceback
    Malformed(
        "string_with_unknown_escape",
        'system s\nparam P: string = "a\\qb"\n',
        2,
        21,
        "EARL-S018",
        "`\\q` is not an escape a string can hold",
        "the escapes of JSON",
    ),
    Malformed(
        "string_with_short_unicode_escape",
        _in_cs('        f/pf(->) = python "m:\\u12"\n'),
        9,
        30,
        "EARL-S018",
        "`\\u12` is not an escape a string can hold",
        "four hexadecimal digits",
    ),
    Malformed(
        "string_with_a_tab",
        'system s\nimport "lib\tx.earl"\n',
        2,
        12,
        "EARL-S018",
        "a string cannot hold the control character U+0009 as it is",
        "`\\t` for a tab",
    ),
    Malformed(
        "string_with_half_a_surrogate_pair",
        _in_cs('        label/m: string = "\\ud800"\n'),
        9,
        27,
        "EARL-S018",
        "half of a surrogate pair (`\\ud800`)",
        "both halves of its pair",
    ),
    Malformed(
        "number_with_five_thousand_digits",
        "system s\nparam N: int = " + "9" * 5000 + "\n",
        2,
        16,
        "EARL-S019",
        "(5000 characters) has more digits than any EARL number type holds",
    ),
    Malformed(
        "duration_of_infinity",
        _in_cs("        period 1e999 ms\n"),
        9,
        16,
        "EARL-S012",
        "a duration is at most 1,000,000,000 s",
    ),
    Malformed(
        "block_comment_after_a_value",
        "system s\n\nparam N: int = 1\n\n/* a block */\nparam M: int = 2\n",
        5,
        1,
        "EARL-S006",
        "`/*` does not start a comment: EARL has line comments only",
    ),
    Malformed(
        "block_comment_after_the_system_line",
        "system s\n/* a block */\n",
        2,
        1,
        "EARL-S006",
        "`/*` does not start a comment",
    ),
    Malformed(
        "duration_below_a_nanosecond",
        _in_cs("        period 0.0001 us\n"),
        9,
        16,
        "EARL-S012",
        "a duration is at least 1 ns (earl keeps time in whole nanoseconds), not `0.0001` us",
    ),
    Malformed(
        "duration_of_centuries",
        _in_cs("        period 1e13 s\n"),
        9,
        16,
        "EARL-S012",
        "a duration is at most 1,000,000,000 s",
    ),
    Malformed(
        "unexpected_character_dollar",
        _in_cs("        x/pp = $true\n"),
        9,
        16,
        "EARL-S001",
        "unexpected character `$`",
    ),
    Malformed(
        "non_ascii_name",
        _in_cs("        été/m: double\n"),
        9,
        9,
        "EARL-S001",
        "unexpected character `é`",
    ),
    Malformed(
        "misspelt_initial",
        _in_cs("        fsm {\n            inital idle\n        }\n"),
        10,
        13,
        "EARL-S006",
        "expected `initial` after `{`, found `inital`",
    ),
    Malformed(
        "misspelt_obligatory",
        _in_cs(
            "        fsm {\n            initial idle\n            state idle: b/bb { obligatroy x/ib }\n        }\n"
        ),
        11,
        32,
        "EARL-S006",
        "expected `obligatory`, `optional`, `timeout` or `}` after `{`, found `",
    ),
    Malformed(
        "missing_comma_in_pf_reads",
        _in_cs("        f/pf(x/ib y/ib -> z/mo)\n"),
        9,
        19,
        "EARL-S003",
        "expected `,` or `->` before `y`",
    ),
    Malformed(
        "empty_family_index",
        _in_cs("        x[]/m: double\n"),
        9,
        11,
        "EARL-S006",
        "expected a name after `[`, found `]`",
    ),
    Malformed(
        "family_without_in",
        _in_cs("        x[K 1..3]/m: double\n"),
        9,
        13,
        "EARL-S006",
        "expected `in` after `K`, found `1`",
    ),
    Malformed(
        "quantifier_without_colon",
        _in_cs("        x/pp = any(K in 1..3 y[K]/ib)\n"),
        9,
        30,
        "EARL-S006",
        "expected `:`, found `y`",
    ),
    Malformed(
        "tf_then_without_set",
        _in_cs("        b/bb {\n            tf = {f/pf} then\n            tc = true\n        }\n"),
        10,
        29,
        "EARL-S006",
        "expected `{` after `then`, found `tc`",
    ),
    Malformed(
        "duration_unit_alone",
        _in_cs("        fsm {\n            initial a\n            state a: b/bb { timeout ms }\n        }\n"),
        11,
        37,
        "EARL-S006",
        "expected a number after `timeout`, found `ms`",
    ),
    Malformed(
        "robot_with_subsystem",
        "system s\n\nr/r {\n    cs {\n    }\n}\n",
        4,
        5,
        "EARL-S007",
        "`cs` cannot be written here",
    ),
    Malformed(
        "link_end_without_buffer",
        "system s\n\nlink a,b: a/a.cs -> b/a.cs.in\n",
        3,
        18,
        "EARL-S006",
        "expected `.` after `cs`, found `->`",
    ),
    Malformed(
        "or_at_end",
        _in_cs("        x/pp = true or\n        y/pp = false\n"),
        9,
        21,
        "EARL-S006",
        "expected an expression after `or` at the end of line 9",
    ),
]

NAMES = [
    Malformed(
        "misspelt_memory",
        _in_cs("        toggles/m: int = 0\n        done/pp = toggle/mi >= 6\n"),
        10,
        19,
        "EARL-R022",
        "`a/a.cs` has no Internal Memory `toggle`",
        hint="did you mean `toggles`?",
    ),
    Malformed(
        "unknown_type",
        _in_cs("        pose/m: Pose2\n") + "\nstruct Pose2D {\n    x: double\n}\n",
        9,
        17,
        "EARL-R012",
        "unknown data type `Pose2`",
        hint="did you mean `Pose2D`?",
    ),
    Malformed(
        "duplicate_memory",
        _in_cs("        x/m: int\n        x/m: double\n"),
        10,
        9,
        "EARL-R002",
        "`x/m` is declared twice (first declared at line 9)",
        hint="give each element its own name",
    ),
    Malformed(
        "unknown_state_in_transition",
        _in_cs(
            "        false/pp = false\n        b/bb {\n            tf = {}\n            tc = false/pp\n        }\n        fsm {\n            initial idle\n            state idle: b/bb\n            idle -> idel when false/pp\n        }\n"
        ),
        17,
        21,  # the misspelt state, not the whole transition
        "EARL-R032",
        "transition `idle,idel/t` names the state `idel`, which this FSM does n",
        hint="did you mean `idle`?",
    ),
    Malformed(
        "unknown_state_in_transition_with_no_near_name",
        _in_cs(
            "        false/pp = false\n        b/bb {\n            tf = {}\n            tc = false/pp\n        }\n        fsm {\n            initial idle\n            state idle: b/bb\n            idle -> grasp when false/pp\n        }\n"
        ),
        17,
        21,  # the misspelt state, not the whole transition
        "EARL-R032",
        "transition `idle,grasp/t` names the state `grasp`, which this FSM does not declare",
        hint="its states are `idle`; declare `state grasp: BEHAVIOUR/bb` to add one",
    ),
    Malformed(
        "initial_not_a_state",
        _in_cs(
            "        false/pp = false\n        b/bb {\n            tf = {}\n            tc = false/pp\n        }\n        fsm {\n            initial start\n            state idle: b/bb\n        }\n"
        ),
        15,
        21,
        "EARL-R031",
        "the initial state `start` is not a state of this FSM",
        hint="add `state start: start/bb`",
    ),
    Malformed(
        "unknown_parameter",
        _in_cs("        period 1 ms\n        x/m: double[SIZE]\n"),
        10,
        21,
        "EARL-R014",
        "an array size must be a constant: `SIZE` is not a parameter or index i",
        hint=None,
    ),
    Malformed(
        "negative_family_range",
        _in_cs("    }\n    m[K in 1..-5]/ve {\n"),
        10,
        7,
        "EARL-R016",
        "the family range 1..-5 is empty",
        hint="the last index must not be smaller than the first",
    ),
    Malformed(
        "huge_family_range",
        _in_cs("    }\n    m[K in 1..1000000000]/ve {\n"),
        10,
        7,
        "EARL-R017",
        "the family range 1..1000000000 has 1,000,000,000 members; at most 100,",
        hint=None,
    ),
    Malformed(
        "unknown_field",
        "system s\n\nstruct C {\n    stop: boolean\n}\n\nr/r {\n    a/a\n}\n\na/a {\n    cs {\n        c/ib: C\n        s/pp = c/ib.stpo\n    }\n}\n",
        14,
        21,
        "EARL-R045",
        "`C` has no field `stpo`",
        hint="did you mean `stop`?",
    ),
    Malformed(
        "robot_names_unknown_agent",
        "system s\n\nr/r {\n    b/a\n}\n\na/a {\n    cs {\n    }\n}\n",
        4,
        5,
        "EARL-R056",
        "robot `r/r` refers to the agent `b/a`, which is not declared",
        hint=None,
    ),
    Malformed(
        "newdata_of_memory",
        _in_cs("        x/m: boolean\n        p/pp = newData(x/mi)\n"),
        10,
        24,
        "EARL-R042",
        "`newData(…)` applies to an Input Buffer, e.g. `newData(manipulatorComm",
        hint=None,
    ),
    Malformed(
        "unknown_function",
        _in_cs("        c/ib: boolean\n        p/pp = newDat(c/ib)\n"),
        10,
        16,
        "EARL-R040",
        "unknown function `newDat`",
        hint="did you mean `newData`?",
    ),
    Malformed(
        "python_as_a_function_of_a_condition",
        _in_cs("        m/m: int = 0\n        p/pp = python(m/mi)\n"),
        10,
        16,
        "EARL-R040",
        "`python(…)` is no function of a condition",
        hint='a predicate computed by Python is declared `NAME/pp(READS) = python "MODULE:FUNCTION"`, '
        "and named in conditions as `NAME/pp`",
    ),
    Malformed(
        "stale_of_a_memory",
        _in_cs("        m/m: int = 0\n        p/pp = stale(m/mi)\n"),
        10,
        22,
        "EARL-R042",
        "`stale(…)` applies to an Input Buffer, e.g. `stale(manipulatorCommand/ib)`",
        hint=None,
    ),
    Malformed(
        "link_unknown_buffer",
        "system s\n\nr/r {\n    a/a\n}\n\na/a {\n    cs {\n        out/ob: double\n    }\n    d/ve {\n        in/ib: double\n    }\n    link cs,d: cs.out -> d/ve.inn\n}\n",
        14,
        31,
        "EARL-R054",
        "`a/a.d/ve` has no Input Buffer `inn`",
        hint="did you mean `in`?",
    ),
    Malformed(
        "link_wrong_direction",
        "system s\n\nr/r {\n    a/a\n}\n\na/a {\n    cs {\n        out/ob: double\n    }\n    d/ve {\n        in/ib: double\n    }\n    link d,cs: d/ve.in -> cs.out\n}\n",
        14,
        21,
        "EARL-R054",
        "`a/a.d/ve` has no Output Buffer `in`",
        hint="`in` is an Input Buffer there; a link runs from an Output Buffer to an Input Buffer",
    ),
]


def _first_error(text: str) -> tuple[EarlError, Diagnostic]:
    with pytest.raises(EarlError) as caught:
        earl.loads(text, "spec.earl")
    return caught.value, caught.value.diagnostics[0]


def test_there_are_at_least_forty_malformed_specs() -> None:
    assert len(SYNTAX) + len(NAMES) >= 40
    assert len({case.name for case in SYNTAX + NAMES}) == len(SYNTAX) + len(NAMES)


@pytest.mark.parametrize("case", SYNTAX, ids=lambda case: case.name)
def test_a_syntax_error_is_one_located_sentence(case: Malformed) -> None:
    error, diagnostic = _first_error(case.text)
    assert len(error.diagnostics) == 1  # a syntax error stops reading the file
    assert diagnostic.location is not None
    assert (diagnostic.location.file, diagnostic.location.line, diagnostic.location.column) == (
        "spec.earl",
        case.line,
        case.column,
    )
    assert diagnostic.code == case.code
    assert case.fragment in diagnostic.message
    assert "\n" not in diagnostic.message
    assert "Token(" not in diagnostic.message and "Tree(" not in diagnostic.message  # no parser internals
    if case.hint is not None:  # a fragment of it
        assert case.hint in (diagnostic.hint or "")


@pytest.mark.parametrize("case", NAMES, ids=lambda case: case.name)
def test_a_name_error_is_located_and_hinted(case: Malformed) -> None:
    _error, diagnostic = _first_error(case.text)
    assert diagnostic.location is not None
    assert (diagnostic.location.line, diagnostic.location.column) == (case.line, case.column)
    assert diagnostic.code == case.code
    assert case.fragment in diagnostic.message
    assert diagnostic.hint == case.hint


def test_the_command_prints_file_line_column_source_line_caret_and_hint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("lamp.earl").write_text(_in_cs("        toggles/m: int = 0\n        done/pp = toggle/mi >= 6\n"))
    assert main(["check", "lamp.earl"]) == 1
    output = capsys.readouterr()
    printed = output.out + output.err
    assert "error[EARL-R022]: `a/a.cs` has no Internal Memory `toggle`" in printed
    assert "--> lamp.earl:10:19" in printed
    lines = printed.splitlines()
    source = lines.index("10 |         done/pp = toggle/mi >= 6")
    assert lines[source + 1] == "   |                   ^^^^^^^^^"
    assert "= hint: did you mean `toggles`?" in lines[source + 2]
    assert "Traceback" not in printed


def test_a_syntax_error_from_the_command_exits_1_with_a_caret(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("fsm.earl").write_text(SYNTAX[0].text)
    assert main(["check", "fsm.earl"]) == 1
    output = capsys.readouterr()
    printed = output.out + output.err
    assert "error[EARL-S003]: expected `->` after the source state `idle`" in printed
    assert "--> fsm.earl:18:18" in printed
    assert "18 |             idle busy when x/pp" in printed
    assert "   |                  ^^^^" in printed


@pytest.mark.parametrize(
    "arguments",
    [["check", "no-such-file.earl"], ["check", "--no-such-option", "x.earl"], ["fmt", "no-such-file.earl"], []],
    ids=["missing file", "unknown option", "fmt missing file", "no command"],
)
def test_usage_errors_exit_2(
    arguments: list[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    try:
        code = main(arguments)
    except SystemExit as exit:  # argparse refuses an unknown option by exiting
        code = int(exit.code or 0)
    assert code == 2
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize("column", [1, 20, 500, 981, 1000])
def test_a_long_source_line_is_cut_around_the_spot(column: int) -> None:
    """At most SHOWN_COLUMNS of a 1,000-column line, `…` where it was cut, the caret under the same text."""
    from earl.diagnostics import SHOWN_COLUMNS, Diagnostic, Severity, SourceMap, render
    from earl.model.location import SourceLocation

    line = "".join(chr(ord("a") + i % 26) for i in range(1000))
    sources = SourceMap()
    sources.add("long.earl", "system s\n" + line + "\n")
    location = SourceLocation("long.earl", 2, column, 2, column + 3)
    text = render(Diagnostic(Severity.ERROR, "here", location, code="EARL-S006"), sources)
    _, _, _, shown, carets = text.splitlines()
    quoted = shown[len("2 | ") :]
    assert len(quoted) <= SHOWN_COLUMNS + 2  # and the two `…`
    assert quoted.startswith("…") == (column > 31) and quoted.endswith("…") == (column < 900)
    start = carets.index("^") - len("  | ")
    width = carets.count("^")
    assert quoted[start : start + width] == line[column - 1 : column - 1 + width]
    assert width == min(3, 1001 - column)


def test_a_star_before_a_comment_holding_an_arrow_is_still_a_multiplication_and_quick(tmp_path: Path) -> None:
    """`* // a -> b` then a number: the `->` is in the comment, so the `*` multiplies; and a comment of many
    `//` after a `*` took exponential time to look past (the any-state lookahead split it every way)."""
    import time

    path = tmp_path / "star.earl"
    slashes = " //" * 40
    path.write_text(f"system s\nparam M: int = 2 * // twice -> more\n    3\nparam N: int = 2 *{slashes}\n    3\n")
    started = time.monotonic()
    system = earl.load(path)
    assert time.monotonic() - started < 5
    assert [p.name for p in system.parameters] == ["M", "N"]
