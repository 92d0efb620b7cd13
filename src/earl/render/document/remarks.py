"""What a person wrote in `//` comments at the elements of a spec, for the document to show with them.

The SysML export carries these comments (docs/sysml.md); the document showed none of them, though
they say what a value means ("in radians", "metres to the goal").  An expanded system keeps where each
element was written but not its comments, so they are found by location in the declared system.
"""

from __future__ import annotations

import dataclasses

from earl.model.comment_paragraphs import comment_paragraphs
from earl.model.location import Comments, SourceLocation


class Remarks:
    """The comments of every element of a declared system, by where the element was written."""

    def __init__(self, declared: object) -> None:
        self._by_location: dict[SourceLocation, Comments] = {}
        self._walk(declared, set())

    def _walk(self, element: object, seen: set[int]) -> None:
        if id(element) in seen:
            return
        seen.add(id(element))
        if isinstance(element, list | tuple):
            for item in element:
                self._walk(item, seen)
            return
        if not dataclasses.is_dataclass(element) or isinstance(element, type):
            return
        location = getattr(element, "location", None)
        comments = getattr(element, "comments", None)
        if isinstance(location, SourceLocation) and isinstance(comments, Comments) and _said(comments):
            self._by_location.setdefault(location, comments)
        for field in dataclasses.fields(element):
            if field.name in ("location", "comments", "clause_comments", "member_comments"):
                continue
            value = getattr(element, field.name, None)
            if isinstance(value, list | tuple) or dataclasses.is_dataclass(value):
                self._walk(value, seen)

    def of(self, element: object, closing: bool = True) -> str:
        """The element's comments as one paragraph ("" when it has none)."""
        comments = getattr(element, "comments", None)
        if not isinstance(comments, Comments) or not _said(comments):
            location = getattr(element, "location", None)
            comments = self._by_location.get(location) if isinstance(location, SourceLocation) else None
        return " ".join(comment_paragraphs(comments, closing))


def _said(comments: Comments) -> bool:
    return bool(comments.leading or comments.trailing or comments.closing or comments.after)
