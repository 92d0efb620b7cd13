"""earl.sim: the MJCF arm, the plant adapter (stepping, current → torque, limits, encoders, faults), pictures."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from earl.sim import MujocoPlant, PlantError, arm
from earl.sim.plant import Encoder

BOX = (0.45, 0.0)
TARGET = (0.10, 0.42)


def _plant(n: int = 6, seed: int = 0) -> MujocoPlant:
    q = arm.tool_down_configuration(n, (0.45, 0.0, 0.26))
    return MujocoPlant.from_xml(arm.workcell_mjcf(n, BOX, TARGET, q), seed=seed, keyframe="initial")


@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
def test_every_arm_points_its_gripper_down_at_the_asked_point(n: int) -> None:
    point = (0.30, 0.25, 0.08)
    q = arm.tool_down_configuration(n, point)
    plant = MujocoPlant.from_xml(arm.workcell_mjcf(n, BOX, TARGET, q), keyframe="initial")
    pose = plant.site_pose(arm.GRASP_SITE)
    assert np.allclose(pose.position, point, atol=1e-5)
    # Rz(yaw)·Ry(π) as a quaternion is (0, -sin(yaw/2), cos(yaw/2), 0), up to sign
    half = math.atan2(point[1], point[0]) / 2
    expected = np.array([0.0, -math.sin(half), math.cos(half), 0.0])
    assert abs(abs(float(np.dot(pose.orientation, expected))) - 1.0) < 1e-6
    assert plant.model.nu == n + 1  # N joint motors and the finger drive


@pytest.mark.parametrize("n", [2, 8])
def test_an_arm_without_a_layout_is_refused_in_plain_words(n: int) -> None:
    with pytest.raises(ValueError, match=rf"3 to 7 joints; the spec asks for N = {n}"):
        arm.robot_mjcf(n)


def test_out_of_reach_is_refused() -> None:
    with pytest.raises(ValueError, match="out of the arm's reach"):
        arm.tool_down_configuration(6, (1.5, 0.0, 0.1))


def test_winding_current_becomes_torque_through_motor_constant_and_gear() -> None:
    plant = _plant()
    drive = arm.drive(6, 2)
    applied = plant.set_input("motor2", 1.5)
    plant.advance(plant.timestep)
    assert applied == 1.5
    assert plant.joint_torque("motor2") == pytest.approx(drive.motor_constant * 1.5 * drive.gear_ratio)


def test_the_driver_limits_the_current() -> None:
    plant = _plant()
    limit = arm.drive(6, 2).current_limit
    assert plant.set_input("motor2", 100.0) == limit
    assert plant.set_input("motor2", -100.0) == -limit
    assert plant.set_input("motor2", float("nan")) == 0.0
    plant.advance(plant.timestep)
    assert plant.joint_torque("motor2") == pytest.approx(0.0)


def test_the_rotor_and_gear_friction_appear_at_the_joint() -> None:
    plant = _plant()
    drive = arm.drive(6, 2)
    joint = plant.model.joint(arm.joint_name(2))
    assert float(plant.model.dof_armature[joint.dofadr[0]]) == pytest.approx(drive.rotor_inertia * drive.gear_ratio**2)
    assert float(plant.model.dof_damping[joint.dofadr[0]]) == pytest.approx(
        drive.viscous_friction * drive.gear_ratio**2
    )


def test_encoder_reports_whole_counts_of_the_motor_shaft() -> None:
    encoder = Encoder("m", 0, gear_ratio=100.0, counts_per_revolution=4096)
    for q in np.linspace(-1.0, 1.0, 37):
        reading = encoder.read(float(q))
        counts = reading / encoder.resolution
        assert counts == pytest.approx(round(counts), abs=1e-6)
        assert 0.0 <= q * 100.0 - reading < encoder.resolution + 1e-12
    # finer than one count does not show
    assert encoder.read(0.0) == encoder.read(0.9 * encoder.resolution / 100.0)


def test_plant_encoders_come_from_the_mjcf() -> None:
    plant = _plant()
    assert set(plant.encoders) == {*(arm.actuator_name(k) for k in range(1, 7)), arm.FINGER_ACTUATOR}
    drive = arm.drive(6, 3)
    q = plant.joint_position(arm.joint_name(3))
    reading = plant.encoder("motor3")
    assert abs(q * drive.gear_ratio - reading) < drive.encoder_resolution
    opening = 2 * plant.encoder(arm.FINGER_ACTUATOR) / arm.FINGER_DRIVE.gear_ratio
    assert opening == pytest.approx(arm.INITIAL_OPENING, abs=1e-4)


def test_advance_steps_in_lockstep_and_never_backwards() -> None:
    plant = _plant()
    plant.advance(0.010)
    assert plant.time == pytest.approx(0.010)
    plant.advance(0.010)  # already there: nothing to do
    assert plant.time == pytest.approx(0.010)
    with pytest.raises(PlantError, match="cannot go back in time"):
        plant.advance(0.005)


def test_unknown_names_are_reported_with_what_exists() -> None:
    plant = _plant(3)
    with pytest.raises(PlantError, match=r"no actuator named `motor9` \(it has: motor1, motor2, motor3, fingerDrive\)"):
        plant.set_input("motor9", 1.0)
    with pytest.raises(PlantError, match="no site named `nose`"):
        plant.site_pose("nose")


def test_a_driver_fault_stops_the_current_from_its_time_on() -> None:
    plant = _plant()
    plant.inject_fault("motor2", 0.002)
    assert not plant.driver_fault("motor2")
    assert plant.set_input("motor2", 2.0) == 2.0
    plant.advance(0.002)
    assert plant.driver_fault("motor2")
    assert plant.set_input("motor2", 2.0) == 0.0
    assert not plant.driver_fault("motor1")


def _run(seed: int) -> bytes:
    plant = _plant(seed=seed)
    for i in range(1, 101):
        plant.set_input("motor2", 2.0 * math.sin(i / 10.0))
        plant.set_input(arm.FINGER_ACTUATOR, -1.0)
        plant.advance(i * 0.001)
    return plant.data.qpos.tobytes() + plant.data.qvel.tobytes()


def test_equal_inputs_and_seeds_give_identical_states() -> None:
    assert _run(4) == _run(4)


def test_levelling_wrist_keeps_the_gripper_pointing_down() -> None:
    """N = 3: the passive joints follow shoulder and elbow, so the gripper stays vertical as the arm moves."""
    plant = _plant(3)
    for i in range(1, 201):
        plant.set_input("motor2", 1.0)
        plant.set_input("motor3", -1.0)
        plant.advance(i * 0.001)
    assert abs(plant.joint_position("joint2")) > 0.01  # it did move
    pose = plant.site_pose(arm.GRASP_SITE)
    _, x, y, _ = pose.orientation
    tool_axis_z = 1.0 - 2.0 * (x * x + y * y)  # the z component of the gripper's z axis
    assert tool_axis_z == pytest.approx(-1.0, abs=2e-3)


def test_jacobian_of_the_plant_matches_finite_differences() -> None:
    plant = _plant(6)
    jacp, _ = plant.site_jacobian(arm.GRASP_SITE)
    import mujoco

    base = np.array(plant.site_pose(arm.GRASP_SITE).position)
    dof = int(plant.model.joint("joint2").dofadr[0])
    plant.data.qpos[int(plant.model.joint("joint2").qposadr[0])] += 1e-6
    mujoco.mj_kinematics(plant.model, plant.data)
    moved = np.array(plant.data.site(arm.GRASP_SITE).xpos)
    assert np.allclose((moved - base) / 1e-6, jacp[:, dof], atol=1e-4)


def test_pictures_are_png_or_the_reason_why_not(tmp_path: object) -> None:
    from pathlib import Path

    from earl.sim.render import PlantCamera, RenderUnavailable, VideoRecorder

    plant = _plant(3)
    try:
        camera = PlantCamera(plant, 96, 64, camera="overview")
    except RenderUnavailable as error:
        assert "MUJOCO_GL" in str(error)
        pytest.skip(str(error))
    out = Path(str(tmp_path))
    png = camera.save_png(out / "still.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = camera.frame()
    assert image.shape == (64, 96, 3) and image.std() > 1.0  # not a blank picture
    video = VideoRecorder(camera, plant, fps=100.0)
    plant.advance(0.05)
    assert abs(len(video.frames) - 0.05 * 100) <= 1  # one frame per 10 ms of simulated time
    written = video.save(out / "clip")
    assert written.exists() and written.suffix in {".mp4", ".gif"}
    plant.close()


def test_importing_earl_sim_without_a_display_loads_no_opengl_until_a_picture_is_taken() -> None:
    import os
    import subprocess
    import sys

    environment = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY", "PYOPENGL_PLATFORM")}
    probe = (
        "import os, sys, earl.sim\n"
        "print('OpenGL' in sys.modules, os.environ.get('MUJOCO_GL'))\n"
        "earl.sim.use_offscreen_backend()\n"
        "from mujoco.rendering.classic import gl_context\n"
        "print(os.environ.get('MUJOCO_GL'), gl_context.GLContext.__module__)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, env=environment, timeout=60, check=True
    )
    # a run without pictures never loads PyOpenGL, and leaves MUJOCO_GL unset for the processes it starts
    assert result.stdout.splitlines() == ["False None", "egl mujoco.egl"]


def test_mujoco_s_errors_on_reading_a_model_are_one_line_that_names_the_line(tmp_path: Path) -> None:
    good = arm.robot_mjcf(3)
    with pytest.raises(PlantError) as refused:
        MujocoPlant.from_xml(good.replace("<worldbody>", "<worldbody>\n<body>", 1))
    said = str(refused.value)
    assert "\n" not in said
    assert said.startswith("MuJoCo could not read the XML given to MujocoPlant.from_xml, line ")
    assert "(MujocoPlant.from_file reads a file and names it here)" in said
    model = tmp_path / "robot.xml"
    model.write_text(good.replace("<joint ", "<joint dumping='1' ", 1))
    with pytest.raises(PlantError) as refused:
        MujocoPlant.from_file(model)
    line = 1 + good[: good.index("<joint ")].count("\n")
    assert str(refused.value) == (
        f"MuJoCo could not read {model}, line {line} (element `<joint>`): "
        "Schema violation: unrecognized attribute: 'dumping'"
    )
    with pytest.raises(PlantError, match=r"MuJoCo could not read the model: nowhere\.xml does not exist \(a relative"):
        MujocoPlant.from_file("nowhere.xml")
    with pytest.raises(PlantError, match=r"the XML given to MujocoPlant\.from_xml is empty"):
        MujocoPlant.from_xml("  \n")


@pytest.mark.parametrize(
    ("data", "said"),
    [
        (
            "100 0",
            'data="100 0"/> has 0 counts per revolution: COUNTS, its second number, is a whole number, 1 or more',
        ),
        ("100 40.5", "has 40.5 counts per revolution"),
        ("0 4096", "has the gear ratio 0: GEAR, its first number, is the motor shaft's turns per turn of the joint"),
        ("100", 'has 1 numbers: write data="GEAR COUNTS"'),
    ],
)
def test_an_encoder_s_numbers_are_checked_when_the_plant_is_built(data: str, said: str) -> None:
    xml = arm.robot_mjcf(3)
    declared = re.search(r'<numeric name="earl\.encoder\.motor2" data="[^"]*"', xml)
    assert declared is not None
    xml = xml.replace(declared[0], f'<numeric name="earl.encoder.motor2" data="{data}"')
    line = 1 + xml[: xml.index('"earl.encoder.motor2"')].count("\n")
    with pytest.raises(PlantError) as refused:
        MujocoPlant.from_xml(xml)
    message = str(refused.value)
    assert message.startswith(
        f'the XML given to MujocoPlant.from_xml, line {line}: the encoder <numeric name="earl.encoder.motor2"'
    )
    assert said in message


def test_an_encoder_of_no_actuator_is_said_with_the_actuators_the_model_has() -> None:
    xml = arm.robot_mjcf(3).replace('"earl.encoder.motor2"', '"earl.encoder.motr2"')
    with pytest.raises(PlantError, match=r"names no actuator of the model: .*did you mean `motor2`\?"):
        MujocoPlant.from_xml(xml)


def test_advance_never_steps_beyond_the_time_asked_for() -> None:
    plant = MujocoPlant.from_xml(arm.robot_mjcf(3, timestep=0.003))
    assert plant.timestep == 0.003
    plant.advance(0.002)  # within the first step: the world at 3 ms would be the future
    assert plant.time == 0.0
    plant.advance(0.003)
    assert plant.time == pytest.approx(0.003)
    plant.advance(0.0059)
    assert plant.time == pytest.approx(0.003)
    plant.advance(0.006)  # 0.006 / 0.003 is 1.9999999999999998 in floats: still two steps
    assert plant.time == pytest.approx(0.006)
