"""Models of any size either solve or raise (issue 23), with memory linear in their size.

The constraint coupling workspace is sized for ``max_constraints`` columns (default: the smaller
of 6 per segment and 256), not for 6 per segment: a 1,000-joint chain's solver took 2.7 GB and a
4,000-joint one was killed by the operating system; the friction solver's dense joint-space
workspace is built at the first friction-aware solve only. Memory is measured in child processes
(peak resident set of the process before and after building the solver and solving once).
"""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import vereshchagin as vs

CHAIN = """
import resource, numpy as np, vereshchagin as vs
def long_chain(n):
    c = vs.Chain()
    T = np.eye(4); T[2, 3] = 0.01
    for k in range(n):
        c.add_segment(f"l{k}", "rot_y" if k % 2 else "rot_x", tip=T, mass=0.1, com=[0, 0, -0.005],
                      inertia=np.diag([1e-5, 1e-5, 1e-6]))
    return c
def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
"""


def run_python(code, timeout=600):
    proc = subprocess.run(
        [sys.executable, "-c", CHAIN + textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def test_a_1000_joint_solver_takes_under_20_mb():
    out = run_python(
        """
        chain = long_chain(1000)
        q = np.zeros(1000)
        before = peak_mb()
        solver = vs.Solver(chain)
        res = solver.solve(q, q)
        print(peak_mb() - before, np.isfinite(res.qdd).all())
        """
    )
    grown, finite = out.split()
    assert finite == "True"
    assert float(grown) < 20.0, f"a 1,000-joint solver grew the process by {grown} MB"


def test_a_10000_joint_chain_solves_and_agrees_with_its_own_inverse_dynamics():
    out = run_python(
        """
        chain = long_chain(10000)
        rng = np.random.default_rng(1)
        q, qd = rng.uniform(-0.3, 0.3, 10000), rng.uniform(-0.1, 0.1, 10000)
        res = vs.Solver(chain).solve(q, qd)
        tau = chain.inverse_dynamics(q, qd, res.qdd)  # RNEA: zero torque reproduces the free motion
        print(np.abs(tau).max() / np.abs(chain.gravity_torques(q)).max())
        """,
        timeout=900,
    )
    assert float(out) < 1e-8  # relative to the gravity torques; round-off grows with the chain's length


def test_max_constraints_sets_the_capacity_and_names_itself_when_exceeded():
    rng = np.random.default_rng(3)
    chain = vs.robots.gen3()
    q, qd = rng.uniform(-1, 1, 7), np.zeros(7)
    keys = list(chain.segment_names)
    constraints = {k: (np.eye(6)[:, :2], np.zeros(2)) for k in keys[:4]}  # 8 columns
    capped = vs.Solver(chain, max_constraints=8)
    default = vs.Solver(chain)
    np.testing.assert_array_equal(
        capped.solve(q, qd, constraints=constraints).qdd, default.solve(q, qd, constraints=constraints).qdd
    )
    constraints[keys[4]] = (np.eye(6)[:, :1], np.zeros(1))  # 9 columns
    with pytest.raises(vs.SolverError, match="max_constraints"):
        capped.solve(q, qd, constraints=constraints)
    with pytest.raises(vs.SolverError, match="max_constraints"):
        capped.solve_batch(np.tile(q, (3, 1)), np.zeros((3, 7)), constraints=constraints)
    default.solve(q, qd, constraints=constraints)  # 9 of at most 42: fine
    import pickle

    again = pickle.loads(pickle.dumps(capped))
    with pytest.raises(vs.SolverError, match="max_constraints"):
        again.solve(q, qd, constraints=constraints)
    for bad in (0, -1, 2.5, True, "8"):
        with pytest.raises(vs.SolverError, match="max_constraints"):
            vs.Solver(chain, max_constraints=bad)


def affine_oracle(solver, q, qd, joints, constraints=None):
    """Columns of d qdd / d tau_ff by differences of solves (qdd is affine in tau_ff: exact up to
    round-off), the oracle of response_columns on models wider than its 64-column chunks."""
    n = len(q)
    base = solver.solve(q, qd, constraints=constraints).qdd
    cols = []
    for j in joints:
        tau = np.zeros(n)
        tau[j] = 1.0
        cols.append(solver.solve(q, qd, tau_ff=tau, constraints=constraints).qdd - base)
    return np.array(cols).T


def test_response_columns_of_a_100_joint_chain_in_chunks():
    c = vs.Chain()
    T = np.eye(4)
    T[2, 3] = 0.05
    for k in range(100):
        c.add_segment(
            f"l{k}",
            ("rot_x", "rot_y", "rot_z")[k % 3],
            tip=T,
            mass=0.5,
            com=[0, 0, -0.02],
            inertia=np.diag([2e-4, 2e-4, 1e-4]),
        )
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-0.5, 0.5, 100), rng.uniform(-0.2, 0.2, 100)
    solver = vs.Solver(c)
    constraints = {"l99": (np.eye(6)[:, :3], np.zeros(3)), "l40": (np.eye(6)[:, 3:5], np.zeros(2))}
    for cons in (None, constraints):
        solver.solve(q, qd, constraints=cons)
        joints = list(range(100))
        dqdd, _ = solver.response_columns(joints)
        expected = affine_oracle(solver, q, qd, joints, cons)
        scale = np.abs(expected).max()
        assert np.abs(dqdd - expected).max() <= 1e-9 * scale
