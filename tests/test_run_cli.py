"""`earl run`, `earl trace summary` and `earl plot` as a person uses them: real processes, real files."""

from __future__ import annotations

import importlib.util
import os
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from random import Random

import pytest

import earl
from earl.diagnostics import EarlError

SPECS = Path(__file__).parent / "runtime_specs"
EXAMPLE = Path(__file__).parent.parent / "examples" / "pick_and_place"
EARL = [sys.executable, "-m", "earl.cli.main"]


def earl_cli(*arguments: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*EARL, *arguments], capture_output=True, text=True, timeout=120, cwd=cwd, check=False)


def counter_copy(tmp_path: Path, old: str = "", new: str = "") -> Path:
    target = tmp_path / "counter"
    shutil.copytree(SPECS / "counter", target)
    spec = target / "system.earl"
    if old:
        text = spec.read_text()
        assert old in text
        spec.write_text(text.replace(old, new))
    return spec


def counter_whose_increment_then(tmp_path: Path, code: str, prelude: str = "") -> Path:
    """The counter, its `increment` running `code` (indented lines) after it counts, `prelude` at the top of
    its module: how these tests put misbehaving code in a real spec."""
    spec = counter_copy(tmp_path)
    functions = spec.parent / "counting" / "cs.py"
    line = "    outputs.count = inputs.count + 1\n"
    functions.write_text(prelude + functions.read_text().replace(line, line + code))
    return spec


def test_run_prints_a_summary_and_writes_a_trace_that_summary_and_plot_read(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    result = earl_cli(
        "run", str(SPECS / "counter"), "--duration", "200ms", "--trace", str(trace), "--record-memory", "all"
    )
    assert result.returncode == 0, result.stderr
    assert "counter/a.cs" in result.stdout and "finished" in result.stdout
    assert "ran 0.200 s of virtual time" in result.stdout
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "counting,finished" in summary.stdout
    assert "finished: 0.180 s" in summary.stdout
    png = tmp_path / "count.png"
    plot = earl_cli(
        "plot", str(trace), "--signal", "counter/a.cs.count", "--signal", "counter/a.relay/ve.forward", "-o", str(png)
    )
    assert plot.returncode == 0, plot.stderr
    assert png.read_bytes().startswith(b"\x89PNG")


def test_plot_of_a_signal_the_trace_lacks_says_how_to_record_it(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "50ms", "--trace", str(trace)).returncode == 0
    result = earl_cli("plot", str(trace), "--signal", "counter/a.cs.sent", "-o", str(tmp_path / "x.png"))
    assert result.returncode == 1
    assert "if it is memory, record it with `--record-memory counter/a.cs`" in result.stderr
    assert "Traceback" not in result.stderr
    # what an output buffer sent is in the trace without recording memory
    sent = earl_cli("plot", str(trace), "--signal", "counter/a.relay/ve.back", "-o", str(tmp_path / "z.png"))
    assert sent.returncode == 0, sent.stderr
    assert (tmp_path / "z.png").is_file()


def test_a_signal_naming_a_subsystem_alone_or_a_misspelt_value_is_told_what_the_trace_has(tmp_path: Path) -> None:
    """`counter/a.cs` was said not to "start with a subsystem of this trace (counter/a.cs, …)", the list
    naming it: it is a subsystem, and a signal goes on to one of its values, which are listed."""
    recorded, unrecorded = tmp_path / "memory.mcap", tmp_path / "links.mcap"
    run = ["run", str(SPECS / "counter"), "--duration", "50ms", "--trace"]
    assert earl_cli(*run, str(recorded), "--record-memory", "all").returncode == 0
    assert earl_cli(*run, str(unrecorded)).returncode == 0
    png = tmp_path / "p.png"
    alone = earl_cli("plot", str(recorded), "--signal", "counter/a.cs", "-o", str(png))
    assert alone.returncode == 1
    assert alone.stderr == (
        "earl plot: `counter/a.cs` names a subsystem: a signal goes on to its memory or output buffer, "
        "e.g. `counter/a.cs.count` (the trace has `count`, `sent`)\n"
    )
    # without its memory: what its links sent, and how to record the rest
    links = earl_cli("plot", str(unrecorded), "--signal", "counter/a.cs", "-o", str(png))
    assert links.returncode == 1
    assert "(the trace has `count`); its memory is not in this trace (`earl run --record-memory counter/a.cs`" in (
        links.stderr
    )
    misspelt = earl_cli("plot", str(recorded), "--signal", "counter/a.cs.cuont", "-o", str(png))
    assert misspelt.returncode == 1 and "did you mean `count`?" in misspelt.stderr, misspelt.stderr
    unknown = earl_cli("plot", str(recorded), "--signal", "counter/a.relay/ve.zzz", "-o", str(png))
    assert unknown.returncode == 1 and "(the trace has `back`, `forward`, `last`, `lost`)" in unknown.stderr
    assert not png.exists()
    # `earl run --plot` lists them the same way, from the spec
    before = earl_cli(
        "run", str(SPECS / "counter"), "--duration", "50ms", "--plot", str(png), "--signal", "counter/a.cs"
    )
    assert before.returncode == 2 and "e.g. `counter/a.cs.count` (it has `count`, `sent`)" in before.stderr


@pytest.mark.parametrize(
    ("signal_name", "column", "said"),
    [
        ("x[", 3, "the signal ends where an index belongs: a whole number, as in `x[1]`, or `*`"),
        ("counter/a.cs.count[", 20, "the signal ends where an index belongs"),
        ("counter/a.cs.count[1", 21, "the signal ends where the `]` closing `[` belongs"),
        ("counter/a.cs.count[-1]", 20, "`-` where an index belongs"),
        ("counter/a.cs.", 14, "the signal ends after `.`, where a name belongs"),
        ("counter/a.cs..count", 14, "`.` after `.`, where a name belongs"),
        ("counter/a.cs.count ", 19, "a space after `count`"),
        ("counter/a.cs.count]", 19, "`]` after `count`"),
        (
            "/odom.x",
            1,
            "`/` where the first name belongs: a signal starts with its agent's name, as in `manip/a.cs.count`",
        ),
    ],
)
def test_a_malformed_signal_is_a_usage_error_pointing_at_the_spot(
    tmp_path: Path, signal_name: str, column: int, said: str
) -> None:
    """`x[` was "does not start with a subsystem of this trace" (exit 1), `counter/a.cs.count[` "had no
    value in this run": a signal not written as one is a usage error that shows where it goes wrong."""
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "20ms", "--trace", str(trace)).returncode == 0
    plot = earl_cli("plot", str(trace), "--signal", signal_name, "-o", str(tmp_path / "p.png"))
    assert plot.returncode == 2, plot.stderr
    lines = plot.stderr.splitlines()
    assert lines[0].startswith(f"earl: error: --signal `{signal_name}` is malformed at character {column}: {said}")
    assert lines[1:] == [f"  {signal_name}", "  " + " " * (column - 1) + "^"]
    # `earl run --plot` says the same before the run, of --signal and of run.toml's `plot`
    started = time.monotonic()
    run = ["run", str(SPECS / "counter"), "--duration", "1000s", "--plot", str(tmp_path / "p.png")]
    refused = earl_cli(*run, "--signal", signal_name)
    assert refused.returncode == 2 and refused.stderr == plot.stderr
    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text(f"plot = [{signal_name!r}]\n".replace("'", '"'))
    from_settings = earl_cli("run", str(spec.parent), "--duration", "1000s", "--plot", str(tmp_path / "p.png"))
    assert from_settings.returncode == 2
    assert from_settings.stderr.startswith(f"earl: error: run.toml's plot: `{signal_name}` is malformed at")
    assert time.monotonic() - started < 30  # before the run
    assert not (tmp_path / "p.png").exists()


def test_run_plot_records_the_memory_it_draws_and_refuses_a_signal_the_system_lacks(tmp_path: Path) -> None:
    png = tmp_path / "sent.png"
    # `sent` is memory: recorded for the plot without --record-memory
    result = earl_cli(
        "run", str(SPECS / "counter"), "--duration", "50ms", "--plot", str(png), "--signal", "counter/a.cs.sent"
    )
    assert result.returncode == 0, result.stderr
    assert png.read_bytes().startswith(b"\x89PNG")
    started = time.monotonic()
    wrong = earl_cli(
        "run", str(SPECS / "counter"), "--duration", "1000s", "--plot", str(png), "--signal", "counter/a.cs.snet"
    )
    assert wrong.returncode == 2
    assert "--signal `counter/a.cs.snet`: `counter/a.cs` has no memory or output buffer `snet`" in wrong.stderr
    assert "did you mean `sent`?" in wrong.stderr
    assert time.monotonic() - started < 30  # before the run
    nowhere = earl_cli("run", str(SPECS / "counter"), "--plot", str(png), "--signal", "counter/a.cz.count")
    assert nowhere.returncode == 2 and "does not start with a subsystem of this system" in nowhere.stderr
    # a signal of run.toml's `plot` is said as one of run.toml, not of --signal, which was not given
    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text('plot = ["counter/a.cs.snet"]\n')
    from_settings = earl_cli("run", str(spec.parent), "--duration", "50ms", "--plot", str(png))
    assert from_settings.returncode == 2
    assert "run.toml's plot: `counter/a.cs.snet`: `counter/a.cs` has no memory" in from_settings.stderr
    assert "--signal" not in from_settings.stderr


def test_a_plot_that_cannot_be_written_is_a_usage_error_said_before_anything_runs(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "50ms", "--trace", str(trace)).returncode == 0
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    for output, fragment in [
        (tmp_path / "x.txt", "a plot is written as .png"),
        (tmp_path, "it is a directory"),
        (a_file / "p.png", "is a file, not a directory"),
    ]:
        plot = earl_cli("plot", str(trace), "--signal", "counter/a.cs.count", "-o", str(output))
        assert plot.returncode == 2 and fragment in plot.stderr, plot.stderr
        assert "Traceback" not in plot.stderr
    empty = earl_cli("plot", str(trace), "--signal", "", "-o", str(tmp_path / "p.png"))
    assert empty.returncode == 2 and "--signal names no signal" in empty.stderr  # a usage error, not 1
    started = time.monotonic()
    run = earl_cli("run", str(SPECS / "counter"), "--duration", "1000s", "--plot", str(tmp_path / "x.txt"))
    assert run.returncode == 2 and "--plot" in run.stderr
    assert time.monotonic() - started < 30  # refused before the run, not after it


def test_a_trace_summary_of_something_else_is_a_clear_error(tmp_path: Path) -> None:
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not an mcap file at all")
    result = earl_cli("trace", "summary", str(junk))
    assert result.returncode == 1
    assert "not a readable MCAP trace" in result.stderr
    assert earl_cli("trace", "summary", str(tmp_path / "missing.mcap")).returncode == 2


def write_another_tool_s_mcap(path: Path, encoding: str, data: bytes, topic: str = "/odom") -> None:
    """An MCAP file as another tool writes one: its own schema, one channel, five messages."""
    from mcap.writer import Writer

    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        schema = writer.register_schema("nav.Odometry", "jsonschema" if encoding == "json" else "protobuf", b"{}")
        channel = writer.register_channel(topic, encoding, schema)
        for step in range(5):
            writer.add_message(channel, step * 1000, data, step * 1000)
        writer.finish()


