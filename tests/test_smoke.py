from pathlib import Path

import earl


def test_load_and_format_round_trip(tmp_path: Path) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text("system demo\n\nparam N: int = 2\n")
    system = earl.load(spec)
    assert system.name == "demo"
    assert system.parameters[0].name == "N"
    assert earl.loads(system.to_earl(), str(spec)) == system


def test_python_dash_m_earl_is_the_earl_command(tmp_path: Path) -> None:
    """`python -m earl` works where the `earl` script is not on PATH, with the same exit codes."""
    import subprocess
    import sys

    flagship = Path(__file__).parent.parent / "examples" / "pick_and_place"
    valid = subprocess.run([sys.executable, "-m", "earl", "check", str(flagship)], capture_output=True, text=True)
    assert valid.returncode == 0, valid.stderr
    missing = subprocess.run(
        [sys.executable, "-m", "earl", "check", str(tmp_path / "none.earl")], capture_output=True, text=True
    )
    assert missing.returncode == 2
    assert "no such file" in missing.stderr
    assert "Traceback" not in missing.stderr
