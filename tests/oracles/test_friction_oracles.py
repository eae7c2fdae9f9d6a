"""Static joint friction (Vereshchagin's max-min, docs/friction.md) against
independent oracles (tests/support/friction_oracles.py; none of them calls our solver):

(a) SLSQP on the primal  min Z0(qdd) + sum_{resting j} f_j |qdd_j|  s.t.  A qdd = b, polished to
    the exact solution of its stick/slip pattern and certified optimal by bounded least squares;
(b) exhaustive enumeration of the 3^k stick/slip patterns of the k resting joints (exact
    null-space solves), plus the exact tie-break of section 4 (smallest ||tau_command||);
(c) MuJoCo's ``frictionloss`` with the noslip post-processor, for tasks without alpha at rest.

H, qdd_free, A and b come from Pinocchio (crba with armature, aba, the LWA tip Jacobian and frame
acceleration drift, as in tests/oracles/test_pinocchio_oracle.py). Besides agreeing with the oracles, every
result is checked for what makes it optimal on its own: the equation of motion through pin.rnea
(tau_ff + tau_command + friction_torque = rnea(q, qd, qdd, f_ext)), the task, tau_command in the
range of -J^T alpha, and stick/slip complementarity (these are the KKT conditions of the convex
problem, so together they certify qdd without any oracle).

Status convention assumed (friction-maxmin.md sec. 3 and the API note): a resting joint is 1
(stick) iff qdd_j = 0, also when its friction is at the bound |friction_j| = f_j (the holding case
of sec. 4 against 14.7 Nm); 2 / 3 iff it slips with qdd_j > 0 / < 0.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import (
    pin_configuration,
    G_EARTH,
    build,
    planar_rot_z_links,
    fext_generalized,
    fext_to_pinocchio,
    random_alpha,
    random_chain,
    well_conditioned_task,
)
from support.friction_checks import (
    LWA,
    both_oracles,
    check_against_oracles,
    check_chain_case,
    friction_arg,
    hold_beta,
    nontrivial_tie,
    random_chain_case,
    random_velocities,
    rel,
    solve_chain_case,
    task_target,
)
from support.urdf_robots import panda
from support.friction_oracles import (
    MOVING,
    SLIP_NEG,
    SLIP_POS,
    STICK,
    enumeration_oracle,
    mujoco_qacc,
    null_space,
    pinocchio_problem,
    random_friction,
    random_problem,
    scipy_oracle,
    tie_break_scipy,
)


# ------------------------------------------------------------------------------------------------
# The 1-DOF arm of Vukcevic 2018, ch. 6: mass 1, length 1, COM 0.5, joint-axis inertia 2.25, revolute about z
# ------------------------------------------------------------------------------------------------
def arm_1dof():
    return build(planar_rot_z_links(1, np.diag([1.0, 1.0, 2.0]), 0.0))


def _arm_problem(rc, gravity, tau_ff=0.0, f_tip=None, alpha=None, beta=None, f=10.0):
    rc.model.gravity = pin.Motion(np.r_[gravity, 0.0, 0.0, 0.0])
    data = rc.data()
    q, qd = np.zeros(1), np.zeros(1)
    f_ext = np.zeros((1, 6)) if f_tip is None else np.array([[0.0, f_tip, 0.0, 0.0, 0.0, 0.0]])
    prob = pinocchio_problem(
        rc.model,
        data,
        q,
        qd,
        tau_ff=np.array([tau_ff]),
        fext_tau=fext_generalized(rc, data, q, f_ext),
        static=[f],
        tip_frame=rc.tip_frames[-1],
        alpha=alpha,
        beta=beta,
    )
    return prob, f_ext


def _e(k, m=1):
    a = np.zeros((6, m))
    a[k, 0] = 1.0
    return a


# (gravity, tau_ff, tip force (N, along y at q = 0), alpha, beta, qdd, friction, tau_command, status)
REPORT_CASES = {
    "scenario1_force": (np.zeros(3), 0.0, -5.0, None, None, 0.0, 5.0, 0.0, STICK),
    "scenario1_torque": (np.zeros(3), -5.0, None, None, None, 0.0, 5.0, 0.0, STICK),
    "scenario2_force": (np.zeros(3), 0.0, -11.0, None, None, -1.0 / 2.25, 10.0, 0.0, SLIP_NEG),
    "scenario2_torque": (np.zeros(3), -11.0, None, None, None, -1.0 / 2.25, 10.0, 0.0, SLIP_NEG),
    # Fig. 5.5: task fixes the angular acceleration to 5 rad/s^2 (angular z, or the tangential tip
    # direction: at q = 0 the tip's linear acceleration is qdd * y, length 1)
    "constrained_angular": (np.zeros(3), 0.0, None, _e(5), [5.0], 5.0, -10.0, 21.25, SLIP_POS),
    "constrained_tangential": (np.zeros(3), 0.0, None, _e(1), [5.0], 5.0, -10.0, 21.25, SLIP_POS),
    # Sec. 4: held still by the task against gravity in the swing plane (torque -4.9 / -14.7 Nm at q = 0)
    "hold_4.9_angular": (np.array([0.0, -9.8, 0.0]), 0.0, None, _e(5), [0.0], 0.0, 4.9, 0.0, STICK),
    "hold_14.7_angular": (np.array([0.0, -29.4, 0.0]), 0.0, None, _e(5), [0.0], 0.0, 10.0, 4.7, STICK),
    # tangential: beta = alpha^T a_N with a_N = [-g; 0] (base acceleration) when held still
    "hold_4.9_tangential": (np.array([0.0, -9.8, 0.0]), 0.0, None, _e(1), [9.8], 0.0, 4.9, 0.0, STICK),
    "hold_14.7_tangential": (np.array([0.0, -29.4, 0.0]), 0.0, None, _e(1), [29.4], 0.0, 10.0, 4.7, STICK),
}


def _report_expected_gauss(case):
    g, tau, ftip, alpha, beta, qdd, fr, tc, st = REPORT_CASES[case]
    rc = arm_1dof()
    prob, _ = _arm_problem(rc, g, tau, ftip, alpha, beta)
    return prob, prob.objective(np.array([qdd]))


@pytest.mark.parametrize("case", sorted(REPORT_CASES))
def test_oracles_reproduce_report_000(case):
    """The oracles themselves reproduce the report's numbers (guards their sign conventions)."""
    g, tau, ftip, alpha, beta, qdd, fr, tc, st = REPORT_CASES[case]
    rc = arm_1dof()
    prob, _ = _arm_problem(rc, g, tau, ftip, alpha, beta)
    assert prob.H[0, 0] == pytest.approx(2.25, rel=1e-14)
    for o in both_oracles(prob).values():
        assert o.qdd[0] == pytest.approx(qdd, abs=1e-12)
        assert o.friction_torque[0] == pytest.approx(fr, abs=1e-12)
        assert o.tau_command[0] == pytest.approx(tc, abs=1e-12)
        assert o.status[0] == st
    if alpha is None:  # MuJoCo agrees on the unconstrained ones
        qacc, _, _ = mujoco_qacc(rc.segments, g, np.zeros(1), [tau + (ftip or 0.0)], [10.0])
        assert qacc[0] == pytest.approx(qdd, abs=1e-12)


