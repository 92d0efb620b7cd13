"""`earl run`, `earl plot` and `earl trace` on a conveyor sorter (tests/runtime_specs/sorter): a family of
agents (`pusher[K in 1..NBINS]/a`), a family of links to them and a family of output buffers, as a new
user wrote it. Real processes, real files."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

SORTER = Path(__file__).parent / "runtime_specs" / "sorter"
EARL = [sys.executable, "-m", "earl.cli.main"]


def earl_cli(*arguments: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*EARL, *arguments], capture_output=True, text=True, timeout=120, cwd=cwd, check=False)


@pytest.fixture(scope="module")
def sorter_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A trace of 4 s of the sorter (its run.toml records `sorter/a.cs`'s memory): parts have been
    dispatched to the pushers by then, so `push[1..3]` sent messages."""
    trace = tmp_path_factory.mktemp("sorter") / "run.mcap"
    ran = earl_cli("run", str(SORTER), "--trace", str(trace))
    assert ran.returncode == 0, ran.stderr
    return trace


@pytest.mark.parametrize(
    ("signal", "said"),
    [
        # a misspelt field of a member of a family of output buffers: the trace's schema has its fields
        (
            "sorter/a.cs.push[2].abortt",
            "`sorter/a.cs.push[2].abortt`: `push[2]` has no field `abortt` where the signal names it; "
            "did you mean `abort`?",
        ),
        # a member that never sent in 4 s (no part for bin 1 yet): its field is checked by its siblings' schema
        (
            "sorter/a.cs.push[1].abortt",
            "`sorter/a.cs.push[1].abortt`: `push[1]` has no field `abortt` where the signal names it; "
            "did you mean `abort`?",
        ),
        # past the end of an `int[NBINS]` memory: its schema says it has 3 elements
        (
            "sorter/a.cs.perBin[5]",
            "`sorter/a.cs.perBin[5]`: `perBin` has elements 0 to 2 where the signal indexes it, not 5",
        ),
        # a member the family of output buffers does not have
        ("sorter/a.cs.push[7]", "`sorter/a.cs.push[7]`: `push` has members 1..3, not 7"),
        ("sorter/a.cs.push[7].abort", "`sorter/a.cs.push[7].abort`: `push` has members 1..3, not 7"),
        # a field of something that is not a struct
        (
            "sorter/a.cs.sorted.count",
            "`sorter/a.cs.sorted.count`: `sorted` has no field `count` where the signal names it: it is a whole number",
        ),
    ],
)
def test_a_path_the_trace_s_schemas_do_not_have_is_refused_not_drawn_without(
    sorter_trace: Path, tmp_path: Path, signal: str, said: str
) -> None:
    """A misspelt field, an index past a fixed array's end or a member a family lacks is refused with
    what the trace has (exit 1, as a misspelt memory name is), not left out as "no value in this run"
    while the other signals are drawn (exit 0)."""
    picture = tmp_path / "x.png"
    plot = earl_cli("plot", str(sorter_trace), "--signal", "sorter/a.cs.sorted", "--signal", signal, "-o", str(picture))
    assert plot.returncode == 1, plot.stderr
    assert plot.stderr == f"earl plot: {said}\n"
    assert not picture.exists()


def test_the_paths_the_trace_has_are_drawn(sorter_trace: Path, tmp_path: Path) -> None:
    """The same elements named rightly are drawn: the check refuses only what the schemas lack."""
    picture = tmp_path / "x.png"
    signals = ["sorter/a.cs.perBin[2]", "sorter/a.cs.push[*].partId", "sorter/a.cs.push[2].abort"]
    plot = earl_cli("plot", str(sorter_trace), *(f"--signal={s}" for s in signals), "-o", str(picture))
    assert plot.returncode == 0, plot.stderr
    assert plot.stderr == "" and picture.stat().st_size > 0


