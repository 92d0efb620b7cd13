"""Rules on the parts of a system (manual §2.1, §2.2 Figure 4b, §2.4 Table 1)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import replace

from earl.check.context import CheckContext
from earl.check.registry import Finding, rule
from earl.diagnostics import Severity
from earl.model.expressions import ElementReference
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.text import agent_name, instance_name, reference_text, subsystem_name


@rule("EARL-E001", Severity.ERROR, "a System contains at least one Robot", "§2.1, Figure 2")
def system_has_a_robot(context: CheckContext) -> Iterator[Finding]:
    """A System must contain at least one Robot; agents outside any robot (a coordinator) are
    allowed in addition."""
    if not context.declared.robots:
        yield Finding(
            f"system `{context.declared.name}` has no Robot",
            context.declared.location,
            "group the agents of a robot with `myRobot/r { someAgent/a … }`",
        )


@rule("EARL-E002", Severity.ERROR, "a Robot contains at least one Agent", "§2.1, Figure 2")
def robot_has_an_agent(context: CheckContext) -> Iterator[Finding]:
    """A Robot is composed of at least one Agent."""
    for robot in context.declared.robots:
        if not robot.agents:
            yield Finding(f"robot `{robot.name}/r` contains no Agent", robot.location, "list its agents: `manip/a`")


@rule("EARL-E003", Severity.ERROR, "an Agent belongs to at most one Robot", "§2.1, Figure 2")
def agent_in_one_robot(context: CheckContext) -> Iterator[Finding]:
    """An Agent is a part of at most one Robot (it may belong to none, e.g. a coordinator of several robots)."""
    owner: dict[str, str] = {}
    for robot in context.system.robots:
        for reference in robot.agents:
            agent = context.agent(reference)
            if agent is None:
                continue
            name = instance_name(agent.name, agent.index)
            if name in owner and owner[name] != robot.name:
                yield Finding(
                    f"agent `{name}/a` belongs to robot `{owner[name]}/r` and to robot `{robot.name}/r`",
                    reference.location,
                    "an agent is a part of at most one robot",
                )
            owner.setdefault(name, robot.name)


@rule("EARL-E004", Severity.ERROR, "a Robot refers only to links between its own Agents", "§2.1, Figure 2")
def robot_links_connect_its_agents(context: CheckContext) -> Iterator[Finding]:
    """Each inter-agent link a Robot refers to connects two of that Robot's own Agents."""
    links = {link.link.name_text: link for link in context.links if link.between_agents}
    for robot in context.system.robots:
        members = {id(context.agent(reference)) for reference in robot.agents}
        for reference in robot.links:
            link = links.get(reference.name)
            if link is None:
                continue
            outside = [a for a in (link.source_agent, link.destination_agent) if id(a) not in members]
            if outside:
                yield Finding(
                    f"robot `{robot.name}/r` refers to link `{reference.name}`, but `{instance_name(outside[0].name, outside[0].index)}/a` is not one of its agents",
                    reference.location,
                    "add the agent to the robot, or drop the link from it",
                )


@rule("EARL-E005", Severity.ERROR, "an Agent has exactly one Control Subsystem", "§2.1, Table 1")
def one_control_subsystem(context: CheckContext) -> Iterator[Finding]:
    """The Control Subsystem `cs` is indispensable: it coordinates the agent's subsystems and is the only
    one that talks to other agents."""
    for agent in context.declared.agents:
        if not agent.control_subsystems:
            yield Finding(f"agent `{agent_name(agent)}` has no Control Subsystem", agent.location, "add `cs { … }`")


def _pairs(context: CheckContext, virtual: Kind, real: Kind) -> Iterator[Finding]:
    for agent in context.declared.agents:
        has_virtual = bool(agent.subsystems_of(virtual))
        has_real = bool(agent.subsystems_of(real))
        if has_virtual != has_real:
            present, missing = (virtual, real) if has_virtual else (real, virtual)
            yield Finding(
                f"agent `{agent_name(agent)}` has a {KIND_TITLES[present]} but no {KIND_TITLES[missing]}",
                agent.location,
                f"Equation (1): |{virtual.value}| ≥ 1 ⇔ |{real.value}| ≥ 1; add a `/{missing.value}` or remove the `/{present.value}`",
            )


