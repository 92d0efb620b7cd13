"""Rules on links (manual §2.3, Figure 7; the permitted-link table is `earl.model.tables`)."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Iterator
from operator import attrgetter

from earl.check.context import CheckContext, ResolvedLink, written_output_buffers
from earl.check.registry import Finding, rule
from earl.diagnostics import Severity
from earl.model.elements import Agent, InputBuffer, Link, LinkNamePart, State, Subsystem, default_link_name
from earl.model.expressions import ElementReference, Literal
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.tables import PERMITTED_LINKS, permitted_link
from earl.model.text import expression_text, instance_name, subsystem_name
from earl.model.types import type_text


@rule("EARL-E010", Severity.ERROR, "a link connects buffers of the same data type", "§2.2, §2.3")
def link_types_match(context: CheckContext) -> Iterator[Finding]:
    """A link carries the message of its Output Buffer into its Input Buffer, so both hold the same dataType."""
    for link in context.links:
        if not context.same_type(link.source_buffer.data_type, link.destination_buffer.data_type):
            yield Finding(
                f"link `{link.link.name_text}` sends `{type_text(link.source_buffer.data_type)}` into an Input Buffer of type `{type_text(link.destination_buffer.data_type)}`",
                link.link.location,
                "give both buffers the same data type",
            )


@rule("EARL-E011", Severity.ERROR, "an Input Buffer is fed by at most one link", "§2.3")
def one_link_per_input(context: CheckContext) -> Iterator[Finding]:
    """Each Input Buffer receives from at most one Output Buffer; two links into one buffer would overwrite
    each other's messages unpredictably."""
    for links in context.links_into.values():
        if len(links) > 1:
            first, second = links[0], links[1]
            buffer = instance_name(first.destination_buffer.name, first.destination_buffer.index)
            yield Finding(
                f"`{subsystem_name(first.destination_agent, first.destination_subsystem)}.{buffer}/ib` is fed by link `{first.link.name_text}` and by link `{second.link.name_text}`",
                second.link.location,
                "give the destination one Input Buffer per incoming link",
            )


@rule("EARL-E012", Severity.ERROR, "only permitted pairs of subsystems are linked", "§2.3, Figure 7")
def permitted_pairs(context: CheckContext) -> Iterator[Finding]:
    """Links follow the permitted-link table (Figure 7): the compulsory chains cs → ve → re and rr → vr → cs,
    the optional ve → cs, re → ve, cs → vr, vr → rr inside one agent, and cs → cs between two agents (an
    inter-agent link with another end is EARL-E013's, which names that end)."""
    for link in context.links:
        source, destination = link.source_subsystem.kind, link.destination_subsystem.kind
        if link.between_agents and (
            link.source_agent is link.destination_agent or {source, destination} != {Kind.CONTROL_SUBSYSTEM}
        ):
            # EARL-E013 reports it, naming the end that is not a Control Subsystem: said once is enough
            continue
        if permitted_link(source, destination, link.between_agents) is None:
            allowed = ", ".join(
                f"{row.source.value} → {row.destination.value}"
                for row in PERMITTED_LINKS
                if row.between_agents == link.between_agents
            )
            where = "between agents" if link.between_agents else "inside an agent"
            yield Finding(
                f"a link from a {KIND_TITLES[source]} to a {KIND_TITLES[destination]} is not permitted {where} (link `{link.link.name_text}`)",
                link.link.location,
                f"permitted {where}: {allowed}",
            )