def test_a_member_that_never_sent_is_drawn_without_as_having_no_value(sorter_trace: Path, tmp_path: Path) -> None:
    """`push[1]` is a member of the family (the trace's metadata lists the buffers links leave) that sent
    nothing in 4 s: no slip, so the others are drawn and it is said to have had no value."""
    picture = tmp_path / "x.png"
    signals = ["--signal=sorter/a.cs.sorted", "--signal=sorter/a.cs.push[1].abort"]
    plot = earl_cli("plot", str(sorter_trace), *signals, "-o", str(picture))
    assert plot.returncode == 0, plot.stderr
    assert "`sorter/a.cs.push[1].abort` had no value in this run" in plot.stderr


def test_earl_run_plot_suggests_the_field_a_signal_misspells(tmp_path: Path) -> None:
    """Before the run, from the spec: the same did-you-mean as `earl plot` gives from a trace."""
    ran = earl_cli("run", str(SORTER), "--plot", str(tmp_path / "x.png"), "--signal", "sorter/a.cs.push[2].abortt")
    assert ran.returncode == 2
    assert "`push[2]` has no field `abortt` where the signal names it; did you mean `abort`?" in ran.stderr


def recorded_links(trace: Path) -> list[str]:
    from earl.runtime.trace_reader import topics

    return sorted(topic.removeprefix("/link/") for topic in topics(trace) if topic.startswith("/link/"))


@pytest.mark.parametrize(
    ("pattern", "links"),
    [
        # brackets with a number: that member (they were a glob's character class, `1`, and matched nothing)
        ("pusher[2],sorter", ["pusher[2],sorter"]),
        # `[*]` and the index variable: every member, as `[*]` and `[K]` name a family elsewhere
        ("pusher[*],sorter", ["pusher[1],sorter", "pusher[2],sorter", "pusher[3],sorter"]),
        ("pusher[K],sorter", ["pusher[1],sorter", "pusher[2],sorter", "pusher[3],sorter"]),
        ("sorter,pusher[1]", ["sorter,pusher[1]"]),
        ("sorter,pusher[*]", ["sorter,pusher[1]", "sorter,pusher[2]", "sorter,pusher[3]"]),
        ("sorter,pusher[K]", ["sorter,pusher[1]", "sorter,pusher[2]", "sorter,pusher[3]"]),
        # the agent family's index variable names its members' links alike
        ("pusher[K]/a:cs,*", ["pusher[1]/a:cs,arm", "pusher[2]/a:cs,arm", "pusher[3]/a:cs,arm"]),
        # other brackets are a glob's character class, as before families had names: `c` and `d`
        ("sorter/a:[cd]*", ["sorter/a:camera,detector", "sorter/a:cs,beltDrive", "sorter/a:detector,cs"]),
        (
            "pusher[3]/a:*",
            ["pusher[3]/a:arm,armMotor", "pusher[3]/a:arm,cs", "pusher[3]/a:armMotor,arm", "pusher[3]/a:cs,arm"],
        ),
    ],
)
def test_record_links_names_a_member_of_a_link_family_by_its_index(
    tmp_path: Path, pattern: str, links: list[str]
) -> None:
    trace = tmp_path / "run.mcap"
    # 6 s: by then a part has been pushed by each pusher (a link is in the trace once it has a message)
    ran = earl_cli("run", str(SORTER), "--duration", "6s", "--trace", str(trace), "--record-links", pattern)
    assert ran.returncode == 0, ran.stderr
    assert "matches no link" not in ran.stderr
    assert recorded_links(trace) == links


def test_a_link_pattern_matching_nothing_lists_the_names_one_can_write_families_once(tmp_path: Path) -> None:
    """The list was the first 8 links in order, all of them members of `pusher[1]` and `pusher[2]`:
    the sorter's own links and `sorter,pusher[…]` never appeared."""
    ran = earl_cli(
        "run",
        str(SORTER),
        "--duration",
        "0.1s",
        "--trace",
        str(tmp_path / "r.mcap"),
        "--record-links",
        "sortr,pusher[1]",
    )
    assert ran.returncode == 0, ran.stderr
    assert (
        "earl run: --record-links `sortr,pusher[1]` matches no link; did you mean `sorter,pusher[1]`? (the links: "
        "pusher[*],sorter, pusher[*]/a:arm,armMotor, pusher[*]/a:arm,cs, pusher[*]/a:armMotor,arm, pusher[*]/a:cs,arm, "
        "sorter,pusher[*], sorter/a:beltDrive,beltMotor, sorter/a:camera,detector, sorter/a:cs,beltDrive, "
        "sorter/a:detector,cs)\n"
    ) in ran.stderr


