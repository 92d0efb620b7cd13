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

from earl.diagnostics import Diagnostic, EarlError, Severity
from earl.lang.loader import load, loads
from earl.model import *  # noqa: F403  (the model's names are the API)
from earl.model import __all__ as _model_names

__version__ = "0.1.0"

__all__ = ["Diagnostic", "EarlError", "Severity", "load", "loads", "__version__", *_model_names]
