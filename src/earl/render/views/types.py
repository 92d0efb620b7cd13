"""The types view (the manual's Figures 9 and 11): data types and their fields, as a bdd.

A struct is a «dataType» block with one row per field (`[0..1]` marks an optional
one); an alias is a «valueType».  An arrow with a diamond goes from a struct to
each type it is composed of, labelled with the field.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from earl.model.elements import Agent, System
from earl.model.types import ArrayType, DataType, StructType, TypeDefinition, TypeReference, type_text
from earl.render.diagram import Diagram
from earl.render.dot import Graph, html
from earl.render.names import slug
from earl.render.views.common import node_id


def referenced_type_names(data_type: DataType) -> list[str]:
    """The defined types a type mentions (`JointPosition` in `JointPosition[]`)."""
    if isinstance(data_type, TypeReference):
        return [data_type.name]
    if isinstance(data_type, ArrayType):
        return referenced_type_names(data_type.element)
    return []


def closure(system: System, roots: Iterable[str]) -> list[TypeDefinition]:
    """The definitions of `roots` and of every type they are built from, in declaration order."""
    wanted: set[str] = set()
    pending = list(roots)
    while pending:
        name = pending.pop()
        if name in wanted:
            continue
        definition = system.type_named(name)
        if definition is None:
            continue
        wanted.add(name)
        if isinstance(definition, StructType):
            for field in definition.fields:
                pending += referenced_type_names(field.data_type)
        else:
            pending += referenced_type_names(definition.data_type)
    return [definition for definition in system.types if definition.name in wanted]


def agent_types(system: System, agent: Agent) -> list[TypeDefinition]:
    """The types an agent's buffers and memory hold (Figure 11 for `manip/a`)."""
    roots: list[str] = []
    for subsystem in agent.subsystems:
        held = [b.data_type for b in subsystem.input_buffers] + [b.data_type for b in subsystem.output_buffers]
        held += [m.data_type for m in subsystem.memories]
        for data_type in held:
            roots += referenced_type_names(data_type)
    return closure(system, roots)


def field_port(index: int) -> str:
    """The DOT port of a struct's field row, the tail of the composition arrow its field draws."""
    return f"f{index}"


#: The port of an alias's one row (`= double[N]`).
ALIAS_PORT = "alias"


def _block(definition: TypeDefinition) -> str:
    if isinstance(definition, StructType):
        stereotype = "dataType"
        rows = [
            f'<tr><td port="{field_port(index)}" align="left">{html(f.name)}: {html(type_text(f.data_type))}'
            f"{' [0..1]' if f.optional else ''}&#160;&#160;</td></tr>"
            for index, f in enumerate(definition.fields)
        ]
    else:
        stereotype = "valueType"
        rows = [
            f'<tr><td port="{ALIAS_PORT}" align="left">= {html(type_text(definition.data_type))}&#160;&#160;</td></tr>'
        ]
    head = f"<tr><td><i>«{stereotype}»</i><br/><b>{html(definition.name)}</b></td></tr>"
    separator = "<hr/>" if rows else ""
    return (
        '<<table border="1" cellborder="0" cellspacing="0" cellpadding="3" bgcolor="#fbfbf4">'
        + head
        + separator
        + "".join(rows)
        + "</table>>"
    )


def types_view(definitions: Sequence[TypeDefinition], owner: str, subject: str = "dataTypes") -> Diagram:
    """A bdd of `definitions`; `owner` names the package (`pickAndPlace`) or agent (`manip/a`)."""
    graph = Graph(" ".join(part for part in ("bdd [Package]", owner, subject) if part), rankdir="LR")
    graph.graph_attributes.update(nodesep="0.25", ranksep="0.8")
    shown = {definition.name for definition in definitions}
    names = []
    connected: set[str] = set()
    for definition in definitions:
        names.append(definition.name)
        graph.add(f'{node_id("type", definition.name)} [shape="plain", label={_block(definition)}];')
    for definition in definitions:
        # (label, the row's port, target): each arrow leaves the row of the field it stands for.
        parts: list[tuple[str, str, str]] = []
        if isinstance(definition, StructType):
            for index, field in enumerate(definition.fields):
                parts += [(field.name, field_port(index), target) for target in referenced_type_names(field.data_type)]
        else:
            parts += [("", ALIAS_PORT, target) for target in referenced_type_names(definition.data_type)]
        for label, port, target in parts:
            if target in shown:
                connected |= {definition.name, target}
                if label:
                    names.append(label)
                graph.add(
                    f"{node_id('type', definition.name)} -> {node_id('type', target)} "
                    f'[tailport="{port}:e", dir="both", arrowtail="diamond", arrowhead="open", label="{html(label)}"];'
                )
    if not definitions:  # Graphviz draws no cluster without a node: the frame and its header would vanish
        graph.add('none [shape="plaintext", fontsize="10", label="no struct or alias: only primitive types"];')
    # Types that stand alone would stack in one tall column; invisible edges set them in rows of three.
    alone = [node_id("type", d.name) for d in definitions if d.name not in connected]
    for start in range(0, len(alone), 3):
        row = alone[start : start + 3]
        if len(row) > 1:
            graph.add(" -> ".join(row) + ' [style="invis"];')
    return Diagram("types", graph.header, graph.source(), slug("types", owner), tuple(names))
