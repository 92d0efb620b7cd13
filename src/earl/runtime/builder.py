"""From an expanded System to subsystem engines wired by their links.

Everything that can be wrong before the first iteration is found here and reported
together, each problem located at the spec element it concerns: code that cannot
be imported, a subsystem that could never wait (no period and nothing obligatory).
"""

from __future__ import annotations

import zlib
from pathlib import Path
from typing import Any, Protocol

from earl.diagnostics import Diagnostic, EarlError, Severity
from earl.model.elements import Agent, Link, LinkEnd, PrimitivePredicate, Subsystem, System, duration_problems
from earl.model.expressions import ElementReference, Literal, Read
from earl.model.kinds import Kind
from earl.model.text import subsystem_name
from earl.model.types import DataType
from earl.runtime.binding import (
    PREDICATE_SIGNATURE,
    PREDICATE_USE,
    BindingProblem,
    UserFunction,
    bind_function,
    resolve_callable,
    user_code_path,
)
from earl.runtime.channels import Channel
from earl.runtime.engine import (
    BehaviourRuntime,
    Destination,
    FunctionRuntime,
    PredicateFault,
    Sink,
    StateRuntime,
    SubsystemEngine,
    TransitionRuntime,
    shown,
)
from earl.runtime.events import Recorder, TransitionName
from earl.runtime.names import agent_name, indexed, reference_key
from earl.runtime.parameters import agent_parameters, subsystem_parameters
from earl.runtime.predicates import (
    CompiledPredicate,
    PredicateCompileError,
    compile_predicate,
    kept_for_the_decision,
    repeatedly_evaluated,
)
from earl.runtime.structure import undeclared
from earl.runtime.values import TypeSystem, ValueTypeError
from earl.runtime.views import Context, build_inputs, build_outputs

NANOSECONDS = 1_000_000_000


def to_nanoseconds(seconds: float) -> int:
    return round(seconds * NANOSECONDS)


class RemoteLinks(Protocol):
    """A transport that serves the links whose other end runs in another process (docs/distributed.md)."""

    def outgoing(self, link: str, data_type: DataType, types: TypeSystem, source: str, destination_agent: str) -> Sink:
        """Where the messages of a link to `destination_agent`, a remote agent, go."""
        ...

    def incoming(
        self, link: str, data_type: DataType, types: TypeSystem, engine: SubsystemEngine, buffer: str, source_agent: str
    ) -> None:
        """Feed `engine`'s input buffer `buffer` from a link whose sender, `source_agent`, is remote."""
        ...


class Network:
    """The engines of a run, in their deterministic order, and how to find them by name."""

    def __init__(self, types: TypeSystem) -> None:
        self.types = types
        self.engines: list[SubsystemEngine] = []
        self.by_name: dict[str, SubsystemEngine] = {}
        self.initial_states: dict[str, str] = {}
        self.links: list[str] = []
        #: the data type each link carries, and each subsystem's memory types (for trace schemas)
        self.link_types: dict[str, DataType] = {}
        self.memory_types: dict[str, dict[str, DataType]] = {}
        self.output_types: dict[str, dict[str, DataType]] = {}
        self.input_types: dict[str, dict[str, DataType]] = {}
        #: link name -> `subsystem.outputBuffer` it carries, so a trace can be read by buffer name
        self.link_sources: dict[str, str] = {}
        #: link name -> the index variables of the families it is a member of (`K` of
        #: `link sorter,pusher[K in 1..N]` or of `pusher[K in 1..N]/a`): what `[K]` in a link pattern names
        self.link_index_variables: dict[str, frozenset[str]] = {}


