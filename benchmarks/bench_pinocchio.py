#!/usr/bin/env python3
"""Python benchmark: vereshchagin.Solver against Pinocchio's forward dynamics, both called from Python.

Chains: the Kinova Gen3 7-DoF arm of bench_solver.cpp (same joint origins and inertias) and seeded
random chains with n = 7, 15, 30, 60 revolute joints built with bench_solver.cpp's recipe (numpy's
generator, so not the same numbers as the C++ random chains). Each chain is built twice, as a
vereshchagin.Chain and as a pinocchio.Model, with the correspondence of tests/support/chains.py (the KDL tip
frame of the last segment is a Pinocchio OP_FRAME). 64 seeded states per chain; m = 0, 1, 6
orthonormal constraint columns on the last segment, beta = alpha^T (0, 0, 9.81, 0, 0, 0) + U(-1, 1).

Timed per call, from Python:
  ours solve        Solver.solve(q, qd, alpha, beta, None, tau)
  ours batch        Solver.solve_batch over the 64 states, time per row
  pin FD            m = 0: pin.aba(q, v, tau); m > 0: pin.forwardDynamics(q, v, tau, J, gamma) with
                    J = alpha^T J_tip and gamma precomputed
  pin pipeline      m > 0: what our solve does from alpha and beta: pin.computeAllTerms(q, v) (forward
                    kinematics with zero acceleration, joint Jacobians, M, b), J = alpha^T
                    getFrameJacobian(LWA), gamma = alpha^T (getFrameAcceleration(LWA) + [-g; 0]) - beta,
                    then pin.forwardDynamics(tau, J, gamma). m = 0: pin.aba (same as pin FD).
Our constraint alpha^T a_tip = beta is Pinocchio's J qdd + gamma = 0 with the J and gamma above
(see tests/oracles/test_pinocchio_oracle.py); every case is checked once for equal joint accelerations.

Usage: python benchmarks/bench_pinocchio.py [--out FILE] [--batches N] [--batch-ms MS]
The Markdown section goes to stdout (and FILE); progress to stderr. Exit code 2 if a check failed.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import time
from collections import namedtuple

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from bench_output import publish

N_STATES = 64
TASK_SIZES = (0, 1, 6)
UP = np.array([0.0, 0.0, 9.81, 0.0, 0.0, 0.0])  # base acceleration -g, our beta convention
LWA = pin.LOCAL_WORLD_ALIGNED
RTOL = 1e-8

# One segment: a revolute joint about `axis` of the joint frame, whose pose in the segment's root
# frame (the previous tip) is P; the tip frame in the joint frame is T; the body (mass, com, inertia
# about the com) is given in the tip frame.
Segment = namedtuple("Segment", "P axis T mass com inertia")

# Kinova Gen3 7-DoF, the table of bench_solver.cpp: URDF joint origin xyz, rpy; child link mass,
# com and inertia (ixx, iyy, izz, ixy, ixz, iyz). All joints rotate about z of the joint frame.
GEN3 = [
    (
        (0.0, 0.0, 0.15643),
        (3.1416, 2.7629e-18, -4.9305e-36),
        1.3773,
        (-2.3e-05, -0.010364, -0.07336),
        (0.00457, 0.004831, 0.001409, 1e-06, 2e-06, 0.000448),
    ),
    (
        (0.0, 0.005375, -0.12838),
        (1.5708, 2.1343e-17, -1.1102e-16),
        1.1636,
        (-4.4e-05, -0.09958, -0.013278),
        (0.011088, 0.001072, 0.011255, 5e-06, 0.0, -0.000691),
    ),
    (
        (0.0, -0.21038, -0.006375),
        (-1.5708, 1.2326e-32, -2.9122e-16),
        1.1636,
        (-4.4e-05, -0.006641, -0.117892),
        (0.010932, 0.011127, 0.001043, 0.0, -7e-06, 0.000606),
    ),
    (
        (0.0, 0.006375, -0.21038),
        (1.5708, -6.6954e-17, -1.6653e-16),
        0.9302,
        (-1.8e-05, -0.075478, -0.015006),
        (0.008147, 0.000631, 0.008316, -1e-06, 0.0, -0.0005),
    ),
    (
        (0.0, -0.20843, -0.006375),
        (-1.5708, 2.2204e-16, -6.373e-17),
        0.6781,
        (1e-06, -0.009432, -0.063883),
        (0.001596, 0.001607, 0.000399, 0.0, 0.0, 0.000256),
    ),
    (
        (0.0, 0.00017505, -0.10593),
        (1.5708, 9.2076e-28, -8.2157e-15),
        0.6781,
        (1e-06, -0.045483, -0.00965),
        (0.001641, 0.00041, 0.001641, 0.0, 0.0, -0.000278),
    ),
    (
        (0.0, -0.10593, -0.00017505),
        (-1.5708, -5.5511e-17, 9.6396e-17),
        0.364,
        (-9.3e-05, 0.000132, -0.022905),
        (0.000214, 0.000223, 0.00024, 0.0, 1e-06, -2e-06),
    ),
]


def rpy(roll, pitch, yaw):
    """KDL::Rotation::RPY: Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def frame(R=None, p=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = np.eye(3) if R is None else R, p
    return T


def gen3_segments():
    segs = []
    for xyz, angles, mass, com, (ixx, iyy, izz, ixy, ixz, iyz) in GEN3:
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        segs.append(Segment(frame(rpy(*angles), xyz), "z", np.eye(4), mass, np.array(com), inertia))
    return segs


def random_segments(n, seed):
    """bench_solver.cpp's makeRandomChain recipe: joints about x, y or z of the root frame."""
    rng = np.random.default_rng(seed)
    u = rng.uniform
    segs = []
    for _ in range(n):
        axis = "xyz"[rng.integers(3)]
        tip_pos = np.array([u(-0.05, 0.05), u(-0.05, 0.05), u(0.08, 0.2)])
        T = frame(rpy(u(-np.pi, np.pi), u(-np.pi / 2, np.pi / 2), u(-np.pi, np.pi)), tip_pos)
        mass = u(0.5, 2.0)
        com = tip_pos * u(0.3, 0.7) + u(-0.01, 0.01, 3)
        a, b, c = u(2e-4, 5e-3, 3)  # second moments: the principal moments obey the triangle inequality
        R = rpy(u(-np.pi, np.pi), u(-np.pi / 2, np.pi / 2), u(-np.pi, np.pi))
        inertia = R @ np.diag(mass * np.array([b + c, a + c, a + b])) @ R.T
        segs.append(Segment(np.eye(4), axis, T, mass, com, 0.5 * (inertia + inertia.T)))
    return segs


def build_ours(segs):
    """KDL semantics: a revolute joint with origin p and axis R e in the root frame, tip P T at q = 0."""
    chain = vs.Chain()
    for i, s in enumerate(segs):
        if np.array_equal(s.P, np.eye(4)):
            joint, tip = "rot_" + s.axis, s.T
        else:
            e = np.eye(3)["xyz".index(s.axis)]
            joint, tip = vs.Joint.revolute(s.P[:3, :3] @ e, s.P[:3, 3]), s.P @ s.T
        chain.add_segment(f"seg{i}", joint, tip=tip, mass=s.mass, com=s.com, inertia=s.inertia)
    return vs.Solver(chain, gravity=[0.0, 0.0, -9.81])


def build_pinocchio(segs):
    """One Pinocchio joint per segment (placement = previous tip * P), body and tip frame at T."""
    joint_model = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}
    model = pin.Model()
    parent, prev_tip = 0, np.eye(4)
    for i, s in enumerate(segs):
        M = prev_tip @ s.P
        parent = model.addJoint(parent, joint_model[s.axis](), pin.SE3(M[:3, :3], M[:3, 3]), f"joint{i}")
        tip = pin.SE3(s.T[:3, :3], s.T[:3, 3])
        model.appendBodyToJoint(parent, pin.Inertia(s.mass, s.com, s.inertia), tip)
        fid = model.addFrame(pin.Frame(f"tip{i}", parent, tip, pin.FrameType.OP_FRAME), False)
        prev_tip = s.T
    model.gravity = pin.Motion(np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0]))
    return model, fid  # fid: the last tip


