"""Reading a trace back: the summary of `earl trace summary` and the signals of `earl plot`.

A *signal* is named as a person names the thing it measures:

    manip/a.cs.windingCurrent[1]                    memory (recorded with --record-memory)
    manip/a.cs.manipulatorState.currentJointPos[0]  a field of what an output buffer sent
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import make_reader

from earl.runtime.values import iter_leaves


class TraceError(Exception):
    """The file is not a readable earl trace, or it lacks what was asked for."""


@dataclass
class SubsystemSummary:
    name: str
    state_time: dict[str, int] = field(default_factory=dict)
    transitions: dict[str, int] = field(default_factory=dict)
    faults: int = 0
    iterations: int = 0
    final_state: str = ""


@dataclass
class TraceSummary:
    end_time: int
    subsystems: dict[str, SubsystemSummary]
    faults: list[dict[str, Any]]
    messages: int
    settings: dict[str, Any]


def _messages(path: Path, topics: list[str] | None = None) -> Iterator[tuple[str, dict[str, str], int, Any]]:
    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream)
            for _, channel, message in reader.iter_messages(topics=topics, log_time_order=True):
                yield channel.topic, channel.metadata, message.log_time, json.loads(message.data)
    except FileNotFoundError:
        raise TraceError(f"no such file: {path}") from None
    except (McapError, json.JSONDecodeError, ValueError, EOFError) as error:
        raise TraceError(f"{path} is not a readable MCAP trace ({error})") from None


def summarise(path: Path) -> TraceSummary:
    subsystems: dict[str, SubsystemSummary] = {}
    entered: dict[str, tuple[str, int]] = {}
    faults: list[dict[str, Any]] = []
    end_time = 0
    messages = 0
    settings: dict[str, Any] = {}
    seen_run = False

    def of(name: str) -> SubsystemSummary:
        found = subsystems.get(name)
        if found is None:
            found = subsystems[name] = SubsystemSummary(name)
        return found

    for topic, metadata, time, data in _messages(path):
        end_time = max(end_time, time)
        if topic == "/earl/run":
            seen_run = True
            if data.get("event") == "start":
                settings = {k: v for k, v in data.items() if k != "event"}
            elif data.get("event") == "end":
                for name, count in data.get("iterations", {}).items():
                    of(name).iterations = int(count)
        elif topic == "/earl/faults":
            faults.append({"time": time, **data})
            of(data.get("subsystem", "?")).faults += 1
        elif topic.startswith("link/"):
            messages += 1
        elif topic.endswith("/fsm"):
            name = metadata.get("subsystem", topic[: -len("/fsm")])
            summary = of(name)
            if name in entered:
                state, since = entered[name]
                summary.state_time[state] = summary.state_time.get(state, 0) + time - since
                summary.transitions[data["transition"]] = summary.transitions.get(data["transition"], 0) + 1
            entered[name] = (data["to"], time)
            summary.final_state = data["to"]
    if not seen_run:
        raise TraceError(f"{path} is an MCAP file but not an earl trace (it has no /earl/run topic)")
    for name, (state, since) in entered.items():
        summary = subsystems[name]
        summary.state_time[state] = summary.state_time.get(state, 0) + end_time - since
    return TraceSummary(end_time, subsystems, faults, messages, settings)


def topics(path: Path) -> dict[str, dict[str, str]]:
    try:
        with open(path, "rb") as stream:
            summary = make_reader(stream).get_summary()
    except FileNotFoundError:
        raise TraceError(f"no such file: {path}") from None
    except (McapError, ValueError, EOFError) as error:
        raise TraceError(f"{path} is not a readable MCAP trace ({error})") from None
    if summary is None:
        return {}
    return {channel.topic: dict(channel.metadata) for channel in summary.channels.values()}


def signal(path: Path, name: str) -> tuple[str, list[float], list[float]]:
    """(subsystem, times in s, values) of a signal; TraceError saying what the trace has otherwise."""
    available = topics(path)
    subsystems = sorted({t[: -len("/fsm")] for t in available if t.endswith("/fsm")}, key=len, reverse=True)
    subsystem = next((s for s in subsystems if name.startswith(s + ".")), None)
    if subsystem is None:
        raise TraceError(
            f"`{name}` does not start with a subsystem of this trace ({', '.join(sorted(subsystems)) or 'none'})"
        )
    rest = name[len(subsystem) + 1 :]
    candidates: list[tuple[str, str]] = []
    if f"{subsystem}/memory" in available:
        candidates.append((f"{subsystem}/memory", rest))
    for topic, metadata in available.items():
        source = metadata.get("source", "")
        if topic.startswith("link/") and source.startswith(subsystem + "."):
            buffer = source[len(subsystem) + 1 :]
            if rest == buffer or rest.startswith(buffer + ".") or rest.startswith(buffer + "["):
                leaf = rest[len(buffer) :].lstrip(".")
                candidates.append((topic, leaf or "value"))
                break
    for topic, leaf in candidates:
        times: list[float] = []
        values: list[float] = []
        for _, _, time, data in _messages(path, [topic]):
            for path_text, value in iter_leaves(data):
                if path_text == leaf or (leaf and path_text == f"value{leaf}") or path_text == f"value.{leaf}":
                    times.append(time * 1e-9)
                    values.append(float(value))
                    break
        if times:
            return subsystem, times, values
    hint = (
        f"record its memory with `--record-memory {subsystem}`"
        if f"{subsystem}/memory" not in available
        else "check the name against the spec"
    )
    raise TraceError(f"the trace has no values for `{name}`; {hint}")


def state_bands(path: Path, subsystem: str, end_time: float) -> list[tuple[float, float, str]]:
    """(start s, end s, state) for each stay of `subsystem` in an FSM state."""
    bands: list[tuple[float, float, str]] = []
    current: tuple[float, str] | None = None
    for _, _, time, data in _messages(path, [f"{subsystem}/fsm"]):
        if current is not None:
            bands.append((current[0], time * 1e-9, current[1]))
        current = (time * 1e-9, data["to"])
    if current is not None:
        bands.append((current[0], end_time, current[1]))
    return bands