def build_network(
    system: System,
    *,
    recorder: Recorder,
    environment: object = None,
    seed: int = 0,
    code_directories: list[Path] | None = None,
    agents: set[str] | None = None,
    remote: RemoteLinks | None = None,
) -> Network:
    """Engines for every subsystem of the expanded `system` (of the agents named in `agents`, if given).

    With `remote`, a link with one end built here and the other in an agent not built here
    goes through that transport; without it, such a link is left out.
    """
    types = TypeSystem(system)
    network = Network(types)
    problems: list[Diagnostic] = []
    bound: dict[str, UserFunction] = {}
    #: modules that cannot be imported: what was said of each, at the first line naming it, and the lines naming it
    unimportable: dict[str, _Unimportable] = {}
    directories = code_directories or []
    keys: dict[tuple[str, int | None, Kind, str, int | None], SubsystemEngine] = {}
    with user_code_path(directories):
        for agent in system.agents:
            if agents is not None and agent_name(agent) not in agents and agent.name not in agents:
                continue
            inherited = agent_parameters(system, agent)
            for subsystem in agent.subsystems:
                wrong = duration_problems(subsystem)
                if wrong:  # a model built in Python, where the reader's S012 never looked
                    what, problem, location = wrong[0]
                    problems.append(
                        Diagnostic(
                            Severity.ERROR,
                            f"{subsystem_name(agent, subsystem)} cannot run: {what} {problem}",
                            location or subsystem.location,
                            code="EARL-X014",
                        )
                    )
                    continue
                names = undeclared(subsystem, subsystem_name(agent, subsystem))
                if names:  # a model built or edited in Python, run with check=False
                    problems.extend(names)
                    continue
                try:
                    engine = _engine(
                        agent, subsystem, len(network.engines), inherited, types, recorder, environment, seed
                    )
                    _behaviour(engine, subsystem, types, bound, _Problems(problems, unimportable))
                except (ValueTypeError, PredicateCompileError) as error:
                    problems.append(
                        Diagnostic(
                            Severity.ERROR,
                            f"{subsystem_name(agent, subsystem)} cannot run: {error}",
                            getattr(error, "location", None) or subsystem.location,
                            code="EARL-X010",
                        )
                    )
                    continue
                network.engines.append(engine)
                network.by_name[engine.name] = engine
                network.memory_types[engine.name] = {indexed(m.name, m.index): m.data_type for m in subsystem.memories}
                network.output_types[engine.name] = {
                    indexed(o.name, o.index): o.data_type for o in subsystem.output_buffers
                }
                network.input_types[engine.name] = {
                    indexed(i.name, i.index): i.data_type for i in subsystem.input_buffers
                }
                keys[(agent.name, agent.index, subsystem.kind, subsystem.name, subsystem.index)] = engine
                if subsystem.fsm is not None:
                    network.initial_states[engine.name] = subsystem.fsm.initial
    for agent in system.agents:
        for link in agent.links:
            _connect(link, agent, keys, network, problems, remote)
    for link in system.links:
        _connect(link, None, keys, network, problems, remote)
    for module in unimportable.values():
        module.say_where_else()
    if problems:
        raise EarlError(_once_per_binding(problems), system.sources)  # type: ignore[arg-type]
    return network


class _Unimportable:
    """A module that cannot be imported, said once at the first spec line that names it: one broken file
    of five functions is one error to fix, not five."""

    def __init__(self, diagnostic: Diagnostic, module: str) -> None:
        self.diagnostic = diagnostic
        self.module = module
        self.lines: set[tuple[str, int]] = set()

    def named_at(self, diagnostic: Diagnostic, problems: list[Diagnostic]) -> None:
        """Another function or predicate names the module: the error moves to its line if that comes first."""
        location, first = diagnostic.location, self.diagnostic.location
        if location is None:
            return
        if first is not None and location.file == first.file and location.line < first.line:
            problems[problems.index(self.diagnostic)] = diagnostic
            self.lines.add((first.file, first.line))
            self.diagnostic = diagnostic
        elif first is None or (location.file, location.line) != (first.file, first.line):
            self.lines.add((location.file, location.line))

    def say_where_else(self) -> None:
        if not self.lines:
            return
        first = self.diagnostic.location
        files: dict[str, list[int]] = {}
        for file, line in sorted(self.lines):
            files.setdefault(file, []).append(line)
        places = "; ".join(
            ("lines " if len(lines) > 1 else "line ")
            + ", ".join(map(str, lines))
            + ("" if first is not None and file == first.file else f" of {Path(file).name}")
            for file, lines in files.items()
        )
        also = f"`{self.module}` is named at {places} too: this error stands for those"
        self.diagnostic.hint = f"{self.diagnostic.hint}; {also}" if self.diagnostic.hint else also