@pytest.mark.parametrize("case", sorted(REPORT_CASES))
def test_report_000_numbers(case):
    g, tau, ftip, alpha, beta, qdd, fr, tc, st = REPORT_CASES[case]
    rc = arm_1dof()
    prob, f_ext = _arm_problem(rc, g, tau, ftip, alpha, beta)
    solver = vs.Solver(rc.chain, gravity=g)
    res = solver.solve(
        [0.0],
        [0.0],
        alpha=alpha,
        beta=beta,
        f_ext=f_ext if ftip is not None else None,
        tau_ff=[tau],
        friction=friction_arg([10.0]),
    )
    np.testing.assert_allclose(res.qdd, [qdd], rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.friction_torque, [fr], rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.tau_command, [tc], rtol=0, atol=1e-12)
    assert list(res.status) == [st]
    assert res.gauss_value == pytest.approx(prob.objective(np.array([qdd])), rel=1e-12, abs=1e-12)
    data = rc.data()
    fext = fext_to_pinocchio(rc, data, np.zeros(1), f_ext)
    check_against_oracles(
        res,
        prob,
        lambda a: pin.rnea(rc.model, data, np.zeros(1), np.zeros(1), a, fext),
        oracles=both_oracles(prob),
        what=case,
    )


def test_report_000_net_torque_and_gauss_values():
    """Sec. 5 by hand: net torque 0 / -1 Nm; Z0 + f|qdd| = 5.556, 26.667, 78.125."""
    expected = {
        "scenario1_force": 0.5 * 2.25 * (5 / 2.25) ** 2,
        "scenario2_force": 0.5 * 2.25 * (10 / 2.25) ** 2 + 10 / 2.25,
        "constrained_angular": 0.5 * 2.25 * 25 + 50.0,
    }
    for case, value in expected.items():
        prob, gauss = _report_expected_gauss(case)
        assert gauss == pytest.approx(value, rel=1e-14)
        assert enumeration_oracle(prob).objective == pytest.approx(value, rel=1e-12)


