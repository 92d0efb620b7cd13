"""Where in the spec's own code a fault happened, read from its traceback (`Fault.traceback`).

A fault's traceback holds only the frames of the spec's code (earl's own are left out as the fault is
recorded, earl/runtime/engine.py), from the function's own frame, the first, down to the innermost,
where the exception was raised. Its text is what a trace stores, so a trace written before this
module existed is read alike.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

#: a frame of a traceback as `traceback.format_list` writes it
_FRAME = re.compile(r'^  File "(?P<file>[^"\n]*)", line (?P<line>[0-9]+), in (?P<name>[^\n]*)$', re.MULTILINE)


@dataclass(frozen=True)
class Frame:
    """A frame of the spec's code: its file as it was run, its line, and the function it is in."""

    file: str
    line: int
    name: str

    def shown(self, here: Path | None = None) -> str:
        """`sorting/sorter.py:8 in classify`: the file relative to `here` (the working directory) when it
        is inside it, else as it was run."""
        return f"{_file_shown(self.file, here)}:{self.line} in {self.name}"


def user_frames(traceback: str) -> list[Frame]:
    """The frames of a fault's traceback, the function's own first; none for a fault without one."""
    return [Frame(m.group("file"), int(m.group("line")), m.group("name")) for m in _FRAME.finditer(traceback)]


def fault_place(traceback: str, here: Path | None = None) -> str:
    """` (at sorting/sorter.py:8 in classify)`, or, raised deeper in the spec's code,
    ` (at sorting/ratios.py:3 in ratio, from sorting/sorter.py:8 in classify)`: the innermost frame of
    the spec's code and the function's own; "" for a fault without a traceback."""
    frames = user_frames(traceback)
    if not frames:
        return ""
    innermost, own = frames[-1], frames[0]
    place = innermost.shown(here)
    if own != innermost:
        place += f", from {own.shown(here)}"
    return f" (at {place})"


def _file_shown(file: str, here: Path | None) -> str:
    """A file of a traceback as a person finds it: relative to `here` when inside it."""
    try:
        base = here if here is not None else Path.cwd()
        relative = os.path.relpath(file, base)
    except (OSError, ValueError):  # no working directory, another drive
        return file
    return file if relative.startswith("..") or os.path.isabs(relative) else relative
