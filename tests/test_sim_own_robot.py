"""A MuJoCo model of the user's own (docs/simulation.md, "Your own robot in MuJoCo"): the pendulum of
tests/runtime_specs/pendulum run with `earl run` against the real engine, as the page shows it."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.diagnostics import EarlError

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


# ------------------------------------------------------------------ mistakes in the model, said before the run


def test_xml_that_is_not_well_formed_is_one_line_naming_the_file_and_line_at_run_toml_s_environment(
    tmp_path: Path,
) -> None:
    copy = pendulum_copy(tmp_path, old="  </worldbody>", new="  </worldbod>")
    result = earl_cli("run", str(copy), "--duration", "10ms", cwd=tmp_path)
    assert result.returncode == 1, result.stdout
    assert "\\n" not in result.stderr  # MuJoCo's line breaks, which a diagnostic would show escaped
    first = result.stderr.splitlines()[0]
    assert first.startswith("error[EARL-X020]: the environment `swinging.environment:make` failed to start")
    assert f"MuJoCo could not read {copy / 'pendulum.xml'}, line 4: the element `<worldbody>`" in first
    assert "closed by an end tag of another name (XML_ERROR_MISMATCHED_ELEMENT)" in first
    # where the environment is named
    assert " --> pendulum/run.toml:1:15" in result.stderr
    assert '1 | environment = "swinging.environment:make"' in result.stderr


def test_a_model_mujoco_refuses_is_one_line_naming_the_line_and_the_element(tmp_path: Path) -> None:
    copy = pendulum_copy(tmp_path, old='joint="elbow"', new='joint="elbw"')
    result = earl_cli("run", str(copy / "system.earl"), "--duration", "10ms", cwd=copy)
    assert result.returncode == 1
    assert "\\n" not in result.stderr
    assert (
        f"MuJoCo could not read {copy / 'pendulum.xml'}, line 17 (the element named `motor2`): "
        "unknown transmission target 'elbw' for actuator id = 1"
    ) in result.stderr
    assert " --> run.toml:1:15" in result.stderr


def test_an_environment_whose_advance_is_no_method_is_said_at_run_toml_s_line(tmp_path: Path) -> None:
    copy = pendulum_copy(
        tmp_path,
        "swinging/environment.py",
        old='    plant = MujocoPlant.from_file(MODEL, seed=seed, keyframe="start")',
        new="    return type('World', (), {'advance': 0.001})()",
    )
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X020" and "`advance` is a float, not a method" in diagnostic.message
    assert diagnostic.location is not None and diagnostic.location.file.endswith("run.toml")
    assert (diagnostic.location.line, diagnostic.location.column) == (1, 15)


def test_an_encoder_of_zero_counts_is_said_at_its_line_before_the_run(tmp_path: Path) -> None:
    copy = pendulum_copy(
        tmp_path, old='"earl.encoder.motor1" data="100 4096"', new='"earl.encoder.motor1" data="100 0"'
    )
    result = earl_cli("run", str(copy), "--duration", "10ms", cwd=tmp_path)
    assert result.returncode == 1
    assert "ZeroDivisionError" not in result.stderr
    assert (
        f'PlantError: {copy / "pendulum.xml"}, line 21: the encoder <numeric name="earl.encoder.motor1" data="100 0"/> '
        "has 0 counts per revolution: COUNTS, its second number, is a whole number, 1 or more"
    ) in result.stderr


def spec_line(copy: Path, text: str) -> int:
    lines = (copy / "system.earl").read_text(encoding="utf-8").splitlines()
    return 1 + next(number for number, line in enumerate(lines) if line.strip().startswith(text))


def test_an_actuator_missing_from_the_model_is_refused_before_the_run_naming_effector_actuator_and_model(
    tmp_path: Path,
) -> None:
    """The environment maps motor[K]/re to `motor{K}`: the model without `motor2` would fault in every
    iteration of motor[2]/re (and exit 0), so the run is refused before it starts, with what exists."""
    copy = pendulum_copy(tmp_path, old='<motor name="motor2"', new='<motor name="motr2"')
    xml = copy / "pendulum.xml"  # its encoder goes too: an encoder of no actuator is refused when the plant is built
    text = xml.read_text(encoding="utf-8")
    xml.write_text(text.replace(next(x for x in text.splitlines(True) if "encoder.motor2" in x), ""), encoding="utf-8")
    result = earl_cli("run", str(copy), "--duration", "10ms", cwd=copy)
    assert result.returncode == 1, result.stdout
    assert "nothing was executed" in result.stderr and "iterations" not in result.stdout
    assert result.stderr.splitlines()[0] == (
        "error[EARL-X021]: `arm/a.motor[2]/re` acts on the actuator `motor2` (map_actuator('arm/a.motor[K]/re', "
        f"'motor{{K}}')), but {copy / 'pendulum.xml'} has no actuator named so; its actuators: motor1, motr2"
    )
    assert f" --> system.earl:{spec_line(copy, 'motor[K in 1..J]/re {')}:5" in result.stderr
    assert "= hint: did you mean `motr2`?" in result.stderr


def test_an_encoder_missing_from_the_model_is_refused_before_the_run(tmp_path: Path) -> None:
    copy = pendulum_copy(tmp_path)
    xml = copy / "pendulum.xml"
    text = xml.read_text(encoding="utf-8")
    line = next(line for line in text.splitlines(keepends=True) if "earl.encoder.motor2" in line)
    xml.write_text(text.replace(line, ""), encoding="utf-8")
    result = earl_cli("run", str(copy), "--duration", "10ms", cwd=copy)
    assert result.returncode == 1, result.stdout
    assert result.stderr.splitlines()[0] == (
        "error[EARL-X021]: `arm/a.motor[2]/re` reads the encoder of `motor2` (map_actuator('arm/a.motor[K]/re', "
        f"'motor{{K}}', encoder=True)), but {xml} declares none for it; the encoders it declares: motor1"
    )
    assert (
        '= hint: add <numeric name="earl.encoder.motor2" data="GEAR COUNTS"/> to its <custom> section' in result.stderr
    )


def test_a_map_that_misnames_the_family_is_refused_once(tmp_path: Path) -> None:
    # `J` is the spec's number of joints, not the family's index: the map would name motor[2]/re alone
    copy = pendulum_copy(tmp_path, "swinging/environment.py", old='"arm/a.motor[K]/re"', new='"arm/a.motor[J]/re"')
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X021"
    assert "`J` is no index of the family `arm/a.motor[K]/re` (it is a parameter, J = 2)" in diagnostic.message
    copy = pendulum_copy(
        tmp_path / "typo", "swinging/environment.py", old='"arm/a.motor[K]/re"', new='"arm/a.motr[K]/re"'
    )
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.message.startswith("the environment maps `arm/a.motr[K]/re` to `motor{K}`, but the system has no")
    assert diagnostic.hint == "did you mean `arm/a.motor[K]/re`?"
    # at no line of the spec: said at run.toml's, which names the environment
    assert diagnostic.location is not None and diagnostic.location.file.endswith("run.toml")


def test_a_map_naming_a_member_by_a_digit_that_is_not_ascii_is_refused(tmp_path: Path) -> None:
    """`\\d` took `٢`: the map was read as naming a member beyond the family's range, and skipped without a word."""
    copy = pendulum_copy(
        tmp_path,
        "swinging/environment.py",
        old="encoder=True)",
        new='encoder=True)\n    plant.map_actuator("arm/a.motor[٢]/re", "motor2")',
    )
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.message.startswith("the environment maps `arm/a.motor[٢]/re` to `motor2`, but the system has no")


