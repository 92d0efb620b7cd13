"""Name resolution: every name a spec uses must denote a declared element of the right kind.

The resolver walks the declared model once, with the parameters and family
indices in scope, and reports each unknown, duplicate or misused name at the
place it was written, with a did-you-mean hint where one helps.  It never
changes the model; `earl.model.expand` can rely on a system it accepted.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, fields, is_dataclass, replace
from typing import Any

from earl.diagnostics import Diagnostic, Severity, SourceMap, did_you_mean
from earl.model.elements import (
    FSM,
    Agent,
    Family,
    Link,
    LinkEnd,
    Parameter,
    Predicate,
    Subsystem,
    System,
    duration_problems,
    is_duration,
)
from earl.model.expressions import (
    ARITHMETIC_OPERATORS,
    BUILTIN_FUNCTIONS,
    COMPARISON_OPERATORS,
    PYTHON_PREDICATE,
    BooleanOperation,
    Call,
    ConstantError,
    ElementReference,
    Expression,
    FieldAccess,
    Literal,
    Name,
    Quantifier,
    Read,
    Star,
    children,
    evaluate_constant,
    evaluate_integer,
    walk,
)
from earl.model.graphs import cycles
from earl.model.kinds import KIND_TITLES, Kind
from earl.model.location import SourceLocation
from earl.model.text import expression_text, reference_text, subsystem_name
from earl.model.types import (
    MAX_ARRAY_DIMENSIONS,
    PARAMETER_TYPES,
    PRIMITIVE_TYPES,
    ArrayType,
    DataType,
    PrimitiveType,
    StructType,
    TypeAlias,
    TypeReference,
    parameter_value_problem,
    type_text,
)

Value = bool | int | float | str

#: the operators of each kind of expression, and the quantifiers (EARL-R047)
OPERATORS: dict[str, tuple[str, ...]] = {
    "Comparison": COMPARISON_OPERATORS,
    "Arithmetic": ARITHMETIC_OPERATORS,
    "BooleanOperation": ("and", "or"),
    "Quantifier": ("any", "all"),
}
_OPERATOR_ROLES = {
    "Comparison": "comparison operator",
    "Arithmetic": "arithmetic operator",
    "BooleanOperation": "Boolean operator",
    "Quantifier": "quantifier",
}

#: aliases and arrays nested in a type written out: walks over types recurse once per level
MAX_ALIAS_NESTING = 100
#: structs nested in structs (through fields, aliases and fixed-size arrays): the runtime builds, checks and
#: encodes a value with one call per level
MAX_STRUCT_NESTING = 100
#: numbers, Booleans and strings in one value of a type, over its fixed-size arrays and every field: the
#: runtime builds each buffer's and memory's first value element by element (`double[1000000000000]` would
#: never end), and ten million take a second or two and 80 MB
MAX_VALUE_ELEMENTS = 10_000_000
#: A family larger than this is almost certainly a typo (`1..1000000`), and would exhaust memory.
MAX_FAMILY_MEMBERS = 100_000
#: subsystems and their elements once every family is expanded: nested families multiply (100,000
#: agents of 100,000 subsystems each), and each element takes a few kB of memory to check or run
MAX_EXPANDED_ELEMENTS = 4_000_000

_INTEGER_TYPES = {name for name, accepted in PARAMETER_TYPES.items() if accepted == (int,)}


@dataclass(frozen=True)
class IndexRange:
    """An index variable while a family body is resolved: every value from first to last."""

    first: int
    last: int

    def values(self) -> range:
        return range(self.first, self.last + 1)


@dataclass(frozen=True)
class ParameterRange(IndexRange):
    """A whole-number parameter of a family computed from its index (`param joint: int = K`): it ranges as an
    index does, but it is a parameter, which is how a message that names it must say it."""


@dataclass(frozen=True)
class PerMember:
    """A parameter of a family computed from its index, whose values are not whole numbers
    (`param GAIN: double = 0.5 * K`): in scope, with one value per member, known once expanded."""

    type_name: str


Scope = dict[str, "Value | IndexRange | PerMember"]

_REAL_TYPES = frozenset({"double", "float32", "float64"})


@dataclass
class _Declared:
    element: Any
    family: IndexRange | None


@dataclass
class _SubsystemTable:
    """The elements of one subsystem by kind and name."""

    subsystem: Subsystem
    by_kind: dict[Kind, dict[str, _Declared]] = field(default_factory=dict)

    def lookup(self, kind: Kind) -> dict[str, _Declared]:
        if kind in (Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT):
            kind = Kind.MEMORY
        return self.by_kind.setdefault(kind, {})


@dataclass
class _AgentTable:
    agent: Agent
    family: IndexRange | None
    scope: Scope
    subsystems: dict[tuple[str, Kind], tuple[_SubsystemTable, IndexRange | None]] = field(default_factory=dict)
    #: subsystems declared more than once (EARL-R002): a link to one may mean either declaration
    declared_twice: set[tuple[str, Kind]] = field(default_factory=set)


class _Place:
    """Where the resolver is within an element (`reads[0] of `store/pf` of `worker/a.cs``), put in words only
    when a problem without a location needs it: every element of every spec read is entered."""

    __slots__ = ("attribute", "element", "outer")

    def __init__(self, element: str, attribute: str, outer: str | _Place | None) -> None:
        self.element = element
        self.attribute = attribute
        self.outer = outer

    def __str__(self) -> str:
        inner = f"{self.attribute} of {self.element}" if self.attribute else self.element
        return f"{inner} of {self.outer}"


def _uses_merged(diagnostics: list[Diagnostic]) -> list[Diagnostic]:
    """One EARL-R022 per unknown name, at its first use, saying where the others are: a misspelt
    `hi/pp` used in three conditions is one mistake, not three errors."""
    uses: dict[str, list[Diagnostic]] = {}
    for diagnostic in diagnostics:
        if diagnostic.code == "EARL-R022":
            uses.setdefault(diagnostic.message, []).append(diagnostic)
    merged: list[Diagnostic] = []
    for diagnostic in diagnostics:
        repeats = uses.get(diagnostic.message) if diagnostic.code == "EARL-R022" else None
        if repeats is None:
            merged.append(diagnostic)
        elif repeats[0] is diagnostic:
            if len(repeats) > 1:
                more = "1 more use" if len(repeats) == 2 else f"{len(repeats) - 1} more uses"
                places = _places(diagnostic.location, [other.location for other in repeats[1:]])
                diagnostic = replace(diagnostic, message=f"{diagnostic.message} (and {more}{places})")
            merged.append(diagnostic)
    return merged


def _places(first: SourceLocation | None, others: list[SourceLocation | None]) -> str:
    """`, at lines 25 and 26` in the first use's file; `file:line` for one in another file."""
    if any(location is None for location in others):
        return ""  # a model built in Python: its references have no place
    here = first is not None and all(location.file == first.file for location in others if location)
    # each line once: `hi/pp or not hi/pp` is two uses on one line
    said = list(
        dict.fromkeys(
            str(location.line) if here else f"{location.file}:{location.line}" for location in others if location
        )
    )
    listed = said[0] if len(said) == 1 else ", ".join(said[:-1]) + " and " + said[-1]
    return f", at {'line' if len(said) == 1 else 'lines'} {listed}" if here else f", at {listed}"


class _Within:
    """`with resolver._within(…)`: a class, not a generator, for it is entered for every element read."""

    __slots__ = ("attribute", "element", "outer", "resolver")

    def __init__(self, resolver: Resolver, element: str, attribute: str) -> None:
        self.resolver = resolver
        self.element = element
        self.attribute = attribute

    def __enter__(self) -> None:
        self.outer = self.resolver._place
        self.resolver._place = _Place(self.element, self.attribute, self.outer)

    def __exit__(self, *_: object) -> None:
        self.resolver._place = self.outer


