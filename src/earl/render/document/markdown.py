"""The document as Markdown (GitHub-flavoured tables), for reading on a code host.

Markdown tables cannot span cells: Table 6's behaviour is written on its first
row only, and the `/mo` and `/ob` header groups become prefixes of the columns.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from earl.render.document.tree import (
    Block,
    BulletList,
    Cell,
    Code,
    Document,
    Figure,
    Inline,
    Link,
    Monospace,
    Paragraph,
    Section,
    Strong,
    Table,
    Text,
)


def _escape(text: str) -> str:
    """Text that Markdown shows as written.  `&` becomes `&amp;` before `<` becomes `&lt;`: Markdown
    reads entities in text, so a spec's string `"&amp;<x>"` would otherwise be shown as `"&<x>"`."""
    return (
        text.replace("&", "&amp;")
        .replace("\\", "\\\\")
        .replace("|", "\\|")
        .replace("*", "\\*")
        .replace("_", "\\_")
        .replace("<", "&lt;")
    )


def _code(text: str, in_table: bool) -> str:
    """`text` as a code span that CommonMark and GitHub read back as `text`.

    The spaces at its ends stay outside the span (CommonMark trims a space from each end of a span,
    so `` ` and not ` `` would read "and not" glued to its neighbours); the fence is longer than any
    run of backticks inside. In a table cell a `|` is written `\\|`: GitHub splits the cells before
    it reads code spans and then drops the backslash, where an entity would be shown as written."""
    body = text.strip(" ")
    if not body:
        return text
    lead, trail = text[: len(text) - len(text.lstrip(" "))], text[len(text.rstrip(" ")) :]
    longest = max((len(run) for run in re.findall("`+", body)), default=0)
    fence = "`" * (longest + 1)
    pad = " " if body.startswith("`") or body.endswith("`") else ""
    if in_table:
        body = body.replace("|", "\\|")
    return f"{lead}{fence}{pad}{body}{pad}{fence}{trail}"


def _merged(parts: Sequence[Inline]) -> list[Inline]:
    """Neighbouring code written as one span: two spans side by side (`` `a``b` ``) would read as one
    span fenced by a double backtick."""
    merged: list[Inline] = []
    for part in parts:
        if isinstance(part, Code) and merged and isinstance(merged[-1], Code):
            merged[-1] = Code(merged[-1].text + part.text)
        else:
            merged.append(part)
    return merged


def _as_code(part: Inline) -> Inline:
    """A piece of a Monospace run: its text is code, a link's text too."""
    if isinstance(part, Text):
        return Code(part.text)
    if isinstance(part, Link):
        return Link(part.anchor, tuple(_as_code(piece) for piece in part.content))
    return part


def inline(part: Inline, in_table: bool = False) -> str:
    if isinstance(part, Text):
        return _escape(part.text)
    if isinstance(part, Code):
        return _code(part.text, in_table)
    if isinstance(part, Link):
        return f"[{content(part.content, in_table)}](#{part.anchor})"
    if isinstance(part, Strong):
        return f"**{content(part.content, in_table)}**"
    if isinstance(part, Monospace):
        # Markdown has no links inside code spans: each piece between links becomes its own span
        pieces: list[Inline] = [_as_code(piece) for piece in part.content]
        return content(pieces, in_table)
    raise TypeError(part)


def content(parts: Sequence[Inline], in_table: bool = False) -> str:
    return "".join(inline(part, in_table) for part in _merged(parts)).replace("\n", " ")


def _cell(item: Cell) -> str:
    anchor = f'<a id="{item.anchor}"></a>' if item.anchor else ""
    said = content(item.content, in_table=True)
    if item.css == "group":  # a comment heading the rows below, in its first column: set apart as in HTML
        said = f"*{said}*"
    return anchor + said


def _header(item: Table) -> list[str]:
    """One header row: a spanning group's label becomes a prefix of the cells under it."""
    if len(item.header) == 1:
        return [content(c.content, in_table=True) for c in item.header[0]]
    top, bottom = item.header[0], item.header[1]
    names: list[str] = []
    below = iter(bottom)
    for group in top:
        if group.rowspan > 1:
            names.append(content(group.content, in_table=True))
            continue
        prefix = content(group.content, in_table=True)
        names += [f"{prefix} {content(next(below).content, in_table=True)}" for _ in range(group.colspan)]
    return names


def table(item: Table) -> str:
    header = _header(item)
    lines = [f"**{content(item.caption)}**", ""]
    for note in item.notes:  # a paragraph each, under the caption's title, not bold
        lines += [content(note), ""]
    if item.anchor:
        lines.insert(0, f'<a id="{item.anchor}"></a>')
    lines.append("| " + " | ".join(header) + " |")
    lines.append("|" + "|".join(" --- " for _ in header) + "|")
    pending: list[int] = [0] * len(header)  # rows still covered by a rowspan, per column
    for row in item.rows:
        cells: list[str] = []
        source = iter(row)
        for column in range(len(header)):
            if pending[column] > 0:
                pending[column] -= 1
                cells.append("")
                continue
            entry = next(source, None)
            if entry is None:
                cells.append("")
                continue
            pending[column] = entry.rowspan - 1
            cells.append(_cell(entry))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def block(item: Block) -> str:
    if isinstance(item, Paragraph):
        return content(item.content)
    if isinstance(item, BulletList):
        return "\n".join(f"- {content(entry)}" for entry in item.items)
    if isinstance(item, Table):
        return table(item)
    if isinstance(item, Figure):
        anchor = f'<a id="{item.anchor}"></a>\n' if item.anchor else ""
        return f"{anchor}![{item.alt}]({item.path})\n\n*{content(item.caption)}*"
    return section(item)


def section(item: Section) -> str:
    heading = "#" * min(item.level, 6)
    parts = [f'<a id="{item.anchor}"></a>', "", f"{heading} {content(item.title)}"]
    parts += [block(b) for b in item.blocks]
    return "\n\n".join(parts)


def render_markdown(document: Document) -> str:
    contents = []
    for item in document.sections:
        contents.append(f"- [{content(item.title)}](#{item.anchor})")
        contents += [f"  - [{content(c.title)}](#{c.anchor})" for c in item.blocks if isinstance(c, Section)]
    parts = [f"# {_escape(document.title)}", f"*{_escape(document.subtitle)}*"]
    if document.notice:
        parts.append(f"> **{content(document.notice)}**")
    parts.append("\n".join(contents))
    parts += [section(s) for s in document.sections]
    return "\n\n".join(parts) + "\n"
