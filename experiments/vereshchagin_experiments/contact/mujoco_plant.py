"""The plant: a MuJoCo model of the Kinova Gen3 (or a tree of Gen3 arms) built from our own URDF, at 1 kHz.

:func:`build_model` compiles the URDF of :func:`vereshchagin.robots.gen3_urdf` (rigid Robotiq
2F-85) with MuJoCo's URDF reader, so the plant and the controller's :class:`vereshchagin.Chain`
come from the same text: same masses, centres of mass, inertias and frames (the gripper's fixed
links are fused into ``bracelet_link`` by both). Then it adds

- joint friction ``frictionloss`` and viscous ``damping`` from the URDF ``<dynamics>`` tags
  (MuJoCo reads them: friction -> frictionloss, damping -> damping), ``armature`` = the chain's
  rotor inertia (0 for the Gen3: Kinova gives none);
- one torque motor per joint (gear 1, ``ctrlrange`` = +-effort limit: 39 N m joints 0-3,
  9 N m joints 4-6, counted from 0);
- a table (box; top at ``Scene.table_top``), optionally an elbow support (box) and a pen held in
  the gripper (capsule, pointing down at the start pose);
- a collision sphere around each elbow actuator (joint 3 counted from 0 as in the report; every
  body named ``*forearm_link``), radius 0.055 m;
- names for the URDF's unnamed collision geoms: ``gripper`` for the gripper's box, the link's
  name for the others.

A tree robot (:func:`vereshchagin.robots.dual_gen3_urdf` with a :class:`vereshchagin.Tree`) is
built the same way: one motor per joint in the tree's joint order, contact geoms on every arm.

Collision filtering: the arm's rough primitives (URDF cylinders, the gripper box, pen, elbow
sphere) have ``contype`` 1 / ``conaffinity`` 0 and the environment 0 / 1, so the arm touches the
table and the support but never itself. Contact friction (sliding) is ``Scene.friction``
(default 0.3, paper / plastic on wood), torsional 0.005, rolling 1e-4; MuJoCo's default soft
contact (solref 0.02 s, damping ratio 1). Time step 1 ms, ``implicitfast`` integrator, gravity
-9.81 m/s^2 along z.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import mujoco
import numpy as np

from vereshchagin import Chain
from .robot_interface import JointState

__all__ = ["MujocoGen3", "Scene", "build_model"]

ARM, ENV = 1, 2  # geom groups (for visual filtering)
ELBOW_RADIUS = 0.055  # m, the joint-4 actuator housing
PEN_GRIP = 0.10  # m along the end-effector z axis: where the fingers hold the pen
PEN_LENGTH = 0.12  # m from the grip to the tip
PEN_RADIUS = 0.005  # m


@dataclass(frozen=True)
class Scene:
    """What surrounds the arm (m, base frame; the arm's base is at the origin).

    Attributes
    ----------
    table_top : float or None
        Height of the table's top surface; None: no table.
    table_x, table_y : (float, float)
        Extent of the table top.
    support : tuple or None
        ``(center (3,), half_sizes (3,))`` of a box the elbow can rest on; None: no support.
    pen_direction : array_like (3,) or None
        Unit direction of a pen in the end-effector frame (None: no pen).
    friction : float
        Sliding friction coefficient of every contact.
    """

    table_top: Optional[float] = None
    table_x: tuple = (0.30, 1.00)
    table_y: tuple = (-0.45, 0.45)
    support: Optional[tuple] = None
    pen_direction: Optional[tuple] = None
    friction: float = 0.3


def pen_tip(direction) -> np.ndarray:
    """Pen tip position in the end-effector frame (m) for a pen along unit ``direction``."""
    d = np.asarray(direction, float)
    return np.array([0.0, 0.0, PEN_GRIP]) + PEN_LENGTH * d / np.linalg.norm(d)


def _pose_of_body(m, d, body: str) -> np.ndarray:
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body)
    T = np.eye(4)
    T[:3, :3] = d.xmat[i].reshape(3, 3)
    T[:3, 3] = d.xpos[i]
    return T


def _quat(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).reshape(-1))
    return q


def _add_pen(spec, chain, direction, fr) -> None:
    """A massless capsule held by the gripper along ``direction`` (end-effector frame)."""
    # End-effector frame in the bracelet body (the URDF's fixed joints are fused into it).
    probe = spec.compile()
    pd = mujoco.MjData(probe)
    mujoco.mj_kinematics(probe, pd)
    T_b_ee = np.linalg.inv(_pose_of_body(probe, pd, "bracelet_link")) @ np.asarray(chain.fk(np.zeros(chain.n_joints)))

    def in_bracelet(p_ee):
        return (T_b_ee @ np.append(p_ee, 1.0))[:3]

    grip = in_bracelet([0.0, 0.0, PEN_GRIP])
    tip = in_bracelet(pen_tip(direction))
    spec.body("bracelet_link").add_geom(
        name="pen",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        size=[PEN_RADIUS, 0, 0],
        fromto=np.concatenate([grip, tip]),
        contype=1,
        conaffinity=0,
        group=ARM,
        friction=fr,
        mass=0.0,
        rgba=[0.1, 0.1, 0.8, 1],
    )


def _name_arm_geoms(spec) -> None:
    """Name the URDF's unnamed collision geoms after what they are (the logs list who touches the table).

    The gripper's box (on ``*robotiq_85_base_link``) becomes ``*gripper``; any other geom takes its
    link's name (``forearm_link``, ...), with ``_2``, ``_3`` ... when a link holds several.
    """
    for body in spec.bodies:
        unnamed = [g for g in body.geoms if not g.name]
        for k, g in enumerate(unnamed):
            base = body.name
            if g.type == mujoco.mjtGeom.mjGEOM_BOX and base.endswith("robotiq_85_base_link"):
                base = base.removesuffix("robotiq_85_base_link") + "gripper"
            g.name = base if k == 0 else f"{base}_{k + 1}"


def build_model(urdf: str, chain, scene: Scene = Scene()) -> mujoco.MjModel:
    """Compile the plant (see module doc).

    Parameters
    ----------
    urdf : str
        URDF text of the robot: the Gen3 (from :func:`vereshchagin.robots.gen3_urdf`,
        ``gripper=True``) or a tree of Gen3 arms such as
        :func:`vereshchagin.robots.dual_gen3_urdf`.
    chain : Chain or Tree
        The controller's model from the same URDF: its joint order is the plant's (checked), its
        effort limits the motors' ranges, its rotor inertia the armature; a chain also
        gives the end-effector frame for the pen.
    scene : Scene
        A pen (``pen_direction``) needs a :class:`~vereshchagin.Chain`.

    Raises
    ------
    ValueError
        If MuJoCo orders the joints differently from ``chain``, or a pen is asked for on a tree.
    """
    spec = mujoco.MjSpec.from_string(urdf)
    spec.option.timestep = 1e-3
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0.0, 0.0, -9.81]
    fr = [scene.friction, 0.005, 1e-4]
    for g in spec.geoms:
        g.contype, g.conaffinity, g.group, g.friction = 1, 0, ARM, fr
    _name_arm_geoms(spec)
    joints = list(chain.joint_names)
    rotor = np.asarray(chain.rotor_inertia, float)
    for k, name in enumerate(joints):
        joint = spec.joint(name)
        joint.armature = float(rotor[k])
        # Dry friction as hard as the 1 ms step allows (time constant 2 dt, impedance ~1).
        joint.solref_friction = [2e-3, 1.0]
        joint.solimp_friction = [0.99, 0.999, 1e-3, 0.5, 2.0]
        lim = float(chain.effort_limit[k])
        spec.add_actuator(
            name=f"motor_{k + 1}",
            target=name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            ctrlrange=[-lim, lim],
        )
    if scene.pen_direction is not None:
        if not isinstance(chain, Chain):
            raise ValueError("a pen (scene.pen_direction) needs a Chain: its end-effector frame holds the pen")
        _add_pen(spec, chain, scene.pen_direction, fr)
    for body in spec.bodies:
        if body.name.endswith("forearm_link"):
            body.add_geom(
                name=body.name.removesuffix("forearm_link") + "elbow",
                type=mujoco.mjtGeom.mjGEOM_SPHERE,
                size=[ELBOW_RADIUS, 0, 0],
                pos=[0, 0, 0],
                contype=1,
                conaffinity=0,
                group=ARM,
                friction=fr,
                mass=0.0,
            )
    world = spec.worldbody
    if scene.table_top is not None:
        (x0, x1), (y0, y1) = scene.table_x, scene.table_y
        world.add_geom(
            name="table",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[(x1 - x0) / 2, (y1 - y0) / 2, 0.02],
            pos=[(x0 + x1) / 2, (y0 + y1) / 2, scene.table_top - 0.02],
            contype=0,
            conaffinity=1,
            group=ENV,
            friction=fr,
            rgba=[0.6, 0.45, 0.3, 1],
        )
    if scene.support is not None:
        center, half = scene.support
        world.add_geom(
            name="support",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=list(half),
            pos=list(center),
            contype=0,
            conaffinity=1,
            group=ENV,
            friction=fr,
            rgba=[0.3, 0.5, 0.3, 1],
        )
    model = spec.compile()
    order = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    if order != joints:
        raise ValueError(f"MuJoCo orders the joints {order}, the controller's model {joints}")
    return model


class MujocoGen3:
    """:class:`~.robot_interface.RobotInterface` backed by a MuJoCo simulation at 1 kHz.

    Parameters
    ----------
    model : mujoco.MjModel
        From :func:`build_model`.
    q0 : array_like, shape (n,)
        Initial joint positions (rad), at rest.

    Attributes
    ----------
    model : mujoco.MjModel
        The compiled plant.
    data : mujoco.MjData
        The simulation state (``qpos``, ``qvel``, ``ctrl``, ``time``, contacts).
    n_joints : int
        Number of actuated joints (one torque motor each).
    period : float
        Control period = simulation time step (s).
    gripper : float
        Last gripper command, 0 (open) .. 1 (closed); recorded only (the gripper is rigid).
    """

    def __init__(self, model: mujoco.MjModel, q0):
        self.model = model
        self.data = mujoco.MjData(model)
        self.n_joints = model.nu
        self.period = float(model.opt.timestep)
        self.data.qpos[:] = np.asarray(q0, float)
        self.gripper = 0.0
        mujoco.mj_forward(model, self.data)
        self._env: dict[int, str] = {}  # environment geom id -> name
        for name in ("table", "support"):
            gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
            if gid >= 0:
                self._env[gid] = name
        self._f6 = np.zeros(6)
        self._frictionloss = model.dof_frictionloss[: self.n_joints].copy()

    def read(self) -> JointState:
        """The simulation's current joint sample.

        Returns
        -------
        JointState
            ``q`` (rad), ``qd`` (rad/s), ``tau`` the motor torques applied in the last step after
            saturation at the ``ctrlrange`` (N m), ``time`` the simulation clock (s); copies.
        """
        d = self.data
        return JointState(q=d.qpos.copy(), qd=d.qvel.copy(), tau=d.actuator_force.copy(), time=float(d.time))

    def write(self, tau) -> None:
        """Command joint torques for the next step (MuJoCo clips them to +-effort limit).

        Parameters
        ----------
        tau : array_like, shape (n,)
            Motor torques (N m, positive along each joint's axis).

        Raises
        ------
        ValueError
            If ``tau`` has another shape or a non-finite entry.
        """
        tau = np.asarray(tau, float)
        if tau.shape != (self.n_joints,) or not np.all(np.isfinite(tau)):
            raise ValueError(f"torque command must be {self.n_joints} finite values, got {tau!r}")
        self.data.ctrl[:] = tau

    def wait(self) -> None:
        """Advance the physics by one period (one ``mj_step`` of ``period`` s)."""
        mujoco.mj_step(self.model, self.data)

    def set_gripper(self, position: float) -> None:
        """Record a gripper command (the gripper is rigid: no motion).

        Parameters
        ----------
        position : float
            0 (open) .. 1 (closed); clipped to that range.
        """
        self.gripper = float(np.clip(position, 0.0, 1.0))  # rigid gripper: recorded only

    # -- simulator-only diagnostics ------------------------------------------------------------
    def contact_forces(self) -> dict:
        """Normal force (N) on each environment geom (``"table"``, ``"support"``) and which arm geoms touch it.

        Returns
        -------
        dict
            ``{name: (normal force, set of arm geom names)}`` for environment geoms in contact.
        """
        m, d = self.model, self.data
        out: dict[str, tuple[float, set[str]]] = {}
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            env = self._env.get(g1, self._env.get(g2))
            if env is None:
                continue
            arm = g2 if g1 in self._env else g1
            mujoco.mj_contactForce(m, d, i, self._f6)
            force, who = out.get(env, (0.0, set()))
            who.add(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, arm) or f"geom{arm}")
            out[env] = (force + float(self._f6[0]), who)
        return out

    def joint_friction_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The plant's dry joint friction at the last step: who sticks, and its torque.

        Returns
        -------
        stick : ndarray of bool, shape (n,)
            Joint j's friction torque stayed inside its bound, |torque| < (1 - 1e-3) f_j: friction
            held the joint (a sliding joint gets exactly f_j). False for joints without friction.
            (MuJoCo's ``efc_state`` of ``frictionloss`` rows is no stick flag: held joints with
            |torque| well below f_j are often labelled linear.)
        torque : ndarray, shape (n,)
            Friction torque on each joint (N m, acting on the joint like a motor torque; MuJoCo's
            ``efc_force`` of the joint's ``frictionloss`` row).
        """
        d = self.data
        torque = np.zeros(self.n_joints)
        rows = slice(d.ne, d.ne + d.nf)  # MuJoCo orders the rows: equality, friction, limits, contacts
        dof = d.efc_id[rows]
        mine = d.efc_type[rows] == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF
        torque[dof[mine]] = d.efc_force[rows][mine]
        bound = self._frictionloss
        stick = (bound > 0.0) & (np.abs(torque) < (1.0 - 1e-3) * bound)
        return stick, torque

    def mass_matrix(self, q) -> np.ndarray:
        """Joint-space mass matrix (n, n) at ``q`` (MuJoCo's ``mj_fullM``, armature included)."""
        d = mujoco.MjData(self.model)
        d.qpos[:] = np.asarray(q, float)
        mujoco.mj_forward(self.model, d)
        M = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, d, M)
        return M
