"""The manual's kind suffixes, as data.

EARL names an instance by its name and the kind of its part after a slash
(`manip/a`, `motorController1/ve`, `jointMove/bb`, manual §3).  This table is the
one place that lists those suffixes and what they denote.
"""

from __future__ import annotations

from enum import StrEnum


class Kind(StrEnum):
    """The suffix after the slash of an instance name."""

    ROBOT = "r"
    AGENT = "a"
    CONTROL_SUBSYSTEM = "cs"
    VIRTUAL_EFFECTOR = "ve"
    REAL_EFFECTOR = "re"
    VIRTUAL_RECEPTOR = "vr"
    REAL_RECEPTOR = "rr"
    INPUT_BUFFER = "ib"
    OUTPUT_BUFFER = "ob"
    MEMORY = "m"
    MEMORY_INPUT = "mi"
    MEMORY_OUTPUT = "mo"
    PRIMITIVE_PREDICATE = "pp"
    PARTIAL_TRANSITION_FUNCTION = "pf"
    BASIC_BEHAVIOUR = "bb"
    TRANSITION = "t"
    INTER_AGENT_LINK = "aa"

    def __str__(self) -> str:
        return self.value


#: What each suffix is called in the manual, for messages a person reads.
KIND_TITLES: dict[Kind, str] = {
    Kind.ROBOT: "Robot",
    Kind.AGENT: "Agent",
    Kind.CONTROL_SUBSYSTEM: "Control Subsystem",
    Kind.VIRTUAL_EFFECTOR: "Virtual Effector",
    Kind.REAL_EFFECTOR: "Real Effector",
    Kind.VIRTUAL_RECEPTOR: "Virtual Receptor",
    Kind.REAL_RECEPTOR: "Real Receptor",
    Kind.INPUT_BUFFER: "Input Buffer",
    Kind.OUTPUT_BUFFER: "Output Buffer",
    Kind.MEMORY: "Internal Memory",
    Kind.MEMORY_INPUT: "Internal Memory (read)",
    Kind.MEMORY_OUTPUT: "Internal Memory (written)",
    Kind.PRIMITIVE_PREDICATE: "Primitive Predicate",
    Kind.PARTIAL_TRANSITION_FUNCTION: "Partial Transition Function",
    Kind.BASIC_BEHAVIOUR: "Basic Behaviour",
    Kind.TRANSITION: "FSM Transition",
    Kind.INTER_AGENT_LINK: "inter-agent Link",
}

SUBSYSTEM_KINDS: tuple[Kind, ...] = (
    Kind.CONTROL_SUBSYSTEM,
    Kind.VIRTUAL_EFFECTOR,
    Kind.REAL_EFFECTOR,
    Kind.VIRTUAL_RECEPTOR,
    Kind.REAL_RECEPTOR,
)

#: What a Partial Transition Function may declare it reads and writes (§2.2, Figure 6).
READ_KINDS: tuple[Kind, ...] = (Kind.INPUT_BUFFER, Kind.MEMORY_INPUT)
WRITE_KINDS: tuple[Kind, ...] = (Kind.MEMORY_OUTPUT, Kind.OUTPUT_BUFFER)
