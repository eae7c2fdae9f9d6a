"""Dual-arm use case (issue 17): one hand rests on a table while the other slides, on a tree robot.

Robot: :func:`vereshchagin.robots.dual_gen3_urdf`, two Gen3 arms (rigid grippers) on a torso that
turns about the vertical, 15 joints, the arms' joint friction and damping of
:data:`~.use_cases.JOINT_FRICTION` / :data:`~.use_cases.JOINT_DAMPING`, the torso's of
:data:`vereshchagin.robots.TORSO`. Both arms start at :data:`vereshchagin.robots.GEN3_START_POSE`
(torso at 0): each gripper points forward (+x), about 0.46 m in front of its shoulder.

Task (base frame, m):

- the **left hand rests**: a 6-D segment constraint on :data:`REST_FRAME`, a frame fixed to the
  left gripper at the middle of its box's lowest edge (where it touches the table), holds the
  start pose (cascaded P of :mod:`.controller`, in the discrete-time mode of :data:`CONFIG`,
  which lets joint friction hold the resting arm). Its third column
  (linear base z, the table normal) is the table's: when the solver's ``nu_z < 0`` (the
  constraint pushes the hand up), the share ``-J_r^T e_z nu_z`` of the command is left to the
  table, as the ``constraint`` variant of :mod:`.elbow` does for the elbow;
- the **right hand slides** 0.10 m along +x in the air, all six directions constrained at
  :data:`TASK_FRAME` (settle, slide, hold phases as in :mod:`.elbow`), free-space gains of
  :data:`~.controller.FREE_GAINS`, twist saturated at 0.05 m/s / 0.5 rad/s;
- 15 - 12 = 3 redundant DOF: the motor-side posture term ``K (q_ref - q) - D qd`` (K = 20, D = 3)
  acts only there (the solver realises both hands' tasks regardless).

Variants (:data:`VARIANTS`):

- ``table``: the tree solver, a table under the left gripper, the upward share left to it;
- ``unsupported``: the tree solver, no table, the motors hold the resting hand;
- ``separate``: the shortcut. Two :class:`vereshchagin.Chain` s, torso + left arm and torso +
  right arm, each from :func:`~vereshchagin.robots.dual_gen3_urdf` with ``torso_share = 0.5``
  (half the mass and inertia of the torso segment: the torso link and both arm base links;
  half the torso joint's friction and damping) and
  each solved with its own hand's constraint only (the left with the table share as in
  ``table``); the arm joints take their chain's torque, the torso joint the **sum** of the two
  chains' torso torques, and each chain gets half the torso's posture term. So the torso is
  counted once, but neither chain knows the other arm: the coupling through the torso (the
  other arm's inertia about the torso axis, its reaction on the torso) is what it ignores.

With the surfaces as the solver's contacts (:data:`CONTACT_VARIANT`, ``contacts``): the tree
solver, the same table, and the resting hand's point a support with the table's friction in the
solve (:mod:`.surfaces`) instead of the share removed by hand; the resting hand's task holds only
its orientation (:data:`REST_COLUMNS`), the table its position (normal force and static friction).
With the 6-D hold the support is redundant with the task and gets the forces of least motor
effort: the P loop's corrections then asked the held point to accelerate into the table, which
the solve rightly refuses ("no consistent contact forces"). Holding x and y as well (5 columns)
ran, but the least-effort share of the friction jumped from cycle to cycle (chatter 0.37 N m per
step at the torso and the left shoulder, against 0.12 with the orientation alone; both with the
hold band at the instant, before the discrete-time mode).

Open-loop task error (:func:`open_loop_error`): the torques a solve intends for every joint
(motors, the table's share, the joint friction the solve predicted, ``tau_ff`` with the viscous
damping) are applied to the true tree dynamics (the tree solver without constraints, i.e.
forward dynamics, checked against ``pin.aba`` in the tests) and the hands' spatial
accelerations are compared with the constraints' ``beta``: exact (round-off) for the tree
solver, the coupling error for the separate chains.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Union

import numpy as np

from vereshchagin import robots
from vereshchagin import Chain, Tree
from vereshchagin.friction import Friction
from vereshchagin import Solver
from vereshchagin.task import beta_for, pose_error
from .controller import CONTROL_PERIOD, ControllerConfig, CycleInfo, cascaded_acceleration
from .mujoco_plant import MujocoGen3, Scene, build_model
from .surfaces import SceneContacts, point_jacobian, tool_support
from .use_cases import (
    JOINT_DAMPING,
    JOINT_FRICTION,
    SLIDE,
    Phase,
    _gripper_low_point,
    _shifted,
    run_loop,
    with_tool_link,
)

__all__ = [
    "REST_FRAME",
    "TASK_FRAME",
    "VARIANTS",
    "BAND_CONFIG",
    "CONFIG",
    "FRICTION_MODES",
    "DualArmController",
    "dual_arm",
    "dual_arm_model",
    "open_loop_error",
]

VARIANTS = ("table", "unsupported", "separate")
CONTACT_VARIANT = "contacts"
"""The tree solver with the resting hand as the solver's contact (module doc)."""
FRICTION_MODES = ("maxmin", "none", "smooth")
"""``ControllerConfig.friction_mode`` s the dual-arm controller takes (see :data:`CONFIG`)."""
CONFIG = ControllerConfig(time_step=CONTROL_PERIOD)
"""The controller settings of the case: the exact max-min (``friction_mode="maxmin"``, joints with
|qd| <= 0.01 rad/s at rest) in the discrete-time mode: each cycle's friction-aware solve is posed
over the next 1 ms control period (``time_step``, :class:`~.controller.CascadedController`), so a
joint that friction keeps at rest gets the friction torque that holds it, continuous in the P
loop's corrections. At the instant the corrections give resting joints small commanded
accelerations whose sign changes almost every cycle; the max-min charges the full breakaway
friction against each (its ``f_j |qdd_j|`` term), so the command jumps by up to ``2 f_j`` per
cycle. :data:`BAND_CONFIG` is the earlier fix, kept as the report's "before"."""
BAND_CONFIG = ControllerConfig(hold_band=(1e-3, 1e-2))
"""Before the discrete-time mode: the solve at the instant and a hold band of 1 mm / 0.01 rad on
each hand's pose error, inside which that hand's task asks for zero acceleration ("stay")."""
REST_FRAME = "left_rest_point"
"""Frame of the resting hand: fixed to ``left_end_effector_link`` at the gripper box's lowest edge."""
TASK_FRAME = "right_end_effector_link"
"""Frame of the sliding hand (the Gen3 end-effector frame of the right arm)."""
UP = 2
"""Column of the resting hand's ``alpha`` (= I6) along the table normal (linear base z)."""
GRAVITY = np.array([0.0, 0.0, -9.81])
ALPHA = np.eye(6)
REST_COLUMNS = [3, 4, 5]
"""The resting hand's task columns in the ``contacts`` variant: its orientation (the table holds its position)."""


