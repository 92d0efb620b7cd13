"""What several commands share: finding the spec file and reading `--param NAME=VALUE`."""

from __future__ import annotations

import contextlib
import os
import re
import sys
from collections import Counter
from collections.abc import Iterable
from pathlib import Path

from rich.console import Console

from earl.diagnostics import escape_controls
from earl.lang.loader import ParameterValue, locate_spec

EXIT_USAGE = 2


class UsageError(Exception):
    """A mistake in how the command was called; exit code 2."""


def spec_path(text: str) -> Path:
    if not text.strip():  # `earl check ""`, `earl run "$SPEC"` with SPEC unset: Path("") is the directory here
        raise UsageError("SPEC is empty: name the .earl file, or a directory with a system.earl")
    path = locate_spec(Path(text))
    if not path.exists():
        raise UsageError(f"no such file: {text}")
    if path.is_dir():
        raise UsageError(f"{text} is a directory without a system.earl; name the .earl file")
    return path


def named(text: str, option: str, example: str, what: str) -> str:
    """What an option names, refused as a usage error when it names nothing: an empty value
    (`--record-links ""`, `--record-links "$LINKS"` with LINKS unset) or one of spaces is a mistake,
    not a name, and is said in the same words for every option."""
    if not text.strip():
        raise UsageError(f"{option} names no {what}: name one, e.g. {option} {example}")
    return text


def named_path(text: str, option: str, example: str, what: str = "file") -> Path:
    """The path an option names (an output, a file to read). An empty one (`-o ""`,
    `-o "$OUT"` with OUT unset) names nothing, as one of spaces does: Path("") is the current
    directory, which one command took for standard output and another for the place to write, so
    every command refuses it alike, as a usage error, before anything is read."""
    return Path(named(text, option, example, what))


