"""Running Graphviz's `dot` program.

`dot` is called directly through `subprocess` rather than through the `graphviz`
PyPI package: earl writes the DOT text itself (HTML-like labels with ports need
hand-written markup anyway), so the package would only wrap this one call, and
calling the program ourselves lets a missing `dot` become one clear message.
"""

from __future__ import annotations

import os
import shutil
import subprocess

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
    output = completed.stdout
    if output_format == "svg":
        output = standalone_svg(output.decode("utf-8")).encode("utf-8")
    return output


def standalone_svg(svg: str) -> str:
    """The SVG without its DOCTYPE, whose DTD address a strict offline reader might try to fetch."""
    start = svg.find("<!DOCTYPE")
    if start != -1:
        end = svg.find(">", start)
        svg = svg[:start] + svg[end + 1 :].lstrip("\n")
    return svg
