"""The topics of a trace, and what a topic of a trace (of this earl or an earlier one) is about.

Every topic starts with `/`, as ROS's and Foxglove's do (`/earl/run`, `/manip/a.cs/fsm`,
`/link/manip/a:cs,motorController[1]`). Earlier traces named only `/earl/run` and `/earl/faults`
so, the others without the leading slash (`manip/a.cs/fsm`, `link/task,manip`): `classify` reads
both, so that `earl trace summary` and `earl plot` read the traces users already have.
"""

from __future__ import annotations

#: the trace format this earl writes, in the `/earl/run` start message (`format`), and the newest it
#: reads. A trace without it is format 1: earl before formats were numbered (fields that were absent or
#: infinite written `null`, anyOf schemas). Format 2: an absent optional field is left out of its
#: message, an infinite real is `1e999`, a memory channel's metadata names its families.
FORMAT = 2

RUN = "/earl/run"
FAULTS = "/earl/faults"

#: the kinds of topic a subsystem has, each its subsystem's name and this suffix
SUBSYSTEM_KINDS = ("fsm", "behaviour", "memory")


def fsm(subsystem: str) -> str:
    return f"/{subsystem}/fsm"


def behaviour(subsystem: str) -> str:
    return f"/{subsystem}/behaviour"


def memory(subsystem: str) -> str:
    return f"/{subsystem}/memory"


def link(name: str) -> str:
    return f"/link/{name}"


def classify(topic: str, metadata: dict[str, str]) -> tuple[str, str]:
    """(kind, name) of a topic: ("run", ""), ("faults", ""), ("link", LINK), ("fsm" | "behaviour" |
    "memory", SUBSYSTEM), or ("other", topic) for a topic earl does not write.

    The channel's metadata names the subsystem or link where the writer said it (every earl has);
    the topic's name is the fallback."""
    if topic in (RUN, FAULTS):
        return ("run" if topic == RUN else "faults", "")
    bare = topic.removeprefix("/")
    if bare.startswith("link/"):
        return "link", metadata.get("link") or bare[len("link/") :]
    for kind in SUBSYSTEM_KINDS:
        if bare.endswith(f"/{kind}"):
            return kind, metadata.get("subsystem") or bare[: -len(kind) - 1]
    return "other", topic
