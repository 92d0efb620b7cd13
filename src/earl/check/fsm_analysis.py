"""FSM analysis: overlapping, dead and missing transition conditions, decided with binary decision diagrams.

A transition condition is a Boolean formula over *atoms*: each comparison, each call of
`newData`/`timeout`/`stale`, each Boolean value read from a buffer or memory is a variable;
`and`, `or`, `not` and `==`/`!=` between Booleans are the BDD's own operations, and a
sub-formula of constants (`2 == 1` in member 2 of a family), or an index (`arr/ib[N - 1]`), is
folded to its value.  A primitive predicate is a variable of its own, tied to its definition, so a
message can say `hot/pp = true` while the analysis knows that `hot/pp` *is* `v/ib > 3.0`.  What
the atoms mean adds constraints, conjoined with the FSM's `assume` formulas:

- comparisons of one value with constants (`v/ib > 5.0`, `v/ib < 3.0`, `mode/ib == "stop"`) are
  decided over the real numbers (or the distinct strings): `v/ib > 5.0 and v/ib < 3.0` never holds.
  A value of an integer type holds only the whole numbers of its range, so `n/ib > 3 and n/ib < 4`
  never holds for an `int`, nor `u/ib < 0` for a `uint8`;
- two values compared with each other (`v/ib > x/mi`, `x/mi >= v/ib`) are one of below, equal, above;
- `newData(x/ib.field)` holds only when `newData(x/ib)` does, and `timeout(x/ib)` only when it
  does not (docs/semantics.md);
- per state, what receiving there makes true: a buffer the state waits for (`obligatory`) took a
  message or timed out, and with no `timeout` took one; one it does not wait for never times out,
  unless an inter-agent link feeds it (over Zenoh its sender may go stale, and a stale buffer reads
  as timed out in every state: a finding that needs this says so);
- a primitive predicate defined through itself (EARL-E045) stays a free Boolean;
- a state whose conditions have a type error (EARL-E030) is not analysed: what they mean is unknown.

The transitions leaving a state are evaluated only when its behaviour stops (`tc or ec`, step 5
of docs/semantics.md), in priority order.  With these, for every state of every FSM:

- two leaving transitions into different states whose conditions can hold together when the
  behaviour stops, without distinct priorities, make the FSM nondeterministic (error, with one assignment);
- a behaviour that can stop while no leaving transition holds is stuck (warning, with one assignment);
- a transition that can never be taken — its condition never holds when the behaviour stops, or
  a transition of higher priority always holds then too — is dead (warning);
- a behaviour whose `tc` and `ec` can never hold never ends (note: fine for a sink state); one that
  the assumptions alone keep from stopping makes the transitions leaving its state dead;
- `assume` formulas that can never hold together would switch every check off (error); those that
  cannot hold in one state (with what receiving there makes true) are an error there, and the state
  is checked without them.

The BDDs come from `dd` (a maintained BDD package; its pure-Python backend needs no
compiler), not from a hand-made solver.
"""

from __future__ import annotations

import importlib
import itertools
import math
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from fractions import Fraction
from types import ModuleType
from typing import TYPE_CHECKING, Any

from earl.check.constants import ORDERINGS, Constant, constant_value, indices_folded
from earl.check.context import CheckContext
from earl.check.expression_types import BOOLEAN, NUMBER, UNKNOWN, ExpressionTyper
from earl.check.registry import Finding, rule
from earl.check.rules_behaviour import followable_definitions
from earl.diagnostics import Severity
from earl.held_signals import stop_signals_held
from earl.model.elements import FSM, Agent, Assumption, State, Subsystem, Transition
from earl.model.expressions import (
    BooleanOperation,
    Call,
    Comparison,
    ElementReference,
    Expression,
    FieldAccess,
    IndexAccess,
    Literal,
    Not,
    Read,
    reads,
)
from earl.model.kinds import Kind
from earl.model.text import expression_text, literal_text, reference_text, subsystem_name
from earl.model.types import StructType


def _import_dd_without_networkx() -> ModuleType:
    """dd's BDDs, imported while `import networkx` fails: `dd.cudd` (CUDD, in C) where dd's wheel
    brings it, else the pure-Python `dd.autoref` (same interface, 20–100× slower on large FSMs).

    dd imports networkx only to draw BDDs as graphs, which earl never does, and falls back
    quietly when it is missing; importing it takes a quarter of a second of every `earl check`
    and `earl run`. Only dd's own import sees it missing: the entry is removed again, so user
    code that imports networkx later gets it as usual.

    A stop signal (Ctrl-C) is held back until the import is done: CPython would lose it inside the
    initialisation of dd's Cython module (earl/held_signals.py).
    """
    absent = "networkx" not in sys.modules
    if absent:
        sys.modules["networkx"] = None  # type: ignore[assignment]  # makes `import networkx` raise ImportError
    try:
        with stop_signals_held():
            try:
                return importlib.import_module("dd.cudd")
            except ImportError:
                return importlib.import_module("dd.autoref")
    finally:
        if absent and "networkx" in sys.modules and sys.modules["networkx"] is None:
            del sys.modules["networkx"]


if TYPE_CHECKING:
    from dd.autoref import BDD, Function
else:
    _dd = _import_dd_without_networkx()
    BDD, Function = _dd.BDD, _dd.Function


@dataclass(frozen=True)
class Analysis:
    """The findings of one FSM, keyed by rule code."""

    findings: dict[str, list[Finding]]


#: `c < x` is `x > c`
_MIRRORED = {"<": ">", "<=": ">=", ">": "<", ">=": "<=", "==": "==", "!=": "!="}


#: the most operands of one `and`/`or` the analysis looks into
_MOST_OPERANDS = 64
#: the most different comparisons of one value with constants it relates (their regions cost the square)
_MOST_COMPARISONS = 128