@rule("EARL-E013", Severity.ERROR, "agents communicate only through their Control Subsystems", "§2.3, Figure 7")
def inter_agent_links_between_control_subsystems(context: CheckContext) -> Iterator[Finding]:
    """Inter-agent communication happens only between the Control Subsystems of two different agents."""
    for link in context.links:
        if not link.between_agents:
            continue
        if link.source_agent is link.destination_agent:
            yield Finding(
                f"link `{link.link.name_text}` starts and ends in `{instance_name(link.source_agent.name, link.source_agent.index)}/a`",
                link.link.location,
                "declare links between the subsystems of one agent inside that agent",
            )
            continue
        for subsystem, agent, end in (
            (link.source_subsystem, link.source_agent, "starts"),
            (link.destination_subsystem, link.destination_agent, "ends"),
        ):
            if subsystem.kind is not Kind.CONTROL_SUBSYSTEM:
                yield Finding(
                    f"inter-agent link `{link.link.name_text}` {end} at `{subsystem_name(agent, subsystem)}`, "
                    "not at a Control Subsystem",
                    link.link.location,
                    "agents exchange messages only through their `cs`",
                )


def _chain(context: CheckContext, middle: Kind, real: Kind, towards_real: bool) -> Iterator[Finding]:
    """Real subsystems of kind `real` not on cs → middle → real (or real → middle → cs)."""
    inside: dict[int, list[ResolvedLink]] = {}
    for link in context.links:
        if not link.between_agents:
            inside.setdefault(id(link.source_agent), []).append(link)
    chain = f"cs → {middle.value} → {real.value}" if towards_real else f"{real.value} → {middle.value} → cs"
    # per agent, once: an agent with a family of N effectors has N of them and some 2N links
    on_a_chain: dict[int, set[int]] = {}
    for agent, subsystem in context.subsystems():
        if subsystem.kind is not real:
            continue
        complete = on_a_chain.get(id(agent))
        if complete is None:
            complete = on_a_chain[id(agent)] = _ends_of_chains(inside.get(id(agent), []), middle, towards_real)
        if id(subsystem) not in complete:
            yield Finding(
                f"`{subsystem_name(agent, subsystem)}` is not on a chain {chain}",
                subsystem.location,
                f"§2.3: every {KIND_TITLES[real]} needs the chain {chain}; link the missing step",
            )


def _ends_of_chains(links: list[ResolvedLink], middle: Kind, towards_real: bool) -> set[int]:
    """The subsystems (by id) that a cs → middle → x chain reaches, or that start an x → middle → cs chain.

    Each link has an end towards the control subsystem (`near`) and one away from it (`far`): the
    source and the destination for commands, the other way round for reports."""
    ends = ("source_subsystem", "destination_subsystem")
    near, far = map(attrgetter, ends if towards_real else reversed(ends))
    next_to_cs = {id(far(link)) for link in links if near(link).kind is Kind.CONTROL_SUBSYSTEM}
    return {id(far(link)) for link in links if near(link).kind is middle and id(near(link)) in next_to_cs}


@rule("EARL-E014", Severity.ERROR, "every Real Effector is commanded through cs → ve → re", "§2.3, Figure 7")
def effector_chain(context: CheckContext) -> Iterator[Finding]:
    """The commands produced by the Control Subsystem, transformed by a Virtual Effector, must reach every
    Real Effector."""
    # every member is said: the family's members that share the problem are merged into one finding
    # (`motor[1..6]/re`, check/merging.py), where keeping only the first would name `motor[1]` alone
    yield from _chain(context, Kind.VIRTUAL_EFFECTOR, Kind.REAL_EFFECTOR, towards_real=True)


@rule("EARL-E015", Severity.ERROR, "every Real Receptor reports through rr → vr → cs", "§2.3, Figure 7")
def receptor_chain(context: CheckContext) -> Iterator[Finding]:
    """The data of every Real Receptor passes through a Virtual Receptor to the Control Subsystem."""
    yield from _chain(context, Kind.VIRTUAL_RECEPTOR, Kind.REAL_RECEPTOR, towards_real=False)