class _Problems:
    """Where `_behaviour` puts what it finds: the run's problems, a module that cannot be imported once."""

    def __init__(self, problems: list[Diagnostic], unimportable: dict[str, _Unimportable]) -> None:
        self.problems = problems
        self.unimportable = unimportable

    def append(self, diagnostic: Diagnostic) -> None:
        self.problems.append(diagnostic)

    def binding(self, problem: BindingProblem) -> None:
        module = problem.module
        if module is None:
            self.problems.append(problem.diagnostic)
            return
        known = self.unimportable.get(module)
        if known is None:
            self.unimportable[module] = _Unimportable(problem.diagnostic, module)
            self.problems.append(problem.diagnostic)
        else:
            known.named_at(problem.diagnostic, self.problems)


#: the codes of code that cannot be bound: the same spec line fails alike for every member of a family
_BINDING_CODES = frozenset({"EARL-X002", "EARL-X003", "EARL-X004", "EARL-X005"})


def _once_per_binding(problems: list[Diagnostic]) -> list[Diagnostic]:
    """A binding that fails is said once for its line, not once per member of the family that names it."""
    seen: set[tuple[str, object]] = set()
    kept = []
    for problem in problems:
        if problem.code in _BINDING_CODES and problem.location is not None:
            place = (problem.code, (problem.location.file, problem.location.line, problem.location.column))
            if place in seen:
                continue
            seen.add(place)
        kept.append(problem)
    return kept


def _value(expression: Any) -> Any:
    return expression.value if isinstance(expression, Literal) else expression


def _engine(
    agent: Agent,
    subsystem: Subsystem,
    order: int,
    inherited: dict[str, Any],
    types: TypeSystem,
    recorder: Recorder,
    environment: object,
    seed: int,
) -> SubsystemEngine:
    import numpy

    name = subsystem_name(agent, subsystem)
    parameters = subsystem_parameters(inherited, subsystem)
    period = None if subsystem.period is None else to_nanoseconds(subsystem.period.seconds)
    # one stream per subsystem, so that adding a subsystem does not change another's numbers
    entropy = [seed, zlib.crc32(name.encode())]
    context = Context(
        name,
        parameters,
        None if period is None else period / NANOSECONDS,
        environment,
        lambda: numpy.random.default_rng(entropy),
    )
    engine = SubsystemEngine(name, order, period, context, recorder)
    for buffer in subsystem.input_buffers:
        key = indexed(buffer.name, buffer.index)
        engine.inputs[key] = types.default(buffer.data_type)
        engine.new_data[key] = False
        engine.timed_out[key] = False
        capacity = None
        overflow = "dropOldest"
        if buffer.queue is not None:
            capacity = int(_value(buffer.queue.capacity))
            overflow = buffer.queue.overflow
        engine.channels[key] = Channel(capacity, overflow)
    for memory in subsystem.memories:
        key = indexed(memory.name, memory.index)
        if memory.initial_value is None:
            engine.memory[key] = types.default(memory.data_type)
        else:
            try:
                engine.memory[key] = types.constant(
                    memory.initial_value, memory.data_type, f"the initial value of {key}/m"
                )
            except ValueTypeError as wrong:
                wrong.location = memory.initial_value.location or memory.location  # said at the memory's line
                raise
    for predicate in subsystem.primitive_predicates:
        if predicate.implementation is None:  # Python ones are bound with the functions
            engine.predicates[predicate.name] = compile_predicate(
                predicate.expression, f"{name} {predicate.name}/pp", engine.stale
            )
    return engine


