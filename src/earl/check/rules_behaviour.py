"""Rules on predicates, partial transition functions and transition functions (manual §2.2, §3, Eq. 4–8)."""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from fractions import Fraction

from earl.check.constants import constant_value
from earl.check.context import CheckContext, reference_key, written_output_buffers
from earl.check.expression_types import BOOLEAN, ExpressionTyper
from earl.check.registry import Finding, rule
from earl.diagnostics import Severity
from earl.model.elements import BasicBehaviour, Subsystem, duration_problem
from earl.model.expressions import (
    Call,
    ElementReference,
    Expression,
    ListLiteral,
    Literal,
    Read,
    children,
    reads,
    walk,
)
from earl.model.graphs import cycles
from earl.model.kinds import Kind
from earl.model.location import SourceLocation
from earl.model.text import expression_text, instance_name, reference_text, subsystem_name
from earl.model.types import INTEGER_RANGES, ArrayType, PrimitiveType


def _conditions(
    subsystem: Subsystem, with_predicates: bool = True
) -> Iterator[tuple[str, Expression, SourceLocation | None]]:
    """Every Boolean formula of a subsystem, with what it is called in messages; without `with_predicates`,
    only those the FSM evaluates itself (terminal, error and initial conditions, assumptions)."""
    for predicate in subsystem.primitive_predicates if with_predicates else ():
        yield f"primitive predicate `{predicate.name}/pp`", predicate.expression, predicate.location
    for behaviour in subsystem.basic_behaviours:
        yield (
            f"the terminal condition of `{behaviour.name}/bb`",
            behaviour.terminal_condition.expression,
            behaviour.terminal_condition.location,
        )
        if behaviour.error_condition is not None:
            yield (
                f"the error condition of `{behaviour.name}/bb`",
                behaviour.error_condition.expression,
                behaviour.error_condition.location,
            )
    if subsystem.fsm is not None:
        for transition in subsystem.fsm.transitions:
            yield (
                f"the initial condition of `{transition.name}/t`",
                transition.condition.expression,
                transition.condition.location,
            )
        for assumption in subsystem.fsm.assumptions:
            yield "an assumption", assumption.expression, assumption.location


def _once(findings: Iterable[Finding]) -> Iterator[Finding]:
    """Family members share declarations: report each problem once."""
    seen: set[tuple[str, SourceLocation | None]] = set()
    for finding in findings:
        if (finding.message, finding.location) not in seen:
            seen.add((finding.message, finding.location))
            yield finding


@rule("EARL-E030", Severity.ERROR, "predicates are Boolean", "§2.2, Table 4, Table 5")
def predicates_are_boolean(context: CheckContext) -> Iterator[Finding]:
    """Primitive predicates, terminal, error and initial conditions, and assumptions produce a Boolean
    (`fun` returns true or false), and their operators are applied to operands of the right type. An
    array's index is a whole number within the array (`v/ib[1.5]`, `v/ib[true]` or `v/ib[d/ib]` of a
    `double` name no element)."""

    def findings() -> Iterator[Finding]:
        for _agent, subsystem in context.distinct_subsystems():
            typer = ExpressionTyper(context, subsystem)
            for role, expression, location in _conditions(subsystem):
                kind = typer.type_of(expression)
                if kind not in (BOOLEAN, "unknown"):
                    yield Finding(
                        f"{role} is a {kind}, not a Boolean: `{expression_text(expression)}`",
                        expression.location or location,
                        "compare it, e.g. `x > 0.5`, or test it with `newData(…)`",
                    )
            for problem in typer.problems:
                yield Finding(problem.message, problem.location, problem.hint)

    yield from _once(findings())


