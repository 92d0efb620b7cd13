"""Writing the document: `index.html`, `index.md` and one SVG per diagram under `diagrams/`."""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from earl.diagnostics import Diagnostic
from earl.render.build import Subject
from earl.render.diagram import Diagram
from earl.render.document.build import DocumentBuilder
from earl.render.document.html import render_html
from earl.render.document.markdown import render_markdown


@dataclass(frozen=True)
class DocumentResult:
    html: Path
    markdown: Path
    diagrams: tuple[Path, ...]


def write_site(subject: Subject, diagnostics: Sequence[Diagnostic], directory: Path) -> DocumentResult:
    """Build the document and write it to `directory` (created if needed; earl's files there are replaced)."""
    builder = DocumentBuilder(subject, diagnostics)
    document = builder.build()
    folder = directory / "diagrams"
    folder.mkdir(parents=True, exist_ok=True)
    unique = _unique(builder.diagrams)
    # `dot` runs as a separate process per diagram, so threads draw them in parallel.
    with ThreadPoolExecutor(max_workers=max(1, min(4, os.cpu_count() or 1))) as pool:
        drawn = list(pool.map(lambda diagram: diagram.render("svg"), unique))
    paths = []
    for diagram, svg in zip(unique, drawn, strict=True):
        path = folder / f"{diagram.slug}.svg"
        path.write_bytes(svg)
        paths.append(path)
    # diagrams/ is earl's: an element renamed since the last run must not leave its old picture behind
    for stale in set(folder.glob("*.svg")) - set(paths):
        stale.unlink()
    html = directory / "index.html"
    markdown = directory / "index.md"
    html.write_text(render_html(document), encoding="utf-8")
    markdown.write_text(render_markdown(document), encoding="utf-8")
    return DocumentResult(html, markdown, tuple(paths))


def _unique(diagrams: Sequence[Diagram]) -> list[Diagram]:
    seen: dict[str, Diagram] = {}
    for diagram in diagrams:
        seen.setdefault(diagram.slug, diagram)
    return list(seen.values())