def start_pose() -> np.ndarray:
    """Joint positions (rad, shape (15,)) at the start: torso 0, both arms at the Gen3 start pose."""
    arm = np.array(robots.GEN3_START_POSE)
    return np.concatenate([[0.0], arm, arm])


def dual_arm_model(torso_share: float = 1.0) -> tuple[str, Tree]:
    """URDF text and tree of the dual-arm robot with :data:`REST_FRAME` added (module doc).

    Parameters
    ----------
    torso_share : float
        Passed to :func:`vereshchagin.robots.dual_gen3_urdf` (0.5: the half torso of each chain
        of the ``separate`` variant).

    Returns
    -------
    urdf : str
        URDF text (for the plant).
    tree : Tree
        15 joints, :data:`vereshchagin.robots.DUAL_GEN3_JOINT_NAMES`.
    """
    key = float(torso_share)
    if key not in _MODELS:
        _MODELS[key] = _model(key)
    return _MODELS[key]


_MODELS: dict[float, tuple[str, Tree]] = {}  # torso_share -> (urdf, tree), built once


def _model(torso_share: float) -> tuple[str, Tree]:
    urdf = robots.dual_gen3_urdf(JOINT_FRICTION, JOINT_DAMPING, torso_share=torso_share)
    tree = Tree.from_urdf(urdf)
    q0 = start_pose()
    probe = build_model(urdf, tree)
    T_ee = tree.fk(q0, "left_end_effector_link")
    low = _gripper_low_point(probe, q0, T_ee, body="left_bracelet_link")
    urdf = with_tool_link(urdf, REST_FRAME, [float(x) for x in low], parent="left_end_effector_link")
    return urdf, Tree.from_urdf(urdf)


@dataclass
class _Part:
    """One solve of the command: a model (the tree, or one chain of the shortcut) and where its joints go."""

    solver: Solver
    model: Union[Chain, Tree]
    idx: np.ndarray  # its joints' indices in the tree's q
    frames: tuple  # the hand frames it constrains
    torso_scale: np.ndarray  # factor on the posture term per joint (0.5 at a shared torso)
    friction: Optional[Friction]


