"""From a declared system to its concrete instances.

A spec declares `motorController[K in 1..N]/ve` once, as the manual's Figure 10
draws it once with the letter K.  Checking and execution need every member:
`expand` returns a System in which

- every family is replaced by its members, each keeping the declaration's
  `family` and its own `index` (`motorController[3]/ve` has index 3);
- references name members: `motorControllerState[*]/ib` in a function's reads
  becomes one reference per member, `x[K]/ib` with K known becomes `x[3]/ib`;
- `any(K in 1..N: …)` and `all(…)` are unrolled into `or` / `and`;
- parameters and family indices inside expressions and array sizes are
  replaced by their values, so nothing outside the model is needed to read it.

The input must be a system the resolver accepted; `expand` reports nothing.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import fields, is_dataclass, replace
from typing import Any

from earl.model.elements import (
    FSM,
    Agent,
    BasicBehaviour,
    Family,
    InputBuffer,
    Link,
    LinkEnd,
    LinkNamePart,
    Memory,
    OutputBuffer,
    Parameter,
    PartialTransitionFunction,
    Predicate,
    PrimitivePredicate,
    Queue,
    StageSet,
    State,
    Subsystem,
    System,
    Transition,
    TransitionFunction,
)
from earl.model.expressions import (
    PYTHON_PREDICATE,
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ElementReference,
    Expression,
    IndexAccess,
    ListLiteral,
    Literal,
    Name,
    Negate,
    Not,
    Quantifier,
    Read,
    Star,
    evaluate_constant,
    evaluate_integer,
)
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.types import REAL_TYPES, ArrayType, DataType, StructType, TypeAlias
from earl.model.validate import explaining

Value = bool | int | float | str
Environment = dict[str, Value]
#: The members of each family of one subsystem, by the family's name and kind.
Members = dict[tuple[str, Kind], list[int]]


def _key(reference: ElementReference) -> tuple[str, Kind]:
    """Memory is declared `/m` and referenced as `/mi` or `/mo`: all three name one element."""
    kind = Kind.MEMORY if reference.kind in (Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT) else reference.kind
    return reference.name, kind


def family_members(family: Family, environment: Mapping[str, Value]) -> list[int]:
    first = evaluate_integer(family.first, environment)
    last = evaluate_integer(family.last, environment)
    return list(range(first, last + 1))


def parameter_values(
    parameters: list[Parameter], environment: Mapping[str, Value], overrides: Mapping[str, Value] = {}
) -> Environment:
    """The environment extended by these parameters, in declaration order."""
    result = dict(environment)
    for parameter in parameters:
        value = overrides[parameter.name] if parameter.name in overrides else evaluate_constant(parameter.value, result)
        if getattr(parameter.data_type, "name", "") in REAL_TYPES and isinstance(value, int):
            value = float(value)
        result[parameter.name] = value
    return result


def expand(system: System, overrides: Mapping[str, Value] | None = None) -> System:
    """The concrete system: every family member, every reference resolved to a member. A value of a wrong
    type in a model built in Python (`initial_value = 0.0`) raises ModelTypeError naming where it is."""
    with explaining(system):
        return _expand(system, overrides)


def _expand(system: System, overrides: Mapping[str, Value] | None) -> System:
    environment = parameter_values(system.parameters, {}, overrides or {})
    cache = _Shared()
    expanded = System(
        system.name,
        imports=list(system.imports),
        parameters=[replace(p, value=Literal(environment[p.name], p.value.location)) for p in system.parameters],
        types=[_type_definition(t, environment) for t in system.types],
        location=system.location,
    )
    expanded.source_file = system.source_file
    expanded.sources = system.sources
    expanded.robots = [copy.copy(r) for r in system.robots]
    agent_members: dict[str, list[int] | None] = {}
    for agent in system.agents:
        if agent.family is None:
            agent_members[agent.name] = None
            expanded.agents.append(_agent(agent, environment, None, cache))
        else:
            members = family_members(agent.family, environment)
            agent_members[agent.name] = members
            for index in members:
                inner = {**environment, agent.family.index: index}
                expanded.agents.append(_agent(agent, inner, index, cache))
    #: a link's declared name (`alpha,worker[K in 1..N]`) -> its members' (`alpha,worker[1]`, …)
    link_members: dict[str, list[str]] = {}
    for link in system.links:
        members_of_link = _links(link, environment)
        expanded.links.extend(members_of_link)
        # a family's members; a single link's name with its parameters' values (`alpha,worker[N]`: `[2]`)
        link_members[link.name_text] = [member.name_text for member in members_of_link]
    for robot in expanded.robots:
        robot.agents = [
            member
            for reference in robot.agents
            for member in _members(reference, agent_members.get(reference.name), environment)
        ]
        # a robot that names a link family holds each of its members, as it holds each member of `worker[*]/a`
        robot.links = [
            replace(reference, name=name)
            for reference in robot.links
            for name in link_members.get(reference.name, [reference.name])
        ]
    expanded.order = [*expanded.parameters, *expanded.types, *expanded.agents, *expanded.links, *expanded.robots]
    return expanded


# ---------------------------------------------------------------------- types
def _data_type(data_type: DataType, environment: Mapping[str, Value]) -> DataType:
    if isinstance(data_type, ArrayType):
        size = None if data_type.size is None else Literal(evaluate_integer(data_type.size, environment))
        return ArrayType(_data_type(data_type.element, environment), size, data_type.location)
    return data_type


def _type_definition(definition: Any, environment: Mapping[str, Value]) -> Any:
    if isinstance(definition, StructType):
        fields = [replace(f, data_type=_data_type(f.data_type, environment)) for f in definition.fields]
        return replace(definition, fields=fields)
    assert isinstance(definition, TypeAlias)
    return replace(definition, data_type=_data_type(definition.data_type, environment))


# ---------------------------------------------------------------------- agents and subsystems
class _Shared:
    """What members of a family can share during one expansion.

    Two members of a family differ only where their declaration names a value that
    differs between them (the index, a parameter).  The behaviour of a subsystem — its
    predicates, functions, behaviours and FSM, which the model never changes after
    expansion — is built once for each distinct set of such values and shared; buffers
    and memory stay separate objects per member.  A spec of 10,000 agent family members
    expands several times faster this way.
    """

    def __init__(self) -> None:
        self.names: dict[int, tuple[object, tuple[str, ...]]] = {}
        self.insides: dict[tuple[int, tuple[tuple[str, Value | None], ...]], tuple[Any, ...]] = {}
        self.links: dict[tuple[int, tuple[tuple[str, Value | None], ...]], tuple[Link, list[Link]]] = {}

    def free_names(self, root: object) -> tuple[str, ...]:
        """Every parameter or index name a declaration mentions anywhere inside it."""
        cached = self.names.get(id(root))
        if cached is not None and cached[0] is root:
            return cached[1]
        names: set[str] = set()
        stack: list[object] = [root]
        seen: set[int] = set()
        while stack:
            node = stack.pop()
            if isinstance(node, Name):
                names.add(node.name)
            elif isinstance(node, Family):
                names.add(node.index)
                stack.extend((node.first, node.last))
            elif isinstance(node, Quantifier):
                names.add(node.index)
                stack.extend((node.first, node.last, node.body))
            elif isinstance(node, (str, int, float, bool, type(None), SourceLocation, Kind)) or id(node) in seen:
                continue
            else:
                seen.add(id(node))
                if isinstance(node, (list, tuple)):
                    stack.extend(node)
                else:
                    stack.extend(getattr(node, name) for name in _field_names(type(node)))
        result = tuple(sorted(names))
        self.names[id(root)] = (root, result)
        return result

    def key(self, root: object, environment: Mapping[str, Value]) -> tuple[int, tuple[tuple[str, Value | None], ...]]:
        return id(root), tuple((name, environment.get(name)) for name in self.free_names(root))


#: the field names of each model class, for walking a declaration (dataclasses.fields is slow to ask)
_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def _field_names(cls: type) -> tuple[str, ...]:
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = tuple(f.name for f in fields(cls)) if is_dataclass(cls) else ()
    return names


def _agent(agent: Agent, environment: Environment, index: int | None, cache: _Shared) -> Agent:
    inner = parameter_values(agent.parameters, environment)
    result = Agent(
        agent.name,
        agent.family,
        parameters=[replace(p, value=Literal(inner[p.name], p.value.location)) for p in agent.parameters],
        location=agent.location,
        index=index,
    )
    members: dict[tuple[str, str], list[int] | None] = {}
    for subsystem in agent.subsystems:
        key = (subsystem.name, subsystem.kind.value)
        if subsystem.family is None:
            members[key] = None
            result.subsystems.append(_subsystem(subsystem, inner, None, cache))
        else:
            indices = family_members(subsystem.family, inner)
            members[key] = indices
            for member in indices:
                sub_environment = {**inner, subsystem.family.index: member}
                result.subsystems.append(_subsystem(subsystem, sub_environment, member, cache))
    for link in agent.links:
        link_key = cache.key(link, inner)
        shared = cache.links.get(link_key)
        if shared is None or shared[0] is not link:
            shared = cache.links[link_key] = (link, _links(link, inner))
        result.links.extend(shared[1])
    return result


def _subsystem(subsystem: Subsystem, environment: Environment, index: int | None, cache: _Shared) -> Subsystem:
    inner = parameter_values(subsystem.parameters, environment)
    members: Members = {}
    result = type(subsystem)(
        subsystem.name,
        subsystem.family,
        period=subsystem.period,
        parameters=[replace(p, value=Literal(inner[p.name], p.value.location)) for p in subsystem.parameters],
        location=subsystem.location,
        index=index,
    )
    for buffer in subsystem.input_buffers:
        for member in _family(buffer, inner, members):
            queue = buffer.queue
            if queue is not None:
                queue = Queue(Literal(evaluate_integer(queue.capacity, inner)), queue.overflow)
            result.input_buffers.append(
                InputBuffer(
                    buffer.name,
                    _data_type(buffer.data_type, inner),
                    buffer.family,
                    queue,
                    buffer.location,
                    index=member,
                )
            )
    for output in subsystem.output_buffers:
        for member in _family(output, inner, members):
            result.output_buffers.append(
                OutputBuffer(
                    output.name, _data_type(output.data_type, inner), output.family, output.location, index=member
                )
            )
    for memory in subsystem.memories:
        for member in _family(memory, inner, members):
            own = inner if memory.family is None or member is None else {**inner, memory.family.index: member}
            initial = None if memory.initial_value is None else _expression(memory.initial_value, own, members)
            result.memories.append(
                Memory(
                    memory.name,
                    _data_type(memory.data_type, inner),
                    memory.family,
                    initial,
                    memory.location,
                    index=member,
                )
            )
    key = cache.key(subsystem, inner)
    shared = cache.insides.get(key)
    if shared is not None and shared[0] is subsystem:
        (
            _,
            result.primitive_predicates,
            result.partial_transition_functions,
            result.stage_sets,
            result.basic_behaviours,
            result.fsm,
        ) = shared
        return result
    context = _Context(inner, members)
    result.primitive_predicates = [
        PrimitivePredicate(
            p.name,
            context.expression(p.expression),
            p.location,
            reads=context.references(p.reads),
            implementation=p.implementation,
        )
        for p in subsystem.primitive_predicates
    ]
    result.partial_transition_functions = [
        PartialTransitionFunction(
            f.name, context.references(f.reads), context.references(f.writes), f.implementation, f.location
        )
        for f in subsystem.partial_transition_functions
    ]
    result.stage_sets = [StageSet(s.name, list(s.functions), s.location) for s in subsystem.stage_sets]
    result.basic_behaviours = [
        BasicBehaviour(
            b.name,
            TransitionFunction([list(stage) for stage in b.transition_function.stages], b.transition_function.location),
            context.predicate(b.terminal_condition),
            None if b.error_condition is None else context.predicate(b.error_condition),
            b.location,
        )
        for b in subsystem.basic_behaviours
    ]
    if subsystem.fsm is not None:
        result.fsm = context.fsm(subsystem.fsm)
    cache.insides[key] = (
        subsystem,
        result.primitive_predicates,
        result.partial_transition_functions,
        result.stage_sets,
        result.basic_behaviours,
        result.fsm,
    )
    return result


def _family(element: Any, environment: Environment, members: Members) -> list[int | None]:
    if element.family is None:
        return [None]
    indices = family_members(element.family, environment)
    members[(element.name, element.kind)] = indices
    return list(indices)


class _Context:
    """Expands references and expressions of one subsystem member."""

    def __init__(self, environment: Environment, members: Members) -> None:
        self.environment = environment
        self.members = members

    def expression(self, expression: Expression) -> Expression:
        return _expression(expression, self.environment, self.members)

    def predicate(self, predicate: Predicate) -> Predicate:
        return Predicate(self.expression(predicate.expression), predicate.location)

    def references(self, references: list[ElementReference]) -> list[ElementReference]:
        return [
            member
            for reference in references
            for member in _members(reference, self.members.get(_key(reference)), self.environment)
        ]

    def fsm(self, fsm: FSM) -> FSM:
        result = FSM(fsm.initial, location=fsm.location, initial_location=fsm.initial_location)
        result.states = [
            State(
                s.name,
                s.behaviour,
                self.references(s.obligatory),
                self.references(s.optional),
                s.timeout,
                s.location,
                behaviour_location=s.behaviour_location,
            )
            for s in fsm.states
        ]
        result.transitions = [
            Transition(
                t.source,
                t.destination,
                self.predicate(t.condition),
                t.priority,
                t.location,
                from_any_state=t.from_any_state,
            )
            for t in fsm.concrete_transitions()
        ]
        result.assumptions = [replace(a, expression=self.expression(a.expression)) for a in fsm.assumptions]
        return result


def _members(
    reference: ElementReference, members: list[int] | None, environment: Mapping[str, Value]
) -> list[ElementReference]:
    """`x[*]/ib` → one reference per member; `x[K]/ib` → `x[3]/ib`; a plain reference unchanged."""
    if not reference.indices:
        return [reference]
    index = reference.indices[0]
    # built directly: dataclasses.replace costs several times more, and this runs for every reference
    if isinstance(index, Star):
        return [
            ElementReference(reference.name, reference.kind, (Literal(member),), reference.location)
            for member in members or []
        ]
    return [
        ElementReference(
            reference.name, reference.kind, (Literal(evaluate_integer(index, environment)),), reference.location
        )
    ]


def _links(link: Link, environment: Environment) -> list[Link]:
    if link.family is None:
        return [_link(link, environment, None)]
    return [
        _link(link, {**environment, link.family.index: member}, member)
        for member in family_members(link.family, environment)
    ]


def _link(link: Link, environment: Environment, member: int | None) -> Link:
    name = tuple(
        LinkNamePart(part.name, None if part.index is None else Literal(evaluate_integer(part.index, environment)))
        for part in link.name
    )
    source = _link_end(link.source, environment)
    destination = _link_end(link.destination, environment)
    return Link(name, source, destination, link.family, link.location, index=member)


def _link_end(end: LinkEnd, environment: Mapping[str, Value]) -> LinkEnd:
    def concrete(reference: ElementReference | None) -> ElementReference | None:
        if reference is None or not reference.indices:
            return reference
        return _members(reference, None, environment)[0]

    agent = concrete(end.agent)
    subsystem = concrete(end.subsystem)
    buffer = concrete(end.buffer)
    assert subsystem is not None and buffer is not None
    return LinkEnd(agent, subsystem, buffer, end.location)


# ---------------------------------------------------------------------- expressions
def _filled(operator: str, left: Expression, right: Expression, location: SourceLocation | None) -> Expression | None:
    """`[0.0] * N` (or `N * [0.0]`), with `N` now a number: the list repeated, an array's initial value
    sized by a parameter. None when it is no such product, or the count is no whole number of 0 or
    more (the initial value's check then says what it is)."""
    if operator != "*":
        return None
    items, count = (left, right) if isinstance(left, ListLiteral) else (right, left)
    if not isinstance(items, ListLiteral) or not isinstance(count, Literal):
        return None
    times = count.value
    if isinstance(times, bool) or not isinstance(times, int) or times < 0:
        return None
    return ListLiteral(items.items * times, location)


def _expression(expression: Expression, environment: Mapping[str, Value], members: Members) -> Expression:
    """Parameters and indices replaced by values; `any`/`all` unrolled; references made concrete."""
    if isinstance(expression, Literal):
        return expression
    if isinstance(expression, Name):
        if expression.name in environment:
            return Literal(environment[expression.name], expression.location)
        return expression
    if isinstance(expression, ListLiteral):
        return ListLiteral(tuple(_expression(i, environment, members) for i in expression.items), expression.location)
    if isinstance(expression, Read):
        target = _members(expression.target, members.get(_key(expression.target)), environment)[0]
        path = tuple(
            IndexAccess(_expression(a.index, environment, members), a.location) if isinstance(a, IndexAccess) else a
            for a in expression.path
        )
        return Read(target, path, expression.location)
    if isinstance(expression, Call) and expression.function == PYTHON_PREDICATE:
        # the reads of a predicate computed by Python: `x[*]/ib` is every member, as in a function's reads
        expanded: list[Expression] = []
        for argument in expression.arguments:
            if isinstance(argument, Read) and not argument.path:
                targets = _members(argument.target, members.get(_key(argument.target)), environment)
                expanded.extend(Read(target, (), argument.location) for target in targets)
            else:
                expanded.append(_expression(argument, environment, members))
        return Call(expression.function, tuple(expanded), expression.location)
    if isinstance(expression, Call):
        arguments = tuple(_expression(a, environment, members) for a in expression.arguments)
        return Call(expression.function, arguments, expression.location)
    if isinstance(expression, Not):
        return Not(_expression(expression.operand, environment, members), expression.location)
    if isinstance(expression, Negate):
        return Negate(_expression(expression.operand, environment, members), expression.location)
    if isinstance(expression, BooleanOperation):
        operands = tuple(_expression(o, environment, members) for o in expression.operands)
        return BooleanOperation(expression.operator, operands, expression.location)
    if isinstance(expression, Comparison):
        return Comparison(
            expression.operator,
            _expression(expression.left, environment, members),
            _expression(expression.right, environment, members),
            expression.location,
        )
    if isinstance(expression, Arithmetic):
        left = _expression(expression.left, environment, members)
        right = _expression(expression.right, environment, members)
        filled = _filled(expression.operator, left, right, expression.location)
        if filled is not None:
            return filled
        return Arithmetic(expression.operator, left, right, expression.location)
    if isinstance(expression, Quantifier):
        first = evaluate_integer(expression.first, environment)
        last = evaluate_integer(expression.last, environment)
        bodies = tuple(
            _expression(expression.body, {**environment, expression.index: value}, members)
            for value in range(first, last + 1)
        )
        if not bodies:
            # an empty `any` is false and an empty `all` true, as in logic
            return Literal(expression.quantifier == "all", expression.location)
        if len(bodies) == 1:
            return bodies[0]
        operator = "or" if expression.quantifier == "any" else "and"
        return BooleanOperation(operator, bodies, expression.location, expression)
    raise TypeError(f"not an expression: {expression!r}")
