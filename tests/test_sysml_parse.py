"""The SysML v2 export read by an independent SysML v2 parser: zero syntax errors, or the test fails.

The parser is sysmlpy (PyPI, in the `dev` extra): its ANTLR grammar is generated from the OMG
SysML v2 specification, it reads every file of the OMG standard library and is strict (see
docs/sysml.md for why this one).  It shares nothing with earl.

sysmlpy's Python ANTLR runtime builds its prediction tables (DFA) on first use, which takes
minutes on a fresh machine; it keeps them in its cache directory (~/.cache/sysmlpy), after which
a parse of the flagship example takes about a second.  The helpers below save that cache after a
slow parse, so the price is paid once per machine, not once per run.

`parse_tree` and `syntax_errors` are also used by tests/test_sysml_export.py.
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import os
import re
import sys
import threading
import time
import warnings
from functools import cache
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.export.sysml import export_sysml, library_text

ROOT = Path(__file__).resolve().parent.parent
FLAGSHIP = ROOT / "examples" / "pick_and_place" / "system.earl"
GOLDEN = ROOT / "tests" / "golden" / "sysml"
LANGUAGE = ROOT / "docs" / "language.md"

# Deep expressions make the ANTLR runtime recurse deeply, and pickling its cache deeper still.
_STACK_BYTES = 512 * 1024 * 1024
_RECURSION_LIMIT = 200_000
# A parse slower than this built new prediction tables worth keeping for the next run.
_COLD_SECONDS = 5.0
_SAVE_AT_EXIT: list[bool] = []


def _in_big_stack(function: Any) -> Any:
    """Run `function` in a thread with a large stack and recursion limit, and return what it returns."""
    result: dict[str, Any] = {}

    def target() -> None:
        try:
            result["value"] = function()
        except BaseException as error:  # handed back to the caller's thread
            result["error"] = error

    previous_limit = sys.getrecursionlimit()
    previous_stack = threading.stack_size(_STACK_BYTES)
    sys.setrecursionlimit(max(previous_limit, _RECURSION_LIMIT))
    try:
        thread = threading.Thread(target=target, name="sysml-parser")
        thread.start()
        thread.join()
    finally:
        threading.stack_size(previous_stack)
        sys.setrecursionlimit(previous_limit)
    if "error" in result:
        raise result["error"]
    return result["value"]


def _sysmlpy() -> Any:
    try:
        from sysmlpy import antlr_parser, dfa_cache
    except ImportError:  # pragma: no cover - the dev extra installs it
        pytest.skip("sysmlpy, the independent SysML v2 parser, is not installed: pip install -e '.[dev]'")
    return antlr_parser, dfa_cache


@cache
def _parse(text: str) -> tuple[Any, tuple[str, ...]]:
    antlr_parser, dfa_cache = _sysmlpy()

    def run() -> tuple[Any, tuple[str, ...]]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            # recover=True reports every syntax error and never rewrites the text to make it parse; SLL
            # prediction alone is cached between runs and never accepts what full LL would refuse.
            tree, errors = antlr_parser.parse(text, recover=True, prediction_mode="sll_only")
        return tree, tuple(errors)

    started = time.monotonic()
    result: tuple[Any, tuple[str, ...]] = _in_big_stack(run)
    if time.monotonic() - started > _COLD_SECONDS and not _SAVE_AT_EXIT:
        # Saved once, when the run ends: pickling the tables takes seconds.
        _SAVE_AT_EXIT.append(True)
        atexit.register(_in_big_stack, dfa_cache.save_dfa_cache)
    return result


def _verdict_file(text: str) -> Path:
    """Where a clean parse of exactly this text by this parser version is remembered."""
    from importlib.metadata import version

    key = hashlib.sha256(f"sysmlpy {version('sysmlpy')}\n{text}".encode()).hexdigest()
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "earl" / "sysml-parsed" / f"{key}.ok"


def syntax_errors(text: str) -> list[str]:
    """Every syntax error the independent parser finds in `text`, as `Syntax error at LINE:COLUMN: …`.

    A text this parser version already read without error is not read again: the parser is
    deterministic, and reading takes seconds.  Any change to the export is a new text.
    """
    verdict = _verdict_file(text)
    if verdict.exists():
        return []
    errors = list(_parse(text)[1])
    if not errors:
        with contextlib.suppress(OSError):
            verdict.parent.mkdir(parents=True, exist_ok=True)
            verdict.write_text("parsed without syntax errors\n", encoding="utf-8")
    return errors


def parse_tree(text: str) -> Any:
    """The parser's concrete syntax tree of `text` (an ANTLR context)."""
    return _parse(text)[0]


