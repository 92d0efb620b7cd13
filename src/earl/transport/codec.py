"""The wire format of a link between processes (docs/distributed.md, "Wire format").

    message = fingerprint (8 bytes) + msgpack(value)

The fingerprint is a hash of the link's data type *as a structure*: struct and field
names, optional marks, primitive names and fixed array sizes, aliases followed.  Two
processes built from specs that disagree on a link's type therefore disagree on the
fingerprint, and the receiver refuses the message instead of misreading it.  Records
travel as msgpack maps and tuples as arrays; what arrives is checked with the
runtime's own coercers, so user code always gets Records and tuples, never raw lists.
"""

from __future__ import annotations

import hashlib
import struct
from collections.abc import Callable
from typing import Any

import msgpack  # type: ignore[import-untyped]

from earl.model.types import ArrayType, DataType, PrimitiveType, StructType
from earl.runtime.values import TypeSystem, ValueTypeError

FINGERPRINT_SIZE = 8


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
        size = resolved.size
        if size is None:
            count = ""
        else:
            value = getattr(size, "value", None)
            if not isinstance(value, int):
                raise ValueTypeError("an array's size must be a known whole number to send it between processes")
            count = str(value)
        return f"{describe(types, resolved.element)}[{count}]"
    return _describe_struct(types, resolved)


def _describe_struct(types: TypeSystem, struct: StructType) -> str:
    fields = ",".join(
        f"{field.name}:{describe(types, field.data_type)}{'?' if field.optional else ''}" for field in struct.fields
    )
    return f"struct {struct.name}{{{fields}}}"


def fingerprint(description: str) -> bytes:
    """8 bytes of BLAKE2b over the canonical description."""
    return hashlib.blake2b(description.encode("utf-8"), digest_size=FINGERPRINT_SIZE).digest()


_REAL = frozenset({"double", "float64", "float32"})
_FLOAT64 = b"\xcb"  # msgpack's marker of a float 64


class _RealArray:
    """Reads msgpack of a fixed `double[N]` — robot data's usual shape — checked in one C-speed slice.

    msgpack writes every Python float as 0xcb + 8 big-endian bytes, so the array is a header
    and N such 9-byte cells: when every cell starts with 0xcb, every element is a float and
    one struct unpack reads them all, with no per-element type check afterwards.  A body of
    another shape (ints in the array, another encoder) takes the general path.  (Writing is
    msgpack's own: building the cells in Python is slower than its C packer.)
    """

    __slots__ = ("_markers", "_unpack", "header", "size")

    def __init__(self, size: int) -> None:
        self.size = size
        self.header = msgpack.packb([0.0] * size)[: -9 * size] if size else b"\x90"
        self._markers = _FLOAT64 * size
        self._unpack = struct.Struct(">" + "xd" * size).unpack_from

    def decode(self, body: bytes) -> tuple[float, ...] | None:
        start = len(self.header)
        if len(body) != start + 9 * self.size or body[:start] != self.header or body[start::9] != self._markers:
            return None
        values: tuple[float, ...] = self._unpack(body, start)
        total = sum(values)
        return values if total == total else None  # a NaN: the general path says what is wrong


def _real_array(types: TypeSystem, data_type: DataType) -> _RealArray | None:
    resolved = types.resolve(data_type)
    if not isinstance(resolved, ArrayType) or resolved.size is None:
        return None
    element = types.resolve(resolved.element)
    size = getattr(resolved.size, "value", None)
    if not isinstance(element, PrimitiveType) or element.name not in _REAL or not isinstance(size, int):
        return None
    return _RealArray(size)


class LinkCodec:
    """Encodes and decodes the messages of one data type."""

    __slots__ = ("_coerce", "_pack", "_real_array", "_unpack", "description", "fingerprint")

    def __init__(self, types: TypeSystem, data_type: DataType, where: str) -> None:
        self.description = describe(types, data_type)
        self.fingerprint = fingerprint(self.description)
        self._coerce: Callable[[Any], Any] = types.coercer(data_type, where)
        self._pack: Callable[[Any], bytes] = msgpack.Packer(use_bin_type=True).pack
        self._unpack: Callable[..., Any] = msgpack.unpackb
        self._real_array = _real_array(types, data_type)

    def encode(self, value: Any) -> bytes:
        """`value` (already a checked run-time value: it left an output buffer) on the wire."""
        return self.fingerprint + self._pack(value)

    def decode(self, payload: bytes) -> Any:
        """The run-time value in `payload`; `FingerprintMismatch` or `MalformedMessage` otherwise."""
        if len(payload) <= FINGERPRINT_SIZE:
            raise MalformedMessage(f"{len(payload)} bytes, shorter than a fingerprint and a value")
        received = payload[:FINGERPRINT_SIZE]
        if received != self.fingerprint:
            raise FingerprintMismatch(received)
        body = payload[FINGERPRINT_SIZE:]
        if self._real_array is not None:
            values = self._real_array.decode(body)
            if values is not None:
                return values
        try:
            raw = self._unpack(body, use_list=False, raw=False, strict_map_key=True)
        except Exception as error:  # msgpack raises several unrelated types for bad input
            raise MalformedMessage(f"not msgpack: {type(error).__name__}: {error}") from None
        try:
            return self._coerce(raw)
        except (ValueTypeError, TypeError, ValueError) as error:
            raise MalformedMessage(f"not a {self.description}: {error}") from None