def test_maps_that_name_the_actuators_otherwise_run_without_a_fault(tmp_path: Path) -> None:
    """The check is the lookup the effectors make during the run: whatever the names, a map that finds them runs."""
    copy = pendulum_copy(tmp_path, "swinging/environment.py", old='"motor{K}"', new='"drive{K}"')
    xml = copy / "pendulum.xml"
    renamed = xml.read_text(encoding="utf-8").replace('"motor', '"drive').replace("encoder.motor", "encoder.drive")
    xml.write_text(renamed, encoding="utf-8")
    result = earl_cli("run", str(copy), "--duration", "200ms")
    assert result.returncode == 0, result.stderr
    assert "fault(s)" not in result.stdout


def test_an_environment_s_own_bind_may_refuse_the_system(tmp_path: Path) -> None:
    copy = pendulum_copy(
        tmp_path,
        "swinging/environment.py",
        old='    plant = MujocoPlant.from_file(MODEL, seed=seed, keyframe="start")',
        new=(
            '    plant = MujocoPlant.from_file(MODEL, seed=seed, keyframe="start")\n'
            "    def bind(system: Any) -> None:\n"
            '        raise ValueError(f"{system.name} needs a third joint")\n'
            "    plant.bind = bind  # type: ignore[method-assign]\n"
            "    return plant"
        ),
    )
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X021"
    assert diagnostic.message == "the environment does not fit the system: ValueError: pendulum needs a third joint"
    assert diagnostic.location is not None and diagnostic.location.file.endswith("run.toml")


