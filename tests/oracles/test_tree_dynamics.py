"""The dynamics companions of Tree against Pinocchio reading the same URDF trees.

Robots as in ``tests/oracles/test_tree_solver.py``: Baxter, Talos (``talos_reduced`` below ``base_link``)
and random trees (``tests/support/trees.py``); joints are mapped to Pinocchio's by name. Every expected
value comes from Pinocchio (``pin.rnea``, ``pin.crba``, ``pin.computeGeneralizedGravity``,
``pin.nonLinearEffects``, frame placements and Jacobian time variations, ``armature`` for the rotor
inertia), from the Chain's KDL-based companions (a chain given as a tree), or from the hybrid
solver (its qdd replayed through inverse dynamics gives back its tau_ff).
"""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import fext_at_frames, moving_frames, symmetric
from support.trees import ROBOTS, robot
from support.urdf_robots import LWA, assert_rel
from vereshchagin.robots import gen3_urdf

RTOL = 1e-9
GRAVITY = np.array([1.3, -0.8, -9.7])  # tilted: a gravity frame error cannot hide


def _pin_with(case, gravity=GRAVITY, rotor=None):
    """A copy of the case's Pinocchio model with this gravity and (ours, (n,)) rotor inertia."""
    model = case.model.copy()
    model.gravity = pin.Motion(np.r_[gravity, 0.0, 0.0, 0.0])
    model.armature = case.pin_v(np.zeros(case.n) if rotor is None else rotor)
    return model


def _state(case, rng):
    q, qd = case.random_state(rng)
    return q, qd, rng.normal(size=case.n) * 2.0


# ------------------------------------------------------------------------------------------------
# Against Pinocchio
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_inverse_dynamics_matches_rnea(name):
    case = robot(name)
    model = _pin_with(case)
    data = model.createData()
    rng = np.random.default_rng([51, len(name)])
    for k in range(4):
        q, qd, qdd = _state(case, rng)
        f_ext = rng.normal(size=(case.tree.n_segments, 6)) * 5.0 if k % 2 else None
        pq = case.pin_q(q)
        rows = None if f_ext is None else dict(zip(case.tree.segment_names, f_ext))  # per segment's tip frame
        fext = None if rows is None else fext_at_frames(model, data, pq, rows)
        args = (model, data, pq, case.pin_v(qd), case.pin_v(qdd)) + ((fext,) if fext is not None else ())
        expected = case.ours(pin.rnea(*args))
        got = case.tree.inverse_dynamics(q, qd, qdd, f_ext=f_ext, gravity=GRAVITY)
        assert_rel(got, expected, f"{name}: inverse_dynamics vs pin.rnea (f_ext {f_ext is not None})", RTOL)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_inverse_dynamics_reads_an_f_ext_dict_as_pinocchio(name):
    """f_ext as {frame: wrench}, the moment about that frame's origin (merged links included), as
    Pinocchio's fext on the frame's parent joint."""
    case = robot(name)
    model = _pin_with(case)
    data = model.createData()
    rng = np.random.default_rng([52, len(name)])
    frames = moving_frames(case.tree)
    for k in range(3):
        q, qd, qdd = _state(case, rng)
        pq = case.pin_q(q)
        wrenches = {f: rng.normal(size=6) * 5.0 for f in frames[k::3][:6]}
        fext = fext_at_frames(model, data, pq, wrenches)
        expected = case.ours(pin.rnea(model, data, pq, case.pin_v(qd), case.pin_v(qdd), fext))
        got = case.tree.inverse_dynamics(q, qd, qdd, f_ext=wrenches, gravity=GRAVITY)
        assert_rel(got, expected, f"{name}: inverse_dynamics with f_ext {sorted(wrenches)} vs pin.rnea", RTOL)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_mass_gravity_and_coriolis_match_pinocchio(name):
    case = robot(name)
    model = _pin_with(case)
    data = model.createData()
    rng = np.random.default_rng([52, len(name)])
    for _ in range(3):
        q, qd, _ = _state(case, rng)
        pq, pv = case.pin_q(q), case.pin_v(qd)
        M = symmetric(pin.crba(model, data, pq))[np.ix_(case.idx_v, case.idx_v)]
        assert_rel(case.tree.mass_matrix(q), M, f"{name}: mass_matrix vs pin.crba", RTOL)
        g = case.ours(pin.computeGeneralizedGravity(model, data, pq))
        assert_rel(case.tree.gravity_torques(q, gravity=GRAVITY), g, f"{name}: gravity_torques", RTOL)
        c = case.ours(pin.nonLinearEffects(model, data, pq, pv)) - g
        assert_rel(case.tree.coriolis_torques(q, qd), c, f"{name}: coriolis_torques", RTOL)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_fk_all_and_jacobian_dot_match_pinocchio(name):
    case = robot(name)
    model = case.model
    data = model.createData()
    tree = case.tree
    rng = np.random.default_rng([53, len(name)])
    q, qd, _ = _state(case, rng)
    pq, pv = case.pin_q(q), case.pin_v(qd)
    pin.computeJointJacobiansTimeVariation(model, data, pq, pv)
    pin.updateFramePlacements(model, data)
    poses = tree.fk_all(q)
    assert poses.shape == (tree.n_segments, 4, 4)
    for i, seg in enumerate(tree.segment_names):
        expected = data.oMf[model.getFrameId(seg, pin.BODY)].homogeneous
        assert_rel(poses[i], expected, f"{name}: fk_all[{seg}]", RTOL)
    for link in tree.link_names:  # segments, merged links (offset from their tip) and base links
        dJ = pin.getFrameJacobianTimeVariation(model, data, model.getFrameId(link, pin.BODY), LWA)
        assert_rel(tree.jacobian_dot_times_qd(q, qd, link), dJ @ pv, f"{name}: Jdot qd of {link}", RTOL)