def _shortened(text: str) -> str:
    return text if len(text) <= 80 else text[:77] + "…"


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class _Encoder:
    """Formulas of one subsystem as BDDs, and the constraints that say what their atoms mean."""

    def __init__(self, context: CheckContext, subsystem: Subsystem) -> None:
        self.bdd = BDD()
        # the order is `order_variables`' alone: CUDD would otherwise sift it as the BDDs grow
        self.bdd.configure(reordering=False)
        self.subsystem = subsystem
        self.typer = ExpressionTyper(context, subsystem)
        self.names: dict[str, str] = {}  # BDD variable → the text a person reads
        self.by_text: dict[str, str] = {}
        #: the variables a condition names itself; examples show these, not what predicates stand for
        self.surface: set[str] = set()
        self._depth = 0  # > 0 while encoding a predicate's definition
        #: what each predicate stands for; one computed by Python is a Boolean of its own (its
        #: `python(reads)` says only what it reads, which two different predicates may share)
        #: a predicate too deep written out (EARL-E047) stays a Boolean of its own: following it to its
        #: definition would recurse past Python's limit
        self.definitions: dict[str, Expression] = followable_definitions(subsystem)
        self._defining: set[str] = set()
        #: predicates reached again while their own definition was being encoded: defined through
        #: themselves (EARL-E045), they stay free Booleans; `p ≡ not p` would make every formula false
        self._cyclic: set[str] = set()
        self._open: list[str] = []  # the predicates whose definitions are being encoded, innermost last
        self._constants: dict[str, Function] = {}  # predicates whose definitions are constants
        #: what each predicate's variable means, conjoined only in `constraints`: one conjunction of
        #: them all, built before `order_variables`, was most of the work of reordering
        self.definitions_met: list[Function] = []
        #: per compared value (its text): the comparisons with a constant, as (operator, constant, variable)
        self.comparisons: dict[str, list[tuple[str, Constant, Function]]] = {}
        #: per compared value of an integer type: the whole numbers it may hold (`uint8`: 0 to 255)
        self.integer_ranges: dict[str, tuple[int, int]] = {}
        self.calls: dict[tuple[str, str], Function] = {}  # (function, argument text) → variable
        #: per two numbers compared (their texts, in order): `<`, `<=`, `==` between them, as variables
        self.relations: dict[tuple[str, str], dict[str, Function]] = {}
        self.call_arguments: dict[str, Read] = {}
        #: per predicate's variable: the variables its definition is written in (`order_variables`)
        self.defined_over: dict[str, set[str]] = {}
        #: per variable, and per compared value (its text): the member of a family or the element of an
        #: array it reads (`order_variables` puts `a[3]/ib` beside `b[3]/ib`)
        self.members: dict[str, _Member] = {}
        self.compared_members: dict[str, _Member] = {}
        self._families: dict[str, int] = {}  # family → rank of first use
        self._last_member: tuple[tuple[int, ...], int] | None = None  # the greatest placed so far

    def variable(self, text: str, expression: Expression | None = None) -> Function:
        """The Boolean named by `text` (the whole text: two long formulas alike in their first words
        are two Booleans), which stands for `expression`; messages show it shortened."""
        name = self.by_text.get(text)
        if name is None:
            name = self.by_text[text] = f"v{len(self.by_text)}"
            self.names[name] = _shortened(text)
            self.bdd.declare(name)
            member = None if expression is None else _member_read(expression)
            if member is not None:
                self.members[name] = member
                self._place(name, member)
        if self._depth == 0:
            self.surface.add(name)
        return self.bdd.var(name)

    def _place(self, name: str, member: _Member) -> None:
        """Declare a member's variable beside the members of other families with its index, not at the
        bottom: `order_variables` comes only once every formula is built, and with all of `a[1..N]/ib`
        above all of `b[1..N]/ib`, building `any(K in 1..N: a[K]/ib and b[K]/ib)` takes 2^N nodes."""
        rank = self._families.setdefault(member.family, len(self._families))
        placed = (member.indices, rank)
        if self._last_member is None or placed >= self._last_member:
            self._last_member = placed  # its place is the bottom, where `declare` put it
            return
        levels = self.bdd.var_levels
        order = sorted((n for n in levels if n != name), key=levels.__getitem__)
        at = next(
            (
                level
                for level, other in enumerate(order)
                if other in self.members
                and (self.members[other].indices, self._families[self.members[other].family]) > placed
            ),
            len(order),
        )
        order.insert(at, name)
        self.bdd.reorder({n: level for level, n in enumerate(order)})

    def encode(self, expression: Expression) -> Function:
        folded = constant_value(expression)
        if isinstance(folded, bool):
            return self.bdd.true if folded else self.bdd.false
        if isinstance(expression, Not):
            return ~self.encode(expression.operand)
        if isinstance(expression, BooleanOperation):
            if len(expression.operands) > _MOST_OPERANDS:
                # `any(K in 1..N: …)` unrolled for a large N: one Boolean of its own, so that no
                # BDD grows with N (dd's operations recurse once per variable)
                return self.variable(expression_text(expression), expression)
            operands = [self.encode(o) for o in expression.operands]
            result = operands[0]
            for operand in operands[1:]:
                result = (result & operand) if expression.operator == "and" else (result | operand)
            return result
        # `arr/ib[N - 1]` is `arr/ib[2]`: one value, compared with the same constants
        expression = indices_folded(expression)
        if isinstance(expression, Read) and expression.target.kind is Kind.PRIMITIVE_PREDICATE and not expression.path:
            return self._predicate(expression)
        if isinstance(expression, Comparison):
            return self._comparison(expression)
        if isinstance(expression, Call) and len(expression.arguments) == 1:
            argument = expression.arguments[0]
            if isinstance(argument, Read) and argument.path and expression.function in ("timeout", "stale"):
                # `timeout(x/ib.f)` is `timeout(x/ib)`: a buffer times out or goes stale as a whole
                argument = Read(argument.target, (), argument.location)
                expression = Call(expression.function, (argument,), expression.location)
            if isinstance(argument, Read):
                return self._call(expression.function, argument)
            return self.variable(expression_text(expression), expression)
        return self.variable(expression_text(expression), expression)

    def _call(self, function: str, argument: Read) -> Function:
        """`newData(x/ib)`, `timeout(x/ib)`, `stale(x/ib)`: a Boolean each, related by `constraints`."""
        variable = self.variable(expression_text(Call(function, (argument,))), argument)
        self.calls[(function, expression_text(argument))] = variable
        self.call_arguments[expression_text(argument)] = argument
        return variable

    def _predicate(self, read: Read) -> Function:
        text = expression_text(read)
        name = read.target.name
        definition = self.definitions.get(name)
        if name in self._open:
            self._cyclic.add(name)
        if definition is not None and name not in self._defining and text not in self.by_text:
            self._defining.add(name)  # each once
            self._depth += 1
            self._open.append(name)
            try:
                meaning = self.encode(definition)
            finally:
                self._depth -= 1
                self._open.pop()
            if name in self._cyclic:
                pass  # defined through itself: free
            elif meaning in (self.bdd.true, self.bdd.false):
                self._constants[name] = meaning  # the manual's `false/pp`: the constant itself
            else:
                self.definitions_met.append(self.variable(text).equiv(meaning))
                self.defined_over[self.by_text[text]] = self.bdd.support(meaning)
        constant = self._constants.get(name)
        return constant if constant is not None else self.variable(text)

    def _comparison(self, comparison: Comparison) -> Function:
        text = expression_text(comparison)
        left, right = constant_value(comparison.left), constant_value(comparison.right)
        operator = comparison.operator
        if left is not None and right is None:
            left, right, operator = right, left, _MIRRORED[operator]
            value_side = comparison.right
        else:
            value_side = comparison.left
        if right is not None and left is None:
            if isinstance(right, bool) and operator in ("==", "!="):
                # `s/ib.b == false` is `not s/ib.b`: the Boolean itself, not an atom of its own
                value = self.encode(value_side)
                return value if (operator == "==") == right else ~value
            variable = self.variable(text, value_side)
            value_text = expression_text(value_side)
            member = _member_read(value_side)
            if member is not None:
                self.compared_members.setdefault(value_text, member)
            self.comparisons.setdefault(value_text, []).append((operator, right, variable))
            whole_numbers = self.typer.integer_range(value_side)
            if whole_numbers is not None:
                self.integer_ranges[value_text] = whole_numbers
            return variable
        if operator in ("==", "!=") and BOOLEAN == self.typer.type_of(comparison.left) == self.typer.type_of(
            comparison.right
        ):
            same = self.encode(comparison.left).equiv(self.encode(comparison.right))
            return same if operator == "==" else ~same
        if left is None and right is None:
            relation = self._two_values(comparison)
            if relation is not None:
                return relation
        return self.variable(text, comparison)

    def _two_values(self, comparison: Comparison) -> Function | None:
        """`a > b` as `not (a <= b)`, `b >= a` as `not (a < b)`, `a != b` as `not (a == b)`: a comparison of
        two values written as one of `a < b`, `a <= b`, `a == b`, its operands in the order of their text,
        so that `v/ib > x/mi` and `x/mi >= v/ib` are seen to exclude each other (`constraints` relates the
        three). Values are numbers, as with constants (a NaN is no value the analysis considers); `==` and
        `!=` between two strings or structs of one type too. None for anything else."""
        first, second, operator = comparison.left, comparison.right, comparison.operator
        first_text, second_text = expression_text(first), expression_text(second)
        if first_text == second_text:
            return None
        if first_text > second_text:
            first, second, operator = second, first, _MIRRORED[operator]
            first_text, second_text = second_text, first_text
        kinds = {self.typer.type_of(first), self.typer.type_of(second)}
        if len(kinds) != 1 or UNKNOWN in kinds or BOOLEAN in kinds:
            return None
        if kinds != {NUMBER} and operator not in ("==", "!="):
            return None
        written_as = {"<": ("<", False), "<=": ("<=", False), ">": ("<=", True), ">=": ("<", True)}
        written_as.update({"==": ("==", False), "!=": ("==", True)})
        relation, negated = written_as[operator]
        variable = self.variable(f"{first_text} {relation} {second_text}", Comparison(relation, first, second))
        if kinds == {NUMBER}:
            self.relations.setdefault((first_text, second_text), {})[relation] = variable
        return ~variable if negated else variable

    def order_variables(self) -> None:
        """Put the variables in an order that keeps the BDDs small (call once every formula is encoded,
        before `constraints`): each compared value's comparisons side by side, sorted by their
        constants; what reads members of families (or elements of arrays) interleaved by index
        (`a[1]/ib`, `b[1]/ib`, `a[2]/ib`, …); each predicate just after the last variable of its
        definition; the rest in the order of first use.

        The order of first use interleaves the comparisons of different values, and a BDD then
        carries every value's region at once: 8 values of 10 comparisons and 40 prioritised
        transitions took a minute. Side by side, a value's regions form a chain one node wide.
        It also puts all of `a[1..N]/ib` before all of `b[1..N]/ib`, where `any(K in 1..N: a[K]/ib
        and b[K]/ib)` has 2^N nodes (N = 24: minutes); interleaved it has 2N."""
        groups: dict[str, int] = {}  # compared value → its group's position of first use
        ranks: dict[str, tuple[str, int]] = {}  # comparison's variable → (compared value, rank by constant)
        for value_text, atoms in self.comparisons.items():
            for rank, (_, _, variable) in enumerate(sorted(atoms, key=_constant_order)):
                if variable.var is not None:  # always: an atom is one variable
                    ranks.setdefault(variable.var, (value_text, rank))
        position_of = {name: position for position, name in enumerate(self.names)}
        for name, (value_text, _) in ranks.items():
            groups[value_text] = min(groups.get(value_text, position_of[name]), position_of[name])
        members = {name: member for name, member in self.members.items() if name not in ranks}
        members.update(
            {name: self.compared_members[value] for name, (value, _) in ranks.items() if value in self.compared_members}
        )
        # every member's slot is where the first of them was used, then by index, then by family
        first_member = min((position_of[name] for name in members), default=0)
        families: dict[str, int] = {}
        for name in sorted(members, key=position_of.__getitem__):
            families.setdefault(members[name].family, len(families))

        def slot(name: str, position: int) -> tuple[int, tuple[int, ...], int]:
            member = members.get(name)
            if member is None:
                return (position, (), 0)
            return (first_member, member.indices, families[member.family])

        key: dict[str, tuple[Any, ...]] = {}
        for name, position in position_of.items():  # in the order of first use
            over = self.defined_over.get(name)
            if name in ranks:
                value_text, rank = ranks[name]
                key[name] = (*slot(name, groups[value_text]), rank)
            elif over and all(v in key for v in over):
                key[name] = (*max(key[v] for v in over), position)
            else:
                key[name] = (*slot(name, position), 0)
        order = sorted(self.names, key=key.__getitem__)
        self.bdd.reorder({name: level for level, name in enumerate(order)})

    def constraints(self) -> Function:
        """What the atoms mean (call once every formula is encoded): comparisons by their regions;
        `newData(x/ib.f)` only with `newData(x/ib)`; `timeout(x/ib)` only without it (a buffer that took
        a message did not time out, stale or not). `stale` is related to nothing: a message may arrive
        from a peer whose liveliness is not known yet."""
        meaning = self.bdd.true
        for definition in self.definitions_met:
            meaning &= definition
        for value_text, atoms in self.comparisons.items():
            meaning &= self._regions(atoms, self.integer_ranges.get(value_text))
        for relations in self.relations.values():
            # two numbers are one of below, equal, above: `a < b` and `a == b` each imply `a <= b`, which
            # is one of them; never both
            below, at_most, equal = relations.get("<"), relations.get("<="), relations.get("==")
            if below is not None and equal is not None:
                meaning &= ~(below & equal)
            if at_most is not None:
                either = self.bdd.false
                for part in (below, equal):
                    if part is not None:
                        meaning &= part.implies(at_most)
                        either |= part
                if below is not None and equal is not None:
                    meaning &= at_most.implies(either)
        depth, self._depth = self._depth, 1  # the buffer's own `newData` is no word of a condition
        try:
            for (function, _), variable in list(self.calls.items()):
                read = self.call_arguments[_]
                if function == "newData" and read.path:
                    whole = self._call("newData", Read(read.target))
                    # a field that every message holds is new exactly when the message is
                    meaning &= variable.equiv(whole) if self._always_present(read) else variable.implies(whole)
                elif function == "timeout":
                    meaning &= variable.implies(~self._call("newData", read))
        finally:
            self._depth = depth
        return meaning

    def _always_present(self, read: Read) -> bool:
        """Whether every message of the buffer holds what `read` names: fields none of them optional, no
        array element on the way (an index can be out of range)."""
        element = self.typer.context.input_buffer(self.subsystem, read.target)
        if element is None:
            return False
        current = self.typer.context.structural(element.data_type)
        for accessor in read.path:
            if not (isinstance(accessor, FieldAccess) and isinstance(current, StructType)):
                return False
            field = current.field_named(accessor.name)
            if field is None or field.optional:
                return False
            current = self.typer.context.structural(field.data_type)
        return True

    def _regions(self, atoms: list[tuple[str, Constant, Function]], whole_numbers: tuple[int, int] | None) -> Function:
        """One value compared with constants lies in one region of the line (or is one of the strings):
        the atoms hold together only as in one of the regions. A value of an integer type lies only in
        the regions that hold a whole number of its range (`n/ib > 3 and n/ib < 4` never holds)."""
        # each Boolean once, by its name (dd makes a new wrapper per `var`, so not by identity); two
        # texts of one comparison (`3.0 < v/ib`, `v/ib > 3.0`) are two Booleans, each in the regions
        atoms = list({variable.var: (op, c, variable) for op, c, variable in atoms}.values())
        if len(atoms) > _MOST_COMPARISONS:
            return self.bdd.true  # regions × atoms grows as the square: such comparisons stay unrelated
        constants = [constant for _, constant, _ in atoms]
        if all(_is_number(c) for c in constants):
            # exact: a float is a fraction, and so is an int of any size (2**53 + 1 is not 2**53); an
            # infinity (`1e999`) is a value a real may hold, and compares with fractions as it should;
            # a NaN constant (`1e999 - 1e999`) compares false with every value, as at run time
            finite = sorted({Fraction(c) for c in constants if isinstance(c, int) or math.isfinite(c)})  # type: ignore[arg-type]
            samples: list[object]
            if whole_numbers is not None:
                samples = _whole_number_samples(finite, *whole_numbers)
            else:
                samples = [-math.inf, math.inf, *finite]
                if finite:
                    samples += [finite[0] - 1, finite[-1] + 1]
                    samples += [(low + high) / 2 for low, high in itertools.pairwise(finite)]
                else:
                    samples.append(Fraction(0))
        elif all(isinstance(c, str) for c in constants) and all(op in ("==", "!=") for op, _, _ in atoms):
            samples = [*dict.fromkeys(constants), object()]  # the strings, and any other
        else:
            return self.bdd.true
        regions = self.bdd.false
        for sample in samples:
            region = self.bdd.true
            for operator, constant, variable in atoms:
                region &= variable if ORDERINGS[operator](sample, constant) else ~variable
            regions |= region
        return regions

    def example(self, formula: Function) -> str:
        hidden = [name for name in self.names if name not in self.surface]
        shown = self.bdd.exist(hidden, formula) if hidden else formula
        assignment = self._first_path(shown)
        if not assignment:
            return "whatever the inputs"
        # a value compared with numbers is said as the range it lies in (`58.0 < v/ib <= 59.0`), not as
        # each comparison's truth: 120 of them, sorted as text, was no example a person could read
        compared: dict[str, tuple[str, str, Constant]] = {
            variable.var: (value_text, operator, constant)
            for value_text, atoms in self.comparisons.items()
            for operator, constant, variable in atoms
            if variable.var is not None
            and _is_number(constant)
            and not (isinstance(constant, float) and math.isnan(constant))
        }
        parts: list[tuple[str, str]] = []  # (what it is sorted by, what is said)
        ranges: dict[str, list[tuple[str, Constant, bool]]] = {}
        for name, value in assignment.items():
            if name in compared:
                value_text, operator, constant = compared[name]
                ranges.setdefault(value_text, []).append((operator, constant, value))
            else:
                parts.append((self.names[name], f"{self.names[name]} = {'true' if value else 'false'}"))
        for value_text, facts in ranges.items():
            said = _range_text(value_text, facts)
            if said is not None:
                parts.append((value_text, said))
            else:  # comparisons left unrelated (EARL's limit of 128): each as it is, in numeric order
                for operator, constant, value in sorted(facts, key=lambda fact: (fact[1], fact[0])):
                    text = f"{value_text} {operator} {literal_text(constant)}"
                    parts.append((value_text, f"{text} = {'true' if value else 'false'}"))
        return ", ".join(said for _, said in sorted(parts, key=lambda part: part[0]))

    def _first_path(self, formula: Function) -> dict[str, bool]:
        """One way to satisfy `formula` (not false), the same whatever the BDD library: from the top
        variable down, false where that still leaves a way, true otherwise; variables the path does not
        meet are free."""
        bdd = self.bdd
        assignment: dict[str, bool] = {}
        while formula != bdd.true:
            name = formula.var
            assert name is not None, "a constant other than true has no way to satisfy it"
            low = bdd.let({name: False}, formula)
            value = low == bdd.false
            assignment[name] = value
            formula = bdd.let({name: True}, formula) if value else low
        return assignment


