"""earl: the open implementation of EARL, the Embodied Agent-Based Robot Control Systems Modelling Language.

    >>> import earl
    >>> system = earl.load("examples/pick_and_place/system.earl")
    >>> system.agent("manip").control_subsystem.fsm.initial
    'idle'
    >>> text = system.to_earl()          # canonical .earl text

`earl.model` holds one class per concept of the manual (§2); `earl.lang` reads
and writes `.earl` text.
"""

from __future__ import annotations

# first: in the `earl` program, Ctrl-C while it imports is one line, not a traceback (earl/_program.py)
from earl import _program  # noqa: F401  # isort: skip
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from earl.diagnostics import Diagnostic, EarlError, Severity
from earl.model import *  # noqa: F403  (the model's names are the API)
from earl.model import __all__ as _model_names
from earl.model.elements import System
from earl.model.validate import ModelCommentError, ModelNameError, ModelTypeError

if TYPE_CHECKING:
    import os
    from typing import IO

    from earl.render.document import DocumentResult
    from earl.runtime import Simulation
    from earl.runtime.traces import Trace

ParameterValue = bool | int | float | str


def load(path: str | Path, parameters: Mapping[str, ParameterValue] | None = None) -> System:
    """Read a `.earl` file (or a directory holding `system.earl`) into a resolved System.

    `parameters` override system parameters (`{"N": 3}`).  Raises `EarlError` with
    every problem found, each located at its file, line and column.
    """
    # Imported here so that `import earl.model` never loads the parser.
    from earl.lang.loader import load as load_file

    return load_file(path, parameters)


def save(system: System, path: str | Path) -> None:
    """Write `system` to `path` as canonical `.earl` text (the file is replaced atomically); a directory
    stands for the `system.earl` in it, as for `load`."""
    from earl.lang.loader import save as save_file

    save_file(system, path)


def loads(text: str, path: str = "<text>", parameters: Mapping[str, ParameterValue] | None = None) -> System:
    """Like `load`, for `.earl` text in memory; `path` names it in messages."""
    from earl.lang.loader import loads as load_text

    return load_text(text, path, parameters)


def simulate(system: System, **options: object) -> Simulation:
    """Run `system` in virtual time: `sim = earl.simulate(model, seed=1); sim.advance_to(2.0)`.

    Options are those of `earl.runtime.Simulation` (parameters, seed, environment, trace,
    record_memory, realtime, …).  This imports the user code the spec names.
    """
    from earl.runtime import simulate as run

    return run(system, **options)


def read_trace(source: str | os.PathLike[str] | IO[bytes]) -> Trace:
    """A trace (`earl run --trace`, `earl.simulate(…, trace=…)`) read back: a path, or a binary file object
    such as the `io.BytesIO` a run wrote to. `.summary()` is what `earl trace summary` shows, and
    `.signals(["counter/a.cs.count"])` what `earl plot` draws; `earl.TraceError` says why one cannot be read."""
    from earl.runtime.traces import read_trace as read

    return read(source)


def write_doc(
    system: System,
    directory: str | os.PathLike[str],
    *,
    expand: bool = False,
    parameters: Mapping[str, ParameterValue] | None = None,
) -> DocumentResult:
    """Write what `earl doc` writes (`index.html`, `index.md`, `diagrams/`) for `system` into `directory`;
    `expand` and `parameters` are `--expand` and `--param`. Needs Graphviz's `dot`."""
    from earl.render.document import write_doc as write

    return write(system, directory, expand=expand, parameters=parameters)


__version__ = "0.1.0"

#: the packages `earl.NAME` reaches without an import of its own (`earl.check.check(system)`), loaded
#: on first use so that `import earl` stays quick
_SUBPACKAGES = frozenset({"check", "export", "lang", "render", "runtime", "transport"})


#: names `earl.NAME` reaches in a module loaded on first use (not in `__all__`: `from earl import *` stays quick)
_LAZY_NAMES = {"Trace": "earl.runtime.traces", "TraceError": "earl.runtime.trace_reader"}


def __getattr__(name: str) -> object:
    if name in _SUBPACKAGES:
        import importlib

        return importlib.import_module(f"earl.{name}")
    if name in _LAZY_NAMES:
        import importlib

        return getattr(importlib.import_module(_LAZY_NAMES[name]), name)
    raise AttributeError(f"module 'earl' has no attribute {name!r}")


def _display_in_notebooks() -> None:
    """In a Jupyter kernel, model objects display as their diagrams (SVG); elsewhere nothing is loaded."""
    import sys

    if "IPython" in sys.modules:
        import earl.render  # noqa: F401  (registers the display formatters)


_display_in_notebooks()

__all__ = [
    "Diagnostic",
    "EarlError",
    "ModelCommentError",
    "ModelNameError",
    "ModelTypeError",
    "Severity",
    "__version__",
    "load",
    "loads",
    "read_trace",
    "save",
    "simulate",
    "write_doc",
    *_model_names,
]