def make_states(n, seed):
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(N_STATES):
        q, qd, tau = rng.uniform(-np.pi, np.pi, n), rng.uniform(-1, 1, n), rng.uniform(-2, 2, n)
        tasks = {}
        for m in TASK_SIZES:
            Q, _ = np.linalg.qr(rng.uniform(-1, 1, (6, 6)))
            alpha = np.ascontiguousarray(Q[:, :m])
            tasks[m] = (alpha, alpha.T @ UP + rng.uniform(-1, 1, m))
        states.append((q, qd, tau, tasks))
    return states


def pinocchio_task(model, data, fid, q, qd, alpha, beta):
    """J and gamma of Pinocchio's J qdd + gamma = 0, the way tests/oracles/test_pinocchio_oracle.py builds them."""
    pin.forwardKinematics(model, data, q, qd, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    drift = pin.getFrameAcceleration(model, data, fid, LWA).vector
    J = np.reshape(pin.computeFrameJacobian(model, data, q, fid, LWA), (6, model.nv))
    return alpha.T @ J, alpha.T @ (drift + UP) - beta


# ----------------------------------------------------------------------------------------------
# Timing: every variant runs all states once per repetition; batches of the variants of one case
# are interleaved (A B C A B C ...) and the median over batches is reported.
def time_group(variants, batches, batch_s):
    reps = {}
    for name, run in variants.items():
        elapsed, count = 0.0, 0
        while elapsed < 0.02:
            t0 = time.perf_counter()
            run(1)
            elapsed += time.perf_counter() - t0
            count += 1
        reps[name] = max(1, round(batch_s * count / elapsed))
    us = {name: [] for name in variants}
    gc.disable()
    try:
        for _ in range(batches):
            for name, run in variants.items():
                t0 = time.perf_counter()
                run(reps[name])
                us[name].append((time.perf_counter() - t0) * 1e6 / (reps[name] * N_STATES))
    finally:
        gc.enable()
    return us


def paired_ratio(a, b):
    return statistics.median(x / y for x, y in zip(a, b))


def per_state(fn, args):
    def run(reps):
        for _ in range(reps):
            for a in args:
                fn(*a)

    return run


def rel_diff(a, b):
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1.0)