# ------------------------------------------------------------------------------------------------
# The oracles against each other (these pass without the feature)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(60))
def test_oracle_scipy_matches_enumeration_synthetic(seed):
    rng = np.random.default_rng([seed, 71])
    n = int(rng.integers(1, 8))
    m = int(rng.integers(0, min(n, 3) + 1))
    prob = random_problem(
        rng, n, m, resting_fraction=[1.0, 0.6][seed % 2], friction=["mixed", "moderate", "zero", "large"][seed % 4]
    )
    b = enumeration_oracle(prob)
    a = scipy_oracle(prob)
    s = prob.accel_scale(b.qdd)
    assert rel(a.qdd, b.qdd, s) <= 1e-10
    assert abs(a.objective - b.objective) <= 1e-10 * prob.objective_scale(b.qdd)
    np.testing.assert_array_equal(a.status, b.status)
    assert rel(a.friction_torque, b.friction_torque, prob.torque_scale(b.qdd)) <= 1e-9
    # (a.info["polish_shift"]: the raw SLSQP point is typically 1e-9 off, but up to 0.1 (relative)
    # when some f_j is 1e4 times the other terms; the certified polish is what counts)
    # optimality of the enumeration's qdd along random feasible directions
    N = null_space(prob.A)
    for _ in range(5):
        d = N @ rng.normal(size=N.shape[1]) if N.shape[1] else np.zeros(n)
        for h in (1e-3, 1e-6):
            assert prob.objective(b.qdd + h * d) >= b.objective - 1e-12 * prob.objective_scale(b.qdd)


@pytest.mark.parametrize("seed", range(12))
def test_oracle_tie_break_exact_vs_slsqp(seed):
    """Exact tie-break (active-set enumeration) vs SLSQP on the same QP; problems where the
    multipliers are not unique (all joints resting and a task, k + m > n)."""
    rng = np.random.default_rng([seed, 72])
    n = int(rng.integers(2, 7))
    m = int(rng.integers(1, n + 1))
    prob = random_problem(rng, n, m, resting_fraction=1.0, friction="moderate")
    b = enumeration_oracle(prob)
    tau = tie_break_scipy(prob, b.qdd)
    t = prob.torque_scale(b.qdd)
    assert np.linalg.norm(b.tau_command) <= np.linalg.norm(tau) + 1e-9 * t  # exact is never worse
    assert rel(b.tau_command, tau, t) <= 1e-6  # SLSQP's accuracy


@pytest.mark.parametrize("seed", range(10))
def test_oracle_problem_matches_pin_forward_dynamics(seed):
    """With zero friction the oracle problem is Pinocchio's constrained forward dynamics."""
    rng = np.random.default_rng([seed, 73])
    case = random_chain_case(rng, int(rng.integers(2, 8)), int(rng.integers(1, 4)), rest="mixed", friction="zero")
    rc, prob = case["rc"], case["prob"]
    data = rc.data()
    q, qd = case["q"], case["qd"]
    pin.forwardKinematics(rc.model, data, q, qd, np.zeros(rc.n_joints))
    pin.updateFramePlacements(rc.model, data)
    drift = pin.getFrameAcceleration(rc.model, data, rc.tip_frames[-1], LWA).vector
    gamma = case["alpha"].T @ (drift + np.r_[-case["g"], 0, 0, 0]) - case["beta"]
    tau = case["tau"] + fext_generalized(rc, data, q, case["f_ext"])
    ddq = pin.forwardDynamics(rc.model, data, q, qd, tau, prob.A, gamma)
    o = enumeration_oracle(prob)
    assert rel(o.qdd, ddq, prob.accel_scale(ddq)) <= 1e-10
    assert rel(o.tau_command, prob.A.T @ np.array(data.lambda_c), prob.torque_scale()) <= 1e-10  # nu = -lambda


