"""The manual's diagrams and tables, drawn from a spec: `earl diagram` and `earl doc`.

    >>> from earl.render import build_diagram
    >>> build_diagram(system, "fsm", "manip/a.cs").svg()       # needs Graphviz's `dot`

Rendering reads the model only; it never imports or runs code a spec names.
In Jupyter, `%load_ext earl.render` (or `import earl.render` in a running
notebook) makes systems, agents, subsystems, FSMs, basic behaviours and data
types display as SVG diagrams.
"""

from __future__ import annotations

import sys

from earl.render.build import MERMAID_VIEWS, VIEWS, Subject, build_diagram, diagram_of
from earl.render.diagram import Diagram
from earl.render.graphviz import GraphvizError
from earl.render.jupyter import load_ipython_extension, register_formatters
from earl.render.targets import TargetError

__all__ = [
    "MERMAID_VIEWS",
    "VIEWS",
    "Diagram",
    "GraphvizError",
    "Subject",
    "TargetError",
    "build_diagram",
    "diagram_of",
    "load_ipython_extension",
    "register_formatters",
]

# Inside a running IPython kernel, importing earl.render is enough: the model displays as SVG.
if "IPython" in sys.modules:  # never import IPython ourselves: outside a notebook it is not wanted
    register_formatters()
