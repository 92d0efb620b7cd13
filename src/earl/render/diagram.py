"""A diagram: its SysML header, its DOT source, and the file name it is written under."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

from earl.render.graphviz import fit_frame, run_dot

#: what `Diagram.render` makes, as `earl diagram --format` names them
RENDERED_FORMATS = ("svg", "png", "dot", "mermaid")


@dataclass(frozen=True)
class Diagram:
    view: str  # "system" | "agent" | "fsm" | "activity" | "types"
    header: str  # the SysML frame header, `ibd [Agent] manip/a`
    dot: str  # Graphviz source
    slug: str  # a file name stem, unique within one document
    #: The element names the diagram shows, so tests and tooltips know what to look for.
    names: tuple[str, ...] = ()
    #: Its Mermaid text, made when asked (`build_diagram` gives one to the system and fsm views): the
    #: same diagram as `earl diagram --format mermaid` writes, for Markdown on code hosts that draw it.
    mermaid_text: Callable[[], str] | None = field(default=None, repr=False, compare=False)

    @cached_property
    def laid_out(self) -> str:
        """The DOT source drawn: `dot` with the frame widened to hold every edge label (one more
        layout by Graphviz; see `fit_frame`)."""
        return fit_frame(self.dot)

    def render(self, output_format: str = "svg") -> bytes:
        """The diagram as `svg` or `png` (drawn by Graphviz's `dot`), or as `dot` or `mermaid` text (UTF-8):
        the formats of `earl diagram --format`."""
        if output_format == "mermaid":
            return self.mermaid().encode("utf-8")
        if output_format == "dot":
            return self.dot.encode("utf-8")  # as `earl diagram --format dot` writes it
        if output_format not in RENDERED_FORMATS:
            raise ValueError(f"unknown diagram format {output_format!r}: the formats are {', '.join(RENDERED_FORMATS)}")
        return run_dot(self.laid_out, output_format)

    def mermaid(self) -> str:
        """The Mermaid text of the system and fsm views, as `build_diagram` makes them."""
        if self.mermaid_text is None:
            raise ValueError(
                f"this {self.view} diagram has no Mermaid text: Mermaid draws the system and fsm views, "
                "as build_diagram(system, view, target) makes them"
            )
        return self.mermaid_text()

    def svg(self) -> str:
        return self.render("svg").decode("utf-8")
