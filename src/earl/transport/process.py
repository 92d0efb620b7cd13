"""One process of a distributed run: its agents, its Zenoh configuration, its peers.

`earl run SPEC --transport zenoh --agents manip/a,grip/a` comes here for its transport before
the network is built; its Zenoh session opens once the run is set up (`ZenohTransport.start`).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from earl.diagnostics import escape_controls
from earl.model.elements import System
from earl.model.expand import expand
from earl.model.kinds import Kind
from earl.runtime.names import agent_name, named_members
from earl.transport.deployment import normalise_agent, read_deployment
from earl.transport.zenoh_transport import (
    TransportError,
    ZenohTransport,
    config_from_file,
    default_config,
)

DEPLOYMENT_FILE = "deploy.toml"
#: seconds; see prepare_transport
SWITCH_INTERVAL = 0.0005


def log(line: str) -> None:
    """A line about the links on standard error; dropped when nobody reads it any more (`2>&1 | head`),
    since it is also called on Zenoh's threads, where a failure would leave the session open for ever."""
    with contextlib.suppress(OSError):  # BrokenPipeError is one
        print(line, file=sys.stderr, flush=True)


def acting_agents(expanded: System) -> list[str]:
    """The agents with a Real Effector or Receptor: those that act on the environment."""
    real = (Kind.REAL_EFFECTOR, Kind.REAL_RECEPTOR)
    return [agent_name(agent) for agent in expanded.agents if any(s.kind in real for s in agent.subsystems)]


def prepare_transport(
    system: System,
    parameters: Mapping[str, Any],
    spec: Path,
    agents: list[str],
    arguments: argparse.Namespace,
    environment: str | None = None,
) -> tuple[list[str], ZenohTransport, bool]:
    """The agents this process runs (normalised), its transport, and whether `environment` (the one
    run.toml or --environment names, if any) runs here; `ValueError` for bad options.  The transport's
    session is not open yet: `Simulation` opens it once the spec's code is bound and the environment
    started, so that none of their errors is said after the process has shown itself to its peers; a
    session Zenoh refuses then raises `TransportError`, naming the endpoints and where they come from.

    The deployment file says where the environment lives (`Deployment.place_environment`); with
    the user's own --zenoh-config it lives in the process that runs every agent acting on it."""
    expanded = expand(system, dict(parameters))
    known = [agent_name(agent) for agent in expanded.agents]
    environment_here = environment is not None
    names = agents_of(system, parameters, agents)
    path = Path(arguments.deployment) if arguments.deployment else spec.parent / DEPLOYMENT_FILE
    group = None
    if arguments.deployment or not arguments.zenoh_config:
        # with --zenoh-config, a deployment file named on the command line still says where run.toml's
        # environment lives, and is checked as without it; only its endpoints are not used
        if not arguments.deployment and not path.is_file():
            raise ValueError(
                f"--transport zenoh needs the processes' endpoints: write {path} (docs/distributed.md), "
                "name one with --deployment, or give your own --zenoh-config"
            )
        deployment = read_deployment(path)  # a DeploymentError: exit 1, as `earl launch` says it
        deployment = deployment.check_agents(known)
        if environment is not None:
            deployment = deployment.place_environment(acting_agents(expanded))
        group = deployment.group_of(names)
        if environment is not None and not group.names_its_environment:
            environment_here = bool(group.environment)
    if arguments.zenoh_config:
        config_path = Path(arguments.zenoh_config)
        if not config_path.is_file():
            kind = "a directory, not a file" if config_path.is_dir() else "no such file"
            raise ValueError(f"--zenoh-config: {kind}: {config_path}")
        try:
            config = config_from_file(config_path)
        except TransportError as error:
            raise ValueError(str(error)) from None
        where = f"the Zenoh configuration {arguments.zenoh_config}"
        if environment is not None and group is None:
            # No deployment file says where run.toml's environment lives: it lives with the agents that act
            # on it, and only where all of them run (each process would simulate a world of its own).
            acting = acting_agents(expanded)
            here = [agent for agent in acting if agent in names]
            if here and len(here) != len(acting):
                raise ValueError(
                    f"the environment run.toml names serves {', '.join(acting)}, which act on it; this process "
                    f"runs {', '.join(here)} alone, and another would need it too (two worlds): run them all in one "
                    "process, or say where it runs with a deployment file (docs/distributed.md)"
                )
            environment_here = bool(here)
    else:
        assert group is not None
        connect = deployment.connect_for(group)
        config = default_config([group.listen], connect)
        where = f"listening on {group.listen}, connecting to {', '.join(connect) or 'nobody'}"
    # Zenoh's callbacks need the GIL: while the scheduler runs Python, a message would wait up
    # to the interpreter's switch interval (5 ms) to be taken; 0.5 ms bounds that delay
    sys.setswitchinterval(SWITCH_INTERVAL)
    # the user's own file that Zenoh refuses is a usage error (exit 2, `earl run` says it)
    context = f"with {where}" if arguments.zenoh_config else f"{where}, as {path} says"
    announce = f"earl run: {', '.join(names)} over Zenoh ({where})"
    transport = ZenohTransport(system.name, names, config, log, announce=announce, context=context)
    return names, transport, environment_here


