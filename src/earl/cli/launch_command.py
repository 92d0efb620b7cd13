"""`earl launch SPEC --deployment deploy.toml`: every process of a deployment on this host, supervised.

Each process is `earl run SPEC --transport zenoh --agents …` for one `[[process]]` of the
deployment file.  Their output is shown line by line, prefixed with the process's
agents; Ctrl-C or SIGTERM stops them all (SIGTERM, a bounded wait, then SIGKILL).
A process that fails is reported and the others go on: the distributed runtime is
built to outlive a lost peer (docs/distributed.md).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import IO, Any

from earl.cli.common import UsageError, spec_path, usage_error
from earl.cli.output import print_diagnostics
from earl.diagnostics import EarlError

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

exit codes: 0 every process completed, 1 a process failed or the deployment is invalid,
            2 usage error, 130 interrupted (every process was stopped)
"""


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "launch",
        help="start the processes of a deployment (agents split over processes, linked by Zenoh) and supervise them",
        description="Start one `earl run --transport zenoh` process per group of agents of the deployment file that "
        "runs on this host; show their output prefixed by their agents; stop them all on Ctrl-C.",
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
    from earl.transport.deployment import DeploymentError, read_deployment
    from earl.transport.process import DEPLOYMENT_FILE

    try:
        path = spec_path(arguments.spec)
    except UsageError as error:
        return usage_error(str(error))
    deployment_path = Path(arguments.deployment) if arguments.deployment else path.parent / DEPLOYMENT_FILE
    if not deployment_path.is_file():
        return usage_error(f"no deployment file {deployment_path}; name one with --deployment (docs/distributed.md)")
    try:
        deployment = read_deployment(deployment_path)
        deployment.check_agents(_agents(path, arguments.param))
    except DeploymentError as error:
        print(f"earl launch: {error}", file=sys.stderr)
        return EXIT_FAILED
    except UsageError as error:
        return usage_error(str(error))
    except EarlError as error:
        print_diagnostics(error.diagnostics, error.sources)
        print("earl launch: the specification cannot be read; nothing was started", file=sys.stderr)
        return EXIT_FAILED
    local = [process for process in deployment.processes if process.is_local]
    if not local:
        print(f"earl launch: {deployment_path} has no process for this host", file=sys.stderr)
        return EXIT_FAILED
    common = [str(path), "--transport", "zenoh", "--deployment", str(deployment_path), "--no-progress"]
    if arguments.duration:
        common += ["--duration", arguments.duration]
    for parameter in arguments.param:
        common += ["--param", parameter]
    supervisor = _Supervisor()
    for process in local:
        command = [sys.executable, "-m", "earl.cli.main", "run", *common, "--agents", process.label]
        if not process.environment:
            command += ["--environment", "none"]
        command += list(process.args)
        supervisor.start(process.label, command)
    return supervisor.wait()


def _agents(spec: Path, parameters: list[str]) -> list[str]:
    """The agents of the expanded system, so that a deployment missing one fails before anything starts."""
    from earl.cli.common import parse_parameter
    from earl.lang.loader import load
    from earl.model.expand import expand
    from earl.runtime.names import agent_name

    values = dict(parse_parameter(p) for p in parameters)
    return [agent_name(agent) for agent in expand(load(spec, values), values).agents]


class _Supervisor:
    """The children, the threads that copy their output, and the stop on Ctrl-C / SIGTERM."""

    def __init__(self) -> None:
        self.children: list[tuple[str, subprocess.Popen[bytes]]] = []
        self.copiers: list[threading.Thread] = []
        self.lock = threading.Lock()
        self.width = 0

    def start(self, label: str, command: list[str]) -> None:
        self.width = max(self.width, len(label))
        child = subprocess.Popen(
            command,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            # a session of its own: Ctrl-C reaches the supervisor, which stops the children in order
            start_new_session=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        self.children.append((label, child))
        assert child.stdout is not None
        copier = threading.Thread(target=self._copy, args=(label, child.stdout), daemon=True)
        copier.start()
        self.copiers.append(copier)
        self._print(label, f"started (pid {child.pid}): earl {' '.join(command[3:])}")

    def _copy(self, label: str, stream: IO[bytes]) -> None:
        for raw in iter(stream.readline, b""):
            self._print(label, raw.decode("utf-8", errors="replace").rstrip("\n"))

    def _print(self, label: str, line: str) -> None:
        with self.lock:
            sys.stdout.write(f"[{label.ljust(self.width)}] {line}\n")
            sys.stdout.flush()

    def wait(self) -> int:
        previous = signal.getsignal(signal.SIGTERM)

        def stop(*_: object) -> None:
            raise KeyboardInterrupt

        signal.signal(signal.SIGTERM, stop)
        try:
            while any(child.poll() is None for _, child in self.children):
                time.sleep(0.1)
        except KeyboardInterrupt:
            self.stop_all()
            self._join()
            return EXIT_INTERRUPTED
        finally:
            signal.signal(signal.SIGTERM, previous)
        self._join()
        failed = [(label, child.returncode) for label, child in self.children if child.returncode != 0]
        for label, code in failed:
            self._print(label, f"failed with exit code {code}")
        return EXIT_FAILED if failed else EXIT_OK

    def stop_all(self) -> None:
        """SIGTERM to each (they close their traces and exit 130), then SIGKILL after a bounded wait."""
        for label, child in self.children:
            if child.poll() is None:
                self._print(label, "stopping")
                child.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + STOP_GRACE
        for label, child in self.children:
            try:
                child.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                self._print(label, f"did not stop within {STOP_GRACE:g} s; killed")
                child.kill()
                child.wait()

    def _join(self) -> None:
        for copier in self.copiers:
            copier.join(timeout=2.0)
