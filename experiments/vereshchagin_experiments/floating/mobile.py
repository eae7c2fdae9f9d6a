"""Mobile manipulation: a Kinova Gen3 on a holonomic base reaches over a table and slides its tool
along it, with the base helping (MuJoCo plant, controller built on the solver's planar base).

Robot: the Gen3 (:func:`vereshchagin.robots.gen3_urdf`, no gripper) mounted :data:`MOUNT` above the
origin of a box-shaped mobile base (:data:`BASE_MASS`, :data:`BASE_BOX`), one URDF for both sides.

- ``base`` variant (after): the controller's model is ``Tree.from_urdf(urdf, base="planar")``
  (docs/floating-base.md: q = (x, y, cos yaw, sin yaw, joints), qd = (v_x, v_y in base axes,
  yaw rate, joints)). A holonomic base has motors on its three planar DOF, so the base rows of
  the command (a force and a moment on the base, base axes) go to the base's motors: the task is
  then realized by the base and the arm together, with the solver's least-constraint split.
  Plant: MuJoCo, the same URDF with two slide joints (world x, y) and a yaw hinge under the base
  (three motors; the command's base force rotated into world axes).
- ``arm`` variant (before): the base locked (``Tree.from_urdf(urdf)``: the base welded to the
  world, its mass then irrelevant), the arm alone realizes the same task.

Task (both): on a minimum-jerk path from the tool's (``end_effector_link``) start pose
(:data:`vereshchagin.robots.GEN3_START_POSE`, base at the origin), the tool's full pose (world
axes) until its ball (:data:`TOOL_RADIUS`) touches the table ahead; then the tool presses on the
table with :data:`PRESS` N and slides along y and back, orientation held: a force set-point
contact (``vs.Contact(..., mu=MU, force=PRESS)``: the table pushes with exactly that force, its
friction opposes the sliding) and five task rows (x, y and the orientation; z is the contact's).
:data:`PATHS`: ``near`` within the locked arm's reach, ``far`` beyond it. The motors saturate at
their limits (the Gen3's effort limits, :data:`BASE_LIMITS`). Computed-torque PD on the path
through the solve (``a = a_ref + KP e + KD (v_ref - v)``, ``beta_for``), a posture term on the
arm (spring to the start pose, damping) and damping on the base's velocity as feed-forward
torques (the redundant directions). 1 kHz, MuJoCo ``implicitfast``, no joint friction; in the
plant only the tool's ball touches the table (friction :data:`MU`).

Measured: the tool's tracking error (x, y and z while it reaches, x and y while it slides), each
motor's RMS torque, the arm's ∫τ², the base's travel, the table's normal force in the plant
against the set-point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import mujoco
import numpy as np

from vereshchagin import Contact, Solver, Tree, robots
from vereshchagin.task import beta_for, directions, pose_error

from ._common import min_jerk

__all__ = ["BASE_MASS", "PATHS", "VARIANTS", "MobileRun", "metrics", "mobile_urdf", "run_variant"]

VARIANTS = ("arm", "base")
BASE_MASS = 30.0
"""kg: the mobile base (a box :data:`BASE_BOX`, centre of mass half its height above the floor)."""
BASE_BOX = (0.50, 0.40, 0.30)
"""m: the base's box (x, y, z)."""
MOUNT = 0.30
"""m: the arm's base_link above the mobile base's origin (on the box's top)."""
TIP = "end_effector_link"
TABLE_TOP = 0.25
"""m: the table's top surface above the floor (the base origin's height)."""
TOOL_RADIUS = 0.02
"""m: the ball at the tool (the end-effector origin at its centre) that touches the table."""
PRESS = 10.0
"""N: the normal force the tool presses on the table with while it slides."""
MU = 0.3
"""Tool-table friction coefficient (model and plant)."""
PRESS_RAMP = 0.3
"""s: the set-point rises from 1 N to :data:`PRESS` over this time after touch-down."""
CONTACT_TOLERANCE = 1e-2
"""m/s: the solves' ``contact_velocity_tolerance`` (the plant's soft contact moves the ball a little)."""
PATHS = {"near": (0.30, 0.20), "far": (0.50, 0.30)}
"""``(reach, slide)`` in m: how far ahead (+x) of its start position the tool reaches, then how far
it slides along +y and back. ``near`` is within the locked arm's reach, ``far`` is not."""
BASE_LIMITS = (300.0, 300.0, 100.0)
"""The base motors' limits: N along world x and y, N m about z."""
TIMES = (2.0, 2.0, 2.0, 1.0)
"""s: reach, slide out, slide back, hold."""
GAINS = (225.0, 30.0)
"""``(KP, KD)`` of the task PD (1/s^2, 1/s)."""
POSTURE = (10.0, 4.0)
"""Arm posture spring and damping on the joints (N m/rad, N m s/rad)."""
BASE_DAMPING = (60.0, 60.0, 10.0)
"""The base's damping on (v_x, v_y, yaw rate) (N s/m, N s/m, N m s/rad)."""
GRAVITY = np.array([0.0, 0.0, -9.81])
DT = 1e-3


