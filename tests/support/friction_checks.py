"""Checks of friction-aware solves against the oracles of :mod:`support.friction_oracles`.

``check_against_oracles`` is every check of one result: the self-certifying KKT conditions (the
equation of motion through ``pin.rnea``, the task, ``tau_command`` in the range of ``-J^T alpha``,
stick/slip complementarity) and agreement with the oracles. ``random_chain_case`` draws a random
chain, state, task and friction with its Pinocchio problem; ``solve_chain_case`` and
``check_chain_case`` solve it with vereshchagin and check the result. Shared by the friction,
joint-limit, segment-constraint and KDL-migration tests.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from support.chains import (
    G_EARTH,
    fext_generalized,
    fext_to_pinocchio,
    random_alpha,
    random_chain,
    random_f_ext,
    random_state,
    well_conditioned_task,
)
from support.friction_oracles import (
    MOVING,
    SLIP_NEG,
    SLIP_POS,
    STICK,
    enumeration_oracle,
    null_space,
    pinocchio_problem,
    random_friction,
    scipy_oracle,
)

# Solver vs oracles (qdd, gauss_value, friction_torque, tau_command): the enumeration is exact and
# the SLSQP primal is polished to its pattern's exact solution, so the exact-algorithm tolerance.
# Measured worst relative error over tests/oracles/test_friction_oracles.py: 1.1e-12 (qdd vs
# enumeration), 7.1e-12 (Gauss value vs scipy).
RTOL = 1e-9
KKT_TOL = 1e-9  # complementarity, equation of motion, task, range of tau_command (scaled)
LWA = pin.LOCAL_WORLD_ALIGNED


def rel(a, b, scale):
    """||a - b|| / scale."""
    return np.linalg.norm(np.asarray(a, float) - np.asarray(b, float)) / scale


def friction_arg(static, kinetic=None, tol=1e-6):
    return vs.Friction(
        static=np.asarray(static, float),
        kinetic=None if kinetic is None else np.asarray(kinetic, float),
        velocity_tolerance=tol,
    )


def complementarity_residual(prob, qdd, friction, status):
    """Largest scaled violation of the friction laws by a solver result (no oracle involved).

    Resting j: status STICK -> qdd_j = 0 and |friction_j| <= f_j; SLIP_POS -> qdd_j > 0 and
    friction_j = -f_j; SLIP_NEG -> qdd_j < 0 and friction_j = +f_j. Moving j: status MOVING and
    friction_j = -fk_j sign(qd_j). A wrong status/sign is reported as infinity."""
    a, t = prob.accel_scale(qdd), prob.torque_scale(qdd)
    worst = 0.0
    for j in range(prob.n):
        s, f = int(status[j]), prob.static[j]
        if not prob.resting[j]:
            if s != MOVING:
                return np.inf
            worst = max(worst, abs(friction[j] - prob.kinetic_torque[j]) / t)
        elif s == STICK:
            worst = max(worst, abs(qdd[j]) / a, max(0.0, abs(friction[j]) - f) / t)
        elif s == SLIP_POS:
            if qdd[j] <= 0:
                return np.inf
            worst = max(worst, abs(friction[j] + f) / t)
        elif s == SLIP_NEG:
            if qdd[j] >= 0:
                return np.inf
            worst = max(worst, abs(friction[j] - f) / t)
        else:
            return np.inf
    return worst


def check_motion(prob, rnea_tau, qdd, tau_command, joint_torques, a_s, t_s, what=""):
    """Self-certifying checks of a friction-aware solve (no oracle): the equation of motion with
    ``joint_torques`` (friction, plus the limit reactions when there are limits), the task, and
    ``tau_command`` in range(-J^T alpha); ``a_s``, ``t_s``: the acceleration and torque scales."""
    eom = rnea_tau(qdd) - (prob.extra["tau_ff"] + tau_command + joint_torques)
    assert np.linalg.norm(eom) <= KKT_TOL * t_s, f"{what}: equation of motion residual {np.linalg.norm(eom):.2e}"
    if prob.A.shape[0]:
        task = prob.A @ qdd - prob.b
        assert np.linalg.norm(task) <= KKT_TOL * max(1.0, np.linalg.norm(prob.b), np.linalg.norm(prob.A) * a_s), (
            f"{what}: task residual {np.linalg.norm(task):.2e}"
        )
    off_range = null_space(prob.A).T @ tau_command
    assert np.linalg.norm(off_range) <= KKT_TOL * t_s, (
        f"{what}: tau_command not in range(-J^T alpha): {np.linalg.norm(off_range):.2e}"
    )


def check_oracle_optima(res, prob, qdd, oracles, what=""):
    """qdd and gauss_value against each oracle's optimum."""
    a_s = prob.accel_scale(qdd)
    for name, o in oracles.items():
        assert rel(qdd, o.qdd, a_s) <= RTOL, f"{what}: qdd vs oracle {name}\n{qdd}\n{o.qdd}"
        assert abs(res.gauss_value - o.objective) <= RTOL * prob.objective_scale(o.qdd), (
            f"{what}: gauss_value {res.gauss_value!r} vs oracle {name} {o.objective!r}"
        )


