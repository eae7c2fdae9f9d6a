"""The solver against Pinocchio 4.1 on random chains (see tests/support/chains.py for how both models are built).

Oracle relations used (all expected values come from Pinocchio or dense numpy linear algebra):

* m = 0: qdd = pin.aba(q, v, tau_ff, fext), fext our f_ext converted to joint-local wrenches.
* m > 0: qdd = pin.forwardDynamics(q, v, tau, J, gamma) whose constraint is J ddq + gamma = 0
  (checked in test_oracle_forward_dynamics_convention). With J_lwa the LOCAL_WORLD_ALIGNED Jacobian
  of the last tip frame, our constraint alpha^T (J_lwa qdd + drift + [-g; 0]) = beta gives
  J = alpha^T J_lwa and gamma = alpha^T (drift + [-g; 0]) - beta, drift = Pinocchio's LWA frame
  acceleration at qdd = 0 (the LOCAL spatial acceleration rotated to world axes). Our link_acc rows
  are Pinocchio's LWA frame accelerations plus [-g; 0] (base acceleration -g).
* Pinocchio's M ddq + b = tau + J^T lambda, so our nu (constraint wrench -alpha nu on the last
  segment, i.e. generalised force -A^T nu) equals -lambda.
"""

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import (
    G_EARTH,
    SegmentSpec,
    assert_close,
    build,
    fext_generalized,
    fext_to_pinocchio,
    frame_jacobian,
    homogeneous,
    random_alpha,
    random_chain,
    random_f_ext,
    random_state,
    rot_axis,
    symmetric,
)

RTOL = 1e-9
LWA = pin.LOCAL_WORLD_ALIGNED


def _gravity(rng, kind):
    if kind == "zero":
        return np.zeros(3)
    if kind == "earth":
        return G_EARTH.copy()
    return rng.normal(size=3) * 5.0


def _motion6(g):
    return np.concatenate([-np.asarray(g), np.zeros(3)])


def _mass_matrix_inverse(rc, data, q):
    return symmetric(np.reshape(pin.computeMinverse(rc.model, data, q), (rc.n_joints, rc.n_joints)))


def _frame_accelerations(rc, data, q, qd, qdd, g):
    """Pinocchio's LWA frame accelerations of every tip, plus the base acceleration [-g; 0]."""
    pin.forwardKinematics(rc.model, data, q, qd, qdd)
    pin.updateFramePlacements(rc.model, data)
    return np.array([pin.getFrameAcceleration(rc.model, data, f, LWA).vector for f in rc.tip_frames]) + _motion6(g)


def _constrained_case(seed, m, fixed_prob=0.0, gravity="random"):
    """A random chain/state/task with n >= m and a well-conditioned coupling matrix K."""
    rng = np.random.default_rng([seed, m, 12345])
    for _ in range(200):
        n = int(rng.integers(m, 11))
        rc = random_chain(rng, n, fixed_prob=fixed_prob)
        q, qd = random_state(rng, rc)
        alpha = random_alpha(rng, m)
        data = rc.data()
        J = frame_jacobian(rc, data, q)
        A = alpha.T @ J
        Minv = _mass_matrix_inverse(rc, data, q)
        ev = np.linalg.eigvalsh(A @ Minv @ A.T)
        if ev.min() > 1e-5 * ev.max():
            g = _gravity(rng, gravity)
            beta = rng.normal(size=m) * 3.0
            f_ext = random_f_ext(rng, rc)
            tau = rng.normal(size=n) * 3.0
            return dict(
                rc=rc,
                q=q,
                qd=qd,
                alpha=alpha,
                beta=beta,
                f_ext=f_ext,
                tau=tau,
                g=g,
                J=J,
                A=A,
                Minv=Minv,
                K=A @ Minv @ A.T,
            )
    raise AssertionError("no well-conditioned sample found")  # pragma: no cover