@rule("EARL-W030", Severity.WARNING, "every primitive predicate is used", "§2.2, Table 4")
def unused_primitive_predicates(context: CheckContext) -> Iterator[Finding]:
    """A primitive predicate no condition uses is dead specification: remove it, or use it. So is one that
    only such predicates use (`p1/pp` in `p2/pp = p1/pp and …`, with `p2/pp` unused): the message says
    which."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            named_in_definition: dict[str, set[str]] = {}  # predicate → the predicates its definition names
            live: set[str] = set()  # the predicates a terminal, error or initial condition or an assumption reaches
            for _role, expression, _location in _conditions(subsystem, with_predicates=False):
                live.update(r.target.name for r in reads(expression) if r.target.kind is Kind.PRIMITIVE_PREDICATE)
            for predicate in subsystem.primitive_predicates:
                named_in_definition[predicate.name] = {
                    r.target.name for r in reads(predicate.expression) if r.target.kind is Kind.PRIMITIVE_PREDICATE
                }
            frontier = list(live)
            while frontier:  # through definitions: what a live predicate names is live too
                for name in named_in_definition.get(frontier.pop(), ()):
                    if name not in live:
                        live.add(name)
                        frontier.append(name)
            for predicate in subsystem.primitive_predicates:
                if predicate.name in live:
                    continue
                users = [
                    user.name
                    for user in subsystem.primitive_predicates
                    if user.name != predicate.name and predicate.name in named_in_definition.get(user.name, set())
                ]
                if not users:
                    yield Finding(
                        f"primitive predicate `{predicate.name}/pp` is never used",
                        predicate.location,
                        "use it in a terminal, error or initial condition, or remove it",
                    )
                    continue
                listed = ", ".join(f"`{user}/pp`" for user in users[:-1])
                listed = f"{listed} and `{users[-1]}/pp`" if listed else f"`{users[-1]}/pp`"
                which = "which is" if len(users) == 1 else "which are"
                yield Finding(
                    f"primitive predicate `{predicate.name}/pp` is used only by {listed}, {which} never used "
                    "in a condition",
                    predicate.location,
                    "use one of them in a terminal, error or initial condition, or remove them together",
                )


def _writes(
    subsystem: Subsystem, behaviour: BasicBehaviour
) -> list[list[tuple[str, ElementReference, ElementReference]]]:
    """Per stage: (function name, function reference, written element) for every declared write."""
    stages = []
    for stage in behaviour.transition_function.stages:
        entries = []
        for function_reference in stage:
            function = subsystem.partial_transition_function(function_reference.name)
            if function is None:
                continue
            entries += [(function.name, function_reference, written) for written in function.writes]
        stages.append(entries)
    return stages


def _families(names: list[str]) -> list[str]:
    """`x[1]/ob, x[2]/ob` as the spec writes them: `x[*]/ob` (an expanded function lists every member)."""
    bases = [re.sub(r"\[\d+\]", "[*]", name) for name in names]
    return [base if bases.count(base) > 1 else name for name, base in dict(zip(bases, names, strict=True)).items()]


def _stage_fix(function: str, outputs: list[str], stages: int, number: int, sender: bool, others: list[str]) -> str:
    """How to move output-buffer writes out of an early stage: the hint of EARL-E040. `sender`: the
    function reads only memory and writes only output buffers, a last-stage function already;
    `others`: the other functions of its stage."""
    outputs = _families(outputs)
    memory = ", ".join(f"{name.removesuffix('/ob')}/mo" for name in outputs)
    sends = ", ".join(outputs)
    if sender and stages == 1 and others:
        first = ", ".join(f"{name}/pf" for name in others)
        return f"`{function}/pf` reads only memory: make it the second stage, `tf = {{{first}}} then {{{function}/pf}}`"
    if stages == 1:
        return (
            f"a one-stage `tf` has no stage for outputs (Eq. 4–6): let `{function}/pf` write memory instead "
            f"(`-> {memory}`, declared as `/m`) and add a second stage that sends it, "
            f"`tf = {{{function}/pf}} then {{send/pf}}` with `send/pf(… /mi -> {sends})`"
        )
    if sender:
        return f"`{function}/pf` reads only memory: move it into the last stage (stage {stages})"
    return f"let `{function}/pf` write memory (`-> {memory}`) that a function of the last stage sends to {sends}"


@rule("EARL-E040", Severity.ERROR, "only the last stage writes output buffers", "Eq. (4), Eq. (6)")
def output_buffers_in_last_stage(context: CheckContext) -> Iterator[Finding]:
    """The first-stage functions (`pf`, Eq. 4) read Input Buffers and memory and write only Internal Memory
    (`mo`, Eq. 5); the Output Buffers are produced by the second stage (`pfo`, Eq. 6), which reads only
    memory (`mi`). So a transition function that sends anything has two stages, even when one function
    does all the work (`tf = {control/pf}` writing `motor/ob` is refused): the fix is to let that function
    write memory and add a second-stage function that copies the memory into the Output Buffer."""

    def findings() -> Iterator[Finding]:
        for agent, subsystem in context.distinct_subsystems():
            for behaviour in subsystem.basic_behaviours:
                stages = behaviour.transition_function.stages
                for number, stage in enumerate(stages, start=1):
                    last = number == len(stages) and len(stages) > 1
                    for function_reference in stage:
                        function = subsystem.partial_transition_function(function_reference.name)
                        if function is None:
                            continue
                        if not last:
                            outputs = list(
                                dict.fromkeys(
                                    f"{reference_key(w)}/ob" for w in function.writes if w.kind is Kind.OUTPUT_BUFFER
                                )
                            )
                            if outputs:
                                why = (
                                    "a transition function of one stage; output buffers are written by a second stage"
                                    if len(stages) == 1
                                    else "only the last stage writes output buffers"
                                )
                                sender = all(r.kind is Kind.MEMORY_INPUT for r in function.reads) and all(
                                    w.kind is Kind.OUTPUT_BUFFER for w in function.writes
                                )
                                others = [f.name for f in stage if f.name != function.name]
                                yield Finding(
                                    f"`{function.name}/pf` writes `{'`, `'.join(_families(outputs))}` in stage {number} of `{behaviour.name}/bb` in `{subsystem_name(agent, subsystem)}`: {why}",
                                    function_reference.location,
                                    _stage_fix(function.name, outputs, len(stages), number, sender, others),
                                )
                        else:
                            for element in [*function.reads, *function.writes]:
                                if element.kind in (Kind.INPUT_BUFFER, Kind.MEMORY_OUTPUT):
                                    what = "reads" if element.kind is Kind.INPUT_BUFFER else "writes"
                                    yield Finding(
                                        f"`{function.name}/pf` {what} `{reference_text(element)}` in the last stage of `{behaviour.name}/bb` in `{subsystem_name(agent, subsystem)}`",
                                        function_reference.location,
                                        "Eq. (6): a second-stage function reads memory (`/mi`) and writes output buffers (`/ob`) only; "
                                        "move this work into a function of the first stage",
                                    )

    yield from _once(findings())


@rule("EARL-E041", Severity.ERROR, "transition-function stages follow the declared stage sets", "Eq. (4), Eq. (6)")
def stages_follow_stage_sets(context: CheckContext) -> Iterator[Finding]:
    """When a subsystem declares its stage sets (`stage pf = {…}` for Eq. 4, `stage pfo = {…}` for Eq. 6),
    the i-th stage of every transition function takes its functions from the i-th set."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            if not subsystem.stage_sets:
                continue
            for behaviour in subsystem.basic_behaviours:
                stages = behaviour.transition_function.stages
                if len(stages) > len(subsystem.stage_sets):
                    yield Finding(
                        f"`{behaviour.name}/bb` has {len(stages)} stages but `{subsystem.name}` declares {len(subsystem.stage_sets)} stage sets",
                        behaviour.transition_function.location,
                    )
                    continue
                for stage, stage_set in zip(stages, subsystem.stage_sets, strict=False):
                    members = {f.name for f in stage_set.functions}
                    for function in stage:
                        if function.name not in members:
                            yield Finding(
                                f"`{function.name}/pf` is in a stage of `{behaviour.name}/bb` that takes its functions from `{stage_set.name}`, which does not contain it",
                                function.location,
                                f"add it to `stage {stage_set.name}`, or move it to the stage it belongs to",
                            )


