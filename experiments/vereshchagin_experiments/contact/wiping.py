"""Wiping case (issue 27): a Gen3 wipes a table at 1 kHz, before and after the discrete-time mode.

Robot: the contact experiments' Gen3 (:func:`~.use_cases.gen3_model`: joint friction
:data:`~.use_cases.JOINT_FRICTION`, damping :data:`~.use_cases.JOINT_DAMPING`) from
:data:`vereshchagin.robots.GEN3_START_POSE`. The tool (the end-effector origin) rests on a
horizontal table: a :class:`vereshchagin.Contact` support with Coulomb friction :data:`MU`. The
motors press it down with :data:`PRESS` (a force at the tool, motor side) and a task moves it back
and forth along x, ``x0 + AMPLITUDE sin(2 pi t / CYCLE)``, holding y and the orientation (five
directions; z is the table's): PD on the reference, ``a = a_ref + KP e + KD (v_ref - v)``.

The plant is our own solver, with the same friction and contact (a correct model), so the two
variants differ only in discrete time:

- ``instant`` (before; what a new user writes first): the controller's friction-aware solve at the
  instant, and the plant integrates the instant solve's ``qdd`` explicitly (semi-implicit Euler:
  ``qd += dt qdd``, ``q += dt qd``), with joint friction ``Friction(static=f)`` at its default rest
  tolerance. A joint whose velocity friction should stop overshoots zero instead: its velocity
  changes sign step after step, and the friction torque and the command with it;
- ``step`` (after): the controller solves over the next period (``time_step=dt``, the
  discrete-time mode of :class:`~.controller.CascadedController`) and the plant is
  :meth:`vereshchagin.Solver.step`, the exact velocity-level step (a joint friction can hold ends
  the step exactly at rest).

Measured (:func:`metrics`) per joint over the run: the steps in which its velocity changes sign,
and the jumps of its commanded torque at its stick / slip switches (a switch: the plant's friction
regime of the joint, sticking or sliding up or down, changes from one step to the next).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vereshchagin import Contact, Friction, Solver, robots
from vereshchagin.task import beta_for, directions, pose_error

from .controller import CONTROL_PERIOD
from .surfaces import FACETS, point_jacobian
from .use_cases import gen3_model

__all__ = ["AMPLITUDE", "CYCLE", "MU", "PRESS", "STEPS", "VARIANTS", "Wipe", "metrics", "wiping"]

VARIANTS = ("instant", "step")
STEPS = 2000
"""Control periods of a run (2 s at 1 kHz)."""
AMPLITUDE = 0.05
"""m: half the wiping stroke along x."""
CYCLE = 1.0
"""s: one back-and-forth stroke."""
PRESS = 10.0
"""N: downward force the motors press the tool on the table with (on top of the arm's weight)."""
MU = 0.3
"""Coulomb friction coefficient between tool and table."""
GAINS = (400.0, 40.0)
"""``(KP, KD)`` of the task PD (1/s^2, 1/s)."""
POSTURE_DAMPING = 3.0
"""N m s/rad: motor-side joint damping for the two free directions (self-motion and z)."""
REST_TOLERANCE = 1e-2
"""rad/s: |qd| at or below which the controller's solve takes a joint as resting (the experiments')."""
CONTACT_TOLERANCE = 1e-2
"""m/s: the instant solves' ``contact_velocity_tolerance``: the explicit integration lets the tool's
normal velocity drift from zero, which the instant would otherwise refuse as an impact."""
DIRECTIONS = ("x", "y", "rx", "ry", "rz")
GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass
class Wipe:
    """One wiping run: one row per control period.

    Attributes
    ----------
    variant : str
        ``"instant"`` or ``"step"``.
    t : ndarray, shape (k,)
        Time (s).
    qd : ndarray, shape (k, 7)
        Joint velocities at the end of each period (rad/s).
    command : ndarray, shape (k, 7)
        Motor torques sent (N m).
    regime : ndarray, shape (k, 7)
        The plant's friction regime per joint: 0 sticking, +1 / -1 the friction torque's sign.
    x_error : ndarray, shape (k,)
        Tool position minus reference along x (m).
    normal_force : ndarray, shape (k,)
        The table's normal force on the tool (N).
    """

    variant: str
    t: np.ndarray
    qd: np.ndarray
    command: np.ndarray
    regime: np.ndarray
    x_error: np.ndarray
    normal_force: np.ndarray
    info: dict = field(default_factory=dict)


def _reference(t: float, x0: float) -> tuple[float, float, float]:
    """Position, velocity and acceleration of the tool's x reference at time ``t`` (m, m/s, m/s^2)."""
    w = 2.0 * np.pi / CYCLE
    return x0 + AMPLITUDE * np.sin(w * t), AMPLITUDE * w * np.cos(w * t), -AMPLITUDE * w * w * np.sin(w * t)


def _command(chain, solver, q, qd, t, T0, friction, contact, dt) -> np.ndarray:
    """Motor torques (N m) of one control period: task PD solve + the press and posture damping."""
    T = np.asarray(chain.fk(q))
    tw = np.asarray(chain.twist(q, qd))
    x, v, a = _reference(t, T0[0, 3])
    goal = T0.copy()
    goal[0, 3] = x
    v_ref = np.array([v, 0.0, 0.0, 0.0, 0.0, 0.0])
    a_des = np.array([a, 0.0, 0.0, 0.0, 0.0, 0.0]) + GAINS[0] * pose_error(T, goal) + GAINS[1] * (v_ref - tw)
    alpha = directions(DIRECTIONS)
    beta = beta_for(alpha, a_des, tw, GRAVITY)
    push = point_jacobian(chain, q, robots.GEN3_TIP_LINK, np.zeros(3)).T @ np.array([0.0, 0.0, -PRESS])
    motor_ff = push - POSTURE_DAMPING * qd
    tau_ff = motor_ff - np.asarray(chain.damping) * qd
    over = {"time_step": dt} if dt else {"contact_velocity_tolerance": CONTACT_TOLERANCE}
    res = solver.solve(q, qd, alpha, beta, tau_ff=tau_ff, friction=friction, contacts=[contact], **over)
    return np.asarray(res.tau_command) + motor_ff


def wiping(variant: str, steps: int = STEPS) -> Wipe:
    """Run the wiping case in one of :data:`VARIANTS` (module doc).

    Parameters
    ----------
    variant : {"instant", "step"}
        Before (instant controller, explicit plant) or after (step controller, exact step plant).
    steps : int
        Control periods (1 ms each).

    Returns
    -------
    Wipe
        The run's log.

    Raises
    ------
    ValueError
        Unknown ``variant``.
    """
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    _, chain = gen3_model()
    ctl, plant = Solver(chain, gravity=GRAVITY), Solver(chain, gravity=GRAVITY)
    f = np.asarray(chain.friction)
    ctl_friction = Friction(static=f, velocity_tolerance=REST_TOLERANCE)
    plant_friction = Friction(static=f)  # the default rest tolerance: what a new user passes
    contact = Contact(robots.GEN3_TIP_LINK, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), mu=MU, facets=FACETS)
    dt, step = CONTROL_PERIOD, variant == "step"
    q, qd = np.array(robots.GEN3_START_POSE, float), np.zeros(chain.n_joints)
    T0 = np.asarray(chain.fk(q))
    n = chain.n_joints
    log = {k: np.zeros((steps, n)) for k in ("qd", "command", "regime")}
    x_err, force = np.zeros(steps), np.zeros(steps)
    for k in range(steps):
        t = k * dt
        tau = _command(chain, ctl, q, qd, t, T0, ctl_friction, contact, dt if step else None)
        plant_in = dict(tau_ff=tau - np.asarray(chain.damping) * qd, friction=plant_friction, contacts=[contact])
        if step:
            q, qd, res = plant.step(q, qd, dt, **plant_in)
        else:
            res = plant.solve(q, qd, contact_velocity_tolerance=CONTACT_TOLERANCE, **plant_in)
            qd = qd + dt * np.asarray(res.qdd)
            q = q + dt * qd
        sticking = np.asarray(res.status) == 1
        log["regime"][k] = np.where(sticking, 0.0, np.sign(np.asarray(res.friction_torque)))
        log["qd"][k], log["command"][k] = qd, tau
        x_err[k] = np.asarray(chain.fk(q))[0, 3] - _reference(t + dt, T0[0, 3])[0]
        force[k] = float(np.asarray(res.contact_force)[0, 2])
    t = dt * np.arange(1, steps + 1)
    return Wipe(variant, t, log["qd"], log["command"], log["regime"], x_err, force)


