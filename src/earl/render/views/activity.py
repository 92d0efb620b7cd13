"""The activity view (the manual's Figure 15): `bb.tf.execute()`, the stages of a Transition Function.

Each stage is a fork/join region whose Partial Transition Functions run as if in
parallel (Eq. 7–8 make that safe); the stages run one after another.  A stage is
named after the stage set that holds all of its functions (`pf`, `pfo`, Eq. 4 and 6).
"""

from __future__ import annotations

from earl.model.elements import BasicBehaviour, PartialTransitionFunction, Subsystem
from earl.model.expressions import ElementReference
from earl.model.text import reference_text
from earl.render.diagram import Diagram
from earl.render.dot import Graph, html, wrapped
from earl.render.names import slug

_BAR = 'shape="box", style="filled", fillcolor="black", label="", height="0.06", width="{width}", fixedsize="true"'


def stage_set_name(stage: list[ElementReference], subsystem: Subsystem | None) -> str | None:
    if subsystem is None or not stage:
        return None
    names = {reference.name for reference in stage}
    for stage_set in subsystem.stage_sets:
        if names <= {reference.name for reference in stage_set.functions}:
            return stage_set.name
    return None


def _action_label(reference: ElementReference, function: PartialTransitionFunction | None) -> str:
    # a space either side: dot measures the bold name narrower than a browser draws it, and the rounded
    # border's corners took the rest (`outputManipState/pf` touched it)
    rows = [f"<tr><td><b>&#160;{html(reference_text(reference))}&#160;</b></td></tr>"]
    if function is not None and function.writes:
        writes = ", ".join(reference_text(w) for w in function.writes)
        for line in wrapped(f"→ {writes}", 40):
            rows.append(f'<tr><td><font point-size="9" color="#555555">&#160;{html(line)}&#160;</font></td></tr>')
    return (
        '<<table border="1" style="rounded" cellborder="0" cellspacing="0" cellpadding="3" bgcolor="#f7f9fc">'
        + "".join(rows)
        + "</table>>"
    )


def activity_view(behaviour: BasicBehaviour, owner: str, subsystem: Subsystem | None = None) -> Diagram:
    """`owner` names the subsystem (`manip/a.cs`); the header names the operation."""
    # a behaviour shown alone (Jupyter) has no owner to name: no leading dot then
    operation = f"{owner + '.' if owner else ''}{behaviour.name}/bb.tf.execute()"
    graph = Graph(f"act [Operation] {operation}", rankdir="TB")
    graph.graph_attributes.update(nodesep="0.4", ranksep="0.45")
    names = [f"{behaviour.name}/bb"]
    graph.add('start [shape="circle", style="filled", fillcolor="black", label="", width="0.18", fixedsize="true"];')
    previous = "start"
    for number, stage in enumerate(behaviour.transition_function.stages, start=1):
        stage_set = stage_set_name(stage, subsystem)
        title = f"stage {number}" + (f": {stage_set}" if stage_set else "")
        graph.add(f"subgraph cluster_stage_{number} {{")
        graph.add(f'  label="{html(title)}"; labeljust="l"; style="dashed,rounded"; color="#888888"; fontsize="9";')
        actions = []
        for position, reference in enumerate(stage):
            node = f"action_{number}_{position}"
            actions.append(node)
            function = subsystem.partial_transition_function(reference.name) if subsystem is not None else None
            names.append(reference_text(reference))
            tooltip = html(reference_text(reference))
            graph.add(f'  {node} [shape="plain", label={_action_label(reference, function)}, tooltip="{tooltip}"];')
        parallel = len(actions) > 1
        if len(actions) == 1:
            # The control flow runs down the middle of a stage of one action, and struck through its label
            # (`stage 1`, at the top left) when the action was narrow: an invisible spacer as wide as the
            # label either side of the action keeps the label left of it.
            width = f"{len(title) * 0.075 + 0.1:.2f}"  # inches: a 9 pt letter is about 0.07 in wide
            spacer = f'shape="box", style="invis", label="", width="{width}", height="0.02", fixedsize="true"'
            graph.add(f"  spacer_{number}_l [{spacer}];")
            graph.add(f"  spacer_{number}_r [{spacer}];")
            graph.add(f'  {{ rank=same; spacer_{number}_l -> {actions[0]} -> spacer_{number}_r [style="invis"]; }}')
        if parallel:
            width = str(max(1.2, 1.9 * len(actions)))
            graph.add(f"  fork_{number} [{_BAR.format(width=width)}];")
            graph.add(f"  join_{number} [{_BAR.format(width=width)}];")
        graph.add("}")
        if parallel:
            graph.add(f"{previous} -> fork_{number};")
            for node in actions:
                graph.add(f"fork_{number} -> {node};")
                graph.add(f"{node} -> join_{number};")
            previous = f"join_{number}"
        elif actions:
            graph.add(f"{previous} -> {actions[0]};")
            previous = actions[0]
    graph.add(
        'final [shape="doublecircle", style="filled", fillcolor="black", label="", width="0.14", fixedsize="true"];'
    )
    graph.add(f"{previous} -> final;")
    return Diagram("activity", graph.header, graph.source(), slug("act", owner, behaviour.name), tuple(names))