@rule("EARL-E042", Severity.ERROR, "no two functions of one stage write the same element", "Eq. (7), Eq. (8)")
def one_writer_per_stage(context: CheckContext) -> Iterator[Finding]:
    """Within one stage of one behaviour's transition function the functions run as if in parallel, so no
    two of them may produce the same Internal Memory (Eq. 7) or Output Buffer (Eq. 8)."""

    def findings() -> Iterator[Finding]:
        for agent, subsystem in context.distinct_subsystems():
            for behaviour in subsystem.basic_behaviours:
                for number, stage in enumerate(_writes(subsystem, behaviour), start=1):
                    writer: dict[str, str] = {}
                    for function, function_reference, written in stage:
                        key = f"{reference_key(written)}/{'m' if written.kind is Kind.MEMORY_OUTPUT else written.kind.value}"
                        if key in writer and writer[key] != function:
                            yield Finding(
                                f"`{writer[key]}/pf` and `{function}/pf` both write `{key}` in stage {number} of `{behaviour.name}/bb` ({subsystem_name(agent, subsystem)})",
                                function_reference.location,
                                "functions of one stage run in parallel: let one of them write it, or put them in different stages",
                            )
                        writer.setdefault(key, function)

    yield from _once(findings())


@rule("EARL-W040", Severity.WARNING, "every output buffer is written by some behaviour", "§2.2, Figure 5b")
def output_buffers_written(context: CheckContext) -> Iterator[Finding]:
    """`tf.pf.ob.send()` sends the Output Buffers the transition function computed; one that no function of
    any behaviour writes is never sent, and whatever it is linked to never receives data."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            written = written_output_buffers(subsystem)
            for buffer in subsystem.output_buffers:
                if buffer.name not in written:
                    yield Finding(
                        f"output buffer `{subsystem_name(agent, subsystem)}.{buffer.name}/ob` is never written by a "
                        "function of any behaviour, so it is never sent",
                        buffer.location,
                        f"add `{buffer.name}/ob` to the writes of a second-stage function",
                    )


def _memory_written(subsystem: Subsystem, behaviour: BasicBehaviour) -> set[str]:
    """Memory some function of the behaviour's transition function writes (every iteration runs them all)."""
    written: set[str] = set()
    for function_reference in behaviour.transition_function.partial_transition_functions:
        function = subsystem.partial_transition_function(function_reference.name)
        if function is not None:
            written.update(reference_key(w) for w in function.writes if w.kind is Kind.MEMORY_OUTPUT)
    return written


