"""A standing quadruped shifts its weight: Solo 12 in MuJoCo with the whole-body least-effort
controller built on the solver (issue 28).

Model: ``Tree.from_urdf(solo12_urdf(), base="free")`` (:mod:`.solo_plant`: the same URDF in the
plant, a free joint, sphere feet on a floor). Each control period (1 kHz) the controller calls
:func:`vereshchagin.whole_body.least_effort`: the task is the base's pose (six rows on the base body: PD on a
reference, ``a = a_ref + KP e + KD (v_ref - v)``), the four feet are supports with friction cones
(:data:`MU_MODEL`, :data:`FACETS` facets), the base has no motor: it returns the twelve joint
torques of least effort ``sum(tau^2)`` with foot forces in their cones, which go to the plant's
motors. A joint-space damping (:data:`JOINT_DAMPING`) is added as feed-forward torque.

Motion: from :data:`STAND` the base moves (minimum jerk, :data:`TIMES`) toward the centroid of
the feet FL, FR, HL (:data:`SHIFT`: the whole way, the centre of mass then over that triangle), holds, and returns; its height and orientation
are held.

Measured: base position and orientation errors, each motor's RMS torque, each foot's normal force
in the model (the least-effort answer) and in the plant (MuJoCo's contact forces), the largest
tangential-to-normal ratio of the model's forces, and foot slip in the plant.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from vereshchagin import Contact, Solver, Tree
from vereshchagin.whole_body import least_effort
from vereshchagin.task import beta_for, pose_error

from . import solo_plant as sp
from ._common import min_jerk

__all__ = ["SHIFT", "STAND", "TIMES", "StandRun", "metrics", "run"]

STAND = np.array([0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6])
"""rad: the joints' standing posture (HAA, HFE, KFE per leg FL, FR, HL, HR)."""
SHIFT = 1.0
"""Fraction of the way from the base's start (x, y) to the centroid of the feet FL, FR, HL."""
TIMES = (0.5, 2.0, 1.0, 2.0, 0.5)
"""s: settle, shift, hold, return, hold."""
GAINS = (400.0, 40.0)
"""``(KP, KD)`` of the base's PD (1/s^2, 1/s)."""
JOINT_DAMPING = 0.02
"""N m s/rad: damping added to each motor's command."""
MU_MODEL = 0.6
"""The controller's friction coefficient (the plant's is :data:`solo_plant.MU`: a margin)."""
FACETS = 4
GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass
class StandRun:
    """One run, one row per control period.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Time (s).
    base_error : ndarray, shape (k, 2)
        Base position error (m) and orientation error (rad).
    torque : ndarray, shape (k, 12)
        Motor torques (N m).
    model_force : ndarray, shape (k, 4, 3)
        The least-effort foot forces (N, world axes).
    plant_normal : ndarray, shape (k, 4)
        The plant's normal force at each foot (N).
    foot_speed : ndarray, shape (k, 4)
        Each foot's speed in the plant (m/s).
    base : ndarray, shape (k, 3)
        Base position (m).
    """

    t: np.ndarray
    base_error: np.ndarray
    torque: np.ndarray
    model_force: np.ndarray
    plant_normal: np.ndarray
    foot_speed: np.ndarray
    base: np.ndarray
    info: dict = field(default_factory=dict)


