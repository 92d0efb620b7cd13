"""The trace of a run: an MCAP file that Foxglove opens (JSON messages with JSON schemas).

Topics (one channel each; log time = run time in ns; names in `trace_topics.py`):

    /SUBSYSTEM/fsm        a state change   {"from", "to", "transition", "declared" (a `*` line)}
    /SUBSYSTEM/behaviour  a behaviour starts or stops {"event", "state", "behaviour", "iterations", "reason"}
    /SUBSYSTEM/memory     a memory snapshot after an iteration (only for subsystems asked for); a
                          memory family is one array, member K at index K (`windingCurrent[1]`)
    /link/LINK            every message sent on a link (or those chosen); a struct as itself,
                          any other value as {"value": ...}
    /earl/faults          faults, with the traceback of a failing function
    /earl/run             the run's settings at the start and its end time

Every topic starts with `/`, as ROS's and Foxglove's do. A subsystem is named as everywhere else:
`/manip/a.cs/fsm`, `/manip/a.motorController[3]/ve/memory`. Every field of a message is a name
Foxglove's message paths take (letters, digits, `_`), so that `"/manip/a.cs/memory".windingCurrent[1]`
plots in Foxglove what `earl plot` calls `manip/a.cs.windingCurrent[1]`.
The same spec and seed give a byte-identical file: nothing in it depends on the wall clock.

`TraceWriter` decides what is written (topics, schemas, which links); a sink writes it.
A trace written to a file is written by a second process (`trace_process.py`): encoding a
message as JSON and framing it in MCAP costs about ten times what handing it over costs,
and a run sends tens of thousands of messages a second, so the run goes on on one core
while its trace is written on the other.  A stream (`io.BytesIO`) is written in-process.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import math
import os
import re
import select
import struct
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, NoReturn

import msgpack  # type: ignore[import-untyped]

from earl import __version__
from earl.model.types import DataType
from earl.runtime import link_patterns, trace_topics
from earl.runtime.events import Fault, MessageWriter, Recorder
from earl.runtime.values import TypeSystem, json_schema, to_json

# Foxglove's reader of JSON schemas takes one `type` per field and an object's `properties` (see
# `values.json_schema`): a field that may be null (`from` before the first state) is its type, and
# left out of `required`.
_STATE_SCHEMA = {
    "type": "object",
    "title": "earl.StateChange",
    "properties": {
        "from": {"type": "string", "description": "left out at the first state"},
        "to": {"type": "string"},
        "transition": {"type": "string", "description": "left out at the first state"},
        "declared": {
            "type": "string",
            "description": "the transition as the spec declares it, `*,to` for a `* -> to` line; left out when "
            "it is `transition`",
        },
    },
    "required": ["to"],
}
_BEHAVIOUR_SCHEMA = {
    "type": "object",
    "title": "earl.BehaviourEvent",
    "properties": {
        "event": {"type": "string", "enum": ["start", "stop"]},
        "state": {"type": "string"},
        "behaviour": {"type": "string"},
        "iterations": {"type": "integer"},
        "reason": {"type": "string"},
    },
    "required": ["event", "state", "behaviour"],
}
_FAULT_SCHEMA = {
    "type": "object",
    "title": "earl.Fault",
    "properties": {
        name: {"type": "string"}
        for name in ("subsystem", "kind", "message", "state", "behaviour", "function", "traceback")
    },
}
#: the start message's settings and the end message's counts; `parameters` (the values given with
#: --param, by name) has no fixed fields, so it is left out, as a field of no fixed type must be
_RUN_SCHEMA = {
    "type": "object",
    "title": "earl.Run",
    "properties": {
        "event": {"type": "string", "enum": ["start", "end"]},
        "format": {"type": "integer", "description": "the trace format, at the start (none: format 1)"},
        "earl": {"type": "string"},
        "system": {"type": "string"},
        "seed": {"type": "integer"},
        "realtime": {"type": "boolean"},
        "faults": {"type": "integer"},
        "iterations": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {"subsystem": {"type": "string"}, "iterations": {"type": "integer"}},
            },
        },
    },
    "required": ["event"],
}

#: a member of a memory family, as the runtime keys it: `windingCurrent[3]`
_MEMBER = re.compile(r"(\w+)\[(\d+)\]\Z")


class MemoryLayout:
    """How a subsystem's memory is written: each memory under its name, and a family as one array
    with member K at index K (null before the family's first index), so that its members are
    `windingCurrent[1]` … in Foxglove as in the spec. The runtime keys a member `windingCurrent[1]`,
    which no message path can name (a field is letters, digits and `_`)."""

    def __init__(self, types: TypeSystem, memory_types: dict[str, DataType]) -> None:
        families: dict[str, dict[int, str]] = {}
        #: each field with whether it is a family, in declaration order
        order: list[tuple[str, bool]] = []
        #: each field's schema (a family's: its members'), None for one Foxglove cannot be told
        schemas: dict[str, dict[str, Any] | None] = {}
        for key, data_type in memory_types.items():
            member = _MEMBER.match(key)
            if member is None:
                order.append((key, False))
                schemas[key] = json_schema(types, data_type)
                continue
            name, index = member.group(1), int(member.group(2))
            if name not in families:
                families[name] = {}
                order.append((name, True))
                schemas[name] = json_schema(types, data_type)
            families[name][index] = key
        self.plan: list[tuple[str, str | list[str | None]]] = []
        self.properties: dict[str, Any] = {}
        #: the memories (not families) in the messages but not in the schema (`grid/m: double[2][2]`), for
        #: the channel's metadata: earl plot lists a subsystem's values from the schema and the metadata
        self.unschemed: list[str] = []
        for name, family in order:
            schema = schemas[name]
            if family:
                members = families[name]
                first, last = min(members), max(members)
                self.plan.append((name, [members.get(index) for index in range(last + 1)]))
                if schema is not None and schema["type"] != "array":
                    schema = {"type": "array", "items": schema, "minItems": last + 1, "maxItems": last + 1}
                    if first:
                        # standard JSON Schema for "the first items are null": earl's reader skips them
                        schema["prefixItems"] = [{"type": "null"}] * first
                else:
                    # a family of arrays is an array of arrays, which no message path indexes and
                    # Foxglove refuses in a schema, with the whole channel: in the messages only
                    schema = None
            else:
                self.plan.append((name, name))
            if schema is not None:
                self.properties[name] = schema
            elif not family:
                self.unschemed.append(name)
        self.has_families = any(isinstance(source, list) for _, source in self.plan)
        #: each family with its first index, for the channel's metadata (`{"windingCurrent": 1}`)
        self.families = {name: min(members) for name, members in families.items()}

    def snapshot(self, memory: dict[str, Any]) -> dict[str, Any]:
        """The message for `memory`: a copy, since the engine goes on changing its memory."""
        if not self.has_families:
            return dict(memory)
        return {
            name: memory.get(source)
            if isinstance(source, str)
            else [None if key is None else memory.get(key) for key in source]
            for name, source in self.plan
        }


#: one encoder for the whole run: `json.dumps` with these options would build one per message
_ENCODER = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=False, check_circular=False)


def _refuse(value: object) -> NoReturn:
    raise TypeError(f"{type(value).__name__} is not JSON")


def _c_encoder() -> Callable[[Any], str]:
    """`_ENCODER.encode`, without making a new C encoder at each call as `JSONEncoder.encode` does.

    The trace's process encodes every message of the run: a third of the time of encoding a small
    message went to that set-up. Python without its C accelerator gets the plain encoder.
    """
    make = getattr(json.encoder, "c_make_encoder", None)
    if make is None:
        return _ENCODER.encode
    # markers, default, encoder, indent, key and item separators, sort_keys, skipkeys, allow_nan
    chunks = make(None, _refuse, json.encoder.encode_basestring, None, ":", ",", False, False, False)
    return lambda value: "".join(chunks(value, 0))


_to_json_text = _c_encoder()


def _encode(value: Any) -> bytes:
    """A run-time value (or a dict of them) as JSON, every message valid against its channel's schema.

    Run-time values are JSON as they are (tuples become arrays, Records objects), except for three
    things: an absent optional field (None), left out of its object, as the schema leaves it out of
    `required`; bytes, a list of numbers; and an infinite real, which JSON has no word for: written
    `1e999` or `-1e999`, a number beyond every double, which JSON readers read as infinity. The
    last two make the encoder raise, and only then is the value walked in Python (`_json_data`). A
    message is written for every send (and a memory snapshot for every iteration), so the common
    case must not walk the value: an absent field is taken out of the text, where `null` is found.
    """
    try:
        text = _to_json_text(value)
    except (TypeError, ValueError):  # UnicodeEncodeError too: a lone surrogate is written as JSON's `\udcff`
        text = _text_of(_json_data(value))
    else:
        if "null" in text:  # in an array, a null stays: the elements before a memory family's first member
            text = _FIRST_ABSENT.sub("{", _LATER_ABSENT.sub("", text))
    return text.encode("utf-8", "backslashreplace")


# A field written `"name":null` after `{` or `,`, before `,` or `}`. Inside a string every `"` is written
# `\"`, so neither pattern matches in one. Every field but the first of its object goes with the comma
# before it; then a first field, with the comma after it (no absent field follows it any more).
_LATER_ABSENT = re.compile(r',"\w+":null(?=[,}])')
_FIRST_ABSENT = re.compile(r'\{"\w+":null(?:,|(?=\}))')


def _json_data(value: Any) -> Any:
    """`value` as plain JSON data: an object without its None fields (absent optional fields), bytes as
    a list of numbers; None in an array stays null (the elements before a memory family's first member)."""
    if isinstance(value, dict):
        return {key: _json_data(inner) for key, inner in dict.items(value) if inner is not None}
    if isinstance(value, (list, tuple)):
        return [_json_data(inner) for inner in value]
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    return value


def _text_of(data: Any) -> str:
    """JSON text of plain data, an infinite real as `1e999` or `-1e999` (Python's `json` refuses it)."""
    try:
        return _to_json_text(data)
    except ValueError:
        pass
    if isinstance(data, float) and not math.isfinite(data):
        return "null" if math.isnan(data) else ("1e999" if data > 0 else "-1e999")
    if isinstance(data, dict):
        return "{" + ",".join(f"{_to_json_text(str(key))}:{_text_of(inner)}" for key, inner in data.items()) + "}"
    if isinstance(data, list):
        return "[" + ",".join(_text_of(inner) for inner in data) + "]"
    return _to_json_text(data)


class McapSink:
    """Writes what a TraceWriter decides into an MCAP file: channels, then messages as JSON.

    The file is written by Foxglove's own SDK (`foxglove-sdk`), whose MCAP writer is Rust: it
    takes a message in a third of the time the pure-Python `mcap` writer needs, and a run
    writes tens of thousands a second. Each channel numbers its messages from 1 (the
    sequence); the publish time is the log time, the run time of the message.

    A channel registered with `wrap` carries a link's values: those that are not structs are
    written as `{"value": ...}`, since Foxglove's JSON messages are objects.
    """

    def __init__(self, stream: IO[bytes]) -> None:
        import foxglove
        from foxglove.mcap import MCAPWriteOptions

        self._foxglove = foxglove
        self.output = _Output(stream)
        # a context of its own: channels made here reach this file only, whatever else the process logs
        self._context = foxglove.Context()
        # no compression threads: the run's own process needs the other core
        options = MCAPWriteOptions(compression_threads=0, profile="")
        self._writer = foxglove.open_mcap(self.output, context=self._context, writer_options=options)
        #: the TraceWriter's channel numbers -> the SDK's channels
        self._channels: dict[int, Any] = {}
        self._wrapped: set[int] = set()

    def channel(
        self,
        number: int,
        topic: str,
        schema_name: str,
        schema: dict[str, Any],
        metadata: dict[str, str],
        wrap: bool = False,
    ) -> None:
        foxglove = self._foxglove
        self._channels[number] = foxglove.Channel(
            topic,
            message_encoding="json",
            schema=foxglove.Schema(name=schema_name, encoding="jsonschema", data=_encode(schema)),
            metadata=metadata,
            context=self._context,
        )
        if wrap:
            self._wrapped.add(number)

    def message(self, channel: int, time: int, value: Any) -> None:
        if channel in self._wrapped and not isinstance(value, dict):
            value = {"value": value}
        self._channels[channel].log(_encode(value), log_time=time)

    def writer_of(self, register: Callable[[], int]) -> MessageWriter:
        """`message` for one channel, which `register()` registers at the first message and numbers."""
        channel = 0

        def write(time: int, value: Any) -> None:
            nonlocal channel
            if not channel:
                channel = register()
            self.message(channel, time, value)

        return write

    def finish(self) -> None:
        try:
            self._writer.close()
        except RuntimeError as error:  # the SDK's words for a write that failed earlier; the output has the reason
            self.output.raise_error()
            raise OSError(str(error)) from None
        self.output.raise_error()


class _Output:
    """The stream the SDK writes to, keeping the first error a write met.

    The SDK turns a failed write into a log line and refuses every later one; the file's
    own error (`No space left on device`) is what a user needs to read, so it is kept here
    and raised by `raise_error`.
    """

    def __init__(self, stream: IO[bytes]) -> None:
        self.stream = stream
        self.error: OSError | None = None

    def _kept(self, error: OSError) -> OSError:
        if self.error is None:
            self.error = error
        return error

    def write(self, data: bytes | bytearray) -> int:
        try:
            return self.stream.write(data)
        except OSError as error:
            raise self._kept(error) from None

    def seek(self, offset: int, whence: int = 0) -> int:
        try:
            return self.stream.seek(offset, whence)
        except OSError as error:
            raise self._kept(error) from None

    def flush(self) -> None:
        try:
            self.stream.flush()
        except OSError as error:
            raise self._kept(error) from None

    def raise_error(self) -> None:
        if self.error is not None:
            raise self.error


class TraceWriter(Recorder):
    """Writes the events of a run to an MCAP file."""

    def __init__(
        self,
        output: str | Path | IO[bytes],
        types: TypeSystem,
        link_types: dict[str, DataType],
        memory_types: dict[str, dict[str, DataType]],
        links: list[str] | None = None,
        link_sources: dict[str, str] | None = None,
        link_index_variables: dict[str, frozenset[str]] | None = None,
        output_types: dict[str, dict[str, DataType]] | None = None,
    ) -> None:
        self._sink: McapSink | BackgroundSink
        if isinstance(output, (str, Path)):
            self._sink = BackgroundSink(Path(output))
        else:
            self._sink = McapSink(output)
        self.types = types
        self.link_types = link_types
        self.memory_types = memory_types
        self.link_patterns = links
        self.link_sources = link_sources or {}
        #: link -> its families' index variables: what `[K]` in a link pattern names
        self.link_index_variables = link_index_variables or {}
        #: subsystem -> every output buffer it declares (`push[1]`, `push[2]`, `beltSpeed`), for its FSM
        #: channel's metadata: a link's channel is made at its first message, so the trace alone could not
        #: tell a member of a family that never sent from one the family does not have (earl plot). Not
        #: the buffers links leave: a run of some agents (`--agents`) has no link to the others' members
        self._outputs = {subsystem: sorted(buffers) for subsystem, buffers in (output_types or {}).items()}
        #: links recorded whatever the patterns say: those leaving an output buffer a plot draws
        self.links_also_recorded: set[str] = set()
        #: topic -> channel number; None for a link that is not recorded
        self._channels: dict[str, int | None] = {}
        #: link -> channel number or None, the same as `_channels` without making the topic's name
        self._links: dict[str, int | None] = {}
        #: subsystem -> its memory's channel and layout
        self._memories: dict[str, tuple[int, MemoryLayout]] = {}
        self.closed = False

    # ------------------------------------------------------------------ plumbing
    def _channel(
        self, topic: str, schema_name: str, schema: dict[str, Any], metadata: dict[str, str], wrap: bool = False
    ) -> int:
        found = self._channels.get(topic)
        if found is None:
            found = self._channels[topic] = len(self._channels) + 1
            self._sink.channel(found, topic, schema_name, schema, metadata, wrap)
        return found

    def _write(self, channel: int, time: int, message: Any) -> None:
        self._sink.message(channel, time, message)

    # ------------------------------------------------------------------ events
    def run_started(self, settings: dict[str, Any]) -> None:
        # the file's header names the SDK that wrote it; which earl ran is said here
        start = {"event": "start", "format": trace_topics.FORMAT, "earl": __version__, **settings}
        self._write(self._channel(trace_topics.RUN, "earl.Run", _RUN_SCHEMA, {}), 0, start)

    def state_changed(
        self, time: int, subsystem: str, source: str | None, destination: str, transition: str | None
    ) -> None:
        metadata = {"subsystem": subsystem}
        if self._outputs.get(subsystem):
            metadata["outputs"] = json.dumps(self._outputs[subsystem], separators=(",", ":"))
        channel = self._channel(trace_topics.fsm(subsystem), "earl.StateChange", _STATE_SCHEMA, metadata)
        change = {"from": source, "to": destination, "transition": None if transition is None else str(transition)}
        declared = getattr(transition, "declared", transition)
        if declared != transition:  # `*,to`: which line was taken, when two name the same move
            change["declared"] = str(declared)
        self._write(channel, time, change)

    def behaviour_started(self, time: int, subsystem: str, state: str, behaviour: str) -> None:
        channel = self._channel(
            trace_topics.behaviour(subsystem), "earl.BehaviourEvent", _BEHAVIOUR_SCHEMA, {"subsystem": subsystem}
        )
        self._write(channel, time, {"event": "start", "state": state, "behaviour": behaviour})

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        channel = self._channel(
            trace_topics.behaviour(subsystem), "earl.BehaviourEvent", _BEHAVIOUR_SCHEMA, {"subsystem": subsystem}
        )
        self._write(
            channel,
            time,
            {"event": "stop", "state": state, "behaviour": behaviour, "iterations": iterations, "reason": reason},
        )

    def message_sent(self, time: int, link: str, value: Any) -> None:
        channel = self._link(link)
        if channel is not None:
            self._write(channel, time, value)

    def message_writer(self, link: str) -> MessageWriter | None:
        """The sink's own writer for the link's channel, or None if the link is not recorded.

        The channel is registered at the link's first message, as with `message_sent`, so that
        the file is the same whichever way its messages came."""
        if self._links.get(link, -1) is None or not self._recorded(link):
            return None

        def register() -> int:
            channel = self._link(link)
            assert channel is not None  # a recorded link has a channel
            return channel

        return self._sink.writer_of(register)

    def idle(self, seconds: float) -> None:
        if isinstance(self._sink, BackgroundSink) and not self.closed:
            self._sink.idle(seconds)

    def _recorded(self, link: str) -> bool:
        return (
            self.link_patterns is None
            or link in self.links_also_recorded
            or any(
                link_patterns.matches(p, link, self.link_index_variables.get(link, frozenset()))
                for p in self.link_patterns
            )
        )

    def _link(self, link: str) -> int | None:
        channel = self._links.get(link, -1)
        if channel == -1:
            channel = self._links[link] = self._link_channel(link)
        return channel

    def _link_channel(self, link: str) -> int | None:
        topic = trace_topics.link(link)
        if not self._recorded(link):
            self._channels[topic] = None
            return None
        data_type = self.link_types.get(link)
        schema: dict[str, Any] = {"type": "object", "properties": {}}
        name = "earl.Message"
        if data_type is not None:
            inner = json_schema(self.types, data_type)
            if inner is not None and inner["type"] == "object":
                schema, name = inner, str(inner.get("title", name))
            else:
                value = {} if inner is None else {"value": inner}
                schema = {"type": "object", "properties": value, "required": list(value)}
                name = f"earl.{type(data_type).__name__}.{json.dumps(inner, sort_keys=True)}"
        metadata = {"link": link, "source": self.link_sources.get(link, "")}
        return self._channel(topic, name, schema, metadata, wrap=True)

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        found = self._memories.get(subsystem)
        if found is None:
            layout = MemoryLayout(self.types, self.memory_types.get(subsystem, {}))
            schema = {
                "type": "object",
                "title": f"{subsystem}.m",
                "properties": layout.properties,
                "required": list(layout.properties),
            }
            metadata = {"subsystem": subsystem}
            if layout.families:
                # a family is an array as an array is: the schema cannot say which fields are families
                metadata["families"] = json.dumps(layout.families, separators=(",", ":"))
            if layout.unschemed:
                # an array of arrays, or a struct inside itself: no schema Foxglove takes says it is there
                metadata["unschemed"] = json.dumps(layout.unschemed, separators=(",", ":"))
            channel = self._channel(trace_topics.memory(subsystem), f"earl.Memory.{subsystem}", schema, metadata)
            found = self._memories[subsystem] = (channel, layout)
        channel, layout = found
        self._write(channel, time, layout.snapshot(memory))

    def fault(self, fault: Fault) -> None:
        channel = self._channel(trace_topics.FAULTS, "earl.Fault", _FAULT_SCHEMA, {})
        self._write(
            channel,
            fault.time_ns,
            {
                "subsystem": fault.subsystem,
                "kind": fault.kind,
                "message": fault.message,
                "state": fault.state,
                "behaviour": fault.behaviour,
                "function": fault.function,
                "traceback": fault.traceback,
            },
        )

    def close(self, end_time: int, summary: dict[str, Any] | None = None) -> None:
        """Finish the file (also after Ctrl-C, so that it stays readable)."""
        if self.closed:
            return
        self.closed = True
        end: dict[str, Any] = {"event": "end", **(summary or {})}
        if isinstance(end.get("iterations"), dict):
            # a list, not an object keyed by subsystem: `manip/a.cs` is no name a message path can take
            end["iterations"] = [{"subsystem": name, "iterations": count} for name, count in end["iterations"].items()]
        self._write(self._channel(trace_topics.RUN, "earl.Run", _RUN_SCHEMA, {}), end_time, end)
        self._sink.finish()

    def abandon(self) -> None:
        """The run did not start: no file is left (a stream given is left as it is)."""
        if self.closed:
            return
        self.closed = True
        if isinstance(self._sink, BackgroundSink):
            self._sink.abandon()


class TraceWriteError(OSError):
    """The trace file could not be written (a full disk, a removed directory): the message says why."""


#: the first bytes of every MCAP file
MCAP_MAGIC = b"\x89MCAP0\r\n"


def refuse_to_replace(path: Path) -> None:
    """A trace replaces an earlier trace or an empty file, never other data: `--trace system.earl`,
    a slip of the keyboard, must not destroy the spec."""
    try:
        if not path.is_file() or path.stat().st_size == 0:
            return
        with open(path, "rb") as existing:
            head = existing.read(len(MCAP_MAGIC))
    except OSError:
        return  # what cannot be read is reported when it is written
    if head != MCAP_MAGIC:
        raise TraceWriteError(
            "the file exists and is not an MCAP trace, and only an earlier trace is replaced "
            "(choose another name, or remove the file first)"
        )


class BackgroundSink:
    """A McapSink in a second process (`python -m earl.runtime.trace_process FILE`), fed in batches.

    The file is created here first, so that a path that cannot be written fails at once, in
    the caller. A batch travels as msgpack: it packs Records as maps and Reals as arrays in C,
    as the plain values they are in JSON, where pickle would call back into Python for each
    (their classes are made at run time, so the writer could not find them by name anyway).
    If this process ends without `finish` (killed), the writer sees its input end and
    finishes the file, which therefore stays readable (a writer sent nothing leaves the file alone).
    """

    #: messages per batch: large enough to make the hand-over cheap, small enough to stay in flight
    BATCH = 2048
    #: a batch goes at the latest this long after the previous one (s): a run in real time sends
    #: few messages, and a run that is killed loses at most this much of its trace
    LATEST = 0.2
    #: how long `finish` waits for the writer (s): it has a batch or two to write, unless the disk hangs
    FINISH_TIMEOUT = 120.0

    def __init__(self, path: Path) -> None:
        self.path = path
        refuse_to_replace(path)
        #: whether this sink made the file, which `abandon` then removes
        self._created = not os.path.lexists(path)
        self._finished = False
        open(path, "wb").close()  # only to fail now if the file cannot be written
        # the writer imports earl from where this process found it, installed or not
        package_root = str(Path(__file__).resolve().parents[2])
        search_path = os.pathsep.join(p for p in (package_root, os.environ.get("PYTHONPATH", "")) if p)
        try:
            self._process = subprocess.Popen(
                # -P: the current directory is not searched first, so that a spec's `msgpack.py` cannot stand in
                [sys.executable, "-P", "-m", "earl.runtime.trace_process", str(path)],
                stdin=subprocess.PIPE,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                env={**os.environ, "PYTHONPATH": search_path},
                # A session of its own: a stop signal for the run's process group or session (Ctrl-C,
                # `timeout`, `earl launch`'s SIGKILL) never reaches it, not even while it starts and has not
                # yet set its signals aside. It ends when the run says so, or when the pipe closes. (Ctrl-C
                # inside Popen, once the writer is started, leaves it unknown here: it then ends when its
                # input does, without a word, having been sent nothing.)
                start_new_session=True,
            )
            _widen(self._process.stdin)
            self._due = _clock() + self.LATEST
            self._packer = msgpack.Packer(use_bin_type=True, default=_plain)
            self._start_batch()
        except BaseException:
            self.abandon()
            raise

    def abandon(self) -> None:
        """The run will not start (Ctrl-C while it is set up): stop the writer and wait for it, and remove
        the file this sink made, which holds no run. Left to itself, the writer would see its input end and
        write an empty trace, after `earl run` had removed the file and said that it wrote none."""
        self._finished = True
        process: subprocess.Popen[bytes] | None = getattr(self, "_process", None)  # None: it was not started
        if process is not None:
            process.kill()  # it has set the stop signals aside
            for pipe in (process.stdin, process.stderr):
                if pipe is not None:
                    with contextlib.suppress(OSError):
                        pipe.close()
            process.wait()
        with contextlib.suppress(OSError):
            if self._created:
                self.path.unlink()
            elif self.path.is_file():
                open(self.path, "wb").close()  # what the writer began is no trace: emptied, as it was opened

    def _start_batch(self) -> None:
        # Three lists, not a tuple per message: appending what exists allocates nothing that Python's
        # collector tracks, where thousands of new tuples a second would make it run hundreds of times.
        # They are emptied in place after each batch, so that the writers keep their `append`s.
        self._numbers: list[int] = []
        self._times: list[int] = []
        self._values: list[Any] = []
        self._channels: list[tuple[Any, ...]] = []

    def channel(
        self,
        number: int,
        topic: str,
        schema_name: str,
        schema: dict[str, Any],
        metadata: dict[str, str],
        wrap: bool = False,
    ) -> None:
        # with the number of messages before it in the batch: the writer keeps the order exactly
        self._channels.append((len(self._values), number, topic, schema_name, schema, metadata, wrap))

    def message(self, channel: int, time: int, value: Any) -> None:
        self._numbers.append(channel)
        self._times.append(time)
        self._values.append(value)
        if len(self._values) >= self.BATCH or _clock() >= self._due:
            self._batch_done()

    def idle(self, seconds: float) -> None:
        """The run waits `seconds`: send what the batch holds if it is due, or would be before the run
        wakes. A batch went only with the next message after it was due, so a run that recorded nothing
        more (a subsystem holding a state) kept seconds of its trace here, lost when it was killed."""
        if (self._values or self._channels) and _clock() + seconds >= self._due:
            self._batch_done()

    def _batch_done(self) -> None:
        """The batch is full or due: it goes to the writer, or is dropped once the writer has failed
        (which was said then)."""
        if self._finished:
            self._numbers.clear()
            self._times.clear()
            self._values.clear()
            return
        self._send()

    def writer_of(self, register: Callable[[], int]) -> MessageWriter:
        """`message` for one channel, which `register()` registers at the first message and numbers: a
        closure over the batch's lists, since it is the path of every message of a link."""
        numbers, times, values = self._numbers.append, self._times.append, self._values.append
        batch = self._values
        limit = self.BATCH
        channel = 0

        def write(time: int, value: Any) -> None:
            nonlocal channel
            if not channel:
                channel = register()
            numbers(channel)
            times(time)
            values(value)
            if len(batch) >= limit or _clock() >= self._due:
                self._batch_done()

        return write

    def _send(self, finish: bool = False) -> None:
        batch = (self._channels, self._numbers, self._times, self._values, finish)
        try:
            data = self._packer.pack(batch)
        except (UnicodeEncodeError, OverflowError, TypeError, ValueError):
            # Text that is not UTF-8 (a lone surrogate in an exception's message, say) or an int beyond
            # 64 bits, which the type checks keep out of values but not out of what the spec's code
            # says: recorded as near as can be, rather than losing the batch and the trace with it.
            data = msgpack.packb(_packable(batch), use_bin_type=True, default=_plain)
        self._numbers.clear()
        self._times.clear()
        self._values.clear()
        self._channels = []
        self._due = _clock() + self.LATEST
        stdin = self._process.stdin
        assert stdin is not None
        try:
            stdin.write(_LENGTH.pack(len(data)))
            stdin.write(data)
            # now, not when Python's 8 KiB buffer fills: what is still in this process dies with it (SIGKILL)
            stdin.flush()
        except (BrokenPipeError, OSError):
            del data
            self._fail()

    def finish(self) -> None:
        """Send what is left, and wait until the file is complete."""
        if self._finished:
            return
        self._finished = True
        self._send(finish=True)
        stdin = self._process.stdin
        assert stdin is not None
        with contextlib.suppress(OSError):  # a writer that failed has closed its end: said below
            stdin.close()
        said = self._read_until_exit()
        status = self._process.wait()
        self._close_stderr()
        if status != 0:
            self._fail(said)

    def _close_stderr(self) -> None:
        """The writer's standard error, read to its end: closed, not left to the collector (which says
        ResourceWarning under `python -X dev`)."""
        stderr = self._process.stderr
        if stderr is not None:
            with contextlib.suppress(OSError):
                stderr.close()

    def _read_until_exit(self) -> bytes:
        """What the writer says on standard error until it exits (its end of the pipe closes then).

        Waiting on the pipe wakes up the moment the writer ends; `Popen.wait` with a timeout
        polls with sleeps of up to 50 ms instead, which every run would wait out at its end.
        """
        stderr = self._process.stderr
        assert stderr is not None
        descriptor = stderr.fileno()
        deadline = _clock() + self.FINISH_TIMEOUT
        said: list[bytes] = []
        while True:
            remaining = deadline - _clock()
            if remaining <= 0 or not select.select([descriptor], [], [], remaining)[0]:
                self._process.kill()
                self._process.wait()
                self._close_stderr()
                raise TraceWriteError(
                    f"cannot write the trace {self.path}: its writer did not finish within {self.FINISH_TIMEOUT:g} s"
                )
            chunk = os.read(descriptor, 65536)
            if not chunk:
                return b"".join(said)
            said.append(chunk)

    def _fail(self, said: bytes | None = None) -> NoReturn:
        """Raise what went wrong in the writer: `said` is its standard error, if already read."""
        self._finished = True
        process = self._process
        if process.stdin is not None:
            with contextlib.suppress(OSError):
                process.stdin.close()
        if said is None:
            said = self._read_until_exit()
        process.wait()
        self._close_stderr()
        text = said.decode("utf-8", "replace").strip()
        why = text.splitlines()[-1] if text else ""  # the last line: the error itself, never a traceback
        raise TraceWriteError(
            f"cannot write the trace {self.path}: {why or f'its writer stopped (exit code {process.returncode})'}"
        )


def _widen(pipe: IO[bytes] | None) -> None:
    """Let the pipe to the writer hold several batches (Linux; up to the system's limit, 1 MiB by default).

    A batch is about 200 kB and a pipe holds 64 kB: the run would wait at every batch until the
    writer had taken the one before, which the writer does only once it has written that one out.
    """
    set_size = getattr(fcntl, "F_SETPIPE_SZ", None)
    if pipe is None or set_size is None:
        return
    with contextlib.suppress(OSError):  # above the limit for this user: the pipe keeps its size
        fcntl.fcntl(pipe.fileno(), set_size, PIPE_SIZE)


#: bytes the pipe to the trace's writer holds
PIPE_SIZE = 1 << 20
#: the length of each batch, before it
_LENGTH = struct.Struct("<Q")
_clock = time.monotonic


def _packable(value: Any) -> Any:
    """`value` with text that UTF-8 cannot carry escaped (`\\udcff`), ints beyond 64 bits as text, and
    what msgpack cannot pack as its `repr`."""
    if isinstance(value, str):
        return value.encode("utf-8", "backslashreplace").decode("utf-8")
    if isinstance(value, bool) or value is None or isinstance(value, float):
        return value
    if isinstance(value, int):
        return value if -(1 << 63) <= value < (1 << 64) else str(value)
    if isinstance(value, dict):
        return {_packable(key): _packable(item) for key, item in dict.items(value)}
    if isinstance(value, (list, tuple)):
        return [_packable(item) for item in value]
    if isinstance(value, bytes):
        return value
    plain = _plain(value)
    return repr(value) if plain is value else _packable(plain)


def _plain(value: Any) -> Any:
    """What msgpack cannot pack by itself, as JSON would have it (a NumPy array a function left in memory)."""
    return to_json(value)
