"""Canonical `.earl` text for a model: what `earl fmt` prints and `System.to_earl()` returns.

Canonical means: four-space indentation, one declaration per line, the parts of a
subsystem in the order of manual §2.2 (period, parameters, buffers, memory,
predicates, functions, stages, behaviours, FSM), top-level declarations in the
order they were written, comments kept where they were.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from earl.lang.layout import agent_groups, apart, fsm_groups, subsystem_groups
from earl.model.elements import (
    FSM,
    Agent,
    Assumption,
    BasicBehaviour,
    Duration,
    Import,
    InputBuffer,
    Link,
    LinkEnd,
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
    is_duration,
)
from earl.model.expressions import ElementReference
from earl.model.location import Comments
from earl.model.text import (
    expression_text,
    family_text,
    index_text,
    literal_text,
    reference_text,
    robot_member_keys,
)
from earl.model.types import DataType, StructType, TypeAlias, type_text

INDENT = "    "


class _Printer:
    def __init__(self) -> None:
        self.lines: list[str] = []
        self.opened = -1  # how many lines there were when the last block's `{` was written

    def blank(self) -> None:
        """One blank line, never two, nor one first in a body (a "" a model built in Python put before
        its first member would not read back)."""
        if self.lines and self.lines[-1] != "" and len(self.lines) != self.opened:
            self.lines.append("")

    def line(self, depth: int, text: str, comments: Comments | None = None, closed: bool = False) -> None:
        """A line of code after its leading comments, ending with its own; `closed`: a block written on this
        one line, so the comment that followed its `}` ends the line too."""
        code = text
        if comments is not None:
            for comment in comments.leading:
                self.comment(depth, comment)
            if comments.trailing:
                text = f"{text}  {comments.trailing.strip()}"
            if closed and comments.after:
                text = f"{text}  {comments.after.strip()}"
        self.lines.append(f"{INDENT * depth}{text}")
        if code.endswith("{"):
            self.opened = len(self.lines)

    def comment(self, depth: int, comment: str) -> None:
        """A whole-line comment; "" is the blank line that kept it apart from what follows (one, however
        many are asked for in a row)."""
        # trailing space, the `\r` a CRLF file leaves in a comment, and leading space a model built in Python
        # gave it (which would indent it past its line's depth and read back without it)
        comment = comment.strip()
        if comment:
            self.lines.append(f"{INDENT * depth}{comment}")
        else:
            self.blank()

    def close(self, depth: int, comments: Comments) -> None:
        """A block's `}`, after the comments that ended its body, and with the comment written after it.

        A blank line before the `}` is left out: a file never has one there (the "" a model built in
        Python put last would come back as no comment, and the text be written otherwise the second time)."""
        closing = list(comments.closing)
        while closing and not closing[-1].strip():
            closing.pop()
        for comment in closing:
            self.comment(depth + 1, comment)
        self.line(depth, "}" + (f"  {comments.after.strip()}" if comments.after else ""))

    def text(self) -> str:
        while self.lines and self.lines[-1] == "":
            self.lines.pop()
        return "\n".join(self.lines) + "\n"


def duration_text(duration: Duration) -> str:
    if not is_duration(duration):
        raise TypeError(f"not a duration: {duration!r}")  # `Duration("20", "ms")` would print `"20" ms`
    return f"{literal_text(duration.value)} {duration.unit}"


def data_type_text(data_type: DataType) -> str:
    return type_text(data_type)


def _references(references: Iterable[ElementReference]) -> str:
    return ", ".join(reference_text(r) for r in references)


def _pf_set(references: Iterable[ElementReference]) -> str:
    return "{" + _references(references) + "}"


def link_end_text(end: LinkEnd) -> str:
    parts = []
    if end.agent is not None:
        parts.append(reference_text(end.agent))
    parts.append(reference_text(end.subsystem))
    indices = "".join(f"[{index_text(i)}]" for i in end.buffer.indices)
    parts.append(f"{end.buffer.name}{indices}")
    return ".".join(parts)


def format_system(system: System) -> str:
    """The whole system as canonical text, imports kept as `import` lines.

    A parameter of an imported file given another value since it was read (`load(path, {"N": 3})`, or
    an edit in Python) cannot be printed: the text holds the root file alone, and would read back with
    the imported file's value.
    That is a ValueError, never a text that silently means another system."""
    elsewhere = sorted(
        p.name
        for p in system.parameters
        if p.name in system.imported_values and p.value != system.imported_values[p.name] and not _from_root(system, p)
    )
    if elsewhere:
        where = next(
            (p.location.file for p in system.parameters if p.name == elsewhere[0] and p.location is not None),
            "an import",
        )
        raise ValueError(
            f"to_earl() prints the root file alone, and `{elsewhere[0]}`, given another value, is declared in "
            f"{where}, which it imports: the text would read back with that file's value. Give the value when the text "
            f"is read (`earl.loads(text, path, {{{elsewhere[0]!r}: …}})`, `--param {elsewhere[0]}=…`), or change it there"
        )
    printer = _Printer()
    for comment in system.comments.leading:
        printer.comment(0, comment)
    if system.name:
        printer.line(0, f"system {system.name}")
    declared = _declaration_order(system)
    for import_ in system.imports:
        printer.blank()
        _import(printer, import_)
    previous: object | None = None
    for declaration in declared:
        # One-line declarations of one kind (links, parameters, aliases) stay together as written.
        if apart(previous, declaration):
            printer.blank()
        previous = declaration
        if isinstance(declaration, Parameter):
            _parameter(printer, 0, declaration)
        elif isinstance(declaration, StructType):
            _struct(printer, declaration)
        elif isinstance(declaration, TypeAlias):
            printer.line(0, f"type {declaration.name} = {data_type_text(declaration.data_type)}", declaration.comments)
        elif isinstance(declaration, Robot):
            _robot(printer, declaration)
        elif isinstance(declaration, Agent):
            _agent(printer, declaration)
        elif isinstance(declaration, Link):
            _link(printer, 0, declaration)
        else:  # a model built in Python: never dropped without a word (System.to_earl says where)
            raise TypeError(f"not a declaration of a system: {declaration!r}")
    if system.comments.closing:
        printer.blank()
        for comment in system.comments.closing:
            printer.comment(0, comment)
    return printer.text()


def _from_root(system: System, element: object) -> bool:
    """True for declarations of the root file (or built in Python), not of an imported one."""
    location = getattr(element, "location", None)
    return location is None or system.source_file is None or location.file == system.source_file


def _declaration_order(system: System) -> list[object]:
    """The declarations to print: where `system.order` (as read) holds them all, its interleaving of
    parameters, types, agents, links and robots is kept, but within each list the list's own order wins,
    so that `system.agents.reverse()` on a loaded system is saved reversed. Otherwise parameters, types,
    agents, links, robots."""
    lists: list[list[Any]] = [system.parameters, system.types, system.agents, system.links, system.robots]
    mine = [[d for d in declarations if _from_root(system, d)] for declarations in lists]
    owner = {id(d): position for position, declarations in enumerate(mine) for d in declarations}
    slots = [owner.get(id(o)) for o in system.order]
    if any(slots.count(position) != len(declarations) for position, declarations in enumerate(mine)) or (None in slots):
        return [d for declarations in mine for d in declarations]
    following = [iter(declarations) for declarations in mine]
    return [next(following[position]) for position in slots]  # type: ignore[index]


def _import(printer: _Printer, import_: Import) -> None:
    printer.line(0, f"import {literal_text(import_.path)}", import_.comments)


def _parameter(printer: _Printer, depth: int, parameter: Parameter) -> None:
    text = f"param {parameter.name}: {data_type_text(parameter.data_type)} = {expression_text(parameter.value)}"
    printer.line(depth, text, parameter.comments)


def _struct(printer: _Printer, struct: StructType) -> None:
    if not struct.fields and not struct.comments.closing:
        printer.line(0, f"struct {struct.name} {{}}", struct.comments, closed=True)
        return
    printer.line(0, f"struct {struct.name} {{", struct.comments)
    for field in struct.fields:
        if not isinstance(field.optional, bool):  # `optional="yes"`: a model built in Python, named at its path
            raise TypeError(f"not a bool: {field.optional!r}")
        optional = "?" if field.optional else ""
        printer.line(1, f"{field.name}: {data_type_text(field.data_type)}{optional}", field.comments)
    printer.close(0, struct.comments)


def _robot(printer: _Printer, robot: Robot) -> None:
    printer.line(0, f"{robot.name}/r {{", robot.comments)
    written = [reference_text(agent) for agent in robot.agents] + [f"link {link.name}" for link in robot.links]
    for text, key in zip(written, robot_member_keys(robot), strict=True):
        printer.line(1, text, robot.member_comments.get(key))
    printer.close(0, robot.comments)


def _agent(printer: _Printer, agent: Agent) -> None:
    printer.line(0, f"{family_text(agent.name, agent.family)}/a {{", agent.comments)
    for index, group in enumerate(agent_groups(agent)):
        if index:
            printer.blank()
        for item in group:
            if isinstance(item, Parameter):
                _parameter(printer, 1, item)
            elif isinstance(item, Subsystem):
                _subsystem(printer, item)
            elif isinstance(item, Link):
                _link(printer, 1, item)
            else:  # a model built in Python: never left out without a word
                raise TypeError(f"not a part of an agent: {item!r}")
    printer.close(0, agent.comments)


def _link(printer: _Printer, depth: int, link: Link) -> None:
    text = f"link {link.name_text}: {link_end_text(link.source)} -> {link_end_text(link.destination)}"
    printer.line(depth, text, link.comments)


def _subsystem(printer: _Printer, subsystem: Subsystem) -> None:
    header = (
        "cs"
        if subsystem.kind.value == "cs"
        else f"{family_text(subsystem.name, subsystem.family)}/{subsystem.kind.value}"
    )
    printer.line(1, f"{header} {{", subsystem.comments)
    depth = 2
    for index, group in enumerate(subsystem_groups(subsystem)):
        if index:
            printer.blank()
        for item in group:
            if isinstance(item, str):  # the period, whose comments its subsystem keeps
                period = subsystem.period
                if not isinstance(period, Duration):  # a model built in Python: named, never left out
                    raise TypeError(f"not a period of a subsystem: {period!r}")
                printer.line(depth, f"period {duration_text(period)}", subsystem.clause_comments.get(item))
            elif isinstance(item, BasicBehaviour):
                _basic_behaviour(printer, depth, item)
            elif isinstance(item, FSM):
                _fsm(printer, depth, item)
            else:
                _body_item(printer, depth, item)
    printer.close(1, subsystem.comments)


def _body_item(printer: _Printer, depth: int, item: object) -> None:
    if isinstance(item, Parameter):
        _parameter(printer, depth, item)
    elif isinstance(item, InputBuffer):
        text = f"{family_text(item.name, item.family)}/ib: {data_type_text(item.data_type)}"
        if item.queue is not None:
            text += f" fifo {expression_text(item.queue.capacity)} overflow {item.queue.overflow}"
        printer.line(depth, text, item.comments)
    elif isinstance(item, OutputBuffer):
        printer.line(
            depth, f"{family_text(item.name, item.family)}/ob: {data_type_text(item.data_type)}", item.comments
        )
    elif isinstance(item, Memory):
        text = f"{family_text(item.name, item.family)}/m: {data_type_text(item.data_type)}"
        if item.initial_value is not None:
            text += f" = {expression_text(item.initial_value)}"
        printer.line(depth, text, item.comments)
    elif isinstance(item, PrimitivePredicate):
        if item.implementation is not None:
            text = f"{item.name}/pp({_references(item.reads)}) = python {literal_text(item.implementation.path)}"
            printer.line(depth, text, item.comments)
        else:
            printer.line(depth, f"{item.name}/pp = {expression_text(item.expression)}", item.comments)
    elif isinstance(item, PartialTransitionFunction):
        reads = _references(item.reads)
        writes = _references(item.writes)
        arrow = f"{reads} -> {writes}".strip()
        text = f"{item.name}/pf({arrow})"
        if item.implementation is not None:
            text += f" = python {literal_text(item.implementation.path)}"
        printer.line(depth, text, item.comments)
    elif isinstance(item, StageSet):
        printer.line(depth, f"stage {item.name} = {_pf_set(item.functions)}", item.comments)
    else:  # a model built in Python (`period = "2 ms"`): never left out without a word (to_earl says where)
        raise TypeError(f"not a declaration of a subsystem: {item!r}")


def _basic_behaviour(printer: _Printer, depth: int, behaviour: BasicBehaviour) -> None:
    printer.line(depth, f"{behaviour.name}/bb {{", behaviour.comments)
    stages = " then ".join(_pf_set(stage) for stage in behaviour.transition_function.stages) or "{}"
    said = behaviour.clause_comments
    printer.line(depth + 1, f"tf = {stages}", said.get("tf"))
    printer.line(depth + 1, f"tc = {expression_text(behaviour.terminal_condition.expression)}", said.get("tc"))
    if behaviour.error_condition is not None:
        printer.line(depth + 1, f"ec = {expression_text(behaviour.error_condition.expression)}", said.get("ec"))
    printer.close(depth, behaviour.comments)


def _fsm(printer: _Printer, depth: int, fsm: FSM) -> None:
    printer.line(depth, "fsm {", fsm.comments)
    if not isinstance(fsm.initial, str):  # a model built in Python: `initial None` would read back otherwise
        raise TypeError(f"the initial state is {fsm.initial!r}, not a name")
    for index, group in enumerate(fsm_groups(fsm)):
        if index:
            printer.blank()
        for item in group:
            if isinstance(item, str):  # `initial`, whose comments the FSM keeps
                printer.line(depth + 1, f"initial {fsm.initial}", fsm.clause_comments.get("initial"))
            elif isinstance(item, State):
                _state(printer, depth + 1, item)
            elif isinstance(item, Transition):
                _transition(printer, depth + 1, item)
            elif isinstance(item, Assumption):
                printer.line(depth + 1, f"assume {expression_text(item.expression)}", item.comments)
            else:  # a model built in Python: never left out without a word
                raise TypeError(f"not a part of an FSM: {item!r}")
    printer.close(depth, fsm.comments)


def _state(printer: _Printer, depth: int, state: State) -> None:
    text = f"state {state.name}: {state.behaviour}/bb"
    group = []
    if state.obligatory:
        group.append(f"obligatory {_references(state.obligatory)}")
    if state.optional:
        group.append(f"optional {_references(state.optional)}")
    if state.timeout is not None:
        group.append(f"timeout {duration_text(state.timeout)}")
    said = state.clause_comments
    if not any(_has_comments(c) for c in said.values()) and not state.comments.closing:
        if group:
            text += " { " + "  ".join(group) + " }"
        printer.line(depth, text, state.comments, closed=True)
        return
    # a body with comments in it is written a clause a line, each clause with the comments of the lines
    # it was written on
    printer.line(depth, text + " {", state.comments)
    for clause in group:
        printer.line(depth + 1, clause, _merged([c for k, c in said.items() if k.startswith(clause.split()[0] + " ")]))
    printer.close(depth, state.comments)


def _has_comments(comments: Comments) -> bool:
    return bool(comments.leading or comments.trailing or comments.closing)


def _merged(said: list[Comments]) -> Comments:
    """The comments of several lines written as one: every one kept, the first end-of-line comment at
    the end of the line, the others above it."""
    merged = Comments()
    for comments in said:
        merged.leading.extend(comments.leading)
        if comments.trailing:
            if merged.trailing is None:
                merged.trailing = comments.trailing
            else:
                merged.leading.append(comments.trailing)
    return merged


def _transition(printer: _Printer, depth: int, transition: Transition) -> None:
    source = transition.source if transition.source is not None else "*"
    text = f"{source} -> {transition.destination} when {expression_text(transition.condition.expression)}"
    if transition.priority is not None:
        if isinstance(transition.priority, bool) or not isinstance(transition.priority, int):
            raise TypeError(f"not a priority: {transition.priority!r}")  # `priority True` would not read back
        text += f" priority {transition.priority}"
    printer.line(depth, text, transition.comments)
