"""Hypothesis strategies for declared EARL models, for round-trip tests of the formatter.

The models are syntactically complete but need not make sense: names need not
resolve, types need not match.  What they must satisfy is what the grammar can
express, because `parse(format(m)) == m` is only a fair demand for such models:

* names are identifiers but not keywords (`KEYWORDS`); `true`/`false` only where
  the grammar takes them as names (primitive predicates and element references);
* a `BooleanOperation` has two or more operands (one operand prints as the operand);
* a transition function is never one empty stage (`tf = {}` reads back as no stage);
* a link family is declared by exactly one part of the link's name;
* a robot's link is stored as the text of its name, which is how the reader keeps it.
"""

from __future__ import annotations

import operator
import string
from collections.abc import Iterable, Iterator
from typing import Any

from hypothesis import strategies as st
from hypothesis.strategies import DrawFn, SearchStrategy

from earl.model import (
    FSM,
    SUBSYSTEM_CLASSES,
    Agent,
    Arithmetic,
    ArrayType,
    Assumption,
    BasicBehaviour,
    BooleanOperation,
    Call,
    Comparison,
    ControlSubsystem,
    DataType,
    Duration,
    ElementReference,
    Expression,
    Family,
    Field,
    FieldAccess,
    Import,
    IndexAccess,
    InputBuffer,
    Kind,
    Link,
    LinkEnd,
    LinkNamePart,
    ListLiteral,
    Literal,
    Memory,
    Name,
    Negate,
    Not,
    OutputBuffer,
    Parameter,
    PartialTransitionFunction,
    Predicate,
    PrimitivePredicate,
    PrimitiveType,
    PythonImplementation,
    Quantifier,
    Queue,
    Read,
    Robot,
    StageSet,
    Star,
    State,
    StructType,
    Subsystem,
    System,
    Transition,
    TransitionFunction,
    TypeAlias,
    TypeReference,
)
from earl.model.expressions import ARITHMETIC_OPERATORS, COMPARISON_OPERATORS
from earl.model.location import Comments
from earl.model.text import expression_text, robot_member_keys
from earl.model.types import PRIMITIVE_TYPES

#: Every keyword of src/earl/lang/earl.lark (test_roundtrip checks this against the grammar).
KEYWORDS = frozenset(
    {
        "all",
        "and",
        "any",
        "assume",
        "cs",
        "ec",
        "false",
        "fifo",
        "fsm",
        "import",
        "in",
        "initial",
        "link",
        "not",
        "obligatory",
        "optional",
        "or",
        "overflow",
        "param",
        "period",
        "priority",
        "python",
        "stage",
        "state",
        "struct",
        "system",
        "tc",
        "tf",
        "then",
        "timeout",
        "true",
        "type",
        "when",
    }
)

# Names that look like something else to a careless lexer: kind suffixes, time units,
# float words, exponent-like names and keywords with a prefix or suffix.
_TRICKY_NAMES = (
    "a",
    "r",
    "m",
    "s",
    "ms",
    "us",
    "ib",
    "ob",
    "mi",
    "mo",
    "pp",
    "pf",
    "bb",
    "ve",
    "re",
    "vr",
    "rr",
    "t",
    "aa",
    "e",
    "E5",
    "e1",
    "inf",
    "nan",
    "K",
    "N",
    "_",
    "_1",
    "newData",
    "anyway",
    "notice",
    "order",
    "index",
    "true_",
    "False",
    "TRUE",
    "cs2",
    "python3",
    "fsm_",
    "dropOldest",
)

_FIRST = string.ascii_letters + "_"
names: SearchStrategy[str] = st.one_of(
    st.sampled_from(_TRICKY_NAMES),
    st.builds(operator.add, st.sampled_from(_FIRST), st.text(_FIRST + string.digits, max_size=8)),
).filter(lambda name: name not in KEYWORDS)

#: A type name never spells a primitive type: `int` always reads back as a PrimitiveType.
type_names: SearchStrategy[str] = names.filter(lambda name: name not in PRIMITIVE_TYPES)

#: Element references (`false/pp`, `true[1]/ib`) may use the Boolean keywords as names.
reference_names: SearchStrategy[str] = st.one_of(names, st.sampled_from(("true", "false")))

#: The kinds an element reference may carry (`_ref_kind` in the grammar: no `/m`).
REFERENCE_KINDS = (
    Kind.INPUT_BUFFER,
    Kind.OUTPUT_BUFFER,
    Kind.MEMORY_INPUT,
    Kind.MEMORY_OUTPUT,
    Kind.PRIMITIVE_PREDICATE,
    Kind.PARTIAL_TRANSITION_FUNCTION,
    Kind.BASIC_BEHAVIOUR,
)
OTHER_SUBSYSTEM_KINDS = (Kind.VIRTUAL_EFFECTOR, Kind.REAL_EFFECTOR, Kind.VIRTUAL_RECEPTOR, Kind.REAL_RECEPTOR)


