"""Link patterns of `--record-links` and run.toml's `record_links`: globs over the links' names.

A link is named as in the spec, with its members' indices in brackets: `sorter,pusher[2]`,
`pusher[2]/a:cs,arm`. So brackets holding a member's number name that member, and `[*]` or the
index variable the family declares (`[K]` of `pusher[K in 1..N]`) every member. Brackets holding
anything else are a glob's character class, as in a shell (`task,[mg]*` is `task,manip` and
`task,gripper`), so the patterns written before families had names keep matching what they did.
`*` is any run of characters and `?` any one.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from fnmatch import translate
from functools import lru_cache

from earl.diagnostics import did_you_mean

#: what is between a pattern's brackets when they name members whatever the family: a number or `*`
_ANY_FAMILY_INDEX = re.compile(r"[0-9]+|\*")
#: the links shown at most when a pattern matches none (families shown once, as `x[*]`)
SHOWN = 12


def matches(pattern: str, link: str, index_variables: frozenset[str] = frozenset()) -> bool:
    """Whether `link` (`sorter,pusher[2]`) is one `pattern` names; `index_variables` are those of the
    families `link` is a member of (`K` of `link sorter,pusher[K in 1..N]`, or of its agent's family)."""
    return _compiled(pattern, index_variables).fullmatch(link) is not None


def matching(pattern: str, links: Mapping[str, frozenset[str]]) -> list[str]:
    """The links (each with its families' index variables, `Network.link_index_variables`) `pattern` names."""
    return [link for link, variables in links.items() if matches(pattern, link, variables)]


def no_link_matched(pattern: str, links: Iterable[str]) -> str:
    """What is said of `pattern` after its name when it matches none of `links`: the names one can write, a family
    once as `x[*]` (its members listed one by one would crowd out every other link)."""
    names = sorted(links)
    written = sorted(dict.fromkeys(re.sub(r"\[[0-9]+\]", "[*]", name) for name in names))
    shown = ", ".join(written[:SHOWN]) + (f" and {len(written) - SHOWN} more" if len(written) > SHOWN else "")
    hint = did_you_mean(pattern, names)
    return "matches no link" + (f"; {hint}" if hint else "") + f" (the links: {shown or 'none'})"


@lru_cache(maxsize=256)  # a pattern is matched against each link of the run, with few sets of variables
def _compiled(pattern: str, index_variables: frozenset[str]) -> re.Pattern[str]:
    """`pattern` as a regular expression: the brackets that name members as an index, the rest as
    `fnmatch` takes it (an unclosed `[` is itself, as there)."""
    parts: list[str] = []
    glob_from = position = 0
    while position < len(pattern):
        end = _class_end(pattern, position) if pattern[position] == "[" else -1
        if end < 0:
            position += 1
            continue
        index = pattern[position + 1 : end]
        if _ANY_FAMILY_INDEX.fullmatch(index) or index in index_variables:
            parts.append(_glob(pattern[glob_from:position]))
            parts.append(rf"\[{int(index)}\]" if index.isdigit() else r"\[[0-9]+\]")
            glob_from = end + 1
        position = end + 1
    parts.append(_glob(pattern[glob_from:]))
    return re.compile("".join(parts))


def _class_end(pattern: str, start: int) -> int:
    """Where the `]` closing the `[` at `start` is, by fnmatch's rules (`[!]]`, `[]]`), or -1."""
    end = start + 1
    if end < len(pattern) and pattern[end] == "!":
        end += 1
    if end < len(pattern) and pattern[end] == "]":
        end += 1
    end = pattern.find("]", end)
    return end


def _glob(text: str) -> str:
    """A glob without member indices as a regular expression to join with others (fnmatch's, unanchored)."""
    return translate(text).removesuffix(r"\Z") if text else ""
