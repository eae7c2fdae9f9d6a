"""The three use cases of W. K. Lau (2023), sec. 6.2-6.4, each with and without contact, run in closed loop.

Every run: the MuJoCo plant (:mod:`.mujoco_plant`) behind :class:`~.robot_interface.RobotInterface`,
the controller of :mod:`.controller`, a list of phases (goal, directions, contact detection,
duration). The loop (:func:`run_loop`) only uses the interface.

Geometry (base frame, m). Start pose: the report's ``q`` (joint angles wrapped to [-pi, pi],
:data:`vereshchagin.robots.GEN3_START_POSE`): the end-effector at (0.457, 0.001, 0.434), tool axis
along +x. The tables are placed from that pose:

- grasp: the gripper box's lowest point is ``descent`` (0.25 m as in the report, 0.05 m quick)
  above the table; contact: approach until contact, slide 0.10 m along +x in contact (z
  released), close the gripper; contactless: stop 0.03 m above the table, slide in the air;
- writing: a pen (0.12 m, pointing down) in the gripper; contact: the table 0.01 m below the pen
  tip, approach until contact, draw 0.10 m along +x with z released; contactless: the table 0.10 m
  below the tip, draw in the air with all six directions constrained;
- resting elbow (:mod:`.elbow`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from vereshchagin import robots
from vereshchagin import Chain
from vereshchagin import Solver
from .controller import CascadedController, ControllerConfig
from .mujoco_plant import MujocoGen3, Scene, build_model, pen_tip
from .surfaces import CONTACT_CONFIG, SceneContacts, pen_setpoint, tool_support

__all__ = [
    "JOINT_FRICTION",
    "JOINT_DAMPING",
    "Phase",
    "Run",
    "gen3_model",
    "grasp",
    "run_loop",
    "with_tool_link",
    "writing",
]

JOINT_FRICTION = (0.5, 0.5, 0.5, 0.5, 0.3, 0.3, 0.3)
"""Static (breakaway) joint friction, N m (Kinova publishes none; plausible harmonic-drive values)."""
JOINT_DAMPING = (0.1, 0.1, 0.1, 0.1, 0.05, 0.05, 0.05)
"""Viscous joint damping, N m s/rad."""

SLIDE = 0.10  # m, Lau (2023): d_x = 0.1
DESCENT = 0.25  # m, Lau (2023): "about 25 cm"
CLEARANCE = 0.03  # m, tool above the table in the contactless grasp
PEN_DIRECTION_WORLD = (0.0, 0.0, -1.0)


def gen3_model(friction_scale: float = 1.0, payload: Optional[tuple] = None):
    """URDF text and chain of the Gen3 with the rigid gripper, friction and damping above.

    Parameters
    ----------
    friction_scale : float
        Factor on :data:`JOINT_FRICTION` (>= 0).
    payload : (float, (3,)) or None
        ``(mass kg, position m in the end-effector frame)`` of a solid sphere (radius
        :data:`PAYLOAD_RADIUS`) held rigidly by the gripper (:func:`with_tool_link`); the plant
        and the chain both carry it (a known payload).

    Returns
    -------
    urdf : str
        URDF text (for the plant, :func:`~.mujoco_plant.build_model`).
    chain : Chain
        ``base_link`` to :data:`vereshchagin.robots.GEN3_TIP_LINK`, 7 joints, with the URDF's
        friction (N m) and damping (N m s/rad).
    """
    friction = tuple(friction_scale * f for f in JOINT_FRICTION)
    urdf = robots.gen3_urdf(gripper=True, joint_friction=friction, joint_damping=JOINT_DAMPING)
    if payload is not None:
        urdf = with_tool_link(urdf, "payload", payload[1], mass=payload[0], radius=PAYLOAD_RADIUS)
    return urdf, Chain.from_urdf(urdf, root="base_link", tip=robots.GEN3_TIP_LINK)


PAYLOAD_RADIUS = 0.04
"""m, the payload sphere of :func:`gen3_model` (inertia 2/5 m r^2 about its centre)."""


def with_tool_link(
    urdf: str, name: str, xyz, mass: float = 0.0, radius: float = 0.0, parent: str = robots.GEN3_TIP_LINK
) -> str:
    """The URDF with a link ``name`` fixed to the link ``parent`` (the end-effector link) at ``xyz`` (m).

    Parameters
    ----------
    urdf : str
        URDF text with a link named ``parent``.
    name : str
        Name of the new link (its fixed joint is ``{name}_joint``).
    xyz : sequence of 3 float
        Its origin in the frame of ``parent`` (m), no rotation.
    mass : float
        kg; 0 (default): massless. Else the link is a solid sphere of that mass and ``radius``
        (m) centred at its origin (inertial only, no collision shape).
    radius : float
        m, used only with ``mass`` > 0.
    parent : str
        The link it is fixed to; default :data:`vereshchagin.robots.GEN3_TIP_LINK`.

    Returns
    -------
    str
        The URDF text with the link and joint added before ``</robot>``.
    """
    inertial = ""
    if mass > 0.0:
        i = 0.4 * mass * radius**2
        inertial = (
            f'    <inertial>\n      <origin xyz="0 0 0" rpy="0 0 0"/>\n      <mass value="{mass!r}"/>\n'
            f'      <inertia ixx="{i!r}" ixy="0" ixz="0" iyy="{i!r}" iyz="0" izz="{i!r}"/>\n'
            "    </inertial>\n"
        )
    link = (
        f'  <joint name="{name}_joint" type="fixed">\n    <parent link="{parent}"/>\n'
        f'    <child link="{name}"/>\n    <origin xyz="{xyz[0]!r} {xyz[1]!r} {xyz[2]!r}" rpy="0 0 0"/>\n'
        f'  </joint>\n  <link name="{name}">\n{inertial}  </link>\n'
    )
    return urdf.replace("</robot>", link + "</robot>")


@dataclass
class Phase:
    """One step of a task: drive the end-effector to ``goal`` for at most ``duration`` s.

    Attributes
    ----------
    name : str
        Phase name (``Run.window(name)`` selects its samples).
    goal : ndarray (4, 4) or callable
        Goal pose of the end-effector (homogeneous transform, base frame, m), or a callable
        ``goal(pose_now) -> (4, 4)`` evaluated once when the phase starts.
    duration : float
        Length of the phase (s); it ends earlier on contact when ``detect``.
    detect : bool
        Watch for contact and end the phase when it is detected.
    contact : bool or None
        Switch the controller to contact mode (True: z released) or free space (False) at the
        phase start; None: keep the current mode.
    gripper : float or None
        Gripper command at the phase start, 0 (open) .. 1 (closed); None: none.
    path : callable or None
        ``path(goal, t) -> (4, 4)``: the goal ``t`` s into the phase, set every cycle (a moving
        reference); None: the fixed ``goal``.
    """

    name: str
    goal: object
    duration: float
    detect: bool = False
    contact: Optional[bool] = None
    gripper: Optional[float] = None
    path: Optional[Callable] = None


@dataclass
class Run:
    """The log of one run (arrays over the k logged samples, one per control cycle) and its summary.

    Attributes
    ----------
    case : str
        ``"grasp"``, ``"writing"`` or ``"elbow"``.
    variant : str
        ``"contact"`` / ``"contactless"``, or one of :data:`vereshchagin_experiments.contact.elbow.VARIANTS`.
    t : ndarray, shape (k,)
        Plant clock after each step (s).
    q, qd, tau : ndarray, shape (k, n)
        Measured joint positions (rad), velocities (rad/s) and applied motor torques (N m).
    tip : ndarray, shape (k, 3)
        End-effector origin (base frame, m) at the start of each cycle.
    tool : ndarray, shape (k, 3)
        The tool's contact point (base frame, m) at the start of each cycle.
    phase : ndarray of int, shape (k,)
        Index into ``phases`` of each sample.
    contact_mode : ndarray of bool, shape (k,)
        The controller was in contact mode (z released).
    table_force, support_force : ndarray, shape (k,)
        Plant: total normal force on the table and on the elbow support (N, >= 0).
    table_touch : list of str
        Names of the arm geoms that ever touched the table, sorted.
    phases : list of Phase
        The phases run.
    contact_time : float or None
        Plant time (s) at which contact was detected; None: never.
    info : dict
        Case-specific extras (e.g. ``table_top`` m, ``tool_point`` (3,) m in the end-effector
        frame; :func:`~.elbow.elbow` adds the elbow logs).
    """

    case: str
    variant: str
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    tip: np.ndarray
    tool: np.ndarray
    phase: np.ndarray
    contact_mode: np.ndarray
    table_force: np.ndarray
    support_force: np.ndarray
    table_touch: list
    phases: list
    contact_time: Optional[float]
    info: dict = field(default_factory=dict)

    def window(self, name: str) -> np.ndarray:
        """Boolean mask, shape (k,), of the samples of phase ``name`` (ValueError if no such phase)."""
        k = [p.name for p in self.phases].index(name)
        return self.phase == k


def _shifted(T, dx=0.0, dy=0.0, dz=0.0, R=None):
    """``T`` moved by (dx, dy, dz) (base axes), with orientation ``R`` if given."""
    T = np.array(T, float)
    T[:3, 3] += [dx, dy, dz]
    if R is not None:
        T[:3, :3] = R
    return T


def run_loop(
    robot,
    controller: Any,
    phases,
    case: str,
    variant: str,
    tool_point,
    progress: Optional[Callable[[float], None]] = None,
    on_cycle: Optional[Callable[[int, np.ndarray, object], None]] = None,
) -> Run:
    """Run the phases on ``robot`` (any :class:`~.robot_interface.RobotInterface`).

    Parameters
    ----------
    robot : RobotInterface
        The backend; a ``contact_forces()`` method, if it has one, fills the force logs.
    controller : CascadedController
        Gets each phase's goal, contact mode and detection, and computes every command;
        ``controller.pose(q)`` is the pose the goals refer to (any controller with the same
        methods, e.g. :class:`~.dual_arm.DualArmController`).
    phases : sequence of Phase
        Run in order; a phase with ``detect`` ends early on contact.
    case, variant : str
        Labels stored in the :class:`Run`.
    tool_point : sequence of 3 float
        The tool's contact point in the end-effector frame (m), logged as ``tool``.
    progress : callable, optional
        ``progress(fraction)`` with the fraction (0..1) of the planned samples done, every 500.
    on_cycle : callable, optional
        ``on_cycle(k, command, cycle_info)`` after each step: the sample index, the torque written
        (N m, shape (n,)) and the controller's :class:`~.controller.CycleInfo` (extra logging).

    Returns
    -------
    Run
        One sample per control cycle.
    """
    dt = robot.period
    total = int(round(sum(p.duration for p in phases) / dt)) + len(phases)
    n = robot.n_joints
    t, q, qd, tau = np.zeros(total), np.zeros((total, n)), np.zeros((total, n)), np.zeros((total, n))
    tip, tool = np.zeros((total, 3)), np.zeros((total, 3))
    ph, cm = np.zeros(total, int), np.zeros(total, bool)
    tf, sf = np.zeros(total), np.zeros(total)
    touch = set()
    contact_time = None
    tp = np.append(np.asarray(tool_point, float), 1.0)
    diag = getattr(robot, "contact_forces", None)
    k = 0
    for i, p in enumerate(phases):
        s = robot.read()
        T_now = controller.pose(s.q)
        goal = p.goal(T_now) if callable(p.goal) else p.goal
        controller.set_goal(goal)
        if p.contact is not None:
            controller.set_contact(p.contact)
        controller.arm_contact_detection(p.detect)
        if p.gripper is not None:
            robot.set_gripper(p.gripper)
        steps = int(round(p.duration / dt))
        for step in range(steps):
            if p.path is not None:
                controller.set_goal(p.path(goal, step * dt))
            s = robot.read()
            cmd, ci = controller.command(s.q, s.qd)
            robot.write(cmd)
            robot.wait()
            s2 = robot.read()
            t[k], q[k], qd[k], tau[k] = s2.time, s2.q, s2.qd, s2.tau
            tip[k] = ci.pose[:3, 3]
            tool[k] = (ci.pose @ tp)[:3]
            ph[k], cm[k] = i, controller.in_contact
            if on_cycle is not None:
                on_cycle(k, cmd, ci)
            if diag is not None:
                forces = diag()
                if "table" in forces:
                    tf[k] = forces["table"][0]
                    touch |= forces["table"][1]
                if "support" in forces:
                    sf[k] = forces["support"][0]
            k += 1
            if progress is not None and k % 500 == 0:
                progress(k / total)
            if p.detect and controller.in_contact:
                contact_time = s2.time
                break
    sl = slice(0, k)
    return Run(
        case,
        variant,
        t[sl],
        q[sl],
        qd[sl],
        tau[sl],
        tip[sl],
        tool[sl],
        ph[sl],
        cm[sl],
        tf[sl],
        sf[sl],
        sorted(touch),
        list(phases),
        contact_time,
    )


def _lowest_arm_point(model, q) -> float:
    """Lowest z (m) of the arm's collision geoms at ``q`` (MuJoCo's geom AABBs)."""
    import mujoco

    d = mujoco.MjData(model)
    d.qpos[:] = q
    mujoco.mj_forward(model, d)
    low = np.inf
    for g in range(model.ngeom):
        if model.geom_contype[g] != 1:
            continue
        R = d.geom_xmat[g].reshape(3, 3)
        c = d.geom_xpos[g]
        t = model.geom_type[g]
        size = model.geom_size[g]
        if t == mujoco.mjtGeom.mjGEOM_BOX:
            ext = np.abs(R[2]) @ size
        elif t == mujoco.mjtGeom.mjGEOM_SPHERE:
            ext = size[0]
        else:  # capsule / cylinder along local z
            ext = abs(R[2, 2]) * size[1] + (
                size[0] if t == mujoco.mjtGeom.mjGEOM_CAPSULE else size[0] * np.hypot(R[2, 0], R[2, 1])
            )
        low = min(low, c[2] - ext)
    return float(low)


def _gripper_low_point(model, q, T_frame, body: str = "bracelet_link") -> np.ndarray:
    """The lowest edge's middle of the gripper box on ``body`` at ``q``, in the frame ``T_frame`` (m).

    ``T_frame`` is that frame's pose (4, 4) in the base frame at ``q`` (e.g. the end-effector's).
    """
    import mujoco

    d = mujoco.MjData(model)
    d.qpos[:] = q
    mujoco.mj_forward(model, d)
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    boxes = [
        g for g in range(model.ngeom) if model.geom_bodyid[g] == bid and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
    ]
    g = boxes[0]
    R = d.geom_xmat[g].reshape(3, 3)
    corner = d.geom_xpos[g] - R @ (np.sign(R[2]) * model.geom_size[g])
    # The lowest edge runs along the box's longest axis: take its middle (sliding contact line).
    long_axis = int(np.argmax(model.geom_size[g]))
    corner = corner + R[:, long_axis] * np.sign(R[2, long_axis]) * model.geom_size[g][long_axis]
    return (np.linalg.inv(np.asarray(T_frame)) @ np.append(corner, 1.0))[:3]


def _settings(settings: Optional[dict]) -> dict:
    """The controller settings of a run with the solver's contacts (default :data:`~.surfaces.CONTACT_CONFIG`)."""
    return dict(CONTACT_CONFIG if settings is None else settings)