@pytest.mark.parametrize(
    "pattern",
    [
        "pusher[1-2],sorter",  # a character class of `1`, `-` and `2`: no link
        "pusher[J],sorter",  # `J` is no index variable of the family (`K`): the character `J`
        "pusher[1,sorter",  # an unclosed `[` stands for itself, as in a shell
    ],
)
def test_brackets_that_name_no_member_are_a_glob_s_and_match_no_link_with_a_did_you_mean(
    tmp_path: Path, pattern: str
) -> None:
    """They were refused before the run (exit 2) since brackets with a name were taken for a family's
    index; a shell's glob with a character class (`task,[mg]*`) then matched nothing."""
    trace = tmp_path / "run.mcap"
    ran = earl_cli("run", str(SORTER), "--duration", "0.1s", "--trace", str(trace), "--record-links", pattern)
    assert ran.returncode == 0, ran.stderr
    said = f"earl run: --record-links `{pattern}` matches no link; did you mean `pusher["
    assert said in ran.stderr and "],sorter`? (the links: pusher[*],sorter, " in ran.stderr
    assert recorded_links(trace) == []


def test_run_toml_record_links_names_members_alike(tmp_path: Path) -> None:
    spec = tmp_path / "sorter"
    shutil.copytree(SORTER, spec, ignore=shutil.ignore_patterns("__pycache__"))
    settings = spec / "run.toml"
    text = settings.read_text()
    settings.write_text(text + 'record_links = ["sorter/a:*", "pusher[2],sorter"]\n')
    trace = tmp_path / "run.mcap"
    ran = earl_cli("run", str(spec), "--duration", "0.2s", "--trace", str(trace))
    assert ran.returncode == 0, ran.stderr
    assert "matches no link" not in ran.stderr
    assert recorded_links(trace) == [
        "pusher[2],sorter",
        "sorter/a:beltDrive,beltMotor",
        "sorter/a:camera,detector",
        "sorter/a:cs,beltDrive",
        "sorter/a:detector,cs",
    ]
    settings.write_text(text + 'record_links = ["pusher[a-c],sorter"]\n')
    warned = earl_cli("run", str(spec), "--duration", "0.2s", "--trace", str(trace))
    assert warned.returncode == 0, warned.stderr
    assert "record_links `pusher[a-c],sorter` in run.toml matches no link" in warned.stderr


def test_the_python_api_takes_the_same_link_patterns() -> None:
    import earl

    system = earl.load(SORTER / "system.earl")
    from earl.runtime import RecordingWarning

    # brackets that name no member are a character class (they were a ValueError): no link, warned of
    with pytest.warns(RecordingWarning, match=r"record_links: `pusher\[1-3\],sorter` matches no link"):
        earl.simulate(system, environment=None, record_links=["pusher[1-3],sorter"]).close()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordingWarning)  # `[K]` is the family's index variable: its members
        earl.simulate(system, environment=None, record_links=["pusher[K],sorter"]).close()


def recorded_memories(trace: Path) -> list[str]:
    from earl.runtime.trace_reader import topics

    return sorted(topic.strip("/").removesuffix("/memory") for topic in topics(trace) if topic.endswith("/memory"))


@pytest.mark.parametrize("family", ["pusher[*]/a.cs", "pusher[K]/a.cs", "pusher/a.cs"])
def test_record_memory_names_a_family_of_agents_whole_as_a_robot_does(tmp_path: Path, family: str) -> None:
    """It was refused: "names no subsystem of this run … (subsystems are named like sorter/a.cs)"."""
    trace = tmp_path / "run.mcap"
    ran = earl_cli("run", str(SORTER), "--duration", "0.1s", "--trace", str(trace), "--record-memory", family)
    assert ran.returncode == 0, ran.stderr
    assert recorded_memories(trace) == ["pusher[1]/a.cs", "pusher[2]/a.cs", "pusher[3]/a.cs"]


