"""The agent view (the manual's Figure 10): subsystems, their buffers and memory, inter-subsystem links.

Input Buffers are small squares on the left edge of a subsystem, Output Buffers
on the right; a link is an arrow from an Output Buffer to an Input Buffer.
Internal Memory is listed under the buffers with the manual's bidirectional arrow.
Agents at the other end of this agent's inter-agent links are drawn dashed, outside.
"""

from __future__ import annotations

from dataclasses import dataclass

from earl.model.elements import Agent, InputBuffer, Link, OutputBuffer, Subsystem, System
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.text import expression_text
from earl.model.types import type_text
from earl.render.diagram import Diagram
from earl.render.dot import FILL, Graph, html
from earl.render.names import (
    Key,
    agent_name,
    element_key,
    element_name,
    family_note,
    indexed_name,
    link_label,
    lookup,
    slug,
    subsystem_name,
)
from earl.render.views.common import Port, block, link_statements, node_id
from earl.render.views.system import inter_agent_links


@dataclass(frozen=True)
class SubsystemLink:
    """A link inside an agent with the subsystems and buffers at its ends."""

    link: Link
    source: Subsystem
    output: OutputBuffer
    destination: Subsystem
    input: InputBuffer


def agent_links(agent: Agent) -> list[SubsystemLink]:
    """The agent's inter-subsystem links whose ends can be found; the checker reports the others."""
    subsystems: dict[Key, Subsystem] = {element_key(s, s.kind): s for s in agent.subsystems}
    result = []
    for link in agent.links:
        source = lookup(subsystems, link.source.subsystem)
        destination = lookup(subsystems, link.destination.subsystem)
        if source is None or destination is None:
            continue
        output = lookup({element_key(b, Kind.OUTPUT_BUFFER): b for b in source.output_buffers}, link.source.buffer)
        input_ = lookup(
            {element_key(b, Kind.INPUT_BUFFER): b for b in destination.input_buffers}, link.destination.buffer
        )
        if output is not None and input_ is not None:
            result.append(SubsystemLink(link, source, output, destination, input_))
    return result


#: Left to right, the way data flows from receptors through the Control Subsystem to effectors (§2.3).
_ORDER = {
    Kind.REAL_RECEPTOR: 0,
    Kind.VIRTUAL_RECEPTOR: 1,
    Kind.CONTROL_SUBSYSTEM: 2,
    Kind.VIRTUAL_EFFECTOR: 3,
    Kind.REAL_EFFECTOR: 4,
}


def port_name(direction: str, element_key_text: str) -> str:
    return "p_" + direction + "_" + "".join(c if c.isalnum() else "_" for c in element_key_text)


def _queue_text(buffer: InputBuffer) -> str:
    """` {fifo 4, dropOldest}` after an Input Buffer that keeps a FIFO, as UML writes a property's
    modifiers; nothing after one that keeps the latest message."""
    if buffer.queue is None:
        return ""
    return f" {{fifo {expression_text(buffer.queue.capacity)}, {buffer.queue.overflow}}}"


def subsystem_block(subsystem: Subsystem) -> str:
    title = [f"<i>«{html(KIND_TITLES[subsystem.kind])}»</i>", f"<b>{html(subsystem_name(subsystem))}</b>"]
    notes = [note for note in (family_note(subsystem),) if note]
    if subsystem.period is not None:
        notes.append(f"period {subsystem.period.value} {subsystem.period.unit}")
    inputs = [
        Port(port_name("ib", indexed_name(b)), element_name(b, Kind.INPUT_BUFFER) + _queue_text(b))
        for b in subsystem.input_buffers
    ]
    outputs = [
        Port(port_name("ob", indexed_name(b)), element_name(b, Kind.OUTPUT_BUFFER)) for b in subsystem.output_buffers
    ]
    memory = [
        f'⇅ {html(element_name(m, Kind.MEMORY))} <font color="#666666">: {html(type_text(m.data_type))}</font>'
        for m in subsystem.memories
    ]
    return block(title, inputs, outputs, memory, FILL.get(subsystem.kind.value, "white"), notes)