def _unwritten_on_entry(subsystem: Subsystem, memory: str) -> dict[str, list[str]]:
    """The states that can be entered while `memory` was never written, each with the path of states from
    the initial one that gets there; a state whose behaviour writes it hands it on written."""
    fsm = subsystem.fsm
    assert fsm is not None
    paths = {fsm.initial: [fsm.initial]}
    frontier = [fsm.initial]
    while frontier:
        name = frontier.pop(0)
        state = fsm.state_named(name)
        behaviour = subsystem.basic_behaviour(state.behaviour) if state else None
        if behaviour is None or memory in _memory_written(subsystem, behaviour):
            continue
        for transition in fsm.transitions:
            if transition.source == name and transition.destination not in paths:
                paths[transition.destination] = [*paths[name], transition.destination]
                frontier.append(transition.destination)
    return paths


def _memory_read(subsystem: Subsystem, expression: Expression) -> Iterator[tuple[str, Read]]:
    """Memory a condition reads, directly (`x/mi`) or through a primitive predicate, with the read in the
    condition that leads to it."""
    for node in reads(expression):
        if node.target.kind is Kind.MEMORY_INPUT:
            yield reference_key(node.target), node
        elif node.target.kind is Kind.PRIMITIVE_PREDICATE:
            predicate = subsystem.primitive_predicate(node.target.name)
            if predicate is not None:
                for inner in reads(predicate.expression):
                    if inner.target.kind is Kind.MEMORY_INPUT:
                        yield reference_key(inner.target), node


