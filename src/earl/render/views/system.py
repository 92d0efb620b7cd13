"""The system view (the manual's Figure 8): agents as blocks, inter-agent links with their data types.

The Input and Output Buffers of the Control Subsystems are the ends of the links
(§2.5), drawn as small squares on the border of their agent's block.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from earl.model.elements import Agent, Link, System
from earl.model.expressions import ElementReference, Literal
from earl.model.kinds import Kind
from earl.model.tables import AgentType
from earl.model.text import index_text
from earl.model.types import type_text
from earl.render.diagram import Diagram
from earl.render.dot import FILL, Graph, html
from earl.render.names import Indexed, Key, agent_name, element_key, family_note, indexed_name, link_label, lookup
from earl.render.views.common import Port, block, link_statements, node_id

AgentTypeOf = Callable[[Agent], AgentType | None]


@dataclass(frozen=True)
class InterAgentLink:
    """An inter-agent link with the agents and Control Subsystem buffers at its ends."""

    link: Link
    source: Agent
    source_buffer: str  # the buffer's indexed name: `cmd[K]` for a family
    destination: Agent
    destination_buffer: str
    data_type: str
    #: the buffers as the link names them: `cmd[1]` where it feeds one member of the family `cmd[K]`
    source_end: str = ""
    destination_end: str = ""

    def __post_init__(self) -> None:
        if not self.source_end:
            object.__setattr__(self, "source_end", self.source_buffer)
        if not self.destination_end:
            object.__setattr__(self, "destination_end", self.destination_buffer)


def inter_agent_links(system: System) -> list[InterAgentLink]:
    """The system's links whose ends can be found; the checker reports the others."""
    agents: dict[Key, Agent] = {element_key(agent, Kind.AGENT): agent for agent in system.agents}
    result = []
    for link in system.links:
        if link.source.agent is None or link.destination.agent is None:
            continue
        source = lookup(agents, link.source.agent)
        destination = lookup(agents, link.destination.agent)
        if source is None or destination is None:
            continue
        source_cs, destination_cs = source.control_subsystem, destination.control_subsystem
        if source_cs is None or destination_cs is None:
            continue
        outputs = {element_key(b, Kind.OUTPUT_BUFFER): b for b in source_cs.output_buffers}
        inputs = {element_key(b, Kind.INPUT_BUFFER): b for b in destination_cs.input_buffers}
        output = lookup(outputs, link.source.buffer)
        input_ = lookup(inputs, link.destination.buffer)
        if output is None or input_ is None:
            continue
        result.append(
            InterAgentLink(
                link,
                source,
                indexed_name(output),
                destination,
                indexed_name(input_),
                type_text(output.data_type),
                end_name(output, link.source.buffer),
                end_name(input_, link.destination.buffer),
            )
        )
    return result


def end_name(buffer: Indexed, reference: ElementReference | None) -> str:
    """The buffer at a link's end as the link names it: `cmd[1]` when it feeds one member of the
    family `cmd[K]`, which is otherwise drawn as a whole."""
    if (
        reference is not None
        and buffer.family is not None
        and buffer.index is None
        and reference.indices
        and all(isinstance(index, Literal) for index in reference.indices)
    ):
        return f"{buffer.name}[{', '.join(index_text(index) for index in reference.indices)}]"
    return indexed_name(buffer)


