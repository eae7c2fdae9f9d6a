"""The solver's contacts (``Solver.solve(..., contacts=[vs.Contact(...)])``) against oracles written
independently of it: Pinocchio's ``constraintDynamics`` for a sticking point, the convex QP of
Gauss's principle (scipy) for frictionless supports, and the enumeration of contact modes
(:mod:`support.contact_oracle`) for supports with friction and force set-points, on random chains
(1 to 4 contacts, with and without a task) at 1e-9 relative."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import pin_configuration, random_chain, random_state
from support.contact_oracle import contact_problem, enumerate_modes, frictionless_qp, pin_rigid_3d, tangent_basis

RTOL = 1e-9
STATUS = {"separating": vs.ContactStatus.SEPARATING, "sticking": vs.ContactStatus.STICKING}


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


def _resting(rng, n, k, mu, force=None, first=2):
    """A random chain at rest with k contacts on distinct random segments from ``first`` on."""
    rc = random_chain(rng, n, prismatic=False)
    q, _ = random_state(rng, rc)
    qd = np.zeros(n)
    tau = rng.normal(size=n) * 3
    # Segments `first` on, distinct: with friction each resting point holds three directions, and
    # the enumeration (least-squares forces per mode) needs them independent, which takes as many
    # joints before the points (on segments 0 and 1 alone, or with more rows than joints, the
    # sticking forces are a family the enumeration does not represent).
    segs = rng.choice(np.arange(first, rc.n_segments), size=k, replace=False)
    contacts = []
    for s in segs:
        normal = rng.normal(size=3)
        contacts.append(
            vs.Contact(
                int(s), point=rng.normal(size=3) * 0.1, normal=normal / np.linalg.norm(normal), mu=mu, force=force
            )
        )
    return rc, q, qd, tau, contacts


def _problem(rc, q, qd, tau, contacts, A=None, b=None):
    specs = [
        dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu, facets=c.facets, force=c.force)
        for c in contacts
    ]
    model = rc.model
    return contact_problem(model, model.createData(), pin_configuration(model, q), qd, tau, specs, A, b)


@pytest.mark.parametrize("seed", range(6))
def test_a_sticking_point_is_pinocchios_rigid_3d_contact(seed):
    rng = np.random.default_rng(100 + seed)
    rc = random_chain(rng, 7, prismatic=False)
    solver = rc.solver()
    q, _ = random_state(rng, rc)
    qd = np.zeros(7)
    tau = rng.normal(size=7)
    point = rng.normal(size=3) * 0.1
    contact = vs.Contact(rc.n_segments - 1, point=point, normal=[0.0, 0.0, 1.0], mu=1e6)
    r = solver.solve(q, qd, tau_ff=tau, contacts=[contact])
    qdd, lam = pin_rigid_3d(rc.model, rc.data(), pin_configuration(rc.model, q), qd, tau, rc.tip_frames[-1], point)
    if lam[2] <= 0.0:  # Pinocchio's bilateral answer pulls: the support lifts off instead
        assert r.contact_status[0] == vs.ContactStatus.SEPARATING
        return
    assert _rel(r.qdd, qdd) <= RTOL
    assert _rel(r.contact_force[0], lam) <= RTOL
    assert r.contact_status[0] == vs.ContactStatus.STICKING


@pytest.mark.parametrize("seed", range(10))
def test_frictionless_supports_are_gauss_qp(seed):
    rng = np.random.default_rng(200 + seed)
    k = 1 + seed % 4
    rc, q, qd, tau, contacts = _resting(rng, 6, k, 0.0)
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=contacts)
    prob = _problem(rc, q, qd, tau, contacts)
    expected = frictionless_qp(prob)
    assert _rel(r.qdd, expected) <= RTOL
    assert r.contact_outcome == vs.ContactOutcome.UNIQUE
    # The generalised contact force H qdd - h is unique; each force pushes along its normal.
    gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force))
    assert _rel(gen, prob.H @ expected - prob.h) <= RTOL
    for c, f in zip(contacts, r.contact_force):
        assert c.normal @ f >= 0.0
        assert np.linalg.norm(f - (c.normal @ f) * c.normal) <= 1e-12 * max(1.0, np.linalg.norm(f))


def _matches_an_enumerated_solution(r, prob, contacts):
    found = enumerate_modes(prob)
    assert found, "the enumeration found no consistent answer"
    best = min(found, key=lambda s: _rel(r.qdd, s.qdd))
    assert _rel(r.qdd, best.qdd) <= RTOL
    gen_ours = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force))
    gen_oracle = sum(c.J.T @ f for c, f in zip(prob.contacts, best.forces))
    assert _rel(gen_ours, gen_oracle) <= RTOL
    for c, f in zip(contacts, r.contact_force):  # inside the cone, pushing
        fn = c.normal @ f
        assert fn >= -1e-12 * max(1.0, np.linalg.norm(f))
        assert np.linalg.norm(f - fn * c.normal) <= c.mu * fn + 1e-9 * max(1.0, np.linalg.norm(f))
    return best


@pytest.mark.parametrize("seed", range(10))
def test_supports_with_friction_meet_an_enumerated_mode(seed):
    rng = np.random.default_rng(300 + seed)
    k = 1 + seed % 2
    rc, q, qd, tau, contacts = _resting(rng, 7, k, 0.7, first=4)
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=contacts)
    _matches_an_enumerated_solution(r, _problem(rc, q, qd, tau, contacts), contacts)


@pytest.mark.parametrize("seed", range(6))
def test_force_set_points_push_with_their_force(seed):
    rng = np.random.default_rng(400 + seed)
    k = 1 + seed % 2
    rc, q, qd, tau, contacts = _resting(rng, 7, k, 0.5, force=4.0, first=4)
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=contacts)
    for c, f in zip(contacts, r.contact_force):
        assert abs(c.normal @ f - 4.0) <= RTOL * 4.0
    _matches_an_enumerated_solution(r, _problem(rc, q, qd, tau, contacts), contacts)


@pytest.mark.parametrize("seed", range(6))
def test_a_force_set_point_is_pinocchios_constrained_forward_dynamics(seed):
    """A force set-point F: Pinocchio's ``forwardDynamics`` with the point's normal row held (and,
    when it sticks, its two tangential rows) and the surface's push F n as a known force. The
    normal row's multiplier is the motors' (tau_command), the tangential ones the surface's."""
    rng = np.random.default_rng(450 + seed)
    rc = random_chain(rng, 7, prismatic=False)
    q, _ = random_state(rng, rc)
    qd, tau = np.zeros(7), rng.normal(size=7)
    point, normal, force = rng.normal(size=3) * 0.1, rng.normal(size=3), 6.0
    normal /= np.linalg.norm(normal)
    stick = seed % 2 == 0  # friction far inside the cone (sticks), or none (frictionless)
    contact = vs.Contact(rc.n_segments - 2, point=point, normal=normal, mu=1e4 if stick else 0.0, force=force)
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=[contact])
    c = _problem(rc, q, qd, tau, [contact]).contacts[0]
    t1, t2 = tangent_basis(normal)
    rows = np.vstack([normal, t1, t2]) if stick else normal[None, :]
    model = rc.model
    data = model.createData()
    pq = pin_configuration(model, q)
    qdd = pin.forwardDynamics(model, data, pq, qd, tau + c.J.T @ (force * normal), rows @ c.J, rows @ c.bias)
    lam = data.lambda_c.copy()  # M qdd = tau - b + J^T lam
    assert _rel(r.qdd, qdd) <= RTOL
    expected_force = force * normal + (lam[1] * t1 + lam[2] * t2 if stick else 0.0)
    assert _rel(r.contact_force[0], expected_force) <= RTOL
    assert _rel(r.tau_command, c.J.T @ normal * lam[0]) <= RTOL
    assert r.contact_status[0] == (vs.ContactStatus.STICKING if stick else vs.ContactStatus.SLIDING)


