"""What KDL users bring (issue: KDL drop-in), from Python: identified inertial parameters
(``inertia_check``) and driver pass-through.

Oracles: Pinocchio (``aba`` on models with the same non-rigid-body inertias; the dense
pass-through formula with ``crba``, ``rnea``, frame Jacobians and accelerations), the scipy primal
and stick/slip enumeration oracles of tests/support/friction_oracles.py for friction on identified models.
"""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pinocchio as pin
import pytest

from support import chains, friction_checks
import vereshchagin as vs
from support.chains import fext_generalized, frame_jacobian, random_alpha, random_f_ext, random_state
from support.urdf_robots import BUILDERS, G, LWA, assert_rel

RTOL = 1e-9
GRAV = np.r_[-G, 0.0, 0.0, 0.0]


def not_rigid(inertia, factor=1.5):
    """An 'identified' inertia: the smallest principal moment pushed below zero (symmetric, not PSD)."""
    w, V = np.linalg.eigh(inertia)
    return inertia - factor * w[0] * np.outer(V[:, 0], V[:, 0]) - 1e-4 * np.outer(V[:, 0], V[:, 0])


def identified_chain(rng, n, fixed_prob=0.2, **kw):
    """A random chain whose every body has a non-PSD rotational inertia (H stays positive definite)."""
    rc = chains.random_chain(rng, n, fixed_prob=fixed_prob, **kw)
    segs = copy.deepcopy(rc.segments)
    for s in segs:
        s.inertia = not_rigid(np.asarray(s.inertia))
    return chains.build(segs, inertia_check="joint_space")


# ------------------------------------------------------------------------------------------------
# inertia_check
# ------------------------------------------------------------------------------------------------
def test_physical_check_rejects_what_no_rigid_body_has_and_names_the_option():
    c = vs.Chain()
    with pytest.raises(vs.SolverError, match="triangle.*inertia_check='joint_space'"):
        c.add_segment("rod", "rot_z", mass=1.0, inertia=np.diag([0.1, 0.01, 0.01]))
    with pytest.raises(vs.SolverError, match="positive semi-definite.*joint_space"):
        c.add_segment("bad", "rot_z", mass=1.0, inertia=np.diag([0.1, 0.1, -0.01]))
    with pytest.raises(vs.SolverError, match="inertia_check must be 'physical'"):
        c.add_segment("x", "rot_z", mass=1.0, inertia_check="loose")
    c.add_segment("thin_rod", "rot_z", mass=1.0, inertia=np.diag([0.1, 0.1, 0.0]))  # a rod: allowed


@pytest.mark.parametrize("seed", range(6))
def test_identified_models_solve_like_pinocchio(seed):
    rng = np.random.default_rng([seed, 141])
    rc = identified_chain(rng, int(rng.integers(2, 8)))
    assert any(np.linalg.eigvalsh(s.inertia)[0] < 0 for s in rc.segments)
    with pytest.raises(vs.SolverError, match="joint_space"):
        vs.Solver(rc.chain, inertia_check="physical")  # the physical check names the option
    solver = vs.Solver(rc.chain, inertia_check="joint_space")
    assert solver.inertia_check == "joint_space"
    assert pickle.loads(pickle.dumps(solver)).inertia_check == "joint_space"
    # The chain was built with the joint-space check: a Solver takes it by default (issue 24).
    assert rc.chain.inertia_check == "joint_space"
    assert vs.Solver(rc.chain).inertia_check == "joint_space"
    data = rc.data()
    for _ in range(3):
        q, qd = random_state(rng, rc)
        H = pin.crba(rc.model, data, q)
        if np.linalg.eigvalsh(0.5 * (H + H.T))[0] <= 1e-6:
            continue
        tau = rng.normal(size=rc.n_joints)
        f = random_f_ext(rng, rc)
        res = solver.solve(q, qd, f_ext=f, tau_ff=tau)
        expected = pin.aba(rc.model, data, q, qd, tau + fext_generalized(rc, data, q, f))
        assert_rel(res.qdd, expected, "qdd", RTOL)


