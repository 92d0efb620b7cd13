"""`10s`, `500 ms`, `2.5`: durations as people write them on a command line."""

from __future__ import annotations

import re

from earl.model.elements import Duration

_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "min": 60.0, "": 1.0}
_PATTERN = re.compile(r"^\s*([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(s|ms|us|min|)\s*$")


def parse_duration(text: str, zero: bool = False) -> float:
    """Seconds; a bare number is seconds. Raises ValueError with an example of what is accepted.

    `zero`: 0, written any way (`0`, `0.0`, `00`, `0min`), is accepted too (and is 0.0)."""
    if not text.strip():  # `--duration=`: not "the default", which is no option at all
        raise ValueError("the duration is empty; write e.g. `10s`, `500ms`, `2.5` (seconds) or `1min`")
    match = _PATTERN.match(text)
    if match is None:
        raise ValueError(f"`{text}` is not a duration; write e.g. `10s`, `500ms`, `2.5` (seconds) or `1min`")
    value = float(match.group(1)) * _UNITS[match.group(2)]
    if value == 0 and zero:
        return 0.0
    if value <= 0:
        raise ValueError(f"`{text}`: a duration must be {'0 or more' if zero else 'positive'}")
    if not value <= Duration.MAX_SECONDS:  # the language's own limit; also catches the infinity of `1e400`
        raise ValueError(f"`{text}` is too long: a duration is at most {Duration.MAX_SECONDS:,.0f} s (about 31 years)")
    return value