def mobile_urdf(plant: bool = False) -> str:
    """URDF text of the Gen3 on its mobile base.

    Parameters
    ----------
    plant : bool
        True: with the plant's planar joints (``base_slide_x``, ``base_slide_y``, ``base_yaw``;
        two massless links between world and base) for MuJoCo; False: the base as the root link
        (the controller's model: ``base="planar"``, or welded for the ``arm`` variant).
    """
    arm = robots.gen3_urdf(gripper=False)
    a, b, c = BASE_BOX
    inertia = (BASE_MASS / 12 * (b * b + c * c), BASE_MASS / 12 * (a * a + c * c), BASE_MASS / 12 * (a * a + b * b))
    base = (
        f'<link name="mobile_base"><inertial><origin xyz="0 0 {c / 2}"/><mass value="{BASE_MASS}"/>'
        f'<inertia ixx="{inertia[0]}" iyy="{inertia[1]}" izz="{inertia[2]}" ixy="0" ixz="0" iyz="0"/>'
        f'</inertial><collision><origin xyz="0 0 {c / 2}"/><geometry><box size="{a} {b} {c}"/></geometry>'
        '</collision></link><joint name="mount" type="fixed"><parent link="mobile_base"/>'
        f'<child link="base_link"/><origin xyz="0 0 {MOUNT}"/></joint>'
    )
    if plant:
        tiny = '<inertial><mass value="1e-6"/><inertia ixx="1e-9" iyy="1e-9" izz="1e-9" ixy="0" ixz="0" iyz="0"/></inertial>'
        limit = '<limit lower="-10" upper="10" effort="1000" velocity="10"/>'
        base = (
            f'<link name="world_anchor"/><link name="base_x">{tiny}</link><link name="base_y">{tiny}</link>'
            '<joint name="base_slide_x" type="prismatic"><parent link="world_anchor"/><child link="base_x"/>'
            f'<axis xyz="1 0 0"/>{limit}</joint>'
            '<joint name="base_slide_y" type="prismatic"><parent link="base_x"/><child link="base_y"/>'
            f'<axis xyz="0 1 0"/>{limit}</joint>'
            '<joint name="base_yaw" type="continuous"><parent link="base_y"/><child link="mobile_base"/>'
            '<axis xyz="0 0 1"/></joint>' + base
        )
    i = arm.index("<link ")
    return arm[:i] + base + arm[i:]


