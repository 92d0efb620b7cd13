"""A diagram: its SysML header, its DOT source, and the file name it is written under."""

from __future__ import annotations

from dataclasses import dataclass

from earl.render.graphviz import run_dot


@dataclass(frozen=True)
class Diagram:
    view: str  # "system" | "agent" | "fsm" | "activity" | "types"
    header: str  # the SysML frame header, `ibd [Agent] manip/a`
    dot: str  # Graphviz source
    slug: str  # a file name stem, unique within one document
    #: The element names the diagram shows, so tests and tooltips know what to look for.
    names: tuple[str, ...] = ()

    def render(self, output_format: str = "svg") -> bytes:
        return run_dot(self.dot, output_format)

    def svg(self) -> str:
        return self.render("svg").decode("utf-8")
