"""Joint-limit reactions of the static-friction solver against independent oracles.

A resting joint on its lower (upper) limit may not accelerate further into it: the primal of
tests/support/friction_oracles.py gains qdd_j >= 0 (qdd_j <= 0), and the friction multiplier mu_j (friction
torque plus limit reaction = -mu_j) gets the bounds (-inf, f_j] ([-f_j, +inf)). The oracles (none
calls our solver; H, qdd_free, A, b from Pinocchio):

(a) ``scipy_oracle``: SLSQP on the primal with the sign bounds on qdd, polished and certified by
    BVLS with the opened multiplier bounds;
(b) ``enumeration_oracle``: the stick/slip patterns with slips only away from the limits, and the
    exact tie-break (smallest ||tau_command||) over the opened bounds;
(c) ``limit_margin`` (linear programming): whether the task leaves any acceleration that does not
    enter a limit; if not, the primal is infeasible and the solver must raise.

Every result is also checked on its own (the KKT conditions): the equation of motion through
pin.rnea, rnea(q, qd, qdd, f_ext) = tau_ff + tau_command + friction_torque + limit_torque (the sign
convention of tests/unit/test_friction_limits.py: pushed into the lower limit by -4.9 N m with f = 2, the
friction is +2 and the limit +2.9); the task; |friction_j| <= f_j; limit_torque >= 0 at a lower limit,
<= 0 at an upper one, exactly 0 elsewhere; a nonzero limit torque only at a joint sticking on its
limit with its friction at the bound; qdd_j >= 0 at a lower limit and <= 0 at an upper one.

``test_small_friction_on_limit_held_by_task`` is the regression test of a fixed solver bug: with
friction 0 or <~ 1e-6 of the torques on a limit joint whose acceleration the task fixes, the QP's
gradient tolerance fell below the round-off of its gradient ('unbounded' error, no tie-break).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import (
    G_EARTH,
    fext_generalized,
    fext_to_pinocchio,
    pin_configuration,
    random_alpha,
    random_chain,
    random_f_ext,
    well_conditioned_task,
)
from support.friction_oracles import (
    SLIP_NEG,
    SLIP_POS,
    STICK,
    OracleFailure,
    OracleInfeasible,
    enumeration_oracle,
    limit_flags,
    limit_margin,
    pinocchio_problem,
    random_friction,
    scipy_oracle,
)
from support.friction_checks import check_motion, check_oracle_optima, hold_beta, rel
from support.urdf_robots import BUILDERS

# Solver vs oracles: exact enumeration and the polished primal, so the exact-algorithm tolerance.
# Measured worst relative error over this file: 2.5e-11 (qdd vs enumeration), 2.3e-11 (Gauss value).
RTOL = 1e-9
KKT_TOL = 1e-9  # self-certifying checks (scaled)
LIMIT_TOL = 1e-9  # Friction.limit_tolerance used throughout
LWA = pin.LOCAL_WORLD_ALIGNED


# ------------------------------------------------------------------------------------------------
# Checks
# ------------------------------------------------------------------------------------------------
def check_limit_result(res, prob, rnea_tau, oracles, what=""):
    """All checks of one solve with joint limits. rnea_tau(qdd) = pin.rnea(q, qd, qdd, f_ext)."""
    n = prob.n
    for name in ("qdd", "tau_command", "friction_torque", "limit_torque", "status"):
        assert np.shape(getattr(res, name)) == (n,), f"{what}: {name} shape"
    qdd, fr, lt = np.asarray(res.qdd), np.asarray(res.friction_torque), np.asarray(res.limit_torque)
    tc, st = np.asarray(res.tau_command), np.asarray(res.status)
    assert np.all(np.isfinite(qdd)) and np.all(np.isfinite(fr)) and np.all(np.isfinite(lt))
    a_s, t_s = prob.accel_scale(qdd), prob.torque_scale(qdd)
    t_s = max(t_s, np.linalg.norm(lt))

    # --- KKT on its own ---
    check_motion(prob, rnea_tau, qdd, tc, fr + lt, a_s, t_s, what)
    for j in range(n):
        f = prob.static[j]
        lo, up = prob.at_lower[j], prob.at_upper[j]
        tag = (
            f"{what}: joint {j} (lower {lo}, upper {up}, f {f:.3g}, qdd {qdd[j]:.3e}, friction {fr[j]:.6g}, "
            f"limit {lt[j]:.6g}, status {st[j]})"
        )
        assert abs(fr[j]) <= f * (1 + 1e-12), f"{tag}: friction outside [-f, f]"
        if lo:
            assert qdd[j] >= -KKT_TOL * a_s, f"{tag}: accelerates into the lower limit"
        if up:
            assert qdd[j] <= KKT_TOL * a_s, f"{tag}: accelerates into the upper limit"
        if not (lo or up):
            assert lt[j] == 0.0, f"{tag}: limit torque off the limits"
        elif lo and not up:
            assert lt[j] >= 0.0, f"{tag}: lower-limit reaction pulls"
        elif up and not lo:
            assert lt[j] <= 0.0, f"{tag}: upper-limit reaction pulls"
        if st[j] == STICK:
            assert abs(qdd[j]) <= KKT_TOL * a_s, f"{tag}: stick with qdd != 0"
        elif st[j] == SLIP_POS:
            assert qdd[j] > 0 and abs(fr[j] + f) <= KKT_TOL * t_s, f"{tag}: slip+ law"
        elif st[j] == SLIP_NEG:
            assert qdd[j] < 0 and abs(fr[j] - f) <= KKT_TOL * t_s, f"{tag}: slip- law"
        else:
            raise AssertionError(f"{tag}: status of a resting joint")
        if abs(lt[j]) > KKT_TOL * t_s:  # the limit holds only a sticking joint, friction first
            assert st[j] == STICK, f"{tag}: limit reaction on a slipping joint"
            if not (lo and up):
                assert abs(fr[j] - (f if lo else -f)) <= KKT_TOL * t_s, f"{tag}: limit acts before friction is used up"
        if st[j] != STICK:
            assert lt[j] == 0.0, f"{tag}: limit reaction on a slipping joint"

    # --- the oracles ---
    check_oracle_optima(res, prob, qdd, oracles, what)
    ref = oracles["enumeration"]
    np.testing.assert_array_equal(st, ref.status, err_msg=f"{what}: status vs enumeration")
    assert rel(fr, ref.friction_torque, t_s) <= RTOL, f"{what}: friction_torque\n{fr}\n{ref.friction_torque}"
    assert rel(lt, ref.limit_torque, t_s) <= RTOL, f"{what}: limit_torque\n{lt}\n{ref.limit_torque}"
    assert rel(tc, ref.tau_command, t_s) <= RTOL, f"{what}: tau_command (min ||tau_command||)\n{tc}\n{ref.tau_command}"
    assert abs(res.gauss_value - prob.objective(qdd)) <= RTOL * prob.objective_scale(qdd), f"{what}: gauss_value"


# ------------------------------------------------------------------------------------------------
# Cases: a chain (random or a robot), all joints at rest, some exactly on a limit
# ------------------------------------------------------------------------------------------------
ROLES = ("lower", "upper", "free", "inside_tol", "outside_tol")


def _place(rng, q, lower, upper, p_limit, allow_tol_variants=True):
    """Put each joint with a finite limit on it with probability p_limit: q_j = lower_j or upper_j
    exactly, sometimes within the tolerance (on it) or just outside (not on it). Returns q."""
    q = q.copy()
    for j in range(q.size):
        if rng.random() >= p_limit:
            continue
        sides = [s for s, v in (("lower", lower[j]), ("upper", upper[j])) if np.isfinite(v)]
        if not sides:
            continue
        side = sides[int(rng.integers(len(sides)))]
        v = lower[j] if side == "lower" else upper[j]
        into = -1.0 if side == "lower" else 1.0  # direction into the limit
        r = rng.random() if allow_tol_variants else 0.0
        if r < 0.8:
            q[j] = v
        elif r < 0.9:
            q[j] = v - into * 0.5 * LIMIT_TOL  # within the tolerance: on the limit
        else:
            q[j] = v - into * 1e-6  # just off the limit
    return q


def make_case(
    rng,
    chain,
    model,
    fid,
    q_range,
    m,
    *,
    friction,
    task="random",
    p_limit=0.5,
    push=0.7,
    gravity=G_EARTH,
    fext_fn=None,
    fixed_limits=None,
    feasible=True,
    locked=0,
):
    """A limit case: q in q_range, limits (fixed_limits or random around q), tau_ff pushing the
    on-limit joints into their limits with probability ``push``. feasible: True -> redraw until the
    primal is strictly feasible (or, for 'hold' / 'partial' tasks, feasible); False -> until it is
    infeasible (limit_margin < -1e-6); None -> either, but not within 1e-6 of the boundary; "any"
    -> no condition (no oracle run). locked: number of joints with lower = upper."""
    n = chain.n_joints
    lo_q, hi_q = q_range
    for _ in range(200):
        if fixed_limits is None:
            q0 = rng.uniform(lo_q, hi_q)
            lower = q0 - rng.uniform(0.1, 1.0, n)
            upper = q0 + rng.uniform(0.1, 1.0, n)
            none = rng.random(n) < 0.15  # some joints without a limit on one side
            lower[none & (rng.random(n) < 0.5)] = -np.inf
            upper[none & (rng.random(n) < 0.5)] = np.inf
        else:
            lower, upper = (np.array(v, float) for v in fixed_limits)
            q0 = rng.uniform(np.maximum(lower, lo_q), np.minimum(upper, hi_q))
        q = _place(rng, q0, lower, upper, p_limit)
        if locked:
            for j in rng.choice(n, locked, replace=False):
                lower[j] = upper[j] = q[j]
        at_lower, at_upper = limit_flags(q, lower, upper, LIMIT_TOL)
        if not (at_lower | at_upper).any():
            continue
        qd = rng.uniform(-0.5, 0.5, n) * 1e-6 * (rng.random(n) < 0.3)  # all at rest
        pq = pin_configuration(model, q)
        model.gravity = pin.Motion(np.r_[gravity, 0.0, 0.0, 0.0])
        data = model.createData()
        f_ext, fext_tau = (None, np.zeros(n)) if fext_fn is None else fext_fn(rng, data, q)
        alpha = random_alpha(rng, m) if m else None
        if m:
            J = np.reshape(pin.computeFrameJacobian(model, data, pq, fid, LWA), (6, n))
            A = alpha.T @ J
            Minv = np.linalg.inv(pinocchio_problem(model, data, pq, qd, static=np.zeros(n)).H)
            if not well_conditioned_task(A, Minv):
                continue
        if not m:
            beta = None
        elif task == "random":
            beta = rng.normal(size=m) * 3.0
        else:  # met by qdd = 0, or by one joint (not on a limit, or moving away from it) accelerating
            target = np.zeros(n)
            if task == "partial":
                j = int(rng.integers(n))
                target[j] = (
                    (1.0 if at_lower[j] else -1.0 if at_upper[j] else rng.choice([-1.0, 1.0]))
                    * rng.uniform(0.5, 3.0)
                    * (0.0 if at_lower[j] and at_upper[j] else 1.0)
                )
            beta = hold_beta(model, data, pq, qd, fid, alpha, gravity, target)
        bias = pin.rnea(model, data, pq, qd, np.zeros(n)) - fext_tau  # torque holding the arm still
        scale = max(1.0, np.linalg.norm(bias) / np.sqrt(n))
        tau = rng.normal(size=n) * scale + (bias if rng.random() < 0.5 else 0.0)
        into = np.where(at_lower, -1.0, 0.0) + np.where(at_upper, 1.0, 0.0)
        pushed = rng.random(n) < push
        tau += np.where(pushed, into * rng.uniform(0.5, 3.0, n) * scale, 0.0)
        static = random_friction(rng, n, friction, scale)
        prob = pinocchio_problem(
            model,
            data,
            pq,
            qd,
            tau_ff=tau,
            fext_tau=fext_tau,
            static=static,
            tip_frame=fid,
            alpha=alpha,
            beta=beta,
            at_lower=at_lower,
            at_upper=at_upper,
        )
        margin = limit_margin(prob)
        if feasible is True and not (margin > 1e-6 or (task != "random" and margin >= 0.0)):
            continue
        if feasible is False and not margin < -1e-6:
            continue
        if feasible is None and abs(margin) <= 1e-6:
            continue
        if feasible == "any":
            return case_dict(locals())
        case = case_dict(locals())
        if margin < 0:
            return case
        o = enumeration_oracle(prob)
        R = prob.rest_idx
        slipping = np.abs(o.qdd[R])[o.status[R] != STICK]
        if slipping.size and slipping.min() < 1e-6 * prob.accel_scale(o.qdd):
            continue  # near a stick/slip boundary: the status is a matter of round-off
        case["enumeration"] = o
        return case
    raise AssertionError("no usable sample")  # pragma: no cover


def case_dict(v):
    keys = (
        "chain",
        "model",
        "data",
        "q",
        "pq",
        "qd",
        "tau",
        "f_ext",
        "alpha",
        "beta",
        "static",
        "lower",
        "upper",
        "prob",
        "margin",
        "fid",
    )
    out = {k: v[k] for k in keys}
    out["g"] = np.array(v["gravity"], float)
    return out


def solve_case(case, **override):
    friction = vs.Friction(
        static=case["static"],
        kinetic=None,
        velocity_tolerance=1e-6,
        lower=override.get("lower", case["lower"]),
        upper=override.get("upper", case["upper"]),
        limit_tolerance=LIMIT_TOL,
    )
    solver = vs.Solver(case["chain"], gravity=case["g"])
    return solver.solve(
        case["q"],
        case["qd"],
        alpha=case["alpha"],
        beta=case["beta"],
        f_ext=case["f_ext"],
        tau_ff=case["tau"],
        friction=friction,
    )


def check_case(case, what):
    res = solve_case(case)
    prob, model, data = case["prob"], case["model"], case["data"]
    pq, qd = case["pq"], case["qd"]
    fext = None
    if case["f_ext"] is not None:
        fext = fext_to_pinocchio(case["rc"], data, case["q"], case["f_ext"])

    def rnea_tau(a):
        return pin.rnea(model, data, pq, qd, a) if fext is None else pin.rnea(model, data, pq, qd, a, fext)

    oracles = {"enumeration": case["enumeration"], "scipy": scipy_oracle(prob)}
    check_limit_result(res, prob, rnea_tau, oracles, what)
    return res, oracles


# ---- random chains ----
def _random_chain_setup(rng, n):
    rc = random_chain(rng, n, fixed_prob=0.2)
    lo = np.array([-np.pi if s.revolute else -0.5 for s in rc.segments if s.moving])
    hi = -lo

    def fext_fn(rng_, data, q):
        f_ext = random_f_ext(rng_, rc)
        return f_ext, fext_generalized(rc, data, q, f_ext)

    return rc, (lo, hi), fext_fn


def random_limit_case(rng, n, m, **kw):
    rc, q_range, fext_fn = _random_chain_setup(rng, n)
    use_fext = kw.pop("fext", rng.random() < 0.5)
    g = kw.pop("gravity", [np.zeros(3), G_EARTH, rng.normal(size=3) * 5.0][int(rng.integers(3))])
    case = make_case(
        rng, rc.chain, rc.model, rc.tip_frames[-1], q_range, m, gravity=g, fext_fn=fext_fn if use_fext else None, **kw
    )
    case["rc"] = rc
    return case


FRICTION_KINDS = ("mixed", "moderate", "zero", "large")


@pytest.mark.parametrize("m", [0, 1, 2, 3])
@pytest.mark.parametrize("seed", range(8))
def test_random_chains_on_limits(seed, m):
    rng = np.random.default_rng([seed, m, 91])
    n = int(rng.integers(max(2, m), 8))
    case = random_limit_case(rng, n, m, friction=FRICTION_KINDS[(seed + m) % 4])
    p = case["prob"]
    check_case(
        case,
        f"seed {seed} n {n} m {m} lower {p.at_lower.astype(int)} upper {p.at_upper.astype(int)} f {case['static']}",
    )


@pytest.mark.parametrize("task", ["hold", "partial"])
@pytest.mark.parametrize("seed", range(5))
def test_random_chains_on_limits_held_by_task(seed, task):
    """Tasks met by qdd = 0 (or all but one joint): a task that keeps a joint on its limit still
    leaves its reaction free, so the split friction / limit / command is the tie-break's."""
    rng = np.random.default_rng([seed, task == "hold", 92])
    m = int(rng.integers(1, 4))
    n = int(rng.integers(m + 1, 8))
    case = random_limit_case(rng, n, m, friction="moderate", task=task, p_limit=0.6, push=0.9)
    check_case(case, f"{task} seed {seed} n {n} m {m}")


