"""Data types of buffers and memory (manual §2.2: a *dataType* is primitive or a nested structure)."""

from __future__ import annotations

from dataclasses import dataclass, field

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