# ---------------------------------------------------------------------- expressions
def _tuples(elements: SearchStrategy[Any], min_size: int = 0, max_size: int = 3) -> SearchStrategy[tuple[Any, ...]]:
    return st.lists(elements, min_size=min_size, max_size=max_size).map(tuple)


numbers: SearchStrategy[int | float] = st.one_of(
    st.integers(min_value=-10, max_value=10),
    st.integers(),
    st.floats(allow_nan=False),  # infinities too: `1e999` is a number the reader accepts
    st.sampled_from((0.5, -0.5, 1e-07, 1e16, -2.5e300, 1e-320, 0.1, 100.0)),
)

#: Strings with quotes, backslashes, control characters, line separators and astral characters.
texts: SearchStrategy[str] = st.one_of(
    st.text(max_size=8),
    st.sampled_from(('"', "\\", '\\"', "\n\t\r", "\x00\x7f\x85", "\u2028\u2029", "é ü ß", "日本", "🤖", "//", "")),
)

literals: SearchStrategy[Expression] = st.one_of(
    st.builds(Literal, numbers),
    st.builds(Literal, st.booleans()),
    st.builds(Literal, texts),
)


def element_references(
    indices: SearchStrategy[Expression],
    kinds: tuple[Kind, ...] = REFERENCE_KINDS,
    *,
    star: bool = True,
    max_indices: int = 2,
) -> SearchStrategy[ElementReference]:
    """`name[i][*]/kind`: an element reference as the grammar's `element_ref` reads it."""
    index: SearchStrategy[Expression | Star] = st.one_of(indices, st.builds(Star)) if star else indices
    return st.builds(ElementReference, reference_names, st.sampled_from(kinds), _tuples(index, max_size=max_indices))


def _accessors(indices: SearchStrategy[Expression]) -> SearchStrategy[FieldAccess | IndexAccess]:
    return st.one_of(st.builds(FieldAccess, names), st.builds(IndexAccess, indices))


def reads(indices: SearchStrategy[Expression]) -> SearchStrategy[Expression]:
    return st.builds(Read, element_references(indices), _tuples(_accessors(indices)))


_simple_indices: SearchStrategy[Expression] = st.one_of(
    st.builds(Literal, st.integers(min_value=-3, max_value=20)), st.builds(Name, names)
)

_leaves: SearchStrategy[Expression] = st.one_of(literals, st.builds(Name, names), reads(_simple_indices))


def _compound(children: SearchStrategy[Expression]) -> SearchStrategy[Expression]:
    return st.one_of(
        st.builds(Not, children),
        st.builds(Negate, children),
        st.builds(BooleanOperation, st.sampled_from(("and", "or")), _tuples(children, min_size=2)),
        st.builds(Comparison, st.sampled_from(COMPARISON_OPERATORS), children, children),
        st.builds(Arithmetic, st.sampled_from(ARITHMETIC_OPERATORS), children, children),
        # `newData(x/ib.f)` and `timeout(x/ib)` are the built-ins; the grammar takes any name.
        st.builds(Call, st.one_of(st.sampled_from(("newData", "timeout")), names), _tuples(children)),
        st.builds(Quantifier, st.sampled_from(("any", "all")), names, children, children, children),
        st.builds(ListLiteral, _tuples(children)),
        reads(children),
    )


def expressions(max_leaves: int = 8) -> SearchStrategy[Expression]:
    return st.recursive(_leaves, _compound, max_leaves=max_leaves)


#: Array sizes, family ranges, queue capacities: usually small, sometimes anything.
small_expressions: SearchStrategy[Expression] = st.one_of(_simple_indices, expressions(max_leaves=3))


# ---------------------------------------------------------------------- types
@st.composite
def data_types(draw: DrawFn) -> DataType:
    """`double`, `Cmd`, `double[N][]`, `Cmd[2][K + 1]`: arrays nest to the left."""
    data_type: DataType = draw(
        st.one_of(st.builds(PrimitiveType, st.sampled_from(PRIMITIVE_TYPES)), st.builds(TypeReference, type_names))
    )
    for size in draw(st.lists(st.none() | small_expressions, max_size=3)):
        data_type = ArrayType(data_type, size)
    return data_type