@rule("EARL-E006", Severity.ERROR, "Virtual and Real Effectors come together", "Equation (1)")
def effectors_in_pairs(context: CheckContext) -> Iterator[Finding]:
    """|ve| ≥ 1 ⇔ |re| ≥ 1: a real effector cannot exist without a virtual one supervising it, and vice versa."""
    yield from _pairs(context, Kind.VIRTUAL_EFFECTOR, Kind.REAL_EFFECTOR)


@rule("EARL-E007", Severity.ERROR, "Virtual and Real Receptors come together", "Equation (1)")
def receptors_in_pairs(context: CheckContext) -> Iterator[Finding]:
    """|vr| ≥ 1 ⇔ |rr| ≥ 1: a real receptor cannot exist without a virtual one aggregating its data, and vice versa."""
    yield from _pairs(context, Kind.VIRTUAL_RECEPTOR, Kind.REAL_RECEPTOR)


#: Figure 4b: the buffers each kind of subsystem needs at the least.
_REQUIRED_BUFFERS: dict[Kind, tuple[bool, bool]] = {
    Kind.VIRTUAL_EFFECTOR: (True, True),
    Kind.VIRTUAL_RECEPTOR: (True, True),
    Kind.REAL_EFFECTOR: (True, False),
    Kind.REAL_RECEPTOR: (False, True),
}