def _data_type(subsystem: Subsystem, reference: ElementReference) -> DataType:
    key = reference_key(reference)
    if reference.kind == Kind.OUTPUT_BUFFER:
        for output in subsystem.output_buffers:
            if indexed(output.name, output.index) == key:
                return output.data_type
    else:
        for memory in subsystem.memories:
            if indexed(memory.name, memory.index) == key:
                return memory.data_type
    raise ValueTypeError(f"`{key}` is not declared in this subsystem")


def _behaviour(
    engine: SubsystemEngine,
    subsystem: Subsystem,
    types: TypeSystem,
    bound: dict[str, UserFunction],
    problems: _Problems,
) -> None:
    for predicate in subsystem.primitive_predicates:
        if predicate.implementation is not None:
            try:
                engine.predicates[predicate.name] = _python_predicate(engine, predicate)
                engine.keeps_predicate_values = True
            except BindingProblem as problem:
                problems.binding(problem)
    _keep_repeated_predicates(engine, subsystem)
    functions: dict[str, FunctionRuntime] = {}
    for declared in subsystem.partial_transition_functions:
        try:
            implementation = declared.implementation
            cache_key = implementation.path if implementation is not None else ""
            function = bound.get(cache_key) if cache_key else None
            if function is None:
                function = bind_function(declared, engine.name)
                bound[cache_key] = function
        except BindingProblem as problem:
            problems.binding(problem)
            continue
        functions[declared.name] = FunctionRuntime(
            declared.name,
            function,
            build_inputs(declared.name + "/pf", declared.reads, engine.inputs, engine.memory),
            build_outputs(
                declared.name + "/pf",
                declared.writes,
                types,
                engine.memory,
                lambda reference, s=subsystem: _data_type(s, reference),  # type: ignore[misc]
            ),
            declared.location,
        )
    behaviours: dict[str, BehaviourRuntime] = {}
    for behaviour in subsystem.basic_behaviours:
        stages = [
            [functions[reference.name] for reference in stage if reference.name in functions]
            for stage in behaviour.transition_function.stages
        ]
        error_condition = (
            None
            if behaviour.error_condition is None
            else compile_predicate(
                behaviour.error_condition.expression, f"{engine.name} {behaviour.name}/bb ec", engine.stale
            )
        )
        behaviours[behaviour.name] = BehaviourRuntime(
            behaviour.name,
            stages,
            compile_predicate(
                behaviour.terminal_condition.expression, f"{engine.name} {behaviour.name}/bb tc", engine.stale
            ),
            error_condition,
            never_ends=error_condition is None and _constant_false(behaviour.terminal_condition.expression, subsystem),
        )
    fsm = subsystem.fsm
    if fsm is None:
        problems.append(
            Diagnostic(
                Severity.ERROR,
                f"{engine.name} has no `fsm`, so it cannot run",
                subsystem.location,
                "EARL-X011",
                hint="give it one, naming one of its behaviours: `fsm { initial s  state s: b/bb }`",
            )
        )
        return
    for state in fsm.states:
        leaving = [
            (position, transition)
            for position, transition in enumerate(fsm.transitions)
            if transition.source == state.name
        ]
        # priority 1 first; transitions without a priority after all that have one, in declaration order
        leaving.sort(key=lambda item: (item[1].priority is None, item[1].priority or 0, item[0]))
        behaviour_runtime = behaviours.get(state.behaviour)
        if behaviour_runtime is None:
            continue
        obligatory = [reference_key(reference) for reference in state.obligatory]
        timeout = None if state.timeout is None else to_nanoseconds(state.timeout.seconds)
        if engine.period is None and not obligatory:
            problems.append(
                Diagnostic(
                    Severity.ERROR,
                    f"{engine.name} has no `period` and state `{state.name}` waits for no obligatory buffer, "
                    "so nothing would ever pace it",
                    state.location,
                    code="EARL-X012",
                    hint="give the subsystem a `period`, or list the buffers it waits for: "
                    "`state NAME: BEHAVIOUR/bb { obligatory x/ib }`",
                )
            )
        engine.states[state.name] = StateRuntime(
            state.name,
            behaviour_runtime,
            obligatory,
            timeout,
            [
                TransitionRuntime(
                    TransitionName(
                        f"{transition.source},{transition.destination}",
                        f"*,{transition.destination}" if transition.from_any_state else None,
                    ),
                    transition.destination,
                    compile_predicate(
                        transition.condition.expression,
                        f"{engine.name} {transition.source},{transition.destination}/t",
                        engine.stale,
                    ),
                )
                for _, transition in leaving
            ],
            location=state.location,
        )


