"""Property-based tests (hypothesis) on random chains and random inputs.

Valid inputs: the outputs are finite and satisfy invariants derived from the mechanics, each
checked against a second, independent call rather than against the code path under test:

- command torques reproduce qdd: an unconstrained solve with ``tau_ff + tau_command`` (and, with
  friction, ``+ friction_torque + limit_torque`` on resting joints) gives back ``qdd``;
- the task is what the policy says (any ``nu`` passes the two invariants above and below, so this
  is checked too, in Pinocchio's frame accelerations): per eigen-direction ``v_k`` of the coupling
  matrix ``K = A H^-1 A^T`` (``A = alpha^T J``, Pinocchio's ``crba`` and frame Jacobian), the
  residual ``e = alpha^T a_N - beta`` has ``v_k . e = 0`` where ``lambda_k`` is kept (the task met,
  or least-squares optimal when rank-deficient or conflicting), ``v_k . e = v_k . r`` where it is
  dropped, and ``d^2 / (lambda_k^2 + d^2) v_k . r`` with damping ``d``, ``r`` the unconstrained
  robot's residual (``pin.aba``);
- friction complementarity: resting joints get ``|friction| <= f``; a sticking joint has
  ``qdd = 0``, a slipping one the full ``-f sign(qdd)``; moving joints ``-fk sign(qd)``;
- energy identity (no gravity, no external force): the power of all generalised forces equals
  the rate of change of kinetic energy, ``d/dt (1/2 qd^T H qd) = qd . (tau_ff + tau_command)``,
  with ``H`` the inverse of the unconstrained response columns and the derivative taken by central
  differences along the solved motion.

Invalid inputs (wrong shapes, NaN/Inf, strings, ragged lists, None, bad chain parameters): a
``vereshchagin.SolverError`` (a ValueError) or a valid result, never another exception or a crash.

Examples are derandomised so that CI is reproducible; the drawn seed and sizes are printed by
hypothesis on failure.
"""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

import vereshchagin as vs
from support.chains import (
    G_EARTH,
    fext_to_pinocchio,
    frame_jacobian,
    random_alpha,
    random_chain,
    random_f_ext,
    random_state,
)

SETTINGS = settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

# The replays are exact algebra (ABA of the total torque); measured worst relative error over the
# derandomised examples: 2.8e-14 (command torques), 1.8e-12 (friction and limit torques).
REPLAY_RTOL = 1e-9

chain_params = st.fixed_dictionaries(
    {
        "seed": st.integers(0, 2**32 - 1),
        "n": st.integers(1, 8),
        "prismatic": st.booleans(),
        "fixed_prob": st.sampled_from([0.0, 0.2, 0.5]),
    }
)


def make(params):
    rng = np.random.default_rng(params["seed"])
    rc = random_chain(rng, params["n"], prismatic=params["prismatic"], fixed_prob=params["fixed_prob"])
    return rng, rc


def dependent_alpha(rng, m, dependent):
    """(6, m) unit columns; with ``dependent`` the last column duplicates or combines earlier ones."""
    alpha = random_alpha(rng, m)
    if dependent and m >= 2:
        c = rng.normal(size=m - 1)
        last = alpha[:, :-1] @ c
        alpha[:, -1] = last / np.linalg.norm(last)
    return alpha


def assert_finite(res, *names):
    for name in names:
        value = np.asarray(getattr(res, name), dtype=float)
        assert np.all(np.isfinite(value)), f"{name} not finite: {value}"


def close(a, b, rtol):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, np.abs(b).max(initial=0.0))
    return np.abs(a - b).max(initial=0.0) <= rtol * scale


def task_residual(rc, q, qd, qdd, alpha, beta, g):
    """alpha^T a_N - beta at qdd, a_N Pinocchio's LWA acceleration of the last tip plus [-g; 0]."""
    data = rc.data()
    pin.forwardKinematics(rc.model, data, q, qd, qdd)
    pin.updateFramePlacements(rc.model, data)
    acc = pin.getFrameAcceleration(rc.model, data, rc.tip_frames[-1], pin.LOCAL_WORLD_ALIGNED).vector
    return alpha.T @ (acc + np.concatenate([-np.asarray(g, float), np.zeros(3)])) - beta


