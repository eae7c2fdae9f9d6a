"""Independent oracles for point contacts with Coulomb friction at the instant.

The problem (Gauss's principle with unilateral constraints, in joint space): find ``qdd``, the
task multipliers ``nu`` (supplied by the motors) and one force ``f_c`` (3,) per contact (supplied
by the environment, base axes, applied at the contact point to the robot) with

    H qdd = h + A^T nu + sum_c J_c^T f_c (+ J_c^T n_c nu_c for force set-points)
    A qdd = b

and per contact, a_c = J_c qdd + bias_c the contact point's acceleration:

* support, separating (normal velocity > tol): f_c = 0;
* support in touch: a_n >= 0, f_n >= 0, a_n f_n = 0; the tangential force lies in the polygon
  ``mu f_n conv{d_j}`` (``facet_directions``) and, sliding (tangential velocity > tol), sits at
  the vertex most opposed to the velocity; at rest it sticks (a_t = 0) or sits where it opposes
  the tangential acceleration most (maximum dissipation: a vertex or an edge of the polygon);
* force set-point: a_n = 0 held by the motors (multiplier nu_c), f_n equal to the set-point, the
  tangential force as for a support.

Joint friction and limits (``ContactProblem.joints``): a resting joint j gets a torque tau_j on
the joint in [lo, hi] (-f_j .. f_j; hi = +inf at a lower limit, lo = -inf at an upper one) with
maximum dissipation: it sticks (qdd_j = 0, tau_j inside the bounds), or moves up with tau_j = lo
(qdd_j >= 0) or down with tau_j = hi (qdd_j <= 0). Moving joints' kinetic friction is part of h.

``enumerate_modes`` tries every mode per contact (separate, stick, slide at a vertex, slide on an
edge) and per resting joint (stick, up, down) with one linear KKT solve each and keeps the
candidates that meet every sign condition.
``frictionless_qp`` solves the frictionless case as the convex QP of Gauss's principle with scipy
and polishes it to its active set's exact KKT solution. ``contact_problem`` builds the problem of a
Pinocchio model. Written from the formulation above, independently of the solver under test.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
import pinocchio as pin

LWA = pin.LOCAL_WORLD_ALIGNED


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def tangent_basis(normal):
    """(t1, t2): t1 = unit(e x n) for the base axis e least aligned with n (first on ties)."""
    n = np.asarray(normal, float)
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    t1 = np.cross(e, n)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def facet_directions(normal, facets):
    """The polygon's vertex directions d_j = cos(2 pi j / k) t1 + sin(2 pi j / k) t2, (k, 3)."""
    t1, t2 = tangent_basis(normal)
    ang = 2.0 * np.pi * np.arange(facets) / facets
    return np.cos(ang)[:, None] * t1 + np.sin(ang)[:, None] * t2


@dataclass
class Contact:
    J: np.ndarray  # (3, n) linear velocity Jacobian of the contact point, base axes
    bias: np.ndarray  # (3,) the point's classical acceleration at qdd = 0, gravity excluded
    velocity: np.ndarray  # (3,) J qd
    normal: np.ndarray  # (3,) unit, along which the surface pushes the robot
    mu: float
    facets: int = 4
    force: Optional[float] = None  # normal force set-point (N); None: a support
    tol: float = 1e-6  # velocity below which the point is at rest (normal) or not sliding

    @property
    def directions(self):
        return facet_directions(self.normal, self.facets)


@dataclass
class JointFriction:
    index: int  # the joint (velocity index)
    lo: float  # bounds of the torque on the joint, N m (-inf / +inf: unbounded on that side)
    hi: float
    offset: float = 0.0  # the joint's row is qdd_j + offset (over a time step: qd_j / dt)


@dataclass
class ContactProblem:
    H: np.ndarray
    h: np.ndarray  # generalised force: tau - C(q, qd) qd - g(q) + J_ext^T f_ext (+ kinetic friction)
    A: np.ndarray  # (m, n) task rows
    b: np.ndarray  # (m,)
    contacts: list = field(default_factory=list)
    joints: list = field(default_factory=list)  # JointFriction of the resting joints


