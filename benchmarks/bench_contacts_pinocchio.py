#!/usr/bin/env python3
"""Point contacts on the Gen3: our exact contact solve against Pinocchio 4's ADMM and PGS, from Python.

Robot: the Kinova Gen3 7-DoF of ``vereshchagin.robots.gen3_urdf(gripper=False,
use_external_cable=True)``, loaded by ``vereshchagin.Chain.from_urdf`` and by
``pinocchio.buildModelFromXML`` (segment k of our chain is Pinocchio's joint k + 1; both frames are
the URDF child link's). The problem is bench_contacts.cpp's: a 3-D task on the tool (its origin held
still) and point contacts with the normal +z under segments 2 to 5 (the forearm and the wrist over
a table); q near the pose (0, 0.9, 0, 1.9, 0, 0.4, 1.57) +- 0.3 rad, q_dot = 0, no torque.

The same problem for Pinocchio (``PointContactConstraintModel`` per contact, the task as a
``PointAnchorConstraintModel`` on the tool's origin, both to the world): our acceleration-level
problem is its velocity-level one at time step 1 with zero velocity. The Delassus matrix
G = J M^-1 J^T (``ConstraintCholeskyDecomposition``), the drift g = J qdd_free (qdd_free =
aba(q, 0, 0); q_dot = 0, so no velocity products), the impulses lambda are forces, and
sigma = G lambda + g are the constraint points' accelerations; the solvers find lambda in the
cone (circular, Coulomb's mu) with sigma in the dual cone, complementary (``solve_ncp``: the de Saxce
correction, which vanishes at sticking points), and qdd = aba(q, 0, J^T lambda). Pinocchio's point
contact measures the world's motion against the link's (J = -R^T J_point), so each contact's frame
is placed with its z axis along world -z: lambda_n >= 0 is then the table pushing up, and the force
ON the link in base axes is -R lambda (R = diag(1, -1, -1)). The anchor sits on our task's point
(the tip of our last segment: the URDF's end_effector_link, fixed on Pinocchio's joint 7).

Where the cone's shape cannot matter, the problems have the same answer: frictionless supports
(mu = 0: the convex problem, qdd unique) and states where each of our forces pushes strictly
inside the circular cone (every point sticks; our polygon is inscribed in the cone). qdd is then unique and compared; the contact forces are
unique only when the held columns are independent: with 4 contacts and a 3-D task on 7 joints
they are not (qdd is fixed, the split of the load is not: ours takes the least motor effort,
the ADMM / PGS whatever their iteration reaches), so forces are also compared on a variant with one
sticking contact (segment 3, mu = 1: 3 + 3 independent rows on 7 joints), where they are unique.

Timed per call (interleaved batches, medians, as bench_pinocchio.py):
  ours          Solver.solve(q, qd, alpha, beta, contacts=[...])  (Contacts prebuilt)
  ours plain 6  Solver.solve(q, qd, alpha6, beta6)  (the tool's 6-D hold, for scale)
  pin ADMM      crba, the free aba, computeJointJacobians, each constraint's calc, the constraint
                Cholesky, J and g, ADMMConstraintSolver at tolerance 1e-10 (Anderson acceleration 4,
                rho momentum 0.9, up to 100000 iterations), the final aba
  pin PGS       the same with PGSConstraintSolver at tolerance 1e-10 (up to 100000 iterations)
The constraint models are built per state before timing (their frames depend on q).

Usage: python benchmarks/bench_contacts_pinocchio.py [--out FILE] [--batches N] [--batch-ms MS]
Markdown to stdout (and FILE); progress to stderr. Exit code 2 if, with frictionless supports (unique
qdd), a converged ADMM solve's qdd differs from ours by more than 1e-6 (relative to max(1, |qdd|)).
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

TOL = 1e-10
RTOL_CHECK = 1e-6
POSE = np.array([0.0, 0.9, 0.0, 1.9, 0.0, 0.4, 1.57])
SEGMENTS = (2, 3, 4, 5)
POINTS = [
    np.array([0.03 * (1 if k % 2 else -1), 0.02 * (1 if k < 2 else -1), z])
    for k, z in enumerate((-0.05, -0.15, -0.02, -0.08))
]
ALPHA3, BETA3 = np.eye(6)[:, :3], np.array([0.0, 0.0, 9.81])  # the tool's origin held (gravity as base acc.)
ALPHA6, BETA6 = np.eye(6), np.array([0.0, 0.0, 9.81, 0.0, 0.0, 0.0])
FLIP = np.diag([1.0, -1.0, -1.0])  # contact frame: z along world -z


def our_contacts(which, mu):
    return [vs.Contact(SEGMENTS[k], point=POINTS[k], normal=[0, 0, 1], mu=mu) for k in which]


def pin_constraints(model, data, q, which, mu):
    """The contacts and the task's anchor at configuration q, with their datas."""
    pin.forwardKinematics(model, data, q)
    cms = pin.StdVec_ConstraintModel()
    for k in which:
        j = SEGMENTS[k] + 1
        oMj = data.oMi[j]
        placement = pin.SE3(oMj.rotation.T @ FLIP, POINTS[k])  # the contact frame: z along world -z
        cm = pin.PointContactConstraintModel(model, j, placement, 0, pin.SE3(FLIP, oMj.act(POINTS[k])))
        cm.setFriction(mu)
        cms.append(pin.ConstraintModel(cm))
    # The task's point: our last segment's tip, the URDF's end_effector_link (fixed on joint 7).
    tool = model.frames[model.getFrameId("end_effector_link")]
    world = data.oMi[tool.parentJoint] * tool.placement
    cms.append(pin.ConstraintModel(pin.PointAnchorConstraintModel(model, tool.parentJoint, tool.placement, 0, world)))
    cds = pin.StdVec_ConstraintData()
    for cm in cms:
        cds.append(cm.createData())
    return cms, cds


