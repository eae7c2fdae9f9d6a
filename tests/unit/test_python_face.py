"""The Python face (issue: consistent, complete): argument forms, batch broadcasting and options,
one segment-addressing rule, frames merged into segments, f_ext dicts, dtype checks, `out=`,
response columns after friction, pickling and deep copies.

Expected values come from Pinocchio (frames merged into segments, held joints), from the
documented equivalences between argument forms (scalar vs (1,) beta, dict vs array f_ext, batch
row vs single solve: bit for bit), or from finite differences of the friction-aware solve.
"""

from __future__ import annotations

import copy
import multiprocessing
import pickle
from functools import partial

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import random_alpha, random_chain, random_f_ext, random_state, well_conditioned_task
from support.urdf_robots import BUILDERS, G, LWA, minv, assert_rel

GRAV = np.r_[-G, 0.0, 0.0, 0.0]


def assert_same(a, b):
    """Two results (SolveResult or a BatchResult row as dict) equal bit for bit."""
    for name in ("qdd", "tau_command", "nu", "link_acc"):
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def fields(r, b=None):
    names = ("qdd", "tau_command", "nu", "link_acc", "friction_torque", "limit_torque", "status")
    out = {}
    for n in names:
        v = getattr(r, n)
        out[n] = None if v is None else (np.asarray(v)[b] if b is not None else np.asarray(v))
    return out


def arm(seed=3, n=6):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, n, fixed_prob=0.2)
    return rng, rc, vs.Solver(rc.chain)


def assert_error(fn, *parts):
    with pytest.raises(vs.SolverError) as ei:
        fn()
    for p in parts:
        assert p in str(ei.value), f"{p!r} not in {str(ei.value)!r}"
    return str(ei.value)


# ------------------------------------------------------------------------------------------------
# Argument forms
# ------------------------------------------------------------------------------------------------
def test_scalar_beta_and_one_dimensional_alpha():
    rng, rc, solver = arm()
    q, qd = random_state(rng, rc)
    a = random_alpha(rng, 1)
    ref = solver.solve(q, qd, alpha=a, beta=np.array([4.0]))
    for alpha in (a, a[:, 0], list(a[:, 0])):
        for beta in (4.0, np.float64(4.0), np.array(4.0), [4.0], 4):
            r = solver.solve(q, qd, alpha=alpha, beta=beta)
            assert_same(fields(r), fields(ref))
    assert_error(lambda: solver.solve(q, qd, alpha=random_alpha(rng, 2), beta=4.0), "beta", "(2,)")


@pytest.mark.parametrize(
    "bad,what",
    [
        (np.array(["1"] * 6), "dtype"),
        (np.ones(6, dtype=bool), "dtype"),
        (np.ones(6, dtype=complex), "dtype"),
        (np.array([object()] * 6), "dtype"),
        ("abcdef", "real"),
        (True, "bool"),
        ([1, "a", 3, 4, 5, 6], "real"),
    ],
)
def test_non_numeric_arrays_are_rejected(bad, what):
    rng, rc, solver = arm(n=6)
    q, qd = random_state(rng, rc)
    n = rc.n_joints
    bad_n = bad if not isinstance(bad, np.ndarray) else np.resize(bad, n)
    assert_error(lambda: solver.solve(bad_n, qd), "q", what)
    assert_error(lambda: solver.solve(q, qd, tau_ff=bad_n), "tau_ff", what)
    if isinstance(bad, np.ndarray):
        assert_error(lambda: solver.solve(q, qd, alpha=bad, beta=[0.0]), "alpha", what)
        assert_error(lambda: solver.solve(q, qd, alpha=np.eye(6)[:, :1], beta=bad[:1]), "beta", what)
        assert_error(lambda: solver.solve(q, qd, f_ext=np.resize(bad, (rc.n_segments, 6))), "f_ext", what)
        assert_error(lambda: solver.solve(q, qd, friction=vs.Friction(static=bad_n)), "static")
        assert_error(lambda: solver.solve_batch(np.resize(bad, (2, n)), qd), "q", what)


def test_integer_arrays_are_accepted_as_float():
    rng, rc, solver = arm()
    n = rc.n_joints
    r_int = solver.solve(np.arange(n) % 2, np.zeros(n, dtype=np.int32), tau_ff=np.ones(n, dtype=np.int64))
    r_float = solver.solve((np.arange(n) % 2).astype(float), np.zeros(n), tau_ff=np.ones(n))
    assert_same(fields(r_int), fields(r_float))