def check_against_oracles(res, prob, rnea_tau, *, oracles, what=""):
    """All checks of one friction-aware solve. rnea_tau(qdd) = pin.rnea(q, qd, qdd, f_ext)."""
    n = prob.n
    for name in ("qdd", "tau_command", "friction_torque", "status"):
        assert np.shape(getattr(res, name)) == (n,), f"{what}: {name} shape"
    qdd = np.asarray(res.qdd)
    fr = np.asarray(res.friction_torque)
    tc = np.asarray(res.tau_command)
    st = np.asarray(res.status)
    assert np.issubdtype(st.dtype, np.integer), f"{what}: status dtype {st.dtype}"
    assert int(res.iterations) >= 0
    a_s, t_s = prob.accel_scale(qdd), prob.torque_scale(qdd)

    # --- self-certifying KKT checks (no oracle) ---
    check_motion(prob, rnea_tau, qdd, tc, fr, a_s, t_s, what)
    comp = complementarity_residual(prob, qdd, fr, st)
    assert comp <= KKT_TOL, f"{what}: complementarity residual {comp:.2e}; status {st}, qdd {qdd}, friction {fr}"

    # --- the oracles ---
    check_oracle_optima(res, prob, qdd, oracles, what)
    ref = oracles["enumeration"]
    np.testing.assert_array_equal(st, ref.status, err_msg=f"{what}: status vs enumeration")
    assert rel(fr, ref.friction_torque, t_s) <= RTOL, (
        f"{what}: friction_torque vs tie-broken oracle\n{fr}\n{ref.friction_torque}"
    )
    assert rel(tc, ref.tau_command, t_s) <= RTOL, (
        f"{what}: tau_command vs tie-broken oracle (min ||tau_command||)\n{tc}\n{ref.tau_command}"
    )
    # gauss_value is the objective at the solver's own qdd
    assert abs(res.gauss_value - prob.objective(qdd)) <= RTOL * prob.objective_scale(qdd), f"{what}: gauss_value"


def both_oracles(prob):
    b = enumeration_oracle(prob)
    a = scipy_oracle(prob)
    return {"enumeration": b, "scipy": a}


def random_gravity(rng, kind):
    return {"zero": np.zeros(3), "earth": G_EARTH.copy()}.get(kind, rng.normal(size=3) * 5.0)


def random_velocities(rng, n, rest, tol):
    """qd: resting joints exactly 0 or within the tolerance; moving ones well above it."""
    if rest == "all":
        resting = np.ones(n, bool)
    elif rest == "one":  # exactly one joint moving
        resting = np.ones(n, bool)
        resting[rng.integers(n)] = False
    else:
        resting = rng.random(n) < 0.5
        if not resting.any():
            resting[rng.integers(n)] = True
    qd = rng.uniform(0.05, 2.0, n) * rng.choice([-1.0, 1.0], n)
    small = rng.uniform(-0.5, 0.5, n) * tol * (rng.random(n) < 0.5)  # inside the tolerance
    return np.where(resting, small, qd)


def hold_beta(model, data, q, qd, fid, alpha, g, qdd_target):
    """beta of the task met by qdd_target: alpha^T (J qdd_target + a0 + [-g; 0])."""
    pin.forwardKinematics(model, data, q, qd, qdd_target)
    pin.updateFramePlacements(model, data)
    return alpha.T @ (pin.getFrameAcceleration(model, data, fid, LWA).vector + np.r_[-g, 0.0, 0.0, 0.0])


def task_target(rng, n, task):
    """qdd the task is built around: 'hold' -> 0; 'partial' -> 0 except on one joint."""
    qdd = np.zeros(n)
    if task == "partial":
        qdd[rng.integers(n)] = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 3.0)
    return qdd