def agent_view(agent: Agent, system: System | None = None) -> Diagram:
    name = agent_name(agent)
    graph = Graph(f"ibd [Agent] {name}")
    graph.graph_attributes["ranksep"] = "0.5"
    names: list[str] = [name]
    nodes: dict[Key, tuple[str, Subsystem]] = {}
    if not agent.subsystems:  # Graphviz draws no cluster without a node: the frame and its header would vanish
        graph.add('none [shape="plaintext", fontsize="10", label="no subsystem"];')
    for subsystem in agent.subsystems:
        key = element_key(subsystem, subsystem.kind)
        node = node_id("ss", subsystem_name(subsystem))
        nodes[key] = (node, subsystem)
        names.append(subsystem_name(subsystem))
        names += [element_name(b, Kind.INPUT_BUFFER) for b in subsystem.input_buffers]
        names += [element_name(b, Kind.OUTPUT_BUFFER) for b in subsystem.output_buffers]
        names += [element_name(m, Kind.MEMORY) for m in subsystem.memories]
        tooltip = html(f"{name}.{subsystem_name(subsystem)}")
        graph.add(f'{node} [shape="plain", label={subsystem_block(subsystem)}, tooltip="{tooltip}"];')

    for number, link in enumerate(agent_links(agent)):
        source_node = nodes[element_key(link.source, link.source.kind)][0]
        destination_node = nodes[element_key(link.destination, link.destination.kind)][0]
        label = link_label(link.link)
        names.append(label)
        source = f"{source_node}:{port_name('ob', indexed_name(link.output))}:e"
        destination = f"{destination_node}:{port_name('ib', indexed_name(link.input))}:w"
        backward = _ORDER[link.destination.kind] < _ORDER[link.source.kind]
        data_type = type_text(link.output.data_type)
        for statement in link_statements(number, source, destination, label, data_type, backward).all():
            graph.add(statement)

    if system is not None:
        _external_links(agent, system, graph, names)
    return Diagram("agent", graph.header, graph.source(), slug("agent", name), tuple(names))


def _external_links(agent: Agent, system: System, graph: Graph, names: list[str]) -> None:
    """The agents this one talks to, dashed and outside the frame, linked to its Control Subsystem's buffers.

    An agent that sends to this one is drawn on the left, one that receives on the
    right (an agent that does both appears twice), so every link runs left to right.
    Invisible edges to and from every subsystem hold them there: the frame is a cluster,
    and dot would otherwise put an outside node that shares a rank with the frame's
    contents below the frame.
    """
    cs = agent.control_subsystem
    if cs is None:
        return
    cs_node = node_id("ss", "cs")
    subsystem_nodes = [node_id("ss", subsystem_name(subsystem)) for subsystem in agent.subsystems]
    drawn: set[str] = set()
    for number, link in enumerate(inter_agent_links(system)):
        if link.source is agent and link.destination is not agent:
            other = agent_name(link.destination)
            node = node_id("ext_out", other)
            source = f"{cs_node}:{port_name('ob', link.source_buffer)}:e"
            destination = node
        elif link.destination is agent and link.source is not agent:
            other = agent_name(link.source)
            node = node_id("ext_in", other)
            source = node
            destination = f"{cs_node}:{port_name('ib', link.destination_buffer)}:w"
        else:
            continue
        if node not in drawn:
            drawn.add(node)
            if other not in names:
                names.append(other)
            graph.outside.append(
                f'{node} [shape="box", style="dashed,rounded", color="#777777", fontcolor="#555555", '
                f"label=<<i>«Agent»</i><br/>{html(other)}>];"
            )
            for subsystem_node in subsystem_nodes:
                before, after = (subsystem_node, node) if destination == node else (node, subsystem_node)
                graph.outside.append(f'{before} -> {after} [style="invis"];')
        statements = link_statements(number + 10_000, source, destination, link_label(link.link), link.data_type, False)
        graph.outside += [
            statement.replace("];", ', style="dashed"];') if "->" in statement else statement
            for statement in statements.all()
        ]
