"""Builds the declared model elements of one `.earl` file, one method per grammar rule.

The methods are called while the LALR parser reduces (see `reductions.py`): each gets
the span of text its rule covered and the rule's children (tokens, and what the
methods of the inner rules returned).  The parser's own stack is a list, so a deeply
nested expression cannot exhaust Python's stack here; depth is still measured and
refused above a bound so that nothing later in the pipeline can.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from typing import Any

from lark import Token

from earl.diagnostics import Diagnostic, Severity
from earl.lang.reductions import Span
from earl.lang.syntax_errors import said_twice
from earl.model.elements import (
    FSM,
    SUBSYSTEM_CLASSES,
    Agent,
    Assumption,
    BasicBehaviour,
    ControlSubsystem,
    Duration,
    Family,
    Import,
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
    PythonImplementation,
    Queue,
    Robot,
    StageSet,
    State,
    Subsystem,
    Transition,
    TransitionFunction,
    default_link_name,
)
from earl.model.expressions import (
    PYTHON_PREDICATE,
    Arithmetic,
    BooleanOperation,
    Call,
    Comparison,
    ElementReference,
    Expression,
    FieldAccess,
    IndexAccess,
    ListLiteral,
    Literal,
    Name,
    Negate,
    Not,
    Quantifier,
    Read,
    Star,
)
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.text import family_text
from earl.model.types import (
    MAX_ARRAY_DIMENSIONS,
    PRIMITIVE_TYPES,
    ArrayType,
    DataType,
    Field,
    PrimitiveType,
    StructType,
    TypeAlias,
    TypeReference,
)

#: a suffix's Kind by its text: `Kind(text)` looks it up through Enum's Python-level machinery,
#: and a large spec has a hundred thousand references
_KIND_OF_SUFFIX: dict[str, Kind] = {kind.value: kind for kind in Kind}


def _kind(suffix: str) -> Kind:
    return _KIND_OF_SUFFIX.get(suffix) or Kind(suffix)  # Kind(...) explains an unknown suffix


#: Deeper expressions are refused: no person writes them, and they would exhaust the stack.
MAX_EXPRESSION_DEPTH = 100


class SpecificationSyntaxError(Exception):
    """A problem found while building the tree into elements (e.g. an expression nested too deep)."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


@dataclass
class ParsedFile:
    """The declarations of one file, in the order written."""

    path: str
    system_name: str | None
    system_location: SourceLocation | None
    declarations: list[Any] = field(default_factory=list)
    closing_comments: list[str] = field(default_factory=list)
    header_comments: list[str] = field(default_factory=list)


@dataclass(slots=True)
class _DeclaredName:
    name: str
    family: Family | None


@dataclass(slots=True)
class _BodyItem:
    """A `period` or buffer-group line, before it is placed in its subsystem or state."""

    what: str
    value: Any
    location: SourceLocation | None = None


#: What a method gets as `meta`: the span its rule covered, or one token.
Meta = Span | Token | None

#: The source of `* -> state`, until the transition is built (its model value is None).
_ANY_STATE = object()


def _location(path: str, meta: Meta) -> SourceLocation:
    if isinstance(meta, Token):
        line = meta.line or 1
        column = meta.column or 1
        return SourceLocation(path, line, column, meta.end_line or line, meta.end_column or column + 1)
    if meta is None:
        return SourceLocation(path, 1, 1, 1, 1)
    return SourceLocation(path, *meta)


