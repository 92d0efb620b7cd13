"""Link patterns of `--record-links` and run.toml's `record_links`: globs over the links' names.

A link is named as in the spec, with its members' indices in brackets: `sorter,pusher[2]`,
`pusher[2]/a:cs,arm`. So brackets in a pattern name an index, as everywhere else in earl, not a
character class as in a shell's globs: `[2]` is member 2, and `[*]` or the family's index variable
(`[K]`) is every member. `*` is any run of characters and `?` any one, as in a glob.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from functools import lru_cache

from earl.diagnostics import did_you_mean

#: what is between a pattern's brackets: a member's number, `*`, or an index variable
_INDEX = re.compile(r"[0-9]+|\*|[A-Za-z_]\w*")
#: the links shown at most when a pattern matches none (families shown once, as `x[*]`)
SHOWN = 12


def link_pattern_problem(pattern: str) -> str | None:
    """Why `pattern` is no link pattern (brackets that hold no index, or are not closed), or None."""
    try:
        _compiled(pattern)
    except ValueError as error:
        return str(error)
    return None


def matches(pattern: str, link: str) -> bool:
    """Whether `link` (`sorter,pusher[2]`) is one `pattern` names; a pattern that is no link pattern
    (`link_pattern_problem`) names none."""
    try:
        return _compiled(pattern).fullmatch(link) is not None
    except ValueError:
        return False


def no_link_matched(pattern: str, links: Iterable[str]) -> str:
    """What is said of `pattern` after its name when it matches none of `links`: the names one can write, a family
    once as `x[*]` (its members listed one by one would crowd out every other link)."""
    names = sorted(links)
    written = sorted(dict.fromkeys(re.sub(r"\[[0-9]+\]", "[*]", name) for name in names))
    shown = ", ".join(written[:SHOWN]) + (f" and {len(written) - SHOWN} more" if len(written) > SHOWN else "")
    hint = did_you_mean(pattern, names)
    return "matches no link" + (f"; {hint}" if hint else "") + f" (the links: {shown or 'none'})"


@lru_cache(maxsize=256)  # a pattern is matched against each link of the run
def _compiled(pattern: str) -> re.Pattern[str]:
    """`pattern` as a regular expression; a ValueError saying what is wrong with it."""
    parts: list[str] = []
    position = 0
    while position < len(pattern):
        character = pattern[position]
        if character == "[":
            end = pattern.find("]", position)
            if end < 0:
                raise ValueError(
                    f"`{pattern}`: the `[` at character {position + 1} is not closed; brackets name a member, "
                    "`pusher[2]`, or every one, `pusher[*]`"
                )
            index = pattern[position + 1 : end].strip()
            if not _INDEX.fullmatch(index):
                raise ValueError(
                    f"`{pattern}`: `[{pattern[position + 1 : end]}]` is no index; brackets name a member by its "
                    "number, `pusher[2]`, or every one, `pusher[*]` (or `pusher[K]`), as in the spec"
                )
            parts.append(rf"\[{int(index)}\]" if index.isdigit() else r"\[[0-9]+\]")
            position = end + 1
            continue
        parts.append({"*": ".*", "?": "."}.get(character) or re.escape(character))
        position += 1
    return re.compile("".join(parts), re.DOTALL)