class Resolver:
    #: whether every comment came from the reader (`resolve`)
    comments_from_text = False

    def __init__(self, system: System, overrides: Mapping[str, Value]) -> None:
        self.system = system
        self.overrides = dict(overrides)
        self.diagnostics: list[Diagnostic] = []
        self._said: set[tuple[str, str, SourceLocation | None]] = set()
        self.types: dict[str, Any] = {}
        #: the declaration being resolved (`a/a.cs`), named by a message that has no location
        self._place: str | _Place | None = None
        #: per named type: (structs nested, numbers/Booleans/strings in one value), once every type is read
        self._type_sizes: dict[str, tuple[int, int]] | None = None
        self.agents: dict[str, _AgentTable] = {}
        #: elements the system will have once its families are expanded, counted as they are declared
        self._expanded = 0
        self._expanded_reported = False
        #: per parameter, the system parameters given from outside (`--param`) that its value comes from
        self._given: dict[str, frozenset[str]] = {}
        #: family ranges made wrong by a value given from outside: told once per cause, after the walk
        self._wrong_from_outside: dict[tuple[str, str, frozenset[str]], list[Family]] = {}

    # ------------------------------------------------------------------ reporting
    def error(self, message: str, location: SourceLocation | None, code: str, hint: str | None = None) -> None:
        # An element of a family, or a link resolved from both of its ends, can meet the same problem
        # more than once: the reader is told once, at the place it was written.
        if location is None and self._place is not None and str(self._place) not in message:
            # a model built in Python has no locations: the message says which element it is about
            message = f"{message} (in {self._place})"
        key = (code, message, location)
        if key in self._said:
            return
        self._said.add(key)
        self.diagnostics.append(Diagnostic(Severity.ERROR, message, location, code=code, hint=hint))

    def _within(self, element: str, attribute: str = "") -> _Within:
        """Inside, a problem without a location (a model built in Python) says the element it is in, and
        the attribute (`in reads[0] of `store/pf` of `worker/a.cs``), not only the subsystem."""
        return _Within(self, element, attribute)

    def duplicate(self, what: str, location: SourceLocation | None, first: SourceLocation | None) -> None:
        where = f" (first declared at line {first.line})" if first is not None else ""
        self.error(f"{what} is declared twice{where}", location, "EARL-R002", "give each element its own name")

    # ------------------------------------------------------------------ the walk
    def run(self) -> list[Diagnostic]:
        scope: Scope = {}
        self._parameters(self.system.parameters, scope, overrides=self.overrides)
        for name in self.overrides:
            if not any(p.name == name for p in self.system.parameters):
                known = [p.name for p in self.system.parameters]
                self.error(
                    f"there is no system parameter `{name}` to set",
                    None,
                    "EARL-R001",
                    did_you_mean(name, known) or f"system parameters: {', '.join(known) or 'none'}",
                )
        self._names()
        self._imports()
        if not self.comments_from_text:
            self._comments()
        self._types(scope)
        for agent in self.system.agents:
            self._declare_agent(agent, scope)
        for table in self.agents.values():
            self._agent_body(table)
        self._place = "the links between agents"
        self._links(self.system.links, scope, agent=None)
        self._robots(scope)
        self._place = None
        self._tell_wrong_from_outside()
        return _uses_merged(self.diagnostics)

    def _names(self) -> None:
        """EARL-R006: a declared name the language could not read back (`my arm`, `a1/a`, `système`, a
        keyword where it stands: `period/m`); only a model built in Python can hold one, and `to_earl()`
        would write text that does not load."""
        for name, what, location, _ in unreadable_names(self.system):
            self._unreadable(name, what, location)
        if self.system.name == "":  # only `System("")`: the reader refuses a specification without its name
            self.error(
                "the system has no name: the text would start without its `system` line, which a specification needs",
                self.system.location,
                "EARL-R006",
                'name it, e.g. `System("demo", …)`',
            )

    def _imports(self) -> None:
        """EARL-R009: an import added in Python (it has no location: the reader's have theirs). What an imported
        file declares is merged into the model as the file is read; a System built in Python holds its
        `Import` alone, so check and the run would not know the file's declarations, and the saved text, read
        back, would hold them."""
        for position, declaration in enumerate(self.system.imports):
            if declaration.location is None:
                self.error(
                    f'system.imports[{position}]: `import "{declaration.path}"` in a model built in Python is not'
                    " read: what that file declares is not in this model, which check and the run see as it is",
                    None,
                    "EARL-R009",
                    'save the model and load it, `earl.save(system, "system.earl")` then `earl.load("system.earl")`:'
                    " the import is read next to the saved file; or put the declarations in the System itself",
                )

    def _comments(self) -> None:
        """EARL-R007: a comment `.earl` text cannot hold (`/* x */`, two lines); only a model built in Python
        can hold one, and `to_earl()` would write text that does not load."""
        from earl.model.comment_text import unwritable_comments

        for path, comment in unwritable_comments(self.system):
            self.error(
                f"{path}: {comment!r} is no EARL comment: the text would not read back",
                None,
                "EARL-R007",
                'a comment is one line starting with `//` ("" for a blank line); write one string per line',
            )

    def _of_kind(self, reference: ElementReference, kind: Kind, what: str) -> bool:
        """Whether `reference` (a robot's member, a link's end: only a model built in Python can hold another
        kind there, and the text, which writes the kind, would not load or would read back as `kind`) is of
        `kind`; EARL-R021 if not. A kind that is no Kind (`"agent"`) is a ModelTypeError at its path."""
        if reference.kind is kind:
            return True
        if not isinstance(reference.kind, Kind):
            raise TypeError(f"not a Kind: {reference.kind!r}")  # `explaining` names it at its path
        self.error(
            f"{what} is `{reference_text(reference)}`, of kind `/{reference.kind.value}` ({KIND_TITLES[reference.kind]});"
            f" it must be `/{kind.value}` ({KIND_TITLES[kind]})",
            reference.location,
            "EARL-R021",
            f'write `ElementReference("{reference.name}", Kind.{kind.name})`',
        )
        return False

    def _unreadable(self, name: object, what: str, location: SourceLocation | None) -> None:
        """EARL-R006 of one name."""
        if isinstance(name, str) and _NAME.fullmatch(name):  # a keyword where it stands
            self.error(
                f"`{name}` is a keyword of EARL where it is declared ({what}): the text would not read back",
                location,
                "EARL-R006",
                f"rename it, e.g. `{name}_` or `my{name[:1].upper()}{name[1:]}`",
            )
            return
        if isinstance(name, str) and "/" in name and _NAME.fullmatch(name.split("/")[0]):
            hint = f"write the name without its kind: `{name.split('/')[0]}` (the kind is the element's class)"
        else:
            suggestion = re.sub(r"\W", "_", name, flags=re.ASCII) if isinstance(name, str) and name else ""
            if suggestion[:1].isdigit():
                suggestion = "_" + suggestion
            hint = "a name is a letter or `_`, then letters, digits and `_`" + (
                f", e.g. `{suggestion}`" if suggestion else ""
            )
        self.error(f"{name!r} is no EARL name ({what})", location, "EARL-R006", hint)

    def _parameters(self, parameters: Sequence[Parameter], scope: Scope, overrides: Mapping[str, Value] = {}) -> None:
        seen: dict[str, Parameter] = {}
        for parameter in parameters:
            if parameter.name in seen:
                self.duplicate(f"parameter `{parameter.name}`", parameter.location, seen[parameter.name].location)
                continue
            seen[parameter.name] = parameter
            self._given[parameter.name] = (
                frozenset({parameter.name})
                if parameter.name in overrides
                else frozenset().union(*(self._given.get(n.name, frozenset()) for n in _names(parameter.value)))
            )
            type_name = getattr(parameter.data_type, "name", "?")
            if not isinstance(parameter.data_type, PrimitiveType) or type_name not in PARAMETER_TYPES:
                self.error(
                    f"parameter `{parameter.name}` must have a primitive type, not `{type_name}`",
                    parameter.data_type.location or parameter.location,
                    "EARL-R003",
                    "parameters are `int`, `double`, `boolean` or `string` (or a sized integer or float)",
                )
                continue
            if parameter.name in overrides:
                value: Value = overrides[parameter.name]
            elif any(isinstance(scope.get(n.name), IndexRange | PerMember) for n in _names(parameter.value)):
                # `param joint: int = K` differs per family member: check every member's value.
                reals = sorted(n.name for n in _names(parameter.value) if isinstance(scope.get(n.name), PerMember))
                if reals and type_name not in _REAL_TYPES:
                    # computed from a real that differs per member: no whole number, Boolean or string
                    self.error(
                        f"parameter `{parameter.name}` is `{type_name}` but its value is computed from "
                        f"`{reals[0]}`, a `{scope[reals[0]].type_name}` that differs per family member",  # type: ignore[union-attr]
                        parameter.value.location or parameter.location,
                        "EARL-R005",
                    )
                    scope[parameter.name] = PerMember(type_name)  # in scope, so that its uses say nothing more
                    continue
                if type_name in _INTEGER_TYPES:
                    values = self.index_values(parameter.value, scope)
                    if values is not None and values:
                        scope[parameter.name] = ParameterRange(min(values), max(values))
                else:
                    self._member_values(parameter, type_name, scope)
                    scope[parameter.name] = PerMember(type_name)
                continue
            else:
                try:
                    value = evaluate_constant(parameter.value, _values(scope))
                except ConstantError as problem:
                    self.error(str(problem), problem.location or parameter.location, "EARL-R004")
                    continue
            wrong = parameter_value_problem(type_name, value)
            if wrong is not None:
                given = parameter.name in overrides
                self.error(
                    f"parameter `{parameter.name}` is `{type_name}` but {wrong}"
                    + (", given from outside the spec (`--param`, or `parameters=` in Python)" if given else ""),
                    parameter.value.location or parameter.location,
                    "EARL-R005",
                    # the caret is at the spec's own value, which is not the wrong one: say what to change
                    f"give `{parameter.name}` a value of type `{type_name}`, as the spec's own (marked) is"
                    if given
                    else _whole_double_hint(parameter, type_name, value),
                )
                if parameter.name not in overrides:
                    continue
                # a value given from outside (`--param N=x`) is wrong: the spec's own value stands in for
                # the rest of the reading, so that every use of `N` is not reported as an error too
                try:
                    value = evaluate_constant(parameter.value, _values(scope))
                except ConstantError:
                    continue
                if parameter_value_problem(type_name, value) is not None:
                    continue
            if type_name in ("double", "float32", "float64"):
                value = float(value)
            scope[parameter.name] = value

    def _member_values(self, parameter: Parameter, type_name: str, scope: Scope) -> None:
        """Each member's value of a parameter computed from family indices fits its type (R005), where
        it depends on the indices alone; one computed from another such parameter is checked as the
        family is expanded."""
        names = {n.name for n in _names(parameter.value)}
        if any(isinstance(scope.get(name), PerMember) for name in names):
            return  # a real computed from a real: whatever it is, a real (expansion computes each value)
        ranged = sorted(name for name in names if isinstance(scope.get(name), IndexRange))
        ranges = [scope[name].values() for name in ranged]  # type: ignore[union-attr]
        if _product_size(ranges) > 10_000:
            return
        base = _values(scope)
        for combination in itertools.product(*ranges):
            members = dict(zip(ranged, combination, strict=True))
            try:
                value = evaluate_constant(parameter.value, {**base, **members})
            except ConstantError as problem:
                self.error(str(problem), problem.location or parameter.location, "EARL-R004")
                return
            wrong = parameter_value_problem(type_name, value)
            if wrong is not None:
                where = ", ".join(f"{name} = {index}" for name, index in members.items())
                self.error(
                    f"parameter `{parameter.name}` is `{type_name}` but, where {where}, {wrong}",
                    parameter.value.location or parameter.location,
                    "EARL-R005",
                )
                return

    # ------------------------------------------------------------------ data types
    def _types(self, scope: Scope) -> None:
        for definition in self.system.types:
            if definition.name in PRIMITIVE_TYPES:
                self.error(
                    f"`{definition.name}` is a primitive type and cannot be redefined",
                    definition.location,
                    "EARL-R010",
                )
            elif definition.name in self.types:
                self.duplicate(f"type `{definition.name}`", definition.location, self.types[definition.name].location)
            else:
                self.types[definition.name] = definition
        for definition in self.system.types:
            self._place = f"type `{definition.name}`"
            if isinstance(definition, StructType):
                names: dict[str, Any] = {}
                for member in definition.fields:
                    if not isinstance(member.optional, bool):  # `optional="yes"`: named at its path (explaining)
                        raise TypeError(f"a field's `optional` is a bool, not {member.optional!r}")
                    if member.name in names:
                        self.duplicate(
                            f"field `{member.name}` of `{definition.name}`",
                            member.location,
                            names[member.name].location,
                        )
                    names[member.name] = member
                    self.data_type(member.data_type, scope, member.location)
            else:
                self.data_type(definition.data_type, scope, definition.location)
        self._place = None
        reported = self._type_cycles()
        self._alias_depths(reported)
        self._value_sizes(scope, reported)

    def _alias_depths(self, reported: set[str]) -> None:
        """An alias is written out wherever it is used (the SysML export, a document's types): one that
        names itself through an array (`type A = A[]`) names no type, and a chain of thousands of aliases
        (`type A2 = A1[]` …) is as deep as the array types the reader refuses (S017)."""
        # per alias: (aliases and arrays nested, array dimensions) of its type written out; None while
        # it is being measured, which is how a cycle shows
        measured: dict[str, tuple[int, int] | None] = {}
        inner: dict[str, str | None] = {}  # the type each alias names, under its arrays

        def too_deep(name: str | None) -> bool:
            found = measured.get(name) if name is not None else None
            return found is not None and (found[1] > MAX_ARRAY_DIMENSIONS or found[0] > MAX_ALIAS_NESTING)

        def measure(name: str) -> tuple[int, int]:
            # iterative over the chain of aliases: a recursive walk is what this rule protects the others from
            chain: list[tuple[str, int]] = []  # each alias on the way, with the arrays around its next one
            current: str | None = name
            nested = (0, 0)
            while current is not None:
                if current in measured:
                    known = measured[current]
                    if known is None:  # back at an alias measured in this chain: a cycle
                        cycle = [n for n, _ in chain]
                        start = cycle.index(current)
                        self._alias_cycle([*cycle[start:], current], reported)
                        known = (0, 0)
                    nested = known
                    break
                definition = self.types.get(current)
                if not isinstance(definition, TypeAlias):
                    break
                measured[current] = None
                data_type, arrays = definition.data_type, 0
                while isinstance(data_type, ArrayType):
                    data_type, arrays = data_type.element, arrays + 1
                chain.append((current, arrays))
                current = data_type.name if isinstance(data_type, TypeReference) else None
                inner[chain[-1][0]] = current
            for alias, arrays in reversed(chain):
                nested = (nested[0] + 1 + arrays, nested[1] + arrays)
                measured[alias] = nested
            return nested

        for name, definition in self.types.items():
            if not isinstance(definition, TypeAlias) or name in measured:
                continue
            measure(name)
        for name, definition in self.types.items():
            found = measured.get(name)
            if found is None or name in reported:
                continue
            nested, dimensions = found
            # the first alias of a chain that is too deep: those built on it say nothing new
            if too_deep(name) and not too_deep(inner.get(name)):
                written = (
                    f"{dimensions} array dimensions"
                    if dimensions > MAX_ARRAY_DIMENSIONS
                    else f"{nested} aliases and arrays deep"
                )
                self.error(
                    f"type `{name}` written out is {written}: at most {MAX_ARRAY_DIMENSIONS} dimensions and "
                    f"{MAX_ALIAS_NESTING} levels",
                    definition.location,
                    "EARL-R019",
                    "flatten the dimensions (`double[N * M]`), or group them in a struct",
                )

    def _value_sizes(self, scope: Scope, reported: set[str]) -> None:
        """Structs nested too deep (EARL-R019) and values too large (EARL-R013), per named type, measured in
        one walk over the types without recursion; the uses of types (buffers, memory) are measured by
        `value_too_large`. A variable-size array counts as empty and is not followed: a struct may hold
        itself through one (`children: T[]`), and what it holds is the messages' business."""
        sizes: dict[str, tuple[int, int]] = {}
        state: dict[str, bool] = {}  # False while being measured (a cycle R011 reported), True once measured

        def named_inside(data_type: DataType) -> Iterator[str]:
            while isinstance(data_type, ArrayType) and data_type.size is not None:
                data_type = data_type.element
            if isinstance(data_type, TypeReference) and data_type.name in self.types:
                yield data_type.name

        def successors(name: str) -> list[str]:
            definition = self.types[name]
            if isinstance(definition, StructType):
                return [inner for field in definition.fields for inner in named_inside(field.data_type)]
            return list(named_inside(definition.data_type))

        for root in self.types:
            if root in state:
                continue
            stack = [(root, iter(successors(root)))]
            state[root] = False
            while stack:
                name, pending = stack[-1]
                child = next(pending, None)
                if child is None:
                    stack.pop()
                    state[name] = True
                    sizes[name] = self._measure_definition(self.types[name], sizes, scope)
                elif child not in state and child not in reported:
                    state[child] = False
                    stack.append((child, iter(successors(child))))
        self._type_sizes = sizes
        for name, definition in self.types.items():
            if name in reported or name not in sizes:
                continue
            nesting, elements = sizes[name]
            inner = [sizes.get(n, (0, 0)) for n in successors(name)]
            if isinstance(definition, StructType) and nesting > MAX_STRUCT_NESTING:
                if all(n <= MAX_STRUCT_NESTING for n, _ in inner):  # the first struct too deep, not each above it
                    self.error(
                        f"struct `{name}` holds structs {nesting} levels deep: at most {MAX_STRUCT_NESTING}",
                        definition.location,
                        "EARL-R019",
                        "flatten the nesting, or hold the inner structs in a variable-size array (`parts: Part[]`)",
                    )
            elif elements > MAX_VALUE_ELEMENTS and all(e <= MAX_VALUE_ELEMENTS for _, e in inner):
                self.error(
                    f"a value of type `{name}` holds {elements:,} numbers, Booleans and strings: at most "
                    f"{MAX_VALUE_ELEMENTS:,}",
                    definition.location,
                    "EARL-R013",
                    "make its fixed-size arrays smaller, or variable-size (`double[]`)",
                )

    def _measure_definition(self, definition: Any, sizes: dict[str, tuple[int, int]], scope: Scope) -> tuple[int, int]:
        if isinstance(definition, StructType):
            measured = [self._measure(f.data_type, sizes, scope) for f in definition.fields]
            return 1 + max((n for n, _ in measured), default=0), sum(e for _, e in measured)
        return self._measure(definition.data_type, sizes, scope)

    def _measure(self, data_type: DataType, sizes: dict[str, tuple[int, int]], scope: Scope) -> tuple[int, int]:
        """(structs nested, numbers/Booleans/strings) of one value of a type as written; named types from `sizes`."""
        count = 1
        while isinstance(data_type, ArrayType):
            if data_type.size is None:
                return 0, 0
            try:
                length = evaluate_constant(data_type.size, _values(scope))
            except ConstantError:
                return 0, 0  # reported where the type is read, or depends on a family index
            if isinstance(length, bool) or not isinstance(length, int) or length < 0:
                return 0, 0
            count *= length
            data_type = data_type.element
        if isinstance(data_type, TypeReference):
            nesting, elements = sizes.get(data_type.name, (0, 0))
            return nesting, count * elements
        return 0, count

    def value_too_large(self, data_type: DataType, scope: Scope, where: SourceLocation | None) -> None:
        """EARL-R013 for a buffer or memory whose type, as written there, holds too many elements (a named
        type too large is reported once, at its definition)."""
        if self._type_sizes is None or isinstance(data_type, TypeReference):
            return
        _, elements = self._measure(data_type, self._type_sizes, scope)
        inner: DataType = data_type
        while isinstance(inner, ArrayType):
            inner = inner.element
        if isinstance(inner, TypeReference) and self._type_sizes.get(inner.name, (0, 0))[1] > MAX_VALUE_ELEMENTS:
            return
        if elements > MAX_VALUE_ELEMENTS:
            self.error(
                f"a value of `{type_text(data_type)}` holds {elements:,} numbers, Booleans and strings: at most "
                f"{MAX_VALUE_ELEMENTS:,}",
                (data_type.size.location if isinstance(data_type, ArrayType) and data_type.size is not None else None)
                or where,
                "EARL-R013",
                "make the fixed-size arrays smaller, or variable-size (`double[]`)",
            )

    def _alias_cycle(self, cycle: list[str], reported: set[str]) -> None:
        if cycle[0] in reported:
            return
        reported.update(cycle)
        definition = self.types[cycle[0]]
        self.error(
            f"type `{cycle[0]}` is an alias of itself ({' -> '.join(cycle)}), so it names no type",
            definition.location,
            "EARL-R011",
            "a type that holds itself is a struct with a variable array field: `struct T { children: T[] }`",
        )

    def _type_cycles(self) -> set[str]:
        """A struct that contains itself (other than through a variable array) has no finite size; the
        types reported are returned."""

        def direct(data_type: DataType) -> Iterable[str]:
            if isinstance(data_type, TypeReference):
                yield data_type.name
            elif isinstance(data_type, ArrayType) and data_type.size is not None:
                yield from direct(data_type.element)

        def contained(name: str) -> list[str]:
            node = self.types.get(name)
            if node is None:
                return []
            if isinstance(node, StructType):
                return [t for f in node.fields for t in direct(f.data_type)]
            return list(direct(node.data_type))

        # one walk over every type: a walk from each type in turn took a minute for 5,000 chained aliases
        reported: set[str] = set()
        for cycle in cycles(self.types, contained):
            if set(cycle) <= reported:
                continue
            reported.update(cycle)
            first = cycle[0]
            self.error(
                f"type `{first}` contains itself ({' -> '.join([*cycle, first])}), so it has no finite size",
                self.types[first].location,
                "EARL-R011",
                "break the cycle with a variable array (`T[]`): an optional field does not end it",
            )
        return reported

    def data_type(self, data_type: DataType, scope: Scope, where: SourceLocation | None = None) -> None:
        """`where`: the declaration that holds it, for a value that has no location of its own."""
        if isinstance(data_type, TypeReference):
            if data_type.name not in self.types:
                self.error(
                    f"unknown data type `{data_type.name}`",
                    data_type.location,
                    "EARL-R012",
                    did_you_mean(data_type.name, [*self.types, *PRIMITIVE_TYPES])
                    or "declare it with `struct` or `type`, or import the file that does",
                )
        elif isinstance(data_type, ArrayType):
            self.data_type(data_type.element, scope, where)
            if data_type.size is not None:
                size = self.constant_integer(data_type.size, scope, "an array size")
                if size is not None and size < 0:
                    self.error(
                        f"an array size must not be negative, here it is {size}", data_type.size.location, "EARL-R013"
                    )
        elif isinstance(data_type, PrimitiveType):
            if data_type.name not in PRIMITIVE_TYPES:
                # only a model built in Python can hold this: the reader makes a TypeReference of a name
                self.error(
                    f"unknown primitive type `{data_type.name}`",
                    data_type.location or where,
                    "EARL-R012",
                    did_you_mean(str(data_type.name), PRIMITIVE_TYPES)
                    or f"the primitive types: {', '.join(PRIMITIVE_TYPES)}; a struct or alias is a `TypeReference`",
                )
        elif not isinstance(data_type, PrimitiveType):
            # only a model built in Python can hold this (`data_type="double"`); the reader makes types
            written = f"`{data_type}`" if isinstance(data_type, str) else type(data_type).__name__
            self.error(
                f"{written} is not a data type",
                where,
                "EARL-R012",
                f'write `PrimitiveType("{data_type}")` or `TypeReference("{data_type}")`'
                if isinstance(data_type, str)
                else "a data type is a PrimitiveType, a TypeReference or an ArrayType",
            )

    def structural_type(self, data_type: DataType) -> DataType | StructType | None:
        """The type behind aliases: a primitive, an array or a struct; None when unknown."""
        seen: set[str] = set()
        while isinstance(data_type, TypeReference):
            if data_type.name in seen:
                return None
            seen.add(data_type.name)
            definition = self.types.get(data_type.name)
            if definition is None:
                return None
            if isinstance(definition, StructType):
                return definition
            data_type = definition.data_type
        return data_type

    # ------------------------------------------------------------------ constants and families
    def constant_integer(self, expression: Expression, scope: Scope, what: str) -> int | None:
        if any(isinstance(scope.get(n.name), IndexRange | PerMember) for n in _names(expression)):
            return None  # depends on a family index; checked per member where it matters
        try:
            value = evaluate_constant(expression, _values(scope))
        except ConstantError as problem:
            self.error(f"{what} must be a constant: {problem}", problem.location or expression.location, "EARL-R014")
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            self.error(f"{what} must be a whole number, not {value!r}", expression.location, "EARL-R014")
            return None
        return value

    def family_range(self, family: Family | None, scope: Scope) -> IndexRange | None:
        if family is None:
            return None
        if family.index in scope:
            self.error(
                _in_use(family.index, scope),
                family.location,
                "EARL-R015",
                "give the inner family another index letter",
            )
        first = self.constant_integer(family.first, scope, "the first index of a family")
        last = self.constant_integer(family.last, scope, "the last index of a family")
        if first is None or last is None:
            return IndexRange(1, 0)
        if first < 0:
            if not self._from_outside(family, "EARL-R016", f"starts a family at {first}, below 0"):
                self.error(
                    f"a family index starts at 0 or more, not {first}",
                    family.first.location or family.location,
                    "EARL-R016",
                )
            return IndexRange(1, 0)
        if last < first:
            if not self._from_outside(family, "EARL-R016", f"leaves the family range {first}..{last} empty"):
                self.error(
                    f"the family range {first}..{last} is empty",
                    family.location,
                    "EARL-R016",
                    "the last index must not be smaller than the first",
                )
            return IndexRange(1, 0)
        if last - first + 1 > MAX_FAMILY_MEMBERS:
            members = f"{last - first + 1:,} members; at most {MAX_FAMILY_MEMBERS:,} are allowed"
            if not self._from_outside(family, "EARL-R017", f"gives the family range {first}..{last} {members}"):
                self.error(f"the family range {first}..{last} has {members}", family.location, "EARL-R017")
            return IndexRange(1, 0)
        return IndexRange(first, last)

    def _from_outside(self, family: Family, code: str, problem: str) -> bool:
        """Keeps a family range made wrong by a value given from outside the spec, to be told once for
        all the families it makes wrong (`_tell_wrong_from_outside`); False when the spec's own values
        make it wrong."""
        names = _names(family.first) + _names(family.last)
        causes = frozenset().union(*(self._given.get(n.name, frozenset()) for n in names))
        if not causes:
            return False
        self._wrong_from_outside.setdefault((code, problem, causes), []).append(family)
        return True

    def _tell_wrong_from_outside(self) -> None:
        """`--param NBINS=0`: one error at `NBINS`, naming the families it empties, not one per family at
        lines whose text is right."""
        declared = {parameter.name: parameter for parameter in self.system.parameters}
        for (code, problem, causes), families in self._wrong_from_outside.items():
            names = sorted(causes)
            values = " and ".join(f"`{name}` = {self.overrides[name]!r}" for name in names)
            written = sorted({f"{expression_text(f.first)}..{expression_text(f.last)}" for f in families})
            lines = sorted({f.location.line for f in families if f.location is not None})
            where = f" at line{'s' if len(lines) > 1 else ''} {_listed([str(line) for line in lines])}" if lines else ""
            parameter = declared.get(names[0])
            location = None if parameter is None else parameter.value.location or parameter.location
            last = families[0].last
            given = _listed([f"`{name}`" for name in names])
            if code == "EARL-R017":
                hint = f"give {given} a smaller value"
            elif "empty" not in problem:
                hint = "a family index starts at 0 or more"
            elif isinstance(last, Name) and last.name in causes:
                hint = f"give `{last.name}` a value of at least {expression_text(families[0].first)}"
            else:
                hint = "the last index must not be smaller than the first"
            self.error(
                f"{values}, given from outside the spec (`--param`, or `parameters=` in Python), {problem}: "
                f"{_listed([f'`{text}`' for text in written])}{where}",
                location,
                code,
                hint,
            )

    def index_values(self, expression: Expression, scope: Scope) -> list[int] | None:
        """Every value an index expression takes over the family indices in scope."""
        for name in _names(expression):
            if name.name not in scope:
                self.unknown_name(name, scope)
                return None
        reals = sorted({n.name for n in _names(expression) if isinstance(scope.get(n.name), PerMember)})
        if reals:
            self.error(
                f"an index must be a whole number; `{reals[0]}` is a `{scope[reals[0]].type_name}`",  # type: ignore[union-attr]
                expression.location,
                "EARL-R014",
            )
            return None
        ranged = sorted({n.name for n in _names(expression) if isinstance(scope.get(n.name), IndexRange)})
        ranges = [scope[name].values() for name in ranged]  # type: ignore[union-attr]
        if any(len(r) == 0 for r in ranges):
            return []
        if _product_size(ranges) > 10_000:
            return None
        values: list[int] = []
        base = _values(scope)
        for combination in itertools.product(*ranges):
            try:
                value = evaluate_constant(expression, {**base, **dict(zip(ranged, combination, strict=False))})
            except ConstantError as problem:
                self.error(f"an index must be a whole-number expression: {problem}", problem.location, "EARL-R014")
                return None
            if isinstance(value, bool) or not isinstance(value, int):
                self.error(f"an index must be a whole number, not {value!r}", expression.location, "EARL-R014")
                return None
            values.append(value)
        return values

    def unknown_name(self, name: Name, scope: Scope, table: _SubsystemTable | None = None) -> None:
        """EARL-R020; `table`: the subsystem whose elements a condition may read, told when one has the name."""
        readable = (
            []
            if table is None
            else [f"`{name.name}/{read.value}`" for kind, read in _READ_AS.items() if name.name in table.lookup(kind)]
        )
        self.error(
            f"`{name.name}` is not a parameter or family index in scope here",
            name.location,
            "EARL-R020",
            (f"an element is read with its kind: write {' or '.join(readable)}" if readable else None)
            or did_you_mean(name.name, list(scope))
            or "declare it with `param`, or write an element with its kind (`x/pp`)",
        )

    # ------------------------------------------------------------------ agents and subsystems
    def _declare_agent(self, agent: Agent, scope: Scope) -> None:
        if agent.name in self.agents:
            self.duplicate(f"agent `{agent.name}/a`", agent.location, self.agents[agent.name].agent.location)
            return
        inner: Scope = dict(scope)
        self._place = f"`{agent.name}/a`"
        family = self.family_range(agent.family, scope)
        if agent.family is not None and family is not None:
            inner[agent.family.index] = family
        self._parameters(agent.parameters, inner)
        table = _AgentTable(agent, family, inner)
        self.agents[agent.name] = table
        agents = _size(family)
        for subsystem in agent.subsystems:
            key = (subsystem.name, subsystem.kind)
            if subsystem.kind is Kind.CONTROL_SUBSYSTEM and subsystem.name != "cs":
                # `ControlSubsystem("main", …)`: the text writes `cs`, the manual's name for it, and the
                # reload's is `cs`; links name it `cs` too, so it is known by that name from here on
                self.error(
                    f"the Control Subsystem of `{agent.name}/a` is named {subsystem.name!r}; an agent's Control"
                    " Subsystem is called `cs` (§2.2) and is saved so",
                    subsystem.location,
                    "EARL-R008",
                    "leave the name out: `ControlSubsystem(period=…, …)`",
                )
                key = ("cs", subsystem.kind)
            if key in table.subsystems:
                self._place = f"`{agent.name}/a`"  # not the subsystem declared before it
                what = (
                    "the Control Subsystem `cs`"
                    if subsystem.kind is Kind.CONTROL_SUBSYSTEM
                    else f"`{subsystem.name}/{subsystem.kind.value}`"
                )
                self.duplicate(
                    f"{what} of `{agent.name}/a`", subsystem.location, table.subsystems[key][0].subsystem.location
                )
                table.declared_twice.add(key)
                continue
            sub_scope = dict(inner)
            self._place = f"`{subsystem_name(agent, subsystem)}`"
            sub_family = self.family_range(subsystem.family, inner)
            if subsystem.family is not None and sub_family is not None:
                sub_scope[subsystem.family.index] = sub_family
            self._parameters(subsystem.parameters, sub_scope)
            subsystems = agents * _size(sub_family)
            self._count_expanded(subsystems, subsystem.location)
            sub_table = self._subsystem_table(subsystem, sub_scope, subsystems)
            sub_table.scope = sub_scope  # type: ignore[attr-defined]
            table.subsystems[key] = (sub_table, sub_family)
        self._place = None

    def _count_expanded(self, count: int, location: SourceLocation | None) -> None:
        """EARL-R017, once, when the expanded system passes MAX_EXPANDED_ELEMENTS: each family is within
        its own limit, but families inside families multiply."""
        self._expanded += count
        if self._expanded > MAX_EXPANDED_ELEMENTS and not self._expanded_reported:
            self._expanded_reported = True
            self.error(
                f"expanded, the families make more than {MAX_EXPANDED_ELEMENTS:,} subsystems and elements "
                f"({self._expanded:,} by here): families inside families multiply, and a system that large "
                "would need more memory than a machine has",
                location,
                "EARL-R017",
                "make the families smaller (their ranges, or the parameters that set them)",
            )

    def _subsystem_table(self, subsystem: Subsystem, scope: Scope, subsystems: int = 1) -> _SubsystemTable:
        table = _SubsystemTable(subsystem)
        groups: list[tuple[Kind, Sequence[Any]]] = [
            (Kind.INPUT_BUFFER, subsystem.input_buffers),
            (Kind.OUTPUT_BUFFER, subsystem.output_buffers),
            (Kind.MEMORY, subsystem.memories),
            (Kind.PRIMITIVE_PREDICATE, subsystem.primitive_predicates),
            (Kind.PARTIAL_TRANSITION_FUNCTION, subsystem.partial_transition_functions),
            (Kind.BASIC_BEHAVIOUR, subsystem.basic_behaviours),
        ]
        for kind, elements in groups:
            names = table.lookup(kind)
            for element in elements:
                if element.name in names:
                    self.duplicate(
                        f"`{element.name}/{kind.value}`", element.location, names[element.name].element.location
                    )
                    continue
                family = self.family_range(getattr(element, "family", None), scope)
                names[element.name] = _Declared(element, family)
                self._count_expanded(subsystems * _size(family), element.location)
                if hasattr(element, "data_type"):
                    with self._within(f"`{element.name}/{kind.value}`"):
                        self.data_type(element.data_type, scope, element.location)
                        self.value_too_large(element.data_type, scope, element.location)
        return table

    def _agent_body(self, table: _AgentTable) -> None:
        for sub_table, _family in table.subsystems.values():
            self._place = f"`{subsystem_name(table.agent, sub_table.subsystem)}`"
            self._subsystem_body(table, sub_table, sub_table.scope)  # type: ignore[attr-defined]
        self._place = f"the links of `{table.agent.name}/a`"
        self._links(table.agent.links, table.scope, agent=table)
        self._place = None

    def _subsystem_body(self, agent: _AgentTable, table: _SubsystemTable, scope: Scope) -> None:
        subsystem = table.subsystem
        owner = subsystem_name(agent.agent, subsystem)
        for buffer in subsystem.input_buffers:
            if buffer.queue is not None:
                with self._within(f"`{buffer.name}/ib`"):
                    capacity = self.constant_integer(buffer.queue.capacity, scope, "a FIFO capacity")
                    if capacity is not None and capacity < 1:
                        self.error(
                            f"a FIFO holds at least one message, not {capacity}",
                            buffer.queue.capacity.location,
                            "EARL-R018",
                        )
                policies = buffer.queue.OVERFLOW_POLICIES
                if buffer.queue.overflow not in policies:
                    # only a model built in Python can say this: the reader refuses it (EARL-S013)
                    self.error(
                        f"`{buffer.name}/ib` has the overflow policy {buffer.queue.overflow!r}",
                        buffer.location,
                        "EARL-R018",
                        did_you_mean(str(buffer.queue.overflow), policies)
                        or f"a FIFO's overflow policy is one of {', '.join(policies)}",
                    )
        for memory in subsystem.memories:
            if memory.initial_value is not None:
                # a family's index is known in its own initial value: `history[J in 1..N]/m: double = J`
                declared = table.lookup(Kind.MEMORY).get(memory.name)
                inner = scope
                if memory.family is not None and declared is not None and declared.family is not None:
                    inner = {**scope, memory.family.index: declared.family}
                with self._within(f"`{memory.name}/m`", "the initial value"):
                    self.expression(memory.initial_value, table, inner, owner, reads_allowed=False)
        for predicate in subsystem.primitive_predicates:
            mismatch = predicate.python_problem  # only a model built in Python: the reader builds them alike
            if mismatch is not None:
                self.error(
                    f"`{predicate.name}/pp` of `{owner}` {mismatch}: the text would save the code alone,"
                    f" so the reload would not be this model",
                    predicate.location,
                    "EARL-R048",
                    f"build it with `PrimitivePredicate.python({predicate.name!r}, reads, "
                    f"{predicate.implementation.path if predicate.implementation else ''!r})`",
                )
                continue
            with self._within(f"`{predicate.name}/pp`"):
                self.expression(
                    predicate.expression, table, scope, owner, computed_by_python=predicate.implementation is not None
                )
        for function in subsystem.partial_transition_functions:
            for position, reference in enumerate(function.reads):
                with self._within(f"`{function.name}/pf`", f"reads[{position}]"):
                    self.reference(
                        reference,
                        table,
                        scope,
                        owner,
                        (Kind.INPUT_BUFFER, Kind.MEMORY_INPUT),
                        "read by a Partial Transition Function",
                        star=True,
                    )
            for position, reference in enumerate(function.writes):
                with self._within(f"`{function.name}/pf`", f"writes[{position}]"):
                    self.reference(
                        reference,
                        table,
                        scope,
                        owner,
                        (Kind.MEMORY_OUTPUT, Kind.OUTPUT_BUFFER),
                        "written by a Partial Transition Function",
                        star=True,
                    )
        stage_names: dict[str, Any] = {}
        for stage in subsystem.stage_sets:
            if stage.name in stage_names:
                self.duplicate(f"stage `{stage.name}`", stage.location, stage_names[stage.name].location)
            stage_names[stage.name] = stage
            with self._within(f"stage `{stage.name}`"):
                for reference in stage.functions:
                    self.reference(reference, table, scope, owner, (Kind.PARTIAL_TRANSITION_FUNCTION,), "in a stage")
        for behaviour in subsystem.basic_behaviours:
            behaviour_name = f"`{behaviour.name}/bb`"
            with self._within(behaviour_name, "tf"):
                for stage_functions in behaviour.transition_function.stages:
                    for reference in stage_functions:
                        self.reference(
                            reference,
                            table,
                            scope,
                            owner,
                            (Kind.PARTIAL_TRANSITION_FUNCTION,),
                            "in a transition function",
                        )
            with self._within(behaviour_name, "tc"):
                self.expression(behaviour.terminal_condition.expression, table, scope, owner)
            if behaviour.error_condition is not None:
                with self._within(behaviour_name, "ec"):
                    self.expression(behaviour.error_condition.expression, table, scope, owner)
        if subsystem.fsm is not None:
            self._fsm(subsystem.fsm, table, scope, owner)
        # the reader refuses such a duration; a model built in Python may hold one
        states = subsystem.fsm.states if subsystem.fsm is not None else []
        for duration in [subsystem.period, *(state.timeout for state in states)]:
            if duration is not None and not is_duration(duration):
                # `timeout=0.05`: a value not of its declared type, which `check`'s `explaining` names at its
                # path as a ModelTypeError, as it names every other such value
                raise TypeError(f'not a Duration such as `Duration(2, "ms")`: {duration!r}')
        for what, wrong, location in duration_problems(subsystem):
            self.error(f"{what} of `{owner}` {wrong}", location, "EARL-S012")

    def _fsm(self, fsm: FSM, table: _SubsystemTable, scope: Scope, owner: str) -> None:
        states: dict[str, Any] = {}
        for state in fsm.states:
            if state.name in states:
                self.duplicate(f"state `{state.name}`", state.location, states[state.name].location)
                continue
            states[state.name] = state
            behaviours = table.lookup(Kind.BASIC_BEHAVIOUR)
            if state.behaviour not in behaviours:
                self.error(
                    f"state `{state.name}` names `{state.behaviour}/bb`, which `{owner}` does not declare",
                    state.behaviour_location or state.location,
                    "EARL-R030",
                    did_you_mean(state.behaviour, behaviours) or f"declare `{state.behaviour}/bb {{ tf = … tc = … }}`",
                )
            for group in ("obligatory", "optional"):
                for position, reference in enumerate(getattr(state, group)):
                    with self._within(f"state `{state.name}`", f"{group}[{position}]"):
                        self.reference(
                            reference, table, scope, owner, (Kind.INPUT_BUFFER,), "in a buffer group", star=True
                        )
        if fsm.initial not in states:
            self.error(
                f"the initial state `{fsm.initial}` is not a state of this FSM",
                fsm.initial_location or fsm.location,
                "EARL-R031",
                did_you_mean(fsm.initial, states) or f"add `state {fsm.initial}: {fsm.initial}/bb`",
            )
        for transition in fsm.transitions:
            ends = {transition.destination: transition.destination_location}
            if transition.source is not None:
                ends = {transition.source: transition.source_location, **ends}
            for end, named_at in ends.items():
                if end not in states:
                    self.error(
                        f"transition `{transition.name}/t` names the state `{end}`, which this FSM does not declare",
                        named_at or transition.location,
                        "EARL-R032",
                        did_you_mean(end, states)
                        or (
                            f"its states are {', '.join(f'`{name}`' for name in states)}; "
                            f"declare `state {end}: BEHAVIOUR/bb` to add one"
                            if states
                            else f"declare `state {end}: BEHAVIOUR/bb` first"
                        ),
                    )
            priority = transition.priority
            if priority is not None and (isinstance(priority, bool) or not isinstance(priority, int) or priority < 0):
                # only a model built in Python can say this: the grammar reads a whole number
                self.error(
                    f"transition `{transition.name}/t` has the priority {priority!r}; a priority is a whole number, "
                    "0 or more (lower first)",
                    transition.location,
                    "EARL-R033",
                )
            with self._within(f"transition `{transition.name}/t`", "the condition"):
                self.expression(transition.condition.expression, table, scope, owner)
        for position, assumption in enumerate(fsm.assumptions):
            with self._within("the FSM", f"assumptions[{position}]"):
                self.expression(assumption.expression, table, scope, owner)

    # ------------------------------------------------------------------ references and expressions
    def reference(
        self,
        reference: ElementReference,
        table: _SubsystemTable,
        scope: Scope,
        owner: str,
        allowed: Sequence[Kind],
        role: str,
        star: bool = False,
        read: Read | None = None,
    ) -> _Declared | None:
        """`read`: the expression's read that names `reference`, whose members `any`/`all` may test."""
        if reference.kind not in allowed:
            text = reference_text(reference)  # made for messages only: a large spec has 100,000 references
            permitted = ", ".join(f"`/{k.value}`" for k in allowed)
            hint = None
            if reference.kind is Kind.OUTPUT_BUFFER and Kind.INPUT_BUFFER in allowed:
                hint = "an Output Buffer is written, not read; read what it is computed from in memory (`/mi`)"
            elif reference.kind in (Kind.MEMORY_OUTPUT,) and Kind.MEMORY_INPUT in allowed:
                hint = f"memory is read through `mi`: `{reference.name}/mi`"
            elif reference.kind is Kind.MEMORY_INPUT and Kind.MEMORY_OUTPUT in allowed:
                hint = f"memory is written through `mo`: `{reference.name}/mo`"
            self.error(f"`{text}` cannot be {role}; expected {permitted}", reference.location, "EARL-R021", hint)
            return None
        declared = table.lookup(reference.kind).get(reference.name)
        if declared is None:
            candidates = table.lookup(reference.kind)
            hint = did_you_mean(reference.name, candidates)
            if hint is None:
                other = [k for k, names in table.by_kind.items() if reference.name in names and k is not reference.kind]
                if other:
                    kind = Kind.MEMORY_INPUT if other[0] is Kind.MEMORY and Kind.MEMORY_INPUT in allowed else other[0]
                    hint = (
                        f"there is `{reference.name}/{other[0].value}`; write `{reference.name}/{kind.value}`"
                        if kind in allowed
                        else f"there is `{reference.name}/{other[0].value}`, but that cannot be {role}"
                    )
            if hint is None and reference.kind is Kind.PRIMITIVE_PREDICATE and reference.name in ("true", "false"):
                # the manual's Table 5 writes `false/pp`; its examples declare it first
                hint = f"declare `{reference.name}/pp = {reference.name}`, or write the constant itself: `{reference.name}`"
            title = KIND_TITLES[
                Kind.MEMORY if reference.kind in (Kind.MEMORY_INPUT, Kind.MEMORY_OUTPUT) else reference.kind
            ]
            self.error(f"`{owner}` has no {title} `{reference.name}`", reference.location, "EARL-R022", hint)
            return None
        self._indices(reference, declared.family, scope, star, declared.element, read)
        return declared

    def _read_type(self, element: Any, read: Read) -> Any:
        """The type a read gives, through its fields and elements; None when it cannot be told."""
        current: Any = self.structural_type(element.data_type) if hasattr(element, "data_type") else None
        for accessor in read.path:
            if isinstance(accessor, FieldAccess) and isinstance(current, StructType):
                member = current.field_named(accessor.name)
                current = None if member is None else self.structural_type(member.data_type)
            elif not isinstance(accessor, FieldAccess) and isinstance(current, ArrayType):
                current = self.structural_type(current.element)
            else:
                return None
        return current

    def _indices(
        self,
        reference: ElementReference,
        family: IndexRange | None,
        scope: Scope,
        star: bool,
        element: Any = None,
        read: Read | None = None,
    ) -> None:
        """The indices of `reference` fit its family; `element`: the one declared, for the hints; `read`:
        the read in an expression that names it (None in a list of reads, a link's end, a robot)."""
        if family is None:
            if reference.indices:
                self.error(
                    f"`{reference.name}/{reference.kind.value}` is a single element, not a family; drop the `[…]`",
                    reference.location,
                    "EARL-R023",
                )
            return
        if not reference.indices:
            kind = reference.kind.value
            around = self._index_in_scope(family, scope) if read is None else None
            if star:
                hint = f"write `{reference.name}[1]/{kind}`, or `{reference.name}[*]/{kind}` for every member"
            elif around is not None:
                hint = f"write `{reference.name}[{around}]/{kind}`"  # the index of the family around it
            else:
                hint = f"write `{reference.name}[1]/{kind}`" + self._every_member(
                    reference, family, scope, element, read
                )
            self.error(
                f"`{reference.name}/{kind}` is a family of {len(family.values())}; say which member",
                reference.location,
                "EARL-R024",
                hint,
            )
            return
        if len(reference.indices) > 1:
            self.error(
                f"`{reference_text(reference)}` has {len(reference.indices)} indices; a family has one",
                reference.location,
                "EARL-R025",
            )
            return
        index = reference.indices[0]
        if isinstance(index, Star):
            if not star:
                every = self._every_member(reference, family, scope, element, read)
                self.error(
                    f"`{reference_text(reference)}`: `[*]` stands for every member and cannot be a value in an expression",
                    reference.location,
                    "EARL-R026",
                    f"name one member, `{reference.name}[1]/{reference.kind.value}`{every}",
                )
            return
        values = self.index_values(index, scope)
        if values is None:
            return
        outside = sorted({v for v in values if v < family.first or v > family.last})
        # an empty range is one already refused (R016, R017): every index would be "outside" it
        if outside and family.last >= family.first:
            self.error(
                f"`{reference_text(reference)}` reaches index {outside[0]}, outside the family's {family.first}..{family.last}",
                index.location or reference.location,
                "EARL-R027",
            )

    @staticmethod
    def _index_in_scope(family: IndexRange, scope: Scope) -> str | None:
        """An index in scope that runs over the family's members: `K` of the link family around `pusher/a`."""
        for name, value in scope.items():
            if type(value) is IndexRange and (value.first, value.last) == (family.first, family.last):
                return name
        return None

    def _every_member(
        self, reference: ElementReference, family: IndexRange, scope: Scope, element: Any, read: Read | None
    ) -> str:
        """How every member is taken, as the rest of a hint: by `any`/`all` when the read is a Boolean, by a
        predicate computed by Python when it is not; nothing outside a condition."""
        if read is None:
            return ""
        written: Family | None = getattr(element, "family", None)
        # the family's own index letter, unless that means something else here
        letters = [written.index] if written is not None else []
        letters += ["K", "J", "I", "L", "M"] + [chr(c) for c in range(ord("A"), ord("Z") + 1)]
        letter = next((c for c in letters if c not in scope), "K")
        first, last = (
            (expression_text(written.first), expression_text(written.last))
            if written is not None
            else (str(family.first), str(family.last))
        )
        member = replace(read, target=replace(reference, indices=(Name(letter),)))
        read_type = None if reference.kind is Kind.PRIMITIVE_PREDICATE else self._read_type(element, read)
        boolean = isinstance(read_type, PrimitiveType) and read_type.name == "boolean"
        if reference.kind is Kind.PRIMITIVE_PREDICATE or boolean:
            return f", or every member: `any({letter} in {first}..{last}: {expression_text(member)})` or `all(…)`"
        return (
            f"; a predicate computed by Python reads every member: "
            f'`name/pp({reference.name}[*]/{reference.kind.value}) = python "module:function"`'
        )

    def expression(
        self,
        expression: Expression,
        table: _SubsystemTable | None,
        scope: Scope,
        owner: str,
        reads_allowed: bool = True,
        computed_by_python: bool = False,
    ) -> None:
        """Names, functions and reads of `expression`; `computed_by_python`: it is the `python(reads)` that
        stands for a primitive predicate declared `= python "module:function"`, and only there."""
        stack: list[tuple[Expression, Scope]] = [(expression, scope)]
        while stack:
            node, node_scope = stack.pop()
            self._operator(node)
            if isinstance(node, Name):
                if node.name not in node_scope:
                    self.unknown_name(node, node_scope, table if reads_allowed else None)
                continue
            if isinstance(node, Quantifier):
                if _unreadable_index(node.index):  # built in Python: read from text, it is a name
                    self._unreadable(node.index, _QUANTIFIER_INDEX, node.location)
                if node.index in node_scope:  # it would hide the family's (or outer quantifier's) index
                    self.error(
                        _in_use(node.index, node_scope),
                        node.location,
                        "EARL-R015",
                        f"give `{node.quantifier}` another index letter: inside it, `{node.index}` would no longer "
                        + ("be the parameter" if _is_parameter(node_scope[node.index]) else "be the one outside"),
                    )
                for bound in (node.first, node.last):
                    stack.append((bound, node_scope))
                first = self.constant_integer(node.first, node_scope, "the first index of `any`/`all`")
                last = self.constant_integer(node.last, node_scope, "the last index of `any`/`all`")
                inner = dict(node_scope)
                inner[node.index] = (
                    IndexRange(first, last) if first is not None and last is not None else IndexRange(1, 0)
                )
                stack.append((node.body, inner))
                continue
            if isinstance(node, Read):
                if not reads_allowed or table is None:
                    self.error(
                        f"`{reference_text(node.target)}` cannot be read here: an initial value is a constant",
                        node.location,
                        "EARL-R028",
                    )
                    continue
                declared = self.reference(
                    node.target,
                    table,
                    node_scope,
                    owner,
                    (Kind.INPUT_BUFFER, Kind.MEMORY_INPUT, Kind.PRIMITIVE_PREDICATE),
                    "read by a predicate",
                    read=node,
                )
                if declared is not None:
                    self._path(node, declared, node_scope)
                for accessor in node.path:
                    index = getattr(accessor, "index", None)
                    if index is not None:
                        stack.append((index, node_scope))
                continue
            if (
                isinstance(node, Call)
                and node.function == PYTHON_PREDICATE
                and node is expression
                and computed_by_python
            ):
                # a Python primitive predicate: its arguments are the reads it declares, a list of reads as a
                # Partial Transition Function's, where `x[*]/ib` reads every member of a family
                for argument in node.arguments:
                    if isinstance(argument, Read) and not argument.path and table is not None:
                        self.reference(
                            argument.target,
                            table,
                            node_scope,
                            owner,
                            (Kind.INPUT_BUFFER, Kind.MEMORY_INPUT, Kind.PRIMITIVE_PREDICATE),
                            "read by a predicate",
                            star=True,
                        )
                    else:
                        stack.append((argument, node_scope))
                continue
            if isinstance(node, Call) and node.function == PYTHON_PREDICATE:
                self.error(
                    "`python(…)` is no function of a condition",
                    node.location,
                    "EARL-R040",
                    'a predicate computed by Python is declared `NAME/pp(READS) = python "MODULE:FUNCTION"`, '
                    "and named in conditions as `NAME/pp`"
                    # built in Python (no location): how to build one there
                    + (
                        '; in Python, `PrimitivePredicate.python(NAME, READS, "MODULE:FUNCTION")`'
                        if node.location is None
                        else ""
                    ),
                )
                continue
            if isinstance(node, Call):
                arity = BUILTIN_FUNCTIONS.get(node.function)
                if arity is None:
                    self.error(
                        f"unknown function `{node.function}`",
                        node.location,
                        "EARL-R040",
                        did_you_mean(node.function, BUILTIN_FUNCTIONS)
                        or f"functions: {', '.join(BUILTIN_FUNCTIONS)}, any, all",
                    )
                    continue
                if len(node.arguments) != arity:
                    self.error(
                        f"`{node.function}` takes {arity} argument, not {len(node.arguments)}",
                        node.location,
                        "EARL-R041",
                    )
                    continue
                argument = node.arguments[0]
                if not isinstance(argument, Read) or argument.target.kind is not Kind.INPUT_BUFFER:
                    self.error(
                        f"`{node.function}(…)` applies to an Input Buffer, e.g. `{node.function}(manipulatorCommand/ib)`",
                        argument.location or node.location,
                        "EARL-R042",
                    )
                    continue
            stack.extend((child, node_scope) for child in children(node))

    def _operator(self, node: Expression) -> None:
        """EARL-R047: an operator or quantifier the language does not have (only a model built in Python
        can hold one: the grammar reads none other)."""
        operator = getattr(node, "operator", None) if not isinstance(node, Quantifier) else node.quantifier
        if operator is None:
            return
        known = OPERATORS.get(type(node).__name__, ())
        if operator not in known:
            self.error(
                f"`{operator}` is no {_OPERATOR_ROLES[type(node).__name__]} of EARL",
                node.location,
                "EARL-R047",
                did_you_mean(str(operator), known) or f"EARL has {', '.join(f'`{k}`' for k in known)}",
            )
        elif isinstance(node, BooleanOperation) and len(node.operands) < 2:
            # `BooleanOperation("and", (a,))`: the text writes `a` alone, which reads back as no operation
            self.error(
                f"`{operator}` over {len(node.operands)} operand{'' if len(node.operands) == 1 else 's'}; it takes"
                " two or more",
                node.location,
                "EARL-R047",
                "write the operand itself for one" if node.operands else "write `Literal(True)` or `Literal(False)`",
            )

    def _path(self, read: Read, declared: _Declared, scope: Scope) -> None:
        if not read.path:
            return
        element = declared.element
        if read.target.kind is Kind.PRIMITIVE_PREDICATE:
            self.error(f"`{reference_text(read.target)}` is a Boolean and has no fields", read.location, "EARL-R043")
            return
        current: Any = self.structural_type(element.data_type)
        described = reference_text(read.target)
        for accessor in read.path:
            if current is None:
                return
            if isinstance(accessor, FieldAccess):
                if not isinstance(current, StructType):
                    self.error(
                        f"`{described}` is not a struct, so it has no field `{accessor.name}`",
                        accessor.location,
                        "EARL-R044",
                    )
                    return
                member = current.field_named(accessor.name)
                if member is None:
                    self.error(
                        f"`{current.name}` has no field `{accessor.name}`",
                        accessor.location,
                        "EARL-R045",
                        did_you_mean(accessor.name, [f.name for f in current.fields])
                        or f"its fields: {', '.join(f.name for f in current.fields) or 'none'}",
                    )
                    return
                described += f".{accessor.name}"
                current = self.structural_type(member.data_type)
            else:
                if not isinstance(current, ArrayType):
                    self.error(f"`{described}` is not an array and cannot be indexed", accessor.location, "EARL-R046")
                    return
                described += "[…]"
                current = self.structural_type(current.element)

    # ------------------------------------------------------------------ links and robots
    def _links(self, links: Sequence[Link], scope: Scope, agent: _AgentTable | None) -> None:
        names: dict[str, Link] = {}
        #: each link's name once its family is expanded (`cs,mc[2]`), and the declaration that gives it
        members: dict[str, Link] = {}
        for link in links:
            if not 1 <= len(link.name) <= 2:  # only a model built in Python: `link :` and `link a,b,c:` do not read
                self.error(
                    f"link `{link.name_text}` has {len(link.name)} parts to its name; a link is named by one or two"
                    " (`source,destination`, §2.5)",
                    link.location,
                    "EARL-R058",
                    "name it after its ends, e.g. `(LinkNamePart(SOURCE), LinkNamePart(DESTINATION))`",
                )
                continue
            name = link.name_text
            if name in names:
                self.duplicate(
                    f"link `{name}`",
                    link.location,
                    names[name].location,
                )
                continue
            names[name] = link
            link_scope = dict(scope)
            family = self.family_range(link.family, scope)
            if link.family is not None and family is not None:
                link_scope[link.family.index] = family
            for member in _member_names(link, family, scope):
                first = members.setdefault(member, link)
                if first is not link:  # `link cs,mc[2]` beside the family `cs,mc[K in 1..N]`: two links, one name
                    families = [f"`{each.name_text}`" for each in (first, link) if each.family is not None]
                    self.duplicate(
                        f"link `{member}` (a member of the family {' and of '.join(families)})"
                        if families
                        else f"link `{member}`",
                        link.location,
                        first.location,
                    )
                    break
            for part in link.name:
                if part.index is not None:
                    self.index_values(part.index, link_scope)
            self._link_end(link, link.source, link_scope, agent, Kind.OUTPUT_BUFFER)
            self._link_end(link, link.destination, link_scope, agent, Kind.INPUT_BUFFER)

    def _link_end(self, link: Link, end: LinkEnd, scope: Scope, agent: _AgentTable | None, kind: Kind) -> None:
        role = "source" if kind is Kind.OUTPUT_BUFFER else "destination"
        if not self._of_kind(end.buffer, kind, f"the {role} buffer of link `{link.name_text}`"):
            return
        if end.agent is not None and not self._of_kind(
            end.agent, Kind.AGENT, f"the {role} agent of link `{link.name_text}`"
        ):
            return
        if agent is None:
            if end.agent is None:
                self.error(
                    f"the {role} of link `{link.name_text}` must name its agent, e.g. `task/a.cs.{end.buffer.name}`",
                    end.location,
                    "EARL-R050",
                    "links between subsystems of one agent are declared inside that agent",
                )
                return
            table = self.agents.get(end.agent.name)
            if table is None:
                self.error(
                    f"link `{link.name_text}` names the agent `{end.agent.name}/a`, which is not declared",
                    end.agent.location,
                    "EARL-R051",
                    did_you_mean(end.agent.name, self.agents),
                )
                return
            self._indices(end.agent, table.family, scope, star=False)
        else:
            if end.agent is not None:
                self.error(
                    f"a link inside `{agent.agent.name}/a` connects its own subsystems; drop `{reference_text(end.agent)}.`",
                    end.agent.location,
                    "EARL-R052",
                    "links between agents are declared at the top level of the system",
                )
                return
            table = agent
        key = (end.subsystem.name, end.subsystem.kind)
        found = table.subsystems.get(key)
        if found is None:
            names = [n for (n, k) in table.subsystems if k is end.subsystem.kind]
            # `driver/re` where `driver/ve` is declared: the kind, not the name, is what was mistyped
            other_kinds = [k for (n, k) in table.subsystems if n == end.subsystem.name]
            hint = did_you_mean(end.subsystem.name, names)
            if other_kinds and other_kinds[0] is not Kind.CONTROL_SUBSYSTEM:
                # written with the end's own indices (`motor[K]/re` for `motor[K]/ve`)
                corrected = replace(end.subsystem, kind=other_kinds[0])
                hint = (
                    f"`{end.subsystem.name}` is its {KIND_TITLES[other_kinds[0]]}: write `{reference_text(corrected)}`"
                )
            self.error(
                f"`{table.agent.name}/a` has no subsystem `{reference_text(end.subsystem)}`",
                end.subsystem.location,
                "EARL-R053",
                hint,
            )
            return
        sub_table, sub_family = found
        self._indices(end.subsystem, sub_family, scope, star=False)
        buffers = sub_table.lookup(kind)
        declared = buffers.get(end.buffer.name)
        if declared is None and key in table.declared_twice:
            return  # the buffer may be the other declaration's: EARL-R002 already says what to fix
        if declared is None:
            other = Kind.INPUT_BUFFER if kind is Kind.OUTPUT_BUFFER else Kind.OUTPUT_BUFFER
            # the buffer there in the other direction says more than a similar name: the link is reversed
            hint = (
                f"`{end.buffer.name}` is an {KIND_TITLES[other]} there; a link runs from an Output Buffer to an Input Buffer"
                if end.buffer.name in sub_table.lookup(other)
                else did_you_mean(end.buffer.name, buffers)
            )
            where = f"{table.agent.name}/a.{reference_text(end.subsystem)}"
            self.error(
                f"`{where}` has no {KIND_TITLES[kind]} `{end.buffer.name}`", end.buffer.location, "EARL-R054", hint
            )
            return
        self._indices(end.buffer, declared.family, scope, star=False)

    def _robots(self, scope: Scope) -> None:
        """`scope`: the system's parameters, which a robot's member may name (`worker[N]/a`)."""
        seen: dict[str, Any] = {}
        links = {link.name_text for link in self.system.links}
        #: link families by their name without indices: a robot naming one member (`alpha,worker[1]`) is told
        families = {
            _without_indices(link.name_text): link.name_text for link in self.system.links if link.family is not None
        }
        for robot in self.system.robots:
            self._place = f"`{robot.name}/r`"
            if robot.name in seen:
                self.duplicate(f"robot `{robot.name}/r`", robot.location, seen[robot.name].location)
                continue
            seen[robot.name] = robot
            if robot.name in self.agents:
                self.error(f"`{robot.name}` names both a robot and an agent", robot.location, "EARL-R055")
            for reference in robot.agents:
                if not self._of_kind(reference, Kind.AGENT, f"an agent of robot `{robot.name}/r`"):
                    continue
                table = self.agents.get(reference.name)
                if table is None:
                    self.error(
                        f"robot `{robot.name}/r` refers to the agent `{reference.name}/a`, which is not declared",
                        reference.location,
                        "EARL-R056",
                        did_you_mean(reference.name, self.agents),
                    )
                    continue
                self._indices(reference, table.family, scope, star=True)
            for reference in robot.links:
                if not self._of_kind(reference, Kind.INTER_AGENT_LINK, f"a link of robot `{robot.name}/r`"):
                    continue
                if reference.indices:  # only a model built in Python: `link NAME` has none, they were dropped
                    self.error(
                        f"robot `{robot.name}/r` names the link `{reference.name}` with indices; a robot names a"
                        " link, or a link family whole, by its name as declared",
                        reference.location,
                        "EARL-R057",
                        f'write `ElementReference("{families.get(_without_indices(reference.name), reference.name)}",'
                        " Kind.INTER_AGENT_LINK)`",
                    )
                    continue
                if reference.name not in links:
                    family = families.get(_without_indices(reference.name))
                    self.error(
                        f"robot `{robot.name}/r` refers to the link `{reference.name}`, which is not declared",
                        reference.location,
                        "EARL-R057",
                        f"a robot names a link family whole, as it is declared: `link {family}`"
                        if family is not None
                        else did_you_mean(reference.name, links),
                    )