def test_indefinite_joint_space_inertia_fails_at_solve_naming_the_joint():
    """H(q) positive definite at some configurations only: those solve, the others name the joint."""
    c = vs.Chain()
    T = np.eye(4)
    T[0, 3] = 0.5
    c.add_segment(
        "upper", "rot_z", tip=T, mass=1.0, com=[-0.25, 0, 0], inertia=np.diag([1e-3, 2e-2, 2e-2]), joint_name="shoulder"
    )
    c.add_segment(
        "forearm",
        "rot_y",
        tip=T,
        mass=1.0,
        com=[-0.25, 0, 0],
        inertia=np.diag([0.05, 0.05, -0.2]),
        joint_name="elbow",
        inertia_check="joint_space",
    )
    with pytest.raises(vs.SolverError, match="joint_space"):
        vs.Solver(c, inertia_check="physical")
    assert vs.Solver(c).inertia_check == "joint_space"  # the model's check by default
    solver = vs.Solver(c, inertia_check="joint_space")
    ok = solver.solve([0.0, 0.0], [0.0, 0.0])  # forearm along x: the shoulder feels m r^2 > 0.2
    assert np.isfinite(ok.qdd).all()
    with pytest.raises(vs.SolverError, match="'shoulder'.*D = .* <= 0"):
        solver.solve([0.0, np.pi], [0.0, 0.0])  # folded back over the shoulder axis: D < 0
    assert np.array_equal(solver.solve([0.0, 0.0], [0.0, 0.0]).qdd, ok.qdd)  # still usable


def test_urdf_option():
    urdf = """<robot name="r"><link name="base"/>
      <link name="l1"><inertial><mass value="1"/><origin xyz="0 0 0.1"/>
        <inertia ixx="0.01" iyy="0.01" izz="-0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 1 0"/></joint>
    </robot>"""
    with pytest.raises(vs.SolverError, match="joint_space"):
        vs.Chain.from_urdf(urdf)
    chain = vs.Chain.from_urdf(urdf, inertia_check="joint_space")
    res = vs.Solver(chain, inertia_check="joint_space").solve([0.3], [0.0])
    assert np.isfinite(res.qdd).all()


@pytest.mark.parametrize("seed", range(6))
def test_friction_on_identified_models_vs_scipy_and_enumeration(seed, monkeypatch):
    """The max-min needs G positive semi-definite, which holds when every D_j > 0."""
    monkeypatch.setattr(friction_checks, "random_chain", identified_chain)
    rng = np.random.default_rng([seed, 142])
    n = int(rng.integers(2, 7))
    m = int(rng.integers(0, 3))
    case = friction_checks.random_chain_case(rng, n, m, rest="mixed", friction="moderate")
    solver = vs.Solver(case["rc"].chain, gravity=case["g"], inertia_check="joint_space")
    res = solver.solve(
        case["q"],
        case["qd"],
        alpha=case["alpha"],
        beta=case["beta"],
        f_ext=case["f_ext"],
        tau_ff=case["tau"],
        friction=friction_checks.friction_arg(case["static"], case["kinetic"], case["tol"]),
    )
    friction_checks.check_chain_case(case, res, f"identified seed {seed} n {n} m {m}")


# ------------------------------------------------------------------------------------------------
# Driver pass-through: nu solves K nu = a_nature + (1 - p_f) a_fext + (1 - p_t) a_ff - beta
# ------------------------------------------------------------------------------------------------
def dense_pass_through(model, data, pq, qd, tau, tau_fext, A, drift, beta, p_f, p_t):
    """qdd, nu of the dense formula: each driver's unconstrained acceleration along the rows A."""
    H = pin.crba(model, data, pq)
    H = np.triu(H) + np.triu(H, 1).T
    b = pin.rnea(model, data, pq, qd, np.zeros(model.nv))  # gravity and velocity products
    qdd_nature, qdd_f, qdd_t = (np.linalg.solve(H, x) for x in (-b, tau_fext, tau))
    a_nature, a_f, a_t = A @ qdd_nature + drift, A @ qdd_f, A @ qdd_t
    K = A @ np.linalg.solve(H, A.T)
    nu = np.linalg.solve(K, a_nature + (1 - p_f) * a_f + (1 - p_t) * a_t - beta)
    return qdd_nature + qdd_f + qdd_t - np.linalg.solve(H, A.T @ nu), nu