@dataclass(frozen=True)
class _Member:
    """A member of a family, or an element of an array, that a variable reads: `a[3]/ib` is (`a`, (3,))."""

    family: str
    indices: tuple[int, ...]


def _member_read(expression: Expression) -> _Member | None:
    """The first read of `expression` with whole-number indices (family indices, then array elements)."""
    for read in reads(expression):
        indices = [*read.target.indices, *(a.index for a in read.path if isinstance(a, IndexAccess))]
        values = [index.value for index in indices if isinstance(index, Literal)]
        whole = tuple(v for v in values if isinstance(v, int) and not isinstance(v, bool))
        if whole:
            return _Member(read.target.name, whole)
    return None


#: what `value OPERATOR constant` being true (or false) says of the value: (bound, strict) where bound is
#: "lower", "upper", "equal" or "unequal"
_BOUNDS: dict[tuple[str, bool], tuple[str, bool]] = {
    (">", True): ("lower", True),
    (">", False): ("upper", False),
    (">=", True): ("lower", False),
    (">=", False): ("upper", True),
    ("<", True): ("upper", True),
    ("<", False): ("lower", False),
    ("<=", True): ("upper", False),
    ("<=", False): ("lower", True),
    ("==", True): ("equal", False),
    ("==", False): ("unequal", False),
    ("!=", True): ("unequal", False),
    ("!=", False): ("equal", False),
}


