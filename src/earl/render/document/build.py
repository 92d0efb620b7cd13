"""The document's content: what the manual's §3 shows, computed from a spec.

A system overview with the Table 1 type of every agent and the inter-agent links
(Figures 8 and 9); per agent its structure and data types (Figures 10 and 11);
per subsystem its buffers, Table 3 (memory), Table 4 (primitive predicates),
Table 5 (transition and terminal conditions), the FSM (Figure 12), its partial
transition functions, Table 6 (compositions) and one activity diagram per basic
behaviour (Figure 15); the checker's findings, each linked to the section of the
element it is about.  Names in tables and expressions link to where they are defined.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from earl import __version__
from earl.diagnostics import Diagnostic, Severity
from earl.model.elements import Agent, Queue, Subsystem, System
from earl.model.expressions import ConstantError, ElementReference, evaluate_constant
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.location import SourceLocation
from earl.model.tables import AGENT_TYPES
from earl.model.text import expression_text, literal_text, reference_text
from earl.model.types import type_text
from earl.render.build import Subject
from earl.render.diagram import Diagram
from earl.render.document.parameters import Environment, ParameterRow, parameter_rows
from earl.render.document.remarks import Remark, Remarks
from earl.render.document.tree import (
    BulletList,
    Cell,
    Code,
    Content,
    Document,
    Figure,
    Inline,
    Link,
    Monospace,
    Paragraph,
    Section,
    Strong,
    Table,
    Text,
    cell,
    code,
    text,
    with_code,
)
from earl.render.names import (
    Indexed,
    agent_name,
    indexed_name,
    link_label,
    qualified_subsystem_name,
    slug,
    subsystem_name,
)
from earl.render.tables import (
    Column,
    CompositionTable,
    assumption_table,
    composition_table,
    condition_table,
    memory_table,
    predicate_table,
    transition_table,
)
from earl.render.views.activity import activity_view
from earl.render.views.agent import agent_links, agent_view
from earl.render.views.fsm import fsm_view
from earl.render.views.system import (
    NO_ROBOT,
    InterAgentLink,
    end_name,
    inter_agent_links,
    member_list,
    robot_text,
    system_view,
)
from earl.render.views.types import agent_types, closure, types_view

_REFERENCE = re.compile(r"\b([A-Za-z_]\w*)((?:\[[^\]]*\])?)/(pp|ib|ob|mi|mo|m|bb|pf)\b")
_WORD = re.compile(r"[A-Za-z_]\w*")
#: a bare name that may be a parameter: not a field (`.x`), a call (`any(`), or a name with its kind (`x/pp`)
_PARAMETER = re.compile(r"(?<!\w)(?:(?<=\.\.)|(?<!\.))[A-Za-z_]\w*(?![\w(/\[])")  # `1..N`, not `.x`
_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')
_SEVERITY_CSS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.NOTE: "note"}


@dataclass
class Scope:
    """The anchors of one subsystem's elements, so its tables and expressions can link to them.

    An element answers to its indexed name (`windingCurrent[K]`, `windingCurrent[3]`)
    and, when that is not found, to its bare name (a reference `windingCurrent[*]/mo`).
    """

    prefix: str  # the subsystem's qualified name
    names: dict[tuple[str, str], str] = field(default_factory=dict)  # (name, kind) → anchor
    #: the parameters in scope (the subsystem's, its agent's, the system's) → the anchor of their rows
    parameters: dict[str, str] = field(default_factory=dict)

    @staticmethod
    def _kind(kind: str) -> str:
        return "m" if kind in ("mi", "mo") else kind

    def anchor(self, indexed: str, kind: str) -> str:
        return slug(self._kind(kind), self.prefix, indexed)

    def define(self, name: str, indexed: str, kind: str) -> str:
        anchor = self.anchor(indexed, kind)
        self.names[(indexed, self._kind(kind))] = anchor
        self.names.setdefault((name, self._kind(kind)), anchor)
        return anchor

    def find(self, name: str, index: str, kind: str) -> str | None:
        kind = self._kind(kind)
        return self.names.get((name + index, kind)) or self.names.get((name, kind))


@dataclass
class DocumentBuilder:
    subject: Subject
    diagnostics: Sequence[Diagnostic]
    diagrams: list[Diagram] = field(default_factory=list)
    type_names: set[str] = field(default_factory=set)
    #: Where each diagnostic belongs: the anchor of the innermost element whose source holds it.
    owners: list[tuple[SourceLocation, str, str]] = field(default_factory=list)
    #: The rows of a subsystem's tables a finding can link to (a buffer, a predicate, a transition …),
    #: inside the subsystem's section, which lists its findings.
    rows: list[tuple[SourceLocation, str, str]] = field(default_factory=list)
    #: The values of the system's parameters, in which agents' and subsystems' parameters are computed.
    environment: Environment = field(default_factory=dict)
    remarks: Remarks = field(init=False)

    def __post_init__(self) -> None:
        self.remarks = Remarks(self.subject.declared)

    def commented(self, table: Table, elements: Sequence[object]) -> Table:
        """`table` with a last column of the comments written at `elements` (one a row, in order), when any
        has one: units and explanations ("in radians") the SysML export carries, shown with their rows; a
        comment heading a group of them (`// Table 3: manip/a.cs.m`) is a caption row above the group."""
        return _with_remarks(table, self.remarks.of_rows(elements))

    # ------------------------------------------------------------------ inline helpers
    def figure(self, diagram: Diagram, caption: str) -> Figure:
        self.diagrams.append(diagram)
        return Figure(
            f"diagrams/{diagram.slug}.svg",
            (Text(caption + ": "), Code(diagram.header)),
            diagram.header,
            slug("fig", diagram.slug),
        )

    def type_content(self, written: str) -> Content:
        """`JointPosition[]` with `JointPosition` linked to its definition."""
        parts: list[Inline] = []
        position = 0
        for match in _WORD.finditer(written):
            if match.group() in self.type_names:
                if match.start() > position:
                    parts.append(Code(written[position : match.start()]))
                parts.append(Link(slug("type", match.group()), code(match.group())))
                position = match.end()
        if position < len(written):
            parts.append(Code(written[position:]))
        return tuple(parts)

    @staticmethod
    def expression_content(expression: str, scope: Scope) -> Content:
        """An expression in one monospace run, each `name/kind` linked to the row that defines it."""
        parts: list[Inline] = []
        position = 0
        found = [
            (match.start(), match.end(), anchor)
            for match in _REFERENCE.finditer(expression)
            if (anchor := scope.find(match.group(1), match.group(2), match.group(3))) is not None
        ]
        # a parameter (`STANDSTILL`, `N`) links to its row of a parameters table, outside string literals
        strings = [(m.start(), m.end()) for m in _STRING.finditer(expression)]
        for match in _PARAMETER.finditer(expression):
            anchor = scope.parameters.get(match.group())
            taken = any(start < match.end() and match.start() < end for start, end, _ in found)
            quoted = any(start <= match.start() < end for start, end in strings)
            if anchor is not None and not taken and not quoted:
                found.append((match.start(), match.end(), anchor))
        for start, end, anchor in sorted(found):
            if start > position:
                parts.append(Text(expression[position:start]))
            parts.append(Link(anchor, text(expression[start:end])))
            position = end
        if position < len(expression):
            parts.append(Text(expression[position:]))
        return (Monospace(tuple(parts)),)

    # ------------------------------------------------------------------ the document
    def build(self) -> Document:
        system = self.subject.shown
        self.type_names = {definition.name for definition in system.types}
        self._owners(system)
        sections = [self.overview(system)]
        sections += [self.agent_section(system, agent) for agent in system.agents]
        sections.append(self.types_section(system))
        sections.append(self.check_section())
        source = system.source_file or "a specification"
        mode = "every family member drawn" if self.subject.expand else "indexed families drawn once"
        if self.subject.parameters:
            given = " ".join(f"--param {name}={value}" for name, value in self.subject.parameters.items())
            mode += f"; {given}"
        subtitle = f"Generated by earl {__version__} from {source} ({mode}). Section and table numbers refer to the EARL reference manual 1.0."
        notice, css = self.check_notice()
        return Document(f"{system.name}: an EARL specification", subtitle, sections, notice, css)

    def check_notice(self) -> tuple[Content, str]:
        """`earl check found 2 errors and 3 warnings …` under the title, linked to the check results: a
        document of a broken spec said so only at its end, mixed with notes."""
        errors = sum(1 for d in self.diagnostics if d.severity is Severity.ERROR)
        warnings = sum(1 for d in self.diagnostics if d.severity is Severity.WARNING)
        if not errors and not warnings:
            return (), ""
        found = _and([_count(n, word) for n, word in ((errors, "error"), (warnings, "warning")) if n])
        verdict = " The specification breaks rules of the EARL manual." if errors else ""
        return (
            (
                Text(f"earl check found {found}.{verdict} "),
                Link("check", text("See the check results")),
                Text("."),
            ),
            "error" if errors else "warning",
        )

    def _owners(self, system: System) -> None:
        """The elements a finding can link to, by the lines they span: the smallest one that holds the
        finding's line is its owner (an agent's subsystem before the agent)."""
        for definition in system.types:  # each has a row of the data types table
            if definition.location is not None:
                self.owners.append((definition.location, slug("type", definition.name), definition.name))
        for link in inter_agent_links(system):  # each has a row of the links table
            if link.link.location is not None:
                self.owners.append((link.link.location, slug("aa", link.link.name_text), link.link.name_text))
        for robot in system.robots:  # robots are named in the overview of the system
            if robot.location is not None:
                self.owners.append((robot.location, "system", f"{robot.name}/r"))
        for agent in system.agents:
            if agent.location is not None:
                self.owners.append((agent.location, slug("agent", agent_name(agent)), agent_name(agent)))
            for subsystem in agent.subsystems:
                if subsystem.location is not None:
                    name = qualified_subsystem_name(agent, subsystem)
                    self.owners.append((subsystem.location, slug("ss", name), name))
                self._rows(agent, subsystem)

    def _rows(self, agent: Agent, subsystem: Subsystem) -> None:
        """The rows of the subsystem's tables that have anchors, by where their elements were written."""
        qualified = qualified_subsystem_name(agent, subsystem)

        def add(element: object, anchor: str, name: str) -> None:
            location = getattr(element, "location", None)
            if isinstance(location, SourceLocation):
                self.rows.append((location, anchor, f"{qualified}.{name}"))

        for parameter in subsystem.parameters:
            add(parameter, slug(slug("parameters", qualified), parameter.name), parameter.name)
        for kind, buffers in (("ib", subsystem.input_buffers), ("ob", subsystem.output_buffers)):
            for buffer in buffers:
                add(buffer, slug(kind, qualified, indexed_name(buffer)), f"{indexed_name(buffer)}/{kind}")
        for memory in subsystem.memories:
            add(memory, slug("m", qualified, indexed_name(memory)), f"{indexed_name(memory)}/m")
        for predicate in subsystem.primitive_predicates:
            add(predicate, slug("pp", qualified, predicate.name), f"{predicate.name}/pp")
        for function in subsystem.partial_transition_functions:
            add(function, slug("pf", qualified, function.name), f"{function.name}/pf")
        for behaviour in subsystem.basic_behaviours:
            add(behaviour, slug("bb", qualified, behaviour.name), f"{behaviour.name}/bb")
        if subsystem.fsm is not None:
            seen: dict[str, int] = {}  # numbered as Table 5 anchors them
            for transition in subsystem.fsm.transitions:
                seen[transition.name] = seen.get(transition.name, 0) + 1
                number = "" if seen[transition.name] == 1 else f"-{seen[transition.name]}"
                add(transition, slug("t", qualified, transition.name) + number, f"{transition.name}/t")

    def owner_of(self, location: SourceLocation | None, rows: bool = True) -> tuple[str, str] | None:
        """The anchor and name of the innermost element whose source holds `location`: with `rows`, a row
        of a subsystem's tables where one holds it, else the section (a subsystem's, an agent's …)."""
        if location is None:
            return None
        best: tuple[int, str, str] | None = None
        for span, anchor, name in self.owners + (self.rows if rows else []):
            if span.file == location.file and span.line <= location.line <= span.end_line:
                size = span.end_line - span.line
                if best is None or size < best[0]:
                    best = (size, anchor, name)
        return None if best is None else (best[1], best[2])

    # ------------------------------------------------------------------ §3.1: the system
    def overview(self, system: System) -> Section:
        section = Section(text(f"System {system.name}"), "system", 2)
        section.add(
            Paragraph(
                text(
                    f"{self.agents_summary(system)} {self.links_summary(system)} "
                    "The type of each agent is computed from its subsystems and links as in the manual's Table 1."
                )
            )
        )
        said = self.remarks.of(system, closing=False)
        if said:
            section.add(Paragraph(with_code(said)))
        rows, self.environment = parameter_rows(system.parameters, {}, self.subject.parameters)
        if rows:
            section.add(self.parameters_table(rows, f"Parameters of the system {system.name}", "parameters"))
        section.add(self.agents_table(system))
        section.add(
            self.figure(
                system_view(system, self.subject.agent_type, self.subject.placements),
                "Structure of the system (cf. Figure 8)",
            )
        )
        links = inter_agent_links(system)
        if links:
            section.add(self.commented(self.links_table(links), [link.link for link in links]))
            carried = closure(system, [name for link in links for name in _type_words(link.data_type)])
            if carried:
                diagram = types_view(carried, system.name, "dataTypes between agents")
                diagram = Diagram(diagram.view, diagram.header, diagram.dot, "types-between-agents", diagram.names)
                section.add(self.figure(diagram, "dataTypes transmitted between the agents (cf. Figure 9)"))
        return section

    def agents_summary(self, system: System) -> str:
        """How many agents, and which robot holds which: `2 agents. mobileRobot/r holds base/a;
        coordinator/a belongs to no robot.`  A family drawn once counts once, and the sentence says how
        many agents it stands for; a robot holding some of its members names them (`worker[1]/a`)."""
        families = [a for a in system.agents if a.family is not None and a.index is None]
        sentence = _count(len(system.agents), "agent")
        if families:
            expanded = sum(len(self.subject.context.instances(agent)) for agent in system.agents)
            names = _and(agent_name(agent) for agent in families)
            sentence += f" ({expanded} once the famil{'ies' if len(families) > 1 else 'y'} {names} {'are' if len(families) > 1 else 'is'} expanded)"
        if not system.robots:
            return sentence + "; the specification declares no robot."
        placements = self.subject.placements
        clauses = []
        for number, robot in enumerate(system.robots):
            held = []
            for agent in system.agents:
                for share in placements[id(agent)].shares:
                    if share.robot == number:
                        held += [agent_name(agent)] if share.members is None else member_list(agent, share.members)
            clauses.append(f"{robot.name}/r holds {_and(held) if held else 'no agent'}")
        outside = []
        for agent in system.agents:
            placement = placements[id(agent)]
            if not placement.shares:
                outside.append(agent_name(agent))
            elif placement.outside:
                outside += member_list(agent, placement.outside)
        if outside:
            many = len(outside) > 1 or any(".." in name for name in outside)  # `worker[3..5]/a` is three
            clauses.append(f"{_and(outside)} belong{'' if many else 's'} to no robot")
        return f"{sentence}. " + "; ".join(clauses) + "."

    def links_summary(self, system: System) -> str:
        """How many inter-agent links: a link family (`link boss,worker[K in 1..N]`) is one declaration
        standing for a link per member, and the sentence counts both."""
        families = [link for link in system.links if link.family is not None and link.index is None]
        sentence = _count(len(system.links), "inter-agent link")
        if families:
            concrete = len(self.subject.context.system.links)
            sentence += f" declared, {len(families)} of them {'a link family' if len(families) == 1 else 'link families'}: {concrete} once expanded"
        return sentence + "."

    def agents_table(self, system: System) -> Table:
        context = self.subject.context
        header = [
            [cell("agent"), cell("robot"), cell("type"), cell("description")]
            + [cell(f"|{kind}|") for kind in ("cs", "ve", "re", "vr", "rr", "aa")]
        ]
        rows = []
        for agent in system.agents:
            name = agent_name(agent)
            # a family drawn once may be split over robots: the cell names the members each holds
            robot = robot_text(system, agent, self.subject.placements[id(agent)])
            row = self.subject.agent_type(agent)
            instances = context.instances(agent) or [agent]
            first = instances[0]
            counts = [
                len(first.subsystems_of(kind))
                for kind in (
                    Kind.CONTROL_SUBSYSTEM,
                    Kind.VIRTUAL_EFFECTOR,
                    Kind.REAL_EFFECTOR,
                    Kind.VIRTUAL_RECEPTOR,
                    Kind.REAL_RECEPTOR,
                )
            ]
            counts.append(len(context.inter_agent_links(first)))
            type_cell = cell((Strong(text(row.name)),)) if row is not None else cell("—")
            rows.append(
                [
                    cell((Link(slug("agent", name), code(name)),)),
                    cell(code(robot) if robot != NO_ROBOT else text(robot)),
                    type_cell,
                    cell(row.description if row is not None else ""),
                    *[cell(str(count)) for count in counts],
                ]
            )
        known = ", ".join(f"{t.name} ({t.description})" for t in AGENT_TYPES)
        # a family of subsystems counts every member (`|ve|` 6 for motorController[K in 1..6]/ve): the caption
        # had said "counts of one member for a family" beside manip/a's 6
        caption = text(
            "Agents and their types (Table 1; a family of subsystems or links counts every member, a family of "
            f"agents shows the counts of one member). Table 1's types: {known}."
        )
        return Table(caption, header, rows, "agents")

    def links_table(self, links: list[InterAgentLink]) -> Table:
        """Each inter-agent link with its buffers and data type; where robots list links (`twoRobots/r { …
        link left,right }`), which robot lists each (that had been shown nowhere)."""
        system = self.subject.shown
        listing = {
            reference.name: [r.name + "/r" for r in system.robots if any(ref.name == reference.name for ref in r.links)]
            for robot in system.robots
            for reference in robot.links
        }
        header = [[cell("link"), cell("from"), cell("to"), cell("dataType")] + ([cell("robot")] if listing else [])]
        rows = []
        for link in links:
            robots = listing.get(link.link.name_text, [])
            robot_cell = [cell(code(", ".join(robots)) if robots else text("—"))] if listing else []
            source = qualified_subsystem_name(link.source, _cs(link.source))
            destination = qualified_subsystem_name(link.destination, _cs(link.destination))
            rows.append(
                [
                    cell(code(link.link.name_text), anchor=slug("aa", link.link.name_text)),
                    cell((Link(slug("ob", source, link.source_buffer), code(f"{source}.{link.source_end}/ob")),)),
                    cell(
                        (
                            Link(
                                slug("ib", destination, link.destination_buffer),
                                code(f"{destination}.{link.destination_end}/ib"),
                            ),
                        )
                    ),
                    cell(self.type_content(link.data_type)),
                    *robot_cell,
                ]
            )
        return Table(
            text("Inter-agent links aa (§2.5: the source agent's name, a comma, the destination's)"),
            header,
            rows,
            "links",
        )

    # ------------------------------------------------------------------ §3.2: an agent
    def agent_section(self, system: System, agent: Agent) -> Section:
        name = agent_name(agent)
        section = Section((Text("Agent "), Code(name)), slug("agent", name), 2)
        row = self.subject.agent_type(agent)
        facts: list[Inline] = []
        if agent.family is not None and agent.index is None:  # as a family of subsystems is introduced
            members = len(self.subject.context.instances(agent))
            facts.append(
                Text(
                    f"An indexed family, drawn once: {name} for {agent.family.index} ∈ {reference_range(agent)}"
                    f" ({_count(members, 'agent')}). "
                )
            )
        if row is not None:
            facts += [Text("Type "), Strong(text(row.name)), Text(f" ({row.description}, Table 1). ")]
        facts.append(Text("Subsystems: "))
        for position, subsystem in enumerate(agent.subsystems):
            qualified = qualified_subsystem_name(agent, subsystem)
            if position:
                facts.append(Text(", "))
            facts.append(Link(slug("ss", qualified), code(subsystem_name(subsystem))))
        facts.append(Text("."))
        section.add(Paragraph(tuple(facts)))
        said = self.remarks.of(agent)
        if said:
            section.add(Paragraph(with_code(said)))
        rows, environment = parameter_rows(agent.parameters, self.environment, family=agent.family, index=agent.index)
        if rows:
            section.add(self.parameters_table(rows, f"Parameters of {name}", slug("parameters", name)))
        section.add(self.figure(agent_view(agent, system), f"Structure of {name} (cf. Figure 10)"))
        used = agent_types(system, agent)
        if used:
            section.add(self.figure(types_view(used, name), f"dataTypes of {name} (cf. Figure 11)"))
        links = _buffer_links(system, agent)
        for subsystem in agent.subsystems:
            section.add(self.subsystem_section(agent, subsystem, links, environment))
        return section

    def parameters_table(self, rows: Sequence[ParameterRow], caption: str, anchor: str) -> Table:
        """Name, type, the spec's expression where it is more than a value, the value, where it was given,
        and a person's comments on it where any has one."""
        header = [[cell("parameter"), cell("type"), cell("value"), cell("given by")]]
        body = []
        for row in rows:
            value: Content = code(row.value) if row.value != "—" else text("—")
            if row.written:  # `N - 1 = 5`; for a family member by member, `K: 1 (K = 1), 2 (K = 2)`
                value = (Code(row.written), Text(": " if "(" in row.value else " = "), *value)
            body.append(
                [
                    cell(code(row.name), anchor=slug(anchor, row.name)),
                    cell(self.type_content(row.data_type)),
                    cell(value),
                    cell(code(row.given) if row.given.startswith("--param") else text(row.given)),
                ]
            )
        return _with_remarks(Table(text(caption), header, body, anchor), [row.remark for row in rows])

    def subsystem_section(
        self, agent: Agent, subsystem: Subsystem, links: BufferLinks, environment: Environment | None = None
    ) -> Section:
        qualified = qualified_subsystem_name(agent, subsystem)
        scope = Scope(qualified)
        for buffer in subsystem.input_buffers:
            scope.define(buffer.name, indexed_name(buffer), "ib")
        for output in subsystem.output_buffers:
            scope.define(output.name, indexed_name(output), "ob")
        for memory in subsystem.memories:
            scope.define(memory.name, indexed_name(memory), "m")
        for predicate in subsystem.primitive_predicates:
            scope.define(predicate.name, predicate.name, "pp")
        for function in subsystem.partial_transition_functions:
            scope.define(function.name, function.name, "pf")
        for behaviour in subsystem.basic_behaviours:
            scope.define(behaviour.name, behaviour.name, "bb")
        # the innermost declaration of a name hides the outer ones, as in the language
        scope.parameters = {p.name: slug("parameters", p.name) for p in self.subject.shown.parameters}
        agent_anchor = slug("parameters", agent_name(agent))
        scope.parameters |= {p.name: slug(agent_anchor, p.name) for p in agent.parameters}
        scope.parameters |= {p.name: slug(slug("parameters", qualified), p.name) for p in subsystem.parameters}

        title = (Code(qualified), Text(f" — {KIND_TITLES[subsystem.kind]}"))
        section = Section(title, slug("ss", qualified), 3)
        facts = []
        if subsystem.family is not None and subsystem.index is None:
            note = subsystem.family
            facts.append(
                f"An indexed family, drawn once: {subsystem_name(subsystem)} for {note.index} ∈ "
                f"{reference_range(subsystem)}."
            )
        if subsystem.period is not None:
            facts.append(f"Period {subsystem.period.value} {subsystem.period.unit}.")
        if facts:
            section.add(Paragraph(text(" ".join(facts))))
        said = self.remarks.of(subsystem)
        if said:
            section.add(Paragraph(with_code(said)))
        rows, inside = parameter_rows(
            subsystem.parameters,
            self.environment if environment is None else environment,
            family=subsystem.family,
            index=subsystem.index,
        )
        if rows:
            section.add(self.parameters_table(rows, f"Parameters of {qualified}", slug("parameters", qualified)))
        findings = [
            d for d in self.diagnostics if (self.owner_of(d.location, rows=False) or ("", ""))[0] == section.anchor
        ]
        if findings:
            section.add(self.findings_list(_worst_first(findings)))
        if subsystem.input_buffers or subsystem.output_buffers:
            buffers = [*subsystem.input_buffers, *subsystem.output_buffers]
            section.add(self.commented(self.buffers_table(subsystem, qualified, scope, links, inside), buffers))
        if subsystem.memories:
            section.add(self.commented(self.memory_table(subsystem, qualified, scope), subsystem.memories))
        if subsystem.primitive_predicates:
            predicates = subsystem.primitive_predicates
            section.add(self.commented(self.predicates_table(subsystem, qualified, scope), predicates))
        if subsystem.fsm is not None or subsystem.basic_behaviours:
            transitions = subsystem.fsm.transitions if subsystem.fsm is not None else []
            # a row per transition, the `bb` header row when there are transitions, a row per behaviour
            rows_of: list[object] = [*transitions, *([None] if transitions else []), *subsystem.basic_behaviours]
            section.add(self.commented(self.conditions_table(subsystem, qualified, scope), rows_of))
        if subsystem.fsm is not None:
            section.add(
                self.figure(
                    fsm_view(subsystem.fsm, qualified, subsystem, self.subject.expand),
                    f"{qualified}.fsm; conditions in Table 5 (cf. Figure 12)",
                )
            )
        if subsystem.partial_transition_functions:
            functions = subsystem.partial_transition_functions
            section.add(self.commented(self.functions_table(subsystem, qualified, scope), functions))
        if subsystem.basic_behaviours:
            section.add(self.composition_table(subsystem, qualified, scope))
            for behaviour in subsystem.basic_behaviours:
                diagram = activity_view(behaviour, qualified, subsystem)
                section.add(self.figure(diagram, f"{behaviour.name}/bb.tf.execute() (cf. Figure 15)"))
        return section

    def findings_list(self, findings: Sequence[Diagnostic]) -> BulletList:
        items: list[Content] = []
        for d in findings:
            where = f" ({d.location})" if d.location else ""
            label = Strong(text(f"{d.severity.value} {d.code or ''}".strip()))
            items.append((label, Text(": "), *with_code(d.message), Text(where)))
        return BulletList(items)

    def buffers_table(
        self, subsystem: Subsystem, qualified: str, scope: Scope, links: BufferLinks, environment: Environment
    ) -> Table:
        """Each buffer with its dataType and what it is linked with; where an Input Buffer keeps a FIFO
        (`goal/ib: NavigationGoal fifo 4 overflow dropOldest`), a column says what each Input Buffer keeps."""
        queues = any(buffer.queue is not None for buffer in subsystem.input_buffers)
        header = [[cell("buffer"), cell("dataType")] + ([cell("keeps")] if queues else []) + [cell("linked with")]]
        rows = []
        for kind, buffers in (("ib", subsystem.input_buffers), ("ob", subsystem.output_buffers)):
            for buffer in buffers:
                name = indexed_name(buffer)
                others: list[Inline] = []
                for other_anchor, other_name, link_name in links.get((id(subsystem), kind, name), []):
                    if others:
                        others.append(Text(", "))
                    arrow = "← " if kind == "ib" else "→ "
                    others += [Text(arrow), Link(other_anchor, code(other_name)), Text(f" ({link_name})")]
                keeps: list[Cell] = []
                if queues:
                    queue = getattr(buffer, "queue", None)
                    keeps = [cell(_queue_content(queue, environment) if kind == "ib" else text("—"))]
                rows.append(
                    [
                        cell(code(f"{name}/{kind}"), anchor=slug(kind, qualified, name)),
                        cell(self.type_content(type_text(buffer.data_type))),
                        *keeps,
                        cell(tuple(others) or text("—")),
                    ]
                )
        return Table(text(f"Input and Output Buffers of {qualified}"), header, rows)

    def memory_table(self, subsystem: Subsystem, qualified: str, scope: Scope) -> Table:
        header = [[cell("m"), cell("dataType"), cell("initial value")]]
        rows = [
            [
                cell(code(f"{row.name}/m"), anchor=scope.anchor(row.name, "m")),
                cell(self.type_content(row.data_type)),
                cell(code(row.initial_value) if row.initial_value is not None else text("—")),
            ]
            for row in memory_table(subsystem)
        ]
        return Table(text(f"Table 3: {qualified}.m dataTypes"), header, rows)

    def predicates_table(self, subsystem: Subsystem, qualified: str, scope: Scope) -> Table:
        header = [[cell("pp"), cell("fun")]]
        rows = [
            [
                cell(code(f"{row.name}/pp"), anchor=scope.anchor(row.name, "pp")),
                cell(self.expression_content(row.fun, scope)),
            ]
            for row in predicate_table(subsystem)
        ]
        return Table(text(f"Table 4: definitions of {qualified}.pp.fun"), header, rows)

    def conditions_table(self, subsystem: Subsystem, qualified: str, scope: Scope) -> Table:
        transitions = transition_table(subsystem)
        # an FSM of one state (a Real Effector's `drive`) has no transition: a `t` header over no row said
        # nothing, so the table holds the terminal conditions alone and a line under the caption says why
        header = [[cell("t"), cell("PREDICATE (initial condition ic)"), cell("priority")]]
        if not transitions:
            header = [[cell("bb"), cell("PREDICATE (terminal condition tc; error condition ec)")]]
        rows: list[list[Cell]] = []
        #: transitions between the same two states, with different conditions, are valid and share a name:
        #: the second `one,two` is anchored `…-one-two-2`, so every id of the page stays unique
        seen: dict[str, int] = {}
        total: dict[str, int] = {}
        for row in transitions:
            total[row.name] = total.get(row.name, 0) + 1
        for row in transitions:
            seen[row.name] = seen.get(row.name, 0) + 1
            anchor = slug("t", qualified, row.name) + ("" if seen[row.name] == 1 else f"-{seen[row.name]}")
            if row.source is None:
                name: Content = (Code(f"i,{row.destination}/t"), Text(f" where i ≠ {row.destination}"))
            else:
                name = code(f"{row.name}/t")
            if total[row.name] > 1:  # as `earl check` names it: `dispatching,waiting/t` #2 (line 67)
                name += (Text(f" #{seen[row.name]}" + (f" (line {row.line})" if row.line is not None else "")),)
            rows.append(
                [
                    cell(name, anchor=anchor),
                    cell(self.expression_content(row.predicate, scope)),
                    cell("—" if row.priority is None else str(row.priority)),
                ]
            )
        if transitions:
            rows.append(
                [
                    cell((Strong(text("bb")),)),
                    cell((Strong(text("PREDICATE (terminal condition tc; error condition ec)")),)),
                    cell(""),
                ]
            )
        for condition in condition_table(subsystem):
            predicate: Content = (Text("tc: "), *self.expression_content(condition.terminal_condition, scope))
            if condition.error_condition is not None:
                predicate += (Text("; ec: "), *self.expression_content(condition.error_condition, scope))
            row_cells = [
                cell(code(f"{condition.behaviour}/bb"), anchor=scope.anchor(condition.behaviour, "bb")),
                cell(predicate),
            ]
            rows.append(row_cells + ([cell("")] if transitions else []))
        caption = text(
            f"Table 5: initial conditions labelling {qualified}.fsm transitions and terminal conditions of {qualified}.bb"
        )
        notes: list[Content] = []
        if not transitions and subsystem.fsm is not None:
            states = subsystem.fsm.states
            if len(states) == 1:
                notes.append(
                    (
                        Text(f"No transition: {qualified}.fsm has one state, "),
                        Code(states[0].name),
                        Text(", and stays in it."),
                    )
                )
            else:
                notes.append(
                    (
                        Text(
                            f"No transition: {qualified}.fsm has {len(states)} states and stays in its initial state "
                        ),
                        Code(subsystem.fsm.initial),
                        Text("."),
                    )
                )
        # the manual's caption states what the FSM assumes ("It is assumed that task/a can not set simultaneously
        # …"): the conditions above are read under those facts, so they are said where the conditions are
        for assumption in assumption_table(subsystem.fsm):
            said = with_code(f" — {assumption.comment}") if assumption.comment else ()
            notes.append((Text("Assumed: "), *self.expression_content(assumption.formula, scope), *said))
        return Table(caption, header, rows, notes=notes)

    def functions_table(self, subsystem: Subsystem, qualified: str, scope: Scope) -> Table:
        header = [
            [cell("pf"), cell("reads (ib, mi)"), cell("writes (mo, ob)"), cell("stage set"), cell("implementation")]
        ]
        stage_sets = {
            reference.name: stage_set.name for stage_set in subsystem.stage_sets for reference in stage_set.functions
        }
        rows = []
        for function in subsystem.partial_transition_functions:
            implementation = function.implementation.path if function.implementation is not None else "—"
            rows.append(
                [
                    cell(code(f"{function.name}/pf"), anchor=scope.anchor(function.name, "pf")),
                    cell(self._references(function.reads, scope)),
                    cell(self._references(function.writes, scope)),
                    cell(code(stage_sets[function.name]) if function.name in stage_sets else text("—")),
                    # the path is shown, never imported: documenting a spec runs none of its code
                    cell(code(implementation) if function.implementation is not None else text(implementation)),
                ]
            )
        return Table(text(f"Partial transition functions of {qualified} (§2.2, Figure 6; Eq. 4 and 6)"), header, rows)

    def _references(self, references: Sequence[ElementReference], scope: Scope) -> Content:
        parts: list[Inline] = []
        for reference in references:
            written = reference_text(reference)
            if parts:
                parts.append(Text(", "))
            parts += list(self.expression_content(written, scope))
        return tuple(parts) or text("—")

    def composition_table(self, subsystem: Subsystem, qualified: str, scope: Scope) -> Table:
        table = composition_table(subsystem)
        memory = [c for c in table.columns if c.kind is Kind.MEMORY_OUTPUT]
        outputs = [c for c in table.columns if c.kind is Kind.OUTPUT_BUFFER]
        header = [
            [cell("bb", rowspan=2), cell("pf", rowspan=2)]
            + ([cell("/mo", colspan=len(memory))] if memory else [])
            + ([cell("/ob", colspan=len(outputs))] if outputs else []),
            [cell(code(c.name)) for c in [*memory, *outputs]],
        ]
        rows: list[list[Cell]] = []
        spans: dict[str, int] = {}
        for row in table.rows:
            spans[row.behaviour] = spans.get(row.behaviour, 0) + 1
        seen: set[str] = set()
        # a behaviour whose transition function is empty (`tf = {}`) has no function to list: it has a row
        # saying so, where it was left out of the table without a word
        empty = {b.name for b in subsystem.basic_behaviours if b.name not in spans}
        ordered = [b.name for b in subsystem.basic_behaviours]
        for name in ordered:
            if name in empty:
                rows.append(
                    [
                        cell((Link(scope.anchor(name, "bb"), code(f"{name}/bb")),)),
                        cell(
                            (Text("no stage: its transition function is empty ("), Code("tf = {}"), Text(")")),
                            colspan=1 + len(memory) + len(outputs),
                            css="note",
                        ),
                    ]
                )
                continue
            rows += self._composition_rows(table, name, spans, seen, scope, [*memory, *outputs])
        caption = text(
            f"Table 6: compositions of Transition Functions {qualified}.bb.tf.pf; a bullet marks the Internal Memory "
            "and Output Buffers each Partial Transition Function produces"
        )
        return Table(caption, header, rows, slug("table6", qualified), css="matrix")

    def _composition_rows(
        self,
        table: CompositionTable,
        behaviour: str,
        spans: dict[str, int],
        seen: set[str],
        scope: Scope,
        columns: list[Column],
    ) -> list[list[Cell]]:
        """Table 6's rows of one behaviour: a row per function of its transition function, in stage order."""
        rows: list[list[Cell]] = []
        for row in table.rows:
            if row.behaviour != behaviour:
                continue
            cells: list[Cell] = []
            if row.behaviour not in seen:
                seen.add(row.behaviour)
                cells.append(
                    cell(
                        (Link(scope.anchor(row.behaviour, "bb"), code(f"{row.behaviour}/bb")),),
                        rowspan=spans[row.behaviour],
                    )
                )
            function_name = code(f"{row.function}/pf")
            cells.append(cell((Link(scope.anchor(row.function, "pf"), function_name),) if row.known else function_name))
            for column in columns:
                cells.append(cell("•", css="bullet") if table.bullet(row, column) else cell("", css="bullet"))
            rows.append(cells)
        return rows

    # ------------------------------------------------------------------ data types and check results
    def types_section(self, system: System) -> Section:
        section = Section(text("Data types"), "types", 2)
        if not system.types:
            section.add(Paragraph(text("The specification defines no data types; it uses primitive types only.")))
            return section
        header = [[cell("dataType"), cell("definition")]]
        rows = []
        for definition in system.types:
            fields: list[Inline] = []
            if hasattr(definition, "fields"):
                for field_ in definition.fields:
                    if fields:
                        fields.append(Text("; "))
                    fields += [Code(f"{field_.name}: "), *self.type_content(type_text(field_.data_type))]
                    if field_.optional:
                        fields.append(Text(" (optional)"))
                    said = self.remarks.of(field_)
                    if said:
                        fields += [Text(" ("), *with_code(said), Text(")")]
            else:
                fields += [Text("= "), *self.type_content(type_text(definition.data_type))]
            rows.append(
                [cell(code(definition.name), anchor=slug("type", definition.name)), cell(tuple(fields) or text("—"))]
            )
        section.add(self.commented(Table(text("Data types of the specification"), header, rows), system.types))
        section.add(self.figure(types_view(system.types, system.name), "All dataTypes of the specification"))
        return section

    def check_section(self) -> Section:
        section = Section(text("Check results"), "check", 2)
        counts = {severity: sum(1 for d in self.diagnostics if d.severity is severity) for severity in Severity}
        summary = ", ".join(f"{n} {s.value}{'s' if n != 1 else ''}" for s, n in counts.items())
        verdict = (
            "The specification breaks rules of the EARL manual."
            if counts[Severity.ERROR]
            else "The specification follows every rule of the EARL manual that `earl check` knows."
        )
        section.add(Paragraph(text(f"earl check: {summary}. {verdict}")))
        if not self.diagnostics:
            return section
        header = [[cell("severity"), cell("rule"), cell("where"), cell("message")]]
        rows = []
        for d in _worst_first(self.diagnostics):
            owner = self.owner_of(d.location)
            where: Content = text(str(d.location) if d.location else "—")
            if owner is not None:
                where = (Link(owner[0], code(owner[1])), Text(f" ({d.location})"))
            message = with_code(d.message + (f" — hint: {d.hint}" if d.hint else ""))
            rows.append(
                [
                    cell(d.severity.value, css=_SEVERITY_CSS[d.severity]),
                    cell(code(d.code) if d.code else text("—"), css="rule"),
                    cell(where),
                    cell(message),
                ]
            )
        section.add(Table(text("Findings of earl check (docs/rules.md explains each rule)"), header, rows, "findings"))
        return section


