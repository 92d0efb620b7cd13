"""`earl launch SPEC --deployment deploy.toml`: every process of a deployment on this host, supervised.

Each process is `earl run SPEC --transport zenoh --agents …` for one `[[process]]` of the
deployment file; the `args` of each are checked before any is started.  Their output is
shown line by line, prefixed with the process's agents; Ctrl-C, SIGTERM or SIGHUP stops them
all (SIGTERM, a bounded wait, then SIGKILL; a second Ctrl-C kills at once), and so does a
reader of the output that goes away.
Each process says on a pipe of its own (STATUS_VARIABLE) when its run has started: set up,
its code bound, its Zenoh session open.  A process that ends before that stops them all (the
others cannot run the deployment without it); one that fails later is reported and the others
go on: the distributed runtime is built to outlive a lost peer (docs/distributed.md).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import select
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import IO, Any

from earl.cli.common import (
    STARTED,
    STATUS_VARIABLE,
    SUPERVISOR_VARIABLE,
    UsageError,
    named_path,
    spec_path,
    usage_error,
)
from earl.cli.output import print_diagnostics
from earl.cli.run_command import handling_stop_signals
from earl.diagnostics import EarlError
from earl.transport.deployment import Deployment

EXIT_OK, EXIT_FAILED, EXIT_INTERRUPTED = 0, 1, 130
#: seconds a process gets to finish its trace after SIGTERM before it is killed
STOP_GRACE = 5.0

EPILOG = """\
examples:
  earl launch examples/pick_and_place --deployment examples/pick_and_place/deploy.toml
  earl launch examples/pick_and_place --deployment deploy.toml --duration 20s

The deployment file lists the processes: their agents, their Zenoh `listen` endpoint,
whether the run.toml environment lives there, and extra `earl run` options
(docs/distributed.md). Only processes whose `host` is this machine are started.

Ctrl-C, SIGTERM or SIGHUP (a closed terminal) stops every process: SIGTERM to each (they
close their traces), at most 5 s of grace, then SIGKILL; a second Ctrl-C kills at once. A
reader of the output that goes away (`earl launch … | head`) stops them the same way.

A process that ends before its run has started (its code cannot be bound, its port is held,
bad options) stops them all: the others cannot run the deployment without it. One that fails
later is reported, and the others go on (the runtime outlives a lost peer).

exit codes: 0 every process completed, 1 a process failed (or ended before its run started,
            and every process was stopped), the deployment or a process's `args` is invalid,
            or the output was closed (every process was stopped), 2 usage error (a missing
            spec or deployment file, a bad option; --duration is checked before anything
            starts), 130 interrupted by Ctrl-C, SIGTERM or SIGHUP (every process was stopped)
