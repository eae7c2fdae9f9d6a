#!/usr/bin/env python3
"""Static joint friction, all joints at rest: our exact solve against Pinocchio 4's ADMM, from Python.

Robot: the Kinova Gen3 7-DoF of ``vereshchagin.robots.gen3_urdf(gripper=False,
use_external_cable=True)`` (revolute joints with +-2 pi limits instead of continuous ones, so
Pinocchio's configuration is the 7 joint angles; the dynamics are the same), loaded by
``vereshchagin.Chain.from_urdf`` and by ``pinocchio.buildModelFromXML``. m = 0 (no task) only.

64 seeded states (numpy): q in [-pi, pi], q_dot = 0, static friction f_j in [0.5, 3] N m, feed-forward
torques = (random factor in [0, 1]) x gravity torque + U(-2, 2) N m (bench_friction.cpp's recipe with
numpy's generator, so not the same numbers).

Pinocchio's formulation (pinocchio 4.1, ``JointFrictionConstraintModel``): one box constraint per joint
on the constraint impulse lambda in [-f dt, f dt] with Jacobian J = I, Delassus operator
G = J M^-1 J^T = M^-1 and drift g = J v_free = dt qdd_free (v = 0); ``ADMMConstraintSolver`` solves
the nonlinear complementarity problem sigma = G lambda + g in the normal cone of the box at lambda,
which at dt = 1 (the constraint models' default time step) is exactly our box QP: lambda is the
friction torque and qdd = qdd_free + M^-1 lambda.

Timed per call, from Python (interleaved batches, medians, as bench_pinocchio.py):
  ours friction     Solver.solve(q, qd, tau_ff=tau, friction=Friction(static=f))  (Friction prebuilt)
  ours plain        Solver.solve(q, qd, tau_ff=tau)
  pin aba           pin.aba(q, v, tau) (the plain solve, for scale)
  pin ADMM <kind>   pin.crba; qdd_free = pin.aba; ConstraintCholeskyDecomposition.compute; ADMM on its
                    Delassus expression; qdd = pin.aba(q, v, tau + lambda), with the settings
                    default (as constructed: tolerances 1e-6, at most 1000 iterations),
                    tuned (Anderson acceleration 4, rho momentum 0.9 as in Pinocchio's own ADMM test,
                    at most 10000 iterations, tolerances 1e-6) or tight (tuned, tolerances 1e-12)
Before timing, qdd and the friction torques of every ADMM variant are compared with ours.

Usage: python benchmarks/bench_friction_pinocchio.py [--out FILE] [--batches N] [--batch-ms MS]
Markdown to stdout (and FILE); progress to stderr. Exit code 2 if our solve and the tight ADMM disagree
by more than 1e-6 (relative to max(1, |qdd|)).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from vereshchagin.robots import gen3_urdf

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pinocchio import N_STATES, paired_ratio, per_state, time_group  # noqa: E402
from bench_output import publish  # noqa: E402

TOL_TIGHT = 1e-12
RTOL_CHECK = 1e-6  # tight ADMM vs ours, relative to max(1, |qdd|)


def make_states(model, data, seed=2024):
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(N_STATES):
        q = rng.uniform(-np.pi, np.pi, model.nv)
        gravity_torque = pin.computeGeneralizedGravity(model, data, q).copy()
        tau = rng.uniform() * gravity_torque + rng.uniform(-2.0, 2.0, model.nv)
        f = rng.uniform(0.5, 3.0, model.nv)
        states.append((q, tau, f))
    return states


def admm_settings(kind, n):
    """ "default": ADMMSolverSettings() as constructed (tolerances 1e-6, 1000 iterations, no Anderson
    acceleration); "tuned": Anderson acceleration (capacity 4) and rho momentum 0.9 as in Pinocchio's
    own ADMM unit test (unittest/python/bindings_admm.py), up to 10000 iterations, tolerances 1e-6;
    "tight": "tuned" with tolerances 1e-12. All with lanczos_size = n, as Pinocchio's tests."""
    s = pin.ADMMSolverSettings()
    s.lanczos_size = n
    if kind in ("tuned", "tight"):
        s.anderson_capacity = 4
        s.rho_momentum = 0.9
        s.max_iterations = 10000
    if kind == "tight":
        s.absolute_feasibility_tol = s.relative_feasibility_tol = TOL_TIGHT
        s.absolute_complementarity_tol = s.relative_complementarity_tol = TOL_TIGHT
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="also write the Markdown section to this file")
    ap.add_argument("--batches", type=int, default=31)
    ap.add_argument("--batch-ms", type=float, default=10.0)
    args = ap.parse_args()
    t_start = time.perf_counter()

    urdf = gen3_urdf(gripper=False, use_external_cable=True)
    solver = vs.Solver(vs.Chain.from_urdf(urdf), gravity=[0.0, 0.0, -9.81])
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    n = model.nv
    assert model.nq == n == 7, (model.nq, model.nv)
    v0 = np.zeros(n)
    states = make_states(model, data)
    frictions = [vs.Friction(static=f) for _, _, f in states]

    # One Pinocchio constraint list per state (the friction bounds are part of the model).
    joints = pin.StdVec_Index(list(range(1, model.njoints)))
    cms_per_state, cds_per_state = [], []
    for _, _, f in states:
        cms = pin.StdVec_ConstraintModel()
        cms.append(pin.ConstraintModel(pin.JointFrictionConstraintModel(model, joints, -f, f)))
        cds = pin.StdVec_ConstraintData()
        for cm in cms:
            cds.append(cm.createData())
        cms_per_state.append(cms)
        cds_per_state.append(cds)
    chol = pin.ConstraintCholeskyDecomposition(model, data, cms_per_state[0], cds_per_state[0])
    admm = pin.ADMMConstraintSolver(n)
    settings = {kind: admm_settings(kind, n) for kind in ("default", "tuned", "tight")}
    last = {}

    def pin_friction(q, tau, cms, cds, st):
        pin.crba(model, data, q)
        qdd_free = pin.aba(model, data, q, v0, tau).copy()
        chol.compute(model, data, cms, cds, 0.0)
        res = pin.ADMMSolverResult()
        converged = admm.solve(chol.getDelassusOperatorCholeskyExpression(), qdd_free, cms, cds, st, res)
        lam = res.retrieveConstraintImpulses()
        last.update(converged=converged, iterations=res.iterations, lam=lam)
        return pin.aba(model, data, q, v0, tau + lam)

    # Check.
    ours = [solver.solve(q, v0, tau_ff=tau, friction=fr) for (q, tau, _), fr in zip(states, frictions)]
    check = {}
    for name, st in settings.items():
        dq, dtau, iters, conv = [], [], [], 0
        for (q, tau, _), r, cms, cds in zip(states, ours, cms_per_state, cds_per_state):
            qdd = np.array(pin_friction(q, tau, cms, cds, st))
            dq.append(np.abs(qdd - r.qdd).max() / max(1.0, np.abs(r.qdd).max()))
            dtau.append(np.abs(last["lam"] - r.friction_torque).max())
            iters.append(last["iterations"])
            conv += bool(last["converged"])
        check[name] = dict(
            dq_max=max(dq),
            dq_med=statistics.median(dq),
            dtau_max=max(dtau),
            it_mean=float(np.mean(iters)),
            it_max=int(max(iters)),
            converged=conv,
        )
    stick = np.mean([np.sum(np.asarray(r.status) == 1) for r in ours])
    our_iters = np.mean([r.iterations for r in ours])

    def ours_friction(q, tau, fr):
        return solver.solve(q, v0, tau_ff=tau, friction=fr)

    def ours_plain(q, tau):
        return solver.solve(q, v0, tau_ff=tau)

    variants = {
        "ours friction": per_state(ours_friction, [(q, tau, fr) for (q, tau, _), fr in zip(states, frictions)]),
        "ours plain": per_state(ours_plain, [(q, tau) for q, tau, _ in states]),
        "pin aba": per_state(pin.aba, [(model, data, q, v0, tau) for q, tau, _ in states]),
    }
    for kind, st in settings.items():
        variants[f"pin ADMM {kind}"] = per_state(
            pin_friction,
            [(q, tau, cms, cds, st) for (q, tau, _), cms, cds in zip(states, cms_per_state, cds_per_state)],
        )
    print("timing Gen3 static friction (Python) ...", file=sys.stderr, flush=True)
    us = time_group(variants, args.batches, args.batch_ms * 1e-3)
    med = {k: statistics.median(v) for k, v in us.items()}
    wall = time.perf_counter() - t_start

    ok = check["tight"]["dq_max"] <= RTOL_CHECK
    out = ["# Python: ours against Pinocchio's JointFrictionConstraintModel + ADMM (Gen3, m = 0)", ""]
    out.append(
        f"pinocchio {pin.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}, vereshchagin "
        f"from `{vs.__file__}`. Gen3 from `gen3_urdf(gripper=False, use_external_cable=True)`, "
        f"{N_STATES} seeded states, every joint at rest (q_dot = 0), static friction in [0.5, 3] N m, "
        "feed-forward = (random factor in [0, 1]) x gravity torque + U(-2, 2) N m; no task (m = 0). Pinocchio: "
        "`JointFrictionConstraintModel` on all 7 joints with bounds +-f (time step 1, so impulses are torques), "
        "`ConstraintCholeskyDecomposition` for the Delassus operator M^-1, `ADMMConstraintSolver` "
        "(`lanczos_size` 7) with the settings `default` (as constructed: tolerances 1e-6, at most 1000 "
        "iterations), `tuned` (Anderson acceleration 4 and rho momentum 0.9 as in Pinocchio's own ADMM test, "
        "at most 10000 iterations, tolerances 1e-6) or `tight` (tuned, tolerances 1e-12), qdd = "
        "`aba(tau + lambda)`; the timed call includes `crba`, the free `aba`, the "
        "decomposition, the ADMM and the final `aba`. Ours: `Solver.solve(q, qd, tau_ff=tau, "
        f"friction=Friction(static=f))` (exact active set). {args.batches} interleaved batches of about "
        f"{args.batch_ms:.0f} ms, median per-call time; ratio = median of per-batch ratios. Run time {wall:.0f} s."
    )
    out.append("")
    out.append(
        f"At the exact optimum {stick:.2f} of 7 joints stick on average; our active-set iterations: "
        f"{our_iters:.2f} on average."
    )
    out.append("")
    out.append(
        "| variant | us per call | ratio to ours friction | ADMM iterations mean (max) | converged | "
        "max rel. qdd diff to ours | median rel. qdd diff | max friction torque diff (N m) |"
    )
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name in us:
        ratio = paired_ratio(us[name], us["ours friction"])
        if name.startswith("pin ADMM"):
            c = check[name.split()[-1]]
            extra = (
                f"{c['it_mean']:.1f} ({c['it_max']}) | {c['converged']} / {N_STATES} | {c['dq_max']:.1e} | "
                f"{c['dq_med']:.1e} | {c['dtau_max']:.1e}"
            )
        else:
            extra = "- | - | - | - | -"
        out.append(f"| {name} | {med[name]:.1f} | {ratio:.2f} | {extra} |")
    out.append("")
    out.append(
        "Relative qdd difference: max |qdd_pin - qdd_ours| / max(1, max |qdd_ours|) per state. ADMM is "
        "iterative: its answer is as accurate as its tolerances (absolute and relative feasibility and "
        "complementarity, 1e-6 by default); ours satisfies the complementarity conditions to round-off. Both "
        "libraries pay Python call overhead here (the C++ table above has ours without it)."
    )
    if not ok:
        out.append("")
        out.append(
            f"**The tight ADMM and our solve disagree by {check['tight']['dq_max']:.1e} (relative) > "
            f"{RTOL_CHECK:.0e}.**"
        )
    text = "\n".join(out) + "\n"
    publish(text, args.out)
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
