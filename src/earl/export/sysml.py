"""A specification as SysML v2 textual notation, on top of the EARL library (`EARL.sysml`).

    >>> from earl.export.sysml import export_sysml
    >>> text = export_sysml(earl.load("examples/pick_and_place"))

The system is written as one part typed by `EARL::System`; its agents, subsystems,
buffers, memory, predicates, functions, behaviours, state machines and links are
usages that specialise the library's definitions, with every indexed family expanded
into its members.  Each element keeps its EARL name as its SysML short name and the
place it was written in a doc comment.  docs/sysml.md has the whole mapping.

Exporting reads the model only: it never imports or runs code a spec names.
"""

from __future__ import annotations

import textwrap
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from earl import __version__
from earl.check import context_for as check_context_for
from earl.check.context import CheckContext
from earl.diagnostics import EarlError, Severity
from earl.export.sysml_expressions import ExpressionWriter, literal
from earl.export.sysml_names import Namespace, name_text, quoted, readable
from earl.lang.resolver import resolve
from earl.model.comment_paragraphs import comment_paragraphs
from earl.model.elements import (
    FSM,
    Agent,
    BasicBehaviour,
    Duration,
    InputBuffer,
    Link,
    Memory,
    OutputBuffer,
    Parameter,
    PartialTransitionFunction,
    PrimitivePredicate,
    Robot,
    StageSet,
    State,
    Subsystem,
    System,
    Transition,
)
from earl.model.expressions import ElementReference, Literal
from earl.model.kinds import Kind
from earl.model.location import Comments, SourceLocation
from earl.model.text import expression_text, instance_name, robot_member_keys
from earl.model.types import ArrayType, DataType, PrimitiveType, StructType, TypeAlias, TypeReference, type_text
from earl.model.validate import refuse_wrong_types

Value = bool | int | float | str

#: The file name of the library, shipped in this package.
LIBRARY_FILE = "EARL.sysml"

#: The library definition each kind of subsystem specialises, and the Agent feature it subsets.
SUBSYSTEM_DEFINITIONS: dict[Kind, str] = {
    Kind.CONTROL_SUBSYSTEM: "ControlSubsystem",
    Kind.VIRTUAL_EFFECTOR: "VirtualEffector",
    Kind.REAL_EFFECTOR: "RealEffector",
    Kind.VIRTUAL_RECEPTOR: "VirtualReceptor",
    Kind.REAL_RECEPTOR: "RealReceptor",
}

# Features the library's definitions give every usage of them: a name of the specification
# must not hide one (docs/sysml.md, "Names").
_SYSTEM_FEATURES = ("robots", "agents", "links")
_AGENT_FEATURES = ("cs", "ve", "re", "vr", "rr", "aa", "agentType", "equation1", "table1")
_SUBSYSTEM_FEATURES = ("period", "ib", "ob", "m", "pp", "pf", "bb", "fsm", "figure4b")


def library_text() -> str:
    """The text of `EARL.sysml`, the SysML v2 library every export imports."""
    return resources.files("earl.export").joinpath(LIBRARY_FILE).read_text(encoding="utf-8")


#: the packages the export and its library `EARL.sysml` import: a system of one of these names is renamed
LIBRARY_PACKAGES = frozenset({"EARL", "ScalarValues", "ISQ", "SequenceFunctions", "SI"})


def export_sysml(system: System, parameters: Mapping[str, Value] | None = None) -> str:
    """`system` as SysML v2 text, every family expanded with `parameters` (the system's own values by default).

    A system built or edited in Python never met the reader: its names and types are resolved first,
    and what the reader would refuse (a type alias naming itself, which the writer would follow for
    ever) raises `EarlError` with the reader's diagnostics; a value of a wrong type (`reads = ["cmd/ib"]`)
    raises ModelTypeError naming where it is, as `check` and `to_earl` do, not Python's error from inside."""
    refuse_wrong_types(system)
    unresolved = [d for d in resolve(system, parameters or {}) if d.severity is Severity.ERROR]
    if unresolved:
        raise EarlError(unresolved)
    return _Writer(system, check_context_for(system, parameters or {})).write()


# ---------------------------------------------------------------------- small helpers
def _where(location: SourceLocation | None) -> str | None:
    # The file's own name, not the path it was read by, so the export does not depend on the working directory.
    return None if location is None else f"{Path(location.file).name}:{location.line}"


def _duration(duration: Duration) -> str:
    seconds = duration.seconds
    text = repr(float(seconds)) if not float(seconds).is_integer() else f"{seconds:.1f}"
    return f"{text} [SI::s]"


def _index_of(reference: ElementReference) -> int | None:
    index = reference.indices[0] if reference.indices else None
    return index.value if isinstance(index, Literal) and isinstance(index.value, int) else None