@dataclass
class ContactSolution:
    qdd: np.ndarray
    nu: np.ndarray
    forces: np.ndarray  # (k, 3)
    modes: tuple  # per contact: 'separate', 'stick', ('vertex', j), ('edge', j)
    setpoint_nu: np.ndarray  # motor multipliers of the force set-points
    joint_torques: np.ndarray = None  # (n,) the resting joints' friction and limit torques
    joint_modes: tuple = ()  # per resting joint: 'stick', 'up', 'down'

    @property
    def status(self):
        return tuple("separating" if m == "separate" else "sticking" if m == "stick" else "sliding" for m in self.modes)


def _normal_velocity(c):
    return float(c.normal @ c.velocity)


def _tangential_velocity(c):
    return c.velocity - c.normal * _normal_velocity(c)


def contact_modes(c):
    """The modes contact ``c`` can be in at this state."""
    tol = c.tol
    if c.force is None and _normal_velocity(c) > tol:
        return ["separate"]
    vt = _tangential_velocity(c)
    sep = [] if c.force is not None else ["separate"]
    if c.mu == 0.0:  # every vertex is the normal: one mode for all (touching, sliding alike)
        return sep + [("vertex", 0)]
    if np.linalg.norm(vt) > tol:  # sliding: the vertex most opposed to the velocity
        return sep + [("vertex", int(np.argmin(c.directions @ vt)))]
    k = c.facets
    return sep + ["stick"] + [("vertex", j) for j in range(k)] + [("edge", j) for j in range(k)]


def _force_columns(c, mode):
    """(G (3, p), f0 (3,)): the contact force is G x + f0 for the mode's p parameters x."""
    n, D, mu = c.normal, c.directions, c.mu
    fixed = c.force
    if mode == "separate":
        return np.zeros((3, 0)), np.zeros(3)
    if mode == "stick":
        if fixed is None:
            return np.eye(3), np.zeros(3)
        t1, t2 = tangent_basis(n)
        return np.column_stack([t1, t2]), fixed * n
    kind, j = mode
    if kind == "vertex":
        g = n + mu * D[j]
        return (np.zeros((3, 0)), fixed * g) if fixed is not None else (g[:, None], np.zeros(3))
    jn = (j + 1) % c.facets  # edge: f_n n + mu (g d_j + (f_n - g) d_jn), parameters (f_n, g)
    if fixed is not None:
        return (mu * (D[j] - D[jn]))[:, None], fixed * (n + mu * D[jn])
    return np.column_stack([n + mu * D[jn], mu * (D[j] - D[jn])]), np.zeros(3)


def _mode_equations(c, mode):
    """Rows R (r, 3) with R a_c = 0 imposed by the mode (a_c the point's acceleration)."""
    n, D = c.normal, c.directions
    if mode == "separate":
        return np.zeros((0, 3))
    if mode == "stick":
        if c.force is None:
            return np.eye(3)
        t1, t2 = tangent_basis(n)
        return np.vstack([t1, t2])
    kind, j = mode
    if kind == "vertex":
        return np.zeros((0, 3)) if c.force is not None else n[None, :]
    dj = D[j] - D[(j + 1) % c.facets]
    return dj[None, :] if c.force is not None else np.vstack([n, dj])


def joint_modes(j):
    """The modes resting joint ``j`` (JointFriction) can be in."""
    return ["stick"] + (["up"] if np.isfinite(j.lo) else []) + (["down"] if np.isfinite(j.hi) else [])


