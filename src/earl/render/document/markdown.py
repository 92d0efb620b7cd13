"""The document as Markdown (GitHub-flavoured tables), for reading on a code host.

Markdown tables cannot span cells: Table 6's behaviour is written on its first
row only, and the `/mo` and `/ob` header groups become prefixes of the columns.
"""

from __future__ import annotations

from earl.render.document.tree import (
    Block,
    BulletList,
    Cell,
    Code,
    Content,
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
    return text.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*").replace("_", "\\_").replace("<", "&lt;")


def _code(text: str) -> str:
    fence = "``" if "`" in text else "`"
    return f"{fence}{text.replace('|', '&#124;')}{fence}"


def inline(part: Inline) -> str:
    if isinstance(part, Text):
        return _escape(part.text)
    if isinstance(part, Code):
        return _code(part.text)
    if isinstance(part, Link):
        return f"[{content(part.content)}](#{part.anchor})"
    if isinstance(part, Strong):
        return f"**{content(part.content)}**"
    if isinstance(part, Monospace):
        # Markdown has no links inside code spans: each piece becomes its own span
        return "".join(inline(Code(piece.text)) if isinstance(piece, Text) else inline(piece) for piece in part.content)
    raise TypeError(part)


def content(parts: Content) -> str:
    return "".join(inline(part) for part in parts).replace("\n", " ")


def _cell(item: Cell) -> str:
    anchor = f'<a id="{item.anchor}"></a>' if item.anchor else ""
    return anchor + content(item.content)


def _header(item: Table) -> list[str]:
    """One header row: a spanning group's label becomes a prefix of the cells under it."""
    if len(item.header) == 1:
        return [content(c.content) for c in item.header[0]]
    top, bottom = item.header[0], item.header[1]
    names: list[str] = []
    below = iter(bottom)
    for group in top:
        if group.rowspan > 1:
            names.append(content(group.content))
            continue
        prefix = content(group.content)
        names += [f"{prefix} {content(next(below).content)}" for _ in range(group.colspan)]
    return names


def table(item: Table) -> str:
    header = _header(item)
    lines = [f"**{content(item.caption)}**", ""]
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
    parts = [f"# {_escape(document.title)}", f"*{_escape(document.subtitle)}*", "\n".join(contents)]
    parts += [section(s) for s in document.sections]
    return "\n\n".join(parts) + "\n"
