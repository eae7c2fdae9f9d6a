"""The companions on the C++ kinematics and dynamics: batched fk, twist and beta_for, the cache
dropped when the model changes, and Task.solve's one-call beta equal to beta_for's."""

import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin.task import Task, beta_for


def _chain(n=5, seed=0):
    rng = np.random.default_rng(seed)
    c = vs.Chain()
    for i in range(n):
        T = np.eye(4)
        T[:3, 3] = rng.uniform(-0.3, 0.3, 3)
        c.add_segment(
            f"s{i}", "rot_" + "xyz"[i % 3], tip=T, mass=1.0 + i, com=[0.1, 0.0, 0.05], inertia=np.eye(3) * 0.01
        )
    return c


def test_batched_fk_and_twist_match_rows():
    c = _chain()
    rng = np.random.default_rng(1)
    Q, V = rng.uniform(-3, 3, (9, 5)), rng.uniform(-1, 1, (9, 5))
    F, T = c.fk(Q, "s3"), c.twist(Q, V)
    assert F.shape == (9, 4, 4) and T.shape == (9, 6)
    for r in range(9):
        np.testing.assert_array_equal(F[r], c.fk(Q[r], "s3"))
        np.testing.assert_array_equal(T[r], c.twist(Q[r], V[r]))


def test_batched_beta_for_matches_rows():
    c = _chain()
    rng = np.random.default_rng(2)
    Q, V, A = rng.uniform(-3, 3, (4, 5)), rng.uniform(-1, 1, (4, 5)), rng.uniform(-1, 1, (4, 6))
    alpha = vs.task.directions(["x", "rz"])
    T = c.twist(Q, V)
    B = beta_for(alpha, A, T)
    assert B.shape == (4, 2)
    for r in range(4):
        np.testing.assert_allclose(B[r], beta_for(alpha, A[r], T[r]), rtol=1e-15, atol=1e-15)


def test_cache_follows_model_changes():
    c = _chain(3)
    q = np.array([0.3, -0.2, 0.5])
    g3 = c.gravity_torques(q)
    c.add_segment("extra", "rot_z", mass=2.0, com=[0.2, 0.0, 0.0])
    assert c.gravity_torques(np.append(q, 0.1)).shape == (4,)
    c2 = _chain(3)
    c2.rotor_inertia = [1.0, 1.0, 1.0]
    np.testing.assert_allclose(np.diag(c2.mass_matrix(q)) - np.diag(_chain(3).mass_matrix(q)), 1.0)
    np.testing.assert_allclose(_chain(3).gravity_torques(q), g3)


def test_task_solve_beta_is_beta_for():
    c = _chain()
    solver = vs.Solver(c)
    task = Task(["x", "y", "z"])
    q, qd, a = np.full(5, 0.3), np.full(5, -0.4), [0.1, 0.0, -0.2, 0.0, 0.0, 0.0]
    expected = solver.solve(q, qd, task.alpha, beta_for(task.alpha, a, c.twist(q, qd), solver.gravity))
    # Task.solve forms beta inside the solve (a_desired=) from the sweep's own tip twist: the same
    # beta as beta_for's up to round-off (the twist is computed along another path).
    np.testing.assert_allclose(task.solve(solver, c, q, qd, a).qdd, expected.qdd, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(task.solve(solver, c, q, qd, a).qdd, solver.solve(q, qd, task.alpha, a_desired=a).qdd)
    with pytest.raises(vs.SolverError, match="a_desired must be finite"):
        task.solve(solver, c, q, qd, [np.nan] * 6)