@pytest.mark.parametrize("cut", [False, True], ids=["whole", "cut-short"])
@pytest.mark.parametrize(("encoding", "data"), [("json", b'{"x": 1.5}'), ("protobuf", b"\x08\x96\x01")])
def test_an_mcap_file_of_another_tool_is_said_not_to_be_an_earl_trace_by_summary_and_plot(
    tmp_path: Path, encoding: str, data: bytes, cut: bool
) -> None:
    """`earl plot` said "`/odom.x` does not start with a subsystem of this trace (none)", and of a file
    whose messages are not JSON `earl trace summary` said that a message is not JSON: both say what
    the file is, in the same words, exit 1. Also of a file cut short, which has no summary section
    listing its topics: summary decoded its messages first, "a message is not JSON text"."""
    other = tmp_path / "other.mcap"
    write_another_tool_s_mcap(other, encoding, data)
    if cut:  # its end (the summary section, the footer) is lost; its channel and messages are whole
        other.write_bytes(other.read_bytes()[:-40])
    said = (
        f"{other} is an MCAP file but not an earl trace: it has no /earl/run topic (its topics: /odom); "
        "`earl run --trace FILE.mcap` writes one"
    )
    summary = earl_cli("trace", "summary", str(other))
    assert summary.returncode == 1
    assert summary.stderr == f"earl trace: {said}\n"
    for named in ("odom.x", "counter/a.cs.count"):
        plot = earl_cli("plot", str(other), "--signal", named, "-o", str(tmp_path / "p.png"))
        assert plot.returncode == 1
        assert plot.stderr == f"earl plot: {said}\n"
    assert not (tmp_path / "p.png").exists()


def test_a_bit_flipped_in_a_trace_is_damage_said_as_such_not_other_numbers(tmp_path: Path) -> None:
    """The chunks' checksums were not checked: one bit flipped inside the compressed data gave a summary of
    1.858 s for a run of 0.1 s, and exit 0. Other files say what they are: a directory, a file of another
    kind, Python's own words for them no more."""
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "100ms", "--trace", str(trace)).returncode == 0
    data = bytearray(trace.read_bytes())
    damaged = tmp_path / "damaged.mcap"
    data[610] ^= 1  # inside the first chunk's compressed messages
    damaged.write_bytes(bytes(data))
    for command in (["trace", "summary"], ["plot"]):
        extra = ["--signal", "counter/a.cs.count", "-o", str(tmp_path / "p.png")] if command == ["plot"] else []
        result = earl_cli(*command, str(damaged), *extra)
        assert result.returncode == 1, result.stdout
        assert "is damaged: a checksum of its data does not match" in result.stderr, result.stderr
    text = tmp_path / "notes.mcap"
    text.write_text("a few\n")
    said = earl_cli("trace", "summary", str(text)).stderr
    assert "it does not begin as an MCAP file does" in said and "unpack" not in said
    (tmp_path / "runs").mkdir()
    directory = earl_cli("trace", "summary", str(tmp_path / "runs"))
    assert directory.returncode == 2 and "is a directory, not a trace" in directory.stderr


def test_a_damaged_trace_is_a_clear_error_for_summary_and_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Cut short or with bytes changed anywhere (a disk error, a copy that stopped): exit 1 and one line,
    whatever the MCAP reader or its decompressor raises on the way, or, for a file whose end is missing
    or damaged, what comes before the damage, with a line that says so."""
    from earl.cli.main import main

    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "200ms", "--trace", str(trace)).returncode == 0
    data = trace.read_bytes()
    damaged = tmp_path / "damaged.mcap"
    random = Random(7)
    cases = [data[:length] for length in (8, len(data) // 3, len(data) // 2, len(data) - 20)]
    for _ in range(60):
        changed = bytearray(data)
        for _ in range(random.randint(1, 6)):
            changed[random.randrange(len(changed))] = random.randrange(256)
        cases.append(bytes(changed))
    failures = 0
    for case in cases:
        damaged.write_bytes(case)
        for command in (
            ["trace", "summary", str(damaged)],
            ["plot", str(damaged), "--signal", "counter/a.relay/ve.back", "-o", str(tmp_path / "p.png")],
        ):
            code = main(command)
            output = capsys.readouterr()
            assert code in (0, 1), command
            if code == 1:
                failures += 1
                assert output.err.startswith(f"earl {command[0]}: "), output.err
                assert output.err.count("\n") == 1
            elif "no valid end" in " ".join((output.out + output.err).split()):
                failures += 1  # found, and read up to the damage
    assert failures >= len(cases)  # most damage is found: some changed bytes (in a padding, say) harm nothing


@pytest.mark.parametrize(("status", "code"), [("", 0), ("0", 0), ("3", 1), ("'gave up'", 1)])
def test_a_function_that_calls_sys_exit_ends_the_run_in_order(tmp_path: Path, status: str, code: int) -> None:
    spec = counter_whose_increment_then(
        tmp_path,
        f"    if inputs.count == 2:\n        import sys\n        sys.exit({status})\n",
    )
    trace = tmp_path / "run.mcap"
    result = earl_cli("run", str(spec), "--duration", "200ms", "--trace", str(trace))
    assert result.returncode == code, result.stderr
    assert "called sys.exit(" in result.stderr and "at 0.020 s" in result.stderr
    assert "Traceback" not in result.stderr
    assert "counter/a.cs" in result.stdout  # the summary of what ran
    assert earl_cli("trace", "summary", str(trace)).returncode == 0  # closed and readable


@pytest.mark.parametrize(
    ("old", "new", "code", "fragment"),
    [
        ('"counting.cs:increment"', '"counting.nowhere:increment"', "EARL-X002", "cannot be found (no module"),
        ('"counting.cs:increment"', '"counting.cs:incremnt"', "EARL-X004", "did you mean `increment`"),
        # said by `earl check` before anything is bound (EARL-E044); unchecked, by the binding (EARL-X001)
        ('"counting.cs:increment"', '"increment"', "EARL-E044", 'write `python "module:function"`'),
    ],
)
def test_code_that_is_not_where_the_spec_says_is_reported_at_the_spec_line(
    tmp_path: Path, old: str, new: str, code: str, fragment: str
) -> None:
    spec = counter_copy(tmp_path, old, new)
    line = next(n for n, text in enumerate(spec.read_text().splitlines(), 1) if "increment/pf(" in text)
    result = earl_cli("run", str(spec), "--duration", "10ms")
    assert result.returncode == 1
    output = result.stdout + result.stderr
    assert f"system.earl:{line}:" in output
    assert code in output and fragment in output
    assert "Traceback" not in output
    assert "nothing was executed" in output


def test_a_function_with_the_wrong_signature_is_refused_before_the_run(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "counting" / "cs.py").write_text(
        "def increment(inputs, outputs):\n    pass\n\n\ndef send(inputs, outputs, context):\n    pass\n\n\n"
        "def rest(inputs, outputs, context):\n    pass\n"
    )
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.load(spec))
    [diagnostic] = raised.value.diagnostics
    assert diagnostic.code == "EARL-X005"
    assert "calls `counting.cs:increment` with 3 arguments, but it is defined as `increment(inputs, outputs)`" in (
        diagnostic.message
    )
    assert diagnostic.location is not None and diagnostic.location.line > 1


def test_a_module_that_fails_to_import_is_reported_with_its_error(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "counting" / "cs.py").write_text("raise ImportError('the lab printer is offline')\n")
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.load(spec))
    assert any("the lab printer is offline" in d.message and d.code == "EARL-X003" for d in raised.value.diagnostics)


REST = "\n\ndef send(inputs, outputs, context):\n    pass\n\n\ndef rest(inputs, outputs, context):\n    pass\n"


@pytest.mark.parametrize(
    ("increment", "code", "fragment"),
    [
        ("async def increment(inputs, outputs, context):\n    pass\n", "EARL-X005", "a coroutine function"),
        ("def increment(inputs, outputs, context):\n    yield\n", "EARL-X005", "a generator function"),
        ("class increment:\n    def __init__(self, a, b, c):\n        pass\n", "EARL-X005", "a class"),
        ("increment = None\n", "EARL-X004", "which is a NoneType, not a function"),
        ("import sys\nsys.exit(4)\n", "EARL-X003", "it called sys.exit(4) while being imported"),
        ("class Odd(BaseException):\n    pass\n\nraise Odd('no')\n", "EARL-X003", "Odd: no (/"),
        ("def increment(inputs, outputs, context)\n    pass\n", "EARL-X003", "SyntaxError"),
        ("import no_such_helper_module\n", "EARL-X003", "No module named 'no_such_helper_module' (/"),
    ],
    ids=["async", "generator", "class", "None", "sys.exit", "BaseException", "syntax", "import inside"],
)
def test_code_the_runtime_cannot_call_as_a_function_is_refused_before_the_run(
    tmp_path: Path, increment: str, code: str, fragment: str
) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "counting" / "cs.py").write_text(increment + REST)
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.load(spec))
    diagnostic = raised.value.diagnostics[0]  # the first function the module fails to give
    assert (diagnostic.code, fragment in diagnostic.message) == (code, True), diagnostic.message
    assert "<frozen" not in diagnostic.message


@pytest.mark.parametrize(
    ("raising", "message"),
    [
        ("class Odd(BaseException):\n    pass\n", "`increment/pf` raised Odd: odd"),
        (
            "class Odd(Exception):\n    def __str__(self):\n        raise RuntimeError\n",
            "`increment/pf` raised Odd: (its message cannot be shown: its __str__ failed)",
        ),
        ("Odd = GeneratorExit\n", "`increment/pf` raised GeneratorExit: odd"),
    ],
    ids=["BaseException", "broken __str__", "GeneratorExit"],
)
def test_any_exception_of_a_function_is_its_fault_and_the_run_goes_on(
    tmp_path: Path, raising: str, message: str
) -> None:
    spec = counter_whose_increment_then(
        tmp_path,
        "    if inputs.count == 1:\n        raise Odd('odd')\n",
        prelude=raising + "\n\n",
    )
    simulation = earl.simulate(earl.load(spec))
    simulation.advance_to(0.05)
    simulation.close()
    assert simulation.faults and simulation.faults[0].message == message
    assert simulation.state_of("counter/a.display/re").iterations == 6  # everything else ran on


PLANT = """\
class Plant:
    def advance(self, seconds):
        if seconds > 0.03 and {advance}:
            raise RuntimeError("physics diverged")

    def close(self):
        if {close}:
            raise RuntimeError("the viewer is gone")


def make(system, seed):
    return Plant()
