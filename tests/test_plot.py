"""`read_signals` and `plot_signals` on small traces written here, message by message."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer

from earl.runtime.signal_syntax import signal_syntax_error
from earl.runtime.trace_reader import TraceError, read_signals

SECOND = 1_000_000_000


def write_trace(
    path: Path,
    states: list[tuple[float, str]],
    messages: list[tuple[float, Any]],
    schema: Any,
    memory: dict[str, float] | None = None,
    legacy: bool = False,
) -> None:
    """A trace of subsystem `s/a.cs`: its FSM's `states`, what its output buffer `cmd` sent and, if
    given, one snapshot of its `memory` (numbers). Its topics are named as earl writes them
    (`/s/a.cs/fsm`), or `legacy` as earl wrote them before they had a leading slash (`s/a.cs/fsm`)."""
    slash = "" if legacy else "/"
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        # the run's start, which makes the file an earl trace
        run_schema = writer.register_schema("earl.Run", "jsonschema", json.dumps({"type": "object"}).encode())
        run = writer.register_channel("/earl/run", "json", run_schema)
        writer.add_message(run, 0, json.dumps({"event": "start", "seed": 0}).encode(), 0)
        fsm_schema = writer.register_schema("Fsm", "jsonschema", json.dumps({"type": "object"}).encode())
        fsm = writer.register_channel(f"{slash}s/a.cs/fsm", "json", fsm_schema, {"subsystem": "s/a.cs"})
        link_schema = writer.register_schema("Cmd", "jsonschema", json.dumps(schema).encode())
        link = writer.register_channel(
            f"{slash}link/s/a:cs,ve", "json", link_schema, {"link": "s/a:cs,ve", "source": "s/a.cs.cmd"}
        )
        for time, state in states:
            data = {"from": "", "to": state, "transition": "t"}
            writer.add_message(fsm, int(time * SECOND), json.dumps(data).encode(), int(time * SECOND))
        for time, value in messages:
            writer.add_message(link, int(time * SECOND), json.dumps(value).encode(), int(time * SECOND))
        if memory is not None:
            properties = {key: {"type": "number"} for key in memory}
            memory_schema = writer.register_schema(
                "Memory", "jsonschema", json.dumps({"type": "object", "properties": properties}).encode()
            )
            snapshots = writer.register_channel(f"{slash}s/a.cs/memory", "json", memory_schema, {"subsystem": "s/a.cs"})
            writer.add_message(snapshots, SECOND, json.dumps(memory).encode(), SECOND)
        writer.finish()


GOAL = {
    "type": "object",
    "properties": {
        "goal": {
            "anyOf": [
                {"type": "object", "properties": {"x": {"type": "array", "items": {"type": "number"}}}},
                {"type": "null"},
            ]
        },
        "ready": {"type": "boolean"},
    },
}


def test_an_optional_field_a_later_message_withdraws_ends_its_line_there(tmp_path: Path) -> None:
    """A message without the optional field (null) is a gap from its time on, not the last value held;
    the line comes back with the field. An array sent shorter ends the line of the elements it lost."""
    trace = tmp_path / "t.mcap"
    messages = [
        (1.0, {"goal": {"x": [1.0, 5.0]}, "ready": True}),
        (2.0, {"goal": None, "ready": True}),
        (2.5, {"goal": None, "ready": True}),
        (3.0, {"goal": {"x": [3.0]}, "ready": False}),
    ]
    write_trace(trace, [(0.0, "idle")], messages, GOAL)
    data = read_signals(trace, ["s/a.cs.cmd.goal.x[*]", "s/a.cs.cmd.ready"])
    found = {series.name: list(zip(series.times, series.values, strict=True)) for series in data.series}
    first, second = found["cmd.goal.x[0]"], found["cmd.goal.x[1]"]
    assert [time for time, _ in first] == [1.0, 2.0, 3.0]
    assert first[0][1] == 1.0 and math.isnan(first[1][1]) and first[2][1] == 3.0
    assert [time for time, _ in second] == [1.0, 2.0] and math.isnan(second[1][1])  # one gap, not one a message
    assert [value for _, value in found["cmd.ready"]] == [1.0, 1.0, 1.0, 0.0]


def test_legends_are_beside_the_panels_and_hide_no_data_however_many_series(tmp_path: Path) -> None:
    """Each panel's legend is right of its axes, inside the figure, which is widened for it (the panels
    keep their width); twenty series go in columns no taller than the panel, and past the ten colours
    the line style tells them apart."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from earl.runtime.plot import PANEL_WIDTH, draw_signals

    trace = tmp_path / "t.mcap"
    schema = {"type": "object", "properties": {"v": {"type": "array", "items": {"type": "number"}}}}
    messages = [(time, {"v": [time * k for k in range(20)]}) for time in (0.0, 1.0, 2.0)]
    write_trace(trace, [(0.0, "idle"), (1.0, "moving")], messages, schema)
    figure = draw_signals(read_signals(trace, ["s/a.cs.cmd.v[*]"]), "a title")
    try:
        renderer = figure.canvas.get_renderer()  # type: ignore[attr-defined]
        assert figure.get_figwidth() > PANEL_WIDTH
        for axis in figure.axes:
            legend = axis.get_legend()
            box, panel = legend.get_window_extent(renderer), axis.get_window_extent(renderer)
            assert box.x0 > panel.x1 and box.x1 <= figure.bbox.x1
            assert box.height <= panel.height * 1.2
            texts = [text.get_text() for text in legend.get_texts()]
            assert texts[:2] == ["cmd.v[0]", "cmd.v[1]"] and texts[-2:] == ["state idle", "state moving"]
        styles = {line.get_label(): line.get_linestyle() for line in figure.axes[0].get_lines()}
        assert styles["cmd.v[0]"] == "-" and styles["cmd.v[10]"] == "--"
    finally:
        plt.close(figure)


