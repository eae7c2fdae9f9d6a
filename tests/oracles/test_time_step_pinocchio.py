"""The solve over a time step (``solve(..., time_step=dt)``) against Pinocchio 4's constraint
solver on the same velocity-level (impulse) problem: random chains, random trees and the Gen3,
joints at rest and moving, joint friction and point contacts.

The mapping (Pinocchio 4.1's ``JointFrictionConstraintModel``, ``PointContactConstraintModel`` and
``ADMMConstraintSolver``). The unknowns are the constraint impulses ``lambda`` over the step; the
free end velocity is ``v_free = qd + dt aba(q, qd, tau)`` and the end velocity
``v+ = v_free + M^-1 J^T lambda``; with the Delassus matrix ``G = J M^-1 J^T`` and the drift ``g``
the constraint velocities are ``sigma = G lambda + g`` (the rows of ``v+``), and the ADMM finds
``lambda`` in its set ``K`` with ``sigma`` in the dual set, complementary (``solve_ncp``: with the
de Saxce correction, which vanishes at sticking points).

* Joint friction: one box row per joint with friction, ``J = e_j``, drift ``g = v_free_j``, the box
  ``dt [-F_j, F_j]`` (the bounds ``F_j`` with ``setTimeStep(dt)``) where ``F_j`` is the joint's
  static friction when it is at rest at the start of the step and its kinetic friction when it
  moves (our step's bounds); ``lambda_j = dt`` times our ``friction_torque[j]``.
* Point contacts: the contact frame's z axis along ``-n`` (``n`` our normal, along which the surface
  pushes), so Pinocchio's row velocity (the world side's motion against the link's, ``J = -R^T
  J_p``) has ``sigma_z = n . v_p``: the point's normal velocity. Our point's end velocity is
  ``v_p + dt a_p`` to first order (docs/time-step.md) with the classical acceleration
  ``a_p = J_p qdd + bias``, so the drift is ``g = J v_free - dt R^T bias`` (``bias`` = the point's
  acceleration at ``qdd = 0``, nonzero only when the arm moves). The force on the link, base axes,
  is ``-R lambda = dt`` times our ``contact_force``.

Compared: the end velocities ``qd + dt qdd`` (ours) and ``v+`` (Pinocchio's ``aba`` with the
impulses over ``dt`` added to ``tau``), and the impulses where they are unique (the constraint
rows independent). Only where the cone's shape cannot matter: frictionless supports, or one
support with friction whose force we find sticking strictly inside the circular cone (our cone is
the polygon inscribed in it, docs/contacts.md), where the sticking answer solves both problems.

Tolerance: ADMM at 1e-12 (absolute and relative feasibility and complementarity) against our
exact pivoting (round-off). The ADMM stops on its residuals, not on its error: the error in
``lambda`` is the residual amplified by the conditioning of ``G`` (random masses and inertias), so
we compare at 1e-8 relative (the largest difference seen in these cases is below 1e-9), and a test
shows the difference falling with the ADMM's tolerance (1e-6 -> 1e-12), so it is the ADMM's.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import pin_configuration, random_chain, random_state
from support.contact_oracle import point_jacobian, tangent_basis
from support.trees import robot
from vereshchagin.robots import gen3_urdf

RTOL = 1e-8
ADMM_TOL = 1e-12
G_EARTH = np.array([0.0, 0.0, -9.81])
GEN3_Q = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])


def _settings(n, tol):
    s = pin.ADMMSolverSettings()
    s.lanczos_size = n
    s.anderson_capacity = 4
    s.rho_momentum = 0.9
    s.max_iterations = 100_000
    s.absolute_feasibility_tol = s.relative_feasibility_tol = tol
    s.absolute_complementarity_tol = s.relative_complementarity_tol = tol
    return s


def _contact_model(model, data, frame_id, point, normal, mu):
    """A PointContactConstraintModel at ``point`` of frame ``frame_id`` (local coordinates), its
    frame's z axis along -normal, and that frame's rotation R in base axes."""
    t1, t2 = tangent_basis(-np.asarray(normal, float))
    R = np.column_stack([t1, t2, -np.asarray(normal, float)])
    frame = model.frames[frame_id]
    j = frame.parentJoint
    p_joint = frame.placement.act(np.asarray(point, float))
    oMj = data.oMi[j]
    cm = pin.PointContactConstraintModel(
        model, j, pin.SE3(oMj.rotation.T @ R, p_joint), 0, pin.SE3(R, oMj.act(p_joint))
    )
    cm.setFriction(mu)
    return cm, R


def pin_step(model, q, qd, tau, dt, bounds, contacts=(), tol=ADMM_TOL):
    """Pinocchio's velocity-level step. ``q`` Pinocchio's configuration, ``qd``, ``tau`` and
    ``bounds`` (friction bound per velocity index, 0: none) in its velocity order; ``contacts``:
    (frame_id, point, normal, mu). Returns (v+, friction impulses per velocity index, contact
    impulses on the links (k, 3) base axes, ADMM result, the constraint Jacobian's rows that can
    carry an impulse: the impulses are unique when they are independent)."""
    data = model.createData()
    v_free = qd + dt * pin.aba(model, data, q, qd, tau)
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, qd, np.zeros(model.nv))  # for the points' bias
    cms, drift_bias, Rs = pin.StdVec_ConstraintModel(), [], []
    dofs = np.flatnonzero(bounds > 0.0)
    if dofs.size:
        joints = sorted({next(k for k in range(1, model.njoints) if model.joints[k].idx_v == d) for d in dofs})
        fm = pin.JointFrictionConstraintModel(model, pin.StdVec_Index(joints), -bounds, bounds)  # nv-sized
        fm.setTimeStep(dt)  # the box on the impulses: dt * bounds
        assert list(fm.getActiveDofs()) == list(dofs)
        cms.append(pin.ConstraintModel(fm))
        drift_bias.append(np.zeros(dofs.size))
    for frame_id, point, normal, mu in contacts:
        Jp, bias, _ = point_jacobian(model, data, frame_id, point)
        cm, R = _contact_model(model, data, frame_id, point, normal, mu)
        cms.append(pin.ConstraintModel(cm))
        drift_bias.append(-dt * R.T @ bias)
        Rs.append((R, Jp, mu))
    cds = pin.StdVec_ConstraintData()
    for cm in cms:
        cds.append(cm.createData())
    pin.crba(model, data, q)
    for cm, cd in zip(cms, cds):
        cm.calc(model, data, cd)
    chol = pin.ConstraintCholeskyDecomposition(model, data, cms, cds)
    chol.compute(model, data, cms, cds, 0.0)
    J = pin.getConstraintsJacobian(model, data, cms, cds)
    carried = np.ones(J.shape[0], bool)  # the rows that can carry an impulse
    for k, (R, Jp, mu) in enumerate(Rs):  # our reading of Pinocchio's contact rows: J = -R^T J_p
        rows = slice(dofs.size + 3 * k, dofs.size + 3 * k + 3)
        np.testing.assert_allclose(J[rows], -R.T @ Jp, atol=1e-12 * max(1.0, np.abs(Jp).max()))
        carried[rows.start : rows.start + 2] = mu > 0.0  # no tangential impulse without friction
    g = J @ v_free + np.concatenate(drift_bias)
    res = pin.ADMMSolverResult()
    pin.ADMMConstraintSolver(J.shape[0]).solve(
        chol.getDelassusOperatorCholeskyExpression(), g, cms, cds, _settings(J.shape[0], tol), res
    )
    lam = np.array(res.retrieveConstraintImpulses())
    v_next = qd + dt * pin.aba(model, data, q, qd, tau + J.T @ lam / dt)
    fric = np.zeros(model.nv)
    fric[dofs] = lam[: dofs.size]
    forces = np.array([-R @ lam[dofs.size + 3 * k : dofs.size + 3 * k + 3] for k, (R, _, _) in enumerate(Rs)])
    return v_next, fric, forces.reshape(-1, 3), res, J[carried]


def _bounds(qd, fs, fk):
    """Our step's box per joint: static friction at rest, kinetic friction while moving."""
    return np.where(np.abs(qd) > 1e-6, fk, fs)