@rule("EARL-W010", Severity.WARNING, "link names join source and destination", "§2.1, §2.5")
def link_names(context: CheckContext) -> Iterator[Finding]:
    """Good practice (§2.5): a link is named by its source, a comma, and its destination — agent names for
    inter-agent links (`task,manip`), subsystem names inside an agent. The name suggested is the one a link
    declared without a name gets, indices as its ends write them (`cs,mc[2]`). Link names are unique (EARL-R002), so
    of two links between the same ends only one can have that name: the other is named by the pair with what
    tells it apart after the destination's name (`v,csPose`, `v,cs2`)."""
    between = _links_between(context.links)
    as_written = _declared_links(context)
    reported: set[int] = set()
    for link in context.links:
        parts = [part.name for part in link.link.name]
        expected = _ends_names(link)
        if id(link.link.location) in reported:
            continue
        alongside = [other for other in between[_ends(link)] if other.link is not link.link]
        if parts == expected or (alongside and _tells_apart(parts, expected)):
            continue
        reported.add(id(link.link.location))
        taken = any([part.name for part in other.link.name] == expected for other in alongside)
        # the name a link declared without one gets (`cs,mc[2]`, `s[K],v[1]`): what `earl fmt` would write
        written = as_written.get(id(link.link.location), link.link) if link.link.location is not None else link.link
        default = list(default_link_name(written.source, written.destination))
        pair = _name_parts_text(default)
        if taken:
            # the pair's name is another link's: the destination buffer, the message's content, tells them apart
            destination = default[1]
            apart = destination.name + _capitalised(link.destination_buffer.name)
            default[1] = LinkNamePart(apart, destination.index)
        suggested = _name_parts_text(default)
        name = link.link.name_text
        family = link.link.family
        if family is not None and len(expected) == len(link.link.name):
            # a member of a link family: said as the family is written, its index kept on the indexed side
            name = _family_link_name(parts, link.link.name, family.index)
        elif family is not None:
            name = f"{parts[0]}[{family.index}]" if len(parts) == 1 else name
        if not taken:
            yield Finding(f"link `{name}` is not named after its ends; §2.5 suggests `{suggested}`", link.link.location)
            continue
        yield Finding(
            f"link `{name}` is not named after its ends; §2.5 suggests `{pair}`, but another "
            f"link between them has that name: name it `{suggested}`",
            link.link.location,
            "of two links between the same ends, name one `source,destination` and the other the same with what "
            "tells it apart after the destination's name (link names are unique, EARL-R002)",
        )


def _declared_links(context: CheckContext) -> dict[int, Link]:
    """Every link as the spec writes it (`s[K]/rr.o -> v[1]/vr.i`, its family index unexpanded), by the
    identity of its location, which the expanded members share."""
    links = list(context.declared.links)
    for agent in context.declared.agents:
        links += agent.links
    return {id(link.location): link for link in links if link.location is not None}


def _name_parts_text(parts: Iterable[LinkNamePart]) -> str:
    """`cs,mc[2]`: a link name's parts, each with the index it is written with."""
    return ",".join(
        part.name if part.index is None else f"{part.name}[{expression_text(part.index)}]" for part in parts
    )


def _ends_names(link: ResolvedLink) -> list[str]:
    """The names §2.5 builds a link's name from: its agents' between agents, its subsystems' inside one."""
    if link.between_agents:
        return [link.source_agent.name, link.destination_agent.name]
    return [link.source_subsystem.name, link.destination_subsystem.name]


def _ends(link: ResolvedLink) -> tuple[int, int]:
    """What a link joins, by identity: two agents, or two subsystems of one agent."""
    if link.between_agents:
        return id(link.source_agent), id(link.destination_agent)
    return id(link.source_subsystem), id(link.destination_subsystem)


def _links_between(links: list[ResolvedLink]) -> dict[tuple[int, int], list[ResolvedLink]]:
    between: dict[tuple[int, int], list[ResolvedLink]] = defaultdict(list)
    for link in links:
        between[_ends(link)].append(link)
    return between


def _tells_apart(parts: list[str], expected: list[str]) -> bool:
    """`v,cs2` or `v,csPose` for a link from `v` to `cs`: the pair's names with something after the destination's."""
    return len(parts) == 2 and parts[0] == expected[0] and parts[1].startswith(expected[1]) and parts[1] != expected[1]