def _pin_constrained(case):
    """(ddq, lambda) from pin.forwardDynamics for the case's task."""
    rc, q, qd, g = case["rc"], case["q"], case["qd"], case["g"]
    rc.model.gravity = pin.Motion(np.concatenate([g, np.zeros(3)]))
    data = rc.data()
    pin.forwardKinematics(rc.model, data, q, qd, np.zeros(rc.n_joints))
    pin.updateFramePlacements(rc.model, data)
    drift = pin.getFrameAcceleration(rc.model, data, rc.tip_frames[-1], LWA).vector
    gamma = case["alpha"].T @ (drift + _motion6(g)) - case["beta"]
    tau_total = case["tau"] + fext_generalized(rc, data, q, case["f_ext"])
    ddq = np.array(pin.forwardDynamics(rc.model, data, q, qd, tau_total, case["A"], gamma)).reshape(-1)
    return ddq, np.array(data.lambda_c).reshape(-1), gamma, tau_total


# ------------------------------------------------------------------------------------------------
# Checks of the oracle itself (if these fail, the other failures say nothing about the solver)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(20))
def test_oracle_model_matches_kdl_kinematics(seed):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, int(rng.integers(1, 11)), fixed_prob=0.3)
    data = rc.data()
    for _ in range(3):
        q, _ = random_state(rng, rc)
        pin.forwardKinematics(rc.model, data, q)
        pin.updateFramePlacements(rc.model, data)
        for fid, T in zip(rc.tip_frames, rc.tip_poses(q)):
            np.testing.assert_allclose(data.oMf[fid].homogeneous, T, atol=1e-12)


@pytest.mark.parametrize("seed", range(10))
def test_oracle_fext_conversions_agree(seed):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, int(rng.integers(1, 11)), fixed_prob=0.3)
    data = rc.data()
    q, qd = random_state(rng, rc)
    f = random_f_ext(rng, rc)
    tau = rng.normal(size=rc.n_joints)
    a1 = pin.aba(rc.model, data, q, qd, tau, fext_to_pinocchio(rc, data, q, f))
    a2 = pin.aba(rc.model, data, q, qd, tau + fext_generalized(rc, data, q, f))
    assert_close(a1, a2, 1e-11, "aba with local fext vs with J^T f_ext")
    # and f_ext really matters
    a0 = pin.aba(rc.model, data, q, qd, tau)
    assert np.linalg.norm(a0 - a1) > 1e-3


@pytest.mark.parametrize("seed", range(10))
def test_oracle_minverse_includes_armature(seed):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, int(rng.integers(1, 11)))
    data = rc.data()
    q, qd = random_state(rng, rc)
    M = np.array(pin.crba(rc.model, data, q)).reshape(rc.n_joints, rc.n_joints)
    M = np.triu(M) + np.triu(M, 1).T
    Minv = _mass_matrix_inverse(rc, data, q)
    assert_close(Minv @ M, np.eye(rc.n_joints), 1e-10, "Minv M")
    tau = rng.normal(size=rc.n_joints)
    nle = pin.nonLinearEffects(rc.model, data, q, qd)
    assert_close(Minv @ (tau - nle), pin.aba(rc.model, data, q, qd, tau), 1e-10, "Minv (tau - b) vs aba")
    arm = np.array(rc.model.armature)
    rc.model.armature = np.zeros(rc.n_joints)
    M0 = np.array(pin.crba(rc.model, rc.data(), q)).reshape(rc.n_joints, rc.n_joints)
    rc.model.armature = arm
    np.testing.assert_allclose(np.diag(M) - np.diag(M0), arm, atol=1e-12)


@pytest.mark.parametrize("seed", range(10))
def test_oracle_forward_dynamics_convention(seed):
    """pin.forwardDynamics(q, v, tau, J, gamma): J ddq + gamma = 0 and M ddq + b = tau + J^T lambda."""
    case = _constrained_case(seed, 1 + seed % 6)
    ddq, lam, gamma, tau_total = _pin_constrained(case)
    rc, q, qd = case["rc"], case["q"], case["qd"]
    assert_close(case["A"] @ ddq, -gamma, 1e-9, "J ddq + gamma")
    data = rc.data()
    M = np.array(pin.crba(rc.model, data, q)).reshape(rc.n_joints, rc.n_joints)
    M = np.triu(M) + np.triu(M, 1).T
    b = pin.nonLinearEffects(rc.model, data, q, qd)
    assert_close(M @ ddq + b, tau_total + case["A"].T @ lam, 1e-9, "M ddq + b = tau + J^T lambda")


