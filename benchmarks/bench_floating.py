#!/usr/bin/env python3
"""Python benchmark: floating bases (free-flyer) against Pinocchio, both called from Python.

Talos (reduced), solo12 and ANYmal from example-robot-data, loaded by both libraries with a
free-flyer root (``Tree.from_urdf(..., base="free")``, ``pin.JointModelFreeFlyer()``):

  free motion   ``Solver.solve(q, qd, tau_ff=tau)`` against ``pin.aba(q, v, tau)``
  feet held     ``Solver.solve(q, qd, tau_ff=tau, constraints={foot: (alpha, beta)})`` (6-D soles on
                Talos, 3-D points on the quadrupeds' feet; alpha identity columns, world axes,
                beta = -gravity) against ``pin.constraintDynamics`` with one ``RigidConstraintModel``
                per foot (CONTACT_6D / CONTACT_3D, LOCAL, ``ProximalSettings(1e-12, 0, 1)``); qd = 0
                there, so that the feet's spatial and classical accelerations coincide.

64 seeded states per case (a unit quaternion, joint torques, zero on the base); every answer is
compared (relative 1e-9) before timing. Interleaved batches, medians; ratio = ours / Pinocchio
(median of per-batch ratios).

Usage: python benchmarks/bench_floating.py [--out FILE] [--batches N]
The Markdown section goes to stdout (and FILE); progress to stderr. Exit code 2 if a check failed.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

N_STATES = 64
RTOL = 1e-9
GRAVITY = np.array([0.0, 0.0, -9.81])
ROBOTS = [  # label, URDF (example-robot-data), feet, 6-D feet
    ("Talos (reduced)", "talos_data/robots/talos_reduced.urdf", ["left_sole_link", "right_sole_link"], True),
    ("solo12", "solo_description/robots/solo12.urdf", ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"], False),
    ("ANYmal", "anymal_b_simple_description/robots/anymal.urdf", ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"], False),
]


class Pair:
    """One URDF in both libraries on a free-flyer, with the maps of our state to Pinocchio's."""

    def __init__(self, path, check):
        self.tree = vs.Tree.from_urdf(path, base="free", inertia_check=check)
        self.solver = vs.Solver(self.tree, gravity=GRAVITY, max_constraints=24, inertia_check=check)
        self.model = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
        self.model.gravity = pin.Motion(np.r_[GRAVITY, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        ids = [self.model.getJointId(n) for n in self.tree.joint_names]
        self.iq = np.r_[np.arange(7), [self.model.joints[i].idx_q for i in ids]]
        self.iv = np.r_[np.arange(6), [self.model.joints[i].idx_v for i in ids]]

    def states(self, rng, moving):
        out = []
        for _ in range(N_STATES):
            q = np.r_[rng.uniform(-0.8, 0.8, 7 + self.tree.n_joints)]
            q[3:7] /= np.linalg.norm(q[3:7])
            qd = rng.uniform(-1.0, 1.0, self.tree.nv) if moving else np.zeros(self.tree.nv)
            tau = np.r_[np.zeros(6), rng.uniform(-5.0, 5.0, self.tree.n_joints)]
            pq, pv, ptau = np.empty(self.model.nq), np.empty(self.model.nv), np.empty(self.model.nv)
            pq[self.iq], pv[self.iv], ptau[self.iv] = q, qd, tau
            out.append((q, qd, tau, pq, pv, ptau))
        return out


def rel_diff(ours, pins, iv):
    ref = np.asarray(ours)
    return float(np.max(np.abs(np.asarray(pins)[iv] - ref)) / max(1.0, np.max(np.abs(ref))))


def timed(fns, states, batches, batch_s=0.01):
    """Per-call microseconds of each fn over the states, interleaved batches: (medians, ratios to fns[0])."""
    reps = []
    for fn in fns:
        n, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < 0.02:
            for s in states:
                fn(s)
            n += 1
        reps.append(max(1, round(batch_s / ((time.perf_counter() - t0) / n))))
    us = [[] for _ in fns]
    for _ in range(batches):
        for k, fn in enumerate(fns):
            t0 = time.perf_counter()
            for _ in range(reps[k]):
                for s in states:
                    fn(s)
            us[k].append((time.perf_counter() - t0) / (reps[k] * len(states)) * 1e6)
    med = [statistics.median(u) for u in us]
    ratios = [statistics.median(a / b for a, b in zip(us[0], u)) for u in us]
    return med, ratios


def bench_robot(label, urdf, feet, six_d, seed, batches, rows):
    p = Pair(example_robot_urdf(urdf), "joint_space" if label == "ANYmal" else "physical")
    rng = np.random.default_rng(seed)
    solve, m, d = p.solver.solve, p.model, p.data
    states = p.states(rng, moving=True)
    err = max(rel_diff(solve(q, qd, tau_ff=t).qdd, pin.aba(m, d, a, b, c), p.iv) for q, qd, t, a, b, c in states)
    print(f"timing {label} free motion ...", file=sys.stderr)
    med, ratio = timed(
        [lambda s: solve(s[0], s[1], tau_ff=s[2]), lambda s: pin.aba(m, d, s[3], s[4], s[5])], states, batches
    )
    dof = f"{label} ({p.tree.nv} DOF)"
    rows += [(dof, "free motion", "ours (Solver.solve)", med[0], None, None)]
    rows += [("", "", "pin.aba", med[1], ratio[1], err)]

    k = 6 if six_d else 3
    alpha, beta = np.eye(6)[:, :k], -np.r_[GRAVITY, 0.0, 0.0, 0.0][:k]
    cons = {f: (alpha, beta) for f in feet}
    kind = pin.ContactType.CONTACT_6D if six_d else pin.ContactType.CONTACT_3D
    cms = []
    for f in feet:
        fr = m.frames[m.getFrameId(f)]
        cms.append(pin.RigidConstraintModel(kind, m, fr.parentJoint, fr.placement, pin.ReferenceFrame.LOCAL))
    cds = [c.createData() for c in cms]
    pin.initConstraintDynamics(m, d, cms, cds)
    settings = pin.ProximalSettings(1e-12, 0.0, 1)
    states = p.states(rng, moving=False)
    err = max(
        rel_diff(
            solve(q, qd, tau_ff=t, constraints=cons).qdd,
            pin.constraintDynamics(m, d, a, b, c, cms, cds, settings),
            p.iv,
        )
        for q, qd, t, a, b, c in states
    )
    print(f"timing {label} feet held ...", file=sys.stderr)
    med, ratio = timed(
        [
            lambda s: solve(s[0], s[1], tau_ff=s[2], constraints=cons),
            lambda s: pin.constraintDynamics(m, d, s[3], s[4], s[5], cms, cds, settings),
        ],
        states,
        batches,
    )
    rows += [("", f"{len(feet)} feet, {k}-D (m = {len(feet) * k})", "ours (Solver.solve)", med[0], None, None)]
    rows += [("", "", "pin.constraintDynamics", med[1], ratio[1], err)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None)
    ap.add_argument("--batches", type=int, default=31)
    args = ap.parse_args()
    rows = []
    for r, (label, urdf, feet, six_d) in enumerate(ROBOTS):
        bench_robot(label, urdf, feet, six_d, 2800 + r, args.batches, rows)
    md = [
        "### Python (bench_floating.py)",
        "",
        f"pinocchio {pin.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}. Both libraries "
        f"called from Python (each pays its call overhead). {N_STATES} seeded states per case, {args.batches} "
        "interleaved batches of about 10 ms, medians; ratio = ours / Pinocchio (median of per-batch ratios; target "
        "at most 0.7). Free motion against `pin.aba` (random q, qd, joint torques); feet held (qd = 0) against "
        "`pin.constraintDynamics` with one `RigidConstraintModel` per foot (CONTACT_6D soles on Talos, CONTACT_3D "
        "points on the quadrupeds, LOCAL, `ProximalSettings(1e-12, 0, 1)`), ours one `constraints=` entry per foot "
        "(alpha identity columns, beta = -gravity). `max rel. diff` = largest |qdd - ours|_inf / max(1, "
        "|ours|_inf), checked before timing.",
        "",
        "| robot | case | solver | us per call | ours / it | max rel. diff of qdd |",
        "|---|---|---|---:|---:|---:|",
    ]
    for robot, case, solver, us, ratio, err in rows:
        r = "-" if ratio is None else f"{ratio:.2f}"
        e = "-" if err is None else f"{err:.1e}"
        md.append(f"| {robot} | {case} | {solver} | {us:.2f} | {r} | {e} |")
    text = "\n".join(md) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)
    bad = [r for r in rows if r[5] is not None and not r[5] <= RTOL]
    if bad:
        print(f"answers differ from Pinocchio's by more than {RTOL:g}: {bad}", file=sys.stderr)
    return 2 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
