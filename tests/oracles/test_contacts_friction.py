"""Contacts together with joint friction and joint limits (``solve(..., friction=, contacts=)``)
against the enumeration of contact and joint modes (:mod:`support.contact_oracle`), written
independently of the solver: every resting joint with static friction sticks or slips with the
full breakaway torque against its acceleration, a joint on a limit gets a one-sided reaction, and
moving joints their kinetic friction, in the same problem as the contacts. Random chains and trees,
1 to 3 contacts, at 1e-9 relative; the joint outputs (friction and limit torques, statuses) and the
contact forces replay to qdd through Pinocchio's forward dynamics."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import pin_configuration, random_chain, random_state
from support.contact_oracle import contact_problem, enumerate_modes

RTOL = 1e-9


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


def _case(rng, k, mu, n=7, friction_joints=3, moving=0, first=4):
    """A random chain at rest (``moving`` joints with velocity), breakaway friction on
    ``friction_joints`` random joints, k contacts on distinct segments from ``first`` on."""
    rc = random_chain(rng, n, prismatic=False)
    q, _ = random_state(rng, rc)
    qd = np.zeros(n)
    mv = rng.choice(n, size=moving, replace=False)
    qd[mv] = rng.normal(size=moving)
    fs = np.zeros(n)
    fs[rng.choice(n, size=friction_joints, replace=False)] = rng.uniform(0.3, 3.0, size=friction_joints)
    fs[mv] = rng.uniform(0.3, 3.0, size=moving)
    tau = rng.normal(size=n) * 3
    contacts = []
    for s in rng.choice(np.arange(first, rc.n_segments), size=k, replace=False):
        normal = rng.normal(size=3)
        contacts.append(
            vs.Contact(int(s), point=rng.normal(size=3) * 0.1, normal=normal / np.linalg.norm(normal), mu=mu)
        )
    return rc, q, qd, tau, fs, contacts


def _problem(rc, q, qd, tau, contacts, friction):
    specs = [
        dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu, facets=c.facets) for c in contacts
    ]
    model = rc.model
    return contact_problem(model, model.createData(), pin_configuration(model, q), qd, tau, specs, friction=friction)


def _check(r, prob, rc, q, qd, tau, contacts):
    found = enumerate_modes(prob)
    assert found, "the enumeration found no consistent answer"
    best = min(found, key=lambda s: _rel(r.qdd, s.qdd))
    assert _rel(r.qdd, best.qdd) <= RTOL
    # The environment's generalised force on the resting joints and at the contacts is the
    # oracle's (the motors' share follows from qdd and the task).
    gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)) + r.friction_torque + r.limit_torque
    resting = np.zeros(rc.n_joints)
    for j in prob.joints:
        resting[j.index] = 1.0
    gen_oracle = sum(c.J.T @ f for c, f in zip(prob.contacts, best.forces)) + best.joint_torques
    kinetic = (1.0 - resting) * r.friction_torque  # moving joints: -fk sign(qd), in prob.h
    assert _rel(gen - kinetic, gen_oracle) <= RTOL
    # Replay: the motors, the friction and limit torques and the contact forces give qdd.
    model = rc.model
    qdd = pin.aba(model, model.createData(), pin_configuration(model, q), qd, tau + r.tau_command + gen)
    assert _rel(r.qdd, qdd) <= RTOL
    for j in prob.joints:  # the resting joints' torques within their bounds, opposing their motion
        t = r.friction_torque[j.index] + r.limit_torque[j.index]
        assert j.lo - 1e-9 * max(1.0, abs(t)) <= t <= j.hi + 1e-9 * max(1.0, abs(t))
        a = r.qdd[j.index]
        if abs(a) > 1e-9 * max(1.0, np.linalg.norm(r.qdd)):
            assert t == pytest.approx(j.lo if a > 0 else j.hi, rel=1e-9, abs=1e-9)
    return best


@pytest.mark.parametrize("seed", range(10))
def test_supports_with_friction_and_joint_friction_meet_an_enumerated_mode(seed):
    rng = np.random.default_rng(500 + seed)
    rc, q, qd, tau, fs, contacts = _case(rng, 1 + seed % 2, 0.7)
    r = rc.solver().solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs), contacts=contacts)
    _check(r, _problem(rc, q, qd, tau, contacts, dict(static=fs)), rc, q, qd, tau, contacts)


@pytest.mark.parametrize("seed", range(8))
def test_frictionless_supports_with_moving_and_resting_joints(seed):
    rng = np.random.default_rng(600 + seed)
    rc, q, qd, tau, fs, contacts = _case(rng, 1 + seed % 3, 0.0, moving=2, first=2)
    # The contact points must not move along their normals: keep the moving joints' velocity
    # only where it leaves every point on its surface (project it out of the normal rows).
    prob0 = _problem(rc, q, np.zeros(rc.n_joints), tau, contacts, None)
    N = np.array([c.normal @ c.J for c in prob0.contacts])
    qd = qd - np.linalg.pinv(N) @ (N @ qd)
    r = rc.solver().solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs), contacts=contacts)
    _check(r, _problem(rc, q, qd, tau, contacts, dict(static=fs)), rc, q, qd, tau, contacts)


@pytest.mark.parametrize("seed", range(6))
def test_a_joint_on_its_limit_with_contacts(seed):
    """A resting joint on its lower (even seeds) or upper limit gets a one-sided reaction together
    with its friction and the contacts."""
    rng = np.random.default_rng(700 + seed)
    rc, q, qd, tau, fs, contacts = _case(rng, 1 + seed % 2, 0.6 if seed % 3 else 0.0)
    n = rc.n_joints
    j = int(rng.integers(n))
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    if seed % 2 == 0:
        lower[j] = q[j]
    else:
        upper[j] = q[j]
    fr = vs.Friction(static=fs, lower=lower, upper=upper)
    r = rc.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts)
    prob = _problem(rc, q, qd, tau, contacts, dict(static=fs, lower=lower, upper=upper, q=q))
    assert any(jf.index == j and not (np.isfinite(jf.lo) and np.isfinite(jf.hi)) for jf in prob.joints)
    _check(r, prob, rc, q, qd, tau, contacts)
    assert (r.limit_torque[j] >= 0.0) if seed % 2 == 0 else (r.limit_torque[j] <= 0.0)


@pytest.mark.parametrize("seed", range(4))
def test_with_a_task_the_motion_is_an_enumerated_mode(seed):
    """A 3-D task on the last segment's tip with joint friction and supports: qdd is the
    enumeration's (the split between the motors and the environment is ruled by least effort)."""
    rng = np.random.default_rng(800 + seed)
    rc, q, qd, tau, fs, contacts = _case(rng, 1, 0.0 if seed % 2 else 0.8)
    alpha = np.zeros((6, 3))
    alpha[:3, :3] = np.eye(3)
    beta = rng.normal(size=3)
    r = rc.solver().solve(q, qd, alpha=alpha, beta=beta, tau_ff=tau, friction=vs.Friction(static=fs), contacts=contacts)
    model = rc.model
    data = model.createData()
    pq = pin_configuration(model, q)
    pin.computeJointJacobians(model, data, pq)
    pin.forwardKinematics(model, data, pq, qd, np.zeros(rc.n_joints))
    from support.contact_oracle import point_jacobian

    J, bias, _ = point_jacobian(model, data, rc.tip_frames[-1], np.zeros(3))
    # The task in joint space: J qdd + bias = beta - (gravity's share: beta includes the root's
    # acceleration, i.e. the tip's acceleration in the solver's frame with gravity as -g).
    g = np.asarray(model.gravity.linear)
    prob = _problem(rc, q, qd, tau, contacts, dict(static=fs))
    prob.A, prob.b = J, beta + g - bias
    found = enumerate_modes(prob)
    assert found
    assert min(_rel(r.qdd, s.qdd) for s in found) <= RTOL
    qdd = pin.aba(
        model,
        model.createData(),
        pq,
        qd,
        tau
        + r.tau_command
        + r.friction_torque
        + r.limit_torque
        + sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)),
    )
    assert _rel(r.qdd, qdd) <= RTOL


