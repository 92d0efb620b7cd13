"""Binding user code: `= python "pick_and_place.manip:joint_move"` to a Python function.

Everything is bound before anything runs, so that a missing module, a misspelt
function or a wrong signature is reported at once — located at the spec element
that names it — and never as a traceback in the middle of a run.  This module and
the runtime are the only parts of earl that import user code (`earl check`,
`earl doc` and the exports never do).
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import inspect
import sys
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from earl import _program
from earl.diagnostics import Diagnostic, Severity
from earl.model.elements import PartialTransitionFunction
from earl.model.location import SourceLocation

#: A partial transition function as the runtime calls it: `function(inputs, outputs, context)`.
UserFunction = Callable[[Any, Any, Any], object]

SIGNATURE = "def NAME(inputs, outputs, context) -> None"
#: how a primitive predicate computed by Python is written
PREDICATE_SIGNATURE = "def NAME(inputs, context) -> bool"
#: how the runtime uses a partial transition function, and a predicate, as hints say it
FUNCTION_USE = "the runtime calls it and uses what it wrote through `outputs` at once"
PREDICATE_USE = "the runtime calls it and uses the Boolean it returns at once"


class BindingProblem(Exception):
    def __init__(self, diagnostic: Diagnostic, module: str | None = None) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic
        #: the module that cannot be imported, when that is the problem: said once for all that name it
        self.module = module


@contextlib.contextmanager
def user_code_path(directories: list[Path]) -> Iterator[None]:
    """Put the spec's directory first on `sys.path` while user modules are imported.

    Two specs may both ship a package of the same name (every example has its own); a
    package already imported from elsewhere is forgotten when the spec's directory has
    its own, so each run binds the code beside its spec.
    """
    resolved = [d.resolve() for d in directories]
    _SHADOWING.clear()
    _UNIMPORTABLE.clear()  # a module fixed since an earlier run (in a notebook) is imported again
    for directory in resolved:
        _forget_shadowed(directory)
    added = [str(d) for d in resolved if str(d) not in sys.path]
    sys.path[:0] = added
    try:
        yield
    finally:
        for entry in added:
            with contextlib.suppress(ValueError):
                sys.path.remove(entry)


def _forget_shadowed(directory: Path) -> None:
    # what the directory can be imported as, listed once: a run starts with hundreds of modules loaded
    try:
        entries = list(directory.iterdir())
    except OSError:
        return
    importable = {e.name for e in entries if e.is_dir()} | {e.stem for e in entries if e.suffix == ".py"}
    for name, module in list(sys.modules.items()):
        top = name.partition(".")[0]
        if top not in importable:
            continue
        locations = _locations(module)
        if any(Path(location).resolve().is_relative_to(directory) for location in locations):
            continue
        if top in sys.stdlib_module_names or top in sys.builtin_module_names or _installed(locations):
            # earl itself, a library it uses (msgpack, numpy) or Python's own: forgetting it would break the
            # runtime; the spec's module of that name cannot be imported, which binding it then says
            _SHADOWING[top] = directory
            continue
        del sys.modules[name]


#: names of modules next to a spec that an installed module of the same name hides, and where they are
_SHADOWING: dict[str, Path] = {}


def _locations(module: object) -> list[str]:
    """Where a module was read from: its file, or the directories of a package without `__init__.py` (a
    namespace package, whose `__file__` is None: a spec's own package often is one)."""
    location = getattr(module, "__file__", None)
    if isinstance(location, str):
        return [location]
    try:
        return [entry for entry in getattr(module, "__path__", []) if isinstance(entry, str)]
    except Exception:  # a module object of some library's making, with a `__path__` of its own kind
        return []


def _installed(locations: list[str]) -> bool:
    """Whether a module's files belong to Python's installation or environment, or to earl itself."""
    if not locations:
        return True  # a built-in module: nothing of a spec's
    roots = [
        Path(root).resolve()
        for root in {sys.prefix, sys.base_prefix, sys.exec_prefix, str(Path(__file__).resolve().parents[1])}
    ]
    return any(Path(location).resolve().is_relative_to(root) for location in locations for root in roots)


def resolve_callable(
    path: str,
    what: str,
    location: SourceLocation | None,
    arity: int = 3,
    signature: str = SIGNATURE,
    placeholder: str = "FUNCTION",
    use: str = FUNCTION_USE,
    classes: bool = False,
) -> Callable[..., Any]:
    """Import `module:function` and check that it can be called with `arity` arguments.

    `signature` shows how such a function is written, in hints (`def NAME(inputs, outputs, context)`);
    `placeholder` stands for its name in a hint that cannot know it (`pendulum.env:FACTORY`), and `use`
    says what is done with it, for a hint about something that cannot be used so. With `classes`, a
    class is taken too: what calling it makes is what is wanted (an environment object), not writes.
    """
    module_name, function_name = _split(path)
    if not module_name or not function_name:
        raise BindingProblem(
            Diagnostic(
                Severity.ERROR,
                f"`{path}` does not name a function: write `module:function`",
                location,
                code="EARL-X001",
                hint=_colon_hint(path.strip(), placeholder),
            )
        )
    module = _import(module_name, what, location)
    # under the `earl` command, `__main__` is earl's own (whose `script` a spec never means)
    function = _ABSENT if module_name == "__main__" and _program.PROGRAM else getattr(module, function_name, _ABSENT)
    if function is _ABSENT:
        raise BindingProblem(_no_such_function(module, module_name, function_name, what, location, signature))
    kind = None if classes and inspect.isclass(function) else _not_a_plain_function(function)
    if kind is not None:
        written = f"write it as `{signature.replace('NAME', function_name)}`"
        if classes:
            written += " (or as a class whose `__init__` takes them)"
        raise BindingProblem(
            Diagnostic(
                Severity.ERROR,
                f"{what} names `{module_name}:{function_name}`, which is {kind}, not a function",
                location,
                code="EARL-X004" if not callable(function) else "EARL-X005",
                hint=f"{written}: {use}",
            )
        )
    _check_arity(function, arity, f"{module_name}:{function_name}", what, location, signature)
    return function  # type: ignore[return-value]


_ABSENT = object()


def _no_such_function(
    module: Any, module_name: str, function_name: str, what: str, location: SourceLocation | None, signature: str
) -> Diagnostic:
    """EARL-X004 for a module without the function: a near name, else where to define it."""
    from earl.diagnostics import did_you_mean

    available = sorted(n for n, v in vars(module).items() if callable(v) and not n.startswith("_"))
    message = f"{what} names `{function_name}`, but the module `{module_name}` has no such function"
    defined = f"`{signature.replace('NAME', function_name)}`"
    if module_name == "__main__":
        if _program.PROGRAM:
            # a model saved from the script that built it (`earl.save`): that script's functions went with it
            return Diagnostic(
                Severity.ERROR,
                f"{what} names `__main__:{function_name}`, but `__main__` is the program that is running, here "
                "the `earl` command: a function defined in the script that built the model exists only while "
                "that script runs",
                location,
                code="EARL-X004",
                hint=f"move `{function_name}` into a module beside the spec (e.g. `functions.py`) and name it "
                f'`python "functions:{function_name}"`',
            )
        if not isinstance(getattr(module, "__file__", None), str):
            # `python -c`, the REPL, a notebook's kernel: `__main__` is the session itself, which has no file
            return Diagnostic(
                Severity.ERROR,
                message,
                location,
                code="EARL-X004",
                hint=did_you_mean(function_name, available)
                or f"`__main__` is this interactive session (a notebook, the REPL, `python -c`): define {defined} "
                "in it (run the cell that defines it) before the run, or name a function of a module",
            )
    hint = did_you_mean(function_name, available) or _define_in(module, defined)
    if module_name == "__main__":
        hint += (
            " (`__main__` is the script being run: the functions of another script, one that built and saved the "
            "model, are not there; move them into a module and name that)"
        )
    return Diagnostic(Severity.ERROR, message, location, code="EARL-X004", hint=hint)


def _define_in(module: Any, defined: str) -> str:
    """Where to define a missing function: the module's file, or for a package without `__init__.py` (a
    namespace package, which has no file to hold one) a module in it."""
    file = getattr(module, "__file__", None)
    if isinstance(file, str):
        return f"define {defined} in `{file}`"
    name = getattr(module, "__name__", "module")
    places = _locations(module)
    where = f" ({places[0]})" if places else ""
    return (
        f"`{name}` is a directory without `__init__.py`{where}, which can define no function: define {defined} "
        f'in a module in it and name that, `python "{name}.MODULE:FUNCTION"`, or create `__init__.py` there'
    )


#: what each module that could not be imported in this binding says, by module name: a module is imported
#: once however many functions name it (importing it again would run its failing code again), and each
#: function naming it is told the same at its own line
_UNIMPORTABLE: dict[str, Callable[[str, SourceLocation | None], Diagnostic]] = {}


def _import(module_name: str, what: str, location: SourceLocation | None) -> Any:
    """The module, or a BindingProblem that says why it cannot be imported (its `module` names it)."""
    say = _UNIMPORTABLE.get(module_name)
    if say is None:
        found = _importing(module_name)
        if isinstance(found, _Imported):
            return found.module
        say = _UNIMPORTABLE[module_name] = found
    raise BindingProblem(say(what, location), module=module_name)


class _Imported:
    """A module imported (a module object is no value to tell apart from what `_importing` says otherwise)."""

    def __init__(self, module: Any) -> None:
        self.module = module


def _importing(module_name: str) -> _Imported | Callable[[str, SourceLocation | None], Diagnostic]:
    """The module imported, or what to say, for a function at a spec line, about why it cannot be."""
    top = module_name.partition(".")[0]
    if top in _SHADOWING:
        directory = _SHADOWING[top]
        return lambda what, location: Diagnostic(
            Severity.ERROR,
            f"{what} names the module `{module_name}`, but `{top}` is also the name of a module that earl or "
            "Python itself uses, which is imported instead",
            location,
            code="EARL-X002",
            hint=f'rename `{top}` in {directory} (and the spec\'s `python "{top}…"` with it)',
        )
    try:
        return _Imported(importlib.import_module(module_name))
    except ModuleNotFoundError as error:
        missing = error.name or module_name
        if missing == module_name or module_name.startswith(missing + "."):
            return lambda what, location: Diagnostic(
                Severity.ERROR,
                f"{what} names the module `{module_name}`, which cannot be found (no module `{missing}`)",
                location,
                code="EARL-X002",
                hint="modules are looked up next to the spec file first, then on the Python path; "
                f"create `{module_name.replace('.', '/')}.py` there",
            )
        failure: BaseException = error  # the module is there, but something it imports is not
    except KeyboardInterrupt:
        raise
    except BaseException as error:  # the user's module failed while importing, sys.exit() included
        if _program.stop_received():  # a Ctrl-C that a compiled module's initialisation put in other words
            raise KeyboardInterrupt from error
        failure = error
    said = f"{_import_failure(failure)}{_where(failure)}"
    return lambda what, location: Diagnostic(
        Severity.ERROR,
        f"importing `{module_name}` for {what} failed: {said}",
        location,
        code="EARL-X003",
    )


def _import_failure(error: BaseException) -> str:
    from earl.runtime.engine import exception_text

    if isinstance(error, SystemExit):
        return f"it called sys.exit({'' if error.code is None else repr(error.code)}) while being imported"
    return exception_text(error)


def _where(error: BaseException) -> str:
    """` (usr.py:3)`: where in the user's files the import failed; never a frame of Python's import machinery."""
    if isinstance(error, SyntaxError) and error.filename and error.lineno:
        return f" ({error.filename}:{error.lineno})"
    try:
        frames = [f for f in traceback.extract_tb(error.__traceback__) if not f.filename.startswith("<frozen ")]
    except Exception:  # an exception class that breaks its own traceback
        return ""
    return f" ({frames[-1].filename}:{frames[-1].lineno})" if frames else ""


def _not_a_plain_function(function: object) -> str | None:
    """What `function` is when the runtime cannot use what calling it does ("a generator function"), or None.

    A coroutine or generator function returns an object and runs none of its body; a class makes an
    instance: the writes would vanish and a predicate would always hold."""
    if not callable(function):
        return f"a {type(function).__name__}"
    if inspect.isclass(function):
        return "a class"
    if inspect.iscoroutinefunction(function):
        return "a coroutine function (`async def`)"
    if inspect.isasyncgenfunction(function):
        return "an asynchronous generator function"
    if inspect.isgeneratorfunction(function):
        return "a generator function (it uses `yield`)"
    return None


def _split(path: str) -> tuple[str, str]:
    """`module:function`: the colon is the only separator (a dot could end a module's name as well as
    stand before a function's: `pendulum.env` is a module whose factory was left out)."""
    module, _, function = path.partition(":")
    return module.strip(), function.strip()


def _colon_hint(path: str, placeholder: str) -> str:
    """What `path`, which has no `module:function` colon, was likely meant to be."""
    module_name, dot, last = path.rpartition(".")
    if ":" in path or not dot or not last.isidentifier():
        return f'write the module, a colon and the function, e.g. `"pick_and_place.manip:{placeholder.lower()}"`'
    whole = _importable(path)
    if whole is not None:  # `pendulum.env`: the module alone, its function left out
        functions = _functions_defined_in(whole)
        name = functions[0] if len(functions) == 1 else placeholder
        listed = f" (it defines {', '.join(f'`{f}`' for f in functions[:6])})" if len(functions) > 1 else ""
        return f'`{path}` is a module: name its function after a colon, `"{path}:{name}"`{listed}'
    return f'did you mean `"{module_name}:{last}"`? A colon separates the module from the function'


def _importable(module_name: str) -> Any:
    """The module `module_name` if it exists and imports, else None (a hint never fails the binding)."""
    try:
        if importlib.util.find_spec(module_name) is None:
            return None
    except (ImportError, ValueError):
        return None
    except KeyboardInterrupt:
        raise
    except BaseException:  # a package whose `__init__` fails: the binding says so when it imports it
        return None
    found = _importing(module_name)
    return found.module if isinstance(found, _Imported) else None


def _functions_defined_in(module: Any) -> list[str]:
    """The public functions and classes a module defines itself (not those it imports)."""
    name = getattr(module, "__name__", "")
    return sorted(
        key
        for key, value in vars(module).items()
        if callable(value) and not key.startswith("_") and getattr(value, "__module__", None) == name
    )


def _check_arity(
    function: Any, arity: int, name: str, what: str, location: SourceLocation | None, signature: str
) -> None:
    try:
        actual = inspect.signature(function)
    except Exception:  # a builtin or C function (or a `__signature__` that fails): trust it
        return
    try:
        actual.bind(*range(arity))
    except TypeError:
        short = name.rpartition(":")[2]
        if inspect.isclass(function):  # a class is called through its `__init__`, which takes `self` first
            parameters = signature[signature.index("(") + 1 : signature.index(")")]
            hint = f"give `{short}` an `__init__(self, {parameters})` (see docs/runtime.md)"
        else:
            hint = f"write it as `{signature.replace('NAME', short)}` (see docs/runtime.md)"
        raise BindingProblem(
            Diagnostic(
                Severity.ERROR,
                f"{what} calls `{name}` with {arity} argument{'s' if arity != 1 else ''}, but it is defined as "
                f"`{short}{actual}`",
                location,
                code="EARL-X005",
                hint=hint,
            )
        ) from None


def bind_function(function: PartialTransitionFunction, owner: str) -> UserFunction:
    """The Python function implementing a partial transition function of subsystem `owner`."""
    what = f"`{function.name}/pf` of {owner}"
    if function.implementation is None:
        raise BindingProblem(
            Diagnostic(
                Severity.ERROR,
                f"{what} has no implementation, so it cannot run",
                function.location,
                code="EARL-X000",
                hint='bind it to Python code: `... ) = python "module:function"`',
            )
        )
    return resolve_callable(function.implementation.path, what, function.location)
