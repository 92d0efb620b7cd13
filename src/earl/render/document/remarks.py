"""What a person wrote in `//` comments at the elements of a spec, for the document to show with them.

The SysML export carries these comments (docs/sysml.md); the document showed none of them, though
they say what a value means ("in radians", "metres to the goal").  An expanded system keeps where each
element was written but not its comments, so they are found by location in the declared system.

A comment above a declaration is not always about it alone: `// Table 3: manip/a.cs.m` heads five
memories.  The rule, as a Go doc comment's: a row's own comment is the block of `//` lines right above
its declaration, with no blank line between, and the one after it on its line; a block that a blank
line parts from the declaration heads the rows from it on, and is shown as a caption of their group.
Where a comment stands in a group tells nothing: `// Goals queue up …` above the first buffer of a
subsystem is about that buffer, `// Table 3: …` above the first memory about all of them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

from earl.model.comment_paragraphs import comment_paragraphs
from earl.model.location import Comments, SourceLocation


@dataclass(frozen=True)
class Remark:
    """What was said at one row's element: its own comment, and a heading written above it for the rows
    from it on ("" where nothing was)."""

    own: str = ""
    heading: str = ""


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

    def comments(self, element: object) -> Comments | None:
        comments = getattr(element, "comments", None)
        if not isinstance(comments, Comments) or not _said(comments):
            location = getattr(element, "location", None)
            comments = self._by_location.get(location) if isinstance(location, SourceLocation) else None
        return comments

    def of(self, element: object, closing: bool = True) -> str:
        """The element's comments as one paragraph ("" when it has none)."""
        return " ".join(comment_paragraphs(self.comments(element), closing))

    def of_rows(self, elements: Sequence[object]) -> list[Remark]:
        """The remarks of the elements of a table's rows, in their order (None: a row of no element)."""
        return row_remarks(elements, [self.comments(element) for element in elements])


def row_remarks(elements: Sequence[object], comments: Sequence[Comments | None]) -> list[Remark]:
    """Each element's own comment and the heading above it, given each element's comments: the blocks
    a blank line parts from the element head it (see the module's docstring).  The comment a file opens
    with is the file's (types.earl's "The data types of the mobile robot example …" above its first
    parameter), not a heading of the rows."""
    remarks = []
    for element, said in zip(elements, comments, strict=True):
        if said is None or not _said(said):
            remarks.append(Remark())
            continue
        blocks = _blocks(said.leading)
        near = blocks[-1] if blocks and said.leading[-1] != "" else []
        above = [block for block in (blocks[:-1] if near else blocks) if _words(block)]
        location = getattr(element, "location", None)
        if above and isinstance(location, SourceLocation) and location.line - len(said.leading) <= 1:
            above = above[1:]  # `earl fmt` writes one blank line where "" stands: the first block is on line 1
        own = comment_paragraphs(dataclasses.replace(said, leading=near))
        heading = [paragraph for block in above for paragraph in comment_paragraphs(Comments(leading=block))]
        remarks.append(Remark(" ".join(own), " ".join(heading)))
    return remarks


def _blocks(lines: Sequence[str]) -> list[list[str]]:
    """Comment lines in the blocks a blank line ("") parts."""
    blocks: list[list[str]] = [[]]
    for line in lines:
        if line == "":
            blocks.append([])
        else:
            blocks[-1].append(line)
    return [block for block in blocks if block]


def _words(block: list[str]) -> bool:
    """Whether a block says something: a ruler (`// ---- Figure 9`) heads a part of the file and says nothing."""
    return bool(comment_paragraphs(Comments(leading=block)))


def _said(comments: Comments) -> bool:
    return bool(comments.leading or comments.trailing or comments.closing or comments.after)
