"""The document as one static HTML page: inline CSS, no script, nothing fetched from the network."""

from __future__ import annotations

import re
from collections.abc import Mapping
from html import escape

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

CSS = """
:root { --ink: #1d2430; --muted: #5b6472; --rule: #d5dae1; --accent: #1f5fa8; --shade: #f4f6f9; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.5 -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; color: var(--ink); }
nav { position: fixed; top: 0; bottom: 0; left: 0; width: 280px; overflow-y: auto; padding: 18px 14px;
      background: var(--shade); border-right: 1px solid var(--rule); font-size: 13px; }
nav ul { list-style: none; margin: 0; padding-left: 12px; }
nav > ul { padding-left: 0; }
nav a { color: var(--ink); text-decoration: none; display: block; padding: 1px 0; overflow-wrap: anywhere; }
nav a:hover { color: var(--accent); }
main { margin-left: 280px; padding: 24px 40px 80px; max-width: 1300px; }
h1 { font-size: 26px; margin: 0 0 4px; }
h2 { font-size: 21px; margin-top: 40px; padding-top: 8px; border-top: 2px solid var(--rule); }
h3 { font-size: 17px; margin-top: 30px; }
.subtitle { color: var(--muted); margin-top: 0; }
code { font: 13px/1.4 "DejaVu Sans Mono", Menlo, Consolas, monospace; background: #eef1f5; padding: 0 3px;
       border-radius: 3px; }
a { color: var(--accent); }
a code { color: var(--accent); }
code code { background: none; padding: 0; }
table { border-collapse: collapse; margin: 14px 0 22px; font-size: 13.5px; }
caption { caption-side: top; text-align: left; font-weight: 600; padding: 0 0 6px; }
caption .note { font-weight: 400; margin-top: 2px; }
th, td { border: 1px solid var(--rule); padding: 4px 8px; vertical-align: top; text-align: left;
         overflow-wrap: break-word; }
th { background: var(--shade); }
table.matrix td.bullet, table.matrix th { text-align: center; }
table.matrix thead tr:nth-child(2) th { writing-mode: vertical-rl; transform: rotate(180deg); white-space: nowrap;
                                        vertical-align: bottom; padding: 6px 4px; }
.wide { overflow-x: auto; max-width: 100%; }
table.matrix td.bullet { font-size: 18px; line-height: 1; min-width: 34px; }
td.error { color: #b00020; font-weight: 600; }
td.warning { color: #9a6700; font-weight: 600; }
td.note { color: var(--muted); }
td.group { font-style: italic; color: var(--muted); background: #fafbfc; }  /* a comment heading rows */
td.group > div { width: 0; min-width: 100%; }
td.comment { min-width: 12em; max-width: 32em; }  /* prose: wraps in a column of a readable width */
td.rule, .whole { white-space: nowrap; }  /* `EARL-I063` broke after its hyphen */
wbr { display: none; }  /* a long name breaks only in a narrow window (below), not where a wide one has room */
p.notice { padding: 8px 12px; border-left: 4px solid; background: var(--shade); font-weight: 600; }
p.notice.error { border-color: #b00020; color: #b00020; background: #fdecee; }
p.notice.warning { border-color: #9a6700; color: #6b4800; background: #fff8e1; }
tr:target, td:target { background: #fff6cc; }
figure { margin: 16px 0 28px; }
figure img { max-width: 100%; height: auto; border: 1px solid var(--rule); background: white; }
figure .diagram { overflow-x: auto; max-width: 100%; }
figure .diagram img { max-width: none; }
figcaption { color: var(--muted); font-size: 13px; margin-top: 4px; }
@media (max-width: 960px) {
  nav { position: static; width: auto; max-height: 45vh; border-right: none; border-bottom: 1px solid var(--rule); }
  main { margin-left: 0; padding: 16px 14px 60px; }
  wbr { display: inline; }
  h1 { font-size: 22px; }
}
@media print { nav { display: none; } main { margin-left: 0; } }
"""


