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
    (`system.agents[0].subsystems[1].comments.closing[0]`), in the order of the tree.

    `earl check` walks every model it checks, a 1,000-agent one included: the way to each value is kept as
    a chain of steps and put in words only for a comment that is reported, and only values that can hold
    a comment are visited."""
    stack: list[tuple[object, _Steps]] = [(root, None)]
    seen: set[int] = set()
    while stack:
        value, steps = stack.pop()
        if isinstance(value, Comments):
            for where, comment in _in_comments(value):
                yield _spelled(path, steps) + where, comment
        elif isinstance(value, list | tuple):
            for index in range(len(value) - 1, -1, -1):
                item = value[index]
                if not isinstance(item, _LEAVES):
                    stack.append((item, (steps, index)))
        elif isinstance(value, dict):
            for key, item in reversed(list(value.items())):
                if not isinstance(item, _LEAVES):
                    stack.append((item, (steps, _Key(key))))
        elif dataclasses.is_dataclass(value) and not isinstance(value, type) and id(value) not in seen:
            seen.add(id(value))
            for name in reversed(_walked_fields(type(value))):
                item = getattr(value, name, None)
                if not isinstance(item, _LEAVES):
                    stack.append((item, (steps, name)))


#: values that hold no comment, left out of the walk
_LEAVES = (str, int, float, type(None))


class _Key:
    """A step into a dict, by its key."""

    __slots__ = ("key",)

    def __init__(self, key: object) -> None:
        self.key = key


#: the way from the root: (the way to the parent, a step: an attribute name, an index or a _Key)
_Steps = tuple["_Steps", "str | int | _Key"] | None

_FIELDS: dict[type, tuple[str, ...]] = {}


def _walked_fields(cls: type) -> tuple[str, ...]:
    names = _FIELDS.get(cls)
    if names is None:
        fields = dataclasses.fields(cls)  # type: ignore[arg-type]
        names = _FIELDS[cls] = tuple(f.name for f in fields if f.compare or f.name in _COMMENT_FIELDS)
    return names


def _spelled(path: str, steps: _Steps) -> str:
    words: list[str] = []
    while steps is not None:
        steps, step = steps
        if isinstance(step, str):
            words.append(f".{step}")
        elif isinstance(step, _Key):
            words.append(f"[{step.key!r}]")
        else:
            words.append(f"[{step}]")
    return path + "".join(reversed(words))


def _in_comments(comments: Comments) -> Iterator[tuple[str, object]]:
    for attribute in ("leading", "closing"):
        lines = getattr(comments, attribute)
        if isinstance(lines, list | tuple):
            for i, comment in enumerate(lines):
                if not is_writable_comment(comment):
                    yield f".{attribute}[{i}]", comment
    for attribute in ("trailing", "after"):
        comment = getattr(comments, attribute)
        # a comment after code cannot be a blank line: "" and None both mean none
        if comment is not None and not is_writable_comment(comment):
            yield f".{attribute}", comment