def assert_task_policy(rc, q, qd, tau, f_ext, alpha, beta, res, g=G_EARTH, damping=None, rcond=1e-12):
    """The task residual per eigen-direction of K is what the singularity policy prescribes.

    Tolerance: 1e-9 x scale x lambda_max / lambda_k per direction (the solve's conditioning along
    it), with lambda_k the smallest kept eigenvalue for dropped directions. The cut rcond * max(lambda_max, kappa) is only bracketed (kappa >= trace K is internal to
    the solver), so directions between rcond * lambda_max and 1e-6 lambda_max are not judged.
    """
    g = np.asarray(g, float)
    rc.model.gravity = pin.Motion(np.concatenate([g, np.zeros(3)]))
    data = rc.data()
    fext = fext_to_pinocchio(rc, data, q, f_ext if f_ext is not None else np.zeros((rc.n_segments, 6)))
    free = pin.aba(rc.model, data, q, qd, tau, fext)
    r = task_residual(rc, q, qd, free, alpha, beta, g)
    e = task_residual(rc, q, qd, res.qdd, alpha, beta, g)
    M = np.array(pin.crba(rc.model, data, q))
    M = np.triu(M) + np.triu(M, 1).T
    A = alpha.T @ frame_jacobian(rc, data, q)
    lam, V = np.linalg.eigh(A @ np.linalg.solve(M, A.T))
    lmax = max(lam.max(), 0.0)
    if lmax == 0.0:  # no joint can move the task: nothing is dropped or met, e = r
        assert np.allclose(e, r, rtol=1e-9, atol=1e-9)
        return
    scale = max(1.0, np.linalg.norm(r), np.linalg.norm(beta))
    lam_kept = lam[lam > 1e-6 * lmax].min()  # the conditioning of the solve along what it keeps
    for lam_k, v in zip(lam, V.T):
        if damping is not None:
            if lam_k < 1e-6 * lmax:
                continue  # the damped multiplier there amplifies K's round-off
            want = damping**2 / (lam_k**2 + damping**2) * (v @ r)
        elif lam_k > 1e-6 * lmax:
            want = 0.0  # kept (the cut rcond * max(lmax, kappa) is far below): met, or least-squares optimal
        elif lam_k < rcond * lmax:
            want = v @ r  # dropped (the cut is at least rcond * lmax): the unconstrained residual stays
        else:
            continue
        tol = 1e-9 * scale * lmax / max(lam_k, lam_kept)
        assert abs(v @ e - want) <= tol, (lam_k, lmax, v @ e, want, tol)


# ------------------------------------------------------------------------------------------------
# Valid inputs
# ------------------------------------------------------------------------------------------------
@SETTINGS
@given(params=chain_params, m=st.integers(0, 6), dependent=st.booleans(), damped=st.booleans(), with_fext=st.booleans())
def test_command_torques_reproduce_qdd(params, m, dependent, damped, with_fext):
    rng, rc = make(params)
    q, qd = random_state(rng, rc)
    tau = rng.normal(size=rc.n_joints)
    f_ext = random_f_ext(rng, rc) if with_fext else None
    alpha = dependent_alpha(rng, m, dependent) if m else None
    beta = rng.normal(size=m) * 3.0 if m else None
    kw = dict(damping=1e-8) if damped else {}
    res = vs.Solver(rc.chain, **kw).solve(q, qd, alpha, beta, f_ext, tau)
    assert_finite(res, "qdd", "tau_command", "nu", "link_acc", "smallest_singular_value")
    assert 0 <= res.constraint_rank <= m
    if dependent and m >= 2:
        assert res.constraint_rank < m
    free = vs.Solver(rc.chain).solve(q, qd, f_ext=f_ext, tau_ff=tau + res.tau_command)
    assert close(free.qdd, res.qdd, REPLAY_RTOL), (free.qdd, res.qdd)
    if m:  # the replay holds for any nu: the task decides which one
        assert_task_policy(rc, q, qd, tau, f_ext, alpha, beta, res, damping=1e-8 if damped else None)