# ------------------------------------------------------------------------------------------------
# out=
# ------------------------------------------------------------------------------------------------
def test_out_reuses_the_result_and_equals_a_fresh_solve():
    rng, rc, solver = arm()
    a = random_alpha(rng, 3)
    q, qd = random_state(rng, rc)
    out = solver.solve(q, qd, alpha=a, beta=np.zeros(3))
    views = fields(out)  # arrays are views of the result's storage: out= rewrites them in place
    for _ in range(3):
        q, qd = random_state(rng, rc)
        b = rng.normal(size=3)
        got = solver.solve(q, qd, alpha=a, beta=b, out=out)
        fresh = fields(vs.Solver(rc.chain).solve(q, qd, alpha=a, beta=b))
        assert got is out
        assert_same(fields(out), fresh)
        assert_same(views, fresh)
    assert_error(lambda: solver.solve(q, qd, alpha=random_alpha(rng, 2), beta=np.zeros(2), out=out), "out")
    assert_error(lambda: solver.solve(q, qd, alpha=a, beta=np.zeros(3), friction=True, out=out), "out")
    with pytest.raises(vs.SolverError, match="out"):
        solver.solve(q, qd, out=np.zeros(3))
    # friction results can be reused too
    fr = vs.Friction(static=np.full(rc.n_joints, 0.3))
    out_f = solver.solve(q, np.zeros(rc.n_joints), friction=fr)
    got = solver.solve(q, np.zeros(rc.n_joints), tau_ff=np.ones(rc.n_joints), friction=fr, out=out_f)
    ref = vs.Solver(rc.chain).solve(q, np.zeros(rc.n_joints), tau_ff=np.ones(rc.n_joints), friction=fr)
    assert got is out_f
    for k, v in fields(ref).items():
        np.testing.assert_array_equal(fields(got)[k], v, err_msg=k)
    assert got.gauss_value == ref.gauss_value and got.iterations == ref.iterations


# ------------------------------------------------------------------------------------------------
# solve_batch: everything solve takes, broadcasting, threads
# ------------------------------------------------------------------------------------------------
def _rows(solver, B, **per):
    return [solver.solve(**{k: (v(b) if callable(v) else v) for k, v in per.items()}) for b in range(B)]


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_batch_with_friction_and_constraints_equals_solve_bitwise(threads):
    rng, rc, solver = arm(5, n=7)
    B, n = 11, rc.n_joints
    Q = np.array([random_state(rng, rc)[0] for _ in range(B)])
    QD = rng.uniform(-1, 1, (B, n))
    QD[:, ::2] = 0.0  # resting joints: friction decides
    tau = rng.normal(size=(B, n))
    a_end = random_alpha(rng, 2)
    b_end = rng.normal(size=(B, 2))
    mid = rc.chain.segment_names[2]
    a_mid = np.array([random_alpha(rng, 1) for _ in range(B)])
    b_mid = rng.normal(size=B)  # (B,) for m_i = 1
    frs = [vs.Friction(static=rng.uniform(0, 2, n)) if b % 3 else None for b in range(B)]
    batch = solver.solve_batch(
        Q, QD, a_end, b_end, None, tau, friction=frs, constraints={mid: (a_mid, b_mid)}, threads=threads
    )
    ref = vs.Solver(rc.chain)
    for b in range(B):
        r = ref.solve(
            Q[b],
            QD[b],
            alpha=a_end,
            beta=b_end[b],
            tau_ff=tau[b],
            friction=frs[b],
            constraints={mid: (a_mid[b], b_mid[b])},
        )
        got = fields(batch, b)
        for k, v in fields(r).items():
            if v is None:
                if k in ("friction_torque", "limit_torque"):
                    assert np.all(np.isnan(got[k])), k
                elif k == "status":
                    assert np.all(got[k] == -1)
                continue
            np.testing.assert_array_equal(got[k], v, err_msg=f"row {b} {k}")
        np.testing.assert_array_equal(batch.segment_nu[mid][b], r.segment_nu[mid])
        assert batch.constraint_rank[b] == r.constraint_rank
        if r.gauss_value is not None:
            assert batch.gauss_value[b] == r.gauss_value and batch.iterations[b] == r.iterations


