"""Contacts and joint friction on a floating base (docs/floating-base.md, docs/contacts.md) against
Pinocchio with ``JointModelFreeFlyer``, 1e-9 relative (over a time step 1e-8, the ADMM's).

* Sticking supports and force set-points: every contact point at rest and held (mu large enough
  for the answer to stick) is Pinocchio's ``constraintDynamics`` with one ``RigidConstraintModel``
  CONTACT_3D per point (solo12's four feet, random floating trees), or, with more rows than
  independent directions (Talos's feet corners), the KKT system of ``pin.crba``,
  ``pin.nonLinearEffects`` and the points' frame Jacobians (qdd unique, the forces not).
* Unilateral and frictional cases (feet separating, a foot sliding, frictionless feet): the
  enumeration of contact and joint modes of :mod:`support.contact_oracle`, whose problem is built
  from Pinocchio's pieces on the free-flyer model (crba, rnea, LOCAL_WORLD_ALIGNED frame Jacobians
  and classical accelerations).
* Joint friction (alone and with contacts): the same enumeration, the joints' rows only (the base
  has no friction).
* Over a time step: Pinocchio 4's ADMM (tests/oracles/test_time_step_pinocchio.py's pin_step) on
  frictionless feet and joint friction.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.contact_oracle import contact_problem, enumerate_modes, point_jacobian
from test_floating_base import case
from test_time_step_pinocchio import pin_step

RTOL = 1e-9
UP = np.array([0.0, 0.0, 1.0])
SOLO_FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


def _rel(a, b):
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b)))


def _standing_q(c, rng, spread=0.2):
    """solo12 (or any case) near its neutral posture, the base tilted a little."""
    q, _ = c.random_state(rng)
    q[c.nbq :] *= spread
    if c.nb == 6:
        q[3:7] = [*(0.1 * rng.normal(size=3)), 1.0]
        q[3:7] /= np.linalg.norm(q[3:7])
    return q


def _points(c, pq, specs):
    """Per (link, point) spec: the point's Jacobian (3 x nv), bias and velocity at pq (Pinocchio's
    order); forwardKinematics must have run with the state."""
    return [point_jacobian(c.model, c.data, c.frame(link), point) for link, point in specs]


def _held_velocity(c, pq, specs, rng, extra=None):
    """A random velocity (ours) with every spec point at rest (extra: (rows, values) more)."""
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq)
    J = np.vstack([point_jacobian(c.model, c.data, c.frame(link), p)[0] for link, p in specs])
    rows, values = J, np.zeros(J.shape[0])
    if extra is not None:
        rows, values = np.vstack([J, extra[0]]), np.r_[values, extra[1]]
    v = rng.uniform(-1.0, 1.0, c.model.nv)
    v = v - np.linalg.pinv(rows) @ (rows @ v - values)
    return c.ours(v)


def _contacts(c, specs, mu, forces=None):
    seg = c.tree.segment_names
    return [
        vs.Contact(
            seg.index(link),
            point=np.asarray(p, float),
            normal=UP,
            mu=mu,
            **({} if forces is None or forces[k] is None else dict(force=forces[k])),
        )
        for k, (link, p) in enumerate(specs)
    ]


def _pin_rigid(c, pq, pv, ptau, specs):
    """constraintDynamics with a CONTACT_3D (LOCAL_WORLD_ALIGNED) per spec: (qdd, forces (k, 3))."""
    cms = []
    for link, p in specs:
        f = c.model.frames[c.frame(link)]
        cms.append(
            pin.RigidConstraintModel(
                pin.ContactType.CONTACT_3D,
                c.model,
                f.parentJoint,
                f.placement * pin.SE3(np.eye(3), np.asarray(p, float)),
                0,
                pin.SE3.Identity(),
                pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
            )
        )
    cds = [cm.createData() for cm in cms]
    pin.initConstraintDynamics(c.model, c.data, cms, cds)
    qdd = pin.constraintDynamics(c.model, c.data, pq, pv, ptau, cms, cds, pin.ProximalSettings(1e-14, 0.0, 1))
    return qdd.copy(), c.data.lambda_c.copy().reshape(-1, 3)


def _solo_tau(c, pq, pv, rng, noise=0.1):
    """Joint torques (base rows zero) that hold the robot on its four feet with the least change
    of an even weight split (qdd = 0 up to the velocity terms), plus noise."""
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq, pv, np.zeros(c.model.nv))
    J = np.vstack([point_jacobian(c.model, c.data, c.frame(f), np.zeros(3))[0] for f in SOLO_FEET])
    weight = sum(i.mass for i in c.model.inertias) * 9.81 / 4
    nle = pin.nonLinearEffects(c.model, c.data, pq, pv)
    f = np.tile([0.0, 0.0, weight], 4)
    f = f + np.linalg.pinv(J[:, :6].T) @ (nle[:6] - J[:, :6].T @ f)  # the base rows balanced
    tau = nle - J.T @ f + rng.normal(scale=noise, size=c.model.nv)
    tau[:6] = 0.0
    return c.ours(tau)


def _standing_case(c, rng, specs):
    """A state with the feet at rest and torques for which Pinocchio's rigid contacts push up,
    inside a cone of mu = 10 (drawn again until they do: deterministic per seed)."""
    for _ in range(50):
        q = _standing_q(c, rng)
        pq = c.pin_q(q)
        qd = 0.3 * _held_velocity(c, pq, specs, rng)
        tau = _solo_tau(c, pq, c.pin_v(qd), rng)
        qdd_pin, f_pin = _pin_rigid(c, pq, c.pin_v(qd), c.pin_v(tau), specs)
        if np.all(f_pin[:, 2] > 0.1 * np.linalg.norm(f_pin[:, :2], axis=1)):
            return q, qd, tau, qdd_pin, f_pin
    raise AssertionError("no standing case drawn")


@pytest.mark.parametrize("seed", range(4))
def test_solo12_four_feet_sticking_is_constraint_dynamics(seed):
    rng = np.random.default_rng(100 + seed)
    c = case("solo12")
    specs = [(f, np.zeros(3)) for f in SOLO_FEET]
    q, qd, tau, qdd_pin, f_pin = _standing_case(c, rng, specs)
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=_contacts(c, specs, mu=10.0))
    assert _rel(r.qdd, c.ours(qdd_pin)) <= RTOL
    assert _rel(r.contact_force, f_pin) <= RTOL
    assert list(r.contact_status) == [vs.ContactStatus.STICKING] * 4


@pytest.mark.parametrize("seed", range(3))
def test_solo12_force_set_points_are_constraint_dynamics(seed):
    """Two feet as supports, two as force set-points: every foot held, qdd as four rigid contacts
    (the set-points' normal force is theirs, the rest of the held force the environment's)."""
    rng = np.random.default_rng(200 + seed)
    c = case("solo12")
    specs = [(f, np.zeros(3)) for f in SOLO_FEET]
    q, qd, tau, qdd_pin, f_pin = _standing_case(c, rng, specs)
    # The set-points' forces are Pinocchio's normal forces (their friction bound mu F).
    contacts = _contacts(c, specs, mu=10.0, forces=[None, None, f_pin[2, 2], f_pin[3, 2]])
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=contacts)
    assert _rel(r.qdd, c.ours(qdd_pin)) <= RTOL
    assert _rel(r.contact_force, f_pin) <= RTOL
    assert _rel(r.tau_command, np.zeros(c.tree.nv)) <= RTOL  # the set-points' columns carry nothing


@pytest.mark.parametrize("seed", range(3))
def test_random_floating_trees_sticking_points(seed):
    rng = np.random.default_rng(300 + seed)
    c = case(f"random{seed + 1}")
    seg = c.tree.segment_names
    leaves = [s for s in seg if c.model.existFrame(s)][-3:]
    specs = [(link, rng.uniform(-0.05, 0.05, 3)) for link in leaves]
    q, _ = c.random_state(rng)
    pq = c.pin_q(q)
    qd = _held_velocity(c, pq, specs, rng)
    tau = np.r_[np.zeros(6), rng.normal(size=c.tree.n_joints)]
    qdd_pin, f_pin = _pin_rigid(c, pq, c.pin_v(qd), c.pin_v(tau), specs)
    # Each surface's normal along Pinocchio's force: the supports push and stick (any mu > 0).
    seg = c.tree.segment_names
    contacts = [
        vs.Contact(seg.index(link), point=p, normal=f / np.linalg.norm(f), mu=0.5) for (link, p), f in zip(specs, f_pin)
    ]
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=contacts)
    assert _rel(r.qdd, c.ours(qdd_pin)) <= RTOL
    pin.computeJointJacobians(c.model, c.data, c.pin_q(q))
    pin.forwardKinematics(c.model, c.data, c.pin_q(q))
    J = np.vstack([j for j, _, _ in _points(c, c.pin_q(q), specs)])
    if np.linalg.matrix_rank(J) == J.shape[0]:  # independent rows: the forces are unique
        assert _rel(r.contact_force, f_pin) <= RTOL
    else:  # they replay to the same generalized force
        assert _rel(J.T @ r.contact_force.ravel(), J.T @ f_pin.ravel()) <= RTOL


def test_talos_feet_corners_match_the_kkt_system():
    """Eight corners, two rigid feet: 24 rows for 12 independent directions. qdd is unique: the
    KKT system's least-squares solution (pin.crba, nonLinearEffects, frame Jacobians)."""
    rng = np.random.default_rng(7)
    c = case("talos")
    corners = [(x, y, 0.0) for x in (-0.08, 0.1) for y in (-0.05, 0.05)]
    specs = [(foot, np.array(p)) for foot in ("left_sole_link", "right_sole_link") for p in corners]
    q = _standing_q(c, rng, spread=0.05)
    pq = c.pin_q(q)
    qd = _held_velocity(c, pq, specs, rng) * 0.3
    pv = c.pin_v(qd)
    H = pin.crba(c.model, c.data, pq)
    H = np.triu(H) + np.triu(H, 1).T
    h = -pin.nonLinearEffects(c.model, c.data, pq, pv)
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq, pv, np.zeros(c.model.nv))
    pts = _points(c, pq, specs)
    J = np.vstack([p[0] for p in pts])
    b = -np.concatenate([p[1] for p in pts])
    k = J.shape[0]
    K = np.block([[H, -J.T], [J, np.zeros((k, k))]])
    qdd_kkt = np.linalg.lstsq(K, np.r_[h, b], rcond=None)[0][: c.model.nv]
    r = c.solver.solve(q, qd, contacts=_contacts(c, specs, mu=5.0))
    assert _rel(r.qdd, c.ours(qdd_kkt)) <= RTOL
    assert set(r.contact_status) <= {vs.ContactStatus.STICKING, vs.ContactStatus.SEPARATING}
    # The forces replay to qdd (applied as a generalized force through the free-flyer aba).
    gen = sum(p[0].T @ f for p, f in zip(pts, r.contact_force))
    assert _rel(c.ours(pin.aba(c.model, c.data, pq, pv, gen)), r.qdd) <= RTOL