@pytest.mark.parametrize("seed", range(4))
def test_random_chains_locked_joint(seed):
    """A joint with lower = upper = q: both flags, qdd_j = 0, a reaction of either sign."""
    rng = np.random.default_rng([seed, 93])
    m = int(rng.integers(0, 3))
    n = int(rng.integers(max(2, m + 1), 7))
    case = random_limit_case(rng, n, m, friction=["moderate", "zero"][seed % 2], locked=1)
    p = case["prob"]
    assert np.any(p.at_lower & p.at_upper)
    res, _ = check_case(case, f"locked seed {seed} n {n} m {m}")
    j = np.flatnonzero(p.at_lower & p.at_upper)
    assert np.all(res.status[j] == STICK)


# ---- robots ----
ROBOT_CASES = [
    ("panda", 0, "moderate", "random"),
    ("panda", 1, "mixed", "random"),
    ("panda", 2, "zero", "random"),
    ("panda", 3, "moderate", "random"),
    ("panda", 2, "moderate", "hold"),
    ("panda", 3, "large", "random"),
    ("gen3_bare", 0, "mixed", "random"),
    ("gen3_bare", 1, "moderate", "random"),
    ("gen3_bare", 2, "moderate", "partial"),
    ("gen3_bare", 3, "zero", "random"),
    ("gen3_gripper", 2, "mixed", "random"),
    ("gen3_gripper", 3, "moderate", "hold"),
]


