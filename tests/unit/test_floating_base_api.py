"""The floating-base face of the Python package (docs/floating-base.md): base kinds from URDF,
nq / nv, the sizes Solver.solve takes and returns, and what is refused with a message."""

from __future__ import annotations

import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin.robots import gen3_urdf


@pytest.fixture(scope="module")
def urdf():
    return gen3_urdf(gripper=False)


def test_base_kinds_and_sizes(urdf):
    fixed = vs.Tree.from_urdf(urdf)
    n = fixed.n_joints
    assert (fixed.base, fixed.nq, fixed.nv) == ("fixed", n, n)
    free = vs.Tree.from_urdf(urdf, base="free")
    assert (free.base, free.nq, free.nv) == ("free", n + 7, n + 6)
    planar = vs.Tree.from_urdf(urdf, base="planar")
    assert (planar.base, planar.nq, planar.nv) == ("planar", n + 4, n + 3)
    with pytest.raises(vs.SolverError, match="base must be 'fixed', 'free' or 'planar'"):
        vs.Tree.from_urdf(urdf, base="floating")


def test_copies_and_pickles_keep_the_base(urdf):
    # (Round 1 refused to pickle a floating Tree; its state now carries the base kind and inertia.)
    import copy
    import pickle

    for kind in ("planar", "free"):
        tree = vs.Tree.from_urdf(urdf, base=kind)
        assert copy.copy(tree).base == copy.deepcopy(tree).base == kind
        back = pickle.loads(pickle.dumps(tree))
        assert back.base == kind and (back.nq, back.nv) == (tree.nq, tree.nv)
        q = np.r_[0.1, -0.2, np.zeros(tree.nq - 2)]
        q[6 if kind == "free" else 2] = 1.0
        qd = np.linspace(-0.5, 0.5, tree.nv)
        np.testing.assert_array_equal(vs.Solver(back).solve(q, qd).qdd, vs.Solver(tree).solve(q, qd).qdd)
        np.testing.assert_array_equal(back.mass_matrix(q), tree.mass_matrix(q))
    fixed = vs.Tree.from_urdf(urdf)
    assert len(fixed.__getstate__()) == 7  # a fixed base's state as before
    state = list(tree.__getstate__())
    state[7] = ("free", [1.0] * 12)
    with pytest.raises(vs.SolverError, match="malformed base entry"):
        vs.Tree.__new__(vs.Tree).__setstate__(tuple(state))
    state[7] = ("floating", [1.0] * 13)
    with pytest.raises(vs.SolverError, match="the base must be 'fixed', 'free' or 'planar'"):
        vs.Tree.__new__(vs.Tree).__setstate__(tuple(state))


def test_solve_sizes(urdf):
    tree = vs.Tree.from_urdf(urdf, base="free")
    solver = vs.Solver(tree)
    q = np.r_[0.1, -0.2, 0.3, 0.0, 0.0, 0.0, 1.0, np.zeros(tree.n_joints)]
    r = solver.solve(q, np.zeros(tree.nv), tau_ff=np.zeros(tree.nv))
    assert r.qdd.shape == (tree.nv,) and r.tau_command.shape == (tree.nv,)
    np.testing.assert_allclose(r.qdd[:3], [0.0, 0.0, -9.81], atol=1e-12)  # free fall
    with pytest.raises(vs.SolverError, match="qd"):
        solver.solve(q, np.zeros(tree.n_joints))
    with pytest.raises(vs.SolverError, match="not supported on a floating base yet"):  # (friction is)
        held = {tree.segment_names[-1]: (np.eye(6)[:, :1], [0.0])}
        solver.solve(q, np.zeros(tree.nv), constraints=held, f_ext_pass_through=[0.5])
    r = solver.solve(q, np.zeros(tree.nv), friction=vs.Friction(static=np.ones(tree.n_joints)))
    assert r.qdd.shape == (tree.nv,) and r.friction_torque.shape == (tree.nv,)  # the base rows 0


def test_fixed_base_unchanged(urdf):
    # base="fixed" is the default load, bit for bit.
    a, b = vs.Tree.from_urdf(urdf), vs.Tree.from_urdf(urdf, base="fixed")
    q = np.linspace(-1.0, 1.0, a.n_joints)
    qd = np.linspace(0.5, -0.5, a.n_joints)
    np.testing.assert_array_equal(vs.Solver(a).solve(q, qd).qdd, vs.Solver(b).solve(q, qd).qdd)
