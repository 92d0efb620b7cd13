"""`run.toml`: the defaults of `earl run` kept next to a spec (docs/runtime.md, `run.toml`).

A value that cannot be used is refused when the file is read, before anything runs, in one line
that names the file, the line and the key, says what is expected and shows what is written:
`counter/run.toml:3: `seed` is a whole number >= 0, not "x"`. The caller says it as a usage error
(`earl run` and `earl launch`: exit 2); from Python it is a ValueError."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from difflib import get_close_matches
from pathlib import Path

from earl.diagnostics import SourceMap
from earl.model.location import SourceLocation
from earl.toml_lines import as_written, invalid_toml, key_lines

#: the file's name, next to the spec
RUN_TOML = "run.toml"

#: what each list names, for the message about an empty item: (what, an example list)
_LISTS = {
    "record_memory": ("subsystem", '["manip/a.cs"]'),
    "record_links": ("link pattern", '["task,*"]'),
    "plot": ("signal", '["manip/a.cs.count"]'),
}
#: what each string names: (what, the form it is written in)
_NAMES = {
    "environment": ("environment", '"MODULE:FACTORY", or "none" for none'),
    "report": ("function", '"MODULE:FUNCTION", or leave `report` out'),
}
KNOWN = frozenset({"duration", "seed", *_LISTS, *_NAMES})


@dataclass
class RunSettings:
    """Defaults for `earl run` read from a `run.toml` next to the spec (command-line options win)."""

    environment: str | None = None
    duration: float | None = None
    seed: int | None = None
    record_memory: list[str] | None = None
    report: str | None = None
    plot: list[str] | None = None
    record_links: list[str] | None = None
    #: the file as a diagnostic names it, its text and the line of each key: a wrong `report` or
    #: `environment` is said at its line, as a wrong function is at the spec's
    file: str = ""
    text: str = ""
    lines: dict[str, int] = field(default_factory=dict)

    def location(self, key: str) -> SourceLocation | None:
        """Where `key = …` is written in run.toml (None without a run.toml, or for a key it does not set)."""
        line = self.lines.get(key)
        if line is None:
            return None
        written = self.text.split("\n")[line - 1].rstrip("\r").rstrip()
        # the value, after the `=` (the caret under what is wrong: a misspelt `module:function`)
        equals = written.find("=")
        start = equals + 1 + (len(written) - equals - 1 - len(written[equals + 1 :].lstrip())) if equals >= 0 else 0
        if start >= len(written):
            start = 0
        return SourceLocation(self.file, line, start + 1, line, max(start + 1, len(written)))

    def sources(self) -> SourceMap:
        """run.toml's text, for a diagnostic to quote its line."""
        sources = SourceMap()
        if self.file:
            sources.add(self.file, self.text)
        return sources


def read_run_settings(spec: Path) -> RunSettings:
    """The run.toml next to `spec`, if there is one; ValueError for one that cannot be used."""
    path = spec.resolve().parent / RUN_TOML  # next to the file itself, as its modules and imports
    if not path.is_file():
        return RunSettings()
    # named as the spec is (`run.toml` beside `system.earl`), unless the spec is a link to another directory
    beside = spec.parent / RUN_TOML
    shown = str(beside) if beside.resolve() == path else str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{shown}: not UTF-8 text") from None
    except OSError as error:
        raise ValueError(f"cannot read {shown}: {error.strerror or error}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ValueError(invalid_toml(shown, error)) from None
    lines = key_lines(text)

    def where(key: str) -> str:
        return f"{shown}:{lines[key]}" if key in lines else shown

    for key in data:
        if key not in KNOWN:
            close = get_close_matches(key.lower(), sorted(KNOWN), n=1)
            guess = f"; did you mean `{close[0]}`?" if close else ""
            raise ValueError(f"{where(key)}: unknown setting `{key}`{guess} (known: {', '.join(sorted(KNOWN))})")

    def refuse(key: str, wanted: str) -> ValueError:
        return ValueError(f"{where(key)}: `{key}` is {wanted}, not {as_written(data[key])}")

    duration = data.get("duration")
    if duration is not None:
        wanted = 'a duration such as "13s" or a positive number of seconds'
        if isinstance(duration, bool) or not isinstance(duration, str | int | float):
            raise refuse("duration", wanted)
        from earl.runtime.durations import parse_duration

        try:  # a number is seconds, as a bare number on the command line is: one set of rules for both
            duration = parse_duration(str(duration))
        except ValueError as error:
            if not isinstance(duration, str):
                raise refuse("duration", wanted) from None
            raise ValueError(f"{where('duration')}: `duration`: {error}") from None
    seed = data.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise refuse("seed", "a whole number >= 0")
    for key, (what, form) in _NAMES.items():
        if key not in data:
            continue
        if not isinstance(data[key], str):
            raise refuse(key, 'a "module:function" string')
        if not data[key].strip():  # no function to call: not the setting left out
            raise ValueError(f"{where(key)}: `{key}` names no {what}: name one as {form}")
    for key, (what, example) in _LISTS.items():
        if key not in data:
            continue
        if not (isinstance(data[key], list) and all(isinstance(item, str) for item in data[key])):
            raise refuse(key, f"a list of strings, e.g. {example}")
        if any(not item.strip() for item in data[key]):  # a pattern that matched nothing, a signal of no one
            raise ValueError(
                f"{where(key)}: `{key}` has an empty string in {as_written(data[key])}: each names a {what}, "
                f"e.g. {example}"
            )
    return RunSettings(
        environment=data.get("environment"),
        duration=duration,
        seed=seed,
        record_memory=data.get("record_memory"),
        report=data.get("report"),
        plot=data.get("plot"),
        record_links=data.get("record_links"),
        file=shown,
        text=text,
        lines=lines,
    )