def test_batch_broadcasts_arguments_without_batch_axis():
    rng, rc, solver = arm(6)
    B, n = 5, rc.n_joints
    q0, qd0 = random_state(rng, rc)
    QD = rng.uniform(-1, 1, (B, n))
    f = random_f_ext(rng, rc)
    batch = solver.solve_batch(q0, QD, f_ext=f, friction=True)  # q (n,), f_ext shared
    for b in range(B):
        r = solver.solve(q0, QD[b], f_ext=f, friction=True)
        np.testing.assert_array_equal(batch.qdd[b], r.qdd)
    one = solver.solve_batch(q0, qd0)  # nothing batched: one row
    assert one.qdd.shape == (1, n)
    np.testing.assert_array_equal(one.qdd[0], solver.solve(q0, qd0).qdd)


def test_batch_shape_errors_name_argument_and_axis():
    rng, rc, solver = arm(7)
    n = rc.n_joints
    Q = np.zeros((4, n))
    assert_error(lambda: solver.solve_batch(Q, np.zeros((3, n))), "qd", "axis 0", "3 rows", "q", "4")
    assert_error(lambda: solver.solve_batch(Q, np.zeros(n), tau_ff=np.zeros((5, n))), "tau_ff", "axis 0")
    assert_error(lambda: solver.solve_batch(Q, np.zeros(n), friction=[True] * 3), "friction")
    assert_error(lambda: solver.solve_batch(Q, np.zeros(n), tau_ff=np.zeros((4, n + 1))), "tau_ff", f"({n},)")
    assert_error(lambda: solver.solve_batch(Q, np.zeros(n), threads=-1), "threads")


def test_batch_threads_give_identical_results_and_release_the_gil():
    rng, rc, solver = arm(8, n=7)
    B = 64
    Q = np.array([random_state(rng, rc)[0] for _ in range(B)])
    QD = rng.uniform(-1, 1, (B, rc.n_joints))
    one = solver.solve_batch(Q, QD, friction=True)
    for threads in (0, 2, 7, 200):
        many = solver.solve_batch(Q, QD, friction=True, threads=threads)
        np.testing.assert_array_equal(many.qdd, one.qdd)
        np.testing.assert_array_equal(many.tau_command, one.tau_command)


def test_batch_failure_names_the_first_failing_row():
    rng, rc, solver = arm(9)
    n = rc.n_joints
    Q = np.zeros((6, n))
    QD = np.zeros((6, n))
    QD[4, 1] = np.nan
    QD[2, 0] = np.inf
    assert_error(lambda: solver.solve_batch(Q, QD, threads=2), "batch row 2", "qd")


# ------------------------------------------------------------------------------------------------
# One segment-addressing rule
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def panda():
    return BUILDERS["panda"]()


def test_segment_addressing_is_one_rule(panda):
    chain = panda.chain
    ns, names = chain.n_segments, chain.segment_names
    q = np.linspace(-0.5, 0.5, chain.n_joints)
    for k in range(-ns, ns):
        key_name = names[k]
        assert chain.segment_index(k) == chain.segment_index(key_name) == k % ns
        np.testing.assert_array_equal(chain.fk(q, k), chain.fk(q, key_name))
        np.testing.assert_array_equal(chain.jacobian(q, k), chain.jacobian(q, key_name))
    # the base: by its name only
    base = chain.root_link
    np.testing.assert_array_equal(chain.fk(q, base), np.eye(4))
    np.testing.assert_array_equal(chain.jacobian(q, base), np.zeros((6, chain.n_joints)))
    assert_error(lambda: chain.segment_index(base), base, "base")
    assert chain.segment_index(-1) == ns - 1
    # unknown names and out-of-range indices: the same wording everywhere
    solver = vs.Solver(chain)
    qd = np.zeros(chain.n_joints)
    calls = {
        "fk": lambda key: chain.fk(q, key),
        "jacobian": lambda key: chain.jacobian(q, key),
        "twist": lambda key: chain.twist(q, qd, key),
        "segment_index": lambda key: chain.segment_index(key),
        "constraints": lambda key: solver.solve(q, qd, constraints={key: (np.eye(6)[:, :1], [0.0])}),
        "f_ext": lambda key: solver.solve(q, qd, f_ext={key: np.zeros(6)}),
    }
    for call in calls.values():
        msg = assert_error(partial(call, "no_such_link"), "no segment or link named 'no_such_link'")
        assert "segments(" not in msg and "= -1" not in msg, msg
        assert_error(partial(call, ns), f"segment index {ns} out of range", "the base is addressed by its name")
        assert_error(partial(call, -ns - 1), "out of range")
        assert_error(partial(call, 1.5), "str", "int")
    for call in (calls["constraints"], calls["f_ext"]):
        assert_error(partial(call, base), base, "base")


