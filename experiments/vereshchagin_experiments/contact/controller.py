"""The controller of W. K. Lau (2023), sec. 5.1: cascaded P position -> velocity -> ``beta``, our solver inside.

One cycle (:meth:`CascadedController.command`):

1. pose error ``e = pose_error(X_curr, X_goal)`` (translation difference, rotation axis * angle,
   base axes) and the desired twist ``v_d = k_pos * e``, each part saturated at ``v_max`` (m/s)
   and ``w_max`` (rad/s) -- the report gives no saturation; without it a 25 cm error and
   k_pos = 40 ask for 10 m/s;
2. the desired classical acceleration ``a_d = k_vel * (v_d - v_curr)``, turned into ``beta`` by
   :func:`vereshchagin.task.beta_for` (adds ``-gravity`` and the velocity product);
3. directions: free space constrains all six (x, y, z, rx, ry, rz); in contact the linear z is
   released so gravity presses the tool on the surface;
4. in contact the table's reaction enters ``f_ext`` on the last segment: a normal force ``N``
   estimated from the model (the force along ``w = [e_z; r x e_z]`` at the contact point ``r``
   that stops the predicted z acceleration of that point: ``N = (g - w.a_pred) / (w^T J G J^T w)``
   with ``G`` the constrained inverse inertia from :meth:`Solver.response_columns`, clipped at 0)
   and a friction force ``mu_est * N`` against the desired sliding direction (Lau (2023) used
   ``f_ext`` "to counter friction");
5. the solver's command: ``solve(q, qd, alpha, beta, f_ext, tau_ff, friction)``. ``tau_ff`` holds
   the plant's modelled viscous damping ``-d * qd`` (the plant applies it, the motors compensate
   it) plus an optional motor-side posture term; ``friction=Friction(static=chain.friction)``
   makes resting joints get the max-min static friction and moving ones Coulomb friction, so
   ``tau_command`` is the motor torque with friction acting (friction compensation).
   The motor torque sent is ``tau_command`` + the motor-side part of ``tau_ff``.
   ``ControllerConfig.time_step`` (the control period, s) makes it the discrete-time mode: the
   same solve with ``time_step=``, i.e. friction, joint limits and contacts posed on the joint
   velocities at the end of the next control period (docs/time-step.md, "Controllers over a
   step"): a joint that will stay at rest gets the friction that holds it (continuous in the
   P correction) instead of the full breakaway torque against the sign of its acceleration.
   ``ControllerConfig.friction_mode`` selects how joint friction enters (the friction-energy
   experiment compares them): ``"maxmin"`` (the above, default), ``"none"`` (plain solve, friction
   left to feedback), ``"sign"`` (plain solve + ``f_j sign(qd_j)``, at rest the sign of the
   commanded ``qdd_j``), ``"smooth"`` (plain solve + ``f_j tanh(qd_j / eps_v)``).

Contact detection: |v_z| of the end-effector below ``contact_threshold`` for
``contact_samples`` (10) consecutive samples, armed once the tool has moved (|v_z| above twice
the threshold). On contact the gains switch to the contact set and the directions to "contact".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Union

import numpy as np

from vereshchagin.friction import Friction
from vereshchagin.task import beta_for, directions, pose_error

__all__ = [
    "CONTACT_GAINS",
    "CONTROL_PERIOD",
    "FREE_GAINS",
    "REPORT_CONTACT_GAINS",
    "REPORT_FREE_GAINS",
    "FRICTION_MODES",
    "CascadedController",
    "ControllerConfig",
    "Gains",
    "cascaded_acceleration",
]

G = 9.81
CONTROL_PERIOD = 1e-3
"""s: the experiments' control period (the MuJoCo plant's time step, :mod:`.mujoco_plant`), the
``time_step`` of the discrete-time controller mode (:attr:`ControllerConfig.time_step`)."""


@dataclass(frozen=True)
class Gains:
    """Gains of the cascaded P controller, each split into a linear and an angular part.

    Attributes
    ----------
    k_pos : (float, float)
        Position gains ``(linear, angular)`` (1/s): the desired twist is ``k_pos * e`` for the
        pose error ``e`` (translation in m, rotation axis * angle in rad, base axes), before
        saturation at ``v_max`` / ``w_max``.
    k_vel : (float, float)
        Velocity gains ``(linear, angular)`` (1/s): the desired classical acceleration is
        ``k_vel * (v_d - v)`` (m/s^2, rad/s^2) for the desired and measured twists (base axes,
        linear part at the end-effector origin).
    """

    k_pos: tuple = (40.0, 80.0)
    k_vel: tuple = (30.0, 2.0)


REPORT_FREE_GAINS = Gains((40.0, 80.0), (30.0, 2.0))
"""Gains of W. K. Lau (2023), use case 1, before contact, as published (sec. 5.1); see :data:`FREE_GAINS`."""
REPORT_CONTACT_GAINS = Gains((10.0, 80.0), (4.0, 40.0))
"""Gains of W. K. Lau (2023), use case 1, after contact, as published (sec. 5.1); not used as such
(:data:`CONTACT_GAINS`)."""
FREE_GAINS = Gains((40.0, 80.0), (30.0, 40.0))
"""Free-space gains: :data:`REPORT_FREE_GAINS` with the angular ``k_vel`` = 40 instead of 2.