def test_record_memory_of_no_subsystem_shows_how_a_member_and_a_family_are_named(tmp_path: Path) -> None:
    ran = earl_cli("run", str(SORTER), "--trace", str(tmp_path / "r.mcap"), "--record-memory", "pusher[4]/a.cs")
    assert ran.returncode == 2
    assert "names no subsystem of this run: pusher[4]/a.cs" in ran.stderr
    assert "a family's member `pusher[1]/a.cs`, or every member, `pusher[*]/a.cs`" in ran.stderr


def test_agents_names_a_family_whole(tmp_path: Path) -> None:
    """`--agents 'pusher[*]'` is every member (`earl launch` passes a process's agents as it got them)."""
    trace = tmp_path / "run.mcap"
    ran = earl_cli(
        "run",
        str(SORTER),
        "--agents",
        "pusher[*]",
        "--environment",
        "none",
        "--duration",
        "0.05s",
        "--trace",
        str(trace),
        "--record-memory",
        "pusher/a.arm/ve",
    )
    assert ran.returncode == 0, ran.stderr
    from earl.runtime.trace_reader import summarise

    assert sorted(summarise(trace).subsystems) == [
        f"pusher[{k}]/a.{s}" for k in (1, 2, 3) for s in ("arm/ve", "armMotor/re", "cs")
    ]
    assert recorded_memories(trace) == ["pusher[1]/a.arm/ve", "pusher[2]/a.arm/ve", "pusher[3]/a.arm/ve"]
    twice = earl_cli(
        "run", str(SORTER), "--agents", "pusher[*],pusher[2]", "--environment", "none", "--duration", "0.05s"
    )
    assert twice.returncode == 2 and "--agents: `pusher[2]/a` is named twice" in twice.stderr


def test_launch_runs_a_family_of_agents_a_deploy_toml_names_whole(tmp_path: Path) -> None:
    """`agents = ["pusher[*]/a"]` is the process of every member (it was "not an agent of this system");
    the two processes exchange messages over Zenoh on 127.0.0.1."""
    import socket

    spec = tmp_path / "sorter"
    shutil.copytree(SORTER, spec, ignore=shutil.ignore_patterns("__pycache__"))
    sockets = [socket.socket() for _ in range(2)]
    for s in sockets:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in sockets]
    for s in sockets:
        s.close()
    (spec / "deploy.toml").write_text(
        f'[[process]]\nagents = ["sorter/a"]\nlisten = "tcp/127.0.0.1:{ports[0]}"\nenvironment = true\n\n'
        f'[[process]]\nagents = ["pusher[*]/a"]\nlisten = "tcp/127.0.0.1:{ports[1]}"\nenvironment = false\n'
        'args = ["--environment", "none"]\n'
    )
    launched = earl_cli("launch", str(spec), "--duration", "1s")
    assert "[pusher[1]/a,pusher[2]/a,pusher[3]/a] system conveyorSorter: 1.000 s" in launched.stdout, launched.stdout
    received = [line for line in launched.stdout.splitlines() if line.startswith("[sorter/a") and "received" in line]
    assert len(received) == 3 and all(" 0 received" not in line for line in received), launched.stdout
    assert "Traceback" not in launched.stdout + launched.stderr


def sorter_dividing_by_zero(tmp_path: Path) -> Path:
    """The sorter whose `classify/pf` calls a helper of its own package that divides by zero."""
    spec = tmp_path / "sorter"
    shutil.copytree(SORTER, spec, ignore=shutil.ignore_patterns("__pycache__"))
    (spec / "sorting" / "ratios.py").write_text("def ratio(a, b):\n    return a / b\n")
    code = spec / "sorting" / "sorter.py"
    text = code.read_text()
    old = "    outputs.lastPart = d.partId\n"
    assert old in text
    code.write_text("from sorting.ratios import ratio\n\n\n" + text.replace(old, old + "    ratio(1, 0)\n"))
    return spec


