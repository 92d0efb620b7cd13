"""Functions generated as Python text: compiled once per text, run with their own names.

The runtime writes its hottest paths out as straight-line code (iteration.py,
compiled_iteration.py, the value checkers of values.py, the refreshes of views.py).
Names from a spec enter such text only as string literals written by `repr`; every
object the code uses comes in through its namespace. The members of a family
(`motorController[1..6]`) generate the same text, so each text is compiled once.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from types import CodeType
from typing import Any


@functools.lru_cache(maxsize=1024)
def compiled(source: str) -> CodeType:
    """`source` compiled for `exec` (the file name `<string>` marks runtime frames in tracebacks)."""
    return compile(source, "<string>", "exec")


def generated_function(name: str, lines: list[str], namespace: dict[str, Any]) -> Callable[..., Any]:
    """The function `name` that `lines` define, with every name of `namespace` a closure variable.

    It is made inside a factory whose parameters are everything it uses, so that each is a
    closure variable (as fast to read as a local) rather than a global (a dictionary).
    """
    names = sorted(namespace)
    source = "\n".join([f"def make({', '.join(names)}):", *(f"    {line}" for line in lines), f"    return {name}"])
    scope: dict[str, Any] = {}
    exec(compiled(source), scope)
    function = scope["make"](**namespace)
    function.source = source  # for whoever debugs the engine: print(behaviour.execute.source)
    return function  # type: ignore[no-any-return]
