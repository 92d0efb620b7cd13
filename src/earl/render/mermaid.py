"""Mermaid text for the system and FSM views, for Markdown on code hosts that draw Mermaid.

Mermaid has no ports and no "every other state" pseudo-state, so the system view
links agents directly (the buffers go in the link's label) and a transition from
`*` is written once per source state.
"""

from __future__ import annotations

from earl.model.elements import FSM, Subsystem
from earl.model.kinds import Kind
from earl.model.text import expression_text
from earl.render.build import Subject
from earl.render.names import agent_name, element_key, link_label, lookup, qualified_subsystem_name
from earl.render.targets import TargetError, find_subsystem, only_fsm
from earl.render.views.system import inter_agent_links


def text(value: str) -> str:
    """A Mermaid quoted label: quotes and characters Mermaid reads as markup become entity codes."""
    replacements = {'"': "#quot;", "<": "#lt;", ">": "#gt;", "#": "#35;", "|": "#124;"}
    return "".join(replacements.get(c, c) for c in value)


def _identifier(prefix: str, name: str) -> str:
    return prefix + "_" + "".join(c if c.isalnum() else "_" for c in name)


def system_mermaid(subject: Subject) -> str:
    system = subject.shown
    lines = ["---", f"title: ibd [System] {system.name}", "---", "flowchart LR"]
    agents_by_key = {element_key(a, Kind.AGENT): a for a in system.agents}
    placed: set[int] = set()

    def agent_line(indent: str, agent_index: int) -> str:
        agent = system.agents[agent_index]
        name = agent_name(agent)
        row = subject.agent_type(agent)
        kind = f"<br/>{text(row.name)}: {text(row.description)}" if row is not None else ""
        return f'{indent}{_identifier("a", name)}["«Agent» {text(name)}{kind}"]'

    positions = {id(a): n for n, a in enumerate(system.agents)}
    for number, robot in enumerate(system.robots):
        lines.append(f'    subgraph robot_{number}["«Robot» {text(robot.name)}/r"]')
        for reference in robot.agents:
            found = lookup(agents_by_key, reference)
            members = [found] if found is not None else [a for k, a in agents_by_key.items() if k[0] == reference.name]
            for agent in members:
                if id(agent) not in placed:
                    placed.add(id(agent))
                    lines.append(agent_line("        ", positions[id(agent)]))
        lines.append("    end")
    for agent in system.agents:
        if id(agent) not in placed:
            lines.append(agent_line("    ", positions[id(agent)]))
    for link in inter_agent_links(system):
        label = f"{link_label(link.link)}: {link.source_end}/ob → {link.destination_end}/ib : {link.data_type}"
        source = _identifier("a", agent_name(link.source))
        destination = _identifier("a", agent_name(link.destination))
        lines.append(f'    {source} -->|"{text(label)}"| {destination}')
    return "\n".join(lines) + "\n"


def fsm_mermaid(fsm: FSM, owner: str, subsystem: Subsystem | None = None) -> str:
    lines = ["---", f"title: stm [FSM] {owner}.fsm", "---", "stateDiagram-v2"]
    for state in fsm.states:
        identifier = _identifier("s", state.name)
        lines.append(f'    state "{text(state.name)}" as {identifier}')
        lines.append(f"    {identifier} : do / {text(state.behaviour)}/bb")
    if fsm.state_named(fsm.initial) is not None:
        lines.append(f"    [*] --> {_identifier('s', fsm.initial)}")
    for transition in fsm.concrete_transitions():
        if transition.source is None:
            continue
        label = f"[{expression_text(transition.condition.expression)}]"
        if transition.priority is not None:
            label += f" priority {transition.priority}"
        source = _identifier("s", transition.source)
        destination = _identifier("s", transition.destination)
        lines.append(f"    {source} --> {destination} : {text(label).replace(':', '#58;')}")
    return "\n".join(lines) + "\n"


def mermaid_of(subject: Subject, view: str, target: str | None) -> str:
    if view == "system":
        if target is not None:
            raise TargetError("the system view shows the whole system; leave out --target")
        return system_mermaid(subject)
    if view == "fsm":
        system = subject.shown
        agent, subsystem = find_subsystem(system, target) if target is not None else only_fsm(system)
        if subsystem.fsm is None:
            raise TargetError(f"{qualified_subsystem_name(agent, subsystem)} has no FSM to draw")
        return fsm_mermaid(subsystem.fsm, qualified_subsystem_name(agent, subsystem), subsystem)
    raise TargetError(f"Mermaid text exists for the system and fsm views only, not for `{view}`")