def _candidate(prob, modes, jmodes=()):
    """The KKT solution of one mode per contact and per resting joint (least squares if singular)
    and its residual."""
    n, m = prob.H.shape[0], prob.A.shape[0]
    cols, f0s, rows = [], [], []
    for c, mode in zip(prob.contacts, modes):
        G, f0 = _force_columns(c, mode)
        cols.append(G)
        f0s.append(f0)
        rows.append(_mode_equations(c, mode))
    setp = [i for i, c in enumerate(prob.contacts) if c.force is not None]
    p = sum(G.shape[1] for G in cols)
    stuck = [j.index for j, jm in zip(prob.joints, jmodes) if jm == "stick"]
    size = n + m + len(setp) + p + len(stuck)
    top = np.zeros((n, size))
    top[:, :n] = prob.H
    top[:, n : n + m] = -prob.A.T
    h = prob.h.copy()
    slipping = np.zeros(n)
    for j, jm in zip(prob.joints, jmodes):
        if jm != "stick":
            slipping[j.index] = j.lo if jm == "up" else j.hi
    h = h + slipping
    for s_, idx in enumerate(stuck):
        top[idx, size - len(stuck) + s_] = -1.0
    for s, i in enumerate(setp):
        c = prob.contacts[i]
        top[:, n + m + s] = -c.J.T @ c.normal
    off = n + m + len(setp)
    for c, G, f0 in zip(prob.contacts, cols, f0s):
        top[:, off : off + G.shape[1]] = -c.J.T @ G
        h = h + c.J.T @ f0
        off += G.shape[1]
    K = np.vstack([top, np.hstack([prob.A, np.zeros((m, size - n))])])
    rhs = [h, prob.b]
    for i in setp:
        c = prob.contacts[i]
        row = np.zeros(size)
        row[:n] = c.normal @ c.J
        K = np.vstack([K, row])
        rhs.append([-(c.normal @ c.bias)])
    for c, R in zip(prob.contacts, rows):
        block = np.zeros((R.shape[0], size))
        block[:, :n] = R @ c.J
        K = np.vstack([K, block])
        rhs.append(-(R @ c.bias))
    offsets = {j.index: j.offset for j in prob.joints}
    for idx in stuck:  # qdd_j + offset = 0
        row = np.zeros(size)
        row[idx] = 1.0
        K = np.vstack([K, row])
        rhs.append([-offsets[idx]])
    rhs = np.concatenate([np.atleast_1d(r) for r in rhs])
    x = np.linalg.lstsq(K, rhs, rcond=None)[0]
    resid = np.linalg.norm(K @ x - rhs) / max(1.0, np.linalg.norm(rhs))
    qdd, nu, snu = x[:n], x[n : n + m], x[n + m : n + m + len(setp)]
    forces, off = [], n + m + len(setp)
    for G, f0 in zip(cols, f0s):
        forces.append(G @ x[off : off + G.shape[1]] + f0)
        off += G.shape[1]
    torques = slipping.copy()
    torques[stuck] = x[off:]
    sol = ContactSolution(qdd, nu, np.array(forces).reshape(-1, 3), tuple(modes), snu, torques, tuple(jmodes))
    return sol, resid


def _signs_hold(c, mode, f, acc, tol):
    """The mode's sign conditions for force f and point acceleration acc (tol relative)."""
    n, D, mu = c.normal, c.directions, c.mu
    fn = float(n @ f)
    ft = f - fn * n
    an = float(n @ acc)
    at = acc - an * n
    scale_f = max(1.0, np.linalg.norm(f))
    scale_a = max(1.0, np.linalg.norm(acc))
    if mode == "separate":
        return _normal_velocity(c) > c.tol or an >= -tol * scale_a
    if fn < -tol * scale_f:
        return False
    apothem = mu * fn * np.cos(np.pi / c.facets)
    outward = facet_directions(n, 2 * c.facets)[1::2]  # edge normals at (2j + 1) pi / k
    if np.any(outward @ ft > apothem + tol * scale_f):
        return False
    sliding = np.linalg.norm(_tangential_velocity(c)) > c.tol
    if mode == "stick" or sliding or mu == 0.0:  # a_t = 0 imposed, the vertex chosen by the velocity,
        # or no friction (every vertex is the normal)
        return True
    kind, j = mode
    proj = D @ at
    if kind == "vertex":  # at rest, starting to slide: the vertex most opposed to a_t
        return proj[j] <= proj.min() + tol * scale_a and np.linalg.norm(at) > tol * scale_a
    # on edge j (proj[j] == proj[j + 1] imposed): both most opposed, a_t not zero
    return proj[j] <= proj.min() + tol * scale_a and proj[j] < -tol * scale_a


def _joint_signs_hold(j, mode, torque, qdd_j, tol, scale_a):
    if mode == "up":
        return qdd_j >= -tol * scale_a
    if mode == "down":
        return qdd_j <= tol * scale_a
    scale_t = max(1.0, abs(torque))
    return j.lo - tol * scale_t <= torque <= j.hi + tol * scale_t