"""


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "launch",
        help="start the processes of a deployment (agents split over processes, linked by Zenoh) and supervise them",
        description="Start one `earl run --transport zenoh` process per group of agents of the deployment file that "
        "runs on this host; show their output prefixed by their agents; stop them all on Ctrl-C, SIGTERM or SIGHUP.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", metavar="SPEC", help="the .earl file, or a directory with a system.earl")
    parser.add_argument(
        "--deployment",
        metavar="deploy.toml",
        help="the processes and their endpoints (default: deploy.toml next to SPEC)",
    )
    parser.add_argument("--duration", metavar="TIME", help="run time of every process (default: run.toml's)")
    parser.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="set a system parameter (repeatable)"
    )
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from earl.runtime.run_settings import read_run_settings
    from earl.transport.deployment import DeploymentError, read_deployment
    from earl.transport.process import DEPLOYMENT_FILE

    try:
        path = spec_path(arguments.spec)
        if arguments.deployment is not None:  # an empty one is not the default deploy.toml
            named_path(arguments.deployment, "--deployment", "deploy.toml")
    except UsageError as error:
        return usage_error(str(error))
    deployment_path = Path(arguments.deployment) if arguments.deployment else path.parent / DEPLOYMENT_FILE
    if deployment_path.is_dir():
        return usage_error(f"the deployment {deployment_path} is a directory; name its file, e.g. {DEPLOYMENT_FILE}")
    if not deployment_path.is_file():
        return usage_error(f"no deployment file {deployment_path}; name one with --deployment (docs/distributed.md)")
    try:
        deployment = read_deployment(deployment_path)
        known, acting = _agents(path, arguments.param)
        deployment = deployment.check_agents(known)
        environment = read_run_settings(path).environment
        if environment not in (None, "none"):
            # each `earl run` places it by the same rule; said here, before anything starts
            deployment = deployment.place_environment(acting)
    except DeploymentError as error:
        print(f"earl launch: {error}", file=sys.stderr)
        return EXIT_FAILED
    except ValueError as error:  # a run.toml that cannot be used
        return usage_error(str(error))
    except UsageError as error:
        return usage_error(str(error))
    except EarlError as error:
        print_diagnostics(error.diagnostics, error.sources)
        print("earl launch: the specification cannot be read; nothing was started", file=sys.stderr)
        return EXIT_FAILED
    local = [process for process in deployment.processes if process.is_local]
    if not local:
        from earl.transport.deployment import this_host_name

        hosts = ", ".join(sorted({process.host for process in deployment.processes}))
        print(
            f"earl launch: {deployment.at(1, 'host')}: no process for this host, `{this_host_name()}` "
            f"(its processes run on {hosts})",
            file=sys.stderr,
        )
        return EXIT_FAILED
    shared = _shared_output(deployment)
    if shared is not None:
        print(f"earl launch: {shared}; nothing was started", file=sys.stderr)
        return EXIT_FAILED
    if arguments.duration is not None:  # `--duration=` too: the processes would run the default
        from earl.runtime.durations import parse_duration

        try:
            parse_duration(arguments.duration)
        except ValueError as error:
            return usage_error(f"--duration: {error}")
    common = [str(path), "--transport", "zenoh", "--deployment", str(deployment_path), "--no-progress"]
    if arguments.duration is not None:
        common += ["--duration", arguments.duration]
    for parameter in arguments.param:
        common += ["--param", parameter]
    for number, process in enumerate(deployment.processes, start=1):
        if not process.is_local:
            continue
        problem = _args_problem([*common, "--agents", process.label, *process.args])
        if problem is not None:
            print(
                f"earl launch: {deployment.at(number, 'args')}: process {number} ({process.label}) cannot run "
                f"with its `args`: "
                f"{problem}; nothing was started",
                file=sys.stderr,
            )
            return EXIT_FAILED
    supervisor = _Supervisor([process.label for process in deployment.processes])
    for process in deployment.processes:
        if not process.is_local:
            # said, not silent: a misspelt host would otherwise leave its agents' links stale without a word
            supervisor.say(process.label, f"runs on host `{process.host}`, not started here")
    with supervisor.stopping_on_signals():
        for process in local:
            if supervisor.stop_requested:
                break
            # whether the environment runs there, each process reads from the deployment file as checked above
            command = [sys.executable, "-m", "earl.cli.main", "run", *common, "--agents", process.label]
            command += list(process.args)
            supervisor.start(process.label, command)
        return supervisor.wait()


def _agents(spec: Path, parameters: list[str]) -> tuple[list[str], list[str]]:
    """The agents of the expanded system, and those with Real Effectors or Receptors, so that a
    deployment missing one, or keeping one apart from the environment, fails before anything starts."""
    from earl.cli.common import parse_parameters
    from earl.lang.loader import load
    from earl.model.expand import expand
    from earl.runtime.names import agent_name
    from earl.transport.process import acting_agents

    values = parse_parameters(parameters)
    expanded = expand(load(spec, values), values)
    return [agent_name(agent) for agent in expanded.agents], acting_agents(expanded)


class _Refused(Exception):
    """What argparse would say of a process's command line (instead of printing it and exiting)."""


class _RefusingParser(argparse.ArgumentParser):
    def error(self, message: str) -> Any:
        raise _Refused(message)

    def exit(self, status: int = 0, message: str | None = None) -> Any:
        # `--help` or `--version` among the args: the process would print them and end, running nothing
        raise _Refused("it asks for help, and would run nothing")


def _args_problem(command: list[str]) -> str | None:
    """What `earl run` would refuse in `command` (its options after `earl run`) before running anything:
    an unknown option, a bad value, a trace or plot directory that does not exist, an empty --duration.
    Found without reading the spec, as `earl run` finds it (`run_command.check_options`)."""
    import io

    from earl.cli import run_command

    parser = _RefusingParser(prog="earl", add_help=False)
    run_command.register(parser.add_subparsers(dest="command", parser_class=_RefusingParser))
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            options = parser.parse_args(["run", *command])
        run_command.check_options(options)
    except _Refused as refused:
        return str(refused)
    except UsageError as error:
        return str(error)
    return None