# ------------------------------------------------------------------------------------------------
# The KDL segment convention, by hand
# ------------------------------------------------------------------------------------------------
def test_revolute_origin_is_a_point_on_the_axis():
    """Joint.revolute(z, origin=(d, 0, 0)) with tip = identity: the body (at the root origin at
    q = 0) swings about the line through (d, 0, 0): inertia about the axis = Izz + m d^2."""
    d, mass, izz = 0.3, 2.0, 0.05
    chain = vs.Chain()
    chain.add_segment(
        "s", vs.Joint.revolute([0, 0, 1], [d, 0, 0]), tip=np.eye(4), mass=mass, inertia=np.diag([0.1, 0.12, izz])
    )
    solver = vs.Solver(chain, gravity=[0, 0, 0])
    for q in (0.0, 0.7, -2.0):
        res = solver.solve([q], [0.0], tau_ff=[1.5])
        assert res.qdd[0] == pytest.approx(1.5 / (izz + mass * d * d), rel=1e-12)
    # At q = pi/2 the tip origin (at the root origin for q = 0) has swung to (d, -d, 0). With
    # qd = w and qdd = 0 its classical acceleration is w^2 (p_axis - tip); link_acc holds the
    # body-fixed spatial acceleration, whose linear part is a_classical - w x v.
    w = np.array([0.0, 0.0, 2.0])
    res = solver.solve([np.pi / 2], [2.0])
    axis_point, tip = np.array([d, 0.0, 0.0]), np.array([d, -d, 0.0])
    v = np.cross(w, tip - axis_point)
    a_classical = 4.0 * (axis_point - tip)
    np.testing.assert_allclose(res.qdd, [0.0], atol=1e-15)
    np.testing.assert_allclose(res.link_acc[1], np.r_[a_classical - np.cross(w, v), 0, 0, 0], atol=1e-12)


def test_prismatic_origin_has_no_effect():
    rng = np.random.default_rng(99)
    rc = random_chain(rng, 5, prismatic=False)
    segs = list(rc.segments)
    base = SegmentSpec(
        "prismatic",
        np.array([0.6, 0.0, 0.8]),
        np.zeros(3),
        homogeneous(rot_axis(np.array([1.0, 0, 0]), 0.4), [0.1, 0.2, 0.3]),
        1.5,
        np.array([0.1, 0.0, 0.0]),
        np.diag([0.1, 0.2, 0.25]),
        0.1,
    )
    shifted = SegmentSpec(**{**base.__dict__, "origin": np.array([0.5, -0.4, 0.3])})
    a = build(segs[:2] + [base] + segs[2:])
    b = build(segs[:2] + [shifted] + segs[2:])
    q, qd = random_state(rng, a)
    ra = a.solver().solve(q, qd, tau_ff=np.ones(a.n_joints))
    rb = b.solver().solve(q, qd, tau_ff=np.ones(b.n_joints))
    np.testing.assert_allclose(ra.qdd, rb.qdd, rtol=1e-12, atol=1e-12)


