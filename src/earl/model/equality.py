"""Equality of the model's mutable classes that takes a list and a tuple of the same items as equal.

The reader makes lists where a class declares a list and tuples where it declares a tuple; a person
building a model in Python writes either (`System(agents=(a, b))`, `link.name = [p, q]`, stages as
tuples), and every part of earl reads either. A dataclass's own `__eq__` compares them as Python does,
`[a] != (a,)`, so such a model never equalled itself read back from its text (`load(save(m)) != m`).
The frozen expression classes turn a list into a tuple as they are made (they are hashed, and cannot
be changed after); the mutable ones can be given a list or a tuple at any time, so they compare so.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

T = TypeVar("T")


def _same(left: Any, right: Any) -> bool:
    if left.__class__ in (list, tuple) and right.__class__ in (list, tuple):
        return len(left) == len(right) and all(_same(a, b) for a, b in zip(left, right, strict=True))
    return bool(left == right)


def sequences_compare_equal(cls: type[T]) -> type[T]:
    """Give a mutable dataclass an `__eq__` over its compared fields (as `dataclass` makes it) in which a list
    and a tuple holding equal items are equal, at any depth (`stages`, a list of lists)."""
    names = tuple(field.name for field in dataclasses.fields(cls) if field.compare)  # type: ignore[arg-type]

    def __eq__(self: Any, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        if self is other:
            return True
        return all(_same(getattr(self, name), getattr(other, name)) for name in names)

    __eq__.__qualname__ = f"{cls.__qualname__}.__eq__"
    cls.__eq__ = __eq__  # type: ignore[method-assign,assignment]
    return cls


__all__ = ["sequences_compare_equal"]