@rule("EARL-W041", Severity.WARNING, "memory is written or initialised before it is read", "§2.2, Table 3")
def memory_read_before_written(context: CheckContext) -> Iterator[Finding]:
    """Memory without an initial value holds only its type's zero value until a function writes it. A
    state can be entered with such memory unwritten when a chain of transitions leads to it from the
    initial state through states whose behaviours never write it; there, a function that reads it before
    an earlier stage wrote it, or a terminal or error condition, or the condition of a transition out of
    the state, that the behaviour's functions do not write it for, reads a value nobody computed."""

    def findings() -> Iterator[Finding]:
        for agent, subsystem in context.distinct_subsystems():
            if subsystem.fsm is None:
                continue
            owner = subsystem_name(agent, subsystem)
            for memory in subsystem.memories:
                if memory.initial_value is not None:
                    continue
                key = instance_name(memory.name, memory.index)
                for name, path in _unwritten_on_entry(subsystem, key).items():
                    state = subsystem.fsm.state_named(name)
                    behaviour = subsystem.basic_behaviour(state.behaviour) if state else None
                    if behaviour is None:
                        continue
                    where = (
                        f"(the initial state of {owner})"
                        if len(path) == 1
                        else f"(state `{name}` of {owner}, entered by {' → '.join(path)} where nothing writes it)"
                    )
                    hint = f"give `{memory.name}/m` an initial value, or write it in an earlier stage or state"
                    yield from _early_function_reads(subsystem, behaviour, key, where, hint)
                    if key in _memory_written(subsystem, behaviour):
                        continue
                    # the behaviour's own conditions, and those of the transitions tried when it stops
                    conditions = [
                        (f"the condition of `{behaviour.name}/bb`", behaviour.terminal_condition),
                        (f"the condition of `{behaviour.name}/bb`", behaviour.error_condition),
                        *(
                            (f"the condition of transition `{t.name}/t`", t.condition)
                            for t in subsystem.fsm.transitions
                            if t.source == name
                        ),
                    ]
                    for what, condition in conditions:
                        if condition is None:
                            continue
                        for read_key, read in _memory_read(subsystem, condition.expression):
                            if read_key == key:
                                # a read of the memory itself needs no "through": only a predicate's does
                                through = (
                                    f" (through `{reference_text(read.target)}`)"
                                    if read.target.kind is Kind.PRIMITIVE_PREDICATE
                                    else ""
                                )
                                yield Finding(
                                    f"{what} reads `{key}/mi`{through} after the first iteration {where}, before anything wrote it",
                                    read.location or condition.location,
                                    hint,
                                )

    yield from _once(findings())


def _early_function_reads(
    subsystem: Subsystem, behaviour: BasicBehaviour, key: str, where: str, hint: str
) -> Iterator[Finding]:
    """Functions of the behaviour that read `key` before an earlier stage of it wrote the memory."""
    for stage in behaviour.transition_function.stages:
        stage_writes = False
        for function_reference in stage:
            function = subsystem.partial_transition_function(function_reference.name)
            if function is None:
                continue
            if any(r.kind is Kind.MEMORY_INPUT and reference_key(r) == key for r in function.reads):
                yield Finding(
                    f"`{function.name}/pf` reads `{key}/mi` in the first iteration of `{behaviour.name}/bb` {where} before anything wrote it",
                    function_reference.location,
                    hint,
                )
            stage_writes |= any(w.kind is Kind.MEMORY_OUTPUT and reference_key(w) == key for w in function.writes)
        if stage_writes:
            return


@rule("EARL-E043", Severity.ERROR, "a memory's initial value is of its data type", "§2.2, Table 3")
def memory_initial_values(context: CheckContext) -> Iterator[Finding]:
    """Internal Memory starts with the value written after `=`; it must be a value of the memory's data
    type (`moving/m: boolean = 3` is not), or the subsystem cannot start. A real number is no value of an
    integer type (`count/m: int = 1.0` is refused, as `param X: int = 1.0` is). The check is the
    runtime's own, made before anything runs."""
    from earl.runtime.values import TypeSystem, ValueTypeError  # values only: no user code is imported

    types = TypeSystem(context.system)
    for _, subsystem in context.distinct_subsystems():
        for memory in subsystem.memories:
            if memory.initial_value is None:
                continue
            key = instance_name(memory.name, memory.index)
            try:
                types.constant(memory.initial_value, memory.data_type, f"the initial value of `{key}/m`")
            except ValueTypeError as wrong:
                value = constant_value(memory.initial_value)
                structure = context.structural(memory.data_type)
                integer = isinstance(structure, PrimitiveType) and structure.name in INTEGER_RANGES
                hint = "write a constant of the memory's type, or leave out `= …` for the type's zero value"
                if integer and isinstance(value, float) and value.is_integer():
                    hint = f"write `{int(value)}`: an integer type holds whole numbers, written without a decimal point"
                elif (
                    isinstance(memory.initial_value, ListLiteral)
                    and memory.initial_value.items
                    and isinstance(structure, ArrayType)
                    and isinstance(structure.size, Literal)
                    and structure.size.value != len(memory.initial_value.items)
                ):
                    # a list of the wrong length: the size may be a parameter's, which a repeated list follows
                    hint = _filled_hint(context, memory.location, memory.initial_value) or hint
                yield Finding(str(wrong), memory.initial_value.location or memory.location, hint)