def _keep_repeated_predicates(engine: SubsystemEngine, subsystem: Subsystem) -> None:
    """Predicates that a condition would compute many times over are computed once per decision instead."""
    definitions = {
        predicate.name: predicate.expression
        for predicate in subsystem.primitive_predicates
        if predicate.implementation is None and predicate.expression is not None
    }
    conditions = [transition.condition.expression for transition in subsystem.fsm.transitions] if subsystem.fsm else []
    for behaviour in subsystem.basic_behaviours:
        conditions.append(behaviour.terminal_condition.expression)
        if behaviour.error_condition is not None:
            conditions.append(behaviour.error_condition.expression)
    for name in repeatedly_evaluated(definitions, conditions):
        if name not in engine.predicates:  # not compiled: the run refuses the spec for it already
            continue
        engine.predicates[name] = kept_for_the_decision(engine.predicates[name], name, engine.predicate_values)
        engine.keeps_predicate_values = True


def _python_predicate(engine: SubsystemEngine, predicate: PrimitivePredicate) -> CompiledPredicate:
    """`ready/pp(x/ib, y/mi) = python "m:f"`: `f(inputs, context)`, which returns True or False.

    Anything else (None, "no", NaN, a number) is a fault rather than its truth value: `return "no"` or a
    NaN would hold, and a function that forgot its `return` would never hold, without a word."""
    from numpy import bool_, ndarray

    assert predicate.implementation is not None
    function = resolve_callable(
        predicate.implementation.path,
        f"`{predicate.name}/pp` of {engine.name}",
        predicate.location,
        arity=2,
        signature=PREDICATE_SIGNATURE,
        use=PREDICATE_USE,
    )
    inputs = build_inputs(f"{predicate.name}/pp", predicate.reads, engine.inputs, engine.memory)
    refresh = inputs._earl_refresh
    context = engine.context
    values = engine.predicate_values
    name = predicate.name

    def evaluate(*_: object) -> bool:
        # once per decision: a predicate that keeps state or draws random numbers must not be
        # asked again by the terminal condition's second reading or by a transition naming it too
        known = values.get(name)
        if known is None:
            refresh()
            try:
                result = function(inputs, context)
            except (KeyboardInterrupt, SystemExit):
                raise
            except BaseException as raised:
                # named here: the compiled predicate that asked for it would be blamed otherwise
                known = values[name] = PredicateFault.raised(name, raised)
                raise known from None
            if result is True or result is False:
                known = values[name] = result
            elif isinstance(result, bool_) or (
                isinstance(result, ndarray) and result.shape == () and result.dtype == bool
            ):
                known = values[name] = bool(result)  # NumPy's Boolean, alone or as an array of no dimension
            else:
                known = values[name] = PredicateFault(
                    name,
                    f": `{name}/pp` returned {shown(result)}, not a Boolean, so the condition counts as false "
                    "(a predicate computed by Python returns True or False)",
                )
        if isinstance(known, BaseException):
            raise known  # the engine records it once, then leaves a PredicateFailedBefore in its place
        return known

    return evaluate


def _constant_false(expression: Any, subsystem: Subsystem) -> bool:
    """`false`, or a primitive predicate defined as `false` (the manual's `false/pp`)."""
    if isinstance(expression, Literal):
        return expression.value is False
    if isinstance(expression, Read) and expression.target.kind == Kind.PRIMITIVE_PREDICATE and not expression.path:
        predicate = subsystem.primitive_predicate(expression.target.name)
        return (
            predicate is not None and isinstance(predicate.expression, Literal) and predicate.expression.value is False
        )
    return False


