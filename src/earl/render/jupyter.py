"""Model objects as SVG in Jupyter.

The model imports no renderer, so instead of `_repr_svg_` methods on the model's
classes, this module registers IPython display formatters for them: a System
shows its system view, an Agent its agent view, a Subsystem or an FSM its state
machine, a BasicBehaviour its activity diagram, a data type its bdd.  Load it with
`%load_ext earl.render`, or import `earl.render` inside a running kernel.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from typing import Any

from earl.model.elements import FSM, Agent, BasicBehaviour, Subsystem, System
from earl.model.types import StructType, TypeAlias
from earl.model.validate import ModelTypeError, refuse_wrong_types, root_path
from earl.render.diagram import Diagram
from earl.render.graphviz import GraphvizError
from earl.render.names import subsystem_name
from earl.render.views.activity import activity_view
from earl.render.views.agent import agent_view
from earl.render.views.fsm import fsm_view
from earl.render.views.system import system_view
from earl.render.views.types import types_view

SVG = "image/svg+xml"


def diagram_for(element: object) -> Diagram | None:
    """The diagram an element is shown as, or None for elements without one. A value of a wrong type in
    it raises ModelTypeError naming where it is, as `check` and `to_earl` do."""
    if isinstance(element, (Agent, Subsystem, FSM, BasicBehaviour, StructType, TypeAlias)):
        refuse_wrong_types(element, root_path(element))  # a System is looked at by its Subject
    if isinstance(element, System):
        from earl.render.build import Subject
        from earl.render.mermaid import mermaid_of

        subject = Subject(element)
        drawn = system_view(element, subject.agent_type, subject.placements)
        # as build_diagram gives it: the notebook's system diagram has its Mermaid text too
        return replace(drawn, mermaid_text=lambda: mermaid_of(subject, "system", None))
    if isinstance(element, Agent):
        return agent_view(element)
    if isinstance(element, Subsystem):
        if element.fsm is None:
            return None
        return fsm_view(element.fsm, subsystem_name(element), element)
    if isinstance(element, FSM):
        return fsm_view(element, "")
    if isinstance(element, BasicBehaviour):
        return activity_view(element, "")
    if isinstance(element, (StructType, TypeAlias)):
        return types_view([element], element.name, "")
    return None


def svg_for(element: object) -> str | None:
    """The SVG of an element; None (IPython then shows the text repr) when there is none, when `dot` is
    missing, or when the element holds a value of a wrong type (said in a line, not IPython's traceback
    from inside earl)."""
    try:
        diagram = diagram_for(element)
    except ModelTypeError as error:
        sys.stderr.write(f"earl: {error}\n")
        return None
    if diagram is None:
        return None
    try:
        return diagram.svg()
    except GraphvizError as error:
        sys.stderr.write(f"earl: {error}\n")
        return None


def register_formatters(shell: Any = None) -> bool:
    """Register the SVG formatters with `shell` (the running IPython shell by default); False if there is none."""
    if shell is None:
        ipython = sys.modules.get("IPython")
        shell = ipython.get_ipython() if ipython is not None else None  # type: ignore[attr-defined]
    if shell is None:
        return False
    formatter = shell.display_formatter.formatters[SVG]
    for kind in (System, Agent, Subsystem, FSM, BasicBehaviour, StructType, TypeAlias):
        formatter.for_type(kind, svg_for)
    return True


def load_ipython_extension(shell: Any) -> None:
    """`%load_ext earl.render`."""
    register_formatters(shell)


__all__ = ["diagram_for", "load_ipython_extension", "register_formatters", "svg_for"]