# ------------------------------------------------------------------------------------------------
# m = 0: plain forward dynamics
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("gravity", ["zero", "earth", "random"])
@pytest.mark.parametrize("seed", range(25))
def test_unconstrained_matches_aba(seed, gravity):
    rng = np.random.default_rng([seed, 1])
    rc = random_chain(rng, int(rng.integers(1, 11)), fixed_prob=0.25 if seed % 2 else 0.0)
    g = _gravity(rng, gravity)
    solver = rc.solver(g)
    data = rc.data()
    for k in range(3):
        q, qd = random_state(rng, rc)
        f = random_f_ext(rng, rc) if k > 0 else None
        tau = rng.normal(size=rc.n_joints) * 3.0 if k != 1 else None
        res = solver.solve(q, qd, f_ext=f, tau_ff=tau)
        fext = fext_to_pinocchio(rc, data, q, f if f is not None else np.zeros((rc.n_segments, 6)))
        expected = pin.aba(rc.model, data, q, qd, tau if tau is not None else np.zeros(rc.n_joints), fext)
        assert_close(res.qdd, expected, RTOL, "qdd vs pin.aba")
        assert_close(res.link_acc[1:], _frame_accelerations(rc, data, q, qd, res.qdd, g), RTOL, "link_acc")
        np.testing.assert_array_equal(res.link_acc[0], _motion6(g))
        assert res.nu.shape == (0,)
        assert res.constraint_rank == 0
        np.testing.assert_array_equal(res.tau_command, np.zeros(rc.n_joints))


@pytest.mark.parametrize("seed", range(5))
def test_unconstrained_with_empty_alpha_is_plain_forward_dynamics(seed):
    rng = np.random.default_rng([seed, 2])
    rc = random_chain(rng, int(rng.integers(1, 11)))
    solver = rc.solver()
    q, qd = random_state(rng, rc)
    a = solver.solve(q, qd)
    b = solver.solve(q, qd, np.zeros((6, 0)), np.zeros(0))
    np.testing.assert_array_equal(a.qdd, b.qdd)
    # an all-zero constraint is no constraint either
    c = solver.solve(q, qd, np.zeros((6, 2)), np.zeros(2))
    assert_close(c.qdd, a.qdd, 1e-12, "zero alpha")
    assert c.constraint_rank == 0


# ------------------------------------------------------------------------------------------------
# m = 1..6: constrained dynamics
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("m", range(1, 7))
@pytest.mark.parametrize("seed", range(12))
def test_constrained_matches_forward_dynamics(seed, m):
    case = _constrained_case(
        seed, m, fixed_prob=0.25 if seed % 3 == 0 else 0.0, gravity=["zero", "earth", "random"][seed % 3]
    )
    rc, q, qd, g = case["rc"], case["q"], case["qd"], case["g"]
    solver = rc.solver(g)
    res = solver.solve(q, qd, case["alpha"], case["beta"], f_ext=case["f_ext"], tau_ff=case["tau"])
    ddq, lam, _, _ = _pin_constrained(case)
    assert_close(res.qdd, ddq, RTOL, "qdd vs pin.forwardDynamics")
    assert_close(res.nu, -lam, RTOL, "nu vs -lambda")
    assert res.constraint_rank == m
    ev = np.linalg.eigvalsh(case["K"])
    assert res.smallest_singular_value == pytest.approx(ev.min(), rel=1e-7, abs=1e-9 * ev.max())
    # link accelerations: Pinocchio's LWA frame accelerations + base acceleration
    acc = _frame_accelerations(rc, rc.data(), q, qd, res.qdd, g)
    assert_close(res.link_acc[1:], acc, RTOL, "link_acc")
    np.testing.assert_array_equal(res.link_acc[0], _motion6(g))
    # the task is met
    assert_close(case["alpha"].T @ res.link_acc[-1], case["beta"], RTOL, "alpha^T a_N = beta")


@pytest.mark.parametrize("m", [0, 1, 3, 6])
@pytest.mark.parametrize("seed", range(8))
def test_tau_command_reproduces_qdd(seed, m):
    if m == 0:
        rng = np.random.default_rng([seed, 3])
        rc = random_chain(rng, int(rng.integers(1, 11)))
        q, qd = random_state(rng, rc)
        case = dict(
            rc=rc,
            q=q,
            qd=qd,
            alpha=None,
            beta=None,
            f_ext=random_f_ext(rng, rc),
            tau=rng.normal(size=rc.n_joints),
            g=G_EARTH,
        )
    else:
        case = _constrained_case(seed + 100, m, fixed_prob=0.2, gravity="earth")
    rc, q, qd = case["rc"], case["q"], case["qd"]
    res = rc.solver(case["g"]).solve(q, qd, case["alpha"], case["beta"], f_ext=case["f_ext"], tau_ff=case["tau"])
    data = rc.data()
    fext = fext_to_pinocchio(rc, data, q, case["f_ext"])
    replay = pin.aba(rc.model, data, q, qd, case["tau"] + res.tau_command, fext)
    assert_close(replay, res.qdd, RTOL, "aba(tau_ff + tau_command) vs qdd")
    # tau_command = -J^T alpha nu, J the base-axes Jacobian of the last tip
    if m:
        J = frame_jacobian(rc, data, q)
        assert_close(res.tau_command, -J.T @ case["alpha"] @ res.nu, RTOL, "tau_command = -J^T alpha nu")
        # and it is a real correction: without it, aba gives something else
        free = pin.aba(rc.model, data, q, qd, case["tau"], fext)
        assert np.linalg.norm(free - res.qdd) > 1e-6