@pytest.mark.parametrize("rcase", ROBOT_CASES, ids=lambda c: "-".join(map(str, c)))
def test_robots_on_urdf_limits(rcase):
    """Panda and Gen3 on their URDF limits (Gen3's continuous joints have none)."""
    name, m, friction, task = rcase
    rng = np.random.default_rng([len(name), m, len(friction), len(task), 94])
    robot = BUILDERS[name]()
    chain, model = robot.chain, robot.model
    rotor = rng.uniform(0.0, 0.3, chain.n_joints)
    chain.rotor_inertia = rotor
    model.armature = rotor
    case = make_case(
        rng,
        chain,
        model,
        model.getFrameId(robot.tip),
        (-np.pi, np.pi),
        m,
        friction=friction,
        task=task,
        p_limit=0.6,
        fixed_limits=(chain.lower, chain.upper),
    )
    np.testing.assert_array_equal(case["lower"], chain.lower)
    check_case(case, str(rcase))
    if m == 0:  # friction=True: the chain's URDF friction (Panda: 0) and limits
        p = case["prob"]
        prob = pinocchio_problem(
            model,
            case["data"],
            case["pq"],
            case["qd"],
            tau_ff=case["tau"],
            static=chain.friction,
            at_lower=p.at_lower,
            at_upper=p.at_upper,
        )
        res = vs.Solver(chain, gravity=case["g"]).solve(case["q"], case["qd"], tau_ff=case["tau"], friction=True)
        check_limit_result(
            res,
            prob,
            lambda a: pin.rnea(model, case["data"], case["pq"], case["qd"], a),
            {"enumeration": enumeration_oracle(prob), "scipy": scipy_oracle(prob)},
            f"{rcase} friction=True",
        )