@pytest.mark.parametrize("seed", range(20))
def test_oracle_mujoco_matches_enumeration(seed):
    """(c) vs (b) on random chains at rest without a task.

    MuJoCo settings (friction_oracles.MUJOCO_OPTIONS): Newton main solver, tolerance 0, 200
    iterations; noslip_iterations 1000, noslip_tolerance 0. The main solver alone is a soft-
    constraint answer: with default solref/solimp it is off by up to 0.34 (relative) and with hard
    solreffriction 0.0002 / solimpfriction 0.9999 still by 5e-4; the noslip post-processor solves
    the friction rows without regularisation (projected Gauss-Seidel) and from about 100 sweeps on
    agrees to round-off (4.5e-15 worst over these samples). Tolerance used: 1e-12."""
    rng = np.random.default_rng([seed, 74])
    n = int(rng.integers(2, 8))
    case = random_chain_case(
        rng, n, 0, rest="all", friction=["mixed", "moderate"][seed % 2], fext=False, cap_friction=1e3
    )
    prob = case["prob"]
    o = enumeration_oracle(prob)
    qacc, _, _ = mujoco_qacc(case["rc"].segments, case["g"], case["q"], case["tau"], prob.static)
    assert rel(qacc, o.qdd, prob.accel_scale(o.qdd)) <= 1e-12


# ------------------------------------------------------------------------------------------------
# Random chains
# ------------------------------------------------------------------------------------------------
FRICTION_KINDS = ("mixed", "moderate", "zero", "large")


@pytest.mark.parametrize("rest", ["all", "mixed"])
@pytest.mark.parametrize("m", [0, 1, 2, 3])
@pytest.mark.parametrize("seed", range(10))
def test_random_chains(seed, m, rest):
    rng = np.random.default_rng([seed, m, rest == "all", 75])
    n = int(rng.integers(2, 8))
    tol = [1e-6, 1e-3][seed % 2]
    case = random_chain_case(rng, n, m, rest=rest, friction=FRICTION_KINDS[(seed + m) % 4], tol=tol)
    res = solve_chain_case(case)
    check_chain_case(case, res, f"seed {seed} n {n} m {m} rest {rest} f {case['static']}")


TIE_CASES = [
    ("hold", "all", 1),
    ("hold", "all", 2),
    ("hold", "all", 3),
    ("hold", "all", 4),
    ("hold", "all", 5),
    ("partial", "all", 2),
    ("partial", "all", 3),
    ("partial", "all", 4),
    ("partial", "all", 5),
    ("hold", "one", 2),
    ("hold", "one", 3),
    ("hold", "one", 4),
    ("partial", "one", 3),
    ("partial", "one", 4),
]


@pytest.mark.parametrize("tie", TIE_CASES, ids=lambda t: "-".join(map(str, t)))
@pytest.mark.parametrize("seed", range(10))
def test_random_chains_tie_break(seed, tie):
    """Tasks met by accelerations that vanish on resting joints ('hold': qdd = 0; 'partial': all
    but one joint; rest 'one': one joint moving): the friction torques are not unique, the motors
    must still help, and tau_command must be the smallest one (vs the exact tie-break oracle)."""
    task, rest, m = tie
    rng = np.random.default_rng([seed, m, rest == "all", task == "hold", 81])
    n = int(rng.integers(m + 1, 8))
    case = random_chain_case(rng, n, m, rest=rest, friction="moderate", task=task, accept=nontrivial_tie)
    res = solve_chain_case(case)
    check_chain_case(case, res, f"seed {seed} n {n} m {m} rest {rest} task {task} f {case['static']}")


@pytest.mark.parametrize("seed", range(6))
def test_random_chains_at_rest_vs_mujoco(seed):
    """Unconstrained, all joints at rest: our qdd against MuJoCo's frictionloss + noslip."""
    rng = np.random.default_rng([seed, 76])
    n = int(rng.integers(2, 8))
    case = random_chain_case(rng, n, 0, rest="all", friction="moderate", fext=False, cap_friction=1e3)
    res = solve_chain_case(case)
    qacc, _, _ = mujoco_qacc(case["rc"].segments, case["g"], case["q"], case["tau"], case["static"])
    assert rel(res.qdd, qacc, case["prob"].accel_scale(qacc)) <= 1e-10