def _filled_hint(context: CheckContext, location: SourceLocation | None, written: ListLiteral) -> str | None:
    """`perBin/m: int[NBINS] = [0, 0, 0]` under `--param NBINS=4`: a list as long as a parameter says is
    written `[0] * NBINS`, which `earl check` cannot tell of a list written out."""
    declared = next(
        (
            memory
            for agent in context.declared.agents
            for subsystem in agent.subsystems
            for memory in subsystem.memories
            if location is not None and memory.location == location
        ),
        None,
    )
    size = getattr(getattr(declared, "data_type", None), "size", None)
    if size is None or isinstance(size, Literal) or len(set(written.items)) != 1:
        return None
    filled = f"[{expression_text(written.items[0])}] * {expression_text(size)}"
    return f"write `{filled}`: the list repeated as many times as `{expression_text(size)}` says, whatever it is"


@rule("EARL-W042", Severity.WARNING, "every partial transition function is used", "§2.2, Table 6")
def unused_functions(context: CheckContext) -> Iterator[Finding]:
    """A partial transition function that no behaviour's transition function composes never runs."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            used = {f.name for b in subsystem.basic_behaviours for stage in b.transition_function.stages for f in stage}
            for function in subsystem.partial_transition_functions:
                if function.name not in used:
                    yield Finding(
                        f"partial transition function `{function.name}/pf` is not used by any behaviour",
                        function.location,
                        "compose it into a `tf`, or remove it",
                    )


@rule("EARL-W043", Severity.WARNING, "every subsystem has an FSM", "§2.2, Figure 3")
def subsystems_have_an_fsm(context: CheckContext) -> Iterator[Finding]:
    """A subsystem's behaviour is chosen by its FSM (Figure 3). One without an `fsm` is drawn and checked,
    but never behaves: `earl run` refuses it (EARL-X011)."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            if subsystem.fsm is None:
                if subsystem.basic_behaviours:
                    behaviour = subsystem.basic_behaviours[0].name
                    hint = f"add one: `fsm {{ initial {behaviour}  state {behaviour}: {behaviour}/bb }}`"
                else:  # an FSM names a behaviour: one that is not declared is EARL-R030
                    hint = (
                        "declare a behaviour and an FSM that runs it: `idle/bb { tf = {} tc = false }` and "
                        "`fsm { initial idle  state idle: idle/bb }`"
                    )
                yield Finding(
                    f"{subsystem_name(agent, subsystem)} has no `fsm`: it never runs a behaviour, and `earl run` "
                    "refuses it",
                    subsystem.location,
                    hint,
                )


#: nanoseconds in one of each unit a period or timeout is written in
_NANOSECONDS_PER = {"s": 10**9, "ms": 10**6, "us": 10**3}


