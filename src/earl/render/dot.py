"""Writing DOT text: escaping, the SysML frame and the look every diagram shares."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field
from html import escape

FONT = "Helvetica,Arial,sans-serif"

#: Fill colours of the subsystem kinds: control blue, effectors orange, receptors green.
FILL = {
    "cs": "#dbe8f7",
    "ve": "#fde9d4",
    "re": "#f9d5b3",
    "vr": "#e2f2dc",
    "rr": "#c9e6bf",
    "a": "#f4f4f4",
}


#: Space between the frame and what it holds, in points; `earl.render.graphviz.fit_frame` widens it
#: when an edge label sticks out (dot leaves edge labels out of a cluster's bounding box).
FRAME_MARGIN = 14
#: Ends the line of the frame's margin, so that the margin can be found and widened.
FRAME_MARGIN_COMMENT = "// the frame's margin"


def html(text: str) -> str:
    """Text for an HTML-like label."""
    return escape(text, quote=True)


def quoted(text: str) -> str:
    """A DOT double-quoted string."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def wrapped(text: str, width: int = 44) -> list[str]:
    """Long conditions broken at spaces so that labels stay narrow."""
    return textwrap.wrap(text, width, break_long_words=False, break_on_hyphens=False) or [""]


def frame_label(header: str) -> str:
    """The SysML frame's name tab, `ibd [Agent] manip/a`: the diagram kind bold, the rest plain, and a space
    after it: dot measures the text narrower than a browser draws it, and the `)` of `…execute()` ran over the
    tab's border."""
    kind, _, rest = header.partition(" ")
    return (
        '<<table border="1" cellborder="0" cellspacing="0" cellpadding="4" bgcolor="white">'
        f"<tr><td><b>{html(kind)}</b>&#160;{html(rest)}&#160;</td></tr></table>>"
    )


@dataclass
class Graph:
    """A directed graph inside a SysML frame; `lines` are the statements inside the frame."""

    header: str
    rankdir: str = "LR"
    lines: list[str] = field(default_factory=list)
    outside: list[str] = field(default_factory=list)
    graph_attributes: dict[str, str] = field(default_factory=dict)

    def add(self, statement: str) -> None:
        self.lines.append(statement)

    def source(self) -> str:
        attributes = {
            "rankdir": self.rankdir,
            "fontname": FONT,
            "fontsize": "11",
            "nodesep": "0.35",
            "ranksep": "0.6",
            "bgcolor": "white",
            "pad": "0.2",
            **self.graph_attributes,
        }
        graph = ", ".join(f"{key}={quoted(value)}" for key, value in attributes.items())
        body = "\n".join(f"    {line}" for line in self.lines)
        after = "\n".join(f"  {line}" for line in self.outside)
        return (
            "digraph earl {\n"
            f"  graph [{graph}];\n"
            f'  node [fontname="{FONT}", fontsize="10"];\n'
            f'  edge [fontname="{FONT}", fontsize="9", arrowsize="0.7", color="#333333"];\n'
            "  subgraph cluster_frame {\n"
            f"    label={frame_label(self.header)};\n"
            '    labeljust="l"; labelloc="t"; style="solid"; color="#333333";\n'
            f'    margin="{FRAME_MARGIN}";  {FRAME_MARGIN_COMMENT}\n'
            f"{body}\n"
            "  }\n"
            f"{after}\n"
            "}\n"
        )