def _plant(mobile: bool, model) -> mujoco.MjModel:
    """MuJoCo model: the robot (planar joints if ``mobile``), a table, one motor per DOF; the joint
    order checked against ``model``'s."""
    spec = mujoco.MjSpec.from_string(mobile_urdf(plant=mobile))
    spec.option.timestep = DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = list(GRAVITY)
    for g in spec.geoms:  # the arm touches nothing but with its tool's ball
        g.contype, g.conaffinity = 0, 0
    spec.body(TIP).add_geom(
        name="tool", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[TOOL_RADIUS, 0, 0], mass=0.0,
        contype=1, conaffinity=0, friction=[MU, 0.005, 1e-4],
    )  # fmt: skip
    spec.worldbody.add_geom(
        name="table", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.6, TABLE_TOP / 2],
        pos=[1.05, 0.0, TABLE_TOP / 2], contype=0, conaffinity=1, friction=[MU, 0.005, 1e-4],
    )  # fmt: skip
    for j in spec.joints:
        spec.add_actuator(name=f"motor_{j.name}", target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    plant = spec.compile()
    names = [plant.joint(i).name for i in range(plant.njnt)][3 if mobile else 0 :]
    if names != list(model.joint_names):
        raise ValueError(f"the plant's joints {names} are not the model's {list(model.joint_names)}")
    return plant


@dataclass
class MobileRun:
    """One run, one row per control period.

    Attributes
    ----------
    variant : str
        ``"arm"`` (base locked) or ``"base"`` (base helping).
    t : ndarray, shape (k,)
        Time (s).
    error : ndarray, shape (k,)
        Tool position error (m).
    torque : ndarray, shape (k, 7)
        Arm motor torques (N m).
    base_force : ndarray, shape (k, 3)
        Base motor force (N, world x and y) and moment (N m, about z); zero for ``arm``.
    base_pose : ndarray, shape (k, 3)
        Base x, y (m) and yaw (rad).
    tool : ndarray, shape (k, 3)
        Tool position, world (m).
    model_normal, plant_normal : ndarray, shape (k,)
        The table's normal force on the tool (N): the model's (the set-point) and the plant's.
    """

    variant: str
    t: np.ndarray
    error: np.ndarray
    torque: np.ndarray
    base_force: np.ndarray
    base_pose: np.ndarray
    tool: np.ndarray
    model_normal: np.ndarray
    plant_normal: np.ndarray
    info: dict = field(default_factory=dict)


def reference(t: float, p0: np.ndarray, path: str = "near") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tool's reference position, velocity and acceleration at time ``t`` on ``path`` (a key of
    :data:`PATHS`) from ``p0`` (world, m, m/s, m/s^2)."""
    reach, slide = PATHS[path]
    goal = np.array([p0[0] + reach, p0[1], TABLE_TOP + TOOL_RADIUS])  # the ball on the table
    legs = [(p0, goal), (goal, goal + [0.0, slide, 0.0]), (goal + [0.0, slide, 0.0], goal)]
    start = 0.0
    for (a, b), T in zip(legs, TIMES):
        if t < start + T:
            s, ds, dds = min_jerk((t - start) / T)
            return a + s * (b - a), ds / T * (b - a), dds / T**2 * (b - a)
        start += T
    return goal.copy(), np.zeros(3), np.zeros(3)


def _rz(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tool_world(model: Tree, base: np.ndarray, qa, qda):
    """Tool pose (4x4) and twist ``[v; omega]`` in world axes from the base's (x, y, yaw, v_x, v_y
    (base axes), yaw rate) and the arm's state (the kinematics companions work relative to the base)."""
    x, y, yaw, vx, vy, wz = base
    R = _rz(yaw)
    T_rel = np.asarray(model.fk(qa, TIP))
    tw_rel = np.asarray(model.twist(qa, qda, TIP))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R @ T_rel[:3, :3], R @ T_rel[:3, 3] + [x, y, 0.0]
    w_b = np.array([0.0, 0.0, wz])
    v = R @ (np.array([vx, vy, 0.0]) + np.cross(w_b, T_rel[:3, 3]) + tw_rel[:3])
    return T, np.r_[v, R @ (w_b + tw_rel[3:])]


def _base_state(variant: str, data) -> np.ndarray:
    """(x, y, yaw, v_x, v_y in base axes, yaw rate) of the plant's base; zeros when locked."""
    if variant == "arm":
        return np.zeros(6)
    x, y, yaw = data.qpos[:3]
    v = _rz(yaw)[:2, :2].T @ data.qvel[:2]
    return np.array([x, y, yaw, v[0], v[1], data.qvel[2]])


def _press(t: float) -> Optional[float]:
    """The set-point at ``t`` (N), None before touch-down (the reach: no contact)."""
    if t < TIMES[0]:
        return None
    return 1.0 + (PRESS - 1.0) * min(1.0, (t - TIMES[0]) / PRESS_RAMP)


def _command(variant, path, model, solver, data, t, p0, R0):
    """The plant's motor commands of one period (arm torques N m; base forces world N and N m),
    the tool's position error (m; x and y only in contact), the model's table normal force (N), the
    base's state (:func:`_base_state`) and the tool's world pose (4 x 4) at the period's start."""
    nb = 0 if variant == "arm" else 3
    qa, qda = data.qpos[nb:], data.qvel[nb:]
    base = _base_state(variant, data)
    T, tw = _tool_world(model, base, qa, qda)
    p, v, a = reference(t, p0, path)
    goal = np.eye(4)
    goal[:3, :3], goal[:3, 3] = R0, p
    e = pose_error(T, goal)
    a_des = np.r_[a, 0.0, 0.0, 0.0] + GAINS[0] * e + GAINS[1] * (np.r_[v, 0.0, 0.0, 0.0] - tw)
    press = _press(t)
    args = {}
    if press is None:
        alpha, err = np.eye(6), float(np.linalg.norm(e[:3]))
    else:  # z is the contact's: the ball stays on the table, pushed with the set-point
        alpha, err = directions(("x", "y", "rx", "ry", "rz")), float(np.linalg.norm(e[:2]))
        point = -TOOL_RADIUS * R0.T @ np.array([0.0, 0.0, 1.0])  # the ball's lowest point, tip frame
        args = {
            "contacts": [Contact(TIP, point=point, normal=(0.0, 0.0, 1.0), mu=MU, force=press)],
            "contact_velocity_tolerance": CONTACT_TOLERANCE,
        }
    beta = beta_for(alpha, a_des, tw, GRAVITY)
    ff = POSTURE[0] * (np.asarray(robots.GEN3_START_POSE) - qa) - POSTURE[1] * qda
    if variant == "arm":
        r = solver.solve(qa, qda, tau_ff=ff, constraints={TIP: (alpha, beta)}, **args)
        return ff + r.tau_command, err, _normal(r, press), base, T
    q = np.r_[base[:2], np.cos(base[2]), np.sin(base[2]), qa]
    qd = np.r_[base[3:], qda]
    ff = np.r_[-np.asarray(BASE_DAMPING) * base[3:], ff]
    r = solver.solve(q, qd, tau_ff=ff, constraints={TIP: (alpha, beta)}, **args)
    u = ff + r.tau_command
    world = _rz(base[2])[:2, :2] @ u[:2]  # the base's force from base axes into the world's
    return np.r_[world, u[2:]], err, _normal(r, press), base, T