def test_jacobian_dot_is_the_derivative_of_the_jacobian():
    """Independent of Pinocchio: (J(q + h qd) - J(q - h qd)) / 2h @ qd on a random tree."""
    case = robot("random_8")
    tree = case.tree
    q, qd, _ = _state(case, np.random.default_rng(54))
    h = 1e-6
    for seg in tree.segment_names:
        dJ = (tree.jacobian(q + h * qd, seg) - tree.jacobian(q - h * qd, seg)) / (2 * h)
        assert_rel(tree.jacobian_dot_times_qd(q, qd, seg), dJ @ qd, f"Jdot qd of {seg} vs differences", 1e-7)


# ------------------------------------------------------------------------------------------------
# Rotor inertia
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["baxter", "talos", "random_3"])
def test_rotor_inertia_is_pinocchios_armature_and_reaches_the_solver(name):
    case = robot(name)
    tree = copy.copy(case.tree)
    rng = np.random.default_rng([55, len(name)])
    rotor = rng.uniform(0.0, 0.5, case.n)
    before = vs.Solver(tree, gravity=GRAVITY)
    np.testing.assert_array_equal(tree.rotor_inertia, np.zeros(case.n))
    tree.rotor_inertia = rotor
    np.testing.assert_array_equal(tree.rotor_inertia, rotor)
    assert list(tree.joint_names) == list(case.tree.joint_names)
    assert list(tree.segment_names) == list(case.tree.segment_names)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(tree)).rotor_inertia, rotor)
    after = vs.Solver(tree, gravity=GRAVITY)
    np.testing.assert_array_equal(after.model.rotor_inertia, rotor)
    plain, armed = _pin_with(case), _pin_with(case, rotor=rotor)
    data = armed.createData()
    q, qd, qdd = _state(case, rng)
    pq, pv = case.pin_q(q), case.pin_v(qd)
    tau = rng.normal(size=case.n) * 3.0
    M = symmetric(pin.crba(armed, data, pq))[np.ix_(case.idx_v, case.idx_v)]
    assert_rel(tree.mass_matrix(q), M, f"{name}: mass_matrix with armature", RTOL)
    expected = case.ours(pin.rnea(armed, data, pq, pv, case.pin_v(qdd)))
    assert_rel(tree.inverse_dynamics(q, qd, qdd, gravity=GRAVITY), expected, f"{name}: rnea with armature", RTOL)
    aba = case.ours(pin.aba(armed, data, pq, pv, case.pin_v(tau)))
    assert_rel(after.solve(q, qd, tau_ff=tau).qdd, aba, f"{name}: Solver built after the set", RTOL)
    aba0 = case.ours(pin.aba(plain, plain.createData(), pq, pv, case.pin_v(tau)))
    assert_rel(before.solve(q, qd, tau_ff=tau).qdd, aba0, f"{name}: Solver built before keeps its copy", RTOL)
    assert not np.allclose(aba, aba0, rtol=1e-3), "the rotor inertia must change the motion"


# ------------------------------------------------------------------------------------------------
# Consistency with the Chain and with the hybrid solver
# ------------------------------------------------------------------------------------------------
def test_a_chain_loaded_as_a_tree_has_the_chains_companions():
    urdf = gen3_urdf(False)
    chain, tree = vs.Chain.from_urdf(urdf), vs.Tree.from_urdf(urdf)
    rotor = np.linspace(0.1, 0.7, 7)
    chain.rotor_inertia = rotor
    tree.rotor_inertia = rotor
    rng = np.random.default_rng(56)
    tip = chain.segment_names[-1]
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, 7), rng.uniform(-1, 1, 7), rng.normal(size=7)
        f_ext = rng.normal(size=(chain.n_segments, 6)) * 4.0
        pairs = {
            "inverse_dynamics": (
                tree.inverse_dynamics(q, qd, qdd, f_ext, GRAVITY),
                chain.inverse_dynamics(q, qd, qdd, f_ext, GRAVITY),
            ),
            "mass_matrix": (tree.mass_matrix(q), chain.mass_matrix(q)),
            "gravity_torques": (tree.gravity_torques(q, GRAVITY), chain.gravity_torques(q, GRAVITY)),
            "coriolis_torques": (tree.coriolis_torques(q, qd), chain.coriolis_torques(q, qd)),
            "jacobian_dot_times_qd": (tree.jacobian_dot_times_qd(q, qd, tip), chain.jacobian_dot_times_qd(q, qd)),
            "fk_all": (tree.fk_all(q), chain.fk_all(q)),
        }
        for what, (ours, kdl) in pairs.items():
            assert_rel(ours, kdl, f"tree vs chain: {what}", RTOL)


