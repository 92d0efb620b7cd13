"""Controller state that the spec declares no memory for: trajectories, integrals, filters.

The spec's memories (Table 3) hold what the manual names; a real regulator also
remembers its integral and where its trajectory started.  Those live here, one
dictionary per subsystem and per run: a run is told apart by its environment
object, and a clock that goes backwards means a new run in the same process.
The values depend only on what the functions were given, so two runs with the same
seed still compute the same currents.
"""

from __future__ import annotations

import contextlib
import weakref
from typing import Any

_BY_ENVIRONMENT: dict[int, dict[str, dict[str, Any]]] = {}
_WITHOUT_ENVIRONMENT: dict[str, dict[str, Any]] = {}


def state_of(context: Any) -> dict[str, Any]:
    """The mutable state of the subsystem `context.subsystem` in this run."""
    environment = context.environment
    if environment is None:
        bucket = _WITHOUT_ENVIRONMENT
    else:
        key = id(environment)
        bucket = _BY_ENVIRONMENT.get(key)  # type: ignore[assignment]
        if bucket is None:
            bucket = _BY_ENVIRONMENT[key] = {}
            # an environment that cannot be weakly referenced keeps its state until the process ends
            with contextlib.suppress(TypeError):
                weakref.finalize(environment, _BY_ENVIRONMENT.pop, key, None)
    slot = bucket.setdefault(context.subsystem, {})
    now = float(context.time)
    if slot.get("__time__", now) > now:
        slot.clear()
    slot["__time__"] = now
    return slot