def _capitalised(name: str) -> str:
    return name[:1].upper() + name[1:]


def _family_link_name(names: list[str], parts: Iterable[LinkNamePart], index: str) -> str:
    """`eye[K],detector`: the names of a link family's ends, the index on the side that has one."""
    return ",".join(f"{n}[{index}]" if part.index is not None else n for n, part in zip(names, parts, strict=True))


@rule("EARL-E016", Severity.ERROR, "a subsystem never waits for ever", "§2.2, Figure 5b")
def waits_for_nothing_for_ever(context: CheckContext) -> Iterator[Finding]:
    """A state's obligatory Input Buffers are received by waiting until each has a new message, at most
    for the state's `timeout`. An obligatory buffer that no link feeds never gets one: in a state without
    a timeout the subsystem would wait there for ever, silently. So does one whose links all come from
    output buffers that no function of any behaviour writes (EARL-W040): those are never sent."""
    for members in context.distinct_subsystem_groups():
        _, subsystem = members[0]
        if subsystem.fsm is None:
            continue
        for state in subsystem.fsm.states:
            if state.timeout is not None:
                continue
            told: set[str] = set()  # a buffer listed twice waits for ever once (the repeat is EARL-W022)
            for reference in state.obligatory:
                buffer = context.input_buffer(subsystem, reference)
                if buffer is None:
                    continue
                name = instance_name(buffer.name, buffer.index)
                if name in told:
                    continue
                for agent, member in members:  # each member is linked on its own: each is said
                    why = _never_receives(context, member, reference)
                    if why is None:
                        continue
                    told.add(name)
                    said, hint = why
                    yield Finding(
                        f"state `{state.name}` of {subsystem_name(agent, member)} waits for ever: "
                        f"`{name}/ib` is obligatory, {said}, and the state has no `timeout`",
                        reference.location or state.location,
                        f"{hint}, give the state's buffer group a `timeout`, or make it optional",
                    )


def _never_receives(context: CheckContext, subsystem: Subsystem, reference: ElementReference) -> tuple[str, str] | None:
    """Why the input buffer `reference` of `subsystem` never takes a message, and what would feed it:
    no link feeds it, or every link that does comes from an output buffer nothing writes; None when
    some link may bring one."""
    buffer = context.input_buffer(subsystem, reference)
    if buffer is None:
        return None
    links = context.links_into.get(id(buffer), [])
    if not links:
        return "no link feeds it", "link an Output Buffer to it"
    unwritten = [link for link in links if link.source_buffer.name not in written_output_buffers(link.source_subsystem)]
    if len(unwritten) < len(links):
        return None
    sources = list(
        dict.fromkeys(
            f"`{subsystem_name(link.source_agent, link.source_subsystem)}."
            f"{instance_name(link.source_buffer.name, link.source_buffer.index)}/ob`"
            for link in unwritten
        )
    )
    first = unwritten[0]
    sender = subsystem_name(first.source_agent, first.source_subsystem)
    said = (
        f"fed only by {_listed(sources)}, which no function of any behaviour writes, so "
        f"{'it is' if len(sources) == 1 else 'they are'} never sent"
    )
    return said, f"add `{first.source_buffer.name}/ob` to the writes of a function of {sender}"


def _index(buffer: InputBuffer) -> tuple[Literal, ...]:
    """The index of an expanded family member (`x[2]/ib`) as a reference writes it."""
    return () if buffer.index is None else (Literal(buffer.index),)


def _listed(names: list[str]) -> str:
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