#: Where a long name may break in a narrow column: after a dot, colon, comma or underscore before a
#: letter (a number such as `0.25` stays whole), and
#: between the words of a camelCase name (`manip/a.motor<wbr>Controller[K]/ve.<wbr>fsm`).
_BREAK = re.compile(r"(?<=[.:,_])(?=[A-Za-z])|(?<=[a-z])(?=[A-Z])")


#: A unary minus and its operand (`-STANDSTILL` in `x > -STANDSTILL`): a browser breaks a line after a
#: hyphen, which parted them; a binary minus is written with spaces (`a - b`).
_NEGATED = re.compile(r"(?:^|(?<=[\s(,\[]))-[\w.\[\]*/]+")


def breakable(text: str) -> str:
    """`text` escaped for HTML with `<wbr>` where a long name may break: a narrow window wraps a
    table's long names there instead of pushing the table off the page (copying the text is unchanged);
    a negated operand is kept whole."""
    parts = []
    position = 0
    for found in _NEGATED.finditer(text):
        parts.append(_with_breaks(text[position : found.start()]))
        parts.append(f'<span class="whole">{escape(found.group())}</span>')
        position = found.end()
    parts.append(_with_breaks(text[position:]))
    return "".join(parts)


def _with_breaks(text: str) -> str:
    return "<wbr>".join(escape(piece) for piece in _BREAK.split(text))


def inline(part: Inline, monospace: bool = False) -> str:
    """`monospace`: inside code, whose names may break where `breakable` lets them."""
    if isinstance(part, Text):
        return breakable(part.text) if monospace else escape(part.text)
    if isinstance(part, Code):
        return f"<code>{breakable(part.text)}</code>"
    if isinstance(part, Link):
        return f'<a href="#{escape(part.anchor)}">{content(part.content, monospace)}</a>'
    if isinstance(part, Strong):
        return f"<strong>{content(part.content, monospace)}</strong>"
    if isinstance(part, Monospace):
        return f"<code>{content(part.content, True)}</code>"
    raise TypeError(part)


_ENDS_NEGATING = re.compile(r"(?:^|(?<=[\s(,\[]))-$")


def content(parts: Content, monospace: bool = False) -> str:
    out = []
    position = 0
    while position < len(parts):
        part = parts[position]
        after = parts[position + 1] if position + 1 < len(parts) else None
        if monospace and isinstance(part, Text) and isinstance(after, Link) and _ENDS_NEGATING.search(part.text):
            # `-` then a linked name (`> -STANDSTILL`, the parameter linked): kept on one line with it
            out.append(inline(Text(part.text[:-1]), monospace))
            out.append(f'<span class="whole">-{inline(after, monospace)}</span>')
            position += 2
            continue
        out.append(inline(part, monospace))
        position += 1
    return "".join(out)


def _cell(tag: str, item: Cell) -> str:
    attributes = ""
    if item.rowspan > 1:
        attributes += f' rowspan="{item.rowspan}"'
    if item.colspan > 1:
        attributes += f' colspan="{item.colspan}"'
    if item.anchor:
        attributes += f' id="{escape(item.anchor)}"'
    if item.css:
        attributes += f' class="{item.css}"'
    inner = content(item.content)
    if item.css == "group":  # a heading's prose wraps at the table's width and never widens it
        inner = f"<div>{inner}</div>"
    return f"<{tag}{attributes}>{inner}</{tag}>"


#: What a character takes, in px, in the fonts of a table (13 px DejaVu Sans Mono for code, 13.5 px text,
#: DejaVu Sans where Helvetica and Arial are missing: its widest), and a cell's padding and border: enough
#: to tell, before a browser draws it, how wide a table is whose names do not break.
_CODE_CHARACTER = 7.9
_TEXT_CHARACTER = 8.6
_CELL_EDGES = 18
#: A window is this much wider than the text beside the sidebar (280 px sidebar, 2 × 40 px padding),
#: and the text never wider than `_WIDEST_TEXT` (main's max-width less its padding).
_BESIDE_TEXT = 360
#: What the estimate may miss (it was 1 px short for a buffers table of manip/a).
_MARGIN = 16
_WIDEST_TEXT = 1220
#: Thresholds are rounded up to this step, so the page has a few rules, not one per table.
_STEP = 80