def random_chain_case(
    rng,
    n,
    m,
    *,
    rest="all",
    friction="mixed",
    fext=True,
    cap_friction=None,
    gravity=None,
    tol=1e-6,
    task="random",
    accept=None,
):
    """A random chain, state, well-conditioned task (m <= n) and friction; its Pinocchio problem.

    task: 'random' beta, or beta met by qdd = 0 ('hold') or by a qdd that is zero on most joints
    ('partial'): these make the task fix accelerations of resting joints, so that the friction
    torques are not unique and the tie-break of sec. 4 decides them. accept(prob, oracle) -> bool
    rejects samples.

    Samples whose optimum is near a stick/slip boundary (a slipping joint with |qdd_j| below 1e-6 of
    the scale) are redrawn: there the status is a matter of round-off."""
    m = min(m, n)
    for _ in range(100):
        rc = random_chain(rng, n, fixed_prob=0.2)
        q, _ = random_state(rng, rc)
        qd = random_velocities(rng, n, rest, tol)
        g = random_gravity(rng, gravity or ["zero", "earth", "random"][int(rng.integers(3))])
        rc.model.gravity = pin.Motion(np.r_[g, 0.0, 0.0, 0.0])
        data = rc.data()
        tau = rng.normal(size=n) * 3.0
        f_ext = random_f_ext(rng, rc) if fext else np.zeros((rc.n_segments, 6))
        fext_tau = fext_generalized(rc, data, q, f_ext)
        alpha = random_alpha(rng, m) if m else None
        J = np.reshape(pin.computeFrameJacobian(rc.model, data, q, rc.tip_frames[-1], LWA), (6, n))
        if m:
            A = alpha.T @ J
            Minv = np.linalg.inv(pinocchio_problem(rc.model, data, q, qd, static=np.zeros(n)).H)
            if not well_conditioned_task(A, Minv):
                continue
        if not m:
            beta = None
        elif task == "random":
            beta = rng.normal(size=m) * 3.0
        else:
            beta = hold_beta(rc.model, data, q, qd, rc.tip_frames[-1], alpha, g, task_target(rng, n, task))
        load = pin.rnea(rc.model, data, q, qd, np.zeros(n)) - tau - fext_tau
        scale = max(1.0, np.linalg.norm(load) / np.sqrt(n))
        static = random_friction(rng, n, friction, scale)
        if cap_friction is not None:
            static = np.minimum(static, cap_friction)
        kinetic = static * rng.uniform(0.3, 1.0, n)
        prob = pinocchio_problem(
            rc.model,
            data,
            q,
            qd,
            tau_ff=tau,
            fext_tau=fext_tau,
            static=static,
            kinetic=kinetic,
            velocity_tolerance=tol,
            tip_frame=rc.tip_frames[-1],
            alpha=alpha,
            beta=beta,
        )
        o = enumeration_oracle(prob)
        R = prob.rest_idx
        slipping = np.abs(o.qdd[R])[o.status[R] != STICK]
        if slipping.size and slipping.min() < 1e-6 * prob.accel_scale(o.qdd):
            continue
        if accept is not None and not accept(prob, o):
            continue
        return dict(
            rc=rc,
            q=q,
            qd=qd,
            g=g,
            tau=tau,
            f_ext=f_ext,
            alpha=alpha,
            beta=beta,
            static=static,
            kinetic=kinetic,
            tol=tol,
            prob=prob,
            enumeration=o,
        )
    raise AssertionError("no usable sample")  # pragma: no cover


def multipliers_not_unique(prob, o):
    """[A; e_j^T (j stuck)] has dependent rows: the friction torques are not unique."""
    Z = [j for j in prob.rest_idx if o.status[j] == STICK]
    E = np.zeros((len(Z), prob.n))
    E[np.arange(len(Z)), Z] = 1.0
    C = np.vstack([prob.A, E])
    return C.shape[0] > 0 and np.linalg.matrix_rank(C) < C.shape[0]


def nontrivial_tie(prob, o):
    """Not unique, and the motors must still help (the tie-break is not simply tau_command = 0)."""
    return multipliers_not_unique(prob, o) and np.linalg.norm(o.tau_command) > 1e-2 * prob.torque_scale(o.qdd)


def solve_chain_case(case):
    rc = case["rc"]
    solver = vs.Solver(rc.chain, gravity=case["g"])
    return solver.solve(
        case["q"],
        case["qd"],
        alpha=case["alpha"],
        beta=case["beta"],
        f_ext=case["f_ext"],
        tau_ff=case["tau"],
        friction=friction_arg(case["static"], case["kinetic"], case["tol"]),
    )


def check_chain_case(case, res, what):
    rc, q, qd = case["rc"], case["q"], case["qd"]
    prob = case["prob"]
    data = rc.data()
    fext = fext_to_pinocchio(rc, data, q, case["f_ext"])
    oracles = {"enumeration": case["enumeration"], "scipy": scipy_oracle(prob)}
    check_against_oracles(res, prob, lambda a: pin.rnea(rc.model, data, q, qd, a, fext), oracles=oracles, what=what)