"""


@pytest.mark.parametrize(
    ("advance", "close", "fragment"),
    [
        (True, False, "the environment's advance(0.030000) raised RuntimeError: physics diverged at 0.030 s"),
        (False, True, "the environment's close() raised RuntimeError: the viewer is gone"),
    ],
)
def test_an_environment_that_fails_ends_the_run_with_one_line_and_a_readable_trace(
    tmp_path: Path, advance: bool, close: bool, fragment: str
) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "plant.py").write_text(PLANT.format(advance=advance, close=close))
    (spec.parent / "run.toml").write_text('environment = "plant:make"\n')
    trace = tmp_path / "run.mcap"
    result = earl_cli("run", str(spec), "--duration", "100ms", "--trace", str(trace))
    assert result.returncode == 1, result.stderr
    assert fragment in result.stderr
    assert "Traceback" not in result.stderr
    assert earl_cli("trace", "summary", str(trace)).returncode == 0


def test_a_simulation_stopped_inside_an_instant_refuses_to_go_on(tmp_path: Path) -> None:
    """A KeyboardInterrupt raised in a function leaves its subsystem halfway through an iteration: going on
    would silently skip the rest of it (the subsystem used to stop for good, with no word)."""
    spec = counter_whose_increment_then(
        tmp_path,
        "    if inputs.count == 1:\n        raise KeyboardInterrupt\n",
    )
    simulation = earl.simulate(earl.load(spec))
    with pytest.raises(KeyboardInterrupt):
        simulation.advance_to(0.05)
    with pytest.raises(RuntimeError, match=r"stopped inside an instant \(KeyboardInterrupt at 0\.010000 s\)"):
        simulation.advance_to(0.1)
    assert simulation.state_of("counter/a.cs").state == "counting"  # what it reached can still be read
    simulation.close()


def test_modules_next_to_the_spec_named_like_earl_or_its_libraries_break_nothing(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    for name in ("earl", "msgpack", "json"):
        (spec.parent / f"{name}.py").write_text("raise RuntimeError('imported by mistake')\n")
    trace = spec.parent / "run.mcap"

    def earl_script(*arguments: str) -> subprocess.CompletedProcess[str]:
        # as the `earl` command runs: the current directory is not on the module path (-P)
        command = [sys.executable, "-P", "-m", "earl.cli.main", *arguments]
        return subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=spec.parent, check=False)

    result = earl_script("run", ".", "--duration", "50ms", "--trace", "run.mcap")
    assert result.returncode == 0, result.stderr
    assert earl_cli("trace", "summary", str(trace)).returncode == 0
    spec.write_text(spec.read_text().replace('"counting.cs:increment"', '"earl:increment"'))
    result = earl_script("run", ".", "--duration", "50ms")
    assert result.returncode == 1
    assert "EARL-X002" in result.stderr and "`earl` is also the name of a module that earl or Python" in result.stderr


def test_a_package_without_init_py_binds_again_in_the_same_process(tmp_path: Path) -> None:
    # a namespace package (no __init__.py) has no `__file__`: it was taken for one of Python's own modules
    # the second time the spec's code was bound, and refused as shadowed (EARL-X002)
    spec = counter_copy(tmp_path)
    (spec.parent / "counting" / "__init__.py").unlink()
    system = earl.load(spec)
    for _ in range(2):
        simulation = earl.simulate(system)
        simulation.advance_to(0.05)
        assert simulation.state_of("counter/a.cs").state == "finished"
        simulation.close()
    # and an environment from the same package, imported before the functions are bound
    (spec.parent / "counting" / "world.py").write_text("def make(system, seed):\n    return None\n")
    result = earl_cli("run", str(spec.parent), "--duration", "50ms", "--environment", "counting.world:make")
    assert result.returncode == 0, result.stderr
    assert "EARL-X002" not in result.stderr
    # another spec's package of the same name, also without __init__.py, is its own
    other = counter_copy(tmp_path / "other")
    (other.parent / "counting" / "__init__.py").unlink()
    functions = other.parent / "counting" / "cs.py"
    functions.write_text(functions.read_text() + "\nRAN_FROM_OTHER = True\n")
    simulation = earl.simulate(earl.load(other))
    simulation.close()
    assert getattr(sys.modules["counting.cs"], "RAN_FROM_OTHER", False)


def test_a_thread_the_specs_code_leaves_running_does_not_keep_earl_run_alive(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    functions = spec.parent / "counting" / "cs.py"
    functions.write_text(
        "import threading, time\n\nthreading.Thread(target=time.sleep, args=(3600,), name='poller').start()\n\n"
        + functions.read_text()
    )
    started = time.monotonic()
    result = earl_cli("run", str(spec), "--duration", "50ms")
    assert result.returncode == 0, result.stderr
    assert time.monotonic() - started < 60
    assert "threads still running at the end (poller) are stopped with the program" in result.stderr
    assert "counter/a.cs" in result.stdout  # the summary came out before the end


def test_the_checker_runs_first_and_its_errors_stop_the_run(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path, "counterRobot/r {\n    counter/a\n}", "")
    marker = tmp_path / "ran"
    (spec.parent / "counting" / "cs.py").write_text(
        f"from pathlib import Path\nPath({str(marker)!r}).write_text('imported')\n"
        "def increment(i, o, c): pass\ndef send(i, o, c): pass\ndef rest(i, o, c): pass\n"
    )
    result = earl_cli("run", str(spec), "--duration", "10ms")
    assert result.returncode == 1
    assert "EARL-E001" in result.stdout + result.stderr
    assert not marker.exists()  # a spec with errors never imports its code


@pytest.mark.parametrize(
    ("arguments", "fragment"),
    [
        (["--duration", "ten seconds"], "is not a duration"),
        (["--duration", "1e400s"], "is too long: a duration is at most"),  # infinite as a float
        (["--duration=-1s"], "must be positive"),
        (["--duration="], "the duration is empty"),  # not the default 10 s
        (["--duration", " "], "the duration is empty"),
        (["--agents", ","], "--agents names no agent"),
        (
            ["--plot", "/nonexistent/dir/x.png", "--signal", "counter/a.cs.count"],
            "the directory `/nonexistent/dir` does",
        ),
        (["--trace", "/nonexistent/dir/x.mcap"], "cannot write the trace /nonexistent/dir/x.mcap: the directory"),
        (["--record-memory", "counter/a.nothing", "--trace", "t.mcap"], "names no subsystem"),
        (["--param", "LIMIT"], "NAME=VALUE"),
    ],
)
def test_usage_errors_exit_2_with_one_line(tmp_path: Path, arguments: list[str], fragment: str) -> None:
    result = earl_cli("run", str(SPECS / "counter"), *arguments, cwd=tmp_path)
    assert result.returncode == 2
    assert fragment in result.stderr
    assert "Traceback" not in result.stderr


def realtime_run_under_way(
    trace: Path, spec: Path = SPECS / "counter", own_group: bool = False
) -> subprocess.Popen[str]:
    """`earl run` of the counter in real time for a minute, a second after its trace appeared; `own_group`:
    in a process group of its own, as `timeout` or a terminal starts it."""
    process = subprocess.Popen(
        [*EARL, "run", str(spec), "--realtime", "--duration", "60s", "--trace", str(trace)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=own_group,
    )
    deadline = time.monotonic() + 30
    while not trace.exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)
    return process


def test_ctrl_c_stops_the_run_cleanly_and_the_trace_stays_readable(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    process = realtime_run_under_way(trace)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert "interrupted at" in stderr
    assert "Traceback" not in stderr
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "counting,finished" in summary.stdout


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_a_stop_signal_to_the_whole_process_group_leaves_a_readable_trace(tmp_path: Path, stop: int) -> None:
    """`timeout`, a closed terminal and Ctrl-C signal every process of the group, the trace's writer too:
    the writer ignores them and finishes the file when the run, stopped in order, says so."""
    trace = tmp_path / "run.mcap"
    process = realtime_run_under_way(trace, own_group=True)
    os.killpg(process.pid, stop)
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert "interrupted at" in stderr and "Traceback" not in stderr
    # "Ctrl-C again" is advice for a terminal, not for the signals `timeout` and `earl launch` send
    assert ("Ctrl-C again to stop at once" in stderr) == (stop == signal.SIGINT), stderr
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "counting,finished" in summary.stdout


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT])
def test_a_stop_signal_as_the_trace_is_opened_still_leaves_a_readable_trace(tmp_path: Path, stop: int) -> None:
    """The signal comes as the trace's writer starts, before the run (and the writer) handle it: the
    writer, in a session of its own, never sees it and finishes the file when the pipe closes; the run
    ends with 130, not SIGTERM's silent 143."""
    trace = tmp_path / "run.mcap"
    process = subprocess.Popen(
        [*EARL, "run", str(SPECS / "counter"), "--realtime", "--duration", "60s", "--trace", str(trace)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 30
    while not trace.exists() and time.monotonic() < deadline:
        time.sleep(0.002)
    os.killpg(process.pid, stop)
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr and "cannot write the trace" not in stderr
    if not trace.exists():  # stopped before the run started: said, and no empty trace left behind
        assert "interrupted before the run started; nothing was executed; no trace was written" in stderr
        return
    deadline = time.monotonic() + 30
    summary = earl_cli("trace", "summary", str(trace))
    while summary.returncode != 0 and time.monotonic() < deadline:  # the writer may still be finishing
        time.sleep(0.2)
        summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr


def test_ctrl_c_stops_the_run_even_when_the_specs_code_swallows_it(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    functions = spec.parent / "counting" / "cs.py"
    functions.write_text(
        "import time\n\n"
        + functions.read_text().replace(
            "def rest(inputs, outputs, context):\n",
            "def rest(inputs, outputs, context):\n    try:\n        time.sleep(0.005)\n    except:  # noqa: E722\n        pass\n",
        )
    )
    trace = tmp_path / "run.mcap"
    process = realtime_run_under_way(trace, spec.parent)
    started = time.monotonic()
    process.send_signal(signal.SIGINT)
    try:
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    assert time.monotonic() - started < 15  # at the next of the run's 200 steps (0.3 s), not after 60 s
    assert earl_cli("trace", "summary", str(trace)).returncode == 0


def test_text_of_the_specs_code_is_printed_as_it_is_never_as_markup(tmp_path: Path) -> None:
    """An exception's message goes to the closing summary and `earl trace summary` unchanged: a Rich
    tag in it (`[/dev/ttyUSB0]` closes one) neither fails nor vanishes; a huge one is cut for the terminal."""
    spec = counter_whose_increment_then(
        tmp_path,
        "    if inputs.count == 1:\n"
        "        raise OSError('cannot open [/dev/ttyUSB0] as [bold]root[/bold]' + 'x' * 3_000_000)\n",
    )
    trace = tmp_path / "run.mcap"
    result = earl_cli("run", str(spec), "--duration", "100ms", "--trace", str(trace))
    assert result.returncode == 0, result.stderr
    assert "cannot open [/dev/ttyUSB0] as [bold]root[/bold]" in result.stdout
    assert "more characters; the trace has them all" in result.stdout
    assert len(result.stdout) < 10_000
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "cannot open [/dev/ttyUSB0] as [bold]root[/bold]" in summary.stdout


def test_a_message_that_is_not_utf8_text_is_recorded_escaped_and_the_trace_stays_whole(tmp_path: Path) -> None:
    """A file name of undecodable bytes in an exception's message (a lone surrogate) used to lose the trace."""
    spec = counter_whose_increment_then(
        tmp_path,
        "    if inputs.count == 1:\n        raise FileNotFoundError('cannot open ' + os.fsdecode(b'/dev/tty\\xff'))\n",
        prelude="import os\n\n",
    )
    trace = tmp_path / "run.mcap"
    result = earl_cli("run", str(spec), "--duration", "100ms", "--trace", str(trace))
    assert result.returncode == 0, result.stderr
    summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    assert "counter/a.display/re" in summary.stdout  # the trace is whole: every subsystem to the end
    assert "cannot open /dev/tty\\udcff" in summary.stdout


def test_a_message_that_is_not_utf8_text_in_a_trace_written_to_a_stream(tmp_path: Path) -> None:
    import io

    from earl.runtime.trace_reader import summarise

    spec = counter_whose_increment_then(
        tmp_path,
        "    raise OSError(os.fsdecode(b'/dev/tty\\xff'))\n",
        prelude="import os\n\n",
    )
    stream = io.BytesIO()
    simulation = earl.simulate(earl.load(spec), trace=stream)
    simulation.advance_to(0.05)
    simulation.close()
    (tmp_path / "api.mcap").write_bytes(stream.getvalue())
    faults = summarise(tmp_path / "api.mcap").faults
    assert faults and faults[0]["message"].endswith("/dev/tty\udcff")


def test_a_trace_never_replaces_a_file_that_is_not_a_trace(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    before = spec.read_bytes()
    result = earl_cli("run", str(spec.parent), "--duration", "10ms", "--trace", str(spec))
    assert result.returncode == 2
    assert "the file exists and is not an MCAP trace" in result.stderr
    assert spec.read_bytes() == before
    trace = tmp_path / "run.mcap"
    for _ in range(2):  # an earlier trace is replaced
        assert earl_cli("run", str(spec.parent), "--duration", "10ms", "--trace", str(trace)).returncode == 0


def summary_once_finished(process: subprocess.Popen[str], trace: Path) -> subprocess.CompletedProcess[str]:
    """`earl trace summary` of the trace of a run that was killed, once its writer has finished the file."""
    process.communicate(timeout=30)
    summary = earl_cli("trace", "summary", str(trace))
    deadline = time.monotonic() + 20
    while summary.returncode != 0 and time.monotonic() < deadline:  # the writer may still be finishing
        time.sleep(0.2)
        summary = earl_cli("trace", "summary", str(trace))
    assert summary.returncode == 0, summary.stderr
    return summary


def test_a_run_killed_with_sigkill_still_leaves_a_readable_trace(tmp_path: Path) -> None:
    """The trace's own process finishes the file when the run's process disappears."""
    trace = tmp_path / "run.mcap"
    process = realtime_run_under_way(trace)
    time.sleep(1.5)
    process.kill()
    summary = summary_once_finished(process, trace)
    assert "counter/a.cs" in summary.stdout
    # the counts are written at the end, which never came: unknown, not 0
    assert "without the run's end (the run was killed)" in summary.stdout
    # killed 2.5 s after the trace appeared: the batches sent every 0.2 s reached the writer (unflushed,
    # they waited in this process's 8 KiB pipe buffer and died with it: the trace ended near 0.56 s)
    ended = re.search(r"the trace ends at ([0-9.]+) s", " ".join(summary.stdout.split()))
    assert ended is not None and float(ended.group(1)) >= 1.2, summary.stdout


HOLDS = """\
system holds
r/r { x/a }
x/a {
    cs {
        period 100 ms
        go/pp = true
        never/pp = false
        start/bb {
            tf = {}
            tc = go/pp
        }
        hold/bb {
            tf = {}
            tc = never/pp
        }
        fsm {
            initial start
            state start: start/bb
            state hold: hold/bb
            start -> hold when go/pp
        }
    }
}
"""


def test_a_run_killed_while_it_records_nothing_more_has_its_earlier_records_in_the_trace(tmp_path: Path) -> None:
    """A batch went to the trace's process only with the next record after it was due: a run that went on
    holding a state recorded nothing more, and a kill lost what it had recorded (seconds of a real run;
    here the transition into `hold` at 0.1 s). It now goes while the run waits for its next instant."""
    spec = tmp_path / "holds" / "system.earl"
    spec.parent.mkdir()
    spec.write_text(HOLDS)
    trace = tmp_path / "run.mcap"
    process = realtime_run_under_way(trace, spec.parent)
    process.kill()
    summary = summary_once_finished(process, trace)
    assert "start,hold" in summary.stdout, summary.stdout


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full here")
def test_a_trace_on_a_full_disk_stops_the_run_with_one_line_and_exit_1() -> None:
    result = earl_cli(
        "run", str(SPECS / "counter"), "--duration", "2s", "--trace", "/dev/full", "--record-memory", "all"
    )
    assert result.returncode == 1, result.stderr
    assert "earl run: cannot write the trace /dev/full: No space left on device" in result.stderr
    assert "Traceback" not in result.stderr


def test_run_help_teaches_with_examples() -> None:
    result = earl_cli("run", "--help")
    assert result.returncode == 0
    assert "examples:" in result.stdout and "exit codes:" in result.stdout and "run.toml" in result.stdout
    # as docs/runtime.md says them
    assert (
        "or the --plot or run.toml's report asked for failed at the end (the run and its trace are whole)"
        in " ".join(result.stdout.split())
    )
    # as docs/distributed.md says it
    assert "with --transport zenoh also when a link's messages were refused for another data type" in " ".join(
        result.stdout.split()
    )


@pytest.fixture(autouse=True)
def _wide_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    # Rich wraps tables to the terminal; a wide one keeps each row on one line for the assertions
    monkeypatch.setenv("COLUMNS", "200")


@pytest.mark.parametrize(
    ("setting", "fragment"),
    [
        ("seed = -5", "`seed` is a whole number >= 0, not -5"),
        ("seed = true", "`seed` is a whole number >= 0"),
        ("duration = -3", "`duration` is a duration such as"),
        ('duration = "soon"', "`soon` is not a duration"),
        ("environment = 5", '`environment` is a "module:function" string, not 5'),
        ('environment = ["counting.cs:increment"]', '`environment` is a "module:function" string, not ["counting'),
        ('record_memory = "counter/a.cs"', '`record_memory` is a list of strings, e.g. ["manip/a.cs"], not "counter'),
        ('plot = ""', '`plot` is a list of strings, e.g. ["manip/a.cs.count"], not ""'),
        ("colour = 1", "unknown setting `colour` (known: duration, environment, plot, record_links, record_memory"),
        ('Duration = "1s"', "unknown setting `Duration`; did you mean `duration`? (known: "),
        ("[plot]", '`plot` is a list of strings, e.g. ["manip/a.cs.count"], not a table'),
        ('seed = "x"', '`seed` is a whole number >= 0, not "x"'),
        ("duration = true", '`duration` is a duration such as "13s" or a positive number of seconds, not true'),
        ('duration = ""', "`duration`: the duration is empty; write e.g. `10s`"),
        ('environment = ""', '`environment` names no environment: name one as "MODULE:FACTORY", or "none" for none'),
        ('report = " "', '`report` names no function: name one as "MODULE:FUNCTION", or leave `report` out'),
        ('plot = [""]', '`plot` has an empty string in [""]: each names a signal, e.g. ["manip/a.cs.count"]'),
        ('record_links = ["counter/a:*", ""]', '`record_links` has an empty string in ["counter/a:*", ""]: each'),
        ('record_memory = [""]', '`record_memory` has an empty string in [""]: each names a subsystem'),
        ("seed =", "3:7: not valid TOML: Invalid value"),
    ],
)
def test_a_run_toml_setting_of_the_wrong_kind_is_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], setting: str, fragment: str
) -> None:
    """One line naming the file, the line and the key, what is expected and what is written (as TOML
    writes it: `true`, `"x"`). `environment = ""` was EARL-X001 (exit 1) and `report = ""` was ignored;
    an empty string in a list named no subsystem (or matched no link, recording none); the message
    named neither the line nor the file as the spec names it; `true` was shown as `True`."""
    from earl.cli.main import main

    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text("# the counter's defaults\n\n" + setting + "\n")
    assert main(["run", str(spec), "--duration", "10ms", "--no-progress"]) == 2
    error = capsys.readouterr().err
    where = f"{spec.parent / 'run.toml'}:3"
    assert error.startswith(f"earl: error: {where}") and len(error.splitlines()) == 1, error
    assert fragment in error, error


def test_run_toml_is_read_next_to_the_spec_a_symbolic_link_points_to(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """As the spec's imports and Python modules: next to the file itself."""
    from earl.cli.main import main

    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text("colour = 1\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "system.earl").symlink_to(spec)
    assert main(["run", str(elsewhere / "system.earl"), "--duration", "10ms", "--no-progress"]) == 2
    assert "unknown setting `colour`" in capsys.readouterr().err


@pytest.mark.parametrize("seed", ["-1", "x", "1.5", "٣", "1_000", "²", "-+5", "+-5", "5 "])
def test_a_seed_that_is_not_a_whole_number_from_zero_is_a_usage_error(seed: str) -> None:
    result = earl_cli("run", str(SPECS / "counter"), f"--seed={seed}", "--duration", "10ms")
    assert result.returncode == 2
    assert "argument --seed" in result.stderr and "Traceback" not in result.stderr


def test_a_seed_written_with_a_plus_sign_is_taken_as_param_and_run_toml_take_it() -> None:
    plus = earl_cli("run", str(SPECS / "counter"), "--seed=+5", "--duration", "10ms")
    plain = earl_cli("run", str(SPECS / "counter"), "--seed=5", "--duration", "10ms")
    assert plus.returncode == 0, plus.stderr

    def table(result: subprocess.CompletedProcess[str]) -> list[str]:  # the wall time differs run to run
        return [line for line in result.stdout.splitlines() if "wall time" not in line]

    assert table(plus) == table(plain)


def test_an_empty_trace_file_is_said_to_be_empty_with_why_a_run_leaves_one(tmp_path: Path) -> None:
    """The run's process makes the trace file and its writer fills it from the first batch: a run killed
    with SIGKILL before that (in its first 0.2 s, or while it waited for its peers) leaves 0 bytes, which
    was said as "it ends early"."""
    empty = tmp_path / "t.mcap"
    empty.write_bytes(b"")
    for command in (["trace", "summary", str(empty)], ["plot", str(empty), "--signal", "a/a.cs.x", "-o", "p.png"]):
        result = earl_cli(*command)
        assert result.returncode == 1, result.stderr
        assert "is empty: nothing was recorded in it" in result.stderr and "Traceback" not in result.stderr


def test_a_stop_signal_ends_the_run_between_two_instants(tmp_path: Path) -> None:
    """Every function takes 2 ms, so a signal most likely comes inside an instant: the run still ends
    after it, every subsystem having run the same instants (all three run every 10 ms)."""
    from earl.runtime.trace_reader import _messages

    spec = counter_copy(tmp_path)
    for module in ("cs", "relay", "display"):
        functions = spec.parent / "counting" / f"{module}.py"
        text = functions.read_text()
        text = re.sub(r"(def \w+\(inputs, outputs, context\):\n)", r"\1    time.sleep(0.002)\n", text)
        functions.write_text("import time\n\n" + text)
    trace = tmp_path / "run.mcap"
    process = subprocess.Popen(
        [*EARL, "run", str(spec), "--duration", "600s", "--trace", str(trace)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        time.sleep(3.0)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    assert "stopping after this instant" in stderr and "interrupted at" in stderr
    [end] = [data for topic, _, _, data in _messages(trace, ["/earl/run"]) if "iterations" in data]
    counts = {entry["iterations"] for entry in end["iterations"]}
    assert len(counts) == 1 and counts != {0}, end["iterations"]


ARRAY_SENDER = """\
system arrays

a/a {
    cs {
        period 10 ms
        v/ob: double[2]
        t/m: double = 0.0
        false/pp = false
        tick/pf(t/mi -> t/mo) = python "arrays:tick"
        emit/pf(t/mi -> v/ob) = python "arrays:emit"
        run/bb {
            tf = {tick/pf} then {emit/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

b/a {
    cs {
        period 10 ms
        v/ib: double[2]
        x/m: double = 0.0
        false/pp = false
        take/pf(v/ib -> x/mo) = python "arrays:take"
        run/bb {
            tf = {take/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

link a,b: a/a.cs.v -> b/a.cs.v

r/r {
    a/a
    b/a
    link a,b
}
"""


def test_an_element_of_an_array_output_buffer_is_plotted_by_its_index(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text(ARRAY_SENDER)
    (tmp_path / "arrays.py").write_text(
        "def tick(inputs, outputs, context):\n    outputs.t = inputs.t + 1.0\n\n\n"
        "def emit(inputs, outputs, context):\n    outputs.v = (inputs.t, 2.0)\n\n\n"
        "def take(inputs, outputs, context):\n    outputs.x = inputs.v[0]\n"
    )
    trace = tmp_path / "run.mcap"
    ran = earl_cli("run", str(tmp_path), "--duration", "50ms", "--trace", str(trace))
    assert ran.returncode == 0, ran.stderr
    plot = earl_cli("plot", str(trace), "--signal", "a/a.cs.v[0]", "-o", str(tmp_path / "v.png"))
    assert plot.returncode == 0, plot.stderr
    wrong = earl_cli("plot", str(trace), "--signal", "a/a.cs.v.value[0]", "-o", str(tmp_path / "w.png"))
    assert wrong.returncode == 1 and "it is an array; name an element, `v[0]`, or every one, `v[*]`" in wrong.stderr


@pytest.mark.parametrize(
    ("options", "said"),
    [
        (["--signal", "counter/a.cs.count"], "--signal needs --plot FILE.png: it names what the plot draws"),
        (["--record-memory", "all"], "--record-memory needs --trace FILE.mcap: it chooses what the trace records"),
        (["--record-links", "*"], "--record-links needs --trace FILE.mcap: it chooses what the trace records"),
        (
            ["--record-memory", "all", "--record-links", "*"],
            "--record-memory and --record-links need --trace FILE.mcap: they choose what the trace records",
        ),
    ],
)
def test_an_option_without_the_one_it_goes_with_is_a_usage_error(tmp_path: Path, options: list[str], said: str) -> None:
    """`--signal` without `--plot` went nowhere without a word; `--record-*` without a trace recorded
    nothing and ran on (exit 0), as `--wait-for-peers` without `--transport zenoh` is refused."""
    result = earl_cli("run", str(SPECS / "counter"), "--duration", "20ms", *options, cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert result.stderr.startswith(f"earl: error: {said}") and len(result.stderr.splitlines()) == 1, result.stderr
    assert result.stdout == "" and list(tmp_path.iterdir()) == []  # refused before the run
    # with what they go with, they are used: --plot writes the trace they choose from
    plotted = earl_cli(
        "run",
        str(SPECS / "counter"),
        "--duration",
        "20ms",
        *options,
        *([] if "--signal" in options else ["--signal", "counter/a.cs.count"]),
        "--plot",
        str(tmp_path / "p.png"),
    )
    assert plotted.returncode == 0, plotted.stderr
    assert (tmp_path / "p.png").is_file() and (tmp_path / "p.mcap").is_file()


def test_a_record_links_pattern_that_matches_no_link_is_said(tmp_path: Path) -> None:
    traced = earl_cli(
        "run",
        str(SPECS / "counter"),
        "--duration",
        "20ms",
        "--trace",
        str(tmp_path / "t.mcap"),
        "--record-links",
        "counter/a:relay*",
        "--record-links",
        "nomatch*",
    )
    assert traced.returncode == 0
    assert "--record-links `nomatch*` matches no link (the links: counter/a:cs,relay" in traced.stderr
    assert "`counter/a:relay*`" not in traced.stderr


def test_a_record_links_glob_with_a_character_class_records_the_links_it_matches(tmp_path: Path) -> None:
    """`[mg]` is a shell glob's character class, `m` or `g`: it was taken for a link family's index
    variable, so the pattern matched no link and the trace kept none (exit 0)."""
    from earl.runtime.trace_reader import topics

    trace = tmp_path / "t.mcap"
    ran = earl_cli("run", str(EXAMPLE), "--duration", "0.2s", "--trace", str(trace), "--record-links", "task,[mg]*")
    assert ran.returncode == 0, ran.stderr
    assert "matches no link" not in ran.stderr
    assert sorted(topic for topic in topics(trace) if topic.startswith("/link/")) == [
        "/link/task,grip",
        "/link/task,manip",
    ]


def test_a_plot_or_trace_into_a_directory_that_does_not_exist_is_refused_before_the_run(tmp_path: Path) -> None:
    """Whether the trace goes beside the plot or elsewhere: one line, exit 2, and no directory made."""
    missing = tmp_path / "nodir"
    plot = ["--plot", str(missing / "p.png"), "--signal", "counter/a.cs.count"]
    for extra in ([], ["--trace", str(tmp_path / "ok.mcap")]):
        result = earl_cli("run", str(SPECS / "counter"), "--duration", "1000s", *plot, *extra)
        assert result.returncode == 2, result.stdout + result.stderr
        assert result.stderr.strip().splitlines() == [
            f"earl: error: --plot '{missing / 'p.png'}': the directory `{missing}` does not exist"
        ]
        assert not missing.exists() and not (tmp_path / "ok.mcap").exists()
    trace = earl_cli("run", str(SPECS / "counter"), "--trace", str(missing / "x.mcap"))
    assert trace.returncode == 2
    said = trace.stderr.strip()
    assert said == f"earl: error: cannot write the trace {missing / 'x.mcap'}: the directory `{missing}` does not exist"
    assert (
        earl_cli("run", str(SPECS / "counter"), "--duration", "20ms", "--trace", str(tmp_path / "t.mcap")).returncode
        == 0
    )
    drawn = earl_cli("plot", str(tmp_path / "t.mcap"), "--signal", "counter/a.cs.count", "-o", str(missing / "p.png"))
    assert drawn.returncode == 2 and "the directory" in drawn.stderr and not missing.exists()


@pytest.mark.parametrize("given", ["", " "])
@pytest.mark.parametrize(
    ("command", "said"),
    [
        (["plot", "run.mcap", "--signal", "counter/a.cs.count", "-o"], "-o names no file: name one, e.g. -o plot.png"),
        (["export", "sysml", str(SPECS / "counter"), "-o"], "-o names no file: name one, e.g. -o model.sysml"),
        (
            ["diagram", str(SPECS / "counter"), "--view", "system", "-o"],
            "-o names no file: name one, e.g. -o system.svg",
        ),
        (["doc", str(SPECS / "counter"), "-o"], "-o names no directory: name one, e.g. -o site/"),
        (["run", str(SPECS / "counter"), "--duration", "20ms", "--trace"], "--trace names no file"),
        (["run", str(SPECS / "counter"), "--duration", "20ms", "--signal", "counter/a.cs.count", "--plot"], "--plot"),
    ],
)
def test_an_empty_output_is_a_usage_error_of_one_line_for_every_command(
    tmp_path: Path, command: list[str], said: str, given: str
) -> None:
    """`-o ""` (`-o "$OUT"` with OUT unset) was the directory here to `earl doc`, which wrote its site
    there, standard output to `earl diagram`, "a directory" to `earl plot` and `earl export`, and no
    plot at all to `earl run --plot`: every command refuses it alike, before anything is written."""
    (tmp_path / "run.mcap").write_bytes(b"")  # what `earl plot` reads is looked at after its -o
    result = earl_cli(*command, given, cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert result.stderr.splitlines() == [result.stderr.strip()] and result.stderr.startswith("earl: error: ")
    assert said in result.stderr
    assert [path.name for path in tmp_path.iterdir()] == ["run.mcap"]  # nothing written here


ZENOH_PROCESS = ["--agents", "counter/a", "--transport", "zenoh"]


@pytest.mark.parametrize(
    ("command", "said"),
    [
        (["run", str(SPECS / "pendulum"), "--environment", ""], "--environment names no environment: name one as"),
        (["run", str(SPECS / "counter"), *ZENOH_PROCESS, "--deployment", ""], "--deployment names no file"),
        (["run", str(SPECS / "counter"), *ZENOH_PROCESS, "--zenoh-config", " "], "--zenoh-config names no file"),
        (["run", str(SPECS / "counter"), "--record-links", "", "--trace", "t.mcap"], "--record-links names no link"),
        (
            ["run", str(SPECS / "counter"), "--record-links", "*", "--record-links", " ", "--trace", "t.mcap"],
            "--record-links names no",
        ),
        (
            ["run", str(SPECS / "counter"), "--record-memory", "", "--trace", "t.mcap"],
            "--record-memory names no subsystem",
        ),
        (["launch", str(SPECS / "counter"), "--deployment", ""], "--deployment names no file: name one, e.g."),
        (["diagram", str(SPECS / "counter"), "--view", "fsm", "--target", ""], "--target names no element"),
    ],
)
def test_an_empty_option_is_not_taken_for_the_option_left_out(tmp_path: Path, command: list[str], said: str) -> None:
    """`--environment ""` ran run.toml's environment, `--deployment ""` read the deploy.toml beside the
    spec (or said it was missing), `--target ""` was "`` is not a target: `` should look like …",
    `--record-links ""` said it matched no link and ran on, recording no link at all, `--record-memory ""`
    was "names no subsystem of this run:  (subsystems are named like …)"."""
    result = earl_cli(*command, cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert result.stderr.startswith(f"earl: error: {said}") and len(result.stderr.splitlines()) == 1, result.stderr


def test_an_empty_spec_or_trace_is_named_as_such_not_as_a_directory(tmp_path: Path) -> None:
    """`Path("")` is the directory here: an empty SPEC was "a directory without a system.earl"."""
    for command in (["check", ""], ["export", "sysml", " "], ["doc", "", "-o", "site"]):
        result = earl_cli(*command, cwd=tmp_path)
        assert result.returncode == 2
        assert result.stderr == "earl: error: SPEC is empty: name the .earl file, or a directory with a system.earl\n"
    for command in (["plot", "", "--signal", "counter/a.cs.count"], ["trace", "summary", ""]):
        result = earl_cli(*command, cwd=tmp_path)
        assert result.returncode == 2
        assert result.stderr.startswith("earl: error: FILE.mcap is empty: name the trace"), result.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_record_links_pattern_of_run_toml_that_matches_no_link_is_said(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text('record_links = ["filter,*", "counter/a:relay*"]\n')
    trace = str(tmp_path / "t.mcap")
    result = earl_cli("run", str(spec.parent), "--duration", "20ms", "--trace", trace)
    assert result.returncode == 0, result.stderr
    said = " ".join(result.stderr.split())
    assert "record_links `filter,*` in run.toml matches no link (the links: counter/a:cs,relay" in said
    assert "`counter/a:relay*`" not in said
    # the command line wins: run.toml's patterns are not used, so not checked either
    overridden = earl_cli("run", str(spec.parent), "--duration", "20ms", "--trace", trace, "--record-links", "*")
    assert overridden.returncode == 0 and "matches no link" not in overridden.stderr, overridden.stderr


def test_record_links_empty_in_run_toml_records_no_link_and_says_nothing_as_docs_runtime_md_advises(
    tmp_path: Path,
) -> None:
    page = " ".join((Path(__file__).parent.parent / "docs" / "runtime.md").read_text(encoding="utf-8").split())
    advice = page.split("to record no link,", 1)[1].split(";", 1)[0]
    assert "`record_links = []` in run.toml" in advice and "pattern" not in advice  # a pattern is warned of
    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text("record_links = []\n")
    trace = tmp_path / "t.mcap"
    result = earl_cli("run", str(spec.parent), "--duration", "20ms", "--trace", str(trace))
    assert result.returncode == 0 and "matches no link" not in result.stderr, result.stderr
    summary = earl_cli("trace", "summary", str(trace))
    assert "0 messages on links" in summary.stdout, summary.stdout


def test_run_toml_s_record_links_are_not_checked_against_the_links_of_some_agents_only() -> None:
    """The example's run.toml names links of every agent; a run of the grip agent has only its own."""
    result = earl_cli("run", str(EXAMPLE), "--agents", "grip/a", "--environment", "none", "--duration", "10ms")
    assert result.returncode == 0, result.stderr
    assert "matches no link" not in result.stderr


def test_a_stop_while_waiting_for_the_next_instant_is_made_at_once(tmp_path: Path) -> None:
    """Real time, periods of 20 s: the run sleeps between instants, and a stop must not wait for the next."""
    spec = counter_copy(tmp_path)
    spec.write_text(spec.read_text().replace("period 10 ms", "period 20 s"))
    process = subprocess.Popen(
        [*EARL, "run", str(spec.parent), "--realtime", "--duration", "120s", "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        time.sleep(4.0)
        started = time.monotonic()
        process.send_signal(signal.SIGTERM)
        process.send_signal(signal.SIGTERM)  # as `timeout` does: to the run and to its group, the same request
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    assert time.monotonic() - started < 5
    assert "interrupted at " in stderr and "trace is closed" not in stderr


def test_a_plot_records_the_links_of_the_output_buffers_it_draws(tmp_path: Path) -> None:
    """`forward` is an output buffer: its values are the messages on its link, which the plot records
    even when --record-links would leave it out."""
    png = tmp_path / "p.png"
    result = earl_cli(
        "run",
        str(SPECS / "counter"),
        "--duration",
        "20ms",
        "--plot",
        str(png),
        "--signal",
        "counter/a.relay/ve.forward",
        "--record-links",
        "nothing",
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert png.is_file()


def test_a_plot_that_cannot_be_drawn_makes_the_run_exit_1(tmp_path: Path) -> None:
    png = tmp_path / "p.png"
    # the only signal is an optional field the task agent first sends after 8 s
    result = earl_cli(
        "run",
        str(EXAMPLE),
        "--duration",
        "1s",
        "--no-progress",
        "--plot",
        str(png),
        "--signal",
        "task/a.cs.manipulatorCommand.jointPosSetpoint[*]",
    )
    assert result.returncode == 1, result.stderr
    assert "no plot" in result.stdout + result.stderr and not png.exists()


@pytest.mark.parametrize(
    ("signal_name", "fragment"),
    [
        ("manip/a.cs.currentJointPos[9]", "`currentJointPos` has elements 0 to 5 where the signal indexes it, not 9"),
        ("manip/a.cs.windingCurrent[7]", "`windingCurrent` has members 1..6"),
        ("manip/a.cs.currentJointPos.x", "`currentJointPos` has no field `x` where the signal names it"),
        (
            "manip/a.motorController[*]/ve.motorControllerState.currentMotorPos",
            "a signal names one subsystem; name each member of the family: "
            "`manip/a.motorController[1]/ve.motorControllerState.currentMotorPos`",
        ),
    ],
)
def test_run_plot_refuses_an_index_or_field_the_signal_s_element_lacks_before_the_run(
    tmp_path: Path, signal_name: str, fragment: str
) -> None:
    result = earl_cli(
        "run", str(EXAMPLE), "--duration", "100s", "--plot", str(tmp_path / "p.png"), "--signal", signal_name
    )
    assert result.returncode == 2 and fragment in result.stderr, result.stderr


def test_a_signal_without_a_value_in_a_short_run_is_left_out_of_the_plot_not_the_plot(tmp_path: Path) -> None:
    """run.toml's signals include an optional field the task agent first sends after 8 s: a 2 s run
    still draws the others, and says which one had no value."""
    png = tmp_path / "p.png"
    result = earl_cli("run", str(EXAMPLE), "--duration", "2s", "--plot", str(png), "--no-progress")
    assert result.returncode == 0, result.stdout + result.stderr
    assert png.is_file()
    said = " ".join((result.stdout + result.stderr).split())
    assert "`task/a.cs.manipulatorCommand.jointPosSetpoint[*]` had no value in this run" in said
    assert "drawn without it" in said


def test_a_trace_cut_short_is_read_up_to_the_cut(tmp_path: Path) -> None:
    """A run killed together with its writer leaves a file without its summary, its last chunk cut:
    the summary and the plot read every record before the cut; the summary says the run's end is
    missing."""
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "2s", "--trace", str(trace)).returncode == 0
    data = trace.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    summary = earl_cli("trace", "summary", str(cut))
    assert summary.returncode == 0, summary.stderr
    assert "counter/a.cs" in summary.stdout and "no valid end" in " ".join(summary.stdout.split())
    plot = earl_cli("plot", str(cut), "--signal", "counter/a.relay/ve.forward", "-o", str(tmp_path / "p.png"))
    assert plot.returncode == 0, plot.stderr
    assert (tmp_path / "p.png").is_file()


def test_trace_and_plot_on_one_file_is_a_usage_error(tmp_path: Path) -> None:
    same = tmp_path / "same.png"
    result = earl_cli("run", str(SPECS / "counter"), "--trace", str(same), "--plot", str(same), "--signal", "x")
    assert result.returncode == 2
    assert "--trace and --plot both name" in result.stderr and not same.exists()


def example_reporting_with(tmp_path: Path, report: str, code: str) -> Path:
    """The pick-and-place example, its run.toml's `report` naming `report`, with closing.py holding `code`."""
    example = tmp_path / "pick_and_place"
    shutil.copytree(EXAMPLE, example)
    settings = example / "run.toml"
    settings.write_text(re.sub(r'report = "[^"]*"', f'report = "{report}"', settings.read_text()))
    (example / "closing.py").write_text(code)
    return example


def test_run_toml_s_environment_without_its_factory_is_said_at_its_line(tmp_path: Path) -> None:
    spec = counter_copy(tmp_path)
    (spec.parent / "run.toml").write_text('duration = "10ms"\nenvironment = "counting.relay"\n')
    result = earl_cli("run", "counter", cwd=tmp_path)
    assert result.returncode == 1
    assert "error[EARL-X001]: `counting.relay` does not name a function: write `module:function`" in result.stderr
    assert "--> counter/run.toml:2:1" in result.stderr and 'environment = "counting.relay"' in result.stderr
    assert '`counting.relay` is a module: name its function after a colon, `"counting.relay:' in result.stderr
    # given on the command line, it is the command line's: no run.toml line
    result = earl_cli("run", "counter", "--environment", "counting.relay", cwd=tmp_path)
    assert result.returncode == 1 and "EARL-X001" in result.stderr and "run.toml" not in result.stderr


@pytest.mark.parametrize(
    ("code", "said"),
    [
        ("import sys\n\n\ndef summary(simulation):\n    sys.exit(5)\n", "called sys.exit(5); its text is lost"),
        ("def summary(simulation):\n    return 1 / 0\n", "failed: ZeroDivisionError: division by zero"),
    ],
)
def test_a_report_that_fails_at_the_end_exits_1_not_what_it_chose(tmp_path: Path, code: str, said: str) -> None:
    """The run and its trace are whole, but what run.toml asked for is missing: exit 1, as for a plot not drawn
    (and never the 5 the report's sys.exit chose)."""
    result = earl_cli("run", str(example_reporting_with(tmp_path, "closing:summary", code)), "--duration", "20ms")
    assert result.returncode == 1, result.stderr
    assert "ran 0.020 s of virtual time" in result.stdout
    assert f"the report `closing:summary` {said}" in result.stdout + result.stderr


@pytest.mark.parametrize(
    ("report", "code", "said", "hint"),
    [
        (
            "closing:sumary",
            "def summary(simulation):\n    return 'done'\n",
            "error[EARL-X004]: the run report names `sumary`, but the module `closing` has no such function",
            "did you mean `summary`?",
        ),
        (
            "closing:summary",
            "def summary():\n    return 'done'\n",
            "error[EARL-X005]: the run report calls `closing:summary` with 1 argument, but it is defined as "
            "`summary()`",
            "write it as `def summary(simulation) -> str`",
        ),
    ],
)
def test_a_report_that_cannot_be_bound_is_said_at_its_run_toml_line_before_the_run(
    tmp_path: Path, report: str, code: str, said: str, hint: str
) -> None:
    example = example_reporting_with(tmp_path, report, code)
    line = 1 + (example / "run.toml").read_text().split("\n").index(f'report = "{report}"')
    result = earl_cli("run", "pick_and_place", "--duration", "20ms", cwd=tmp_path)
    assert result.returncode == 1
    assert said in result.stderr and hint in result.stderr
    assert f"--> pick_and_place/run.toml:{line}:1" in result.stderr
    assert f'report = "{report}"' in result.stderr  # the line, quoted
    assert "virtual time" not in result.stdout  # nothing ran


def test_a_stop_before_the_run_never_removes_a_file_this_command_did_not_create(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while the spec is read: a file --trace names that was there before stays as it was."""
    import earl.lang.loader
    from earl.cli.main import main

    def interrupted(*_: object, **__: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(earl.lang.loader, "load", interrupted)
    victim = tmp_path / "notes.txt"
    victim.write_text("precious")
    assert main(["run", str(SPECS / "counter"), "--trace", str(victim)]) == 130
    assert victim.read_text() == "precious"
    assert "interrupted before the run started; nothing was executed\n" in capsys.readouterr().err


def _writers_of(trace: Path) -> list[str]:
    """The processes (Linux) whose command line names `trace`: its writer, while it runs."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                command = (entry / "cmdline").read_bytes()
            except OSError:
                continue  # ended meanwhile
            if b"earl.runtime.trace_process" in command and os.fsencode(trace) in command:
                found.append(entry.name)
    return found


def _after_the_writer(trace: Path) -> bool:
    """Whether the trace exists once its writer, if one is left, has ended (within 30 s)."""
    deadline = time.monotonic() + 30
    while _writers_of(trace) and time.monotonic() < deadline:
        time.sleep(0.05)
    return trace.exists()


@pytest.mark.skipif(not Path("/proc/self/cmdline").exists(), reason="finds the writer in /proc")
def test_a_stop_as_the_run_is_set_up_after_the_trace_is_opened_leaves_no_trace(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C (or SIGTERM) after the trace's writer started and before the run was set up: the command
    removed the file and said it wrote none, and the writer, left running, then wrote an empty trace there."""
    import earl.runtime.simulation
    from earl.cli.main import main

    def interrupted(*_: object, **__: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(earl.runtime.simulation, "Scheduler", interrupted)
    trace = tmp_path / "run.mcap"
    assert main(["run", str(SPECS / "counter"), "--duration", "1s", "--trace", str(trace)]) == 130
    said = f"interrupted before the run started; nothing was executed; no trace was written to {trace}\n"
    assert said in capsys.readouterr().err
    assert _writers_of(trace) == []  # stopped and waited for, not left to end when it will
    assert not _after_the_writer(trace)


def test_a_trace_writer_sent_nothing_leaves_no_file(tmp_path: Path) -> None:
    """A stop signal inside Popen, once the writer has started, leaves it unknown to the run, which removes
    the file: the writer, its input ended before anything came, made the file again with an empty trace."""
    trace = tmp_path / "run.mcap"
    writer = subprocess.run(
        [sys.executable, "-m", "earl.runtime.trace_process", str(trace)],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        timeout=60,
        check=False,
    )
    assert (writer.returncode, writer.stderr, trace.exists()) == (0, b"", False)


@pytest.mark.skipif(not Path("/proc/self/cmdline").exists(), reason="finds the writer in /proc")
def test_a_simulation_stopped_while_it_is_set_up_closes_its_environment_and_leaves_no_trace(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import earl.runtime.simulation

    def interrupted(*_: object, **__: object) -> None:
        raise KeyboardInterrupt

    class Environment:
        closed = False

        def close(self) -> None:
            self.closed = True

    monkeypatch.setattr(earl.runtime.simulation, "Scheduler", interrupted)
    trace = tmp_path / "run.mcap"
    environment = Environment()
    with pytest.raises(KeyboardInterrupt):
        earl.simulate(earl.load(str(SPECS / "counter")), environment=environment, trace=trace)
    assert environment.closed
    assert _writers_of(trace) == []
    assert not _after_the_writer(trace)


def test_a_trace_cut_before_its_first_whole_record_says_so(tmp_path: Path) -> None:
    trace = tmp_path / "run.mcap"
    assert earl_cli("run", str(SPECS / "counter"), "--duration", "300ms", "--trace", str(trace)).returncode == 0
    for length in (12, 40):
        cut = tmp_path / f"cut{length}.mcap"
        cut.write_bytes(trace.read_bytes()[:length])
        summary = earl_cli("trace", "summary", str(cut))
        assert summary.returncode == 1
        assert "cut short (or damaged) before its first whole record" in summary.stderr, summary.stderr


def test_the_faults_are_counted_by_kind_so_that_more_faults_than_iterations_is_explained(tmp_path: Path) -> None:
    """A function that raises at every iteration stops its behaviour each time, and the state may find no
    transition: the closing line and `earl trace summary` count each kind, as docs/semantics.md names them."""
    spec = counter_whose_increment_then(tmp_path, "    raise RuntimeError('the counter is broken')\n")
    trace = tmp_path / "run.mcap"
    result = earl_cli("run", str(spec), "--duration", "20ms", "--trace", str(trace))
    assert result.returncode == 0, result.stderr
    found = re.search(
        r"(\d+) fault\(s\) \((\d+) exception, (\d+) no-transition; docs/semantics.md, Faults\)", result.stdout
    )
    assert found, result.stdout
    total, raised, stuck = map(int, found.groups())
    assert total == raised + stuck and raised > stuck >= 1
    summary = earl_cli("trace", "summary", str(trace))
    assert f"{total} faults ({raised} exception, {stuck} no-transition)" in summary.stdout, summary.stdout


def test_the_closing_table_written_to_a_pipe_is_not_cut_to_80_columns() -> None:
    """A log has no screen to fit: the real-time table's seven columns, cut to 80, broke states and
    figures over several lines (`opera` / `te`)."""
    environment = {name: value for name, value in os.environ.items() if name != "COLUMNS"}
    result = subprocess.run(
        [*EARL, "run", str(SPECS / "counter"), "--realtime", "--duration", "30ms"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env=environment,
    )
    assert result.returncode == 0, result.stderr
    rows = [line for line in result.stdout.splitlines() if "counter/a.relay/ve" in line]
    assert len(rows) == 1 and re.search(r"\d+ µs / \d+ µs", rows[0]), result.stdout
    assert any("start lateness p50 / p99" in line for line in result.stdout.splitlines())


OPTIONAL_SENDER = """\
system optionals

struct Reading {
    level: double
    spin: double[2]
    note: string?
    spare: double?
}

a/a {
    cs {
        period 10 ms
        r/ob: Reading
        t/m: double = 0.0
        false/pp = false
        tick/pf(t/mi -> t/mo) = python "readings:tick"
        emit/pf(t/mi -> r/ob) = python "readings:emit"
        run/bb {
            tf = {tick/pf} then {emit/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

b/a {
    cs {
        period 10 ms
        r/ib: Reading
        x/m: double = 0.0
        false/pp = false
        take/pf(r/ib -> x/mo) = python "readings:take"
        run/bb {
            tf = {take/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}

link a,b: a/a.cs.r -> b/a.cs.r

r/r {
    a/a
    b/a
    link a,b
}
"""

#: `level` is infinite every other message (a gap in its line), `note` is always text, `spare` never sent
READINGS = """\
def tick(inputs, outputs, context):
    outputs.t = inputs.t + 1.0


def emit(inputs, outputs, context):
    level = float("inf") if inputs.t % 2 else inputs.t
    outputs.r = {"level": level, "spin": [0.0, 1.0], "note": "reading", "spare": None}


def take(inputs, outputs, context):
    outputs.x = 1.0
"""


def optional_sender(tmp_path: Path) -> Path:
    (tmp_path / "system.earl").write_text(OPTIONAL_SENDER)
    (tmp_path / "readings.py").write_text(READINGS)
    return tmp_path


def test_an_optional_field_never_sent_has_no_value_and_an_infinite_real_is_a_gap(tmp_path: Path) -> None:
    """JSON writes an absent optional field and an infinite real both as null: the first is a signal
    without a value, left out of the plot; the second a gap in a signal that has values."""
    spec = optional_sender(tmp_path)
    alone = earl_cli(
        "run", str(spec), "--duration", "50ms", "--plot", str(tmp_path / "a.png"), "--signal", "a/a.cs.r.spare"
    )
    said = " ".join((alone.stdout + alone.stderr).split())
    assert alone.returncode == 1, said
    assert "no plot: no signal has a value" in said and "`a/a.cs.r.spare` had no value in this run" in said
    assert not (tmp_path / "a.png").exists()
    trace = tmp_path / "a.mcap"
    again = earl_cli("plot", str(trace), "--signal", "a/a.cs.r.spare", "-o", str(tmp_path / "b.png"))
    assert again.returncode == 1 and "`a/a.cs.r.spare` had no value in this run" in again.stderr, again.stderr
    both = earl_cli(
        "plot", str(trace), "--signal", "a/a.cs.r.spare", "--signal", "a/a.cs.r.level", "-o", str(tmp_path / "c.png")
    )
    assert both.returncode == 0, both.stderr
    assert "`a/a.cs.r.spare` had no value in this run (an optional field never sent); drawn without it" in both.stderr
    assert "level" not in both.stderr
    infinite = earl_cli("plot", str(trace), "--signal", "a/a.cs.r.level", "-o", str(tmp_path / "d.png"))
    assert infinite.returncode == 0 and infinite.stderr == "", infinite.stderr


def test_a_signal_that_is_no_number_is_refused_before_the_run_and_by_earl_plot(tmp_path: Path) -> None:
    spec = optional_sender(tmp_path)
    png = tmp_path / "p.png"
    for signal_name, fragment in [
        ("a/a.cs.r.note", "`r.note` is a string, not a number"),
        ("a/a.cs.r", "`r` is a struct (Reading), not a number; name a field of it: `r.level`"),
    ]:
        started = time.monotonic()
        refused = earl_cli("run", str(spec), "--duration", "1000s", "--plot", str(png), "--signal", signal_name)
        assert refused.returncode == 2 and fragment in refused.stderr, refused.stderr
        assert time.monotonic() - started < 30  # before the run
    trace = tmp_path / "t.mcap"
    assert earl_cli("run", str(spec), "--duration", "50ms", "--trace", str(trace)).returncode == 0
    text = earl_cli("plot", str(trace), "--signal", "a/a.cs.r.note", "-o", str(png))
    assert text.returncode == 1 and "`a/a.cs.r.note` is not a number" in text.stderr, text.stderr
    # an optional string never sent is no number either: the channel's schema says it is text
    (spec / "readings.py").write_text(READINGS.replace('"note": "reading"', '"note": None'))
    assert earl_cli("run", str(spec), "--duration", "50ms", "--trace", str(trace)).returncode == 0
    never = earl_cli("plot", str(trace), "--signal", "a/a.cs.r.note", "-o", str(png))
    assert never.returncode == 1 and "`a/a.cs.r.note` is not a number" in never.stderr, never.stderr
    whole = earl_cli("plot", str(trace), "--signal", "a/a.cs.r", "-o", str(png))
    assert whole.returncode == 1 and "`a/a.cs.r` is not a number but has parts" in whole.stderr, whole.stderr
    assert "`a/a.cs.r.level`" in whole.stderr


@pytest.mark.parametrize(
    ("signal_name", "fragment"),
    [
        ("a/a.cs.r.spin[2]", "`r.spin` has elements 0 to 1 where the signal indexes it, not 2"),
        ("a/a.cs.r.level.x", "`r.level` has no field `x` where the signal names it"),
        ("a/a.cs", "`a/a.cs` names a subsystem: a signal goes on to its memory or output buffer, e.g. `a/a.cs.t`"),
    ],
)
def test_a_wrong_signal_is_said_naming_the_part_that_is_wrong(tmp_path: Path, signal_name: str, fragment: str) -> None:
    spec = optional_sender(tmp_path)
    result = earl_cli("run", str(spec), "--plot", str(tmp_path / "p.png"), "--signal", signal_name)
    assert result.returncode == 2 and fragment in result.stderr, result.stderr
    assert "did you mean" not in result.stderr


def test_a_run_of_some_agents_plots_their_signals_of_run_toml_and_refuses_another_agent_s_on_the_command_line(
    tmp_path: Path,
) -> None:
    """run.toml names the signals of the whole system; a process that runs some of its agents (`--agents`,
    a process of a distributed run) has only theirs in its trace."""
    spec = tmp_path / "pingpong"
    shutil.copytree(Path(__file__).parent / "distributed_specs" / "pingpong", spec)
    (spec / "run.toml").write_text('plot = ["sender/a.cs.count", "receiver/a.cs.received"]\n')
    png = tmp_path / "p.png"
    command = ["run", str(spec), "--agents", "sender", "--duration", "200ms", "--plot", str(png)]
    drawn = earl_cli(*command)
    assert drawn.returncode == 0, drawn.stdout + drawn.stderr
    assert png.read_bytes().startswith(b"\x89PNG")
    said = " ".join(drawn.stderr.split())
    assert (
        "earl run: plot: run.toml's `receiver/a.cs.received` left out, of receiver/a, which this process does not "
        "run (it runs sender/a)" in said
    ), said
    named = earl_cli(*command, "--signal", "receiver/a.cs.received")
    assert named.returncode == 2, named.stdout + named.stderr
    assert "--signal `receiver/a.cs.received`: of receiver/a, which this process does not run" in named.stderr
    assert "ran " not in named.stdout  # said before the run
    (spec / "run.toml").write_text('plot = ["receiver/a.cs.received"]\n')
    none = earl_cli(*command)
    assert none.returncode == 1, none.stdout + none.stderr
    assert "no signal of run.toml's `plot` is of an agent this process runs" in " ".join(none.stderr.split())


def _interrupted_early(
    command: list[str], delay: float, stop: signal.Signals = signal.SIGINT, *, prints_only_at_its_end: bool = True
) -> tuple[int, list[str]] | None:
    """`command` (run with `python -X importtime`, which says on stderr each module as it is imported)
    gets `stop` (SIGINT) `delay` seconds after the first module of earl's own is imported: past Python's
    start, which no program can answer, somewhere in the imports, the parsing or the command itself. Its
    exit code and what it said on stderr; None when it had ended before the signal (for a command that
    `prints_only_at_its_end`, also when its output was all written before the signal: it was ending)."""
    child = subprocess.Popen(
        [sys.executable, "-X", "importtime", *command],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        assert child.stderr is not None
        lines: list[str] = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            line = child.stderr.readline().decode(errors="replace")
            lines.append(line)
            if not line or line.rsplit("|", 1)[-1].strip() == "earl._program":
                break
        assert lines[-1].strip(), "the program ended before it imported earl"
        time.sleep(delay)
        if child.poll() is not None:
            return None
        assert child.stdout is not None
        ending = prints_only_at_its_end and bool(select.select([child.stdout], [], [], 0)[0])
        child.send_signal(stop)
        _, rest_bytes = child.communicate(timeout=60)
        rest = rest_bytes.decode(errors="replace")
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    # -X importtime's lines, and the tail of one a write of the program's split under load (`1134 |   copy`)
    said = [
        line
        for line in "".join(lines).splitlines() + rest.splitlines()
        if not line.startswith("import time:") and re.match(r"\s*\d+ \|", line) is None
    ]
    if ending and child.returncode in (0, -stop) and not said:
        # its output written before the signal, which came as the interpreter shut down: its handler never
        # ran (a signal noted then is dropped) or, later still, CPython had put the default handlers back and
        # the signal ended the process; either way the command had ended before the signal
        return None
    return child.returncode, said


@pytest.mark.parametrize("entry", ["python -m earl", "python -m earl.cli.main", "the earl script"])
def test_ctrl_c_at_any_moment_of_the_start_is_exit_130_with_one_line(tmp_path: Path, entry: str) -> None:
    """A Ctrl-C while the program imports its modules printed a KeyboardInterrupt traceback from an import
    (and `python -m earl` could end by SIGINT itself, -2, instead of exit 130)."""
    if entry == "the earl script":
        script = tmp_path / "earl"  # what pip writes for the console script `earl`
        script.write_text("import sys\nfrom earl.cli.main import script\nsys.exit(script())\n")
        program = [str(script)]
    else:
        program = ["-m", entry.split()[-1]]
    spec = str(Path(__file__).parent.parent / "examples" / "pick_and_place")
    interrupted = 0
    for delay in (0.0, 0.0, 0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2, 0.3):
        result = _interrupted_early([*program, "check", spec], delay)
        if result is None:
            continue  # done before the signal
        code, said = result
        assert code == 130, (delay, said)
        assert len(said) == 1 and "interrupted" in said[0], (delay, said)
        interrupted += 1
    assert interrupted >= 4


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_or_sighup_at_any_moment_of_the_start_of_earl_run_is_exit_130_with_one_line(
    stop: signal.Signals,
) -> None:
    """A SIGTERM in the first few tenths of a second of `earl run` (`timeout`, a service manager), before the
    run's own handler was in place, ended the program by the signal (-15, 143 in a shell), and a little later
    it was exit 130 with one line; now it is 130 from the first line of earl on, as for Ctrl-C."""
    spec = str(EXAMPLE)
    interrupted = 0
    for delay in (0.0, 0.0, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.6):
        result = _interrupted_early(["-m", "earl", "run", spec, "--duration", "1s", "--no-progress"], delay, stop)
        if result is None:
            continue  # done before the signal
        code, said = result
        assert code == 130, (delay, said)
        # once the run has started, it first says it stops after the instant running (docs/semantics.md)
        assert said[:-1] in ([], ["earl run: stopping after this instant"]), (delay, said)
        assert said and "interrupted" in said[-1], (delay, said)
        interrupted += 1
    assert interrupted >= 6


def test_a_sigterm_the_shell_has_earl_run_ignore_stays_ignored_while_it_starts() -> None:
    """`nohup` (SIGHUP) or `trap '' TERM`: earl's start-up handler must not replace the ignore."""

    def ignoring() -> None:  # as `nohup` and `trap '' TERM` leave them to the program they start
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        signal.signal(signal.SIGHUP, signal.SIG_IGN)

    child = subprocess.Popen(
        [sys.executable, "-m", "earl", "run", str(EXAMPLE), "--duration", "0.3s", "--no-progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=ignoring,
    )
    try:
        for _ in range(20):  # through the imports and the start of the run
            time.sleep(0.05)
            child.send_signal(signal.SIGTERM)
            child.send_signal(signal.SIGHUP)
        stderr = child.communicate(timeout=120)[1].decode(errors="replace")
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert child.returncode == 0, stderr


#: the `earl` script as pip writes it, which sends itself the stop signal EARL_TEST_SIGNAL as Python starts to
#: import the module EARL_TEST_AT_IMPORT: a moment the delays of the test above hit only by chance
SIGNALLED_AT_AN_IMPORT = """\
import os, signal, sys

sent = False


def send(event, arguments):
    global sent
    if event == "import" and arguments[0] == os.environ["EARL_TEST_AT_IMPORT"] and not sent:
        sent = True
        os.write(2, b"(signal sent)\\n")
        os.kill(os.getpid(), getattr(signal, os.environ["EARL_TEST_SIGNAL"]))


sys.addaudithook(send)
from earl.cli.main import script
sys.exit(script())
"""


@pytest.mark.parametrize(
    ("stop", "command", "said"),
    [
        ("SIGINT", "check", "earl: interrupted"),
        ("SIGTERM", "run", "earl run: interrupted before the run started; nothing was executed"),
    ],
)
def test_a_stop_signal_while_dds_compiled_module_initialises_is_exit_130(
    tmp_path: Path, stop: str, command: str, said: str
) -> None:
    """The initialisation of dd's Cython module (dd.cudd, imported as the FSMs are analysed) imports
    `backports_abc` and clears its failure, a KeyboardInterrupt too: a Ctrl-C (or, in `earl run`, a
    SIGTERM) that came then was lost, and the command went on to its end, exit 0."""
    if importlib.util.find_spec("dd.cudd") is None:
        pytest.skip("dd without CUDD: its pure-Python BDDs have no compiled module to initialise")
    script = tmp_path / "earl"
    script.write_text(SIGNALLED_AT_AN_IMPORT)
    options = ["--duration", "1s", "--no-progress"] if command == "run" else []
    environment = {**os.environ, "EARL_TEST_AT_IMPORT": "backports_abc", "EARL_TEST_SIGNAL": stop}
    result = subprocess.run(
        [sys.executable, str(script), command, str(EXAMPLE), *options],
        capture_output=True,
        text=True,
        timeout=120,
        env=environment,
        check=False,
    )
    lines = result.stderr.splitlines()
    assert lines[:1] == ["(signal sent)"], result.stderr  # the moment came (dd's module still imports it)
    assert (result.returncode, lines[1:], result.stdout) == (130, [said], ""), result.stdout + result.stderr


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_ctrl_c_while_launch_starts_is_exit_130_without_a_traceback(tmp_path: Path, stop: signal.Signals) -> None:
    """So is a SIGTERM or SIGHUP, which ended `earl launch` by the signal before its own handler was in place."""
    spec = Path(__file__).parent / "distributed_specs" / "pingpong"
    ports = []
    for _ in range(2):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            ports.append(probe.getsockname()[1])
    deploy = tmp_path / "deploy.toml"
    deploy.write_text(
        "".join(
            f'[[process]]\nagents = ["{agent}"]\nlisten = "tcp/127.0.0.1:{port}"\n'
            for agent, port in zip(("sender/a", "receiver/a"), ports, strict=True)
        )
    )
    for delay in (0.0, 0.02, 0.05, 0.1):
        result = _interrupted_early(
            ["-m", "earl", "launch", str(spec), "--deployment", str(deploy)], delay, stop, prints_only_at_its_end=False
        )
        assert result is not None
        code, said = result
        assert code == 130, (delay, said)
        assert len(said) <= 1 and "Traceback" not in "".join(said), (delay, said)


def _run_with_an_environment_that_is_stopped_while_imported(
    tmp_path: Path, then: str
) -> subprocess.CompletedProcess[str]:
    """`earl run` of the counter spec whose environment module sends its own process a SIGTERM while it is
    imported, and then does `then` with the KeyboardInterrupt, as compiled code may: the moment is the
    test's, not a race."""
    spec = tmp_path / "counter"
    shutil.copytree(SPECS / "counter", spec)
    (spec / "stopped.py").write_text(
        "import os, signal, time\n"
        "try:\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    time.sleep(5)  # the handler raises here\n"
        "except KeyboardInterrupt:\n"
        f"    {then}\n"
        "def make(system, seed):\n"
        "    return None\n"
    )
    return subprocess.run(
        [sys.executable, "-m", "earl", "run", str(spec), "--environment", "stopped:make", "--duration", "0.1s"],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_stop_that_a_compiled_module_s_import_puts_in_other_words_is_exit_130_not_its_error(
    tmp_path: Path,
) -> None:
    """pybind11 (MuJoCo's bindings) turns a KeyboardInterrupt raised while its module initialises into
    "ImportError: generic_type: …": a SIGTERM at that moment of `earl run`'s start (a CI run sent it at
    0.4 s, as the environment imported mujoco) was said as EARL-X003, the environment's import failing, and
    exit 1."""
    result = _run_with_an_environment_that_is_stopped_while_imported(
        tmp_path, "raise ImportError('generic_type: type is already registered') from None"
    )
    said = result.stderr.splitlines()
    assert result.returncode == 130, result.stderr
    assert "EARL-X003" not in result.stderr and "Traceback" not in result.stderr
    assert said and "interrupted" in said[-1]


def test_a_stop_that_compiled_code_swallows_while_a_command_starts_still_ends_it_with_130(tmp_path: Path) -> None:
    """A Cython module's initialisation clears a KeyboardInterrupt (dd's did: `earl check` printed ok and
    exit 0). Whatever code swallows it while the run is set up, a stop signal that came then stops the run
    before its first instant, with 130 and one line."""
    result = _run_with_an_environment_that_is_stopped_while_imported(
        tmp_path, "pass  # as compiled code that clears it"
    )
    assert result.returncode == 130, result.stderr
    assert "Traceback" not in result.stderr
    assert result.stderr.splitlines() == ["earl run: interrupted before the run started; nothing was executed"]
    assert "ran 0.100 s" not in result.stdout  # the run did not go on as if no stop had come
