"""The deployment file: which agents run together in one process, and where it listens.

    # deploy.toml
    [[process]]
    agents = ["manip/a", "grip/a"]       # run together in one OS process
    listen = "tcp/127.0.0.1:7451"        # its Zenoh endpoint; every other process connects to it
    environment = true                   # the run.toml environment (physics) lives here (see below)

    [[process]]
    agents = ["task/a"]
    listen = "tcp/127.0.0.1:7452"
    environment = false
    host = "localhost"                   # `earl launch` starts only this host's processes
    args = ["--trace", "task.mcap"]      # more `earl run` options for this process

Every agent of the system must be in exactly one process (docs/distributed.md).

The environment (run.toml's simulated world) exists once: the Real Effectors and Receptors that act
on it must all run in the one process that holds it, or each process would simulate a world of its
own and the gripper would close in another world than the arm's.  Unwritten, `environment` is true
for the process whose agents have Real Effectors or Receptors (the first process when no agent has).
"""

from __future__ import annotations

import contextlib
import functools
import socket
import tomllib
from collections.abc import Collection
from dataclasses import dataclass, field, replace
from pathlib import Path

from earl.diagnostics import did_you_mean
from earl.transport.listeners import Listener, clash, listener

LOCAL_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})


class DeploymentError(ValueError):
    """The deployment file cannot be used; the message names the file and what is wrong."""


@dataclass(frozen=True)
class ProcessGroup:
    """One OS process: the agents it runs and its Zenoh endpoint."""

    agents: tuple[str, ...]
    listen: str
    #: whether run.toml's environment lives here; None when the file does not say (`place_environment`)
    environment: bool | None = None
    host: str = "localhost"
    args: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        return ",".join(self.agents)

    @property
    def names_its_environment(self) -> bool:
        """Its `args` choose its environment (`--environment hardware:open`): the user's, not checked."""
        return any(arg == "--environment" or arg.startswith("--environment=") for arg in self.args)

    @property
    def is_local(self) -> bool:
        return is_this_host(self.host)


def is_this_host(host: str) -> bool:
    """Whether `host` names this machine: `localhost`, a loopback address, its name or full name (in any
    case, with or without the final dot), or one of the addresses its name resolves to."""
    name = host.strip().rstrip(".").lower().strip("[]")
    if name in LOCAL_HOSTS or name.startswith("127."):
        return True
    return name in _this_host_names()


def same_host(first: str, second: str) -> bool:
    """Whether two processes' `host`s are one computer, whose ports they share: the same name (in any case,
    with or without the final dot), or both this machine. Two names of one other computer (`robot` and its
    address) cannot be told apart here: they are taken to be two."""

    def plain(host: str) -> str:
        return host.strip().rstrip(".").lower().strip("[]")

    return plain(first) == plain(second) or (is_this_host(first) and is_this_host(second))


@functools.cache
def _this_host_names() -> frozenset[str]:
    names = {socket.gethostname().lower(), socket.getfqdn().lower().rstrip(".")}
    with contextlib.suppress(OSError):
        names |= {address.lower() for address in socket.gethostbyname_ex(socket.gethostname())[2]}
    return frozenset(names)


def this_host_name() -> str:
    return socket.gethostname()


