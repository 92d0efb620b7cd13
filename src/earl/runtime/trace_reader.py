"""Reading a trace back: the summary of `earl trace summary` and the signals of `earl plot`.

A *signal* is named as a person names the thing it measures:

    manip/a.cs.windingCurrent[1]                    memory (recorded with --record-memory)
    manip/a.cs.manipulatorState.currentJointPos[0]  a field of what an output buffer sent
"""

from __future__ import annotations

import json
import math
import re
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import CRCValidationError, StreamReader

from earl.diagnostics import did_you_mean, escape_controls
from earl.runtime import trace_paths, trace_topics
from earl.runtime.signal_syntax import signal_syntax_error
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
    #: whether the run's end is in the trace (with the iteration counts); not when the run was killed
    ended: bool = True
    #: set when the file had no valid end (cut short, or damaged): read up to its first damaged record
    cut: bool = False


#: said when a file without a valid end was read up to its first damaged record
CUT = "the file has no valid end (cut short, or damaged): read up to its first damaged record"


def _messages(
    path: Path, topics: list[str] | None = None, cut: list[bool] | None = None
) -> Iterator[tuple[str, dict[str, str], int, Any]]:
    """Every message (of `topics`) in file order; `cut` gets True appended when the file had to be read
    up to a cut."""
    yielded = False
    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream, validate_crcs=True)  # a flipped bit is damage, not other numbers
            for _, channel, message in reader.iter_messages(topics=topics, log_time_order=False):
                yielded = True
                yield channel.topic, channel.metadata, message.log_time, json.loads(message.data)
        return
    except FileNotFoundError:
        raise TraceError(f"no such file: {path}") from None
    except Exception as error:  # a damaged file provokes whatever the reader and its decompressors raise
        if yielded:
            raise _unreadable(path, error) from None
        failure = error
    # No summary at its end: a trace cut short (a run killed with its writer, a copy interrupted). Its
    # records are read in order up to the cut, so that what the run wrote before is not lost.
    wanted = None if topics is None else set(topics)
    seen_channel = False
    if cut is not None:
        cut.append(True)
    try:
        for channel, record in _records_up_to_the_cut(path):
            seen_channel = True
            if record is not None and (wanted is None or channel.topic in wanted):
                yield channel.topic, channel.metadata, record.log_time, json.loads(record.data)
    except ValueError as error:  # a message that is not JSON (or not UTF-8): damage, not a cut
        raise _unreadable(path, error) from None
    if not seen_channel:  # not an MCAP file at all, or nothing before the damage
        raise _nothing_readable(path, failure) from None


def _records_up_to_the_cut(
    path: Path, schemas: dict[int, Schema] | None = None
) -> Iterator[tuple[Channel, Message | None]]:
    """Each channel as it is declared (with None) and each message with its channel, in file order,
    until the file ends or its first damaged record (a chunk cut in half). `schemas` gets each schema
    by its number as it is declared (before the channels that use it)."""
    channels: dict[int, Channel] = {}
    with open(path, "rb") as stream:
        records = StreamReader(stream, validate_crcs=True).records
        while True:
            try:
                record = next(records)
            except Exception:  # the cut: an end of file inside a record, a chunk that does not decompress
                return
            if isinstance(record, Schema) and schemas is not None:
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                yield record, None
            elif isinstance(record, Message) and record.channel_id in channels:
                yield channels[record.channel_id], record


_MAGIC = b"\x89MCAP0\r\n"


def _nothing_readable(path: Path, error: BaseException) -> TraceError:
    """An MCAP file cut before its first whole record says so; anything else is `_unreadable`."""
    try:
        with open(path, "rb") as stream:
            start = stream.read(len(_MAGIC))
    except OSError:
        start = b""
    if isinstance(error, CRCValidationError):
        return TraceError(
            f"{path} is damaged: a checksum of its data does not match what it holds (a bit changed on disk or "
            "in a copy), before anything of it could be read"
        )
    if start == _MAGIC:
        return TraceError(
            f"{path} is not a readable MCAP trace: it was cut short (or damaged) before its first whole "
            "record (a run killed in its first 0.2 s, or a copy cut short)"
        )
    if start == b"" and _is_empty(path):
        # the run's process makes the file and its writer fills it from the first batch: a run killed
        # (SIGKILL) before that batch went out, or while it waited for its peers, leaves it empty
        return TraceError(
            f"{path} is empty: nothing was recorded in it (a run killed before its first 0.2 s, or while it "
            "waited for its peers, leaves its trace so)"
        )
    return _unreadable(path, error)


def _is_empty(path: Path) -> bool:
    try:
        return path.stat().st_size == 0
    except OSError:
        return False