def check_solution(prob, sol, tol=1e-9):
    """True if ``sol`` meets the equations and every sign condition of its modes."""
    r = prob.H @ sol.qdd - prob.h - prob.A.T @ sol.nu
    if sol.joint_torques is not None:
        r = r - sol.joint_torques
    setp = [c for c in prob.contacts if c.force is not None]
    for c, s in zip(setp, sol.setpoint_nu):
        r = r - c.J.T @ c.normal * s
    for c, f in zip(prob.contacts, sol.forces):
        r = r - c.J.T @ f
    scale = max(1.0, np.linalg.norm(prob.h), np.linalg.norm(prob.H @ sol.qdd))
    if np.linalg.norm(r) > tol * scale or np.linalg.norm(prob.A @ sol.qdd - prob.b) > tol * scale:
        return False
    for c, mode, f in zip(prob.contacts, sol.modes, sol.forces):
        acc = c.J @ sol.qdd + c.bias
        if c.force is not None and abs(c.normal @ f - c.force) > tol * max(1.0, c.force):
            return False
        if not _signs_hold(c, mode, f, acc, tol):
            return False
    scale_a = max(1.0, np.linalg.norm(sol.qdd))
    for j, mode in zip(prob.joints, sol.joint_modes):
        row = sol.qdd[j.index] + j.offset
        if not _joint_signs_hold(j, mode, sol.joint_torques[j.index], row, tol, scale_a):
            return False
    return True


def enumerate_modes(prob, tol=1e-9, resid_tol=1e-10):
    """Every mode combination whose KKT solution meets the sign conditions, distinct in qdd."""
    found = []
    k = len(prob.contacts)
    for combo in itertools.product(*[contact_modes(c) for c in prob.contacts], *[joint_modes(j) for j in prob.joints]):
        sol, resid = _candidate(prob, combo[:k], combo[k:])
        if resid > resid_tol or not check_solution(prob, sol, tol):
            continue
        scale = max(1.0, np.linalg.norm(sol.qdd))
        if all(np.linalg.norm(sol.qdd - s.qdd) > 1e-7 * scale for s in found):
            found.append(sol)
    return found


def frictionless_qp(prob):
    """Gauss's principle with a_n >= 0 on the touching supports (mu ignored), by scipy SLSQP,
    polished to the exact KKT solution of its active set. Returns qdd."""
    from scipy.optimize import minimize

    a_free = np.linalg.solve(prob.H, prob.h)
    touching = [c for c in prob.contacts if c.force is None and _normal_velocity(c) <= c.tol]
    N = np.array([c.normal @ c.J for c in touching]).reshape(-1, prob.H.shape[0])
    d = np.array([c.normal @ c.bias for c in touching])
    cons = [{"type": "ineq", "fun": lambda x: N @ x + d, "jac": lambda x: N}]
    if prob.A.shape[0]:
        cons.append({"type": "eq", "fun": lambda x: prob.A @ x - prob.b, "jac": lambda x: prob.A})
    res = minimize(
        lambda x: 0.5 * (x - a_free) @ prob.H @ (x - a_free),
        a_free,
        jac=lambda x: prob.H @ (x - a_free),
        constraints=cons,
        method="SLSQP",
        options=dict(ftol=1e-15, maxiter=500),
    )
    x = res.x
    scale = max(1.0, np.linalg.norm(N @ x + d) if len(d) else 1.0)
    active = np.flatnonzero(N @ x + d <= 1e-6 * scale) if len(d) else []
    C = np.vstack([prob.A, N[active]]) if len(active) else prob.A
    e = np.concatenate([prob.b, -d[active]]) if len(active) else prob.b
    n, k = prob.H.shape[0], C.shape[0]
    KKT = np.block([[prob.H, -C.T], [C, np.zeros((k, k))]])
    sol = np.linalg.lstsq(KKT, np.concatenate([prob.h, e]), rcond=None)[0]
    return sol[:n]


def point_jacobian(model, data, frame_id, point):
    """(J (3, n), bias (3,), velocity (3,)) of a point fixed in frame ``frame_id`` (its local
    coordinates), base axes, after ``pin.forwardKinematics(model, data, q, qd, 0)``."""
    pin.updateFramePlacements(model, data)
    R = data.oMf[frame_id].rotation
    r = R @ np.asarray(point, float)
    J6 = pin.getFrameJacobian(model, data, frame_id, LWA)
    J = J6[:3] - skew(r) @ J6[3:]
    v = pin.getFrameVelocity(model, data, frame_id, LWA)
    a = pin.getFrameClassicalAcceleration(model, data, frame_id, LWA)
    w = v.angular
    bias = a.linear + np.cross(a.angular, r) + np.cross(w, np.cross(w, r))
    return J, bias, v.linear + np.cross(w, r)