@SETTINGS
@given(
    params=chain_params,
    m=st.integers(0, 3),
    rest_mask=st.lists(st.booleans(), min_size=8, max_size=8),
    friction_scale=st.sampled_from([0.0, 0.1, 1.0, 10.0, 1e6]),
    kinetic_ratio=st.floats(0.0, 1.0),
    with_limits=st.booleans(),
)
def test_friction_complementarity(params, m, rest_mask, friction_scale, kinetic_ratio, with_limits):
    rng, rc = make(params)
    n = rc.n_joints
    q, qd = random_state(rng, rc)
    qd[np.array(rest_mask[:n])] = 0.0
    tau = rng.normal(size=n) * 2.0
    fs = rng.uniform(0.0, 1.0, n) * friction_scale
    fk = fs * kinetic_ratio
    lower = upper = None
    if with_limits:  # some resting joints exactly on a limit
        lower = np.where(rng.random(n) < 0.3, q, -np.inf)
        upper = np.where(rng.random(n) < 0.3, q + np.where(np.isfinite(lower), 0.5, 0.0), np.inf)
    alpha = random_alpha(rng, m) if m else None
    beta = rng.normal(size=m) if m else None
    fr = vs.Friction(static=fs, kinetic=fk, lower=lower, upper=upper)
    try:
        res = vs.Solver(rc.chain).solve(q, qd, alpha, beta, tau_ff=tau, friction=fr)
    except vs.SolverError as e:
        # the only documented failure of a valid friction problem: a task pushing into a limit
        assert "limit" in str(e), str(e)
        event("task drives a joint into its limit")
        return
    event("solved")
    assert_finite(res, "qdd", "tau_command", "nu", "friction_torque", "limit_torque", "link_acc")
    assert np.isfinite(res.gauss_value)
    acc_scale = max(1.0, np.abs(res.qdd).max())
    for j in range(n):
        f, qdd_j = res.friction_torque[j], res.qdd[j]
        if qd[j] != 0.0:
            assert res.status[j] == 0
            assert f == pytest.approx(-fk[j] * np.sign(qd[j]), rel=1e-12, abs=0.0)
            continue
        assert abs(f) <= fs[j] * (1 + 1e-12)
        if res.status[j] == 1:  # stick
            assert abs(qdd_j) <= 1e-9 * acc_scale
        elif res.limit_torque[j] == 0.0:  # slipping freely: full friction against the motion
            assert res.status[j] in (2, 3)
            assert f == pytest.approx(-fs[j] * np.sign(qdd_j), rel=1e-9, abs=1e-12)
    # The equations of motion in torque space, to the size of the torques that are summed: friction
    # up to 1e6 N m cancels against the constraint forces, so a replay through a free solve would
    # lose about eps * 1e6 * |H^-1| of qdd to rounding alone.
    terms = (tau, res.tau_command, res.friction_torque, res.limit_torque)
    torque_scale = max(1.0, max(np.abs(t).max(initial=0.0) for t in terms))
    needed = rc.chain.inverse_dynamics(q, qd, res.qdd)
    assert np.abs(needed - sum(terms)).max() <= REPLAY_RTOL * torque_scale, (needed, sum(terms))


def _kinetic_energy(solver, n, q, qd):
    solver.solve(q, qd)
    G, _ = solver.response_columns(list(range(n)))  # = H^-1 without constraints
    H = np.linalg.inv(G)
    return 0.5 * qd @ H @ qd


@SETTINGS
@given(params=chain_params, m=st.integers(0, 4))
def test_power_balance(params, m):
    rng, rc = make(params)
    n = rc.n_joints
    q, qd = random_state(rng, rc, qd_scale=1.0)
    tau = rng.normal(size=n)
    alpha = random_alpha(rng, m) if m else None
    beta = rng.normal(size=m) if m else None
    res = vs.Solver(rc.chain, gravity=[0.0, 0.0, 0.0]).solve(q, qd, alpha, beta, tau_ff=tau)
    probe = vs.Solver(rc.chain, gravity=[0.0, 0.0, 0.0])  # unconstrained: its columns are H^-1
    probe.solve(q, qd)
    assume(np.linalg.cond(probe.response_columns(list(range(n)))[0]) < 1e8)
    h = 1e-5
    T = [_kinetic_energy(probe, n, q + s * qd + 0.5 * s * s * res.qdd, qd + s * res.qdd) for s in (-h, h)]
    dTdt = (T[1] - T[0]) / (2 * h)
    power = qd @ (tau + res.tau_command)
    T0 = _kinetic_energy(probe, n, q, qd)
    scale = max(1.0, abs(power), T0, np.abs(qd).max() * np.abs(tau + res.tau_command).max())
    assert abs(dTdt - power) <= 1e-6 * scale, (dTdt, power)
    if m:  # the balance holds for any nu: the task decides which one
        assert_task_policy(rc, q, qd, tau, None, alpha, beta, res, g=np.zeros(3))


