"""What is not of its declared type in a model built in Python, said in the model's own terms.

The reader builds well-typed models; a person building one in code may write `tc = Literal(True)`
where a `Predicate(Literal(True))` belongs, or `data_type="boolean"` for `PrimitiveType("boolean")`.
The printers and the checker would then fail deep inside (`'Literal' object has no attribute
'expression'`). `type_problems(system)` walks the model against the type hints of its dataclasses
and says where the first wrong value is:

    system.agents[0].subsystems[0].basic_behaviours[1].terminal_condition: expected Predicate, got Literal

Where a model is only read, it is called after such a failure (`explaining`), so that a well-typed
model costs nothing there (`to_earl`, `check`, `expand`); what draws or exports a model, whose cost the
walk hardly adds to, calls `refuse_wrong_types` first, as a value of a wrong type may not fail there
but be drawn or written as it is.
"""

from __future__ import annotations

import dataclasses
import functools
import re
import types
import typing
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

#: how many values are looked at, at most: a model of a million elements is not walked for ever
_LIMIT = 2_000_000


def type_problems(root: object, path: str = "system", limit: int = 1) -> list[str]:
    """Where values of `root`'s model tree are not of their declared types, at most `limit` of them."""
    found: list[str] = []
    seen: set[int] = set()
    budget = [_LIMIT]
    _walk(root, path, found, limit, seen, budget)
    return found


def _walk(value: object, path: str, found: list[str], limit: int, seen: set[int], budget: list[int]) -> None:
    if len(found) >= limit or budget[0] <= 0 or id(value) in seen:
        return
    if not dataclasses.is_dataclass(value) or isinstance(value, type):
        return
    seen.add(id(value))
    hints = _hints(type(value))
    for field in dataclasses.fields(value):
        if not field.compare or field.name not in hints:
            continue  # the order of declarations, the source texts: bookkeeping, not the model
        _check(getattr(value, field.name, None), hints[field.name], f"{path}.{field.name}", found, limit, seen, budget)
        if len(found) >= limit:
            return


def _check(
    value: object, hint: Any, path: str, found: list[str], limit: int, seen: set[int], budget: list[int]
) -> None:
    """Says at `path` why `value` is not a `hint`, or walks into the model objects it holds."""
    budget[0] -= 1
    if hint is Any or hint is object or budget[0] <= 0:
        return
    origin = typing.get_origin(hint)
    if origin is typing.Union or origin is types.UnionType:
        for option in typing.get_args(hint):
            if _fits(value, option):
                _check(value, option, path, found, limit, seen, budget)
                return
        found.append(f"{path}: expected {_name(hint)}, got {_got(value)}{_advice(value, typing.get_args(hint))}")
        return
    if origin in (list, tuple, set, frozenset):
        # `indices=[Name("K")]` for a tuple, `agents=tuple(…)` for a list: every part of earl reads either,
        # and refusing one where a model is drawn or exported first would refuse what checks, prints and runs
        accepted = (tuple, list) if origin in (tuple, list) else origin
        if not isinstance(value, accepted):
            found.append(f"{path}: expected a {origin.__name__} ({_name(hint)}), got {_got(value)}")
            return
        arguments = [a for a in typing.get_args(hint) if a is not Ellipsis]
        if arguments:
            for position, item in enumerate(value):  # type: ignore[call-overload]
                _check(item, arguments[0], f"{path}[{position}]", found, limit, seen, budget)
                if len(found) >= limit:
                    return
        return
    if origin is not None:  # dict[…], Literal[…], ClassVar[…]: only whether it is one
        if not _fits(value, hint):
            found.append(f"{path}: expected {_name(hint)}, got {_got(value)}")
        return
    if not _fits(value, hint):
        found.append(f"{path}: expected {_name(hint)}, got {_got(value)}{_advice(value, (hint,))}")
        return
    _walk(value, path, found, limit, seen, budget)


def _fits(value: object, hint: Any) -> bool:
    """Whether `value` is of `hint` at its top level (what a union picks its option by)."""
    if hint is Any or hint is object:
        return True
    if hint is None or hint is type(None):
        return value is None
    origin = typing.get_origin(hint)
    if origin is typing.Union or origin is types.UnionType:
        return any(_fits(value, option) for option in typing.get_args(hint))
    if origin is not None:
        if origin is typing.Literal:
            return value in typing.get_args(hint)
        return isinstance(value, (tuple, list) if origin in (tuple, list) else origin)
    if hint is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, hint) if isinstance(hint, type) else True


def _advice(value: object, expected: tuple[Any, ...]) -> str:
    """How to write it instead, where the mistake is a common one."""
    names = {getattr(option, "__name__", "") for option in expected}
    if callable(value) and not isinstance(value, type) and str in expected:
        # `PythonImplementation(my_function)`: the model names its code as text, which the run imports
        module, name = getattr(value, "__module__", "module"), getattr(value, "__qualname__", "function")
        return f': name the function as text, `"{module}:{name}"`'
    if "Predicate" in names and type(value).__module__ == "earl.model.expressions":
        return f": wrap the expression, `Predicate({type(value).__name__}(…))`"
    if "Kind" in names:
        from earl.model.kinds import Kind

        return f": a Kind (`Kind.INPUT_BUFFER`) or its text, one of {', '.join(kind.value for kind in Kind)}"
    if isinstance(value, str) and names & {"PrimitiveType", "TypeReference"}:
        return f': write `PrimitiveType("{value}")` or `TypeReference("{value}")`'
    if isinstance(value, str) and "Literal" in names and _EXPRESSION_TEXT.search(value):
        # `expression = "count/mi >= 3"`: EARL text, not a string; `Literal(…)` would make it a string (E030)
        return f": build the expression, e.g. `{_built(value)}`; `Literal(…)` would make it a string"
    if isinstance(value, bool | int | float | str) and "Literal" in names:
        return f": write `Literal({value!r})`"
    return ""