def parse_parameter(text: str) -> tuple[str, ParameterValue]:
    """`N=3` → ("N", 3); numbers and true/false are typed, anything else is a string."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip().isidentifier():
        raise UsageError(f"--param expects NAME=VALUE, e.g. --param N=3, not `{text}`")
    raw = raw.strip()
    value: ParameterValue
    if raw in ("true", "false"):
        value = raw == "true"
    elif _WHOLE.fullmatch(raw):
        value = int(raw)
    elif _REAL.fullmatch(raw):
        value = float(raw)
    else:
        # text, as the spec would read it: Python's int() and float() would also take `1_000` and
        # other scripts' digits (`٣`), which no spec can write
        value = raw
    return name.strip(), value


def parse_parameters(texts: list[str]) -> dict[str, ParameterValue]:
    """Every `--param NAME=VALUE`; a name given twice is a usage error (which value was meant?)."""
    values: dict[str, ParameterValue] = {}
    for text in texts:
        name, value = parse_parameter(text)
        if name in values:
            raise UsageError(f"--param sets `{name}` twice; give it once")
        values[name] = value
    return values


_WHOLE = re.compile(r"[+-]?[0-9]+")
_REAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[+-]?(?:inf|nan)", re.IGNORECASE)


def usage_error(message: str) -> int:
    sys.stderr.write(f"earl: error: {message}\n")
    return EXIT_USAGE


#: characters of a message from the spec's code shown on the terminal (the trace keeps it whole)
SHOWN_MESSAGE = 400


def brief(text: str, limit: int = SHOWN_MESSAGE) -> str:
    """A message the spec's code wrote (an exception's text), cut for the terminal: a megabyte-long
    message would fill the screen, and the table renderer takes time quadratic in a line's length.
    Text that is not UTF-8 (a lone surrogate from undecodable bytes) is shown escaped, `\\udcff`."""
    shown = (
        text
        if len(text) <= limit
        else f"{text[:limit]}… ({len(text) - limit:,} more characters; the trace has them all)"
    )
    shown = escape_controls(shown)  # an exception's text must not drive the terminal or forge a line
    return shown if shown.isascii() else shown.encode("utf-8", "backslashreplace").decode("utf-8")


def refuse_to_overwrite_inputs(output: Path, sources: object) -> None:
    """UsageError when `output` is a file the command read (the spec or a file it imports), even through
    a symbolic link: `-o system.earl`, a slip of the keyboard, must not replace the spec."""
    texts = getattr(sources, "texts", {})
    try:
        target = output.resolve()
        read = {Path(name).resolve() for name in texts}
    except (OSError, RuntimeError):  # a loop of links: the write then says what is wrong
        return
    if target in read:
        raise UsageError(f"cannot write {output}: it is a file of the specification itself; choose another name")


#: set by `earl launch` for each child: the supervisor's pid, which the child watches (`watch_supervisor`)
SUPERVISOR_VARIABLE = "EARL_LAUNCH_SUPERVISOR"


def watch_supervisor() -> None:
    """In a process `earl launch` started: should the supervisor die without stopping it (SIGKILL, which
    it cannot catch), the process is re-parented; it then stops itself as on SIGTERM (in order, its trace
    finished) instead of running on unsupervised, holding its ports."""
    import os
    import signal
    import threading
    import time

    supervisor = os.environ.get(SUPERVISOR_VARIABLE, "")
    if not supervisor.isdigit() or os.getppid() != int(supervisor):
        return  # not started by a supervisor that is still there (a test, a user's own script)

    def watch() -> None:
        while os.getppid() == int(supervisor):
            time.sleep(0.5)
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=watch, name="earl-supervisor-watch", daemon=True).start()


#: set by `earl launch` for each child: a file descriptor, the write end of a pipe, on which `earl run`
#: says `started` once its run is set up (docs/distributed.md, "earl launch")
STATUS_VARIABLE = "EARL_LAUNCH_STATUS_FD"
#: what is written on that pipe
STARTED = b"started\n"


def take_launch_status() -> int | None:
    """The pipe `earl launch` gave this process to say that its run started, or None (not started by
    `earl launch`). The variable is taken out of the environment and the descriptor kept from child
    processes, so that a program the spec's code starts never writes on it (nor on another file that
    happens to have that number there)."""
    import stat

    text = os.environ.pop(STATUS_VARIABLE, "")
    if not (text.isascii() and text.isdigit()):
        return None
    descriptor = int(text)
    try:
        if not stat.S_ISFIFO(os.fstat(descriptor).st_mode):
            return None
        os.set_inheritable(descriptor, False)
    except OSError:
        return None
    return descriptor


def say_started(descriptor: int | None) -> None:
    """Tell `earl launch` that this process's run started (its code bound, its links open): from now
    on, its failure is a lost peer for the others, not a deployment that cannot start."""
    if descriptor is None:
        return
    try:
        os.write(descriptor, STARTED)
    except OSError:  # the supervisor is gone: `watch_supervisor` stops this process
        pass
    finally:
        with contextlib.suppress(OSError):
            os.close(descriptor)


def fault_kinds(kinds: Iterable[str]) -> str:
    """`88 exception, 4 no-transition`: how many faults of each kind, most first.  A subsystem's
    faults can outnumber its iterations (two functions that raise in one iteration are two faults,
    and the behaviour they stop may then find no transition), which the counts by kind make plain."""
    counts = Counter(kinds)
    return ", ".join(f"{count} {kind}" for kind, count in sorted(counts.items(), key=lambda item: (-item[1], item[0])))


#: the width of a table written to a file or a pipe: a log has no screen to fit, and Rich's default of
#: 80 columns cut the run's table into cells like `opera` / `te`
UNBOUNDED_TABLE_WIDTH = 200


def table_console() -> Console:
    """A console for the closing tables: the terminal's width on a terminal, a wide one in a file."""
    console = Console(highlight=False, markup=False)  # names and messages are the spec's text, not markup
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console.width = UNBOUNDED_TABLE_WIDTH
    return console
