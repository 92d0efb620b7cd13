"""Where a key is written in a TOML file: `tomllib` gives values, not lines, and a message about a
setting (run.toml, deploy.toml) says `FILE:LINE:` so that an editor opens it there.

The file is read line by line as TOML writes keys: `key = …`, `"key" = …`, a dotted `key.sub = …`
(the line of `key`), `[table]` and `[[table]]` headers. A line inside a multi-line string that looks
like a key may be taken for one; the message then names a line near the key, never a wrong file."""

from __future__ import annotations

import json
import math
import re
import tomllib
from dataclasses import dataclass, field

_KEY = r"""(?:"([^"]*)"|'([^']*)'|([A-Za-z0-9_-]+))"""
#: `key = …`, `"key" = …`, and the first part of a dotted key (`plot.x = …` sets the top-level `plot`)
_ASSIGNMENT = re.compile(rf"\s*{_KEY}\s*[=.]")
#: `[table]`, `[[table]]`, `[table.sub]`: a top-level key too
_TABLE = re.compile(rf"\s*(\[\[?)\s*{_KEY}\s*(\]\]?)?")


@dataclass(frozen=True)
class TomlTable:
    """One table as written: the top level (`name` ""), a `[name]` or each `[[name]]` of an array."""

    name: str
    #: the line of its header (1 for the top level, which has none)
    line: int
    #: `[[name]]`: one table of an array of tables, named by that one key
    in_array: bool = False
    #: the line each of its keys is set on
    keys: dict[str, int] = field(default_factory=dict)
    #: the last line before the next header (or the file's end)
    end: int = 0


def _key(match: re.Match[str], first: int) -> str:
    return next(group for group in match.groups()[first : first + 3] if group is not None)


def toml_tables(text: str) -> list[TomlTable]:
    """The top level and then each table of `text`, in the order written, with the line of each key."""
    lines = text.split("\n")
    tables = [TomlTable("", 1)]
    ends: list[int] = []
    for number, line in enumerate(lines, start=1):
        header = _TABLE.match(line)
        if header is not None:
            ends.append(number - 1)
            whole = header.group(1) == "[[" and header.group(5) == "]]"  # `[[name]]`, not `[[name.sub]]`
            tables.append(TomlTable(_key(header, 1), number, in_array=whole))
            continue
        assignment = _ASSIGNMENT.match(line)
        if assignment is not None:
            tables[-1].keys.setdefault(_key(assignment, 0), number)
    ends.append(len(lines))
    return [TomlTable(t.name, t.line, t.in_array, t.keys, end) for t, end in zip(tables, ends, strict=True)]


def key_lines(text: str) -> dict[str, int]:
    """The line each top-level key is set on (`report = "…"`, `"report" = "…"`, `[table]`, `[[table]]`)."""
    tables = toml_tables(text)
    lines = dict(tables[0].keys)
    for table in tables[1:]:
        lines.setdefault(table.name, table.line)
    return lines


def value_line(text: str, table: TomlTable, key: str, value: str, nth: int = 1) -> int | None:
    """The line of the string `value` in `key`'s list of `table` (`agents = [` on one line, `"grip/a",`
    on another), the `nth` time it is written; the key's own line when it is not found, None for a key
    the table does not set."""
    start = table.keys.get(key)
    if start is None:
        return None
    following = [line for line in table.keys.values() if line > start]
    end = min(following, default=table.end + 1) - 1
    written = (json.dumps(value, ensure_ascii=False), f"'{value}'")
    seen = 0
    for number, line in enumerate(text.split("\n")[start - 1 : end], start=start):
        seen += sum(line.count(form) for form in written)
        if seen >= nth:
            return number
    return start


def as_written(value: object) -> str:
    """A value as TOML writes it (`true`, `"x"`, `["a"]`), not as Python prints it (`True`, `'x'`);
    control characters escaped, and cut when long."""
    if isinstance(value, bool):
        shown = "true" if value else "false"
    elif isinstance(value, str):
        shown = json.dumps(value, ensure_ascii=False)
    elif isinstance(value, float) and not math.isfinite(value):
        shown = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    elif isinstance(value, list):
        shown = "[" + ", ".join(as_written(item) for item in value) + "]"
    elif isinstance(value, dict):
        shown = "a table"
    else:  # a number, a date or a time
        shown = value.isoformat() if hasattr(value, "isoformat") else str(value)
    return shown if len(shown) <= 60 else shown[:59] + "…"


def invalid_toml(shown: str, error: tomllib.TOMLDecodeError) -> str:
    """`run.toml:3:5: not valid TOML: Invalid value`: tomllib says where at the end of its message."""
    message = str(error)
    at = re.fullmatch(r"(.*) \(at line (\d+), column (\d+)\)", message, re.DOTALL)
    if at is None:
        return f"{shown}: not valid TOML: {message}"
    return f"{shown}:{at.group(2)}:{at.group(3)}: not valid TOML: {at.group(1)}"