def test_separating_contacts_leave_the_friction_solve_unchanged():
    rng = np.random.default_rng(900)
    rc, q, qd, tau, fs, _ = _case(rng, 0, 0.0)
    solver = rc.solver()
    fr = vs.Friction(static=fs)
    # A support whose point moves away from its surface carries nothing.
    qd = rng.normal(size=rc.n_joints)
    plain = solver.solve(q, qd, tau_ff=tau, friction=fr)
    prob = _problem(rc, q, qd, tau, [vs.Contact(rc.n_segments - 1, normal=[0, 0, 1])], None)
    v = prob.contacts[0].velocity
    contact = vs.Contact(rc.n_segments - 1, normal=v / np.linalg.norm(v), mu=0.5)
    r = solver.solve(q, qd, tau_ff=tau, friction=fr, contacts=[contact])
    assert r.contact_status[0] == vs.ContactStatus.SEPARATING
    np.testing.assert_allclose(r.qdd, plain.qdd, rtol=0, atol=1e-12 * max(1.0, np.abs(plain.qdd).max()))
    np.testing.assert_array_equal(r.friction_torque, plain.friction_torque)
    np.testing.assert_array_equal(r.status, plain.status)


def test_solve_batch_with_friction_and_contacts_equals_solve_row_by_row():
    rng = np.random.default_rng(901)
    rc, q, qd, tau, fs, contacts = _case(rng, 2, 0.5, n=6, first=3)
    solver = rc.solver()
    fr = vs.Friction(static=fs)
    qs = np.array([q + 0.01 * rng.normal(size=6) for _ in range(4)])
    batch = solver.solve_batch(qs, np.zeros((4, 6)), tau_ff=tau, friction=fr, contacts=contacts)
    for b in range(4):
        r = solver.solve(qs[b], np.zeros(6), tau_ff=tau, friction=fr, contacts=contacts)
        np.testing.assert_array_equal(batch.qdd[b], r.qdd)
        np.testing.assert_array_equal(batch.friction_torque[b], r.friction_torque)
        np.testing.assert_array_equal(batch.contact_force[b], r.contact_force)


