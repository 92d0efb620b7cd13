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
from earl.runtime.names import named_members
from earl.toml_lines import TomlTable, as_written, invalid_toml, key_lines, toml_tables, value_line
from earl.transport.listeners import clash, listener

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
    #: the file's text and where each process is written in it, for messages that say `FILE:LINE:`
    text: str = field(default="", compare=False, repr=False)
    tables: tuple[TomlTable, ...] = field(default=(), compare=False, repr=False)

    def at(self, number: int, key: str | None = None, value: str | None = None, nth: int = 1) -> str:
        """`deploy.toml:7`: where process `number` sets `key` (its string `value` in a list, the `nth`
        time it is written there), or where the process begins."""
        if not 1 <= number <= len(self.tables):
            return str(self.path)
        table = self.tables[number - 1]
        line = table.keys.get(key, table.line) if key is not None else table.line
        if key is not None and value is not None:
            line = value_line(self.text, table, key, value, nth) or line
        return f"{self.path}:{line}"

    def first_line(self) -> str:
        """`deploy.toml:1`, where the first process begins: said of what no process has."""
        return self.at(1) if self.tables else str(self.path)

    def group_of(self, agents: list[str]) -> ProcessGroup:
        """The process that runs exactly `agents` (in any order)."""
        wanted = {normalise_agent(a) for a in agents}
        for process in self.processes:
            if set(process.agents) == wanted:
                return process
        known = "; ".join(process.label for process in self.processes)
        # said at the process that runs one of them (it runs others too, or not all), else at the first
        nearest = next((n for n, p in enumerate(self.processes, start=1) if not wanted.isdisjoint(p.agents)), None)
        where = self.first_line()
        if nearest is not None:
            agent = next(a for a in self.processes[nearest - 1].agents if a in wanted)
            where = self.at(nearest, "agents", self._written_agent(nearest, agent))
        raise DeploymentError(
            f"{where}: no process runs exactly the agents {', '.join(sorted(wanted))} (its processes: {known})"
        )

    def _written_agent(self, number: int, agent: str) -> str:
        """How process `number`'s `agents` writes `agent` (`task` for `task/a`), to find its line."""
        table = self.tables[number - 1] if 1 <= number <= len(self.tables) else None
        start = table.keys.get("agents") if table is not None else None
        if table is None or start is None:
            return agent
        plain = agent.removesuffix("/a")
        text = "\n".join(self.text.split("\n")[start - 1 : table.end])
        return plain if f'"{plain}"' in text or f"'{plain}'" in text else agent

    def connect_for(self, process: ProcessGroup) -> list[str]:
        """The endpoints `process` connects to: every other process's."""
        return [other.listen for other in self.processes if other is not process]

    def check_agents(self, system_agents: list[str]) -> Deployment:
        """Every agent of the system runs in one process, and the file names no other. Returned: this
        deployment with a family named whole (`pusher[*]/a`, `pusher[K]/a` or `pusher/a`, as a robot
        names one) replaced by its members, in the system's order: a process runs whole agents, and a
        family's members are agents."""
        processes: list[ProcessGroup] = []
        runs: dict[str, int] = {}
        for number, process in enumerate(self.processes, start=1):
            agents: list[str] = []
            for agent in process.agents:
                where = self.at(number, "agents", self._written_agent(number, agent))
                members = named_members(agent, system_agents)
                if not members:
                    raise DeploymentError(
                        f"{where}: process {number}: `{agent}` is not an agent of this system "
                        f"(its agents: {', '.join(system_agents)})"
                    )
                for member in members:
                    of = "" if member == agent else f" (a member of `{agent}`)"
                    if member in agents:
                        raise DeploymentError(f"{where}: process {number}: `{member}`{of} is listed twice")
                    if member in runs:
                        raise DeploymentError(
                            f"{where}: process {number}: `{member}`{of} already runs in process {runs[member]}"
                        )
                    runs[member] = number
                    agents.append(member)
            processes.append(replace(process, agents=tuple(agents)))
        missing = [agent for agent in system_agents if agent not in runs]
        if missing:
            raise DeploymentError(
                f"{self.first_line()}: the agent `{missing[0]}` runs in no process; add it to a process's `agents`"
            )
        return replace(self, processes=tuple(processes))

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
                f"{self.at(second, 'environment')}: the environment would run in process {first} ({one.label}) and in process "
                f"{second} ({other.label}), each simulating a world of its own; give it to one process "
                "(`environment = false` in the others) and run every agent with Real Effectors or Receptors there"
            )
        if not holders:
            unheld = [(n, agent) for n, p in numbered for agent in p.agents if agent in acting]
            if unheld:
                number, agent = unheld[0]
                raise DeploymentError(
                    f"{self.at(number, 'environment')}: no process runs the environment, but `{agent}` (process {number}) has Real "
                    f"Effectors or Receptors that act on it; give process {number} `environment = true`, or "
                    'its own environment in its `args` (`args = ["--environment", "module:factory"]`)'
                )
            return
        number, holder = holders[0]
        for other_number, process in numbered:
            away = [agent for agent in process.agents if agent in acting]
            if process is not holder and away:
                raise DeploymentError(
                    f"{self.at(other_number, 'agents', self._written_agent(other_number, away[0]))}: "
                    f"process {other_number} runs `{away[0]}`, whose Real Effectors or Receptors "
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
    """The deployment file at `path`; a DeploymentError, `FILE:LINE: …` with the key or process that is
    wrong and what is expected, when it cannot be used."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise DeploymentError(f"cannot read the deployment file {path}: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise DeploymentError(f"{path}: not UTF-8 text") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise DeploymentError(invalid_toml(str(path), error)) from None
    tables = toml_tables(text)
    top = key_lines(text)
    unknown = [key for key in data if key != "process"]
    if unknown:
        hint = did_you_mean(unknown[0], ["process"]) or "a deployment has only `[[process]]` tables"
        raise DeploymentError(f"{path}:{top.get(unknown[0], 1)}: unknown setting `{unknown[0]}`; {hint}")
    processes_line = top.get("process", 1)
    written = data.get("process")
    if isinstance(written, dict):
        raise DeploymentError(
            f"{path}:{processes_line}: `[process]` is one table; write `[[process]]`, with two brackets, "
            "before each process"
        )
    if not isinstance(written, list) or not written:
        shown = "" if written is None else f" (`process = {as_written(written)}`)"
        raise DeploymentError(
            f"{path}:{processes_line}: no `[[process]]` table{shown}; each names its `agents` and `listen` endpoint"
        )
    headers = [table for table in tables if table.name == "process" and table.in_array]
    if len(headers) != len(written):  # `process = [{…}, {…}]` inline: every process is said at that line
        headers = [TomlTable("process", processes_line) for _ in written]
    deployment = Deployment(path, text=text, tables=tuple(headers))
    processes: list[ProcessGroup] = []
    for number, table in enumerate(written, start=1):
        if not isinstance(table, dict):
            raise DeploymentError(
                f"{deployment.at(number)}: process {number} is {as_written(table)}, not a table; "
                "write each as `[[process]]` with its keys below"
            )
        processes.append(_read_process(deployment, number, table, processes))
    return replace(deployment, processes=tuple(processes))


#: the keys of a `[[process]]` table
_PROCESS_KEYS = ("agents", "listen", "environment", "host", "args")


def _read_process(
    deployment: Deployment, number: int, table: dict[str, object], before: list[ProcessGroup]
) -> ProcessGroup:
    """Process `number` of the file, checked against the processes `before` it."""

    def refuse(key: str | None, message: str, value: str | None = None, nth: int = 1) -> DeploymentError:
        return DeploymentError(f"{deployment.at(number, key, value, nth)}: process {number}: {message}")

    extra = [key for key in table if key not in _PROCESS_KEYS]
    if extra:
        hint = did_you_mean(extra[0], _PROCESS_KEYS)
        hint = f"; {hint}" if hint else ""
        raise refuse(extra[0], f"unknown key `{extra[0]}`{hint} (known: {', '.join(_PROCESS_KEYS)})")
    example = '["manip/a", "grip/a"]'
    agents = table.get("agents")
    if agents is None:
        raise refuse(None, f"no `agents`; list the agents it runs, e.g. `agents = {example}`")
    if agents == []:
        raise refuse("agents", f"`agents` is empty; list the agents it runs, e.g. {example}")
    if not isinstance(agents, list) or not all(isinstance(a, str) and a.strip() for a in agents):
        raise refuse("agents", f"`agents` is a list of agent names, e.g. {example}, not {as_written(agents)}")
    runs = {agent: other for other, process in enumerate(before, start=1) for agent in process.agents}
    names: list[str] = []
    for written in agents:
        agent = normalise_agent(written)
        if agent in names:
            again = agents[: len(names)].count(written) + 1  # the message points at this writing
            raise refuse("agents", f"`{agent}` is listed twice in its `agents`", written, again)
        if agent in runs:
            raise refuse("agents", f"`{agent}` already runs in process {runs[agent]}", written)
        names.append(agent)
    listen = table.get("listen")
    endpoint = '"tcp/127.0.0.1:7451"'
    if listen is None:
        raise refuse(None, f"no `listen` endpoint; give it one such as `listen = {endpoint}`")
    if not isinstance(listen, str) or "/" not in listen:
        raise refuse("listen", f"`listen` is a Zenoh endpoint such as {endpoint}, not {as_written(listen)}")
    problem = endpoint_problem(listen)
    if problem is not None:
        raise refuse("listen", f"`listen = {as_written(listen)}`: {problem}")
    host = table.get("host", "localhost")
    if not isinstance(host, str) or not host:
        raise refuse("host", f'`host` is a host name such as "robot" or "localhost", not {as_written(host)}')
    this = listener(listen)
    for other_number, other in enumerate(before, start=1):
        if not same_host(host, other.host):
            continue  # each computer has its own ports: `0.0.0.0:7451` on one, `192.168.1.20:7451` on another
        why = clash(this, listener(other.listen))
        if why == "":
            raise refuse(
                "listen", f"`{listen}` is the same endpoint as process {other_number}'s; give each its own port"
            )
        if why is not None:
            raise refuse(
                "listen",
                f"`{listen}` and process {other_number}'s `{other.listen}` cannot both listen on port "
                f"{this.port} ({why}); give each its own port",
            )
    environment = table.get("environment")
    if environment is not None and not isinstance(environment, bool):
        raise refuse("environment", f"`environment` is true or false, not {as_written(environment)}")
    args = table.get("args", [])
    if not isinstance(args, list) or not all(isinstance(a, str) for a in args):
        raise refuse(
            "args", f'`args` is a list of `earl run` options, e.g. ["--trace", "x.mcap"], not {as_written(args)}'
        )
    for arg in args:
        option = _launch_option(arg)
        if option is not None:
            written = arg.split("=", 1)[0]
            shortened = f" (as `{written}`)" if written != option else ""
            raise refuse(
                "args",
                f"`args` sets `{option}`{shortened}, which `earl launch` sets for each process itself "
                f"({LAUNCH_SETS[option]})",
                arg,
            )
    return ProcessGroup(tuple(names), listen, environment, host, tuple(args))