def _earl_name(name: str, index: int | None, kind: Kind | None) -> str:
    own = instance_name(name, index)
    return own if kind is None else f"{own}/{kind.value}"


def _subsystem_key(name: str, index: int | None, kind: Kind) -> str:
    return "cs" if kind is Kind.CONTROL_SUBSYSTEM else _earl_name(name, index, kind)


def _memory_kind(kind: Kind) -> Kind:
    return Kind.MEMORY if kind in (Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT) else kind


@dataclass
class _Named:
    """An element's SysML name and the declaration text that names it (`manip_a <'manip/a'>`)."""

    name: str
    declaration: str


class _Writer:
    def __init__(self, declared: System, context: CheckContext) -> None:
        self.declared = declared
        self.context = context
        self.system = context.system
        self.lines: list[str] = []
        self.depth = 0
        self.comments = _comments_by_location(declared)
        self.clause_comments = _clause_comments_by_location(declared)
        #: SysML names of the spec's data types and of the helper definitions made for array types.
        self.type_names: dict[str, str] = {}
        self.helper_types: dict[str, tuple[str, DataType]] = {}
        #: SysML names of agents, and of links by identity, for references between them.
        self.agent_names: dict[str, str] = {}
        self.link_names: dict[int, str] = {}
        self.link_declarations: dict[int, str] = {}
        #: Per agent and subsystem (EARL names): the subsystem's SysML name and its elements' names, for link ends.
        self.scopes: dict[tuple[str, str], tuple[str, _SubsystemNames]] = {}

    # ------------------------------------------------------------------ output
    def emit(self, line: str = "") -> None:
        self.lines.append(("    " * self.depth + line) if line else "")

    @contextmanager
    def block(self, header: str) -> Iterator[None]:
        self.emit(header + " {")
        self.depth += 1
        yield
        self.depth -= 1
        self.emit("}")

    def doc(self, *paragraphs: str) -> None:
        text = [p.replace("*/", "* /") for p in paragraphs if p]
        if not text:
            return
        if len(text) == 1 and len(text[0]) + self.depth * 4 <= 100:
            self.emit(f"doc /* {text[0]} */")
            return
        self.emit("doc")
        self.emit("/*")
        for paragraph in text:
            for line in textwrap.wrap(paragraph, width=max(60, 96 - self.depth * 4)) or [""]:
                self.emit(f" * {line}")
        self.emit(" */")

    def element_doc(self, location: SourceLocation | None, *extra: str) -> None:
        """The person's comments on an element and at its clauses, what the export adds, and where it was written."""
        where = _where(location)
        self.doc(
            *comment_paragraphs(self.comments.get(location) if location else None),
            *self.clause_notes(location),
            *extra,
            *([f"From {where}."] if where else []),
        )

    def clause_notes(self, location: SourceLocation | None) -> list[str]:
        """The comments written at an element's clauses (`period`, `tf`, `tc`, `ec`, `initial`, a state's
        `obligatory`, `optional` and `timeout` lines), each after the clause it is about: the clauses are
        features of the element in SysML too, and its doc is where a SysML tool shows what was said of them."""
        said = self.clause_comments.get(location) if location is not None else None
        notes = []
        for key, comments in (said or {}).items():
            # a state's clause spreads over several lines, keyed `obligatory 0`, `obligatory 1`, …
            clause = key.split()[0]
            lines = comment_paragraphs(comments)
            if lines:
                notes.append(f"At `{clause}`: {' '.join(lines)}")
        return notes

    def named(self, namespace: Namespace, earl_name: str, preferred: str | None = None) -> _Named:
        """A readable, unique name, with the EARL name as short name when the two differ, unless that
        EARL name is a name or short name of the namespace already: SysML resolves short names too, and an
        owned `<'agents'>` would be found where the library's inherited `agents` is meant."""
        free = not namespace.taken(earl_name)
        name = namespace.claim(preferred or readable(earl_name))
        if name == earl_name or not free or not namespace.claim_short(earl_name):
            return _Named(name, name_text(name))
        return _Named(name, f"<{quoted(earl_name)}> {name_text(name)}")

    # ------------------------------------------------------------------ the file
    def write(self) -> str:
        source = Path(self.declared.source_file).name if self.declared.source_file else None
        origin = f" from {source}" if source else ""
        self.emit(f"// SysML v2 text written by earl {__version__} (`earl export sysml`){origin}.")
        self.emit(f"// It needs {LIBRARY_FILE}, the EARL library shipped with earl: export it beside this file.")
        # a system named as a package the export or its library imports (`EARL`, `ScalarValues`, …) would
        # hide it: it is exported as `EARL_system`
        taken = self.system.name in LIBRARY_PACKAGES
        package = f"{self.system.name}_system" if taken else self.system.name
        with self.block(f"package {name_text(package)}"):
            settings = ", ".join(f"{p.name} = {literal(_parameter_value(p))}" for p in self.system.parameters)
            self.doc(
                *comment_paragraphs(self.declared.comments, closing=False),
                f"EARL system `{self.system.name}`{origin}"
                + (f", exported with {settings}" if settings else "")
                + ". Every indexed family is expanded into its members; the short name of each element is its "
                "EARL name.",
            )
            self.emit("private import EARL::*;")
            # Array-of-array definitions are found while writing the rest, and go before it.
            head, self.lines = self.lines, []
            self.types()
            self.emit()
            self.system_part()
            body, self.lines = self.lines, head
            for helper, array in sorted(self.helper_types.values(), key=lambda entry: entry[0]):
                self.emit()
                self.array_definition(helper, array)
            self.lines.extend(body)
        return "\n".join(self.lines) + "\n"

    # ------------------------------------------------------------------ data types (§2.2, Figures 9 and 11)
    def types(self) -> None:
        namespace = Namespace((self.system.name,), (definition.name for definition in self.system.types))
        for definition in self.system.types:
            self.type_names[definition.name] = namespace.claim(definition.name)
        for definition in self.system.types:
            self.emit()
            name = name_text(self.type_names[definition.name])
            if isinstance(definition, StructType):
                with self.block(f"attribute def {name}"):
                    self.element_doc(definition.location)
                    for field in definition.fields:
                        declaration = (
                            f"attribute {name_text(field.name)} : {self.typed(field.data_type, field.optional)}"
                        )
                        # A field someone commented gets the comment as its doc, and where it was written.
                        if comment_paragraphs(self.comments.get(field.location) if field.location else None):
                            with self.block(declaration):
                                self.element_doc(field.location)
                        else:
                            self.emit(declaration + ";")
            else:
                self.alias(name, definition)

    def alias(self, name: str, definition: TypeAlias) -> None:
        element, size = self.shape(definition.data_type)
        note = f"EARL: type {definition.name} = {type_text(definition.data_type)}" + (
            f"; a usage of it holds {size} values (multiplicity [{size}], ordered)." if size is not None else "."
        )
        with self.block(f"attribute def {name} :> {element}"):
            self.element_doc(definition.location, note)

    def array_definition(self, helper: str, array: DataType) -> None:
        with self.block(f"attribute def {helper}"):
            self.doc(f"The EARL array type {type_text(array)} as one value, for arrays of arrays and optional arrays.")
            self.emit(f"attribute elements : {self.typed(array)};")

    def array_value(self, array: DataType) -> str:
        """The name of the definition holding `array` (an array type, or the name of an alias of one) as one
        value: `'double[3]'`, `'JointPosition value'` (not `'JointPosition'`, which is the alias's own name)."""
        text = f"{array.name} value" if isinstance(array, TypeReference) else type_text(array)
        return self.helper_types.setdefault(text, (quoted(text), array))[0]

    def shape(self, data_type: DataType) -> tuple[str, str | None]:
        """The SysML type of a value and, for an array, its size: SysML v2 has multiplicities, not array types."""
        if isinstance(data_type, PrimitiveType):
            return f"EARL::{data_type.name}", None
        if isinstance(data_type, TypeReference):
            definition = self.system.type_named(data_type.name)
            name = name_text(self.type_names.get(data_type.name, data_type.name))
            return name, self.shape(definition.data_type)[1] if isinstance(definition, TypeAlias) else None
        element, inner = self.shape(data_type.element)
        if inner is not None:
            # An array of arrays: the inner array becomes a definition of its own (`'double[3]'`).
            element = self.array_value(data_type.element)
        return element, "*" if data_type.size is None else _size_text(data_type)

    def typed(self, data_type: DataType, optional: bool = False) -> str:
        """A type with its multiplicity: `EARL::double[3] ordered nonunique`, `OperPosition[0..1]`, and for an
        optional array `'double[3]'[0..1]`: absent, or one value holding exactly its elements ([0..3] would
        admit one or two, and [*] could not tell an absent variable array from an empty one)."""
        element, size = self.shape(data_type)
        if size is None:
            return element + ("[0..1]" if optional else "")
        if optional:
            return f"{self.array_value(data_type)}[0..1]"
        return f"{element}[{size}] ordered nonunique"

    # ------------------------------------------------------------------ the system (§2.1, Figure 2)
    def system_part(self) -> None:
        system = self.system
        namespace = Namespace(_SYSTEM_FEATURES, (p.name for p in system.parameters))
        with self.block(f"part {name_text(system.name)} : EARL::System"):
            self.element_doc(system.location)
            self.parameter_list(system.parameters, namespace)
            for agent in system.agents:
                earl_name = _earl_name(agent.name, agent.index, Kind.AGENT)
                # Claimed before any is written, so that links and robots can refer to every agent.
                self.agent_names[earl_name] = self.named(namespace, earl_name).name
            for link in system.links:
                named = self.named(namespace, link.name_text)
                self.link_names[id(link)], self.link_declarations[id(link)] = named.name, named.declaration
            for agent in system.agents:
                self.emit()
                self.agent(agent)
            for link in system.links:
                self.emit()
                self.link(link, None)
            for robot in system.robots:
                self.emit()
                self.robot(robot, namespace)

    def parameter_list(self, parameters: list[Parameter], namespace: Namespace) -> None:
        for parameter in parameters:
            name = self.named(namespace, parameter.name, parameter.name)
            value = literal(_parameter_value(parameter))
            # a doc, not a `//` note: a SysML tool keeps the doc, so the comment and the line stay with the attribute
            with self.block(f"attribute {name.declaration} : {self.typed(parameter.data_type)} = {value}"):
                self.element_doc(parameter.location)

    def robot(self, robot: Robot, namespace: Namespace) -> None:
        name = self.named(namespace, f"{robot.name}/r")
        with self.block(f"part {name.declaration} : EARL::Robot :> robots"):
            self.element_doc(robot.location)
            agents = [
                self.agent_names[_earl_name(r.name, _index_of(r), Kind.AGENT)]
                for r in robot.agents
                if _earl_name(r.name, _index_of(r), Kind.AGENT) in self.agent_names
            ]
            if agents:
                self.emit(f"ref part :>> agents = {_sequence(agents)};")
            links = [
                self.link_names[id(link)]
                for reference in robot.links
                for link in self.system.links
                if _robot_refers_to(reference, link)
            ]
            if links:
                self.emit(f":>> links = {_sequence(links)};")

    # ------------------------------------------------------------------ agents (§2.1, §2.4)
    def agent(self, agent: Agent) -> None:
        earl_name = _earl_name(agent.name, agent.index, Kind.AGENT)
        own = self.agent_names[earl_name]
        short = "" if own == earl_name else f"<{quoted(earl_name)}> "
        with self.block(f"part {short}{name_text(own)} : EARL::Agent :> agents"):
            self.element_doc(agent.location, *self.member_note(agent.family is not None, agent.index))
            namespace = Namespace(_AGENT_FEATURES, (p.name for p in agent.parameters))
            self.parameter_list(agent.parameters, namespace)
            row = self.context.agent_type(agent)
            self.emit(f"attribute :>> agentType = EARL::AgentType::{row.name}; // Table 1: {row.description}")
            links = [
                self.link_names[id(resolved.link)]
                for resolved in self.context.inter_agent_links(agent)
                if id(resolved.link) in self.link_names
            ]
            if links:
                self.emit(f":>> aa = {_sequence(list(dict.fromkeys(links)))};")
            subsystem_names = {}
            for subsystem in agent.subsystems:
                earl_sub = (
                    "cs"
                    if subsystem.kind is Kind.CONTROL_SUBSYSTEM
                    else _earl_name(subsystem.name, subsystem.index, subsystem.kind)
                )
                subsystem_names[id(subsystem)] = self.named(namespace, earl_sub)
            for link in agent.links:
                named = self.named(namespace, link.name_text)
                self.link_names[id(link)], self.link_declarations[id(link)] = named.name, named.declaration
            for subsystem in agent.subsystems:
                self.emit()
                names = self.subsystem(subsystem, subsystem_names[id(subsystem)])
                key = (earl_name, _subsystem_key(subsystem.name, subsystem.index, subsystem.kind))
                self.scopes[key] = (
                    "cs" if subsystem.kind is Kind.CONTROL_SUBSYSTEM else subsystem_names[id(subsystem)].name,
                    names,
                )
            for link in agent.links:
                self.emit()
                self.link(link, agent)

    def member_note(self, is_member: bool, index: int | None) -> tuple[str, ...]:
        return (f"Member {index} of an indexed family.",) if is_member and index is not None else ()

    # ------------------------------------------------------------------ subsystems (§2.2, Figures 3 and 4)
    def subsystem(self, subsystem: Subsystem, named: _Named) -> _SubsystemNames:
        definition = SUBSYSTEM_DEFINITIONS[subsystem.kind]
        if subsystem.kind is Kind.CONTROL_SUBSYSTEM:
            header = f"part :>> cs : EARL::{definition}"  # the one `cs` of Agent, redefined
        else:
            header = f"part {named.declaration} : EARL::{definition} :> {subsystem.kind.value}"
        with self.block(header):
            self.element_doc(subsystem.location, *self.member_note(subsystem.family is not None, subsystem.index))
            namespace = Namespace(_SUBSYSTEM_FEATURES, (p.name for p in subsystem.parameters))
            names = _SubsystemNames()
            if subsystem.period is not None:
                self.emit(
                    f"attribute :>> period = {_duration(subsystem.period)}; // {_duration_text(subsystem.period)}"
                )
            self.parameter_list(subsystem.parameters, namespace)
            for buffer in subsystem.input_buffers:
                self.input_buffer(buffer, namespace, names)
            for output in subsystem.output_buffers:
                self.output_buffer(output, namespace, names)
            for memory in subsystem.memories:
                self.memory(memory, namespace, names)
            for predicate in subsystem.primitive_predicates:
                names.add(
                    predicate.name, None, Kind.PRIMITIVE_PREDICATE, self.named(namespace, f"{predicate.name}/pp").name
                )
            for function in subsystem.partial_transition_functions:
                names.add(
                    function.name,
                    None,
                    Kind.PARTIAL_TRANSITION_FUNCTION,
                    self.named(namespace, f"{function.name}/pf").name,
                )
            for behaviour in subsystem.basic_behaviours:
                names.add(
                    behaviour.name, None, Kind.BASIC_BEHAVIOUR, self.named(namespace, f"{behaviour.name}/bb").name
                )
            expressions = self.expressions(names)
            for predicate in subsystem.primitive_predicates:
                self.primitive_predicate(predicate, names, expressions)
            for function in subsystem.partial_transition_functions:
                self.partial_transition_function(function, names)
            for stage_set in subsystem.stage_sets:
                self.stage_set(stage_set, namespace, names)
            for behaviour in subsystem.basic_behaviours:
                self.basic_behaviour(behaviour, names, expressions)
            if subsystem.fsm is not None:
                self.fsm(subsystem, names, expressions)
        return names

    def expressions(self, names: _SubsystemNames) -> ExpressionWriter:
        return ExpressionWriter(names.resolve, names.data_type, self.system.type_named)

    def input_buffer(self, buffer: InputBuffer, namespace: Namespace, names: _SubsystemNames) -> None:
        named = self.named(namespace, _earl_name(buffer.name, buffer.index, Kind.INPUT_BUFFER))
        names.add(buffer.name, buffer.index, Kind.INPUT_BUFFER, named.name, buffer.data_type)
        with self.block(f"port {named.declaration} : EARL::InputBuffer :> ib"):
            self.element_doc(buffer.location, *self.member_note(buffer.family is not None, buffer.index))
            self.emit(f"in item :>> msg : {self.typed(buffer.data_type)};")
            if buffer.queue is not None:
                capacity = buffer.queue.capacity
                if isinstance(capacity, Literal):
                    self.emit(f"attribute :>> capacity = {literal(capacity.value)};")
                self.emit(f"attribute :>> overflow = EARL::OverflowPolicy::{buffer.queue.overflow};")

    def output_buffer(self, buffer: OutputBuffer, namespace: Namespace, names: _SubsystemNames) -> None:
        named = self.named(namespace, _earl_name(buffer.name, buffer.index, Kind.OUTPUT_BUFFER))
        names.add(buffer.name, buffer.index, Kind.OUTPUT_BUFFER, named.name, buffer.data_type)
        with self.block(f"port {named.declaration} : EARL::OutputBuffer :> ob"):
            self.element_doc(buffer.location, *self.member_note(buffer.family is not None, buffer.index))
            self.emit(f"out item :>> msg : {self.typed(buffer.data_type)};")

    def memory(self, memory: Memory, namespace: Namespace, names: _SubsystemNames) -> None:
        named = self.named(namespace, _earl_name(memory.name, memory.index, Kind.MEMORY))
        names.add(memory.name, memory.index, Kind.MEMORY, named.name, memory.data_type)
        with self.block(f"item {named.declaration} : EARL::InternalMemory :> m"):
            self.element_doc(memory.location, *self.member_note(memory.family is not None, memory.index))
            initial = ""
            if memory.initial_value is not None:
                initial = " := " + self.expressions(names).text(memory.initial_value)
            self.emit(f"attribute :>> data : {self.typed(memory.data_type)}{initial};")

    # ------------------------------------------------------------------ behaviour (§2.2, Table 4, Figures 5 and 6)
    def primitive_predicate(
        self, predicate: PrimitivePredicate, names: _SubsystemNames, expressions: ExpressionWriter
    ) -> None:
        own = names.name(predicate.name, None, Kind.PRIMITIVE_PREDICATE)
        with self.block(f"constraint {_declaration(own, f'{predicate.name}/pp')} : EARL::PrimitivePredicate :> pp"):
            implementation = (
                f"Computed by python {literal(predicate.implementation.path)}." if predicate.implementation else ""
            )
            self.element_doc(predicate.location, implementation)
            self.emit(expressions.text(predicate.expression))

    def partial_transition_function(self, function: PartialTransitionFunction, names: _SubsystemNames) -> None:
        own = names.name(function.name, None, Kind.PARTIAL_TRANSITION_FUNCTION)
        header = f"action {_declaration(own, f'{function.name}/pf')} : EARL::PartialTransitionFunction :> pf"
        with self.block(header):
            implementation = (
                f"Implemented by python {literal(function.implementation.path)}." if function.implementation else ""
            )
            self.element_doc(function.location, implementation)
            groups: dict[str, list[str]] = {"ib": [], "mi": [], "mo": [], "ob": []}
            for reference in function.reads:
                groups["ib" if reference.kind is Kind.INPUT_BUFFER else "mi"].append(names.resolve(reference))
            for reference in function.writes:
                groups["ob" if reference.kind is Kind.OUTPUT_BUFFER else "mo"].append(names.resolve(reference))
            for feature, targets in groups.items():
                if targets:
                    self.emit(f":>> {feature} = {_sequence(targets)};")

    def stage_set(self, stage_set: StageSet, namespace: Namespace, names: _SubsystemNames) -> None:
        named = self.named(namespace, f"stage {stage_set.name}", f"{stage_set.name}Stage")
        targets = [names.resolve(reference) for reference in stage_set.functions]
        with self.block(f"ref action {named.declaration} : EARL::PartialTransitionFunction[*] = {_sequence(targets)}"):
            self.element_doc(stage_set.location)

    def basic_behaviour(self, behaviour: BasicBehaviour, names: _SubsystemNames, expressions: ExpressionWriter) -> None:
        own = names.name(behaviour.name, None, Kind.BASIC_BEHAVIOUR)
        with self.block(f"action {_declaration(own, f'{behaviour.name}/bb')} : EARL::BasicBehaviour :> bb"):
            self.element_doc(behaviour.location)
            stages = behaviour.transition_function.stages
            if not any(stages):
                self.emit("action :>> tf; // no Partial Transition Function")
            else:
                with self.block("action :>> tf"):
                    self.transition_function(stages, names)
            self.emit(
                f"constraint :>> terminalCondition {{ {expressions.text(behaviour.terminal_condition.expression)} }}"
            )
            if behaviour.error_condition is not None:
                self.emit(
                    f"constraint :>> errorCondition {{ {expressions.text(behaviour.error_condition.expression)} }}"
                )

    def transition_function(self, stages: list[list[ElementReference]], names: _SubsystemNames) -> None:
        """Figure 15: stages one after another; the functions of a stage between a fork and a join."""
        performed = Namespace(("start", "done"))
        previous = "start"
        for number, stage in enumerate((s for s in stages if s), start=1):
            targets = []
            for reference in stage:
                target = names.resolve(reference)
                own = performed.claim(target)
                targets.append(own)
            if len(targets) == 1:
                self.emit(f"first {previous} then {name_text(targets[0])};")
                self.perform(targets[0], names.resolve(stage[0]))
                previous = targets[0]
                continue
            fork, join = performed.claim(f"stage{number}Fork"), performed.claim(f"stage{number}Join")
            self.emit(f"first {previous} then {fork};")
            self.emit(f"fork {fork};")
            self.depth += 1
            for target in targets:
                self.emit(f"then {name_text(target)};")
            self.depth -= 1
            for target, reference in zip(targets, stage, strict=True):
                self.perform(target, names.resolve(reference))
                self.depth += 1
                self.emit(f"then {join};")
                self.depth -= 1
            self.emit(f"join {join};")
            previous = join
        self.emit(f"first {previous} then done;")

    def perform(self, own: str, target: str) -> None:
        if own == target:
            self.emit(f"perform {name_text(target)};")
        else:
            self.emit(f"perform action {name_text(own)} ::> {name_text(target)};")

    # ------------------------------------------------------------------ the FSM (§2.2, Figure 5a; Table 5)
    def fsm(self, subsystem: Subsystem, names: _SubsystemNames, expressions: ExpressionWriter) -> None:
        fsm = subsystem.fsm
        assert fsm is not None
        with self.block("exhibit state :>> fsm : EARL::FSM"):
            self.element_doc(fsm.location)
            # a state body inherits the features `start` and `done` (Actions::Action's first and last snapshots):
            # a state named so would hide them, and `entry; then start;` would be read against the library's
            namespace = Namespace(("start", "done"), (state.name for state in fsm.states))
            states = {state.name: namespace.claim(state.name) for state in fsm.states}
            initial = states.get(fsm.initial, fsm.initial)
            self.emit(f"entry; then {name_text(initial)};")
            for state in fsm.states:
                self.emit()
                self.state(state, states[state.name], names)
            # Named in declaration order, as Table 5 of the document numbers them (a second `one -> two` is
            # `one_two_t_2` whatever its priority); SysML v2 has no priority, so the text lists them in the order
            # they are tried, as `earl run` does: priority 1 first, those without one last (docs/sysml.md).
            named = {
                id(transition): self.named(namespace, f"{transition.source},{transition.destination}/t")
                for transition in fsm.transitions
            }
            for transition in sorted(fsm.transitions, key=lambda t: (t.priority is None, t.priority or 0)):
                self.emit()
                self.transition(transition, states, named[id(transition)], expressions)
            for number, assumption in enumerate(fsm.assumptions, start=1):
                self.emit()
                name = namespace.claim(f"assumption{number}")
                with self.block(f"assert constraint {name} : EARL::Assumption"):
                    self.element_doc(assumption.location)
                    self.emit(expressions.text(assumption.expression))

    def state(self, state: State, own: str, names: _SubsystemNames) -> None:
        with self.block(f"state {name_text(own)} : EARL::FSMState"):
            self.element_doc(state.location)
            behaviour = names.get(state.behaviour, None, Kind.BASIC_BEHAVIOUR)
            if behaviour is not None:
                self.emit(f"do {name_text(behaviour)};")
            if state.obligatory:
                self.emit(f":>> obligatory = {_sequence([names.resolve(r) for r in state.obligatory])};")
            if state.optional:
                self.emit(f":>> optional = {_sequence([names.resolve(r) for r in state.optional])};")
            if state.timeout is not None:
                self.emit(f"attribute :>> timeout = {_duration(state.timeout)}; // {_duration_text(state.timeout)}")

    def transition(
        self,
        transition: Transition,
        states: dict[str, str],
        named: _Named,
        expressions: ExpressionWriter,
    ) -> None:
        source = states.get(transition.source or "", transition.source or "")
        destination = states.get(transition.destination, transition.destination)
        # Table 5 names a transition by its states: a second `one -> two` is `one_two_t_2`, with no short name.
        self.emit(f"transition {named.declaration}")
        self.depth += 1
        self.emit(f"first {name_text(source)}")
        self.emit(f"if {expressions.text(transition.condition.expression)}")
        # always a body: the doc carries the comment and the line, with or without a priority
        with self.block(f"then {name_text(destination)}"):
            self.element_doc(transition.location, *self.declared_transition(transition))
            if transition.priority is not None:
                self.emit(f"@EARL::TransitionPriority {{ priority = {transition.priority}; }}")
        self.depth -= 1

    def declared_transition(self, transition: Transition) -> tuple[str, ...]:
        """`* -> x` is declared once and exported once per state: say so."""
        location = transition.location
        for agent in self.declared.agents:
            for subsystem in agent.subsystems:
                if subsystem.fsm is None:
                    continue
                for declared in subsystem.fsm.transitions:
                    if declared.location == location and location is not None and declared.source is None:
                        return (f"Declared as `* -> {declared.destination}`, one transition from every other state.",)
        return ()

    # ------------------------------------------------------------------ links (§2.3)
    def link(self, link: Link, owner: Agent | None) -> None:
        resolved = next((r for r in self.context.links if r.link is link), None)
        declaration = self.link_declarations[id(link)]
        # A system's links are its `links`; an agent's are between its subsystems and subset nothing.
        definition = "EARL::InterAgentLink :> links" if owner is None else "EARL::InterSubsystemLink"
        source = self.link_end(link.source.agent, link.source.subsystem, link.source.buffer, Kind.OUTPUT_BUFFER, owner)
        target = self.link_end(
            link.destination.agent, link.destination.subsystem, link.destination.buffer, Kind.INPUT_BUFFER, owner
        )
        payload = ""
        if resolved is not None:
            payload = f" of {self.shape(resolved.source_buffer.data_type)[0]}"
        self.emit(f"flow {declaration} : {definition}{payload}")
        self.depth += 1
        self.emit(f"from {source}")
        with self.block(f"to {target}"):
            self.element_doc(link.location, *self.member_note(link.family is not None, link.index))
        self.depth -= 1

    def link_end(
        self,
        agent: ElementReference | None,
        subsystem: ElementReference,
        buffer: ElementReference,
        kind: Kind,
        owner: Agent | None,
    ) -> str:
        parts = []
        if agent is not None:
            agent_key = _earl_name(agent.name, _index_of(agent), Kind.AGENT)
            parts.append(self.agent_names.get(agent_key, readable(agent_key)))
        else:
            assert owner is not None, "a system-level link names the agents at its ends"
            agent_key = _earl_name(owner.name, owner.index, Kind.AGENT)
        scope = self.scopes.get((agent_key, _subsystem_key(subsystem.name, _index_of(subsystem), subsystem.kind)))
        if scope is None:
            # Resolution guarantees the ends exist; names are rebuilt only for a system that skipped it.
            parts.append(readable(_earl_name(subsystem.name, _index_of(subsystem), subsystem.kind)))
            parts.append(readable(_earl_name(buffer.name, _index_of(buffer), kind)))
        else:
            parts.append(scope[0])
            parts.append(scope[1].name(buffer.name, _index_of(buffer), kind))
        return ".".join(name_text(part) for part in [*parts, "msg"])