def _enumerated(c, q, qd, tau, specs, mu, friction=None, facets=4):
    pq = c.pin_q(q)
    psp = [dict(frame=c.frame(link), point=p, normal=UP, mu=mu, facets=facets) for link, p in specs]
    prob = contact_problem(c.model, c.model.createData(), pq, c.pin_v(qd), c.pin_v(tau), psp, friction=friction)
    found = enumerate_modes(prob)
    assert found, "the enumeration found no consistent answer"
    return prob, found


def _check_enumerated(c, r, found, unique=False):
    best = min(found, key=lambda s: _rel(r.qdd, c.ours(s.qdd)))
    assert _rel(r.qdd, c.ours(best.qdd)) <= RTOL
    if unique:
        assert len(found) == 1
    return best


@pytest.mark.parametrize("seed, mu", [(0, 0.2), (1, 0.5), (2, 0.3), (3, 0.5)])
def test_solo12_dropped_feet_separating_and_one_sliding(seed, mu):
    """Two feet at rest on the ground, one lifting off, one sliding: an enumerated mode (the
    problem has one for these friction coefficients)."""
    rng = np.random.default_rng(400 + seed)
    c = case("solo12")
    q = _standing_q(c, rng)
    pq = c.pin_q(q)
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq)
    J_hl = point_jacobian(c.model, c.data, c.frame("HL_FOOT"), np.zeros(3))[0]
    J_hr = point_jacobian(c.model, c.data, c.frame("HR_FOOT"), np.zeros(3))[0]
    extra = (np.vstack([J_hl[2:], J_hr]), np.r_[0.2, 0.3, -0.2, 0.0])  # HL lifts, HR slides
    specs = [(f, np.zeros(3)) for f in SOLO_FEET]
    qd = _held_velocity(c, pq, specs[:2], rng, extra)
    tau = _solo_tau(c, pq, c.pin_v(qd), rng)
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=_contacts(c, specs, mu=mu))
    _, found = _enumerated(c, q, qd, tau, specs, mu)
    best = _check_enumerated(c, r, found)
    S = vs.ContactStatus
    assert r.contact_status[2] == S.SEPARATING and r.contact_status[3] in (S.SLIDING, S.SEPARATING)
    np.testing.assert_allclose(r.contact_force, best.forces, rtol=0, atol=RTOL * max(1.0, np.abs(best.forces).max()))


