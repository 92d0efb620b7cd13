from pathlib import Path

import pytest

import earl
import earl.cli.main as main_module


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


def test_a_ctrl_c_the_shell_has_earl_ignore_stays_ignored(tmp_path: Path) -> None:
    """`trap '' INT` (or a background job of a script): earl's own Ctrl-C handler replaced the ignore, and
    `earl doc` ended with 130 instead of writing the document."""
    import signal
    import subprocess
    import sys
    import time

    flagship = Path(__file__).parent.parent / "examples" / "pick_and_place"
    child = subprocess.Popen(
        [sys.executable, "-m", "earl", "doc", str(flagship), "-o", str(tmp_path / "site")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    try:
        deadline = time.monotonic() + 60
        for delay in (0.05, 0.2, 0.5):  # in the imports, and in the command
            time.sleep(delay)
            if child.poll() is None:
                child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=max(1.0, deadline - time.monotonic()))
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == 0, err
    assert (tmp_path / "site" / "index.html").is_file()


def test_nohup_earl_run_outlives_its_terminal(tmp_path: Path) -> None:
    """`nohup earl run …` ignores SIGHUP; earl's own stop handler replaced the ignore, and closing the
    terminal stopped the run (exit 130) after all."""
    import signal
    import subprocess
    import sys
    import time

    counter = Path(__file__).parent / "runtime_specs" / "counter"
    child = subprocess.Popen(
        [sys.executable, "-m", "earl", "run", str(counter), "--duration", "2s", "--realtime", "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN),
    )
    try:
        time.sleep(1.0)  # in the run
        child.send_signal(signal.SIGHUP)
        out, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == 0, err
    assert b"ran 2.000 s" in out, out


def test_every_command_s_help_says_its_exit_codes() -> None:
    """`earl trace summary --help` said no exit codes (only `earl trace --help` did), nor did `earl rules
    --help`; and none but `run` and `launch` said 130, which docs/language.md gives every command for Ctrl-C."""
    import argparse
    import subprocess
    import sys

    from earl.cli.main import build_parser

    def commands(parser: argparse.ArgumentParser, words: tuple[str, ...]) -> list[tuple[str, ...]]:
        found = [words]
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    found += commands(sub, (*words, name))
        return found

    every = commands(build_parser(), ())
    assert ("trace", "summary") in every and ("rules",) in every
    for words in every:
        shown = subprocess.run(
            [sys.executable, "-m", "earl", *words, "--help"], capture_output=True, text=True, timeout=120
        )
        assert shown.returncode == 0, shown.stderr
        said = " ".join(shown.stdout.split("exit codes:", 1)[-1].split())
        assert "exit codes:" in shown.stdout, f"`earl {' '.join(words)} --help` says no exit codes"
        assert said.startswith("0 "), (words, said)
        assert "2 usage error" in said and "130 interrupted" in said, (words, said)


def test_an_interrupt_that_python_wraps_in_another_error_is_still_exit_130_with_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """CPython 3.11 turns a KeyboardInterrupt raised while a class is made (in a descriptor's
    `__set_name__`, as Lark's classes have while `lark` is imported) into a RuntimeError whose cause is
    the interrupt: a Ctrl-C, or a SIGTERM of `earl run`, at that moment of the start printed a traceback
    and exit 1. A real error that no interrupt caused still goes up as it is."""
    (tmp_path / "interrupted_command.py").write_text(
        "class Interrupting:\n"
        "    def __set_name__(self, owner, name):\n"
        "        raise KeyboardInterrupt\n"
        "class Made:\n"
        "    field = Interrupting()\n"
    )
    (tmp_path / "failing_command.py").write_text("raise RuntimeError('a real error')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(main_module.COMMANDS, "check", "interrupted_command")
    assert main_module.main(["check", "x.earl"]) == 130
    assert capsys.readouterr().err == "earl: interrupted\n"
    monkeypatch.setitem(main_module.COMMANDS, "check", "failing_command")
    with pytest.raises(RuntimeError, match="a real error"):
        main_module.main(["check", "x.earl"])
