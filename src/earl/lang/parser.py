"""Reading `.earl` text: bytes to text, text to declarations, comments kept for the formatter."""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Callable
from functools import lru_cache
from importlib import resources
from itertools import pairwise
from typing import Any

from lark import Lark, Token
from lark.exceptions import UnexpectedInput

from earl.collector import paused as collection_paused
from earl.diagnostics import Diagnostic, EarlError, Severity, SourceMap
from earl.lang import reductions
from earl.lang.driver import Driver, NotWellFormed
from earl.lang.layout import agent_groups, apart, behaviour_groups, fsm_groups, subsystem_groups
from earl.lang.syntax_errors import translate
from earl.lang.transformer import ElementBuilder, ParsedFile, SpecificationSyntaxError
from earl.model.elements import FSM, Agent, BasicBehaviour, Import, Robot, State, Subsystem
from earl.model.location import Comments, SourceLocation
from earl.model.text import robot_member_keys
from earl.model.types import StructType

#: Larger files are refused before parsing.  The benchmark's thousand agents, written out in
#: full, take 5 MB and some 4–5 s of CPU to read (benchmarks/results/parse.json); a file much
#: larger than that would look like a hang rather than a spec, while a 10 MB file gets its
#: error at once.
MAX_FILE_BYTES = 8 * 1024 * 1024


class _CommentCollector:
    """Lark calls this for every comment token; the parse that is running owns the list."""

    def __init__(self) -> None:
        self.comments: list[Token] = []

    def __call__(self, token: Token) -> Token:
        self.comments.append(token)
        return token


_collector = _CommentCollector()


def _grammar() -> str:
    return resources.files("earl.lang").joinpath("earl.lark").read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def _parser() -> Lark:
    """The parser that builds a tree: only used to explain a syntax error, from its stack."""
    return Lark(
        _grammar(),
        parser="lalr",
        propagate_positions=True,
        maybe_placeholders=False,
        strict=True,  # a shift/reduce conflict in the grammar is an error, never a silent choice
        cache=True,  # the LALR tables are computed once per grammar and kept in the temporary directory
    )


class _ElementParser:
    """Lark's LALR parser with callbacks that build elements as it reduces (see `reductions.py`)."""

    def __init__(self) -> None:
        self.lark = Lark(
            _grammar(),
            parser="lalr",
            propagate_positions=False,  # spans are measured by the callbacks, more cheaply
            maybe_placeholders=False,
            strict=True,
            cache=True,
            lexer_callbacks={"COMMENT": _collector},
        )
        self.builder = ElementBuilder("<text>")
        self.spans = reductions.SpanTable()
        reductions.install(self.lark.parser.parser.parser, self.builder, self.spans)
        self.driver = Driver(self.lark)

    def parse(self, text: str, path: str) -> ParsedFile:
        self.builder.reset(path)
        self.spans.clear()
        try:
            try:
                parsed: ParsedFile = self.driver.read(text)  # the callbacks build it
            except NotWellFormed:
                # Lark's own loops, from the start, meet the same spot and raise Lark's own error
                self.builder.reset(path)
                self.spans.clear()
                _collector.comments.clear()
                parsed = self.lark.parse(text)  # type: ignore[assignment]
        finally:
            self.spans.clear()
            self.builder.reset("<text>")
        return parsed


@lru_cache(maxsize=1)
def _element_parser() -> _ElementParser:
    return _ElementParser()


@lru_cache(maxsize=1)
def keyword_terminals() -> dict[str, str]:
    """Terminal name → keyword text, for messages and did-you-mean hints."""
    result: dict[str, str] = {}
    # the reader's own parser has the grammar's terminals: no second parser is made for them
    for terminal in _element_parser().lark.terminals:
        pattern = terminal.pattern
        if pattern.type == "str" and pattern.value.isidentifier():
            result[terminal.name] = pattern.value
    return result


@lru_cache(maxsize=1)
def keywords() -> frozenset[str]:
    """Every keyword of the grammar (`state`, `period`, `false`, …)."""
    return frozenset(keyword_terminals().values())