def _quoted_lines(text: str, errors: list[str]) -> str:
    lines = text.splitlines()
    shown = []
    for error in errors[:10]:
        found = re.search(r"at (\d+):(\d+)", error)
        line = lines[int(found.group(1)) - 1] if found and 0 < int(found.group(1)) <= len(lines) else ""
        shown.append(f"{error}\n    {line.strip()}")
    return "\n".join(shown)


def assert_parses(text: str) -> None:
    errors = syntax_errors(text)
    assert not errors, "the SysML v2 parser found syntax errors:\n" + _quoted_lines(text, errors)


# ---------------------------------------------------------------------- which specifications
def _language_blocks() -> list[tuple[str, str]]:
    blocks = re.findall(r"^```earl\n(.*?)^```", LANGUAGE.read_text(encoding="utf-8"), re.DOTALL | re.MULTILINE)
    return [(f"docs/language.md#{text.split()[1]}", text) for text in blocks]


def _spec_files() -> list[Path]:
    """Every system the test suite reads from a file, the flagship apart (it has its own test)."""
    found = {
        *ROOT.joinpath("examples").rglob("system.earl"),
        *ROOT.joinpath("tests").rglob("system.earl"),
        *GOLDEN.glob("*.earl"),
    }
    return sorted(path for path in found if path != FLAGSHIP)


# ---------------------------------------------------------------------- the tests
def test_the_library_parses_without_syntax_errors() -> None:
    assert_parses(library_text())


def test_the_flagship_example_exports_to_sysml_without_syntax_errors() -> None:
    text = export_sysml(earl.load(FLAGSHIP))
    assert "part <'manip/a'> manip_a : EARL::Agent" in text
    assert "motorController6_ve" in text  # N = 6: the family is expanded
    assert_parses(text)


@pytest.mark.parametrize("path", _spec_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_spec_file_exports_without_syntax_errors(path: Path) -> None:
    assert_parses(export_sysml(earl.load(path)))


@pytest.mark.parametrize("name, text", _language_blocks(), ids=[name for name, _ in _language_blocks()])
def test_every_spec_of_the_language_reference_exports_without_syntax_errors(name: str, text: str) -> None:
    assert_parses(export_sysml(earl.loads(text, name)))


def test_the_spec_files_are_found() -> None:
    names = {path.name for path in _spec_files()}
    assert {"system.earl", "small.earl"} <= names
    assert len(_language_blocks()) >= 5


def test_the_parser_reports_broken_sysml() -> None:
    """The gate can fail: the slips an exporter could make are refused, their corrections accepted."""
    pairs = [
        # a missing semicolon
        ("attribute :>> period = 0.1 [SI::s]", "attribute :>> period = 0.1 [SI::s];"),
        # an EARL name used as a SysML name without quotes
        ("part manip/a : EARL::Agent;", "part <'manip/a'> manip_a : EARL::Agent;"),
        # a SysML keyword used as a name
        ("attribute part : EARL::int[0..1];", "attribute 'part' : EARL::int[0..1];"),
    ]
    for broken, fixed in pairs:
        assert syntax_errors(f"package P {{ part def D {{ {broken} }} }}"), broken
        assert not syntax_errors(f"package P {{ part def D {{ {fixed} }} }}"), fixed
    # a guard with an operand missing
    assert syntax_errors("package P { state def S { state a; state b; transition t first a if x and then b; } }")
