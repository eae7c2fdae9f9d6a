#!/usr/bin/env python3
"""Constraints on several segments: Solver.solve(constraints=...) against Pinocchio's KKT solve, from Python.

Robots: the Kinova Gen3 7-DoF with the rigid Robotiq 2F-85 (``vereshchagin.robots.gen3(True)`` and
``pin.buildModelFromXML(gen3_urdf(True))``; continuous joints are (cos, sin) pairs in Pinocchio) and the
Franka Panda of example-robot-data up to ``panda_hand`` (Pinocchio's finger joints locked at 0, as in
tests/oracles/test_urdf_pinocchio.py). Gravity (0, 0, -9.81) in both, no rotor inertia.

Constraint sets (segment: m_i), in the order of the table: tool: 6; elbow: 3; elbow: 3 + tool: 3;
upper arm: 1 + elbow: 2 + tool: 3. Elbow = the segment whose tip origin is the elbow joint (Gen3
``forearm_link``, Panda ``panda_link4``), upper arm = the one before it (``half_arm_2_link``,
``panda_link3``), tool = ``end_effector_link`` / ``panda_hand``. alpha_i = I for m_i = 6, otherwise m_i
random orthonormal columns of R^6 ([linear; angular], base-frame axes), drawn per state. (Purely linear
elbow rows are not used: the axes of joints 1-3 pass through the shoulder point (Panda) or within about
6 mm of it (Gen3), so the shoulder-elbow distance is (nearly) fixed and three linear elbow rows have rank 2.)
64 seeded states per robot, the same for every set: q uniform within the joint limits clipped to
[-pi, pi], q_dot in [-1, 1], tau_ff in [-2, 2], beta_i = alpha_i^T (0, 0, 9.81, 0, 0, 0) + U(-1, 1) (our
beta includes -g). A state is kept only if every set is well conditioned there: smallest / largest
eigenvalue of A M^-1 A^T >= 1e-4.

Timed per call, from Python (interleaved batches and medians, the timer of bench_pinocchio.py):
  ours              Solver.solve(q, qd, tau_ff=tau, constraints={segment: (alpha_i, beta_i), ...})
  pin pipeline      what our solve does from alpha and beta: pin.computeAllTerms(q, v) (kinematics with
                    zero acceleration, joint Jacobians, M, b), getFrameJacobian and getFrameAcceleration
                    (LOCAL_WORLD_ALIGNED) of every constrained segment's tip frame, A = blockdiag(alpha_i)^T
                    [J_i], gamma = blockdiag(alpha_i)^T [a0_i + (0, 0, 9.81, 0, 0, 0)] - [beta_i], then
                    pin.forwardDynamics(tau, A, gamma) (blockdiag(alpha_i)^T and [beta_i] prepared once per state)
  pin KKT only      pin.forwardDynamics(q, v, tau, A, gamma) with A and gamma precomputed
  ours alpha=       tool-only rows: the same task as Solver.solve(q, qd, alpha, beta, None, tau) (end-segment
                    arguments, no dict), for the cost of the constraints= entry point
Our rows alpha_i^T a_i = beta_i are Pinocchio's A qdd + gamma = 0 (tests/oracles/test_segment_constraints.py);
nu = -lambda. Before timing every state is checked: qdd of all three and nu against -lambda agree to
1e-8 relative, and our constraint rank is the total m.

Usage: python benchmarks/bench_segments.py [--out FILE] [--batches 61] [--batch-ms 10]
Markdown to stdout (and FILE); progress to stderr. Exit code 2 if a check failed. About 15-20 s.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import scipy.linalg

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf, gen3, gen3_urdf

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pinocchio import N_STATES, RTOL, UP, paired_ratio, per_state, rel_diff, time_group  # noqa: E402
from bench_output import publish  # noqa: E402

LWA = pin.LOCAL_WORLD_ALIGNED
G = np.array([0.0, 0.0, -9.81])
MIN_EIG_RATIO = 1e-4  # smallest / largest eigenvalue of A M^-1 A^T for a state to be kept


def gen3_robot():
    return gen3(True), pin.buildModelFromXML(gen3_urdf(True))


def panda_robot():
    path = example_robot_urdf("panda")
    full = pin.buildModelFromUrdf(path)
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    return vs.Chain.from_urdf(path, tip="panda_hand"), pin.buildReducedModel(full, lock, pin.neutral(full))


def constraint_sets(upper, elbow, tool):
    """(label, [(segment, m_i)]) in the order of the table."""
    return [
        ("tool", [(tool, 6)]),
        ("elbow", [(elbow, 3)]),
        ("elbow + tool", [(elbow, 3), (tool, 3)]),
        ("upper arm + elbow + tool", [(upper, 1), (elbow, 2), (tool, 3)]),
    ]


def directions(rng, m):
    """m orthonormal columns in R^6 (all six axes for m = 6), [linear; angular] in the base frame."""
    if m == 6:
        return np.eye(6)
    Q, _ = np.linalg.qr(rng.uniform(-1, 1, (6, 6)))
    return np.ascontiguousarray(Q[:, :m])


ROBOTS = [
    ("Gen3 + gripper", gen3_robot, ("half_arm_2_link", "forearm_link", "end_effector_link"), 7001),
    ("Panda", panda_robot, ("panda_link3", "panda_link4", "panda_hand"), 7002),
]


def pin_configuration(model, q):
    """Pinocchio's configuration of joint angles q: continuous joints (nq = 2) as (cos, sin)."""
    out = []
    for joint, qi in zip(model.joints[1:], q):
        out += [np.cos(qi), np.sin(qi)] if joint.nq == 2 else [qi]
    return np.array(out)