def test_a_fault_of_the_spec_s_code_says_where_and_its_traceback_is_one_command_away(tmp_path: Path) -> None:
    """It said only "`classify/pf` raised ZeroDivisionError: division by zero": no file or line of the
    spec's code, though the traceback was recorded."""
    spec = sorter_dividing_by_zero(tmp_path)
    where = "(at sorting/ratios.py:2 in ratio, from sorting/sorter.py:7 in classify)"
    ran = earl_cli("run", str(spec), "--duration", "2s", cwd=spec)
    assert ran.returncode == 0, ran.stderr
    assert f"`classify/pf` raised ZeroDivisionError: division by zero {where}\n" in ran.stdout
    assert "  tracebacks: run with --trace FILE.mcap, then earl trace faults FILE.mcap\n" in ran.stdout
    traced = earl_cli("run", str(spec), "--duration", "2s", "--trace", "run.mcap", cwd=spec)
    assert "  tracebacks: earl trace faults run.mcap\n" in traced.stdout
    summary = earl_cli("trace", "summary", "run.mcap", cwd=spec)
    assert (
        f"division by zero {where}" in summary.stdout
        and "their tracebacks: earl trace faults run.mcap" in summary.stdout
    )
    faults = earl_cli("trace", "faults", "run.mcap", cwd=spec)
    assert faults.returncode == 0, faults.stderr
    shown = faults.stdout
    assert shown.startswith("run.mcap: ") and " distinct\n" in shown.splitlines()[0] + "\n"
    # the function's frame and the helper's, with their lines of code; none of earl's own
    entry = shown.split(f"division by zero {where}", 1)[1]
    assert entry.startswith(", ×")  # raised at every part seen, shown once
    assert f'File "{spec / "sorting" / "sorter.py"}", line 7, in classify\n      ratio(1, 0)\n' in entry
    assert f'File "{spec / "sorting" / "ratios.py"}", line 2, in ratio\n      return a / b\n' in entry
    assert "ZeroDivisionError: division by zero" in entry and "earl/runtime" not in shown


def test_earl_trace_faults_of_a_run_without_faults_and_of_no_trace(tmp_path: Path, sorter_trace: Path) -> None:
    listed = earl_cli("trace", "faults", str(sorter_trace))
    assert listed.returncode == 0 and listed.stdout == "run.mcap: 0 faults, 0 distinct\n"
    assert earl_cli("trace", "faults", str(tmp_path / "none.mcap")).returncode == 2
    junk = tmp_path / "junk.mcap"
    junk.write_text("not a trace")
    refused = earl_cli("trace", "faults", str(junk))
    assert refused.returncode == 1 and refused.stderr.startswith("earl trace: ") and "Traceback" not in refused.stderr


def test_a_fault_s_time_is_seconds_as_the_python_api_s_other_times_and_the_trace_stamps_it_alike(
    tmp_path: Path,
) -> None:
    """`Fault.time` was integer nanoseconds (950000000) where `sim.time` and `context.time` are seconds."""
    import earl
    from earl.runtime.trace_reader import read_faults

    spec = sorter_dividing_by_zero(tmp_path)
    (spec / "sorting" / "ratios.py").write_text(
        "import json, pathlib\n\n\ndef ratio(a, b, context=None):\n"
        "    pathlib.Path(__file__).with_name('seen.json').write_text(json.dumps(context.time))\n"
        "    return a / b\n"
    )
    code = spec / "sorting" / "sorter.py"
    code.write_text(code.read_text().replace("ratio(1, 0)", "ratio(1, 0, context)"))
    trace = tmp_path / "run.mcap"
    simulation = earl.simulate(earl.load(spec / "system.earl"), trace=str(trace))
    simulation.advance_to(0.96)
    simulation.close()
    first = simulation.faults[0]
    assert first.kind == "exception" and isinstance(first.time, float)
    # the time the function that raised was called at
    assert first.time == json.loads((spec / "sorting" / "seen.json").read_text()) == pytest.approx(0.95)
    assert first.time_ns == 950_000_000 and "ratios.py" in first.traceback
    # the trace keeps its nanoseconds
    faults, _ = read_faults(trace)
    assert faults[0]["time"] == 950_000_000 and faults[0]["message"] == first.message


