"""Solves on kinematic trees against Pinocchio reading the same URDF trees.

Robots: Baxter (example-robot-data: head, two 7-joint arms, two-finger grippers, 19 joints) and
Talos (``talos_reduced``: its 32 joints below ``base_link``, the floating base not modelled, i.e.
``base_link`` held fixed), and random trees written as URDF text (``tests/support/trees.py``).

Joint orders differ (ours: the tree's joint order, Pinocchio: its own depth-first order); every
comparison maps by joint name. Every expected value comes from Pinocchio:

* m = 0: ``qdd = pin.aba`` (also with wrenches on links as Pinocchio's ``fext``);
* constraints on one or several frames of any branches: ``pin.forwardDynamics`` with the stacked
  ``alpha_i^T J_i`` (LOCAL_WORLD_ALIGNED frame Jacobians) and
  ``gamma_i = alpha_i^T (a0_i + [-g; 0]) - beta_i`` (a0_i the LWA frame acceleration at qdd = 0);
  ``nu = -lambda``;
* ``pin.aba(tau_ff + tau_command)`` gives ``qdd`` back; each task holds in Pinocchio's frame
  accelerations of the result;
* response columns against central differences of solves (qdd is affine in tau_ff).
"""

from __future__ import annotations

import pickle

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import well_conditioned_task
from support.friction_oracles import (
    STICK,
    FrictionProblem,
    OracleInfeasible,
    enumeration_oracle,
    pinocchio_problem,
    scipy_oracle,
)
from support.urdf_robots import LWA, G, assert_rel
from support.trees import ROBOTS, robot
from vereshchagin.robots import gen3_urdf

UP = np.r_[-G, 0.0, 0.0, 0.0]  # the base's upward acceleration that stands for gravity


def _frame_terms(case, data, pq, pv, frame):
    """LWA Jacobian (6, n ours) and acceleration at qdd = 0 (6,) of a frame, from Pinocchio."""
    fid = case.model.getFrameId(frame)
    assert fid < len(case.model.frames), frame
    J = pin.computeFrameJacobian(case.model, data, pq, fid, LWA)
    pin.forwardKinematics(case.model, data, pq, pv, np.zeros(case.model.nv))
    pin.updateFramePlacements(case.model, data)
    a0 = pin.getFrameAcceleration(case.model, data, fid, LWA).vector
    return J, a0


def _frame_acc(case, data, pq, pv, pa, frame):
    pin.forwardKinematics(case.model, data, pq, pv, pa)
    pin.updateFramePlacements(case.model, data)
    return pin.getFrameAcceleration(case.model, data, case.model.getFrameId(frame), LWA).vector + UP


# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_unconstrained_tree_matches_aba(name):
    case = robot(name)
    rng = np.random.default_rng([21, len(name)])
    data = case.model.createData()
    for _ in range(6):
        solver = case.solver()
        q, qd = case.random_state(rng)
        tau = rng.normal(size=case.n) * 5.0
        res = solver.solve(q, qd, tau_ff=tau)
        expected = pin.aba(case.model, data, case.pin_q(q), case.pin_v(qd), case.pin_v(tau))
        assert_rel(res.qdd, case.ours(expected), f"{name}: qdd vs pin.aba", 1e-9)
        assert res.nu.shape == (0,)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_link_wrench_matches_aba_with_fext(name):
    """A wrench on a named link (base axes, moment about the link origin) as Pinocchio's fext."""
    case = robot(name)
    rng = np.random.default_rng([23, len(name)])
    data = case.model.createData()
    solver = case.solver()
    frame = next(iter(case.tasks.values()))[0]
    fid = case.model.getFrameId(frame)
    for _ in range(4):
        q, qd = case.random_state(rng)
        w = rng.normal(size=6) * 10.0
        res = solver.solve(q, qd, f_ext={frame: w})
        pq = case.pin_q(q)
        pin.framesForwardKinematics(case.model, data, pq)
        at_link = pin.SE3(np.eye(3), data.oMf[fid].translation)  # world axes, link origin
        world = at_link.act(pin.Force(w[:3], w[3:]))
        fext = [pin.Force.Zero() for _ in range(case.model.njoints)]
        joint = case.model.frames[fid].parentJoint
        fext[joint] = data.oMi[joint].actInv(world)
        expected = pin.aba(case.model, data, pq, case.pin_v(qd), np.zeros(case.model.nv), fext)
        assert_rel(res.qdd, case.ours(expected), f"{name}: qdd with a wrench on {frame}", 1e-9)


