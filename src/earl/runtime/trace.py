"""The trace of a run: an MCAP file that Foxglove opens (JSON messages with JSON schemas).

Topics (one channel each; log time = run time in ns):

    SUBSYSTEM/fsm        a state change   {"from", "to", "transition"}
    SUBSYSTEM/behaviour  a behaviour starts or stops {"event", "state", "behaviour", "iterations", "reason"}
    SUBSYSTEM/memory     a memory snapshot after an iteration (only for subsystems asked for)
    link/LINK            every message sent on a link (or those chosen); a struct as itself,
                         any other value as {"value": ...}
    /earl/faults         faults, with the traceback of a failing function
    /earl/run            the run's settings at the start and its end time

A subsystem is named as everywhere else: `manip/a.cs`, `manip/a.motorController[3]/ve`.
The same spec and seed give a byte-identical file: nothing in it depends on the wall clock.
"""

from __future__ import annotations

import json
from fnmatch import fnmatchcase
from pathlib import Path
from typing import IO, Any

from mcap.writer import CompressionType, Writer

from earl import __version__
from earl.model.types import DataType
from earl.runtime.events import Fault, Recorder
from earl.runtime.values import Record, TypeSystem, json_schema, to_json

_STATE_SCHEMA = {
    "type": "object",
    "title": "earl.StateChange",
    "properties": {
        "from": {"type": ["string", "null"]},
        "to": {"type": "string"},
        "transition": {"type": "string"},
    },
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
}
_FAULT_SCHEMA = {
    "type": "object",
    "title": "earl.Fault",
    "properties": {
        name: {"type": "string"}
        for name in ("subsystem", "kind", "message", "state", "behaviour", "function", "traceback")
    },
}
_RUN_SCHEMA = {"type": "object", "title": "earl.Run"}


#: one encoder for the whole run: `json.dumps` with these options would build one per message
_ENCODER = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=False, check_circular=False)


def _encode(value: Any) -> bytes:
    """A run-time value (or a dict of them) as JSON.

    Run-time values are JSON as they are (tuples become arrays, Records objects), except
    bytes and infinite floats: those two make the encoder raise, and only then is the
    value converted by `to_json`. A message is written for every send, so the common case
    must not walk the value in Python first.
    """
    try:
        return _ENCODER.encode(value).encode()
    except (TypeError, ValueError):
        return _ENCODER.encode(to_json(value)).encode()


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
    ) -> None:
        self._file: IO[bytes] | None = None
        if isinstance(output, (str, Path)):
            self._file = open(output, "wb")  # noqa: SIM115 — closed in close()
            stream: IO[bytes] = self._file
        else:
            stream = output
        self.writer = Writer(stream, compression=CompressionType.ZSTD)
        self.writer.start(profile="", library=f"earl {__version__}")
        self.types = types
        self.link_types = link_types
        self.memory_types = memory_types
        self.link_patterns = links
        self.link_sources = link_sources or {}
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int | None] = {}
        self._sequence = 0
        self.closed = False

    # ------------------------------------------------------------------ plumbing
    def _schema(self, name: str, schema: dict[str, Any]) -> int:
        found = self._schemas.get(name)
        if found is None:
            found = self._schemas[name] = self.writer.register_schema(
                name=name, encoding="jsonschema", data=_encode(schema)
            )
        return found

    def _channel(self, topic: str, schema_name: str, schema: dict[str, Any], metadata: dict[str, str]) -> int:
        found = self._channels.get(topic)
        if found is None:
            found = self._channels[topic] = self.writer.register_channel(
                topic=topic, message_encoding="json", schema_id=self._schema(schema_name, schema), metadata=metadata
            )
        return found

    def _write(self, channel: int, time: int, message: Any) -> None:
        self._sequence += 1
        self.writer.add_message(
            channel, log_time=time, data=_encode(message), publish_time=time, sequence=self._sequence
        )

    # ------------------------------------------------------------------ events
    def run_started(self, settings: dict[str, Any]) -> None:
        self._write(self._channel("/earl/run", "earl.Run", _RUN_SCHEMA, {}), 0, {"event": "start", **settings})

    def state_changed(self, time: int, subsystem: str, source: str | None, destination: str, transition: str) -> None:
        channel = self._channel(f"{subsystem}/fsm", "earl.StateChange", _STATE_SCHEMA, {"subsystem": subsystem})
        self._write(channel, time, {"from": source, "to": destination, "transition": transition})

    def behaviour_started(self, time: int, subsystem: str, state: str, behaviour: str) -> None:
        channel = self._channel(
            f"{subsystem}/behaviour", "earl.BehaviourEvent", _BEHAVIOUR_SCHEMA, {"subsystem": subsystem}
        )
        self._write(channel, time, {"event": "start", "state": state, "behaviour": behaviour})

    def behaviour_stopped(
        self, time: int, subsystem: str, state: str, behaviour: str, iterations: int, reason: str
    ) -> None:
        channel = self._channel(
            f"{subsystem}/behaviour", "earl.BehaviourEvent", _BEHAVIOUR_SCHEMA, {"subsystem": subsystem}
        )
        self._write(
            channel,
            time,
            {"event": "stop", "state": state, "behaviour": behaviour, "iterations": iterations, "reason": reason},
        )

    def message_sent(self, time: int, link: str, value: Any) -> None:
        channel = self._channels.get(f"link/{link}", -1)
        if channel == -1:
            channel = self._link_channel(link)
        if channel is None:
            return
        self._write(channel, time, value if isinstance(value, Record) else {"value": value})

    def _link_channel(self, link: str) -> int | None:
        topic = f"link/{link}"
        if self.link_patterns is not None and not any(fnmatchcase(link, p) for p in self.link_patterns):
            self._channels[topic] = None
            return None
        data_type = self.link_types.get(link)
        schema: dict[str, Any] = {"type": "object"}
        name = "earl.Message"
        if data_type is not None:
            inner = json_schema(self.types, data_type)
            if inner.get("type") == "object":
                schema, name = inner, str(inner.get("title", name))
            else:
                schema = {"type": "object", "properties": {"value": inner}}
                name = f"earl.{type(data_type).__name__}.{json.dumps(inner, sort_keys=True)}"
        return self._channel(topic, name, schema, {"link": link, "source": self.link_sources.get(link, "")})

    def memory_snapshot(self, time: int, subsystem: str, memory: dict[str, Any]) -> None:
        topic = f"{subsystem}/memory"
        channel = self._channels.get(topic)
        if channel is None:
            properties = {key: json_schema(self.types, t) for key, t in self.memory_types.get(subsystem, {}).items()}
            channel = self._channel(
                topic,
                f"earl.Memory.{subsystem}",
                {"type": "object", "title": f"{subsystem}.m", "properties": properties},
                {"subsystem": subsystem},
            )
        self._write(channel, time, memory)

    def fault(self, fault: Fault) -> None:
        channel = self._channel("/earl/faults", "earl.Fault", _FAULT_SCHEMA, {})
        self._write(
            channel,
            fault.time,
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
        self._write(
            self._channel("/earl/run", "earl.Run", _RUN_SCHEMA, {}), end_time, {"event": "end", **(summary or {})}
        )
        self.writer.finish()  # type: ignore[no-untyped-call]
        if self._file is not None:
            self._file.close()