# ------------------------------------------------------------------------------------------------
# response_columns: the constrained inverse inertia G
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("m", [0, 1, 2, 4, 6])
@pytest.mark.parametrize("seed", range(8))
def test_response_columns_dense(seed, m):
    if m == 0:
        rng = np.random.default_rng([seed, 4])
        rc = random_chain(rng, int(rng.integers(1, 11)), fixed_prob=0.2)
        q, qd = random_state(rng, rc)
        data = rc.data()
        case = dict(
            rc=rc,
            q=q,
            qd=qd,
            alpha=None,
            beta=None,
            f_ext=None,
            tau=rng.normal(size=rc.n_joints),
            g=G_EARTH,
            A=np.zeros((0, rc.n_joints)),
            Minv=_mass_matrix_inverse(rc, data, q),
        )
    else:
        case = _constrained_case(seed + 200, m, fixed_prob=0.2)
    rc, q, qd, n = case["rc"], case["q"], case["qd"], case["rc"].n_joints
    solver = rc.solver(case["g"])
    res = solver.solve(q, qd, case["alpha"], case["beta"], f_ext=case["f_ext"], tau_ff=case["tau"])
    A, Minv = case["A"], case["Minv"]
    K = A @ Minv @ A.T
    Kp = np.linalg.pinv(K) if m else np.zeros((0, 0))
    G = Minv - Minv @ A.T @ Kp @ A @ Minv
    dnu = Kp @ A @ Minv  # d nu / d tau_ff
    dtau = -A.T @ dnu

    rng = np.random.default_rng([seed, m, 5])
    joints = rng.permutation(n)[: int(rng.integers(1, n + 1))]
    joints = np.concatenate([joints, joints[:1]])  # a repeated index is allowed
    dqdd, dtau_cmd = solver.response_columns(joints)
    assert dqdd.shape == dtau_cmd.shape == (n, len(joints))
    assert_close(dqdd, G[:, joints], RTOL, "dqdd vs dense G")
    assert_close(dtau_cmd, dtau[:, joints], RTOL, "dtau_command vs -A^T K^+ A Minv")
    full, _ = solver.response_columns(list(range(n)))
    assert_close(full, full.T, 1e-10, "G symmetric")
    # One to four columns (a chain's own-frame path, the friction step's usual request).
    for k in range(1, 5):
        few = rng.integers(0, n, size=k)
        dqdd_few, dtau_few = solver.response_columns(few)
        assert_close(dqdd_few, G[:, few], RTOL, f"dqdd vs dense G, {k} columns")
        assert_close(dtau_few, dtau[:, few], RTOL, f"dtau_command vs dense, {k} columns")

    # Affine: a second solve with tau_ff + e_j differs by exactly the columns.
    for c, j in enumerate(joints[:3]):
        tau2 = case["tau"].copy()
        tau2[j] += 1.0
        res2 = solver.solve(q, qd, case["alpha"], case["beta"], f_ext=case["f_ext"], tau_ff=tau2)
        assert_close(res2.qdd - res.qdd, dqdd[:, c], 1e-8, "finite difference of qdd")
        assert_close(res2.tau_command - res.tau_command, dtau_cmd[:, c], 1e-8, "finite difference of tau_command")