class ElementBuilder:
    """One method per grammar rule; each returns a model element or a piece of one."""

    def __init__(self, path: str) -> None:
        self.path = path
        self._depth: dict[int, int] = {}

    def reset(self, path: str) -> None:
        """Start on another file."""
        self.path = path
        self._depth.clear()

    def _string(self, token: Token) -> str:
        return _string_value(token, self.path)

    def _loc(self, meta: Meta) -> SourceLocation:
        if type(meta) is tuple:  # a rule's span: most of the 300,000 locations of a large spec
            return SourceLocation(self.path, *meta)
        return _location(self.path, meta)

    # ------------------------------------------------------------------ file
    def start(self, meta: Meta, children: list[Any]) -> ParsedFile:
        name: str | None = None
        location: SourceLocation | None = None
        declarations = list(children)
        if declarations and isinstance(declarations[0], tuple) and declarations[0][0] == "system":
            _, name, location = declarations.pop(0)
        return ParsedFile(self.path, name, location, declarations)

    def system_header(self, meta: Meta, children: list[Token]) -> tuple[str, str, SourceLocation]:
        return ("system", str(children[0]), self._loc(children[0]))

    def import_decl(self, meta: Meta, children: list[Token]) -> Import:
        return Import(self._string(children[0]), self._loc(meta))

    def parameter(self, meta: Meta, children: list[Any]) -> Parameter:
        name, data_type, value = children
        return Parameter(str(name), data_type, value, self._loc(meta))

    # ------------------------------------------------------------------ types
    def type_alias(self, meta: Meta, children: list[Any]) -> TypeAlias:
        return TypeAlias(str(children[0]), children[1], self._loc(meta))

    def struct_decl(self, meta: Meta, children: list[Any]) -> StructType:
        return StructType(str(children[0]), list(children[1:]), self._loc(meta))

    def struct_field(self, meta: Meta, children: list[Any]) -> Field:
        return Field(str(children[0]), children[1], len(children) > 2, self._loc(meta))

    def named_type(self, meta: Meta, children: list[Token]) -> DataType:
        name = str(children[0])
        if name in PRIMITIVE_TYPES:
            return PrimitiveType(name, self._loc(meta))
        return TypeReference(name, self._loc(meta))

    def fixed_array(self, meta: Meta, children: list[Any]) -> ArrayType:
        return self._array(ArrayType(children[0], children[1], self._loc(meta)))

    def variable_array(self, meta: Meta, children: list[Any]) -> ArrayType:
        return self._array(ArrayType(children[0], None, self._loc(meta)))

    def _array(self, array: ArrayType) -> ArrayType:
        # `int[1][1]…` thousands deep would exhaust the stack of every recursive walk over types.
        depth = 1 + self._depth.get(id(array.element), 0)
        if depth > MAX_ARRAY_DIMENSIONS:
            raise SpecificationSyntaxError(
                Diagnostic(
                    Severity.ERROR,
                    f"this array type has more than {MAX_ARRAY_DIMENSIONS} dimensions",
                    array.location,
                    code="EARL-S017",
                    hint="flatten the dimensions (`double[N * M]`), or group them in a struct",
                )
            )
        self._depth[id(array)] = depth
        return array

    # ------------------------------------------------------------------ system
    def robot(self, meta: Meta, children: list[Any]) -> Robot:
        name, _kind, *members = children
        robot = Robot(self._single(name, "Robot"), location=self._loc(meta))
        for member in members:
            (robot.links if member.kind is Kind.INTER_AGENT_LINK else robot.agents).append(member)
        return robot

    def robot_agent(self, meta: Meta, children: list[Any]) -> ElementReference:
        indices = tuple(self._star_or(index) for index in children[1:-1])
        return ElementReference(str(children[0]), Kind.AGENT, indices, self._loc(meta))

    def _star_or(self, index: Any) -> Any:
        """`[*]` as the model's Star, any other index as the expression it is."""
        return Star(self._loc(index)) if isinstance(index, Token) and index.type == "STAR" else index

    def robot_link(self, meta: Meta, children: list[Any]) -> ElementReference:
        parts, family = children[0]
        # a link family is named as it is declared (`alpha,worker[K in 1..N]`), the way `name_text` writes it
        text = ",".join(
            p.name
            if p.index is None
            else family_text(p.name, family)
            if family is not None and p.declares_family
            else f"{p.name}[{_index_source(p.index)}]"
            for p in parts
        )
        return ElementReference(text, Kind.INTER_AGENT_LINK, (), self._loc(meta))

    def agent(self, meta: Meta, children: list[Any]) -> Agent:
        declared: _DeclaredName = children[0]
        agent = Agent(declared.name, declared.family, location=self._loc(meta))
        for member in children[2:]:
            if isinstance(member, Parameter):
                agent.parameters.append(member)
            elif isinstance(member, Subsystem):
                agent.subsystems.append(member)
            else:
                agent.links.append(member)
        return agent

    def declared_name(self, meta: Meta, children: list[Any]) -> _DeclaredName:
        family = children[1] if len(children) > 1 else None
        return _DeclaredName(str(children[0]), family)

    def family(self, meta: Meta, children: list[Any]) -> Family:
        return Family(str(children[0]), children[1], children[2], self._loc(meta))

    def link(self, meta: Meta, children: list[Any]) -> Link:
        if len(children) == 3:
            (parts, family), source, destination = children
        else:
            source, destination = children
            parts, family = None, None
        source_end = _link_end(source, Kind.OUTPUT_BUFFER)
        destination_end = _link_end(destination, Kind.INPUT_BUFFER)
        name = tuple(parts) if parts is not None else default_link_name(source_end, destination_end)
        return Link(name, source_end, destination_end, family, self._loc(meta))

    def link_name(self, meta: Meta, children: list[Any]) -> tuple[list[LinkNamePart], Family | None]:
        parts: list[LinkNamePart] = []
        family: Family | None = None
        for name, index in children:
            if isinstance(index, Family):
                if family is not None:
                    raise SpecificationSyntaxError(
                        Diagnostic(
                            Severity.ERROR,
                            "a link family declares one index; the other part of its name uses it",
                            index.location,
                            code="EARL-S010",
                            hint=f"write `[{family.index}]` instead of a second `[... in ...]`",
                        )
                    )
                family = index
                parts.append(LinkNamePart(name, Name(index.index, index.location), declares_family=True))
            else:
                parts.append(LinkNamePart(name, index))
        return parts, family

    def link_name_part(self, meta: Meta, children: list[Any]) -> tuple[str, Any]:
        return str(children[0]), children[1] if len(children) > 1 else None

    def link_end(self, meta: Meta, children: list[Any]) -> dict[str, Any]:
        agent = children[0] if isinstance(children[0], ElementReference) and children[0].kind is Kind.AGENT else None
        rest = children[1:] if agent is not None else children
        subsystem, buffer_name, *indices = rest
        return {
            "agent": agent,
            "subsystem": subsystem,
            "buffer": (str(buffer_name), tuple(indices), self._loc(buffer_name)),
            "location": self._loc(meta),
        }

    def agent_ref(self, meta: Meta, children: list[Any]) -> ElementReference:
        return ElementReference(str(children[0]), Kind.AGENT, tuple(children[1:-1]), self._loc(meta))

    def control_subsystem_ref(self, meta: Meta, children: list[Any]) -> ElementReference:
        return ElementReference("cs", Kind.CONTROL_SUBSYSTEM, (), self._loc(meta))

    def subsystem_ref(self, meta: Meta, children: list[Any]) -> ElementReference:
        return ElementReference(str(children[0]), _kind(str(children[-1])), tuple(children[1:-1]), self._loc(meta))

    # ------------------------------------------------------------------ subsystems
    def subsystem(self, meta: Meta, children: list[Any]) -> Subsystem:
        head = children[0]
        if isinstance(head, Token) and head.type == "CS":
            return self._fill(ControlSubsystem(location=self._loc(meta)), children[1:])
        declared: _DeclaredName = head
        cls = SUBSYSTEM_CLASSES[_kind(str(children[1]))]
        subsystem = cls(declared.name, declared.family, location=self._loc(meta))
        return self._fill(subsystem, children[2:])

    def _fill(self, subsystem: Subsystem, items: list[Any]) -> Subsystem:
        period: _BodyItem | None = None
        for item in items:
            if isinstance(item, _BodyItem):
                # the grammar takes the body's lines in any order and number; a second period would
                # silently win, and `earl fmt` would drop the first
                _refuse_second(period, item, f" in `{subsystem.name}`")
                period = item
                subsystem.period = item.value
                subsystem.period_location = item.location
            elif isinstance(item, Parameter):
                subsystem.parameters.append(item)
            elif isinstance(item, InputBuffer):
                subsystem.input_buffers.append(item)
            elif isinstance(item, OutputBuffer):
                subsystem.output_buffers.append(item)
            elif isinstance(item, Memory):
                subsystem.memories.append(item)
            elif isinstance(item, PrimitivePredicate):
                subsystem.primitive_predicates.append(item)
            elif isinstance(item, PartialTransitionFunction):
                subsystem.partial_transition_functions.append(item)
            elif isinstance(item, StageSet):
                subsystem.stage_sets.append(item)
            elif isinstance(item, BasicBehaviour):
                subsystem.basic_behaviours.append(item)
            elif isinstance(item, FSM):
                if subsystem.fsm is not None:
                    raise SpecificationSyntaxError(
                        Diagnostic(
                            Severity.ERROR,
                            f"`{subsystem.name}` declares a second `fsm`; a Subsystem has exactly one FSM",
                            item.location,
                            code="EARL-S011",
                            hint="put all states and transitions in one `fsm { … }` block",
                        )
                    )
                subsystem.fsm = item
        return subsystem

    def period(self, meta: Meta, children: list[Any]) -> _BodyItem:
        return _BodyItem("period", children[0], self._loc(meta))

    def duration(self, meta: Meta, children: list[Token]) -> Duration:
        number = _number(children[0], self.path)
        if number <= 0:
            raise self._duration_error(children[0], f"a duration must be positive, not {children[0]}")
        duration = Duration(number, str(children[1]))
        try:
            too_long = not duration.seconds <= Duration.MAX_SECONDS
        except OverflowError:  # an int of hundreds of digits, times a float
            too_long = True
        if too_long:
            raise self._duration_error(
                children[0],
                f"a duration is at most {Duration.MAX_SECONDS:,.0f} s (about 31 years), not "
                f"{_number_text(children[0])} {children[1]}",
            )
        if duration.seconds < 1e-9:  # time is kept in whole nanoseconds: it would round to 0, an instant for ever
            raise self._duration_error(
                children[0],
                f"a duration is at least 1 ns (earl keeps time in whole nanoseconds), not {_number_text(children[0])} "
                f"{children[1]}",
            )
        return duration

    def _duration_error(self, number: Token, message: str) -> SpecificationSyntaxError:
        return SpecificationSyntaxError(Diagnostic(Severity.ERROR, message, self._loc(number), code="EARL-S012"))

    def input_buffer(self, meta: Meta, children: list[Any]) -> InputBuffer:
        declared: _DeclaredName = children[0]
        queue = children[3] if len(children) > 3 else None
        return InputBuffer(declared.name, children[2], declared.family, queue, self._loc(meta))

    def queue(self, meta: Meta, children: list[Any]) -> Queue:
        if len(children) > 1:
            policy = str(children[1])
            if policy not in Queue.OVERFLOW_POLICIES:
                choices = ", ".join(f"`{p}`" for p in Queue.OVERFLOW_POLICIES)
                raise SpecificationSyntaxError(
                    Diagnostic(
                        Severity.ERROR,
                        f"unknown overflow policy `{policy}`",
                        self._loc(children[1]),
                        code="EARL-S013",
                        hint=f"choose one of {choices}",
                    )
                )
            return Queue(children[0], policy)
        return Queue(children[0])

    def output_buffer(self, meta: Meta, children: list[Any]) -> OutputBuffer:
        declared: _DeclaredName = children[0]
        return OutputBuffer(declared.name, children[2], declared.family, self._loc(meta))

    def memory(self, meta: Meta, children: list[Any]) -> Memory:
        declared: _DeclaredName = children[0]
        initial = children[3] if len(children) > 3 else None
        return Memory(declared.name, children[2], declared.family, initial, self._loc(meta))

    def _single(self, declared: _DeclaredName | Token, what: str) -> str:
        """The name of an element that cannot be an indexed family."""
        if isinstance(declared, Token):
            return str(declared)
        if declared.family is not None:
            raise SpecificationSyntaxError(
                Diagnostic(
                    Severity.ERROR,
                    f"a {what} cannot be an indexed family",
                    declared.family.location,
                    code="EARL-S016",
                    hint=f"declare one `{declared.name}` and use `any(...)`/`all(...)` or `[*]` inside it",
                )
            )
        return declared.name

    def primitive_predicate(self, meta: Meta, children: list[Any]) -> PrimitivePredicate:
        return PrimitivePredicate(self._single(children[0], "Primitive Predicate"), children[2], self._loc(meta))

    def python_primitive_predicate(self, meta: Meta, children: list[Any]) -> PrimitivePredicate:
        name, _kind, reads, implementation = children
        location = self._loc(meta)
        expression = Call(PYTHON_PREDICATE, tuple(Read(r, (), r.location) for r in reads), location)
        return PrimitivePredicate(
            self._single(name, "Primitive Predicate"),
            expression,
            location,
            reads=list(reads),
            implementation=implementation,
        )

    def partial_transition_function(self, meta: Meta, children: list[Any]) -> PartialTransitionFunction:
        name, _kind, reads, writes, *implementation = children
        return PartialTransitionFunction(
            self._single(name, "Partial Transition Function"),
            reads,
            writes,
            implementation[0] if implementation else None,
            self._loc(meta),
        )

    def pf_reads(self, meta: Meta, children: list[ElementReference]) -> list[ElementReference]:
        return list(children)

    def pf_writes(self, meta: Meta, children: list[ElementReference]) -> list[ElementReference]:
        return list(children)

    def reference_list(self, meta: Meta, children: list[ElementReference]) -> list[ElementReference]:
        return list(children)

    def implementation(self, meta: Meta, children: list[Token]) -> PythonImplementation:
        return PythonImplementation(self._string(children[0]))

    def stage_set(self, meta: Meta, children: list[Any]) -> StageSet:
        return StageSet(str(children[0]), children[1], self._loc(meta))

    def pf_set(self, meta: Meta, children: list[ElementReference]) -> list[ElementReference]:
        return list(children)

    def basic_behaviour(self, meta: Meta, children: list[Any]) -> BasicBehaviour:
        name, _kind, transition_function, terminal, *error = children
        return BasicBehaviour(
            self._single(name, "Basic Behaviour"),
            transition_function,
            terminal,
            error[0] if error else None,
            self._loc(meta),
        )

    def transition_function(self, meta: Meta, children: list[Any]) -> TransitionFunction:
        stages = list(children)
        if stages == [[]]:
            stages = []  # `tf = {}`: a behaviour that computes nothing
        return TransitionFunction(stages, self._loc(meta))

    def terminal_condition(self, meta: Meta, children: list[Any]) -> Predicate:
        return Predicate(children[0], self._loc(meta))

    def error_condition(self, meta: Meta, children: list[Any]) -> Predicate:
        return Predicate(children[0], self._loc(meta))

    # ------------------------------------------------------------------ FSM
    def fsm(self, meta: Meta, children: list[Any]) -> FSM:
        (initial, initial_location), *items = children
        fsm = FSM(initial, location=self._loc(meta), initial_location=initial_location)
        for item in items:
            if isinstance(item, State):
                fsm.states.append(item)
            elif isinstance(item, Transition):
                fsm.transitions.append(item)
            else:
                fsm.assumptions.append(item)
        return fsm

    def initial_state(self, meta: Meta, children: list[Token]) -> tuple[str, SourceLocation]:
        return str(children[0]), self._loc(children[0])

    def state(self, meta: Meta, children: list[Any]) -> State:
        name, behaviour, *group = children
        state = State(str(name), behaviour.name, location=self._loc(meta), behaviour_location=behaviour.location)
        if behaviour.kind is not Kind.BASIC_BEHAVIOUR:
            raise SpecificationSyntaxError(
                Diagnostic(
                    Severity.ERROR,
                    f"state `{name}` must name a Basic Behaviour (`/bb`), not `/{behaviour.kind.value}`",
                    behaviour.location,
                    code="EARL-S014",
                    hint=f"write `state {name}: {behaviour.name}/bb`",
                )
            )
        timeout: _BodyItem | None = None
        for item in group[0] if group else []:
            if item.what == "obligatory":
                state.obligatory.extend(item.value)
            elif item.what == "optional":
                state.optional.extend(item.value)
            else:
                _refuse_second(timeout, item, f" in state `{name}`")
                timeout = item
                state.timeout = item.value
                state.timeout_location = item.location
        return state

    def buffer_group(self, meta: Meta, children: list[_BodyItem]) -> list[_BodyItem]:
        return list(children)

    def obligatory(self, meta: Meta, children: list[Any]) -> _BodyItem:
        return _BodyItem("obligatory", children[0])

    def optional(self, meta: Meta, children: list[Any]) -> _BodyItem:
        return _BodyItem("optional", children[0])

    def state_timeout(self, meta: Meta, children: list[Any]) -> _BodyItem:
        return _BodyItem("timeout", children[0], self._loc(meta))

    def transition(self, meta: Meta, children: list[Any]) -> Transition:
        source, destination, condition, *priority = children
        return Transition(
            None if source is _ANY_STATE else str(source),
            str(destination),
            Predicate(condition, condition.location),
            int(priority[0]) if priority else None,
            self._loc(meta),
            source_location=self._loc(source) if isinstance(source, Token) else None,
            destination_location=self._loc(destination) if isinstance(destination, Token) else None,
        )

    def transition_source(self, meta: Meta, children: list[Token]) -> Token:
        return children[0]  # the name and where it is (`Transition.source_location`)

    def any_state(self, meta: Meta, children: list[Token]) -> object:
        return _ANY_STATE

    def assumption(self, meta: Meta, children: list[Any]) -> Assumption:
        return Assumption(children[0], self._loc(meta))

    # ------------------------------------------------------------------ expressions
    def element_ref(self, meta: Meta, children: list[Any]) -> ElementReference:
        name, *indices, kind = children
        converted = tuple(self._star_or(index) for index in indices)
        return ElementReference(str(name), _kind(str(kind)), converted, self._loc(meta))

    def _expression(self, node: Expression, children: list[Any]) -> Expression:
        depth = 1 + max((self._depth.get(id(c), 0) for c in children), default=0)
        if depth > MAX_EXPRESSION_DEPTH:
            raise SpecificationSyntaxError(
                Diagnostic(
                    Severity.ERROR,
                    f"this expression is nested more than {MAX_EXPRESSION_DEPTH} levels deep",
                    node.location,
                    code="EARL-S015",
                    hint="split it into several primitive predicates",
                )
            )
        self._depth[id(node)] = depth
        return node

    def expression(self, meta: Meta, children: list[Any]) -> Expression:
        return self._expression(BooleanOperation("or", tuple(children), self._loc(meta)), children)

    def and_expression(self, meta: Meta, children: list[Any]) -> Expression:
        return self._expression(BooleanOperation("and", tuple(children), self._loc(meta)), children)

    def not_(self, meta: Meta, children: list[Any]) -> Expression:
        return self._expression(Not(children[0], self._loc(meta)), children)

    def comparison(self, meta: Meta, children: list[Any]) -> Expression:
        left, operator, right = children
        return self._expression(Comparison(str(operator), left, right, self._loc(meta)), [left, right])

    def sum(self, meta: Meta, children: list[Any]) -> Expression:
        return self._fold(meta, children)

    def product(self, meta: Meta, children: list[Any]) -> Expression:
        return self._fold(meta, children)

    def _fold(self, meta: Meta, children: list[Any]) -> Expression:
        result: Expression = children[0]
        for operator, operand in zip(children[1::2], children[2::2], strict=False):
            location = _span(result.location, operand.location) or self._loc(meta)
            result = self._expression(Arithmetic(str(operator), result, operand, location), [result, operand])
        return result

    def negate(self, meta: Meta, children: list[Any]) -> Expression:
        return self._expression(Negate(children[1], self._loc(meta)), children[1:])

    def read(self, meta: Meta, children: list[Any]) -> Expression:
        target, *path = children
        return self._expression(
            Read(target, tuple(path), self._loc(meta)), [a.index for a in path if isinstance(a, IndexAccess)]
        )

    def field_access(self, meta: Meta, children: list[Token]) -> FieldAccess:
        return FieldAccess(str(children[0]), self._loc(children[0]))

    def index_access(self, meta: Meta, children: list[Any]) -> IndexAccess:
        return IndexAccess(children[0], self._loc(meta))

    def number(self, meta: Meta, children: list[Token]) -> Expression:
        return Literal(_number(children[0], self.path), self._loc(meta))

    def string(self, meta: Meta, children: list[Token]) -> Expression:
        return Literal(self._string(children[0]), self._loc(meta))

    def true(self, meta: Meta, children: list[Token]) -> Expression:
        return Literal(True, self._loc(meta))

    def false(self, meta: Meta, children: list[Token]) -> Expression:
        return Literal(False, self._loc(meta))

    def name(self, meta: Meta, children: list[Token]) -> Expression:
        return Name(str(children[0]), self._loc(meta))

    def call(self, meta: Meta, children: list[Any]) -> Expression:
        function, *arguments = children
        return self._expression(Call(str(function), tuple(arguments), self._loc(meta)), arguments)

    def quantifier(self, meta: Meta, children: list[Any]) -> Expression:
        kind, index, first, last, body = children
        node = Quantifier(str(kind), str(index), first, last, body, self._loc(meta))
        return self._expression(node, [first, last, body])

    def list_literal(self, meta: Meta, children: list[Any]) -> Expression:
        return self._expression(ListLiteral(tuple(children), self._loc(meta)), children)


