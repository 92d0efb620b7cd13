"""A MuJoCo model of the user's own (docs/simulation.md, "Your own robot in MuJoCo"): the pendulum of
tests/runtime_specs/pendulum run with `earl run` against the real engine, as the page shows it."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parent.parent
PENDULUM = ROOT / "tests" / "runtime_specs" / "pendulum"
PAGE = ROOT / "docs" / "simulation.md"
EARL = [sys.executable, "-m", "earl.cli.main"]


def earl_cli(*arguments: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*EARL, *arguments], capture_output=True, text=True, timeout=120, cwd=cwd, check=False)


def pendulum_copy(tmp_path: Path, file: str = "pendulum.xml", old: str = "", new: str = "") -> Path:
    """The example in `tmp_path`, with `old` replaced by `new` in `file`: how these tests make a mistake."""
    target = tmp_path / "pendulum"
    shutil.copytree(PENDULUM, target, ignore=shutil.ignore_patterns("__pycache__"))
    if old:
        path = target / file
        text = path.read_text(encoding="utf-8")
        assert old in text
        path.write_text(text.replace(old, new), encoding="utf-8")
    return target


def section() -> str:
    page = PAGE.read_text(encoding="utf-8")
    return page.split("## Your own robot in MuJoCo", 1)[1].split("\n## ", 1)[0]


def test_the_pendulum_runs_with_earl_run_and_hangs_still_at_the_end(tmp_path: Path) -> None:
    # started elsewhere than the spec's directory: the factory finds its XML next to its module
    result = earl_cli("run", str(PENDULUM), "--duration", "1s", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "fault(s)" not in result.stdout
    found = re.search(r"pendulum: shoulder=(\S+) rad elbow=(\S+) rad at 1\.000 s", result.stdout)
    assert found, result.stdout
    assert abs(float(found[1])) < 0.005 and abs(float(found[2])) < 0.005


def test_every_file_the_page_shows_is_the_file_that_runs() -> None:
    shown = re.findall(r"`(tests/runtime_specs/pendulum/[^`]+)`(?: \([^)]*\))?:\n\n```\w*\n(.*?)```", section(), re.S)
    assert {path for path, _ in shown} >= {
        "tests/runtime_specs/pendulum/pendulum.xml",
        "tests/runtime_specs/pendulum/run.toml",
        "tests/runtime_specs/pendulum/swinging/environment.py",
        "tests/runtime_specs/pendulum/swinging/motor.py",
        "tests/runtime_specs/pendulum/system.earl",
    }
    for path, block in shown:
        assert block in (ROOT / path).read_text(encoding="utf-8"), f"docs/simulation.md shows {path} as it is not"


def test_the_page_lists_the_example_s_files_and_its_last_line(tmp_path: Path) -> None:
    listing = re.search(r"\n    tests/runtime_specs/pendulum/\n((?:        .*\n)+)", section())
    assert listing, "the page lists the example's files"
    listed = re.findall(r"^        (\S+?)/?\s{2,}", listing[1], re.M)
    assert sorted(listed) == sorted(path.name for path in PENDULUM.iterdir() if path.name != "__pycache__")
    result = earl_cli("run", str(PENDULUM), cwd=tmp_path)  # run.toml's duration, as the page runs it
    last = result.stdout.strip().splitlines()[-1]
    assert f"# … {last}" in section()
