#!/usr/bin/env python3
"""Python benchmark of the time step and the Simulator (docs/time-step.md, "Simulator").

The Kinova Gen3 (vereshchagin.robots.gen3) near the pose (0, 0.6, 0, 2.1, 0, 0.45, 1.57), 64
seeded states, static friction |gravity torque| x U(0.3, 1.5) + 0.2 N m (kinetic 0.8 of it) so
that some joints stick and some slip, dt = 1 ms. Timed per call, interleaved batches of about
10 ms (A B C A B C ...), medians, ratios the median of the per-batch ratios:

  solve            solver.solve(q, qd, friction=f): the friction-aware solve at the instant
  Solver.step      solver.step(q, qd, dt, friction=f): the same over dt, integrated (the C++ step)

for joints at rest, moving (qd U(-0.5, 0.5) rad/s) and at rest with a support (mu 0.6) under the
wrist. Target (issue 27): a step at most 1.5x the friction-aware solve. Then steps per second of
the Simulator, which steps on from its own state: Simulator.step and Simulator.rollout (per step,
recording friction_torque) of an arm held by friction (1.2 x |gravity torque| + 0.2 N m: the same
problem every step), and of one swinging down from the pose with friction 0.3 N m (reset to the
pose before each batch of 64 steps, so every batch times the same 64 steps; Simulator.step's batch
includes the reset, about 1% of it).

Usage: python benchmarks/bench_step.py [--out FILE] [--batches N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import vereshchagin as vs
from bench_output import publish

POSE = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
DT = 1e-3
N_STATES = 64


def _states(chain, moving, rng):
    out = []
    for _ in range(N_STATES):
        q = POSE + rng.uniform(-0.3, 0.3, 7)
        qd = rng.uniform(-0.5, 0.5, 7) if moving else np.zeros(7)
        fs = np.abs(chain.gravity_torques(q)) * rng.uniform(0.3, 1.5, 7) + 0.2
        out.append((q, qd, vs.Friction(static=fs, kinetic=0.8 * fs)))
    return out


def _calibrate(body, batch_s):
    reps, elapsed = 1, 0.0
    while elapsed < batch_s / 4:
        t0 = time.perf_counter()
        body(reps)
        elapsed = time.perf_counter() - t0
        reps *= 2
    return max(1, int(reps / 2 * batch_s / max(elapsed, 1e-9)))


def _time(bodies, batches, batch_s=0.01):
    """Per-call microseconds per batch for each body(reps) -> calls made."""
    reps = [_calibrate(b, batch_s) for b in bodies]
    us = [[] for _ in bodies]
    for _ in range(batches):
        for k, b in enumerate(bodies):
            t0 = time.perf_counter()
            calls = b(reps[k])
            us[k].append((time.perf_counter() - t0) * 1e6 / calls)
    return us


def _case(chain, states, contacts, batches):
    solver = vs.Solver(chain)
    kw = {"contacts": contacts} if contacts else {}

    def solve(reps):
        for _ in range(reps):
            for q, qd, f in states:
                solver.solve(q, qd, friction=f, **kw)
        return reps * len(states)

    def step(reps):
        for _ in range(reps):
            for q, qd, f in states:
                solver.step(q, qd, DT, friction=f, **kw)
        return reps * len(states)

    us = _time([solve, step], batches)
    return [statistics.median(u) for u in us], statistics.median(a / b for a, b in zip(us[1], us[0]))


def _simulator(chain, q0, friction, batches):
    sim = vs.Simulator(chain, DT, q=q0)
    zero = np.zeros(7)

    def step(reps):
        for _ in range(reps):
            sim.reset(q0, zero)
            for _ in range(N_STATES):
                sim.step(friction=friction)
        return reps * N_STATES

    def rollout(reps):
        for _ in range(reps):
            sim.reset(q0, zero)
            sim.rollout(N_STATES, friction=friction, record=("friction_torque",))
        return reps * N_STATES

    return [statistics.median(u) for u in _time([step, rollout], batches)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="also write the markdown report here")
    ap.add_argument("--batches", type=int, default=31)
    args = ap.parse_args()
    chain = vs.robots.gen3()
    rng = np.random.default_rng(20261127)
    rest, moving = _states(chain, False, rng), _states(chain, True, rng)
    support = [vs.Contact(5, point=[0.0, 0.0, -0.05], normal=[0.0, 0.0, 1.0], mu=0.6)]
    lines = [
        "### Time step (Python, `bench_step.py`)",
        "",
        f"The Gen3 with joint friction, {N_STATES} states (some joints sticking, some slipping), dt = 1 ms; "
        "per-call medians of interleaved batches; the ratio is the median of per-batch ratios. Target (issue 27): "
        "a step at most 1.5x the friction-aware solve.",
        "",
        "| case | solve (friction, instant) us | Solver.step us | step / solve |",
        "|---|---:|---:|---:|",
    ]
    cases = (("at rest", rest, None), ("moving", moving, None), ("at rest + support (mu 0.6)", rest, support))
    for label, states, contacts in cases:
        med, ratio = _case(chain, states, contacts, args.batches)
        lines.append(f"| {label} | {med[0]:.2f} | {med[1]:.2f} | {ratio:.2f}x |")
    lines += [
        "",
        "| Simulator | Simulator.step us | steps per second | rollout us per step | steps per second |",
        "|---|---:|---:|---:|---:|",
    ]
    held = vs.Friction(static=1.2 * np.abs(chain.gravity_torques(POSE)) + 0.2)
    for label, friction in (
        ("held by friction", held),
        ("swinging, friction 0.3 N m", vs.Friction(static=np.full(7, 0.3))),
    ):
        st, ro = _simulator(chain, POSE, friction, args.batches)
        lines.append(f"| {label} | {st:.2f} | {1e6 / st:.0f} | {ro:.2f} | {1e6 / ro:.0f} |")
    md = "\n".join(lines) + "\n"
    publish(md, args.out)


if __name__ == "__main__":
    main()