def test_replaying_the_motors_and_the_contact_forces_gives_qdd():
    """tau_command is the motors' share only: tau_ff + tau_command plus J_c^T f_c through
    Pinocchio's forward dynamics gives the solve's qdd."""
    rng = np.random.default_rng(7)
    rc, q, qd, tau, contacts = _resting(rng, 7, 3, 0.6)
    alpha = np.zeros((6, 3))
    alpha[:3, :3] = np.eye(3)
    r = rc.solver().solve(q, qd, alpha=alpha, beta=np.array([0.0, 0.0, 9.81]), tau_ff=tau, contacts=contacts)
    prob = _problem(rc, q, qd, tau, contacts)
    gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force))
    model = rc.model
    qdd = pin.aba(model, model.createData(), pin_configuration(model, q), qd, tau + r.tau_command + gen)
    assert _rel(r.qdd, qdd) <= RTOL


def test_solve_batch_with_contacts_equals_solve_row_by_row():
    rng = np.random.default_rng(11)
    rc, q, qd, tau, contacts = _resting(rng, 6, 2, 0.5)
    solver = rc.solver()
    qs = np.array([q + 0.01 * rng.normal(size=6) for _ in range(5)])
    batch = solver.solve_batch(qs, np.zeros((5, 6)), tau_ff=tau, contacts=contacts)
    for b in range(5):
        r = solver.solve(qs[b], np.zeros(6), tau_ff=tau, contacts=contacts)
        np.testing.assert_array_equal(batch.qdd[b], r.qdd)
        np.testing.assert_array_equal(batch.contact_force[b], r.contact_force)
        np.testing.assert_array_equal(batch.contact_status[b], r.contact_status)