def metrics(run: Wipe) -> dict:
    """Sign changes, torque jumps at stick / slip switches, tracking and effort of one run.

    Returns
    -------
    dict
        ``sign_changes`` ((7,) steps in which the joint's velocity changes sign, per
        :data:`STEPS` steps), ``switches`` ((7,) stick / slip switches), ``jump_max`` and
        ``jump_mean`` (N m: largest and mean |tau_k - tau_k-1| of the command at a switch, over
        all joints; 0 without switches), ``chatter`` (mean |tau_k - tau_k-1| over joints and
        steps, N m), ``rms_x_error`` (m), ``normal_force`` (mean, N), ``tau2`` (sum over joints
        of the integral of tau^2, N^2 m^2 s).
    """
    scale = STEPS / len(run.t)
    s = np.sign(run.qd)
    flips = (s[1:] * s[:-1]) < 0
    switch = run.regime[1:] != run.regime[:-1]
    dtau = np.abs(np.diff(run.command, axis=0))
    jumps = dtau[switch]
    return dict(
        sign_changes=flips.sum(axis=0) * scale,
        switches=switch.sum(axis=0) * scale,
        jump_max=float(jumps.max()) if jumps.size else 0.0,
        jump_mean=float(jumps.mean()) if jumps.size else 0.0,
        chatter=float(dtau.mean()),
        rms_x_error=float(np.sqrt(np.mean(run.x_error**2))),
        normal_force=float(run.normal_force.mean()),
        tau2=float((run.command**2).sum() * (run.t[1] - run.t[0])),
    )
