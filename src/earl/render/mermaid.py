"""Mermaid text for the system and FSM views, for Markdown on code hosts that draw Mermaid.

Mermaid has no ports and no "every other state" pseudo-state, so the system view
links agents directly (the buffers go in the link's label) and a transition from
`*` is written once per source state.
"""

from __future__ import annotations

import re

from earl.model.elements import FSM, Agent, Subsystem
from earl.model.text import expression_text
from earl.render.build import Subject
from earl.render.names import agent_name, link_label, qualified_subsystem_name
from earl.render.tables import assumption_table
from earl.render.targets import TargetError, find_subsystem, only_fsm
from earl.render.views.system import inter_agent_links, member_names, member_placement_lines

#: The identifier of the composite state that stands for the state machine; the states' are `s_…`, never this.
FSM_STATE = "fsm"


def text(value: str) -> str:
    """A Mermaid quoted label: quotes and characters Mermaid reads as markup become entity codes.

    `&` is one of them: Mermaid draws labels as HTML, where a spec's string `"&lt;"` would be shown as
    `"<"`; written `#38;lt;` it is shown as written. So is `\\`, which Mermaid drops before a quote (`"a\\"b"`)."""
    replacements = {'"': "#quot;", "<": "#lt;", ">": "#gt;", "#": "#35;", "|": "#124;", "&": "#38;", "\\": "#92;"}
    return "".join(replacements.get(c, c) for c in value)


def _identifier(prefix: str, name: str) -> str:
    return prefix + "_" + "".join(c if c.isalnum() else "_" for c in name)


def system_mermaid(subject: Subject) -> str:
    system = subject.shown
    lines = ["---", f"title: ibd [System] {system.name}", "---", "flowchart LR"]
    placements = subject.placements

    def agent_line(indent: str, agent: Agent) -> str:
        name = agent_name(agent)
        row = subject.agent_type(agent)
        kind = f"<br/>{text(row.name)}: {text(row.description)}" if row is not None else ""
        # a family split over robots is drawn outside them, saying where its members are
        where = "".join(f"<br/>{text(line)}" for line in member_placement_lines(system, agent, placements[id(agent)]))
        return f'{indent}{_identifier("a", name)}["«Agent» {text(name)}{kind}{where}"]'

    member_edges: list[str] = []
    for number, robot in enumerate(system.robots):
        lines.append(f'    subgraph robot_{number}["«Robot» {text(robot.name)}/r"]')
        for agent in system.agents:
            placement = placements[id(agent)]
            if placement.robot == number:
                lines.append(agent_line("        ", agent))
                continue
            for share in placement.shares:
                if share.robot == number and share.members is not None:
                    # the members this robot holds, as a stand-in tied to the family drawn outside
                    stand_in = _identifier(f"m{number}", agent_name(agent))
                    held = member_names(agent, share.members)
                    plural = "s" if len(share.members) > 1 else ""
                    lines.append(
                        f'        {stand_in}(["«Agent» {text(held)}<br/>member{plural} of {text(agent_name(agent))}"])'
                    )
                    member_edges.append(f"    {stand_in} -.- {_identifier('a', agent_name(agent))}")
        lines.append("    end")
    for agent in system.agents:
        if placements[id(agent)].robot is None:
            lines.append(agent_line("    ", agent))
    lines += member_edges
    for link in inter_agent_links(system):
        label = f"{link_label(link.link)}: {link.source_end}/ob → {link.destination_end}/ib : {link.data_type}"
        source = _identifier("a", agent_name(link.source))
        destination = _identifier("a", agent_name(link.destination))
        lines.append(f'    {source} -->|"{text(label)}"| {destination}')
    return "\n".join(lines) + "\n"


def fsm_mermaid(fsm: FSM, owner: str, subsystem: Subsystem | None = None) -> str:
    lines = ["---", f"title: stm [FSM] {owner}.fsm", "---", "stateDiagram-v2"]
    assumptions = assumption_table(fsm)
    # Mermaid attaches a note to a state only: an FSM that assumes something is drawn as a composite state,
    # the state machine, and its assumptions are a note on it, as the Graphviz drawing's note in the frame
    indent = "        " if assumptions else "    "
    if assumptions:
        lines.append(f'    state "{text(owner)}.fsm" as {FSM_STATE} {{')
    for state in fsm.states:
        identifier = _identifier("s", state.name)
        lines.append(f'{indent}state "{text(state.name)}" as {identifier}')
        lines.append(f"{indent}{identifier} : do / {text(state.behaviour)}/bb")
    if fsm.state_named(fsm.initial) is not None:
        lines.append(f"{indent}[*] --> {_identifier('s', fsm.initial)}")
    for transition in fsm.concrete_transitions():
        if transition.source is None:
            continue
        label = f"[{expression_text(transition.condition.expression)}]"
        if transition.priority is not None:
            label += f" priority {transition.priority}"
        source = _identifier("s", transition.source)
        destination = _identifier("s", transition.destination)
        lines.append(f"{indent}{source} --> {destination} : {text(label).replace(':', '#58;')}")
    if assumptions:
        lines.append("    }")
        lines.append(f"    note right of {FSM_STATE}")
        for assumption in assumptions:
            lines.append(f"        assume {_note_text(text(assumption.formula))}")
            if assumption.comment:
                lines.append(f"        {_note_text(text(assumption.comment))}")
        lines.append("    end note")
    return "\n".join(lines) + "\n"


def _note_text(line: str) -> str:
    """A line of a note: Mermaid's lexer ends a note at the first `end note` in it, in any case, so the
    space of one in the text is a non-breaking one (`#160;`)."""
    return re.sub(r"(?i)\b(end)\s+(note)", r"\1#160;\2", line)


def mermaid_of(subject: Subject, view: str, target: str | None) -> str:
    if view == "system":
        if target is not None:
            raise TargetError("the system view shows the whole system; leave out --target")
        return system_mermaid(subject)
    if view == "fsm":
        system = subject.drawn(view, target)
        agent, subsystem = find_subsystem(system, target) if target is not None else only_fsm(system)
        if subsystem.fsm is None:
            raise TargetError(f"{qualified_subsystem_name(agent, subsystem)} has no FSM to draw")
        return fsm_mermaid(subsystem.fsm, qualified_subsystem_name(agent, subsystem), subsystem)
    raise TargetError(f"Mermaid text exists for the system and fsm views only, not for `{view}`")
