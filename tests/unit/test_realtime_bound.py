"""The friction stage's real-time iteration bound (``Friction(max_iterations=...)``, issue 27).

A bound forced below what a resting 7-joint arm needs gives the documented fallback with a
RuntimeWarning (friction within its bounds, doing no positive work in sum), at the instant and
over a step; the default bound is not hit and gives the exhaustive bound's results bitwise;
invalid bounds are refused.
"""

import copy
import pickle
import warnings

import numpy as np
import pytest

import vereshchagin as vs


def arm(seed=7, n=7):
    rng = np.random.default_rng(seed)
    chain = vs.Chain()
    for i in range(n):
        tip = np.eye(4)
        tip[:3, 3] = [rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(0.1, 0.3)]
        chain.add_segment(
            f"link{i}", "rot_" + "xyz"[rng.integers(3)], tip=tip, mass=rng.uniform(0.5, 2.0), com=tip[:3, 3] / 2
        )
    return vs.Solver(chain, gravity=[0.0, 0.0, -9.81])


def hard_cases(solver, count=40, seed=11):
    """Resting states near breakaway whose exhaustive solve needs more than 2 iterations."""
    rng = np.random.default_rng(seed)
    chain = solver.chain
    n = chain.n_joints
    zero = np.zeros(n)
    out = []
    for _ in range(count):
        q = rng.uniform(-np.pi, np.pi, n)
        f = rng.uniform(0.7, 1.3, n) * np.abs(chain.gravity_torques(q)) + 1e-3
        res = solver.solve(q, zero, friction=vs.Friction(static=f, max_iterations=0))
        if res.iterations > 2:
            out.append((q, f, res))
    assert len(out) >= 5
    return out


def check_fallback(res, f, rows):
    fr = res.friction_torque
    assert np.all(np.abs(fr) <= f)
    assert np.all(np.abs(res.limit_torque) <= 1e-12 * f)
    assert fr @ rows <= 1e-9 * max(1.0, np.abs(fr * rows).sum())


def test_forced_bound_gives_the_fallback_with_a_warning():
    solver = arm()
    for q, f, exact in hard_cases(solver):
        for bound in (1, 2):
            with pytest.warns(RuntimeWarning, match="real-time bound"):
                res = solver.solve(q, np.zeros(7), friction=vs.Friction(static=f, max_iterations=bound))
            assert res.iterations == bound
            check_fallback(res, f, res.qdd)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            default = solver.solve(q, np.zeros(7), friction=vs.Friction(static=f))
        assert default.iterations == exact.iterations
        for name in ("qdd", "friction_torque", "tau_command"):
            assert np.array_equal(getattr(default, name), getattr(exact, name))


def test_forced_bound_over_a_step():
    solver = arm(seed=8)
    dt = 1e-3
    degraded = 0
    for q, f, _ in hard_cases(solver, seed=12):
        qd = np.full(7, 0.01)
        exact = solver.solve(q, qd, time_step=dt, friction=vs.Friction(static=f, max_iterations=0))
        if exact.iterations <= 1:
            continue
        with pytest.warns(RuntimeWarning, match="real-time bound"):
            _, _, res = solver.step(q, qd, dt, friction=vs.Friction(static=f, max_iterations=1))
        check_fallback(res, f, res.qdd + qd / dt)
        degraded += 1
    assert degraded >= 3


@pytest.mark.parametrize("bad", [-2, 1.5, True, "3", 2**31])
def test_invalid_bounds_are_refused(bad):
    with pytest.raises(vs.SolverError, match="max_iterations"):
        arm().solve(np.zeros(7), np.zeros(7), friction=vs.Friction(static=np.ones(7), max_iterations=bad))


def test_the_bound_survives_copies():
    fr = vs.Friction(static=np.ones(3), max_iterations=5)
    assert pickle.loads(pickle.dumps(fr)).max_iterations == 5
    assert copy.deepcopy(fr).max_iterations == 5
    assert vs.Friction(static=np.ones(3)).max_iterations == -1