@pytest.mark.parametrize("seed", range(4))
def test_zero_friction_is_the_plain_solve(seed):
    rng = np.random.default_rng([seed, 77])
    n = int(rng.integers(2, 8))
    case = random_chain_case(rng, n, int(rng.integers(0, 4)), rest="mixed", friction="zero")
    res = solve_chain_case(case)
    plain = vs.Solver(case["rc"].chain, gravity=case["g"]).solve(
        case["q"], case["qd"], alpha=case["alpha"], beta=case["beta"], f_ext=case["f_ext"], tau_ff=case["tau"]
    )
    np.testing.assert_allclose(res.qdd, plain.qdd, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(plain.qdd).max()))
    np.testing.assert_allclose(
        res.tau_command, plain.tau_command, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(plain.tau_command).max())
    )
    np.testing.assert_array_equal(res.friction_torque, np.zeros(n))
    check_chain_case(case, res, f"zero friction seed {seed}")


# ------------------------------------------------------------------------------------------------
# The tie-break of section 4 on 2-joint chains, by hand
# ------------------------------------------------------------------------------------------------
def _planar_2link():
    """Two rot_z links of length 1 (COM 0.5, mass 1, Izz 0.1), rotors 0.05; arm along x at q = 0."""
    return build(planar_rot_z_links(2, np.diag([0.01, 0.1, 0.1]), 0.05))


def _tie_break_case(rc, q, g, alpha, beta, static, tau_ff):
    rc.model.gravity = pin.Motion(np.r_[g, 0.0, 0.0, 0.0])
    data = rc.data()
    n = rc.n_joints
    prob = pinocchio_problem(
        rc.model,
        data,
        q,
        np.zeros(n),
        tau_ff=tau_ff,
        static=static,
        tip_frame=rc.tip_frames[-1],
        alpha=alpha,
        beta=beta,
    )
    res = vs.Solver(rc.chain, gravity=g).solve(
        q, np.zeros(n), alpha=alpha, beta=beta, tau_ff=tau_ff, friction=friction_arg(static)
    )
    check_against_oracles(
        res,
        prob,
        lambda a: pin.rnea(rc.model, data, q, np.zeros(n), a),
        oracles=both_oracles(prob),
        what=f"tie-break (static {static})",
    )
    return res, prob, data