@rule("EARL-E017", Severity.ERROR, "something paces every state of a subsystem", "§2.2, Figure 5")
def every_state_is_paced(context: CheckContext) -> Iterator[Finding]:
    """A subsystem iterates every `period`; without one, only its obligatory Input Buffers pace it (each
    iteration waits for their messages). A state of a subsystem without a period that waits for no
    obligatory buffer would iterate again at once, for ever, in zero time: `earl run` refuses it
    (EARL-X012), and this rule says so before a run."""
    for agent, subsystem in context.distinct_subsystems():
        if subsystem.fsm is None or subsystem.period is not None:
            continue
        # only a buffer some link feeds paces: one no link feeds would wait for ever (EARL-E016)
        fed = [
            instance_name(buffer.name, buffer.index)
            for buffer in subsystem.input_buffers
            if _never_receives(context, subsystem, ElementReference(buffer.name, Kind.INPUT_BUFFER, _index(buffer)))
            is None
        ]
        for state in subsystem.fsm.states:
            if not state.obligatory:
                hint = "give the subsystem a `period` (`period 10 ms`)"
                if fed:
                    hint += (
                        ", or list the buffers the state waits for: "
                        f"`state {state.name}: {state.behaviour}/bb {{ obligatory {fed[0]}/ib }}`"
                    )
                else:
                    hint += ": no link feeds an input buffer it could wait for"
                yield Finding(
                    f"{subsystem_name(agent, subsystem)} has no `period` and state `{state.name}` waits for no "
                    "obligatory buffer, so nothing paces it",
                    state.location,
                    hint,
                )


#: a state of an expanded subsystem: (id of the subsystem, the state's name)
_StateNode = tuple[int, str]


@rule(
    "EARL-W018",
    Severity.WARNING,
    "subsystems without a period do not wake each other at once, for ever",
    "§2.2, Figure 5b",
)
def zero_time_cycles(context: CheckContext) -> Iterator[Finding]:
    """A subsystem without a `period` is paced by its obligatory Input Buffers alone (EARL-E017): each
    iteration waits for their messages. When such subsystems wait for each other in a cycle of links,
    each state's obligatory buffers fed only by states of the cycle that send to them, every message
    starts the next iteration in the same instant, and run time never passes: `earl run` ends such a
    run with a `zero-time-loop` fault once a subsystem has iterated 10,000 times in one instant
    (docs/semantics.md). A state's `timeout` does not break the cycle, since a message that comes ends
    the wait at once; a `period` on one of the subsystems does. What the check cannot know: whether a
    function declared to write an Output Buffer writes it in every iteration (a buffer not written is not
    sent), nor whether the subsystems are ever in the states of the cycle at the same time; it warns of
    every cycle of states that could loop so, once per cycle, at the state the cycle is told from."""
    periodless = [
        (agent, subsystem)
        for agent, subsystem in context.subsystems()
        if subsystem.period is None and subsystem.fsm is not None
    ]
    if not periodless:
        return
    states: dict[_StateNode, tuple[Agent, Subsystem, State]] = {}
    for agent, subsystem in periodless:
        assert subsystem.fsm is not None
        for state in subsystem.fsm.states:
            states[(id(subsystem), state.name)] = (agent, subsystem, state)
    # per state, per obligatory buffer: the states of period-less subsystems that may send into it
    senders: dict[_StateNode, list[set[_StateNode]]] = {}
    for node, (_, subsystem, state) in states.items():
        if not state.obligatory:
            continue  # EARL-E017's
        buffers = []
        for reference in state.obligatory:
            buffer = context.input_buffer(subsystem, reference)
            if buffer is None:
                continue
            buffers.append(
                {
                    sender
                    for link in context.links_into.get(id(buffer), ())
                    if link.source_subsystem.period is None and link.source_subsystem.fsm is not None
                    for sender in _states_sending(link)
                }
            )
        if buffers:
            senders[node] = buffers
    # Only states whose every obligatory buffer some state of the set sends to can be woken at once by
    # the set alone: drop the others until none is left to drop (one fed by a subsystem with a period,
    # or by no link, waits for it).
    alive = set(senders)
    changed = True
    while changed:
        changed = False
        for node in list(alive):
            if any(not (fed & alive) for fed in senders[node]):
                alive.discard(node)
                changed = True
    wakes: dict[_StateNode, list[_StateNode]] = defaultdict(list)
    for node in alive:
        for sender in set().union(*senders[node]) & alive:
            wakes[sender].append(node)
    order = {node: position for position, node in enumerate(states)}
    for component in _cycles(sorted(alive, key=order.__getitem__), wakes):
        cycle = _cycle_through(component[0], set(component), wakes, order)
        names = [f"{subsystem_name(states[node][0], states[node][1])} in state `{node[1]}`" for node in cycle]
        first = states[cycle[0]][2]
        yield Finding(
            "subsystems without a `period` wait for each other in a cycle, each message starting the next "
            f"iteration at once: {' → '.join(names + names[:1])}; run time would never pass (`earl run` "
            "ends such a run, a `zero-time-loop` fault)",
            first.location,
            "give one of them a `period` (`period 10 ms`)",
        )