@pytest.mark.parametrize("name", ["baxter", "talos", "random_3", "random_8", "random_11"])
def test_frictionless_supports_on_trees_are_gauss_qp(name):
    """1 to 8 supports on random segments of a tree (Pinocchio's joint order mapped by name)."""
    from support.trees import robot

    case = robot(name)
    rng = np.random.default_rng([31, len(name)])
    names = list(case.tree.segment_names)
    for k in (1, 3, 5, 8):
        q, _ = case.random_state(rng)
        tau = rng.normal(size=case.n) * 3
        contacts = []
        for s in rng.choice(len(names), size=min(k, len(names)), replace=False):
            normal = rng.normal(size=3)
            contacts.append(
                vs.Contact(names[s], point=rng.normal(size=3) * 0.05, normal=normal / np.linalg.norm(normal))
            )
        r = case.solver().solve(q, np.zeros(case.n), tau_ff=tau, contacts=contacts)
        specs = [dict(frame=case.model.getFrameId(c.segment), point=c.point, normal=c.normal, mu=0.0) for c in contacts]
        model = case.model
        prob = contact_problem(model, model.createData(), case.pin_q(q), np.zeros(model.nv), case.pin_v(tau), specs)
        expected = frictionless_qp(prob)
        assert _rel(r.qdd, case.ours(expected)) <= RTOL, f"{name}, {k} supports"
        gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force))
        assert _rel(gen, prob.H @ expected - prob.h) <= RTOL


def _painleve(sign):
    """A chain whose tip slides on a surface with friction mu = 3 where the normal force pulls the
    point into the surface (the sliding direction's effective normal mass n^T J H^-1 J^T (n + mu d*)
    is negative: Painleve's paradox), with tau_ff chosen so the contact-free normal acceleration has
    the given sign: none (sign < 0) or two (sign > 0) consistent answers."""
    for seed in range(400):
        rng = np.random.default_rng(1000 + seed)
        rc = random_chain(rng, 4, prismatic=False)
        q, qd = random_state(rng, rc)
        tau = np.zeros(4)
        point = rng.normal(size=3) * 0.1
        seg = rc.n_segments - 1
        c0 = _problem(rc, q, qd, tau, [vs.Contact(seg, point=point)]).contacts[0]
        v = c0.velocity
        normal = np.cross(v, rng.normal(size=3))  # perpendicular to the velocity: touching, sliding
        normal /= np.linalg.norm(normal)
        contact = vs.Contact(seg, point=point, normal=normal, mu=3.0)
        prob = _problem(rc, q, qd, tau, [contact])
        c = prob.contacts[0]
        d = c.directions[np.argmin(c.directions @ (c.velocity - normal * (normal @ c.velocity)))]
        nJ = normal @ c.J
        m = nJ @ np.linalg.solve(prob.H, c.J.T @ (normal + 3.0 * d))
        if m >= -0.05 * abs(nJ @ np.linalg.solve(prob.H, nJ)):
            continue
        # Shift tau_ff along J^T n until the free normal acceleration is +-1 m/s^2.
        a0 = nJ @ np.linalg.solve(prob.H, prob.h) + normal @ c.bias
        unit = nJ @ np.linalg.solve(prob.H, nJ)
        tau = (sign * 1.0 - a0) / unit * nJ
        return rc, q, qd, tau, contact
    raise AssertionError("no Painleve configuration found")


def test_painleve_without_an_answer_is_reported():
    rc, q, qd, tau, contact = _painleve(-1.0)
    assert enumerate_modes(_problem(rc, q, qd, tau, [contact])) == []
    with pytest.raises(vs.SolverError, match="Painleve"):
        rc.solver().solve(q, qd, tau_ff=tau, contacts=[contact])


def test_painleve_with_two_answers_returns_one_of_them_as_consistent():
    rc, q, qd, tau, contact = _painleve(1.0)
    prob = _problem(rc, q, qd, tau, [contact])
    found = enumerate_modes(prob)
    assert len(found) == 2  # lift off, or press with a large force
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=[contact])
    assert r.contact_outcome == vs.ContactOutcome.CONSISTENT
    assert min(_rel(r.qdd, s.qdd) for s in found) <= RTOL
