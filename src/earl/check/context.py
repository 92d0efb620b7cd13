"""What the rules read: the declared system, its expansion into instances, and indexes over both."""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Hashable, Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TypeVar

from earl.model.elements import (
    Agent,
    InputBuffer,
    Link,
    LinkEnd,
    Memory,
    OutputBuffer,
    Subsystem,
    System,
)
from earl.model.expressions import ElementReference, Literal, Name
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.tables import AgentType, agent_type
from earl.model.text import instance_name
from earl.model.types import ArrayType, DataType, PrimitiveType, StructType, TypeDefinition, TypeReference


def reference_key(reference: ElementReference) -> str:
    """The concrete name a reference denotes in an expanded system (`windingCurrent[2]`)."""
    index = reference.indices[0] if reference.indices else None
    value = getattr(index, "value", None)
    return instance_name(reference.name, value if isinstance(value, int) else None)


MemberKey = tuple[str, int | None]


def written_output_buffers(subsystem: Subsystem) -> frozenset[str]:
    """The names of the output buffers some function of some behaviour of `subsystem` writes: the others
    are never sent (`tf.pf.ob.send()` sends only what a function wrote, docs/semantics.md)."""
    used = {f.name for b in subsystem.basic_behaviours for stage in b.transition_function.stages for f in stage}
    return frozenset(
        w.name
        for f in subsystem.partial_transition_functions
        if f.name in used
        for w in f.writes
        if w.kind is Kind.OUTPUT_BUFFER
    )


def member_key(reference: ElementReference) -> MemberKey:
    """`reference_key` as a (name, index) pair: the lookup tables' key, with no text to build."""
    indices = reference.indices
    if not indices:
        return reference.name, None
    value = getattr(indices[0], "value", None)
    return reference.name, value if isinstance(value, int) and not isinstance(value, bool) else None


_Element = TypeVar("_Element", InputBuffer, OutputBuffer, Memory)


def _by_member(elements: list[_Element]) -> dict[MemberKey, _Element]:
    """Elements by (name, index); the first of two equal names wins, as a scan would find it."""
    return {(e.name, e.index): e for e in reversed(elements)}


_LEAVES = (str, int, float, bool, type(None), SourceLocation, Kind)


def _names_in(root: object) -> frozenset[str]:
    """Every `Name` anywhere inside a declaration: over-approximating is safe (it only makes two members
    look different), missing one is not, so the walk is generic rather than field by field."""
    names: set[str] = set()
    stack: list[object] = [root]
    seen: set[int] = set()
    while stack:
        node = stack.pop()
        if isinstance(node, Name):
            names.add(node.name)
        elif isinstance(node, _LEAVES) or id(node) in seen:
            continue
        else:
            seen.add(id(node))
            if isinstance(node, (list, tuple)):
                stack.extend(node)
            elif dataclasses.is_dataclass(node):
                stack.extend(getattr(node, f.name) for f in dataclasses.fields(node))
    return frozenset(names)


def _value_of(name: str, agent: Agent, subsystem: Subsystem) -> object:
    """The value `name` has inside an expanded subsystem, looked up from the innermost scope out;
    None for a system parameter or a name bound inside the body (the same for every member)."""
    if subsystem.family is not None and subsystem.family.index == name:
        return subsystem.index
    for parameter in subsystem.parameters:
        if parameter.name == name:
            return _literal(parameter.value)
    if agent.family is not None and agent.family.index == name:
        return agent.index
    for parameter in agent.parameters:
        if parameter.name == name:
            return _literal(parameter.value)
    return None


def _literal(value: object) -> object:
    return value.value if isinstance(value, Literal) else id(value)


@dataclass(slots=True)
class ResolvedLink:
    """A concrete link with the subsystems and buffers at its ends."""

    link: Link
    source_agent: Agent
    source_subsystem: Subsystem
    source_buffer: OutputBuffer
    destination_agent: Agent
    destination_subsystem: Subsystem
    destination_buffer: InputBuffer
    between_agents: bool


def _link_shape(links: Sequence[ResolvedLink]) -> tuple[int, int]:
    """How many links reach a buffer, and how many of them come from or go to another agent."""
    return len(links), sum(link.between_agents for link in links)


