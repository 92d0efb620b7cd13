"""A quicker `__init__` for the model's frozen, slotted dataclasses.

A frozen dataclass's generated `__init__` assigns each field through
`object.__setattr__`, looked up anew for every field; that makes it four times slower
than a plain class's.  A reader builds one such object for every name, expression and
location of a spec — hundreds of thousands for a large one — so `quick_init` gives the
class an `__init__` that stores each field through its slot directly.  Everything else
(immutability, equality, hashing, `repr`, `dataclasses.replace`, pickling) stays as
`dataclass` made it.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

T = TypeVar("T")

_MISSING = dataclasses.MISSING


def quick_init(cls: type[T]) -> type[T]:
    """Replace the `__init__` of a `@dataclass(frozen=True, slots=True)` class (same signature)."""
    params = getattr(cls, "__dataclass_params__", None)
    if params is None or not params.frozen or "__slots__" not in cls.__dict__:
        raise TypeError(f"{cls.__name__} is not a frozen dataclass with slots")
    namespace: dict[str, Any] = {"_MISSING": _MISSING}
    parameters: list[str] = []
    body: list[str] = []
    for field in dataclasses.fields(cls):  # type: ignore[arg-type]
        if field.kw_only:
            raise TypeError(f"{cls.__name__}.{field.name}: keyword-only fields are not supported")
        name = field.name
        namespace[f"_set_{name}"] = cls.__dict__[name].__set__
        has_default = field.default is not _MISSING
        has_factory = field.default_factory is not _MISSING
        namespace[f"_default_{name}"] = field.default
        namespace[f"_factory_{name}"] = field.default_factory
        if field.init:
            if has_factory:
                parameters.append(f"{name}=_MISSING")
                body.append(f"    _set_{name}(self, _factory_{name}() if {name} is _MISSING else {name})")
            else:
                parameters.append(f"{name}=_default_{name}" if has_default else name)
                body.append(f"    _set_{name}(self, {name})")
        elif has_default:
            body.append(f"    _set_{name}(self, _default_{name})")
        elif has_factory:
            body.append(f"    _set_{name}(self, _factory_{name}())")
        # a field without init and without a default stays unset, as `dataclasses` leaves it
    if hasattr(cls, "__post_init__"):
        body.append("    self.__post_init__()")
    source = f"def __init__(self, {', '.join(parameters)}):\n" + ("\n".join(body) or "    pass") + "\n"
    exec(source, namespace)  # the same technique `dataclasses` itself uses to build `__init__`
    init = namespace["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    init.__doc__ = cls.__init__.__doc__  # type: ignore[misc]
    cls.__init__ = init  # type: ignore[misc,method-assign]
    return cls


__all__ = ["quick_init"]