def _range_text(value: str, facts: list[tuple[str, Constant, bool]]) -> str | None:
    """`0.0 < v/ib <= 1.0`, `v/ib > 9.0`, `v/ib == 2.0`, `v/ib != 3.0`: the range of numbers in which each
    comparison of `value` with a constant is as `facts` says (operator, constant, truth); None when there
    is none (comparisons the analysis left unrelated can say what no number does)."""
    lower: tuple[Any, bool] | None = None  # (constant, strict)
    upper: tuple[Any, bool] | None = None
    equal: set[Any] = set()
    unequal: set[Any] = set()
    for operator, constant, truth in facts:
        bound, strict = _BOUNDS[(operator, truth)]
        if bound == "lower" and (lower is None or (constant, strict) > lower):
            lower = (constant, strict)
        elif bound == "upper" and (upper is None or (constant, not strict) < (upper[0], not upper[1])):
            upper = (constant, strict)
        elif bound == "equal":
            equal.add(constant)
        elif bound == "unequal":
            unequal.add(constant)

    def within(number: Any) -> bool:
        above = lower is None or number > lower[0] or (number == lower[0] and not lower[1])
        below = upper is None or number < upper[0] or (number == upper[0] and not upper[1])
        return above and below and number not in unequal

    if equal:
        [exactly, *others] = sorted(equal)
        return f"{value} == {literal_text(exactly)}" if not others and within(exactly) else None
    if lower is not None and upper is not None:
        if lower[0] > upper[0] or (lower[0] == upper[0] and (lower[1] or upper[1])):
            return None
        if lower[0] == upper[0]:
            return f"{value} == {literal_text(lower[0])}" if lower[0] not in unequal else None
    if lower is not None and upper is not None:
        said = (
            f"{literal_text(lower[0])} {'<' if lower[1] else '<='} {value} {'<' if upper[1] else '<='} "
            f"{literal_text(upper[0])}"
        )
    elif lower is not None:
        said = f"{value} {'>' if lower[1] else '>='} {literal_text(lower[0])}"
    elif upper is not None:
        said = f"{value} {'<' if upper[1] else '<='} {literal_text(upper[0])}"
    else:
        said = ""
    excluded = [c for c in sorted(unequal) if lower is None or upper is None or lower[0] < c < upper[0]]
    said_excluded = [f"{value} != {literal_text(c)}" for c in excluded]
    return ", ".join(part for part in [said, *said_excluded] if part) or None