def test_joint_addressing_in_response_columns(panda):
    solver = vs.Solver(panda.chain)
    q = np.linspace(-0.5, 0.5, panda.chain.n_joints)
    solver.solve(q, np.zeros(panda.chain.n_joints))
    names = panda.chain.joint_names
    by_index = solver.response_columns([0, 3, -1])
    by_name = solver.response_columns([names[0], names[3], names[-1]])
    for a, b in zip(by_index, by_name):
        np.testing.assert_array_equal(a, b)
    assert panda.chain.joint_index(names[2]) == 2 and panda.chain.joint_index(-1) == len(names) - 1
    assert_error(lambda: solver.response_columns(["nope"]), "no joint named 'nope'")


# ------------------------------------------------------------------------------------------------
# Links merged into segments by fixed joints are valid targets (Pinocchio frames as oracle)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("links", [("panda_hand_tcp",), ("panda_link8", "panda_hand_tcp"), ("panda_link8",)])
def test_constraints_on_merged_links_match_pinocchio(panda, links):
    r = panda
    rng = np.random.default_rng(hash(links) % 2**32)
    solver = vs.Solver(r.chain, gravity=G)
    data = r.model.createData()
    alphas = [random_alpha(rng, 2) for _ in links]
    for _trial in range(4):
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        tau = rng.normal(size=r.chain.n_joints)
        pin.forwardKinematics(r.model, data, pq, qd, np.zeros(r.model.nv))
        pin.updateFramePlacements(r.model, data)
        fids = [r.model.getFrameId(name) for name in links]
        drift = np.concatenate(
            [a.T @ (pin.getFrameAcceleration(r.model, data, fid, LWA).vector + GRAV) for fid, a in zip(fids, alphas)]
        )
        A = np.vstack([a.T @ pin.computeFrameJacobian(r.model, data, pq, fid, LWA) for fid, a in zip(fids, alphas)])
        if not well_conditioned_task(A, minv(r.model, data, pq)):
            continue
        betas = [rng.normal(size=2) for _ in links]
        res = solver.solve(q, qd, tau_ff=tau, constraints={name: (a, b) for name, a, b in zip(links, alphas, betas)})
        expected = pin.forwardDynamics(r.model, data, pq, qd, tau, A, drift - np.concatenate(betas))
        assert_rel(res.qdd, expected, "qdd")
        assert_rel(res.nu, -data.lambda_c, "nu")
        assert_rel(res.tau_command, -A.T @ res.nu, "tau_command")


def test_f_ext_dict_matches_array_and_pinocchio_on_merged_link(panda):
    r = panda
    rng = np.random.default_rng(12)
    solver = vs.Solver(r.chain, gravity=G)
    data = r.model.createData()
    q, qd = r.random_state(rng)
    pq = r.pin_q(q)
    names = r.chain.segment_names
    w_seg = rng.normal(size=6)
    w_tcp = rng.normal(size=6)
    # dict by segment name == array row
    f = np.zeros((r.chain.n_segments, 6))
    f[3] = w_seg
    np.testing.assert_array_equal(solver.solve(q, qd, f_ext={names[3]: w_seg}).qdd, solver.solve(q, qd, f_ext=f).qdd)
    np.testing.assert_array_equal(solver.solve(q, qd, f_ext={3: w_seg}).qdd, solver.solve(q, qd, f_ext=f).qdd)
    # a wrench on the merged tool frame, moment about its origin: J_tcp^T w in Pinocchio
    res = solver.solve(q, qd, f_ext={"panda_hand_tcp": w_tcp, names[3]: w_seg})
    J_tcp = pin.computeFrameJacobian(r.model, data, pq, r.model.getFrameId("panda_hand_tcp"), LWA)
    J_seg = pin.computeFrameJacobian(r.model, data, pq, r.model.getFrameId(names[3]), LWA)
    expected = pin.aba(r.model, data, pq, qd, J_tcp.T @ w_tcp + J_seg.T @ w_seg)
    assert_rel(res.qdd, expected, "qdd with f_ext on panda_hand_tcp")