def _characters(parts: Content, monospace: bool = False) -> list[tuple[str, bool]]:
    out: list[tuple[str, bool]] = []
    for part in parts:
        if isinstance(part, Text):
            out += [(character, monospace) for character in part.text]
        elif isinstance(part, Code):
            out += [(character, True) for character in part.text]
        elif isinstance(part, Link | Strong):
            out += _characters(part.content, monospace)
        elif isinstance(part, Monospace):
            out += _characters(part.content, True)
    return out


def _narrowest(parts: Content) -> float:
    """How wide a cell is at least with its names whole: its longest word, code or text."""
    widest = 0.0
    word = 0.0
    for character, monospace in [*_characters(parts), (" ", False)]:
        if character.isspace():
            widest = max(widest, word)
            word = 0.0
        else:
            word += _CODE_CHARACTER if monospace else _TEXT_CHARACTER
    return widest + _CELL_EDGES


def unbroken_width(item: Table) -> float:
    """About how wide `item` is at least while no name breaks at its `<wbr>`: the sum of its columns'
    longest words (a cell spanning columns is left out)."""
    columns: dict[int, float] = {}
    pending: dict[int, int] = {}  # column → rows still covered by a cell above
    for row in [*item.header, *item.rows]:
        column = 0
        for entry in row:
            while pending.get(column, 0) > 0:
                pending[column] -= 1
                column += 1
            if entry.colspan == 1:
                columns[column] = max(columns.get(column, 0.0), _narrowest(entry.content))
            for spanned in range(column, column + entry.colspan):
                pending[spanned] = entry.rowspan - 1
            column += entry.colspan
        for later in [c for c in pending if c >= column and pending[c] > 0]:
            pending[later] -= 1
    return sum(columns.values())


