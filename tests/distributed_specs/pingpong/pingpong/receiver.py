"""`receiver/a.cs`: echo every Ping; hold while the sender is gone."""

from __future__ import annotations

from typing import Any


def answer(inputs: Any, outputs: Any, context: Any) -> None:
    ping = inputs.ping
    if not isinstance(ping.stamp, tuple):
        raise TypeError(f"an array arrived as {type(ping.stamp).__name__}, not a tuple")
    outputs.received = inputs.received + 1
    outputs.lastPing = ping


def echo(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.echo = inputs.lastPing


def hold(inputs: Any, outputs: Any, context: Any) -> None:
    outputs.holds = inputs.holds + 1