def _shared_output(deployment: Deployment) -> str | None:
    """Two of this host's processes whose `args` write one file: a `--trace`, a `--plot`, or the trace a
    `--plot` implies (`p.png` → `p.mcap`), said at the second one's `args`. The later would refuse it (an
    existing file) or, started at the same moment, overwrite the other's. The args are read as `earl run`
    reads them (abbreviations too)."""
    reader = argparse.ArgumentParser(add_help=False, exit_on_error=False)
    reader.add_argument("--trace")
    reader.add_argument("--plot")
    written: dict[Path, str] = {}
    for number, process in enumerate(deployment.processes, start=1):
        if not process.is_local:
            continue
        try:
            options, _ = reader.parse_known_args(list(process.args))
        except (argparse.ArgumentError, SystemExit):
            continue  # `earl run` says what is wrong with them, in the process's own output
        files = [("--plot", options.plot)] if options.plot else []
        trace = options.trace or (str(Path(options.plot).with_suffix(".mcap")) if options.plot else None)
        if trace:
            files.append(("--trace" if options.trace else "--plot's trace", trace))
        for option, value in files:
            target = Path(value).resolve()
            if target in written:
                return (
                    f"{deployment.at(number, 'args')}: process {number} ({process.label}) writes {value} "
                    f"({option}), as {written[target]} does: give each its own file"
                )
            written[target] = process.label
    return None


