"""The singularity policies by value (issue 23): damped least squares and the truncated
pseudo-inverse against the dense oracle of tests/support/dense_oracle.py (Pinocchio's M, bias, frame
Jacobians and classical accelerations; numpy for the policy), at 1e-9 relative.

The policy (docs/algorithm.md, "The coupling matrix and singular tasks"): the coupling matrix
K = A H^-1 A^T of the Gauss formulation is inverted per eigenvalue, as lambda / (lambda^2 +
damping^2) with ``damping=``, else as 1 / lambda for eigenvalues above rcond * max(lambda_max,
kappa) and 0 below, kappa >= trace K a scale of the robot and task.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import G_EARTH, assert_close, random_alpha, random_chain, random_f_ext, random_state
from support.dense_oracle import dense_task

RTOL = 1e-9


def _problem(seed, n, tasks_spec, fixed_prob=0.0):
    """A random chain, state, torques and wrenches; tasks_spec(rng, rc) -> [(segment, alpha, beta)]."""
    rng = np.random.default_rng([seed, n, 2323])
    rc = random_chain(rng, n, fixed_prob=fixed_prob)
    q, qd = random_state(rng, rc)
    tau = rng.normal(size=n) * 3.0
    f_ext = random_f_ext(rng, rc)
    tasks = tasks_spec(rng, rc)
    dense = dense_task(
        rc.model, rc.tip_frames, q, qd, G_EARTH, tau, [(rc.tip_frames[s], a, b) for s, a, b in tasks], f_ext
    )
    return rc, q, qd, tau, f_ext, tasks, dense


def _solve(rc, q, qd, tau, f_ext, tasks, **kw):
    solver = vs.Solver(rc.chain, gravity=G_EARTH, **kw)
    constraints = {rc.chain.segment_names[s]: (a, b) for s, a, b in tasks}
    if len(constraints) != len(tasks):
        raise AssertionError("one entry per segment")  # pragma: no cover
    return solver.solve(q, qd, tau_ff=tau, f_ext=f_ext, constraints=constraints)


def _end_task(m):
    def spec(rng, rc):
        return [(rc.n_segments - 1, random_alpha(rng, m), rng.normal(size=m) * 3.0)]

    return spec


def _check_against(res, dense, nu, what):
    qdd, tau_cmd = dense.outputs(nu)
    assert_close(res.nu, nu, RTOL, f"{what}: nu")
    assert_close(res.qdd, qdd, RTOL, f"{what}: qdd")
    assert_close(res.tau_command, tau_cmd, RTOL, f"{what}: tau_command")


def _task_acc(rc, res, tasks):
    """alpha^T a of every task row from the solver's own link accelerations."""
    return np.concatenate([a.T @ res.link_acc[s + 1] for s, a, _ in tasks])


# ------------------------------------------------------------------------------------------------
# The oracle itself: with a well-conditioned task and nothing dropped it is pin.forwardDynamics
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(4))
def test_oracle_agrees_with_pinocchio_forward_dynamics(seed):
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, 6, _end_task(3))
    assert np.linalg.eigvalsh(dense.K).min() > 1e-6 * np.linalg.eigvalsh(dense.K).max()
    nu, rank = dense.truncated(0.0)
    assert rank == 3
    qdd, _ = dense.outputs(nu)
    data = rc.model.createData()
    tau_ext = dense.M @ dense.qdd_free - (tau - np.array(pin.rnea(rc.model, data, q, qd, np.zeros(rc.n_joints))))
    ddq = pin.forwardDynamics(rc.model, data, q, qd, tau + tau_ext, dense.A, dense.drift - dense.beta)
    assert_close(qdd, ddq, 1e-10, "oracle qdd vs pin.forwardDynamics")
    assert_close(nu, -np.array(data.lambda_c), 1e-10, "oracle nu vs -lambda")
    # the oracle's spatial drift agrees with Pinocchio's LWA spatial frame acceleration
    pin.forwardKinematics(rc.model, data, q, qd, qdd)
    pin.updateFramePlacements(rc.model, data)
    s, alpha, beta = tasks[0]
    acc = pin.getFrameAcceleration(rc.model, data, rc.tip_frames[s], pin.LOCAL_WORLD_ALIGNED).vector
    assert_close(alpha.T @ (acc + np.r_[-G_EARTH, 0, 0, 0]), beta, 1e-10, "oracle task met")