@rule("EARL-W045", Severity.WARNING, "a period or timeout is a whole number of nanoseconds", "§2.2, Figure 5")
def whole_nanoseconds(context: CheckContext) -> Iterator[Finding]:
    """earl keeps run time in whole nanoseconds, so a `period` or `timeout` is rounded to the nearest one:
    `period 0.0015 us` (1.5 ns) runs as 2 ns, a third longer than written. A duration that is a whole number of
    nanoseconds runs as written."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            owner = subsystem_name(agent, subsystem)
            durations = [("the period", "period", subsystem.period, subsystem.period_location)]
            if subsystem.fsm is not None:
                durations += [
                    (f"the timeout of state `{state.name}`", "timeout", state.timeout, state.timeout_location)
                    for state in subsystem.fsm.states
                ]
            for what, keyword, duration, location in durations:
                if duration is None or duration_problem(duration) is not None:
                    continue  # none, or one the reader refuses (EARL-S012)
                exact = Fraction(str(duration.value)) * _NANOSECONDS_PER[duration.unit]
                if exact.denominator == 1:
                    continue
                runs = round(duration.seconds * 1e9)  # as the runtime turns it into nanoseconds
                yield Finding(
                    f"{what} of {owner}, `{keyword} {duration.value} {duration.unit}`, is {_decimal(exact)} ns: earl "
                    f"keeps time in whole nanoseconds, so it runs as {runs} ns",
                    location or subsystem.location,
                    f"write a whole number of nanoseconds: `{keyword} {_in_unit(runs, duration.unit)} {duration.unit}` "
                    f"({runs} ns)",
                )


def _in_unit(nanoseconds: int, unit: str) -> str:
    """`0.002` for 2 ns in `us`: a whole number of nanoseconds written in `unit`, exactly."""
    return _decimal(Fraction(nanoseconds, _NANOSECONDS_PER[unit]))


def _decimal(value: Fraction) -> str:
    """`1000000.5`: a fraction whose denominator divides a power of ten, written out in full."""
    whole, rest = divmod(value.numerator, value.denominator)
    digits = ""
    while rest and len(digits) < 30:
        whole_digit, rest = divmod(rest * 10, value.denominator)
        digits += str(whole_digit)
    return f"{whole}.{digits}" if digits else str(whole)


@rule("EARL-W044", Severity.WARNING, "a `timeout` can come true", "§2.2, Figure 5b")
def timeouts_that_can_happen(context: CheckContext) -> Iterator[Finding]:
    """`timeout(x/ib)` is true when the obligatory `x/ib` of the current state did not come before the
    state's timeout. A buffer that no state makes obligatory never times out: such a watchdog never fires."""
    for agent in context.declared.agents:
        for subsystem in agent.subsystems:
            if subsystem.fsm is None:
                continue
            waited = {reference.name for state in subsystem.fsm.states for reference in state.obligatory}
            for predicate in subsystem.primitive_predicates:
                for node in walk(predicate.expression):
                    if not (isinstance(node, Call) and node.function == "timeout" and node.arguments):
                        continue
                    argument = node.arguments[0]
                    target = argument.target if isinstance(argument, Read) else None
                    if target is None or target.name in waited:
                        continue
                    yield Finding(
                        f"`timeout({reference_text(target)})` in `{predicate.name}/pp` is never true: "
                        f"`{target.name}/ib` is obligatory in no state of {subsystem_name(agent, subsystem)}",
                        node.location or predicate.location,
                        f"make it obligatory where it is awaited: `state S: B/bb {{ obligatory {_waited(target)} "
                        "timeout 50 ms }`",
                    )


def _waited(target: ElementReference) -> str:
    """How a buffer group names the buffer `timeout(…)` reads: `x/ib`, or `x[*]/ib` for a family, whose
    members a group names each (`x[2]/ib`) or all at once; `x/ib` alone is EARL-R024."""
    return f"{target.name}[*]/ib" if target.indices else f"{target.name}/ib"


#: levels an expression may have written out through the predicates it names: the checker's walks over a
#: condition recurse once per level, and a condition holds 100 levels of its own (the reader's limit)
MAX_PREDICATE_NESTING = 150


def predicate_depths(subsystem: Subsystem) -> dict[str, int]:
    """Per primitive predicate defined by an expression and not through itself (EARL-E045): how many levels
    its expression has written out, each predicate it names replaced by its definition. One walk, without
    recursion, over the predicates in the order they depend on each other."""
    definitions = {p.name: p.expression for p in subsystem.primitive_predicates if p.implementation is None}
    own: dict[str, list[tuple[int, str | None]]] = {}  # per predicate: (level, predicate named there or None)
    for name, expression in definitions.items():
        found: list[tuple[int, str | None]] = []
        stack = [(expression, 1)]
        while stack:
            node, level = stack.pop()
            named = (
                node.target.name if isinstance(node, Read) and node.target.kind is Kind.PRIMITIVE_PREDICATE else None
            )
            found.append((level, named if named in definitions else None))
            stack.extend((child, level + 1) for child in children(node))
        own[name] = found
    depths: dict[str, int] = {}
    open_: set[str] = set()
    for root in definitions:
        if root in depths:
            continue
        stack2: list[tuple[str, Iterator[str]]] = [(root, iter([n for _, n in own[root] if n is not None]))]
        open_.add(root)
        while stack2:
            name, pending = stack2[-1]
            inner = next(pending, None)
            if inner is None:
                stack2.pop()
                open_.discard(name)
                # a predicate named at level L is replaced there by its definition: its root takes level L
                depths[name] = max(level + (depths.get(n, 1) - 1 if n is not None else 0) for level, n in own[name])
            elif inner not in depths and inner not in open_:
                open_.add(inner)
                stack2.append((inner, iter([n for _, n in own[inner] if n is not None])))
            # a predicate met again while open is defined through itself: EARL-E045, counted as a leaf
    return depths