def stacked_rows(model, data, pq, qd, fids, alpha_t):
    """A = blockdiag(alpha_i)^T [J_i] and the drift blockdiag(alpha_i)^T [a0_i + [-g; 0]] at qdd = 0."""
    pin.forwardKinematics(model, data, pq, qd, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    J = np.vstack([pin.computeFrameJacobian(model, data, pq, f, LWA) for f in fids])
    acc = np.concatenate([pin.getFrameAcceleration(model, data, f, LWA).vector + UP for f in fids])
    return alpha_t @ J, alpha_t @ acc


def make_states(chain, model, data, sets, seed):
    """N_STATES states at which every set is well conditioned; per set the alphas, betas and stacked blocks."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(chain.lower, -np.pi), np.minimum(chain.upper, np.pi)
    fids = [[model.getFrameId(name) for name, _ in segs] for _, segs in sets]
    states, drawn, worst = [], 0, np.inf
    while len(states) < N_STATES:
        drawn += 1
        if drawn > 50 * N_STATES:
            raise RuntimeError("too few well-conditioned states")
        q, qd, tau = rng.uniform(lo, hi), rng.uniform(-1, 1, chain.n_joints), rng.uniform(-2, 2, chain.n_joints)
        tasks = []
        for _, segs in sets:
            alphas = [directions(rng, m) for _, m in segs]
            betas = [a.T @ UP + rng.uniform(-1, 1, a.shape[1]) for a in alphas]
            tasks.append(
                dict(
                    alphas=alphas,
                    betas=betas,
                    beta=np.concatenate(betas),
                    alpha_t=scipy.linalg.block_diag(*[a.T for a in alphas]),
                )
            )
        pq = pin_configuration(model, q)
        Minv = np.array(pin.computeMinverse(model, data, pq))
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        ratios = []
        for task, f in zip(tasks, fids):
            A, _ = stacked_rows(model, data, pq, qd, f, task["alpha_t"])
            ev = np.linalg.eigvalsh(A @ Minv @ A.T)
            ratios.append(ev[0] / ev[-1])
        if min(ratios) < MIN_EIG_RATIO:
            continue
        worst = min(worst, min(ratios))
        states.append(dict(q=q, qd=qd, tau=tau, pq=pq, tasks=tasks))
    return states, fids, drawn, worst


def bench_robot(label, build, names, seed, batches, batch_s):
    chain, model = build()
    model.gravity = pin.Motion(np.r_[G, 0.0, 0.0, 0.0])
    data = model.createData()
    solver = vs.Solver(chain, gravity=G)
    sets = constraint_sets(*names)
    states, fid_sets, drawn, worst_ratio = make_states(chain, model, data, sets, seed)
    rows = []
    for k, (set_label, segs) in enumerate(sets):
        fids = fid_sets[k]
        up = np.tile(UP, len(fids))
        m = sum(m_i for _, m_i in segs)
        tasks = [s["tasks"][k] for s in states]
        cons = [{name: (a, b) for (name, _), a, b in zip(segs, t["alphas"], t["betas"])} for t in tasks]
        kkt = []
        for s, t in zip(states, tasks):
            A, drift = stacked_rows(model, data, s["pq"], s["qd"], fids, t["alpha_t"])
            kkt.append((A, drift - t["beta"]))

        def ours(q, qd, tau, c):
            return solver.solve(q, qd, tau_ff=tau, constraints=c)

        def pipeline(pq, qd, tau, alpha_t, b, fids=fids, up=up):
            pin.computeAllTerms(model, data, pq, qd)
            J = np.vstack([pin.getFrameJacobian(model, data, f, LWA) for f in fids])
            acc = np.concatenate([pin.getFrameAcceleration(model, data, f, LWA).vector for f in fids])
            return pin.forwardDynamics(model, data, tau, alpha_t @ J, alpha_t @ (acc + up) - b)

        ours_args = [(s["q"], s["qd"], s["tau"], c) for s, c in zip(states, cons)]
        pipe_args = [(s["pq"], s["qd"], s["tau"], t["alpha_t"], t["beta"]) for s, t in zip(states, tasks)]
        kkt_args = [(model, data, s["pq"], s["qd"], s["tau"], A, gamma) for s, (A, gamma) in zip(states, kkt)]

        # Check every state: qdd of the three, nu = -lambda, full rank.
        dq, dnu, rank_ok, qdd_pin = 0.0, 0.0, True, []
        for oa, pa, ka in zip(ours_args, pipe_args, kkt_args):
            res = ours(*oa)
            qdd_pipe = np.array(pipeline(*pa))
            qdd_kkt = np.array(pin.forwardDynamics(*ka))
            qdd_pin.append(qdd_kkt)
            lam = np.array(data.lambda_c).reshape(-1)
            dq = max(dq, rel_diff(res.qdd, qdd_kkt), rel_diff(qdd_pipe, qdd_kkt))
            dnu = max(dnu, rel_diff(res.nu, -lam))
            rank_ok &= res.constraint_rank == m
        print(f"timing {label}, {set_label} ...", file=sys.stderr, flush=True)
        variants = {
            "ours": per_state(ours, ours_args),
            "pin pipeline": per_state(pipeline, pipe_args),
            "pin KKT only": per_state(pin.forwardDynamics, kkt_args),
        }
        if len(segs) == 1 and segs[0][0] == chain.segment_names[-1]:
            # the same task through the end-segment arguments alpha=, beta= (no dict), for scale
            end_args = [(s["q"], s["qd"], t["alphas"][0], t["betas"][0], None, s["tau"]) for s, t in zip(states, tasks)]
            dq = max([dq] + [rel_diff(solver.solve(*a).qdd, e) for a, e in zip(end_args, qdd_pin)])
            variants["ours alpha="] = per_state(solver.solve, end_args)
        us = time_group(variants, batches, batch_s)
        segments = ", ".join(f"{name} ({m_i})" for name, m_i in segs)
        rows.append(
            dict(
                robot=label,
                n_seg=len(segs),
                segments=segments,
                set_label=set_label,
                m=m,
                dq=dq,
                dnu=dnu,
                ok=dq <= RTOL and dnu <= RTOL and rank_ok,
                rank_ok=rank_ok,
                **{k: statistics.median(v) for k, v in us.items()},
                r_pipe=paired_ratio(us["ours"], us["pin pipeline"]),
                r_kkt=paired_ratio(us["ours"], us["pin KKT only"]),
                spread=max((np.percentile(v, 75) - np.percentile(v, 25)) / np.median(v) for v in us.values()),
            )
        )
    return rows, dict(robot=label, drawn=drawn, worst=worst_ratio)


def report(rows, kept, batches, batch_s, wall):
    out = ["## Constraints on several segments", ""]
    out.append(
        "Acceleration constraints alpha_i^T a_i = beta_i on any segments (`Solver.solve(..., constraints={segment: "
        "(alpha_i, beta_i)})`) against Pinocchio's constrained forward dynamics (KKT system with the stacked rows "
        "A = [alpha_i^T J_i], J_i the LOCAL_WORLD_ALIGNED Jacobian of segment i's tip frame), both called from Python. "
        f"Python {sys.version.split()[0]}, numpy {np.__version__}, pinocchio {pin.__version__}, vereshchagin from "
        f"`{vs.__file__}`. Robots: Kinova Gen3 with the rigid Robotiq 2F-85 (`vereshchagin.robots.gen3(True)`, "
        "Pinocchio from the same URDF) and the Franka Panda up to `panda_hand` (example-robot-data, fingers locked), "
        "7 joints each, gravity 9.81 m/s^2 along -z. Segments: elbow = Gen3 `forearm_link` / Panda `panda_link4` "
        "(tip origin at the elbow joint), upper arm = `half_arm_2_link` / `panda_link3`, tool = `end_effector_link` / "
        "`panda_hand`. Directions: alpha_i = I for m_i = 6, otherwise m_i random orthonormal columns of R^6 "
        "([linear; angular], base-frame axes) drawn per state (three purely linear elbow rows would have rank 2: "
        "joints 1-3 of both arms keep the shoulder-elbow distance fixed). "
        f"{N_STATES} seeded states per robot (q within the limits, q_dot in [-1, 1], tau_ff in [-2, 2] N m, "
        "beta_i = alpha_i^T (0, 0, 9.81, 0, 0, 0) + U(-1, 1)), the same states for every set of a robot, kept only if "
        f"every set is well conditioned there (eigenvalues of A M^-1 A^T: smallest / largest >= {MIN_EIG_RATIO:.0e}; "
        + "; ".join(
            f"{k['robot']}: {N_STATES} kept of {k['drawn']} drawn, smallest ratio kept {k['worst']:.1e}" for k in kept
        )
        + f"). time.perf_counter with the garbage collector off, {batches} interleaved batches of about "
        f"{batch_s * 1e3:.0f} ms per variant, median per-call time in microseconds; ratio = median of per-batch "
        f"ratios (below 1: ours is faster). Run time {wall:.0f} s; largest batch inter-quartile range / median: "
        f"{100 * max(r['spread'] for r in rows):.0f} %."
    )
    out.append("")
    out.append(
        "Columns: `ours` = `Solver.solve(q, qd, tau_ff=tau, constraints=...)` with the dict built once per state; "
        "`pin pipeline` = what our solve does from alpha and beta: `computeAllTerms(q, v)`, `getFrameJacobian` and "
        "`getFrameAcceleration` (LOCAL_WORLD_ALIGNED) of each constrained segment, A = blockdiag(alpha_i)^T [J_i], "
        "gamma = blockdiag(alpha_i)^T [a0_i + [-g; 0]] - [beta_i] (blockdiag(alpha_i)^T and [beta_i] prepared once "
        "per state), then `forwardDynamics(tau, A, gamma)`; `pin KKT only` = `forwardDynamics(q, v, tau, A, gamma)` "
        "with A and gamma precomputed (it still runs crba and the bias forces); `ours alpha=` (tool rows only) = the "
        "same task through the end-segment arguments, `Solver.solve(q, qd, alpha, beta, None, tau)`, without the dict. "
        "Checked on every state before timing: "
        "max rel dqdd = largest ||qdd - qdd_pin|| / max(||qdd_pin||, 1) over our entry points and the pipeline against the KKT "
        "solve; max rel dnu = the same for our nu against Pinocchio's -lambda; our constraint rank equals m."
    )
    out.append("")
    out.append(
        "| robot | segments (m each) | total m | ours us | pin pipeline us | pin KKT only us | ours / pin pipeline | "
        "ours / pin KKT only | ours alpha= us | max rel dqdd | max rel dnu |"
    )
    out.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        flag = "" if r["ok"] else " **FAIL**" + ("" if r["rank_ok"] else " (rank)")
        end = f"{r['ours alpha=']:.2f}" if "ours alpha=" in r else "-"
        out.append(
            f"| {r['robot']} | {r['n_seg']}: {r['segments']} | {r['m']} | {r['ours']:.2f} | "
            f"{r['pin pipeline']:.2f} | {r['pin KKT only']:.2f} | {r['r_pipe']:.2f} | {r['r_kkt']:.2f} | "
            f"{end} | {r['dq']:.1e} | {r['dnu']:.1e}{flag} |"
        )
    failed = [r for r in rows if not r["ok"]]
    if failed:
        out.append("")
        out.append(
            f"**{len(failed)} case(s) disagree with Pinocchio by more than {RTOL:.0e} (relative) or lost rank.**"
        )
    return "\n".join(out) + "\n", not failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="also write the Markdown section to this file")
    ap.add_argument("--batches", type=int, default=61)
    ap.add_argument("--batch-ms", type=float, default=10.0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    rows, kept = [], []
    for label, build, names, seed in ROBOTS:
        r, k = bench_robot(label, build, names, seed, args.batches, args.batch_ms * 1e-3)
        rows += r
        kept.append(k)
    text, ok = report(rows, kept, args.batches, args.batch_ms * 1e-3, time.perf_counter() - t0)
    publish(text, args.out)
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
