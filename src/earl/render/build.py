"""Which diagram of which element: the entry point of `earl diagram` and of the document.

    >>> from earl.render import build_diagram
    >>> svg = build_diagram(system, "fsm", "manip/a.cs").svg()

Families are drawn once with their index unless `expand` is set, in which case
every member is drawn (the system as `earl check` and the runtime see it).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cached_property

from earl.check import context_for
from earl.check.context import CheckContext
from earl.model.elements import Agent, System
from earl.model.tables import AgentType
from earl.model.validate import refuse_wrong_types
from earl.render.diagram import Diagram
from earl.render.names import agent_name, qualified_subsystem_name
from earl.render.targets import (
    TargetError,
    all_subsystems,
    find_agent,
    find_behaviour,
    find_subsystem,
    names_a_member,
    only_fsm,
)
from earl.render.views.activity import activity_view
from earl.render.views.agent import agent_view
from earl.render.views.fsm import fsm_view
from earl.render.views.system import Placement, robot_placements, system_view
from earl.render.views.types import agent_types, types_view

VIEWS = ("system", "agent", "fsm", "activity", "types")
#: The views that also exist as Mermaid text.
MERMAID_VIEWS = ("system", "fsm")

Parameters = Mapping[str, bool | int | float | str]


@dataclass
class Subject:
    """A declared system, and what the diagrams show of it: itself, or its expansion."""

    declared: System
    expand: bool = False
    parameters: Parameters | None = None

    def __post_init__(self) -> None:
        # a model built in Python with a value of the wrong type (`timeout = 0.05`) would fail inside a
        # view with Python's words, or be drawn as it is: said as check and to_earl say it, at its path
        refuse_wrong_types(self.declared)

    @cached_property
    def context(self) -> CheckContext:
        return context_for(self.declared, self.parameters)

    @property
    def shown(self) -> System:
        return self.context.system if self.expand else self.declared

    def drawn(self, view: str, target: str | None) -> System:
        """What the view of `target` is drawn from: `shown`, or the expansion when the target names one
        member of a family drawn once (`motorController[2]/ve`), which is then drawn alone, as --expand draws
        it, not as its family."""
        if not self.expand and target is not None and names_a_member(self.declared, view, target):
            return self.context.system
        return self.shown

    @cached_property
    def placements(self) -> dict[int, Placement]:
        """By the shown agent's `id`: the robots that hold it, and which members of a family each holds."""
        return robot_placements(self.shown, self.context.system, self.context.instances)

    def agent_type(self, agent: Agent) -> AgentType | None:
        """Table 1's row for an agent; the checker computes it (families count every member)."""
        return self.context.agent_type(agent)


def build_diagram(
    system: System,
    view: str,
    target: str | None = None,
    *,
    expand: bool = False,
    parameters: Parameters | None = None,
) -> Diagram:
    """The diagram `view` of `target`; raises TargetError when the target names nothing. The system and
    fsm views also have Mermaid text: `diagram.render("mermaid")` or `diagram.mermaid()`."""
    subject = Subject(system, expand, parameters)
    try:
        diagram = diagram_of(subject, view, target)
    except TargetError as error:
        raise TargetError(_in_python_words(str(error))) from None
    if view in MERMAID_VIEWS:
        from earl.render.mermaid import mermaid_of  # it imports this module

        diagram = replace(diagram, mermaid_text=lambda: mermaid_of(subject, view, target))
    return diagram


def _in_python_words(message: str) -> str:
    """A TargetError as `build_diagram`'s caller names things: its `target` argument, not `earl diagram`'s
    `--target` option."""
    return (
        message.replace("leave out --target", "give no target (None)")
        .replace("needs --target naming", "needs a target naming")
        .replace("--target", "the target")
    )


def diagram_of(subject: Subject, view: str, target: str | None) -> Diagram:
    system = subject.drawn(view, target)
    if view == "system":
        if target is not None:
            raise TargetError("the system view shows the whole system; leave out --target")
        return system_view(system, subject.agent_type, subject.placements)
    if view == "agent":
        agent = find_agent(system, target) if target is not None else _only_agent(system)
        return agent_view(agent, system)
    if view == "fsm":
        agent, subsystem = find_subsystem(system, target) if target is not None else only_fsm(system)
        if subsystem.fsm is None:
            raise TargetError(f"{qualified_subsystem_name(agent, subsystem)} has no FSM to draw")
        return fsm_view(subsystem.fsm, qualified_subsystem_name(agent, subsystem), subsystem, subject.expand)
    if view == "activity":
        if target is None:
            behaviours = [(a, s, b) for a, s in all_subsystems(system) for b in s.basic_behaviours]
            if len(behaviours) != 1:
                example = (
                    f"{qualified_subsystem_name(behaviours[0][0], behaviours[0][1])}.{behaviours[0][2].name}/bb"
                    if behaviours
                    else "manip/a.cs.jointMove/bb"
                )
                raise TargetError(f"the activity view needs --target naming a basic behaviour, e.g. {example}")
            agent, subsystem, behaviour = behaviours[0]
        else:
            agent, subsystem, behaviour = find_behaviour(system, target)
        return activity_view(behaviour, qualified_subsystem_name(agent, subsystem), subsystem)
    if view == "types":
        if target is None:
            return types_view(system.types, system.name)
        agent = find_agent(system, target)
        return types_view(agent_types(system, agent), agent_name(agent))
    raise TargetError(f"unknown view `{view}`; the views are {', '.join(VIEWS)}")


def _only_agent(system: System) -> Agent:
    if len(system.agents) == 1:
        return system.agents[0]
    names = ", ".join(agent_name(a) for a in system.agents)
    raise TargetError(f"the agent view needs --target naming one of the agents: {names}")