def _whole_number_samples(constants: list[Fraction], least: int, greatest: int) -> list[object]:
    """A whole number of [least, greatest] in every region the constants cut the line into that holds one:
    an open interval (a, b) holds one exactly when floor(a) + 1 < b, and then floor(a) + 1 is one; a
    region unbounded below or above holds `least` or `greatest`, if any."""
    candidates = {least, greatest}
    for constant in constants:
        below = math.floor(constant)
        candidates.update((below - 1, below, below + 1, below + 2))
    return [n for n in sorted(candidates) if least <= n <= greatest]


def _constant_order(atom: tuple[str, Constant, Function]) -> tuple[int, Any]:
    """Numbers by value before the rest by their text: only an order for `order_variables`."""
    constant = atom[1]
    if _is_number(constant) and (isinstance(constant, int) or math.isfinite(constant)):  # type: ignore[arg-type]
        return (0, Fraction(constant))  # type: ignore[arg-type]
    return (1, repr(constant))


def _contradicting(bdd: Any, formulas: list[Function], meaning: Function) -> list[int]:
    """Which of the formulas, unsatisfiable together (under `meaning`), contradict each other: each is
    dropped in turn while the others still cannot hold, so what is left is a set none of which can go
    (innocent assumptions are never blamed)."""
    kept = list(range(len(formulas)))
    for candidate in range(len(formulas)):
        rest = meaning
        for index in kept:
            if index != candidate:
                rest &= formulas[index]
        if rest == bdd.false:
            kept.remove(candidate)
    return kept


#: An assumption quoted in a message is cut to this many characters: its line says where the rest is.
_QUOTED_ASSUMPTION = 60


def _quoted(assumption: Assumption) -> str:
    """`` `v/ib > 3.0` (line 40) ``: an assumption as a message names it."""
    text = expression_text(assumption.expression)
    if len(text) > _QUOTED_ASSUMPTION:
        text = text[: _QUOTED_ASSUMPTION - 1] + "…"
    line = assumption.location.line if assumption.location is not None else None
    return f"`{text}`" + (f" (line {line})" if line is not None else "")


def _contradiction(owner: str, culprits: list[Assumption]) -> Finding:
    """EARL-E064 at the first of the assumptions that cannot hold together, naming each of them."""
    said = [_quoted(assumption) for assumption in culprits]
    if len(said) == 1:
        why = f"{said[0]} holds in no situation"
        hint = "an assumption states what always holds of the inputs; correct it"
    else:
        listed = ", ".join(said[:-1]) + " and " + said[-1]
        why = f"{listed} cannot hold at once"
        hint = "an assumption states what always holds of the inputs; correct one of these"
    return Finding(
        f"the `assume` formulas of {owner} can never hold: {why}, so they would hide every overlap of its transitions",
        culprits[0].location,
        hint,
    )


def _contradiction_in_state(
    owner: str, state: State, culprits: list[Assumption], reasons: list[_BufferFact]
) -> Finding:
    """EARL-E064 at `state`, whose buffer facts (`reasons`) leave the assumptions `culprits` no situation,
    although they can hold in other states: the state is checked without them."""
    said = [_quoted(assumption) for assumption in culprits]
    if len(said) == 1:
        why = f"{said[0]} holds in no situation there"
        without = "it"
    else:
        why = ", ".join(said[:-1]) + " and " + said[-1] + " cannot hold at once there"
        without = "them"
    because = f", as {' and '.join(reason.said for reason in reasons)}" if reasons else ""
    hint = "an assumption states what holds of the inputs in every state of the FSM; correct it"
    unwaited = [reason.not_waited_for for reason in reasons if reason.not_waited_for is not None]
    if unwaited:
        hint += f", or let `{state.name}` wait for `{unwaited[0]}` (`obligatory {unwaited[0]} timeout …`)"
    return Finding(
        f"the `assume` formulas of {owner} cannot hold in state `{state.name}`: {why}{because}; "
        f"`{state.name}` is checked without {without}",
        state.location,
        hint,
    )


def _state_assumptions(
    bdd: Any,
    each_assumed: list[Function],
    meaning: Function,
    explained_facts: list[_BufferFact],
) -> tuple[Function, list[int], list[_BufferFact]]:
    """The assumptions a state is checked under: all of them, unless the state's buffer facts contradict
    some (`assume timeout(x/ib)` in a state that does not wait for `x/ib`). Those are left out, a minimal
    contradicting set at a time. Returned: the kept assumptions conjoined with `meaning`, their indices,
    and the facts that contradict the others."""
    facts = bdd.true
    for fact in explained_facts:
        facts &= fact.formula
    kept = list(range(len(each_assumed)))
    reasons: list[_BufferFact] = []
    while True:
        assumed = meaning
        for index in kept:
            assumed &= each_assumed[index]
        if (assumed & facts) == bdd.false:
            # the facts first, so that each is left out of the contradiction where it can be: what stays
            # is the assumptions that cannot hold and the facts they cannot hold with
            formulas = [fact.formula for fact in explained_facts] + [each_assumed[index] for index in kept]
            culprits = _contradicting(bdd, formulas, meaning)
            blamed = [
                kept[position - len(explained_facts)] for position in culprits if position >= len(explained_facts)
            ]
            if blamed:  # (receiving alone never contradicts itself: no endless loop, whatever happens)
                reasons += [explained_facts[position] for position in culprits if position < len(explained_facts)]
                kept = [index for index in kept if index not in blamed]
                continue
        return assumed, kept, list(dict.fromkeys(reasons))


class _IllTyped:
    """Which formulas have a type error (EARL-E030), their predicates' definitions followed: a number
    where a Boolean belongs (`when v/ib` on a `double`), strings ordered (`s/ib < "b"`). What such a
    formula means is unknown, so the analysis says nothing that rests on it: made a Boolean of its own,
    `v/ib` would be reported as `v/ib = true` in an overlap the author never wrote."""

    def __init__(self, context: CheckContext, subsystem: Subsystem, definitions: dict[str, Expression]) -> None:
        self.context, self.subsystem, self.definitions = context, subsystem, definitions
        self._predicates: dict[str, bool] = {}

    def __call__(self, expression: Expression) -> bool:
        # a typer of its own each time: a typer says each problem once, and a repeat must count too
        typer = ExpressionTyper(self.context, self.subsystem)
        if typer.type_of(expression) not in (BOOLEAN, UNKNOWN) or typer.problems:
            return True
        return any(self._predicate(read.target.name) for read in reads(expression) if _is_predicate(read))

    def _predicate(self, name: str) -> bool:
        known = self._predicates.get(name)
        if known is None:
            self._predicates[name] = False  # defined through itself (EARL-E045): not a type error
            definition = self.definitions.get(name)
            known = self._predicates[name] = definition is not None and self(definition)
        return known


def _is_predicate(read: Read) -> bool:
    return read.target.kind is Kind.PRIMITIVE_PREDICATE and not read.path


def _when(example: str) -> str:
    return example if example == "whatever the inputs" else f"e.g. when {example}"


def _distinct_priorities(first: Transition, second: Transition) -> bool:
    if first.priority is None and second.priority is None:
        return False
    return first.priority != second.priority


def _evaluation_order(transitions: list[Transition]) -> list[Transition]:
    """As `fsm.selectState()` tries them: `priority 1` first, those without a priority last."""
    return sorted(transitions, key=lambda t: (t.priority is None, t.priority or 0))


