"""Traces open in Foxglove: every topic can be named in a message path, with the leading `/` of ROS's
and Foxglove's topics, and traces of an earlier earl are still read.

The rules are Foxglove's, written here from its sources, not from earl's code:

- message paths (docs.foxglove.dev/docs/visualization/message-path-syntax; the grammar is
  `packages/studio-base/src/components/MessagePathSyntax/grammar.ne` of foxglove/studio): a topic is
  ids joined by `/` (`/some/topic`, an id being `[a-zA-Z0-9_]+`) or any text in double quotes with `\\"`
  and `\\\\` escaped (`"/foo.bar".baz`); then `.name` steps, a name being an id, each followed by at most
  one index `[N]` ("Nested arrays (arrays of arrays) are not supported by message path syntax").
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap.writer import Writer

from earl.runtime.trace_reader import read_signals

ROOT = Path(__file__).resolve().parents[1]
PICK_AND_PLACE = ROOT / "examples" / "pick_and_place"

# ---------------------------------------------------------------- Foxglove's message path grammar
ID = r"[a-zA-Z0-9_]+"
UNQUOTED_TOPIC = re.compile(rf"(?:/(?:{ID})?)+|{ID}(?:/(?:{ID})?)*")
QUOTED_TOPIC = re.compile(r'"((?:[^"\\]|\\\\|\\")*)"')
STEP = re.compile(rf"\.({ID})(?:\[(-?[0-9]+)\])?")


def quote_topic(topic: str) -> str:
    """The topic as a message path writes it: bare when the grammar's `slashID`s spell it, else quoted."""
    if UNQUOTED_TOPIC.fullmatch(topic):
        return topic
    return '"' + topic.replace("\\", "\\\\").replace('"', '\\"') + '"'


def parse_path(path: str) -> tuple[str, list[tuple[str, int | None]]]:
    """(topic, [(field, index or None)]) of a message path of names and indices; AssertionError if the
    grammar does not take it."""
    quoted = QUOTED_TOPIC.match(path)
    if quoted is not None:
        topic = re.sub(r"\\(.)", r"\1", quoted.group(1))
        rest = path[quoted.end() :]
    else:
        bare = UNQUOTED_TOPIC.match(path)
        assert bare is not None, f"no topic at the start of {path!r}"
        topic, rest = bare.group(0), path[bare.end() :]
    steps: list[tuple[str, int | None]] = []
    while rest:
        step = STEP.match(rest)
        assert step is not None, f"{path!r}: {rest!r} is no `.name[index]` step of a message path"
        steps.append((step.group(1), None if step.group(2) is None else int(step.group(2))))
        rest = rest[step.end() :]
    return topic, steps


def channels_and_messages(path: Path) -> tuple[dict[str, Any], dict[str, list[Any]]]:
    """Each topic's channel (with its schema's text and encodings) and its messages, decoded."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        channels = {}
        for channel in summary.channels.values():
            schema = summary.schemas[channel.schema_id]
            channels[channel.topic] = (channel.message_encoding, schema.encoding, json.loads(schema.data))
        messages: dict[str, list[Any]] = {topic: [] for topic in channels}
        for _, channel, message in reader.iter_messages():
            messages[channel.topic].append(json.loads(message.data))
    return channels, messages


def run_earl(*arguments: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "earl", *map(str, arguments)],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )


def test_every_topic_of_the_flagship_trace_starts_with_a_slash_and_is_a_message_path_topic(tmp_path: Path) -> None:
    """A trace of the pick-and-place system with all memory and all links recorded: only `/earl/run` and
    `/earl/faults` had the leading `/` of ROS's and Foxglove's topics (`manip/a.cs/fsm`, `link/task,manip`);
    every topic has it now, and each is the topic of a message path (quoted where it has a `.`)."""
    trace = tmp_path / "run.mcap"
    ran = run_earl("run", PICK_AND_PLACE, "--duration", "0.3s", "--trace", trace, "--record-memory", "all")
    assert ran.returncode == 0, ran.stderr
    channels, messages = channels_and_messages(trace)
    assert {"/earl/run", "/manip/a.cs/memory", "/manip/a.cs/fsm", "/link/task,manip"} <= set(channels)
    for topic in channels:
        assert topic.startswith("/"), topic
        assert parse_path(quote_topic(topic)) == (topic, []), topic
        assert messages[topic], f"{topic} has no message"
    assert parse_path('"/manip/a.cs/memory".currentJointPos[2]') == ("/manip/a.cs/memory", [("currentJointPos", 2)])
    summary = run_earl("trace", "summary", trace)
    assert summary.returncode == 0 and "manip/a.motorController[1]/ve" in summary.stdout, summary.stderr
    [series] = read_signals(trace, ["manip/a.cs.currentJointPos[1]"]).series
    assert len(series.values) == len(messages["/manip/a.cs/memory"])


def write_earlier_trace(path: Path) -> None:
    """A trace as earl wrote them before its topics had a leading slash: `s/a.cs/fsm`, a memory family's
    members as keys `level[1]`, and the end's iteration counts keyed by subsystem."""
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        run_schema = writer.register_schema("earl.Run", "jsonschema", b'{"type": "object", "title": "earl.Run"}')
        run = writer.register_channel("/earl/run", "json", run_schema, {})
        fsm_schema = writer.register_schema("earl.StateChange", "jsonschema", b'{"type": "object"}')
        fsm = writer.register_channel("s/a.cs/fsm", "json", fsm_schema, {"subsystem": "s/a.cs"})
        memory = {"type": "object", "properties": {"level[1]": {"type": "number"}, "level[2]": {"type": "number"}}}
        memory_schema = writer.register_schema("earl.Memory.s/a.cs", "jsonschema", json.dumps(memory).encode())
        snapshots = writer.register_channel("s/a.cs/memory", "json", memory_schema, {"subsystem": "s/a.cs"})

        def add(channel: int, time: int, data: Any) -> None:
            writer.add_message(channel, time, json.dumps(data).encode(), time)

        add(run, 0, {"event": "start", "earl": "0.1.0", "system": "s", "seed": 0, "parameters": {}})
        add(fsm, 0, {"from": None, "to": "idle", "transition": None})
        for step in range(1, 4):
            add(snapshots, step * 10_000_000, {"level[1]": float(step), "level[2]": -float(step)})
        add(fsm, 20_000_000, {"from": "idle", "to": "busy", "transition": "idle,busy"})
        add(run, 40_000_000, {"event": "end", "faults": 0, "iterations": {"s/a.cs": 4}})
        writer.finish()


def test_a_trace_of_an_earlier_earl_is_read_as_before(tmp_path: Path) -> None:
    """Topics without the leading slash, family members as keys `level[1]` and iteration counts keyed by
    subsystem: `earl trace summary` and `earl plot` read such a trace as they did."""
    trace = tmp_path / "old.mcap"
    write_earlier_trace(trace)
    summary = run_earl("trace", "summary", trace)
    assert summary.returncode == 0, summary.stderr
    row = next(line for line in summary.stdout.splitlines() if "s/a.cs" in line)
    assert "idle,busy ×1" in row and " 4 " in row, summary.stdout
    signals = read_signals(trace, ["s/a.cs.level[*]"])
    found = [(series.name, series.values) for series in signals.series]
    assert found == [("level[1]", [1.0, 2.0, 3.0]), ("level[2]", [-1.0, -2.0, -3.0])]
    plot = run_earl("plot", trace, "--signal", "s/a.cs.level[1]", "-o", tmp_path / "old.png")
    assert plot.returncode == 0 and (tmp_path / "old.png").stat().st_size > 0, plot.stderr