def _compare(ours, pin_out, qd, dt, unique=True, what=""):
    """End velocities at RTOL relative to max(|v+|, |qd|, dt x 1 rad/s^2) (a step from rest whose
    joints all stick ends at v+ = 0); impulses too when ``unique``, relative to the largest.
    ``ours`` the solve's result and ``pin_out`` pin_step's (already in our joint order)."""
    v_next, fric, forces, res, _ = pin_out
    assert res.converged, f"{what}: ADMM did not converge ({res.iterations} iterations)"
    v_ours = qd + dt * ours.qdd
    scale_v = max(np.linalg.norm(v_ours), np.linalg.norm(qd), dt)
    assert np.linalg.norm(v_next - v_ours) <= RTOL * scale_v, f"{what}: end velocities {v_next} vs {v_ours}"
    if unique:
        scale = max(np.abs(dt * ours.friction_torque).max(), np.abs(dt * ours.contact_force).max(initial=0.0))
        assert np.abs(fric - dt * ours.friction_torque).max() <= RTOL * scale, what
        if len(forces):
            assert np.abs(forces - dt * ours.contact_force).max() <= RTOL * scale, what
    return np.abs(v_next - v_ours).max()


def _chain_case(seed):
    """A random 7-joint revolute chain, moving (slowly for seeds >= 4, so that friction can stop
    joints within a step), three joints at rest, friction (kinetic 0.7 of the breakaway) on four
    joints, random feed-forward torques."""
    rng = np.random.default_rng(2700 + seed)
    rc = random_chain(rng, 7, prismatic=False)
    q, qd = random_state(rng, rc, qd_scale=0.5 if seed < 4 else 0.02)
    qd[rng.choice(7, size=3, replace=False)] = 0.0
    fs = np.zeros(7)
    fs[rng.choice(7, size=4, replace=False)] = rng.uniform(1.0, 30.0, size=4)
    return rng, rc, q, qd, fs, 0.7 * fs, rng.normal(size=7) * 3