#: the kinds a condition reads, and how each is written there (memory is read through `mi`)
_READ_AS = {
    Kind.PRIMITIVE_PREDICATE: Kind.PRIMITIVE_PREDICATE,
    Kind.INPUT_BUFFER: Kind.INPUT_BUFFER,
    Kind.MEMORY: Kind.MEMORY_INPUT,
}


def _listed(items: list[str]) -> str:
    """`a`, `a and b`, `a, b and c`."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _whole_double_hint(parameter: Parameter, type_name: str, value: Value) -> str | None:
    """For `param H: int = 0.5 * N`: EARL has no whole division, so how a whole half is written."""
    if type_name not in _INTEGER_TYPES or not isinstance(value, float) or not value.is_integer():
        return None
    name = parameter.name
    if isinstance(parameter.value, Literal):
        return f"write `{int(value)}`: an integer type holds whole numbers, written without a decimal point"
    return (
        f"a `double` stays a `double` even when it is whole (and there is no whole division): give `{name}` "
        f"its own value (`param {name}: {type_name} = {int(value)}`) and compute the others from it by "
        f"multiplying, or declare `{name}` a `double`"
    )


def _without_indices(name: str) -> str:
    """`alpha,worker` for `alpha,worker[K in 1..N]` and `alpha,worker[1]`."""
    return re.sub(r"\[[^\]]*\]", "", name)


def _names(expression: Expression) -> list[Name]:
    return [node for node in walk(expression) if isinstance(node, Name)]


def _is_parameter(value: object) -> bool:
    """Whether a name in scope is a parameter's (a value, or one per family member), not an index's."""
    return not isinstance(value, IndexRange) or isinstance(value, ParameterRange)


def _in_use(index: str, scope: Scope) -> str:
    """Why an index cannot be named `index` here: another index has that name, or a parameter."""
    if not _is_parameter(scope[index]):
        return f"the index `{index}` is already in use here"
    return f"the index `{index}` has the name of a parameter in use here"


def _member_names(link: Link, family: IndexRange | None, scope: Scope) -> list[str]:
    """The names a link's members have once expanded: one for a single link, one per index of a family; none
    when an index is not a constant here (its own error is said elsewhere)."""
    values = _values(scope)
    indices = family.values() if link.family is not None and family is not None else [None]
    names = []
    for member in indices:
        environment = values if member is None else {**values, link.family.index: member}  # type: ignore[union-attr]
        try:
            parts = [
                part.name if part.index is None else f"{part.name}[{evaluate_integer(part.index, environment)}]"
                for part in link.name
            ]
        except ConstantError:
            return []
        names.append(",".join(parts))
    return names


def _values(scope: Scope) -> dict[str, Value]:
    return {name: value for name, value in scope.items() if not isinstance(value, IndexRange | PerMember)}


def _product_size(ranges: Sequence[range]) -> int:
    size = 1
    for values in ranges:
        size *= len(values)
    return size


def resolve(
    system: System, overrides: Mapping[str, Value] | None = None, *, comments_from_text: bool = False
) -> list[Diagnostic]:
    """Every name-resolution problem of a declared system, in the order found. `comments_from_text`: every
    comment of the system came from the reader, so none needs EARL-R007's walk over the whole model
    (the reader's own resolve, and `check` of a system loaded from a file: a comment edited in Python
    there is still refused by `to_earl()`)."""
    resolver = Resolver(system, overrides or {})
    resolver.comments_from_text = comments_from_text
    return resolver.run()


_ELEMENT_LISTS = {
    "input_buffers": "an input buffer",
    "output_buffers": "an output buffer",
    "memories": "a memory",
    "primitive_predicates": "a primitive predicate",
    "partial_transition_functions": "a partial transition function",
    "basic_behaviours": "a basic behaviour",
}
#: a name as the grammar reads it (earl.lark's NAME)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _declared_names(system: System) -> Iterator[tuple[object, str, SourceLocation | None, str]]:
    """Every name the system declares, with what it names (for a message without a location) and the
    attribute path that holds it (`system.agents[1].subsystems[0].memories[0].name`)."""
    yield system.name, "the system", system.location, "system.name"
    for i, parameter in enumerate(system.parameters):
        yield parameter.name, "a system parameter", parameter.location, f"system.parameters[{i}].name"
    for i, definition in enumerate(system.types):
        yield definition.name, "a type", definition.location, f"system.types[{i}].name"
        for j, member in enumerate(getattr(definition, "fields", ())):
            where = f"system.types[{i}].fields[{j}].name"
            yield member.name, f"a field of `{definition.name}`", member.location, where
    for i, robot in enumerate(system.robots):
        yield robot.name, "a robot", robot.location, f"system.robots[{i}].name"
    for i, agent in enumerate(system.agents):
        at = f"system.agents[{i}]"
        yield agent.name, "an agent", agent.location, f"{at}.name"
        if agent.family is not None:
            where = f"{at}.family.index"
            yield agent.family.index, f"the family index of `{agent.name}/a`", agent.family.location, where
        for j, parameter in enumerate(agent.parameters):
            where = f"{at}.parameters[{j}].name"
            yield parameter.name, f"a parameter of `{agent.name}/a`", parameter.location, where
        for j, subsystem in enumerate(agent.subsystems):
            owner, held = f"{agent.name}/a.{subsystem.name}", f"{at}.subsystems[{j}]"
            if subsystem.kind is not Kind.CONTROL_SUBSYSTEM:  # that one is written `cs`, whatever its name
                yield subsystem.name, f"a subsystem of `{agent.name}/a`", subsystem.location, f"{held}.name"
            if subsystem.family is not None:
                where = f"{held}.family.index"
                yield subsystem.family.index, f"the family index of `{owner}`", subsystem.family.location, where
            for k, parameter in enumerate(subsystem.parameters):
                where = f"{held}.parameters[{k}].name"
                yield parameter.name, f"a parameter of {owner}", parameter.location, where
            for kind, called in _ELEMENT_LISTS.items():
                for k, element in enumerate(getattr(subsystem, kind)):
                    yield element.name, f"{called} of {owner}", element.location, f"{held}.{kind}[{k}].name"
                    family = getattr(element, "family", None)
                    if family is not None:
                        what = f"the family index of `{element.name}` in {owner}"
                        yield family.index, what, family.location, f"{held}.{kind}[{k}].family.index"
            for k, stage in enumerate(subsystem.stage_sets):
                yield stage.name, f"a stage set of {owner}", stage.location, f"{held}.stage_sets[{k}].name"
            if subsystem.fsm is not None:
                for k, state in enumerate(subsystem.fsm.states):
                    where = f"{held}.fsm.states[{k}].name"
                    yield state.name, f"a state of the FSM of {owner}", state.location, where
        yield from _link_names(agent.links, f"`{agent.name}/a`", at)
    yield from _link_names(system.links, "the system", "system")


def _link_names(links: Sequence[Link], owner: str, at: str) -> Iterator[tuple[object, str, SourceLocation | None, str]]:
    """The names a link declares: each part of its name (`cs` is written as the keyword it is, and reads back)
    and the index of a link family (`link cs,mc[K in 1..N]: …`)."""
    for i, link in enumerate(links):
        held = f"{at}.links[{i}]"
        for j, part in enumerate(link.name):
            if part.name != "cs":
                yield part.name, f"a part of the name of a link of {owner}", link.location, f"{held}.name[{j}].name"
        if link.family is not None:
            what = f"the family index of a link of {owner}"
            yield link.family.index, what, link.family.location, f"{held}.family.index"


def unreadable_names(system: System) -> list[tuple[object, str, SourceLocation | None, str]]:
    """The declared names (as `_declared_names` gives them) that the reader would not read back from
    `to_earl()`'s text: no EARL name at all (`my arm`), or a keyword where it stands (`period/m`,
    `state/a`). Whether a keyword is one depends on where it is written (`python/m` and `initial/m`
    read back; `period/m` does not), so a system naming something as a keyword is printed and parsed:
    the names a syntax error's line holds are the unreadable ones. Costs nothing without such names."""
    from earl.lang.parser import keywords  # the grammar's keywords; imported on need only

    declared = list(_declared_names(system))
    if system.name == "":
        declared = declared[1:]  # a system without a name is printed without its `system` line
    found = [entry for entry in declared if not (isinstance(entry[0], str) and is_earl_name(entry[0]))]
    if found:
        return found  # the text would not read back for these alone; keywords are asked once they are gone
    # a name as it was read from text reads back: a loaded spec is not printed and read again for its
    # `false/pp`, as the manual names that predicate. One given since, in Python, to an element read from
    # text (which keeps its location) is not the name written there, and is asked as a new one is.
    grammar = keywords()
    suspects = [
        entry
        for entry in declared
        if entry[0] in grammar and (entry[2] is None or _written_at(system, entry[2], entry[3]) != entry[0])
    ]
    if not suspects:
        return []
    from earl.diagnostics import EarlError
    from earl.lang.formatter import format_system
    from earl.lang.parser import parse_text

    try:
        text = format_system(system)
    except (AttributeError, TypeError, KeyError, ValueError):
        return []  # a value no text can say: named elsewhere (ModelTypeError, EARL-R0xx)
    try:
        parse_text(text)
    except EarlError as error:
        diagnostic = error.diagnostics[0] if error.diagnostics else None
        # the word the parser stopped at, as its message quotes it (`unexpected `fifo``, `found `link``):
        # that suspect, not another keyword-named one on the same line (`python/m` reads back)
        quoted = set(re.findall(r"`([^`]+)`", diagnostic.message)) if diagnostic is not None else set()
        stopped_at = [entry for entry in suspects if entry[0] in quoted]
        if stopped_at:
            return stopped_at[:1]
        location = diagnostic.location if diagnostic is not None else None
        lines = text.splitlines()
        # the parser may place its error at the end of the token before the keyword (`… = 0.0` ⏎ ⏎ `state/m`)
        at = location.line - 1 if location is not None else len(lines)
        near = "\n".join(line for line in lines[at : at + 4] if line.strip())
        return [entry for entry in suspects if re.search(rf"(?<![\w]){entry[0]}(?![\w])", near)][:1]
    return []


