"""The controller's own model of the robot, built from the robot's MJCF (not from the plant).

A real controller does not look inside the world it acts on: it knows the robot from
its description and its drives' datasheets.  So `RobotModel` loads
`earl.sim.arm.robot_mjcf(N)` — the arm and gripper alone, no table, no box — into a
MuJoCo model of its own and uses it for forward kinematics, Jacobians (inverse
kinematics by damped least squares) and inverse dynamics (gravity and inertia
feed-forward).  Only measured joint positions and set-points ever go into it.

With a levelling wrist (N < 5) two passive joints follow the shoulder and the elbow;
the coupling matrix `C` (nv × N) maps motor joint velocities to all of the model's
joint velocities, so Jacobians are `J·C` and torques are `Cᵀ·τ`.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import mujoco
import numpy as np
from numpy.typing import NDArray

from earl.sim import arm

Vector = NDArray[np.float64]

#: weight of one radian of orientation error against one metre of position error in IK
ORIENTATION_WEIGHT = 0.2
#: how fast a redundant arm's null-space motion returns the posture (fraction per IK step)
POSTURE_GAIN = 0.05
#: multiplies a unit quaternion (w, x, y, z) into its conjugate, the inverse rotation
_CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])
_WEIGHTS = np.array([1.0, 1.0, 1.0, ORIENTATION_WEIGHT, ORIENTATION_WEIGHT, ORIENTATION_WEIGHT])


class Pose(NamedTuple):
    position: Vector
    #: unit quaternion w, x, y, z
    orientation: Vector


class RobotModel:
    """Kinematics and dynamics of the N-joint arm, for one controller."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.model = mujoco.MjModel.from_xml_string(arm.robot_mjcf(n))
        # the controller's model never collides: it is only for kinematics and dynamics
        self.model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        self.data = mujoco.MjData(self.model)
        self.drives = arm.drives(n)
        self.gear = np.array([d.gear_ratio for d in self.drives])
        self.torque_per_ampere = np.array([d.torque_per_ampere for d in self.drives])
        self.current_limit = np.array([d.current_limit for d in self.drives])
        self.site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, arm.GRASP_SITE)
        self.coupling = self._coupling()
        low = np.array([self.model.jnt_range[self._joint(k)][0] for k in range(1, n + 1)])
        high = np.array([self.model.jnt_range[self._joint(k)][1] for k in range(1, n + 1)])
        self.lower, self.upper = low, high
        #: the roll joints' preferred position; the others are free (used only by a redundant arm)
        self.posture = np.zeros(n)
        self.roll_joints = np.array([1.0 if kind == "roll" else 0.0 for kind in arm.joint_layout(n)])
        self._configured: tuple[float, ...] | None = None
        self._dynamics = False
        self._bias = np.zeros(self.model.nv)
        self._identity = np.eye(n)
        # Views and copies made once: each `data.qpos` or `model.dof_damping` makes a new view, and
        # these run several times an iteration.
        self._qpos = self.data.qpos
        self._qvel = self.data.qvel
        self._site_position = self.data.site_xpos[self.site]
        self._site_rotation = self.data.site_xmat[self.site]
        self._damping = self.model.dof_damping.copy()
        self._coupling_transposed = np.ascontiguousarray(self.coupling.T)
        self._jacobian = np.empty((6, self.model.nv))

    def _joint(self, k: int) -> int:
        return int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, arm.joint_name(k)))

    def _coupling(self) -> Vector:
        """C: every degree of freedom as a linear function of the N motor joints."""
        m = self.model
        coupling = np.zeros((m.nv, self.n))
        column_of_dof = {}
        for k in range(1, self.n + 1):
            dof = int(m.jnt_dofadr[self._joint(k)])
            coupling[dof, k - 1] = 1.0
            column_of_dof[dof] = k - 1
        for e in range(m.neq):
            if m.eq_type[e] != mujoco.mjtEq.mjEQ_JOINT:
                continue
            follower = int(m.jnt_dofadr[m.eq_obj1id[e]])
            leader = int(m.jnt_dofadr[m.eq_obj2id[e]])
            if leader in column_of_dof:
                coupling[follower, column_of_dof[leader]] = float(m.eq_data[e][1])
        return coupling

    # ------------------------------------------------------------ kinematics

    def motor_to_joint(self, motor_positions: Vector) -> Vector:
        joints: Vector = np.asarray(motor_positions, dtype=float) / self.gear
        return joints

    def joint_to_motor(self, joint_positions: Vector) -> Vector:
        motors: Vector = np.asarray(joint_positions, dtype=float) * self.gear
        return motors

    def _configure(self, q: Vector, qd: Vector | None = None) -> None:
        """Positions (and, given velocities, everything dynamics needs) for the joints at `q`."""
        dynamics = qd is not None
        # Python floats (tolist), not NumPy scalars: building and comparing the key is then cheap
        key = tuple(q.tolist() + qd.tolist()) if qd is not None else tuple(q.tolist())
        if key == self._configured and (self._dynamics or not dynamics):
            return
        m, d = self.model, self.data
        self._qpos[:] = self.coupling @ q
        if qd is None:
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
        else:
            # only what inverse dynamics needs: the mass matrix and the bias forces (no constraints)
            self._qvel[:] = self.coupling @ qd
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            mujoco.mj_crb(m, d)
            mujoco.mj_comVel(m, d)
            mujoco.mj_rne(m, d, 0, self._bias)
        self._configured = key
        self._dynamics = dynamics

    def forward(self, q: Vector) -> Pose:
        """The grasp point's pose with the joints at `q`."""
        self._configure(np.asarray(q, dtype=float))
        quaternion = np.empty(4)
        mujoco.mju_mat2Quat(quaternion, self._site_rotation)
        return Pose(self._site_position.copy(), quaternion)

    def jacobian(self, q: Vector) -> Vector:
        """6 × N: the grasp point's linear and angular velocity per motor joint velocity."""
        self._configure(np.asarray(q, dtype=float))
        # MuJoCo writes the linear rows and the angular rows straight into one 6 × nv array
        full = self._jacobian
        mujoco.mj_jacSite(self.model, self.data, full[:3], full[3:], self.site)
        result: Vector = full @ self.coupling
        return result

    def pose_error(self, target: Pose, q: Vector) -> Vector:
        """[position error; rotation vector taking the current orientation to the target], world frame."""
        current = self.forward(q)
        conjugate = current.orientation * _CONJUGATE
        difference = np.empty(4)
        mujoco.mju_mulQuat(difference, target.orientation, conjugate)
        rotation = np.empty(3)
        mujoco.mju_quat2Vel(rotation, difference, 1.0)
        return np.concatenate([target.position - current.position, rotation])

    def inverse_kinematics(
        self, target: Pose, q: Vector, iterations: int = 3, damping: float = 0.02, max_step: float = 0.2
    ) -> Vector:
        """Damped least squares from `q` towards `target`: at most `iterations` steps.

        Each step solves (JᵀWJ + λ²I) Δq = JᵀW e; the damping keeps steps bounded near
        singular configurations, and starting from the previous solution keeps a
        redundant arm (N = 7) from wandering; for that arm a second task, projected into
        the Jacobian's null space, turns the roll joints back towards zero.
        """
        q = np.asarray(q, dtype=float).copy()
        for _ in range(iterations):
            error = self.pose_error(target, q) * _WEIGHTS
            if float(error @ error) < 1e-14:
                break
            jac = self.jacobian(q) * _WEIGHTS[:, None]
            step = _solve_positive_definite(jac.T @ jac + damping**2 * self._identity, jac.T @ error)
            if self.n > 6:
                # a redundant arm: in the Jacobian's null space, turn the roll joints back towards zero
                null_space = np.eye(self.n) - np.linalg.pinv(jac, rcond=1e-3) @ jac
                step += null_space @ (POSTURE_GAIN * self.roll_joints * (self.posture - q))
            largest = float(np.abs(step).max())
            if largest > max_step:
                step *= max_step / largest
            q = np.minimum(np.maximum(q + step, self.lower), self.upper)  # np.clip, without its overhead
        return q

    # ------------------------------------------------------------ dynamics

    def inverse_dynamics(self, q: Vector, qd: Vector, qdd: Vector) -> Vector:
        """Joint torques for the motion (q, q̇, q̈) of the robot alone: M·q̈ + bias + viscous friction."""
        q = np.asarray(q, dtype=float)
        qd = np.asarray(qd, dtype=float)
        self._configure(q, qd)
        d = self.data
        acceleration = np.empty(self.model.nv)
        mujoco.mj_mulM(self.model, d, acceleration, self.coupling @ np.asarray(qdd, dtype=float))
        friction = self._damping * (self.coupling @ qd)
        torques: Vector = self._coupling_transposed @ (acceleration + self._bias + friction)
        return torques

    def joint_inertia(self, q: Vector) -> Vector:
        """Each motor joint's inertia at `q` as its regulator feels it: 1 / (M⁻¹)ₖₖ, rotor included.

        With the other joints free to move, a joint feels less than Mₖₖ where the arm's
        inertias are coupled (the N = 7 arm's base and upper-arm roll), so gains placed on
        this value do not push the coupled modes too high.
        """
        q = np.asarray(q, dtype=float)
        self._configure(q, np.zeros_like(q))
        full = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, self.data, full)
        reduced = self.coupling.T @ full @ self.coupling
        inertia: Vector = 1.0 / np.diag(np.linalg.inv(reduced))
        return inertia


@functools.cache
def robot_model(n: int) -> RobotModel:
    """One model per N, shared by the functions of a run (they run one at a time)."""
    return RobotModel(n)


def tool_down_orientation(yaw: float) -> Vector:
    """Rz(yaw)·Ry(π) as a quaternion: the gripper pointing down, fingers closing radially."""
    half = yaw / 2.0
    # Rz(yaw) = (cos h, 0, 0, sin h); Ry(π) = (0, 0, 1, 0); their product:
    return np.array([0.0, -math.sin(half), math.cos(half), 0.0])


def _solve_positive_definite(matrix: Vector, vector: Vector) -> Vector:
    """x with matrix·x = vector, for a symmetric positive definite matrix (JᵀWJ + λ²I is one).

    MuJoCo's own Cholesky factorisation: on a 6 × 6 system it takes a tenth of
    np.linalg.solve's time, most of which is argument handling.
    """
    factor = np.array(matrix, dtype=float, order="C")  # a copy: it is factorised in place
    mujoco.mju_cholFactor(factor, 0.0)
    solution = np.empty(len(vector))
    mujoco.mju_cholSolve(solution, factor, np.ascontiguousarray(vector, dtype=float))
    return solution