def _controller(chain, tool_point, **overrides):
    solver = Solver(chain, gravity=[0.0, 0.0, -9.81])
    return CascadedController(chain, solver, ControllerConfig(contact_point=tuple(tool_point), **overrides))


def _plant(urdf, chain, scene, q0, perturb=None):
    """The MuJoCo plant of ``scene`` at rest at ``q0``, changed by ``perturb`` (model error) if given.

    Returns the :class:`~.mujoco_plant.MujocoGen3` and ``perturb``'s result (None without it).
    """
    model = build_model(urdf, chain, scene)
    error = perturb(model) if perturb is not None else None
    return MujocoGen3(model, q0), error


def grasp(
    contact: bool,
    quick: bool = False,
    progress=None,
    descent: Optional[float] = None,
    solver_contacts: bool = False,
    mu: Optional[float] = None,
    perturb: Optional[Callable[[Any], dict]] = None,
    settings: Optional[dict] = None,
) -> Run:
    """Use case 1: approach the table, slide 0.10 m along +x (in contact or 0.03 m above), grasp.

    Gains: :data:`~.controller.FREE_GAINS` and :data:`~.controller.CONTACT_GAINS` (why they
    differ from the report's: their documentation). Nothing is grasped: the gripper is rigid and
    its closing command is only recorded.

    Parameters
    ----------
    contact : bool
        True: descend until contact is detected, slide with z released; False: stop 0.03 m above
        the table and slide in the air with all six directions constrained.
    quick : bool
        Shorter run: 0.05 m descent instead of 0.25 m.
    progress : callable, optional
        ``progress(fraction)``, see :func:`run_loop`.
    descent : float, optional
        Height (m) of the gripper's lowest point above the table at the start; overrides
        ``quick``'s choice.
    solver_contacts : bool
        With ``contact``: once contact is detected, the gripper's lowest edge is a support with
        the table's friction in the solve (:mod:`.surfaces`) instead of the estimated table force
        in ``f_ext``; variant ``"solver-contacts"``.
    mu : float, optional
        The table's friction coefficient (plant and contact); None: the scene's default (0.3).
    perturb : callable, optional
        ``perturb(mujoco.MjModel) -> dict``: changes the compiled plant in place before the run
        (model error, :mod:`.model_error`); its result is stored as ``info["plant_error"]``.
        None: the plant is the controller's model.
    settings : dict, optional
        With ``solver_contacts``: the controller's :class:`~.controller.ControllerConfig` fields;
        None: :data:`~.surfaces.CONTACT_CONFIG` (the discrete-time mode).

    Returns
    -------
    Run
        Phases ``approach``, ``slide``, ``grasp``; ``info``: ``table_top`` (m, base z),
        ``descent`` (m), ``tool_point`` (3,) (the gripper's lowest point, end-effector frame, m),
        ``mu``, ``table_force_model`` ((k,) the model's table force per sample, N: the ``f_ext``
        estimate, or the solver's contact force) and ``command`` ((k, n) the commands, N m).
    """
    urdf, chain = gen3_model()
    q0 = np.array(robots.GEN3_START_POSE)
    R0 = np.asarray(chain.fk(q0))[:3, :3]
    descent = (0.05 if quick else DESCENT) if descent is None else descent
    probe = build_model(urdf, chain, Scene())
    low = _gripper_low_point(probe, q0, chain.fk(q0))
    z_low = (np.asarray(chain.fk(q0)) @ np.append(low, 1.0))[2]
    scene = Scene(table_top=float(z_low - descent), **_friction(mu))
    robot, plant_error = _plant(urdf, chain, scene, q0, perturb)
    ctl = _controller(chain, low, **(_settings(settings) if contact and solver_contacts else {}))
    if contact and solver_contacts:
        points = [tool_support(robots.GEN3_TIP_LINK, low, scene.friction)]
        ctl.contacts = SceneContacts(chain, points, active=lambda: ctl.in_contact, reference=lambda: ctl.v_des[:3])
    v = ctl.config.v_max
    approach_time = descent / v + 2.0
    slide_time = SLIDE / v + 1.5
    if contact:
        phases = [
            Phase(
                "approach", lambda T: _shifted(T, dz=-(descent + 0.05), R=R0), approach_time, detect=True, contact=False
            ),
            Phase("slide", lambda T: _shifted(T, dx=SLIDE, R=R0), slide_time),
            Phase("grasp", lambda T: _shifted(T, R=R0), 0.3, gripper=1.0),
        ]
    else:
        phases = [
            Phase(
                "approach", lambda T: _shifted(T, dz=-(descent - CLEARANCE), R=R0), approach_time - 0.5, contact=False
            ),
            Phase("slide", lambda T: _shifted(T, dx=SLIDE, R=R0), slide_time),
            Phase("grasp", lambda T: _shifted(T, R=R0), 0.3, gripper=1.0),
        ]
    log, on_cycle = _model_force_log()
    run = run_loop(robot, ctl, phases, "grasp", _variant(contact, solver_contacts), low, progress, on_cycle)
    run.info.update(
        table_top=scene.table_top,
        descent=descent,
        tool_point=low,
        mu=scene.friction,
        plant_error=plant_error,
        **_arrays(log),
    )
    return run


