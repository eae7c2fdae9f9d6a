"""The least-effort rule over a time step (``solve(..., time_step=dt)``, docs/time-step.md) against
an independent formulation (Pinocchio, ProxQP), at 1e-9 relative.

Where the step's impulses are not unique (redundant supports, supports and friction-held joints
sharing a load, a redundant task with joint friction) the step's end velocities still are, and the
solve picks, as at the instant, the impulses of least motor effort ``||tau_command||^2`` and among
those the least contact forces ``sum_c ||f_c||^2``. The oracle takes the step's ``qdd`` (so its end
velocities) and writes every admissible impulse as linear constraints in the motors' multipliers
``nu`` (``tau_command = A^T nu``, A the task's rows from Pinocchio's Jacobians), the contact forces
as non-negative weights on their friction polygon's edges (a sticking point: every edge ``n + mu
d_j``; sliding: the edges most opposed to its end sliding velocity; frictionless: ``n``; leaving:
none) and the torques of the joints with friction (sticking: within their bounds; slipping: the
bound against their end velocity), with the equation of motion ``H qdd - h = A^T nu + sum_c J_c^T
f_c + tau_joints`` (Pinocchio's ``crba`` and ``rnea``). The two programmes, least effort and then
least contact force with the effort kept, are solved by ProxQP (the proxsuite package: a proximal
augmented Lagrangian method, to 1e-12) and polished to the exact KKT solution on the bounds active
there (numpy), checked to meet every bound and equality and to do no worse than ProxQP's answer,
independently of the solver. (Before, a primal active-set method of our own from a linear
programme's feasible point solved them: on degenerate cases, many force weights and joint torques
at their bounds at once, it cycled to its iteration limit and its polish returned a feasible but
larger least contact force than the solver's, so a round-off change in the solver looked like a
failure. An SLSQP start was used before that: on the Baxter case with four supports it stopped at
its iteration limit with the equalities unmet.)
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import proxsuite
import pytest
from scipy.optimize import nnls

import vereshchagin as vs
from support.chains import G_EARTH, pin_configuration, random_chain, random_state
from support.contact_oracle import contact_problem, facet_directions, point_jacobian
from vereshchagin.robots import gen3_urdf

RTOL = 1e-9
GEN3_Q = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
TOOL = "end_effector_link"
LWA = pin.LOCAL_WORLD_ALIGNED


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


def _generators(c, row, scale):
    """The edges (3, g) whose non-negative weights span the admissible forces of contact ``c``
    given its row (end velocity over dt) in the solved motion: leaving (no force), sticking (the
    whole polygon cone), sliding (the polygon's edges most opposed to the sliding) or frictionless."""
    tol = 1e-9 * scale
    wn = c.normal @ row
    if wn > tol:
        return np.zeros((3, 0))
    if c.mu == 0.0:
        return c.normal[:, None]
    D = facet_directions(c.normal, c.facets)
    wt = row - wn * c.normal
    if np.linalg.norm(wt) <= tol:
        return np.array([c.normal + c.mu * d for d in D]).T
    score = D @ wt
    # Ties to the rows' round-off (not to |wt|'s): a point sliding exactly along an edge's outward
    # normal, as the polygon makes it whenever its force lies inside that edge, has two tied vertices.
    best = np.flatnonzero(score <= score.min() + tol)
    return np.array([c.normal + c.mu * D[j] for j in best]).T


def _qp(P, E, e, lo, hi):
    """min 1/2 x^T P x subject to E x = e and lo <= x <= hi (P positive semi-definite): ProxQP's
    answer (the proxsuite package, a proximal augmented Lagrangian method, to 1e-12), then the
    exact minimiser on the bounds active there (numpy), checked to meet every bound and the
    equalities and to do no worse than ProxQP's answer."""
    N = P.shape[0]
    U, sv, _ = np.linalg.svd(E, full_matrices=False)  # independent equality rows
    rank = int(np.sum(sv > 1e-12 * max(1.0, sv.max())))
    E, e = U[:, :rank].T @ E, U[:, :rank].T @ e
    big = 1e20  # ProxQP's infinite bound
    res = proxsuite.proxqp.dense.solve(
        P,
        np.zeros(N),
        E,
        e,
        np.eye(N),
        np.where(np.isfinite(lo), lo, -big),
        np.where(np.isfinite(hi), hi, big),
        eps_abs=1e-12,
        eps_rel=0.0,
        max_iter=100000,
    )
    assert res.info.status == proxsuite.proxqp.QPSolverOutput.PROXQP_SOLVED, res.info.status
    x_p = res.x
    tol = 1e-9 * max(1.0, np.abs(x_p).max())
    active = [(i, 0) for i in range(N) if x_p[i] <= lo[i] + tol] + [(i, 1) for i in range(N) if x_p[i] >= hi[i] - tol]
    B = np.zeros((len(active), N))
    B[np.arange(len(active)), [i for i, _ in active]] = 1.0
    C = np.vstack([E, B])
    d = np.concatenate([e, [lo[i] if side == 0 else hi[i] for i, side in active]])
    K = np.block([[P, C.T], [C, np.zeros((C.shape[0], C.shape[0]))]])
    # The least change of ProxQP's answer (where P is singular the minimisers form a set: the one
    # nearest it, which keeps the inactive bounds).
    x = x_p + np.linalg.lstsq(K, np.concatenate([-P @ x_p, d - C @ x_p]), rcond=None)[0][:N]
    scale = max(1.0, np.abs(x).max())
    assert np.all(x >= lo - 1e-9 * scale) and np.all(x <= hi + 1e-9 * scale), "the oracle's polish left the bounds"
    assert np.abs(E @ x - e).max() <= 1e-9 * max(1.0, np.abs(e).max()), "the oracle's polish left the equalities"
    assert x @ P @ x <= x_p @ P @ x_p + 1e-9 * max(1.0, x_p @ P @ x_p), "the oracle's polish did worse than ProxQP"
    return x


def _oracle(prob, A, qdd):
    """The least-effort impulses given the step's qdd: (tau_command, forces (k, 3), joint torques (n,)).
    ``prob``: contact_problem over the time step (rows a + v / dt, joints' offsets qd / dt)."""
    n, m = prob.H.shape[0], A.shape[0]
    rhs = prob.H @ qdd - prob.h
    scale_a = max(1.0, np.abs(qdd).max(), *(np.abs(c.J @ qdd + c.bias).max() for c in prob.contacts))
    gens = [_generators(c, c.J @ qdd + c.bias, scale_a) for c in prob.contacts]
    cols = [A.T] + [c.J.T @ G for c, G in zip(prob.contacts, gens)]
    lo, hi = [np.full(m, -np.inf)] + [np.zeros(G.shape[1]) for G in gens], [np.full(m, np.inf)]
    hi += [np.full(G.shape[1], np.inf) for G in gens]
    fixed = np.zeros(n)
    for j in prob.joints:  # sticking: a torque within its bounds; slipping: the bound against its row
        row = qdd[j.index] + j.offset
        if abs(row) <= 1e-9 * scale_a:
            cols.append(np.eye(n)[:, [j.index]])
            lo.append(np.array([j.lo])), hi.append(np.array([j.hi]))
        else:
            fixed[j.index] = j.lo if row > 0 else j.hi
    E, lo, hi = np.hstack(cols), np.concatenate(lo), np.concatenate(hi)
    e = rhs - fixed
    sizes = np.cumsum([0, m] + [G.shape[1] for G in gens])
    # Least effort: 1/2 ||A^T nu||^2.
    T = np.zeros((n, E.shape[1]))
    T[:, :m] = A.T
    x1 = _qp(T.T @ T, E, e, lo, hi)
    tau_cmd = T @ x1
    # Then the least contact forces with the motors' torques kept: tau_command = A^T nu is unique,
    # so the second programme is over the other unknowns y (force weights, sticking joints'
    # torques) with A^T nu moved to the right-hand side: E_y y = e - tau_command. (Held instead to
    # T x = tau_command beside E x = e over all unknowns, a feasible set that is a single point or a
    # thin face of the bounds left ProxQP's second solve reporting primal infeasibility.)
    F = np.zeros((3 * len(gens), E.shape[1] - m))
    for i, G in enumerate(gens):
        F[3 * i : 3 * i + 3, sizes[i + 1] - m : sizes[i + 2] - m] = G
    y = _qp(F.T @ F, E[:, m:], e - tau_cmd, lo[m:], hi[m:]) if E.shape[1] > m else np.zeros(0)
    x2 = np.concatenate([x1[:m], y])
    F = np.hstack([np.zeros((F.shape[0], m)), F])
    forces = (F @ x2).reshape(-1, 3)
    joint = rhs - A.T @ x2[:m] - sum((c.J.T @ f for c, f in zip(prob.contacts, forces)), np.zeros(n))
    return T @ x2, forces, joint


def _redundant(prob, A, qdd):
    """True when the step's impulses are not unique: the response columns of the free coordinates
    (sticking joints' torques, the contacts' admissible directions) are dependent."""
    scale_a = max(1.0, np.abs(qdd).max(), *(np.abs(c.J @ qdd + c.bias).max() for c in prob.contacts))
    cols = []
    for c in prob.contacts:
        G = _generators(c, c.J @ qdd + c.bias, scale_a)
        if G.shape[1]:
            cols.append(c.J.T @ np.linalg.qr(G)[0][:, : np.linalg.matrix_rank(G)])
    n = prob.H.shape[0]
    cols += [np.eye(n)[:, [j.index]] for j in prob.joints if abs(qdd[j.index] + j.offset) <= 1e-9 * scale_a]
    if not cols:
        return False
    M = np.hstack(cols)
    # Modulo the task: the directions the motors hold do not move qdd either.
    if A.shape[0]:
        Pa = np.eye(n) - A.T @ np.linalg.pinv(A.T)
        M = Pa @ M
    return np.linalg.matrix_rank(M, tol=1e-9 * max(1.0, np.abs(M).max())) < M.shape[1]


def _admissible(prob, qdd, forces, joint):
    """The solver's impulses meet the step's conditions: each force in its admissible cone, each
    joint's torque within its bounds (at the bound against a slipping joint's end velocity)."""
    scale_a = max(1.0, np.abs(qdd).max(), *(np.abs(c.J @ qdd + c.bias).max() for c in prob.contacts))
    for c, f in zip(prob.contacts, forces):
        G = _generators(c, c.J @ qdd + c.bias, scale_a)
        resid = np.linalg.norm(f) if G.shape[1] == 0 else nnls(G, f)[1]
        assert resid <= 1e-9 * max(1.0, np.linalg.norm(f)), (f, resid)
    for j in prob.joints:
        t, row, tol = joint[j.index], qdd[j.index] + j.offset, 1e-9 * max(1.0, abs(joint[j.index]))
        assert j.lo - tol <= t <= j.hi + tol
        if abs(row) > 1e-9 * scale_a:
            assert abs(t - (j.lo if row > 0 else j.hi)) <= tol


def _check(r, prob, A, what, tau_cmd=None, forces=None, joint=None, order=lambda x: x):
    """The solver's least effort, then its least contact forces, against the oracle's."""
    if tau_cmd is None:
        tau_cmd, forces, joint = _oracle(prob, A, order(r.qdd))
    scale = max(1.0, np.linalg.norm(tau_cmd), np.linalg.norm(forces), np.linalg.norm(joint))
    mine = order(r.friction_torque + r.limit_torque)
    assert np.linalg.norm(order(r.tau_command) - tau_cmd) <= RTOL * scale, f"{what}: {r.tau_command} vs {tau_cmd}"
    _admissible(prob, order(r.qdd), r.contact_force, mine)
    assert np.linalg.norm(r.contact_force - forces) <= RTOL * scale, f"{what}: forces {r.contact_force} vs {forces}"
    assert np.linalg.norm(mine - joint) <= RTOL * scale, f"{what}: joints {mine} vs {joint}"


def _gen3():
    urdf = gen3_urdf(gripper=False, use_external_cable=True)
    model = pin.buildModelFromXML(urdf)
    model.gravity = pin.Motion(np.r_[G_EARTH, 0.0, 0.0, 0.0])
    return vs.Solver(vs.Chain.from_urdf(urdf), gravity=G_EARTH), model


def _task_rows(model, data, q, frame_id, alpha):
    """A = alpha^T J (the frame's origin, base axes: linear rows 0..2, angular 3..5)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    return alpha.T @ pin.getFrameJacobian(model, data, frame_id, LWA)


@pytest.mark.parametrize("qd_scale", [0.0, 0.02])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_gen3_pressed_on_a_table_by_two_supports_with_joints_holding(qd_scale, dt):
    """Hold test B with a second support and the tool's orientation held by the motors: the tool
    and the wrist on a table (mu 0.8), the tool pushed by (8, 0, -20) N, joint friction half the
    gravity torque plus 0.3 N m: the table, the joints and the motors share the load."""
    solver, model = _gen3()
    data = model.createData()
    tool, wrist = model.getFrameId(TOOL), model.getFrameId("spherical_wrist_2_link")
    pin.computeJointJacobians(model, data, GEN3_Q)
    pin.forwardKinematics(model, data, GEN3_Q, np.zeros(7), np.zeros(7))
    J_tool, _, _ = point_jacobian(model, data, tool, np.zeros(3))
    N = np.array([J_tool[2], point_jacobian(model, data, wrist, np.zeros(3))[0][2]])
    qd = np.random.default_rng(3).normal(size=7) * qd_scale
    qd -= np.linalg.pinv(N) @ (N @ qd)  # moving along the table, not away from it
    tau = J_tool.T @ np.array([8.0, 0.0, -20.0])  # the push, as joint torques
    g = pin.computeGeneralizedGravity(model, data, GEN3_Q)
    fs = 0.5 * np.abs(g) + 0.3
    fr = vs.Friction(static=fs, kinetic=0.7 * fs)
    contacts = [
        vs.Contact(TOOL, normal=[0.0, 0.0, 1.0], mu=0.8),
        vs.Contact("spherical_wrist_2_link", normal=[0.0, 0.0, 1.0], mu=0.8),
    ]
    alpha = np.zeros((6, 3))
    alpha[3:, :] = np.eye(3)  # the tool's angular acceleration held at zero
    r = solver.solve(
        GEN3_Q, qd, alpha=alpha, beta=np.zeros(3), tau_ff=tau, friction=fr, contacts=contacts, time_step=dt
    )
    specs = [dict(frame=model.getFrameId(c.segment), point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
    prob = contact_problem(
        model, data, GEN3_Q, qd, tau, specs, friction=dict(static=fs, kinetic=0.7 * fs), time_step=dt
    )
    A = _task_rows(model, model.createData(), GEN3_Q, tool, alpha)
    assert r.contact_force[:, 2].sum() > 1.0  # the table carries
    if qd_scale == 0.0:
        assert _redundant(prob, A, r.qdd) and np.all(r.status == 1)  # held: the split is the rule's
        inst = solver.solve(GEN3_Q, qd, alpha=alpha, beta=np.zeros(3), tau_ff=tau, friction=fr, contacts=contacts)
        assert _rel(r.contact_force, inst.contact_force) <= RTOL  # at rest the step's problem is the instant's
        assert _rel(r.tau_command, inst.tau_command) <= RTOL
    _check(r, prob, A, f"dt {dt}, qd {qd_scale}")


def _free_motion(rng, rc, q, qd, tau, data):
    """(Pinocchio's q, joint friction 0.5 to 1.5 times each joint's load, the free motion M^-1 h) of
    a random chain's state, ``data`` left with its Jacobians and kinematics at (q, qd)."""
    n = rc.n_joints
    pq = pin_configuration(rc.model, q)
    h = tau - pin.rnea(rc.model, data, pq, qd, np.zeros(n))
    fs = np.abs(h) * rng.uniform(0.5, 1.5, size=n) + 0.05
    minv_h = np.linalg.solve(pin.crba(rc.model, data, pq), h)
    pin.computeJointJacobians(rc.model, data, pq)
    pin.forwardKinematics(rc.model, data, pq, qd, np.zeros(n))
    return pq, fs, minv_h


def _chain_case(rng, k, mu, moving):
    """A random 7-joint chain at rest or creeping (joints at 1e-3 rad/s: friction can stop them
    within the step), friction on every joint 0.5 to 1.5 times its load (the gravity and
    feed-forward torques), k supports on the last segments whose normals oppose the points' motion
    without them (so that they carry), a 2-D task on the tip."""
    n = 7
    rc = random_chain(rng, n, prismatic=False)
    q, qd = random_state(rng, rc, qd_scale=1e-3)
    if not moving:
        qd[:] = 0.0
    tau = rng.normal(size=n) * 3
    model = rc.model
    data = model.createData()
    pq, fs, minv_h = _free_motion(rng, rc, q, qd, tau, data)
    contacts = []
    for s in rng.choice(np.arange(n - 3, rc.n_segments), size=k, replace=False):
        point = rng.normal(size=3) * 0.1
        J, bias, v = point_jacobian(model, data, rc.tip_frames[s], point)
        a = J @ minv_h + bias
        normal = -(a + v) / np.linalg.norm(a + v) + 0.2 * rng.normal(size=3)
        contacts.append(vs.Contact(int(s), point=point, normal=normal / np.linalg.norm(normal), mu=mu))
    alpha = rng.normal(size=(6, 2))
    alpha /= np.linalg.norm(alpha, axis=0)
    return rc, q, qd, tau, fs, contacts, alpha, alpha[:3].T @ -G_EARTH


def _random_chain_step(seed):
    """Random chain case ``seed`` of the tests below, solved over its step: (result, problem, task rows)."""
    rng = np.random.default_rng(4200 + seed)
    k, mu, moving, dt = 2 + seed % 2, (0.8, 0.0, 0.5)[seed % 3], seed % 4 >= 2, (1e-3, 1e-2)[seed % 2]
    rc, q, qd, tau, fs, contacts, alpha, beta = _chain_case(rng, k, mu, moving)
    fr = vs.Friction(static=fs, kinetic=0.7 * fs)
    r = rc.solver().solve(q, qd, alpha=alpha, beta=beta, tau_ff=tau, friction=fr, contacts=contacts, time_step=dt)
    model = rc.model
    pq = pin_configuration(model, q)
    specs = [dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
    prob = contact_problem(
        model, model.createData(), pq, qd, tau, specs, friction=dict(static=fs, kinetic=0.7 * fs), time_step=dt
    )
    return r, prob, _task_rows(model, model.createData(), pq, rc.tip_frames[-1], alpha)


@pytest.mark.parametrize("seed", range(12))
def test_redundant_supports_on_random_chains(seed):
    """Two or three supports (with friction, or frictionless) on random chains with friction on
    every joint and a 2-D task, at rest or moving, dt 1 ms or 10 ms."""
    r, prob, A = _random_chain_step(seed)
    _check(r, prob, A, f"chain seed {seed}")


def test_some_random_chain_cases_are_redundant():
    """The cases above do exercise the rule: in several of them the impulses are not unique."""
    count = 0
    for seed in range(12):
        r, prob, A = _random_chain_step(seed)
        count += _redundant(prob, A, r.qdd)
    assert count >= 4, count


def _tree_supports(case, rng, q, qd, tau, k, mu):
    """Pinocchio's (q, qd, tau) of a tree case and k supports on random segments whose normals
    oppose their points' free motion (the free acceleration, plus qd / dt's part v), a little
    tilted."""
    model, names, n = case.model, list(case.tree.segment_names), case.n
    pq, pqd, ptau = case.pin_q(q), case.pin_v(qd), case.pin_v(tau)
    data = model.createData()
    minv_h = np.linalg.solve(pin.crba(model, data, pq), ptau - pin.rnea(model, data, pq, pqd, np.zeros(n)))
    pin.computeJointJacobians(model, data, pq)
    pin.forwardKinematics(model, data, pq, pqd, np.zeros(n))
    contacts = []
    for s in rng.choice(len(names), size=k, replace=False):
        point = rng.normal(size=3) * 0.05
        J, bias, v = point_jacobian(model, data, model.getFrameId(names[s]), point)
        d = J @ minv_h + bias + v
        normal = -d / max(np.linalg.norm(d), 1e-9) + 0.2 * rng.normal(size=3)
        contacts.append(vs.Contact(names[s], point=point, normal=normal / np.linalg.norm(normal), mu=mu))
    return pq, pqd, ptau, contacts


@pytest.mark.parametrize("name", ["baxter", "random_8"])
def test_redundant_supports_on_trees(name):
    """Three to five supports (frictionless and with friction) on a tree, friction on every
    joint, a 3-D angular task on one segment, at rest and moving."""
    from support.trees import robot

    case = robot(name)
    model = case.model
    names = list(case.tree.segment_names)
    n = case.n
    rng = np.random.default_rng([77, len(name)])
    for k, mu, qd_scale in ((3, 0.0, 0.0), (4, 0.6, 0.0), (5, 0.0, 0.2), (5, 0.6, 0.0)):
        q, qd = case.random_state(rng, qd_scale=max(qd_scale, 1e-3))
        qd *= qd_scale > 0.0
        tau = rng.normal(size=n) * 2
        fs = rng.uniform(0.2, 2.0, size=n)
        pq, pqd, ptau, contacts = _tree_supports(case, rng, q, qd, tau, k, mu)
        seg = names[int(rng.integers(len(names)))]
        alpha = np.zeros((6, 3))
        alpha[3:, :] = np.eye(3)
        fr = vs.Friction(static=fs, kinetic=0.7 * fs)
        dt = 1e-3
        r = case.solver().solve(
            q, qd, tau_ff=tau, friction=fr, contacts=contacts, constraints={seg: (alpha, np.zeros(3))}, time_step=dt
        )
        specs = [dict(frame=model.getFrameId(c.segment), point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
        fric = dict(static=case.pin_v(fs), kinetic=case.pin_v(0.7 * fs))
        prob = contact_problem(model, model.createData(), pq, pqd, ptau, specs, friction=fric, time_step=dt)
        A = _task_rows(model, model.createData(), pq, model.getFrameId(seg), alpha)
        what = f"{name}: {k} supports, mu {mu}, qd {qd_scale}"
        _check(r, prob, A, what, order=case.pin_v)


@pytest.mark.parametrize("m", [1, 3])
@pytest.mark.parametrize("qd_scale", [0.0, 0.3])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_redundant_task_with_friction_over_a_step(m, qd_scale, dt):
    """The Gen3 with friction on every joint and an m-D task on the tool (friction alone, no
    contacts): the sticking joints and the motors share the load by the least-command rule."""
    solver, model = _gen3()
    rng = np.random.default_rng([m, int(10 * qd_scale), int(1e3 * dt)])
    qd = rng.normal(size=7) * qd_scale
    g = pin.computeGeneralizedGravity(model, model.createData(), GEN3_Q)
    fs = 0.6 * np.abs(g) + 0.2
    fr = vs.Friction(static=fs, kinetic=0.7 * fs)
    alpha = np.zeros((6, m))
    alpha[np.arange(m) + 3, np.arange(m)] = 1.0  # the tool's angular acceleration, m axes
    r = solver.solve(GEN3_Q, qd, alpha=alpha, beta=np.zeros(m), friction=fr, time_step=dt)
    tau = np.zeros(7)
    prob = contact_problem(
        model, model.createData(), GEN3_Q, qd, tau, [], friction=dict(static=fs, kinetic=0.7 * fs), time_step=dt
    )
    A = _task_rows(model, model.createData(), GEN3_Q, model.getFrameId(TOOL), alpha)
    if qd_scale == 0.0:
        assert _redundant(prob, A, r.qdd)
    _check(r, prob, A, f"m {m}, qd {qd_scale}, dt {dt}")


@pytest.mark.parametrize("seed", [89, 127, 173])
def test_baxter_steps_that_found_no_impulses(seed):
    """Baxter with three supports with friction (mu 0.6), joints moving at up to 0.2 rad/s, joint
    friction, dt 1 ms: the step raised "no consistent contact forces" (NoContactSolution); such a
    velocity-level problem always has an answer. Now the impulses meet the step's conditions (each
    force in its admissible cone, each joint's torque within its bounds, against its end velocity)
    and the equation of motion. Lemke's pivoting ended on a ray there that exact arithmetic would
    not meet (ties of a degenerate problem decided by round-off); ContactStage::perturbedLcp
    breaks them."""
    from support.trees import robot

    case = robot("baxter")
    model, n, dt = case.model, case.n, 1e-3
    rng = np.random.default_rng([555, seed])
    q, qd = case.random_state(rng, qd_scale=0.2)
    tau = rng.normal(size=n) * 2
    fs = rng.uniform(0.2, 2.0, size=n)
    pq, pqd, ptau, contacts = _tree_supports(case, rng, q, qd, tau, 3, 0.6)
    fr = vs.Friction(static=fs, kinetic=0.7 * fs)
    r = case.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts, time_step=dt)
    specs = [dict(frame=model.getFrameId(c.segment), point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
    fric = dict(static=case.pin_v(fs), kinetic=case.pin_v(0.7 * fs))
    prob = contact_problem(model, model.createData(), pq, pqd, ptau, specs, friction=fric, time_step=dt)
    qdd, joint = case.pin_v(r.qdd), case.pin_v(r.friction_torque + r.limit_torque)
    gen = sum((c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)), joint)
    assert _rel(prob.H @ qdd - prob.h, gen) <= RTOL  # no motors: the environment alone
    assert r.contact_force[:, :].any()  # the supports do carry
    f = r.contact_force.copy()  # a leaving support's force is zero to round-off of the largest
    f[np.linalg.norm(f, axis=1) <= 1e-9 * np.abs(f).max()] = 0.0
    _admissible(prob, qdd, f, joint)


def _sliding_chain(seed, k=5, mu=0.6, dt=2e-3):
    """A random 6-joint chain moving at about 1 rad/s, no joint friction, k supports with friction
    on its segments whose normals oppose the points' motion (the randomized search's chains)."""
    rng = np.random.default_rng([2026, seed])
    rc = random_chain(rng, 6, prismatic=False)
    q, qd = random_state(rng, rc, qd_scale=1.0)
    tau = rng.normal(size=6) * 3
    model, data = rc.model, rc.model.createData()
    pq = pin_configuration(model, q)
    a = np.linalg.solve(pin.crba(model, data, pq), tau - pin.rnea(model, data, pq, qd, np.zeros(6)))
    pin.computeJointJacobians(model, data, pq)
    pin.forwardKinematics(model, data, pq, qd, np.zeros(6))
    contacts = []
    for s in rng.choice(rc.n_segments, size=k, replace=False):
        point = rng.normal(size=3) * 0.1
        J, bias, v = point_jacobian(model, data, rc.tip_frames[s], point)
        normal = -(J @ a * dt + v) / np.linalg.norm(J @ a * dt + v) + 0.2 * rng.normal(size=3)
        contacts.append(vs.Contact(int(s), point=point, normal=normal / np.linalg.norm(normal), mu=mu))
    return rc, q, qd, tau, contacts


def test_chain_seed_2070_slides_along_an_edge_normal():
    """Chain seed 2070 of the randomized search (5 supports, mu 0.6, about 1 rad/s, dt 2 ms): its
    impulses failed the admissibility check, support 2's force (771, -358, -1219) N lying inside
    the polygon edge between vertices 0 and 1 while the check wanted vertex 1 alone. The answer was
    right: that support slides (end velocity 7.6e-7 m/s) exactly along the edge's outward normal,
    where maximum dissipation allows any force on the edge, and the polygon's complementarity
    makes it so (two positive edge weights: d_0 . v+ = d_1 . v+); the two scores differ by 2e-14
    of the rows' scale, round-off, but the check took ties relative to the sliding speed itself
    (1e-9 |v_t+|), far below round-off of rows near 1e3. Ties are now the rows' round-off."""
    dt = 2e-3
    rc, q, qd, tau, contacts = _sliding_chain(2070)
    r = rc.solver().solve(q, qd, tau_ff=tau, contacts=contacts, time_step=dt)
    model = rc.model
    pq = pin_configuration(model, q)
    specs = [dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
    prob = contact_problem(model, model.createData(), pq, qd, tau, specs, time_step=dt)
    gen = sum((c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)), np.zeros(6))
    assert _rel(prob.H @ r.qdd - prob.h, gen) <= RTOL  # no motors, no joint friction
    _admissible(prob, r.qdd, r.contact_force, np.zeros(6))
    c, f = prob.contacts[2], r.contact_force[2]
    row = c.J @ r.qdd + c.bias
    wt = row - (c.normal @ row) * c.normal
    D = facet_directions(c.normal, c.facets)
    weights = nnls(np.array([c.normal + c.mu * d for d in D]).T, f)[0]
    assert np.count_nonzero(weights > 1e-6 * weights.max()) == 2  # inside an edge
    tied = np.flatnonzero(weights > 1e-6 * weights.max())
    scale = max(np.abs(c.J @ r.qdd).max(), np.abs(c.bias).max())  # the terms of the row (v / dt in bias)
    assert np.linalg.norm(wt) > 1e-7 * scale  # it slides
    assert abs((D[tied[0]] - D[tied[1]]) @ wt) <= 1e-12 * scale  # exactly along the edge's normal
    assert (D[tied[0]] @ wt) <= (D @ wt).min() + 1e-12 * scale  # the edge most opposed


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("dt", [0.0, 1e-3])
def test_least_contact_force_without_motor_columns(seed, dt):
    """No task and no force set-point (m == 0): every split of the load costs the motors nothing,
    and the least contact forces pick it (docs/contacts.md). Random chains at rest with friction
    on every joint and two or three supports, at the instant and over a step (the same problem at
    rest): before, the complementarity problem's own split stood (the programme was skipped)."""
    rng = np.random.default_rng(4300 + seed)
    rc, q, qd, tau, fs, contacts, _, _ = _chain_case(rng, 2 + seed % 2, 0.8, False)
    fr = vs.Friction(static=fs, kinetic=0.7 * fs)
    r = rc.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts, time_step=dt)
    model = rc.model
    pq = pin_configuration(model, q)
    specs = [dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
    fric = dict(static=fs, kinetic=0.7 * fs)
    prob = contact_problem(model, model.createData(), pq, qd, tau, specs, friction=fric, time_step=dt or None)
    A = np.zeros((0, rc.n_joints))
    assert r.tau_command.size == 0 or not r.tau_command.any()  # no motors
    _check(r, prob, A, f"m 0, seed {seed}, dt {dt}")


def test_some_cases_without_motor_columns_are_redundant():
    """The cases above do exercise the rule: in several of them the forces are not unique."""
    count = 0
    for seed in range(6):
        rng = np.random.default_rng(4300 + seed)
        rc, q, qd, tau, fs, contacts, _, _ = _chain_case(rng, 2 + seed % 2, 0.8, False)
        fr = vs.Friction(static=fs, kinetic=0.7 * fs)
        r = rc.solver().solve(q, qd, tau_ff=tau, friction=fr, contacts=contacts)
        model = rc.model
        pq = pin_configuration(model, q)
        specs = [dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu) for c in contacts]
        prob = contact_problem(model, model.createData(), pq, qd, tau, specs, friction=dict(static=fs))
        count += _redundant(prob, np.zeros((0, rc.n_joints)), r.qdd)
    assert count >= 3, count