#: a declared name where its element's location starts, after the keyword its declaration starts with:
#: `param N: …`, `type T = …`, `struct S {`, `state s: …`, `stage s = …` (a line end or a comment may part
#: them); only for that kind, as a family index `state` (`seen[state in 1..2]/m`) is the name itself, not `in`
#: after it
_WRITTEN_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_AFTER_KEYWORD = {
    keyword: re.compile(rf"{keyword}(?:\s|//[^\n]*)+([A-Za-z_][A-Za-z0-9_]*)")
    for keyword in ("param", "type", "struct", "state", "stage")
}
_PARAMETER = re.compile(r"\.parameters\[\d+\]\.name$")
_TYPE = re.compile(r"^system\.types\[(\d+)\]\.name$")
_STATE = re.compile(r"\.fsm\.states\[\d+\]\.name$")
_STAGE = re.compile(r"\.stage_sets\[\d+\]\.name$")
_LINK_NAME_PART = re.compile(r"\.links\[\d+\]\.name\[(\d+)\]\.name$")
_COMMENT = re.compile(r"//[^\n]*")


def _declaring_keyword(system: System, path: str) -> str | None:
    """The keyword the declaration of the name at `path` (as `_declared_names` gives it) starts with."""
    if _PARAMETER.search(path):
        return "param"
    if _STATE.search(path):
        return "state"
    if _STAGE.search(path):
        return "stage"
    definition = _TYPE.match(path)
    if definition is not None:
        return "struct" if isinstance(system.types[int(definition[1])], StructType) else "type"
    return None


