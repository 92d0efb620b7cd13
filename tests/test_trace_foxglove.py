"""Traces open in Foxglove: every topic and every field of a message can be named in a message path,
and every channel's JSON schema is one Foxglove's reader of JSON channels takes.

The rules are Foxglove's, written here from its sources, not from earl's code:

- message paths (docs.foxglove.dev/docs/visualization/message-path-syntax; the grammar is
  `packages/studio-base/src/components/MessagePathSyntax/grammar.ne` of foxglove/studio): a topic is
  ids joined by `/` (`/some/topic`, an id being `[a-zA-Z0-9_]+`) or any text in double quotes with `\\"`
  and `\\\\` escaped (`"/foo.bar".baz`); then `.name` steps, a name being an id, each followed by at most
  one index `[N]` ("Nested arrays (arrays of arrays) are not supported by message path syntax");
- JSON schemas (`packages/mcap-support/src/parseJsonSchema.ts` of foxglove/studio): the root and every
  object are `"type": "object"` with `properties`; each property has one `type` of boolean, string,
  number, integer, object or array, and an array's `items` one of those but array.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from mcap.reader import make_reader
from mcap.writer import Writer

from earl.runtime import trace_topics
from earl.runtime.trace_reader import TraceError, read_signals, summarise

ROOT = Path(__file__).resolve().parents[1]
PICK_AND_PLACE = ROOT / "examples" / "pick_and_place"
MOBILE_ROBOT = ROOT / "examples" / "mobile_robot"

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


def evaluate(message: Any, steps: list[tuple[str, int | None]]) -> Any:
    """What the path's steps name in a message, as Foxglove's paths go: a field, then an element."""
    value = message
    for name, index in steps:
        value = value[name]
        if index is not None:
            value = value[index]
    return value


def field_paths(value: Any, prefix: str = "") -> list[tuple[str, Any]]:
    """(path, leaf) for every leaf of a message, each step a `.field` with at most one `[index]` after
    it; an AssertionError for a key that is no id or an array directly inside an array."""
    if isinstance(value, dict):
        found = []
        for key, inner in value.items():
            assert re.fullmatch(ID, key), f"field {key!r} after {prefix or 'the topic'} is no name a path can take"
            found.extend(field_paths(inner, f"{prefix}.{key}"))
        return found
    if isinstance(value, list):
        assert not prefix.endswith("]"), f"{prefix} is an array inside an array, which no message path indexes"
        found = []
        for index, inner in enumerate(value):
            found.extend(field_paths(inner, f"{prefix}[{index}]"))
        return found
    return [(prefix, value)]


# ---------------------------------------------------------------- Foxglove's reader of JSON schemas
SCALARS = {"boolean", "string", "number", "integer"}


def assert_foxglove_takes(schema: Any, where: str) -> None:
    assert isinstance(schema, dict) and schema.get("type") == "object", f"{where}: not an object schema"
    properties = schema.get("properties")
    assert isinstance(properties, dict), f"{where}: an object without `properties`"
    for name, field in properties.items():
        here = f"{where}.{name}"
        assert isinstance(field, dict) and "oneOf" not in field and "anyOf" not in field, here
        kind = field.get("type")
        if kind == "object":
            assert_foxglove_takes(field, here)
        elif kind == "array":
            items = field.get("items")
            assert isinstance(items, dict), f"{here}: an array without `items`"
            assert items.get("type") in SCALARS | {"object"}, f"{here}: array items of type {items.get('type')!r}"
            if items.get("type") == "object":
                assert_foxglove_takes(items, f"{here}[]")
        else:
            assert kind in SCALARS, f"{here}: type {kind!r}"


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


def test_every_topic_and_field_of_the_flagship_trace_is_a_foxglove_message_path(tmp_path: Path) -> None:
    """A trace of the pick-and-place system with all memory and all links recorded: every topic starts
    with `/` and is a message path's topic; every leaf of every message is a path of `.field[index]`
    steps that names that leaf; every schema is one Foxglove reads. Memory families (`windingCurrent[K
    in 1..6]`) were keys `windingCurrent[1]` that no path could name: they are arrays, member K at K."""
    trace = tmp_path / "run.mcap"
    ran = run_earl("run", PICK_AND_PLACE, "--duration", "0.3s", "--trace", trace, "--record-memory", "all")
    assert ran.returncode == 0, ran.stderr
    channels, messages = channels_and_messages(trace)
    assert {"/earl/run", "/manip/a.cs/memory", "/manip/a.cs/fsm", "/link/task,manip"} <= set(channels)
    for topic, (message_encoding, schema_encoding, schema) in channels.items():
        assert topic.startswith("/"), topic
        assert (message_encoding, schema_encoding) == ("json", "jsonschema"), topic
        assert parse_path(quote_topic(topic)) == (topic, []), topic
        assert_foxglove_takes(schema, topic)
        assert messages[topic], f"{topic} has no message"
        for message in messages[topic]:
            for path, leaf in field_paths(message):
                named, steps = parse_path(quote_topic(topic) + path)
                assert named == topic and evaluate(message, steps) == leaf, (topic, path)
    # the example of docs/runtime.md: member 1 of the memory family is element 1 in Foxglove
    topic, steps = parse_path('"/manip/a.cs/memory".windingCurrent[1]')
    in_foxglove = [evaluate(message, steps) for message in messages[topic]]
    [series] = read_signals(trace, ["manip/a.cs.windingCurrent[1]"]).series
    assert series.values == in_foxglove and any(value != 0.0 for value in in_foxglove)
    # the end of the run counts each subsystem's iterations in a list, a subsystem's name being no field name
    [end] = [message for message in messages["/earl/run"] if message["event"] == "end"]
    assert {entry["subsystem"] for entry in end["iterations"]} >= {"manip/a.cs", "task/a.cs"}
    summary = run_earl("trace", "summary", trace)
    assert summary.returncode == 0 and "manip/a.motorController[1]/ve" in summary.stdout, summary.stderr


FAMILIES = """\
system families
famRobot/r {
    f/a
}
f/a {
    cs {
        period 10 ms
        fromZero[J in 0..1]/m: double = 1.5 * J
        fromTwo[J in 2..3]/m: double = 1.0 * J
        rows[J in 1..2]/m: double[2] = [1.0, 2.0]
        grid/m: double[2][2] = [[1.0, 2.0], [3.0, 4.0]]
        far/m: double = 1e999
        go/pp = true
        run/bb {
            tf = {}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}
"""


def test_memory_families_are_arrays_indexed_as_the_spec_counts_and_arrays_of_arrays_stay_out_of_the_schema(
    tmp_path: Path,
) -> None:
    """A family from 0 is an array from its first element, one from 2 has two nulls before it (in the
    schema's `prefixItems`), and `earl plot` of `fromTwo[*]` draws members 2 and 3, not the nulls. A
    family of arrays and a `double[2][2]` are arrays of arrays: in the messages, left out of the schema
    (Foxglove refuses a channel whose schema has one), and still plotted by earl."""
    (tmp_path / "system.earl").write_text(FAMILIES)
    trace = tmp_path / "f.mcap"
    ran = run_earl("run", tmp_path, "--duration", "0.05s", "--trace", trace, "--record-memory", "all")
    assert ran.returncode == 0, ran.stderr
    channels, messages = channels_and_messages(trace)
    _, _, schema = channels["/f/a.cs/memory"]
    assert_foxglove_takes(schema, "memory")
    assert set(schema["properties"]) == {"fromZero", "fromTwo", "far"}
    assert schema["properties"]["fromTwo"]["prefixItems"] == [{"type": "null"}] * 2
    last = messages["/f/a.cs/memory"][-1]
    assert last["fromZero"] == [0.0, 1.5] and last["fromTwo"] == [None, None, 2.0, 3.0]
    assert last["rows"] == [None, [1.0, 2.0], [1.0, 2.0]] and last["grid"] == [[1.0, 2.0], [3.0, 4.0]]
    signals = read_signals(trace, ["f/a.cs.fromTwo[*]", "f/a.cs.grid[1][0]", "f/a.cs.rows[2][1]", "f/a.cs.far"])
    assert [series.name for series in signals.series] == ["fromTwo[2]", "fromTwo[3]", "grid[1][0]", "rows[2][1]", "far"]
    assert signals.series[2].values[-1] == 3.0 and signals.series[3].values[-1] == 2.0
    assert not signals.empty  # `far`, an infinite real, had a value: no optional field never sent


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


TREES = """\
system trees

struct Tree {
    label: double
    children: Tree[]
    spare: double?
}

treeRobot/r {
    t/a
    u/a
}

t/a {
    cs {
        period 10 ms
        out/ob: Tree
        send/pf(-> out/ob) = python "trees:send"
        go/pp = true
        run/bb {
            tf = {} then {send/pf}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}

u/a {
    cs {
        period 10 ms
        in/ib: Tree
        go/pp = true
        run/bb {
            tf = {}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}

link t,u: t/a.cs.out -> u/a.cs.in
"""

SEND_TREE = """\
def send(inputs, outputs, context):
    outputs.out = {"label": 1.0, "children": [{"label": 2.0, "children": [], "spare": None}], "spare": 3.0}
"""


def test_a_struct_inside_itself_is_traced_and_its_schema_ends(tmp_path: Path) -> None:
    """`children: Tree[]` of `Tree` (a type may contain itself through a variable array): writing the
    link's schema recursed without end, a RecursionError traceback when the run started. The recursive
    field is left out of the schema, which Foxglove reads; its values are in the messages."""
    (tmp_path / "system.earl").write_text(TREES)
    (tmp_path / "trees.py").write_text(SEND_TREE)
    trace = tmp_path / "t.mcap"
    ran = run_earl("run", tmp_path, "--duration", "0.05s", "--trace", trace)
    assert ran.returncode == 0 and "Traceback" not in ran.stderr, ran.stderr
    channels, messages = channels_and_messages(trace)
    _, _, schema = channels["/link/t,u"]
    assert_foxglove_takes(schema, "/link/t,u")
    assert set(schema["properties"]) == {"label", "spare"} and schema["required"] == ["label"]
    assert messages["/link/t,u"][-1]["children"][0]["label"] == 2.0
    [series] = read_signals(trace, ["t/a.cs.out.children[0].label"]).series
    assert series.values[-1] == 2.0


# ---------------------------------------------------------------- every message fits its channel's schema
def messages_not_fitting_their_schema(path: Path) -> dict[str, str]:
    """Each topic with a message that its channel's JSON schema refuses, as `jsonschema` (the reference
    implementation) says it, with the first such message's first error; each schema is checked to be
    one (`check_schema`) first."""
    validators: dict[str, Any] = {}
    refused: dict[str, str] = {}
    with open(path, "rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages():
            validator = validators.get(channel.topic)
            if validator is None:
                assert schema is not None and schema.encoding == "jsonschema", channel.topic
                document = json.loads(schema.data)
                kind = jsonschema.validators.validator_for(document)
                kind.check_schema(document)
                validator = validators[channel.topic] = kind(document)
            error = next(validator.iter_errors(json.loads(message.data)), None)
            if error is not None and channel.topic not in refused:
                refused[channel.topic] = f"{error.message} at {list(error.absolute_path)}"
    assert validators, f"{path} has no message"
    return refused


def test_every_message_of_the_flagship_trace_is_valid_against_its_channel_s_schema(tmp_path: Path) -> None:
    """19 of 84 topics of this trace had messages their schemas refuse: the first state change's `from`
    and `transition` were null against `"type": "string"`, an absent optional field (`jointPosSetpoint`
    of `/link/task,manip`) null against its type. They are left out of the message, as the schema leaves
    them out of `required`, and `earl plot` still says such a field was never sent."""
    trace = tmp_path / "run.mcap"
    ran = run_earl(
        "run", PICK_AND_PLACE, "--duration", "1s", "--trace", trace, "--record-memory", "all", "--record-links", "*"
    )
    assert ran.returncode == 0, ran.stderr
    assert messages_not_fitting_their_schema(trace) == {}
    channels, messages = channels_and_messages(trace)
    for topic, (_, _, schema) in channels.items():
        assert_foxglove_takes(schema, topic)
    assert messages["/manip/a.cs/fsm"][0] == {"to": "idle"}
    assert all("jointPosSetpoint" not in message for message in messages["/link/task,manip"])
    start = messages["/earl/run"][0]
    assert start["event"] == "start" and start["format"] == trace_topics.FORMAT
    signals = read_signals(trace, ["task/a.cs.manipulatorCommand.jointPosSetpoint[0]", "manip/a.cs.windingCurrent[1]"])
    assert signals.empty == [
        "`task/a.cs.manipulatorCommand.jointPosSetpoint[0]` had no value in this run (an optional field never sent)"
    ]
    # the first state change, without `from` and `transition`, is the entry into the initial state
    manip = summarise(trace).subsystems["manip/a.cs"]
    assert set(manip.transitions) == {"idle,operationalMove"}
    assert manip.state_time["idle"] > 0


def test_every_message_of_a_mobile_robot_trace_is_valid_and_an_infinite_real_is_a_number(tmp_path: Path) -> None:
    """`nearestObstacle`, infinite while nothing is in view, was written null against `"type": "number"`:
    JSON has no infinity, and `1e999`, a number beyond every double, is read as one by JSON readers."""
    trace = tmp_path / "run.mcap"
    ran = run_earl(
        "run", MOBILE_ROBOT, "--duration", "1s", "--trace", trace, "--record-memory", "all", "--record-links", "*"
    )
    assert ran.returncode == 0, ran.stderr
    assert messages_not_fitting_their_schema(trace) == {}
    with open(trace, "rb") as stream:
        texts = [message.data for _, _, message in make_reader(stream).iter_messages(topics=["/link/base,coordinator"])]
    assert any(b'"nearestObstacle":1e999' in text for text in texts)
    assert any(json.loads(text)["nearestObstacle"] == math.inf for text in texts)


INFINITIES = """\
system inf
infRobot/r {
    f/a
}
f/a {
    cs {
        period 10 ms
        grid/m: double[2][2] = [[1e999, 2.0], [3.0, 4.0]]
        rows[J in 1..2]/m: double[2] = [-1e999, 2.0]
        level[J in 0..1]/m: double = 1.0
        go/pp = true
        run/bb {
            tf = {}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}
"""


def test_an_infinite_real_inside_a_part_the_schema_leaves_out_is_a_value(tmp_path: Path) -> None:
    """`rows[1][0]` and `grid[0][0]` (arrays of arrays, in no schema) were null, read as "an optional
    field never sent" (exit 1): an infinite real is written `1e999` now, and is a value, a gap in its line."""
    (tmp_path / "system.earl").write_text(INFINITIES)
    trace = tmp_path / "i.mcap"
    ran = run_earl("run", tmp_path, "--duration", "0.05s", "--trace", trace, "--record-memory", "all")
    assert ran.returncode == 0, ran.stderr
    assert messages_not_fitting_their_schema(trace) == {}
    _, messages = channels_and_messages(trace)
    last = messages["/f/a.cs/memory"][-1]
    assert last["grid"][0][0] == math.inf and last["rows"] == [None, [-math.inf, 2.0], [-math.inf, 2.0]]
    signals = read_signals(trace, ["f/a.cs.rows[1][0]", "f/a.cs.grid[0][0]", "f/a.cs.rows[2][1]"])
    assert not signals.empty
    assert [series.name for series in signals.series] == ["rows[1][0]", "grid[0][0]", "rows[2][1]"]
    assert all(math.isnan(value) for value in signals.series[0].values + signals.series[1].values)
    assert signals.series[2].values[-1] == 2.0
    plot = run_earl("plot", trace, "--signal", "f/a.cs.rows[1][0]", "-o", tmp_path / "i.png")
    assert plot.returncode == 0, plot.stderr


def test_a_subsystem_named_alone_lists_its_memory_families_with_their_star(tmp_path: Path) -> None:
    """A family is one array, which its schema cannot tell from an array: the memory channel's metadata
    names the families (`{"level":0,"rows":1}`), and `earl plot --signal f/a.cs` lists `level[*]`, as it
    did of traces whose members were fields `level[0]`, and `rows[*]`, a family of arrays in no schema.
    `grid/m: double[2][2]`, an array of arrays the schema leaves out, was not listed: the metadata names
    it (`unschemed`), and `grid[0][1]` plots."""
    (tmp_path / "system.earl").write_text(INFINITIES)
    trace = tmp_path / "i.mcap"
    assert run_earl("run", tmp_path, "--duration", "0.05s", "--trace", trace, "--record-memory", "all").returncode == 0
    with open(trace, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    [memory] = [channel for channel in summary.channels.values() if channel.topic == "/f/a.cs/memory"]
    schema = json.loads(summary.schemas[memory.schema_id].data)
    assert "grid" not in schema["properties"] and json.loads(memory.metadata["unschemed"]) == ["grid"]
    plot = run_earl("plot", trace, "--signal", "f/a.cs", "-o", tmp_path / "i.png")
    assert plot.returncode == 1
    assert "(the trace has `grid`, `level[*]`, `rows[*]`)" in plot.stderr, plot.stderr
    plot = run_earl("plot", trace, "--signal", "f/a.cs.grid[0][1]", "-o", tmp_path / "grid.png")
    assert plot.returncode == 0, plot.stderr
    assert (tmp_path / "grid.png").stat().st_size > 0


def write_trace_of_format(path: Path, start: dict[str, Any], memory_schema: dict[str, Any], memory: Any) -> None:
    """A trace with topics as this earl names them, the start message `start` and one memory message."""
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        run_schema = writer.register_schema("earl.Run", "jsonschema", b'{"type": "object", "title": "earl.Run"}')
        run = writer.register_channel("/earl/run", "json", run_schema, {})
        fsm_schema = writer.register_schema("earl.StateChange", "jsonschema", b'{"type": "object"}')
        fsm = writer.register_channel("/s/a.cs/fsm", "json", fsm_schema, {"subsystem": "s/a.cs"})
        schema = writer.register_schema("earl.Memory.s/a.cs", "jsonschema", json.dumps(memory_schema).encode())
        snapshots = writer.register_channel("/s/a.cs/memory", "json", schema, {"subsystem": "s/a.cs"})
        writer.add_message(run, 0, json.dumps(start).encode(), 0)
        writer.add_message(fsm, 0, b'{"from": null, "to": "idle", "transition": null}', 0)
        writer.add_message(snapshots, 10_000_000, json.dumps(memory).encode(), 10_000_000)
        writer.add_message(run, 20_000_000, b'{"event": "end", "faults": 0, "iterations": []}', 20_000_000)
        writer.finish()


def test_a_trace_without_a_format_reads_a_null_element_of_an_array_the_schema_leaves_out_as_infinite(
    tmp_path: Path,
) -> None:
    """Traces written before the format was numbered (format 1) wrote an infinite real null: inside an
    array of arrays, which the schema leaves out, it was read as an optional field never sent. An array
    has no optional elements; the nulls before a family of arrays' first member stay no value."""
    trace = tmp_path / "f1.mcap"
    start = {"event": "start", "earl": "0.1.0", "system": "s", "seed": 0}
    memory = {"grid": [[None, 2.0], [3.0, 4.0]], "rows": [None, [None, 2.0]], "note": None, "x": 1.0}
    schema = {"type": "object", "properties": {"note": {"type": "string"}, "x": {"type": "number"}}, "required": ["x"]}
    write_trace_of_format(trace, start, schema, memory)
    signals = read_signals(trace, ["s/a.cs.grid[0][0]", "s/a.cs.rows[1][0]", "s/a.cs.x"])
    assert [series.name for series in signals.series] == ["grid[0][0]", "rows[1][0]", "x"] and not signals.empty
    with pytest.raises(TraceError, match=r"`s/a\.cs\.rows\[0\]` had no value in this run"):
        read_signals(trace, ["s/a.cs.rows[0]"])


@pytest.mark.parametrize("command", ["summary", "plot"])
def test_a_trace_of_a_newer_format_is_said_to_be_one_not_damaged(tmp_path: Path, command: str) -> None:
    """A trace whose start message says a format newer than this earl reads: said plainly, exit 1,
    rather than "a message on … is not one earl writes (the file is damaged …)" once a message of the
    new format met this earl's reader."""
    trace = tmp_path / "new.mcap"
    newer = trace_topics.FORMAT + 1
    start = {"event": "start", "format": newer, "earl": "9.0.0", "system": "s", "seed": 0}
    write_trace_of_format(trace, start, {"type": "object", "properties": {}}, ["written otherwise"])
    said = (
        f"{trace} was written by a newer earl (trace format {newer}; this earl reads up to {trace_topics.FORMAT}): "
        "read it with that earl, or a newer one"
    )
    if command == "summary":
        ran = run_earl("trace", "summary", trace)
    else:
        ran = run_earl("plot", trace, "--signal", "s/a.cs.x", "-o", tmp_path / "p.png")
    assert ran.returncode == 1 and ran.stderr == f"earl {'trace' if command == 'summary' else 'plot'}: {said}\n"
    # the same trace in the format this earl writes is read
    write_trace_of_format(trace, {**start, "format": trace_topics.FORMAT}, {"type": "object"}, {"x": 1.0})
    assert [series.values for series in read_signals(trace, ["s/a.cs.x"]).series] == [[1.0]]
