"""Loading a specification: files and their imports, merged into one System, then resolved."""

from __future__ import annotations

import errno
import fcntl
import os
import re
import shutil
import sys
import tempfile
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import BinaryIO

from earl.collector import paused as collection_paused
from earl.diagnostics import Diagnostic, EarlError, Severity, SourceMap
from earl.lang.parser import MAX_FILE_BYTES, decode, parse_text, too_large
from earl.lang.transformer import ParsedFile
from earl.model.elements import Agent, Import, Link, Parameter, Robot, System
from earl.model.expressions import Literal
from earl.model.location import SourceLocation
from earl.model.types import REAL_TYPES, StructType, TypeAlias, refuse_wrong_parameters

ParameterValue = bool | int | float | str


def _display_path(path: Path) -> str:
    """Paths in messages are relative to the working directory when they can be."""
    try:
        return str(_resolved(path).relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _resolved(path: Path) -> Path:
    """The absolute path with symbolic links followed; as far as they go when they loop, for the
    error that reading it then reports."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python 3.11 raises RuntimeError for a loop of links, 3.13 OSError
        return path.absolute()


def _opened(path: Path) -> BinaryIO:
    """The file, opened for reading without waiting: opening a named pipe that nobody writes to would
    block for ever; opened so, it reads as empty (and a pipe with a writer reads as usual)."""
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        flags = fcntl.fcntl(descriptor, fcntl.F_GETFL)
        fcntl.fcntl(descriptor, fcntl.F_SETFL, flags & ~os.O_NONBLOCK)  # from here on, reads wait for data
    except OSError:
        os.close(descriptor)
        raise
    return os.fdopen(descriptor, "rb")


def read_file(
    path: Path, sources: SourceMap, location: SourceLocation | None = None, imported_as: str | None = None
) -> ParsedFile:
    return _read_file(path, sources, location, imported_as)[0]


def _read_file(
    path: Path, sources: SourceMap, location: SourceLocation | None = None, imported_as: str | None = None
) -> tuple[ParsedFile, bytes]:
    """The file parsed, and its bytes as read (once: a named pipe cannot be read twice).

    `location` and `imported_as` are those of the `import` that names the file, for a file imported.
    """
    shown = _display_path(path)
    try:
        with _opened(path) as file:
            # at most one byte more than a spec may have: `/dev/zero` or a pipe must not be read for ever
            data = file.read(MAX_FILE_BYTES + 1)
            if len(data) > MAX_FILE_BYTES:
                size = os.fstat(file.fileno()).st_size
                raise EarlError([too_large(shown, size if size > MAX_FILE_BYTES else None)], sources)
    except FileNotFoundError:
        raise EarlError(
            [Diagnostic(Severity.ERROR, f"no such file: {shown}", location, code="EARL-S030")], sources
        ) from None
    except IsADirectoryError:
        raise EarlError(
            [
                Diagnostic(
                    Severity.ERROR,
                    f"{shown} is a directory, not an `.earl` file",
                    location,
                    code="EARL-S030",
                    hint="name the specification file, or a directory holding `system.earl`"
                    if imported_as is None
                    else _directory_import_hint(path, imported_as),
                )
            ],
            sources,
        ) from None
    except OSError as error:
        raise EarlError(
            [Diagnostic(Severity.ERROR, f"cannot read {shown}: {error.strerror}", location, code="EARL-S030")],
            sources,
        ) from None
    try:
        text = decode(data, shown)
    except EarlError as error:
        error.sources = sources
        raise
    return parse_text(text, shown, sources), data


def _directory_import_hint(directory: Path, imported_as: str) -> str:
    """What to import instead of a directory: one of its files. A directory stands for its `system.earl`
    only as the specification a command is given; that file starts with `system`, so it is never imported
    (EARL-S032)."""
    try:
        names = sorted(entry.name for entry in directory.glob("*.earl") if entry.is_file())
    except OSError:
        names = []
    importable = [name for name in names if name != "system.earl"]
    inside = imported_as.rstrip("/")
    if importable:
        return f'an import names a file, not a directory: e.g. `import "{inside}/{importable[0]}"`'
    if names:
        return (
            f"an import names a file, not a directory; `{inside}/system.earl` starts a specification of its own "
            "and cannot be imported: move what both need into a file without a `system` line"
        )
    return "an import names an `.earl` file, not a directory"


def locate_spec(path: Path) -> Path:
    """A directory stands for the `system.earl` inside it (`earl run examples/pick_and_place`)."""
    if path.is_dir() and (path / "system.earl").is_file():
        return path / "system.earl"
    return path


def load_files(path: Path, sources: SourceMap) -> tuple[ParsedFile, list[ParsedFile]]:
    """The root file and every file it imports (depth first, each once), cycles refused."""
    root = read_file(path, sources)
    imported: list[ParsedFile] = []
    seen: dict[Path, ParsedFile] = {_resolved(path): root}

    def visit(parsed: ParsedFile, file_path: Path, chain: list[Path]) -> None:
        for declaration in parsed.declarations:
            if not isinstance(declaration, Import):
                continue
            target = _resolved(file_path.parent / declaration.path)
            if target in chain:
                cycle = " -> ".join(_display_path(p) for p in [*chain[chain.index(target) :], target])
                raise EarlError(
                    [
                        Diagnostic(
                            Severity.ERROR,
                            f"import cycle: {cycle}",
                            declaration.location,
                            code="EARL-S031",
                            hint="move what both files need into a third file that imports neither",
                        )
                    ],
                    sources,
                )
            if target in seen:
                continue
            child = read_file(target, sources, declaration.location, declaration.path)
            if child.system_name is not None:
                raise EarlError(
                    [
                        Diagnostic(
                            Severity.ERROR,
                            f"`{declaration.path}` declares `system {child.system_name}`; an imported file "
                            "holds declarations only",
                            child.system_location,
                            code="EARL-S032",
                            hint="remove the `system` line from the imported file",
                        )
                    ],
                    sources,
                )
            seen[target] = child
            visit(child, target, [*chain, target])
            imported.append(child)

    # A file's imports are looked up next to the file itself, where a symbolic link to it points,
    # for the root as for every imported file: a library linked into a project finds its own imports.
    visit(root, _resolved(path), [_resolved(path)])
    return root, imported


def merge(root: ParsedFile, imported: list[ParsedFile], sources: SourceMap, library: bool = False) -> System:
    """One System holding the declarations of all files; only the root's keep their order for printing.

    With `library`, a file without a `system` line is accepted (an imported file); its
    System has the empty name and prints without a header.
    """
    if root.system_name is None and not library:
        raise EarlError(
            [
                Diagnostic(
                    Severity.ERROR,
                    "a specification starts with `system NAME`",
                    SourceLocation(root.path, 1, 1, 1, 1),
                    code="EARL-S033",
                    hint="add a first line such as `system pickAndPlace`",
                )
            ],
            sources,
        )
    # the text read, from the start: the resolver compares a name with what was written at its location
    system = System(root.system_name or "", location=root.system_location, sources=sources)
    system.comments.leading = list(root.header_comments)
    system.comments.closing = list(root.closing_comments)
    for parsed in [*imported, root]:
        for declaration in parsed.declarations:
            if isinstance(declaration, Import):
                if parsed is root:
                    system.imports.append(declaration)
                continue
            if isinstance(declaration, Parameter):
                system.parameters.append(declaration)
            elif isinstance(declaration, (StructType, TypeAlias)):
                system.types.append(declaration)
            elif isinstance(declaration, Robot):
                system.robots.append(declaration)
            elif isinstance(declaration, Agent):
                system.agents.append(declaration)
            elif isinstance(declaration, Link):
                system.links.append(declaration)
            if parsed is root:
                system.order.append(declaration)
    return system


def _refuse_path(path: object, what: str) -> None:
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{what} takes a file name (a str or a Path), not {type(path).__name__} {path!r:.60}")


def load(path: str | Path, parameters: Mapping[str, ParameterValue] | None = None) -> System:
    """Read, parse and resolve a specification; raise `EarlError` with every problem found."""
    from earl.lang.resolver import resolve

    _refuse_path(path, "load")
    refuse_wrong_parameters(parameters)
    sources = SourceMap()
    spec = locate_spec(Path(path))
    with collection_paused():
        root, imported = load_files(spec, sources)
        system = merge(root, imported, sources)
        system.source_file = root.path
        diagnostics = resolve(system, parameters or {}, comments_from_text=True)
    errors = [d for d in diagnostics if d.severity is Severity.ERROR]
    if errors:
        raise EarlError(errors, sources)
    system.sources = sources
    _remember_imported_values(system)
    set_parameters(system, parameters or {})
    return system


def _remember_imported_values(system: System) -> None:
    """The values, as read, of the parameters imported files declare (`System.imported_values`)."""
    system.imported_values = {
        parameter.name: parameter.value
        for parameter in system.parameters
        if parameter.location is not None and parameter.location.file != system.source_file
    }


def set_parameters(system: System, parameters: Mapping[str, ParameterValue]) -> None:
    """The system's parameters take the values given (checked by `resolve` already), so that what is
    checked, run, drawn and printed from the returned model is the system with them: `load(path,
    {"N": 3})` is the spec with `param N: int = 3`."""
    for parameter in system.parameters:
        if parameter.name in parameters:
            value = parameters[parameter.name]
            if getattr(parameter.data_type, "name", "") in REAL_TYPES and type(value) is int:
                value = float(value)  # `N = 3` for a double: the value the runtime would compute
            parameter.value = Literal(value, parameter.value.location)


def parse_file(path: str | Path) -> System:
    """One file read for its syntax only: no imports followed, no names resolved (what `earl fmt` needs)."""
    return parse_file_as_read(path)[0]


def parse_file_as_read(path: str | Path) -> tuple[System, bytes]:
    """`parse_file`, and the file's bytes as read: a named pipe or process substitution (`<(cat x)`)
    can be read only once, and the bytes keep the line ends that a decoded text would not."""
    sources = SourceMap()
    root, data = _read_file(Path(path), sources)
    system = merge(root, [], sources, library=True)
    system.source_file = root.path
    system.sources = sources
    return system, data


def parse_source(text: str, path: str) -> System:
    """A text read for its syntax only, as `parse_file` reads a file."""
    sources = SourceMap()
    return merge(parse_text(text, path, sources), [], sources, library=True)


def save(system: System, path: str | Path, *, warn_of_main: bool = True) -> None:
    """Write the system as canonical `.earl` text, replacing the file atomically.

    The text goes to a temporary file beside the target, which is then renamed over it: a full
    disk or a crash leaves the old file whole.  A symbolic link is followed (the link stays a
    link), the file keeps its permissions, and only a regular file is ever replaced — renaming
    over `/dev/null` would put a file in the device's place.  An OSError says what went wrong, and its
    `filename` is the file asked for.  A directory stands for the `system.earl` in it, as for `load`.
    With `warn_of_main`, a text naming functions of `__main__` is written with a warning (`earl fmt`,
    which rewrites a file as it was, does not warn).
    """
    if not isinstance(system, System):
        raise TypeError(
            f"save writes a System, as earl.load(path) returns it, not {type(system).__name__} {system!r:.60}"
        )
    _refuse_path(path, "save")
    if os.fspath(path) in ("", b""):
        raise ValueError("save takes a file name, not an empty string")
    target = Path(path)
    if target.is_dir():
        target = target / "system.earl"  # as `load(directory)` reads it
    if target.is_symlink():
        target = _resolved(target)
    if target.exists() and not target.is_file():
        raise OSError(
            errno.EINVAL, "not a regular file (a device, a pipe or a directory); only files are rewritten", str(target)
        )
    if not target.parent.is_dir():
        raise FileNotFoundError(
            errno.ENOENT, f"cannot save there: the directory `{target.parent}` does not exist", str(target)
        )
    text = system.to_earl()
    if warn_of_main:
        _warn_of_main(text, target)
    if target.exists():
        if not os.access(target, os.W_OK) or not target.stat().st_mode & 0o222:
            # renaming over it would succeed, since that needs only the directory (and root may write
            # anything): its mode says no
            raise OSError(errno.EACCES, "the file is read-only; make it writable first (chmod u+w)", str(target))
        if target.stat().st_nlink > 1:
            # a rename would leave its other names with the old text: written in place instead
            target.write_text(text, encoding="utf-8")
            return
    # a name of our own beside it (never a user's file), short enough whatever the target's name
    try:
        descriptor, name = tempfile.mkstemp(prefix=".earl-", suffix=".tmp", dir=target.parent)
    except OSError as error:  # said of the file asked for, not of the temporary name beside it
        raise type(error)(
            error.errno, f"cannot write in the directory `{target.parent}`: {error.strerror}", str(target)
        ) from None
    temporary = Path(name)
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8") as stream:
            stream.write(text)
        if target.exists():
            shutil.copymode(target, temporary)
        else:
            os.chmod(temporary, 0o666 & ~_umask())  # mkstemp's 0600 is for secrets, not specs
        temporary.replace(target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


#: `python "__main__:NAME"` as `to_earl()` writes it
_MAIN_FUNCTION = re.compile(r'python\s+"__main__:([^"]*)"')


def _warn_of_main(text: str, target: Path) -> None:
    """A saved spec naming functions of `__main__` (as a model built and run in one script does) cannot be run
    from its file: `__main__` is then another program. Saved all the same (it may be edited), with a warning."""
    names = list(dict.fromkeys(_MAIN_FUNCTION.findall(text)))
    if names:
        shown = ", ".join(f"`{name}`" for name in names[:4]) + (", …" if len(names) > 4 else "")
        warnings.warn(
            f"{target} names functions of `__main__` ({shown}), which exist only while the script that built the "
            f"model runs: `earl run {target.name}` or earl.load(…) from another script cannot find them. Move "
            'them into a module beside the file and name it, `python "module:function"`',
            UserWarning,
            stacklevel=_caller_level(),
        )


def _caller_level() -> int:
    """The `stacklevel` of a warning that points at the first frame outside earl (`earl.save(…)`'s line)."""
    package = str(Path(__file__).resolve().parents[1])
    frame = sys._getframe(1)
    level = 1
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame = frame.f_back  # type: ignore[assignment]
        level += 1
    return level


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def loads(text: str, path: str = "<text>", parameters: Mapping[str, ParameterValue] | None = None) -> System:
    """Like `load`, for text in memory; imports are resolved against the working directory. `path` is the
    name messages give the text."""
    if isinstance(text, (bytes, bytearray)):
        raise TypeError("loads takes the text of a specification (a str): decode the bytes first, `data.decode()`")
    if not isinstance(text, str):
        raise TypeError(f"loads takes the text of a specification (a str), not {type(text).__name__} {text!r:.60}")
    if isinstance(path, Mapping):
        raise TypeError(
            "the second argument of loads is the name messages give the text; pass parameters by name: "
            "loads(text, parameters={...})"
        )
    if isinstance(path, os.PathLike):
        path = os.fspath(path)  # `loads(p.read_text(), p)`: named by its file
    if not isinstance(path, str):
        raise TypeError(f"loads names the text by a str or a Path, not {type(path).__name__} {path!r:.60}")
    refuse_wrong_parameters(parameters)
    sources = SourceMap()
    with collection_paused():
        return _loads(text, path, parameters, sources)


def _loads(text: str, path: str, parameters: Mapping[str, ParameterValue] | None, sources: SourceMap) -> System:
    from earl.lang.resolver import resolve

    root = parse_text(text, path, sources)
    if any(isinstance(d, Import) for d in root.declarations):
        base = _resolved(Path(path)).parent if path != "<text>" else Path.cwd()
        imported: list[ParsedFile] = []
        for declaration in root.declarations:
            if isinstance(declaration, Import):
                first, more = load_files(base / declaration.path, sources)
                imported.extend([*more, first])
    else:
        imported = []
    system = merge(root, imported, sources)
    system.source_file = path
    errors = [d for d in resolve(system, parameters or {}, comments_from_text=True) if d.severity is Severity.ERROR]
    if errors:
        raise EarlError(errors, sources)
    system.sources = sources
    _remember_imported_values(system)
    set_parameters(system, parameters or {})
    return system
