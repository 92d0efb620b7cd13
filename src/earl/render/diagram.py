"""A diagram: its SysML header, its DOT source, and the file name it is written under."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

from earl.render.graphviz import fit_frame, run_dot


@dataclass(frozen=True)
class Diagram:
    view: str  # "system" | "agent" | "fsm" | "activity" | "types"
    header: str  # the SysML frame header, `ibd [Agent] manip/a`
    dot: str  # Graphviz source
    slug: str  # a file name stem, unique within one document
    #: The element names the diagram shows, so tests and tooltips know what to look for.
    names: tuple[str, ...] = ()

    @cached_property
    def laid_out(self) -> str:
        """The DOT source drawn: `dot` with the frame widened to hold every edge label (one more
        layout by Graphviz; see `fit_frame`)."""
        return fit_frame(self.dot)

    def render(self, output_format: str = "svg") -> bytes:
        return run_dot(self.laid_out, output_format)

    def svg(self) -> str:
        return self.render("svg").decode("utf-8")
