"""Acceleration constraints on several segments (Shakhimardanov's extension) against Pinocchio 4.1.

Oracle: ``pin.forwardDynamics(q, v, tau, A, gamma)`` with the stacked rows of every constrained
segment, ``A = [alpha_i^T J_i]`` (J_i the LOCAL_WORLD_ALIGNED Jacobian of segment i's tip link
frame) and ``gamma = [alpha_i^T (a0_i + [-g; 0]) - beta_i]`` (a0_i the frame's LWA acceleration at
qdd = 0); ``nu = -lambda`` in the same row order. Also: ``pin.aba(tau_ff + tau_command)`` replays
``qdd``; ``tau_command = -sum J_i^T alpha_i nu_i``; every constraint is met in Pinocchio's frame
accelerations; the static-friction max-min with mid-chain constraints against the scipy primal
oracle and the stick/slip enumeration (tests/support/friction_oracles.py).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import well_conditioned_task
from support.dense_oracle import dense_task
from support.friction_oracles import FrictionProblem, enumeration_oracle, scipy_oracle
from support.friction_checks import check_against_oracles
from support.urdf_robots import BUILDERS, G, LWA, minv, with_rotors, assert_rel

GRAV = np.r_[-G, 0.0, 0.0, 0.0]  # the base's acceleration [-g; 0] that beta includes
RTOL_EXACT = 1e-9  # exact algorithm vs Pinocchio (CONTRIBUTING.md); assert_rel's default is 1e-8
# Two- and three-segment sets per robot, each with an elbow-plus-tool case first.
SEGMENT_SETS = {
    "panda": [
        ("panda_link4", "panda_hand"),
        ("panda_link2", "panda_link5"),
        ("panda_link3", "panda_link5", "panda_hand"),
    ],
    "gen3_gripper": [
        ("forearm_link", "end_effector_link"),
        ("half_arm_1_link", "spherical_wrist_1_link"),
        ("half_arm_2_link", "forearm_link", "end_effector_link"),
    ],
    "gen3_bare": [
        ("forearm_link", "end_effector_link"),
        ("shoulder_link", "spherical_wrist_2_link", "end_effector_link"),
    ],
}


def _segment_rows(r, data, pq, qd, names, alphas):
    """Stacked A = [alpha_i^T J_i] and drifts alpha_i^T (a0_i + [-g; 0]), Jacobians per segment."""
    pin.forwardKinematics(r.model, data, pq, qd, np.zeros(r.model.nv))
    pin.updateFramePlacements(r.model, data)
    fids = [r.model.getFrameId(name) for name in names]
    drift = [
        alpha.T @ (pin.getFrameAcceleration(r.model, data, fid, LWA).vector + GRAV) for fid, alpha in zip(fids, alphas)
    ]
    jacs = [pin.computeFrameJacobian(r.model, data, pq, fid, LWA) for fid in fids]
    rows = [alpha.T @ J for J, alpha in zip(jacs, alphas)]
    return np.vstack(rows), np.concatenate(drift), jacs


def _random_task(rng, r, names):
    """alpha_i (unit columns), at most (joints up to the segment - columns already placed) each."""
    seg_index = [r.chain.segment_names.index(n) for n in names]
    order = np.argsort(seg_index)
    alphas = [None] * len(names)
    used = 0
    for k in order:
        cap = min(6, seg_index[k] + 1 - used)
        m = int(rng.integers(1, cap + 1)) if cap >= 1 else 0
        a = rng.normal(size=(6, max(m, 1)))[:, :m]
        alphas[k] = a / np.linalg.norm(a, axis=0) if m else a
        used += m
    return alphas


@pytest.mark.parametrize("robot,which", [(rb, k) for rb in sorted(SEGMENT_SETS) for k in range(len(SEGMENT_SETS[rb]))])
def test_segments_match_pinocchio_forward_dynamics(robot, which):
    names = SEGMENT_SETS[robot][which]
    r = BUILDERS[robot]()
    rng = np.random.default_rng([robot.count("_"), len(robot), which, 31])
    data = r.model.createData()
    done = 0
    for _ in range(60):
        solver = with_rotors(r, rng)
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        alphas = _random_task(rng, r, names)
        A, drift, jacs = _segment_rows(r, data, pq, qd, names, alphas)
        if A.shape[0] == 0:
            continue
        if not well_conditioned_task(A, minv(r.model, data, pq)):
            continue
        betas = [rng.normal(size=a.shape[1]) * 3.0 for a in alphas]
        tau = rng.normal(size=r.chain.n_joints) * 5.0
        res = solver.solve(q, qd, tau_ff=tau, constraints={n: (a, b) for n, a, b in zip(names, alphas, betas)})

        ddq = pin.forwardDynamics(r.model, data, pq, qd, tau, A, drift - np.concatenate(betas))
        lam = np.array(data.lambda_c).reshape(-1)
        what = f"{robot} {names}"
        assert_rel(res.qdd, ddq, f"{what}: qdd vs pin.forwardDynamics", RTOL_EXACT)
        assert_rel(res.nu, -lam, f"{what}: nu vs -lambda", RTOL_EXACT)
        assert res.constraint_rank == A.shape[0]
        assert_rel(pin.aba(r.model, data, pq, qd, tau + res.tau_command), res.qdd, f"{what}: aba replay", RTOL_EXACT)
        assert_rel(res.tau_command, -A.T @ res.nu, f"{what}: tau_command = -sum J^T alpha nu", RTOL_EXACT)
        # every constraint holds in Pinocchio's frame accelerations at the solved qdd
        pin.forwardKinematics(r.model, data, pq, qd, res.qdd)
        pin.updateFramePlacements(r.model, data)
        for n, a, b in zip(names, alphas, betas):
            acc = pin.getFrameAcceleration(r.model, data, r.model.getFrameId(n), LWA).vector + GRAV
            assert_rel(a.T @ acc, b, f"{what}: alpha^T a = beta on {n}", RTOL_EXACT)
        done += 1
        if done == 4:
            break
    assert done == 4, "too few well-conditioned samples"


@pytest.mark.parametrize("robot", ["panda", "gen3_gripper"])
def test_last_segment_only_equals_end_segment_solve(robot):
    r = BUILDERS[robot]()
    rng = np.random.default_rng(5)
    solver = with_rotors(r, rng)
    last = r.chain.segment_names[-1]
    for m in range(1, 7):
        q, qd = r.random_state(rng)
        alpha = rng.normal(size=(6, m))
        beta = rng.normal(size=m)
        ref = solver.solve(q, qd, alpha, beta)
        for key in (last, -1, len(r.chain.segment_names) - 1):
            got = solver.solve(q, qd, constraints={key: (alpha, beta)})
            for field in ("qdd", "tau_command", "nu", "link_acc"):
                np.testing.assert_array_equal(getattr(got, field), getattr(ref, field), err_msg=f"{field} key {key!r}")
        # split between alpha= and constraints= on the last segment: the same motion
        if m >= 2:
            got = solver.solve(q, qd, alpha[:, :1], beta[:1], constraints={last: (alpha[:, 1:], beta[1:])})
            assert_rel(got.qdd, ref.qdd, "split end-segment columns", RTOL_EXACT)
            assert_rel(got.nu, ref.nu, "split end-segment nu", RTOL_EXACT)


def test_end_alpha_combines_with_segment_constraints():
    """alpha=/beta= on the last segment plus constraints= elsewhere: nu is end columns first."""
    r = BUILDERS["gen3_gripper"]()
    rng = np.random.default_rng(8)
    solver = with_rotors(r, rng)
    q, qd = r.random_state(rng)
    a_tool, b_tool = np.eye(6)[:, :3], np.array([0.1, -0.2, 9.81])
    a_elbow, b_elbow = np.eye(6)[:, 2:3], np.array([9.81])
    both = solver.solve(q, qd, a_tool, b_tool, constraints={"forearm_link": (a_elbow, b_elbow)})
    dict_only = solver.solve(
        q, qd, constraints={"end_effector_link": (a_tool, b_tool), "forearm_link": (a_elbow, b_elbow)}
    )
    np.testing.assert_allclose(both.qdd, dict_only.qdd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(both.nu, dict_only.nu, rtol=0, atol=1e-12)
    assert both.segment_nu.keys() == {"forearm_link"}
    np.testing.assert_array_equal(both.segment_nu["forearm_link"], both.nu[3:])
    assert list(dict_only.segment_nu) == ["end_effector_link", "forearm_link"]
    np.testing.assert_array_equal(dict_only.segment_nu["end_effector_link"], dict_only.nu[:3])
    assert solver.solve(q, qd, a_tool, b_tool).segment_nu is None  # no constraints=, no split
    reordered = solver.solve(
        q, qd, constraints={"forearm_link": (a_elbow, b_elbow), "end_effector_link": (a_tool, b_tool)}
    )
    np.testing.assert_allclose(reordered.nu, np.r_[dict_only.nu[3:], dict_only.nu[:3]], rtol=0, atol=1e-12)
    # the elbow constraint changes the motion (it is not ignored)
    tool_only = solver.solve(q, qd, a_tool, b_tool)
    assert np.linalg.norm(tool_only.qdd - both.qdd) > 1e-3


def test_conflicting_segment_constraints_are_finite_with_rank():
    """Elbow and tool both fully constrained on a 7-joint arm: 12 rows, rank 7, finite outputs."""
    r = BUILDERS["gen3_gripper"]()
    rng = np.random.default_rng(3)
    for damping in (None, 1e-6):
        solver = vs.Solver(r.chain, damping=damping)
        q, qd = r.random_state(rng)
        cons = {
            "forearm_link": (np.eye(6), rng.normal(size=6)),
            "end_effector_link": (np.eye(6), rng.normal(size=6)),
        }
        res = solver.solve(q, qd, constraints=cons)
        for field in ("qdd", "tau_command", "nu", "link_acc"):
            assert np.all(np.isfinite(getattr(res, field))), field
        assert res.nu.shape == (12,)
        if damping is None:
            assert res.constraint_rank == 7
        # by value (issue 23), against the dense oracle of tests/support/dense_oracle.py
        r.model.armature = np.zeros(r.model.nv)
        tasks = [(r.model.getFrameId(n), a, b) for n, (a, b) in cons.items()]
        dense = dense_task(r.model, [], r.pin_q(q), qd, G, np.zeros(r.model.nv), tasks)
        lam = np.linalg.eigvalsh(dense.K)
        assert lam[4] < 1e-13 * lam[-1] < 1e-6 * lam[5], lam  # rank 7 with a clean gap
        if damping is None:
            nu = dense.truncated(1e-9 * lam[-1])[0]
            assert_rel(res.nu, nu, "conflicting: nu = K^+ r (minimum norm)", RTOL_EXACT)
        else:
            nu = dense.damped(damping)  # its null-space part is round-off / damping^2: not compared
        qdd, tau_cmd = dense.outputs(nu)
        assert_rel(res.qdd, qdd, "conflicting: qdd", RTOL_EXACT)
        assert_rel(res.tau_command, tau_cmd, "conflicting: tau_command", RTOL_EXACT)
        # least squares: the residual of the 12 rows is orthogonal to range(K)
        e = dense.task_acc(res.qdd) - dense.beta  # Pinocchio's frame accelerations at the solver's qdd
        assert np.linalg.norm(dense.K @ e) <= 1e-9 * lam[-1] * max(np.linalg.norm(dense.r), 1.0)


def test_bad_constraints_raise():
    r = BUILDERS["gen3_bare"]()
    solver = vs.Solver(r.chain)
    q = np.zeros(7)
    ok = (np.eye(6)[:, :1], np.zeros(1))
    with pytest.raises(vs.SolverError, match="no_such_link|segment"):
        solver.solve(q, q, constraints={"no_such_link": ok})
    with pytest.raises(vs.SolverError, match="out of range"):
        solver.solve(q, q, constraints={7: ok})
    with pytest.raises(vs.SolverError, match="pair"):
        solver.solve(q, q, constraints={"forearm_link": np.eye(6)})
    with pytest.raises(vs.SolverError, match="shape"):
        solver.solve(q, q, constraints={"forearm_link": (np.eye(5), np.zeros(5))})
    with pytest.raises(vs.SolverError, match="beta"):
        solver.solve(q, q, constraints={"forearm_link": (np.eye(6)[:, :2], np.zeros(3))})
    with pytest.raises(vs.SolverError, match="NaN|finite"):
        solver.solve(q, q, constraints={"forearm_link": (np.full((6, 1), np.nan), np.zeros(1))})
    with pytest.raises(vs.SolverError, match="same frame"):
        solver.solve(q, q, constraints={"forearm_link": ok, 3: ok})
    with pytest.raises(vs.SolverError, match="dict"):
        solver.solve(q, q, constraints=[("forearm_link", ok)])
    with pytest.raises(vs.SolverError, match="more than 6"):
        solver.solve(q, q, np.eye(6)[:, :4], np.zeros(4), constraints={-1: (np.eye(6)[:, :3], np.zeros(3))})


@pytest.mark.parametrize("seed", range(8))
def test_friction_with_mid_chain_constraints_vs_oracles(seed):
    """All joints at rest, friction, an elbow (+ tool) constraint: the max-min vs scipy/enumeration."""
    r = BUILDERS["gen3_gripper" if seed % 2 else "panda"]()
    names = SEGMENT_SETS[r.name][0] if seed % 4 < 2 else SEGMENT_SETS[r.name][0][:1]
    rng = np.random.default_rng([seed, 404])
    data = r.model.createData()
    for _ in range(50):
        solver = with_rotors(r, rng)
        q, _ = r.random_state(rng)
        qd = np.zeros(r.chain.n_joints)
        pq = r.pin_q(q)
        alphas = _random_task(rng, r, names)
        alphas = [a[:, :2] for a in alphas]
        A, drift, _ = _segment_rows(r, data, pq, qd, names, alphas)
        if A.shape[0] == 0:
            continue
        if not well_conditioned_task(A, minv(r.model, data, pq)):
            continue
        betas = [rng.normal(size=a.shape[1]) for a in alphas]
        tau = rng.normal(size=r.chain.n_joints) * 2.0
        static = rng.uniform(0.0, 3.0, r.chain.n_joints)
        res = solver.solve(
            q,
            qd,
            tau_ff=tau,
            friction=vs.Friction(static=static),
            constraints={n: (a, b) for n, a, b in zip(names, alphas, betas)},
        )
        H = np.array(pin.crba(r.model, data, pq))
        H = np.triu(H) + np.triu(H, 1).T
        qdd_free = np.array(pin.aba(r.model, data, pq, qd, tau))
        prob = FrictionProblem(
            H,
            qdd_free,
            A,
            np.concatenate(betas) - drift,
            np.ones(r.chain.n_joints, bool),
            static,
            extra=dict(tau_ff=tau),
        )
        oracles = {"scipy": scipy_oracle(prob), "enumeration": enumeration_oracle(prob)}
        check_against_oracles(
            res,
            prob,
            lambda a, pq=pq, qd=qd: pin.rnea(r.model, data, pq, qd, a),
            oracles=oracles,
            what=f"{r.name} {names} seed {seed}",
        )
        return
    raise AssertionError("no well-conditioned sample found")