# ------------------------------------------------------------------------------------------------
# Invalid (and valid) arbitrary inputs: SolverError or a finite result, never anything else
# ------------------------------------------------------------------------------------------------
def junk(n_hint):
    floats = st.floats(allow_nan=True, allow_infinity=True)
    sizes = st.sampled_from([0, 1, n_hint - 1, n_hint, n_hint + 1, 6, 7])
    arrays = st.builds(
        lambda k, data: np.asarray(data[:k] + [0.0] * max(0, k - len(data))), sizes, st.lists(floats, max_size=8)
    )
    matrices = st.builds(lambda r, c, x: np.full((r, c), x), sizes, sizes, floats)
    return st.one_of(
        st.none(),
        floats,
        arrays,
        matrices,
        st.text(max_size=3),
        st.lists(st.lists(floats, max_size=3), max_size=3),  # possibly ragged
        st.sampled_from([object(), {"a": 1}, [None, 1.0], b"xy", True]),
    )


@settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_arbitrary_solve_arguments(data):
    rng = np.random.default_rng(3)
    rc = random_chain(rng, 4, fixed_prob=0.3)
    n = rc.n_joints
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    args = {"q": q, "qd": qd, "alpha": None, "beta": None, "f_ext": None, "tau_ff": None}
    for name in data.draw(st.lists(st.sampled_from(sorted(args)), min_size=1, max_size=3, unique=True)):
        args[name] = data.draw(junk(n), label=name)
    friction = data.draw(
        st.one_of(
            st.none(),
            st.just(True),
            st.fixed_dictionaries(dict(static=junk(n), kinetic=junk(n), velocity_tolerance=junk(n))),
        ),
        label="friction",
    )
    try:  # a Friction with bad arrays raises when it is made, the solve when the sizes do not fit
        if isinstance(friction, dict):
            friction = vs.Friction(**friction)
        res = solver.solve(friction=friction, **args)
    except vs.SolverError as e:
        assert str(e)
    else:
        assert_finite(res, "qdd", "tau_command", "nu", "link_acc")
    # the solver stays usable
    np.testing.assert_array_equal(solver.solve(q, qd).qdd, vs.Solver(rc.chain).solve(q, qd).qdd)


@settings(max_examples=200, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_arbitrary_chain_parameters(data):
    chain = vs.Chain()
    num = st.one_of(st.floats(-1e3, 1e3), st.sampled_from([0.0, -0.0, 1e-300, 1e300, np.nan, np.inf, -1.0]))
    for k in range(data.draw(st.integers(1, 4))):
        kw = dict(
            name=f"s{k}",
            joint=data.draw(st.sampled_from(["rot_x", "rot_z", "trans_y", "fixed", "bogus"])),
            mass=data.draw(num),
            rotor_inertia=data.draw(num),
            com=data.draw(st.lists(num, min_size=3, max_size=3)),
            inertia=np.diag(data.draw(st.lists(num, min_size=3, max_size=3))),
            tip=data.draw(st.sampled_from([None, np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0])])),
        )
        try:
            chain.add_segment(**kw)
        except vs.SolverError as e:
            assert str(e)
    try:
        solver = vs.Solver(chain)
    except vs.SolverError as e:
        assert str(e)
        return
    n = chain.n_joints
    try:
        res = solver.solve(np.full(n, 0.3), np.full(n, 0.1), tau_ff=np.ones(n))
    except vs.SolverError as e:
        assert str(e)
    else:
        assert_finite(res, "qdd", "tau_command", "link_acc")
