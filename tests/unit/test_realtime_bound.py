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


def pushed_solo12():
    """solo12 on its four feet (mu 0.3) pushed sideways on the base: the feet cannot all stick, so
    the contact stage runs its complementarity problem (Lemke's pivoting)."""
    from vereshchagin.robots import example_robot_urdf

    tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
    legs = {"FL": (0.1, 0.8, -1.6), "FR": (-0.1, 0.8, -1.6), "HL": (0.1, -0.8, 1.6), "HR": (-0.1, -0.8, 1.6)}
    joints = {f"{leg}_{j}": v for leg, vals in legs.items() for j, v in zip(("HAA", "HFE", "KFE"), vals)}
    q = np.r_[0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0, [joints[n] for n in tree.joint_names]]
    feet = [vs.Contact(f, normal=[0, 0, 1], mu=0.3) for f in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")]
    args = dict(tau_ff=np.r_[25.0, 8.0, 0.0, 0.0, 0.0, 1.5, np.zeros(12)], contacts=feet)
    return vs.Solver(tree), q, np.zeros(tree.nv), args


def test_contact_pivot_bound_gives_the_fallback_with_a_warning():
    """contact_max_pivots=1: the contact stage's fallback, reported as the friction stage's bound is
    (a RuntimeWarning of the C++ Error::Degraded message, the result returned); the default bound
    and an explicit -1 give the exact answer without a warning, also in solve_batch and step()."""
    solver, q, qd, args = pushed_solo12()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        exact = solver.solve(q, qd, **args)
        default = solver.solve(q, qd, contact_max_pivots=-1, **args)
    assert np.array_equal(exact.qdd, default.qdd)
    with pytest.warns(RuntimeWarning, match="contacts: the real-time bound of 1 pivots"):
        res = solver.solve(q, qd, contact_max_pivots=1, **args)
    forces = res.contact_force
    assert np.all(forces[:, :2] == 0.0) and np.all(forces[:, 2] >= 0.0)  # along the normals, pushing
    assert not np.allclose(res.qdd, exact.qdd)
    with pytest.warns(RuntimeWarning, match="real-time bound of 2 pivots"):
        solver.step(q, qd, 1e-3, contact_max_pivots=2, **args)
    batch = solver.solve_batch(np.stack([q, q]), qd, contact_max_pivots=1, **args)  # rows: the fallback, no warning
    assert np.array_equal(batch.qdd[1], res.qdd)


@pytest.mark.parametrize("bad", [0, -2, 1.5, True, "3", 2**31, None.__class__])
def test_invalid_contact_pivot_bounds_are_refused(bad):
    solver, q, qd, args = pushed_solo12()
    with pytest.raises(vs.SolverError, match="contact_max_pivots"):
        solver.solve(q, qd, contact_max_pivots=bad, **args)