def followable_definitions(subsystem: Subsystem) -> dict[str, Expression]:
    """The definitions of the subsystem's primitive predicates that a walk over a condition may follow: those
    written as expressions (not computed by Python) and not too deep written out (EARL-E047); the others
    stay Booleans of their own to the FSM analysis and to EARL-W046."""
    depths = predicate_depths(subsystem)
    return {
        p.name: p.expression
        for p in subsystem.primitive_predicates
        if p.implementation is None and depths.get(p.name, 0) <= MAX_PREDICATE_NESTING
    }


@rule(
    "EARL-E047",
    Severity.ERROR,
    "a primitive predicate written out is at most 150 levels deep",
    "§2.2, Table 4",
)
def predicates_nested_too_deep(context: CheckContext) -> Iterator[Finding]:
    """A predicate defined through a long chain of others (`p1/pp = p2/pp and …`, thousands of them) is
    one expression thousands of levels deep once written out: the FSM analysis, which follows each
    predicate to its definition, would exceed Python's recursion limit. Reported at the first predicate
    too deep, not at each built on it."""
    for agent, subsystem in context.distinct_subsystems():
        depths = predicate_depths(subsystem)
        for predicate in subsystem.primitive_predicates:
            depth = depths.get(predicate.name, 0)
            if depth <= MAX_PREDICATE_NESTING:
                continue
            named = {
                node.target.name
                for node in walk(predicate.expression)
                if isinstance(node, Read) and node.target.kind is Kind.PRIMITIVE_PREDICATE
            }
            if any(depths.get(n, 0) > MAX_PREDICATE_NESTING for n in named):
                continue  # one it names is too deep already: said there
            yield Finding(
                f"primitive predicate `{predicate.name}/pp` of {subsystem_name(agent, subsystem)} is {depth} levels "
                f"deep written out through the predicates it names: at most {MAX_PREDICATE_NESTING}",
                predicate.location,
                "define it from fewer predicates in a row, e.g. an `and` of them side by side",
            )


@rule("EARL-E045", Severity.ERROR, "a primitive predicate is not defined through itself", "§2.2, Table 4")
def predicates_defined_through_themselves(context: CheckContext) -> Iterator[Finding]:
    """A primitive predicate defined through itself (`odd/pp = not odd/pp`, or `p/pp = not q/pp` with
    `q/pp = p/pp`) has no value: evaluating it would never end, and the FSM analysis leaves it free."""
    for agent, subsystem in context.distinct_subsystems():
        uses = {
            predicate.name: sorted(
                {
                    node.target.name
                    for node in walk(predicate.expression)
                    if isinstance(node, Read) and node.target.kind is Kind.PRIMITIVE_PREDICATE
                }
            )
            for predicate in subsystem.primitive_predicates
            if predicate.implementation is None
        }
        locations = {p.name: p.location for p in subsystem.primitive_predicates}
        reported: set[str] = set()
        for cycle in cycles(uses, uses.__getitem__):
            if set(cycle) <= reported:
                continue
            reported.update(cycle)
            first = cycle[0]
            yield Finding(
                f"primitive predicate `{first}/pp` of {subsystem_name(agent, subsystem)} is defined through itself "
                f"({' -> '.join(f'{n}/pp' for n in [*cycle, first])}), so it has no value",
                locations[first],
                "define it from buffers, memory and other predicates only",
            )
