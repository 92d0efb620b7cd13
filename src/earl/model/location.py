"""Where an element of a specification was written.

Every model element carries a `SourceLocation` so that a diagnostic can point at
the line a person wrote.  Locations never take part in model equality: a model
printed and parsed again is the same model even though its text moved.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from earl.model.frozen import quick_init


@quick_init
@dataclass(frozen=True, slots=True)
class SourceLocation:
    """A span of text; lines and columns count from 1, the end is inclusive."""

    file: str
    line: int
    column: int
    end_line: int
    end_column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


def location_field() -> SourceLocation | None:
    """A dataclass field for a location that equality and repr ignore."""
    return field(default=None, compare=False, repr=False)  # type: ignore[return-value]


@dataclass(slots=True)
class Comments:
    """Comments a person wrote around an element, kept so `earl fmt` never drops them.

    `leading` are the whole-line comments just above the element ("" where a blank line parted them,
    and first where a blank line parted the element from the one before it in its group of a body, as
    `earl fmt` groups them: earl/lang/layout.py),
    `trailing` the comment at the end of its first line.  They are not part of the model's meaning.
    """

    leading: list[str] = field(default_factory=list)
    trailing: str | None = None
    #: Comments after the last element of a file (kept on the System), or of a block's body, before its
    #: `}` (an agent, subsystem, basic behaviour, FSM, struct or robot); "" keeps a blank line between two.
    closing: list[str] = field(default_factory=list)
    #: The comment after a block's `}` on its line (`}  // end of the arm`), kept after it; a block written
    #: on one line (`r/r { a/a }  // c`) keeps it there too, so where it goes never depends on the layout.
    after: str | None = None


def comments_field() -> Comments:
    return field(default_factory=Comments, compare=False, repr=False)  # type: ignore[return-value]
