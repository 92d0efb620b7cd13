"""Pieces several views share: the block of a subsystem or agent, with buffers as small squares."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from earl.render.dot import html

SQUARE = 9  # side of a buffer square, in points


@dataclass(frozen=True)
class Port:
    """A buffer drawn as a small square on the border of its block; `port` names it in DOT."""

    port: str
    label: str


def square(port: str) -> str:
    return f'<td port="{port}" border="1" width="{SQUARE}" height="{SQUARE}" fixedsize="true" bgcolor="white"></td>'


def block(
    title: Sequence[str],
    inputs: Sequence[Port],
    outputs: Sequence[Port],
    middle: Sequence[str] = (),
    fill: str = "white",
    notes: Sequence[str] = (),
) -> str:
    """An HTML-like label: a titled block, input squares on its left edge, output squares on its right.

    `title` lines are HTML already (the caller bolds the name); `middle` lines
    (memory, with its bidirectional arrow) are listed under the buffers.
    """
    columns = 5
    rows = [f'<tr><td colspan="{columns}" cellpadding="4">{"<br/>".join(title)}</td></tr>']
    for note in notes:
        rows.append(f'<tr><td colspan="{columns}"><font point-size="9" color="#555555">{html(note)}</font></td></tr>')
    count = max(len(inputs), len(outputs))
    if count:
        rows.append("<hr/>")
    for row in range(count):
        cells = []
        if row < len(inputs):
            cells.append(square(inputs[row].port))
            cells.append(f'<td align="left" cellpadding="3">{html(inputs[row].label)}&#160;</td>')
        else:
            cells.append("<td></td><td></td>")
        cells.append('<td width="12"></td>')
        if row < len(outputs):
            cells.append(f'<td align="right" cellpadding="3">&#160;{html(outputs[row].label)}</td>')
            cells.append(square(outputs[row].port))
        else:
            cells.append("<td></td><td></td>")
        rows.append("<tr>" + "".join(cells) + "</tr>")
    if middle:
        rows.append("<hr/>")
        for line in middle:
            rows.append(f'<tr><td></td><td colspan="3" align="left" cellpadding="2">{line}</td><td></td></tr>')
    return (
        f'<<table border="1" cellborder="0" cellspacing="0" cellpadding="1" bgcolor="{fill}">'
        + "".join(rows)
        + "</table>>"
    )


def node_id(*parts: str) -> str:
    """A DOT identifier: letters, digits and underscores only."""
    text = "_".join(parts)
    return "n_" + "".join(c if c.isalnum() else "_" for c in text)


@dataclass(frozen=True)
class LinkStatements:
    """The DOT statements of one link: its nodes (its label, and a backward link's turn) and its edges."""

    nodes: list[str]
    edges: list[str]

    def all(self) -> list[str]:
        return self.nodes + self.edges


def link_statements(
    number: int, source: str, destination: str, name: str, data_type: str, backward: bool
) -> LinkStatements:
    """A link drawn through a small label node, so its name and data type sit on its own path.

    A `backward` link runs against the layout's direction (a Virtual Effector's state going
    back to the Control Subsystem): its label sits just before the Input Buffer it feeds.  It
    leaves its Output Buffer eastwards, as every link does, to a turn point one rank after
    its block, and runs from there back to its label past the blocks in between; both halves
    are declared forwards (towards the turn) and drawn without arrowheads, so they read the
    same.  Declared from the label straight to the Output Buffer's east side, the path had to
    reach that side from the west: dot drew it under (or through) its own block and across the
    border of its robot; left free of the layout (`constraint=false`), it looped along the
    frame's border or outside it.
    """
    node = f"link_{number}"
    label = f"<{html(name)}<br/><i>{html(data_type)}</i>>"
    nodes = [f'{node} [shape="plain", fontsize="9", label={label}, tooltip="{html(name)}"];']
    arrival = f'{node} -> {destination} [tooltip="{html(name)}"];'
    if not backward:
        return LinkStatements(nodes, [f'{source} -> {node} [arrowhead="none", tooltip="{html(name)}"];', arrival])
    turn = f"turn_{number}"
    nodes.append(f'{turn} [shape="point", width="0.01", height="0.01", label="", tooltip="{html(name)}"];')
    return LinkStatements(
        nodes,
        [
            f'{source} -> {turn} [dir="none", tooltip="{html(name)}"];',
            f'{node} -> {turn} [dir="none", tooltip="{html(name)}"];',
            arrival,
        ],
    )