def _unreadable(path: Path, error: BaseException) -> TraceError:
    """A damaged or foreign file: McapError, a decompressor's error, a record too long to allocate …"""
    if isinstance(error, CRCValidationError):
        detail = "a checksum of its data does not match what it holds: a bit changed on disk or in a copy"
    elif isinstance(error, json.JSONDecodeError | UnicodeDecodeError):
        detail = "a message is not JSON text, as every message of an earl trace is: damaged, or another tool's file"
    elif isinstance(error, struct.error) or "invalid magic" in str(error):
        detail = "it does not begin as an MCAP file does: another kind of file, or one cut to a few bytes"
    elif not str(error):
        detail = "it ends early" if isinstance(error, EOFError | EndOfFile) else type(error).__name__
    elif isinstance(error, McapError):
        detail = str(error)
    else:
        detail = f"{type(error).__name__}: {error}"
    return TraceError(f"{path} is not a readable MCAP trace ({detail})")


def _not_from_earl(path: Path, topic: str) -> TraceError:
    return TraceError(
        f"{path}: a message on `{topic}` is not one earl writes (the file is damaged or not an earl trace)"
    )


def _not_an_earl_trace(path: Path, topics: Iterable[str]) -> TraceError:
    """Said alike by `earl trace` and `earl plot` of an MCAP file another tool wrote."""
    found = sorted({escape_controls(topic) for topic in topics})  # another tool's names: shown, not obeyed
    listed = ", ".join(found[:5]) + (f" and {len(found) - 5} more" if len(found) > 5 else "")
    return TraceError(
        f"{path} is an MCAP file but not an earl trace: it has no {trace_topics.RUN} topic "
        f"({f'its topics: {listed}' if found else 'it has no topics'}); `earl run --trace FILE.mcap` writes one"
    )


def summarise(path: Path) -> TraceSummary:
    # another tool's file is said to be one before its messages are read, as `earl plot` says it: they
    # need not be JSON, and a file cut short has no summary section listing its topics
    channels = _channels(path)
    if trace_topics.RUN not in channels:
        raise _not_an_earl_trace(path, channels)
    _refuse_a_newer_format(path)
    summariser = _Summariser()
    cut: list[bool] = []
    seen: set[str] = set()
    for topic, metadata, time, data in _messages(path, cut=cut):
        seen.add(topic)
        try:
            summariser.add(topic, metadata, time, data)
        except (KeyError, TypeError, ValueError, AttributeError):
            raise _not_from_earl(path, topic) from None
    if not summariser.seen_run:
        raise _not_an_earl_trace(path, seen)
    summary = summariser.summary()
    summary.cut = bool(cut)
    return summary


def read_faults(path: Path) -> tuple[list[dict[str, Any]], bool]:
    """The faults of a trace in the order they happened, each as written (`subsystem`, `kind`,
    `message`, `function`, `traceback`, …) with its `time` in nanoseconds; and whether the file had no
    valid end (read up to its first damaged record). Only the faults' topic is read."""
    channels = _channels(path)
    if trace_topics.RUN not in channels:
        raise _not_an_earl_trace(path, channels)
    _refuse_a_newer_format(path)
    cut: list[bool] = []
    faults: list[dict[str, Any]] = []
    for topic, _, time, data in _messages(path, [trace_topics.FAULTS], cut):
        if not isinstance(data, dict):
            raise _not_from_earl(path, topic)
        faults.append({"time": time, **data})
    return faults, bool(cut)


def _refuse_a_newer_format(path: Path) -> None:
    """A trace of a newer format than this earl reads is said to be one, before its messages are read
    as this earl's: they may be written otherwise, which would read as damage. The format is in the
    `/earl/run` start message, the first message earl writes; a trace without it is format 1."""
    for _, _, _, data in _messages(path, [trace_topics.RUN]):
        written = data.get("format", 1) if isinstance(data, dict) and data.get("event") == "start" else 1
        if isinstance(written, int) and not isinstance(written, bool) and written > trace_topics.FORMAT:
            raise TraceError(
                f"{path} was written by a newer earl (trace format {written}; this earl reads up to "
                f"{trace_topics.FORMAT}): read it with that earl, or a newer one"
            )
        return