def _size_text(array: ArrayType) -> str:
    size = array.size
    if isinstance(size, Literal):
        return literal(size.value)
    return expression_text(size) if size is not None else "*"


def _duration_text(duration: Duration) -> str:
    value = duration.value
    return f"{value} {duration.unit}"


def _parameter_value(parameter: Parameter) -> Value:
    value = parameter.value
    return value.value if isinstance(value, Literal) else str(value)


def _sequence(names: list[str]) -> str:
    texts = [name_text(n) for n in names]
    return texts[0] if len(texts) == 1 else "(" + ", ".join(texts) + ")"


def _declaration(own: str, earl_name: str) -> str:
    return name_text(own) if own == earl_name else f"<{quoted(earl_name)}> {name_text(own)}"


def _robot_refers_to(reference: ElementReference, link: Link) -> bool:
    declared = link.name_text
    base = ",".join(part.name for part in link.name)
    return reference.name in (declared, base)


class _SubsystemNames:
    """The SysML name of every buffer, memory, predicate, function and behaviour of one subsystem."""

    def __init__(self) -> None:
        self._names: dict[tuple[str, int | None, Kind], str] = {}
        self._types: dict[tuple[str, int | None, Kind], DataType] = {}

    def add(self, name: str, index: int | None, kind: Kind, sysml_name: str, data_type: DataType | None = None) -> None:
        self._names[(name, index, _memory_kind(kind))] = sysml_name
        if data_type is not None:
            self._types[(name, index, _memory_kind(kind))] = data_type

    def data_type(self, reference: ElementReference) -> DataType | None:
        """The data type of the buffer or memory `reference` names, for reading into it."""
        return self._types.get((reference.name, _index_of(reference), _memory_kind(reference.kind)))

    def get(self, name: str, index: int | None, kind: Kind) -> str | None:
        return self._names.get((name, index, _memory_kind(kind)))

    def name(self, name: str, index: int | None, kind: Kind) -> str:
        found = self.get(name, index, kind)
        return found if found is not None else readable(_earl_name(name, index, kind))

    def resolve(self, reference: ElementReference) -> str:
        return self.name(reference.name, _index_of(reference), reference.kind)