# ------------------------------------------------------------------------------------------------
# Damped least squares
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("rel", [3e-1, 1e-2, 3e-3])
@pytest.mark.parametrize("m", [1, 3, 6])
@pytest.mark.parametrize("seed", range(3))
def test_damped_end_segment_matches_dense_oracle(seed, m, rel):
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, max(m, 3) + seed, _end_task(m))
    lam = np.linalg.eigvalsh(dense.K)
    d = rel * lam.max()  # in K's units; far from 1, so damping and damping^2 differ
    res = _solve(rc, q, qd, tau, f_ext, tasks, damping=d)
    nu = dense.damped(d)
    _check_against(res, dense, nu, f"damping {d:.3g}")
    assert res.constraint_rank == m
    # the damped residual of the task is d^2 (K^2 + d^2)^-1 r, not zero
    residual = dense.r - dense.K @ nu
    assert_close(_task_acc(rc, res, tasks) - dense.beta, residual, RTOL, "damped task residual")
    # the comparison can see the damping: the exact solve is far away at this tolerance
    exact = np.linalg.solve(dense.K, dense.r)
    assert np.linalg.norm(exact - nu) > 1e3 * RTOL * max(np.linalg.norm(nu), 1.0)


def _segments_task(rng, rc):
    """Two or three constrained segments of a chain (the general, segment-wise path)."""
    idx = sorted(rng.choice(rc.n_segments, size=3, replace=False))
    return [(int(s), random_alpha(rng, k), rng.normal(size=k) * 3.0) for s, k in zip(idx, (1, 2, 2))]


@pytest.mark.parametrize("rel", [1e-1, 1e-3])
@pytest.mark.parametrize("seed", range(4))
def test_damped_segment_constraints_match_dense_oracle(seed, rel):
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, 7, _segments_task, fixed_prob=0.2)
    d = rel * np.linalg.eigvalsh(dense.K).max()
    res = _solve(rc, q, qd, tau, f_ext, tasks, damping=d)
    nu = dense.damped(d)
    _check_against(res, dense, nu, f"segments, damping {d:.3g}")
    assert_close(_task_acc(rc, res, tasks) - dense.beta, dense.r - dense.K @ nu, RTOL, "damped residual")


# Rank-deficient and conflicting tasks: (name, n joints, tasks_spec, rank of K).
def _duplicated(rng, rc):
    a, b = random_alpha(rng, 2), rng.normal(size=2)
    return [(rc.n_segments - 1, np.hstack([a, a[:, :1]]), np.r_[b, b[0]])]  # consistent: reachable


def _contradictory(rng, rc):
    a, b = random_alpha(rng, 2), rng.normal(size=2)
    return [(rc.n_segments - 1, np.hstack([a, a[:, :1]]), np.r_[b, b[0] + 0.8])]  # the same row, two set-points


def _too_many(rng, rc):
    return [(rc.n_segments - 1, random_alpha(rng, 6), rng.normal(size=6))]


def _conflicting(rng, rc):
    # both a middle segment and the tip fully constrained: 12 rows on 5 joints
    return [(2, np.eye(6), rng.normal(size=6)), (rc.n_segments - 1, np.eye(6), rng.normal(size=6))]


SINGULAR = [
    ("duplicated", 5, _duplicated, 2),
    ("contradictory", 5, _contradictory, 2),
    ("m_above_n", 3, _too_many, 3),
    ("conflicting", 5, _conflicting, 5),
]


def _gap(dense, rank):
    """The oracle's eigenvalues split cleanly into rank kept ones and round-off zeros."""
    lam = np.linalg.eigvalsh(dense.K)[::-1]
    assert lam[rank - 1] > 1e-6 * lam[0], lam
    if rank < len(lam):
        assert abs(lam[rank]) < 1e-13 * lam[0], lam
    return lam[0]


@pytest.mark.parametrize("name,n,spec,rank", SINGULAR, ids=[s[0] for s in SINGULAR])
@pytest.mark.parametrize("seed", range(3))
def test_damped_singular_tasks_match_dense_oracle(seed, name, n, spec, rank):
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, n, spec)
    lmax = _gap(dense, rank)
    for rel in (1e-1, 1e-2):
        d = rel * lmax
        res = _solve(rc, q, qd, tau, f_ext, tasks, damping=d)
        nu = dense.damped(d)
        _check_against(res, dense, nu, f"{name}, damping {d:.3g}")
        assert res.constraint_rank == rank
        assert_close(_task_acc(rc, res, tasks) - dense.beta, dense.r - dense.K @ nu, RTOL, "damped residual")