def settings(kind, size):
    if kind == "ADMM":
        s = pin.ADMMSolverSettings()
        s.lanczos_size = size
        s.anderson_capacity = 4
        s.rho_momentum = 0.9
    else:
        s = pin.PGSSolverSettings()
    s.max_iterations = 100000
    s.absolute_feasibility_tol = s.relative_feasibility_tol = TOL
    s.absolute_complementarity_tol = s.relative_complementarity_tol = TOL
    return s


class PinSolve:
    """Pinocchio's pipeline for one problem size; the last answer in self.last."""

    def __init__(self, model, data, kind, size):
        self.model, self.data, self.kind = model, data, kind
        self.solver = pin.ADMMConstraintSolver(size) if kind == "ADMM" else pin.PGSConstraintSolver(size)
        self.settings = settings(kind, size)
        self.v0 = np.zeros(model.nv)
        self.chol = None
        self.last = {}

    def __call__(self, q, cms, cds):
        model, data, v0 = self.model, self.data, self.v0
        pin.crba(model, data, q)
        qdd_free = pin.aba(model, data, q, v0, v0).copy()
        pin.computeJointJacobians(model, data, q)
        for cm, cd in zip(cms, cds):
            cm.calc(model, data, cd)
        if self.chol is None:
            self.chol = pin.ConstraintCholeskyDecomposition(model, data, cms, cds)
        self.chol.compute(model, data, cms, cds, 0.0)
        J = pin.getConstraintsJacobian(model, data, cms, cds)
        res = pin.ADMMSolverResult() if self.kind == "ADMM" else pin.PGSSolverResult()
        ok = self.solver.solve(
            self.chol.getDelassusOperatorCholeskyExpression(), J @ qdd_free, cms, cds, self.settings, res
        )
        lam = res.retrieveConstraintImpulses()
        qdd = pin.aba(model, data, q, v0, J.T @ lam)
        self.last = dict(converged=bool(ok), iterations=res.iterations, lam=lam, qdd=qdd)
        return qdd


def inside_cone(f, mu, margin=1e-6):
    """Pushing and strictly inside the circular cone (normal +z): ||f_t|| < mu f_n. Our forces lie in the
    inscribed polygon, so this excludes only its vertices; the sticking answer then solves both problems."""
    return f[2] > margin and np.hypot(f[0], f[1]) < mu * f[2] - margin


def make_states(solver, which, mu, seed):
    """Seeded states; with friction, kept only when every point sticks (ContactStatus 1), each force
    pushing strictly inside the circular cone."""
    rng = np.random.default_rng(seed)
    v0, states = np.zeros(7), []
    for _ in range(20000):
        if len(states) == N_STATES:
            break
        q = POSE + rng.uniform(-0.3, 0.3, 7)
        try:
            r = solver.solve(q, v0, ALPHA3, BETA3, contacts=our_contacts(which, mu))
        except vs.SolverError:  # no consistent forces (Painleve): not a state to compare
            continue
        if mu > 0 and not (all(inside_cone(f, mu) for f in r.contact_force) and (r.contact_status == 1).all()):
            continue
        states.append(q)
    return states