@dataclass
class CheckContext:
    declared: System
    system: System  # expanded: every family member
    _agents: dict[MemberKey, Agent] = field(default_factory=dict)
    _subsystem_tables: dict[int, dict[tuple[Kind, str, int | None], Subsystem]] = field(default_factory=dict)
    _output_tables: dict[int, dict[MemberKey, OutputBuffer]] = field(default_factory=dict)
    _input_tables: dict[int, dict[MemberKey, InputBuffer]] = field(default_factory=dict)
    _memory_tables: dict[int, dict[MemberKey, Memory]] = field(default_factory=dict)
    _same_types: dict[tuple[int, int], tuple[DataType, DataType, bool]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._agents = {(a.name, a.index): a for a in reversed(self.system.agents)}

    # ------------------------------------------------------------------ lookups
    def agent(self, reference: ElementReference) -> Agent | None:
        return self._agents.get(member_key(reference))

    def subsystem(self, agent: Agent, reference: ElementReference) -> Subsystem | None:
        table = self._subsystem_tables.get(id(agent))
        if table is None:
            table = self._subsystem_tables[id(agent)] = {
                (s.kind, s.name, s.index): s for s in reversed(agent.subsystems)
            }
        return table.get((reference.kind, *member_key(reference)))

    # Links into a subsystem with a family of ten thousand buffers would make a scan per link
    # quadratic, so each subsystem's buffers are looked up through a table built on first use.
    def output_buffer(self, subsystem: Subsystem, reference: ElementReference) -> OutputBuffer | None:
        table = self._output_tables.get(id(subsystem))
        if table is None:
            table = self._output_tables[id(subsystem)] = _by_member(subsystem.output_buffers)
        return table.get(member_key(reference))

    def input_buffer(self, subsystem: Subsystem, reference: ElementReference) -> InputBuffer | None:
        table = self._input_tables.get(id(subsystem))
        if table is None:
            table = self._input_tables[id(subsystem)] = _by_member(subsystem.input_buffers)
        return table.get(member_key(reference))

    def memory(self, subsystem: Subsystem, reference: ElementReference) -> Memory | None:
        table = self._memory_tables.get(id(subsystem))
        if table is None:
            table = self._memory_tables[id(subsystem)] = _by_member(subsystem.memories)
        return table.get(member_key(reference))

    def subsystems(self) -> Iterator[tuple[Agent, Subsystem]]:
        for agent in self.system.agents:
            for subsystem in agent.subsystems:
                yield agent, subsystem

    # ------------------------------------------------------------------ one member per distinct content
    @cached_property
    def _free_names(self) -> dict[SourceLocation, frozenset[str]]:
        """For every declared subsystem, the parameters and indices its body names anywhere."""
        return {
            subsystem.location: _names_in(subsystem)
            for agent in self.declared.agents
            for subsystem in agent.subsystems
            if subsystem.location is not None
        }

    def content_key(self, agent: Agent, subsystem: Subsystem) -> Hashable:
        """Equal for two expanded subsystems exactly when they come from one declaration with the same
        values of every name its body uses; such members have the same buffers, predicates, functions,
        behaviours and FSM, and the rules on a subsystem's inside find the same problems in them."""
        names = self._free_names.get(subsystem.location) if subsystem.location is not None else None
        if names is None:
            return id(subsystem)
        values: list[object] = [subsystem.location]
        for name in sorted(names):
            values.append(_value_of(name, agent, subsystem))
        return tuple(values)

    def link_key(self, subsystem: Subsystem) -> Hashable:
        """Equal for two expanded subsystems whose buffers, taken in order, are linked alike: as many links
        into and out of each, and as many of them between agents. Rules that read links (an obligatory
        buffer no link feeds waits for ever, EARL-E016; a buffer fed from another agent may go stale) find
        the same problems in two members exactly when this and `content_key` agree; `worker[1]/a`, fed by
        another agent, and its unlinked siblings are not one subsystem to them."""
        return (
            tuple(_link_shape(self.links_into.get(id(buffer), ())) for buffer in subsystem.input_buffers),
            tuple(_link_shape(self.links_out_of.get(id(buffer), ())) for buffer in subsystem.output_buffers),
        )

    @cached_property
    def _distinct(self) -> list[list[tuple[Agent, Subsystem]]]:
        groups: dict[Hashable, list[tuple[Agent, Subsystem]]] = {}
        for agent, subsystem in self.subsystems():
            key = (self.content_key(agent, subsystem), self.link_key(subsystem))
            groups.setdefault(key, []).append((agent, subsystem))
        return list(groups.values())

    def distinct_subsystems(self) -> Iterator[tuple[Agent, Subsystem]]:
        """One expanded subsystem per distinct content and links (`content_key`, `link_key`), in
        declaration order.

        Ten thousand members of `worker[I]/a` whose control subsystems never name `I`, and are linked
        alike, are one subsystem to the rules about predicates, functions, behaviours and the FSM: a
        problem inside them is fixed once, in the declaration, and said of the first member."""
        for members in self._distinct:
            yield members[0]

    def distinct_subsystem_groups(self) -> Iterator[list[tuple[Agent, Subsystem]]]:
        """The members `distinct_subsystems` stands for, grouped, the one it yields first in each group.

        A rule about links checks the first member and names every member of its group: each member
        is linked on its own, so each needs the fix, and the check merges their names into one
        finding with the indices as a range (`worker[2..3]/a.cs`, check/merging.py)."""
        yield from self._distinct

    # ------------------------------------------------------------------ links
    def _end(self, end: LinkEnd, owner: Agent | None) -> tuple[Agent, Subsystem] | None:
        agent = owner if end.agent is None else self.agent(end.agent)
        if agent is None:
            return None
        subsystem = self.subsystem(agent, end.subsystem)
        return None if subsystem is None else (agent, subsystem)

    @cached_property
    def links(self) -> list[ResolvedLink]:
        """Every concrete link, inter-agent and inter-subsystem, with its ends found."""
        result: list[ResolvedLink] = []
        owned: list[tuple[Link, Agent | None]] = [(link, None) for link in self.system.links]
        owned += [(link, agent) for agent in self.system.agents for link in agent.links]
        for link, owner in owned:
            source = self._end(link.source, owner)
            destination = self._end(link.destination, owner)
            if source is None or destination is None:
                continue
            output = self.output_buffer(source[1], link.source.buffer)
            input_ = self.input_buffer(destination[1], link.destination.buffer)
            if output is None or input_ is None:
                continue
            result.append(
                ResolvedLink(link, source[0], source[1], output, destination[0], destination[1], input_, owner is None)
            )
        return result

    @cached_property
    def links_into(self) -> dict[int, list[ResolvedLink]]:
        """Links by the identity of the input buffer they feed."""
        table: dict[int, list[ResolvedLink]] = defaultdict(list)
        for link in self.links:
            table[id(link.destination_buffer)].append(link)
        return table

    @cached_property
    def links_out_of(self) -> dict[int, list[ResolvedLink]]:
        table: dict[int, list[ResolvedLink]] = defaultdict(list)
        for link in self.links:
            table[id(link.source_buffer)].append(link)
        return table

    @cached_property
    def _inter_agent_links(self) -> dict[int, list[ResolvedLink]]:
        table: dict[int, list[ResolvedLink]] = defaultdict(list)
        for link in self.links:
            if link.between_agents:
                table[id(link.source_agent)].append(link)
                if link.destination_agent is not link.source_agent:
                    table[id(link.destination_agent)].append(link)
        return table

    def inter_agent_links(self, agent: Agent) -> list[ResolvedLink]:
        """The inter-agent links that start or end at `agent` (an expanded agent)."""
        return self._inter_agent_links.get(id(agent), [])

    # ------------------------------------------------------------------ Table 1
    def instances(self, agent: Agent) -> list[Agent]:
        """The expanded agents `agent` stands for: itself, or, for an agent of the declared system, its
        counterpart (every member of a family).  Links are resolved between expanded agents only."""
        if id(agent) in self._expanded_agents:
            return [agent]
        return [
            candidate
            for candidate in self.system.agents
            if candidate.name == agent.name and (agent.index is None or candidate.index == agent.index)
        ]

    @cached_property
    def _expanded_agents(self) -> set[int]:
        return {id(agent) for agent in self.system.agents}

    def agent_type(self, agent: Agent) -> AgentType:
        """The row of Table 1 of an agent of the declared or of the expanded system."""
        effectors = bool(agent.subsystems_of(Kind.VIRTUAL_EFFECTOR) or agent.subsystems_of(Kind.REAL_EFFECTOR))
        receptors = bool(agent.subsystems_of(Kind.VIRTUAL_RECEPTOR) or agent.subsystems_of(Kind.REAL_RECEPTOR))
        transmission = any(self.inter_agent_links(instance) for instance in self.instances(agent))
        return agent_type(effectors, receptors, transmission)

    # ------------------------------------------------------------------ data types
    @cached_property
    def _types(self) -> dict[str, TypeDefinition]:
        return {t.name: t for t in reversed(self.system.types)}

    def structural(self, data_type: DataType) -> DataType | StructType:
        """The type behind aliases (the resolver guarantees the chain ends)."""
        seen = 0
        while isinstance(data_type, TypeReference) and seen < 1000:
            seen += 1
            definition = self._types.get(data_type.name)
            if definition is None or isinstance(definition, StructType):
                return definition if definition is not None else data_type
            data_type = definition.data_type
        return data_type

    def same_type(self, first: DataType, second: DataType) -> bool:
        # Members of a family share their buffers' type objects: each pair is compared once.
        # The pair is kept with the answer, so that neither id can be reused by another object.
        key = (id(first), id(second))
        known = self._same_types.get(key)
        if known is None:
            known = self._same_types[key] = (first, second, self._same_type(first, second))
        return known[2]

    def _same_type(self, first: DataType, second: DataType) -> bool:
        a, b = self.structural(first), self.structural(second)
        if isinstance(a, StructType) or isinstance(b, StructType):
            return a is b
        if isinstance(a, PrimitiveType) and isinstance(b, PrimitiveType):
            return a.name == b.name
        if isinstance(a, ArrayType) and isinstance(b, ArrayType):
            return a.size == b.size and self.same_type(a.element, b.element)
        return False
