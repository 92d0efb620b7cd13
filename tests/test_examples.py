"""The examples and the language reference stay true to the implementation.

Every `system.earl` under examples/ loads and follows the manual's rules, every
`.earl` file there is canonical, and every `earl` code block of docs/language.md
is a complete specification that loads, checks without errors and is canonical;
docs/python-api.md's model built in Python runs as the page says.
Facts the reference lists (keywords, primitive types, overflow policies, kind
suffixes, diagnostic codes) are compared with the code they describe.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import earl
from earl.check import check
from earl.check.registry import RULES
from earl.cli.main import main
from earl.diagnostics import Diagnostic, Severity
from earl.lang.codes import READING_CODES
from earl.lang.parser import keyword_terminals
from earl.model.elements import Queue
from earl.model.kinds import Kind
from earl.model.types import PRIMITIVE_TYPES

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
LANGUAGE = ROOT / "docs" / "language.md"

SYSTEMS = sorted(EXAMPLES.rglob("system.earl"))
#: the examples' files, and the test suite's own specs (tests/*_specs/), which are canonical too
EARL_FILES = sorted(EXAMPLES.rglob("*.earl")) + sorted(ROOT.glob("tests/*_specs/**/*.earl"))


def _name(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _problems(diagnostics: list[Diagnostic], *severities: Severity) -> list[str]:
    return [f"{d.code} {d.location}: {d.message}" for d in diagnostics if d.severity in severities]


# ---------------------------------------------------------------- examples/


def test_the_examples_are_found() -> None:
    # Guards the parametrised tests below against passing because nothing was collected.
    assert EXAMPLES / "mobile_robot" / "system.earl" in SYSTEMS
    assert EXAMPLES / "mobile_robot" / "types.earl" in EARL_FILES


@pytest.mark.parametrize("path", SYSTEMS, ids=_name)
def test_example_loads_and_follows_the_manual(path: Path) -> None:
    system = earl.load(path)
    assert system.name
    diagnostics = check(system)
    # An example is a showcase: not even a warning.
    assert _problems(diagnostics, Severity.ERROR, Severity.WARNING) == []


@pytest.mark.parametrize("path", EARL_FILES, ids=_name)
def test_example_file_is_canonical(path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["fmt", "--check", str(path)])
    assert status == 0, capsys.readouterr().err


def test_the_benchmark_spec_generator_writes_a_valid_canonical_spec() -> None:
    # benchmarks/bench_parse.py times this text; it must be a spec `earl check` accepts.
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from generate import generate
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    text = generate(3)
    system = earl.loads(text, "generated.earl")
    assert [len(agent.subsystems) for agent in system.agents] == [7, 7, 7]
    assert _problems(check(system), Severity.ERROR, Severity.WARNING) == []
    assert system.to_earl() == text
    larger = generate(12)  # two robots
    assert earl.loads(larger, "generated.earl").to_earl() == larger


def test_a_non_canonical_file_fails_fmt_check(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # The canonical-form test above means something only if `fmt --check` can fail.
    source = (EXAMPLES / "mobile_robot" / "types.earl").read_text(encoding="utf-8")
    untidy = tmp_path / "types.earl"
    untidy.write_text(source.replace("    x: double", "x:double"), encoding="utf-8")
    assert main(["fmt", "--check", str(untidy)]) == 1
    assert "not canonical" in capsys.readouterr().err


def test_mobile_robot_uses_every_subsystem_kind_and_an_agent_outside_any_robot() -> None:
    system = earl.load(EXAMPLES / "mobile_robot")
    base = system.agent("base")
    assert base is not None
    kinds = {subsystem.kind for subsystem in base.subsystems}
    assert kinds == {
        Kind.CONTROL_SUBSYSTEM,
        Kind.VIRTUAL_EFFECTOR,
        Kind.REAL_EFFECTOR,
        Kind.VIRTUAL_RECEPTOR,
        Kind.REAL_RECEPTOR,
    }
    in_robots = {reference.name for robot in system.robots for reference in robot.agents}
    assert in_robots == {"base"}
    coordinator = system.agent("coordinator")
    assert coordinator is not None
    assert [s.kind for s in coordinator.subsystems] == [Kind.CONTROL_SUBSYSTEM]
    assert {link.name_text for link in system.links} == {"coordinator,base", "base,coordinator"}
    # The data types come from the imported file.
    assert [i.path for i in system.imports] == ["types.earl"]
    assert system.type_named("LaserScan") is not None


def test_mobile_robot_base_fsm_resolves_overlaps_with_priorities() -> None:
    system = earl.load(EXAMPLES / "mobile_robot")
    base = system.agent("base")
    assert base is not None
    cs = base.control_subsystem
    assert cs is not None and cs.fsm is not None
    assert cs.fsm.initial == "start"
    assert {state.name for state in cs.fsm.states} >= {"idle", "drive", "avoidObstacle", "emergencyStop"}
    from_drive = sorted(t.priority or 0 for t in cs.fsm.transitions if t.source == "drive")
    assert from_drive == [2, 3, 4]
    assert cs.fsm.assumptions
    # Eq. (4)-(8): every behaviour that sends anything has a memory stage and an output stage.
    for behaviour in cs.basic_behaviours:
        assert len(behaviour.transition_function.stages) == 2


def test_mobile_robot_parameters_can_be_changed() -> None:
    # The comments promise `--param WHEELS=4` and `--param SECTORS=16`.
    parameters: dict[str, bool | int | float | str] = {"WHEELS": 4, "SECTORS": 16}
    system = earl.load(EXAMPLES / "mobile_robot", parameters)
    assert _problems(check(system, parameters), Severity.ERROR, Severity.WARNING) == []
    assert main(["check", str(EXAMPLES / "mobile_robot"), "--param", "WHEELS=4", "--strict"]) == 0


# ---------------------------------------------------------------- docs/language.md


def _document() -> str:
    return LANGUAGE.read_text(encoding="utf-8")


def _earl_blocks() -> list[str]:
    return re.findall(r"^```earl\n(.*?)^```", _document(), re.DOTALL | re.MULTILINE)


def _block_name(text: str) -> str:
    match = re.search(r"^system (\w+)", text, re.MULTILINE)
    return match.group(1) if match else text.splitlines()[0]


BLOCKS = _earl_blocks()


def test_the_reference_has_examples() -> None:
    assert len(BLOCKS) >= 10


@pytest.mark.parametrize("text", BLOCKS, ids=_block_name)
def test_reference_example_is_a_valid_canonical_specification(text: str) -> None:
    code = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("//")]
    assert code[0].startswith("system "), "an `earl` block is a complete specification"
    # Named after the page, so that its imports are relative to docs/.
    system = earl.loads(text, str(LANGUAGE))
    assert _problems(check(system), Severity.ERROR) == []
    assert system.to_earl() == text, "write the example in canonical form (earl fmt)"


def test_the_first_reference_example_is_complete() -> None:
    system = earl.loads(BLOCKS[0], str(LANGUAGE))
    assert _problems(check(system), Severity.ERROR, Severity.WARNING) == []
    control = system.agents[0].control_subsystem
    assert system.robots and control is not None and control.fsm is not None


def test_reference_lists_exactly_the_keywords_of_the_grammar() -> None:
    listing = re.search(r"\*\*Keywords\.\*\*.*?```\n(.*?)```", _document(), re.DOTALL)
    assert listing is not None
    assert set(listing.group(1).split()) == set(keyword_terminals().values())


def test_reference_lists_every_primitive_type_and_overflow_policy() -> None:
    section = _document().split("## Data types", 1)[1].split("\n## ", 1)[0]
    for name in PRIMITIVE_TYPES:
        assert f"`{name}`" in section, name
    for policy in Queue.OVERFLOW_POLICIES:
        assert f"| `{policy}`" in _document(), policy


def test_reference_has_a_row_for_every_written_kind_suffix() -> None:
    # `t` and `aa` have no suffix in the text: transitions use `->`, links `link`.
    written = [kind for kind in Kind if kind not in (Kind.TRANSITION, Kind.INTER_AGENT_LINK)]
    for kind in written:
        assert f"\n| `{kind.value}` |" in _document(), kind.value


def test_every_code_the_reference_mentions_exists() -> None:
    mentioned = set(re.findall(r"EARL-[SREWI]\d{3}", _document()))
    assert mentioned, "the reference names diagnostic codes"
    unknown = sorted(code for code in mentioned if code not in READING_CODES and code not in RULES)
    assert unknown == []


# ---------------------------------------------------------------- docs/python-api.md


def test_the_python_api_example_runs_as_a_script_and_says_what_the_page_says(tmp_path: Path) -> None:
    """The page's model built in Python is run as its reader would run it, `python counting.py`: its
    functions are named `"__main__:…"`, so it must run as a script, not be imported."""
    import os
    import subprocess
    import sys

    page = (ROOT / "docs" / "python-api.md").read_text(encoding="utf-8")
    section = page.split("## Building a model in Python", 1)[1]
    [code] = re.findall(r"^```python\n(.*?)^```", section.split("\n## ", 1)[0], re.DOTALL | re.MULTILINE)
    script = tmp_path / "counting.py"
    script.write_text(code, encoding="utf-8")
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=environment, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    text = done.stdout.split("\n")
    assert earl.loads("\n".join(text[:-3])).name == "counting"  # to_earl's text reads back
    # the outputs the page's comments promise
    assert text[-3:] == ["finished {'count': 3}", "{'last': 3} []", ""]