@pytest.mark.parametrize("seed", range(8))
def test_random_chains_with_joint_friction(seed):
    """Joint friction only (a box QP with G = M^-1 on the friction rows: impulses unique)."""
    _, rc, q, qd, fs, fk, tau = _chain_case(seed)
    dt = (1e-3, 1e-2)[seed % 2]
    r = rc.solver().solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs, kinetic=fk), time_step=dt)
    out = pin_step(rc.model, pin_configuration(rc.model, q), qd, tau, dt, _bounds(qd, fs, fk))
    _compare(r, out, qd, dt, what=f"seed {seed}")


def test_the_chain_cases_have_joints_sticking_slipping_and_moving():
    """The friction cases above are not vacuous: over the seeds, joints at rest stick (status 1)
    and break away (2, 3), moving joints with friction keep moving, and some get stopped."""
    seen = set()
    for seed in range(8):
        _, rc, q, qd, fs, fk, tau = _chain_case(seed)
        dt = (1e-3, 1e-2)[seed % 2]
        r = rc.solver().solve(q, qd, tau_ff=tau, friction=vs.Friction(static=fs, kinetic=fk), time_step=dt)
        v = qd + dt * r.qdd
        for j in np.flatnonzero(fs > 0.0):
            if qd[j] == 0.0:
                seen.add("stick" if r.status[j] == 1 else "break away")
            else:
                seen.add("stopped" if abs(v[j]) < 1e-12 else "moving")
    assert seen == {"stick", "break away", "stopped", "moving"}, seen


def _support_contacts(rng, rc, k, mu=0.0):
    segs = rng.choice(np.arange(3, rc.n_segments), size=k, replace=False)
    out = []
    for s in segs:
        normal = rng.normal(size=3)
        out.append(vs.Contact(int(s), point=rng.normal(size=3) * 0.1, normal=normal / np.linalg.norm(normal), mu=mu))
    return out


@pytest.mark.parametrize("seed", range(8))
def test_random_chains_with_friction_and_frictionless_supports(seed):
    """One or two frictionless supports (a convex problem: v+ unique; with 4 friction rows and 1-2
    normal rows on 7 joints the rows are independent, so the impulses are unique too)."""
    rng, rc, q, qd, fs, fk, tau = _chain_case(seed)
    dt = (1e-2, 1e-3)[seed % 2]
    contacts = _support_contacts(rng, rc, 1 + seed % 2)
    r = rc.solver().solve(
        q, qd, tau_ff=tau, friction=vs.Friction(static=fs, kinetic=fk), contacts=contacts, time_step=dt
    )
    specs = [(rc.tip_frames[c.segment], c.point, c.normal, 0.0) for c in contacts]
    out = pin_step(rc.model, pin_configuration(rc.model, q), qd, tau, dt, _bounds(qd, fs, fk), specs)
    assert np.linalg.matrix_rank(out[4]) == out[4].shape[0]
    _compare(r, out, qd, dt, what=f"seed {seed}")


def _inside_cone(f, normal, mu, margin=1e-3):
    """Pushing and strictly inside the circular cone, relative margin."""
    fn = f @ normal
    return fn > 0.0 and np.linalg.norm(f - fn * normal) < (1.0 - margin) * mu * fn