class _Summariser:
    """The summary, message by message; a message not as earl writes it raises KeyError, TypeError …"""

    def __init__(self) -> None:
        self.subsystems: dict[str, SubsystemSummary] = {}
        self.entered: dict[str, tuple[str, int]] = {}
        self.faults: list[dict[str, Any]] = []
        self.end_time = 0
        self.messages = 0
        self.settings: dict[str, Any] = {}
        self.seen_run = False
        self.ended = False

    def of(self, name: str) -> SubsystemSummary:
        found = self.subsystems.get(name)
        if found is None:
            found = self.subsystems[name] = SubsystemSummary(str(name))
        return found

    def add(self, topic: str, metadata: dict[str, str], time: int, data: Any) -> None:
        self.end_time = max(self.end_time, time)
        kind, name = trace_topics.classify(topic, metadata)
        if kind == "run":
            self.seen_run = True
            if data.get("event") == "start":
                # the format is said only when it is newer than this earl reads (`_refuse_a_newer_format`)
                self.settings = {k: v for k, v in data.items() if k not in ("event", "format")}
            elif data.get("event") == "end":
                self.ended = True
                for subsystem, count in _iterations(data.get("iterations", [])):
                    self.of(subsystem).iterations = int(count)
        elif kind == "faults":
            self.faults.append({"time": time, **data})
            self.of(data.get("subsystem", "?")).faults += 1
        elif kind == "link":
            self.messages += 1
        elif kind == "fsm":
            summary = self.of(name)
            state_to = str(data["to"])
            if name in self.entered:
                state, since = self.entered[name]
                summary.state_time[state] = summary.state_time.get(state, 0) + time - since
                transition = str(data["transition"])
                summary.transitions[transition] = summary.transitions.get(transition, 0) + 1
            self.entered[name] = (state_to, time)
            summary.final_state = state_to

    def summary(self) -> TraceSummary:
        for name, (state, since) in self.entered.items():
            summary = self.subsystems[name]
            summary.state_time[state] = summary.state_time.get(state, 0) + self.end_time - since
        return TraceSummary(self.end_time, self.subsystems, self.faults, self.messages, self.settings, self.ended)


def _iterations(counts: Any) -> list[tuple[str, Any]]:
    """(subsystem, count) of the end message: a list of {"subsystem", "iterations"}, or in a trace of
    an earlier earl an object keyed by subsystem."""
    if isinstance(counts, dict):
        return list(counts.items())
    return [(str(entry["subsystem"]), entry["iterations"]) for entry in counts]


def topics(path: Path) -> dict[str, dict[str, str]]:
    """Each topic of the trace with its channel's metadata."""
    return {topic: metadata for topic, (metadata, _) in _channels(path).items()}


def _channels(path: Path) -> dict[str, tuple[dict[str, str], Any]]:
    """Each topic of the trace with its channel's metadata and its JSON schema (None if it has none)."""
    failure: Exception | None = None
    try:
        with open(path, "rb") as stream:
            summary = make_reader(stream, validate_crcs=True).get_summary()
    except FileNotFoundError:
        raise TraceError(f"no such file: {path}") from None
    except Exception as error:  # as in `_messages`
        summary, failure = None, error
    if summary is not None:
        return {
            channel.topic: (dict(channel.metadata), _schema_of(summary.schemas.get(channel.schema_id)))
            for channel in summary.channels.values()
        }
    # a trace cut short has no summary: its schemas and channels are declared before their first message
    schemas: dict[int, Schema] = {}
    found = {
        channel.topic: (dict(channel.metadata), _schema_of(schemas.get(channel.schema_id)))
        for channel, message in _records_up_to_the_cut(path, schemas)
        if message is None
    }
    if not found and failure is not None:
        raise _nothing_readable(path, failure) from None
    return found


def _schema_of(schema: Schema | None) -> Any:
    """A channel's JSON schema as data; None when it has none, or not one in JSON."""
    if schema is None or schema.encoding != "jsonschema":
        return None
    try:
        return json.loads(schema.data)
    except ValueError:  # a damaged schema: its messages are read all the same
        return None


def _null_is_absent(schema: Any, leaf: str) -> bool:
    """Whether a null at `leaf` of a message (`ball.note`, `log[2]`, `value[0]`) is an optional field
    that was absent, rather than an infinite real: traces of format 1 wrote both as null, and only the
    channel's schema tells them apart (format 2 leaves an absent field out and writes an infinity
    `1e999`). A null that the schema does not show to be a real (an optional real, whose absence is the
    likelier, or a field the schema does not show) counts as absent; an element of an array never does,
    an array having no optional elements, even inside a part the schema leaves out (`grid[0][1]` of a
    `double[2][2]`). An optional field is one its object's `required` leaves out; earlier traces wrote
    it `anyOf: [T, null]`."""
    found, optional = _leaf_schema(schema, leaf)
    if optional:
        return True
    if not isinstance(found, dict):
        return not leaf.endswith("]")
    options = found.get("anyOf", [])
    if any(isinstance(option, dict) and option.get("type") == "null" for option in options):
        return True
    return bool(found.get("type") != "number")


#: a memory field's element, `windingCurrent[0]`: where the nulls before a family's first member are
_FIELD_ELEMENT = re.compile(r"(\w+)\[(\d+)\]\Z")


