"""`sender/a.cs`: a Ping every iteration, counting the echoes that came back."""

from __future__ import annotations

from typing import Any


def tick(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.count = inputs.count + 1
    # only a Record of the right type reaches user code: its fields read as attributes
    outputs.echoed = max(inputs.echoed, inputs.echo.count)


def send(inputs: Any, outputs: Any, context: Any) -> None:
    count = inputs.count
    outputs.ping = {"count": count, "stamp": (context.time, float(count)), "note": None if count % 2 else "even"}