def analyse(context: CheckContext, subsystem: Subsystem, fsm: FSM, owner: str) -> Analysis:
    encoder = _Encoder(context, subsystem)
    bdd = encoder.bdd
    findings: dict[str, list[Finding]] = {
        code: [] for code in ("EARL-E064", "EARL-E060", "EARL-W061", "EARL-W062", "EARL-I063", "EARL-W021", "EARL-W020")
    }
    ill_typed = _IllTyped(context, subsystem, encoder.definitions)
    assumed = bdd.true
    # an assumption with a type error (EARL-E030) assumes nothing here
    each_assumed = [
        bdd.true if ill_typed(assumption.expression) else encoder.encode(assumption.expression)
        for assumption in fsm.assumptions
    ]
    for formula in each_assumed:
        assumed &= formula
    conditions = {id(t): encoder.encode(t.condition.expression) for t in fsm.transitions}
    stops: dict[str, Function] = {}
    #: the states where a type error (EARL-E030) in their behaviour's `tc`/`ec` or a leaving condition
    #: leaves unknown what happens: not analysed, their transitions thought possible
    unknown: set[str] = {t.source for t in fsm.transitions if t.source and ill_typed(t.condition.expression)}
    for state in fsm.states:
        behaviour = subsystem.basic_behaviour(state.behaviour)
        if behaviour is not None:
            stop = encoder.encode(behaviour.terminal_condition.expression)
            if behaviour.error_condition is not None:
                stop |= encoder.encode(behaviour.error_condition.expression)
            stops[state.name] = stop
            if ill_typed(behaviour.terminal_condition.expression) or (
                behaviour.error_condition is not None and ill_typed(behaviour.error_condition.expression)
            ):
                unknown.add(state.name)
    encoder.order_variables()
    meaning = encoder.constraints()
    if fsm.assumptions and (assumed & meaning) == bdd.false:
        culprits = [fsm.assumptions[i] for i in _contradicting(bdd, each_assumed, meaning)]
        findings["EARL-E064"].append(_contradiction(owner, culprits))
        return Analysis(findings)
    assumed &= meaning
    fed_by_other_agents = _fed_by_other_agents(context, subsystem)
    #: transitions that a `*` stands for (one per other state), named as written
    starred = {id(t) for t in fsm.transitions if t.from_any_state}

    #: a second transition between the same two states has the same name: it is told apart by its number
    #: among them and its line, as the document's Table 5 writes it (`dispatching,waiting/t` #2 (line 67))
    sharing: dict[str, list[int]] = {}
    for transition in fsm.transitions:
        if id(transition) not in starred:  # a `*` is named apart already
            sharing.setdefault(transition.name, []).append(id(transition))

    def named(transition: Transition) -> str:
        if id(transition) in starred:
            return f"`*,{transition.destination}/t` (from `{transition.source}`)"
        same = sharing.get(transition.name, [])
        if len(same) > 1 and id(transition) in same:
            line = f" (line {transition.location.line})" if transition.location is not None else ""
            return f"`{transition.name}/t` #{same.index(id(transition)) + 1}{line}"
        return f"`{transition.name}/t`"

    #: per transition: when `fsm.selectState()` takes it (its behaviour stopped, nothing before it held)
    taken: dict[int, Function] = {}
    dead: dict[int, Finding] = {}  # transitions of states that can stop which are never taken, and why
    for state in fsm.states:
        behaviour = subsystem.basic_behaviour(state.behaviour)
        if behaviour is None:
            continue
        explained_facts = _explained_buffer_facts(encoder, state, fed_by_other_agents)
        facts = bdd.true
        for fact in explained_facts:
            facts &= fact.formula
        # the assumptions hold in the FSM, but perhaps not in this state (`assume timeout(x/ib)` where
        # `x/ib` is not waited for): said, and the state checked without those, not left unexamined
        in_state = assumed
        kept = list(range(len(each_assumed)))
        if fsm.assumptions and (assumed & facts) == bdd.false:
            in_state, kept, reasons = _state_assumptions(bdd, each_assumed, meaning, explained_facts)
            blamed = [fsm.assumptions[index] for index in range(len(each_assumed)) if index not in kept]
            findings["EARL-E064"].append(_contradiction_in_state(owner, state, blamed, reasons))
        stop = stops[state.name] & in_state & facts
        # what also holds when no sender is stale: in one process, or while every peer is alive
        alive = _buffer_facts(encoder, state, frozenset()) if fed_by_other_agents else bdd.true

        def when(situation: Function, alive: Function = alive) -> str:
            said = _when(encoder.example(situation))
            if (situation & alive) == bdd.false:
                said += (
                    " (only while a sending agent in another process is stale: its buffer then reads as timed out "
                    "in every state)"
                )
            return said

        leaving = [t for t in fsm.transitions if t.source == state.name]
        if state.name in unknown:
            for transition in leaving:
                taken[id(transition)] = bdd.true
            continue
        if stop == bdd.false and (stops[state.name] & meaning & facts) == bdd.false:
            findings["EARL-I063"].append(
                Finding(
                    f"`{behaviour.name}/bb` never ends: its terminal and error conditions can never hold, so state `{state.name}` of {owner} is never left",
                    behaviour.location,
                    "fine for a deliberate sink state such as an emergency stop",
                )
            )
            continue
        if stop == bdd.false:
            # the behaviour could stop, but the assumptions say it never does here: not the note above,
            # whose reason would be untrue; what it makes dead is every transition leaving the state
            ruling_out = [
                fsm.assumptions[kept[position]]
                for position in _contradicting(
                    bdd, [each_assumed[index] for index in kept], stops[state.name] & meaning & facts
                )
            ]
            for transition in leaving:
                dead[id(transition)] = Finding(
                    f"transition {named(transition)} of {owner} can never be taken: the `assume` formulas rule out "
                    f"that `{behaviour.name}/bb` stops in `{state.name}` ({', '.join(map(_quoted, ruling_out))})",
                    transition.location,
                    "check the `assume` formulas and the behaviour's terminal condition",
                )
            continue
        if not leaving:
            findings["EARL-W021"].append(
                Finding(
                    f"state `{state.name}` of {owner} has no way out: `{behaviour.name}/bb` can stop, but no transition leaves it",
                    state.location,
                    f"add a transition `{state.name} -> …`, or make its terminal condition `false/pp` if it is a sink state",
                )
            )
            continue
        ordered = _evaluation_order(leaving)
        # when none of the transitions tried before this priority holds, built up a priority at a time:
        # one conjunction per transition, where conjoining every earlier one anew grew as the square
        none_before = bdd.true
        none_in_group = bdd.true
        group_start = 0
        for position, transition in enumerate(ordered):
            if position and _distinct_priorities(ordered[position - 1], transition):
                none_before &= none_in_group
                none_in_group = bdd.true
                group_start = position
            holds = conditions[id(transition)] & stop
            none_in_group &= ~conditions[id(transition)]
            first_to_hold = holds & none_before
            taken[id(transition)] = first_to_hold
            before = ordered[:group_start]
            if holds == bdd.false:
                condition = conditions[id(transition)]
                if (condition & meaning) == bdd.false:
                    never = "its condition never holds"
                elif (condition & in_state) == bdd.false:
                    # possible in itself: the assumptions rule it out, and the message says which
                    ruling_out = [
                        fsm.assumptions[kept[position]]
                        for position in _contradicting(
                            bdd, [each_assumed[index] for index in kept], condition & meaning
                        )
                    ]
                    never = (
                        f"its condition never holds under the `assume` formulas ({', '.join(map(_quoted, ruling_out))})"
                    )
                else:
                    never = f"its condition never holds when `{behaviour.name}/bb` stops"
                dead[id(transition)] = Finding(
                    f"transition {named(transition)} of {owner} can never be taken: {never}",
                    transition.location,
                    "check the condition, the behaviour's terminal condition and the `assume` formulas",
                )
            elif first_to_hold == bdd.false:
                covering = [t for t in before if (holds & conditions[id(t)]) != bdd.false]
                alone = next((t for t in covering if (holds & ~conditions[id(t)]) == bdd.false), None)
                tried = (
                    f"{named(alone)} holds too and is tried first"
                    if alone is not None
                    else "one of "
                    + ", ".join(dict.fromkeys(named(t) for t in covering))
                    + " holds too and is tried first"
                )
                dead[id(transition)] = Finding(
                    f"transition {named(transition)} of {owner} can never be taken: whenever its condition "
                    f"holds, {tried}",
                    transition.location,
                    "narrow the condition of the transition tried first, or change the priorities",
                )
        for position, first in enumerate(leaving):
            for second in leaving[position + 1 :]:
                if _distinct_priorities(first, second) or first.destination == second.destination:
                    continue  # one is tried first, or the next state is the same either way
                # both the first to hold: one of higher priority holding would be taken instead
                both = taken[id(first)] & taken[id(second)]
                if both != bdd.false:
                    findings["EARL-E060"].append(
                        Finding(
                            f"transitions {named(first)} and {named(second)} of {owner} can both hold, {when(both)}",
                            second.location,
                            "give them distinct priorities (`priority 1` is evaluated first) or declare an `assume` that rules this out",
                        )
                    )
        none_holds = bdd.true
        for transition in leaving:
            none_holds &= ~conditions[id(transition)]
        stuck = stop & none_holds
        if stuck != bdd.false:
            findings["EARL-W061"].append(
                Finding(
                    f"`{behaviour.name}/bb` can stop while no transition out of `{state.name}` holds ({owner}), {when(stuck)}",
                    state.location,
                    "add a transition for this case, narrow the terminal condition, or declare an `assume` that rules it out",
                )
            )
    # `* -> recover` stands for one transition from every other state: dead only when none is ever taken.
    for group in _by_declaration(fsm.transitions).values():
        if len(group) == 1 and not group[0].from_any_state:
            if id(group[0]) in dead:
                findings["EARL-W062"].append(dead[id(group[0])])
        elif all(taken.get(id(t), bdd.false) == bdd.false for t in group):
            findings["EARL-W062"].append(
                Finding(
                    f"transition `*,{group[0].destination}/t` of {owner} can never be taken from any state",
                    group[0].location,
                    "check the condition, the behaviours' terminal conditions and the `assume` formulas",
                )
            )
    # Reachability through transitions that can be taken.
    reachable = {fsm.initial}
    frontier = [fsm.initial]
    while frontier:
        source = frontier.pop()
        for transition in fsm.transitions:
            possible = transition.source == source and taken.get(id(transition), bdd.false) != bdd.false
            if possible and transition.destination not in reachable:
                reachable.add(transition.destination)
                frontier.append(transition.destination)
    for state in fsm.states:
        if state.name not in reachable:
            into = [t for t in fsm.transitions if t.destination == state.name and t.source != state.name]
            if not into:
                hint = f"add a transition into `{state.name}`, or remove the state"
            elif any(t.source in reachable for t in into):
                dead_into = list(dict.fromkeys(named(t) for t in into if t.source in reachable))
                its = "its condition" if len(dead_into) == 1 else "their conditions"
                hint = (
                    f"{', '.join(dead_into)} can never be taken: check {its}, the terminal conditions of the "
                    "behaviours they leave and the `assume` formulas"
                )
            else:
                hint = f"the states the transitions into `{state.name}` leave are unreachable too: reach one of them"
            findings["EARL-W020"].append(
                Finding(
                    f"state `{state.name}` of {owner} is unreachable from the initial state `{fsm.initial}`",
                    state.location,
                    hint,
                )
            )
    return Analysis(findings)