def _is_padding(schema: Any, leaf: str, families: dict[str, int] | None = None) -> bool:
    """Whether `leaf` of a memory message is one of the nulls before a memory family's first member
    (`windingCurrent[0]` of `windingCurrent[K in 1..6]`): no value of the run, which the channel's
    metadata says (`families`, None when it has none), or the schema's `prefixItems`. A trace of
    format 1 has no such metadata, and a family of arrays is in no schema: an element of a memory
    field left out of the schema is no array's element there, since a value the schema leaves out
    is an array of arrays (or a struct inside itself, an object), whose elements are never null."""
    element = _FIELD_ELEMENT.match(leaf)
    if families is not None and element is not None and element.group(1) in families:
        return int(element.group(2)) < families[element.group(1)]
    found, _ = _leaf_schema(schema, leaf)
    if isinstance(found, dict):
        return found.get("type") == "null"
    return element is not None and _leaf_schema(schema, element.group(1))[0] is None


def _families(metadata: dict[str, str]) -> dict[str, int] | None:
    """The memory families a memory channel's metadata names, each with its first index; None when it
    names none (a trace of format 1, or a damaged entry)."""
    try:
        found = json.loads(metadata["families"])
    except (KeyError, ValueError):
        return None
    if not isinstance(found, dict) or not all(isinstance(first, int) for first in found.values()):
        return None
    return found


def _unschemed(metadata: dict[str, str]) -> list[str]:
    """The memories a memory channel's metadata names as in its messages but not in its schema (an array
    of arrays: `grid/m: double[2][2]`); none when it names none (a trace written before it did)."""
    return _listed(metadata, "unschemed") or []


def _listed(metadata: dict[str, str], key: str) -> list[str] | None:
    """The names a channel's metadata lists under `key` (a JSON list): a memory channel's `unschemed`,
    an FSM channel's `outputs` (every output buffer its subsystem declares); None when it has none (a trace written
    before it did, or a damaged entry)."""
    try:
        found = json.loads(metadata[key])
    except (KeyError, ValueError):
        return None
    if not isinstance(found, list):
        return None
    return [name for name in found if isinstance(name, str)]


def _leaf_schema(schema: Any, leaf: str) -> tuple[Any, bool]:
    """The part of a channel's schema for `leaf` of its messages (None when the schema does not show
    it), and whether that leaf is an optional field (one its object's `required` list leaves out)."""
    current = schema
    rest = leaf
    optional = False
    while rest:
        current = _present_branch(current)
        if not isinstance(current, dict):
            return None, False
        properties = current.get("properties")
        if isinstance(properties, dict):
            # in earlier traces a memory family's member is one property, `log[2]`: the longest name that starts `rest`
            name = max(
                (key for key in properties if rest == key or rest.startswith((f"{key}.", f"{key}["))),
                key=len,
                default=None,
            )
            if name is None:
                return None, False
            required = current.get("required")
            optional = isinstance(required, list) and name not in required
            current, rest = properties[name], rest[len(name) :].removeprefix(".")
        else:
            index = re.match(r"\[(\d+)\]", rest)
            if index is None:
                return None, False
            # the nulls before a memory family's first member are described apart, in `prefixItems`
            position, before = int(index.group(1)), current.get("prefixItems")
            current = before[position] if isinstance(before, list) and position < len(before) else current.get("items")
            optional, rest = False, rest[index.end() :].removeprefix(".")
    return current, optional


def _raw_leaf(inner: str, buffer: str) -> str | None:
    """`inner` (a signal's name inside its subsystem) as a leaf of the messages of a topic whose leaves
    start with `buffer` (a link's output buffer; "" for memory), `[*]` as `[0]`; None when it is none."""
    inner = inner.replace("[*]", "[0]")
    if not buffer:
        return inner
    if inner == buffer or inner.startswith(f"{buffer}["):
        return "value" + inner[len(buffer) :]
    return inner[len(buffer) + 1 :] if inner.startswith(f"{buffer}.") else None


def _under_optional(schema: Any, leaf: str | None) -> Any:
    """The schema of `leaf` when the schema shows it at or under an optional field (`jointPosSetpoint[0]`),
    else None."""
    if not leaf:
        return None
    ends = [match.start() for match in re.finditer(r"[.\[]", leaf)] + [len(leaf)]
    for end in ends:
        found, optional = _leaf_schema(schema, leaf[:end])
        if found is None:
            return None
        if optional:
            found, _ = _leaf_schema(schema, leaf)
            return found if isinstance(found, dict) else None
    return None


def _present_branch(schema: Any) -> Any:
    """The schema of an optional field's value when present (`anyOf: [T, null]` gives T)."""
    if isinstance(schema, dict) and isinstance(schema.get("anyOf"), list):
        present = [option for option in schema["anyOf"] if isinstance(option, dict) and option.get("type") != "null"]
        if len(present) == 1:
            return present[0]
    return schema