def test_a_trace_of_some_agents_knows_every_member_of_a_family_of_output_buffers(tmp_path: Path) -> None:
    """A run of `sorter` and `pusher[1]` has a link from `push[1]` only: the trace's metadata listed only it
    (`buffers`), so `earl plot` refused `push[2]`, a member of the spec's family of 3, with "`push` has
    members 1..1, not 2" (exit 1). The metadata lists what the subsystem declares; `push[7]` is refused."""
    import json

    from earl.runtime.trace_reader import _channels

    trace = tmp_path / "sub.mcap"
    ran = earl_cli("run", str(SORTER), "--agents", "sorter,pusher[1]", "--duration", "1s", "--trace", str(trace))
    assert ran.returncode == 0, ran.stderr
    metadata = _channels(trace)["/sorter/a.cs/fsm"][0]
    assert json.loads(metadata["outputs"]) == ["beltSpeed", "push[1]", "push[2]", "push[3]"]
    picture = tmp_path / "p.png"
    signals = ["--signal", "sorter/a.cs.push[2].abort", "--signal", "sorter/a.cs.sorted"]
    plot = earl_cli("plot", str(trace), *signals, "-o", str(picture))
    assert plot.returncode == 0, plot.stderr
    assert plot.stderr == (
        "earl plot: `sorter/a.cs.push[2].abort` had no value in this run (`push[2]` sent no message the trace "
        "recorded); drawn without it\n"
    )
    assert picture.stat().st_size > 0
    beyond = earl_cli("plot", str(trace), "--signal", "sorter/a.cs.push[7].abort", "-o", str(picture))
    assert beyond.returncode == 1
    assert beyond.stderr == "earl plot: `sorter/a.cs.push[7].abort`: `push` has members 1..3, not 7\n"


def test_earl_plot_draws_a_window_of_the_run_where_a_10_ms_state_shows(sorter_trace: Path, tmp_path: Path) -> None:
    """`dispatching` lasts one 10 ms period of `sorter/a.cs`: too narrow to see in a plot of the whole
    run. `--from`/`--to` draw the window around it: the axis is the window, each signal starts it with
    the value it held, the states are cut to it."""
    import matplotlib

    matplotlib.use("Agg")
    from earl.runtime.plot import draw_signals
    from earl.runtime.trace_reader import read_signals, within

    whole = read_signals(sorter_trace, ["sorter/a.cs.sorted"])
    start, stop, _ = next(band for band in whole.bands["sorter/a.cs"] if band[2] == "dispatching")
    assert stop - start == pytest.approx(0.01)
    window = within(whole, start - 0.025, stop + 0.02)  # between two iterations
    assert window.start == pytest.approx(start - 0.025) and window.end == pytest.approx(stop + 0.02)
    [series] = window.series
    assert series.times[0] == window.start and series.held  # the count held when the window starts
    assert all(window.start <= time <= window.end for time in series.times)
    states = [state for _, _, state in window.bands["sorter/a.cs"]]
    assert states == ["watching", "dispatching", "watching"]
    figure = draw_signals(window)
    assert figure.axes[0].get_xlim() == pytest.approx((window.start, window.end))
    picture = tmp_path / "window.png"
    plot = earl_cli(
        "plot",
        str(sorter_trace),
        "--signal",
        "sorter/a.cs.sorted",
        "--from",
        f"{start - 0.02:.3f}",
        "--to",
        f"{(stop + 0.02) * 1000:.0f}ms",
        "-o",
        str(picture),
    )
    assert plot.returncode == 0 and plot.stderr == "" and picture.stat().st_size > 0, plot.stderr