Measured with the report's 2 (joints counted from 0): the full grasp (25 cm descent) completes
(contact slide 99.4 mm, only the gripper touching the table), but in the quick grasp (5 cm
descent) the wrist tilts on landing: the wrist links touch the table too, contact is detected
0.8 s late and the slide ends at 95.7 mm; in writing the pen, pressed on the paper during the
approach, turns the wrist (joint 5 from 55 to 122 degrees before contact is detected) and the
line is drawn 64 mm backwards. The report's use case 3 failed the same way (a wrist joint
rotating to its limit; its text blames the angular gain).
"""
CONTACT_GAINS = Gains((10.0, 80.0), (15.0, 40.0))
"""Gains after contact: :data:`REPORT_CONTACT_GAINS` with the linear ``k_vel`` = 15 instead of 4.

In contact the velocity loop is the only feedback against what the model compensates imperfectly:
the sliding friction ``mu N`` of the table (about 15 N when the arm's weight presses with ~50 N
after the report's 25 cm descent) and the joint friction near rest (the solver's max-min gives
full friction to joints it predicts slipping at tiny accelerations, the plant's soft dry friction
holds them with less). With ``k_vel`` = 4 the correction is at most ``4 * v_max`` = 0.2 m/s^2
(about 1 N at the tool) and the slide stalls. Measured over the full slide (25 cm descent,
``friction_velocity_tolerance`` 0.01): with the report's exact gains (:data:`REPORT_FREE_GAINS`
and :data:`REPORT_CONTACT_GAINS`) the slide reaches 66 mm; with the free-space angular ``k_vel``
= 40 and the in-contact linear ``k_vel`` = 4 -> 48 mm, 7 -> 60 mm, 10 -> 96 mm, 15 -> 99.5 mm.
The quick mode (5 cm descent) completes with 4.
"""


FRICTION_MODES = ("maxmin", "none", "sign", "smooth")
FREE_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
CONTACT_DIRECTIONS = ("x", "y", "rx", "ry", "rz")


@dataclass(frozen=True)
class ControllerConfig:
    """Controller settings (SI units).

    Attributes
    ----------
    free_gains, contact_gains : Gains
        Gains before contact (all directions constrained) and after contact (z released).
    v_max, w_max : float
        Saturation of the desired twist (m/s, rad/s).
    contact_threshold : float
        |v_z| (m/s) below which a sample counts towards contact.
    contact_samples : int
        Consecutive samples needed (report: 10).
    contact_point : (float, float, float)
        The tool's contact point in the end-effector frame (m), for ``f_ext``.
    mu_estimate : float
        Surface friction coefficient assumed in ``f_ext`` (0: no friction compensation).
    friction_mode : {"maxmin", "none", "sign", "smooth"}
        How the chain's joint friction ``f`` (static = kinetic, N m) enters the command:
        ``"maxmin"``: passed to the solver (exact max-min, least command; friction compensation);
        ``"none"``: ignored (plain solve; feedback alone fights friction); ``"sign"``: plain solve
        plus ``f_j sign(qd_j)``, and for a joint at rest (|qd_j| <= ``friction_velocity_tolerance``)
        ``f_j sign(qdd_j)`` of the commanded motion (classical Coulomb compensation);
        ``"smooth"``: plain solve plus ``f_j tanh(qd_j / friction_velocity_tolerance)`` (the
        usual chatter-free variant: about no compensation at rest).
    friction_velocity_tolerance : float
        |qd| (rad/s) at or below which a joint counts as resting for the friction solver. Above
        the plant's creep: MuJoCo's dry friction is a soft constraint that lets a held joint creep
        at ~5 mrad/s; with a tolerance below that (1e-3) the solver assumes Coulomb friction
        against the creep, i.e. helping any reversal, and under-commands every reversing joint
        by twice its friction (the writing line then wanders by 7-12 mm instead of < 0.5 mm).
    posture_gains : (float, float)
        ``(K, D)`` of a motor-side joint posture term ``K (q_ref - q) - D qd`` in ``tau_ff``;
        the solver realises the task regardless, so it only acts in the unconstrained
        directions (self-motion, released z). (0, 0): off, as in the report (tau_ff = 0).
    free_directions : tuple of str
        Constrained directions in free space (names of :func:`vereshchagin.task.directions`,
        base axes); default all six. Fewer leave the rest of the motion to the dynamics.
    hold_band : (float, float) or None
        ``(m, rad)``: while the translational and rotational pose errors along the constrained
        directions are both inside, the task asks for zero acceleration (``a_des = 0``: "stay", so resting joints may stick)
        instead of the P correction. None (default): no band. The step mode (``time_step``)
        replaces it in the experiments; kept as their "before" variant.
    time_step : float or None
        The discrete-time controller mode: the control period ``dt`` (s) passed to the
        friction-aware solve as ``time_step=dt`` (friction and contact conditions on the
        velocities ``qd + dt qdd`` at the end of the period; ``tau_command`` is then the motor
        torque over the period). None (default): the solve at the instant.
    """

    free_gains: Gains = FREE_GAINS
    contact_gains: Gains = CONTACT_GAINS
    v_max: float = 0.05
    w_max: float = 0.5
    contact_threshold: float = 0.005
    contact_samples: int = 10
    contact_point: tuple = (0.0, 0.0, 0.0)
    mu_estimate: float = 0.3
    friction_mode: str = "maxmin"
    friction_velocity_tolerance: float = 1e-2
    posture_gains: tuple = (20.0, 3.0)
    free_directions: tuple = FREE_DIRECTIONS
    hold_band: Optional[tuple] = None
    time_step: Optional[float] = None


@dataclass
class CycleInfo:
    """What one control cycle computed (for logging).

    Attributes
    ----------
    pose : ndarray, shape (4, 4)
        Measured end-effector pose (homogeneous transform, base frame, m).
    twist : ndarray, shape (6,)
        Measured end-effector twist ``[v; w]`` (m/s, rad/s; base axes, linear part at the
        end-effector origin).
    error : ndarray, shape (6,)
        Pose error towards the goal (m, rad; :func:`vereshchagin.task.pose_error`).
    normal_force_estimate : float
        Model estimate ``N`` of the table's normal force (N, >= 0; 0 in free space).
    contact : bool
        The controller was in contact mode (z released) during the cycle.
    result : SolveResult
        The solver's result of the commanding solve.
    inputs : dict
        The solve's arguments (``q, qd, alpha, beta, f_ext, tau_ff`` and segment ``constraints``,
        without ``friction``) and ``motor_ff``, the motor-side part of ``tau_ff`` added to the
        command (N m, shape (n,)).
    """

    pose: np.ndarray
    twist: np.ndarray
    error: np.ndarray
    normal_force_estimate: float
    contact: bool
    result: object = field(repr=False, default=None)
    inputs: dict = field(repr=False, default_factory=dict)


class CascadedController:
    """The cascaded P controller of W. K. Lau (2023) around :class:`vereshchagin.Solver` (module doc).

    Parameters
    ----------
    chain : Chain
        The robot (n joints); its ``friction`` (N m) and ``damping`` (N m s/rad) are the plant's.
    solver : Solver
        Built from ``chain`` with gravity ``[0, 0, -9.81]`` (m/s^2, base frame).
    config : ControllerConfig
        Gains, saturation, contact detection and friction handling.

    Attributes
    ----------
    goal : ndarray, shape (4, 4) or None
        Desired end-effector pose (base frame, m); None until :meth:`set_goal`.
    in_contact : bool
        Contact mode: z released, contact gains, ``f_ext`` with the normal-force estimate.
    q_ref : ndarray, shape (n,) or None
        Reference of the posture term (rad); the first commanded ``q`` when None.
    extra_constraints : dict, callable or None
        Segment constraints passed to :meth:`Solver.solve` as ``constraints=``: a dict
        ``{segment name: (alpha (6, m), beta (m,))}`` or a callable ``(q, qd) -> dict``.
    support_share : callable or None
        ``support_share(result, q) -> (n,)``: joint torque (N m) the environment supplies,
        subtracted from the motor command.
    contacts : callable or None
        ``contacts(q, qd) -> (list of vereshchagin.Contact, qd_solve)`` (e.g.
        :class:`~.surfaces.SceneContacts`): the surfaces passed to the commanding solve with the
        velocity ``qd_solve`` (rad/s) to solve with; when it returns contacts, no table force is
        estimated into ``f_ext`` and ``CycleInfo.normal_force_estimate`` is the solver's upward
        contact force (N, summed over the contacts). None: no contacts (the hand-made variants).
    v_des : ndarray, shape (6,)
        The desired twist of the last cycle (m/s, rad/s; base axes, end-effector origin).
    """

    def __init__(self, chain, solver, config: ControllerConfig = ControllerConfig()):
        self.chain = chain
        self.solver = solver
        self.config = config
        n = chain.n_joints
        self.n = n
        self.damping = np.asarray(chain.damping, float)
        if config.friction_mode not in FRICTION_MODES:
            raise ValueError(f"friction_mode must be one of {FRICTION_MODES}, got {config.friction_mode!r}")
        self.joint_friction = np.asarray(chain.friction, float)
        self.friction = (
            Friction(static=self.joint_friction, velocity_tolerance=config.friction_velocity_tolerance)
            if config.friction_mode == "maxmin" and np.any(self.joint_friction > 0)
            else None
        )
        self.goal: Optional[np.ndarray] = None
        self.in_contact = False
        self.detect = False
        self._armed = False
        self._count = 0
        self.q_ref: Optional[np.ndarray] = None
        self.extra_constraints: Optional[Union[dict, Callable[[np.ndarray, np.ndarray], dict]]] = None
        self.support_share: Optional[Callable[[Any, np.ndarray], np.ndarray]] = None
        self.contacts: Optional[Callable[[np.ndarray, np.ndarray], tuple]] = None
        self.v_des = np.zeros(6)  # the last cycle's desired twist (for contacts' reference velocity)
        self._all = list(range(n))
        self._alpha: dict[tuple, np.ndarray] = {}  # constraint directions (6, m) per tuple of names

    # -- task state ------------------------------------------------------------------------------
    def pose(self, q) -> np.ndarray:
        """End-effector pose (4, 4) at joint positions ``q`` (rad): the frame the goals refer to (base frame, m)."""
        return np.asarray(self.chain.fk(q))

    def set_goal(self, T_goal) -> None:
        """Set the desired end-effector pose.

        Parameters
        ----------
        T_goal : array_like, shape (4, 4)
            Homogeneous transform of the goal in the base frame (m).
        """
        self.goal = np.asarray(T_goal, float)

    def arm_contact_detection(self, on: bool = True) -> None:
        """Start (or stop) watching the end-effector's |v_z| (base z, m/s) for contact.

        Parameters
        ----------
        on : bool
            True: watch, switching to contact mode after ``contact_samples`` slow samples once
            the tool has moved; False: stop watching. Either way the count restarts.
        """
        self.detect = on
        self._armed = False
        self._count = 0

    def set_contact(self, contact: bool) -> None:
        """Switch directions and gains to contact (z released) or free space.

        Parameters
        ----------
        contact : bool
            True: contact mode (directions x, y, rx, ry, rz; contact gains; table force in
            ``f_ext``); False: free space (``free_directions``, free gains).
        """
        self.in_contact = contact

    @property
    def gains(self) -> Gains:
        """The gains in use: ``config.contact_gains`` in contact mode, else ``config.free_gains``."""
        return self.config.contact_gains if self.in_contact else self.config.free_gains

    # -- one cycle -------------------------------------------------------------------------------
    def _contact_update(self, vz: float) -> None:
        thr = self.config.contact_threshold
        if not self._armed:
            self._armed = abs(vz) > 2.0 * thr
            return
        self._count = self._count + 1 if abs(vz) < thr else 0
        if self._count >= self.config.contact_samples:
            self.in_contact = True
            self.detect = False

    def command(self, q, qd) -> tuple[np.ndarray, CycleInfo]:
        """One control cycle: the motor torques for the measured joint state.

        Parameters
        ----------
        q, qd : array_like, shape (n,)
            Measured joint positions (rad) and velocities (rad/s).

        Returns
        -------
        tau : ndarray, shape (n,)
            Motor torque command (N m, acting on the joints; before the plant's saturation).
        info : CycleInfo
            What the cycle computed (pose, twist, error, solve inputs and result).
        """
        cfg = self.config
        q = np.asarray(q, float)
        qd = np.asarray(qd, float)
        T = np.asarray(self.chain.fk(q))
        tw = np.asarray(self.chain.twist(q, qd))
        if self.detect:
            self._contact_update(tw[2])
        e = pose_error(T, self.goal)
        names = CONTACT_DIRECTIONS if self.in_contact else cfg.free_directions
        if names not in self._alpha:
            self._alpha[names] = directions(names)
        alpha = self._alpha[names]
        a_des, v_des = cascaded_acceleration(e, tw, self.gains, cfg, alpha)
        self.v_des = v_des
        beta = beta_for(alpha, a_des, tw, self.solver.gravity)

        tau_motor_ff = np.zeros(self.n)
        K, D = cfg.posture_gains
        if K or D:
            if self.q_ref is None:
                self.q_ref = q.copy()
            tau_motor_ff = K * (self.q_ref - q) - D * qd
        tau_ff = tau_motor_ff - self.damping * qd
        kw: dict[str, Any] = {}
        if self.extra_constraints:
            kw["constraints"] = (
                self.extra_constraints(q, qd) if callable(self.extra_constraints) else self.extra_constraints
            )

        f_ext = None
        N = 0.0
        cts, qd_solve = self.contacts(q, qd) if self.contacts is not None else ([], qd)
        if self.in_contact:
            r = T[:3, :3] @ np.asarray(cfg.contact_point, float)
            w = np.concatenate([[0.0, 0.0, 1.0], np.cross(r, [0.0, 0.0, 1.0])])
            if K or D:  # keep the posture term from lifting the tool: remove its push along w
                tau_ff = self._without_push(q, qd, alpha, beta, tau_ff, tau_motor_ff, w, kw)
                tau_motor_ff = tau_ff + self.damping * qd
        if self.in_contact and not cts:  # no contacts in the solve: the table's force estimated into f_ext
            res0 = self.solver.solve(q, qd, alpha, beta, tau_ff=tau_ff, **kw)
            Gc, _ = self.solver.response_columns(self._all)
            Jw = np.asarray(self.chain.jacobian(q)).T @ w
            lam = float(Jw @ Gc @ Jw)
            N = max(0.0, (G - float(w @ res0.link_acc[-1])) / lam) if lam > 1e-12 else 0.0
            u = np.array([v_des[0], v_des[1], 0.0])
            speed = np.linalg.norm(u)
            u = u / speed * min(1.0, speed / 0.01) if speed > 1e-9 else np.zeros(3)
            F = N * np.array([0.0, 0.0, 1.0]) - cfg.mu_estimate * N * u
            f_ext = np.zeros((self.chain.n_segments, 6))
            f_ext[-1] = np.concatenate([F, np.cross(r, F)])
        if cts:
            kw["contacts"] = cts
        if cfg.time_step is not None and (self.friction is not None or cts):
            kw["time_step"] = cfg.time_step  # the discrete-time mode: the conditions at the period's end
        res = self.solver.solve(q, qd_solve, alpha, beta, f_ext=f_ext, tau_ff=tau_ff, friction=self.friction, **kw)
        if cts:  # the model's upward force of the surfaces, N
            N = float(np.asarray(res.contact_force)[:, 2].sum())
        tau = np.asarray(res.tau_command) + tau_motor_ff + self._friction_feedforward(qd, res.qdd)
        if self.support_share is not None:
            tau = tau - self.support_share(res, q)
        inputs = dict(q=q, qd=qd, alpha=alpha, beta=beta, f_ext=f_ext, tau_ff=tau_ff, motor_ff=tau_motor_ff, **kw)
        return tau, CycleInfo(
            pose=T, twist=tw, error=e, normal_force_estimate=N, contact=self.in_contact, result=res, inputs=inputs
        )

    def _friction_feedforward(self, qd, qdd) -> np.ndarray:
        """Torque added for joint friction by the ``"sign"`` and ``"smooth"`` modes (zero otherwise)."""
        mode, eps = self.config.friction_mode, self.config.friction_velocity_tolerance
        if mode == "sign":
            moving = np.abs(qd) > eps
            return self.joint_friction * np.where(moving, np.sign(qd), np.sign(qdd))
        if mode == "smooth":
            return self.joint_friction * np.tanh(qd / eps)
        return np.zeros(self.n)

    def _without_push(self, q, qd, alpha, beta, tau_ff, tau_motor_ff, w, kw):
        """``tau_ff`` with the motor posture part's effect on the released direction ``w`` removed."""
        self.solver.solve(q, qd, alpha, beta, tau_ff=tau_ff, **kw)
        Gc, _ = self.solver.response_columns(self._all)
        Jw = np.asarray(self.chain.jacobian(q)).T @ w
        lam = float(Jw @ Gc @ Jw)
        if lam <= 1e-12:
            return tau_ff
        push = float(Jw @ Gc @ tau_motor_ff) / lam
        return tau_ff - Jw * push


def cascaded_acceleration(e, tw, gains: Gains, config: ControllerConfig, alpha=None) -> tuple[np.ndarray, np.ndarray]:
    """Desired spatial acceleration (6,) and twist (6,) of the cascaded P at one frame, base axes.

    ``a = k_vel (sat(k_pos e) - tw)`` per linear / angular half, the desired velocity saturated at
    ``config.v_max`` / ``config.w_max``; zero ("stay", so joints the task does not move may
    stick) while the error along the constrained directions is inside ``config.hold_band``.

    Parameters
    ----------
    e : ndarray, shape (6,)
        Pose error towards the goal (:func:`vereshchagin.task.pose_error`: m, rad).
    tw : ndarray, shape (6,)
        The frame's twist (m/s, rad/s).
    gains : Gains
        ``k_pos``, ``k_vel`` (linear, angular).
    config : ControllerConfig
        ``v_max``, ``w_max``, ``hold_band``.
    alpha : ndarray, shape (6, m), optional
        The constrained directions (orthonormal columns) the hold band measures the error
        along; None: all six.

    Returns
    -------
    a : ndarray, shape (6,)
        Desired acceleration [linear (m/s^2); angular (rad/s^2)].
    v : ndarray, shape (6,)
        Desired twist [linear (m/s); angular (rad/s)], saturated.
    """
    v = np.concatenate(
        [_saturate(gains.k_pos[0] * e[:3], config.v_max), _saturate(gains.k_pos[1] * e[3:], config.w_max)]
    )
    a = np.concatenate([gains.k_vel[0] * (v[:3] - tw[:3]), gains.k_vel[1] * (v[3:] - tw[3:])])
    band = config.hold_band
    if band is not None:
        e_task = e if alpha is None else alpha @ (alpha.T @ e)  # the error along the constrained directions
        if np.linalg.norm(e_task[:3]) < band[0] and np.linalg.norm(e_task[3:]) < band[1]:
            a[:] = 0.0
    return a, v


def _saturate(v: np.ndarray, limit: float) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    return v if norm <= limit else v * (limit / norm)