def _end_engine(
    end: LinkEnd,
    agent: Agent | None,
    keys: dict[tuple[str, int | None, Kind, str, int | None], SubsystemEngine],
) -> SubsystemEngine | None:
    if end.agent is not None:
        agent_key = (end.agent.name, _index(end.agent))
    elif agent is not None:
        agent_key = (agent.name, agent.index)
    else:
        return None
    subsystem = end.subsystem
    return keys.get((*agent_key, subsystem.kind, subsystem.name, _index(subsystem)))


def _index(reference: ElementReference) -> int | None:
    if not reference.indices:
        return None
    index = reference.indices[0]
    return index.value if isinstance(index, Literal) and isinstance(index.value, int) else None


def _connect(
    link: Link,
    agent: Agent | None,
    keys: dict[tuple[str, int | None, Kind, str, int | None], SubsystemEngine],
    network: Network,
    problems: list[Diagnostic],
    remote: RemoteLinks | None = None,
) -> None:
    source = _end_engine(link.source, agent, keys)
    destination = _end_engine(link.destination, agent, keys)
    if source is None or destination is None:
        if remote is not None and (source is None) != (destination is None):
            _connect_remote(link, agent, source, destination, network, remote)
        return  # otherwise an end that runs elsewhere (another process) or was not built
    buffer = reference_key(link.destination.buffer)
    channel = destination.channels.get(buffer)
    if channel is None:
        problems.append(
            Diagnostic(
                Severity.ERROR,
                f"the link {link.name_text} ends at `{buffer}/ib`, which {destination.name} does not have",
                link.location,
                code="EARL-X013",
            )
        )
        return
    name = _link_name(link, agent)
    network.links.append(name)
    network.link_index_variables[name] = _index_variables(link, agent)
    source_buffer = reference_key(link.source.buffer)
    data_type = network.output_types.get(source.name, {}).get(source_buffer)
    if data_type is not None:
        network.link_types[name] = data_type
    network.link_sources[name] = f"{source.name}.{source_buffer}"
    source.destinations.setdefault(reference_key(link.source.buffer), []).append(
        Destination(name, channel, destination, buffer)
    )


def _link_name(link: Link, agent: Agent | None) -> str:
    name = link.name_text
    if agent is not None:
        name = f"{agent_name(agent)}:{name}"
    if link.index is not None and "[" not in name:
        name = f"{name}[{link.index}]"
    return name


def _index_variables(link: Link, agent: Agent | None) -> frozenset[str]:
    families = (link.family, agent.family if agent is not None else None)
    return frozenset(family.index for family in families if family is not None)


def _end_agent(end: LinkEnd, agent: Agent | None) -> str:
    """The name (`task/a`) of the agent at one end of a link."""
    if end.agent is not None:
        return f"{indexed(end.agent.name, _index(end.agent))}/a"
    return agent_name(agent) if agent is not None else ""


def _connect_remote(
    link: Link,
    agent: Agent | None,
    source: SubsystemEngine | None,
    destination: SubsystemEngine | None,
    network: Network,
    remote: RemoteLinks,
) -> None:
    """A link with one end here and the other in another process: the transport carries it."""
    name = _link_name(link, agent)
    if source is not None:
        source_buffer = reference_key(link.source.buffer)
        data_type = network.output_types.get(source.name, {}).get(source_buffer)
        if data_type is None:
            return  # the checker reports a link from a buffer that does not exist
        sink = remote.outgoing(name, data_type, network.types, source.name, _end_agent(link.destination, agent))
        network.links.append(name)
        network.link_index_variables[name] = _index_variables(link, agent)
        network.link_types[name] = data_type
        network.link_sources[name] = f"{source.name}.{source_buffer}"
        source.destinations.setdefault(source_buffer, []).append(
            Destination(name, sink, None, reference_key(link.destination.buffer))
        )
    elif destination is not None:
        buffer = reference_key(link.destination.buffer)
        data_type = network.input_types.get(destination.name, {}).get(buffer)
        if data_type is None:
            return
        remote.incoming(name, data_type, network.types, destination, buffer, _end_agent(link.source, agent))
