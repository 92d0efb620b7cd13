"""Which comments of a model built in Python `.earl` text cannot hold.

The language has line comments only (`// …` to the end of the line), so a comment set in Python as
`/* x */`, as plain text, or across two lines would be written as text that does not read back. Blank
("" or spaces) is a blank line between comments; spaces around a comment are dropped when it is written.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

from earl.model.location import Comments

#: the fields that hold comments without taking part in equality (the walk follows those that do)
_COMMENT_FIELDS = ("comments", "clause_comments", "member_comments")


def is_writable_comment(comment: object) -> bool:
    """Whether `comment` is one line comment (`// …`) or blank, once the spaces around it are dropped."""
    if not isinstance(comment, str):
        return False
    text = comment.strip()
    return text == "" or (text.startswith("//") and "\n" not in text and "\r" not in text)


def unwritable_comments(root: object, path: str = "system") -> Iterator[tuple[str, object]]:
    """Each comment of `root`'s model tree that is not writable, with its path
    (`system.agents[0].subsystems[1].comments.closing[0]`), in the order of the tree."""
    stack: list[tuple[object, str]] = [(root, path)]
    seen: set[int] = set()
    while stack:
        value, where = stack.pop()
        if isinstance(value, Comments):
            yield from _in_comments(value, where)
        elif isinstance(value, list | tuple):
            stack.extend((item, f"{where}[{i}]") for i, item in reversed(list(enumerate(value))))
        elif isinstance(value, dict):
            stack.extend((item, f"{where}[{key!r}]") for key, item in reversed(list(value.items())))
        elif dataclasses.is_dataclass(value) and not isinstance(value, type) and id(value) not in seen:
            seen.add(id(value))
            fields = [f for f in dataclasses.fields(value) if f.compare or f.name in _COMMENT_FIELDS]
            stack.extend((getattr(value, f.name, None), f"{where}.{f.name}") for f in reversed(fields))


def _in_comments(comments: Comments, where: str) -> Iterator[tuple[str, object]]:
    for attribute in ("leading", "closing"):
        lines = getattr(comments, attribute)
        if isinstance(lines, list | tuple):
            for i, comment in enumerate(lines):
                if not is_writable_comment(comment):
                    yield f"{where}.{attribute}[{i}]", comment
    for attribute in ("trailing", "after"):
        comment = getattr(comments, attribute)
        # a comment after code cannot be a blank line: "" and None both mean none
        if comment is not None and not is_writable_comment(comment):
            yield f"{where}.{attribute}", comment