def test_a_timestep_that_does_not_divide_the_motors_period_is_refused_before_the_run(tmp_path: Path) -> None:
    copy = pendulum_copy(tmp_path, old='timestep="0.001"', new='timestep="0.003"')
    result = earl_cli("run", str(copy), "--duration", "10ms", cwd=copy)
    assert result.returncode == 1, result.stdout
    assert result.stderr.splitlines()[0] == (
        f"error[EARL-X021]: the model's timestep, 3 ms ({copy / 'pendulum.xml'}, line 3), does not divide the period "
        "of `arm/a.motor[K]/re` (1 ms): the plant is stepped 3 ms at a time, so at their instants it would be up to "
        "a step behind"
    )
    assert f" --> system.earl:{spec_line(copy, 'motor[K in 1..J]/re {')}:5" in result.stderr
    assert (
        '= hint: choose a timestep that divides the period of every real effector and receptor, e.g. <option timestep="0.001"/>'
        in result.stderr
    )


def test_a_timestep_that_divides_the_periods_runs(tmp_path: Path) -> None:
    copy = pendulum_copy(tmp_path, old='timestep="0.001"', new='timestep="0.0005"')
    simulation = earl.simulate(earl.load(copy))
    try:
        simulation.advance_to(0.0105)
        # the run advances its environment to the time it reached, 10.5 ms: 21 steps of 0.5 ms
        assert simulation.environment.time == pytest.approx(0.0105)  # type: ignore[attr-defined]
        assert simulation.faults == []
    finally:
        simulation.close()


def test_a_sensor_a_subsystem_is_mapped_to_is_checked_before_the_run_and_read_during_it(tmp_path: Path) -> None:
    copy = pendulum_copy(
        tmp_path,
        old="  <custom>",
        new='  <sensor>\n    <jointpos name="angle1" joint="shoulder"/>\n    <jointpos name="angel2" joint="elbow"/>\n'
        "  </sensor>\n  <custom>",
    )
    environment = copy / "swinging" / "environment.py"
    text = environment.read_text(encoding="utf-8")
    mapped = '    plant.map_sensor("arm/a.motor[K]/re", "angle{K}")\n    return plant'
    environment.write_text(text.replace("    return plant", mapped), encoding="utf-8")
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X021"
    assert diagnostic.message == (
        "`arm/a.motor[2]/re` acts on the sensor `angle2` (map_sensor('arm/a.motor[K]/re', 'angle{K}')), but "
        f"{copy / 'pendulum.xml'} has no sensor named so; its sensors: angle1, angel2"
    )
    assert diagnostic.hint == "did you mean `angel2`?"
    xml = copy / "pendulum.xml"
    xml.write_text(xml.read_text(encoding="utf-8").replace('"angel2"', '"angle2"'), encoding="utf-8")
    simulation = earl.simulate(earl.load(copy))
    try:
        simulation.advance_to(0.01)
        plant: Any = simulation.environment
        assert simulation.faults == []
        # what the lookup found for each member, and the sensor's reading: the joint's angle
        assert plant.sensor_of(simulation.scheduler.network.by_name["arm/a.motor[2]/re"].context) == "angle2"
        assert plant.sensor("angle2") == (pytest.approx(plant.joint_position("elbow")),)
    finally:
        simulation.close()


