#!/usr/bin/env python3
"""Python benchmark: constrained dynamics of kinematic trees, ours against Pinocchio's pipeline.

Robots: Baxter (example-robot-data: head, two 7-joint arms, two-finger grippers, 19 joints) with
6-D constraints on one hand (m = 6) or on both hands (m = 12), and m = 0 (plain forward dynamics);
seeded random trees of 15, 30 and 60 moving joints (revolute, continuous, prismatic; tests/support/trees.py, written as URDF text and
loaded by both libraries) with 3-D constraints on two leaves of different branches (m = 6; random trees are shallow, so
each leaf has 3 joints of its own, not 6), for the scaling in n at fixed m.

Timed per call, from Python, 64 seeded states per robot, interleaved batches, medians:
  ours          solver.solve(q, qd, tau_ff=tau, constraints={hand: (alpha, beta), ...})
  pin pipeline  what our solve does from alpha and beta: pin.computeAllTerms(q, v) (kinematics with
                zero acceleration, joint Jacobians, M, b), per constrained frame J_i = alpha_i^T
                getFrameJacobian(LWA) and gamma_i = alpha_i^T (getFrameAcceleration(LWA) + [-g; 0])
                - beta_i, then pin.forwardDynamics(tau, J, gamma) on the stacked rows.
                m = 0: pin.aba.
Both are checked once per case for equal joint accelerations (by joint name).

Usage: python benchmarks/bench_tree.py [--out FILE] [--batches N] [--batch-ms MS]
The Markdown section goes to stdout (and FILE); progress to stderr. Exit code 2 if a check failed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests"))
from bench_pinocchio import LWA, N_STATES, UP, paired_ratio, rel_diff, time_group  # noqa: E402
from bench_output import publish  # noqa: E402
from support.trees import pin_q, pin_v_index, random_solvable_tree  # noqa: E402  (tests/support/trees.py)

G = -UP[:3]
RTOL = 1e-8


class Robot:
    """Our tree and solver and Pinocchio's model of one URDF, with the joint map by name."""

    def __init__(self, label, path=None, text=None):
        self.label = label
        self.tree = vs.Tree.from_urdf(path if path is not None else text)
        self.solver = vs.Solver(self.tree, gravity=G)
        self.model = pin.buildModelFromUrdf(path) if path is not None else pin.buildModelFromXML(text)
        self.model.gravity = pin.Motion(np.r_[G, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        self.idx = pin_v_index(self.model, list(self.tree.joint_names))

    @property
    def n(self):
        return self.tree.n_joints

    def to_pin(self, x):
        out = np.zeros(self.model.nv)
        out[self.idx] = x
        return out

    def to_pin_q(self, q):
        return pin_q(self.model, list(self.tree.joint_names), q)


def make_states(robot, frames, seed, cols):
    rng = np.random.default_rng(seed)
    lo = np.maximum(np.asarray(robot.tree.lower, float), -np.pi)
    hi = np.minimum(np.asarray(robot.tree.upper, float), np.pi)
    states = []
    for _ in range(N_STATES):
        q, qd, tau = rng.uniform(lo, hi), rng.uniform(-1, 1, robot.n), rng.uniform(-2, 2, robot.n)
        cons = {}
        for f in frames:
            Q, _ = np.linalg.qr(rng.uniform(-1, 1, (6, 6)))
            alpha = np.ascontiguousarray(Q[:, :cols])
            cons[f] = (alpha, alpha.T @ UP + rng.uniform(-1, 1, cols))
        states.append((q, qd, tau, cons))
    return states


def pipeline(robot, fids):
    model, data = robot.model, robot.data

    def run(q, v, tau, cons):
        pin.computeAllTerms(model, data, q, v)
        rows, gammas = [], []
        for fid, (alpha, beta) in zip(fids, cons.values()):
            rows.append(alpha.T @ pin.getFrameJacobian(model, data, fid, LWA))
            gammas.append(alpha.T @ (pin.getFrameAcceleration(model, data, fid, LWA).vector + UP) - beta)
        return pin.forwardDynamics(model, data, tau, np.vstack(rows), np.concatenate(gammas))

    return run


def bench_case(robot, frames, seed, batches, batch_s, cols=6):
    states = make_states(robot, frames, seed, cols)
    pin_states = [(robot.to_pin_q(q), robot.to_pin(qd), robot.to_pin(tau), c) for q, qd, tau, c in states]
    fids = [robot.model.getFrameId(f) for f in frames]
    solve = robot.solver.solve
    pin_fd = pipeline(robot, fids)
    model, data = robot.model, robot.data

    # correctness first
    worst = 0.0
    for (q, qd, tau, cons), (pq, pv, pt, pc) in zip(states[:8], pin_states[:8]):
        ours = solve(q, qd, tau_ff=tau, constraints=cons).qdd if cons else solve(q, qd, tau_ff=tau).qdd
        ref = pin_fd(pq, pv, pt, pc) if cons else pin.aba(model, data, pq, pv, pt)
        worst = max(worst, rel_diff(ours, np.asarray(ref)[robot.idx]))

    def ours(reps):
        for q, qd, tau, cons in states:
            for _ in range(reps):
                solve(q, qd, tau_ff=tau, constraints=cons)

    def theirs(reps):
        for pq, pv, pt, pc in pin_states:
            for _ in range(reps):
                if pc:
                    pin_fd(pq, pv, pt, pc)
                else:
                    pin.aba(model, data, pq, pv, pt)

    print(f"timing {robot.label}, m = {cols * len(frames)} ...", file=sys.stderr, flush=True)
    us = time_group({"ours": ours, "pin": theirs}, batches, batch_s)
    return dict(
        robot=robot.label,
        n=robot.n,
        m=cols * len(frames),
        frames=", ".join(frames) or "-",
        ours=statistics.median(us["ours"]),
        pin=statistics.median(us["pin"]),
        ratio=paired_ratio(us["ours"], us["pin"]),
        err=worst,
    )


def random_robot(n, seed):
    """A random tree of n moving joints (no fixed ones) and two leaves on different branches, each
    with at least 3 joints of its own (not shared with the other's path), so that 3-D constraints on
    both are independent."""
    drawn = random_solvable_tree(seed, n_links=n, p_fixed=0.0)
    best = None
    for a in drawn.leaves:
        for b in drawn.leaves:
            own_a, own_b = set(drawn.path(a)) - set(drawn.path(b)), set(drawn.path(b)) - set(drawn.path(a))
            if a < b and min(len(own_a), len(own_b)) >= 3:
                score = len(own_a) + len(own_b)
                best = max(best or (0, a, b), (score, a, b))
    assert best is not None, f"random tree {seed}: no two leaves with 3 joints of their own"
    return Robot(f"random tree, {n} joints", text=drawn.urdf), best[1:]


def report(rows, batches, batch_s, wall):
    out = ["## Trees: constrained dynamics of branched robots, ours vs Pinocchio's pipeline (Python)", ""]
    out.append(
        f"Python {sys.version.split()[0]}, numpy {np.__version__}, pinocchio {pin.__version__}, "
        f"{os.cpu_count()} cores, load average {' '.join(open('/proc/loadavg').read().split()[:3])} at the "
        f"end. {N_STATES} seeded states per robot; {batches} interleaved batches of about {batch_s * 1e3:.0f} ms "
        f"per variant, medians; ratio = median of the per-batch ratios. Run time {wall:.0f} s."
    )
    out.append("")
    out.append(
        "`ours` = `solver.solve(q, qd, tau_ff=tau, constraints={frame: (alpha, beta), ...})` on a `vs.Tree`; "
        "`pin` = `pin.computeAllTerms`, the LOCAL_WORLD_ALIGNED frame Jacobians and accelerations of the "
        "constrained frames, `pin.forwardDynamics` on the stacked rows (m = 0: `pin.aba`). `max rel. diff` "
        "= largest relative difference of qdd over 8 states (joints matched by name)."
    )
    out.append("")
    out.append(
        "| robot | n | m | constrained frames | ours us | pin us | ours / pin | us per joint (ours) | max rel. diff |"
    )
    out.append("|---|---:|---:|---|---:|---:|---:|---:|---:|")
    for r in rows:
        out.append(
            f"| {r['robot']} | {r['n']} | {r['m']} | {r['frames']} | {r['ours']:.2f} | {r['pin']:.2f} | "
            f"{r['ratio']:.2f} | {r['ours'] / r['n']:.3f} | {r['err']:.1e} |"
        )
    out.append("")
    baxter = [r["ratio"] for r in rows if r["robot"] == "Baxter" and r["m"] > 0]
    scaling = [r for r in rows if r["robot"].startswith("random")]
    per_joint = [r["ours"] / r["n"] for r in scaling]
    out.append(
        f"Targets: Baxter with constraints, ours / pipeline <= 0.5: {', '.join(f'{x:.2f}' for x in baxter)}; "
        f"linear in n at fixed m: time per joint over n = {', '.join(str(r['n']) for r in scaling)}: "
        f"{', '.join(f'{x:.3f}' for x in per_joint)} us."
    )
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out")
    ap.add_argument("--batches", type=int, default=15)
    ap.add_argument("--batch-ms", type=float, default=10.0)
    args = ap.parse_args()
    batch_s = args.batch_ms * 1e-3
    t0 = time.perf_counter()
    baxter = Robot("Baxter", path=example_robot_urdf("baxter"))
    rows = [
        bench_case(baxter, frames, 300 + k, args.batches, batch_s)
        for k, frames in enumerate([(), ("left_gripper",), ("left_gripper", "right_gripper")])
    ]
    for n in (15, 30, 60):
        robot, leaves = random_robot(n, 0x7EE0000 + n)
        rows.append(bench_case(robot, leaves, 400 + n, args.batches, batch_s, cols=3))
    text = report(rows, args.batches, batch_s, time.perf_counter() - t0)
    publish(text, args.out)
    return 2 if any(r["err"] > RTOL for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
