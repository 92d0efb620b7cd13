"""`earl trace summary FILE` and `earl plot FILE --signal …`: reading a run's MCAP trace."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from rich.table import Table

from earl.cli.common import UsageError, brief, fault_kinds, named_path, table_console, usage_error

EXIT_OK, EXIT_FAILED = 0, 1


def register(commands: Any) -> None:
    trace = commands.add_parser(
        "trace",
        help="read an MCAP trace written by `earl run --trace`",
        description="Read a trace written by `earl run --trace FILE.mcap`.",
        epilog="examples:\n  earl trace summary run.mcap\n  earl trace faults run.mcap\n\nexit codes: 0 ok, 1 not a readable earl trace, 2 usage error (no such file, no ACTION), "
        "130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    actions = trace.add_subparsers(dest="action", metavar="ACTION", parser_class=type(trace))
    summary = actions.add_parser(
        "summary",
        help="per subsystem: time in each state, transitions taken, faults",
        description="Per subsystem: the time spent in each FSM state, the transitions taken and the faults.",
        epilog="example:\n  earl trace summary run.mcap\n\nexit codes: 0 summarised, 1 not a readable earl trace, "
        "2 usage error (no such file), 130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    summary.add_argument("file", metavar="FILE.mcap")
    summary.set_defaults(run=run_summary)
    faults = actions.add_parser(
        "faults",
        help="each fault with the traceback of the spec's code that raised it",
        description="Each fault of the run with where it happened and, for a function or predicate of the\n"
        "spec that raised, the traceback of the spec's own code (earl's frames left out). A fault\n"
        "repeated (the same subsystem, kind, message and traceback) is shown once, with how many\n"
        "times and when it first and last happened.",
        epilog="example:\n  earl trace faults run.mcap\n\nexit codes: 0 listed (also when the run had none), "
        "1 not a readable earl trace, 2 usage error (no such file), 130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    faults.add_argument("file", metavar="FILE.mcap")
    faults.set_defaults(run=run_faults)
    trace.set_defaults(run=lambda _arguments: (trace.print_help(), 2)[1])

    plot = commands.add_parser(
        "plot",
        help="plot signals of a trace, with the FSM states as shaded bands (PNG)",
        description="Plot signals recorded in a trace against time; the FSM states of each signal's\n"
        "subsystem are shaded behind it. A signal is memory (recorded with --record-memory), e.g.\n"
        "manip/a.cs.windingCurrent[1], or a field of what an output buffer sent, e.g.\n"
        "manip/a.cs.manipulatorState.currentJointPos[0].\n\n"
        "Indices are written as in the spec, and the plot's labels write them the same way:\n"
        "brackets after a family's name choose a member by its declared index (windingCurrent[1]\n"
        "is member 1 of windingCurrent[K in 1..6]), brackets after an array an element counted\n"
        "from 0 (currentJointPos[0] is its first); [*] is every member or element.",
        epilog="examples:\n  earl plot run.mcap --signal manip/a.cs.windingCurrent[1] -o current.png\n"
        "  earl plot run.mcap --signal manip/a.cs.windingCurrent[1] --from 2.99 --to 3.02   (a window of 30 ms)\n\n"
        "exit codes: 0 written, 1 the file is not a readable earl trace or lacks a signal (or has none\n"
        "in the --from/--to window, or ends before --from), 2 usage error (no such file, a malformed\n"
        "signal, an empty or unwritable -o, a --from or --to that is no time of 0 or more, --from (0\n"
        "if not given) not before --to), 130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    plot.add_argument("file", metavar="FILE.mcap")
    plot.add_argument(
        "--signal",
        action="append",
        required=True,
        metavar="SIGNAL",
        help="a signal to draw (repeatable); x[1] of a family is member 1, v[0] of an array its first element",
    )
    plot.add_argument(
        "--from",
        dest="start",
        metavar="TIME",
        help="draw the run from this time on, e.g. 2.5 (seconds) or 2500ms (default: its start)",
    )
    plot.add_argument("--to", dest="stop", metavar="TIME", help="draw the run up to this time (default: its end)")
    plot.add_argument("-o", "--output", default="plot.png", metavar="FILE.png", help="default plot.png")
    plot.add_argument("--title", help="a title over the figure")
    plot.set_defaults(run=run_plot)


def run_summary(arguments: argparse.Namespace) -> int:
    from earl.runtime.trace_reader import CUT, TraceError, summarise

    path = Path(arguments.file)
    if not path.is_file():
        return usage_error(_not_a_file(arguments.file))
    try:
        summary = summarise(path)
    except TraceError as error:
        sys.stderr.write(f"earl trace: {error}\n")
        return EXIT_FAILED
    console = table_console()
    end = summary.end_time * 1e-9
    settings = ", ".join(f"{k}={v}" for k, v in summary.settings.items())
    table = Table(title=f"{path.name}: {end:.3f} s ({settings})", title_justify="left")
    # names in full: the members of a family differ only at their end (`manip/a.motorController[3]/ve`)
    table.add_column("subsystem", no_wrap=True, min_width=max((len(name) for name in summary.subsystems), default=9))
    table.add_column("time in each state")
    table.add_column("transitions taken")
    table.add_column("iterations", justify="right")
    table.add_column("faults", justify="right")
    for name, subsystem in summary.subsystems.items():
        states = "\n".join(
            f"{state}: {duration * 1e-9:.3f} s ({100 * duration * 1e-9 / end if end else 0:.0f}%)"
            for state, duration in sorted(subsystem.state_time.items(), key=lambda item: -item[1])
        )
        transitions = "\n".join(f"{t} ×{n}" for t, n in sorted(subsystem.transitions.items())) or "–"
        iterations = str(subsystem.iterations) if summary.ended else "?"
        table.add_row(name, states, transitions, iterations, str(subsystem.faults))
    console.print(table)
    if summary.cut:
        console.print(f"{path.name}: {CUT}")
    if not summary.ended:
        console.print(
            f"the trace ends at {end:.3f} s without the run's end (the run was killed): what it holds is whole, "
            "but the iteration counts, written at the end, are not known"
        )
    kinds = f" ({fault_kinds(str(fault['kind']) for fault in summary.faults)})" if summary.faults else ""
    console.print(f"{summary.messages} messages on links, {len(summary.faults)} faults{kinds}")
    for fault in summary.faults[:10]:
        console.print(f"  {_fault_line(fault)}", soft_wrap=True)
    if len(summary.faults) > 10:
        console.print(f"  … and {len(summary.faults) - 10} more")
    if any(fault.get("traceback") for fault in summary.faults):
        console.print(f"their tracebacks: earl trace faults {path}", soft_wrap=True)
    return EXIT_OK


def _fault_line(fault: dict[str, Any]) -> str:
    """`t=0.950000 s sorter/a.cs (exception): `classify/pf` raised … (at sorting/sorter.py:8 in classify)`."""
    from earl.runtime.fault_places import fault_place

    place = fault_place(str(fault.get("traceback") or ""))
    return f"t={fault['time'] * 1e-9:.6f} s {fault['subsystem']} ({fault['kind']}): {brief(str(fault['message']))}{brief(place)}"


#: the distinct faults `earl trace faults` shows at most: a message with a value in it can make each new
FAULTS_SHOWN = 20


def run_faults(arguments: argparse.Namespace) -> int:
    from earl.runtime.trace_reader import CUT, TraceError, read_faults

    path = Path(arguments.file)
    if not path.is_file():
        return usage_error(_not_a_file(arguments.file))
    try:
        faults, cut = read_faults(path)
    except TraceError as error:
        sys.stderr.write(f"earl trace: {error}\n")
        return EXIT_FAILED
    console = table_console()
    # one entry per fault as it repeats, every iteration, in the order they first happened
    repeated: dict[tuple[str, ...], list[dict[str, Any]]] = {}
    for fault in faults:
        key = tuple(str(fault.get(name, "")) for name in ("subsystem", "kind", "message", "function", "traceback"))
        repeated.setdefault(key, []).append(fault)
    kinds = f" ({fault_kinds(str(fault.get('kind', '')) for fault in faults)})" if faults else ""
    console.print(f"{path.name}: {len(faults)} faults{kinds}, {len(repeated)} distinct", soft_wrap=True)
    for same in list(repeated.values())[:FAULTS_SHOWN]:
        first, last = same[0], same[-1]
        times = f", ×{len(same)} until t={last['time'] * 1e-9:.6f} s" if len(same) > 1 else ""
        console.print(f"\n{_fault_line(first)}{times}", soft_wrap=True)
        text = str(first.get("traceback") or "")
        for line in text.rstrip("\n").split("\n") if text else []:
            console.print(f"  {brief(line)}", soft_wrap=True)
    if len(repeated) > FAULTS_SHOWN:
        console.print(f"\n… and {len(repeated) - FAULTS_SHOWN} more distinct faults")
    if cut:
        console.print(f"{path.name}: {CUT}")
    return EXIT_OK


def run_plot(arguments: argparse.Namespace) -> int:
    from earl.runtime.plot import plot_output_problem, plot_signals
    from earl.runtime.signal_syntax import signal_text_problem
    from earl.runtime.trace_reader import TraceError, nanoseconds

    path = Path(arguments.file)
    if not path.is_file():
        return usage_error(_not_a_file(arguments.file))
    try:
        output = named_path(arguments.output, "-o", "plot.png")
    except UsageError as error:
        return usage_error(str(error))
    problem = plot_output_problem(output)
    if problem is not None:
        return usage_error(f"cannot write {arguments.output!r}: {problem}")
    try:
        start = _time_of("--from", arguments.start)
        stop = _time_of("--to", arguments.stop)
    except UsageError as error:
        return usage_error(str(error))
    # in the trace's nanoseconds, as `within` compares: `--from 1 --to 1.0000000001` is one instant
    if stop is not None and not nanoseconds(start or 0.0) < nanoseconds(stop):
        if start is None:  # --from is the run's start, 0
            return usage_error(
                f"--to {arguments.stop} is not after --from (the run's start, 0 s, when not given): "
                "the window would be empty"
            )
        return usage_error(f"--from {arguments.start} is not before --to {arguments.stop}: the window would be empty")
    for signal in arguments.signal:
        # a signal not written as one is a usage error, not one the trace lacks
        malformed = signal_text_problem(signal)
        if malformed is not None:
            return usage_error(f"--signal {malformed}")
    try:
        left_out = plot_signals(path, arguments.signal, output, arguments.title, start, stop)
    except TraceError as error:
        sys.stderr.write(f"earl plot: {error}\n")
        return EXIT_FAILED
    except OSError as error:  # a read-only directory, a full disk
        return usage_error(f"cannot write {arguments.output}: {error.strerror or error}")
    for line in left_out:
        sys.stderr.write(f"earl plot: {line}\n")
    print(f"wrote {arguments.output}")
    return EXIT_OK


def _time_of(option: str, given: str | None) -> float | None:
    """Seconds of run time that `--from` or `--to` names (`2.5`, `2500ms`); None when not given."""
    from earl.runtime.durations import parse_duration

    if given is None:
        return None
    if given.strip().startswith("-"):
        raise UsageError(f"{option} {given}: a time of the run is 0 s or more")
    try:
        return parse_duration(given, zero=True)
    except ValueError as error:
        said = str(error).replace("a duration", "a time").replace("the duration", "the time")
        raise UsageError(f"{option}: {said}") from None


def _not_a_file(given: str) -> str:
    """Why `given` is no trace to read: a directory is there, only not a file."""
    if not given.strip():  # Path("") is the directory here
        return "FILE.mcap is empty: name the trace (earl run --trace FILE.mcap writes one)"
    if Path(given).is_dir():
        return f"{given} is a directory, not a trace: name the .mcap file (earl run --trace FILE.mcap writes one)"
    return f"no such file: {given}"