@dataclass
class Series:
    """One signal: its subsystem, its name inside the subsystem, and (time s, value) samples.

    A value holds until the next sample; NaN is no value, a gap in the line: an infinite real, or a
    message without the (optional) field or array element, until a message has it again."""

    subsystem: str
    name: str
    times: list[float]
    values: list[float]
    #: whether the signal is a Boolean, its values 0.0 (false) and 1.0 (true)
    boolean: bool = False
    #: whether its first sample is the value it held when a window of the run starts (`within`), no message
    held: bool = False


@dataclass
class Signals:
    """What a plot needs from a trace, read in one pass: the series and each subsystem's state stays."""

    series: list[Series]
    bands: dict[str, list[tuple[float, float, str]]]
    end: float
    #: a line for each signal whose element the trace holds but that had no value in this run (an
    #: optional field never sent, an array sent empty): the others are drawn without it
    empty: list[str] = field(default_factory=list)
    #: whether the file had no valid end and was read up to its first damaged record
    cut: bool = False
    #: where the plot's time axis starts: 0, or the start of a window (`earl plot --from`)
    start: float = 0.0
    #: whether the signals were cut to a window of the run (`within`): its ends are the time axis's
    windowed: bool = False


def within(data: Signals, start: float | None, stop: float | None) -> Signals:
    """`data` from `start` to `stop` seconds (None: the run's start or end), for `earl plot --from/--to`.

    A value holds until the next, so each signal starts the window with the value it held at `start`;
    a signal with no value in the window is left out with a line that says so (`Signals.empty`), and
    the states are cut to the window. A TraceError when the window begins at or after the trace's end,
    or no signal has a value in it; a ValueError when `stop` is not after `start` (the window is empty)."""
    if start is None and stop is None:
        return data
    # a trace's times are its integer nanoseconds times 1e-9: compared as nanoseconds, a sample at an
    # edge of the window is in it (`--to 1.4` keeps the one at 1.4 s, which is 1.4000000000000001 s)
    first = nanoseconds(start or 0.0)
    if stop is not None and not first < nanoseconds(stop):
        raise ValueError(
            f"the window from {start or 0.0:g} s to {stop:g} s is empty: the start must be before the stop"
        )
    last_of_trace = nanoseconds(data.end)
    if first >= last_of_trace:
        raise TraceError(f"the trace ends at {data.end:.6f} s, by --from {start or 0.0:g} s: nothing to draw after it")
    last = last_of_trace if stop is None else min(nanoseconds(stop), last_of_trace)
    # the window's ends as the trace's own times are written: a message at `begin` is the value held there
    begin, end = first * 1e-9, last * 1e-9
    series: list[Series] = []
    empty = list(data.empty)
    for found in data.series:
        stamps = [nanoseconds(time) for time in found.times]
        before = [i for i, stamp in enumerate(stamps) if stamp <= first]
        inside = [i for i, stamp in enumerate(stamps) if first < stamp <= last]
        times = [found.times[i] for i in inside]
        values = [found.values[i] for i in inside]
        if before:  # the value held at the window's start
            times.insert(0, begin)
            values.insert(0, found.values[before[-1]])
        if not times or all(math.isnan(value) for value in values):
            empty.append(f"`{found.subsystem}.{found.name}` had no value from {begin:g} s to {end:g} s")
            continue
        held = bool(before) and stamps[before[-1]] < first  # not a message sent at `begin` itself
        series.append(Series(found.subsystem, found.name, times, values, found.boolean, held))
    if not series:
        raise TraceError(f"no signal has a value from {begin:g} s to {end:g} s: {'; '.join(empty)}")
    bands = {
        subsystem: [
            (max(a, begin), min(b, end), state)
            for a, b, state in stays
            if nanoseconds(b) > first and nanoseconds(a) < last
        ]
        for subsystem, stays in data.bands.items()
    }
    return Signals(series, bands, end, empty, data.cut, begin, True)


def nanoseconds(seconds: float) -> int:
    """`seconds` of run time as the integer nanoseconds a trace stamps its messages with: a time read
    from a trace (its nanoseconds times 1e-9) gives back the nanoseconds it was written with."""
    return round(seconds * 1e9)