def system_view(
    system: System, agent_type: AgentTypeOf = lambda agent: None, placements: dict[int, Placement] | None = None
) -> Diagram:
    """`placements` (from `robot_placements`) say which robots hold which members of a family drawn
    once; without them every agent is taken as concrete (the system is an expanded one)."""
    graph = Graph(f"ibd [System] {system.name}")
    placements = robot_placements(system) if placements is None else placements
    links = inter_agent_links(system)
    ports_in: dict[int, list[Port]] = {id(a): [] for a in system.agents}
    ports_out: dict[int, list[Port]] = {id(a): [] for a in system.agents}
    for link in links:
        _add_port(ports_out[id(link.source)], "ob", link.source_end)
        _add_port(ports_in[id(link.destination)], "ib", link.destination_end)

    names: list[str] = [system.name]
    nodes: dict[int, str] = {}
    statements: dict[int, str] = {}
    for agent in system.agents:
        name = agent_name(agent)
        names.append(name)
        nodes[id(agent)] = node_id("agent", name)
        title = ["<i>«Agent»</i>", f"<b>{html(name)}</b>"]
        notes = [note for note in (family_note(agent),) if note]
        placement = placements[id(agent)]
        if placement.split:
            # no robot holds the whole family: it is drawn outside the robots, saying where its members are
            notes += member_placement_lines(system, agent, placement)
        row = agent_type(agent)
        if row is not None:
            notes.append(f"{row.name}: {row.description}")
        subsystems = ", ".join(
            s.kind.value if s.kind is Kind.CONTROL_SUBSYSTEM else f"{indexed_name(s)}/{s.kind.value}"
            for s in agent.subsystems
        )
        middle = [f'<font point-size="9" color="#555555">{html(subsystems)}</font>'] if subsystems else []
        label = block(title, ports_in[id(agent)], ports_out[id(agent)], middle, FILL["a"], notes)
        statements[id(agent)] = f'{nodes[id(agent)]} [shape="plain", label={label}, tooltip="{html(name)}"];'

    positions = {id(agent): position for position, agent in enumerate(system.agents)}
    #: what each robot draws inside it: whole agents, and for a split family a dashed stand-in naming
    #: the members the robot holds, tied by a dotted line to the family drawn outside the robots
    inside: list[list[str]] = [[] for _ in system.robots]
    member_edges: list[str] = []
    for agent in system.agents:
        placement = placements[id(agent)]
        if placement.robot is not None:
            inside[placement.robot].append(statements[id(agent)])
            continue
        for share in placement.shares:
            if share.members is None:
                continue
            held = member_names(agent, share.members)
            stand_in = node_id("members", str(share.robot), agent_name(agent))
            label = (
                f'<<i>«Agent»</i><br/><b>{html(held)}</b><br/><font point-size="9" color="#555555">'
                f"member{'s' if len(share.members) > 1 else ''} of {html(agent_name(agent))}</font>>"
            )
            inside[share.robot].append(
                f'{stand_in} [shape="box", style="dashed,rounded", color="#777777", label={label}, tooltip="{html(held)}"];'
            )
            member_edges.append(
                f'{stand_in} -> {nodes[id(agent)]} [style="dotted", arrowhead="none", color="#777777", '
                f'tooltip="{html(held)} in {html(system.robots[share.robot].name)}/r"];'
            )

    # A link's label node sits in the robot that holds both its ends: dot keeps a cluster's nodes in one
    # band of ranks, so a label node outside it would squeeze every agent of the robot into one column.
    link_nodes: dict[int | None, list[str]] = {}
    edges: list[str] = []
    link_names: list[str] = []
    for number, link in enumerate(links):
        name = link_label(link.link)
        link_names.append(name)
        source = f"{nodes[id(link.source)]}:{_port('ob', link.source_end)}:e"
        destination = f"{nodes[id(link.destination)]}:{_port('ib', link.destination_end)}:w"
        backward = positions[id(link.destination)] < positions[id(link.source)]
        link_parts = link_statements(number, source, destination, name, link.data_type, backward)
        source_robot = placements[id(link.source)].robot
        destination_robot = placements[id(link.destination)].robot
        shared = source_robot if source_robot == destination_robot else None
        link_nodes.setdefault(shared, []).extend(link_parts.nodes)
        edges.extend(link_parts.edges)

    for number, robot in enumerate(system.robots):
        robot_name = f"{robot.name}/r"
        names.append(robot_name)
        graph.add(f"subgraph cluster_robot_{number} {{")
        graph.add(f'  label=<<i>«Robot»</i> <b>{html(robot_name)}</b>>; style="dashed,rounded"; color="#777777";')
        for statement in inside[number]:
            graph.add("  " + statement)
        for node in link_nodes.get(number, []):
            graph.add("  " + node)
        graph.add("}")
    for agent in system.agents:
        if placements[id(agent)].robot is None:
            graph.add(statements[id(agent)])
    for statement in link_nodes.get(None, []) + edges + member_edges:
        graph.add(statement)
    return Diagram("system", graph.header, graph.source(), "system", (*names, *link_names))


#: The concrete agents a shown agent stands for: itself, or every member of a family drawn once.
Instances = Callable[[Agent], list[Agent]]


@dataclass(frozen=True)
class RobotShare:
    """The part of one shown agent a robot holds."""

    robot: int  # the robot's number in `system.robots`
    #: the family members it holds (`worker[1]`, `worker[2]`), or None when it holds the whole agent
    members: tuple[int, ...] | None = None


@dataclass(frozen=True)
class Placement:
    """Where the robots put one shown agent.

    A family drawn once may be split: `fleetRobot/r` lists `worker[1]/a`, `otherFleet/r` lists
    `worker[2]/a`, and `worker[3]/a` belongs to no robot; then no robot holds the family as a whole.
    """

    shares: tuple[RobotShare, ...] = ()
    #: the members of a family drawn once that no robot lists (a family in no robot at all has no shares)
    outside: tuple[int, ...] = ()

    @property
    def robot(self) -> int | None:
        """The robot that holds all of the agent, where it is drawn; None when none does."""
        if len(self.shares) == 1 and self.shares[0].members is None and not self.outside:
            return self.shares[0].robot
        return None

    @property
    def split(self) -> bool:
        """Its members are in different robots, or some in a robot and others in none."""
        return any(share.members is not None for share in self.shares)


