"""Run-time values of the spec's data types, and the checks that keep them honest.

A value in a buffer or in memory is immutable, so the functions of one stage can all
read the same snapshot without copying it (Eq. 7–8: they run "as if in parallel"):

    primitive  -> bool | int | float | str | bytes
    array      -> tuple
    struct     -> Record (an immutable mapping with attribute access)
    absent optional field -> None

`coerce` turns what user code writes (a dict, a list, a NumPy array, an int where a
double is declared) into that form, or says exactly what does not fit the type.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from operator import itemgetter
from typing import Any, NoReturn

from earl.model.elements import System
from earl.model.expressions import Arithmetic, ConstantError, ListLiteral, Literal, Negate, evaluate_constant
from earl.model.location import SourceLocation
from earl.model.types import (
    INTEGER_RANGES,
    REAL_LIMITS,
    ROUNDS_TO_INFINITY,
    ArrayType,
    DataType,
    PrimitiveType,
    StructType,
    TypeAlias,
    TypeReference,
    lone_surrogate,
    real_fits,
    type_text,
)
from earl.runtime.codegen import compiled

Value = Any  # bool | int | float | str | bytes | tuple[Value, ...] | Record | None

_REAL_TYPES = ("double", "float32", "float64")
_FLOAT_ONLY = frozenset({float})
#: arrays of reals up to this size get their element types tested one by one, written out
UNROLLED_ELEMENTS = 16


class Reals(tuple[float, ...]):
    """A checked value of an array of reals (`double[6]`): a tuple of floats, none of them NaN.

    It is a plain tuple to user code, JSON and msgpack. It only remembers that earl checked
    it, so that the same value written again — forwarded from an input buffer to memory, or
    from memory to an output buffer — passes its type test with one comparison, where
    testing the elements costs about 20 ns each (11 µs for a `double[511]`).
    """

    __slots__ = ()

    def __new__(cls, values: Iterable[Any] = ()) -> Reals:
        # What the spec's code makes with `type(value)(…)` is checked like any value: only the runtime,
        # which has checked the elements itself, makes one unchecked (`new_tuple(Reals, …)`).
        return new_tuple(
            cls,
            [
                _coerce_primitive(item, "double", f"element [{index}] of an array of reals")
                for index, item in enumerate(values)
            ],
        )


#: `new_tuple(Reals, values)`: a Reals of elements the caller has checked (floats, none of them NaN),
#: without `Reals.__new__`'s checks; a third faster than through functools.partial
new_tuple = tuple.__new__


#: what the lines of `QuickTest.lines` use, for the namespace they are compiled in
QUICK_TEST_NAMES: dict[str, Any] = {
    "Reals": Reals,
    "new_tuple": new_tuple,
    "only_floats": _FLOAT_ONLY.issuperset,
    **{builtin.__name__: builtin for builtin in (type, tuple, list, len, sum, map, getattr, float)},
}


@dataclass(frozen=True)
class QuickTest:
    """A test that a written value is valid exactly as it is: a float that is not NaN, a bool, an int in
    range, a tuple of floats of the declared size (a list or a 1-D NumPy array is made one first).

    One test, used in two places: `TypeSystem.coercer` compiles it into the coercer's fast
    path, and the engine writes it inline after each call (earl/runtime/iteration.py). Both
    call the type's full check only when it fails, which then converts (an int to a float)
    or refuses with a precise message.
    """

    kind: str  # "real" | "boolean" | "integer" | "real_array"
    low: int = 0
    high: int = 0
    size: int | None = None
    #: for a real type narrower than a double (float32): the least magnitude it rounds to infinity
    real_limit: float | None = None

    def lines(self, value: str, slow: str) -> list[str]:
        """Python lines leaving the variable `value` checked; `slow(value)` is called only when the test fails."""
        if self.kind == "real":
            test = f"type({value}) is float and {value} == {value}"  # not NaN
            if self.real_limit is not None:  # NaN fails the comparisons too; an infinity is left to `slow`
                test = f"type({value}) is float and {-self.real_limit!r} < {value} < {self.real_limit!r}"
        elif self.kind == "boolean":
            test = f"type({value}) is bool"
        elif self.kind == "integer":
            test = f"type({value}) is int and {self.low!r} <= {value} <= {self.high!r}"
        else:  # real_array: Reals were checked before; a tuple is, in C (a NaN makes the sum NaN)
            size = "" if self.size is None else f" and len({value}) == {self.size!r}"
            wrong_size = "" if self.size is None else f" or len({value}) != {self.size!r}"
            # a list or tuple becomes Reals in one copy; a 1-D NumPy array is made a list first
            sequence = f"(type({value}) is list or type({value}) is tuple)"
            if self.size is not None and self.size <= UNROLLED_ELEMENTS:
                # a robot's arrays are short (six joints): one test per element, written out, takes
                # about two thirds of the time of building a `map` for `only_floats`
                floats = "".join(f" and type({value}[{index}]) is float" for index in range(self.size))
            else:
                floats = f" and only_floats(map(type, {value}))"
            # Reals checked as a double[] are not yet within a float32's range: tested again
            in_range = (
                "" if self.real_limit is None else f" and max(map(abs, {value}), default=0.0) < {self.real_limit!r}"
            )
            trusted = (
                "" if self.real_limit is None else f" or max(map(abs, {value}), default=0.0) >= {self.real_limit!r}"
            )
            return [
                f"if type({value}) is not Reals{wrong_size}{trusted}:",
                f"    if not {sequence} and getattr({value}, 'ndim', None) == 1:",
                f"        {value} = {value}.tolist()",
                f"    if {sequence}{size}{floats} and (total := sum({value})) == total{in_range}:",
                f"        {value} = new_tuple(Reals, {value})",
                "    else:",
                f"        {value} = {slow}({value})",
            ]
        return [f"if not ({test}):", f"    {value} = {slow}({value})"]

    def compile(self, slow: Callable[[Any], Value]) -> Callable[[Any], Value]:
        """A coercer: the test, then `slow` for what fails it."""
        source = "\n".join(
            ["def check(value):", *(f"    {line}" for line in self.lines("value", "slow")), "    return value"]
        )
        namespace: dict[str, Any] = {**QUICK_TEST_NAMES, "slow": slow}
        exec(compiled(source), namespace)  # generated from the test's own kind and bounds, no text of a spec
        function: Callable[[Any], Value] = namespace["check"]
        return function


class Record(dict[str, Any]):
    """A struct value: read `msg.jointPosSetpoint` or `msg["jointPosSetpoint"]`; never changed in place.

    It is a dict underneath so that JSON encoding and equality stay cheap; every
    mutating method is refused, which is what lets one snapshot serve a whole stage.
    A field named like a method of dict (`values`, `items`, `get`) is read as the field: the
    method is then reached as `dict.items(msg)` (earl's own code always reaches it so).

    `copy.copy` and `copy.deepcopy` give an equal value, and it pickles: unpickled, it is a
    Record of a struct of the same name and fields (its class is made again if need be).
    """

    __slots__ = ()

    def __copy__(self) -> Record:
        return self  # immutable: a copy would be the same value

    def __deepcopy__(self, memo: dict[int, Any]) -> Record:
        import copy

        return type(self)(copy.deepcopy(dict(dict.items(self)), memo))

    def __reduce__(self) -> tuple[Any, ...]:
        # the classes of structs are made at run time, so pickle could not find one by its name: the
        # value is made again from its struct's name and fields
        cls = type(self)
        if cls is Record:
            return (Record, (dict(dict.items(self)),))
        return (_remade_record, (cls.__name__, tuple(dict.keys(self)), dict(dict.items(self))))

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            fields = ", ".join(self) or "none"
            raise AttributeError(f"this struct has no field `{name}` (its fields: {fields})") from None

    def _refuse(self, *args: object, **kwargs: object) -> NoReturn:
        raise TypeError("a received message or a memory value cannot be changed in place; write a new value instead")

    __setitem__ = __delitem__ = __setattr__ = __delattr__ = _refuse
    clear = pop = popitem = setdefault = update = __ior__ = _refuse  # type: ignore[assignment]

    def replace(self, **changes: Any) -> Record:
        """A copy with some fields changed: `outputs.state = state.replace(motionFinished=True)`."""
        unknown = set(changes) - set(self)
        if unknown:
            raise AttributeError(f"this struct has no field {', '.join(f'`{u}`' for u in sorted(unknown))}")
        merged = dict(self)
        merged.update(changes)
        # unchecked, so not of the struct's class, which the runtime takes as checked; of a class under
        # it, which reads the fields as it does (`.items` is the field): checked when it is written
        return _unchecked_class(type(self))(merged)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(f"{k}={v!r}" for k, v in dict.items(self)) + ")"


def record_class_of(struct: str, fields: Iterable[str]) -> type[Record]:
    """A Record subclass for a struct: each field a class attribute reading its item (`msg.motorPos` is
    `msg["motorPos"]`), so that a field read never reaches `Record.__getattr__` (getting there costs
    Python an AttributeError it builds and drops, ten times the read itself), and so that a field named
    like a method of dict (`items`, `values`) is read as the field, not as the method."""
    namespace: dict[str, Any] = {"__slots__": ()}
    for name in fields:
        if not (name.startswith("_") and hasattr(Record, name)):  # `__class__`, `_refuse` stay what they are
            namespace[name] = property(itemgetter(name), doc=f"the field `{name}` of `{struct}`")
    return type(struct, (Record,), namespace)


def _unchecked_class(cls: type[Record]) -> type[Record]:
    """The class of values `replace` makes from values of `cls`: a subclass, made once."""
    if cls is Record or cls.__dict__.get("_earl_unchecked", False):
        return cls
    found: type[Record] | None = cls.__dict__.get("_earl_unchecked_class")
    if found is None:
        found = type(cls.__name__, (cls,), {"__slots__": (), "_earl_unchecked": True})
        type.__setattr__(cls, "_earl_unchecked_class", found)
    return found


#: the classes `_remade_record` made, by struct name and fields: values unpickled together share one
_REMADE: dict[tuple[str, tuple[str, ...]], type[Record]] = {}


def _remade_record(struct: str, fields: tuple[str, ...], items: dict[str, Any]) -> Record:
    """A Record unpickled (see `Record.__reduce__`)."""
    key = (struct, fields)
    cls = _REMADE.get(key)
    if cls is None:
        cls = _REMADE[key] = record_class_of(struct, fields)
    return cls(items)


class ValueTypeError(TypeError):
    """A value does not fit the declared data type; the message says where and why."""

    #: where the spec wrote the value, when it is a constant of the spec (a memory's initial value)
    location: SourceLocation | None = None


class TypeSystem:
    """The data types of one (expanded) system: names resolved, defaults and checks at hand."""

    def __init__(self, system: System) -> None:
        self._definitions: dict[str, StructType | TypeAlias] = {t.name: t for t in system.types}
        self._defaults: dict[str, Value] = {}
        self._record_classes: dict[str, type[Record]] = {}

    def resolve(self, data_type: DataType) -> PrimitiveType | ArrayType | StructType:
        """Follow `type` aliases to a primitive, an array or a struct."""
        seen: set[str] = set()
        while isinstance(data_type, TypeReference):
            if data_type.name in seen:
                raise ValueTypeError(f"the type `{data_type.name}` is defined in terms of itself")
            seen.add(data_type.name)
            definition = self._definitions.get(data_type.name)
            if definition is None:
                raise ValueTypeError(f"unknown type `{data_type.name}`")
            if isinstance(definition, StructType):
                return definition
            data_type = definition.data_type
        return data_type

    def default(self, data_type: DataType) -> Value:
        """What a buffer holds before its first message, and memory without an initial value."""
        key = type_text(data_type) if not isinstance(data_type, ArrayType) else None
        if key is not None and key in self._defaults:
            return self._defaults[key]
        resolved = self.resolve(data_type)
        value: Value
        if isinstance(resolved, PrimitiveType):
            value = _primitive_default(resolved.name)
        elif isinstance(resolved, ArrayType):
            size = _fixed_size(resolved)
            value = () if size is None else tuple(self.default(resolved.element) for _ in range(size))
            if self._holds_reals(resolved):
                value = new_tuple(Reals, value)
        else:
            record = self.record_class(resolved.name, [f.name for f in resolved.fields])
            value = record({f.name: (None if f.optional else self.default(f.data_type)) for f in resolved.fields})
        if key is not None:
            self._defaults[key] = value
        return value

    def coerce(self, value: Any, data_type: DataType, where: str = "value") -> Value:
        """`value` in its immutable run-time form, or `ValueTypeError` naming `where` and the type."""
        resolved = self.resolve(data_type)
        if isinstance(resolved, PrimitiveType):
            return _coerce_primitive(value, resolved.name, where)
        if isinstance(resolved, ArrayType):
            if isinstance(value, (str, bytes, Mapping)) or not _is_sequence(value):
                _mismatch(value, data_type, where)
            items = list(value.tolist() if hasattr(value, "tolist") else value)
            size = _fixed_size(resolved)
            if size is not None and len(items) != size:
                raise ValueTypeError(f"{where} must have {size} elements ({type_text(data_type)}), not {len(items)}")
            items = [self.coerce(item, resolved.element, f"{where}[{i}]") for i, item in enumerate(items)]
            return new_tuple(Reals, items) if self._holds_reals(resolved) else tuple(items)
        if not isinstance(value, Mapping):
            _mismatch(value, data_type, where)
        fields = {f.name: f for f in resolved.fields}
        unknown = [name for name in value if name not in fields]
        if unknown:
            raise ValueTypeError(
                f"{where}: `{resolved.name}` has no field `{unknown[0]}` (its fields: {', '.join(fields)})"
            )
        result: dict[str, Value] = {}
        for name, declared in fields.items():
            if name not in value or value[name] is None:
                if declared.optional:
                    result[name] = None
                    continue
                raise ValueTypeError(f"{where}: the field `{name}` of `{resolved.name}` is missing")
            result[name] = self.coerce(value[name], declared.data_type, f"{where}.{name}")
        return self.record_class(resolved.name, [f.name for f in resolved.fields])(result)

    def coercer(self, data_type: DataType, where: str) -> Callable[[Any], Value]:
        """`coerce` for one type, with the type's quick test as a fast path (floats, ints, Booleans, real arrays)."""
        resolved = self.resolve(data_type)
        quick = self.quick_test(data_type)
        if quick is not None:
            if isinstance(resolved, PrimitiveType):
                name = resolved.name
                return quick.compile(lambda value: _coerce_primitive(value, name, where))
            return quick.compile(lambda value: self.coerce(value, data_type, where))
        if isinstance(resolved, StructType):
            return self._struct_coercer(resolved, data_type, where)
        return lambda value: self.coerce(value, data_type, where)

    def _holds_reals(self, array: ArrayType) -> bool:
        element = self.resolve(array.element)
        return isinstance(element, PrimitiveType) and element.name in _REAL_TYPES

    def quick_test(self, data_type: DataType) -> QuickTest | None:
        """How the values user code writes most of this type pass as they are, tested inline (see QuickTest)."""
        resolved = self.resolve(data_type)
        if isinstance(resolved, PrimitiveType):
            if resolved.name in _REAL_TYPES:
                return QuickTest("real", real_limit=ROUNDS_TO_INFINITY.get(resolved.name))
            if resolved.name == "boolean":
                return QuickTest("boolean")
            if resolved.name in INTEGER_RANGES:
                low, high = INTEGER_RANGES[resolved.name]
                return QuickTest("integer", low, high)
        if isinstance(resolved, ArrayType) and self._holds_reals(resolved):
            element = self.resolve(resolved.element)
            limit = ROUNDS_TO_INFINITY.get(element.name) if isinstance(element, PrimitiveType) else None
            return QuickTest("real_array", size=_fixed_size(resolved), real_limit=limit)
        return None

    def record_class(self, struct: str, fields: Iterable[str] = ()) -> type[Record]:
        """The Record subclass of one struct (`record_class_of`): a value of that class was checked already
        and passes at once."""
        found = self._record_classes.get(struct)
        if found is None:
            found = self._record_classes[struct] = record_class_of(struct, fields)
        return found

    def _struct_coercer(self, struct: StructType, data_type: DataType, where: str) -> Callable[[Any], Value]:
        """A checked Record of `struct` from a dict or Record, compiled once per struct and place.

        The generated function tests each field inline (a float that is not NaN, a bool, an int
        in range) and calls the field's own checker otherwise; anything unusual goes to `coerce`,
        which says precisely what is wrong.
        """
        cls = self.record_class(struct.name, [f.name for f in struct.fields])
        names: dict[str, Any] = {"cls": cls, "dict": dict, "float": float, "bool": bool, "int": int}
        names["slow"] = lambda value: self.coerce(value, data_type, where)
        lines = [
            "def coerce_struct(value):",
            "    if type(value) is cls:",
            "        return value",
            f"    if type(value) is not dict or len(value) != {len(struct.fields)}:",
            "        return slow(value)",
        ]
        items = []
        for position, field in enumerate(struct.fields):
            variable = f"v{position}"
            lines.append(f"    {variable} = value.get({field.name!r})")
            resolved = self.resolve(field.data_type)
            primitive = resolved.name if isinstance(resolved, PrimitiveType) else None
            test: str
            if primitive in ROUNDS_TO_INFINITY:  # NaN fails the comparisons too; an infinity goes to `slow`
                limit = ROUNDS_TO_INFINITY[primitive]
                test = f"type({variable}) is float and {-limit!r} < {variable} < {limit!r}"
            elif primitive in _REAL_TYPES:
                test = f"type({variable}) is float and {variable} == {variable}"
            elif primitive == "boolean":
                test = f"type({variable}) is bool"
            elif primitive in INTEGER_RANGES:
                low, high = INTEGER_RANGES[primitive]
                test = f"type({variable}) is int and {low} <= {variable} <= {high}"
            else:
                names[f"c{position}"] = self.coercer(field.data_type, f"{where}.{field.name}")
                lines.append(f"    if {variable} is not None:")
                lines.append(f"        try:\n            {variable} = c{position}({variable})")
                lines.append("        except Exception:\n            return slow(value)")
                test = "True" if field.optional else f"{variable} is not None"
            if field.optional:
                test = f"({variable} is None or ({test}))"
            lines.append(f"    if not ({test}):")
            lines.append("        return slow(value)")
            items.append(f"{field.name!r}: {variable}")
        lines.append("    return cls({" + ", ".join(items) + "})")
        exec(compiled("\n".join(lines)), names)  # the source is generated from the spec's own type definitions
        function: Callable[[Any], Value] = names["coerce_struct"]
        return function

    def constant(self, expression: Any, data_type: DataType, where: str) -> Value:
        """The value of an expanded constant expression (a memory's initial value).

        Stricter than `coerce`, which takes `3.0` from user code for an `int`: a real number the spec
        writes for an integer is refused, as for a parameter (`param X: int = 1.0` is EARL-R005)."""
        value = _constant(expression)
        self._no_reals_for_integers(value, data_type, where)
        return self.coerce(value, data_type, where)

    def _no_reals_for_integers(self, value: Any, data_type: DataType, where: str) -> None:
        resolved = self.resolve(data_type)
        if isinstance(resolved, PrimitiveType) and resolved.name in INTEGER_RANGES and isinstance(value, float):
            raise ValueTypeError(
                f"{where} must be a whole number ({resolved.name}), not the real number {shown_value(value)}"
            )
        if isinstance(resolved, ArrayType) and isinstance(value, list):
            for position, item in enumerate(value):
                self._no_reals_for_integers(item, resolved.element, f"{where}[{position}]")


def _constant(expression: Any) -> Any:
    if isinstance(expression, Literal):
        return expression.value
    if isinstance(expression, ListLiteral):
        return [_constant(item) for item in expression.items]
    if isinstance(expression, Arithmetic) and ListLiteral in (type(expression.left), type(expression.right)):
        # `[0.0] * N` is filled by the expansion once `N` is known: left here, its count was no whole number
        count = expression.right if isinstance(expression.left, ListLiteral) else expression.left
        raise ValueTypeError(
            f"an initial value must be a constant: `[…] {expression.operator} N` repeats a list, `[0.0] * N`, "
            f"where N is a whole number of 0 or more, not {shown_value(_constant(count))}"
            if expression.operator == "*"
            else f"an initial value must be a constant: `{expression.operator}` takes numbers, not a list"
        )
    if isinstance(expression, (Negate, Arithmetic)):
        # `2 * QUEUE + 0.5`: the expansion put the parameter's value in.  `-` is the constant evaluator's too,
        # which refuses `-"x"`, `-[1]` and `-true` (Python's -True is -1) as the reader does for a parameter
        try:
            return evaluate_constant(expression, {})
        except ConstantError as error:
            raise ValueTypeError(f"an initial value must be a constant: {error}") from None
    raise ValueTypeError("an initial value must be a constant")


def _fixed_size(array: ArrayType) -> int | None:
    if array.size is None:
        return None
    if not isinstance(array.size, Literal) or not isinstance(array.size.value, int):
        raise ValueTypeError(f"the size of `{type_text(array)}` is not a known whole number")
    return array.size.value


def _primitive_default(name: str) -> Value:
    if name == "boolean":
        return False
    if name in _REAL_TYPES:
        return 0.0
    if name == "string":
        return ""
    if name == "bytes":
        return b""
    return 0


def _is_sequence(value: Any) -> bool:
    return isinstance(value, (list, tuple)) or (hasattr(value, "tolist") and getattr(value, "ndim", 0) == 1)


def _mismatch(value: Any, data_type: DataType, where: str) -> NoReturn:
    raise ValueTypeError(f"{where} must be {type_text(data_type)}, not {_describe(value)}")


def _describe(value: Any) -> str:
    if value is None:
        return "nothing (None)"
    if isinstance(value, bool):
        return f"the Boolean {value}"
    if isinstance(value, (int, float)):
        return f"the number {shown_value(value)}"
    if isinstance(value, str):
        return f"the string {shown_value(value)}"
    return f"a {type(value).__name__}"


def shown_value(value: int | float | str) -> str:
    """A value as a message quotes it: short, whatever its size (Python refuses to print an int of over
    4,300 digits, and a megabyte string would drown the message)."""
    if isinstance(value, int) and value.bit_length() > 200:
        return f"{'-' if value < 0 else ''}(a whole number of {int(value.bit_length() * math.log10(2)) + 1} digits)"
    text = repr(value)
    return text if len(text) <= 80 else f"{text[:60]}… ({len(text)} characters)"


def _coerce_primitive(value: Any, name: str, where: str) -> Value:
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:
        value = value.item()  # a NumPy scalar
    if name == "boolean":
        if isinstance(value, bool):
            return value
        raise ValueTypeError(f"{where} must be a boolean (true or false), not {_describe(value)}")
    if name in _REAL_TYPES:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueTypeError(f"{where} must be a number ({name}), not {_describe(value)}")
        try:
            result = float(value)
        except OverflowError:  # an int beyond any double
            raise ValueTypeError(f"{where} = {shown_value(value)} is too large for a {name}") from None
        if math.isnan(result):
            raise ValueTypeError(f"{where} is NaN (not a number): a computation went wrong upstream")
        if not real_fits(name, result):
            raise ValueTypeError(
                f"{where} = {shown_value(value)} does not fit {name} (at most ±{REAL_LIMITS[name]:.8g}; infinity may be)"
            )
        return result
    if name in INTEGER_RANGES:
        if isinstance(value, bool) or not isinstance(value, int):
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            else:
                raise ValueTypeError(f"{where} must be a whole number ({name}), not {_describe(value)}")
        low, high = INTEGER_RANGES[name]
        if not low <= value <= high:
            raise ValueTypeError(f"{where} = {shown_value(value)} does not fit {name} ({low}..{high})")
        return value
    if name == "string":
        if isinstance(value, str):
            at = lone_surrogate(value)
            if at is not None:
                raise ValueTypeError(
                    f"{where} is not text: it holds the lone surrogate U+{ord(value[at]):04X} at index "
                    f"{at}, which no trace or peer can carry (decode bytes with errors='replace')"
                )
            return value
        raise ValueTypeError(f"{where} must be a string, not {_describe(value)}")
    if name == "bytes":
        if isinstance(value, (bytes, bytearray)):
            return bytes(value)
        raise ValueTypeError(f"{where} must be bytes, not {_describe(value)}")
    raise ValueTypeError(f"unknown primitive type `{name}`")


def plain(value: Any) -> Any:
    """A value of a run as plain Python data: each struct a `dict`, each array a `list`, all the way
    down; for libraries that call a mapping's `items()` by name (`json.dumps`, `msgpack.packb`), which a
    struct's field named `items` hides on a Record."""
    if isinstance(value, dict):
        return {key: plain(item) for key, item in dict.items(value)}
    if isinstance(value, (tuple, list)):
        return [plain(item) for item in value]
    return value


def to_json(value: Value) -> Any:
    """A value as JSON data (bytes as a list of numbers), for traces."""
    if isinstance(value, tuple):
        return [to_json(v) for v in value]
    if isinstance(value, dict):  # dict's own method: a struct's field may be named `items`
        return {k: to_json(v) for k, v in dict.items(value)}
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def json_schema(types: TypeSystem, data_type: DataType) -> dict[str, Any] | None:
    """A JSON Schema for a data type, so that Foxglove can show the fields of a trace message; None
    for a value whose shape Foxglove cannot be told.

    Only what Foxglove's reader of JSON channels takes (its `parseJsonSchema`): each field one
    `type` of boolean, string, number, integer, object (with `properties`) or array of one of the
    others, written out in place. So an optional field is described as its value when present and
    left out of `required` (its absence is written as null); an array of arrays (`double[3][3]`),
    which that reader refuses along with the whole channel and no message path can index, and a
    struct inside itself (`children: Tree[]` of `Tree`), which no schema written out in place can
    end, are left out of the schema (their values are in the messages all the same)."""
    return _json_schema(types, data_type, frozenset())


def _json_schema(types: TypeSystem, data_type: DataType, enclosing: frozenset[str]) -> dict[str, Any] | None:
    """`json_schema`, inside the structs named `enclosing`."""
    resolved = types.resolve(data_type)
    if isinstance(resolved, PrimitiveType):
        if resolved.name == "boolean":
            return {"type": "boolean"}
        if resolved.name in _REAL_TYPES:
            return {"type": "number"}
        if resolved.name == "string":
            return {"type": "string"}
        if resolved.name == "bytes":
            return {"type": "array", "items": {"type": "integer"}}
        return {"type": "integer"}
    if isinstance(resolved, ArrayType):
        items = _json_schema(types, resolved.element, enclosing)
        if items is None or items["type"] == "array":
            return None
        schema: dict[str, Any] = {"type": "array", "items": items}
        size = _fixed_size(resolved)
        if size is not None:
            schema["minItems"] = schema["maxItems"] = size
        return schema
    if resolved.name in enclosing:
        return None
    properties = {}
    for f in resolved.fields:
        inner = _json_schema(types, f.data_type, enclosing | {resolved.name})
        if inner is not None:
            properties[f.name] = inner
    return {
        "type": "object",
        "title": resolved.name,
        "properties": properties,
        "required": [f.name for f in resolved.fields if not f.optional and f.name in properties],
    }


def iter_leaves(value: Value, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """(path, leaf) for every leaf of a trace's JSON value: `position[0]`, `pose.x` — for plots.

    A leaf is a number, a Boolean, a string or None. None is JSON's null, which stands for two
    things the reader of a trace tells apart by the channel's schema: an absent optional field and
    an infinite real (which JSON cannot write). A string is yielded too, so that a plot of it can
    say it is no number rather than that it was never recorded."""
    if isinstance(value, dict):
        for key, inner in dict.items(value):
            yield from iter_leaves(inner, f"{prefix}.{key}" if prefix else key)
    elif isinstance(value, (list, tuple)):
        for index, inner in enumerate(value):
            yield from iter_leaves(inner, f"{prefix}[{index}]")
    elif value is None or isinstance(value, (bool, int, float, str)):
        yield prefix, value