def read_signals(path: Path, names: list[str]) -> Signals:
    """The signals `names` (`[*]` stands for every member) and the FSM states of their subsystems.

    The file is read once, whatever the number of signals: a trace of a long run is large.
    """
    channels = _channels(path)
    if trace_topics.RUN not in channels:  # before its signals are looked for: another tool's file has none
        raise _not_an_earl_trace(path, channels)
    _refuse_a_newer_format(path)
    available = {topic: metadata for topic, (metadata, _) in channels.items()}
    #: (kind, subsystem) -> topic, whichever way this trace's earl named its topics
    by_kind: dict[tuple[str, str], str] = {}
    links: list[tuple[str, dict[str, str]]] = []
    for topic, metadata in available.items():
        kind, owner = trace_topics.classify(topic, metadata)
        if kind == "link":
            links.append((topic, metadata))
        else:
            by_kind[(kind, owner)] = topic
    subsystems = sorted({owner for kind, owner in by_kind if kind == "fsm"}, key=len, reverse=True)
    wanted: dict[str, tuple[str, str]] = {}  # topic -> (subsystem, prefix of its leaves)
    owners: list[tuple[str, str, str]] = []  # (name, subsystem, name inside the subsystem)
    memory_topics: dict[str, str] = {}

    def elements_of(subsystem: str) -> list[str]:
        memory_topic = by_kind.get(("memory", subsystem))
        if memory_topic is None:
            return _elements_in(subsystem, None, links)
        metadata, schema = channels[memory_topic]
        return _elements_in(subsystem, schema, links, _families(metadata) or {}, _unschemed(metadata))

    for name in names:
        malformed = signal_syntax_error(name)
        if malformed is not None:
            raise TraceError(str(malformed))
        subsystem = next((s for s in subsystems if name.startswith(s + ".")), None)
        if subsystem is None and name in subsystems:
            # the subsystem alone: it is in the trace, but a signal is one of its values
            elements = elements_of(name)
            if not elements:
                raise TraceError(
                    f"`{name}` names a subsystem: a signal goes on to its memory or output buffer, and the trace "
                    f"holds no value of it: record its memory with `--record-memory {name}`"
                )
            listed = ", ".join(f"`{element}`" for element in elements)
            unrecorded = (
                f"; its memory is not in this trace (`earl run --record-memory {name}` records it)"
                if ("memory", name) not in by_kind
                else ""
            )
            raise TraceError(
                f"`{name}` names a subsystem: a signal goes on to its memory or output buffer, "
                f"e.g. `{name}.{elements[0]}` (the trace has {listed}){unrecorded}"
            )
        if subsystem is None:
            raise TraceError(
                f"`{name}` does not start with a subsystem of this trace ({', '.join(sorted(subsystems)) or 'none'})"
            )
        inner = name[len(subsystem) + 1 :]
        owners.append((name, subsystem, inner))
        memory_topic = by_kind.get(("memory", subsystem))
        if memory_topic is not None:
            wanted[memory_topic] = (subsystem, "")
            memory_topics[subsystem] = memory_topic
        # only the links of the output buffer the name starts with: a control subsystem's other links
        # can carry tens of thousands of messages that this plot would decode for nothing
        element = signal_element(inner)
        for topic, metadata in links:
            source = metadata.get("source", "")
            if source.startswith(subsystem + "."):
                buffer = source[len(subsystem) + 1 :]
                if signal_element(buffer) == element:
                    wanted.setdefault(topic, (subsystem, buffer))
        wanted[by_kind[("fsm", subsystem)]] = (subsystem, "")
    fsm_topics = {by_kind[("fsm", subsystem)] for _, subsystem, _ in owners}
    memory_channels = set(memory_topics.values())
    leaves: dict[tuple[str, str], tuple[list[float], list[float]]] = {}
    #: the leaves that had a value at least once: a number, a Boolean, or an infinite real (null)
    valued: set[tuple[str, str]] = set()
    #: the leaves that held a number that is no Boolean: the others that had a value are Booleans
    numeric: set[tuple[str, str]] = set()
    #: the leaves that held text: no number, which the plot says instead of "no value"
    texts: set[tuple[str, str]] = set()
    #: (topic, leaf) -> whether a null there is an absent optional field (else an infinite real), and
    #: whether that field holds text when present (an optional string never sent is no number either),
    #: and whether it is one of the nulls before a memory family's first member
    null_meaning: dict[tuple[str, str], tuple[bool, bool, bool]] = {}
    stays: dict[str, list[tuple[float, str]]] = {}
    #: each topic's leaves that its messages have held: one that a later message lacks (an optional
    #: field withdrawn, an array sent shorter) has no value from then on, a gap until it comes back
    held: dict[str, set[tuple[str, str]]] = {}
    end = 0.0
    cut: list[bool] = []
    for topic, _, time, data in _messages(path, [*wanted, trace_topics.RUN], cut):
        seconds = time * 1e-9
        end = max(end, seconds)
        if topic == trace_topics.RUN:
            continue
        try:
            subsystem, buffer = wanted[topic]
            if topic in fsm_topics:
                stays.setdefault(subsystem, []).append((seconds, str(data["to"])))
                continue
            present: set[tuple[str, str]] = set()
            for raw, value in iter_leaves(data):
                leaf = raw
                if buffer:
                    # a message that is not a struct is recorded as `{"value": …}`: `raw[0]`, not `raw.value[0]`
                    if leaf == "value" or leaf.startswith("value["):
                        leaf = buffer + leaf[len("value") :]
                    else:
                        leaf = f"{buffer}.{leaf}"
                key = (subsystem, leaf)
                if isinstance(value, str):
                    texts.add(key)
                    continue
                if value is None:
                    meaning = null_meaning.get((topic, raw))
                    if meaning is None:
                        metadata, schema = channels[topic]
                        if topic in memory_channels and _is_padding(schema, raw, _families(metadata)):
                            meaning = null_meaning[(topic, raw)] = (True, False, True)
                        else:
                            text = _present_branch(_leaf_schema(schema, raw)[0])
                            is_text = isinstance(text, dict) and text.get("type") == "string"
                            meaning = null_meaning[(topic, raw)] = (_null_is_absent(schema, raw), is_text, False)
                    if meaning[2]:  # before a memory family's first member: no element of the spec
                        continue
                    if meaning[1]:
                        texts.add(key)
                        continue
                    # either way a gap in the line: an absent field has no value to hold until the next
                    number = math.nan
                    if not meaning[0]:  # an infinite real
                        valued.add(key)
                        numeric.add(key)
                else:
                    number = float(value)
                    if math.isinf(number):  # format 2's `1e999`: a gap, as format 1's null
                        number = math.nan
                    valued.add(key)
                    if not isinstance(value, bool):
                        numeric.add(key)
                found = leaves.get(key)
                if found is None:
                    found = leaves[key] = ([], [])
                found[0].append(seconds)
                found[1].append(number)
                present.add(key)
            before = held.setdefault(topic, present)
            if before is not present:
                for key in before - present:
                    times, numbers = leaves[key]
                    if not math.isnan(numbers[-1]):  # the line ends here, not at the next value
                        times.append(seconds)
                        numbers.append(math.nan)
                before |= present
        except (KeyError, TypeError, ValueError, AttributeError):
            raise _not_from_earl(path, topic) from None
    series: list[Series] = []
    empty: list[str] = []
    leaf_hints: list[str] = []
    for name, subsystem, inner in owners:
        pattern = re.compile(re.escape(inner).replace(r"\[\*\]", r"\[\d+\]") + "$")
        named = [key for key in leaves if key[0] == subsystem and pattern.match(key[1])]
        matched = [
            Series(subsystem, leaf, *leaves[(subsystem, leaf)], boolean=(subsystem, leaf) not in numeric)
            for _, leaf in named
            if (subsystem, leaf) in valued
        ]
        if not matched:
            if any(owner == subsystem and pattern.match(leaf) for owner, leaf in texts):
                raise TraceError(f"`{name}` is not a number but text; a plot draws numbers and Booleans")
            # in the trace as null only (format 1), or in the schema only, under an optional field that no
            # message has (format 2 leaves an absent field out): an optional field absent from every message
            never_sent = [
                _under_optional(channels[topic][1], _raw_leaf(inner, buffer))
                for topic, (owner, buffer) in wanted.items()
                if owner == subsystem and topic not in fsm_topics
            ]
            if not named and any(
                isinstance(found, dict) and _present_branch(found).get("type") == "string" for found in never_sent
            ):  # an optional string never sent is no number either: the channel's schema says it is text
                raise TraceError(f"`{name}` is not a number but text; a plot draws numbers and Booleans")
            if named or any(found is not None for found in never_sent):
                empty.append(f"`{name}` had no value in this run (an optional field never sent)")
                leaf_hints.append(empty[-1])
                continue
            # a struct or an array named whole: its numbers are its parts
            parts = sorted(
                {leaf for owner, leaf in valued if owner == subsystem and leaf.startswith((f"{inner}.", f"{inner}["))},
                key=_natural,
            )
            if parts:
                listed = ", ".join(f"`{subsystem}.{leaf}`" for leaf in parts[:4]) + (" …" if len(parts) > 4 else "")
                raise TraceError(f"`{name}` is not a number but has parts that are: name one, {listed}")
            problem = _trace_path_problem(subsystem, inner, by_kind, channels, links, leaves)
            if problem is not None:
                raise TraceError(f"`{name}`: {problem}")
            element = signal_element(inner)
            same = sorted({leaf for (owner, leaf) in leaves if owner == subsystem and signal_element(leaf) == element})
            if same:
                hint = f"the trace has {', '.join(f'`{leaf}`' for leaf in same[:6])}{' …' if len(same) > 6 else ''}"
                # the element is in the trace, this part of it never had a value: an optional field never
                # sent, an array sent empty; or a misspelt part, which the leaves found show
                empty.append(f"`{name}` had no value in this run (an optional field never sent, or an empty array)")
                leaf_hints.append(f"`{name}` had no value in this run ({hint})")
                continue
            declared = _listed(channels[by_kind[("fsm", subsystem)]][0], "outputs") or []
            silent = trace_paths.declared_buffer(inner, declared)
            if silent is not None:
                # an output buffer the subsystem declares (the trace's metadata says so) that sent nothing the
                # trace holds: in a run of some agents (`--agents`), no link may leave it in this process
                empty.append(f"`{name}` had no value in this run (`{silent}` sent no message the trace recorded)")
                leaf_hints.append(empty[-1])
                continue
            if subsystem not in memory_topics:
                hint = (
                    f"if it is memory, record it with `--record-memory {subsystem}`; an output buffer is in the "
                    "trace when a link leaves it (and `--record-links` keeps that link)"
                )
            else:
                elements = elements_of(subsystem)
                has = f" (the trace has {', '.join(f'`{e}`' for e in elements)})" if elements else ""
                hint = did_you_mean(element, [signal_element(e) for e in elements]) or (
                    f"check the name against the spec{has}"
                )
            raise TraceError(f"the trace has no values for `{name}`; {hint}")
        series.extend(sorted(matched, key=lambda item: _natural(item.name)))
    bands = {
        subsystem: [
            (start, changes[i + 1][0] if i + 1 < len(changes) else end, state)
            for i, (start, state) in enumerate(changes)
        ]
        for subsystem, changes in stays.items()
    }
    if not series:
        raise TraceError(f"no signal has a value in this trace: {'; '.join(leaf_hints)}")
    return Signals(series, bands, end, empty, bool(cut))