fields: SearchStrategy[Field] = st.builds(Field, names, data_types(), st.booleans())
structs: SearchStrategy[StructType] = st.builds(StructType, type_names, st.lists(fields, max_size=4))
type_aliases: SearchStrategy[TypeAlias] = st.builds(TypeAlias, type_names, data_types())
parameters: SearchStrategy[Parameter] = st.builds(Parameter, names, data_types(), expressions(max_leaves=4))
families: SearchStrategy[Family] = st.builds(Family, names, small_expressions, small_expressions)
optional_families: SearchStrategy[Family | None] = st.none() | families

durations: SearchStrategy[Duration] = st.builds(
    Duration,
    st.one_of(
        st.integers(min_value=1, max_value=10**6),
        # the reader refuses 0, negative durations and those over Duration.MAX_SECONDS (1e9 s)
        st.floats(min_value=0.0, max_value=1e9, exclude_min=True),
    ),
    st.sampled_from(("s", "ms", "us")),
).filter(lambda duration: duration.seconds >= 1e-9)  # and those below 1 ns, which would round to 0 ns


# ---------------------------------------------------------------------- subsystem body
input_buffers: SearchStrategy[InputBuffer] = st.builds(
    InputBuffer,
    names,
    data_types(),
    optional_families,
    st.none() | st.builds(Queue, small_expressions, st.sampled_from(Queue.OVERFLOW_POLICIES)),
)
output_buffers: SearchStrategy[OutputBuffer] = st.builds(OutputBuffer, names, data_types(), optional_families)
memories: SearchStrategy[Memory] = st.builds(
    Memory, names, data_types(), optional_families, st.none() | expressions(max_leaves=6)
)
primitive_predicates: SearchStrategy[PrimitivePredicate] = st.builds(PrimitivePredicate, reference_names, expressions())

_references: SearchStrategy[ElementReference] = element_references(small_expressions)
_reference_lists: SearchStrategy[list[ElementReference]] = st.lists(_references, max_size=2)

partial_transition_functions: SearchStrategy[PartialTransitionFunction] = st.builds(
    PartialTransitionFunction,
    names,
    _reference_lists,
    _reference_lists,
    st.none() | st.builds(PythonImplementation, st.one_of(texts, st.just("pick_and_place.manip:joint_move"))),
)
stage_sets: SearchStrategy[StageSet] = st.builds(StageSet, names, _reference_lists)

# A lone empty stage prints as `tf = {}`, which reads back as a behaviour with no stage.
_stages = st.lists(_reference_lists, max_size=3).filter(lambda stages: stages != [[]])
basic_behaviours: SearchStrategy[BasicBehaviour] = st.builds(
    BasicBehaviour,
    names,
    st.builds(TransitionFunction, _stages),
    st.builds(Predicate, expressions(max_leaves=6)),
    st.none() | st.builds(Predicate, expressions(max_leaves=6)),
)

states: SearchStrategy[State] = st.builds(
    State,
    names,
    reference_names,  # `state s: false/bb` is an element reference, so `false` may name a behaviour
    _reference_lists,
    _reference_lists,
    st.none() | durations,
)
transitions: SearchStrategy[Transition] = st.builds(
    Transition,
    st.none() | names,  # None is `* -> …`
    names,
    st.builds(Predicate, expressions(max_leaves=8)),
    st.none() | st.integers(min_value=0, max_value=10**9),
)
fsms: SearchStrategy[FSM] = st.builds(
    FSM,
    names,
    st.lists(states, max_size=3),
    st.lists(transitions, max_size=3),
    st.lists(st.builds(Assumption, expressions(max_leaves=6)), max_size=2),
)


@st.composite
def subsystems(draw: DrawFn) -> Subsystem:
    """Any of the five kinds; `cs` is never a family (the grammar has no way to write one)."""
    kind = draw(st.sampled_from(list(SUBSYSTEM_CLASSES)))
    subsystem = (
        ControlSubsystem()
        if kind is Kind.CONTROL_SUBSYSTEM
        else SUBSYSTEM_CLASSES[kind](draw(names), draw(optional_families))
    )
    subsystem.period = draw(st.none() | durations)
    subsystem.parameters = draw(st.lists(parameters, max_size=2))
    subsystem.input_buffers = draw(st.lists(input_buffers, max_size=2))
    subsystem.output_buffers = draw(st.lists(output_buffers, max_size=2))
    subsystem.memories = draw(st.lists(memories, max_size=2))
    subsystem.primitive_predicates = draw(st.lists(primitive_predicates, max_size=2))
    subsystem.partial_transition_functions = draw(st.lists(partial_transition_functions, max_size=2))
    subsystem.stage_sets = draw(st.lists(stage_sets, max_size=2))
    subsystem.basic_behaviours = draw(st.lists(basic_behaviours, max_size=2))
    subsystem.fsm = draw(st.none() | fsms)
    return subsystem