def _written_at(system: System, location: SourceLocation, path: str) -> str | None:
    """The name written where `location` starts, in the text the system was read from; None when that text
    is not at hand (a location copied from another system)."""
    sources = system.sources
    if not isinstance(sources, SourceMap):
        return None
    line = sources.line(location.file, location.line)
    if line is None:
        return None
    keyword = _declaring_keyword(system, path)
    part = _LINK_NAME_PART.search(path)
    if keyword is None and part is None:
        match = _WRITTEN_NAME.match(line, location.column - 1)
        return match.group(0) if match is not None else None
    # the declaration's span, which holds its name whatever lines it is written on
    span = [line[location.column - 1 :]]
    for number in range(location.line + 1, location.end_line + 1):
        span.append(sources.line(location.file, number) or "")
    if part is not None:
        written = _written_link_name("\n".join(span))
        return written[int(part[1])] if int(part[1]) < len(written) else None
    after = _AFTER_KEYWORD[keyword].match("\n".join(span))  # type: ignore[index]
    return after.group(1) if after is not None else None


def _written_link_name(text: str) -> list[str]:
    """The parts of the name a link declaration (`link cs,mc[K in 1..N]: cs.x[K] -> …`) is written with; none
    for a link written without a name (`link cs.x -> v/ve.y`), which is named after its ends."""
    head = _COMMENT.sub(" ", text).removeprefix("link").split("->", 1)[0]
    depth, cut, parts = 0, [0], []
    for at, character in enumerate(head):
        if character in "[(":
            depth += 1
        elif character in "])":
            depth -= 1
        elif depth == 0 and character == ",":
            cut.append(at + 1)
        elif depth == 0 and character == ":":
            cut.append(at + 1)
            break
    else:
        return []  # no `:` before the first end: the link has no name written
    for start, end in itertools.pairwise(cut):
        match = _WRITTEN_NAME.match(head[start : end - 1].strip())
        parts.append(match.group(0) if match is not None else "")
    return parts