@pytest.mark.parametrize("seed", range(6))
def test_tie_break_fully_constrained_two_joints(seed):
    """m = n = 2 (A invertible): qdd* = A^-1 b; the needed torque r = rnea(q, 0, qdd*) - tau_ff
    is split as friction + command with |friction_j| <= f_j where qdd*_j = 0 (friction = -f_j
    sign(qdd*_j) otherwise); min ||tau_command|| gives friction_j = clip(r_j, -f_j, f_j).
    Seeds 0-2 hold the arm still (beta for qdd = 0); 3-5 also accelerate joint 2."""
    rng = np.random.default_rng([seed, 78])
    for _ in range(100):
        rc = random_chain(rng, 2, prismatic=False)
        q = rng.uniform(-np.pi, np.pi, 2)
        alpha = random_alpha(rng, 2)
        rc.model.gravity = pin.Motion(np.r_[G_EARTH, 0.0, 0.0, 0.0])
        data = rc.data()
        J = np.reshape(pin.computeFrameJacobian(rc.model, data, q, rc.tip_frames[-1], LWA), (6, 2))
        A = alpha.T @ J
        if abs(np.linalg.det(A)) > 0.05 * np.linalg.norm(A) ** 2:
            break
    qdd_target = np.zeros(2) if seed < 3 else np.array([0.0, rng.choice([-2.0, 2.0])])
    pin.forwardKinematics(rc.model, data, q, np.zeros(2), qdd_target)
    pin.updateFramePlacements(rc.model, data)
    beta = alpha.T @ (
        pin.getFrameAcceleration(rc.model, data, rc.tip_frames[-1], LWA).vector + np.r_[-G_EARTH, 0.0, 0.0, 0.0]
    )
    tau_ff = rng.normal(size=2)
    r = pin.rnea(rc.model, data, q, np.zeros(2), qdd_target) - tau_ff
    # friction able to hold joint 1 fully and joint 2 partly (seed-dependent)
    static = np.array([abs(r[0]) * 1.5, abs(r[1]) * [0.5, 2.0, 0.3][seed % 3]])
    expected_fr = np.where(qdd_target == 0, np.clip(r, -static, static), -static * np.sign(qdd_target))
    expected_tc = r - expected_fr
    # the same by an independent small QP (SLSQP) on the friction torques
    from scipy.optimize import minimize

    free = qdd_target == 0
    sol = minimize(
        lambda x: np.sum((r[free] - x) ** 2),
        np.zeros(int(free.sum())),
        bounds=list(zip(-static[free], static[free])),
        method="SLSQP",
        options=dict(ftol=1e-14),
    )
    np.testing.assert_allclose(sol.x, expected_fr[free], atol=1e-6 * max(1.0, np.abs(r).max()))

    t = max(1.0, np.abs(r).max())
    # ... and by the oracles' tie-break (guards the oracle used everywhere else)
    prob = pinocchio_problem(
        rc.model,
        data,
        q,
        np.zeros(2),
        tau_ff=tau_ff,
        static=static,
        tip_frame=rc.tip_frames[-1],
        alpha=alpha,
        beta=beta,
    )
    for o in both_oracles(prob).values():
        np.testing.assert_allclose(o.qdd, qdd_target, atol=1e-10 * max(1.0, np.abs(qdd_target).max()))
        np.testing.assert_allclose(o.friction_torque, expected_fr, rtol=0, atol=1e-10 * t)
        np.testing.assert_allclose(o.tau_command, expected_tc, rtol=0, atol=1e-10 * t)

    res, prob, _ = _tie_break_case(rc, q, G_EARTH, alpha, beta, static, tau_ff)
    np.testing.assert_allclose(res.qdd, qdd_target, atol=1e-10 * max(1.0, np.abs(qdd_target).max()))
    np.testing.assert_allclose(res.friction_torque, expected_fr, rtol=0, atol=1e-9 * t)
    np.testing.assert_allclose(res.tau_command, expected_tc, rtol=0, atol=1e-9 * t)
    if seed == 1:  # held still and friction can hold everything: the motors add nothing
        np.testing.assert_allclose(res.tau_command, 0.0, atol=1e-9 * t)


@pytest.mark.parametrize("static", [(12.0, 4.0), (16.0, 6.0), (6.0, 4.0)])
@pytest.mark.parametrize("target", [0.0, 1.0, -30.0])
def test_tie_break_partial_task_two_joints(target, static):
    """Planar 2-link, task on the tip's angular z acceleration: A = [1, 1]. With both joints stuck
    (target 0 and friction (12, 4) or (16, 6); the gravity load r is (17.86, 4.50)),
    tau_command = t (1, 1) and friction = r - t (1, 1) with |r_j - t| <= f_j: t is the smallest |t|
    in the intersection of [r_j - f_j, r_j + f_j] (5.86 and 1.86). Otherwise joints slip."""
    rc = _planar_2link()
    q = np.array([0.3, -0.8])
    g = np.array([0.0, -9.81, 0.0])  # in the plane of motion
    static = np.array(static)
    tau_ff = np.array([0.5, -0.2])
    res, prob, data = _tie_break_case(rc, q, g, _e(5), [target], static, tau_ff)
    o = enumeration_oracle(prob)
    stuck = target == 0.0 and static[0] > 10.0
    assert np.all(o.status == STICK) == stuck
    if stuck:
        r = pin.rnea(rc.model, data, q, np.zeros(2), np.zeros(2)) - tau_ff
        lo, hi = np.max(r - static), np.min(r + static)
        assert 0.0 < lo <= hi
        t = min(max(0.0, lo), hi)
        np.testing.assert_allclose(o.tau_command, [t, t], atol=1e-12)
        np.testing.assert_allclose(res.tau_command, [t, t], atol=1e-10)
        np.testing.assert_allclose(res.friction_torque, r - t, atol=1e-10)


# ------------------------------------------------------------------------------------------------
# Panda and Gen3
# ------------------------------------------------------------------------------------------------
def _panda():
    r = panda()
    return r.chain, r.model, r.tip


