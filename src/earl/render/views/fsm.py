"""The FSM view (the manual's Figure 12): states with their Basic Behaviours, transitions with
their initial conditions and priorities, and the initial state.

The FSM's assumptions (`assume …`, which the manual states in Table 5's caption) are a SysML
note inside the frame, the state machine's own comment.

A transition declared from every other state (`* -> emergencyStop`, Table 5's
`i,emergencyStop/t where i ≠ emergencyStop`) is drawn once from a dashed
"every state i ≠ …" node, as families are drawn once; with `expand` it is drawn
from each state, as the checker and the runtime see it.
"""

from __future__ import annotations

from earl.model.elements import FSM, State, Subsystem, Transition
from earl.model.text import expression_text, literal_text, reference_text
from earl.render.diagram import Diagram
from earl.render.dot import Graph, html, wrapped
from earl.render.names import slug
from earl.render.tables import assumption_table
from earl.render.views.common import node_id


def transition_label(transition: Transition) -> str:
    """`[newJointPos/pp and not emergencyStop/pp]` over `priority 2`, as an HTML-like label."""
    lines = wrapped(f"[{expression_text(transition.condition.expression)}]")
    text = "<br/>".join(html(line) for line in lines)
    if transition.priority is not None:
        text += f'<br/><font color="#555555">priority {transition.priority}</font>'
    return f"<{text}>"


def _state_label(state: State, subsystem: Subsystem | None, initial: bool) -> str:
    name, behaviour = state.name, state.behaviour
    rows = [f"<tr><td><b>{html(name)}</b></td></tr>", "<hr/>", f"<tr><td>do / {html(behaviour)}/bb</td></tr>"]
    # the state's buffer group: what its receive waits for, and for how long (FABRIC's buffer groups)
    group = []
    if state.obligatory:
        group.append("obligatory " + ", ".join(reference_text(r) for r in state.obligatory))
    if state.optional:
        group.append("optional " + ", ".join(reference_text(r) for r in state.optional))
    if state.timeout is not None:
        group.append(f"timeout {literal_text(state.timeout.value)} {state.timeout.unit}")
    for line in wrapped("; ".join(group), 40) if group else []:
        rows.append(f'<tr><td><font point-size="9" color="#1f4e79">{html(line)}</font></td></tr>')
    found = subsystem.basic_behaviour(behaviour) if subsystem is not None else None
    if found is not None:
        terminal = wrapped(f"tc: {expression_text(found.terminal_condition.expression)}", 40)
        for line in terminal:
            rows.append(f'<tr><td><font point-size="9" color="#555555">{html(line)}</font></td></tr>')
        if found.error_condition is not None:
            error = wrapped(f"ec: {expression_text(found.error_condition.expression)}", 40)
            for line in error:
                rows.append(f'<tr><td><font point-size="9" color="#555555">{html(line)}</font></td></tr>')
    fill = "#dbe8f7" if initial else "#f7f9fc"
    return (
        f'<<table border="1" style="rounded" cellborder="0" cellspacing="0" cellpadding="3" bgcolor="{fill}">'
        + "".join(rows)
        + "</table>>"
    )


def fsm_view(fsm: FSM, owner: str, subsystem: Subsystem | None = None, expand: bool = False) -> Diagram:
    """`owner` names the subsystem in the manual's dot notation (`manip/a.cs`)."""
    graph = Graph(f"stm [FSM] {owner + '.' if owner else ''}fsm", rankdir="TB")  # no owner: an FSM shown alone
    graph.graph_attributes.update(nodesep="0.6", ranksep="0.7")
    names: list[str] = []
    graph.add('initial [shape="circle", style="filled", fillcolor="black", label="", width="0.18", fixedsize="true"];')
    for state in fsm.states:
        names += [state.name, f"{state.behaviour}/bb"]
        label = _state_label(state, subsystem, state.name == fsm.initial)
        graph.add(f'{node_id("state", state.name)} [shape="plain", label={label}, tooltip="{html(state.name)}"];')
    if fsm.state_named(fsm.initial) is not None:
        graph.add(f"initial -> {node_id('state', fsm.initial)};")

    transitions = fsm.concrete_transitions() if expand else fsm.transitions
    for number, transition in enumerate(transitions):
        destination = node_id("state", transition.destination)
        if transition.source is None:
            any_node = f"any_{number}"
            note = f"every state i ≠ {transition.destination}"
            graph.add(
                f'{any_node} [shape="box", style="dashed,rounded", color="#777777", fontcolor="#555555", '
                f'label="{html(note)}"];'
            )
            source = any_node
        else:
            source = node_id("state", transition.source)
        tooltip = html(f"{transition.name}/t")
        names.append(f"{transition.name}/t")
        # A transition back into its own state leaves the middle of its east side and comes back under its
        # south-east corner: left to dot, it left the top of that side, where a transition arriving from above
        # lands, whose arrowhead then met the loop's start (grip/a.cs's move).  Under the state, it crossed the
        # transitions leaving for the states below.
        ports = 'tailport="e", headport="se", ' if source == destination else ""
        label = transition_label(transition)
        graph.add(f'{source} -> {destination} [{ports}label={label}, tooltip="{tooltip}"];')
    assumed = assumptions_label(fsm)
    if assumed is not None:
        # inside the frame and tied to no state: a comment of the state machine itself, as a SysML note
        graph.add(
            f'assumptions [shape="note", style="filled", fillcolor="#fffbe6", color="#8a7a3d", margin="0.12,0.06", '
            f'label={assumed}, tooltip="{html(owner + "." if owner else "")}fsm assumes"];'
        )
    return Diagram("fsm", graph.header, graph.source(), slug("fsm", owner), tuple(names))


def assumptions_label(fsm: FSM) -> str | None:
    """`assume not (newJointPos/pp and newOperationalPos/pp)` over its comment, for each assumption: an
    HTML-like label, or None for an FSM that assumes nothing."""
    rows = []
    for assumption in assumption_table(fsm):
        lines = wrapped(f"assume {assumption.formula}")
        rows += [f'<tr><td align="left">{html(line)}</td></tr>' for line in lines]
        for line in wrapped(assumption.comment, 48) if assumption.comment else []:
            rows.append(
                f'<tr><td align="left"><font point-size="9" color="#555555"><i>{html(line)}</i></font></td></tr>'
            )
    if not rows:
        return None
    return '<<table border="0" cellborder="0" cellspacing="0" cellpadding="1">' + "".join(rows) + "</table>>"