def _normal(result, press) -> float:
    return 0.0 if press is None else float(np.asarray(result.contact_force)[0, 2])


def _plant_normal(plant, data) -> float:
    """The table's normal force on the tool's ball in the plant (N)."""
    f6, total = np.zeros(6), 0.0
    tool = plant.geom("tool").id
    for i in range(data.ncon):
        if tool in (data.contact[i].geom1, data.contact[i].geom2):
            mujoco.mj_contactForce(plant, data, i, f6)
            total += f6[0]
    return total


def run_variant(variant: str, path: str = "near", steps: int | None = None) -> MobileRun:
    """Run one variant (``"arm"`` or ``"base"``) on ``path`` (a key of :data:`PATHS`) for ``steps``
    periods (default: the whole path)."""
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    if path not in PATHS:
        raise ValueError(f"path must be one of {tuple(PATHS)}, got {path!r}")
    mobile = variant == "base"
    model = Tree.from_urdf(mobile_urdf(), base="planar" if mobile else "fixed")
    solver = Solver(model, gravity=GRAVITY)
    plant = _plant(mobile, model)
    data = mujoco.MjData(plant)
    nb = 3 if mobile else 0
    limits = np.r_[BASE_LIMITS[:nb], model.effort_limit]
    data.qpos[nb:] = robots.GEN3_START_POSE
    mujoco.mj_forward(plant, data)
    T0, _ = _tool_world(model, _base_state(variant, data), data.qpos[nb:], data.qvel[nb:])
    steps = int(round(sum(TIMES) / DT)) if steps is None else steps
    keys = ("t", "error", "torque", "base_force", "base_pose", "tool", "model_normal", "plant_normal")
    rows = {k: [] for k in keys}
    for k in range(steps):
        u, err, normal, base, T = _command(variant, path, model, solver, data, k * DT, T0[:3, 3], T0[:3, :3])
        u = np.clip(u, -limits, limits)  # what the motors can give
        data.ctrl[:] = u
        vals = (k * DT, err, u[nb:], u[:nb] if mobile else np.zeros(3), base[:3], T[:3, 3], normal)
        for key, val in zip(keys, (*vals, _plant_normal(plant, data))):
            rows[key].append(val)
        mujoco.mj_step(plant, data)
    run = MobileRun(variant, *(np.asarray(rows[k], float) for k in keys))
    run.info.update(path=path, saturated=float(np.mean(np.any(np.abs(run.torque) >= model.effort_limit, axis=1))))
    return run


def metrics(run: MobileRun) -> dict:
    """Tracking and effort numbers of one run: RMS / max position error (m), each arm motor's RMS
    torque (N m), the arm's ∫τ² (N² m² s), the base's RMS force (N) and travel (m), and while the
    tool presses with the full set-point: the plant's mean normal force (N), the RMS deviation of
    its 10 ms means from the model's (N), the fraction of periods the plant's ball is off the table."""
    full = run.t >= TIMES[0] + PRESS_RAMP + 0.1
    window = np.ones(10) / 10.0
    dev = np.convolve(run.plant_normal - run.model_normal, window, "valid")[full[9:]] if full.any() else np.zeros(0)
    return {
        "rms_error": float(np.sqrt(np.mean(run.error**2))),
        "max_error": float(run.error.max()),
        "rms_torque": np.sqrt(np.mean(run.torque**2, axis=0)),
        "tau2": float(np.sum(run.torque**2) * DT),
        "base_rms_force": float(np.sqrt(np.mean(np.sum(run.base_force[:, :2] ** 2, axis=1)))),
        "base_travel": float(np.sum(np.linalg.norm(np.diff(run.base_pose[:, :2], axis=0), axis=1))),
        "plant_normal": float(run.plant_normal[full].mean()) if full.any() else float("nan"),
        "normal_deviation": float(np.sqrt(np.mean(dev**2))) if dev.size else float("nan"),
        "contact_lost": float(np.mean(run.plant_normal[full] == 0.0)) if full.any() else float("nan"),
    }