def _gen3(**kw):
    from vereshchagin.robots import gen3, gen3_urdf

    return gen3(False, **kw), pin.buildModelFromXML(gen3_urdf(False, **kw)), "end_effector_link"


ROBOTS = {"panda": _panda, "gen3": _gen3}


_pin_q = pin_configuration


def _robot_case(name, rng, m, rest, friction, task="random", accept=None, **kw):
    chain, model, tip = ROBOTS[name](**kw)
    n = chain.n_joints
    rotor = rng.uniform(0.0, 0.3, n)
    chain.rotor_inertia = rotor
    model.armature = rotor
    model.gravity = pin.Motion(np.r_[G_EARTH, 0.0, 0.0, 0.0])
    data = model.createData()
    fid = model.getFrameId(tip)
    for _ in range(100):
        q = rng.uniform(np.maximum(chain.lower, -np.pi), np.minimum(chain.upper, np.pi))
        qd = random_velocities(rng, n, rest, 1e-6)
        pq = _pin_q(model, q)
        alpha = random_alpha(rng, m) if m else None
        if m:
            J = pin.computeFrameJacobian(model, data, pq, fid, LWA)
            A = alpha.T @ J
            if not well_conditioned_task(
                A, np.linalg.inv(pinocchio_problem(model, data, pq, qd, static=np.zeros(n)).H)
            ):
                continue
        if not m:
            beta = None
        elif task == "random":
            beta = rng.normal(size=m)
        else:
            beta = hold_beta(model, data, pq, qd, fid, alpha, G_EARTH, task_target(rng, n, task))
        tau = rng.normal(size=n) * 2.0
        load = pin.rnea(model, data, pq, qd, np.zeros(n)) - tau
        static = random_friction(rng, n, friction, max(1.0, np.linalg.norm(load) / np.sqrt(n)))
        kinetic = static * rng.uniform(0.3, 1.0, n)
        prob = pinocchio_problem(
            model, data, pq, qd, tau_ff=tau, static=static, kinetic=kinetic, tip_frame=fid, alpha=alpha, beta=beta
        )
        o = enumeration_oracle(prob)
        slipping = np.abs(o.qdd[prob.rest_idx])[o.status[prob.rest_idx] != STICK]
        if slipping.size and slipping.min() < 1e-6 * prob.accel_scale(o.qdd):
            continue
        if accept is not None and not accept(prob, o):
            continue
        return dict(
            chain=chain,
            model=model,
            data=data,
            q=q,
            pq=pq,
            qd=qd,
            tau=tau,
            alpha=alpha,
            beta=beta,
            static=static,
            kinetic=kinetic,
            prob=prob,
            enumeration=o,
        )
    raise AssertionError("no usable sample")  # pragma: no cover


ROBOT_CASES = [
    ("panda", 0, "all", "moderate", "random"),
    ("panda", 2, "mixed", "mixed", "random"),
    ("panda", 3, "all", "mixed", "random"),
    ("panda", 3, "all", "zero", "random"),
    ("panda", 2, "all", "moderate", "hold"),
    ("panda", 3, "all", "moderate", "partial"),
    ("gen3", 0, "mixed", "mixed", "random"),
    ("gen3", 1, "all", "moderate", "random"),
    ("gen3", 3, "mixed", "moderate", "random"),
    ("gen3", 2, "all", "large", "random"),
    ("gen3", 1, "all", "moderate", "hold"),
    ("gen3", 3, "one", "moderate", "hold"),
]


@pytest.mark.parametrize("case", ROBOT_CASES, ids=lambda c: "-".join(map(str, c)))
def test_robots(case):
    name, m, rest, friction, task = case
    rng = np.random.default_rng([len(name), m, len(rest), len(friction), len(task), 79])
    c = _robot_case(name, rng, m, rest, friction, task, accept=nontrivial_tie if task != "random" else None)
    res = vs.Solver(c["chain"], gravity=G_EARTH).solve(
        c["q"],
        c["qd"],
        alpha=c["alpha"],
        beta=c["beta"],
        tau_ff=c["tau"],
        friction=friction_arg(c["static"], c["kinetic"]),
    )
    model, data, pq, qd = c["model"], c["data"], c["pq"], c["qd"]
    oracles = {"enumeration": c["enumeration"], "scipy": scipy_oracle(c["prob"])}
    check_against_oracles(res, c["prob"], lambda a: pin.rnea(model, data, pq, qd, a), oracles=oracles, what=str(case))