@pytest.mark.parametrize("name", ["baxter", "random_3", "random_8"])
def test_trees_with_joint_friction_and_supports(name):
    """1 to 8 frictionless supports on random segments of a tree with breakaway friction on three
    joints."""
    from support.trees import robot

    case = robot(name)
    rng = np.random.default_rng([41, len(name)])
    names = list(case.tree.segment_names)
    n = case.n
    for k in (1, 3, 5, 8):
        q, _ = case.random_state(rng)
        tau = rng.normal(size=n) * 3
        fs = np.zeros(n)
        fs[rng.choice(n, size=3, replace=False)] = rng.uniform(0.3, 3.0, size=3)
        contacts = []
        for s in rng.choice(len(names), size=min(k, len(names)), replace=False):
            normal = rng.normal(size=3)
            contacts.append(
                vs.Contact(names[s], point=rng.normal(size=3) * 0.05, normal=normal / np.linalg.norm(normal))
            )
        r = case.solver().solve(q, np.zeros(n), tau_ff=tau, friction=vs.Friction(static=fs), contacts=contacts)
        model = case.model
        specs = [dict(frame=model.getFrameId(c.segment), point=c.point, normal=c.normal, mu=0.0) for c in contacts]
        fr = dict(static=case.pin_v(fs))
        prob = contact_problem(
            model, model.createData(), case.pin_q(q), np.zeros(model.nv), case.pin_v(tau), specs, friction=fr
        )
        found = enumerate_modes(prob)
        assert found, f"{name}, {k} supports"
        best = min(found, key=lambda s: _rel(r.qdd, case.ours(s.qdd)))
        assert _rel(r.qdd, case.ours(best.qdd)) <= RTOL, f"{name}, {k} supports"
        gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)) + case.pin_v(r.friction_torque)
        assert _rel(gen, sum(c.J.T @ f for c, f in zip(prob.contacts, best.forces)) + best.joint_torques) <= RTOL