def _refuse_second(first: _BodyItem | None, second: _BodyItem, where: str) -> None:
    """EARL-S009 when `second` repeats a clause said once (`period`, a state's `timeout`)."""
    if first is None or first.location is None or second.location is None:
        return
    raise SpecificationSyntaxError(said_twice(second.what, where, first.location.line, second.location))


def _span(first: SourceLocation | None, last: SourceLocation | None) -> SourceLocation | None:
    if first is None or last is None:
        return None
    return SourceLocation(first.file, first.line, first.column, last.end_line, last.end_column)


#: digits of a whole number read at most: Python refuses to convert longer ones, and no type holds them
MAX_NUMBER_DIGITS = 4000


def _number(token: Token, path: str) -> int | float:
    text = str(token)
    if any(c in text for c in ".eE"):
        return float(text)  # beyond a double's range: infinity, as `1e999` is written (model/text.py)
    if len(text) > MAX_NUMBER_DIGITS:  # Python would refuse to read it, and no EARL type holds it
        raise SpecificationSyntaxError(
            Diagnostic(
                Severity.ERROR,
                f"the whole number {_number_text(token)} has more digits than any EARL number type holds",
                _location(path, token),
                code="EARL-S019",
                hint="an int64 holds 19 digits, a uint64 20; `1e999` is infinity",
            )
        )
    return int(text)