def test_friction_true_uses_chain_friction():
    """friction=True takes chain.friction (URDF <dynamics friction>) as static and kinetic values."""
    f = [0.8, 1.5, 0.3, 2.0, 0.4, 0.6, 0.2]
    rng = np.random.default_rng(80)
    c = _robot_case("gen3", rng, 1, "mixed", "zero", joint_friction=f)
    chain, model, data, pq, qd = c["chain"], c["model"], c["data"], c["pq"], c["qd"]
    np.testing.assert_array_equal(chain.friction, f)
    prob = pinocchio_problem(
        model,
        data,
        pq,
        qd,
        tau_ff=c["tau"],
        static=f,
        kinetic=f,
        tip_frame=model.getFrameId("end_effector_link"),
        alpha=c["alpha"],
        beta=c["beta"],
    )
    solver = vs.Solver(chain, gravity=G_EARTH)
    res = solver.solve(c["q"], qd, alpha=c["alpha"], beta=c["beta"], tau_ff=c["tau"], friction=True)
    explicit = solver.solve(c["q"], qd, alpha=c["alpha"], beta=c["beta"], tau_ff=c["tau"], friction=friction_arg(f, f))
    np.testing.assert_array_equal(res.qdd, explicit.qdd)
    np.testing.assert_array_equal(res.friction_torque, explicit.friction_torque)
    check_against_oracles(
        res, prob, lambda a: pin.rnea(model, data, pq, qd, a), oracles=both_oracles(prob), what="friction=True"
    )


def test_kinetic_defaults_to_static():
    """Friction(static=f) (kinetic=None) moves joints with kinetic friction f (the Friction docstring)."""
    rng = np.random.default_rng(82)
    case = random_chain_case(rng, 5, 1, rest="mixed", friction="moderate")
    case["kinetic"] = case["static"]
    rc = case["rc"]
    solver = vs.Solver(rc.chain, gravity=case["g"])
    args = (case["q"], case["qd"])
    kw = dict(alpha=case["alpha"], beta=case["beta"], f_ext=case["f_ext"], tau_ff=case["tau"])
    a = solver.solve(*args, **kw, friction=vs.Friction(static=case["static"]))
    b = solver.solve(*args, **kw, friction=friction_arg(case["static"], case["static"]))
    np.testing.assert_array_equal(a.qdd, b.qdd)
    np.testing.assert_array_equal(a.friction_torque, b.friction_torque)
    moving = np.abs(case["qd"]) > 1e-6
    assert moving.any()
    np.testing.assert_allclose(
        a.friction_torque[moving], -case["static"][moving] * np.sign(case["qd"][moving]), rtol=1e-15, atol=0
    )


@pytest.mark.parametrize("tol", [1e-6, 1e-2])
def test_velocity_tolerance_boundary(tol):
    """|qd_j| <= velocity_tolerance is at rest (also at equality), above it the joint moves."""
    rc = _planar_2link()
    q = np.array([0.4, 0.9])
    g = np.array([0.0, -9.81, 0.0])
    static, kinetic = np.array([3.0, 1.0]), np.array([2.0, 0.5])
    for qd in (np.array([tol, -1.5 * tol]), np.array([-tol, 1.5 * tol]), np.array([0.5 * tol, 0.0])):
        rc.model.gravity = pin.Motion(np.r_[g, 0.0, 0.0, 0.0])
        data = rc.data()
        prob = pinocchio_problem(
            rc.model, data, q, qd, tau_ff=np.zeros(2), static=static, kinetic=kinetic, velocity_tolerance=tol
        )
        res = vs.Solver(rc.chain, gravity=g).solve(q, qd, friction=friction_arg(static, kinetic, tol))
        assert res.status[0] != MOVING
        assert (res.status[1] == MOVING) == (abs(qd[1]) > tol)
        check_against_oracles(
            res,
            prob,
            lambda a, data=data, qd=qd: pin.rnea(rc.model, data, q, qd, a),
            oracles=both_oracles(prob),
            what=f"qd {qd}",
        )
