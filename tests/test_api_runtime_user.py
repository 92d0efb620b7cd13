"""What a user of the Python API meets at run time: user code named from a notebook or a saved script,
values read from a run, and what errors say (docs/python-api.md)."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import earl
from earl.diagnostics import EarlError, did_you_mean

ROOT = Path(__file__).resolve().parents[1]

SPEC = """\
system c
c/a {
    cs {
        period 10 ms
        count/m: int = 0
        never/pp = false
        increment/pf(count/mi -> count/mo) = python "IMPLEMENTATION"
        go/bb {
            tf = {increment/pf}
            tc = never/pp
        }
        fsm {
            initial go
            state go: go/bb
        }
    }
}
r/r {
    c/a
}
"""


def spec(implementation: str) -> str:
    return SPEC.replace("IMPLEMENTATION", implementation)


def environment() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}


def refusal(implementation: str) -> earl.Diagnostic:
    with pytest.raises(EarlError) as raised:
        earl.simulate(earl.loads(spec(implementation)))
    [diagnostic] = raised.value.diagnostics
    return diagnostic


# ---------------------------------------------------------------- naming user code


def test_a_function_missing_from_main_in_python_c_is_x004_saying_to_define_it_in_the_session() -> None:
    """`python -c` (as the REPL and a notebook's kernel) has a `__main__` without `__file__`: the hint
    said where to define the function by that file, and failed with an AttributeError instead."""
    code = f"import earl\ntry:\n    earl.simulate(earl.loads({spec('__main__:advance')!r}))\n"
    code += "except earl.EarlError as e:\n    print(e.diagnostics[0].code, e.diagnostics[0].hint)\n"
    done = subprocess.run(
        [sys.executable, "-c", code], env=environment(), capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(
        "EARL-X004 `__main__` is this interactive session (a notebook, the REPL, `python -c`)"
    )
    assert "define `def advance(inputs, outputs, context) -> None` in it" in done.stdout


def test_a_function_missing_from_a_namespace_package_says_it_can_define_none(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "nspkg_for_test").mkdir()  # no __init__.py: a namespace package, whose __file__ is None
    monkeypatch.syspath_prepend(str(tmp_path))
    diagnostic = refusal("nspkg_for_test:advance")
    assert diagnostic.code == "EARL-X004"
    assert diagnostic.hint is not None and "in `None`" not in diagnostic.hint
    assert diagnostic.hint.startswith("`nspkg_for_test` is a directory without `__init__.py`")
    assert 'python "nspkg_for_test.MODULE:FUNCTION"' in diagnostic.hint


def test_a_function_named_with_the_wrong_case_gets_a_did_you_mean(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "casecode_for_test.py").write_text("def plan(inputs, outputs, context):\n    pass\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    diagnostic = refusal("casecode_for_test:PLAN")
    assert (diagnostic.code, diagnostic.hint) == ("EARL-X004", "did you mean `plan`?")
    assert did_you_mean("Idle", ["idle", "IDLE", "other"]) == "did you mean `IDLE`?"  # sorted: the first alike


def test_a_model_naming_main_saved_warns_and_its_run_by_earl_says_where_the_functions_went(tmp_path: Path) -> None:
    """The docs' own example names `__main__:increment`; saved and run with `earl run`, `__main__` is earl's
    program, and the hint said to define the function in earl's own `__main__.py`."""
    system = earl.loads(spec("__main__:increment"))
    target = tmp_path / "system.earl"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        earl.save(system, target)
    [warning] = caught
    assert warning.filename == __file__  # at the line that saved, not inside earl
    assert "names functions of `__main__` (`increment`), which exist only while the script" in str(warning.message)
    assert target.read_text(encoding="utf-8") == system.to_earl()  # written all the same
    done = subprocess.run(
        [sys.executable, "-m", "earl", "run", str(target), "--duration", "0.05"],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode != 0
    assert "error[EARL-X004]: `increment/pf` of c/a.cs names `__main__:increment`, but `__main__` is the program" in (
        done.stderr
    )
    assert (
        'hint: move `increment` into a module beside the spec (e.g. `functions.py`) and name it `python "functions:'
        in (done.stderr)
    )
    assert "earl/__main__.py" not in done.stderr


def test_earl_fmt_rewrites_a_spec_naming_main_without_a_warning(tmp_path: Path) -> None:
    target = tmp_path / "system.earl"
    target.write_text(spec("__main__:increment").replace("    period", "  period"), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-W", "error", "-m", "earl", "fmt", "--write", str(target)],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr and "    period 10 ms" in target.read_text(encoding="utf-8")