def _trace_path_problem(
    subsystem: str,
    inner: str,
    by_kind: dict[tuple[str, str], str],
    channels: dict[str, tuple[dict[str, str], Any]],
    links: list[tuple[str, dict[str, str]]],
    leaves: dict[tuple[str, str], Any],
) -> str | None:
    """What the trace's schemas say is wrong with `inner`, a signal of `subsystem` that had no value
    (`trace_paths.path_problem`), or None."""
    memory_topic = by_kind.get(("memory", subsystem))
    memory = None
    if memory_topic is not None:
        metadata, schema = channels[memory_topic]
        memory = (schema, _families(metadata) or {})
    # every output buffer the subsystem declares; not `buffers`, which a trace of this earl's first days
    # has instead: the buffers links left in that process, of a run of some agents not every member
    declared = _listed(channels[by_kind[("fsm", subsystem)]][0], "outputs")
    buffers: dict[str, Any] = {}
    for topic, metadata in links:
        source = metadata.get("source", "")
        if source.startswith(subsystem + "."):
            buffers.setdefault(source[len(subsystem) + 1 :], channels[topic][1])

    def has_leaves(prefix: str) -> bool:
        pattern = re.compile(re.escape(prefix).replace(r"\[\*\]", r"\[\d+\]") + r"(?:[.\[]|\Z)")
        return any(owner == subsystem and pattern.match(leaf) for owner, leaf in leaves)

    return trace_paths.path_problem(inner, memory, buffers, declared, has_leaves)


