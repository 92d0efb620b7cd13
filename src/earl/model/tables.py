"""The manual's rule tables, as data: one place for each, read by the checker and the renderers.

- `AGENT_TYPES` is Table 1 (§2.4): an agent's type from which optional activities it has.
- `PERMITTED_LINKS` is Figure 7 (§2.3), whose picture was lost; the table is the project's
  decision recorded in `shared/reference/figures-and-sources.md` and docs/rules.md, kept here
  as data so it can be corrected without touching code.
"""

from __future__ import annotations

from dataclasses import dataclass

from earl.model.kinds import Kind


@dataclass(frozen=True)
class AgentType:
    """A row of Table 1: which optional activities an agent of this type has."""

    name: str
    effectors: bool  # E: |ve| ≥ 1 and |re| ≥ 1
    receptors: bool  # R: |vr| ≥ 1 and |rr| ≥ 1
    transmission: bool  # T: |aa| ≥ 1
    description: str

    @property
    def useful(self) -> bool:
        return self.effectors or self.receptors or self.transmission


#: Table 1, in the manual's order.  C (control) is indispensable and so in every name.
AGENT_TYPES: tuple[AgentType, ...] = (
    AgentType("C", False, False, False, "zombie (useless)"),
    AgentType("CT", False, False, True, "purely computational agent"),
    AgentType("CE", True, False, False, "blind agent"),
    AgentType("CR", False, True, False, "monitoring agent"),
    AgentType("CET", True, False, True, "teleoperated agent"),
    AgentType("CRT", False, True, True, "remote sensor"),
    AgentType("CER", True, True, False, "autonomous agent"),
    AgentType("CERT", True, True, True, "full capabilities"),
)


def agent_type(effectors: bool, receptors: bool, transmission: bool) -> AgentType:
    """The row of Table 1 with these activities."""
    for row in AGENT_TYPES:
        if (row.effectors, row.receptors, row.transmission) == (effectors, receptors, transmission):
            return row
    raise AssertionError("Table 1 covers every combination")  # pragma: no cover


@dataclass(frozen=True)
class PermittedLink:
    """A row of the permitted-link table: a link from `source` to `destination` subsystems."""

    source: Kind
    destination: Kind
    between_agents: bool  # False: both ends in one agent; True: in two different agents
    compulsory: bool  # part of a chain §2.3 requires (cs → ve → re, rr → vr → cs)
    status: str  # "confirmed" by the manual's text, or the project's "decision"
    note: str


CS, VE, RE, VR, RR = (
    Kind.CONTROL_SUBSYSTEM,
    Kind.VIRTUAL_EFFECTOR,
    Kind.REAL_EFFECTOR,
    Kind.VIRTUAL_RECEPTOR,
    Kind.REAL_RECEPTOR,
)

#: Figure 7, "Communication constraints, where i ≠ j": every link not listed is refused.
PERMITTED_LINKS: tuple[PermittedLink, ...] = (
    PermittedLink(CS, VE, False, True, "confirmed", "commands from the control subsystem to a virtual effector"),
    PermittedLink(VE, RE, False, True, "confirmed", "commands from a virtual effector to its real effector"),
    PermittedLink(RR, VR, False, True, "confirmed", "sensor data from a real receptor to its virtual receptor"),
    PermittedLink(VR, CS, False, True, "confirmed", "aggregated sensor data to the control subsystem"),
    PermittedLink(VE, CS, False, False, "decision", "state of a virtual effector (used in Velma)"),
    PermittedLink(RE, VE, False, False, "decision", "readings of a real effector, e.g. encoders (used in Velma)"),
    PermittedLink(CS, VR, False, False, "decision", "configuring a virtual receptor (used in Velma)"),
    PermittedLink(VR, RR, False, False, "decision", "configuring a sensor"),
    PermittedLink(CS, CS, True, False, "confirmed", "a_i.cs → a_j.cs, i ≠ j: the only inter-agent link"),
)


def permitted_link(source: Kind, destination: Kind, between_agents: bool) -> PermittedLink | None:
    for row in PERMITTED_LINKS:
        if (row.source, row.destination, row.between_agents) == (source, destination, between_agents):
            return row
    return None
