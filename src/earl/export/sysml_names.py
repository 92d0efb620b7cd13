"""SysML v2 names for EARL elements: readable, legal, unique in their namespace.

EARL names an instance with its kind after a slash (`manip/a`, `motorController[3]/ve`);
SysML v2 names are identifiers or quoted "unrestricted names".  The readable name
replaces the slash and brackets (`manip_a`, `motorController3_ve`: the manual's own
"substitute K by a number", Figure 10); the EARL name itself becomes the element's
short name (`<'manip/a'>`), so a person can search the export for what they wrote.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

#: Reserved words of the SysML v2 and KerML textual notations (SysML v2 and KerML 1.0, clause 8.2):
#: a name equal to one of them must be quoted.  KerML's are included because parsers built
#: from the combined grammar reserve them in SysML text too.
RESERVED_WORDS: frozenset[str] = frozenset(
    [
        "about",
        "abstract",
        "accept",
        "action",
        "actor",
        "after",
        "alias",
        "all",
        "allocate",
        "allocation",
        "analysis",
        "and",
        "as",
        "assert",
        "assign",
        "assoc",
        "assume",
        "at",
        "attribute",
        "behavior",
        "bind",
        "binding",
        "bool",
        "by",
        "calc",
        "case",
        "chains",
        "class",
        "classifier",
        "comment",
        "composite",
        "concern",
        "conjugate",
        "conjugates",
        "conjugation",
        "connect",
        "connection",
        "connector",
        "const",
        "constant",
        "constraint",
        "crosses",
        "datatype",
        "decide",
        "def",
        "default",
        "defined",
        "dependency",
        "derived",
        "differences",
        "disjoining",
        "disjoint",
        "do",
        "doc",
        "else",
        "end",
        "entry",
        "enum",
        "event",
        "exhibit",
        "exit",
        "expose",
        "expr",
        "false",
        "feature",
        "featured",
        "featuring",
        "filter",
        "first",
        "flow",
        "for",
        "fork",
        "frame",
        "from",
        "function",
        "hastype",
        "if",
        "implies",
        "import",
        "in",
        "include",
        "individual",
        "inout",
        "interaction",
        "interface",
        "intersects",
        "inv",
        "inverse",
        "inverting",
        "istype",
        "item",
        "join",
        "language",
        "library",
        "locale",
        "loop",
        "member",
        "merge",
        "message",
        "meta",
        "metaclass",
        "metadata",
        "multiplicity",
        "namespace",
        "new",
        "nonunique",
        "not",
        "null",
        "objective",
        "occurrence",
        "of",
        "or",
        "ordered",
        "out",
        "package",
        "parallel",
        "part",
        "perform",
        "port",
        "portion",
        "predicate",
        "private",
        "protected",
        "public",
        "redefines",
        "redefinition",
        "ref",
        "references",
        "render",
        "rendering",
        "rep",
        "require",
        "requirement",
        "return",
        "satisfy",
        "send",
        "snapshot",
        "specialization",
        "specializes",
        "stakeholder",
        "standard",
        "state",
        "step",
        "struct",
        "subclassifier",
        "subject",
        "subset",
        "subsets",
        "subtype",
        "succession",
        "terminate",
        "then",
        "timeslice",
        "to",
        "transition",
        "true",
        "type",
        "typed",
        "typing",
        "unions",
        "until",
        "use",
        "var",
        "variant",
        "variation",
        "verification",
        "verify",
        "via",
        "view",
        "viewpoint",
        "when",
        "while",
        "xor",
    ]
)

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def is_basic_name(text: str) -> bool:
    """Whether `text` can be written without quotes."""
    return _IDENTIFIER.fullmatch(text) is not None and text not in RESERVED_WORDS


def quoted(text: str) -> str:
    """`text` as a SysML unrestricted name: in single quotes, with `'` and `\\` escaped."""
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def name_text(text: str) -> str:
    """`text` as it must appear in SysML source: bare when it can be, quoted otherwise."""
    return text if is_basic_name(text) else quoted(text)


def readable(earl_name: str) -> str:
    """`manip/a` → `manip_a`, `motorController[3]/ve` → `motorController3_ve`, `task,manip` → `task_manip`."""
    text = earl_name.replace("[", "").replace("]", "").replace("/", "_").replace(",", "_")
    text = re.sub(r"[^A-Za-z0-9_]", "_", text)
    if not text or text[0].isdigit():
        text = "_" + text
    return text


class Namespace:
    """The names already given in one SysML namespace; a clash gets `_2`, `_3`, … appended.

    `reserved` holds the names a namespace inherits from the EARL library (`ib`, `period`),
    so that an element of the specification never hides one of them by accident. `users` holds the
    names a person wrote that will be claimed here as they are (states, parameters, types): a suffixed
    name is never one of them, so a state `start` (the library's) becomes `start_3` beside a state
    `start_2`, which keeps its name, whichever is claimed first.
    """

    def __init__(self, reserved: tuple[str, ...] = (), users: Iterable[str] = ()) -> None:
        self._taken: set[str] = set(reserved)
        self._short: set[str] = set()
        self._users: frozenset[str] = frozenset(users)

    def taken(self, name: str) -> bool:
        """Whether `name` is given already here, as a name or a short name, or inherited from the library."""
        return name in self._taken or name in self._short

    def claim_short(self, earl_name: str) -> bool:
        """Whether `earl_name` may be a short name here, claiming it if so: not when it is a name or short
        name of the namespace already, since SysML resolves short names as names."""
        if self.taken(earl_name):
            return False
        self._short.add(earl_name)
        return True

    def claim(self, preferred: str) -> str:
        name = preferred
        counter = 2
        while name in self._taken or (name != preferred and name in self._users):
            name = f"{preferred}_{counter}"
            counter += 1
        self._taken.add(name)
        return name