def _states_sending(link: ResolvedLink) -> Iterator[_StateNode]:
    """The states of the link's source whose behaviour declares a function writing the link's Output Buffer."""
    subsystem = link.source_subsystem
    assert subsystem.fsm is not None
    name = link.source_buffer.name
    writers = {
        function.name
        for function in subsystem.partial_transition_functions
        if any(write.kind is Kind.OUTPUT_BUFFER and write.name == name for write in function.writes)
    }
    for state in subsystem.fsm.states:
        behaviour = subsystem.basic_behaviour(state.behaviour)
        if behaviour is not None and any(
            function.name in writers for function in behaviour.transition_function.partial_transition_functions
        ):
            yield (id(subsystem), state.name)


def _cycles(nodes: list[_StateNode], edges: dict[_StateNode, list[_StateNode]]) -> list[list[_StateNode]]:
    """The strongly connected components of `nodes` that hold a cycle (Tarjan's, without recursion), each in
    the order of `nodes`, in the order of their first node."""
    position = {node: index for index, node in enumerate(nodes)}
    index: dict[_StateNode, int] = {}
    low: dict[_StateNode, int] = {}
    stack: list[_StateNode] = []
    on_stack: set[_StateNode] = set()
    found: list[list[_StateNode]] = []
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter(edges.get(root, ())))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            for successor in successors:
                if successor not in index:
                    index[successor] = low[successor] = len(index)
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(edges.get(successor, ()))))
                    break
                if successor in on_stack:
                    low[node] = min(low[node], index[successor])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in edges.get(node, ()):
                        found.append(sorted(component, key=position.__getitem__))
    return sorted(found, key=lambda component: position[component[0]])


def _cycle_through(
    start: _StateNode,
    component: set[_StateNode],
    edges: dict[_StateNode, list[_StateNode]],
    order: dict[_StateNode, int],
) -> list[_StateNode]:
    """A shortest cycle from `start` back to it within `component` (breadth first, successors in order)."""
    came_from: dict[_StateNode, _StateNode] = {}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for successor in sorted(edges.get(node, ()), key=order.__getitem__):
                if successor not in component:
                    continue
                if successor == start:
                    path = [node]
                    while path[-1] != start:
                        path.append(came_from[path[-1]])
                    return path[::-1]
                if successor not in came_from:
                    came_from[successor] = node
                    following.append(successor)
        frontier = following
    return [start]


@rule("EARL-W011", Severity.WARNING, "every Input Buffer is fed by a link", "§2.2, §2.3")
def unfed_input_buffers(context: CheckContext) -> Iterator[Finding]:
    """An Input Buffer receives messages only over a link (§2.3); one that no link feeds keeps its type's
    zero value for ever, and `newData()` of it is never true."""
    for members in context.distinct_subsystem_groups():
        _, subsystem = members[0]
        for buffer in subsystem.input_buffers:
            if context.links_into.get(id(buffer)):
                continue
            for agent, member in members:  # each member is linked on its own: each is said
                yield Finding(
                    f"`{subsystem_name(agent, member)}.{instance_name(buffer.name, buffer.index)}/ib` is fed by "
                    "no link: it never receives a message",
                    buffer.location,
                    "link an Output Buffer to it, or remove it",
                )