class _Supervisor:
    """The children, the threads that copy their output, and the stop on Ctrl-C, SIGTERM or SIGHUP.

    The signal handlers only take note: a stop requested while a child is being started must not lose
    that child (it runs in a session of its own, where nothing else would ever stop it). A second
    Ctrl-C while the children finish their traces kills them at once.
    """

    def __init__(self, labels: list[str]) -> None:
        self.children: list[tuple[str, subprocess.Popen[bytes]]] = []
        self.copiers: list[threading.Thread] = []
        self.copier_of: dict[int, threading.Thread] = {}
        #: children whose failure was said as it happened
        self.reported: set[int] = set()
        #: the read end of each child's status pipe (by pid), until it says its run started or ends
        self.status: dict[int, int] = {}
        #: what each child wrote on its status pipe so far
        self.said: dict[int, bytes] = {}
        #: children whose run started (said on their status pipe)
        self.started: set[int] = set()
        #: the first child that ended before its run started: every other one is stopped
        self.failed_to_start: str | None = None
        self.lock = threading.Lock()
        self.width = max((len(label) for label in labels), default=0)
        self.signals = 0
        #: the reader of our output went away (`earl launch … | head`): the children are stopped
        self.output_closed = False

    @property
    def stop_requested(self) -> bool:
        return self.signals > 0 or self.output_closed

    def stopping_on_signals(self) -> contextlib.AbstractContextManager[None]:
        def note(*_: object) -> None:
            self.signals += 1

        return handling_stop_signals(note)

    def start(self, label: str, command: list[str]) -> None:
        # Rich draws the children's tables for a pipe 80 columns wide unless told otherwise
        columns = max(100, shutil.get_terminal_size((160, 24)).columns - self.width - 3)
        # the child says on this pipe when its run has started; its end closes the pipe in any case
        status, said = os.pipe()
        try:
            child = subprocess.Popen(
                command,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                # a session of its own: Ctrl-C reaches the supervisor, which stops the children in order
                start_new_session=True,
                pass_fds=(said,),
                env={
                    **os.environ,
                    "PYTHONUNBUFFERED": "1",
                    "COLUMNS": str(columns),
                    # the child stops itself (as on SIGTERM) should this supervisor die without stopping it
                    SUPERVISOR_VARIABLE: str(os.getpid()),
                    STATUS_VARIABLE: str(said),
                },
            )
        except BaseException:
            os.close(status)
            raise
        finally:
            os.close(said)
        os.set_blocking(status, False)
        self.status[child.pid] = status
        self.children.append((label, child))
        assert child.stdout is not None
        copier = threading.Thread(target=self._copy, args=(label, child.stdout), daemon=True)
        copier.start()
        self.copiers.append(copier)
        self.copier_of[child.pid] = copier
        self.say(label, f"started (pid {child.pid}): earl {' '.join(command[3:])}")

    def _copy(self, label: str, stream: IO[bytes]) -> None:
        # read to the end even when our output is gone: a child whose pipe fills up would block for ever
        for raw in iter(stream.readline, b""):
            self.say(label, raw.decode("utf-8", errors="replace").rstrip("\n"))

    def say(self, label: str, line: str) -> None:
        with self.lock:
            if self.output_closed:
                return
            try:
                sys.stdout.write(f"[{label.ljust(self.width)}] {line}\n")
                sys.stdout.flush()
            except (BrokenPipeError, OSError):
                self.output_closed = True

    def wait(self) -> int:
        try:
            return self._wait()
        finally:
            self._close_status()

    def _wait(self) -> int:
        while (
            any(child.poll() is None for _, child in self.children)
            and not self.stop_requested
            and self.failed_to_start is None
        ):
            time.sleep(0.1)
            if _reader_gone():
                self.output_closed = True
            self._report_failures()
        if not self.stop_requested:
            self._report_failures()  # the last to end, since the last look
        if self.failed_to_start is not None and not self.stop_requested:
            # the others would wait for it (--wait-for-peers), then run without it: the deployment cannot run
            self.stop_all()
            self._join()
            with contextlib.suppress(OSError):
                print(
                    f"earl launch: {self.failed_to_start} ended before its run started; every process was stopped",
                    file=sys.stderr,
                )
            return EXIT_FAILED
        if self.stop_requested:
            self.stop_all()
            self._join()
            if self.output_closed:
                with contextlib.suppress(OSError):
                    print("earl launch: the output was closed; every process was stopped", file=sys.stderr)
                return EXIT_FAILED
            return EXIT_INTERRUPTED
        self._join()
        self._report_failures()
        failed = [label for label, child in self.children if child.returncode != 0]
        return EXIT_FAILED if failed else EXIT_OK

    def _report_failures(self) -> None:
        """A process that failed is said as soon as it ends (after its last lines), not after the others:
        they may run for a long while yet. One that ended before its run started (whatever its exit code)
        stops them all (`failed_to_start`)."""
        for label, child in self.children:
            self._read_status(child.pid)
            code = child.poll()
            if code is None or child.pid in self.reported:
                continue
            self._read_status(child.pid)  # what it said before it ended
            before_start = child.pid not in self.started
            if code == 0 and not before_start:
                continue
            self.reported.add(child.pid)
            copier = self.copier_of.get(child.pid)
            if copier is not None:
                copier.join(timeout=2.0)
            if before_start and self.failed_to_start is None and not self.stop_requested:
                self.failed_to_start = label
                self.say(
                    label,
                    f"ended with {_exit_status(code)} before its run started; the others cannot run the "
                    "deployment without it: stopping them",
                )
            else:
                self.say(label, f"failed with {_exit_status(code)}")

    def _read_status(self, pid: int) -> None:
        """Whatever the child wrote on its status pipe since the last look; the pipe is closed once it said
        its run started, or it ended."""
        status = self.status.get(pid)
        if status is None:
            return
        while True:
            try:
                data = os.read(status, 64)
            except BlockingIOError:
                return
            except OSError:
                data = b""
            if data:
                self.said[pid] = self.said.get(pid, b"") + data
                if STARTED in self.said[pid]:
                    self.started.add(pid)
                continue
            del self.status[pid]  # the end of the pipe: the child closed it, or ended
            os.close(status)
            return

    def _close_status(self) -> None:
        for status in self.status.values():
            with contextlib.suppress(OSError):
                os.close(status)
        self.status.clear()

    def stop_all(self) -> None:
        """SIGTERM to each (they close their traces and exit 130), then SIGKILL after a bounded wait, or at
        a second stop signal."""
        signals_before = self.signals
        for label, child in self.children:
            if child.poll() is None:
                self.say(label, "stopping")
                child.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + STOP_GRACE
        while any(child.poll() is None for _, child in self.children):
            if time.monotonic() >= deadline or self.signals > max(signals_before, 1):
                late = time.monotonic() >= deadline
                for label, child in self.children:
                    if child.poll() is None:
                        self.say(label, f"did not stop within {STOP_GRACE:g} s; killed" if late else "killed")
                        _kill_session(child)
                break
            time.sleep(0.05)
        for _, child in self.children:
            child.wait()

    def _join(self) -> None:
        for copier in self.copiers:
            copier.join(timeout=2.0)


def _reader_gone() -> bool:
    """Whether our standard output is a pipe whose reader has closed it (`| head` is done): known at once,
    not only at the next line a child prints, which may come at the end of a long run."""
    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(events & (select.POLLERR | select.POLLHUP) for _, events in poller.poll(0))
    except (OSError, ValueError, AttributeError):  # no file descriptor (a test's stream), no poll here
        return False


def _kill_session(child: subprocess.Popen[bytes]) -> None:
    """SIGKILL to the child's whole session; its trace writer, in a session of its own, finishes the file."""
    try:
        os.killpg(child.pid, signal.SIGKILL)
    except OSError:
        child.kill()


def _exit_status(code: int) -> str:
    """`exit code 1`, or `signal 9 (SIGKILL)` for a process a signal ended (Popen's negative codes)."""
    if code >= 0:
        return f"exit code {code}"
    try:
        name = signal.Signals(-code).name
    except ValueError:
        return f"signal {-code}"
    return f"signal {-code} ({name})"