def _free_point_velocity(rc, q, qd, tau, dt, segment, point):
    """The point's end velocity without contact (Pinocchio), base axes."""
    model = rc.model
    data = model.createData()
    qp = pin_configuration(model, q)
    v_free = qd + dt * pin.aba(model, data, qp, qd, tau)
    pin.computeJointJacobians(model, data, qp)
    pin.forwardKinematics(model, data, qp, qd, np.zeros(model.nv))
    Jp, bias, _ = point_jacobian(model, data, rc.tip_frames[segment], point)
    return Jp @ v_free + dt * bias


@pytest.mark.parametrize("seed", range(6))
def test_random_chains_with_a_support_sticking_inside_the_cone(seed):
    """One support with friction (mu 1) that the free step would drive into its surface, drawn
    until our force sticks strictly inside the circular cone (then both problems have the sticking
    answer; 3 friction + 3 contact rows on 7 joints: impulses unique)."""
    rng = np.random.default_rng(2800 + seed)
    dt = (1e-3, 1e-2)[seed % 2]
    for _ in range(200):
        rc = random_chain(rng, 7, prismatic=False)
        q, qd = random_state(rng, rc, qd_scale=0.5)
        qd[rng.choice(7, size=3, replace=False)] = 0.0
        fs = np.zeros(7)
        fs[rng.choice(7, size=3, replace=False)] = rng.uniform(0.3, 3.0, size=3)
        tau = rng.normal(size=7) * 3
        s, point = int(rng.integers(3, 7)), rng.normal(size=3) * 0.1
        v = _free_point_velocity(rc, q, qd, tau, dt, s, point)
        normal = -(v + 0.3 * np.linalg.norm(v) * rng.normal(size=3))  # against the free motion, tilted
        normal /= np.linalg.norm(normal)
        contacts = [vs.Contact(s, point=point, normal=normal, mu=1.0)]
        fr = vs.Friction(static=fs, kinetic=0.7 * fs)
        r = rc.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts, time_step=dt)
        if r.contact_status[0] == vs.ContactStatus.STICKING and _inside_cone(r.contact_force[0], normal, 1.0):
            break
    else:
        raise AssertionError("no sticking state drawn")
    specs = [(rc.tip_frames[s], point, normal, 1.0)]
    out = pin_step(rc.model, pin_configuration(rc.model, q), qd, tau, dt, _bounds(qd, fs, 0.7 * fs), specs)
    _compare(r, out, qd, dt, what=f"seed {seed}")
    assert np.linalg.norm(dt * r.contact_force[0]) > 1e-3, "the support carries an impulse"


@pytest.mark.parametrize("name", ["random_3", "random_8", "random_11"])
def test_random_trees_with_friction_and_frictionless_supports(name):
    """Trees of tests/support/trees.py (16 links, revolute, continuous and prismatic joints),
    moving, friction on five joints (three at rest), and two frictionless supports."""
    case = robot(name)
    n, names = case.n, list(case.tree.segment_names)
    rng = np.random.default_rng([2900, len(name), int(name.split("_")[1])])
    for dt in (1e-3, 1e-2):
        q, qd = case.random_state(rng, qd_scale=0.5)
        with_f = rng.choice(n, size=5, replace=False)
        qd[with_f[:3]] = 0.0
        fs = np.zeros(n)
        fs[with_f] = rng.uniform(0.3, 3.0, size=5)
        tau = rng.normal(size=n) * 3
        contacts = []
        for s in rng.choice(len(names), size=2, replace=False):
            normal = rng.normal(size=3)
            contacts.append(
                vs.Contact(names[s], point=rng.normal(size=3) * 0.05, normal=normal / np.linalg.norm(normal))
            )
        fr = vs.Friction(static=fs, kinetic=0.7 * fs)
        r = case.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts, time_step=dt)
        specs = [(case.model.getFrameId(c.segment), c.point, c.normal, 0.0) for c in contacts]
        bounds = case.pin_v(_bounds(qd, fs, 0.7 * fs))
        v_next, fric, forces, res, J = pin_step(
            case.model, case.pin_q(q), case.pin_v(qd), case.pin_v(tau), dt, bounds, specs
        )
        unique = np.linalg.matrix_rank(J) == J.shape[0]
        _compare(r, (case.ours(v_next), case.ours(fric), forces, res, J), qd, dt, unique, f"{name}, dt {dt}")


def _gen3():
    urdf = gen3_urdf(gripper=False, use_external_cable=True)  # +-2 pi revolute joints: q is Pinocchio's q
    model = pin.buildModelFromXML(urdf)
    model.gravity = pin.Motion(np.r_[G_EARTH, 0.0, 0.0, 0.0])
    return vs.Solver(vs.Chain.from_urdf(urdf), gravity=G_EARTH), model