def _clause_comments_by_location(system: System) -> dict[SourceLocation, dict[str, Comments]]:
    """The comments at the clauses of every declared subsystem, basic behaviour, FSM and state, by where the
    element was written: as `_comments_by_location`, because expansion keeps locations, not comments."""
    table: dict[SourceLocation, dict[str, Comments]] = {}

    def keep(element: Subsystem | BasicBehaviour | FSM | State) -> None:
        if element.location is not None and element.clause_comments:
            table[element.location] = element.clause_comments

    for agent in system.agents:
        for subsystem in agent.subsystems:
            keep(subsystem)
            for behaviour in subsystem.basic_behaviours:
                keep(behaviour)
            if subsystem.fsm is not None:
                keep(subsystem.fsm)
                for state in subsystem.fsm.states:
                    keep(state)
    return table


def _comments_by_location(system: System) -> dict[SourceLocation, Comments]:
    """Comments of every declared element, by where it was written: expansion keeps locations, not comments."""
    table: dict[SourceLocation, Comments] = {}

    def keep(element: object) -> None:
        location = getattr(element, "location", None)
        comments = getattr(element, "comments", None)
        if location is not None and isinstance(comments, Comments):
            table[location] = comments

    top: list[object] = [*system.parameters, *system.types, *system.links]
    for element in top:
        keep(element)
    for robot in system.robots:
        # a robot's members are references in SysML too (`agents = (…)`): their comments go in the robot's doc
        at_members = [
            said
            for key in robot_member_keys(robot)
            if (comments := robot.member_comments.get(key)) is not None
            for said in [*comments.leading, *([comments.trailing] if comments.trailing else [])]
        ]
        own = robot.comments
        if robot.location is not None:
            table[robot.location] = Comments(list(own.leading), own.trailing, [*at_members, *own.closing], own.after)
    for agent in system.agents:
        keep(agent)
        for element in [*agent.parameters, *agent.links]:
            keep(element)
        for subsystem in agent.subsystems:
            keep(subsystem)
            for part in [
                *subsystem.parameters,
                *subsystem.input_buffers,
                *subsystem.output_buffers,
                *subsystem.memories,
                *subsystem.primitive_predicates,
                *subsystem.partial_transition_functions,
                *subsystem.stage_sets,
                *subsystem.basic_behaviours,
            ]:
                keep(part)
            if subsystem.fsm is not None:
                keep(subsystem.fsm)
                for part in [*subsystem.fsm.states, *subsystem.fsm.transitions, *subsystem.fsm.assumptions]:
                    keep(part)
    for definition in system.types:
        if isinstance(definition, StructType):
            for field in definition.fields:
                keep(field)
    return table


__all__ = ["LIBRARY_FILE", "SUBSYSTEM_DEFINITIONS", "export_sysml", "library_text"]
