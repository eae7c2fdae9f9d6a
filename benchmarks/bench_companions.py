#!/usr/bin/env python3
"""Python benchmark: the dynamics companions of vereshchagin.Chain against Pinocchio, and Task.solve.

Chains: the Kinova Gen3 7-DoF arm and the seeded random 15- and 30-joint chains of bench_pinocchio.py,
built as a vereshchagin.Chain and a pinocchio.Model. 64 seeded states; every pair is checked once for
equal results (relative 1e-9). Timed per call, from Python, in interleaved batches (median of 31):
  gravity_torques(q)            vs pin.computeGeneralizedGravity
  inverse_dynamics(q, qd, qdd)  vs pin.rnea
  mass_matrix(q)                vs pin.crba (upper triangle; ours returns the full symmetric matrix)
  coriolis_torques(q, qd)       vs pin.nonLinearEffects (Coriolis + gravity: one sweep either way)
  jacobian(q)                   vs pin.computeFrameJacobian(LOCAL_WORLD_ALIGNED) of the tip frame
and Task(["x", "y", "z"]).solve against Solver.solve of the same alpha and beta (Gen3).

Usage: python benchmarks/bench_companions.py [--out FILE]
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

import bench_pinocchio as bp
from bench_output import publish
import vereshchagin as vs
from vereshchagin.task import Task, beta_for


def chain_of(segs):
    chain = vs.Chain()
    for i, s in enumerate(segs):
        if np.array_equal(s.P, np.eye(4)):
            joint, tip = "rot_" + s.axis, s.T
        else:
            e = np.eye(3)["xyz".index(s.axis)]
            joint, tip = vs.Joint.revolute(s.P[:3, :3] @ e, s.P[:3, 3]), s.P @ s.T
        chain.add_segment(f"seg{i}", joint, tip=tip, mass=s.mass, com=s.com, inertia=s.inertia)
    return chain


def per_call(fn, states, batches=31, batch_s=0.01):
    """Median per-call time (us) over batches of calls cycling through the states."""
    reps = 1
    while True:
        t0 = time.perf_counter()
        for k in range(reps):
            fn(*states[k % len(states)])
        if time.perf_counter() - t0 > batch_s:
            break
        reps *= 2
    times = []
    for _ in range(batches):
        t0 = time.perf_counter()
        for k in range(reps):
            fn(*states[k % len(states)])
        times.append((time.perf_counter() - t0) / reps * 1e6)
    return statistics.median(times)


def bench_chain(label, segs, seed, rows):
    chain = chain_of(segs)
    model, fid = bp.build_pinocchio(segs)
    data = model.createData()
    n = model.nv
    rng = np.random.default_rng(seed)
    states = [(rng.uniform(-3, 3, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)) for _ in range(64)]
    pairs = [
        (
            "gravity_torques",
            lambda q, v, a: chain.gravity_torques(q),
            lambda q, v, a: pin.computeGeneralizedGravity(model, data, q),
        ),
        (
            "inverse_dynamics",
            lambda q, v, a: chain.inverse_dynamics(q, v, a),
            lambda q, v, a: pin.rnea(model, data, q, v, a),
        ),
        ("mass_matrix", lambda q, v, a: chain.mass_matrix(q), lambda q, v, a: pin.crba(model, data, q)),
        (
            "coriolis_torques",
            lambda q, v, a: chain.coriolis_torques(q, v),
            lambda q, v, a: pin.nonLinearEffects(model, data, q, v),
        ),
        (
            "jacobian",
            lambda q, v, a: chain.jacobian(q),
            lambda q, v, a: pin.computeFrameJacobian(model, data, q, fid, bp.LWA),
        ),
    ]
    q, v, a = states[0]
    checks = {
        "gravity_torques": (chain.gravity_torques(q), pin.computeGeneralizedGravity(model, data, q)),
        "inverse_dynamics": (chain.inverse_dynamics(q, v, a), pin.rnea(model, data, q, v, a)),
        "mass_matrix": (
            chain.mass_matrix(q),
            np.triu(pin.crba(model, data, q)) + np.triu(pin.crba(model, data, q), 1).T,
        ),
        "coriolis_torques": (
            chain.coriolis_torques(q, v) + chain.gravity_torques(q),
            pin.nonLinearEffects(model, data, q, v),
        ),
        "jacobian": (chain.jacobian(q), pin.computeFrameJacobian(model, data, q, fid, bp.LWA)),
    }
    ok = True
    for name, ours, theirs in pairs:
        o, t = checks[name]
        err = np.abs(o - t).max() / max(1.0, np.abs(t).max())
        ok &= err < 1e-9
        print(f"timing {label} {name} ...", file=sys.stderr, flush=True)
        t_ours, t_pin = per_call(ours, states), per_call(theirs, states)
        rows.append((label, n, name, t_ours, t_pin, err))
    return ok


def bench_task(rows):
    segs = bp.gen3_segments()
    chain = chain_of(segs)
    solver = vs.Solver(chain, gravity=[0.0, 0.0, -9.81])
    task = Task(["x", "y", "z"])
    rng = np.random.default_rng(5)
    states = []
    for _ in range(64):
        q, qd, acc = rng.uniform(-3, 3, 7), rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 6)
        states.append((q, qd, acc, beta_for(task.alpha, acc, chain.twist(q, qd), solver.gravity)))
    t_task = per_call(lambda q, qd, acc, beta: task.solve(solver, chain, q, qd, acc), states)
    t_bare = per_call(lambda q, qd, acc, beta: solver.solve(q, qd, task.alpha, beta), states)
    rows.append(("Gen3", 7, "Task.solve (vs Solver.solve)", t_task, t_bare, 0.0))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    args = ap.parse_args()
    gc.disable()
    rows, ok = [], True
    ok &= bench_chain("Gen3", bp.gen3_segments(), 1, rows)
    for n in (15, 30):
        ok &= bench_chain(f"random {n}", bp.random_segments(n, 100 + n), n, rows)
    bench_task(rows)
    out = [
        "## Dynamics companions from Python against Pinocchio",
        "",
        f"`benchmarks/bench_companions.py`: Chain's companions (C++ `dynamics.hpp` / `kinematics.hpp`) against "
        f"Pinocchio {pin.__version__}'s algorithms, both called from Python; median per-call time of 31 "
        "batches of about 10 ms over 64 seeded states (ratio below 1: ours is faster). The last row compares "
        "`Task.solve` with a bare `Solver.solve` of the same alpha and beta.",
        "",
        "| chain | n | call | ours (us) | reference (us) | ratio | max rel. diff |",
        "|---|---:|---|---:|---:|---:|---:|",
    ]
    for label, n, name, t_o, t_p, err in rows:
        out.append(f"| {label} | {n} | {name} | {t_o:.2f} | {t_p:.2f} | {t_o / t_p:.2f} | {err:.1e} |")
    text = "\n".join(out) + "\n"
    publish(text, args.out)
    sys.exit(0 if ok else 2)


if __name__ == "__main__":
    main()