def writing(
    contact: bool,
    quick: bool = False,
    progress=None,
    solver_contacts: bool = False,
    perturb: Optional[Callable[[Any], dict]] = None,
    settings: Optional[dict] = None,
) -> Run:
    """Use case 2: draw a 0.10 m line along +x with the pen on the table, or 0.10 m above it.

    The start pose is the grasp's (the report gives none for writing, only photographs).

    Parameters
    ----------
    contact : bool
        True: the table 0.01 m below the pen tip, approach until contact, draw with z released;
        False: the table 0.10 m below, draw in the air with all six directions constrained.
    quick : bool
        Accepted for a uniform signature; the writing runs are short either way.
    progress : callable, optional
        ``progress(fraction)``, see :func:`run_loop`.
    solver_contacts : bool
        With ``contact``: once contact is detected, the pen tip is a normal-force set-point
        (:data:`~.surfaces.WRITING_FORCE`, the table's friction) in the solve instead of the
        estimated table force in ``f_ext``; variant ``"solver-contacts"``.
    perturb : callable, optional
        Model error of the plant, as in :func:`grasp`.
    settings : dict, optional
        As in :func:`grasp`.

    Returns
    -------
    Run
        Phases ``approach`` (contact) or ``settle``, then ``write``; ``info``: ``table_top``
        (m, base z), ``tool_point`` (3,) (the pen tip, end-effector frame, m),
        ``table_force_model`` and ``command`` as in :func:`grasp`.
    """
    urdf, chain = gen3_model()
    q0 = np.array(robots.GEN3_START_POSE)
    T0 = np.asarray(chain.fk(q0))
    R0 = T0[:3, :3]
    pen_dir = T0[:3, :3].T @ np.array(PEN_DIRECTION_WORLD)
    tip_ee = pen_tip(pen_dir)
    z_tip = (T0 @ np.append(tip_ee, 1.0))[2]
    gap = 0.01 if contact else 0.10
    scene = Scene(table_top=float(z_tip - gap), pen_direction=tuple(pen_dir))
    robot, plant_error = _plant(urdf, chain, scene, q0, perturb)
    # Tracked point: the end-effector origin, as in the report (the pen tip, 0.12 m below the grip,
    # moves with orientation errors). Tracking the pen tip itself (``with_tool_link``) made the
    # free-space variant drift in the self-motion; not pursued.
    ctl = _controller(chain, tip_ee, **(_settings(settings) if contact and solver_contacts else {}))
    if contact and solver_contacts:
        points = [pen_setpoint(robots.GEN3_TIP_LINK, tip_ee, scene.friction)]
        ctl.contacts = SceneContacts(chain, points, active=lambda: ctl.in_contact, reference=lambda: ctl.v_des[:3])
    v = ctl.config.v_max
    draw_time = SLIDE / v + 1.5
    if contact:
        phases = [
            Phase("approach", lambda T: _shifted(T, dz=-0.03, R=R0), 2.0, detect=True, contact=False),
            Phase("write", lambda T: _shifted(T, dx=SLIDE, R=R0), draw_time),
        ]
    else:
        phases = [
            Phase("settle", lambda T: _shifted(T, R=R0), 0.3, contact=False),
            Phase("write", lambda T: _shifted(T, dx=SLIDE, R=R0), draw_time),
        ]
    log, on_cycle = _model_force_log()
    run = run_loop(robot, ctl, phases, "writing", _variant(contact, solver_contacts), tip_ee, progress, on_cycle)
    run.info.update(
        table_top=scene.table_top,
        tool_point=tip_ee,
        plant_error=plant_error,
        **_arrays(log),
    )
    return run


def _friction(mu: Optional[float]) -> dict:
    """``Scene`` keyword for a table friction coefficient ``mu`` (none: the scene's default)."""
    return {} if mu is None else {"friction": float(mu)}


def _arrays(log: dict) -> dict:
    return {k: np.array(v) for k, v in log.items()}


def _variant(contact: bool, solver_contacts: bool) -> str:
    return ("solver-contacts" if solver_contacts else "contact") if contact else "contactless"


def _model_force_log() -> tuple[dict, Callable]:
    """``(log, on_cycle)``: ``on_cycle`` logs the model's table and friction force and the command into ``log``."""
    log: dict[str, list] = {"table_force_model": [], "friction_force_model": [], "command": []}

    def on_cycle(k, command, info) -> None:
        log["table_force_model"].append(float(info.normal_force_estimate))
        f = np.asarray(getattr(info.result, "contact_force", np.zeros((0, 3))))
        log["friction_force_model"].append(float(np.linalg.norm(f[:, :2].sum(0))) if len(f) else 0.0)
        log["command"].append(np.array(command, float))

    return log, on_cycle
