"""The wire format of a link between processes (docs/distributed.md, "Wire format").

    message = fingerprint (8 bytes) + msgpack(value)

The fingerprint is a hash of the link's data type *as a structure*: struct and field
names, optional marks, primitive names and fixed array sizes, aliases followed.  Two
processes built from specs that disagree on a link's type therefore disagree on the
fingerprint, and the receiver refuses the message instead of misreading it.  Records
travel as msgpack maps and tuples as arrays, except arrays of reals (robot data's usual
shape: joint positions, currents), which travel as one msgpack ext of packed
little-endian float64: one C call writes or reads them, where msgpack floats cost a
Python object and a type check each.  What arrives is checked with the runtime's own
coercers, so user code always gets Records and tuples, never raw lists.
"""

from __future__ import annotations

import hashlib
import struct
from collections.abc import Callable
from typing import Any

import msgpack  # type: ignore[import-untyped]

from earl.model.types import ArrayType, DataType, PrimitiveType, StructType
from earl.runtime.values import Reals, TypeSystem, ValueTypeError, new_tuple

FINGERPRINT_SIZE = 8
#: the msgpack ext type of an array of reals: its data is the elements as little-endian float64
REAL_ARRAY_EXT = 1
_REAL = frozenset({"double", "float64", "float32"})


class MalformedMessage(ValueError):
    """The bytes are not a message of this link: too short, not msgpack, or not of the link's type."""


class FingerprintMismatch(ValueError):
    """The message carries another data type's fingerprint."""

    def __init__(self, received: bytes) -> None:
        super().__init__(f"fingerprint {received.hex()}")
        self.received = received


def describe(types: TypeSystem, data_type: DataType) -> str:
    """The canonical structural text of a type: `struct ManipulatorCommand{jointPosSetpoint:double[6]?,…}`."""
    resolved = types.resolve(data_type)
    if isinstance(resolved, PrimitiveType):
        return resolved.name
    if isinstance(resolved, ArrayType):
        return f"{describe(types, resolved.element)}[{_count(resolved)}]"
    return _describe_struct(types, resolved)


def _count(array: ArrayType) -> str:
    if array.size is None:
        return ""
    value = getattr(array.size, "value", None)
    if not isinstance(value, int):
        raise ValueTypeError("an array's size must be a known whole number to send it between processes")
    return str(value)


def _describe_struct(types: TypeSystem, struct: StructType) -> str:
    fields = ",".join(
        f"{field.name}:{describe(types, field.data_type)}{'?' if field.optional else ''}" for field in struct.fields
    )
    return f"struct {struct.name}{{{fields}}}"


def fingerprint(description: str) -> bytes:
    """8 bytes of BLAKE2b over the canonical description."""
    return hashlib.blake2b(description.encode("utf-8"), digest_size=FINGERPRINT_SIZE).digest()


# ---------------------------------------------------------------- arrays of reals as packed float64
def pack_reals(values: Any) -> msgpack.ExtType:
    """An array of reals as the msgpack ext that carries it."""
    return msgpack.ExtType(REAL_ARRAY_EXT, struct.pack(f"<{len(values)}d", *values))


def _read_ext(code: int, data: bytes) -> tuple[float, ...]:
    """msgpack's ext hook: the tuple of floats in a packed array; anything else is malformed."""
    if code != REAL_ARRAY_EXT:
        raise ValueError(f"unknown msgpack ext type {code}")
    if len(data) % 8:
        raise ValueError(f"a packed array of reals of {len(data)} bytes, not a multiple of 8")
    values: tuple[float, ...] = struct.unpack(f"<{len(data) // 8}d", data)
    return values


def _is_real_array(types: TypeSystem, resolved: PrimitiveType | ArrayType | StructType) -> bool:
    if not isinstance(resolved, ArrayType):
        return False
    element = types.resolve(resolved.element)
    return isinstance(element, PrimitiveType) and element.name in _REAL


def _preparer(types: TypeSystem, data_type: DataType) -> Callable[[Any], Any] | None:
    """What turns a checked value of this type into what msgpack writes: its arrays of reals made
    packed exts, and structs with a field named `items` plain dicts; None when the type holds neither (the
    value is written as it is)."""
    resolved = types.resolve(data_type)
    if _is_real_array(types, resolved):
        return pack_reals
    if isinstance(resolved, ArrayType):
        inner = _preparer(types, resolved.element)
        if inner is None:
            return None
        return lambda values: [inner(item) for item in values]
    if isinstance(resolved, StructType):
        fields = [(f.name, p) for f in resolved.fields if (p := _preparer(types, f.data_type)) is not None]
        if not fields:
            if any(f.name == "items" for f in resolved.fields):
                # its Record reads `items` as the field, where msgpack calls a dict's `items()`: a plain dict
                return dict
            return None

        def prepare_struct(value: Any) -> dict[str, Any]:
            prepared = dict(value)
            for name, prepare in fields:
                item = prepared[name]
                if item is not None:  # an absent optional field stays nil
                    prepared[name] = prepare(item)
            return prepared

        return prepare_struct
    return None


