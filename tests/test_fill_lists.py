"""`[0] * N`: a list repeated, the initial value of an array whose size a parameter gives.

`perBin/m: int[NBINS] = [0, 0, 0]` broke under `--param NBINS=4` (EARL-E043) and there was no way to
write an initial value that follows the size. The expansion repeats the list once `N` is known, so
the check, the run and the SysML export take a list as long as the array; the text keeps `[0] * N`.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import earl
from earl.check import check
from earl.diagnostics import Severity

SPEC = """\
system bins

param NBINS: int = 3

r/r {
    sorter/a
}

sorter/a {
    cs {
        period 1 ms

        perBin/m: int[NBINS] = INITIAL
        weights/m: double[2 * NBINS] = [0.5, 1.5] * NBINS

        ready/pp = true

        idle/bb {
            tf = {}
            tc = ready/pp
        }

        fsm {
            initial idle
            state idle: idle/bb
        }
    }
}
"""


def _errors(text: str, parameters: dict[str, int] | None = None) -> list[tuple[str, str, str | None]]:
    system = earl.loads(text, "bins.earl", parameters)
    return [(d.code or "", d.message, d.hint) for d in check(system) if d.severity is Severity.ERROR]


@pytest.mark.parametrize("bins", [None, 1, 4, 0])
def test_a_repeated_list_follows_the_parameter_that_sizes_the_array(bins: int | None) -> None:
    parameters = None if bins is None else {"NBINS": bins}
    text = SPEC.replace("INITIAL", "[0] * NBINS")
    assert _errors(text, parameters) == []
    count = 3 if bins is None else bins
    sim = earl.simulate(earl.loads(text, "bins.earl", parameters))
    try:
        memory = sim.state_of("sorter/a.cs").memory
        assert list(memory["perBin"]) == [0] * count
        assert list(memory["weights"]) == [0.5, 1.5] * count
    finally:
        sim.close()


def test_the_text_keeps_the_product_and_the_export_the_list(tmp_path: Path) -> None:
    text = SPEC.replace("INITIAL", "[0] * NBINS")
    assert earl.loads(text, "bins.earl").to_earl() == text
    spec = tmp_path / "bins.earl"
    spec.write_text(text)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "earl",
            "export",
            "sysml",
            str(spec),
            "--param",
            "NBINS=4",
            "-o",
            str(tmp_path / "b.sysml"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "EARL::int[4] ordered nonunique := (0, 0, 0, 0);" in (tmp_path / "b.sysml").read_text(encoding="utf-8")


def test_a_list_written_out_for_a_parameter_sized_array_is_told_to_repeat_one(tmp_path: Path) -> None:
    spec = tmp_path / "bins.earl"
    spec.write_text(SPEC.replace("INITIAL", "[0, 0, 0]"))
    done = subprocess.run(
        [sys.executable, "-m", "earl", "check", str(spec), "--param", "NBINS=4"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1
    printed = done.stdout + done.stderr
    assert "error[EARL-E043]: the initial value of `perBin/m` must have 4 elements (int[4]), not 3" in printed
    assert "= hint: write `[0] * NBINS`: the list repeated as many times as `NBINS` says, whatever it is" in printed


@pytest.mark.parametrize(
    ("initial", "message"),
    [
        ("[0] * 2.5", "`[…] * N` repeats a list, `[0.0] * N`, where N is a whole number of 0 or more, not 2.5"),
        ("[0] * -1", "`[…] * N` repeats a list, `[0.0] * N`, where N is a whole number of 0 or more, not -1"),
        ("[0] + [1]", "`+` takes numbers, not a list"),
    ],
)
def test_a_list_repeated_by_no_whole_number_is_refused(initial: str, message: str) -> None:
    [(code, said, _hint)] = _errors(SPEC.replace("INITIAL", initial))
    assert code == "EARL-E043"
    assert said == f"an initial value must be a constant: {message}"


def test_a_list_of_the_right_length_but_the_wrong_type_is_not_told_to_repeat() -> None:
    """`[0.0, 0.0, 0.0]` for `int[NBINS]`: the length is right, the items are not (repeating `0.0` would not do)."""
    [(code, message, hint)] = _errors(SPEC.replace("INITIAL", "[0.0, 0.0, 0.0]"))
    assert code == "EARL-E043" and "must be a whole number (int), not the real number 0.0" in message
    assert hint == "write a constant of the memory's type, or leave out `= …` for the type's zero value"