def agents_of(system: System, parameters: Mapping[str, Any], agents: list[str]) -> list[str]:
    """`--agents` normalised (`task` is `task/a`); `ValueError` naming one that the system does not have."""
    known = [agent_name(agent) for agent in expand(system, dict(parameters)).agents]
    names: list[str] = []
    for written in agents:
        name = normalise_agent(written)
        # a family whole (`pusher[*]/a`, `pusher[K]/a`, `pusher/a`) is every member, as in a robot
        members = named_members(name, known)
        if not members:
            raise ValueError(f"--agents: `{name}` is not an agent of this system (its agents: {', '.join(known)})")
        twice = next((member for member in members if member in names), None)
        if twice is not None:
            raise ValueError(f"--agents: `{twice}` is named twice")
        names += members
    return names


#: `--wait-for-peers` when it is not given
DEFAULT_PEERS_WAIT = "30s"


def peers_wait(text: str | None) -> float:
    """`--wait-for-peers`: a duration, or 0 for none (start at once, whoever is there); None: the default."""
    from earl.runtime.durations import parse_duration

    if text is None:
        text = DEFAULT_PEERS_WAIT
    return parse_duration(text, zero=True)


def wait_for_peers(transport: ZenohTransport, arguments: argparse.Namespace) -> None:
    """Start when the agents our links talk to are there, so that no first message is lost."""
    seconds = peers_wait(arguments.wait_for_peers)
    missing = transport.missing_peers()
    if missing and seconds > 0:
        log(f"earl run: waiting up to {seconds:g} s for {', '.join(missing)}")
        missing = transport.wait_for_peers(seconds)
    if missing:
        log(f"earl run: starting without {', '.join(missing)}: their links are stale until they appear")
    else:
        log(f"earl run: peers {', '.join(transport.peers) or '(none)'} are alive; starting")


def print_link_statistics(transport: ZenohTransport) -> None:
    """The closing lines: what went over each remote link."""
    for statistics in transport.statistics:
        arrow = "sent" if statistics.direction == "out" else "received"
        line = f"link {statistics.link} ({statistics.key}): {statistics.messages} {arrow}"
        if statistics.failed:
            line += f", {statistics.failed} not sent (Zenoh refused them)"
        if statistics.direction == "in":
            line += f", {statistics.malformed} malformed (dropped), {statistics.refused} refused (type mismatch)"
        print(line, flush=True)


def say_refused_links(transport: ZenohTransport) -> bool:
    """One closing line on standard error naming the links whose messages were refused for another data
    type, here or by their receiver: the run lost them, and fails (exit code 1). Whether there were any."""
    refused = [f"{link} ({where})" for link, where in transport.refused_links().items()]
    if not refused:
        return False
    links = f"the link {refused[0]}" if len(refused) == 1 else f"the links {', '.join(refused[:-1])} and {refused[-1]}"
    said = f"earl run: {links} lost messages of another data type: the processes run different specifications"
    log(escape_controls(said + " (exit code 1)"))  # a receiver's name is a peer's words: it may forge no line
    return True
