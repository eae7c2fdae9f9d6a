"""The Python API: result types and shapes, batch solving, input validation, singular tasks,
copy semantics, threads and determinism. Expected values are hand-derived or come from other
calls' documented relations, never from the code path under test alone."""

import concurrent.futures
import gc
import threading

import numpy as np
import pytest

import vereshchagin as vs
from support.chains import (
    G_EARTH,
    assert_close,
    build,
    planar_rot_z_links,
    homogeneous,
    random_alpha,
    random_chain,
    random_f_ext,
    random_state,
)
from support.dense_oracle import dense_task


# ------------------------------------------------------------------------------------------------
# Helpers
# ------------------------------------------------------------------------------------------------
def planar_arm(lengths=(1.0, 1.0), mass=1.0):
    """Planar arm of rot_z joints with links along x (fully stretched at q = 0). Each link's centre
    of mass is at its middle, i.e. at -L/2 along x in its tip frame (KDL inertias are in the tip
    frame)."""
    chain = vs.Chain()
    for k, L in enumerate(lengths):
        chain.add_segment(
            f"link{k}",
            "rot_z",
            tip=homogeneous(None, [L, 0.0, 0.0]),
            mass=mass,
            com=[-L / 2, 0.0, 0.0],
            inertia=np.diag([1e-3, mass * L * L / 12, mass * L * L / 12]),
        )
    return chain


def sample(seed=0, n=6, fixed_prob=0.3):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, n, fixed_prob=fixed_prob)
    return rng, rc


