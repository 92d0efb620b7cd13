"""`earl run SPEC`: execute a specification in virtual time (default) or real time."""

from __future__ import annotations

import _thread
import argparse
import contextlib
import gc
import os
import re
import signal
import statistics
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

from earl import _program
from earl.cli.common import (
    UsageError,
    brief,
    fault_kinds,
    named,
    named_path,
    parse_parameters,
    spec_path,
    table_console,
    usage_error,
)
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError
from earl.runtime.fault_places import fault_place
from earl.transport.deployment import DeploymentError

if TYPE_CHECKING:
    from earl.lang.loader import ParameterValue
    from earl.runtime.run_settings import RunSettings

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

EPILOG = """\
examples:
  earl run examples/pick_and_place                        the manual's example, 13 s simulated (run.toml)
  earl run examples/pick_and_place --param N=3 --trace run.mcap --record-memory manip/a.cs
  earl run spec.earl --duration 30s --seed 7              another seed, another random stream
  earl run spec.earl --realtime --duration 5s             paced by the wall clock, jitter reported

Subsystems are named like manip/a.cs or manip/a.motorController[3]/ve; a family whole
(every member) like manip/a.motorController[*]/ve. A `run.toml` next
to the spec may set defaults: environment, duration, seed, record_memory, record_links,
plot, report.
`--environment none` runs without it (a process whose agents have no physics).

distributed (docs/distributed.md):
  earl run examples/pick_and_place --transport zenoh --agents task/a
                        this process runs task/a; deploy.toml next to the spec says
                        where the other agents' processes listen (earl launch starts all)
The spec is checked first; its errors stop the run. Only `earl run` imports the Python
code a spec names (docs/runtime.md).

exit codes: 0 the run completed (or the spec's code called sys.exit(0)), 1 invalid spec,
            the run could not start, its trace could not be written (a full disk), the
            environment failed, subsystems without a period woke each other for ever in one
            instant (a zero-time-loop), the spec's code called sys.exit with a failure, or the --plot
            or run.toml's report asked for failed at the end (the run and its trace are
            whole); with --transport zenoh also when a link's messages were refused for
            another data type (the run goes on, and names the links at its end),
            2 usage error (an option, or a run.toml that cannot be used), 130
            interrupted (the trace is closed and readable): Ctrl-C, SIGTERM or SIGHUP stop
            after the instant running, or inside it when it has not ended 2 s later
"""


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "run",
        help="execute a specification (virtual time by default), optionally recording an MCAP trace",
        description="Run SPEC: every subsystem iterates its basic behaviours as Figure 5 of the EARL manual "
        "defines, links carry messages, FSMs change state. Virtual time (the default) is deterministic and "
        "faster than real time: the same spec and seed give a byte-identical trace.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument("--duration", metavar="TIME", help="run time, e.g. 10s, 500ms (default 10s or run.toml)")
    parser.add_argument("--realtime", action="store_true", help="pace the run by the wall clock, report jitter")
    parser.add_argument("--trace", metavar="FILE.mcap", help="record an MCAP trace (opens in Foxglove)")
    parser.add_argument(
        "--seed",
        type=_seed,
        metavar="N",
        help="seed of the subsystems' random streams, a whole number >= 0 (default 0)",
    )
    parser.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="set a system parameter (repeatable)"
    )
    parser.add_argument(
        "--environment", metavar="MODULE:FACTORY", help="the environment (physics) factory; default from run.toml"
    )
    parser.add_argument(
        "--record-memory",
        action="append",
        default=None,
        metavar="SUBSYSTEM",
        help="with --trace (or --plot): record memory snapshots of a subsystem after each iteration "
        "(repeatable; `all` for every one; a family whole, pusher[*]/a.cs, for every member)",
    )
    parser.add_argument(
        "--record-links",
        action="append",
        default=None,
        metavar="PATTERN",
        help="with --trace (or --plot): record only messages on links matching a glob, e.g. 'task,*'; "
        "brackets name a member of a link family, 'sorter,pusher[2]', or every one, 'sorter,pusher[*]' or with the "
        "index variable the family declares, 'sorter,pusher[K]'; other brackets are a character class, 'task,[mg]*' "
        "(repeatable; default: all; to record none, write record_links = [] in run.toml)",
    )
    parser.add_argument(
        "--plot",
        metavar="FILE.png",
        help="after the run, plot the signals named by --signal (or `plot` in run.toml) from the trace",
    )
    parser.add_argument(
        "--signal",
        action="append",
        default=None,
        metavar="SIGNAL",
        help="with --plot: a signal it draws, e.g. 'manip/a.cs.windingCurrent[*]' (repeatable; x[1] of a family is "
        "member 1, v[0] of an array its first element; see `earl plot --help`)",
    )
    parser.add_argument(
        "--agents",
        metavar="A,B",
        help="run only these agents, e.g. manip/a,grip/a, or a family's every member, pusher[*]/a "
        "(with --transport zenoh the others run in other processes)",
    )
    parser.add_argument(
        "--transport",
        choices=["inproc", "zenoh"],
        default="inproc",
        help="zenoh: links to agents of other processes go over Eclipse Zenoh (implies --realtime); "
        "see docs/distributed.md",
    )
    parser.add_argument(
        "--deployment",
        metavar="deploy.toml",
        help="with --transport zenoh: the processes and their endpoints (default: deploy.toml next to the spec)",
    )
    parser.add_argument(
        "--zenoh-config",
        metavar="FILE",
        help="with --transport zenoh: your own Zenoh configuration (JSON5), used unchanged instead of the endpoints "
        "of the deployment file (routers, TLS, other hosts)",
    )
    parser.add_argument(
        "--wait-for-peers",
        metavar="TIME",
        default=None,
        help="with --transport zenoh: wait at most this long for the agents of other processes before starting "
        "(default 30s; 0: start at once); missing ones start out stale",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """`earl run`. A stop signal before the run has started (while the spec is read and checked, the
    environment built) ends it too, with exit 130, instead of SIGTERM's silent death (143)."""
    try:
        with _stopped_like_ctrl_c():
            return _run(arguments)
    except KeyboardInterrupt:
        print("earl run: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _run(arguments: argparse.Namespace) -> int:
    from earl.cli.common import say_started, take_launch_status, watch_supervisor
    from earl.lang.loader import load

    watch_supervisor()
    launch_status = take_launch_status()
    from earl.runtime.names import named_members
    from earl.runtime.simulation import RecordingWarning, Simulation, bind_report

    try:
        options = check_options(arguments)
    except UsageError as error:
        return usage_error(str(error))
    path, parameters, settings, duration = options.path, options.parameters, options.settings, options.duration
    agents = options.agents
    seed = arguments.seed if arguments.seed is not None else (settings.seed or 0)
    signals = arguments.signal
    #: where the signals were named, for messages about them
    signals_origin = "--signal" if options.signals_from_command_line else "run.toml's plot:"
    # only a trace file this command creates may be removed, should a stop signal come before the run
    trace_was_there = arguments.trace is not None and os.path.lexists(arguments.trace)
    environment = arguments.environment or settings.environment
    if environment == "none":
        environment = None
    record_memory = arguments.record_memory if arguments.record_memory is not None else settings.record_memory
    transport: Any = None
    plotted_outputs: list[str] = []
    try:
        system = load(path, parameters)
        if arguments.transport == "zenoh":
            from earl.transport.process import prepare_transport

            # run.toml's environment lives where the deployment file puts it; --environment is the user's;
            # the Zenoh session opens last, as `Simulation` is set up (its code bound, its environment started)
            from_settings = environment if arguments.environment is None else None
            agents, transport, environment_here = prepare_transport(
                system, parameters, path, agents or [], arguments, from_settings
            )
            if from_settings is not None and not environment_here:
                environment = None
        elif agents:
            from earl.transport.process import agents_of

            agents = agents_of(system, parameters, agents)
        if agents and arguments.record_memory is None and record_memory:
            # run.toml names the subsystems of the whole system; this process records those it runs
            # (a family's, `pusher[*]/a.cs`, if it runs a member)
            record_memory = [m for m in record_memory if named_members(m.split(".", 1)[0], agents)]
        # bound now, as the spec's functions are: not found to be misspelt after the whole run
        report = bind_report(settings.report, path, settings) if settings.report and environment is not None else None
        if arguments.plot:
            # what the plot draws is recorded, and a signal the system does not have is said now
            from earl.model.expand import expand
            from earl.runtime.plot import what_to_record

            try:
                expanded = expand(system, parameters)
                plotted, plotted_outputs = what_to_record(expanded, list(signals or []))
            except ValueError as error:
                _close(transport)
                return usage_error(f"{signals_origin} {error}")
            if agents:  # this process's trace holds its own agents' subsystems only
                plotted = [name for name in plotted if name.split(".", 1)[0] in agents]
                plotted_outputs = [name for name in plotted_outputs if name.split(".", 1)[0] in agents]
                elsewhere = [signal for signal in signals or [] if signal.split(".", 1)[0] not in agents]
                if elsewhere:
                    named = ", ".join(f"`{signal}`" for signal in elsewhere)
                    owners = ", ".join(dict.fromkeys(signal.split(".", 1)[0] for signal in elsewhere))
                    runs = f"of {owners}, which this process does not run (it runs {', '.join(agents)})"
                    if signals_origin == "--signal":  # named on the command line: a mistake
                        _close(transport)
                        return usage_error(
                            f"--signal {named}: {runs}; plot it in the process that runs it, "
                            "or from that process's trace with earl plot"
                        )
                    print(f"earl run: plot: run.toml's {named} left out, {runs}", file=sys.stderr)
                    arguments.signal = [signal for signal in signals or [] if signal not in elsewhere]
            record_memory = sorted({*(record_memory or []), *plotted})
        with warnings.catch_warnings():
            # a link pattern that matches nothing is said by `_say_what_is_not_recorded`, in the CLI's words
            warnings.simplefilter("ignore", RecordingWarning)
            simulation = Simulation(
                system,
                parameters=parameters,
                seed=seed,
                # run.toml's own, read there again, is said at its line when it cannot be bound
                environment="run.toml"
                if environment is not None and arguments.environment is None and environment == settings.environment
                else environment,
                trace=arguments.trace,
                record_memory=record_memory,
                record_links=arguments.record_links if arguments.record_links is not None else settings.record_links,
                record_outputs=plotted_outputs,
                realtime=arguments.realtime,
                agents=agents,
                transport=transport,
            )
    except KeyboardInterrupt:  # a stop signal while the spec was read and the run set up
        _close(transport)
        said = "nothing was executed" + _remove_unrun_trace(arguments, trace_was_there)
        print(f"earl run: interrupted before the run started; {said}", file=sys.stderr)
        return EXIT_INTERRUPTED
    except EarlError as error:
        _close(transport)
        print_diagnostics(error.diagnostics, error.sources)
        print("earl run: the specification cannot run; nothing was executed", file=sys.stderr)
        return EXIT_FAILED
    except DeploymentError as error:  # before ValueError, which it is: the file is wrong, not an option
        _close(transport)
        print(f"earl run: {error}", file=sys.stderr)
        return EXIT_FAILED
    except ValueError as error:
        _close(transport)
        return usage_error(str(error))
    except OSError as error:
        _close(transport)
        beside = " (the trace --plot draws from, beside the plot)" if arguments.plot else ""
        return usage_error(f"cannot write the trace {arguments.trace}{beside}: {error.strerror or error}")
    except RuntimeError as error:  # the transport could not start
        _close(transport)
        if arguments.zenoh_config:
            from earl.transport.zenoh_transport import TransportError, network_failure  # imported already

            if isinstance(error, TransportError) and not network_failure(str(error)):
                return usage_error(str(error))  # the user's own configuration, which Zenoh refuses
        print(f"earl run: {error}", file=sys.stderr)
        return EXIT_FAILED
    # run.toml names the links of the whole system: a process that runs some of its agents has only
    # theirs, and would call every pattern for the others' links wrong
    _say_what_is_not_recorded(arguments, simulation, settings.record_links if not agents else None)
    say_started(launch_status)  # set up, links open: a failure from now on is a lost peer, not a failed start
    try:
        if transport is not None:
            from earl.transport.process import wait_for_peers

            try:
                with _stopped_like_ctrl_c():
                    wait_for_peers(transport, arguments)
            except KeyboardInterrupt:
                simulation.close()
                said = "nothing was executed" + _remove_unrun_trace(arguments, trace_was_there)
                print(f"earl run: interrupted while waiting for the other processes; {said}", file=sys.stderr)
                return EXIT_INTERRUPTED
        return _execute(simulation, duration, arguments, report, settings.report or "", path)
    finally:
        # Closed already, unless printing failed (a reader that went away: `earl run … | head`); an open
        # Zenoh session's threads would keep the process from ever ending.
        with contextlib.suppress(Exception):
            simulation.close()


def _remove_unrun_trace(arguments: argparse.Namespace, trace_was_there: bool) -> str:
    """Remove the trace of a run stopped before its first instant, when this command created it (it
    holds no run); what to say of it: `; no trace was written to FILE`, or nothing. A run stopped while
    it was set up has removed it already (`Simulation` does, once the trace's writer has ended)."""
    trace = Path(arguments.trace) if arguments.trace else None
    if trace is None or trace_was_there:
        return ""
    if trace.is_file() and not trace.is_symlink():
        with contextlib.suppress(OSError):
            trace.unlink()
    return "" if os.path.lexists(trace) else f"; no trace was written to {arguments.trace}"


@dataclass
class CheckedOptions:
    """What `check_options` read from the command line and run.toml."""

    path: Path
    parameters: dict[str, ParameterValue]
    settings: RunSettings
    #: seconds
    duration: float
    #: --agents, split (None: every agent)
    agents: list[str] | None
    #: whether --signal named the signals (else run.toml's `plot` did)
    signals_from_command_line: bool


def check_options(arguments: argparse.Namespace) -> CheckedOptions:
    """What is wrong in the options of `earl run`, found without reading the spec (UsageError): said before
    anything runs, by `earl run` and by `earl launch` for each process's `args`. Fills in what follows from
    them: --signal from run.toml's `plot`, --trace from --plot, --realtime with --transport zenoh."""
    from earl.runtime.durations import parse_duration
    from earl.runtime.run_settings import read_run_settings

    path = spec_path(arguments.spec)
    parameters = parse_parameters(arguments.param)
    # an empty one was no trace (`--trace ""`: "Is a directory" after the spec was read), no plot at all, or
    # the default deployment or configuration, as if the option had not been given
    for option, given, example in (
        ("--trace", arguments.trace, "run.mcap"),
        ("--plot", arguments.plot, "plot.png"),
        ("--deployment", arguments.deployment, "deploy.toml"),
        ("--zenoh-config", arguments.zenoh_config, "zenoh.json5"),
    ):
        if given is not None:
            named_path(given, option, example)
    if arguments.environment is not None and not arguments.environment.strip():  # was run.toml's, unsaid
        raise UsageError("--environment names no environment: name one as MODULE:FACTORY, or `none` for none")
    # an empty pattern matched no link and the trace kept none; an empty subsystem was "names no subsystem: "
    for option, given, example, what in (
        ("--record-links", arguments.record_links, "'task,*'", "link pattern"),
        ("--record-memory", arguments.record_memory, "manip/a.cs", "subsystem"),
    ):
        for text in given or []:
            named(text, option, example, what)
    try:
        settings = read_run_settings(path)
    except ValueError as error:
        raise UsageError(str(error)) from None
    try:
        # an empty `--duration=` is refused, not taken for the default
        duration = parse_duration(arguments.duration) if arguments.duration is not None else (settings.duration or 10.0)
    except ValueError as error:
        raise UsageError(f"--duration: {error}") from None
    from_command_line = arguments.signal is not None
    if from_command_line and not arguments.plot:  # the signals went nowhere, without a word
        raise UsageError("--signal needs --plot FILE.png: it names what the plot draws after the run")
    signals = arguments.signal if from_command_line else settings.plot
    if arguments.plot and not signals:
        raise UsageError("--plot needs signals: name them with --signal, or `plot = [...]` in run.toml")
    if arguments.plot:
        from earl.runtime.plot import plot_output_problem
        from earl.runtime.signal_syntax import signal_text_problem

        problem = plot_output_problem(Path(arguments.plot))
        if problem is not None:  # said now, not after a run of minutes
            raise UsageError(f"--plot {arguments.plot!r}: {problem}")
        origin = "--signal" if from_command_line else "run.toml's plot:"
        for signal in signals or []:
            malformed = signal_text_problem(signal)
            if malformed is not None:
                raise UsageError(f"{origin} {malformed}")
    arguments.signal = signals
    if arguments.plot and not arguments.trace:
        arguments.trace = str(Path(arguments.plot).with_suffix(".mcap"))
    # as --signal without --plot: what they choose went nowhere (a line said so, and the run went on)
    chosen = [
        option
        for option, given in (("--record-memory", arguments.record_memory), ("--record-links", arguments.record_links))
        if given
    ]
    if arguments.trace is None and chosen:
        need, choose = ("needs", "it chooses") if len(chosen) == 1 else ("need", "they choose")
        raise UsageError(
            f"{' and '.join(chosen)} {need} --trace FILE.mcap: {choose} what the trace records (--plot writes one too)"
        )
    if arguments.plot and Path(arguments.plot).resolve() == Path(arguments.trace).resolve():
        raise UsageError(f"--trace and --plot both name {arguments.plot}: the plot would replace the trace")
    if arguments.trace is not None and not Path(arguments.trace).parent.is_dir():
        # said here in the CLI's words; `Simulation` would say it after the spec is read, in the API's
        directory = Path(arguments.trace).parent
        kind = "is not a directory" if directory.exists() else "does not exist"
        raise UsageError(f"cannot write the trace {arguments.trace}: the directory `{directory}` {kind}")
    agents = [a.strip() for a in arguments.agents.split(",") if a.strip()] if arguments.agents is not None else None
    if agents == []:  # `--agents ,` or `--agents ""`: not "all of them", which is no --agents at all
        raise UsageError("--agents names no agent; list them, e.g. --agents manip/a,grip/a")
    if arguments.transport == "zenoh":
        if not agents:
            raise UsageError("--transport zenoh needs --agents: the agents this process runs, e.g. task/a")
        from earl.transport.process import peers_wait  # Zenoh is imported only for a distributed run

        try:
            peers_wait(arguments.wait_for_peers)
        except ValueError as error:
            raise UsageError(f"--wait-for-peers: {error}") from None
        if arguments.deployment and not Path(arguments.deployment).is_file():
            # as `earl launch` says it: a file named on the command line that is not there is a usage error
            kind = "is a directory; name its file" if Path(arguments.deployment).is_dir() else "does not exist"
            raise UsageError(f"--deployment {arguments.deployment} {kind}")
        if arguments.zenoh_config and not Path(arguments.zenoh_config).is_file():
            kind = "a directory, not a file" if Path(arguments.zenoh_config).is_dir() else "no such file"
            raise UsageError(f"--zenoh-config: {kind}: {arguments.zenoh_config}")
        arguments.realtime = True  # distribution runs in real time only (docs/distributed.md)
    elif arguments.zenoh_config or arguments.deployment or arguments.wait_for_peers is not None:
        raise UsageError("--zenoh-config, --deployment and --wait-for-peers go with --transport zenoh")
    return CheckedOptions(path, parameters, settings, duration, agents, from_command_line)


def _say_what_is_not_recorded(
    arguments: argparse.Namespace, simulation: Any, record_links_of_run_toml: list[str] | None
) -> None:
    """A line for each link pattern (of --record-links, or else of run.toml's `record_links`) that
    matches no link of the system: a misspelt glob would otherwise leave the trace quietly empty.
    (--record-links without a trace to record into is refused by `check_options`.)"""
    from earl.runtime.link_patterns import matching, no_link_matched

    links = simulation.network.link_index_variables
    if arguments.record_links is not None:
        patterns, said = arguments.record_links, "--record-links `{}`"
    else:  # the command line wins over run.toml: only the patterns the run uses are checked
        patterns, said = record_links_of_run_toml or [], "record_links `{}` in run.toml"
    for pattern in patterns:
        if not matching(pattern, links):
            print(f"earl run: {said.format(pattern)} {no_link_matched(pattern, links)}", file=sys.stderr)


#: signals that end a run as Ctrl-C does: `kill`, `timeout`, a service manager, a closed terminal
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class _StopRequest:
    """Whether a stop signal came, remembered: a function of the spec that catches every exception
    (`except: pass`) swallows the KeyboardInterrupt, and the run must still stop at its next step."""

    requested = False
    #: whether a Ctrl-C (SIGINT) asked: a second one stops at once
    by_ctrl_c = False
    #: whether the instant running outlasted STOP_INSIDE_AFTER: the run is stopped inside it
    forced = False


@contextlib.contextmanager
def handling_stop_signals(handler: Callable[..., None]) -> Iterator[None]:
    """`handler` for every one of STOP_SIGNALS meanwhile; the previous handlers afterwards. A signal the
    process was started to ignore stays ignored: `nohup earl run …` (SIGHUP) outlives its terminal, and a
    background job of a script (SIGINT) is not stopped by the Ctrl-C meant for the script."""
    previous = {
        number: signal.signal(number, handler) for number in STOP_SIGNALS if signal.getsignal(number) != signal.SIG_IGN
    }
    try:
        yield
    finally:
        for number, before in previous.items():
            signal.signal(number, before)


@contextlib.contextmanager
def _stopped_like_ctrl_c() -> Iterator[_StopRequest]:
    """Ctrl-C, SIGTERM and SIGHUP raise KeyboardInterrupt meanwhile, so that the run ends in order (exit 130)."""
    request = _StopRequest()

    def stop(number: int, frame: object) -> None:
        request.requested = True
        _program.raise_interrupt(number, frame)  # remembered, should compiled code swallow the interrupt

    with handling_stop_signals(stop):
        yield request


#: seconds the instant running may go on after a stop signal before the run is stopped inside it (an
#: instant that never ends: a function that never returns); less than `earl launch`'s STOP_GRACE, after
#: which it kills the process, so that the trace is closed first
STOP_INSIDE_AFTER = 2.0


@contextlib.contextmanager
def _stopped_between_instants() -> Iterator[_StopRequest]:
    """Ctrl-C, SIGTERM and SIGHUP ask the run to stop once the instant running has run to its end, so
    that every subsystem has run the same instants; a second Ctrl-C stops it at once, inside the instant
    (a function that never returns), and so does the first signal once the instant has gone on for
    STOP_INSIDE_AFTER seconds after it. A repeated SIGTERM or SIGHUP is the same request: `timeout` sends
    its SIGTERM to the run and again to the run's process group."""
    request = _StopRequest()
    main = threading.get_ident()
    #: held while the watcher signals the main thread, and taken to end: no signal after the handlers go
    lock = threading.Lock()
    ended = threading.Event()

    def watch(number: int) -> None:
        """Stop the run inside its instant if it has not stopped STOP_INSIDE_AFTER seconds after the request:
        the same signal again, whose handler then raises (and again, should the spec's code swallow it)."""
        while not ended.wait(STOP_INSIDE_AFTER):
            with lock:
                if ended.is_set():
                    return
                if not request.forced:
                    request.forced = True
                    with contextlib.suppress(OSError):
                        os.write(2, b"earl run: the instant running has not ended; stopping inside it\n")
                if hasattr(signal, "pthread_kill"):
                    signal.pthread_kill(main, number)  # wakes a sleep too, as the signal itself did
                else:  # Windows
                    _thread.interrupt_main(signal.Signals(number))

    def stop(number: int, *_: object) -> None:
        if request.forced or (request.requested and number == signal.SIGINT and request.by_ctrl_c):
            raise KeyboardInterrupt
        request.by_ctrl_c = request.by_ctrl_c or number == signal.SIGINT
        if not request.requested:
            request.requested = True
            with contextlib.suppress(OSError):  # said from a signal handler: one write, no Rich
                # `earl launch` stops its processes with SIGTERM: "Ctrl-C again" is advice for a terminal
                said = b" (Ctrl-C again to stop at once)" if number == signal.SIGINT else b""
                os.write(2, b"earl run: stopping after this instant" + said + b"\n")
            threading.Thread(target=watch, args=(number,), name="earl-stop-watch", daemon=True).start()

    with handling_stop_signals(stop):
        try:
            yield request
        finally:
            with lock:
                ended.set()


def _close(transport: Any) -> None:
    if transport is not None:
        transport.close()


def _seed(text: str) -> int:
    """`--seed`: what NumPy's seed sequences take, refused at the command line rather than in a function."""
    # ASCII digits, as run.toml's seed and --param take: `int` would also read `٣` and `1_000`
    if re.fullmatch(r"[+-]?[0-9]+", text) is None:  # `+5` too, as --param N=+6 and run.toml's seed take it
        raise argparse.ArgumentTypeError(f"`{text}` is not a whole number")
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"`{text}`: a seed is a whole number >= 0")
    return value


def _execute(
    simulation: Any,
    duration: float,
    arguments: argparse.Namespace,
    report: Callable[[Any], object] | None,
    report_name: str,
    path: Path,
) -> int:
    from earl.runtime.scheduler import ZeroTimeLoop
    from earl.runtime.simulation import EnvironmentFailed
    from earl.runtime.trace import TraceWriteError

    # markup off: what is printed includes text of the spec's code (`[/dev/ttyUSB0]` is no Rich tag)
    console = Console(stderr=True, highlight=False, markup=False)
    interrupted = False
    failed: TraceWriteError | None = None
    exited: SystemExit | None = None
    broken: EnvironmentFailed | None = None
    looped: ZeroTimeLoop | None = None
    from earl.cli import main as program

    if program.AS_PROGRAM:
        # What is built by now (the model, NumPy, MuJoCo, Lark's tables) lives until the process ends:
        # frozen, it is skipped by the collector's full passes during the run and at the exit. (Any
        # garbage of the set-up is frozen with it, and goes with the process.)
        gc.freeze()
    started = time.perf_counter()
    try:
        with _stopped_between_instants() as stop:
            _advance(simulation, duration, arguments, console, started, stop)
    except KeyboardInterrupt:
        interrupted = True
    except TraceWriteError as error:  # a full disk, say: the run stops, what was written stays readable
        failed = error
    except SystemExit as request:  # the spec's own code called sys.exit(): the run ends there, in order
        exited = request
    except EnvironmentFailed as error:  # the plant failed (a diverging simulation): the run ends there
        broken = error
    except ZeroTimeLoop as error:  # subsystems without a period woke each other for ever: time cannot pass
        looped = error
    finally:
        wall = time.perf_counter() - started
        try:
            simulation.close()
        except TraceWriteError as error:
            failed = failed or error
        except EnvironmentFailed as error:
            broken = broken or error
    if failed is not None:
        print(f"earl run: {failed} (the run reached {simulation.time:.3f} s)", file=sys.stderr)
        return EXIT_FAILED
    _summary(simulation, wall, arguments)
    #: messages of a link refused for another data type (here, or by a receiver that said so): data lost
    lost = False
    if simulation.transport is not None:
        from earl.transport.process import print_link_statistics, say_refused_links

        print_link_statistics(simulation.transport)
        lost = say_refused_links(simulation.transport)
    plotted = _plot(arguments, console) if arguments.plot else True
    # a report that fails is a run that did not give what it was asked for, as a plot not drawn is
    reported = _report(simulation, report, report_name, path, console) if report is not None else True
    delivered = plotted and reported
    if broken is not None:
        console.print(f"earl run: {brief(str(broken))} at {simulation.time:.3f} s; the run stopped there")
        return EXIT_FAILED
    if looped is not None:  # it says its run time
        console.print(f"earl run: {looped}; the run stopped there")
        return EXIT_FAILED
    if interrupted:
        closed = "; the trace is closed" if arguments.trace else ""
        console.print(f"earl run: interrupted at {simulation.time:.3f} s{closed}")
        return EXIT_INTERRUPTED
    if exited is not None:
        status = exited.code
        console.print(
            f"earl run: the spec's code called sys.exit({'' if status is None else repr(status)}) at "
            f"{simulation.time:.3f} s; the run stopped there" + (" and the trace is closed" if arguments.trace else "")
        )
        return EXIT_OK if status in (None, 0) and delivered and not lost else EXIT_FAILED
    # a plot asked for and not drawn (as `earl plot` says it), a report that failed, a link refused
    return EXIT_OK if delivered and not lost else EXIT_FAILED


def _advance(
    simulation: Any,
    duration: float,
    arguments: argparse.Namespace,
    console: Console,
    started: float,
    stop: _StopRequest,
) -> None:
    """Run to `duration` in 200 steps; a progress bar on a terminal once the run takes more than a second."""
    steps = 200
    progress: Progress | None = None
    try:
        for step in range(1, steps + 1):
            simulation.advance_to(duration * step / steps, should_stop=lambda: stop.requested)
            if stop.requested:  # between two instants: the run ends as interrupted (exit 130)
                raise KeyboardInterrupt
            elapsed = time.perf_counter() - started
            if progress is None and elapsed > 1.0 and not arguments.no_progress and console.is_terminal:
                progress = Progress(
                    TextColumn("[bold]earl run[/bold]"),
                    BarColumn(),
                    TextColumn("{task.fields[simulated]}"),
                    TimeRemainingColumn(),
                    console=console,
                    transient=True,
                )
                progress.start()
                progress.add_task("run", total=steps, completed=step, simulated="")
            if progress is not None:
                progress.update(progress.task_ids[0], completed=step, simulated=f"{simulation.time:.2f} s")
    finally:
        if progress is not None:
            progress.stop()


def _summary(simulation: Any, wall: float, arguments: argparse.Namespace) -> None:
    console = table_console()
    table = Table(title=f"system {simulation.system.name}: {simulation.time:.3f} s", title_justify="left")
    # names in full: the members of a family differ only at their end (`manip/a.motorController[3]/ve`)
    longest = max((len(name) for name in simulation.subsystems), default=9)
    table.add_column("subsystem", no_wrap=True, min_width=longest)
    table.add_column("state at the end", overflow="fold")
    table.add_column("iterations", justify="right")
    table.add_column("transitions", justify="right")
    table.add_column("faults", justify="right")
    if arguments.realtime:
        table.add_column("start lateness p50 / p99", justify="right")
        table.add_column("overruns", justify="right")
    for name in simulation.subsystems:
        state = simulation.state_of(name)
        stats = simulation.statistics.subsystems.get(name)
        transitions = sum(stats.transitions.values()) if stats else 0
        row = [name, state.state, str(state.iterations), str(transitions), str(state.faults)]
        if arguments.realtime:
            lateness = simulation.scheduler.lateness.get(name)
            if lateness and lateness.samples:
                samples = sorted(lateness.samples)
                p50 = statistics.median(samples) / 1e3
                p99 = samples[min(len(samples) - 1, int(0.99 * len(samples)))] / 1e3
                row += [f"{p50:.0f} µs / {p99:.0f} µs", str(lateness.overruns)]
            else:
                row += ["–", "0"]
        table.add_row(*row)
    console.print(table)
    faults = simulation.faults
    if faults:
        kinds = fault_kinds(fault.kind for fault in faults)
        console.print(
            Text.assemble((f"{len(faults)} fault(s)", "yellow"), f" ({kinds}; docs/semantics.md, Faults); the first:"),
            soft_wrap=True,
        )
        first = faults[0]
        place = brief(fault_place(first.traceback))
        console.print(
            f"  t={first.time:.6f} s {first.subsystem} ({first.kind}): {brief(first.message)}{place}",
            soft_wrap=True,
        )
        if any(fault.traceback for fault in faults):
            where = arguments.trace or "FILE.mcap"
            after = "" if arguments.trace else "run with --trace FILE.mcap, then "
            console.print(f"  tracebacks: {after}earl trace faults {where}", soft_wrap=True)
    ratio = simulation.time / wall if wall > 0 else float("inf")
    mode = "real time" if arguments.realtime else "virtual time"
    console.print(f"ran {simulation.time:.3f} s of {mode} in {wall:.2f} s of wall time ({ratio:.1f}x real time)")
    if arguments.trace:
        console.print(f"trace: {arguments.trace} (earl trace summary {arguments.trace}; opens in Foxglove)")


def _plot(arguments: argparse.Namespace, console: Console) -> bool:
    """Whether the plot was drawn; the run and its trace are whole either way."""
    from earl.runtime.plot import plot_signals
    from earl.runtime.trace_reader import TraceError

    if not arguments.signal:  # every signal of run.toml's `plot` is of another process's agents
        console.print("earl run: no plot: no signal of run.toml's `plot` is of an agent this process runs")
        return False
    try:
        left_out = plot_signals(Path(arguments.trace), arguments.signal, Path(arguments.plot))
    except TraceError as error:
        console.print(f"earl run: no plot: {error}")
        return False
    except OSError as error:  # a read-only directory, a full disk: the run and its trace are fine
        console.print(f"earl run: no plot: cannot write {arguments.plot}: {error.strerror or error}")
        return False
    for line in left_out:
        console.print(f"earl run: plot: {line}")
    console.print(f"plot: {arguments.plot}")
    return True


def _report(simulation: Any, function: Callable[[Any], object], report: str, path: Path, console: Console) -> bool:
    """The example's own closing lines (`report = "module:function"` in run.toml, bound before the run);
    whether it gave them."""
    from earl.runtime.binding import user_code_path

    with user_code_path([path.resolve().parent]):  # for what the report imports as it runs
        try:
            text = function(simulation)
        except Exception as error:  # the report is the example's code: say what failed
            console.print(f"earl run: the report `{report}` failed: {type(error).__name__}: {error}")
            return False
        except SystemExit as leaving:  # sys.exit in the report must not choose earl's exit code
            console.print(f"earl run: the report `{report}` called sys.exit({leaving.code!r}); its text is lost")
            return False
    if text:
        print(text)
    return True