def too_large(path: str, size: int | None) -> Diagnostic:
    """The error for a file over MAX_FILE_BYTES; `size` None when unknown (a device or a pipe)."""
    measured = f"{size / 2**20:.1f} MiB" if size is not None else f"more than {MAX_FILE_BYTES // 2**20} MiB"
    return Diagnostic(
        Severity.ERROR,
        f"the file is {measured}; specifications larger than {MAX_FILE_BYTES // 2**20} MiB are refused",
        SourceLocation(path, 1, 1, 1, 1),
        code="EARL-S020",
        hint="split the system into files joined with `import`",
    )


def decode(data: bytes, path: str) -> str:
    """The text of a spec file, or an error saying why these bytes are not one."""
    location = SourceLocation(path, 1, 1, 1, 1)
    if len(data) > MAX_FILE_BYTES:
        raise EarlError([too_large(path, len(data))])
    if b"\x00" in data[:8192]:
        raise EarlError(
            [
                Diagnostic(
                    Severity.ERROR,
                    "this is a binary file, not an `.earl` specification",
                    location,
                    code="EARL-S021",
                    hint="an `.earl` specification is UTF-8 text",
                )
            ]
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        column = error.start - (data.rfind(b"\n", 0, error.start) + 1) + 1
        raise EarlError(
            [
                Diagnostic(
                    Severity.ERROR,
                    f"the file is not UTF-8 text: byte 0x{data[error.start]:02x} cannot be decoded",
                    SourceLocation(path, line, column, line, column + 1),
                    code="EARL-S022",
                    hint="save the file as UTF-8",
                )
            ]
        ) from None
    return text.removeprefix("\ufeff")


def parse_text(text: str, path: str = "<text>", sources: SourceMap | None = None) -> ParsedFile:
    """The declarations of one file, or an `EarlError` with one located diagnostic."""
    if "\r" in text:
        # Windows' and old Macs' line ends are lines too: a lone `\r` would otherwise end no comment,
        # and `// note\rparam N …` would hide the parameter in the comment
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    sources = sources if sources is not None else SourceMap()
    sources.add(path, text)
    _collector.comments = []
    try:
        with collection_paused():
            parsed = _element_parser().parse(text, path)
    except UnexpectedInput as error:
        raise EarlError([_explain(error, path, text)], sources) from None
    except SpecificationSyntaxError as error:
        raise EarlError([error.diagnostic], sources) from None
    comments = _collector.comments
    if parsed.system_location is not None:
        header_line = parsed.system_location.line
        parsed.header_comments = _with_blank_lines([c for c in comments if (c.line or 1) <= header_line], header_line)
        comments = [c for c in comments if (c.line or 1) > header_line]
    parsed.closing_comments = attach_comments(parsed.declarations, comments, path, text)
    keep_blank_lines(parsed.declarations, text)
    return parsed


def _with_blank_lines(comments: list[Token], before_line: int) -> list[str]:
    """The header's comments, with "" where a blank line kept two blocks apart (a licence, then what
    the file is), and before the `system` line when one kept them from it."""
    lines: list[str] = []
    previous_end: int | None = None
    for comment in comments:
        line = comment.line or 1
        if previous_end is not None and line > previous_end + 1:
            lines.append("")
        lines.append(str(comment))
        previous_end = comment.end_line or line
    if previous_end is not None and previous_end < before_line - 1:
        lines.append("")
    return lines


def _explain(error: UnexpectedInput, path: str, text: str) -> Diagnostic:
    """The syntax error as one sentence, read from the stack of the tree-building parser.

    The element parser's stack holds elements, not the trees `syntax_errors` reads, so
    the text is parsed again, as trees, up to the same error; an error is rare and the
    second parse stops where the first did.
    """
    try:
        _parser().parse(text)
    except UnexpectedInput as again:
        error = again
    return translate(error, path, text, keyword_terminals())


#: The attributes that hold an element's parts, in any order; `fsm` holds one part, not a list.
_PART_LISTS = (
    "fields",
    "subsystems",
    "links",
    "parameters",
    "input_buffers",
    "output_buffers",
    "memories",
    "primitive_predicates",
    "partial_transition_functions",
    "stage_sets",
    "basic_behaviours",
    "states",
    "transitions",
    "assumptions",
)

#: Per class: whether it carries comments, which of `_PART_LISTS` it has, whether it has an `fsm`, and
#: what else of it carries comments (a robot's members, the clauses of a subsystem, behaviour, FSM, state).
_Shape = tuple[bool, tuple[str, ...], bool, Callable[[Any], list[Any]] | None]
_SHAPES: dict[type, _Shape] = {}


def _shape(cls: type) -> _Shape:
    fields = {f.name for f in getattr(cls, "__dataclass_fields__", {}).values()}
    inner = next((found for kind, found in _INNER.items() if issubclass(cls, kind)), None)
    shape = ("comments" in fields, tuple(a for a in _PART_LISTS if a in fields), "fsm" in fields, inner)
    _SHAPES[cls] = shape
    return shape


def _statements(declarations: list[Any]) -> list[Any]:
    """Every element that can carry comments, in any order (sorted later)."""
    found: list[Any] = []
    stack = list(declarations)
    while stack:
        element = stack.pop()
        carries, parts, has_fsm, inner = _SHAPES.get(type(element)) or _shape(type(element))
        if carries and element.location is not None:
            found.append(element)
        for attribute in parts:
            stack.extend(getattr(element, attribute) or ())
        if has_fsm and element.fsm is not None:
            stack.append(element.fsm)
        if inner is not None:
            found.extend(inner(element))
    return found


def _state_clauses(state: State) -> list[tuple[str, SourceLocation | None]]:
    """The lines of a state's body: each line that names obligatory or optional buffers (at its first
    buffer), and the timeout."""
    clauses: list[tuple[str, SourceLocation | None]] = []
    for clause, references in (("obligatory", state.obligatory), ("optional", state.optional)):
        lines: dict[int, SourceLocation] = {}
        for reference in references:
            if reference.location is not None and reference.location.line > (state.location or reference.location).line:
                lines.setdefault(reference.location.line, reference.location)
        clauses.extend((f"{clause} {number}", location) for number, location in enumerate(lines.values()))
    clauses.append(("timeout 0", state.timeout_location))
    return clauses


def _behaviour_clauses(behaviour: BasicBehaviour) -> list[_Clause]:
    error = behaviour.error_condition
    clauses = [
        ("tf", behaviour.transition_function.location),
        ("tc", behaviour.terminal_condition.location),
        ("ec", error.location if error is not None else None),
    ]
    return _clauses(behaviour, clauses)


class _Clause:
    """A clause (`period 2 ms`, `tc = …`, `initial idle`) as the comments see it: where it was written,
    and its owner's `Comments` for it, made only when a comment comes to it."""

    __slots__ = ("_key", "_owner", "location")

    def __init__(self, location: SourceLocation, owner: dict[str, Comments], key: str) -> None:
        self.location = location
        self._owner = owner
        self._key = key

    @property
    def comments(self) -> Comments:
        return self._owner.setdefault(self._key, Comments())


def _clauses(
    element: Subsystem | BasicBehaviour | FSM | State, clauses: list[tuple[str, SourceLocation | None]]
) -> list[_Clause]:
    return [_Clause(location, element.clause_comments, key) for key, location in clauses if location is not None]


#: the things inside an element, besides its parts, that carry comments of their own
_INNER: dict[type, Callable[[Any], list[Any]]] = {
    Robot: lambda robot: _robot_members(robot),
    Subsystem: lambda subsystem: _clauses(subsystem, [("period", subsystem.period_location)]),
    BasicBehaviour: lambda behaviour: _behaviour_clauses(behaviour),
    FSM: lambda fsm: _clauses(fsm, [("initial", fsm.initial_location)]),
    State: lambda state: _clauses(state, _state_clauses(state)),
}


class _RobotMember:
    """A robot's member as the comments see it: where it was written, and the robot's `Comments` for it."""

    __slots__ = ("comments", "location")

    def __init__(self, location: SourceLocation, comments: Comments) -> None:
        self.location = location
        self.comments = comments


def _robot_members(robot: Robot) -> list[_RobotMember]:
    return [
        _RobotMember(location, robot.member_comments.setdefault(key, Comments()))
        for key, location in zip(robot_member_keys(robot), _member_locations(robot), strict=True)
        if location is not None
    ]


def _member_locations(robot: Robot) -> list[SourceLocation | None]:
    return [agent.location for agent in robot.agents] + [link.location for link in robot.links]


#: the elements written with braces around a body, which keep the comments that end it (`Comments.closing`)
_BLOCKS: tuple[type, ...] = (StructType, Robot, Agent, Subsystem, BasicBehaviour, FSM, State)


def _closing_braces(statements: list[Any], blocks: list[Any], comments: list[Token], text: str) -> dict[int, Any]:
    """By line: the block whose `}` is the last thing on that line before its comment (the outermost of
    those closed there); a line where another element starts after that `}` has none."""
    commented = {comment.line: comment for comment in comments}  # a `//` comment runs to the line's end
    closes: dict[int, Any] = {}
    for block in blocks:
        location = block.location
        end = location.end_line
        comment = commented.get(end)
        if comment is None or comment.start_pos is None:
            continue
        line_start = text.rfind("\n", 0, comment.start_pos) + 1
        if text[line_start + location.end_column - 2 : line_start + location.end_column - 1] != "}":
            continue  # a state without a body ends at its behaviour's name
        if location.line == end and (isinstance(block, State) or (isinstance(block, StructType) and not block.fields)):
            continue  # written on one line by `earl fmt` too: its end-of-line comment is the line's own
        known = closes.get(end)
        if known is None or location.end_column > known.location.end_column:
            closes[end] = block
    if closes:
        for element in statements:  # `} b/a {`: the comment is the next element's
            location = element.location
            closed = closes.get(location.line)
            if closed is not None and location.column >= closed.location.end_column:
                del closes[location.line]
    return closes


def _behaviour_clause_places(behaviour: BasicBehaviour) -> dict[str, Any]:
    error = behaviour.error_condition
    return {
        "tf": behaviour.transition_function.location,
        "tc": behaviour.terminal_condition.location,
        "ec": error.location if error is not None else None,
    }


def _robot_member_places(robot: Robot) -> dict[str, Any]:
    return dict(zip(robot_member_keys(robot), _member_locations(robot), strict=True))


class _BlankLines:
    """keep_blank_lines for one file: whether a blank line follows a line, the text split only when a
    comment stands between two members (lines between two members are blank otherwise: a comment there
    would be the second's), as this runs on every read."""

    __slots__ = ("lines", "text")

    def __init__(self, text: str) -> None:
        self.text = text
        self.lines: list[str] | None = None

    def after(self, line: int) -> bool:
        """Whether the line after `line` is blank."""
        if self.lines is None:
            self.lines = self.text.split("\n")
        return line < len(self.lines) and not self.lines[line].strip()

    def parted(self, previous: SourceLocation, location: SourceLocation, said: Comments | None) -> bool:
        """Whether a blank line was written right after `previous` (the member before in the body), above
        the member at `location` whose comments are `said`."""
        if location.line <= previous.end_line + 1:
            return False
        return said is None or not said.leading or self.after(previous.end_line)

    def keep(
        self,
        block: Any,
        groups: list[list[Any]],
        clauses: dict[str, Any] | None = None,
        table: dict[str, Comments] | None = None,
    ) -> None:
        """The members of `block`, in the groups `earl fmt` writes them in (layout.py); `clauses`: where
        the clauses named there are (`tc`, or `a/a` in a robot), whose comments are in `table`."""
        location = block.location
        if location is None:
            return
        clauses = clauses if clauses is not None else {}
        table = table if table is not None else {}
        previous: SourceLocation | None = None  # the member before, as `earl fmt` writes them
        blank: list[tuple[Any, Comments | None]] = []  # the members with a blank line above, and their comments
        for group in groups:
            starts = True
            for item in group:
                at = clauses.get(item) if isinstance(item, str) else item.location
                if at is None:
                    continue
                if previous is not None:
                    if at.line < previous.end_line:
                        self.keep_in_order_written(block, groups, clauses, table)  # not the order `earl fmt` writes
                        return
                    if not starts and at.line > previous.end_line + 1:
                        said = table.get(item) if isinstance(item, str) else item.comments
                        if self.parted(previous, at, said):
                            blank.append((item, said))
                previous = at
                starts = False
        for item, said in blank:
            _blank_first(table.setdefault(item, Comments()).leading if said is None else said.leading)
        self.closing(block, previous)

    def keep_in_order_written(
        self, block: Any, groups: list[list[Any]], clauses: dict[str, Any], table: dict[str, Comments]
    ) -> None:
        """`keep` for a body written in another order than `earl fmt`'s: the blank line is the one after
        the member written before."""
        members = []  # where, the member or its key, whether it starts a group
        for group in groups:
            for index, item in enumerate(group):
                at = clauses.get(item) if isinstance(item, str) else item.location
                if at is not None:
                    members.append((at, item, index == 0))
        members.sort(key=lambda member: (member[0].line, member[0].column))
        for (previous, _, _), (at, item, starts) in pairwise(members):
            said = table.get(item) if isinstance(item, str) else item.comments
            if not starts and self.parted(previous, at, said):
                _blank_first(table.setdefault(item, Comments()).leading if said is None else said.leading)
        self.closing(block, members[-1][0] if members else None)

    def closing(self, block: Any, last: SourceLocation | None) -> None:
        """A blank line after the last member of a body, before the comments that close it."""
        closing = block.comments.closing
        if closing and last is not None and last.end_line + 1 < block.location.end_line and self.after(last.end_line):
            _blank_first(closing)


def keep_blank_lines(declarations: list[Any], text: str) -> None:
    """A blank line a person left between two members of a body, to group them (two input buffers, two
    states, two top-level parameters): kept as a "" first in the second's leading comments, as one between
    a comment block and what follows is kept. Not where `earl fmt` writes one of its own, before the first
    of a group (layout.py): it is there anyway, and a model read back from `earl fmt`'s text is the one
    printed. Also a blank line before the comments that close a body. Several blank lines are one."""
    blank = _BlankLines(text)
    _keep_at_top_level(declarations, blank)
    for declaration in declarations:
        if isinstance(declaration, StructType):
            blank.keep(declaration, [declaration.fields])
        elif isinstance(declaration, Robot):
            places = _robot_member_places(declaration)
            blank.keep(declaration, [list(places)], places, declaration.member_comments)
        elif isinstance(declaration, Agent):
            blank.keep(declaration, agent_groups(declaration))
            for subsystem in declaration.subsystems:
                period = {"period": subsystem.period_location}
                blank.keep(subsystem, subsystem_groups(subsystem), period, subsystem.clause_comments)
                for behaviour in subsystem.basic_behaviours:
                    clauses = _behaviour_clause_places(behaviour)
                    blank.keep(behaviour, behaviour_groups(behaviour), clauses, behaviour.clause_comments)
                if (fsm := subsystem.fsm) is not None:
                    initial = {"initial": fsm.initial_location}
                    blank.keep(fsm, fsm_groups(fsm), initial, fsm.clause_comments)


def _blank_first(comments: list[str]) -> None:
    if comments[:1] != [""]:
        comments.insert(0, "")


def _keep_at_top_level(declarations: list[Any], blank: _BlankLines) -> None:
    """keep_blank_lines between two top-level declarations: `earl fmt` writes imports first, each after a
    blank line, and the others in the order written, parted as `layout.apart` says."""
    previous: Any = None  # the one `earl fmt` writes before, imports aside
    above: SourceLocation | None = None  # where the one written before ends, an import too
    for declaration in declarations:
        at = declaration.location
        if (
            not isinstance(declaration, Import)
            and above is not None
            and at is not None
            and not apart(previous, declaration)
            and blank.parted(above, at, declaration.comments)
        ):
            _blank_first(declaration.comments.leading)
        if not isinstance(declaration, Import):
            previous = declaration
        above = at if at is not None else above


def attach_comments(declarations: list[Any], comments: list[Token], path: str, text: str | None = None) -> list[str]:
    """Give each comment to the element it sits above, or ends the line of; return those after the last.

    A blank line that parts a comment from the comment or element below it is kept as an
    empty entry in `leading`, so section headers stay apart from what they introduce.
    """
    closing: list[str] = []
    if not comments:
        return closing
    blank_lines: set[int] | None = None

    def parted(first: int, last: int) -> bool:
        """Whether a blank line lies between lines `first` and `last` (lines of code between two
        comments part them no more than the blank lines the source has: a comment above `tf` and one
        above `tc` stay one block)."""
        nonlocal blank_lines
        if last <= first + 1:
            return False
        if text is None:
            return True
        if blank_lines is None:
            blank_lines = {number for number, line in enumerate(text.split("\n"), start=1) if not line.strip()}
        return any(number in blank_lines for number in range(first + 1, last))

    # the first element of each line (the leftmost), and the lines that have one, in order: a
    # comment goes to the first of them at or below it; only lines are sorted, not elements
    by_line: dict[int, Any] = {}
    statements = _statements(declarations)
    for element in statements:
        location = element.location
        first = by_line.get(location.line)
        if first is None or location.column < first.location.column:
            by_line[location.line] = element
    starts = sorted(by_line)
    # the elements written as a block, outermost first: a comment after the last line of a block's
    # body (`// TODO: a way out of fault` before an fsm's `}`) stays in that block
    blocks: list[Any] = [e for e in statements if isinstance(e, _BLOCKS)]  # each has a location (_statements)
    closes = _closing_braces(statements, blocks, comments, text) if text is not None else {}
    blocks = sorted(
        (e for e in blocks if e.location.end_line > e.location.line),
        key=lambda e: (e.location.line, -e.location.end_line),
    )
    inside: list[Any] = []  # the blocks open at the comment, innermost last
    next_block = 0
    last_line: dict[int, int] = {}  # id(element) -> line of its last leading (or closing) comment
    commented: list[Any] = []
    last_closing = 0
    # the statements written over several lines that hold no others (`tc = a/pp` / `or b/pp`, a long
    # `/pf` header), by their first line: a comment on one of their later lines stays with them
    spanning = sorted(
        (e.location.line, e.location.end_line, e)
        for e in statements
        if not isinstance(e, _BLOCKS) and e.location.end_line > e.location.line
    )
    spanning_starts = [start for start, _, _ in spanning]
    for comment in comments:
        said = str(comment)
        line = comment.line or 1
        closed = closes.get(line)
        if closed is not None and (comment.column or 1) >= closed.location.end_column:
            # after a `}` (and nothing after it but the comment): about the block it closes, however that block
            # was laid out (`r/r { a/a }  // c` as `}  // c` of a robot written over lines)
            after = closed.comments.after
            closed.comments.after = said if after is None else f"{after.rstrip()}  {said}"
            continue
        owner = by_line.get(line)
        if owner is not None and (comment.column or 1) > owner.location.column:
            owner.comments.trailing = said
            continue
        within = bisect_left(spanning_starts, line) - 1  # the last statement that starts above the comment
        if within >= 0 and spanning[within][1] >= line and line not in by_line:
            # written one line by `earl fmt`: the comment ends that line, after any it had already
            statement = spanning[within][2]
            trailing = statement.comments.trailing
            statement.comments.trailing = said if trailing is None else f"{trailing.rstrip()}  {said}"
            continue
        while next_block < len(blocks) and blocks[next_block].location.line < line:
            block = blocks[next_block]
            while inside and inside[-1].location.end_line < block.location.line:
                inside.pop()
            inside.append(block)
            next_block += 1
        while inside and inside[-1].location.end_line <= line:  # a comment on the `}` line is after it
            inside.pop()
        position = bisect_left(starts, line)
        if inside and (position == len(starts) or starts[position] > inside[-1].location.end_line):
            block = inside[-1]
            closing_of_block = block.comments.closing
            if closing_of_block and parted(last_line[id(block)], line):
                closing_of_block.append("")
            closing_of_block.append(said)
            last_line[id(block)] = line
            continue
        if position < len(starts):
            element = by_line[starts[position]]
            leading = element.comments.leading
            if leading and parted(last_line[id(element)], line):
                leading.append("")
            elif not leading:
                commented.append(element)
            leading.append(said)
            last_line[id(element)] = line
        else:
            if closing and parted(last_closing, line):
                closing.append("")
            closing.append(said)
            last_closing = line
    for element in commented:
        if parted(last_line[id(element)], element.location.line):
            element.comments.leading.append("")
    return closing