def _number_text(token: Token) -> str:
    """A literal as a message quotes it: a thousand digits are shortened."""
    text = str(token)
    return f"`{text}`" if len(text) <= 40 else f"`{text[:20]}…` ({len(text)} characters)"


#: what a string may hold after a backslash, for the message when it holds something else
_STRING_ESCAPES = '`\\"`, `\\\\`, `\\/`, `\\b`, `\\f`, `\\n`, `\\r`, `\\t` and `\\uXXXX`'


def _string_value(token: Token, path: str) -> str:
    """The text a string literal stands for: its escapes are JSON's (docs/language.md)."""
    text = str(token)
    try:
        value = json.loads(text)
        value.encode("utf-8")  # a lone surrogate (`\ud800`) would fail every file written later
    except json.JSONDecodeError as error:
        # json points at a bad escape's backslash, but at the `u` of a short `\\u` escape
        start = error.pos - 1 if error.msg.startswith("Invalid \\uXXXX") else error.pos
        column = (token.column or 1) + start
        if error.msg.startswith("Invalid control character"):
            message = f"a string cannot hold the control character U+{ord(text[start]):04X} as it is"
            hint = "write it as an escape: `\\t` for a tab, `\\u00XX` for any other"
            width = 1
        else:
            escape = text[start : start + (6 if text[start + 1 : start + 2] == "u" else 2)].rstrip('"')
            message = f"`{escape}` is not an escape a string can hold"
            hint = f"a string takes the escapes of JSON: {_STRING_ESCAPES} (four hexadecimal digits)"
            width = len(escape)
        location = SourceLocation(path, token.line or 1, column, token.line or 1, column + width)
        raise SpecificationSyntaxError(
            Diagnostic(Severity.ERROR, message, location, code="EARL-S018", hint=hint)
        ) from None
    except UnicodeEncodeError as error:
        raise SpecificationSyntaxError(
            Diagnostic(
                Severity.ERROR,
                f"this string holds half of a surrogate pair (`\\u{ord(value[error.start]):04x}`), which is no character",
                _location(path, token),
                code="EARL-S018",
                hint="write the character itself, or both halves of its pair (`\\ud83d\\ude00`)",
            )
        ) from None
    return str(value)


def _index_source(index: Expression) -> str:
    from earl.model.text import expression_text

    return expression_text(index)


def _link_end(end: dict[str, Any], buffer_kind: Kind) -> LinkEnd:
    name, indices, location = end["buffer"]
    buffer = ElementReference(name, buffer_kind, indices, location)
    return LinkEnd(end["agent"], end["subsystem"], buffer, end["location"])


def with_location(element: Any, location: SourceLocation) -> Any:
    return replace(element, location=location)


__all__ = ["MAX_EXPRESSION_DEPTH", "ElementBuilder", "ParsedFile", "SpecificationSyntaxError"]
