"""The structure and behaviour of an EARL system (manual §2, Figures 2–6).

These classes hold a specification *as declared*: an indexed family such as
`motorController[K in 1..N]/ve` is one element with a `Family`, exactly as the
manual's Figure 10 draws it once with the letter K.  `earl.model.expand` turns a
declared system into its concrete instances for checking and execution.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from earl.model.equality import sequences_compare_equal
from earl.model.expressions import PYTHON_PREDICATE, Call, ElementReference, Expression, Read, Star
from earl.model.frozen import quick_init
from earl.model.kinds import Kind
from earl.model.location import Comments, SourceLocation, comments_field, location_field
from earl.model.types import DataType, TypeDefinition


@quick_init
@dataclass(frozen=True, slots=True)
class Family:
    """`[K in 1..N]`: an element declared once for every value of its index."""

    index: str
    first: Expression
    last: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class Duration:
    """A period or timeout as written (`2 ms`); `seconds` is its value."""

    value: int | float
    unit: str  # "s" | "ms" | "us"

    UNITS: ClassVar[dict[str, float]] = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
    #: the longest period, timeout or run: about 31 years, beyond any run and well inside what the
    #: runtime's integer nanoseconds and a float's exact range hold
    MAX_SECONDS: ClassVar[float] = 1e9

    @property
    def seconds(self) -> float:
        return self.value * self.UNITS[self.unit]


def duration_problems(subsystem: Subsystem) -> list[tuple[str, str, SourceLocation | None]]:
    """`(what, problem, where)` for the subsystem's period and each state's timeout that
    `duration_problem` refuses: `("the period", "is -2 ms; it must be …", location)`."""
    durations = [("the period", subsystem.period, subsystem.period_location or subsystem.location)]
    if subsystem.fsm is not None:
        durations += [
            (f"the timeout of state `{state.name}`", state.timeout, state.timeout_location or state.location)
            for state in subsystem.fsm.states
        ]
    found = []
    for what, duration, location in durations:
        problem = None if duration is None else duration_problem(duration)
        if problem is not None:
            found.append((what, problem, location))
    return found


def is_duration(duration: object) -> bool:
    """Whether `duration` is a Duration of a number (`timeout=0.05` and `Duration("20", "ms")` are not)."""
    return (
        isinstance(duration, Duration)
        and isinstance(duration.value, int | float)
        and not isinstance(duration.value, bool)
    )


def duration_problem(duration: object) -> str | None:
    """What keeps `duration` from being a period or timeout, in words, or None: a unit other than
    `s`, `ms`, `us`, no number, or a length under 1 ns (time is kept in whole nanoseconds) or over
    `Duration.MAX_SECONDS`. The reader refuses these as it reads; a model built in Python is asked."""
    if not isinstance(duration, Duration):
        return f'is {duration!r}, not a Duration such as `Duration(2, "ms")`'
    if duration.unit not in Duration.UNITS:
        return f"is in `{duration.unit}`; the units are {', '.join(Duration.UNITS)}"
    if isinstance(duration.value, bool) or not isinstance(duration.value, int | float):
        return f"is {duration.value!r} {duration.unit}, not a number"
    if not 1e-9 <= duration.seconds <= Duration.MAX_SECONDS:
        return f"is {duration.value:g} {duration.unit}; it must be at least 1 ns and at most 10⁹ s"
    return None


@dataclass
class Parameter:
    """`param N: int = 6`: a named constant, visible in its block and the blocks inside it."""

    name: str
    data_type: DataType
    value: Expression
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


@quick_init
@dataclass(frozen=True, slots=True)
class Queue:
    """An Input Buffer that keeps a FIFO of messages instead of only the latest one."""

    capacity: Expression
    overflow: str = "dropOldest"  # "dropOldest" | "dropNewest" | "fault"

    OVERFLOW_POLICIES: ClassVar[tuple[str, ...]] = ("dropOldest", "dropNewest", "fault")


@dataclass
class InputBuffer:
    """`manipulatorCommand/ib: ManipulatorCommand` — receives messages over a Link (§2.2)."""

    name: str
    data_type: DataType
    family: Family | None = None
    queue: Queue | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None
    kind: ClassVar[Kind] = Kind.INPUT_BUFFER


@dataclass
class OutputBuffer:
    """`manipulatorState/ob: ManipulatorState` — sent to the connected Input Buffers (§2.2)."""

    name: str
    data_type: DataType
    family: Family | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None
    kind: ClassVar[Kind] = Kind.OUTPUT_BUFFER


@dataclass
class Memory:
    """`motionFinished/m: boolean = true` — Internal Memory (§2.2, Table 3)."""

    name: str
    data_type: DataType
    family: Family | None = None
    initial_value: Expression | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None
    kind: ClassVar[Kind] = Kind.MEMORY


@dataclass
class PrimitivePredicate:
    """`newJointPos/pp = newData(manipulatorCommand/ib.jointPosSetpoint)` (Table 4).

    A predicate too involved for an expression is computed by Python code:
    `graspStable/pp(fingerState/ib, grip/mi) = python "gripping:stable"`.  Then
    `implementation` names the code, `reads` what it takes its arguments from (Figure 6),
    and `expression` is `python(fingerState/ib, grip/mi)`: a Boolean that depends on those
    reads, which is all the checker needs to know of it.
    """

    name: str
    expression: Expression
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    reads: list[ElementReference] = field(default_factory=list)
    implementation: PythonImplementation | None = None
    kind: ClassVar[Kind] = Kind.PRIMITIVE_PREDICATE

    @classmethod
    def python(
        cls, name: str, reads: list[ElementReference], implementation: PythonImplementation | str
    ) -> PrimitivePredicate:
        """`graspStable/pp(fingerState/ib, grip/mi) = python "gripping:stable"`, as the reader builds it:
        `PrimitivePredicate.python("graspStable", [ElementReference("fingerState", "ib"), …], "gripping:stable")`.
        """
        if isinstance(implementation, str):
            implementation = PythonImplementation(implementation)
        return cls(name, python_expression(reads), reads=list(reads), implementation=implementation)

    @property
    def python_problem(self) -> str | None:
        """Why this predicate's `implementation`, `reads` and `expression` do not say one thing, or None.

        A predicate computed by Python is written `NAME/pp(READS) = python "…"`: the text holds the reads
        and the code, not an expression, so an expression other than `python(READS)` would be lost on
        save, and the run would call the code where the check read the expression (or the reverse)."""
        if self.implementation is None:
            return None
        expected = python_expression(self.reads)
        if self.expression == expected:
            return None
        return (
            f"is computed by Python (`implementation={self.implementation.path!r}`) but its expression is not "
            f"`python(…)` over its `reads`"
        )


def python_expression(reads: list[ElementReference] | tuple[ElementReference, ...]) -> Expression:
    """The expression of a primitive predicate computed by Python: `python(fingerState/ib, grip/mi)`, a
    Boolean that depends on what it reads."""
    return Call(PYTHON_PREDICATE, tuple(Read(reference) for reference in reads))


@dataclass
class Predicate:
    """A Boolean formula over primitive predicates: an initial, terminal or error condition."""

    expression: Expression
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class PythonImplementation:
    """`python "pick_and_place.manip:joint_move"`: where the runtime finds the code.

    The colon is the only separator: `robot.arm.move` could be the module `robot.arm.move` as well as
    the function `move` of `robot.arm`, so it names no function (EARL-E044, EARL-X001)."""

    path: str

    @property
    def module(self) -> str:
        return self.path.partition(":")[0]

    @property
    def function(self) -> str:
        return self.path.partition(":")[2]


@dataclass
class PartialTransitionFunction:
    """`jointMove/pf(ib …, mi … -> mo …, ob …)` (§2.2, Figure 6).

    `reads` lists Input Buffers (`/ib`) and memory read through `mi`; `writes`
    lists memory written through `mo` and Output Buffers (`/ob`).  The
    implementation is optional: a spec that is only checked and documented needs none.
    """

    name: str
    reads: list[ElementReference] = field(default_factory=list)
    writes: list[ElementReference] = field(default_factory=list)
    implementation: PythonImplementation | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    kind: ClassVar[Kind] = Kind.PARTIAL_TRANSITION_FUNCTION


@dataclass
class StageSet:
    """`stage pf = { … }`: a set of Partial Transition Functions of one stage (Eq. 4 and 6)."""

    name: str
    functions: list[ElementReference] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


@dataclass
class TransitionFunction:
    """`tf = { a/pf, b/pf } then { c/pf }`: stages in order, the functions of a stage as if in parallel."""

    stages: list[list[ElementReference]] = field(default_factory=list)
    location: SourceLocation | None = location_field()

    @property
    def partial_transition_functions(self) -> list[ElementReference]:
        return [function for stage in self.stages for function in stage]


@dataclass
class BasicBehaviour:
    """`jointMove/bb { tf = …  tc = …  ec = … }` (§2.2, Figure 5b)."""

    name: str
    transition_function: TransitionFunction
    terminal_condition: Predicate
    error_condition: Predicate | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: the comments at its `tf`, `tc` and `ec` lines, so that `earl fmt` keeps them there
    clause_comments: dict[str, Comments] = field(default_factory=dict, compare=False, repr=False)
    kind: ClassVar[Kind] = Kind.BASIC_BEHAVIOUR


@dataclass
class State:
    """An FSM State and its Basic Behaviour, with the buffers it waits for.

    Obligatory Input Buffers are received with a blocking wait bounded by
    `timeout`; the others are polled (FABRIC's buffer groups).
    """

    name: str
    behaviour: str
    obligatory: list[ElementReference] = field(default_factory=list)
    optional: list[ElementReference] = field(default_factory=list)
    timeout: Duration | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    behaviour_location: SourceLocation | None = location_field()
    #: where `timeout …` is written, for messages about it
    timeout_location: SourceLocation | None = location_field()
    #: the comments at the lines of its body (`obligatory`, `optional`, `timeout`), keyed by the clause
    #: and the line's number among that clause's lines (`obligatory 0`), so that `earl fmt` keeps them
    clause_comments: dict[str, Comments] = field(default_factory=dict, compare=False, repr=False)


@dataclass
class Transition:
    """`idle -> jointMove when …` — the manual's `idle,jointMove/t` with its initial condition.

    `source` is None for `* -> emergencyStop`: a transition from every other state
    (Table 5's `i,emergencyStop/t where i ≠ emergencyStop`).  `priority` 1 is
    evaluated first; transitions without a priority come after all that have one.
    """

    source: str | None
    destination: str
    condition: Predicate
    priority: int | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: one of the transitions a `*` line stands for (`concrete_transitions`), named in messages as written
    from_any_state: bool = field(default=False, compare=False, repr=False)
    #: where the source and destination states are named, for a message about either
    source_location: SourceLocation | None = location_field()
    destination_location: SourceLocation | None = location_field()
    kind: ClassVar[Kind] = Kind.TRANSITION

    @property
    def name(self) -> str:
        return f"{self.source or '*'},{self.destination}"


@dataclass
class Assumption:
    """`assume not (a/pp and b/pp)`: a fact about the environment the FSM may rely on."""

    expression: Expression
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


@dataclass
class FSM:
    """The Finite State Machine of a Subsystem (§2.2, Figure 5a)."""

    initial: str
    states: list[State] = field(default_factory=list)
    transitions: list[Transition] = field(default_factory=list)
    assumptions: list[Assumption] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: where `initial NAME` names the initial state, for messages about it
    initial_location: SourceLocation | None = location_field()
    #: the comments at its `initial` line, so that `earl fmt` keeps them there
    clause_comments: dict[str, Comments] = field(default_factory=dict, compare=False, repr=False)

    def state_named(self, name: str) -> State | None:
        return next((state for state in self.states if state.name == name), None)

    def concrete_transitions(self) -> list[Transition]:
        """The transitions with `*` replaced by one transition per other state."""
        result: list[Transition] = []
        for transition in self.transitions:
            if transition.source is not None:
                result.append(transition)
                continue
            for state in self.states:
                if state.name != transition.destination:
                    result.append(
                        Transition(
                            state.name,
                            transition.destination,
                            transition.condition,
                            transition.priority,
                            transition.location,
                            from_any_state=True,
                        )
                    )
        return result


@dataclass
class Subsystem:
    """What every kind of Subsystem has (§2.2, Figure 3)."""

    name: str
    family: Family | None = None
    period: Duration | None = None
    parameters: list[Parameter] = field(default_factory=list)
    input_buffers: list[InputBuffer] = field(default_factory=list)
    output_buffers: list[OutputBuffer] = field(default_factory=list)
    memories: list[Memory] = field(default_factory=list)
    primitive_predicates: list[PrimitivePredicate] = field(default_factory=list)
    partial_transition_functions: list[PartialTransitionFunction] = field(default_factory=list)
    stage_sets: list[StageSet] = field(default_factory=list)
    basic_behaviours: list[BasicBehaviour] = field(default_factory=list)
    fsm: FSM | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None
    #: where `period …` is written, for messages about it
    period_location: SourceLocation | None = location_field()
    #: the comments at its `period` line, so that `earl fmt` keeps them there
    clause_comments: dict[str, Comments] = field(default_factory=dict, compare=False, repr=False)
    kind: ClassVar[Kind]

    def input_buffer(self, name: str) -> InputBuffer | None:
        return next((b for b in self.input_buffers if b.name == name), None)

    def output_buffer(self, name: str) -> OutputBuffer | None:
        return next((b for b in self.output_buffers if b.name == name), None)

    def memory(self, name: str) -> Memory | None:
        return next((m for m in self.memories if m.name == name), None)

    def primitive_predicate(self, name: str) -> PrimitivePredicate | None:
        return next((p for p in self.primitive_predicates if p.name == name), None)

    def partial_transition_function(self, name: str) -> PartialTransitionFunction | None:
        return next((p for p in self.partial_transition_functions if p.name == name), None)

    def basic_behaviour(self, name: str) -> BasicBehaviour | None:
        return next((b for b in self.basic_behaviours if b.name == name), None)


@dataclass
class ControlSubsystem(Subsystem):
    """`cs`: coordinates the Agent's Subsystems and talks to other Agents; exactly one per Agent."""

    name: str = "cs"
    kind: ClassVar[Kind] = Kind.CONTROL_SUBSYSTEM


@dataclass
class VirtualEffector(Subsystem):
    """`ve`: supervises a Real Effector, e.g. a motor position regulator."""

    kind: ClassVar[Kind] = Kind.VIRTUAL_EFFECTOR


@dataclass
class RealEffector(Subsystem):
    """`re`: affects the environment, e.g. one drive of a joint."""

    kind: ClassVar[Kind] = Kind.REAL_EFFECTOR


@dataclass
class VirtualReceptor(Subsystem):
    """`vr`: aggregates what a Real Receptor gathers before it reaches the Control Subsystem."""

    kind: ClassVar[Kind] = Kind.VIRTUAL_RECEPTOR


@dataclass
class RealReceptor(Subsystem):
    """`rr`: an exteroceptor gathering information from the environment."""

    kind: ClassVar[Kind] = Kind.REAL_RECEPTOR


SUBSYSTEM_CLASSES: dict[Kind, type[Subsystem]] = {
    Kind.CONTROL_SUBSYSTEM: ControlSubsystem,
    Kind.VIRTUAL_EFFECTOR: VirtualEffector,
    Kind.REAL_EFFECTOR: RealEffector,
    Kind.VIRTUAL_RECEPTOR: VirtualReceptor,
    Kind.REAL_RECEPTOR: RealReceptor,
}


@quick_init
@dataclass(frozen=True, slots=True)
class LinkEnd:
    """One end of a Link: `task/a.cs.manipulatorCommand` or, inside an agent, `cs.motorControllerCommand[K]`.

    `agent` is None for an end inside the agent that declares the link.  `buffer`
    has kind `ob` at the source and `ib` at the destination.
    """

    agent: ElementReference | None
    subsystem: ElementReference
    buffer: ElementReference
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class LinkNamePart:
    """One side of a link's name; in `cs,motorController[K in 1..N]` the second part declares the family."""

    name: str
    index: Expression | None = None
    declares_family: bool = False


def default_link_name(source: LinkEnd, destination: LinkEnd) -> tuple[LinkNamePart, ...]:
    """The name of a link declared without one (§2.5): `source,destination`, agent names between agents,
    subsystem names inside one, each with the index its end is written with (`cs,mc[2]`, `s[K],v[1]`)."""
    parts = []
    for end in (source, destination):
        reference = end.agent or end.subsystem
        index = reference.indices[0] if len(reference.indices) == 1 else None
        parts.append(LinkNamePart(reference.name, None if isinstance(index, Star) else index))
    return tuple(parts)


@dataclass
class Link:
    """A unidirectional Link from an Output Buffer to an Input Buffer (§2.3).

    Its name joins the source and destination with a comma (`task,manip`, §2.5).
    Declared at system level it is an inter-agent Link `aa`; inside an agent it
    links two of that agent's Subsystems.
    """

    name: tuple[LinkNamePart, ...]
    source: LinkEnd
    destination: LinkEnd
    family: Family | None = None
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None

    @property
    def name_text(self) -> str:
        from earl.model.text import link_name_text

        return link_name_text(self)


@dataclass
class Agent:
    """`manip/a { … }`: an Embodied Agent with exactly one Control Subsystem (§2.1)."""

    name: str
    family: Family | None = None
    parameters: list[Parameter] = field(default_factory=list)
    subsystems: list[Subsystem] = field(default_factory=list)
    links: list[Link] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: In an expanded system, which member of `family` this element is (see earl.model.expand).
    index: int | None = None
    kind: ClassVar[Kind] = Kind.AGENT

    @property
    def control_subsystems(self) -> list[ControlSubsystem]:
        return [s for s in self.subsystems if isinstance(s, ControlSubsystem)]

    @property
    def control_subsystem(self) -> ControlSubsystem | None:
        found = self.control_subsystems
        return found[0] if found else None

    def subsystems_of(self, kind: Kind) -> list[Subsystem]:
        return [s for s in self.subsystems if s.kind is kind]

    def subsystem(self, name: str, kind: Kind) -> Subsystem | None:
        return next((s for s in self.subsystems if s.name == name and s.kind is kind), None)


@dataclass
class Robot:
    """`manipulationRobot/r { task/a  manip/a  link task,manip }`: a group of Agents (§2.1)."""

    name: str
    agents: list[ElementReference] = field(default_factory=list)
    links: list[ElementReference] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: the comments written at each member (`a/a`, `link b,a`), so that `earl fmt` keeps them there: a
    #: member is a reference, which carries none of its own
    member_comments: dict[str, Comments] = field(default_factory=dict, compare=False, repr=False)
    kind: ClassVar[Kind] = Kind.ROBOT


@dataclass
class Import:
    """`import "types.earl"`: declarations shared from another file."""

    path: str
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


Declaration = Parameter | TypeDefinition | Robot | Agent | Link


@dataclass
class System:
    """The most general EARL concept: Robots, Agents and the Links between them (§2.1)."""

    name: str
    imports: list[Import] = field(default_factory=list)
    parameters: list[Parameter] = field(default_factory=list)
    types: list[TypeDefinition] = field(default_factory=list)
    robots: list[Robot] = field(default_factory=list)
    agents: list[Agent] = field(default_factory=list)
    links: list[Link] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()
    #: The order in which top-level declarations were written, so printing keeps it.
    order: list[Declaration] = field(default_factory=list, compare=False, repr=False)
    #: The file this system was read from, if any.
    source_file: str | None = field(default=None, compare=False, repr=False)
    #: The text of every file read (a `SourceMap`), for quoting lines in diagnostics.
    sources: object | None = field(default=None, compare=False, repr=False)
    #: The values of the parameters imported files declare, as read: `to_earl()` prints the root file
    #: alone, and must not print a system whose imported parameter was given another value since.
    imported_values: dict[str, object] = field(default_factory=dict, compare=False, repr=False)

    def agent(self, name: str) -> Agent | None:
        """The agent called `name`, written bare (`manip`) or as the manual writes it (`manip/a`); None
        when the system has none."""
        name = name.removesuffix("/" + Kind.AGENT.value)
        return next((a for a in self.agents if a.name == name), None)

    def robot(self, name: str) -> Robot | None:
        """The robot called `name` (`arm` or `arm/r`); None when the system has none."""
        name = name.removesuffix("/" + Kind.ROBOT.value)
        return next((r for r in self.robots if r.name == name), None)

    def type_named(self, name: str) -> TypeDefinition | None:
        return next((t for t in self.types if t.name == name), None)

    def to_earl(self) -> str:
        """This system as canonical `.earl` text (what `earl fmt` prints)."""
        from earl.lang.formatter import format_system  # the model itself imports no reader
        from earl.lang.resolver import is_earl_name, unreadable_names, unreadable_quantifier_indexes
        from earl.model.validate import ModelNameError, explaining

        with explaining(self):  # a model built in Python with a wrong value: said at its path
            unreadable = unreadable_names(self) or unreadable_quantifier_indexes(self)
        if unreadable:  # `System("my system")`, `Memory("period", …)`: a text that would not read back
            name, what, _, path = unreadable[0]
            why = (
                "a keyword of EARL where it stands"
                if isinstance(name, str) and is_earl_name(name)
                else "no EARL name (a letter or `_`, then letters, digits and `_`)"
            )
            raise ModelNameError(f"{path}: {name!r} ({what}) is {why}: the text would not read back; rename it")
        for i, agent in enumerate(self.agents):
            for j, subsystem in enumerate(agent.subsystems):
                if isinstance(subsystem, ControlSubsystem) and subsystem.name != "cs":  # the text writes `cs`
                    raise ModelNameError(
                        f"system.agents[{i}].subsystems[{j}].name: {subsystem.name!r} (the Control Subsystem of"
                        f" `{agent.name}/a`) would be saved as `cs`, its name in the manual (§2.2); leave the name out"
                    )
        from earl.model.comment_text import unwritable_comments
        from earl.model.validate import ModelCommentError

        unwritable = next(unwritable_comments(self), None)  # `Comments(closing=["/* x */"])`
        if unwritable is not None:
            path, comment = unwritable
            raise ModelCommentError(
                f'{path}: {comment!r} is no EARL comment (one line starting with `//`, or "" for a blank line):'
                " the text would not read back; write it as `// …`, one line each"
            )
        try:
            with explaining(self):
                return format_system(self)
        except ValueError as error:  # a value no text can say (`Literal(float("nan"))`): said where it is
            from earl.model.validate import not_a_number

            where = not_a_number(self)
            if where is None:
                raise
            raise ValueError(f"{where}: {error}") from error


# the classes holding lists: a list and a tuple of the same items are equal in them (earl/model/equality.py)
for _class in (
    PrimitivePredicate,
    PartialTransitionFunction,
    StageSet,
    TransitionFunction,
    State,
    FSM,
    Subsystem,
    *SUBSYSTEM_CLASSES.values(),
    Link,
    Agent,
    Robot,
    System,
):
    sequences_compare_equal(_class)