#: what makes a string look like EARL text of an expression rather than a string value: a kind's slash
#: (`count/mi`), a comparison, a call, `and`/`or`/`not`
_EXPRESSION_TEXT = re.compile(r"\w/\w|[<>]|[=!]=|\w\(|\b(?:and|or|not)\b")
_COMPARISON_TEXT = re.compile(r"\s*(\w+)/(\w+)\s*(>=|<=|==|!=|>|<)\s*(-?\d+(?:\.\d*)?|true|false)\s*")


def _built(text: str) -> str:
    """The Python that builds `text` when it is a plain comparison (`count/mi >= 3`), else an example."""
    from earl.model.kinds import Kind

    match = _COMPARISON_TEXT.fullmatch(text)
    kinds = {kind.value: kind.name for kind in Kind}
    if match is None or match[2] not in kinds:
        return 'Comparison(">=", Read(ElementReference("count", Kind.MEMORY_INPUT)), Literal(3))'
    name, kind, operator, right = match.groups()
    value = right.capitalize() if right in ("true", "false") else right
    return f'Comparison("{operator}", Read(ElementReference("{name}", Kind.{kinds[kind]})), Literal({value}))'


def _name(hint: Any) -> str:
    from earl.model.expressions import Expression

    if hint is type(None) or hint is None:
        return "None"
    origin = typing.get_origin(hint)
    if origin is typing.Union or origin is types.UnionType:
        options = typing.get_args(hint)
        if set(typing.get_args(Expression)) <= set(options):
            rest = [_name(option) for option in options if option not in typing.get_args(Expression)]
            return " | ".join(["an Expression (Literal, Read, Comparison, …)", *rest])
        return " | ".join(_name(option) for option in options)
    if origin is not None:
        arguments = ", ".join(_name(a) for a in typing.get_args(hint) if a is not Ellipsis)
        return f"{origin.__name__}[{arguments}]"
    return getattr(hint, "__name__", str(hint))


def _got(value: object) -> str:
    shown = repr(value)
    return f"{type(value).__name__} {shown if len(shown) <= 60 else shown[:57] + '…'}"


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    module = __import__(cls.__module__, fromlist=["_"])
    try:
        return typing.get_type_hints(cls, vars(module))
    except (NameError, TypeError):  # a hint that names what the module does not import at run time
        return {}


def not_a_number(root: object, path: str = "system") -> str | None:
    """Where the first NaN of `root`'s model tree is (`system.agents[0].subsystems[0].memories[0].initial_value
    .value`): a value of the right type that no text of the language can say."""
    stack: list[tuple[object, str]] = [(root, path)]
    seen: set[int] = set()
    budget = _LIMIT
    while stack and budget > 0:
        value, where = stack.pop()
        budget -= 1
        if isinstance(value, float) and value != value:
            return where
        if isinstance(value, list | tuple):
            stack.extend((item, f"{where}[{position}]") for position, item in reversed(list(enumerate(value))))
        elif dataclasses.is_dataclass(value) and not isinstance(value, type) and id(value) not in seen:
            seen.add(id(value))
            fields = [field for field in dataclasses.fields(value) if field.compare]
            stack.extend((getattr(value, field.name, None), f"{where}.{field.name}") for field in reversed(fields))
    return None


class ModelTypeError(TypeError):
    """A value of a model built in Python is not of its declared type; the message says where."""


class ModelNameError(ValueError):
    """A name of a model built in Python that the reader would not read back (`my system`, a memory called
    `period`): `to_earl()` refuses to write it; the message says where it is."""


class ModelCommentError(ValueError):
    """A comment of a model built in Python that `.earl` text cannot hold (`/* x */`, two lines): `to_earl()`
    refuses to write it; the message says where it is."""


def explained(system: object, error: Exception, path: str = "system") -> Exception:
    """What to raise for `error`, met while reading `system`: a ModelTypeError naming the first value of
    a wrong type, when there is one (the likely cause), else `error` itself."""
    problems = type_problems(system, path)
    if not problems:
        return error
    return ModelTypeError(f"{problems[0]} (the model is not as its classes declare: {type(error).__name__}: {error})")


def refuse_wrong_types(root: object, path: str = "system") -> None:
    """Raise ModelTypeError naming the first value of `root`'s model tree that is not of its declared type
    (`system.agents[1].subsystems[0].fsm.states[1].timeout: expected Duration | None, got float 0.05`)."""
    problems = type_problems(root, path)
    if problems:
        raise ModelTypeError(problems[0])


@contextmanager
def explaining(root: object, path: str = "system") -> Iterator[None]:
    """Inside, what a wrong value of a model built in Python makes fail (`'float' object has no attribute
    'value'`) is raised as the ModelTypeError naming that value, when there is one."""
    try:
        yield
    except ModelTypeError:
        raise
    except (AttributeError, TypeError, KeyError) as error:
        said = explained(root, error, path)
        if said is error:
            raise  # no value of a wrong type: the error as it was, not chained to itself
        raise said from error


def root_path(element: object) -> str:
    """How the path of a problem begins for `element` when it, not a System, is what was given: `system`,
    `agent`, `controlSubsystem`…"""
    name = type(element).__name__
    return "system" if name == "System" else name[:1].lower() + name[1:]