def _task(case, rng, data, pq, pv, frames):
    """Random unit constraint columns on each frame, their stacked rows A and gamma's a0 part."""
    cols, rows, a0s = {}, [], []
    for frame in frames:
        J, a0 = _frame_terms(case, data, pq, pv, frame)
        reach = min(6, int(np.count_nonzero(np.abs(J).sum(axis=0))))  # joints on the frame's path
        m = int(rng.integers(1, reach + 1)) if len(frames) > 1 else reach
        alpha = rng.normal(size=(6, m))
        alpha /= np.linalg.norm(alpha, axis=0)
        cols[frame] = alpha
        rows.append(alpha.T @ J)
        a0s.append(alpha.T @ (a0 + UP))
    return cols, np.vstack(rows), np.concatenate(a0s)


@pytest.mark.parametrize(
    "name, task",
    [(n, t) for n in sorted(ROBOTS) for t in robot(n).tasks],
)
def test_constraints_on_branches_match_forward_dynamics(name, task):
    case = robot(name)
    frames = case.tasks[task]
    rng = np.random.default_rng([29, len(name), len(task)])
    data = case.model.createData()
    done = 0
    for _ in range(60):
        solver = case.solver()
        q, qd = case.random_state(rng)
        pq, pv = case.pin_q(q), case.pin_v(qd)
        cols, A_pin, a0 = _task(case, rng, data, pq, pv, frames)
        Minv = np.array(pin.computeMinverse(case.model, data, pq))
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        if not well_conditioned_task(A_pin, Minv):
            continue
        beta = {f: rng.normal(size=cols[f].shape[1]) * 3.0 for f in frames}
        tau = rng.normal(size=case.n) * 5.0
        res = solver.solve(q, qd, tau_ff=tau, constraints={f: (cols[f], beta[f]) for f in frames})

        gamma = a0 - np.concatenate([beta[f] for f in frames])
        ddq = pin.forwardDynamics(case.model, data, pq, pv, case.pin_v(tau), A_pin, gamma)
        lam = np.array(data.lambda_c).reshape(-1)
        assert_rel(res.qdd, case.ours(ddq), f"{name} {task}: qdd vs pin.forwardDynamics", 1e-9)
        assert_rel(res.nu, -lam, f"{name} {task}: nu vs -lambda", 1e-9)
        assert res.constraint_rank == A_pin.shape[0]
        ev = np.linalg.eigvalsh(A_pin @ Minv @ A_pin.T)  # K = A H^-1 A^T
        assert res.smallest_singular_value == pytest.approx(ev.min(), rel=1e-9, abs=1e-12 * ev.max())
        # command torques: -sum_i J_i^T alpha_i nu_i, and replayed through ABA
        assert_rel(case.pin_v(res.tau_command), -A_pin.T @ res.nu, "tau_command = -A^T nu", 1e-9)
        replay = pin.aba(case.model, data, pq, pv, case.pin_v(tau + res.tau_command))
        assert_rel(case.ours(replay), res.qdd, "aba(tau_ff + tau_command) vs qdd", 1e-9)
        # every task holds in Pinocchio's frame accelerations of our qdd
        for f in frames:
            acc = _frame_acc(case, data, pq, pv, case.pin_v(res.qdd), f)
            assert_rel(cols[f].T @ acc, beta[f], f"{name} {task}: alpha^T a({f}) = beta", 1e-9)
        done += 1
        if done == 3:
            break
    assert done == 3, "too few well-conditioned samples"


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_response_columns_on_trees_are_the_derivative_of_solve(name):
    case = robot(name)
    frames = list(case.tasks.values())[1]  # two frames on two branches
    rng = np.random.default_rng([31, len(name)])
    data = case.model.createData()
    solver = case.solver()
    q, qd = case.random_state(rng)
    cols, _, _ = _task(case, rng, data, case.pin_q(q), case.pin_v(qd), frames)
    cons = {f: (cols[f], rng.normal(size=cols[f].shape[1])) for f in frames}
    tau = rng.normal(size=case.n)
    solver.solve(q, qd, tau_ff=tau, constraints=cons)
    joints = [0, case.n // 2, case.n - 1]
    dqdd, dtau = solver.response_columns(joints)
    for c, j in enumerate(joints):
        e = np.zeros(case.n)
        e[j] = 1.0
        plus = solver.solve(q, qd, tau_ff=tau + e, constraints=cons)
        minus = solver.solve(q, qd, tau_ff=tau - e, constraints=cons)
        # qdd and tau_command are affine in tau_ff: the central difference is exact up to the two
        # solves' round-off (measured worst 1.8e-13 relative)
        assert_rel(dqdd[:, c], (plus.qdd - minus.qdd) / 2.0, f"dqdd/dtau_{j}", 1e-10)
        assert_rel(dtau[:, c], (plus.tau_command - minus.tau_command) / 2.0, f"dtau_cmd/dtau_{j}", 1e-10)


# ------------------------------------------------------------------------------------------------
# Static friction on trees: the max-min against stick/slip enumeration and the scipy primal of the
# same problem built from Pinocchio's H, ABA and frame Jacobians (tests/support/friction_oracles.py)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["baxter", "talos", "random_3"])
def test_friction_on_trees_matches_enumeration(name):
    case = robot(name)
    frames = list(case.tasks.values())[1]  # two frames on two branches
    rng = np.random.default_rng([37, len(name)])
    data = case.model.createData()
    solver = case.solver()
    checked, statuses = 0, set()
    for _ in range(40):
        q, qd = case.random_state(rng)
        resting = np.zeros(case.n, bool)
        resting[rng.choice(case.n, size=min(6, case.n - 1), replace=False)] = True  # across branches
        qd[resting] = 0.0
        pq, pv = case.pin_q(q), case.pin_v(qd)
        cols, A_pin, a0 = _task(case, rng, data, pq, pv, frames)
        beta = {f: rng.normal(size=cols[f].shape[1]) for f in frames}
        tau = rng.normal(size=case.n) * 3.0
        static = rng.uniform(0.2, 4.0, case.n)
        kinetic = static * rng.uniform(0.3, 1.0, case.n)
        prob = pinocchio_problem(
            case.model, data, pq, pv, tau_ff=case.pin_v(tau), static=case.pin_v(static), kinetic=case.pin_v(kinetic)
        )
        prob = FrictionProblem(
            prob.H,
            prob.qdd_free,
            A_pin,
            np.concatenate([beta[f] for f in frames]) - a0,
            prob.resting,
            prob.static,
            prob.kinetic_torque,
        )
        Minv = np.linalg.inv(prob.H)
        if not well_conditioned_task(A_pin, Minv):
            continue
        try:
            oracle = enumeration_oracle(prob)
        except OracleInfeasible:
            continue
        res = solver.solve(
            q,
            qd,
            tau_ff=tau,
            constraints={f: (cols[f], beta[f]) for f in frames},
            friction=vs.Friction(static=static, kinetic=kinetic),
        )
        R = prob.rest_idx
        slipping = np.abs(oracle.qdd[R])[oracle.status[R] != STICK]
        if slipping.size and slipping.min() < 1e-6 * prob.accel_scale(oracle.qdd):
            continue  # near a stick/slip boundary: the status is a matter of round-off
        assert_rel(res.qdd, case.ours(oracle.qdd), f"{name}: qdd vs enumeration", 1e-9)
        primal = scipy_oracle(prob)  # SLSQP on the primal, polished and certified
        assert_rel(res.qdd, case.ours(primal.qdd), f"{name}: qdd vs scipy primal", 1e-9)
        np.testing.assert_array_equal(res.status, case.ours(oracle.status))
        assert_rel(res.gauss_value, oracle.objective, "Gauss value", 1e-9)
        # the motion is the frictionless solve with the friction torques as feed-forward
        plain = solver.solve(
            q, qd, tau_ff=tau + res.friction_torque, constraints={f: (cols[f], beta[f]) for f in frames}
        )
        assert_rel(plain.qdd, res.qdd, "qdd = solve(tau_ff + friction_torque)", 1e-9)
        statuses.update(int(s) for s in res.status[resting])
        checked += 1
        if checked == 4:
            break
    assert checked == 4, "too few usable samples"
    assert STICK in statuses, "no sticking joint in the samples: the test would not see the max-min"


# ------------------------------------------------------------------------------------------------
# The Python face on trees
# ------------------------------------------------------------------------------------------------
def test_a_chain_loaded_as_a_tree_solves_as_the_chain():
    urdf = gen3_urdf(False)  # a serial URDF (the gripper's fingers would branch)
    chain, tree = vs.Chain.from_urdf(urdf), vs.Tree.from_urdf(urdf)
    assert list(tree.joint_names) == list(chain.joint_names)
    assert list(tree.segment_names) == list(chain.segment_names)
    a, b = vs.Solver(chain), vs.Solver(tree)
    rng = np.random.default_rng(41)
    tip = chain.segment_names[-1]
    for m in range(7):
        q, qd, tau = rng.uniform(-2, 2, 7), rng.uniform(-1, 1, 7), rng.normal(size=7)
        alpha, beta = rng.normal(size=(6, m)), rng.normal(size=m)
        fr = vs.Friction(static=np.full(7, 0.5)) if m % 2 else None
        qd[::3] = 0.0
        ra = a.solve(q, qd, alpha, beta, tau_ff=tau, friction=fr)
        rb = b.solve(q, qd, tau_ff=tau, constraints={tip: (alpha, beta)} if m else None, friction=fr)
        for field in ("qdd", "tau_command", "nu", "link_acc"):
            np.testing.assert_allclose(getattr(rb, field), getattr(ra, field), rtol=1e-12, atol=1e-12, err_msg=field)


def test_tree_batch_rows_equal_solve_and_solver_pickles():
    case = robot("baxter")
    solver = case.solver()
    rng = np.random.default_rng(43)
    B = 9
    Q = rng.uniform(-1, 1, (B, case.n))
    QD = rng.uniform(-1, 1, (B, case.n))
    alpha = rng.normal(size=(B, 6, 3))
    beta = rng.normal(size=(B, 3))
    cons = {"left_gripper": (alpha, beta), "right_lower_elbow": (np.eye(6)[:, :1], [9.81])}
    batch = solver.solve_batch(Q, QD, constraints=cons, threads=2)
    clone = pickle.loads(pickle.dumps(solver))
    for k in range(B):
        row = {"left_gripper": (alpha[k], beta[k]), "right_lower_elbow": cons["right_lower_elbow"]}
        single = solver.solve(Q[k], QD[k], constraints=row)
        np.testing.assert_array_equal(batch.qdd[k], single.qdd)
        np.testing.assert_array_equal(batch.nu[k], single.nu)
        np.testing.assert_array_equal(clone.solve(Q[k], QD[k], constraints=row).qdd, single.qdd)
    assert isinstance(clone.tree, vs.Tree) and isinstance(solver.model, vs.Tree)


def test_tree_solver_errors_name_the_remedy():
    solver = robot("baxter").solver()
    n = solver.n_joints
    with pytest.raises(vs.SolverError, match="constraints="):
        solver.solve(np.zeros(n), np.zeros(n), np.eye(6), np.zeros(6))
    with pytest.raises(vs.SolverError, match="solver.tree"):
        solver.chain  # noqa: B018
    with pytest.raises(vs.SolverError, match="no_such_link"):
        solver.solve(np.zeros(n), np.zeros(n), constraints={"no_such_link": (np.eye(6), np.zeros(6))})
    with pytest.raises(vs.SolverError, match="base"):  # the base cannot be constrained
        solver.solve(np.zeros(n), np.zeros(n), constraints={"base": (np.eye(6), np.zeros(6))})
    with pytest.raises(TypeError, match="Chain or vereshchagin.Tree"):
        vs.Solver("baxter")