def test_a_panel_of_booleans_reads_false_and_true_and_each_panel_says_what_it_shows(tmp_path: Path) -> None:
    """A Boolean panel has the ticks `false` and `true` on a fixed range around 0..1, an all-false one
    too (it had a range of ±0.04 with decimal ticks); a panel with numbers keeps numeric ticks. The y
    axis names the signals: one by its name, several by what they share, `[*]` for differing indices."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from earl.runtime.plot import draw_signals, panel_label

    trace = tmp_path / "t.mcap"
    messages = [(time, {"goal": {"x": [time, 1.0]}, "ready": False}) for time in (0.0, 1.0, 2.0)]
    write_trace(trace, [(0.0, "idle")], messages, GOAL)
    data = read_signals(trace, ["s/a.cs.cmd.ready"])
    assert [series.boolean for series in data.series] == [True]
    figure = draw_signals(data)
    try:
        axis = figure.axes[0]
        assert [label.get_text() for label in axis.get_yticklabels()] == ["false", "true"]
        assert axis.get_ylim() == (-0.25, 1.25) and axis.get_ylabel() == "cmd.ready"
    finally:
        plt.close(figure)
    mixed = read_signals(trace, ["s/a.cs.cmd.goal.x[*]", "s/a.cs.cmd.ready"])
    assert [series.boolean for series in mixed.series] == [False, False, True]
    figure = draw_signals(mixed)
    try:
        axis = figure.axes[0]
        assert "true" not in [label.get_text() for label in axis.get_yticklabels()]
        assert axis.get_ylabel() == "cmd"
    finally:
        plt.close(figure)
    assert panel_label(["windingCurrent[1]", "windingCurrent[6]"]) == "windingCurrent[*]"
    assert panel_label(["cmd.jointPosSetpoint[0]", "cmd.jointPosSetpoint[5]"]) == "cmd.jointPosSetpoint[*]"
    assert panel_label(["mc[1].desiredWindingCurrent", "mc[2].desiredWindingCurrent"]) == "mc[*].desiredWindingCurrent"
    assert panel_label(["cmd.jointPosSetpoint[0]", "cmd.operationalPosSetpoint.position[1]"]) == "cmd"


def test_the_help_of_signal_says_how_a_family_and_an_array_are_indexed() -> None:
    """A family's members are written with their declared index (`windingCurrent[1]` is member 1 of
    `1..6`), an array's elements from 0: the plot labels `windingCurrent[1..6]` beside
    `currentJointPos[0..5]`, as the spec names them, and `--help` says so."""
    from earl.cli.main import build_parser

    plot = build_parser()._subparsers._group_actions[0].choices["plot"]  # type: ignore[union-attr]
    said = " ".join(plot.format_help().split())
    assert "windingCurrent[1] is member 1 of windingCurrent[K in 1..6]" in said
    assert "an element counted from 0 (currentJointPos[0] is its first)" in said
    assert "x[1] of a family is member 1, v[0] of an array its first element" in said
    run = build_parser()._subparsers._group_actions[0].choices["run"]  # type: ignore[union-attr]
    assert "x[1] of a family is member 1, v[0] of an array its first element" in " ".join(run.format_help().split())


@pytest.mark.parametrize(
    "signal",
    [
        "manip/a.cs.windingCurrent[1]",
        "manip/a.cs.currentJointPos[*]",
        "manip/a.motorController[1]/ve.motorControllerState.currentMotorPos",
        "manip/a.cs.manipulatorCommand.jointPosSetpoint[0]",
        "eye[K]/rr.blocked",  # a family's index variable: the lookup says to name its members
        "w[1]/a.cs.out[2].x",
    ],
)
def test_the_signals_the_docs_write_are_well_formed(signal: str) -> None:
    assert signal_syntax_error(signal) is None


def test_a_malformed_signal_is_said_with_its_control_characters_escaped_and_the_caret_under_the_spot() -> None:
    """A signal is echoed in the message: a terminal's escape in it is shown, not obeyed, and the caret
    counts the characters as shown."""
    error = signal_syntax_error("s/a.cs.cmd\x1b[31m")
    assert error is not None
    assert str(error).splitlines() == [
        "`s/a.cs.cmd\\x1b[31m` is malformed at character 11: `\\x1b` after `cmd`: a signal's names are joined "
        "by `.` and `/`, and indexed in brackets, `[1]`",
        "  s/a.cs.cmd\\x1b[31m",
        "  " + " " * 10 + "^",
    ]


def test_read_signals_refuses_a_malformed_signal_and_a_subsystem_alone_saying_which(tmp_path: Path) -> None:
    """From Python too: `read_signals` (and `plot_signals`) say what is wrong with the name."""
    trace = tmp_path / "t.mcap"
    write_trace(trace, [(0.0, "idle")], [(0.1, {"ready": True})], GOAL)
    with pytest.raises(TraceError, match=r"`s/a\.cs\.cmd\[` is malformed at character 12"):
        read_signals(trace, ["s/a.cs.cmd["])
    with pytest.raises(
        TraceError, match=r"`s/a\.cs` names a subsystem: .* e\.g\. `s/a\.cs\.cmd` \(the trace has `cmd`\)"
    ):
        read_signals(trace, ["s/a.cs"])


@pytest.mark.parametrize("legacy", [False, True], ids=["topics-with-slash", "earlier-topics"])
def test_a_subsystem_named_alone_is_answered_with_its_memory_and_buffers_whichever_way_its_topics_are_named(
    tmp_path: Path, legacy: bool
) -> None:
    """Its recorded memory (`/s/a.cs/memory`) and the buffers its recorded links leave are listed, and a
    misspelt value of it gets a did-you-mean, in a trace of this earl and in one an earlier earl wrote
    (`s/a.cs/memory`, `link/…`): looking them up by one spelling said its memory was not recorded."""
    trace = tmp_path / "t.mcap"
    write_trace(trace, [(0.0, "idle")], [(0.1, {"ready": True})], GOAL, memory={"count": 3.0}, legacy=legacy)
    with pytest.raises(TraceError) as caught:
        read_signals(trace, ["s/a.cs"])
    assert "e.g. `s/a.cs.cmd` (the trace has `cmd`, `count`)" in str(caught.value)
    assert "memory is not in this trace" not in str(caught.value)
    with pytest.raises(TraceError, match=r"the trace has no values for `s/a\.cs\.cuont`; did you mean `count`\?"):
        read_signals(trace, ["s/a.cs.cuont"])
    assert [series.values for series in read_signals(trace, ["s/a.cs.count"]).series] == [[3.0]]


def test_another_tool_s_topics_are_listed_escaped_when_its_file_is_said_to_be_no_earl_trace(tmp_path: Path) -> None:
    other = tmp_path / "other.mcap"
    with open(other, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        schema = writer.register_schema("Odometry", "jsonschema", b"{}")
        channel = writer.register_channel("/odom\x1b[2J", "json", schema)
        writer.add_message(channel, 0, b"{}", 0)
        writer.finish()
    with pytest.raises(TraceError) as caught:
        read_signals(other, ["s/a.cs.x"])
    assert "not an earl trace: it has no /earl/run topic (its topics: /odom\\x1b[2J)" in str(caught.value)
    assert "\x1b" not in str(caught.value)


def test_a_foxglove_message_path_given_as_a_signal_gets_earl_s_spelling(tmp_path: Path) -> None:
    """The path docs/semantics.md gives for Foxglove, pasted as a signal: the caret at its `"` came
    without a word on what earl calls that value (`earl plot --signal` and `earl run --signal` say
    the same, `str` of the MalformedSignal)."""
    trace = tmp_path / "t.mcap"
    write_trace(trace, [(0.0, "idle")], [(0.1, {"ready": True})], GOAL)
    with pytest.raises(TraceError) as caught:
        read_signals(trace, ['"/manip/a.cs/memory".windingCurrent[1]'])
    lines = str(caught.value).splitlines()
    assert lines[0].startswith('`"/manip/a.cs/memory".windingCurrent[1]` is malformed at character 1')
    assert lines[-1] == "this is a Foxglove message path; earl names that value `manip/a.cs.windingCurrent[1]`"
    every = str(signal_syntax_error('"/manip/a.cs/memory".windingCurrent[:]'))
    assert every.endswith("earl names that value `manip/a.cs.windingCurrent[*]`")
    link = str(signal_syntax_error('"/link/task,manip".emergencyStopCommand'))
    assert "earl names a value a link carries by the output buffer it leaves" in link
    assert "Foxglove" not in str(signal_syntax_error("s/a.cs.cmd["))