def assert_results_equal(a, b):
    for name in ("qdd", "tau_command", "nu", "link_acc"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.constraint_rank == b.constraint_rank
    assert a.smallest_singular_value == b.smallest_singular_value or (
        np.isnan(a.smallest_singular_value) and np.isnan(b.smallest_singular_value)
    )


def assert_error(fn, *names):
    """fn() raises vs.SolverError (a ValueError) whose message names every string in names."""
    with pytest.raises(vs.SolverError) as ei:
        fn()
    assert isinstance(ei.value, ValueError)
    msg = str(ei.value)
    for name in names:
        assert name in msg, f"{name!r} not in error message {msg!r}"
    return msg


# ------------------------------------------------------------------------------------------------
# Result types and shapes
# ------------------------------------------------------------------------------------------------
def test_error_type_is_value_error():
    assert issubclass(vs.SolverError, ValueError)


@pytest.mark.parametrize("m", range(0, 7))
def test_result_shapes_and_types(m):
    rng, rc = sample(1, n=7, fixed_prob=0.4)
    assert rc.n_segments > rc.n_joints  # fixed segments present: the two counts differ
    solver = vs.Solver(rc.chain)
    assert solver.n_joints == rc.n_joints and solver.n_segments == rc.n_segments
    q, qd = random_state(rng, rc)
    alpha = random_alpha(rng, m) if m else None
    beta = rng.normal(size=m) if m else None
    res = solver.solve(q, qd, alpha, beta, f_ext=random_f_ext(rng, rc), tau_ff=rng.normal(size=rc.n_joints))
    n, ns = rc.n_joints, rc.n_segments
    for name, shape in (("qdd", (n,)), ("tau_command", (n,)), ("nu", (m,)), ("link_acc", (ns + 1, 6))):
        arr = getattr(res, name)
        assert isinstance(arr, np.ndarray), name
        assert arr.dtype == np.float64, name
        assert arr.shape == shape, name
        assert np.all(np.isfinite(arr)), name
    assert type(res.constraint_rank) is int
    assert 0 <= res.constraint_rank <= m
    assert isinstance(res.smallest_singular_value, float)
    assert res.smallest_singular_value >= 0.0


def test_result_arrays_are_independent_copies():
    rng, rc = sample(2)
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    a = solver.solve(q, qd)
    keep = a.qdd.copy(), a.link_acc.copy()
    q2, qd2 = random_state(rng, rc)
    solver.solve(q2, qd2)  # must not overwrite the arrays of the first result
    np.testing.assert_array_equal(a.qdd, keep[0])
    np.testing.assert_array_equal(a.link_acc, keep[1])


def test_inputs_are_not_modified():
    rng, rc = sample(3)
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    alpha, beta = random_alpha(rng, 3), rng.normal(size=3)
    f, tau = random_f_ext(rng, rc), rng.normal(size=rc.n_joints)
    copies = [x.copy() for x in (q, qd, alpha, beta, f, tau)]
    solver.solve(q, qd, alpha, beta, f, tau)
    for x, c in zip((q, qd, alpha, beta, f, tau), copies):
        np.testing.assert_array_equal(x, c)


def test_chain_properties():
    chain = vs.Chain()
    chain.add_segment("a", "rot_z", mass=1.0, com=[0.5, 0, 0], inertia=np.eye(3) * 0.01)
    chain.add_segment("b", vs.Joint.fixed(), mass=1.0)
    chain.add_segment("c", vs.Joint.revolute([1, 1, 0], [0, 0, 0.1]), mass=1.0, com=[0, 0.3, 0], joint_name="elbow")
    assert chain.n_joints == 2 and chain.n_segments == 3
    assert chain.segment_names == ["a", "b", "c"]
    assert chain.joint_names == ["a_joint", "elbow"]


def test_alpha_vector_is_one_constraint():
    rng, rc = sample(4)
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    a = random_alpha(rng, 1)
    r1 = solver.solve(q, qd, a, [0.3])
    r2 = solver.solve(q, qd, a[:, 0], [0.3])
    assert_results_equal(r1, r2)


def test_any_array_layout_and_int_inputs():
    rng, rc = sample(5)
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    alpha, beta = random_alpha(rng, 3), rng.normal(size=3)
    f = random_f_ext(rng, rc)
    ref = solver.solve(q, qd, alpha, beta, f)
    res = solver.solve(list(q), tuple(qd), np.asfortranarray(alpha), list(beta), np.asfortranarray(f))
    assert_results_equal(ref, res)
    big = np.zeros((rc.n_segments, 12))
    big[:, ::2] = f  # strided view
    res = solver.solve(q, qd, alpha.T.copy().T, beta, big[:, ::2])
    assert_results_equal(ref, res)
    # integer arrays are numbers too
    a = solver.solve(np.zeros(rc.n_joints, dtype=int), np.ones(rc.n_joints, dtype=np.int32))
    b = solver.solve(np.zeros(rc.n_joints), np.ones(rc.n_joints))
    assert_results_equal(a, b)


# ------------------------------------------------------------------------------------------------
# Gravity and the documented sign conventions, by hand
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("g", [[0.0, 0.0, -9.81], [0.0, 0.0, 0.0], [1.0, -2.0, 3.5]])
def test_link_acc_base_row_is_minus_gravity(g):
    rng, rc = sample(6)
    solver = vs.Solver(rc.chain, gravity=g)
    np.testing.assert_array_equal(solver.gravity, g)
    q, qd = random_state(rng, rc)
    res = solver.solve(q, qd)
    np.testing.assert_array_equal(res.link_acc[0], np.r_[-np.array(g), 0.0, 0.0, 0.0])


def test_default_gravity_and_gravity_setter():
    rng, rc = sample(7)
    solver = vs.Solver(rc.chain)
    np.testing.assert_array_equal(solver.gravity, G_EARTH)
    q, qd = random_state(rng, rc)
    np.testing.assert_array_equal(solver.solve(q, qd).link_acc[0], [0, 0, 9.81, 0, 0, 0])
    solver.gravity = [0.0, 3.0, 0.0]
    np.testing.assert_array_equal(solver.gravity, [0.0, 3.0, 0.0])
    np.testing.assert_array_equal(solver.solve(q, qd).link_acc[0], [0, -3.0, 0, 0, 0, 0])
    other = vs.Solver(rc.chain, gravity=[0.0, 3.0, 0.0])
    assert_results_equal(solver.solve(q, qd), other.solve(q, qd))
    assert_error(lambda: setattr(solver, "gravity", [0.0, np.inf, 0.0]), "gravity")


def test_hold_weight_with_vertical_slider():
    """A mass on a vertical prismatic joint: beta = 9.81 along z holds it (qdd = 0), the motor
    must supply m g, and the constraint wrench on the body (-alpha nu) is +m g along z."""
    mass = 2.5
    chain = vs.Chain()
    chain.add_segment("slider", "trans_z", mass=mass, inertia=np.eye(3) * 0.1)
    solver = vs.Solver(chain)
    alpha = np.array([0, 0, 1.0, 0, 0, 0])
    hold = solver.solve([0.2], [0.0], alpha, [9.81])
    assert hold.qdd[0] == pytest.approx(0.0, abs=1e-12)
    assert hold.nu[0] == pytest.approx(-mass * 9.81, rel=1e-12)
    assert hold.tau_command[0] == pytest.approx(mass * 9.81, rel=1e-12)
    assert hold.link_acc[-1][2] == pytest.approx(9.81, rel=1e-12)
    fall = solver.solve([0.2], [0.0], alpha, [0.0])
    assert fall.qdd[0] == pytest.approx(-9.81, rel=1e-12)
    assert fall.nu[0] == pytest.approx(0.0, abs=1e-12)
    free = solver.solve([0.2], [0.0])
    assert free.qdd[0] == pytest.approx(-9.81, rel=1e-12)
    # f_ext pushes the body up: base axes, applied to the segment
    pushed = solver.solve([0.2], [0.0], f_ext=[[0, 0, mass * 9.81, 0, 0, 0]])
    assert pushed.qdd[0] == pytest.approx(0.0, abs=1e-12)
    # rotor inertia adds to the diagonal: (m + r) qdd = tau - m g
    chain2 = vs.Chain()
    chain2.add_segment("slider", "trans_z", mass=mass, rotor_inertia=0.5)
    res = vs.Solver(chain2).solve([0.0], [0.0], tau_ff=[10.0])
    assert res.qdd[0] == pytest.approx((10.0 - mass * 9.81) / (mass + 0.5), rel=1e-12)


# ------------------------------------------------------------------------------------------------
# solve_batch
# ------------------------------------------------------------------------------------------------
def _loop(solver, Q, QD, alpha=None, beta=None, f=None, tau=None, per_row=()):
    out = []
    for b in range(len(Q)):
        pick = lambda name, x, b=b: (x[b] if name in per_row else x) if x is not None else None  # noqa: E731
        out.append(solver.solve(Q[b], QD[b], pick("alpha", alpha), pick("beta", beta), pick("f", f), pick("tau", tau)))
    return out


def _compare_batch(batch, loop, m):
    B = len(loop)
    assert isinstance(batch, vs.BatchResult)
    n = loop[0].qdd.shape[0]
    assert batch.qdd.shape == (B, n) and batch.tau_command.shape == (B, n)
    assert batch.nu.shape == (B, m)
    assert batch.link_acc.shape == (B,) + loop[0].link_acc.shape
    assert batch.constraint_rank.shape == (B,) and np.issubdtype(batch.constraint_rank.dtype, np.integer)
    assert batch.smallest_singular_value.shape == (B,)
    for b, r in enumerate(loop):
        np.testing.assert_allclose(batch.qdd[b], r.qdd, rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(batch.tau_command[b], r.tau_command, rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(batch.nu[b, : r.nu.size], r.nu, rtol=1e-13, atol=1e-13)
        assert np.all(np.isnan(batch.nu[b, r.nu.size :]))
        np.testing.assert_allclose(batch.link_acc[b], r.link_acc, rtol=1e-13, atol=1e-13)
        assert batch.constraint_rank[b] == r.constraint_rank
        assert batch.smallest_singular_value[b] == pytest.approx(r.smallest_singular_value, rel=1e-13, abs=1e-300)


def _batch_inputs(rng, rc, B):
    Q = np.array([random_state(rng, rc)[0] for _ in range(B)])
    QD = rng.uniform(-2, 2, (B, rc.n_joints))
    return Q, QD


@pytest.mark.parametrize("m", [0, 1, 4, 6])
def test_solve_batch_shared_arguments(m):
    rng, rc = sample(8, n=7)
    solver = vs.Solver(rc.chain)
    Q, QD = _batch_inputs(rng, rc, 9)
    alpha = random_alpha(rng, m) if m else None
    beta = rng.normal(size=m) if m else None
    f = random_f_ext(rng, rc)
    tau = rng.normal(size=rc.n_joints)
    batch = solver.solve_batch(Q, QD, alpha, beta, f, tau)
    _compare_batch(batch, _loop(vs.Solver(rc.chain), Q, QD, alpha, beta, f, tau), m)


@pytest.mark.parametrize("m", [1, 3, 6])
def test_solve_batch_per_row_arguments(m):
    rng, rc = sample(9, n=7)
    solver = vs.Solver(rc.chain)
    B = 7  # == n_joints, to catch axis confusions
    Q, QD = _batch_inputs(rng, rc, B)
    alpha = np.array([random_alpha(rng, m) for _ in range(B)])
    beta = rng.normal(size=(B, m))
    f = rng.normal(size=(B, rc.n_segments, 6))
    tau = rng.normal(size=(B, rc.n_joints))
    batch = solver.solve_batch(Q, QD, alpha, beta, f, tau)
    _compare_batch(
        batch, _loop(vs.Solver(rc.chain), Q, QD, alpha, beta, f, tau, per_row=("alpha", "beta", "f", "tau")), m
    )
    # mixed: shared alpha, per-row beta; per-row f_ext, shared tau_ff
    batch = solver.solve_batch(Q, QD, alpha[0], beta, f, tau[0])
    _compare_batch(batch, _loop(vs.Solver(rc.chain), Q, QD, alpha[0], beta, f, tau[0], per_row=("beta", "f")), m)


def test_solve_batch_single_row_and_leaves_solver_usable():
    rng, rc = sample(10)
    solver = vs.Solver(rc.chain)
    Q, QD = _batch_inputs(rng, rc, 1)
    batch = solver.solve_batch(Q, QD)
    ref = vs.Solver(rc.chain).solve(Q[0], QD[0])
    np.testing.assert_allclose(batch.qdd[0], ref.qdd, rtol=1e-13, atol=1e-13)
    assert batch.nu.shape == (1, 0)
    # response_columns afterwards refers to the last row solved
    dq, _ = solver.response_columns([0])
    ref_solver = vs.Solver(rc.chain)
    ref_solver.solve(Q[0], QD[0])
    np.testing.assert_allclose(dq, ref_solver.response_columns([0])[0], rtol=1e-13, atol=1e-15)


def test_solve_batch_errors():
    rng, rc = sample(11)
    solver = vs.Solver(rc.chain)
    n = rc.n_joints
    Q, QD = _batch_inputs(rng, rc, 4)
    assert_error(lambda: solver.solve_batch(Q, QD[:3]), "qd", "axis 0", "3 rows")
    assert_error(lambda: solver.solve_batch(Q[:, :-1], QD[:, :-1]), "q")
    bad = QD.copy()
    bad[2, 1] = np.nan
    assert_error(lambda: solver.solve_batch(Q, bad), "row 2", "qd")
    alpha = np.array([random_alpha(rng, 2) for _ in range(3)])  # wrong batch length
    assert_error(lambda: solver.solve_batch(Q, QD, alpha, rng.normal(size=(4, 2))), "alpha")
    assert_error(lambda: solver.solve_batch(Q, QD, None, None, None, np.zeros((3, n))), "tau_ff")
    assert_error(lambda: solver.solve_batch(Q, QD, None, None, np.zeros((4, rc.n_segments, 5))), "f_ext")
    # ragged alphas cannot be a batch
    assert_error(
        lambda: solver.solve_batch(Q[:2], QD[:2], [np.eye(6)[:, :1], np.eye(6)[:, :2]], [[0.0], [0.0, 0.0]]), "alpha"
    )


# ------------------------------------------------------------------------------------------------
# Input validation
# ------------------------------------------------------------------------------------------------
def _solve_kwargs(rc):
    n, ns = rc.n_joints, rc.n_segments
    return dict(
        q=np.zeros(n),
        qd=np.zeros(n),
        alpha=np.eye(6)[:, :2],
        beta=np.zeros(2),
        f_ext=np.zeros((ns, 6)),
        tau_ff=np.zeros(n),
    )


BAD_SOLVE_INPUTS = [
    ("q", dict(q="n1"), "q"),
    ("q", dict(q="col"), "q"),
    ("q", dict(q="short"), "q"),
    ("q", dict(q="2d"), "q"),
    ("qd", dict(qd="short"), "qd"),
    ("qd", dict(qd="col"), "qd"),
    ("alpha", dict(alpha=np.zeros((5, 1)), beta=np.zeros(1)), "alpha"),
    ("alpha", dict(alpha=np.zeros((6, 7)), beta=np.zeros(7)), "alpha"),
    ("alpha", dict(alpha=np.zeros((1, 6)), beta=np.zeros(6)), "alpha"),
    ("alpha", dict(alpha=np.zeros((6, 2, 1)), beta=np.zeros(2)), "alpha"),
    ("beta", dict(beta=np.zeros(3)), "beta"),
    ("beta", dict(beta=np.zeros((2, 1))), "beta"),
    ("beta", dict(beta=None), "beta"),
    ("beta", dict(alpha=None), "beta"),
    ("f_ext", dict(f_ext="transposed"), "f_ext"),
    ("f_ext", dict(f_ext="short"), "f_ext"),
    ("f_ext", dict(f_ext=np.zeros(6)), "f_ext"),
    ("tau_ff", dict(tau_ff="short"), "tau_ff"),
    ("tau_ff", dict(tau_ff="col"), "tau_ff"),
]


def _materialise(rc, kwargs):
    n, ns = rc.n_joints, rc.n_segments
    special = {
        "n1": np.zeros(n + 1),
        "col": np.zeros((n, 1)),
        "short": np.zeros(max(n - 1, 0)),
        "2d": np.zeros((1, n)),
        "transposed": np.zeros((6, ns)),
    }
    out = {}
    for k, v in kwargs.items():
        if isinstance(v, str) and k in ("f_ext",) and v == "short":
            out[k] = np.zeros((ns - 1, 6))
        elif isinstance(v, str):
            out[k] = special[v]
        else:
            out[k] = v
    return out


@pytest.mark.parametrize("label,bad,name", BAD_SOLVE_INPUTS)
def test_bad_shapes_raise(label, bad, name):
    rng, rc = sample(12, n=5, fixed_prob=0.3)
    assert rc.n_segments != 6  # keeps the transposed f_ext case unambiguous
    solver = vs.Solver(rc.chain)
    kw = _solve_kwargs(rc)
    kw.update(_materialise(rc, bad))
    assert_error(lambda: solver.solve(**kw), name)
    assert_error(
        lambda: solver.solve_batch(
            *[
                np.asarray(kw[k])[None] if k in ("q", "qd") else kw[k]
                for k in ("q", "qd", "alpha", "beta", "f_ext", "tau_ff")
            ]
        ),
        name,
    )


@pytest.mark.parametrize("name", ["q", "qd", "alpha", "beta", "f_ext", "tau_ff"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_inputs_raise(name, value):
    rng, rc = sample(13, n=4)
    solver = vs.Solver(rc.chain)
    kw = _solve_kwargs(rc)
    arr = np.array(kw[name], dtype=float)
    arr.flat[arr.size - 1] = value
    kw[name] = arr
    assert_error(lambda: solver.solve(**kw), name)


@pytest.mark.parametrize("name", ["q", "qd", "alpha", "beta", "f_ext", "tau_ff"])
@pytest.mark.parametrize("kind", ["str", "object", "string"])
def test_non_numeric_inputs_raise(name, kind):
    rng, rc = sample(14, n=4)
    solver = vs.Solver(rc.chain)
    kw = _solve_kwargs(rc)
    shape = np.shape(kw[name])
    if kind == "str":
        bad = np.full(shape, "x", dtype=object).tolist()
    elif kind == "object":
        bad = np.full(shape, None, dtype=object)
        bad.flat[0] = object()
        bad = bad.tolist()
    else:
        bad = "abc"
    kw[name] = bad
    assert_error(lambda: solver.solve(**kw), name)


def test_error_leaves_previous_solution_usable():
    rng, rc = sample(15)
    solver = vs.Solver(rc.chain)
    q, qd = random_state(rng, rc)
    ref = solver.solve(q, qd, tau_ff=np.ones(rc.n_joints))
    cols = solver.response_columns([0])
    with pytest.raises(vs.SolverError):
        solver.solve(q, np.full(rc.n_joints, np.nan))
    again = solver.solve(q, qd, tau_ff=np.ones(rc.n_joints))
    assert_results_equal(ref, again)
    np.testing.assert_array_equal(solver.response_columns([0])[0], cols[0])


# Chain construction -----------------------------------------------------------------------------
def _rot_with_det_minus_one():
    T = np.eye(4)
    T[2, 2] = -1.0
    return T


BAD_SEGMENTS = [
    (dict(joint="rot_w"), "rot_w"),
    (dict(joint="ROT_Z"), "ROT_Z"),
    (dict(joint=3), "joint"),
    (dict(tip=_rot_with_det_minus_one()), "tip"),
    (dict(tip=np.diag([2.0, 1.0, 1.0, 1.0])), "tip"),
    (dict(tip=homogeneous(np.array([[1.0, 0.1, 0], [0, 1, 0], [0, 0, 1]]))), "tip"),
    (dict(tip=np.eye(3)), "tip"),
    (dict(tip=np.vstack([np.eye(4)[:3], [0, 0, 1.0, 1.0]])), "tip"),
    (dict(tip=np.full((4, 4), np.nan)), "tip"),
    (dict(tip="abc"), "tip"),
    (dict(mass=-1.0), "mass"),
    (dict(mass=np.nan), "mass"),
    (dict(mass=np.inf), "mass"),
    (dict(com=[0.0, 0.0]), "com"),
    (dict(com=[np.nan, 0.0, 0.0]), "com"),
    (dict(inertia=np.diag([1.0, -0.5, 1.0])), "inertia"),
    (dict(inertia=np.array([[1.0, 0.2, 0], [0, 1, 0], [0, 0, 1]])), "inertia"),
    (dict(inertia=np.array([[1.0, 2.0, 0], [2.0, 1, 0], [0, 0, 1]])), "inertia"),  # symmetric, indefinite
    (dict(inertia=np.eye(2)), "inertia"),
    (dict(inertia=np.diag([np.inf, 1.0, 1.0])), "inertia"),
    (dict(rotor_inertia=-0.1), "rotor_inertia"),
    (dict(rotor_inertia=np.nan), "rotor_inertia"),
]


@pytest.mark.parametrize("bad,name", BAD_SEGMENTS)
def test_bad_segment_raises(bad, name):
    chain = vs.Chain()
    kw = dict(name="s", joint="rot_z", tip=np.eye(4), mass=1.0, com=[0.1, 0.0, 0.0], inertia=np.eye(3) * 0.1)
    kw.update(bad)
    assert_error(lambda: chain.add_segment(**kw), name)
    assert chain.n_segments == 0  # nothing half-added


def test_fixed_joint_with_rotor_inertia_raises():
    assert_error(lambda: vs.Chain().add_segment("s", vs.Joint.fixed(), mass=1.0, rotor_inertia=0.1), "rotor")


@pytest.mark.parametrize("make", [vs.Joint.revolute, vs.Joint.prismatic])
def test_bad_joint_axis_raises(make):
    assert_error(lambda: make([0.0, 0.0, 0.0]), "axis")
    assert_error(lambda: make([0.0, 0.0, 1e-300]), "axis")
    assert_error(lambda: make([0.0, 1.0]), "axis")
    assert_error(lambda: make([np.nan, 0.0, 1.0]), "axis")
    assert_error(lambda: make("abc"), "axis")
    assert_error(lambda: make([0.0, 0.0, 1.0], [0.0, 1.0]), "origin")
    assert_error(lambda: make([0.0, 0.0, 1.0], [0.0, np.inf, 0.0]), "origin")
    make([0.0, 0.0, 2.0], [0.1, 0.2, 0.3])  # a non-unit axis is fine (normalised)


def test_massless_last_body_raises_on_construction():
    chain = planar_arm()
    chain.add_segment("empty", "rot_x", tip=np.eye(4), mass=0.0)
    assert_error(lambda: vs.Solver(chain), "joint 2")
    # the same body with a rotor inertia is fine, and so is a massive fixed segment after it
    ok = planar_arm()
    ok.add_segment("empty", "rot_x", mass=0.0, rotor_inertia=0.01)
    vs.Solver(ok).solve(np.zeros(3), np.zeros(3))
    ok2 = planar_arm()
    ok2.add_segment("empty", "rot_x", mass=0.0)
    ok2.add_segment("payload", vs.Joint.fixed(), tip=homogeneous(None, [0, 0.2, 0]), mass=1.0)
    res = vs.Solver(ok2).solve(np.zeros(3), np.zeros(3))
    assert np.all(np.isfinite(res.qdd))


def test_point_mass_on_prismatic_joint_is_valid():
    # D = mass for a prismatic joint: no inertia tensor needed
    chain = vs.Chain()
    chain.add_segment("s", "trans_x", mass=2.0)
    res = vs.Solver(chain, gravity=[0, 0, 0]).solve([0.0], [0.0], tau_ff=[1.0])
    assert res.qdd[0] == pytest.approx(0.5, rel=1e-14)


@pytest.mark.parametrize(
    "kw,name",
    [
        (dict(rcond=-1.0), "rcond"),
        (dict(rcond=np.nan), "rcond"),
        (dict(damping=0.0), "damping"),
        (dict(damping=-1e-3), "damping"),
        (dict(damping=np.inf), "damping"),
        (dict(gravity=[0.0, 0.0]), "gravity"),
        (dict(gravity=[0.0, np.nan, 0.0]), "gravity"),
        (dict(gravity="up"), "gravity"),
    ],
)
def test_bad_solver_options_raise(kw, name):
    assert_error(lambda: vs.Solver(planar_arm(), **kw), name)


# response_columns -------------------------------------------------------------------------------
def test_response_columns_before_solve_raises():
    solver = vs.Solver(planar_arm())
    assert_error(lambda: solver.response_columns([0]), "solve")


def test_response_columns_after_failed_first_solve_raises():
    solver = vs.Solver(planar_arm())
    with pytest.raises(vs.SolverError):
        solver.solve([0.0, np.nan], [0.0, 0.0])
    assert_error(lambda: solver.response_columns([0]), "solve")


@pytest.mark.parametrize("joints", [[2], [-3], [0, 5], [10**12]])
def test_response_columns_out_of_range_raises(joints):
    solver = vs.Solver(planar_arm())
    solver.solve([0.1, 0.2], [0.0, 0.0])
    assert_error(lambda: solver.response_columns(joints), "joint")


@pytest.mark.parametrize("joints", [[[0]], 1, "a", None, [0.5], ["x"]])
def test_response_columns_bad_joints_argument_raises(joints):
    solver = vs.Solver(planar_arm())
    solver.solve([0.1, 0.2], [0.0, 0.0])
    assert_error(lambda: solver.response_columns(joints), "joint")


def test_response_columns_empty_selection():
    solver = vs.Solver(planar_arm())
    solver.solve([0.1, 0.2], [0.0, 0.0])
    dq, dt = solver.response_columns([])
    assert dq.shape == dt.shape == (2, 0)


def test_response_columns_planar_arm_by_hand():
    """Unconstrained: the columns are those of M^-1, M of the planar arm in closed form."""
    L, mass = 1.0, 1.0
    solver = vs.Solver(planar_arm((L, L), mass), gravity=[0, 0, 0])
    q2 = 0.7
    solver.solve([0.3, q2], [0.0, 0.0])
    Izz = mass * L * L / 12
    lc = L / 2
    m22 = Izz + mass * lc * lc
    m12 = m22 + mass * L * lc * np.cos(q2)
    m11 = 2 * Izz + mass * lc * lc + mass * (L * L + lc * lc + 2 * L * lc * np.cos(q2))
    Minv = np.linalg.inv(np.array([[m11, m12], [m12, m22]]))
    dq, dt = solver.response_columns([1, 0])
    np.testing.assert_allclose(dq, Minv[:, [1, 0]], rtol=1e-12)
    np.testing.assert_array_equal(dt, np.zeros((2, 2)))


# ------------------------------------------------------------------------------------------------
# Singular tasks
# ------------------------------------------------------------------------------------------------
def _stretched_case():
    alpha = np.zeros((6, 2))
    alpha[0, 0] = 1.0  # x: along the stretched arm, not controllable at q = 0
    alpha[1, 1] = 1.0  # y
    return np.zeros(2), np.array([0.5, -0.3]), alpha, np.array([0.2, 0.1])


def test_stretched_arm_x_y_constraint_is_rank_one():
    q, qd, alpha, beta = _stretched_case()
    res = vs.Solver(planar_arm()).solve(q, qd, alpha, beta)
    for name in ("qdd", "tau_command", "nu", "link_acc"):
        assert np.all(np.isfinite(getattr(res, name))), name
    assert res.constraint_rank == 1
    assert res.smallest_singular_value == pytest.approx(0.0, abs=1e-12)
    # the achievable (y) part of the task is met exactly
    assert res.link_acc[-1][1] == pytest.approx(0.1, abs=1e-12)
    # x is not controllable: the tip's classical x acceleration is centripetal,
    # -(L1 w1^2 + L2 (w1 + w2)^2); link_acc is the spatial acceleration a - w x v, and
    # (w x v)_x = -(w1 + w2) (L1 w1 + L2 (w1 + w2)).
    w1, w12 = 0.5, 0.2
    classical = -(w1**2 + w12**2)
    w_cross_v = -w12 * (w1 + w12)
    assert res.link_acc[-1][0] == pytest.approx(classical - w_cross_v, abs=1e-12)


def test_stretched_arm_with_damping_is_finite_and_close():
    q, qd, alpha, beta = _stretched_case()
    res = vs.Solver(planar_arm(), damping=1e-3).solve(q, qd, alpha, beta)
    for name in ("qdd", "tau_command", "nu", "link_acc"):
        assert np.all(np.isfinite(getattr(res, name))), name
    ref = vs.Solver(planar_arm()).solve(q, qd, alpha, beta)
    np.testing.assert_allclose(res.qdd, ref.qdd, rtol=1e-2, atol=1e-3)


@pytest.mark.parametrize("damping", [1e-3, 1e-1])
def test_stretched_arm_damped_value_matches_dense_oracle(damping):
    """The damped solve by value (issue 23: the closeness test above cannot tell damping from
    damping^2): (K^2 + d^2 I)^-1 K r of the dense formulation from Pinocchio (tests/support/dense_oracle.py),
    the same planar arm built through tests/support/chains.py."""
    q, qd, alpha, beta = _stretched_case()
    rc = build(planar_rot_z_links(2, np.diag([1e-3, 1 / 12, 1 / 12]), 0.0))
    dense = dense_task(rc.model, rc.tip_frames, q, qd, G_EARTH, np.zeros(2), [(rc.tip_frames[-1], alpha, beta)])
    res = vs.Solver(planar_arm(), damping=damping).solve(q, qd, alpha, beta)
    nu = dense.damped(damping)
    qdd, tau_cmd = dense.outputs(nu)
    assert_close(res.nu, nu, 1e-9, "nu")
    assert_close(res.qdd, qdd, 1e-9, "qdd")
    assert_close(res.tau_command, tau_cmd, 1e-9, "tau_command")
    # y is met up to the damping's share d^2 / (lambda^2 + d^2) of the free residual
    lam_y = dense.K[1, 1]
    assert dense.K[0, 0] == 0.0 and lam_y > 0.1
    e_y = res.link_acc[-1][1] - beta[1]
    assert e_y == pytest.approx(damping**2 / (lam_y**2 + damping**2) * dense.r[1], rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("damping", [None, 1e-3])
def test_duplicated_alpha_columns(damping):
    rng, rc = sample(16, n=5)
    solver = vs.Solver(rc.chain, damping=damping)
    q, qd = random_state(rng, rc)
    a = random_alpha(rng, 1)
    single = vs.Solver(rc.chain).solve(q, qd, a, [0.7])
    res = solver.solve(q, qd, np.hstack([a, a]), [0.7, 0.7])
    assert np.all(np.isfinite(res.nu)) and np.all(np.isfinite(res.qdd))
    if damping is None:
        assert res.constraint_rank == 1
        np.testing.assert_allclose(res.qdd, single.qdd, rtol=1e-9, atol=1e-9)
        # the duplicated constraint shares the force: the sum equals the single constraint's
        assert res.nu.sum() == pytest.approx(single.nu[0], rel=1e-9)
        assert a[:, 0] @ res.link_acc[-1] == pytest.approx(0.7, abs=1e-9)
    # by value against the dense oracle (tests/support/dense_oracle.py): K = k [[1, 1], [1, 1]]
    dense = dense_task(
        rc.model,
        rc.tip_frames,
        q,
        qd,
        G_EARTH,
        np.zeros(rc.n_joints),
        [(rc.tip_frames[-1], np.hstack([a, a]), [0.7, 0.7])],
    )
    nu = dense.truncated(1e-9 * np.abs(dense.K).max())[0] if damping is None else dense.damped(damping)
    qdd, tau_cmd = dense.outputs(nu)
    assert_close(res.nu, nu, 1e-9, "nu")
    assert_close(res.qdd, qdd, 1e-9, "qdd")
    assert_close(res.tau_command, tau_cmd, 1e-9, "tau_command")


def test_more_constraints_than_joints():
    rng, rc = sample(17, n=2, fixed_prob=0.0)
    q, qd = random_state(rng, rc)
    res = vs.Solver(rc.chain).solve(q, qd, random_alpha(rng, 6), rng.normal(size=6))
    assert res.constraint_rank <= 2
    for name in ("qdd", "tau_command", "nu", "link_acc"):
        assert np.all(np.isfinite(getattr(res, name))), name


# ------------------------------------------------------------------------------------------------
# Copy semantics, threads, determinism
# ------------------------------------------------------------------------------------------------
def test_solver_copies_the_chain():
    rng, rc = sample(18, n=4)
    chain = rc.chain
    solver = vs.Solver(chain)
    q, qd = random_state(rng, rc)
    before = solver.solve(q, qd)
    chain.add_segment("extra", "rot_x", mass=3.0, com=[0.2, 0.1, 0.0], inertia=np.eye(3) * 0.2)
    assert chain.n_joints == rc.n_joints + 1
    assert solver.n_joints == rc.n_joints
    after = solver.solve(q, qd)
    assert_results_equal(before, after)
    grown = vs.Solver(chain)
    assert grown.n_joints == rc.n_joints + 1
    assert not np.allclose(grown.solve(np.r_[q, 0.3], np.r_[qd, 0.0]).qdd[:-1], before.qdd)


def test_solver_outlives_temporary_chain():
    def make():
        return vs.Solver(planar_arm((0.7, 0.4)))

    solver = make()
    gc.collect()
    ref = vs.Solver(planar_arm((0.7, 0.4)))
    assert_results_equal(solver.solve([0.1, 0.2], [0.3, 0.4]), ref.solve([0.1, 0.2], [0.3, 0.4]))


def _workload(seed, count=60):
    rng, rc = sample(seed, n=7, fixed_prob=0.2)
    states = []
    for k in range(count):
        q, qd = random_state(rng, rc)
        m = k % 7
        alpha = random_alpha(rng, m) if m else None
        beta = rng.normal(size=m) if m else None
        states.append((q, qd, alpha, beta, random_f_ext(rng, rc), rng.normal(size=rc.n_joints)))
    return rc, states


def _run(rc, states, barrier=None):
    solver = vs.Solver(rc.chain)
    if barrier is not None:
        barrier.wait()
    out = []
    for _ in range(3):  # several passes to overlap with the other threads
        out = []
        for s in states:
            r = solver.solve(*s)
            cols = solver.response_columns(list(range(rc.n_joints)))
            out.append((r.qdd, r.tau_command, r.nu, r.link_acc, cols[0], cols[1]))
    return out


def test_threads_with_own_solvers_match_sequential():
    work = [_workload(100 + k) for k in range(4)]
    sequential = [_run(rc, states) for rc, states in work]
    barrier = threading.Barrier(4)
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        futures = [pool.submit(_run, rc, states, barrier) for rc, states in work]
        parallel = [f.result() for f in futures]
    for seq, par in zip(sequential, parallel):
        for a, b in zip(seq, par):
            for x, y in zip(a, b):
                np.testing.assert_array_equal(x, y)


def test_repeated_solves_are_bit_identical():
    rc, states = _workload(200, count=20)
    s1, s2 = vs.Solver(rc.chain), vs.Solver(rc.chain)
    first = [s1.solve(*s) for s in states]
    for s, r in zip(states, first):
        assert_results_equal(s1.solve(*s), r)  # same instance, after other solves in between
        assert_results_equal(s2.solve(*s), r)  # another instance
    # interleaving constraint counts does not leak state from one solve into the next
    for s, r in zip(reversed(states), reversed(first)):
        assert_results_equal(s1.solve(*s), r)