#: what the index of `any(K in 1..N: …)` is called in EARL-R006
_QUANTIFIER_INDEX = "the index of `any`/`all`"
#: words the index of `any`/`all` cannot be: the reader takes them for an expression (`any(`, `not …`) or,
#: in its body, for a Boolean literal (`true > 0`), so the text would not read back as the same system
_NOT_AN_INDEX = frozenset({"any", "all", "not", "true", "false"})


def _unreadable_index(index: object) -> bool:
    """Whether the index of a quantifier, as `to_earl` writes it, would not read back as that index."""
    return not isinstance(index, str) or not is_earl_name(index) or index in _NOT_AN_INDEX


def unreadable_quantifier_indexes(system: System) -> list[tuple[object, str, SourceLocation | None, str]]:
    """The index of every `any`/`all` of the system that would not read back (`Quantifier("any", "my K", …)`
    built in Python), with its attribute path. Only `to_earl` asks: check says them as it resolves each
    expression."""
    found: list[tuple[object, str, SourceLocation | None, str]] = []
    for root, at in _expressions(system):
        if isinstance(root, Predicate):  # a condition: `tc = …`, a transition's `when …`
            root, at = root.expression, f"{at}.expression"
        if root is None or not any(
            isinstance(node, Quantifier) and _unreadable_index(node.index) for node in walk(root)
        ):
            continue  # the usual case, asked without building the path of every node
        stack: list[tuple[object, str]] = [(root, at)]
        while stack:
            node, where = stack.pop()
            if isinstance(node, Quantifier) and _unreadable_index(node.index):
                found.append((node.index, _QUANTIFIER_INDEX, node.location, f"{where}.index"))
            if isinstance(node, list | tuple):
                stack.extend(reversed([(item, f"{where}[{i}]") for i, item in enumerate(node)]))
            elif is_dataclass(node) and not isinstance(node, type):
                # what the model compares is what it means: a location is not walked
                named = [(getattr(node, f.name, None), f"{where}.{f.name}") for f in fields(node) if f.compare]
                stack.extend(reversed(named))  # in the order they are written
    return found