def bench_case(label, segs, seed, batches, batch_s):
    solver = build_ours(segs)
    model, fid = build_pinocchio(segs)
    data = model.createData()
    n = model.nv
    states = make_states(n, seed)
    Q, QD, TAU = (np.array([s[k] for s in states]) for k in range(3))
    rows = []
    for m in TASK_SIZES:
        ours_args = [(q, qd, *(s[m] if m else (None, None)), None, tau) for q, qd, tau, s in states]
        batch_args = (
            Q,
            QD,
            *((np.array([s[3][m][0] for s in states]), np.array([s[3][m][1] for s in states])) if m else (None, None)),
            None,
            TAU,
        )
        if m == 0:
            pin_args = [(model, data, q, qd, tau) for q, qd, tau, _ in states]
            pin_fd = pin.aba
        else:
            pin_args = [
                (model, data, q, qd, tau, *pinocchio_task(model, data, fid, q, qd, *s[m])) for q, qd, tau, s in states
            ]
            pin_fd = pin.forwardDynamics

        def pipeline(q, qd, tau, alpha, beta):
            pin.computeAllTerms(model, data, q, qd)
            J = alpha.T @ pin.getFrameJacobian(model, data, fid, LWA)
            gamma = alpha.T @ (pin.getFrameAcceleration(model, data, fid, LWA).vector + UP) - beta
            return pin.forwardDynamics(model, data, tau, J, gamma)

        # Check once: all variants give the same joint accelerations.
        expected = np.array([np.array(pin_fd(*a)) for a in pin_args])
        got = {
            "ours solve": np.array([solver.solve(*a).qdd for a in ours_args]),
            "ours batch": solver.solve_batch(*batch_args).qdd,
        }
        if m:
            got["pin pipeline"] = np.array([np.array(pipeline(q, qd, tau, *s[m])) for q, qd, tau, s in states])
        worst = max(rel_diff(g[i], expected[i]) for g in got.values() for i in range(N_STATES))

        variants = {
            "ours solve": per_state(solver.solve, ours_args),
            "ours batch": lambda reps, args=batch_args: [solver.solve_batch(*args) for _ in range(reps)],
            "pin FD": per_state(pin_fd, pin_args),
        }
        if m:
            variants["pin pipeline"] = per_state(pipeline, [(q, qd, tau, *s[m]) for q, qd, tau, s in states])
        print(f"timing {label}, m {m} ...", file=sys.stderr, flush=True)
        us = time_group(variants, batches, batch_s)
        pipe = "pin pipeline" if m else "pin FD"
        rows.append(
            dict(
                label=label,
                m=m,
                worst=worst,
                **{k: statistics.median(v) for k, v in us.items()},
                r_fd=paired_ratio(us["ours solve"], us["pin FD"]),
                r_pipe=paired_ratio(us["ours solve"], us[pipe]),
                r_batch=paired_ratio(us["ours batch"], us[pipe]),
                spread=max((np.percentile(v, 75) - np.percentile(v, 25)) / np.median(v) for v in us.values()),
            )
        )
    return rows


