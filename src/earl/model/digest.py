"""A short fingerprint of a model's meaning: equal models, equal digests (docs/distributed.md, "Peers").

Processes that run one system from several hosts compare it to find a peer started from
another version of the spec, or with other parameter values, when the data types of their
links still agree (those would be refused message by message).  The digest follows model
equality exactly: only the fields that take part in `==` count, so locations, comments,
the order of declarations in the text and the file a system was read from never change it.
"""

from __future__ import annotations

import dataclasses
import hashlib
from enum import Enum
from typing import Any

#: hex digits of a digest: 64 bits, as a link's data-type fingerprint
DIGEST_SIZE = 8


def model_digest(value: object) -> str:
    """16 hex digits of BLAKE2b over a canonical encoding of `value`'s compared fields."""
    digest = hashlib.blake2b(digest_size=DIGEST_SIZE)
    _encode(value, digest.update)
    return digest.hexdigest()


def _encode(root: object, write: Any) -> None:
    # A loop with its own stack rather than recursion: a model built in Python may nest expressions
    # deeper than Python's recursion limit.
    stack: list[object] = [root]
    while stack:
        value = stack.pop()
        if isinstance(value, _Marker):
            write(value.text)
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            # a number by its value, as `==` compares it: `period 10 ms` and `period 10.0 ms` are one system
            # (a Literal compares its type too, `1` and `1.0`: unequal models, but one value where they run)
            whole = isinstance(value, int) or value.is_integer()
            write(f"number:{int(value) if whole else repr(value)};".encode())
        elif value is None or isinstance(value, (bool, str, bytes)):
            # the type's name too: True, "1" and b"1" are different values of a spec
            write(f"{type(value).__name__}:{value!r};".encode())
        elif isinstance(value, Enum):
            write(f"{type(value).__name__}.{value.name};".encode())
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            fields = [f for f in dataclasses.fields(value) if f.compare]
            write(f"{type(value).__name__}({len(fields)}".encode())
            stack.append(_Marker(b")"))
            for field in reversed(fields):
                stack.append(getattr(value, field.name))
                stack.append(_Marker(f"{field.name}=".encode()))
        elif isinstance(value, (list, tuple)):
            write(f"[{len(value)}".encode())
            stack.append(_Marker(b"]"))
            stack.extend(reversed(value))
        elif isinstance(value, (set, frozenset)):
            # no order of its own (and str hashes differ between processes): its members' digests, sorted
            members = sorted(model_digest(member) for member in value)
            write(f"{{{len(members)}:{','.join(members)}}}".encode())
        elif isinstance(value, dict):
            items = sorted(model_digest(key) + model_digest(item) for key, item in value.items())
            write(f"<{len(items)}:{','.join(items)}>".encode())
        else:  # anything else a model built in Python holds: its repr, which equality then also compares
            write(f"{type(value).__name__}:{value!r};".encode())


class _Marker:
    """Text written when the walk reaches it: the end of a container, a field's name."""

    __slots__ = ("text",)

    def __init__(self, text: bytes) -> None:
        self.text = text


__all__ = ["DIGEST_SIZE", "model_digest"]