def _expressions(system: System) -> Iterator[tuple[Any, str]]:
    """Every expression a quantifier can stand in (a value, a condition), with its attribute path; not the
    sizes of arrays nor the bounds of families, which are integers."""
    for i, parameter in enumerate(system.parameters):
        yield parameter.value, f"system.parameters[{i}].value"
    for i, agent in enumerate(system.agents):
        at = f"system.agents[{i}]"
        for j, parameter in enumerate(agent.parameters):
            yield parameter.value, f"{at}.parameters[{j}].value"
        for j, subsystem in enumerate(agent.subsystems):
            held = f"{at}.subsystems[{j}]"
            for k, parameter in enumerate(subsystem.parameters):
                yield parameter.value, f"{held}.parameters[{k}].value"
            for k, memory in enumerate(subsystem.memories):
                yield memory.initial_value, f"{held}.memories[{k}].initial_value"
            for k, predicate in enumerate(subsystem.primitive_predicates):
                yield predicate.expression, f"{held}.primitive_predicates[{k}].expression"
            for k, behaviour in enumerate(subsystem.basic_behaviours):
                yield behaviour.terminal_condition, f"{held}.basic_behaviours[{k}].terminal_condition"
                yield behaviour.error_condition, f"{held}.basic_behaviours[{k}].error_condition"
            if subsystem.fsm is not None:
                for k, transition in enumerate(subsystem.fsm.transitions):
                    yield transition.condition, f"{held}.fsm.transitions[{k}].condition"
                for k, assumption in enumerate(subsystem.fsm.assumptions):
                    yield assumption.expression, f"{held}.fsm.assumptions[{k}].expression"


def is_earl_name(text: str) -> bool:
    """Whether `text` is written as an EARL name: a letter or `_`, then letters, digits and `_` (ASCII)."""
    return _NAME.fullmatch(text) is not None


def _size(family: IndexRange | None) -> int:
    """Members of a family (1 for an element declared alone)."""
    return 1 if family is None else max(0, family.last - family.first + 1)


__all__ = ["MAX_EXPANDED_ELEMENTS", "MAX_FAMILY_MEMBERS", "IndexRange", "Resolver", "resolve"]
