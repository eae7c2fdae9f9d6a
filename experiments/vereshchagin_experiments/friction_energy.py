"""How much motor effort does exact static friction save on a 7-joint arm? Tasks, controllers, runs.

Vukcevic (TR 03-2018, Hochschule Bonn-Rhein-Sieg, 2018) motivates the static-friction extension of
the Popov-Vereshchagin solver by energy: motors should not fight what friction can hold. This
module measures it in closed loop on the MuJoCo Gen3 of the contact experiments
(:mod:`vereshchagin_experiments.contact`): same plant, same cascaded P controller, same task gains; the
controllers differ only in how joint friction enters the command
(:attr:`~vereshchagin_experiments.contact.controller.ControllerConfig.friction_mode`):

- ``none``: friction-unaware, the plain solve; feedback alone deals with friction;
- ``sign``: naive compensation, plain solve + ``f_j sign(qd_j)``, at rest ``f_j`` times the sign of
  the commanded acceleration (classical Coulomb feed-forward);
- ``smooth``: plain solve + ``f_j tanh(qd_j / eps_v)`` with ``eps_v`` = 0.01 rad/s, the usual
  chatter-free variant a reviewer asks for: the same compensation in motion, (almost) none at rest;
  it separates "do not fight friction at rest" from "let friction hold";
- ``maxmin``: the solver's exact max-min with the least-command rule (``friction=``), joints with
  |qd| <= eps_v at rest;
- ``maxmin_step``: the same solve over the next control period (``time_step`` = 1 ms, the
  discrete-time mode of :class:`~vereshchagin_experiments.contact.controller.CascadedController`):
  friction acts on the joint velocities at the end of the period, so a joint that stays at rest
  gets the friction that holds it, continuous in the P loop's corrections. At the instant
  (``maxmin``) the max-min lets friction hold only joints whose commanded acceleration is exactly
  zero; the P loop's tiny corrections never are, so it pays friction in the direction of each
  correction, like the naive scheme. (It replaces a hold band, zero task acceleration inside
  0.05 mm / 0.5 mrad, which also changed the task feedback.)

Plant: :func:`vereshchagin_experiments.contact.use_cases.gen3_model` (joint friction
:data:`~vereshchagin_experiments.contact.use_cases.JOINT_FRICTION`, scaled by 0.5, 1, 2), 1 kHz. The
controllers' chain carries the same friction values (a correct friction model).

Tasks (:func:`tasks`), each a few seconds from the contact experiments' start pose:

- ``hold``, ``hold_payload``: hold the pose, without and with a 1 kg sphere in the gripper;
- ``slow``: the tool moves 6 cm along +x at 2 cm/s (3 cm quick), then holds; the four joints
  out of the arm's plane barely move;
- ``partial``: tool height and orientation held, x-y free (4 constraints, 3 free directions):
  what the rest of the arm does is left to the dynamics and friction (no posture term), from
  :data:`PARTIAL_POSE`, where the nominal friction can hold the free directions and half of it
  cannot;
- ``reach``: a fast minimum-jerk reach (20 cm in 1 s along (1.5, 1, -1)), then hold, for contrast.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from vereshchagin import robots
from .contact.controller import FREE_GAINS, CascadedController, ControllerConfig
from .contact.mujoco_plant import MujocoGen3, Scene, build_model
from .contact.use_cases import Phase, Run, gen3_model, run_loop
from vereshchagin import Solver

__all__ = [
    "CONTROLLERS",
    "FRICTION_SCALES",
    "PARTIAL_POSE",
    "PAYLOAD",
    "REST_TOLERANCE",
    "Log",
    "TaskSpec",
    "gravity_torques",
    "outcome",
    "run_all",
    "run_case",
    "simulate",
    "task_named",
    "tasks",
]

CONTROLLERS = {
    "none": "friction-unaware",
    "sign": "naive sign compensation",
    "smooth": "smoothed (tanh) compensation",
    "maxmin": "exact max-min (least command)",
    "maxmin_step": "exact max-min over the step (discrete time)",
}
"""Controller key -> label (the key without ``_step`` is :attr:`ControllerConfig.friction_mode`;
``_step``: the discrete-time mode, :attr:`ControllerConfig.time_step` = the plant's period)."""
PARTIAL_POSE = (0.0029, 1.9681, 3.1165, 1.8318, -0.0127, -1.4350, 0.5956)
"""Joint angles (rad) of the partial task: the start pose's tool height and orientation, the
arm 96 % of the way (in joint space, projected back onto that height and orientation) from the
start pose to the minimum of the potential energy with that height and orientation (SLSQP).
There the frictionless free acceleration is 4.3 rad/s^2 (norm over joints); the exact max-min
with zero task acceleration says all seven joints stick with the nominal and the doubled
friction, and two stick with half of it."""
FRICTION_SCALES = (0.5, 1.0, 2.0)
"""Factors on the plant's and the model's joint friction."""
PAYLOAD = (1.0, (0.0, 0.0, 0.12))
"""1 kg sphere held 0.12 m along the end-effector z axis (between the fingers), known to the model."""
REST_TOLERANCE = 1e-2
"""rad/s: |qd| at or below which a joint is at rest, for the max-min and the naive sign (the
contact experiments' value: above the plant's creep under dry friction)."""


@dataclass(frozen=True)
class TaskSpec:
    """One task of the experiment.

    Attributes
    ----------
    name, title : str
    phases : callable
        ``phases(T0) -> list of Phase`` from the start pose ``T0`` (4x4, base frame).
    q0 : tuple
        Start joint angles (rad), at rest.
    payload : bool
        The gripper holds :data:`PAYLOAD`.
    directions : tuple of str
        Constrained directions (base axes); the task error is measured along them only.
    posture_gains : (float, float)
        Motor-side joint posture term ``(K, D)`` (the same for every controller).
    v_max : float
        Saturation of the desired linear speed (m/s).
    hold : str
        Name of the phase over which drift while holding is measured.
    """

    name: str
    title: str
    phases: Callable
    q0: tuple = tuple(robots.GEN3_START_POSE)
    payload: bool = False
    directions: tuple = ("x", "y", "z", "rx", "ry", "rz")
    posture_gains: tuple = (20.0, 3.0)
    v_max: float = 0.05
    hold: str = "hold"


REACH = 0.20
"""m, length of the fast reach."""


def _moved(T, offset) -> np.ndarray:
    T = np.array(T, float)
    T[:3, 3] += offset
    return T


def _ramp(length: float, speed: float, direction) -> Callable:
    """``path(goal, t)``: the goal moved along unit ``direction`` at ``speed`` (m/s) up to ``length`` (m)."""
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    return lambda goal, t: _moved(goal, u * min(speed * t, length))


def _min_jerk(offset, duration: float) -> Callable:
    """``path(goal, t)``: minimum-jerk motion of the goal by ``offset`` (m) in ``duration`` (s)."""
    d = np.asarray(offset, float)

    def path(goal, t):
        s = min(t / duration, 1.0)
        return _moved(goal, d * (10 * s**3 - 15 * s**4 + 6 * s**5))

    return path


def _still(T) -> np.ndarray:
    return T


def tasks(quick: bool = False) -> list[TaskSpec]:
    """The five tasks (module doc); ``quick`` shortens them (about 1-1.5 s each)."""
    hold_s = 0.6 if quick else 2.0
    settle = 0.3 if quick else 1.0
    slow_len = 0.02 if quick else 0.06
    slow_v = 0.02

    def hold(T0):
        return [Phase("hold", _still, hold_s)]

    def slow(T0):
        return [
            Phase("move", _still, slow_len / slow_v, path=_ramp(slow_len, slow_v, (1.0, 0.0, 0.0))),
            Phase("hold", lambda T: _moved(T0, (slow_len, 0.0, 0.0)), settle),
        ]

    def reach(T0):
        off = REACH * np.array([1.5, 1.0, -1.0]) / np.sqrt(4.25)
        return [Phase("move", _still, 1.0, path=_min_jerk(off, 1.0)), Phase("hold", lambda T: _moved(T0, off), settle)]

    return [
        TaskSpec("hold", "(a) hold the pose", hold),
        TaskSpec("hold_payload", "(a) hold the pose with a 1 kg payload", hold, payload=True),
        TaskSpec("slow", f"(b) slow motion, {100 * slow_len:.0f} cm along +x at 2 cm/s, then hold", slow),
        TaskSpec(
            "partial",
            "(c) hold tool height and orientation, x-y free",
            hold,
            q0=PARTIAL_POSE,
            directions=("z", "rx", "ry", "rz"),
            posture_gains=(0.0, 0.0),
        ),
        TaskSpec("reach", "(d) fast reach, 20 cm in 1 s (minimum jerk, peak 0.375 m/s), then hold", reach, v_max=0.5),
    ]


def task_named(name: str, quick: bool = False) -> TaskSpec:
    """The task of :func:`tasks` called ``name``; ValueError if there is none."""
    for task in tasks(quick):
        if task.name == name:
            return task
    raise ValueError(f"unknown task {name!r}; use one of {[t.name for t in tasks(quick)]}")


@dataclass
class Log:
    """Per-sample extras of one run, arrays over the run's samples.

    Attributes
    ----------
    command : (T, n)
        Torque the controller wrote (N m, before the plant's saturation).
    model_command : (T, n)
        The solver's ``tau_command`` in that cycle (N m).
    error : (T, 6)
        Pose error to the current reference (m, rad; base axes), as the controller saw it.
    plant_stick : (T, n) bool
        The plant's friction held the joint (:meth:`MujocoGen3.joint_friction_state`).
    plant_friction : (T, n)
        The plant's friction torque on each joint (N m).
    model_stick : (T, n) bool
        The max-min holds the joint with friction: at rest with zero commanded acceleration (status
        stick, or slip at the friction bound with ``qdd_j`` = 0 to 1e-9), ``maxmin`` only.
    inputs : list of dict
        The solver's inputs per cycle (only with ``keep_inputs``).
    """

    command: np.ndarray
    model_command: np.ndarray
    error: np.ndarray
    plant_stick: np.ndarray
    plant_friction: np.ndarray
    model_stick: np.ndarray
    inputs: list = field(default_factory=list)


def _recorder(robot: MujocoGen3, total: int, n: int, keep_inputs: bool):
    """A :func:`run_loop` ``on_cycle`` hook filling a :class:`Log` of ``total`` samples."""
    log = Log(
        np.zeros((total, n)),
        np.zeros((total, n)),
        np.zeros((total, 6)),
        np.zeros((total, n), bool),
        np.zeros((total, n)),
        np.zeros((total, n), bool),
    )

    def on_cycle(k, command, info):
        res = info.result
        log.command[k] = command
        log.model_command[k] = res.tau_command
        log.error[k] = info.error
        log.plant_stick[k], log.plant_friction[k] = robot.joint_friction_state()
        if res.status is not None and "time_step" in info.inputs:  # over a step: 1 = ends the step held
            log.model_stick[k] = np.asarray(res.status) == 1
        elif res.status is not None:  # at rest and no commanded acceleration: friction (partly) holds it
            log.model_stick[k] = (np.asarray(res.status) != 0) & (np.abs(np.asarray(res.qdd)) <= 1e-9)
        if keep_inputs:
            log.inputs.append(info.inputs)

    return log, on_cycle


def simulate(task: TaskSpec, controller: str, friction_scale: float = 1.0, keep_inputs: bool = False) -> Run:
    """Run ``task`` with ``controller`` (a key of :data:`CONTROLLERS`) on the MuJoCo Gen3.

    Returns
    -------
    Run
        The contact experiments' log (:class:`~vereshchagin_experiments.contact.use_cases.Run`; ``tau`` is the
        torque the plant applied); ``info`` holds ``log`` (:class:`Log`), ``chain``, ``config``,
        ``friction_scale`` and ``task``.
    """
    urdf, chain = gen3_model(friction_scale, PAYLOAD if task.payload else None)
    q0 = np.array(task.q0)
    robot = MujocoGen3(build_model(urdf, chain, Scene()), q0)
    if controller not in CONTROLLERS:
        raise ValueError(f"controller must be one of {list(CONTROLLERS)}, got {controller!r}")
    step = controller.endswith("_step")
    config = ControllerConfig(
        free_gains=FREE_GAINS,
        friction_mode=controller.removesuffix("_step"),
        v_max=task.v_max,
        friction_velocity_tolerance=REST_TOLERANCE,
        posture_gains=task.posture_gains,
        free_directions=task.directions,
        time_step=robot.period if step else None,
    )
    ctl = CascadedController(chain, Solver(chain, gravity=[0.0, 0.0, -9.81]), config)
    phases = task.phases(np.asarray(chain.fk(q0)))
    total = int(round(sum(p.duration for p in phases) / robot.period)) + len(phases)
    log, on_cycle = _recorder(robot, total, chain.n_joints, keep_inputs)
    run = run_loop(robot, ctl, phases, task.name, controller, (0.0, 0.0, 0.0), on_cycle=on_cycle)
    k = len(run.t)
    for name in ("command", "model_command", "error", "plant_stick", "plant_friction", "model_stick"):
        setattr(log, name, getattr(log, name)[:k])
    run.info.update(log=log, chain=chain, config=config, friction_scale=friction_scale, task=task)
    return run


def gravity_torques(task: TaskSpec, q, friction_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The plant's gravity torque ``g(q)`` (N m, what the motors hold at rest) and friction ``f``.

    From MuJoCo's bias force at ``qd = 0`` (independent of our solver), with the task's payload.
    """
    import mujoco

    urdf, chain = gen3_model(friction_scale, PAYLOAD if task.payload else None)
    model = build_model(urdf, chain, Scene())
    data = mujoco.MjData(model)
    data.qpos[:] = np.asarray(q, float)
    mujoco.mj_forward(model, data)
    return data.qfrc_bias[: chain.n_joints].copy(), model.dof_frictionloss[: chain.n_joints].copy()


def outcome(run: Run) -> dict:
    """Effort and task metrics of one run (scalars; joint sums where per joint).

    Keys: ``tau2`` (sum over joints of the integral of tau^2, N^2 m^2 s), ``work`` (integral of
    sum |tau qd|, J), ``peak`` (max |tau| over joints and samples, N m), ``rms_error`` and
    ``final_error`` (m: norm of the translational error along the task's constrained linear
    directions; RMS over the run, and at its end), ``rms_rot`` (rad, rotational error RMS),
    ``drift`` (m: tool displacement over the hold phase; for the partial task its x-y part, the
    free directions), ``stick_plant`` / ``stick_model`` (mean number of joints the plant's friction
    holds / the max-min holds with friction, :class:`Log`), ``friction_share`` (mean over the hold phase of
    sum |plant friction torque| / sum |motor + friction torque|: the share of the holding torque that
    friction supplied), ``saturated`` (fraction of samples with a command beyond the effort limits),
    ``chatter`` (mean |tau_k+1 - tau_k| of the command over joints and steps, N m per 1 ms step).
    """
    from .contact import metrics

    log: Log = run.info["log"]
    task: TaskSpec = run.info["task"]
    e = metrics.effort(run)
    lin = [i for i, d in enumerate(("x", "y", "z")) if d in task.directions]
    err = np.linalg.norm(log.error[:, lin], axis=1)
    rot = np.linalg.norm(log.error[:, 3:], axis=1)
    hold = run.window(task.hold)
    tip = run.tip[hold]
    free = [i for i, d in enumerate(("x", "y", "z")) if d not in task.directions] or [0, 1, 2]
    held = np.abs(run.tau[hold] + log.plant_friction[hold])
    limit = np.asarray(run.info["chain"].effort_limit, float)
    return dict(
        tau2=float(e["energy_tau2"].sum()),
        work=float(e["energy_abs"].sum()),
        peak=float(np.abs(run.tau).max()),
        rms_error=float(np.sqrt(np.mean(err**2))),
        final_error=float(err[-1]),
        rms_rot=float(np.sqrt(np.mean(rot**2))),
        drift=float(np.linalg.norm(tip[-1, free] - tip[0, free])),
        stick_plant=float(log.plant_stick.sum(1).mean()),
        stick_model=float(log.model_stick.sum(1).mean()),
        friction_share=float(np.abs(log.plant_friction[hold]).sum() / max(held.sum(), 1e-12)),
        saturated=float((np.abs(log.command) > limit).any(1).mean()),
        chatter=float(np.abs(np.diff(log.command, axis=0)).mean()),
    )


def _trace(run: Run, every: int = 5) -> dict:
    """Every ``every``-th sample of what the figures show (time s, torque N m, sticking joints, errors)."""
    log: Log = run.info["log"]
    task: TaskSpec = run.info["task"]
    lin = [i for i, d in enumerate(("x", "y", "z")) if d in task.directions]
    sl = slice(None, None, every)
    return dict(
        t=run.t[sl] - run.t[0],
        tau=run.tau[sl],
        stick=log.plant_stick[sl].sum(1),
        error=np.linalg.norm(log.error[sl][:, lin], axis=1),
        rot=np.linalg.norm(log.error[sl, 3:], axis=1),
    )


def run_case(task_name: str, controller: str, friction_scale: float, quick: bool) -> dict:
    """One run, reduced to picklable results (for a process pool).

    Returns
    -------
    dict
        ``task``, ``controller``, ``scale``, ``outcome`` (:func:`outcome`), ``trace`` (figure data),
        ``held_q`` (joint angles at the end, rad), ``simulated`` (s).
    """
    run = simulate(task_named(task_name, quick), controller, friction_scale)
    return dict(
        task=task_name,
        controller=controller,
        scale=friction_scale,
        outcome=outcome(run),
        trace=_trace(run),
        held_q=run.q[-1].copy(),
        simulated=float(run.t[-1] - run.t[0]),
    )


def run_all(quick: bool = False, workers: int = 2, progress: Optional[Callable[[str], None]] = None) -> list[dict]:
    """Every task x controller x friction scale (quick: the nominal friction only), see :func:`run_case`.

    ``workers`` > 1 runs the cases in that many processes.
    """
    scales = (1.0,) if quick else FRICTION_SCALES
    jobs = [(t.name, c, s, quick) for s in scales for t in tasks(quick) for c in CONTROLLERS]
    say = progress or (lambda line: None)
    results = []
    if workers > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            for k, res in enumerate(pool.map(run_case, *zip(*jobs))):
                results.append(res)
                say(f"[friction-energy] {k + 1}/{len(jobs)} {res['task']} {res['controller']} x{res['scale']}")
    else:
        for k, job in enumerate(jobs):
            results.append(run_case(*job))
            say(f"[friction-energy] {k + 1}/{len(jobs)} {job[0]} {job[1]} x{job[2]}")
    return results
