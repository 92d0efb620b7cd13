"""Zenoh key expressions of a running system (docs/distributed.md, "Keys").

    earl/<system>/<link>            the messages of one link
    earl/<system>/alive/<agent>/<process>/<spec>
                                    one liveliness token per running agent and process
    earl/<system>/types/<hex>       the description of a data type, by its fingerprint

A link's name (`task,manip`, `manip/a:cs,motorController[3]`) keeps the characters a key
may hold and writes the others (`/`, `*`, `$`, `?`, `#`, `@`, `%`, spaces, …) as %XX, so
one link is always exactly one chunk and can never match another link's key.
"""

from __future__ import annotations

import string

_KEPT = frozenset(string.ascii_letters + string.digits + "_-.,:[]")


def escape(text: str) -> str:
    """`text` as one key chunk: kept characters as they are, every other UTF-8 byte as %XX."""
    out: list[str] = []
    for character in text:
        if character in _KEPT:
            out.append(character)
        else:
            out.extend(f"%{byte:02X}" for byte in character.encode("utf-8"))
    return "".join(out) or "%00"


def link_key(system: str, link: str) -> str:
    return f"earl/{escape(system)}/{escape(link)}"


#: the last chunk of a liveliness token whose process did not say which specification it runs
UNKNOWN_SPECIFICATION = "-"


def alive_key(system: str, agent: str, process: str, specification: str = UNKNOWN_SPECIFICATION) -> str:
    """The liveliness token of `agent` as run by one process (`process`: an id of its own), so that the
    same agent started twice is seen as two tokens, not one; `specification` is the digest of the system
    the process runs (earl.model.digest), so that its peers can tell when they run another one."""
    return f"earl/{escape(system)}/alive/{escape(agent)}/{escape(process)}/{escape(specification)}"


def alive_prefix(system: str) -> str:
    return f"earl/{escape(system)}/alive/"


def finished_key(system: str, agent: str) -> str:
    """Where a process says, as it closes in order, that its agent has finished (not crashed)."""
    return f"earl/{escape(system)}/finished/{escape(agent)}"


def finished_prefix(system: str) -> str:
    return f"earl/{escape(system)}/finished/"


def type_key(system: str, fingerprint: bytes) -> str:
    return f"earl/{escape(system)}/types/{fingerprint.hex()}"


def unescape(chunk: str) -> str:
    """The inverse of `escape`, for names read back from keys (liveliness tokens)."""
    data = bytearray()
    position = 0
    while position < len(chunk):
        character = chunk[position]
        if character == "%" and _is_hex(chunk[position + 1 : position + 3]):
            data.append(int(chunk[position + 1 : position + 3], 16))
            position += 3
        else:
            data.extend(character.encode("utf-8"))
            position += 1
    return data.decode("utf-8", errors="replace")


def _is_hex(text: str) -> bool:
    return len(text) == 2 and all(c in string.hexdigits for c in text)