def reference(t: float, p0: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Base position, velocity, acceleration at ``t`` (world; m, m/s, m/s^2)."""
    settle, shift, hold, back, _ = TIMES
    d = target - p0
    if t < settle:
        return p0.copy(), np.zeros(3), np.zeros(3)
    if t < settle + shift:
        s, ds, dds = min_jerk((t - settle) / shift)
        return p0 + s * d, ds / shift * d, dds / shift**2 * d
    if t < settle + shift + hold:
        return target.copy(), np.zeros(3), np.zeros(3)
    s, ds, dds = min_jerk((t - settle - shift - hold) / back)
    return target - s * d, -ds / back * d, -dds / back**2 * d


def standing_state(tree: Tree) -> np.ndarray:
    """q (nq) of the robot standing at :data:`STAND`, base level at the origin's x, y, feet on the floor."""
    low = min(np.asarray(tree.fk(STAND, f))[2, 3] for f in sp.FEET)
    return np.r_[0.0, 0.0, sp.FOOT_RADIUS - low, 0.0, 0.0, 0.0, 1.0, STAND]


def _feet_world(tree: Tree, q: np.ndarray) -> np.ndarray:
    R = sp.base_rotation(q)
    return np.array([R @ np.asarray(tree.fk(q[7:], f))[:3, 3] + q[:3] for f in sp.FEET])


def _command(tree, solver, supports, q, qd, ref, R0):
    """Least-effort torques (12), foot forces (4 x 3) and the base's pose error (6: position,
    rotation vector) for the base reference ``ref`` (p, v, a) and orientation ``R0``."""
    R = sp.base_rotation(q)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, q[:3]
    goal = np.eye(4)
    goal[:3, :3], goal[:3, 3] = R0, ref[0]
    twist = np.r_[R @ qd[:3], R @ qd[3:6]]  # world axes, at the base origin
    e = pose_error(T, goal)
    a = np.r_[ref[2], 0.0, 0.0, 0.0] + GAINS[0] * e + GAINS[1] * (np.r_[ref[1], 0, 0, 0] - twist)
    alpha = np.eye(6)
    beta = beta_for(alpha, a, twist, GRAVITY)
    ff = np.r_[np.zeros(6), -JOINT_DAMPING * qd[6:]]
    r = least_effort(solver, q, qd, task={None: (alpha, beta)}, supports=supports, tau_ff=ff)
    return r.tau[6:] + ff[6:], r.contact_force, e


def _plant_feet(plant, data) -> tuple[np.ndarray, np.ndarray]:
    """Normal force (N) and speed (m/s) of each foot in the plant."""
    normal = np.zeros(len(sp.FEET))
    f6 = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        for k, foot in enumerate(sp.FEET):
            if plant.geom(c.geom1).name == foot or plant.geom(c.geom2).name == foot:
                mujoco.mj_contactForce(plant, data, i, f6)
                normal[k] += f6[0]
    speed = np.zeros(len(sp.FEET))
    vel = np.zeros(6)
    for k, foot in enumerate(sp.FEET):
        mujoco.mj_objectVelocity(plant, data, mujoco.mjtObj.mjOBJ_GEOM, plant.geom(foot).id, vel, 0)
        speed[k] = np.linalg.norm(vel[3:])
    return normal, speed


def run(steps: int | None = None) -> StandRun:
    """Simulate the weight shift for ``steps`` periods (default: the whole motion)."""
    tree = Tree.from_urdf(sp.solo12_urdf(), base="free")
    solver = Solver(tree, gravity=GRAVITY)
    plant = sp.build(tree, GRAVITY)
    data = mujoco.MjData(plant)
    q0 = standing_state(tree)
    data.qpos[:] = np.r_[q0[:3], q0[6], q0[3:6], q0[7:]]
    mujoco.mj_forward(plant, data)
    feet = _feet_world(tree, q0)
    supports = [Contact(f, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), mu=MU_MODEL, facets=FACETS) for f in sp.FEET]
    p0 = q0[:3].copy()
    target = p0 + SHIFT * np.r_[feet[:3, :2].mean(axis=0) - p0[:2], 0.0]
    steps = int(round(sum(TIMES) / sp.DT)) if steps is None else steps
    rows = {k: [] for k in ("t", "base_error", "torque", "model_force", "plant_normal", "foot_speed", "base")}
    for k in range(steps):
        q, qd = sp.to_model(data)
        ref = reference(k * sp.DT, p0, target)
        tau, forces, e = _command(tree, solver, supports, q, qd, ref, np.eye(3))
        data.ctrl[:] = tau
        normal, speed = _plant_feet(plant, data)
        err = np.r_[np.linalg.norm(e[:3]), np.linalg.norm(e[3:])]
        for key, val in zip(rows, (k * sp.DT, err, data.ctrl.copy(), forces, normal, speed, q[:3])):
            rows[key].append(val)
        mujoco.mj_step(plant, data)
    out = StandRun(*(np.asarray(rows[k], float) for k in rows))
    out.info.update(
        target=target, p0=p0, saturated=float(np.mean(np.any(np.abs(out.torque) >= sp.TORQUE_LIMIT, axis=1)))
    )
    return out


def metrics(run: StandRun) -> dict:
    """Numbers of one run: base errors (RMS / max, m and rad), RMS torque per motor (N m),
    ∫τ² (N² m² s), the largest |f_t| / f_n of the model's forces, the least model normal force
    per foot (N), the plant's mean normal force per foot while the base holds its shifted pose
    (N), the model's there, the largest foot speed in the plant (m/s)."""
    fn = run.model_force[:, :, 2]
    ft = np.linalg.norm(run.model_force[:, :, :2], axis=2)
    settle, shift, hold = TIMES[:3]
    held = (run.t >= settle + shift) & (run.t < settle + shift + hold)
    return {
        "rms_position_error": float(np.sqrt(np.mean(run.base_error[:, 0] ** 2))),
        "max_position_error": float(run.base_error[:, 0].max()),
        "max_orientation_error": float(run.base_error[:, 1].max()),
        "rms_torque": np.sqrt(np.mean(run.torque**2, axis=0)),
        "tau2": float(np.sum(run.torque**2) * sp.DT),
        "max_ratio": float(np.max(ft / np.maximum(fn, 1e-12))),
        "min_normal": fn.min(axis=0),
        "held_model_normal": fn[held].mean(axis=0) if held.any() else np.full(4, np.nan),
        "held_plant_normal": run.plant_normal[held].mean(axis=0) if held.any() else np.full(4, np.nan),
        "max_foot_speed": float(run.foot_speed[run.t >= TIMES[0]].max()) if (run.t >= TIMES[0]).any() else 0.0,
    }