@pytest.mark.parametrize("name", ["baxter", "talos", "random_11"])
def test_solver_qdd_replayed_through_inverse_dynamics_gives_tau_ff(name):
    case = robot(name)
    tree = copy.copy(case.tree)
    rng = np.random.default_rng([57, len(name)])
    tree.rotor_inertia = rng.uniform(0.0, 0.3, case.n)
    solver = vs.Solver(tree, gravity=GRAVITY)
    for _ in range(3):
        q, qd, _ = _state(case, rng)
        tau = rng.normal(size=case.n) * 4.0
        f_ext = rng.normal(size=(tree.n_segments, 6)) * 3.0
        qdd = solver.solve(q, qd, tau_ff=tau, f_ext=f_ext).qdd
        assert_rel(tree.inverse_dynamics(q, qd, qdd, f_ext, GRAVITY), tau, f"{name}: ID(solve(tau)) = tau", RTOL)


# ------------------------------------------------------------------------------------------------
# Bad input
# ------------------------------------------------------------------------------------------------
def test_bad_input_raises_the_chains_messages():
    tree = robot("baxter").tree
    n, ns = tree.n_joints, tree.n_segments
    z = np.zeros(n)
    chain = tree.chain("left_gripper")
    nc, zc = chain.n_joints, np.zeros(chain.n_joints)
    cases = [
        (lambda t, z, k: t.inverse_dynamics(z[:-1], z, z), "q must have shape ({k},), got ({km},)"),
        (lambda t, z, k: t.inverse_dynamics(z, z, np.r_[z, 0.0]), "qdd must have shape ({k},), got ({kp},)"),
        (lambda t, z, k: t.mass_matrix(np.full(k, np.nan)), "q contains NaN or Inf (flat index 0)"),
        (lambda t, z, k: t.gravity_torques(z, gravity=[0.0, -9.81]), "gravity must have shape (3,), got (2,)"),
        (lambda t, z, k: t.coriolis_torques(z, np.full(k, True)), "qd must hold real numbers (int or float)"),
        (lambda t, z, k: t.fk_all(None), "q must be a real array, got None"),
        (lambda t, z, k: t.coriolis_torques(z, np.full(k, 1e160)), "coriolis_torques: the result overflows"),
    ]
    for call, message in cases:
        for model, zeros, k in ((tree, z, n), (chain, zc, nc)):
            text = message.format(k=k, km=k - 1, kp=k + 1)
            with pytest.raises(vs.SolverError) as err:
                call(model, zeros, k)
            assert text in str(err.value), (type(model).__name__, str(err.value))
    with pytest.raises(vs.SolverError, match=rf"f_ext must have shape \({ns}, 6\) or be a dict .*, got \(6,\)"):
        tree.inverse_dynamics(z, z, z, f_ext=np.zeros(6))
    with pytest.raises(vs.SolverError, match=r"f_ext\['head'\] must have shape \(6,\), got \(3,\)"):
        tree.inverse_dynamics(z, z, z, f_ext={"head": np.zeros(3)})
    with pytest.raises(vs.SolverError, match=r"f_ext\['nowhere'\]: no segment or link named 'nowhere'"):
        tree.inverse_dynamics(z, z, z, f_ext={"nowhere": np.zeros(6)})
    with pytest.raises(vs.SolverError, match=r"f_ext\['head'\] contains NaN or Inf"):
        tree.inverse_dynamics(z, z, z, f_ext={"head": np.r_[np.nan, np.zeros(5)]})
    with pytest.raises(vs.SolverError, match=r"f_ext contains NaN or Inf \(flat index 7\)"):
        tree.inverse_dynamics(z, z, z, f_ext=np.r_[np.zeros(7), np.inf, np.zeros(6 * ns - 8)].reshape(ns, 6))
    with pytest.raises(vs.SolverError, match="segment: no segment or link named 'hand'"):
        tree.jacobian_dot_times_qd(z, z, "hand")
    with pytest.raises(vs.SolverError, match="segment index 99 out of range"):
        tree.jacobian_dot_times_qd(z, z, 99)
    np.testing.assert_array_equal(tree.jacobian_dot_times_qd(z, np.ones(n), tree.root_link), np.zeros(6))
    bad = tree.rotor_inertia.copy()
    bad[3] = -0.1
    for model, values in ((tree, bad), (chain, bad[:nc])):
        with pytest.raises(vs.SolverError, match="rotor_inertia must be >= 0, got -0.100000 at joint 3"):
            model.rotor_inertia = values
        with pytest.raises(vs.SolverError, match=r"rotor_inertia must have shape"):
            model.rotor_inertia = values[:-1]
    np.testing.assert_array_equal(tree.rotor_inertia, np.zeros(n))  # a failed set changes nothing