# ---- infeasible: the task drives a joint into its limit ----
@pytest.mark.parametrize("seed", range(4))
def test_task_forcing_a_joint_into_its_limit_raises(seed):
    """m = n <= 3 fixes every acceleration; the target moves an on-limit joint into its limit.
    The primal is infeasible (LP margin < 0, no feasible pattern, SLSQP not certifiable) and the
    solver raises SolverError mentioning the limit."""
    rng = np.random.default_rng([seed, 95])
    n = m = int(rng.integers(1, 4))
    for _ in range(100):
        rc, q_range, _ = _random_chain_setup(rng, n)
        case = make_case(
            rng,
            rc.chain,
            rc.model,
            rc.tip_frames[-1],
            q_range,
            m,
            friction="moderate",
            task="hold",
            p_limit=0.8,
            feasible="any",
        )
        p = case["prob"]
        j = int(np.flatnonzero(p.on_limit)[0])
        if p.at_lower[j] and p.at_upper[j]:
            continue
        target = np.zeros(n)
        target[j] = (-1.0 if p.at_lower[j] else 1.0) * rng.uniform(0.5, 2.0)  # into the limit
        case["beta"] = hold_beta(
            case["model"], case["data"], case["pq"], case["qd"], case["fid"], case["alpha"], case["g"], target
        )
        prob = pinocchio_problem(
            case["model"],
            case["data"],
            case["pq"],
            case["qd"],
            tau_ff=case["tau"],
            static=case["static"],
            tip_frame=case["fid"],
            alpha=case["alpha"],
            beta=case["beta"],
            at_lower=p.at_lower,
            at_upper=p.at_upper,
        )
        break
    np.testing.assert_allclose(np.linalg.solve(prob.A, prob.b), target, atol=1e-9)
    assert limit_margin(prob) < -1e-6
    with pytest.raises(OracleInfeasible):
        enumeration_oracle(prob)
    with pytest.raises(OracleFailure):
        scipy_oracle(prob)
    with pytest.raises(vs.SolverError, match="limit"):
        solve_case(case)
    # without the limits the same task is fine
    res = solve_case(case, lower=np.full(n, -np.inf), upper=np.full(n, np.inf))
    np.testing.assert_allclose(res.qdd, target, atol=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_solver_raises_iff_primal_infeasible(seed):
    """Random partial tasks with many joints on limits: the solver raises exactly when the LP says
    no acceleration meets the task without entering a limit (samples within 1e-6 of the boundary
    are redrawn); otherwise it matches the oracles. Each seed draws one of each kind."""
    rng = np.random.default_rng([seed, 96])
    for feasible in (False, True):
        m = int(rng.integers(1, 4))
        n = int(rng.integers(m + 1, 6))
        case = random_limit_case(rng, n, m, friction=FRICTION_KINDS[seed % 4], p_limit=0.9, feasible=feasible)
        what = f"seed {seed} n {n} m {m} margin {case['margin']:.3g}"
        if feasible:
            check_case(case, what)
            continue
        with pytest.raises(OracleInfeasible):
            enumeration_oracle(case["prob"])
        with pytest.raises(vs.SolverError, match="limit"):
            solve_case(case)


# ------------------------------------------------------------------------------------------------
# Known solver bug (reported; C++ not changed here): small friction on a limit held by the task
# ------------------------------------------------------------------------------------------------
def _arm_1dof():
    """The 1-DOF arm of Vukcevic (2018): joint-axis inertia 2.25 kg m^2, revolute about z, no gravity."""
    chain = vs.Chain()
    tip = np.eye(4)
    tip[0, 3] = 1.0
    chain.add_segment("link", "rot_z", tip=tip, mass=1.0, com=[-0.5, 0, 0], inertia=np.diag([1.0, 1.0, 2.0]))
    return chain


@pytest.mark.parametrize("f", [0.0, 1e-6])
@pytest.mark.parametrize("side", ["lower", "upper"])
@pytest.mark.parametrize("push", ["into", "away"])
def test_small_friction_on_limit_held_by_task(f, side, push):
    """By hand: the task holds qdd = 0 (angular z). Pushed into the limit by 4.9 N m, friction holds f
    and the limit the rest, the motors nothing (as for f = 2 in the passing cases); pushed away, the
    limit does nothing and the motors hold 4.9 - f."""
    lower, upper = (0.0, 1.0) if side == "lower" else (-1.0, 0.0)
    into = -1.0 if side == "lower" else 1.0
    tau = 4.9 * (into if push == "into" else -into)
    alpha = np.zeros((6, 1))
    alpha[5, 0] = 1.0
    res = vs.Solver(_arm_1dof(), gravity=[0, 0, 0]).solve(
        [0.0],
        [0.0],
        alpha=alpha,
        beta=[0.0],
        tau_ff=[tau],
        friction=vs.Friction(static=[f], lower=[lower], upper=[upper], limit_tolerance=LIMIT_TOL),
    )
    friction = -f * np.sign(tau)
    limit = -(tau + friction) if push == "into" else 0.0
    assert abs(res.qdd[0]) < 1e-12
    assert res.friction_torque[0] == pytest.approx(friction, abs=1e-12)
    assert res.limit_torque[0] == pytest.approx(limit, abs=1e-12)
    assert res.tau_command[0] == pytest.approx(-(tau + friction + limit), abs=1e-12)
