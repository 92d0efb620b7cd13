"""Closed loop without the runtime: the example's functions drive the MuJoCo plant directly.

A small bench plays the part of the scheduler for the manipulator's and the
gripper's chains (cs → ve → re and back) at the spec's periods — drives and
controllers every 1 ms, manip/a.cs every 2 ms, grip/a.cs every 10 ms — and passes
each message on with the delay the runtime gives it: a subsystem reads what it
received at the end of its previous iteration (Figure 5).

Tracking bound (docs/simulation.md): during a joint-space move of the 6-joint arm
at the example's speeds, no joint is farther than TRACKING_BOUND from the reference
the regulator is given; after the move every joint settles within
manip.JOINT_TOLERANCE.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples" / "pick_and_place"))

from pick_and_place import grip, manip, motor, motor_controller, scene
from pick_and_place.environment import PickAndPlaceEnvironment
from pick_and_place.kinematics import tool_down_orientation
from pick_and_place.store import state_of

from earl.sim import arm
from test_pick_and_place_units import Inputs, Msg, Outputs, command, context, msg

#: radians: the largest joint tracking error allowed during a joint-space move
TRACKING_BOUND = 0.005


class Bench:
    """The manipulator's and the gripper's subsystems, stepped on the plant in virtual time."""

    def __init__(self, environment: PickAndPlaceEnvironment) -> None:
        self.env = environment
        self.plant = environment.plant
        self.n = n = environment.n
        self.now_ms = 0
        # the latest message on every link ...
        self.to_controller = {k: Msg(desiredWindingCurrent=0.0, emergencyStopCommand=False) for k in range(1, n + 2)}
        self.to_drive = {k: Msg(windingCurrent=0.0) for k in range(1, n + 2)}
        self.to_controller_from_drive = {k: Msg(motorPos=0.0, driverFault=False) for k in range(1, n + 2)}
        self.to_cs = {k: Msg(currentMotorPos=0.0, emergencyStop=False) for k in range(1, n + 2)}
        # ... and what each subsystem received at the end of its last iteration
        self.received: dict[str, Any] = {}
        self.receive_all()
        self.controller_memory = {k: {"windingCurrent": 0.0, "currentMotorPos": 0.0} for k in range(1, n + 2)}
        self.cs_memory: dict[str, Any] = {
            "motionFinished": True,
            "currentJointPos": (0.0,) * n,
            "currentOperationalPos": Msg(position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0)),
            "windingCurrent": {k: 0.0 for k in range(1, n + 1)},
            "emergencyStopCommand": {k: False for k in range(1, n + 1)},
        }
        self.cs_state, self.cs_iteration = "idle", 0
        self.command: Msg = command()
        self.grip_memory: dict[str, Any] = {
            "desiredFingerPos": arm.INITIAL_OPENING,
            "currentFingerPos": arm.INITIAL_OPENING,
            "windingCurrent": 0.0,
            "motionFinished": True,
            "objectGrasped": False,
        }
        self.grip_state, self.grip_iteration = "idle", 0
        self.gripper_command: Msg | None = None

    def receive_all(self) -> None:
        self.received = {
            "controller": dict(self.to_controller),
            "drive": dict(self.to_drive),
            "encoder": dict(self.to_controller_from_drive),
            "cs": dict(self.to_cs),
        }

    def _context(self, subsystem: str, period: float, iteration: int = 0, **parameters: int) -> Any:
        return context(
            subsystem=subsystem,
            period=period,
            time=self.now_ms / 1000.0,
            iteration=iteration,
            environment=self.env,
            parameters={"N": self.n, **parameters},
        )

    # ------------------------------------------------------------ one millisecond

    def tick(self) -> None:
        n, t = self.n, self.now_ms
        self.plant.advance(t / 1000.0)
        finger = n + 1
        for k in range(1, n + 2):  # drives
            # named as the run names them: the environment maps the drives by name (map_actuator)
            drive = "grip/a.fingerDrive/re" if k == finger else f"manip/a.motor[{k}]/re"
            ctx = self._context(drive, 0.001, joint=k, K=k)
            out = Outputs("appliedCurrent")
            inputs = Inputs(motorCommand=self.received["drive"][k])
            (motor.apply_finger_current if k == finger else motor.apply_current)(inputs, out, ctx)
            reading = Outputs("encoderReading")
            (motor.read_finger_encoder if k == finger else motor.read_encoder)(Inputs(), reading, ctx)
            self.to_controller_from_drive[k] = msg(reading.written["encoderReading"])
        for k in range(1, n + 2):  # motor controllers
            ctx = self._context(f"controller{k}", 0.001, joint=k) if k != finger else self._context("finger", 0.001)
            out = Outputs("windingCurrent", "currentMotorPos")
            if k == finger:
                inputs = Inputs(
                    fingerCommand=self.received["controller"][k], encoderReading=self.received["encoder"][k]
                )
                motor_controller.regulate_finger(inputs, out, ctx)
            else:
                inputs = Inputs(
                    motorControllerCommand=self.received["controller"][k], encoderReading=self.received["encoder"][k]
                )
                motor_controller.regulate(inputs, out, ctx)
            self.controller_memory[k].update(out.written)
            command_out = Outputs("motorCommand")
            motor_controller.output_motor_command(
                Inputs(windingCurrent=self.controller_memory[k]["windingCurrent"]), command_out, ctx
            )
            self.to_drive[k] = msg(command_out.written["motorCommand"])
            # as in the spec: the finger controller reports on fingerState, a joint's on motorControllerState
            state = "fingerState" if k == finger else "motorControllerState"
            state_out = Outputs(state)
            motor_controller.output_state(
                Inputs(currentMotorPos=self.controller_memory[k]["currentMotorPos"], emergencyStop=False),
                state_out,
                ctx,
            )
            self.to_cs[k] = msg(state_out.written[state])
        if t % 2 == 0:
            self._manipulator()
        if t % 10 == 0:
            self._gripper()
        self.receive_all()
        self.now_ms += 1

    def _manipulator(self) -> None:
        n = self.n
        states = {k: self.received["cs"][k] for k in range(1, n + 1)}
        ctx = self._context("manip/a.cs", 0.002, self.cs_iteration)
        memory = self.cs_memory
        position = Outputs("currentJointPos", "currentOperationalPos")
        manip.calculate_position(Inputs(motorControllerState=states), position, ctx)
        move = Outputs("motionFinished", families={"windingCurrent": n})
        if self.cs_state == "jointMove":
            manip.joint_move(
                Inputs(
                    manipulatorCommand=self.command,
                    motorControllerState=states,
                    currentJointPos=memory["currentJointPos"],
                ),
                move,
                ctx,
            )
        elif self.cs_state == "operationalMove":
            manip.operational_move(
                Inputs(
                    manipulatorCommand=self.command,
                    motorControllerState=states,
                    currentOperationalPos=memory["currentOperationalPos"],
                ),
                move,
                ctx,
            )
        else:
            manip.passive_regulation(Inputs(motorControllerState=states), move, ctx)
        memory.update({k: msg(v) for k, v in position.written.items()})
        memory["windingCurrent"].update(move.written["windingCurrent"])
        memory["motionFinished"] = move.written.get("motionFinished", memory["motionFinished"])
        commands = Outputs(families={"motorControllerCommand": n})
        manip.output_motor_con(
            Inputs(
                windingCurrent=dict(memory["windingCurrent"]), emergencyStopCommand=dict(memory["emergencyStopCommand"])
            ),
            commands,
            ctx,
        )
        for k, value in commands.written["motorControllerCommand"].items():
            self.to_controller[k] = msg(value)
        self.cs_iteration += 1
        if self.cs_state != "idle" and memory["motionFinished"]:
            self.cs_state, self.cs_iteration = "idle", 0

    def _gripper(self) -> None:
        finger = self.n + 1
        state = self.received["cs"][finger]
        memory = self.grip_memory
        ctx = self._context("grip/a.cs", 0.01, self.grip_iteration)
        if self.grip_state == "move":
            out = Outputs("desiredFingerPos", "currentFingerPos", "windingCurrent", "motionFinished", "objectGrasped")
            grip.move_fingers(Inputs(gripperCommand=self.gripper_command, fingerState=state), out, ctx)
        else:
            out = Outputs("currentFingerPos", "windingCurrent", "objectGrasped")
            grip.hold_fingers(Inputs(fingerState=state, desiredFingerPos=memory["desiredFingerPos"]), out, ctx)
        memory.update(out.written)
        command_out = Outputs("fingerCommand")
        grip.output_finger_command(Inputs(windingCurrent=memory["windingCurrent"]), command_out, ctx)
        self.to_controller[finger] = msg(command_out.written["fingerCommand"])
        self.grip_iteration += 1
        if self.grip_state == "move" and memory["motionFinished"]:
            self.grip_state, self.grip_iteration = "idle", 0

    # ------------------------------------------------------------ what a test asks

    def send(self, manipulator_command: Msg) -> None:
        self.command = manipulator_command
        self.cs_state = "jointMove" if manipulator_command.jointPosSetpoint is not None else "operationalMove"
        self.cs_iteration = 0
        self.cs_memory["motionFinished"] = False

    def send_gripper(self, opening: float) -> None:
        self.gripper_command = Msg(desiredFingerPos=opening)
        self.grip_state, self.grip_iteration = "move", 0

    def joints(self) -> np.ndarray:
        return np.array([self.plant.joint_position(arm.joint_name(k)) for k in range(1, self.n + 1)])


def test_the_arm_tracks_a_joint_space_move_within_the_documented_bound() -> None:
    n = 6
    bench = Bench(PickAndPlaceEnvironment(n, seed=1))
    for _ in range(100):  # settle: passive regulation holds the parked arm
        bench.tick()
    start = bench.joints()
    goal = arm.tool_down_configuration(n, (0.25, 0.30, 0.16))
    bench.send(command(joints=goal))
    worst = 0.0
    for _ in range(4000):
        bench.tick()
        if bench.now_ms % 2 == 1:  # just after manip/a.cs ran: compare its reference with the arm
            controller = state_of(bench._context("manip/a.cs", 0.002))["controller"]
            worst = max(worst, float(np.max(np.abs(controller.reference - bench.joints()))))
        if bench.cs_state == "idle":
            break
    assert bench.cs_state == "idle", "the move never finished"
    assert float(np.max(np.abs(bench.joints() - goal))) < manip.JOINT_TOLERANCE + 1e-3
    assert float(np.max(np.abs(goal - start))) > 0.5  # a real move
    print(f"largest joint tracking error: {worst:.5f} rad")
    assert worst < TRACKING_BOUND, f"tracking error {worst:.4f} rad"


def test_the_grasp_holds_the_box_while_lifting() -> None:
    n = 6
    grasp_point = (*scene.BOX_XY, scene.GRASP_HEIGHT)
    environment = PickAndPlaceEnvironment(n, seed=2, start=arm.tool_down_configuration(n, grasp_point))
    bench = Bench(environment)
    for _ in range(50):
        bench.tick()
    bench.send_gripper(scene.CLOSED)
    for _ in range(1000):
        bench.tick()
        if bench.grip_state == "idle" and bench.now_ms > 100:
            break
    assert bench.grip_memory["objectGrasped"], "the fingers did not stop on the box"
    assert bench.grip_memory["currentFingerPos"] == pytest.approx(2 * arm.BOX_HALF_SIZE, abs=1e-3)
    box = np.array(bench.plant.body_pose(arm.BOX_BODY).position)
    site = np.array(bench.plant.site_pose(arm.GRASP_SITE).position)
    held = box - site
    lifted = (*scene.BOX_XY, scene.CARRY_HEIGHT)
    bench.send(command(pose=Msg(position=lifted, orientation=tuple(tool_down_orientation(0.0)))))
    for _ in range(3000):
        bench.tick()
        if bench.cs_state == "idle":
            break
    box = np.array(bench.plant.body_pose(arm.BOX_BODY).position)
    site = np.array(bench.plant.site_pose(arm.GRASP_SITE).position)
    assert site[2] == pytest.approx(scene.CARRY_HEIGHT, abs=0.004)
    assert box[2] > arm.BOX_HALF_SIZE + 0.10  # off the table by more than 10 cm
    assert np.linalg.norm((box - site) - held) < 0.003  # it did not slip in the fingers