def report(rows, batches, batch_s, wall):
    failed = [r for r in rows if not r["worst"] <= RTOL]
    out = ["## Python: vereshchagin.Solver vs Pinocchio (both called from Python)", ""]
    out.append(
        f"Python {sys.version.split()[0]}, numpy {np.__version__}, pinocchio {pin.__version__}, "
        f"vereshchagin from `{vs.__file__}`. {N_STATES} seeded states per chain, m = 0, 1, 6; "
        f"time.perf_counter, {batches} interleaved batches of about {batch_s * 1e3:.0f} ms per variant, "
        f"median per-call time; ratio = median of per-batch ratios. Run time {wall:.0f} s; largest batch "
        f"inter-quartile range / median: {100 * max(r['spread'] for r in rows):.0f} %."
    )
    out.append("")
    out.append(
        "Columns (microseconds per call): `ours solve` = `Solver.solve(q, qd, alpha, beta, None, tau)`; "
        "`ours batch` = `Solver.solve_batch` over the 64 states, per row; `pin FD` = `pin.aba` for m = 0, "
        "`pin.forwardDynamics(q, v, tau, J, gamma)` with J and gamma precomputed for m > 0; `pin pipeline` "
        "= what our solve does from alpha and beta: `computeAllTerms`, `getFrameJacobian` and "
        "`getFrameAcceleration` (LOCAL_WORLD_ALIGNED) to form J = alpha^T J_tip and gamma = "
        "alpha^T (a_tip(qdd = 0) + [-g; 0]) - beta, then `forwardDynamics(tau, J, gamma)` (for m = 0 the "
        "same as `pin.aba`). The like-for-like ratio is ours solve / pin pipeline. max rel dqdd = largest "
        "||qdd - qdd_pin|| / max(||qdd_pin||, 1) over the states and our two entry points (and the pipeline)."
    )
    out.append("")
    out.append(
        "| n | m | ours solve us | ours batch us/row | pin FD us | pin pipeline us | ours / pin FD | "
        "ours / pin pipeline | ours batch / pin pipeline | max rel dqdd |"
    )
    out.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        pipe = r.get("pin pipeline", r["pin FD"])
        flag = "" if r["worst"] <= RTOL else " **FAIL**"
        out.append(
            f"| {r['label']} | {r['m']} | {r['ours solve']:.2f} | {r['ours batch']:.2f} | {r['pin FD']:.2f} | "
            f"{pipe:.2f} | {r['r_fd']:.2f} | {r['r_pipe']:.2f} | {r['r_batch']:.2f} | {r['worst']:.1e}{flag} |"
        )
    if failed:
        out.append("")
        out.append(f"**{len(failed)} case(s) disagree with Pinocchio by more than {RTOL:.0e} (relative).**")
    return "\n".join(out) + "\n", not failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="also write the Markdown section to this file")
    ap.add_argument("--batches", type=int, default=31)
    ap.add_argument("--batch-ms", type=float, default=10.0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    cases = [("7 (Gen3)", gen3_segments(), 1000)]
    cases += [(f"{n} (random)", random_segments(n, 0x5EED0000 + n), 1000 + n) for n in (7, 15, 30, 60)]
    rows = []
    for label, segs, seed in cases:
        rows += bench_case(label, segs, seed, args.batches, args.batch_ms * 1e-3)
    text, ok = report(rows, args.batches, args.batch_ms * 1e-3, time.perf_counter() - t0)
    publish(text, args.out)
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
