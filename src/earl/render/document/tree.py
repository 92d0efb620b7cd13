"""The document as a tree that both the HTML and the Markdown printers read."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Text:
    text: str


@dataclass(frozen=True)
class Code:
    """An element name or an expression, in monospace."""

    text: str


@dataclass(frozen=True)
class Link:
    """A cross-link to an anchor of the same document."""

    anchor: str
    content: tuple[Inline, ...]


@dataclass(frozen=True)
class Strong:
    content: tuple[Inline, ...]


@dataclass(frozen=True)
class Monospace:
    """An expression in one monospace run, with links inside it (its Text parts are code)."""

    content: tuple[Inline, ...]


Inline = Text | Code | Link | Strong | Monospace
Content = tuple[Inline, ...]


@dataclass(frozen=True)
class Cell:
    content: Content
    rowspan: int = 1
    colspan: int = 1
    anchor: str | None = None  # the element this cell defines
    css: str = ""  # "bullet", "error", "warning", "note"


@dataclass
class Paragraph:
    content: Content


@dataclass
class BulletList:
    items: list[Content]


@dataclass
class Table:
    caption: Content
    header: list[list[Cell]]  # header rows; cells may span
    rows: list[list[Cell]]
    anchor: str | None = None
    css: str = ""  # "matrix" for Table 6
    #: lines under the caption's title that belong to it: Table 5's "Assumed: …", as the manual's caption says it
    notes: list[Content] = field(default_factory=list)


@dataclass
class Figure:
    path: str  # relative to the document, `diagrams/fsm-manip-a-cs.svg`
    caption: Content
    alt: str
    anchor: str | None = None


@dataclass
class Section:
    title: Content
    anchor: str
    level: int
    blocks: list[Block] = field(default_factory=list)

    def add(self, block: Block) -> None:
        self.blocks.append(block)


Block = Paragraph | BulletList | Table | Figure | Section


@dataclass
class Document:
    title: str
    subtitle: str
    sections: list[Section]
    #: Said under the subtitle, before everything else: what `earl check` found, when it found anything.
    notice: Content = ()
    #: How the notice is marked: `error` (the spec breaks rules) or `warning`.
    notice_css: str = ""


def text(value: str) -> Content:
    return (Text(value),)


def code(value: str) -> Content:
    return (Code(value),)


def with_code(message: str) -> Content:
    """A message whose `backticked` names become code, as the checker writes them."""
    parts: list[Inline] = []
    for position, piece in enumerate(message.split("`")):
        if piece:
            parts.append(Code(piece) if position % 2 else Text(piece))
    return tuple(parts)


def cell(
    content: Content | str, *, rowspan: int = 1, colspan: int = 1, anchor: str | None = None, css: str = ""
) -> Cell:
    inline = text(content) if isinstance(content, str) else content
    return Cell(inline, rowspan, colspan, anchor, css)