# ---------------------------------------------------------------------- links, agents, robots
_index_lists: SearchStrategy[tuple[Expression, ...]] = _tuples(small_expressions, max_size=2)

agent_references: SearchStrategy[ElementReference] = st.builds(
    ElementReference, names, st.just(Kind.AGENT), _index_lists
)
subsystem_references: SearchStrategy[ElementReference] = st.one_of(
    st.just(ElementReference("cs", Kind.CONTROL_SUBSYSTEM)),
    st.builds(ElementReference, names, st.sampled_from(OTHER_SUBSYSTEM_KINDS), _index_lists),
)


def link_ends(buffer_kind: Kind) -> SearchStrategy[LinkEnd]:
    buffers = st.builds(ElementReference, names, st.just(buffer_kind), _index_lists)
    return st.builds(LinkEnd, st.none() | agent_references, subsystem_references, buffers)


_link_part_names: SearchStrategy[str] = st.one_of(names, st.just("cs"))


@st.composite
def links(draw: DrawFn) -> Link:
    """`link a,b[K in 1..N]: …` — a name of one or two parts; a family is declared by one of them."""
    parts = draw(
        st.lists(st.builds(LinkNamePart, _link_part_names, st.none() | small_expressions), min_size=1, max_size=2)
    )
    family = draw(optional_families)
    if family is not None:
        declaring = draw(st.integers(min_value=0, max_value=len(parts) - 1))
        parts[declaring] = LinkNamePart(parts[declaring].name, Name(family.index), declares_family=True)
    return Link(tuple(parts), draw(link_ends(Kind.OUTPUT_BUFFER)), draw(link_ends(Kind.INPUT_BUFFER)), family)


agents: SearchStrategy[Agent] = st.builds(
    Agent,
    names,
    optional_families,
    st.lists(parameters, max_size=2),
    st.lists(subsystems(), min_size=1, max_size=3),
    st.lists(links(), max_size=2),
)


@st.composite
def _robot_link_references(draw: DrawFn) -> ElementReference:
    """The reader keeps a robot's `link task,manip[2]` as the text of the name."""
    parts = draw(st.lists(st.tuples(_link_part_names, st.none() | small_expressions), min_size=1, max_size=2))
    text = ",".join(name if index is None else f"{name}[{expression_text(index)}]" for name, index in parts)
    return ElementReference(text, Kind.INTER_AGENT_LINK)


robots: SearchStrategy[Robot] = st.builds(
    Robot, names, st.lists(agent_references, max_size=3), st.lists(_robot_link_references(), max_size=2)
)


# ---------------------------------------------------------------------- systems
declarations: SearchStrategy[Any] = st.one_of(parameters, structs, type_aliases, robots, agents, links())


@st.composite
def systems(draw: DrawFn, max_declarations: int = 4) -> System:
    """A whole system; `order` lists the top-level declarations as the formatter prints them."""
    system = System(draw(st.one_of(st.just(""), names)))  # "" is a library file, without `system`
    system.imports = draw(st.lists(st.builds(Import, texts), max_size=2))
    written = draw(st.lists(declarations, max_size=max_declarations))
    # Most of the language is inside agents: every system has one, somewhere among the rest.
    written.insert(draw(st.integers(min_value=0, max_value=len(written))), draw(agents))
    for declaration in written:
        system.order.append(declaration)
        if isinstance(declaration, Parameter):
            system.parameters.append(declaration)
        elif isinstance(declaration, StructType | TypeAlias):
            system.types.append(declaration)
        elif isinstance(declaration, Robot):
            system.robots.append(declaration)
        elif isinstance(declaration, Agent):
            system.agents.append(declaration)
        else:
            system.links.append(declaration)
    return system


def expression_systems(expression: Expression) -> System:
    """The smallest system that holds `expression`: one primitive predicate of one agent's `cs`."""
    control = ControlSubsystem(primitive_predicates=[PrimitivePredicate("p", expression)])
    agent = Agent("a", subsystems=[control])
    return System("s", agents=[agent], order=[agent])