@pytest.mark.parametrize(
    ("window", "said"),
    [
        (["--from", "-1"], "earl: error: --from -1: a time of the run is 0 s or more\n"),
        (
            ["--to", "soon"],
            "earl: error: --to: `soon` is not a time; write e.g. `10s`, `500ms`, `2.5` (seconds) or `1min`\n",
        ),
        (["--from", "2", "--to", "1"], "earl: error: --from 2 is not before --to 1: the window would be empty\n"),
        (
            ["--from", "1s", "--to", "1000ms"],
            "earl: error: --from 1s is not before --to 1000ms: the window would be empty\n",
        ),
        # --from left out is the run's start: `--to 0` drew an empty window, exit 0, with a Matplotlib
        # UserWarning naming earl's source (`plot.py:278: … axis.set_xlim(...)`)
        (
            ["--to", "0"],
            "earl: error: --to 0 is not after --from (the run's start, 0 s, when not given): the window would be empty\n",
        ),
        (
            ["--from", "1", "--to", "1.0000000001"],  # one nanosecond of the trace, as the window is compared
            "earl: error: --from 1 is not before --to 1.0000000001: the window would be empty\n",
        ),
        (
            ["--to", "0ms"],
            "earl: error: --to 0ms is not after --from (the run's start, 0 s, when not given): "
            "the window would be empty\n",
        ),
    ],
)
def test_a_window_that_is_no_time_or_empty_is_a_usage_error(
    sorter_trace: Path, tmp_path: Path, window: list[str], said: str
) -> None:
    picture = tmp_path / "x.png"
    plot = earl_cli("plot", str(sorter_trace), "--signal", "sorter/a.cs.sorted", *window, "-o", str(picture))
    assert plot.returncode == 2 and plot.stderr == said and not picture.exists()


def test_the_window_s_edges_are_in_it_whatever_the_float_rounding(sorter_trace: Path) -> None:
    """A trace's times are nanoseconds times 1e-9: the sample at 1.4 s is 1.4000000000000001, so
    `--to 1.4` ended at 1.39 s, and the one at 1.2 s (1.2000000000000002) got a held point at 1.2 too."""
    from earl.runtime.trace_reader import nanoseconds, read_signals, within

    whole = read_signals(sorter_trace, ["sorter/a.cs.sorted"])  # its memory every 10 ms
    [series] = within(whole, 1.2, 1.4).series
    stamps = [nanoseconds(time) for time in series.times]
    assert stamps == list(range(1_200_000_000, 1_400_000_001, 10_000_000))  # both edges, each once
    assert not series.held  # the first is the message sent at 1.2 s, marked as one
    [between] = within(whole, 1.205, 1.4).series
    assert between.held and nanoseconds(between.times[0]) == 1_205_000_000


def test_an_empty_window_from_python_is_a_value_error(sorter_trace: Path) -> None:
    from earl.runtime.trace_reader import read_signals, within

    whole = read_signals(sorter_trace, ["sorter/a.cs.sorted"])
    with pytest.raises(ValueError, match="the window from 0 s to 0 s is empty"):
        within(whole, None, 0.0)


def test_no_matplotlib_warning_reaches_the_user(sorter_trace: Path, tmp_path: Path) -> None:
    """A title too tall for the figure: Matplotlib warned `plot.py:282: UserWarning: Tight layout not
    applied…` twice, with the source line, on earl plot's stderr."""
    title = "\n".join(f"line {number}" for number in range(60))
    picture = tmp_path / "t.png"
    plot = earl_cli("plot", str(sorter_trace), "--signal", "sorter/a.cs.sorted", "--title", title, "-o", str(picture))
    assert plot.returncode == 0 and plot.stderr == "" and picture.stat().st_size > 0


def test_a_window_after_the_trace_s_end_or_without_values_is_said(sorter_trace: Path, tmp_path: Path) -> None:
    after = earl_cli(
        "plot", str(sorter_trace), "--signal", "sorter/a.cs.sorted", "--from", "5", "-o", str(tmp_path / "a.png")
    )
    assert after.returncode == 1
    assert after.stderr == "earl plot: the trace ends at 4.000000 s, by --from 5 s: nothing to draw after it\n"
    # the first part is dispatched at 0.95 s: no push before it
    early = earl_cli(
        "plot",
        str(sorter_trace),
        "--signal",
        "sorter/a.cs.push[*].partId",
        "--to",
        "0.5",
        "-o",
        str(tmp_path / "b.png"),
    )
    assert early.returncode == 1 and "earl plot: no signal has a value from 0 s to 0.5 s: " in early.stderr