def test_a_map_for_a_member_this_run_leaves_out_is_left_alone(tmp_path: Path) -> None:
    """An environment written for up to three joints maps each member by its number; with J = 2 no
    `motor[3]/re` runs and nothing looks its map up, so the run is not refused (docs/simulation.md)."""
    copy = pendulum_copy(
        tmp_path,
        "swinging/environment.py",
        old='    plant.map_actuator("arm/a.motor[K]/re", "motor{K}", encoder=True)',
        new=('    for k in (1, 2, 3):\n        plant.map_actuator(f"arm/a.motor[{k}]/re", f"motor{k}", encoder=True)'),
    )
    simulation = earl.simulate(earl.load(copy))
    try:
        simulation.advance_to(0.01)
        assert simulation.faults == []
        plant: Any = simulation.environment
        assert plant.actuator_of(simulation.scheduler.network.by_name["arm/a.motor[2]/re"].context) == "motor2"
    finally:
        simulation.close()


def test_a_map_on_a_virtual_effector_is_checked_and_looked_up_as_a_real_one_s(tmp_path: Path) -> None:
    """Every subsystem's functions get `context.environment`: a virtual effector may ask `actuator_of` too."""
    mapped = '    plant.map_actuator("arm/a.joint[K]/ve", "{name}")\n    return plant'
    environment = "swinging/environment.py"
    copy = pendulum_copy(tmp_path, environment, old="    return plant", new=mapped.format(name="motor{K}"))
    simulation = earl.simulate(earl.load(copy))
    try:
        simulation.advance_to(0.01)
        plant: Any = simulation.environment
        assert plant.actuator_of(simulation.scheduler.network.by_name["arm/a.joint[2]/ve"].context) == "motor2"
    finally:
        simulation.close()
    copy = pendulum_copy(tmp_path / "missing", environment, old="    return plant", new=mapped.format(name="drive{K}"))
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.message.startswith("`arm/a.joint[1]/ve`, `arm/a.joint[2]/ve` act on the actuator `drive1`")
    assert diagnostic.location is not None and diagnostic.location.line == spec_line(copy, "joint[K in 1..J]/ve {")


def test_a_name_in_braces_that_cannot_be_written_is_said_once_at_the_effector(tmp_path: Path) -> None:
    # `{K[0]}` subscripts the number K: said once, though `encoder=True` maps the name twice
    copy = pendulum_copy(tmp_path, "swinging/environment.py", old='"motor{K}"', new='"motor{K[0]}"')
    with pytest.raises(EarlError) as refused:
        earl.simulate(earl.load(copy))
    [diagnostic] = refused.value.diagnostics
    assert diagnostic.code == "EARL-X021"
    assert diagnostic.message == (
        "the actuator `motor{K[0]}` mapped for `arm/a.motor[1]/re` cannot be written from its parameters "
        "('int' object is not subscriptable); in braces go the names of its parameters: J, K"
    )
    assert diagnostic.location is not None and diagnostic.location.line == spec_line(copy, "motor[K in 1..J]/re {")
