"""What the rules read: the declared system, its expansion into instances, and indexes over both."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cached_property

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
from earl.model.expressions import ElementReference
from earl.model.kinds import Kind
from earl.model.tables import AgentType, agent_type
from earl.model.types import ArrayType, DataType, PrimitiveType, StructType, TypeReference


def instance_name(name: str, index: int | None) -> str:
    return name if index is None else f"{name}[{index}]"


def subsystem_name(agent: Agent, subsystem: Subsystem) -> str:
    """`manip/a.cs`, `manip/a.motorController[3]/ve`: the dot notation of manual §2.2."""
    own = (
        "cs"
        if subsystem.kind is Kind.CONTROL_SUBSYSTEM
        else f"{instance_name(subsystem.name, subsystem.index)}/{subsystem.kind.value}"
    )
    return f"{instance_name(agent.name, agent.index)}/a.{own}"


def reference_key(reference: ElementReference) -> str:
    """The concrete name a reference denotes in an expanded system (`windingCurrent[2]`)."""
    index = reference.indices[0] if reference.indices else None
    value = getattr(index, "value", None)
    return instance_name(reference.name, value if isinstance(value, int) else None)


@dataclass
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


@dataclass
class CheckContext:
    declared: System
    system: System  # expanded: every family member
    _agents: dict[str, Agent] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._agents = {instance_name(a.name, a.index): a for a in self.system.agents}

    # ------------------------------------------------------------------ lookups
    def agent(self, reference: ElementReference) -> Agent | None:
        return self._agents.get(reference_key(reference))

    def subsystem(self, agent: Agent, reference: ElementReference) -> Subsystem | None:
        key = reference_key(reference)
        for subsystem in agent.subsystems:
            if subsystem.kind is reference.kind and instance_name(subsystem.name, subsystem.index) == key:
                return subsystem
        return None

    @staticmethod
    def output_buffer(subsystem: Subsystem, reference: ElementReference) -> OutputBuffer | None:
        key = reference_key(reference)
        return next((b for b in subsystem.output_buffers if instance_name(b.name, b.index) == key), None)

    @staticmethod
    def input_buffer(subsystem: Subsystem, reference: ElementReference) -> InputBuffer | None:
        key = reference_key(reference)
        return next((b for b in subsystem.input_buffers if instance_name(b.name, b.index) == key), None)

    @staticmethod
    def memory(subsystem: Subsystem, reference: ElementReference) -> Memory | None:
        key = reference_key(reference)
        return next((m for m in subsystem.memories if instance_name(m.name, m.index) == key), None)

    def subsystems(self) -> Iterator[tuple[Agent, Subsystem]]:
        for agent in self.system.agents:
            for subsystem in agent.subsystems:
                yield agent, subsystem

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

    def inter_agent_links(self, agent: Agent) -> list[ResolvedLink]:
        return [
            link
            for link in self.links
            if link.between_agents and (link.source_agent is agent or link.destination_agent is agent)
        ]

    # ------------------------------------------------------------------ Table 1
    def instances(self, agent: Agent) -> list[Agent]:
        """The expanded agents `agent` stands for: itself, or, for an agent of the declared system, its
        counterpart (every member of a family).  Links are resolved between expanded agents only."""
        if any(candidate is agent for candidate in self.system.agents):
            return [agent]
        return [
            candidate
            for candidate in self.system.agents
            if candidate.name == agent.name and (agent.index is None or candidate.index == agent.index)
        ]

    def agent_type(self, agent: Agent) -> AgentType:
        """The row of Table 1 of an agent of the declared or of the expanded system."""
        effectors = bool(agent.subsystems_of(Kind.VIRTUAL_EFFECTOR) or agent.subsystems_of(Kind.REAL_EFFECTOR))
        receptors = bool(agent.subsystems_of(Kind.VIRTUAL_RECEPTOR) or agent.subsystems_of(Kind.REAL_RECEPTOR))
        transmission = any(self.inter_agent_links(instance) for instance in self.instances(agent))
        return agent_type(effectors, receptors, transmission)

    # ------------------------------------------------------------------ data types
    def structural(self, data_type: DataType) -> DataType | StructType:
        """The type behind aliases (the resolver guarantees the chain ends)."""
        seen = 0
        while isinstance(data_type, TypeReference) and seen < 1000:
            seen += 1
            definition = self.system.type_named(data_type.name)
            if definition is None or isinstance(definition, StructType):
                return definition if definition is not None else data_type
            data_type = definition.data_type
        return data_type

    def same_type(self, first: DataType, second: DataType) -> bool:
        a, b = self.structural(first), self.structural(second)
        if isinstance(a, StructType) or isinstance(b, StructType):
            return a is b
        if isinstance(a, PrimitiveType) and isinstance(b, PrimitiveType):
            return a.name == b.name
        if isinstance(a, ArrayType) and isinstance(b, ArrayType):
            return a.size == b.size and self.same_type(a.element, b.element)
        return False