def breaks_below(item: Table) -> int | None:
    """The widest window in which `item`'s names may break at their `<wbr>`: a table that fits with its names
    whole keeps them whole (a wide window had split NavigationGoal in a column with room), and one that
    would not fits by breaking them rather than scrolling sideways (the comment column pushed the buffers
    table to 1122 px in a 1040 px text at 1400 px).  None: below 960 px only, as every table."""
    needed = unbroken_width(item) + _MARGIN
    if needed <= _WIDEST_TEXT:
        window = needed + _BESIDE_TEXT
        if window <= NARROW:
            return None
        return int(-(-window // _STEP) * _STEP)
    return WIDEST


#: Below this window width the contents go above the text and every table's names may break.
NARROW = 960
#: From this window width on, the first column's names (what each row is about) stay whole: a table that
#: must break names breaks them in its other columns (`calculate`/`Position/pf` had split at 1400 px).
WHOLE_FIRST_COLUMN = 1200
#: A table too wide for the widest text breaks its names in every window.
WIDEST = 100000


def _class(*names: str) -> str:
    names = tuple(name for name in names if name)
    return f' class="{" ".join(names)}"' if names else ""


def table(item: Table) -> str:
    below = None if item.css == "matrix" else breaks_below(item)
    attributes = (f' id="{escape(item.anchor)}"' if item.anchor else "") + _class(
        item.css, f"breaks-{below}" if below else ""
    )
    head = "".join("<tr>" + "".join(_cell("th", c) for c in row) + "</tr>" for row in item.header)
    body = "".join("<tr>" + "".join(_cell("td", c) for c in row) + "</tr>" for row in item.rows)
    notes = "".join(f'<div class="note">{content(note)}</div>' for note in item.notes)
    return (
        f'<div class="wide"><table{attributes}><caption>{content(item.caption)}{notes}</caption>'
        f"<thead>{head}</thead><tbody>{body}</tbody></table></div>"
    )


#: A diagram wider than the page is shrunk to fit it, but never below this share of its own size:
#: at 43 % (the manip/a agent view) its text was 5 px high.  Beyond, its box scrolls sideways.
LEGIBLE_SCALE = 0.8


def figure(item: Figure, widths: Mapping[str, float]) -> str:
    """The diagram linked to its SVG (which opens at full size); one whose width in CSS pixels is known
    fits the page down to `LEGIBLE_SCALE` of that width, and scrolls sideways in its box when wider."""
    anchor = f' id="{escape(item.anchor)}"' if item.anchor else ""
    width = widths.get(item.path)
    size = ""
    if width:
        size = f' style="width: clamp({LEGIBLE_SCALE * width:.0f}px, 100%, {width:.0f}px)"'
    image = (
        f'<a href="{escape(item.path)}" title="open the diagram at full size">'
        f'<img src="{escape(item.path)}" alt="{escape(item.alt)}"{size}></a>'
    )
    if width:
        image = f'<div class="diagram">{image}</div>'
    return f"<figure{anchor}>{image}<figcaption>{content(item.caption)}</figcaption></figure>"


def block(item: Block, widths: Mapping[str, float] | None = None) -> str:
    if isinstance(item, Paragraph):
        return f"<p>{content(item.content)}</p>"
    if isinstance(item, BulletList):
        return "<ul>" + "".join(f"<li>{content(entry)}</li>" for entry in item.items) + "</ul>"
    if isinstance(item, Table):
        return table(item)
    if isinstance(item, Figure):
        return figure(item, widths or {})
    return section(item, widths)


def section(item: Section, widths: Mapping[str, float] | None = None) -> str:
    tag = f"h{min(item.level, 6)}"
    inner = "\n".join(block(b, widths) for b in item.blocks)
    return f'<section id="{escape(item.anchor)}">\n<{tag}>{content(item.title)}</{tag}>\n{inner}\n</section>'


def _navigation(sections: list[Section]) -> str:
    items = []
    for item in sections:
        children = [b for b in item.blocks if isinstance(b, Section)]
        inner = (
            "<ul>"
            + "".join(f'<li><a href="#{escape(c.anchor)}">{content(c.title)}</a></li>' for c in children)
            + "</ul>"
        )
        items.append(f'<li><a href="#{escape(item.anchor)}">{content(item.title)}</a>{inner if children else ""}</li>')
    return "<nav><ul>" + "".join(items) + "</ul></nav>"


def render_html(document: Document, widths: Mapping[str, float] | None = None) -> str:
    """The page; `widths` gives the natural width in CSS pixels of the diagrams drawn, by path."""
    body = "\n".join(section(s, widths) for s in document.sections)
    thresholds = sorted({int(found) for found in re.findall(r'class="[^"]*\bbreaks-(\d+)', body)})
    css = CSS + "".join(
        f"@media (max-width: {below}px) {{ table.breaks-{below} wbr {{ display: inline; }} }}\n" for below in thresholds
    )
    # in a wide window the name a row is about stays whole: the other columns give way first
    css += f"@media (min-width: {WHOLE_FIRST_COLUMN}px) {{ .wide td:first-child wbr {{ display: none; }} }}\n"
    notice = ""
    if document.notice:
        notice = f'<p class="notice {document.notice_css}" id="check-summary">{content(document.notice)}</p>\n'
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        '<meta name="generator" content="earl doc">\n'
        f"<title>{escape(document.title)}</title>\n<style>{css}</style>\n</head>\n<body>\n"
        f"{_navigation(document.sections)}\n<main>\n<h1>{escape(document.title)}</h1>\n"
        f'<p class="subtitle">{escape(document.subtitle)}</p>\n{notice}{body}\n</main>\n</body>\n</html>\n'
    )