@pytest.mark.parametrize("seed", range(3))
def test_solo12_frictionless_feet_unique(seed):
    rng = np.random.default_rng(500 + seed)
    c = case("solo12")
    specs = [(f, np.zeros(3)) for f in SOLO_FEET]
    q = _standing_q(c, rng)
    qd = _held_velocity(c, c.pin_q(q), specs, rng)
    tau = _solo_tau(c, c.pin_q(q), c.pin_v(qd), rng)
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=_contacts(c, specs, mu=0.0))
    _, found = _enumerated(c, q, qd, tau, specs, 0.0)
    best = _check_enumerated(c, r, found, unique=True)
    np.testing.assert_allclose(r.contact_force, best.forces, rtol=0, atol=RTOL * max(1.0, np.abs(best.forces).max()))


def _friction(c, rng, joints):
    """Static friction on ``joints`` (our joint indices) and the oracle's per-velocity-index dict."""
    fs = np.zeros(c.tree.n_joints)
    fs[joints] = rng.uniform(0.3, 2.0, len(joints))
    return fs, dict(static=c.pin_v(np.r_[np.zeros(c.nb), fs]))


@pytest.mark.parametrize("name", ["solo12", "random1", "random2"])
def test_joint_friction_alone_on_a_floating_base(name):
    """Resting joints with static friction, others moving with kinetic friction; no contacts."""
    rng = np.random.default_rng(11)
    c = case(name)
    n = c.tree.n_joints
    q, qd = c.random_state(rng)
    rest = rng.choice(n, size=min(4, n), replace=False)
    qd[c.nb + rest] = 0.0
    fs, fr = _friction(c, rng, np.arange(n))
    tau = np.r_[np.zeros(c.nb), rng.normal(size=n)]
    r = c.solver.solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs))
    prob, found = _enumerated(c, q, qd, tau, [], 0.0, friction=fr)
    best = _check_enumerated(c, r, found, unique=True)
    # The friction torques (nv rows, the base's zero): kinetic on the moving joints, the
    # enumerated ones on the resting joints.
    expected = c.ours(best.joint_torques)[c.nb :]
    moving = np.abs(qd[c.nb :]) > 1e-6
    expected[moving] = -fs[moving] * np.sign(qd[c.nb :][moving])
    assert r.friction_torque.shape == (c.tree.nv,) and not r.friction_torque[: c.nb].any()
    assert _rel(r.friction_torque[c.nb :], expected) <= RTOL
    assert np.all(r.status[: c.nb] == 0) and np.isfinite(r.gauss_value)