def _elements_in(
    subsystem: str,
    memory_schema: Any,
    links: list[tuple[str, dict[str, str]]],
    families: dict[str, int] | None = None,
    unschemed: list[str] | None = None,
) -> list[str]:
    """What a signal of `subsystem` can go on to in this trace: its recorded memory (`memory_schema`,
    the schema of its memory topic, None when it has none, and the `families` its metadata names) and
    the output buffers whose links are recorded (`links`: every link topic of the trace with its
    metadata), a family written `name[*]`: in format 1 a member was a field, `windingCurrent[1]`; in
    format 2 a family is one array, which only the metadata tells from an array; and the memories the
    metadata names as `unschemed` (an array of arrays, which Foxglove refuses in a schema)."""
    names: list[str] = [f"{name}[*]" for name in families or {}]
    properties = memory_schema.get("properties") if isinstance(memory_schema, dict) else None
    if isinstance(properties, dict):
        names += [str(key) for key in properties if key not in (families or {})]
    names += unschemed or []
    for _, metadata in links:
        source = metadata.get("source", "")
        if source.startswith(subsystem + "."):
            names.append(source[len(subsystem) + 1 :])
    shown = (signal_element(name) + ("[*]" if "[" in name else "") for name in names)
    return sorted(dict.fromkeys(shown), key=_natural)


def signal_element(name: str) -> str:
    """The element a signal or buffer name starts with: `motorControllerCommand` of `motorControllerCommand[2].x`."""
    return re.split(r"[.\[]", name, maxsplit=1)[0]


def _natural(name: str) -> list[object]:
    """`x[2]` before `x[10]`."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]