def robot_placements(
    shown: System, concrete: System | None = None, instances: Instances | None = None
) -> dict[int, Placement]:
    """By the shown agent's `id`: which robots hold it, and which of its members each holds.

    `concrete` is the expanded system (its robots list members: `worker[1]`, or every member for
    `worker`) and `instances` gives a shown agent's members in it; without them `shown` is taken as
    concrete.  A member two robots list belongs to the first (the checker reports the second).
    """
    concrete = shown if concrete is None else concrete
    members_of: Instances = instances if instances is not None else (lambda agent: [agent])
    agents_by_key = {element_key(a, Kind.AGENT): a for a in concrete.agents}
    robot_of: dict[int, int] = {}
    for number, robot in enumerate(concrete.robots):
        for reference in robot.agents:
            for agent in _robot_members(reference, agents_by_key):
                robot_of.setdefault(id(agent), number)
    placements: dict[int, Placement] = {}
    for agent in shown.agents:
        members = members_of(agent) or [agent]
        if agent.family is None or agent.index is not None:
            # one agent, or one member of an expanded family: wholly in a robot or in none
            whole = robot_of.get(id(members[0]))
            placements[id(agent)] = Placement(() if whole is None else (RobotShare(whole),))
            continue
        held: dict[int, list[int]] = {}
        outside: list[int] = []
        for member in members:
            index = member.index if member.index is not None else 0
            holder = robot_of.get(id(member))
            if holder is None:
                outside.append(index)
            else:
                held.setdefault(holder, []).append(index)
        if not held:
            placements[id(agent)] = Placement()
        elif len(held) == 1 and not outside:
            placements[id(agent)] = Placement((RobotShare(next(iter(held))),))
        else:
            shares = tuple(RobotShare(number, tuple(held[number])) for number in sorted(held))
            placements[id(agent)] = Placement(shares, tuple(outside))
    return placements


def member_list(agent: Agent, members: Sequence[int]) -> list[str]:
    """`worker[1]/a`, `worker[3]/a`, `worker[5..1200]/a`: members of a family drawn once, by their numbers, a
    run of three or more as a range (a label of every member of a large family is more than Graphviz takes)."""
    named: list[str] = []
    ordered = sorted(members)
    start = 0
    while start < len(ordered):
        end = start
        while end + 1 < len(ordered) and ordered[end + 1] == ordered[end] + 1:
            end += 1
        if end - start >= 2:
            named.append(f"{agent.name}[{ordered[start]}..{ordered[end]}]/a")
        else:
            named += [f"{agent.name}[{index}]/a" for index in ordered[start : end + 1]]
        start = end + 1
    return named


def member_names(agent: Agent, members: Sequence[int]) -> str:
    return ", ".join(member_list(agent, members))


def member_placement_lines(system: System, agent: Agent, placement: Placement) -> list[str]:
    """`fleetRobot/r: worker[1]/a`, …, `no robot: worker[3]/a`: where a split family's members are."""
    lines = [
        f"{system.robots[share.robot].name}/r: {member_names(agent, share.members)}"
        for share in placement.shares
        if share.members is not None
    ]
    if placement.outside:
        lines.append(f"no robot: {member_names(agent, placement.outside)}")
    return lines


NO_ROBOT = "no robot"


def robot_text(system: System, agent: Agent, placement: Placement) -> str:
    """Table 1's robot column: `fleetRobot/r`; for a split family `fleetRobot/r (worker[1]/a),
    otherFleet/r (worker[2]/a), no robot (worker[3]/a)`; `no robot` for an agent in none, as a split
    family's members in none are said to be (it had been `—`)."""
    parts = []
    for share in placement.shares:
        name = f"{system.robots[share.robot].name}/r"
        parts.append(name if share.members is None else f"{name} ({member_names(agent, share.members)})")
    if parts and placement.outside:
        parts.append(f"no robot ({member_names(agent, placement.outside)})")
    return ", ".join(parts) or NO_ROBOT


def _robot_members(reference: ElementReference, agents: dict[Key, Agent]) -> list[Agent]:
    """The agents a robot lists: one agent, one member, or every member of a family."""
    found = lookup(agents, reference)
    if found is not None:
        return [found]
    return [agent for key, agent in agents.items() if key[0] == reference.name]


def _port(direction: str, buffer: str) -> str:
    return "p_" + direction + "_" + "".join(c if c.isalnum() else "_" for c in buffer)


def _add_port(ports: list[Port], direction: str, buffer: str) -> None:
    port = _port(direction, buffer)
    if all(existing.port != port for existing in ports):
        ports.append(Port(port, f"{buffer}/{direction}"))