GEN3_CASES = {
    # name: (qd, static friction, contacts as (link, point, normal, mu))
    "at rest, some joints held": (np.zeros(7), np.array([1.0, 8.0, 1.0, 3.0, 0.5, 1.5, 0.2]), ()),
    "moving, friction everywhere": (np.array([0.3, -0.2, 0.1, 0.4, -0.5, 0.2, 0.6]), np.full(7, 1.5), ()),
    "moving, forearm and wrist on frictionless supports": (
        np.array([0.2, 0.3, -0.1, -0.2, 0.0, 0.3, 0.0]),
        np.array([2.0, 2.0, 0.0, 1.0, 1.0, 0.5, 0.5]),
        (
            ("forearm_link", [0.0, 0.0, -0.1], [0.0, 0.0, 1.0], 0.0),
            ("spherical_wrist_2_link", [0.0] * 3, [0.3, 0.0, 1.0], 0.0),
        ),
    ),
    "at rest, forearm on a table, sticking inside the cone": (
        np.zeros(7),
        np.array([0.0, 2.0, 0.0, 1.0, 0.0, 0.5, 0.0]),
        (("forearm_link", [0.0, 0.0, -0.1], [0.0, 0.0, 1.0], 0.8),),
    ),
    "wrist turning, forearm on a table, sticking inside the cone": (
        np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 0.0]),
        np.array([0.0, 2.0, 0.0, 1.0, 0.0, 0.5, 0.0]),
        (("forearm_link", [0.0, 0.0, -0.1], [0.0, 0.0, 1.0], 0.8),),
    ),
}


@pytest.mark.parametrize("name", list(GEN3_CASES))
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_gen3(name, dt):
    solver, model = _gen3()
    qd, fs, specs = GEN3_CASES[name]
    fk = 0.7 * fs
    contacts = [
        vs.Contact(link, point=p, normal=np.array(nrm) / np.linalg.norm(nrm), mu=mu) for link, p, nrm, mu in specs
    ]
    tau = np.zeros(7)
    r = solver.solve(GEN3_Q, qd, friction=vs.Friction(static=fs, kinetic=fk), contacts=contacts, time_step=dt)
    for c, f in zip(contacts, r.contact_force):
        if c.mu > 0.0:
            assert r.contact_status[0] == vs.ContactStatus.STICKING and _inside_cone(f, c.normal, c.mu)
    pin_specs = [(model.getFrameId(c.segment), c.point, c.normal, c.mu) for c in contacts]
    out = pin_step(model, GEN3_Q, qd, tau, dt, _bounds(qd, fs, fk), pin_specs)
    _compare(r, out, qd, dt, unique=np.linalg.matrix_rank(out[4]) == out[4].shape[0], what=name)


@pytest.mark.parametrize("name", ["moving, forearm and wrist on frictionless supports", "at rest, some joints held"])
def test_the_difference_shrinks_as_the_admm_tolerance_tightens(name):
    """ADMM's answer converges to ours: its difference from our end velocities and impulses falls
    with its tolerance (1e-6 -> 1e-12) down to the comparison's 1e-8."""
    solver, model = _gen3()
    qd, fs, specs = GEN3_CASES[name]
    dt = 1e-2
    contacts = [
        vs.Contact(link, point=p, normal=np.array(nrm) / np.linalg.norm(nrm), mu=mu) for link, p, nrm, mu in specs
    ]
    r = solver.solve(GEN3_Q, qd, friction=vs.Friction(static=fs, kinetic=0.7 * fs), contacts=contacts, time_step=dt)
    pin_specs = [(model.getFrameId(c.segment), c.point, c.normal, c.mu) for c in contacts]
    ours = np.concatenate([qd + dt * r.qdd, dt * r.friction_torque, dt * r.contact_force.ravel()])
    errors = []
    for tol in (1e-6, 1e-8, 1e-10, 1e-12):
        v, fric, forces, res, _ = pin_step(
            model, GEN3_Q, qd, np.zeros(7), dt, _bounds(qd, fs, 0.7 * fs), pin_specs, tol
        )
        assert res.converged
        errors.append(np.linalg.norm(np.concatenate([v, fric, forces.ravel()]) - ours) / np.linalg.norm(ours))
    assert errors[-1] <= RTOL and errors[0] >= 100 * errors[-1], errors
    assert all(b <= 2 * a for a, b in zip(errors, errors[1:])), errors  # falls (up to ADMM's wobble)