def contact_problem(model, data, q, qd, tau, specs, A=None, b=None, tol=1e-6, friction=None, time_step=None):
    """The problem of a Pinocchio model (gravity = model.gravity). ``specs``: dicts with frame,
    point, normal, mu, facets, force. ``A``, ``b``: task rows in joint space (default none).
    ``friction``: dict with static, kinetic (default static), lower, upper (default none),
    velocity_tolerance (1e-6), limit_tolerance (1e-9), per velocity index of ``model``, and the
    joint positions ``q`` (one per joint) when ``model`` has continuous joints and limits are given.

    ``time_step`` dt: the problem over a time step, every condition on the end velocities: a
    contact's rows are its end velocity over dt to first order, a + v / dt (so each point counts as
    at rest and every mode is tried), a joint's row qdd_j + qd_j / dt, every joint with friction an
    unknown bounded by its static friction at rest and its kinetic friction while moving."""
    nv = model.nv
    H = pin.crba(model, data, q)
    H = np.triu(H) + np.triu(H, 1).T
    h = np.asarray(tau, float) - pin.rnea(model, data, q, qd, np.zeros(nv))
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, qd, np.zeros(nv))
    contacts = []
    for s in specs:
        J, bias, vel = point_jacobian(model, data, s["frame"], s.get("point", np.zeros(3)))
        normal = np.asarray(s["normal"], float)
        if time_step:  # the end velocity over dt: the point counts as at rest, its rows gain v / dt
            bias, vel = bias + vel / time_step, np.zeros(3)
        contacts.append(
            Contact(J, bias, vel, normal / np.linalg.norm(normal), s["mu"], s.get("facets", 4), s.get("force"), tol)
        )
    A = np.zeros((0, nv)) if A is None else np.asarray(A, float)
    b = np.zeros(0) if b is None else np.asarray(b, float)
    joints = []
    if friction is not None:
        h, joints = _joint_friction(friction.get("q", q), qd, h, friction, time_step)
    return ContactProblem(H, h, A, b, contacts, joints)


def _joint_friction(q, qd, h, fr, time_step=None):
    """Kinetic friction of the moving joints into h; the resting joints' bounds (q: one
    coordinate per joint, revolute joints without wrap-around). Over a time step every joint with
    friction is an unknown (kinetic bound while moving), its row offset qd_j / dt."""
    fs = np.asarray(fr["static"], float)
    fk = np.asarray(fr.get("kinetic", fs), float)
    lower, upper = fr.get("lower"), fr.get("upper")
    vtol, ltol = fr.get("velocity_tolerance", 1e-6), fr.get("limit_tolerance", 1e-9)
    h = h.copy()
    joints = []
    for j in range(len(fs)):
        moving = abs(qd[j]) > vtol
        if moving and not time_step:
            h[j] -= fk[j] * np.sign(qd[j])
            continue
        f = fk[j] if moving else fs[j]
        at_lower = not moving and lower is not None and q[j] <= lower[j] + ltol
        at_upper = not moving and upper is not None and q[j] >= upper[j] - ltol
        if f > 0.0 or at_lower or at_upper:
            offset = qd[j] / time_step if time_step else 0.0
            joints.append(JointFriction(j, -np.inf if at_upper else -f, np.inf if at_lower else f, offset))
    return h, joints


def pin_rigid_3d(model, data, q, qd, tau, frame, point):
    """Pinocchio's answer for a point of frame ``frame`` (its local coordinates ``point``) held in
    3-D (``RigidConstraintModel`` CONTACT_3D, LOCAL_WORLD_ALIGNED): ``(qdd, force)``, the force the
    constraint applies to the robot in base axes (``data.lambda_c``)."""
    placement = model.frames[frame].placement * pin.SE3(np.eye(3), np.asarray(point, float))
    cm = pin.RigidConstraintModel(
        pin.ContactType.CONTACT_3D,
        model,
        model.frames[frame].parentJoint,
        placement,
        0,
        pin.SE3.Identity(),
        pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    )
    cd = cm.createData()
    pin.initConstraintDynamics(model, data, [cm], [cd])
    qdd = pin.constraintDynamics(model, data, q, qd, tau, [cm], [cd], pin.ProximalSettings(1e-14, 0.0, 1))
    return qdd, data.lambda_c.copy()