# ---------------------------------------------------------------------- helpers
def _with_remarks(table: Table, remarks: Sequence[Remark]) -> Table:
    """`table` with a comment column when a row's element has a comment of its own, and a caption row,
    across the table, above the rows a comment heads (where it was written in the spec)."""
    if any(remark.own for remark in remarks):
        table.header[0].append(cell("comment", rowspan=len(table.header)))
        for row, remark in zip(table.rows, remarks, strict=False):
            row.append(cell(with_code(remark.own) if remark.own else (), css="comment"))
    columns = sum(entry.colspan for entry in table.header[0])
    for position in reversed(range(min(len(table.rows), len(remarks)))):
        if remarks[position].heading:
            table.rows.insert(position, [cell(with_code(remarks[position].heading), colspan=columns, css="group")])
    return table


BufferLinks = dict[tuple[int, str, str], list[tuple[str, str, str]]]


def _buffer_links(system: System, agent: Agent) -> BufferLinks:
    """For each buffer of the agent (subsystem identity, ib|ob, name): the buffers at the other end of its links."""
    table: BufferLinks = {}
    for link in agent_links(agent):
        source = qualified_subsystem_name(agent, link.source)
        destination = qualified_subsystem_name(agent, link.destination)
        output, input_ = indexed_name(link.output), indexed_name(link.input)
        # A family drawn once has one row per buffer, but a link may reach one member only
        # (`link cs,mc[2]: cs.special -> mc[2]/ve.boost`): each end is named as the link names it,
        # and the row of a family's buffer says which member the link starts from or goes into.
        source_end = _end(link.source, link.link.source.subsystem, link.output, link.link.source.buffer)
        destination_end = _end(
            link.destination, link.link.destination.subsystem, link.input, link.link.destination.buffer
        )
        label = link_label(link.link)
        own_source = f"{subsystem_name(link.source)}.{output}"
        own_destination = f"{subsystem_name(link.destination)}.{input_}"
        table.setdefault((id(link.source), "ob", output), []).append(
            (
                slug("ib", destination, input_),
                f"{agent_name(agent)}.{destination_end}/ib",
                label if source_end == own_source else f"{label}, from {source_end}",
            )
        )
        table.setdefault((id(link.destination), "ib", input_), []).append(
            (
                slug("ob", source, output),
                f"{agent_name(agent)}.{source_end}/ob",
                label if destination_end == own_destination else f"{label}, into {destination_end}",
            )
        )
    for outer in inter_agent_links(system):
        source = qualified_subsystem_name(outer.source, _cs(outer.source))
        destination = qualified_subsystem_name(outer.destination, _cs(outer.destination))
        label = link_label(outer.link)  # `alpha,worker[K]`, as inside an agent
        if outer.source is agent:
            table.setdefault((id(_cs(agent)), "ob", outer.source_buffer), []).append(
                (
                    slug("ib", destination, outer.destination_buffer),
                    f"{destination}.{outer.destination_end}/ib",
                    label if outer.source_end == outer.source_buffer else f"{label}, from {outer.source_end}",
                )
            )
        if outer.destination is agent:
            table.setdefault((id(_cs(agent)), "ib", outer.destination_buffer), []).append(
                (
                    slug("ob", source, outer.source_buffer),
                    f"{source}.{outer.source_end}/ob",
                    label
                    if outer.destination_end == outer.destination_buffer
                    else f"{label}, into {outer.destination_end}",
                )
            )
    return table