def _by_declaration(transitions: list[Transition]) -> dict[object, list[Transition]]:
    """The transitions as written: a `*` line stands for several, one per other state."""
    declared: dict[object, list[Transition]] = {}
    for transition in transitions:
        if transition.from_any_state:
            key: object = ("*", transition.location, transition.destination)
        else:
            key = transition.location or id(transition)
        declared.setdefault(key, []).append(transition)
    return declared


def _fed_by_other_agents(context: CheckContext, subsystem: Subsystem) -> frozenset[tuple[str, int | None]]:
    """The input buffers (name, index) an inter-agent link feeds: over Zenoh their sender can go stale,
    and a stale buffer reads as timed out in every state (docs/distributed.md)."""
    return frozenset(
        (buffer.name, buffer.index)
        for buffer in subsystem.input_buffers
        if any(link.between_agents for link in context.links_into.get(id(buffer), ()))
    )


def _waits_for(references: list[ElementReference], read: Read) -> bool:
    """Whether a state's buffer group names the buffer `read` reads (`wheelState[*]/ib` names them all)."""
    for reference in references:
        if reference.name != read.target.name:
            continue
        if reference.is_family_wide or not reference.indices or reference.indices == read.target.indices:
            return True
    return False


def _buffer_key(read: Read) -> tuple[str, int | None] | None:
    """The buffer a read names, as (name, index); None when its index is no whole number."""
    indices = read.target.indices
    if not indices:
        return (read.target.name, None)
    index = indices[0].value if len(indices) == 1 and isinstance(indices[0], Literal) else None
    return (read.target.name, index) if isinstance(index, int) and not isinstance(index, bool) else None


def _buffer_facts(encoder: _Encoder, state: State, fed_by_other_agents: frozenset[tuple[str, int | None]]) -> Function:
    """What receiving in `state` makes true (docs/semantics.md, step 4), one formula: see `_explained_buffer_facts`."""
    facts = encoder.bdd.true
    for fact in _explained_buffer_facts(encoder, state, fed_by_other_agents):
        facts &= fact.formula
    return facts


@dataclass(frozen=True)
class _BufferFact:
    """One thing receiving in a state makes true, as a formula and as a message says it."""

    said: str
    formula: Function
    #: the buffer (`x/ib`) the fact is about when it holds because the state does not wait for it
    not_waited_for: str | None = None


def _explained_buffer_facts(
    encoder: _Encoder, state: State, fed_by_other_agents: frozenset[tuple[str, int | None]]
) -> list[_BufferFact]:
    """What receiving in `state` makes true (docs/semantics.md, step 4), each fact with what a message says
    of it: a buffer the state waits for took a message or timed out (and, with no timeout, took one); a
    buffer it does not wait for never times out. A buffer an inter-agent link feeds is exempt from the last
    two: its sender may go stale, and a stale buffer reads as timed out in every state (docs/distributed.md)."""
    facts: list[_BufferFact] = []
    for (function, text), variable in list(encoder.calls.items()):
        read = encoder.call_arguments[text]
        if read.path:
            continue
        key = _buffer_key(read)
        may_go_stale = key is None or key in fed_by_other_agents
        waited_for = _waits_for(state.obligatory, read)
        if function == "timeout":
            arrived = encoder.calls.get(("newData", text))
            if waited_for and arrived is not None:
                said = f"`{text}`, which `{state.name}` waits for, took a message or timed out"
                facts.append(_BufferFact(said, arrived | variable))
            elif not waited_for and not may_go_stale:
                said = f"`{text}`, which `{state.name}` does not wait for, never times out"
                facts.append(_BufferFact(said, ~variable, text))
        elif function == "newData" and waited_for and state.timeout is None and not may_go_stale:
            # waited for with no timeout: the iteration ends only once it has come
            said = f"`{text}`, which `{state.name}` waits for with no `timeout`, always took a message"
            facts.append(_BufferFact(said, variable))
    return facts