@pytest.mark.parametrize("seed", range(8))
def test_pass_through_random_chains_vs_dense_formula(seed):
    rng = np.random.default_rng([seed, 143])
    n = int(rng.integers(3, 8))
    rc = chains.random_chain(rng, n, fixed_prob=0.2)
    solver = rc.solver()
    data = rc.data()
    m = int(rng.integers(1, min(n, 6) + 1))
    alpha = random_alpha(rng, m)
    for _ in range(10):
        q, qd = random_state(rng, rc)
        J = frame_jacobian(rc, data, q)
        A = alpha.T @ J
        if chains.well_conditioned_task(A, np.linalg.inv(pin.crba(rc.model, data, q) + np.eye(n) * 0)):
            break
    pin.forwardKinematics(rc.model, data, q, qd, np.zeros(n))
    pin.updateFramePlacements(rc.model, data)
    drift = alpha.T @ (pin.getFrameAcceleration(rc.model, data, rc.tip_frames[-1], LWA).vector + GRAV)
    tau = rng.normal(size=n)
    f = random_f_ext(rng, rc)
    beta = rng.normal(size=m)
    p_f, p_t = rng.uniform(0, 1, m), rng.uniform(0, 1, m)
    p_f[0], p_t[-1] = 1.0, 0.0
    res = solver.solve(
        q, qd, alpha=alpha, beta=beta, f_ext=f, tau_ff=tau, f_ext_pass_through=p_f, tau_ff_pass_through=p_t
    )
    qdd, nu = dense_pass_through(rc.model, data, q, qd, tau, fext_generalized(rc, data, q, f), A, drift, beta, p_f, p_t)
    assert_rel(res.qdd, qdd, "qdd", RTOL)
    assert_rel(res.nu, nu, "nu", RTOL)
    # zero weights are no weights, bit for bit; the weights do not outlive the call
    plain = solver.solve(q, qd, alpha=alpha, beta=beta, f_ext=f, tau_ff=tau)
    zero = solver.solve(
        q,
        qd,
        alpha=alpha,
        beta=beta,
        f_ext=f,
        tau_ff=tau,
        f_ext_pass_through=np.zeros(m),
        tau_ff_pass_through=np.zeros(m),
    )
    np.testing.assert_array_equal(zero.qdd, plain.qdd)
    np.testing.assert_array_equal(zero.nu, plain.nu)
    # the batch takes the weights per row too
    batch = solver.solve_batch(
        np.array([q, q]), qd, alpha, beta, f, tau, f_ext_pass_through=np.array([p_f, 0 * p_f]), tau_ff_pass_through=p_t
    )
    np.testing.assert_array_equal(batch.qdd[0], res.qdd)


@pytest.mark.parametrize("robot", ["panda", "gen3_gripper"])
def test_pass_through_robots_with_segment_constraints_vs_dense_formula(robot):
    r = BUILDERS[robot]()
    rng = np.random.default_rng(len(robot))
    solver = vs.Solver(r.chain, gravity=G)
    data = r.model.createData()
    names = r.chain.segment_names
    elbow, tip = names[3], names[-1]
    a_elbow, a_tip = random_alpha(rng, 1), random_alpha(rng, 2)
    q, qd = r.random_state(rng)
    pq = r.pin_q(q)
    pin.forwardKinematics(r.model, data, pq, qd, np.zeros(r.model.nv))
    pin.updateFramePlacements(r.model, data)
    rows, drift = [], []
    for name, a in ((tip, a_tip), (elbow, a_elbow)):  # nu order: end-segment alpha first, then constraints
        fid = r.model.getFrameId(name)
        rows.append(a.T @ pin.computeFrameJacobian(r.model, data, pq, fid, LWA))
        drift.append(a.T @ (pin.getFrameAcceleration(r.model, data, fid, LWA).vector + GRAV))
    A, drift = np.vstack(rows), np.concatenate(drift)
    tau = rng.normal(size=r.chain.n_joints)
    w = rng.normal(size=6) * 5.0
    J_elbow = pin.computeFrameJacobian(r.model, data, pq, r.model.getFrameId(elbow), LWA)
    beta = rng.normal(size=3)
    p_f, p_t = np.array([1.0, 0.3, 0.6]), np.array([0.0, 1.0, 0.5])
    res = solver.solve(
        q,
        qd,
        alpha=a_tip,
        beta=beta[:2],
        f_ext={elbow: w},
        tau_ff=tau,
        constraints={elbow: (a_elbow, beta[2])},
        f_ext_pass_through=p_f,
        tau_ff_pass_through=p_t,
    )
    qdd, nu = dense_pass_through(r.model, data, pq, qd, tau, J_elbow.T @ w, A, drift, beta, p_f, p_t)
    assert_rel(res.qdd, qdd, "qdd", RTOL)
    assert_rel(res.nu, nu, "nu", RTOL)