def compare(solver, model, data, name, which, mu, seed):
    states = make_states(solver, which, mu, seed)
    if not states:
        raise SystemExit(f"{name}: no state found")
    contacts = our_contacts(which, mu)
    cons = [pin_constraints(model, data, q, which, mu) for q in states]
    size = 3 * len(which) + 3
    v0 = np.zeros(7)
    ours = [solver.solve(q, v0, ALPHA3, BETA3, contacts=contacts) for q in states]
    rows = {}
    runners = {}
    for kind in ("ADMM", "PGS"):
        run = runners[kind] = PinSolve(model, data, kind, size)
        dq, df, it, conv = [], [], [], 0
        for q, (cms, cds), r in zip(states, cons, ours):
            run(q, cms, cds)
            # On the link, base axes: -R lambda (Pinocchio's impulse acts on the world side).
            lam = np.asarray(run.last["lam"])[: 3 * len(which)].reshape(-1, 3) @ -FLIP
            it.append(run.last["iterations"])
            if run.last["converged"]:  # differences over the converged solves only
                conv += 1
                dq.append(np.abs(run.last["qdd"] - r.qdd).max() / max(1.0, np.abs(r.qdd).max()))
                df.append(np.abs(lam - r.contact_force).max())
        dq, df = np.nan_to_num(np.array(dq), nan=np.inf), np.nan_to_num(np.array(df), nan=np.inf)
        agree = dq <= RTOL_CHECK
        rows[kind] = dict(
            conv=conv,
            agree=int(agree.sum()),
            dq=float(np.median(dq)) if conv else np.nan,
            dq_agree=float(dq[agree].max()) if agree.any() else np.nan,
            df_agree=float(df[agree].max()) if agree.any() else np.nan,
            it_mean=float(np.mean(it)),
            it_max=int(max(it)),
        )
    variants = {
        "ours": per_state(lambda q: solver.solve(q, v0, ALPHA3, BETA3, contacts=contacts), [(q,) for q in states]),
        "ours plain 6": per_state(lambda q: solver.solve(q, v0, ALPHA6, BETA6), [(q,) for q in states]),
    }
    for kind, run in runners.items():
        variants[f"pin {kind}"] = per_state(run, [(q, cms, cds) for q, (cms, cds) in zip(states, cons)])
    return dict(name=name, mu=mu, states=len(states), rows=rows, variants=variants)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="also write the Markdown section to this file")
    ap.add_argument("--batches", type=int, default=11)
    ap.add_argument("--batch-ms", type=float, default=10.0)
    args = ap.parse_args()
    t_start = time.perf_counter()
    urdf = gen3_urdf(gripper=False, use_external_cable=True)
    solver = vs.Solver(vs.Chain.from_urdf(urdf), gravity=[0.0, 0.0, -9.81])
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    problems = [
        ("4 frictionless supports + 3-D task", (0, 1, 2, 3), 0.0, 11),
        ("4 supports, mu 0.6, forces inside the cone + 3-D task", (0, 1, 2, 3), 0.6, 12),
        ("1 support (unique force), mu 1.0, inside the cone + 3-D task", (1,), 1.0, 13),
    ]
    results = []
    for name, which, mu, seed in problems:
        print(f"checking and timing: {name} ...", file=sys.stderr, flush=True)
        res = compare(solver, model, data, name, which, mu, seed)
        res["us"] = time_group(res["variants"], args.batches, args.batch_ms * 1e-3)
        results.append(res)
    wall = time.perf_counter() - t_start
    out = ["### Python: point contacts against Pinocchio's ADMM and PGS (Gen3, 3-D task)", ""]
    out.append(
        f"pinocchio {pin.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}, vereshchagin from "
        f"`.../{Path(vs.__file__).parent.parent.name}/vereshchagin` (the installed package). bench_contacts' problem from Python (see the script's docstring for the mapping: time "
        "step 1, q_dot = 0, G = J M^-1 J^T, g = J qdd_free, lambda = forces; the task as a PointAnchorConstraint"
        f"Model); tolerance {TOL:g} for both Pinocchio solvers. {args.batches} interleaved batches of about "
        f"{args.batch_ms:.0f} ms, median per-call time; ratio = median of per-batch ratios. Run time {wall:.0f} s."
    )
    out.append("")
    out.append(
        "| problem | states | ours (us) | ours / plain m = 6 | solver | its (us) | its / ours | iterations mean (max) "
        "| converged | agree (qdd to 1e-6) | median rel. qdd diff | max rel. qdd diff, agreeing | max force diff "
        "(N), agreeing |"
    )
    out.append("|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    worst = 0.0
    for r in results:
        us, med = r["us"], {k: statistics.median(v) for k, v in r["us"].items()}
        for kind in ("ADMM", "PGS"):
            row = r["rows"][kind]
            if r["mu"] == 0.0 and kind == "ADMM":  # convex: every converged ADMM solve must agree
                worst = max(worst, row["conv"] - row["agree"])
            cells = [
                r["name"],
                str(r["states"]),
                f"{med['ours']:.1f}",
                f"{paired_ratio(us['ours'], us['ours plain 6']):.2f}x",
            ]
            cells += [
                f"pin {kind}",
                f"{med[f'pin {kind}']:.1f}",
                f"{paired_ratio(us[f'pin {kind}'], us['ours']):.1f}x",
                f"{row['it_mean']:.0f} ({row['it_max']})",
                f"{row['conv']}/{r['states']}",
                f"{row['agree']}/{row['conv']}",
                f"{row['dq']:.1e}",
                f"{row['dq_agree']:.1e}",
                f"{row['df_agree']:.1e}",
            ]
            out.append("| " + " | ".join(cells) + " |")
    out.append("")
    out.append(
        "qdd is unique in the frictionless rows (a convex problem); with friction the sticking answer is one answer of "
        "the circular-cone problem, which may have others (a converged solve that slides disagrees). The contact "
        "forces are unique only in the one-support rows (4 contacts and a 3-D task hold 7 joints with dependent "
        "columns: ours is the least-motor-effort split, Pinocchio's whatever its iteration reaches, so a force "
        "difference there is a different admissible split, not an error). Differences over the converged solves."
    )
    text = "\n".join(out) + "\n"
    publish(text, args.out)
    return 2 if worst > 0 else 0


if __name__ == "__main__":
    sys.exit(main())