def _part(model, tree: Tree, frames: tuple, config: ControllerConfig, shared_torso: bool) -> _Part:
    idx = np.array([tree.joint_index(j) for j in model.joint_names])
    scale = np.ones(len(idx))
    if shared_torso:
        scale[0] = 0.5
    friction = None
    if config.friction_mode == "maxmin":
        friction = Friction(static=np.asarray(model.friction), velocity_tolerance=config.friction_velocity_tolerance)
    return _Part(Solver(model, gravity=GRAVITY), model, idx, frames, scale, friction)


class DualArmController:
    """Cascaded P on both hands of the dual-arm tree, commanded by the tree solver or the shortcut.

    Parameters
    ----------
    tree : Tree
        From :func:`dual_arm_model` (the model the plant is built from).
    variant : {"table", "unsupported", "separate", "contacts"}
        See the module doc; ``table`` and ``separate`` leave the resting hand's upward share to
        the table.
    config : ControllerConfig, optional
        Free-space gains, twist saturation, posture gains, ``friction_mode`` (one of
        :data:`FRICTION_MODES`: ``"maxmin"`` the friction-aware solve, ``"none"`` a plain solve,
        ``"smooth"`` a plain solve plus ``f_j tanh(qd_j / eps)``), ``friction_velocity_tolerance``
        (``eps``, rad/s), ``time_step`` (the discrete-time mode) and ``hold_band`` (applied to
        each hand's pose error); the contact
        settings are unused. Default :data:`CONFIG`.

    Raises
    ------
    ValueError
        Unknown ``variant`` or ``config.friction_mode``.

    Attributes
    ----------
    goal : ndarray (4, 4) or None
        Goal pose of :data:`TASK_FRAME` (base frame, m).
    rest_goal : ndarray (4, 4) or None
        Pose :data:`REST_FRAME` holds: its pose at the first command.
    in_contact : bool
        Always False (the sliding hand is in the air); for :func:`~.use_cases.run_loop`.
    """

    def __init__(self, tree: Tree, variant: str, config: Optional[ControllerConfig] = None):
        config = CONFIG if config is None else config
        if variant not in VARIANTS + (CONTACT_VARIANT,):
            raise ValueError(f"variant must be one of {VARIANTS + (CONTACT_VARIANT,)}, got {variant!r}")
        if config.friction_mode not in FRICTION_MODES:
            raise ValueError(f"friction_mode must be one of {FRICTION_MODES}, got {config.friction_mode!r}")
        self.tree, self.variant, self.config = tree, variant, config
        self.n = tree.n_joints
        if variant == "separate":
            _, half = dual_arm_model(0.5)
            self.parts = [_part(half.chain(f), tree, (f,), config, True) for f in (REST_FRAME, TASK_FRAME)]
        else:
            self.parts = [_part(tree, tree, (REST_FRAME, TASK_FRAME), config, False)]
        self.table_share = variant in ("table", "separate")
        self.contacts = None
        if variant == CONTACT_VARIANT:
            self.contacts = SceneContacts(tree, [tool_support(REST_FRAME, (0.0, 0.0, 0.0), Scene().friction)])
        self.goal: Optional[np.ndarray] = None
        self.rest_goal: Optional[np.ndarray] = None
        self.q_ref: Optional[np.ndarray] = None
        self.in_contact = False

    def pose(self, q) -> np.ndarray:
        """Pose (4, 4) of :data:`TASK_FRAME` at ``q`` (rad): the frame the phases' goals refer to."""
        return np.asarray(self.tree.fk(q, TASK_FRAME))

    def set_goal(self, T_goal) -> None:
        """Set the goal pose (4, 4, base frame, m) of the sliding hand."""
        self.goal = np.asarray(T_goal, float)

    def set_contact(self, contact: bool) -> None:
        """The sliding hand stays in the air: ``contact`` must be False."""
        if contact:
            raise ValueError("the dual-arm task has no contact mode")

    def arm_contact_detection(self, on: bool = True) -> None:
        """No contact detection in this task (accepted for :func:`~.use_cases.run_loop`)."""

    def _hand_beta(self, frame: str, goal: np.ndarray, q, qd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``beta`` (6,) of the cascaded P towards ``goal`` at ``frame`` (zero acceleration inside the hold band), with its pose and twist."""
        T = np.asarray(self.tree.fk(q, frame))
        tw = np.asarray(self.tree.twist(q, qd, frame))
        # all six directions constrained: the hold band sees the whole error
        a, _ = cascaded_acceleration(pose_error(T, goal), tw, self.config.free_gains, self.config)
        return beta_for(ALPHA, a, tw, GRAVITY), T, tw

    def command(self, q, qd) -> tuple[np.ndarray, CycleInfo]:
        """One control cycle: motor torques (N m, shape (15,)) for the measured ``q``, ``qd``.

        Returns
        -------
        tau : ndarray, shape (15,)
            Motor command (the table's share removed where it carries it).
        info : CycleInfo
            ``pose``/``twist``/``error`` of :data:`TASK_FRAME`; ``inputs`` holds ``constraints``
            (both hands, ``{frame: (I6, beta)}``), ``model_torque`` (the total joint torque the
            solves intend: motors + table share + predicted friction + ``tau_ff``, N m) and
            ``table_force`` (the model's upward force at :data:`REST_FRAME`, N, 0 when none).
        """
        q, qd = np.asarray(q, float), np.asarray(qd, float)
        if self.goal is None:
            raise ValueError("set_goal() before command()")
        if self.rest_goal is None:
            self.rest_goal = np.asarray(self.tree.fk(q, REST_FRAME))
            self.q_ref = q.copy()
        beta_r, _, _ = self._hand_beta(REST_FRAME, self.rest_goal, q, qd)
        beta_t, T, tw = self._hand_beta(TASK_FRAME, self.goal, q, qd)
        cons = {REST_FRAME: (ALPHA, beta_r), TASK_FRAME: (ALPHA, beta_t)}
        if self.contacts is not None:  # the table holds the resting hand's position: the task its orientation
            cons[REST_FRAME] = (ALPHA[:, REST_COLUMNS], beta_r[REST_COLUMNS])
        K, D = self.config.posture_gains
        motor_ff = K * (self.q_ref - q) - D * qd
        tau, total = np.zeros(self.n), np.zeros(self.n)
        force = 0.0
        res = None
        cts, qd_solve = self.contacts(q, qd) if self.contacts is not None else ([], qd)
        for p in self.parts:
            qp, qdp = q[p.idx], qd[p.idx]
            ff = motor_ff[p.idx] * p.torso_scale
            tau_ff = ff - np.asarray(p.model.damping) * qdp
            kw = {"contacts": cts} if cts else {}
            if self.config.time_step is not None and (p.friction is not None or cts):
                kw["time_step"] = self.config.time_step  # the discrete-time mode (controller module doc)
            args = dict(tau_ff=tau_ff, constraints={f: cons[f] for f in p.frames}, **kw)
            res = p.solver.solve(qp, qd_solve[p.idx], friction=p.friction, **args)
            if cts:  # the table's force on the resting hand, and its joint torque in the intended total
                f_c = np.asarray(res.contact_force)[0]
                force = float(f_c[2])
                total[p.idx] += point_jacobian(p.model, qp, REST_FRAME, np.zeros(3)).T @ f_c
            share = np.zeros(len(p.idx))
            if self.table_share and REST_FRAME in p.frames:
                nu_up = float((res.segment_nu or {})[REST_FRAME][UP])
                if nu_up < 0.0:
                    share = -np.asarray(p.model.jacobian(qp, REST_FRAME))[UP] * nu_up
                    force = -nu_up
            tau[p.idx] += np.asarray(res.tau_command) + ff - share
            if self.config.friction_mode == "smooth":  # f tanh(qd / eps), the plain solve's compensation
                tau[p.idx] += np.asarray(p.model.friction) * np.tanh(qdp / self.config.friction_velocity_tolerance)
            total[p.idx] += tau_ff + np.asarray(res.tau_command)
            if res.friction_torque is not None:
                total[p.idx] += np.asarray(res.friction_torque)
        inputs = dict(q=q, qd=qd, constraints=cons, model_torque=total, table_force=force)
        info = CycleInfo(pose=T, twist=tw, error=pose_error(T, self.goal), normal_force_estimate=force, contact=False)
        info.result, info.inputs = res, inputs
        return tau, info


def open_loop_error(tree: Tree, solver: Solver, q, qd, model_torque, constraints) -> dict:
    """The hands' acceleration error when ``model_torque`` drives the true tree (module doc).

    Parameters
    ----------
    tree : Tree
        The dual-arm tree (the truth).
    solver : Solver
        ``Solver(tree, gravity=[0, 0, -9.81])``, reused.
    q, qd : array_like, shape (15,)
        Joint state (rad, rad/s).
    model_torque : array_like, shape (15,)
        Total joint torque (N m) a command intends (``CycleInfo.inputs["model_torque"]``).
    constraints : dict
        ``{frame: (alpha (6, m), beta (m,))}`` the command was computed for.

    Returns
    -------
    dict
        ``{frame: alpha^T Xdd - beta}`` per frame: (m,) in m/s^2 (linear rows) and rad/s^2
        (angular rows), ``Xdd`` the frame's spatial acceleration (``-gravity`` included, the
        convention of ``beta``) under forward dynamics.
    """
    res = solver.solve(q, qd, tau_ff=model_torque)
    out = {}
    for frame, (alpha, beta) in constraints.items():
        seg = tree.segment_index(frame)
        acc = np.asarray(res.link_acc[seg + 1])
        r = np.asarray(tree.fk(q, frame))[:3, 3] - np.asarray(tree.fk(q, seg))[:3, 3]
        xdd = np.concatenate([acc[:3] + np.cross(acc[3:], r), acc[3:]])
        out[frame] = np.asarray(alpha).T @ xdd - np.asarray(beta)
    return out


def _scene(tree: Tree, q0) -> Scene:
    """A table under the left gripper only (its top at the rest point), clear of the right arm."""
    p = np.asarray(tree.fk(q0, REST_FRAME))[:3, 3]
    return Scene(table_top=float(p[2]), table_x=(p[0] - 0.25, p[0] + 0.20), table_y=(p[1] - 0.12, p[1] + 0.15))


def dual_arm(variant: str, quick: bool = False, progress=None, config: Optional[ControllerConfig] = None):
    """Run the dual-arm case in one of :data:`VARIANTS` (module doc).

    Parameters
    ----------
    variant : {"table", "unsupported", "separate", "contacts"}
        Who carries the resting hand and which solver commands.
    quick : bool
        Shorter settle and hold phases (0.5 s instead of 1 s) and a shorter tail on the slide.
    progress : callable, optional
        ``progress(fraction)``, see :func:`~.use_cases.run_loop`.
    config : ControllerConfig, optional
        The controller's settings (:class:`DualArmController`); default :data:`CONFIG`.

    Returns
    -------
    Run
        Phases ``settle``, ``slide``, ``hold``; ``tip`` is :data:`TASK_FRAME`'s origin.
        ``run.info``: ``rest`` ((k, 3) origin of :data:`REST_FRAME`, m), ``table_top`` (m or None),
        ``table_force_model`` ((k,) the model's upward force at the resting hand, N),
        ``open_loop`` ((k, 2) RMS of the open-loop error of the resting and the sliding hand's
        linear rows, m/s^2), ``open_loop_ang`` ((k, 2) the same for the angular rows, rad/s^2).

    Raises
    ------
    ValueError
        If ``variant`` is not one of :data:`VARIANTS` (or ``config.friction_mode`` unknown).
    """
    if variant not in VARIANTS + (CONTACT_VARIANT,):
        raise ValueError(f"variant must be one of {VARIANTS + (CONTACT_VARIANT,)}, got {variant!r}")
    urdf, tree = dual_arm_model()
    q0 = start_pose()
    scene = _scene(tree, q0) if variant != "unsupported" else Scene()
    robot = MujocoGen3(build_model(urdf, tree, scene), q0)
    ctl = DualArmController(tree, variant, config)
    truth = Solver(tree, gravity=GRAVITY)
    R0 = ctl.pose(q0)[:3, :3]
    duration = 0.5 if quick else 1.0
    phases = [
        Phase("settle", lambda T: _shifted(T, R=R0), duration),
        Phase("slide", lambda T: _shifted(T, dx=SLIDE, R=R0), SLIDE / ctl.config.v_max + (1.0 if quick else 1.5)),
        Phase("hold", lambda T: _shifted(T, R=R0), duration),
    ]
    force, lin, ang, rest, commands = [], [], [], [], []

    def log(k, command, info) -> None:
        commands.append(np.array(command, float))
        x = info.inputs
        err = open_loop_error(tree, truth, x["q"], x["qd"], x["model_torque"], x["constraints"])
        e = [err[REST_FRAME], err[TASK_FRAME]]
        lin.append([np.sqrt(np.mean(v[:-3] ** 2)) if len(v) > 3 else np.nan for v in e])  # NaN: no linear rows
        ang.append([np.sqrt(np.mean(v[len(v) - 3 :] ** 2)) for v in e])
        force.append(x["table_force"])
        rest.append(np.asarray(tree.fk(x["q"], REST_FRAME))[:3, 3])

    run = run_loop(robot, ctl, phases, "dual-arm", variant, (0.0, 0.0, 0.0), progress, on_cycle=log)
    run.info.update(
        rest=np.array(rest),
        table_top=scene.table_top,
        table_force_model=np.array(force),
        open_loop=np.array(lin),
        open_loop_ang=np.array(ang),
        command=np.array(commands),
    )
    return run