def test_fk_jacobian_on_merged_link_match_pinocchio(panda):
    r = panda
    data = r.model.createData()
    q, qd = r.random_state(np.random.default_rng(2))
    pq = r.pin_q(q)
    pin.forwardKinematics(r.model, data, pq, qd)
    pin.updateFramePlacements(r.model, data)
    fid = r.model.getFrameId("panda_link8")
    assert_rel(r.chain.fk(q, "panda_link8"), data.oMf[fid].homogeneous, "fk")
    assert_rel(r.chain.jacobian(q, "panda_link8"), pin.computeFrameJacobian(r.model, data, pq, fid, LWA), "jacobian")


# ------------------------------------------------------------------------------------------------
# response_columns after a friction-aware solve
# ------------------------------------------------------------------------------------------------
def test_response_columns_after_friction_hold_the_sticking_joints(panda):
    r = panda
    rng = np.random.default_rng(4)
    solver = vs.Solver(r.chain, gravity=G)
    data = r.model.createData()
    n = r.chain.n_joints
    for _trial in range(20):
        q, _ = r.random_state(rng)
        qd = np.zeros(n)
        qd[:3] = rng.uniform(-1, 1, 3)  # joints 0-2 move, the rest rest
        static = rng.uniform(0.0, 8.0, n)
        fr = vs.Friction(static=static)
        res = solver.solve(q, qd, friction=fr)
        stick = np.flatnonzero(res.status == 1)
        interior = np.all(np.abs(res.friction_torque[stick]) < static[stick] - 0.05)
        if len(stick) == 0 or not interior:
            continue
        held_q, held_t = solver.response_columns(range(n))
        free_q, _ = solver.response_columns(range(n), hold_sticking=False)
        # oracle 1: Pinocchio's inverse inertia with the sticking joints locked (dense Schur form)
        pq = r.pin_q(q)
        Minv = minv(r.model, data, pq)
        E = np.eye(n)[stick]
        K = E @ Minv @ E.T
        expected = Minv - Minv @ E.T @ np.linalg.solve(K, E @ Minv)
        assert_rel(held_q, expected, "held columns vs Pinocchio")
        assert_rel(free_q, Minv, "frictionless columns vs Pinocchio")
        # oracle 2: finite differences of the friction-aware solve itself (joints stay stuck)
        eps = 1e-6
        for j in range(n):
            tau = np.zeros(n)
            tau[j] = eps
            plus = vs.Solver(r.chain, gravity=G).solve(q, qd, tau_ff=tau, friction=fr)
            minus = vs.Solver(r.chain, gravity=G).solve(q, qd, tau_ff=-tau, friction=fr)
            np.testing.assert_allclose((plus.qdd - minus.qdd) / (2 * eps), held_q[:, j], rtol=1e-5, atol=1e-5)
        return
    pytest.fail("no state with interior sticking joints found")


# ------------------------------------------------------------------------------------------------
# Pickling and deep copies (multiprocessing, Dask, Ray ship objects this way)
# ------------------------------------------------------------------------------------------------
def _child_solve(payload):
    solver, chain, fr, args = pickle.loads(payload)
    a = solver.solve(*args, friction=fr)
    b = vs.Solver(chain).solve(*args, friction=fr)
    return pickle.dumps((a, b))


