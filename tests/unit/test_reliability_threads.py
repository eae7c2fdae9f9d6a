"""Thread safety and determinism (issue 7) for every entry point, friction and batch included:
separate solver instances used from 4 Python threads at once (the GIL is released during the
C++ solve) give bit-identical results to sequential use, and the same inputs give bit-identical
outputs across calls and instances. (test_api.py covers the plain frictionless solve.)"""

import threading

import numpy as np

import vereshchagin as vs
from support.chains import random_alpha, random_chain, random_f_ext, random_state

THREADS = 4


def workload(seed, count=12):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, 6, fixed_prob=0.2)
    n = rc.n_joints
    calls = []
    for k in range(count):
        q, qd = random_state(rng, rc)
        qd[rng.random(n) < 0.5] = 0.0  # resting joints for friction
        m = k % 4
        alpha = random_alpha(rng, m) if m else None
        beta = rng.normal(size=m) if m else None
        fs = rng.uniform(0, 3, n)
        fr = vs.Friction(static=fs, kinetic=fs * rng.uniform(0, 1, n))
        calls.append((q, qd, alpha, beta, random_f_ext(rng, rc), rng.normal(size=n), fr))
    batch = (rng.uniform(-1, 1, (16, n)), rng.uniform(-1, 1, (16, n)))
    return rc, calls, batch


def run(rc, calls, batch, barrier=None):
    """Every entry point on a fresh solver; returns all output arrays in order."""
    solver = vs.Solver(rc.chain)
    if barrier is not None:
        barrier.wait()
    out = []
    for _ in range(2):
        out = []
        for q, qd, alpha, beta, f_ext, tau, fr in calls:
            for friction in (None, fr):
                r = solver.solve(q, qd, alpha, beta, f_ext, tau, friction=friction)
                out += [r.qdd, r.tau_command, r.nu, r.link_acc, np.array([r.smallest_singular_value])]
                if friction is not None:
                    out += [r.friction_torque, r.limit_torque, r.status, np.array([r.gauss_value])]
                out += list(solver.response_columns(list(range(rc.n_joints))))
        b = solver.solve_batch(*batch)
        out += [b.qdd, b.tau_command, b.link_acc]
    return out


def test_four_threads_match_sequential_bitwise():
    work = [workload(300 + k) for k in range(THREADS)]
    sequential = [run(*w) for w in work]
    barrier = threading.Barrier(THREADS)
    results = [None] * THREADS
    errors = []

    def worker(i):
        try:
            results[i] = run(*work[i], barrier=barrier)
        except Exception as e:  # reported below with the thread index
            errors.append((i, e))

    threads = [threading.Thread(target=worker, args=(i,)) for i in range(THREADS)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for i in range(THREADS):
        assert len(results[i]) == len(sequential[i])
        for a, b in zip(results[i], sequential[i]):
            assert np.array_equal(a, b), f"thread {i}: results differ from sequential use"


def test_four_threads_share_one_chain():
    # The same Chain object feeding four solvers concurrently (solvers copy it).
    rc, calls, batch = workload(400)
    reference = run(rc, calls, batch)
    barrier = threading.Barrier(THREADS)
    results = [None] * THREADS
    threads = [
        threading.Thread(target=lambda i=i: results.__setitem__(i, run(rc, calls, batch, barrier)))
        for i in range(THREADS)
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert r is not None and all(np.array_equal(a, b) for a, b in zip(r, reference))


def test_bit_identical_across_calls_and_instances():
    rc, calls, batch = workload(500)
    first = run(rc, calls, batch)
    again = run(rc, calls, batch)  # another instance
    for a, b in zip(first, again):
        assert np.array_equal(a, b)
    # the same instance, interleaved with other inputs, then repeated
    solver = vs.Solver(rc.chain)
    q, qd, alpha, beta, f_ext, tau, fr = calls[3]
    r1 = solver.solve(q, qd, alpha, beta, f_ext, tau, friction=fr)
    for c in calls:
        solver.solve(*c[:6], friction=c[6])
    r2 = solver.solve(q, qd, alpha, beta, f_ext, tau, friction=fr)
    for name in ("qdd", "tau_command", "nu", "link_acc", "friction_torque", "limit_torque", "status"):
        assert np.array_equal(getattr(r1, name), getattr(r2, name)), name
    assert r1.gauss_value == r2.gauss_value