class _FixedReals:
    """A fixed `double[N]` link: the whole message is a constant prefix (fingerprint and ext header)
    and N packed doubles, so one struct call writes it and one comparison and one struct call read
    it.  Read values need only the NaN test, done on the bytes when it can (a NaN makes the sum NaN;
    so does an infinity of each sign, which the general path then tells apart)."""

    __slots__ = ("_pack", "_unpack", "length", "prefix")

    def __init__(self, fingerprint: bytes, size: int) -> None:
        layout = struct.Struct(f"<{size}d")
        packed = msgpack.packb(msgpack.ExtType(REAL_ARRAY_EXT, bytes(layout.size)))
        self.prefix: bytes = fingerprint + packed[: len(packed) - layout.size]  # the ext header alone
        self.length = len(self.prefix) + layout.size
        self._pack = layout.pack
        self._unpack = layout.unpack_from

    def encode(self, values: Any) -> bytes:
        return self.prefix + self._pack(*values)

    def decode(self, payload: bytes) -> Reals | None:
        if len(payload) != self.length or not payload.startswith(self.prefix):
            return None
        start = len(self.prefix)
        values: tuple[float, ...] = self._unpack(payload, start)
        # a NaN's top byte is 0x7f or 0xff (little-endian: every 8th byte); when no element has one,
        # two memchr calls prove it without looking at the floats
        top = payload[start + 7 :: 8]
        if b"\x7f" not in top and b"\xff" not in top:
            return new_tuple(Reals, values)
        total = sum(values)
        return new_tuple(Reals, values) if total == total else None


def _fixed_reals(types: TypeSystem, data_type: DataType, fingerprint: bytes) -> _FixedReals | None:
    resolved = types.resolve(data_type)
    if not _is_real_array(types, resolved):
        return None
    assert isinstance(resolved, ArrayType)
    size = getattr(resolved.size, "value", None) if resolved.size is not None else None
    return _FixedReals(fingerprint, size) if isinstance(size, int) else None


class LinkCodec:
    """Encodes and decodes the messages of one data type."""

    __slots__ = ("_coerce", "_fixed", "_pack", "_prepare", "description", "encode", "fingerprint", "fixed_decoder")

    def __init__(self, types: TypeSystem, data_type: DataType, where: str) -> None:
        self.description = describe(types, data_type)
        self.fingerprint = fingerprint(self.description)
        self._coerce: Callable[[Any], Any] = types.coercer(data_type, where)
        self._pack: Callable[[Any], bytes] = msgpack.Packer(use_bin_type=True).pack
        self._prepare = _preparer(types, data_type)
        self._fixed = _fixed_reals(types, data_type, self.fingerprint)
        #: `value` (already a checked run-time value: it left an output buffer) on the wire
        self.encode: Callable[[Any], bytes] = self._fixed.encode if self._fixed is not None else self._encode
        #: for a fixed array of reals: the value of a well-formed message, None for anything else
        #: (which `decode` then explains); None for other types
        self.fixed_decoder: Callable[[bytes], Reals | None] | None = (
            self._fixed.decode if self._fixed is not None else None
        )

    def _encode(self, value: Any) -> bytes:
        prepare = self._prepare
        return self.fingerprint + self._pack(value if prepare is None else prepare(value))

    def decode(self, payload: bytes) -> Any:
        """The run-time value in `payload`; `FingerprintMismatch` or `MalformedMessage` otherwise."""
        fixed = self._fixed
        if fixed is not None:
            values = fixed.decode(payload)
            if values is not None:
                return values
        if len(payload) <= FINGERPRINT_SIZE:
            raise MalformedMessage(f"{len(payload)} bytes, shorter than a fingerprint and a value")
        received = payload[:FINGERPRINT_SIZE]
        if received != self.fingerprint:
            raise FingerprintMismatch(received)
        try:
            raw = msgpack.unpackb(
                payload[FINGERPRINT_SIZE:], use_list=False, raw=False, strict_map_key=True, ext_hook=_read_ext
            )
        except Exception as error:  # msgpack raises several unrelated types for bad input
            raise MalformedMessage(f"not msgpack: {type(error).__name__}: {error}") from None
        try:
            return self._coerce(raw)
        except (ValueTypeError, TypeError, ValueError) as error:
            raise MalformedMessage(f"not a {self.description}: {error}") from None
