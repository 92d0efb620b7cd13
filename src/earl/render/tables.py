"""The manual's tables of a subsystem (§3.2), computed from the spec.

- Table 3: Internal Memory and its dataTypes;
- Table 4: the `fun` of each Primitive Predicate;
- Table 5: initial conditions of FSM Transitions, terminal (and error) conditions of Basic Behaviours,
  and the FSM's assumptions, which the manual states in the table's caption;
- Table 6: Transition Function compositions, with a bullet where a Partial
  Transition Function writes an Internal Memory (`/mo`) or an Output Buffer (`/ob`).

Rows are data; `earl.render.document` turns them into HTML and Markdown.  A
declared family is one row or column (`windingCurrent[K]`); an expanded one has a
row or column per member.
"""

from __future__ import annotations

from dataclasses import dataclass

from earl.model.elements import FSM, PrimitivePredicate, Subsystem
from earl.model.kinds import Kind
from earl.model.location import Comments
from earl.model.text import expression_text
from earl.model.types import type_text
from earl.render.names import Key, element_key, family_note, indexed_name, lookup


@dataclass(frozen=True)
class MemoryRow:  # Table 3
    name: str  # `windingCurrent[K]`
    data_type: str
    initial_value: str | None
    family: str | None  # `K ∈ 1..N`


@dataclass(frozen=True)
class PredicateRow:  # Table 4
    name: str
    fun: str


@dataclass(frozen=True)
class TransitionRow:  # Table 5, upper part
    name: str  # `idle,jointMove` or `*,emergencyStop`
    source: str | None  # None: every state other than the destination
    destination: str
    predicate: str
    priority: int | None
    line: int | None = None  # where it was written: two transitions between the same states differ there


@dataclass(frozen=True)
class ConditionRow:  # Table 5, lower part
    behaviour: str
    terminal_condition: str
    error_condition: str | None


@dataclass(frozen=True)
class AssumptionRow:  # Table 5's caption: "It is assumed that task/a can not set simultaneously …"
    formula: str  # in EARL text, `not (newJointPos/pp and newOperationalPos/pp)`
    comment: str | None  # what the person wrote above or after it, in words


@dataclass(frozen=True)
class Column:
    """A column of Table 6: an Internal Memory written through `mo`, or an Output Buffer."""

    name: str  # `windingCurrent[K]`
    kind: Kind  # MEMORY_OUTPUT or OUTPUT_BUFFER
    key: Key


@dataclass(frozen=True)
class CompositionRow:
    behaviour: str
    function: str
    stage: int  # 1 for the first stage of the behaviour's Transition Function
    writes: frozenset[Key]
    known: bool  # False when the spec names a function it does not declare (the checker says so)


@dataclass(frozen=True)
class CompositionTable:  # Table 6
    columns: tuple[Column, ...]
    rows: tuple[CompositionRow, ...]

    def bullet(self, row: CompositionRow, column: Column) -> bool:
        return column.key in row.writes

    def matrix(self) -> dict[tuple[str, str], frozenset[str]]:
        """(behaviour, function) → the names of the columns it writes: the table, cell by cell."""
        return {
            (row.behaviour, row.function): frozenset(c.name for c in self.columns if self.bullet(row, c))
            for row in self.rows
        }


def memory_table(subsystem: Subsystem) -> list[MemoryRow]:
    return [
        MemoryRow(
            indexed_name(memory),
            type_text(memory.data_type),
            None if memory.initial_value is None else expression_text(memory.initial_value),
            family_note(memory),
        )
        for memory in subsystem.memories
    ]


def predicate_table(subsystem: Subsystem) -> list[PredicateRow]:
    return [PredicateRow(p.name, _definition(p)) for p in subsystem.primitive_predicates]


def _definition(predicate: PrimitivePredicate) -> str:
    """A predicate's `fun`; one computed by Python names its code: `python "gripping:stable"(grip/mi)`."""
    written = expression_text(predicate.expression)
    if predicate.implementation is None:
        return written
    arguments = written[len("python") :] if written.startswith("python(") else f"({written})"
    return f'python "{predicate.implementation.path}"{arguments}'


def transition_table(subsystem: Subsystem) -> list[TransitionRow]:
    if subsystem.fsm is None:
        return []
    return [
        TransitionRow(
            t.name,
            t.source,
            t.destination,
            expression_text(t.condition.expression),
            t.priority,
            t.location.line if t.location is not None else None,
        )
        for t in subsystem.fsm.transitions
    ]


def assumption_table(fsm: FSM | None) -> list[AssumptionRow]:
    """The FSM's `assume` formulas with their comments: facts the FSM relies on, which the document and the
    FSM diagram state beside the conditions, as the manual's Table 5 caption does."""
    if fsm is None:
        return []
    return [AssumptionRow(expression_text(a.expression), comment_words(a.comments)) for a in fsm.assumptions]


def comment_words(comments: Comments | None) -> str | None:
    """A person's `//` comments as one sentence: markers dropped, a ruler (`// ---- …`, which heads a section of
    the file, not the element under it) left out; None when nothing was said."""
    if comments is None:
        return None
    said = []
    for line in [*comments.leading, *([comments.trailing] if comments.trailing else [])]:
        words = line.strip().removeprefix("//").strip()
        if words and not words.startswith("----"):
            said.append(words)
    return " ".join(said) or None


def condition_table(subsystem: Subsystem) -> list[ConditionRow]:
    return [
        ConditionRow(
            b.name,
            expression_text(b.terminal_condition.expression),
            None if b.error_condition is None else expression_text(b.error_condition.expression),
        )
        for b in subsystem.basic_behaviours
    ]


def composition_table(subsystem: Subsystem) -> CompositionTable:
    """Table 6: for each Basic Behaviour, the functions of its Transition Function and what each writes.

    The bullets come from each function's declared writes, the same declarations
    the runtime enforces, so the table cannot drift from what executes.
    """
    columns = [Column(indexed_name(m), Kind.MEMORY_OUTPUT, element_key(m, Kind.MEMORY)) for m in subsystem.memories]
    columns += [
        Column(indexed_name(b), Kind.OUTPUT_BUFFER, element_key(b, Kind.OUTPUT_BUFFER))
        for b in subsystem.output_buffers
    ]
    by_key = {column.key: column for column in columns}
    rows = []
    for behaviour in subsystem.basic_behaviours:
        for stage_number, stage in enumerate(behaviour.transition_function.stages, start=1):
            for reference in stage:
                function = subsystem.partial_transition_function(reference.name)
                written: set[Key] = set()
                for write in function.writes if function is not None else []:
                    column = lookup(by_key, write)
                    if column is not None:
                        written.add(column.key)
                rows.append(
                    CompositionRow(
                        behaviour.name, reference.name, stage_number, frozenset(written), function is not None
                    )
                )
    return CompositionTable(tuple(columns), tuple(rows))