@dataclass(frozen=True)
class Deployment:
    path: Path
    processes: tuple[ProcessGroup, ...] = field(default_factory=tuple)

    def group_of(self, agents: list[str]) -> ProcessGroup:
        """The process that runs exactly `agents` (in any order)."""
        wanted = {normalise_agent(a) for a in agents}
        for process in self.processes:
            if set(process.agents) == wanted:
                return process
        known = "; ".join(process.label for process in self.processes)
        raise DeploymentError(
            f"{self.path}: no process runs exactly the agents {', '.join(sorted(wanted))} (its processes: {known})"
        )

    def connect_for(self, process: ProcessGroup) -> list[str]:
        """The endpoints `process` connects to: every other process's."""
        return [other.listen for other in self.processes if other is not process]

    def check_agents(self, system_agents: list[str]) -> None:
        """Every agent of the system runs in one process, and the file names no other."""
        deployed = [agent for process in self.processes for agent in process.agents]
        known = set(system_agents)
        for number, process in enumerate(self.processes, start=1):
            for agent in process.agents:
                if agent not in known:
                    raise DeploymentError(
                        f"{self.path}: process {number}: `{agent}` is not an agent of this system "
                        f"(its agents: {', '.join(system_agents)})"
                    )
        missing = [agent for agent in system_agents if agent not in deployed]
        if missing:
            raise DeploymentError(
                f"{self.path}: the agent `{missing[0]}` runs in no process; add it to a process's `agents`"
            )

    def place_environment(self, acting: Collection[str]) -> Deployment:
        """This deployment with every process's `environment` decided, for a system whose agents
        `acting` have Real Effectors or Receptors; `DeploymentError` when the environment would run
        twice, or apart from an agent that acts on it.

        A process that does not say gets the environment when it runs an agent that acts on it and
        no process claims it with `environment = true`; in a system with no such agent, the first
        process that does not say gets it."""
        checked = [process for process in self.processes if not process.names_its_environment]
        claimed = any(process.environment for process in checked)
        acting = set(acting)
        anyone_acts = any(not acting.isdisjoint(process.agents) for process in self.processes)
        first_silent = next((process for process in checked if process.environment is None), None)

        def decided(process: ProcessGroup) -> bool | None:
            if process.environment is not None or process.names_its_environment:
                return process.environment
            if claimed:
                return False
            return not acting.isdisjoint(process.agents) if anyone_acts else process is first_silent

        placed = replace(self, processes=tuple(replace(p, environment=decided(p)) for p in self.processes))
        placed._check_environment(acting)
        return placed

    def _check_environment(self, acting: Collection[str]) -> None:
        numbered = [(n, p) for n, p in enumerate(self.processes, start=1) if not p.names_its_environment]
        holders = [(n, p) for n, p in numbered if p.environment]
        if len(holders) > 1:
            (first, one), (second, other) = holders[0], holders[1]
            raise DeploymentError(
                f"{self.path}: the environment would run in process {first} ({one.label}) and in process "
                f"{second} ({other.label}), each simulating a world of its own; give it to one process "
                "(`environment = false` in the others) and run every agent with Real Effectors or Receptors there"
            )
        if not holders:
            unheld = [(n, agent) for n, p in numbered for agent in p.agents if agent in acting]
            if unheld:
                number, agent = unheld[0]
                raise DeploymentError(
                    f"{self.path}: no process runs the environment, but `{agent}` (process {number}) has Real "
                    f"Effectors or Receptors that act on it; give process {number} `environment = true`, or "
                    'its own environment in its `args` (`args = ["--environment", "module:factory"]`)'
                )
            return
        number, holder = holders[0]
        for other_number, process in numbered:
            away = [agent for agent in process.agents if agent in acting]
            if process is not holder and away:
                raise DeploymentError(
                    f"{self.path}: process {other_number} runs `{away[0]}`, whose Real Effectors or Receptors "
                    f"act on the environment, but the environment lives in process {number} ({holder.label}); "
                    f"run `{away[0]}` in process {number}"
                )


def normalise_agent(name: str) -> str:
    """`task` and `task/a` both name the agent `task/a`; a name with another `/` part stays as written,
    so that the message refusing it shows what was written (`sender/b`, not `sender/b/a`)."""
    name = name.strip()
    return name if "/" in name else f"{name}/a"


#: protocols whose endpoints are `PROTOCOL/HOST:PORT`
_NETWORK_PROTOCOLS = frozenset({"tcp", "udp", "tls", "quic", "ws"})


#: Zenoh's other link protocols, whose addresses are Zenoh's own to check
_OTHER_PROTOCOLS = frozenset({"unixsock-stream", "unixpipe", "serial", "vsock"})


def _is_port_number(text: str) -> bool:
    """ASCII digits only: `str.isdigit` also takes `١٧٤٥١` (which Zenoh refuses) and `²` (which `int` refuses)."""
    return text.isascii() and text.isdigit()


def endpoint_problem(endpoint: str) -> str | None:
    """What is wrong with a `listen` endpoint of the network protocols, checked before anything starts
    (Zenoh would say it only as the process opens, in its own words); None when it looks right."""
    protocol, _, address = endpoint.partition("/")
    if protocol in _OTHER_PROTOCOLS:
        return None
    if protocol not in _NETWORK_PROTOCOLS:
        known = sorted(_NETWORK_PROTOCOLS | _OTHER_PROTOCOLS)
        hint = did_you_mean(protocol, known) or f"Zenoh's protocols: {', '.join(known)}"
        return f"`{protocol}` is not a protocol of Zenoh; {hint}"
    address = address.split("#", 1)[0].split("?", 1)[0]  # Zenoh's endpoint metadata and configuration
    host, colon, port = address.rpartition(":")
    if not colon or not host:
        return f"write it as {protocol}/HOST:PORT, e.g. {protocol}/127.0.0.1:7451"
    if not _is_port_number(port) or not 1 <= int(port) <= 65535:
        return f"`{port}` is not a port (a whole number from 1 to 65535, in ASCII digits)"
    return None


#: `earl run` options `earl launch` gives each process, which its `args` may not give again
LAUNCH_SETS = {
    "--transport": "always zenoh",
    "--agents": "from the process's `agents`",
    "--deployment": "this file",
}


#: the other `earl run` options that begin as one of LAUNCH_SETS does (tests/test_transport.py keeps this
#: list equal to the run's parser): a prefix of both is ambiguous, and `earl run` says so itself
SHARING_A_PREFIX = ("--trace", "--duration")


