"""Data types of buffers and memory (manual §2.2: a *dataType* is primitive or a nested structure)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from earl.model.equality import sequences_compare_equal
from earl.model.expressions import Expression
from earl.model.frozen import quick_init
from earl.model.location import Comments, SourceLocation, comments_field, location_field

#: The primitive types a spec may name without defining them.
PRIMITIVE_TYPES: tuple[str, ...] = (
    "boolean",
    "int8",
    "int16",
    "int32",
    "int64",
    "uint8",
    "uint16",
    "uint32",
    "uint64",
    "int",
    "float32",
    "float64",
    "double",
    "string",
    "bytes",
)

#: Deeper array types are refused (EARL-S017; EARL-R019 through aliases): no person writes them, and every
#: walk over a type recurses once per dimension.
MAX_ARRAY_DIMENSIONS = 32

#: The whole numbers each integer type holds (`int` is 64 bits, as in the runtime and on the wire).
INTEGER_RANGES: dict[str, tuple[int, int]] = {
    "int8": (-(2**7), 2**7 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "int": (-(2**63), 2**63 - 1),
    "uint8": (0, 2**8 - 1),
    "uint16": (0, 2**16 - 1),
    "uint32": (0, 2**32 - 1),
    "uint64": (0, 2**64 - 1),
}

#: The primitive types of real numbers: a whole number given for one is that real (`3` is `3.0`).
REAL_TYPES: frozenset[str] = frozenset({"double", "float32", "float64"})

#: The largest finite magnitude of each real type narrower than a double.  Values are held at double
#: precision whatever the type; a finite value beyond its type's range is refused as an integer out of
#: range is (an infinity, which IEEE 754 single precision has too, is not).
REAL_LIMITS: dict[str, float] = {"float32": 3.4028234663852886e38}
#: the least double that single precision rounds to infinity (half an ulp above its largest, 3.4028235e38):
#: below it a value is a float32, `3.4028235e38` as printed included
ROUNDS_TO_INFINITY: dict[str, float] = {"float32": 3.4028235677973366e38}

#: The types a `param` may have, and the Python values each accepts (a boolean is no number here).
PARAMETER_TYPES: dict[str, tuple[type, ...]] = {
    "boolean": (bool,),
    **{name: (int,) for name in INTEGER_RANGES},
    "double": (int, float),
    "float32": (int, float),
    "float64": (int, float),
    "string": (str,),
}


def parameter_value_problem(type_name: str, value: object) -> str | None:
    """Why `value` cannot be a parameter of type `type_name` ("its value is 'abc'"), or None."""
    accepted = PARAMETER_TYPES[type_name]
    if not isinstance(value, accepted) or (isinstance(value, bool) and bool not in accepted):
        return f"its value is {_briefly(value)}"
    if type_name in INTEGER_RANGES:
        assert isinstance(value, int)
        low, high = INTEGER_RANGES[type_name]
        if not low <= value <= high:
            return f"its value {_briefly(value)} does not fit it ({low}..{high})"
    if isinstance(value, float) and value != value:
        return "its value is NaN (not a number), which no computation or export can use"
    if type_name in REAL_TYPES and isinstance(value, int) and not isinstance(value, bool):
        try:
            float(value)
        except OverflowError:  # 400 digits: no double holds it
            return f"its value {_briefly(value)} is too large for a {type_name}"
    if type_name in REAL_LIMITS and isinstance(value, (int, float)) and not real_fits(type_name, float(value)):
        return f"its value {_briefly(value)} does not fit it (at most ±{REAL_LIMITS[type_name]:.8g}; infinity may be)"
    if isinstance(value, str) and lone_surrogate(value) is not None:
        return f"its value {_briefly(value)} is not text (it holds a lone surrogate, from undecodable bytes)"
    return None


def real_fits(type_name: str, value: float) -> bool:
    """Whether a real (not NaN) is within its type's range: any float is a double, an infinity any real."""
    limit = ROUNDS_TO_INFINITY.get(type_name)
    return limit is None or -limit < value < limit or value in (math.inf, -math.inf)


def lone_surrogate(text: str) -> int | None:
    """Where `text` holds half of a surrogate pair, which no UTF-8 file, trace or peer can carry (what
    undecodable bytes become with errors="surrogateescape"); None for text."""
    if text.isascii():
        return None
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as error:
        return error.start
    return None


def _briefly(value: object) -> str:
    """A value as a spec writes it (`true`, `"abc"`, `2.5`), cut short when long."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value != value:
        return "NaN"
    if isinstance(value, str):
        shown = value if len(value) <= 50 else f"{value[:40]}… ({len(value)} characters)"
        shown = shown.encode("utf-8", "backslashreplace").decode("utf-8")  # a lone surrogate, shown escaped
        # as the spec writes it, escapes and all: a newline in a value must not start a line of the message
        return json.dumps(shown, ensure_ascii=False)
    if isinstance(value, int) and abs(value) >= 10**30:
        return f"{'-' if value < 0 else ''}(a whole number of {len(str(abs(value))) if abs(value) < 10**4000 else 'over 4000'} digits)"
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:50]}… ({len(text)} characters)"


@quick_init
@dataclass(frozen=True, slots=True)
class PrimitiveType:
    name: str
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class TypeReference:
    """The name of a `struct` or `type` defined in the spec (`ManipulatorCommand`)."""

    name: str
    location: SourceLocation | None = location_field()


@quick_init
@dataclass(frozen=True, slots=True)
class ArrayType:
    """`double[N]` (fixed: `size` is an expression) or `double[]` (variable: `size` is None)."""

    element: DataType
    size: Expression | None
    location: SourceLocation | None = location_field()

    @property
    def is_fixed(self) -> bool:
        return self.size is not None


DataType = PrimitiveType | TypeReference | ArrayType


@dataclass
class Field:
    """A field of a struct; an optional field (`jointPosSetpoint: JointPosition?`) may be absent."""

    name: str
    data_type: DataType
    optional: bool = False
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


@dataclass
class StructType:
    """`struct ManipulatorCommand { ... }` (Figures 9 and 11)."""

    name: str
    fields: list[Field] = field(default_factory=list)
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()

    def field_named(self, name: str) -> Field | None:
        return next((f for f in self.fields if f.name == name), None)


@dataclass
class TypeAlias:
    """`type JointPosition = double[N]`."""

    name: str
    data_type: DataType
    location: SourceLocation | None = location_field()
    comments: Comments = comments_field()


TypeDefinition = StructType | TypeAlias


def type_text(data_type: DataType) -> str:
    """The type as a person writes it, for messages (`double[N]`, `ManipulatorCommand`)."""
    from earl.model.text import expression_text  # local: text depends on this module

    if isinstance(data_type, ArrayType):
        size = "" if data_type.size is None else expression_text(data_type.size)
        return f"{type_text(data_type.element)}[{size}]"
    return data_type.name


def refuse_wrong_parameters(parameters: object) -> None:
    """A TypeError saying what `parameters` takes, before a misuse fails deep inside with Python's words."""
    if parameters is None:
        return
    if not isinstance(parameters, Mapping):
        raise TypeError(
            f"parameters takes a mapping of parameter names to values, e.g. {{'N': 3}}, not "
            f"{type(parameters).__name__} {parameters!r:.60}"
        )
    for name in parameters:
        # a value of the wrong type is EARL-R005, said with the parameter's declared type
        if not isinstance(name, str):
            raise TypeError(f"a parameter is named by a str, e.g. {{'N': 3}}, not {type(name).__name__} {name!r:.60}")


# a list and a tuple of the same fields are equal (earl/model/equality.py)
sequences_compare_equal(StructType)