@rule("EARL-E008", Severity.ERROR, "subsystems have the buffers their role needs", "§2.2, Figure 4b")
def required_buffers(context: CheckContext) -> Iterator[Finding]:
    """Every Virtual Effector and Virtual Receptor has at least one Input and one Output Buffer; a Real
    Effector at least one Input Buffer to receive commands; a Real Receptor at least one Output Buffer
    to send sensory data."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            needs_input, needs_output = _REQUIRED_BUFFERS.get(subsystem.kind, (False, False))
            name = subsystem_name(agent, subsystem)
            if needs_input and not subsystem.input_buffers:
                yield Finding(
                    f"{KIND_TITLES[subsystem.kind]} `{name}` has no Input Buffer",
                    subsystem.location,
                    "Figure 4b: it receives commands or data through at least one `/ib`",
                )
            if needs_output and not subsystem.output_buffers:
                yield Finding(
                    f"{KIND_TITLES[subsystem.kind]} `{name}` has no Output Buffer",
                    subsystem.location,
                    "Figure 4b: it sends data through at least one `/ob`",
                )


@rule("EARL-W001", Severity.WARNING, "an agent of type C (zombie) is useless", "§2.4, Table 1")
def zombie_agent(context: CheckContext) -> Iterator[Finding]:
    """An agent with neither effectors, receptors nor inter-agent links has type C: it can neither act,
    perceive nor communicate (Table 1 calls it a zombie)."""
    # every member is said: the zombies of one family are merged into one finding (`worker[1, 2, 4, 5]/a`,
    # check/merging.py), where keeping only the first would leave the others unnamed
    for agent in context.system.agents:
        if context.agent_type(agent).name == "C":
            yield Finding(
                f"agent `{instance_name(agent.name, agent.index)}/a` is of type C (zombie): no effectors, receptors or inter-agent links",
                agent.location,
                "link it to another agent's control subsystem, or give it effectors or receptors",
            )


@rule("EARL-W022", Severity.WARNING, "a state's buffer group says each thing once", "§2.2, Figure 5b")
def buffer_groups(context: CheckContext) -> Iterator[Finding]:
    """A state lists an Input Buffer once: as obligatory (waited for) or as optional (taken when new),
    not both, and not twice in one list; its `timeout` bounds the wait for the obligatory buffers, so
    it needs one to bound."""
    for agent, subsystem in context.distinct_subsystems():
        if subsystem.fsm is None:
            continue
        for state in subsystem.fsm.states:
            listed_as: dict[str, str] = {}  # a buffer's text -> the list that named it first
            for role, references in (("obligatory", state.obligatory), ("optional", state.optional)):
                for reference in references:
                    text = reference_text(reference)
                    first_role = listed_as.get(text)
                    if first_role is None:
                        listed_as[text] = role
                    elif first_role == role:
                        # harmless at run time, but a slip: the other buffer meant was likely forgotten
                        yield Finding(
                            f"state `{state.name}` of {subsystem_name(agent, subsystem)} lists `{text}` twice as {role}",
                            reference.location or state.location,
                            f"name it once; was another buffer meant to be {role}?",
                        )
                    else:
                        yield Finding(
                            f"state `{state.name}` of {subsystem_name(agent, subsystem)} lists "
                            f"`{text}` as obligatory and as optional",
                            reference.location or state.location,
                            "name it once: obligatory to wait for it, optional to take it only when it is there",
                        )
            if state.timeout is not None and not state.obligatory:
                yield Finding(
                    f"state `{state.name}` of {subsystem_name(agent, subsystem)} has a `timeout` but no "
                    "obligatory buffer to wait for",
                    state.location,
                    "make a buffer obligatory, or remove the timeout",
                )


@rule("EARL-E044", Severity.ERROR, "an implementation names a module and a function", "§2.2, Figure 6")
def implementations_name_a_function(context: CheckContext) -> Iterator[Finding]:
    """`= python "module:function"` tells `earl run` which function computes a Partial Transition
    Function or a Primitive Predicate; without both parts there is nothing to import (`earl run`
    refuses it, EARL-X001). A dot does not stand for the colon: `robot.arm.move` could be the module
    `robot.arm.move` as well as the function `move` of `robot.arm`. The module is named as `import` names
    it, Python identifiers joined by dots (`robot.arm`), and the function by an identifier: `"1mod:f"`,
    `"a..b:f"` or `"a/b:f"` could never be imported. Nothing is imported to check this."""
    for _, subsystem in context.distinct_subsystems():
        named = [(f"`{f.name}/pf`", f.implementation, f.location) for f in subsystem.partial_transition_functions]
        named += [(f"`{p.name}/pp`", p.implementation, p.location) for p in subsystem.primitive_predicates]
        for what, implementation, location in named:
            if implementation is None:
                continue
            # the runtime strips spaces around each part (`" a : f "` runs)
            module, function = implementation.module.strip(), implementation.function.strip()
            written = f'the implementation of {what}, `python "{implementation.path}"`,'
            if not module or not function:
                path = implementation.path.strip()
                dotted_module, dot, dotted_function = path.rpartition(".")
                dotted = dot and ":" not in path and dotted_module and dotted_function.isidentifier()
                yield Finding(
                    f"{written} does not name a function",
                    location,
                    f'did you mean `python "{dotted_module}:{dotted_function}"`? A colon separates the module from the function'
                    if dotted
                    else 'write `python "module:function"`, e.g. `python "robot.arm:move"`',
                )
                continue
            wrong_part = next((part for part in module.split(".") if not part.isidentifier()), None)
            if wrong_part is not None:
                why = f"`{wrong_part}` is not a Python identifier" if wrong_part else "a dot has no name on one side"
                yield Finding(
                    f"{written} names the module `{module}`, which `import` cannot name: {why}",
                    location,
                    _module_hint(module, function),
                )
            if not function.isidentifier():
                yield Finding(
                    f"{written} names the function `{function}`, which is not a Python identifier",
                    location,
                    "a function is named by an identifier (letters, digits and `_`, not first a digit), the name it "
                    'is defined with: `python "robot.arm:move"`',
                )


def _module_hint(module: str, function: str) -> str:
    """How to name a module as `import` does: `a/b.py` is `a.b`."""
    if "/" in module or "\\" in module or module.endswith(".py"):
        dotted = ".".join(part for part in re.split(r"[/\\]+", module.removesuffix(".py")) if part)
        return f'a module is named with dots, not as a file: `python "{dotted}:{function}"`'
    return (
        "a module is named as `import` names it, identifiers (letters, digits and `_`, not first a digit) "
        'joined by single dots: `python "robot.arm:move"`'
    )


@rule("EARL-W047", Severity.WARNING, "a list says each thing once", "§2.1, §2.2")
def lists_say_each_thing_once(context: CheckContext) -> Iterator[Finding]:
    """What a partial transition function or a Python predicate reads and writes, the functions of one stage,
    the agents and links of a robot: each is named once. A repeat changes nothing when the system runs (a
    set is meant), so it is a slip, often for another name that was meant and is now missing. The manual's
    `pf` and `pfo` sets are disjoint (§3.2): a function is in one stage of a transition function, and in one
    stage set; named in two, it runs twice an iteration, once on what the other stage made of the memory."""
    # the lists as written: expanded, `x[K]/ib, x[1]/ib` are one buffer twice in member 1, which no edit of the
    # declaration could name once
    declared = [(agent, subsystem) for agent in context.declared.agents for subsystem in agent.subsystems]
    for agent, subsystem in declared:
        owner = subsystem_name(agent, subsystem)
        lists: list[tuple[str, list[ElementReference]]] = []
        for function in subsystem.partial_transition_functions:
            lists.append((f"`{function.name}/pf` of {owner} reads", function.reads))
            lists.append((f"`{function.name}/pf` of {owner} writes", function.writes))
        for predicate in subsystem.primitive_predicates:
            lists.append((f"`{predicate.name}/pp` of {owner} reads", predicate.reads))
        for behaviour in subsystem.basic_behaviours:
            for number, stage in enumerate(behaviour.transition_function.stages, start=1):
                lists.append((f"stage {number} of `{behaviour.name}/bb` of {owner} runs", stage))
        for stage_set in subsystem.stage_sets:
            lists.append((f"the stage set `{stage_set.name}` of {owner} holds", stage_set.functions))
        yield from _repeats(lists)
        for behaviour in subsystem.basic_behaviours:
            stages = [(f"stage {n}", stage) for n, stage in enumerate(behaviour.transition_function.stages, start=1)]
            twice = ", and it would run twice an iteration"
            yield from _in_two_stages(stages, f"of `{behaviour.name}/bb` of {owner}", "stages", twice)
        sets = [(f"stage set `{stage_set.name}`", stage_set.functions) for stage_set in subsystem.stage_sets]
        yield from _in_two_stages(sets, f"of {owner}", "stage sets", "")
    for robot in context.declared.robots:
        yield from _repeats(
            [(f"robot `{robot.name}/r` holds", robot.agents), (f"robot `{robot.name}/r` refers to", robot.links)]
        )


def _repeats(lists: list[tuple[str, list[ElementReference]]]) -> Iterator[Finding]:
    for what, references in lists:
        named: set[str] = set()
        for reference in references:
            text = _written(reference)
            if text in named:
                yield Finding(
                    f"{what} `{text}` twice",
                    reference.location,
                    "name it once; was another name meant?",
                )
            named.add(text)


def _in_two_stages(
    stages: list[tuple[str, list[ElementReference]]], owner: str, plural: str, consequence: str
) -> Iterator[Finding]:
    """A function named in two stages (or stage sets), said where it is named again: once per function."""
    first: dict[str, str] = {}
    for stage, functions in stages:
        for reference in functions:
            text = _written(reference)
            if first.setdefault(text, stage) != stage:
                yield Finding(
                    f"`{text}` is in {first[text]} and again in {stage} {owner}: the manual's `pf` and `pfo` "
                    f"sets are disjoint (§3.2){consequence}",
                    reference.location,
                    f"keep it in one of the {plural}; was another function meant?",
                )
                first[text] = stage  # a third stage is said again, not the second one again


def _written(reference: ElementReference) -> str:
    """`c/ib`, `x[K]/mi`, `f/pf`, `b,a`: a reference as written, its kind given as text too (a model built in
    Python may say `ElementReference("c", "ib")`, which the rest of earl takes for Kind.INPUT_BUFFER)."""
    try:
        kind = Kind(reference.kind)
    except ValueError:
        return repr(reference)
    if kind is Kind.INTER_AGENT_LINK:
        return reference.name
    return reference_text(replace(reference, kind=kind)) if kind is not reference.kind else reference_text(reference)