def _fsm_key(context: CheckContext, subsystem: Subsystem) -> tuple[object, ...]:
    """Equal for two members of a family whose FSM, conditions and predicates read the same once
    expanded: one analysis serves them all. A member whose index reaches its conditions (`K == 1`
    is `2 == 1` in member 2) reads differently and is analysed on its own."""
    fsm = subsystem.fsm
    assert fsm is not None
    parts: list[object] = [id(subsystem.location), fsm.initial]
    parts += [(p.name, expression_text(p.expression)) for p in subsystem.primitive_predicates]
    parts += [
        (s.name, s.behaviour, tuple(reference_text(r) for r in s.obligatory), s.timeout is None) for s in fsm.states
    ]
    # which buffers can go stale (`_buffer_facts`): a member fed from another agent reads differently
    parts.append(_fed_by_other_agents(context, subsystem))
    parts += [(t.source, t.destination, t.priority, expression_text(t.condition.expression)) for t in fsm.transitions]
    parts += [expression_text(a.expression) for a in fsm.assumptions]
    for behaviour in subsystem.basic_behaviours:
        parts.append(expression_text(behaviour.terminal_condition.expression))
        parts.append(
            None if behaviour.error_condition is None else expression_text(behaviour.error_condition.expression)
        )
    return tuple(parts)


#: stands for the subsystem in the messages of an analysis shared by the members of a family
_OWNER = "\x00owner\x00"


def analyses(context: CheckContext) -> dict[str, list[Finding]]:
    """Every FSM of the system analysed once per distinct content; cached on the context for the rules below.

    Members of a family whose FSMs read the same (`_fsm_key`) are analysed once, and each member's
    findings named after it, so that the check says them once with the indices as a range
    (`w[1..4]/a.cs`); a member whose conditions depend on its index is analysed on its own."""
    cached = getattr(context, "_fsm_analyses", None)
    if cached is not None:
        return cached  # type: ignore[no-any-return]
    result: dict[str, list[Finding]] = {}
    groups: dict[object, list[tuple[Agent, Subsystem]]] = {}
    for agent, subsystem in context.subsystems():
        if subsystem.fsm is not None:
            groups.setdefault(_fsm_key(context, subsystem), []).append((agent, subsystem))
    for members in groups.values():
        _, subsystem = members[0]
        assert subsystem.fsm is not None
        for code, found in analyse(context, subsystem, subsystem.fsm, _OWNER).findings.items():
            named = result.setdefault(code, [])
            for finding in found:
                for member_agent, member in members:
                    message = finding.message.replace(_OWNER, subsystem_name(member_agent, member))
                    named.append(Finding(message, finding.location, finding.hint))
    context._fsm_analyses = result  # type: ignore[attr-defined]
    return result


def _from_analysis(code: str) -> Any:
    def check(context: CheckContext) -> Iterator[Finding]:
        yield from analyses(context).get(code, [])

    return check


def _register(code: str, severity: Severity, title: str, reference: str, doc: str) -> None:
    function = _from_analysis(code)
    function.__doc__ = doc
    # SARIF names a rule by an identifier, as the other rules' function names are.
    function.__name__ = "_".join(title.split())
    rule(code, severity, title, reference)(function)


_register(
    "EARL-E060",
    Severity.ERROR,
    "transitions leaving a state do not overlap",
    "§2.2, Figure 5a, Table 5",
    "`fsm.selectState()` must pick one next state. Two transitions leaving one state whose initial conditions "
    "can hold at once when its behaviour stops (under the FSM's `assume` formulas) need distinct priorities, "
    "or an assumption that excludes the overlap. Comparisons of one value with constants are decided over "
    "the numbers (`v/ib > 5.0` and `v/ib < 3.0` never hold together, infinity included; a value of an "
    "integer type over the whole numbers of its range; two values compared with each other are one of below, "
    "equal, above, so `v/ib > x/mi` and `x/mi >= v/ib` never hold together), a primitive "
    "predicate stands for its definition, and what receiving in the state makes true is known: a buffer "
    "the state waits for took a message or timed out (with no `timeout`, took one), one it does not wait "
    "for never times out — unless another agent feeds it, whose sender may go stale over Zenoh (the "
    "message then says so). Two transitions into the same state may overlap: the next state is the same. "
    "The manual's own Table 5 overlaps: `jointMove,jointMove/t` and `jointMove,idle/t` "
    "both hold when a new joint position arrives without an emergency stop.",
)
_register(
    "EARL-E064",
    Severity.ERROR,
    "the assumptions of an FSM can hold",
    "§2.2, Table 5",
    "An `assume` formula states what always holds of a subsystem's inputs, and the FSM analysis considers "
    "only situations in which every assumption holds. Assumptions that contradict each other leave no "
    "situation at all: every overlap and every missing transition would pass unseen. The error points at "
    "the assumptions that cannot hold at once, none of which can be left out of the contradiction (the "
    "others, innocent, are not named). An assumption holds in every state: one that cannot hold with what "
    "receiving in a state makes true (`assume timeout(x/ib)` in a state that does not wait for `x/ib`, "
    "where it never times out) is an error at that state, which is then checked without it.",
)
_register(
    "EARL-W061",
    Severity.WARNING,
    "a behaviour never stops without a way out",
    "§2.2, Figure 5",
    "When a behaviour's terminal or error condition holds, the FSM selects a leaving transition; if none "
    "holds the subsystem is stuck (FABRIC fails; earl records a fault, docs/semantics.md).",
)
_register(
    "EARL-W062",
    Severity.WARNING,
    "every transition can be taken",
    "§2.2, Table 5",
    "A transition whose initial condition never holds when its state's behaviour stops (under the "
    "assumptions), or whenever it holds a transition tried before it (a higher priority) holds too, is dead "
    "specification. A `* -> x` transition is dead when it can be taken from no state. One of two transitions "
    "between the same states (both `n,t/t`) is named with its number among them and its line: "
    "`n,t/t` #2 (line 31).",
)
_register(
    "EARL-I063",
    Severity.NOTE,
    "behaviours that never end",
    "§2.2, Table 5",
    "A behaviour whose terminal and error conditions can never hold runs forever, like the manual's "
    "`emergencyStop/bb` with `false/pp`: fine for a deliberate sink state, a mistake elsewhere. When they "
    "can hold but the `assume` formulas rule it out, the transitions leaving the state are dead instead "
    "(EARL-W062).",
)
_register(
    "EARL-W020",
    Severity.WARNING,
    "every state is reachable",
    "§2.2, Figure 5a",
    "A state no chain of possible transitions leads to from the initial state never runs.",
)
_register(
    "EARL-W021",
    Severity.WARNING,
    "a state that can end has a way out",
    "§2.2, Figure 5a",
    "A state whose behaviour can stop but that no transition leaves leaves the FSM with no next state.",
)