def _launch_option(arg: str) -> str | None:
    """The option of LAUNCH_SETS that `arg` gives as `earl run` reads it: whole, with `=VALUE`, or
    abbreviated (`--agent`, `--trans=inproc`: argparse takes any prefix no other option shares)."""
    written = arg.split("=", 1)[0]
    if not written.startswith("--") or len(written) < 3:
        return None
    if written not in LAUNCH_SETS and any(other.startswith(written) for other in SHARING_A_PREFIX):
        return None  # `--tra`: `--trace` or `--transport`, an ambiguity `earl run` refuses in its own words
    return next((option for option in LAUNCH_SETS if option.startswith(written)), None)


def read_deployment(path: Path) -> Deployment:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise DeploymentError(f"cannot read the deployment file {path}: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise DeploymentError(f"{path}: not UTF-8 text") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DeploymentError(f"{path}: not valid TOML: {error}") from None
    unknown = sorted(set(data) - {"process"})
    if unknown:
        raise DeploymentError(f"{path}: unknown setting `{unknown[0]}` (a deployment has `[[process]]` tables)")
    tables = data.get("process")
    if isinstance(tables, dict):
        raise DeploymentError(
            f"{path}: `[process]` is one table; write `[[process]]`, with two brackets, before each process"
        )
    if not isinstance(tables, list) or not tables:
        raise DeploymentError(f"{path}: no `[[process]]` table; each names its `agents` and `listen` endpoint")
    processes: list[ProcessGroup] = []
    seen_agents: dict[str, int] = {}
    #: each process's `listen` endpoint so far, the socket it binds, and the host it runs on
    seen_endpoints: list[tuple[int, str, Listener, str]] = []
    for number, table in enumerate(tables, start=1):
        where = f"{path}: process {number}"
        listed: set[str] = set()
        if not isinstance(table, dict):
            raise DeploymentError(f"{where} is not a table")
        extra = sorted(set(table) - {"agents", "listen", "environment", "host", "args"})
        if extra:
            raise DeploymentError(f"{where}: unknown key `{extra[0]}` (known: agents, listen, environment, host, args)")
        agents = table.get("agents")
        if agents == []:
            raise DeploymentError(f'{where}: `agents` is empty; list the agents it runs, e.g. ["manip/a", "grip/a"]')
        if not isinstance(agents, list) or not all(isinstance(a, str) and a.strip() for a in agents):
            raise DeploymentError(f'{where}: `agents` must be a list of agent names, e.g. ["manip/a", "grip/a"]')
        names = tuple(normalise_agent(a) for a in agents)
        for agent in names:
            if agent in listed:
                raise DeploymentError(f"{where}: `{agent}` is listed twice in its `agents`")
            if agent in seen_agents:
                raise DeploymentError(f"{where}: `{agent}` already runs in process {seen_agents[agent]}")
            listed.add(agent)
            seen_agents[agent] = number
        listen = table.get("listen")
        if not isinstance(listen, str) or "/" not in listen:
            raise DeploymentError(f'{where}: `listen` must be a Zenoh endpoint such as "tcp/127.0.0.1:7451"')
        problem = endpoint_problem(listen)
        if problem is not None:
            raise DeploymentError(f"{where}: `listen = {listen!r}`: {problem}")
        host = table.get("host", "localhost")
        if not isinstance(host, str) or not host:
            raise DeploymentError(f"{where}: `host` must be a host name")
        this = listener(listen)
        for other_number, other, bound, other_host in seen_endpoints:
            if not same_host(host, other_host):
                continue  # each computer has its own ports: `0.0.0.0:7451` on one, `192.168.1.20:7451` on another
            why = clash(this, bound)
            if why == "":
                raise DeploymentError(
                    f"{where}: `{listen}` is the same endpoint as process {other_number}'s; give each its own port"
                )
            if why is not None:
                raise DeploymentError(
                    f"{where}: `{listen}` and process {other_number}'s `{other}` cannot both listen on port "
                    f"{this.port} ({why}); give each its own port"
                )
        seen_endpoints.append((number, listen, this, host))
        environment = table.get("environment")
        args = table.get("args", [])
        if environment is not None and not isinstance(environment, bool):
            raise DeploymentError(f"{where}: `environment` must be true or false")
        if not isinstance(args, list) or not all(isinstance(a, str) for a in args):
            raise DeploymentError(f'{where}: `args` must be a list of `earl run` options, e.g. ["--trace", "x.mcap"]')
        for arg in args:
            option = _launch_option(arg)
            if option is not None:
                written = arg.split("=", 1)[0]
                shortened = f" (as `{written}`)" if written != option else ""
                raise DeploymentError(
                    f"{where}: `args` sets `{option}`{shortened}, which `earl launch` sets for each process itself "
                    f"({LAUNCH_SETS[option]})"
                )
        processes.append(ProcessGroup(names, listen, environment, host, tuple(args)))
    return Deployment(path, tuple(processes))