# ---------------------------------------------------------------------- comments
def comment_carriers(system: System) -> Iterator[Any]:
    """Every element that keeps comments, in the order the formatter prints them."""
    yield from system.imports
    for declaration in system.order:
        yield declaration
        if isinstance(declaration, StructType):
            yield from declaration.fields
        elif isinstance(declaration, Agent):
            yield from declaration.parameters
            for subsystem in declaration.subsystems:
                yield subsystem
                yield from subsystem.parameters
                yield from subsystem.input_buffers
                yield from subsystem.output_buffers
                yield from subsystem.memories
                yield from subsystem.primitive_predicates
                yield from subsystem.partial_transition_functions
                yield from subsystem.stage_sets
                yield from subsystem.basic_behaviours
                if subsystem.fsm is not None:
                    yield subsystem.fsm
                    yield from subsystem.fsm.states
                    yield from subsystem.fsm.transitions
                    yield from subsystem.fsm.assumptions
            yield from declaration.links


# Comment text: printable, without line breaks of any kind, never ending in a space
# (the formatter strips trailing space from comments).
_comment_texts: SearchStrategy[str] = st.builds(
    "//{}".format,
    st.text(st.characters(blacklist_categories=("Cc", "Cs", "Zl", "Zp")), max_size=12),
).map(str.rstrip)


@st.composite
def _leading_comments(draw: DrawFn) -> list[str]:
    """Whole-line comments; "" marks a blank line after a comment (never two, never first)."""
    leading: list[str] = []
    for text in draw(st.lists(_comment_texts, min_size=1, max_size=3)):
        leading.append(text)
        if draw(st.booleans()):
            leading.append("")
    return leading


@st.composite
def commented_systems(draw: DrawFn) -> System:
    """A system whose elements carry leading, trailing, header and closing comments."""
    system = draw(systems())
    if system.name:  # only a file with a `system` line has a header
        system.comments.leading = draw(st.lists(_comment_texts, max_size=2))
    system.comments.closing = draw(st.lists(_comment_texts, max_size=2))
    for carrier in comment_carriers(system):
        if draw(st.booleans()):
            carrier.comments.leading = draw(_leading_comments())
        if draw(st.booleans()):
            carrier.comments.trailing = draw(_comment_texts)
        if _written_over_lines(carrier) and draw(st.booleans()):
            carrier.comments.after = draw(_comment_texts)  # after its `}`
    _blank_lines(draw, system)
    return system


def _blank_lines(draw: DrawFn, system: System) -> None:
    """Blank lines a person left inside a group of a body, to group its members further: a "" first in a
    member's leading comments. Never before the first of a group (the first top-level parameter after a
    type, the first memory, the first transition), where `earl fmt` writes a blank line of its own."""

    def maybe(comments: Comments) -> None:
        if draw(st.booleans()):
            comments.leading.insert(0, "")

    def some(later: Iterable[Any]) -> None:
        for element in later:
            maybe(element.comments)

    def maybe_in(table: dict[str, Comments], key: str) -> None:  # a table holds only comments said
        if draw(st.booleans()):
            table.setdefault(key, Comments()).leading.insert(0, "")

    previous: object = None
    for declaration in system.order:
        # one-line declarations of one kind are one group, but for one with comments above it
        one_liner = isinstance(declaration, Parameter | TypeAlias | Link)
        if one_liner and type(declaration) is type(previous) and not declaration.comments.leading:
            maybe(declaration.comments)
        previous = declaration
        if isinstance(declaration, StructType):
            some(declaration.fields[1:])
        elif isinstance(declaration, Robot):
            for key in robot_member_keys(declaration)[1:]:
                maybe_in(declaration.member_comments, key)
        elif isinstance(declaration, Agent):
            some(declaration.parameters[1:])
            some(declaration.links[1:])
            for subsystem in declaration.subsystems:
                some(subsystem.parameters[0 if subsystem.period is not None else 1 :])
                some([*subsystem.input_buffers, *subsystem.output_buffers][1:])
                for group in (
                    subsystem.memories,
                    subsystem.primitive_predicates,
                    subsystem.partial_transition_functions,
                    subsystem.stage_sets,
                ):
                    some(group[1:])
                for behaviour in subsystem.basic_behaviours:
                    for clause in ("tc", "ec") if behaviour.error_condition is not None else ("tc",):
                        maybe_in(behaviour.clause_comments, clause)
                if subsystem.fsm is not None:
                    some(subsystem.fsm.states)  # after `initial`
                    some(subsystem.fsm.transitions[1:])
                    some(subsystem.fsm.assumptions[1:])


def _written_over_lines(carrier: Any) -> bool:
    """A block that `earl fmt` writes with its `}` on a line of its own."""
    if isinstance(carrier, StructType):
        return bool(carrier.fields)
    return isinstance(carrier, Agent | Subsystem | BasicBehaviour | FSM)