@pytest.mark.parametrize("seed", range(3))
def test_joint_friction_with_feet_on_solo12(seed):
    rng = np.random.default_rng(600 + seed)
    c = case("solo12")
    specs = [(f, np.zeros(3)) for f in SOLO_FEET[:2]]
    q = _standing_q(c, rng)
    joints = rng.choice(12, size=3, replace=False)
    rest = np.array([c.pin_v(np.eye(c.tree.nv)[6 + j]) for j in joints])  # those joints at rest
    qd = _held_velocity(c, c.pin_q(q), specs, rng, (rest, np.zeros(3)))
    fs, fr = _friction(c, rng, joints)
    tau = _solo_tau(c, c.pin_q(q), c.pin_v(qd), rng)
    contacts = _contacts(c, specs, mu=0.0)
    r = c.solver.solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs), contacts=contacts)
    _, found = _enumerated(c, q, qd, tau, specs, 0.0, friction=fr)
    _check_enumerated(c, r, found)


def _step_case(c, rng, fall=0.3):
    specs = [(f, np.zeros(3)) for f in SOLO_FEET]
    q = _standing_q(c, rng)
    qd = _held_velocity(c, c.pin_q(q), specs, rng) * 0.5
    qd[2] -= fall  # the base's LOCAL z: falling onto the feet (a tilted base: mostly down)
    return specs, q, qd


@pytest.mark.parametrize("seed", range(3))
def test_step_frictionless_feet_against_admm(seed):
    rng = np.random.default_rng(700 + seed)
    c = case("solo12")
    specs, q, qd = _step_case(c, rng)
    tau = _solo_tau(c, c.pin_q(q), c.pin_v(qd), rng)
    dt = 1e-3
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=_contacts(c, specs, mu=0.0), time_step=dt)
    pc = [(c.frame(link), p, UP, 0.0) for link, p in specs]
    v_next, _, forces, res, _ = pin_step(
        c.model, c.pin_q(q), c.pin_v(qd), c.pin_v(tau), dt, np.zeros(c.model.nv), contacts=pc
    )
    assert res.converged
    v_ours = qd + dt * r.qdd
    assert np.linalg.norm(c.ours(v_next) - v_ours) <= 1e-8 * max(np.linalg.norm(v_ours), np.linalg.norm(qd))
    assert np.abs(forces - dt * r.contact_force).max() <= 1e-8 * max(1.0, np.abs(forces).max())