def test_pass_through_argument_errors():
    rng = np.random.default_rng(0)
    rc = chains.random_chain(rng, 4)
    solver = rc.solver()
    q, qd = random_state(rng, rc)
    a = random_alpha(rng, 2)
    with pytest.raises(vs.SolverError, match=r"f_ext_pass_through\[1\] must be in \[0, 1\]"):
        solver.solve(q, qd, alpha=a, beta=[0, 0], f_ext_pass_through=[0.5, 1.5])
    with pytest.raises(vs.SolverError, match=r"tau_ff_pass_through must have shape \(2,\)"):
        solver.solve(q, qd, alpha=a, beta=[0, 0], tau_ff_pass_through=[0.5])
    with pytest.raises(vs.SolverError, match="tau_ff_pass_through"):
        solver.solve(q, qd, alpha=a, beta=[0, 0], tau_ff_pass_through=[np.nan, 0.0])


# ------------------------------------------------------------------------------------------------
# A model remembers the inertia check it was built with; a Solver follows it unless told otherwise
# ------------------------------------------------------------------------------------------------
def test_the_model_inertia_check_is_sticky_pickled_and_the_solver_default():
    rng = np.random.default_rng(7)
    rc = identified_chain(rng, 4)
    chain = rc.chain
    assert chain.inertia_check == "joint_space"
    assert pickle.loads(pickle.dumps(chain)).inertia_check == "joint_space"
    assert chain.__copy__().inertia_check == "joint_space"
    q, qd = random_state(rng, rc)
    by_default = vs.Solver(chain).solve(q, qd)
    explicit = vs.Solver(chain, inertia_check="joint_space").solve(q, qd)
    np.testing.assert_array_equal(by_default.qdd, explicit.qdd)
    # A rigid segment added with the physical check keeps the model's joint-space check.
    chain.add_segment("rigid", "rot_z", mass=1.0, inertia=np.diag([0.01, 0.01, 0.01]))
    assert chain.inertia_check == "joint_space"
    # Physical models stay physical, and old six-entry pickle states load as physical.
    physical = vs.Chain()
    physical.add_segment("rod", "rot_x", mass=1.0, inertia=np.diag([0.1, 0.1, 0.0]))
    assert physical.inertia_check == "physical" and vs.Solver(physical).inertia_check == "physical"
    old_state = chain.__getstate__()[:6]
    restored = vs.Chain.__new__(vs.Chain)
    restored.__setstate__(old_state)
    assert restored.inertia_check == "physical"
    with pytest.raises(vs.SolverError, match="inertia_check must be"):
        vs.Chain.__new__(vs.Chain).__setstate__((*old_state, "loose"))


def test_trees_and_their_paths_keep_the_check(tmp_path):
    from vereshchagin.robots import example_robot_urdf

    tree = vs.Tree.from_urdf(example_robot_urdf("baxter"), inertia_check="joint_space")
    assert tree.inertia_check == "joint_space"
    assert tree.chain("left_wrist").inertia_check == "joint_space"
    assert pickle.loads(pickle.dumps(tree)).inertia_check == "joint_space"
    assert vs.Solver(tree).inertia_check == "joint_space"
    assert vs.Tree.from_urdf(example_robot_urdf("baxter")).inertia_check == "physical"