def _end(
    subsystem: Subsystem, subsystem_reference: ElementReference, buffer: Indexed, buffer_reference: ElementReference
) -> str:
    """`mc[2]/ve.boost`: a link's end inside an agent as the link names it, a single member where it
    names one of a family drawn once, else the family (`mc[K]/ve.command`)."""
    owner = (
        "cs"
        if subsystem.kind is Kind.CONTROL_SUBSYSTEM
        else f"{end_name(subsystem, subsystem_reference)}/{subsystem.kind.value}"
    )
    return f"{owner}.{end_name(buffer, buffer_reference)}"


def _cs(agent: Agent) -> Subsystem:
    cs = agent.control_subsystem
    assert cs is not None  # inter_agent_links only returns agents with a control subsystem
    return cs


def _queue_content(queue: Queue | None, environment: Environment) -> Content:
    """`the latest message`, or `a FIFO of 4 messages; when full: dropOldest` (the capacity's expression
    and its value where it names parameters: `QUEUE = 8`)."""
    if queue is None:
        return text("the latest message")
    written = expression_text(queue.capacity)
    try:
        value = literal_text(evaluate_constant(queue.capacity, environment))
    except (ConstantError, TypeError):
        value = written
    capacity: Content = code(value) if value == written else (Code(written), Text(" = "), Code(value))
    return (Text("a FIFO of "), *capacity, Text(" messages; when full: "), Code(queue.overflow))


_SEVERITY_ORDER = {Severity.ERROR: 0, Severity.WARNING: 1, Severity.NOTE: 2}


def _worst_first(diagnostics: Sequence[Diagnostic]) -> list[Diagnostic]:
    """Errors, then warnings, then notes; in the order `earl check` gives them within each."""
    return sorted(diagnostics, key=lambda d: _SEVERITY_ORDER.get(d.severity, 3))


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'' if number == 1 else 's'}"


def _and(names: Iterable[str]) -> str:
    """`a`, `a and b`, `a, b and c`."""
    listed = list(names)
    return listed[0] if len(listed) == 1 else ", ".join(listed[:-1]) + " and " + listed[-1]


def _type_words(written: str) -> list[str]:
    return _WORD.findall(written)


def reference_range(element: Subsystem | Agent) -> str:
    """`1..N`: the range of a family's index, as written."""
    family = element.family
    assert family is not None
    return f"{expression_text(family.first)}..{expression_text(family.last)}"