# ------------------------------------------------------------------------------------------------
# Truncated pseudo-inverse
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,n,spec,rank", SINGULAR, ids=[s[0] for s in SINGULAR])
@pytest.mark.parametrize("seed", range(3))
def test_truncated_singular_tasks_match_pseudo_inverse(seed, name, n, spec, rank):
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, n, spec)
    lmax = _gap(dense, rank)
    res = _solve(rc, q, qd, tau, f_ext, tasks)  # default rcond = 1e-12
    nu, r_oracle = dense.truncated(1e-9 * lmax)  # any cut inside the gap drops the same directions
    assert r_oracle == rank
    _check_against(res, dense, nu, f"{name}, truncated")
    assert res.constraint_rank == rank
    # least squares: the task residual e = alpha^T a - beta = r - K nu is orthogonal to range(K)
    e = _task_acc(rc, res, tasks) - dense.beta
    assert_close(e, dense.r - dense.K @ nu, RTOL, "truncated residual")
    assert np.linalg.norm(dense.K @ e) <= RTOL * lmax * max(np.linalg.norm(dense.r), 1.0)
    if name == "duplicated":  # consistent (reachable) task: met exactly
        assert_close(e, np.zeros_like(e), RTOL, "duplicated task met")
    if name == "contradictory":  # the two set-points of one row are missed by half their gap each
        assert_close(e, [0.4, 0.0, -0.4], RTOL, "contradictory rows split the difference")


def _parallel_task(theta):
    """Two unit columns at angle theta: K's small eigenvalue is about theta^2 / 2 of its trace."""

    def spec(rng, rc):
        a = random_alpha(rng, 2)
        u = a[:, 0]
        w = a[:, 1] - (a[:, 1] @ u) * u
        w /= np.linalg.norm(w)
        alpha = np.column_stack([u, np.cos(theta) * u + np.sin(theta) * w])
        return [(rc.n_segments - 1, alpha, rng.normal(size=2))]

    return spec


@pytest.mark.parametrize("seed", range(3))
def test_rcond_drops_exactly_the_weak_direction(seed):
    """The weak eigenvalue lam_w of K is dropped iff lam_w <= rcond * max(lam_max, kappa), kappa >= trace K."""
    rc, q, qd, tau, f_ext, tasks, dense = _problem(seed, 6, _parallel_task(3e-2))
    lam = np.linalg.eigvalsh(dense.K)
    lam_w, lam_max = lam
    assert 1e-6 < lam_w / lam_max < 1e-2, lam

    def solve(rcond):
        return _solve(rc, q, qd, tau, f_ext, tasks, rcond=rcond)

    # above: rcond * lam_max already exceeds lam_w, whatever kappa is
    res = solve(1.01 * lam_w / lam_max)
    assert res.constraint_rank == 1
    assert res.smallest_singular_value == pytest.approx(lam_w, rel=1e-7)
    nu, _ = dense.truncated(0.5 * (lam_w + lam_max))
    _check_against(res, dense, nu, "weak direction dropped")
    # the threshold: bisection in log(rcond) for the largest rcond that keeps both directions
    lo, hi = 1e-6 * lam_w / lam_max, 1.01 * lam_w / lam_max
    assert solve(lo).constraint_rank == 2
    for _ in range(48):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if solve(mid).constraint_rank == 2 else (lo, mid)
    kappa = lam_w / hi  # the scale the solver used: rcond* = lam_w / max(lam_max, kappa)
    assert hi / lo < 1 + 1e-10
    assert kappa >= np.trace(dense.K) * (1 - 1e-9), (kappa, np.trace(dense.K))
    # below the threshold: both kept, the exact inverse; above it: the truncated one
    res = solve(0.5 * lo)
    assert res.constraint_rank == 2
    _check_against(res, dense, np.linalg.solve(dense.K, dense.r), "weak direction kept")
    assert_close(_task_acc(rc, res, tasks), dense.beta, RTOL, "task met when kept")
    res = solve(2.0 * hi)
    assert res.constraint_rank == 1
    _check_against(res, dense, nu, "weak direction dropped above the threshold")
    # dropping it leaves a residual only along the weak eigenvector of K (least squares)
    e = _task_acc(rc, res, tasks) - dense.beta
    v_w = np.linalg.eigh(dense.K)[1][:, 0]
    assert np.linalg.norm(e) > 1e-6
    assert_close(e, v_w * (v_w @ dense.r), RTOL, "residual along the weak direction")