def test_pickle_and_deepcopy_round_trip_and_solve_in_a_child_process(panda):
    chain = panda.chain
    solver = vs.Solver(chain, gravity=[0.1, 0.0, -9.7], rcond=1e-10, damping=1e-5)
    fr = vs.Friction(
        static=np.full(chain.n_joints, 0.4), kinetic=np.full(chain.n_joints, 0.3), lower=chain.lower, upper=chain.upper
    )
    q, qd = panda.random_state(np.random.default_rng(5))
    qd[::2] = 0.0
    args = (q, qd)
    res = solver.solve(*args, friction=fr, constraints={"panda_link4": (np.eye(6)[:, :2], [1.0, 2.0])})
    for obj in (chain, solver, fr, res):
        for clone in (pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj), copy.copy(obj)):
            assert type(clone) is type(obj)
    c2 = pickle.loads(pickle.dumps(chain))
    assert c2.segment_names == chain.segment_names and c2.joint_names == chain.joint_names
    assert c2.link_names == chain.link_names and c2.root_link == chain.root_link and c2.notes == chain.notes
    for name in ("lower", "upper", "friction", "damping", "rotor_inertia", "effort_limit", "velocity_limit"):
        np.testing.assert_array_equal(getattr(c2, name), getattr(chain, name), err_msg=name)
    s2 = pickle.loads(pickle.dumps(solver))
    assert isinstance(s2, vs.Solver)
    np.testing.assert_array_equal(s2.gravity, solver.gravity)
    r2 = pickle.loads(pickle.dumps(res))
    for k, v in fields(res).items():
        np.testing.assert_array_equal(fields(r2)[k], v)
    np.testing.assert_array_equal(r2.segment_nu["panda_link4"], res.segment_nu["panda_link4"])
    ref = solver.solve(*args, friction=fr)
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        a, b = pickle.loads(pool.apply(_child_solve, (pickle.dumps((solver, chain, fr, args)),)))
    for k, v in fields(ref).items():  # the same numbers, bit for bit, in another process
        np.testing.assert_array_equal(fields(a)[k], v, err_msg=k)
    assert_same(fields(b), fields(vs.Solver(chain).solve(*args, friction=fr)))


# ------------------------------------------------------------------------------------------------
# Missing dependencies: the experiments' CLI names the package to install instead of a traceback
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "case,module",
    [("contact", "mujoco"), ("friction", "matplotlib"), ("all", "mujoco")],
)
def test_cli_names_the_package_when_a_dependency_is_missing(case, module, tmp_path):
    import subprocess
    import sys

    # A child interpreter in which `module` cannot be found (a meta-path finder that refuses it).
    code = (
        "import sys, importlib.abc\n"
        "class Block(importlib.abc.MetaPathFinder):\n"
        f"    def find_spec(self, name, path=None, target=None):\n"
        f"        if name == {module!r} or name.startswith({module!r} + '.'):\n"
        "            raise ModuleNotFoundError(name)\n"
        "        return None\n"
        "sys.meta_path.insert(0, Block())\n"
        "import importlib.util\n"
        "_orig = importlib.util.find_spec\n"
        f"importlib.util.find_spec = lambda n, *a: None if n == {module!r} else _orig(n, *a)\n"
        "from vereshchagin_experiments.__main__ import main\n"
        f"sys.exit(main(['reproduce', '--quick', '--case', {case!r}, '--out', {str(tmp_path)!r}]))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert f"pip install {module}" in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    assert not any(tmp_path.iterdir()), "nothing is run or written when a dependency is missing"


def test_response_columns_after_a_batch_refers_to_its_last_row_whatever_the_threads():
    rng = np.random.default_rng(5)
    n = 6
    rc = random_chain(rng, n)
    Q = rng.uniform(-1, 1, (7, n))
    QD = rng.uniform(-1, 1, (7, n))
    fr = vs.Friction(static=np.full(n, 0.8))
    QD[:, 1::2] = 0.0  # resting joints: some stick
    ref = vs.Solver(rc.chain)
    ref.solve(Q[-1], QD[-1], friction=fr)
    expected = ref.response_columns([0, n - 1])
    for threads in (1, 2, 3):
        solver = vs.Solver(rc.chain)
        solver.solve_batch(Q, QD, friction=fr, threads=threads)
        got = solver.response_columns([0, n - 1])
        np.testing.assert_array_equal(got[0], expected[0])
        np.testing.assert_array_equal(got[1], expected[1])
        # a failing batch leaves no state to linearise around
        with pytest.raises(vs.SolverError, match="row 0.*overflow"):  # fails while solving
            solver.solve_batch(Q[:2], QD[:2], tau_ff=np.full((2, n), 1e308), threads=threads)
        with pytest.raises(vs.SolverError, match="last successful solve"):
            solver.response_columns([0])
        # a batch that fails its argument checks is a failed call too (issue 23): no state stands
        solver.solve(Q[-1], QD[-1], friction=fr)
        with pytest.raises(vs.SolverError):
            solver.solve_batch(Q[:, :2], QD)
        with pytest.raises(vs.SolverError, match="last successful solve"):
            solver.response_columns([0])
        solver.solve(Q[-1], QD[-1], friction=fr)
        np.testing.assert_array_equal(solver.response_columns([0, n - 1])[0], expected[0])