@pytest.mark.parametrize("seed", range(3))
def test_step_joint_friction_and_feet_against_the_enumeration(seed):
    """Over a step, joint friction on four joints (at rest or moving) and frictionless feet: the
    step's problem (end velocities, every joint with friction an unknown bounded by its static or
    kinetic friction) enumerated exactly. (Pinocchio's ADMM converges too slowly on this light
    robot for a 1e-8 comparison of the end velocities: the frictionless step is compared with it
    above.)"""
    rng = np.random.default_rng(800 + seed)
    c = case("solo12")
    specs, q, qd = _step_case(c, rng, fall=0.1)
    joints = rng.choice(12, size=4, replace=False)
    qd[6 + joints[:3]] = 0.0
    fs, fr = _friction(c, rng, joints)
    tau = _solo_tau(c, c.pin_q(q), c.pin_v(qd), rng)
    dt = 1e-3
    r = c.solver.solve(
        q, qd, tau_ff=tau, friction=vs.Friction(static=fs), contacts=_contacts(c, specs, mu=0.0), time_step=dt
    )
    psp = [dict(frame=c.frame(link), point=p, normal=UP, mu=0.0) for link, p in specs]
    prob = contact_problem(
        c.model, c.model.createData(), c.pin_q(q), c.pin_v(qd), c.pin_v(tau), psp, friction=fr, time_step=dt
    )
    found = enumerate_modes(prob)
    assert found
    best = min(found, key=lambda sol: _rel(r.qdd, c.ours(sol.qdd)))
    assert _rel(qd + dt * r.qdd, qd + dt * c.ours(best.qdd)) <= RTOL
    assert _rel(r.friction_torque, c.ours(best.joint_torques)) <= RTOL


def test_response_columns_hold_the_sticking_joints_on_a_floating_base():
    """After a solve with joint friction alone, response_columns holds the sticking joints: the
    inverse of Pinocchio's mass matrix with those joints locked (Schur form), the base free."""
    rng = np.random.default_rng(21)
    c = case("solo12")
    n = c.tree.n_joints
    q, qd = c.random_state(rng)
    qd[6:] = 0.0
    fs = np.full(n, 50.0)  # every joint sticks
    r = c.solver.solve(q, qd, friction=vs.Friction(static=fs))
    stick = np.flatnonzero(r.status[6:] == 1)
    assert len(stick) == n
    held, _ = c.solver.response_columns(range(n))
    free, _ = c.solver.response_columns(range(n), hold_sticking=False)
    H = pin.crba(c.model, c.data, c.pin_q(q))
    H = np.triu(H) + np.triu(H, 1).T
    Minv = np.linalg.inv(H)[np.ix_(c.v_index, c.v_index)]  # our order
    E = np.eye(c.tree.nv)[6 + stick]
    expected = Minv - Minv @ E.T @ np.linalg.solve(E @ Minv @ E.T, E @ Minv)
    assert _rel(held, expected[:, 6:]) <= 1e-8 * max(1.0, np.abs(Minv).max())
    assert _rel(free, Minv[:, 6:]) <= 1e-8 * max(1.0, np.abs(Minv).max())


@pytest.mark.parametrize("seed", range(3))
def test_gen3_on_a_planar_base_sticking_tip_is_constraint_dynamics(seed):
    """A planar base (x, y, yaw): the tool tip held at rest (normal along Pinocchio's force)."""
    rng = np.random.default_rng(900 + seed)
    c = case("gen3_planar")
    tip = c.tree.segment_names[-1]
    specs = [(tip, np.array([0.0, 0.0, 0.05]))]
    q, _ = c.random_state(rng)
    pq = c.pin_q(q)
    qd = _held_velocity(c, pq, specs, rng)
    tau = np.r_[np.zeros(3), rng.normal(size=c.tree.n_joints)]
    qdd_pin, f_pin = _pin_rigid(c, pq, c.pin_v(qd), c.pin_v(tau), specs)
    contact = vs.Contact(
        c.tree.segment_names.index(tip), point=specs[0][1], normal=f_pin[0] / np.linalg.norm(f_pin[0]), mu=0.5
    )
    r = c.solver.solve(q, qd, tau_ff=tau, contacts=[contact])
    assert _rel(r.qdd, c.ours(qdd_pin)) <= RTOL
    assert _rel(r.contact_force, f_pin) <= RTOL
    assert r.contact_status[0] == vs.ContactStatus.STICKING
