"""Running Graphviz's `dot` program.

`dot` is called directly through `subprocess` rather than through the `graphviz`
PyPI package: earl writes the DOT text itself (HTML-like labels with ports need
hand-written markup anyway), so the package would only wrap this one call, and
calling the program ourselves lets a missing `dot` become one clear message.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
from typing import Any

from earl.render.dot import FRAME_MARGIN_COMMENT

#: Output formats earl asks `dot` for.
FORMATS = ("svg", "png")

INSTALL_HINT = "install Graphviz, e.g. `apt-get install graphviz` on Debian or Ubuntu"


class GraphvizError(Exception):
    """Graphviz is missing or refused a graph; the message is meant for a person."""


def dot_program() -> str:
    """The `dot` executable: `$EARL_DOT` when set, else `dot` on the PATH."""
    configured = os.environ.get("EARL_DOT")
    found = shutil.which(configured or "dot")
    if found is None:
        where = f"`{configured}` (from EARL_DOT)" if configured else "Graphviz's `dot` program"
        raise GraphvizError(f"diagrams need {where}, which was not found; {INSTALL_HINT}")
    return found


def run_dot(source: str, output_format: str) -> bytes:
    """`source` (DOT text) laid out and drawn as `svg` or `png`."""
    if output_format not in FORMATS:
        raise ValueError(f"unknown Graphviz output format {output_format!r}")
    output = _dot(source, output_format)
    if output_format == "svg":
        output = standalone_svg(output.decode("utf-8")).encode("utf-8")
    return output


def _dot(source: str, output_format: str) -> bytes:
    arguments = [dot_program(), f"-T{output_format}"]
    if output_format == "png":
        arguments.append("-Gdpi=144")  # screen text stays readable when the picture is shrunk
    try:
        completed = subprocess.run(
            arguments, input=source.encode("utf-8"), capture_output=True, timeout=120, check=False
        )
    except subprocess.TimeoutExpired:
        raise GraphvizError("Graphviz took more than two minutes to lay out a diagram") from None
    except OSError as error:
        raise GraphvizError(f"could not run {arguments[0]}: {error.strerror}; {INSTALL_HINT}") from None
    if completed.returncode != 0:
        detail = completed.stderr.decode("utf-8", "replace").strip()
        raise GraphvizError(
            f"Graphviz could not draw the diagram: {detail or 'exit status ' + str(completed.returncode)}"
        )
    return completed.stdout


_FRAME_MARGIN = re.compile(r'margin="(\d+)";  ' + re.escape(FRAME_MARGIN_COMMENT))


def fit_frame(source: str, attempts: int = 3) -> str:
    """`source` with the SysML frame widened until every edge inside it, and its label, is inside it.

    dot sizes a cluster by its nodes only: the label of a slanting edge or of a self-loop on the
    right-hand state of an FSM was drawn across the frame's border, and a link going back to an
    earlier subsystem could loop around a block along the border or outside it.  The source is
    laid out, how far such labels and paths stick out is measured, and the frame's margin grows
    by that much; a source without the frame (or whose edges fit) comes back unchanged.
    """
    for _ in range(attempts):
        found = _FRAME_MARGIN.search(source)
        if found is None:
            return source
        try:
            layout = json.loads(_dot(source, "json"))
        except (GraphvizError, ValueError):
            # a Graphviz without JSON output (before 2.40) or one that writes something else: the diagram
            # is drawn as dot sizes its frame, rather than not at all (drawing it says what is wrong, if
            # anything is)
            return source
        overflow = frame_overflow(layout)
        if overflow <= 0:
            return source
        margin = int(found.group(1)) + math.ceil(overflow) + 4
        source = source[: found.start(1)] + str(margin) + source[found.end(1) :]
    return source


#: How near, in points, a path drawn inside the frame may come to its border.
EDGE_CLEARANCE = 6.0


def frame_overflow(layout: dict[str, Any], frame: str = "cluster_frame") -> float:
    """How far, in points, an edge between two nodes of `frame` reaches beyond the frame on its worst
    side: the text of its label, or its path to within `EDGE_CLEARANCE` of the border (0 or less:
    all inside); `layout` is dot's JSON output."""
    objects = layout.get("objects", [])
    clusters = [o for o in objects if o.get("name") == frame and "bb" in o]
    if not clusters:
        return 0.0
    left, bottom, right, top = (float(v) for v in clusters[0]["bb"].split(","))
    inside = set(clusters[0].get("nodes", []))
    worst = 0.0
    for edge in layout.get("edges", []):
        if edge.get("tail") not in inside or edge.get("head") not in inside:
            continue  # a link to an agent outside the frame is drawn outside it on purpose
        if "invis" in edge.get("style", ""):
            continue
        size = 14.0
        for key in ("_ldraw_", "_hldraw_", "_tldraw_", "_xldraw_"):
            for operation in edge.get(key, []):
                if operation.get("op") == "F":
                    size = float(operation.get("size", size))
                if operation.get("op") != "T":
                    continue
                x, y = (float(v) for v in operation["pt"])
                width = float(operation.get("width", 0))
                start = {"l": x, "r": x - width}.get(operation.get("align", "c"), x - width / 2)
                worst = max(worst, left - start, start + width - right, bottom - (y - 0.25 * size), y + size - top)
        for operation in edge.get("_draw_", []):
            if operation.get("op") not in ("b", "B"):
                continue
            for x, y in _bezier_points([(float(a), float(b)) for a, b in operation["points"]]):
                worst = max(
                    worst,
                    left + EDGE_CLEARANCE - x,
                    x - (right - EDGE_CLEARANCE),
                    bottom + EDGE_CLEARANCE - y,
                    y - (top - EDGE_CLEARANCE),
                )
    return worst


def _bezier_points(points: list[tuple[float, float]], steps: int = 8) -> list[tuple[float, float]]:
    """Points along a piecewise cubic Bézier curve (dot's spline: 1 + 3n control points)."""
    result = points[:1]
    for index in range(0, len(points) - 3, 3):
        p0, p1, p2, p3 = points[index : index + 4]
        for step in range(1, steps + 1):
            t = step / steps
            a, b, c, d = (1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t**3
            result.append(
                (
                    a * p0[0] + b * p1[0] + c * p2[0] + d * p3[0],
                    a * p0[1] + b * p1[1] + c * p2[1] + d * p3[1],
                )
            )
    return result


def standalone_svg(svg: str) -> str:
    """The SVG without its DOCTYPE, whose DTD address a strict offline reader might try to fetch."""
    start = svg.find("<!DOCTYPE")
    if start != -1:
        end = svg.find(">", start)
        svg = svg[:start] + svg[end + 1 :].lstrip("\n")
    return svg
