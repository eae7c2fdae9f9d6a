"""Randomized search of the contact stage with an independent admissibility check of every answer.

Random problems (instant and step of 1 or 10 ms, chains of 4-8 joints and the Baxter and 8-joint
random trees of tests/support, 1-8 supports with mu in {0, 0.3, 0.6, 0.8} and 3, 4 or 6 facets, at
rest, creeping or moving, with and without joint friction and a task; and the "sliding chains" of
tests/oracles/test_time_step_least_effort.py: 6 joints at about 1 rad/s, five supports, dt 2 ms)
are solved, and every returned answer is checked against the formulation, with Pinocchio's
``crba``, ``rnea`` and point Jacobians, not the solver's:

- dynamics: ``H qdd - h = tau_command + sum_c J_c^T f_c + tau_friction + tau_limit``;
- each support: a leaving point (normal velocity > tol at the instant) carries nothing; no point
  moves into its surface (normal row >= 0: the acceleration, or the end velocity over dt), no
  support pulls, a point whose normal row is positive carries nothing (complementarity);
- friction (maximum dissipation): frictionless forces along the normal; a point sliding now (at
  the instant) at the vertex most opposed to its velocity; otherwise, if its tangential row is zero
  the force anywhere in the polygon cone, else on the edges most opposed to that row (ties: the
  rows' round-off);
- joints with friction: torque within its bounds; a slipping joint at the bound against its row.

Tolerances are 1e-9 of the rows' round-off scale (the size of the terms that cancel in them: the
free motion's, each force's and each joint torque's contributions), 1e-8 for the torques and forces.
Prints the counts of admissible answers, wrong answers (with the reason) and errors (grouped).

    python benchmarks/bench_contacts_admissibility.py [chains trees sliding] [--speed-ties]

(default 500 250 600 problems; ``--speed-ties``: a sliding point's tied vertices to 1e-9 of its
sliding speed, the rule of the tests' check before chain seed 2070, instead of the rows' round-off.)
"""

from __future__ import annotations

import collections
import pathlib
import re
import sys

import numpy as np
import pinocchio as pin
from scipy.optimize import nnls

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests" / "oracles"))

import vereshchagin as vs  # noqa: E402
from support.chains import G_EARTH, pin_configuration, random_chain, random_state  # noqa: E402
from support.contact_oracle import contact_problem, facet_directions, point_jacobian  # noqa: E402
from test_time_step_least_effort import _free_motion, _sliding_chain  # noqa: E402

TOL = 1e-9
SPEED_TIES = "--speed-ties" in sys.argv  # ties relative to the sliding speed: the old rule


def _contact_violation(i, c, f, a, scale_a, fscale, dt):
    """Why contact ``c``'s force ``f`` is not admissible given its row ``a`` (None: it is)."""
    tol, ftol = TOL * scale_a, TOL * fscale
    an, fn = c.normal @ a, c.normal @ f
    if not dt and c.normal @ c.velocity > c.tol:
        return f"c{i} leaving but carries {f}" if np.linalg.norm(f) > ftol else None
    if an < -10 * tol:
        return f"c{i} moves into its surface: normal row {an:.3e}"
    if fn < -ftol:
        return f"c{i} pulls: f_n {fn:.3e}"
    if an > tol and np.linalg.norm(f) > 10 * ftol:
        return f"c{i} leaves (row {an:.3e}) but carries {np.linalg.norm(f):.3e}"
    D = facet_directions(c.normal, c.facets)
    if c.mu == 0.0:
        return f"c{i} frictionless with a tangential force" if np.linalg.norm(f - fn * c.normal) > ftol else None
    vt = c.velocity - (c.normal @ c.velocity) * c.normal
    if not dt and np.linalg.norm(vt) > c.tol:  # sliding now: the vertex most opposed to the velocity
        g = c.normal + c.mu * D[int(np.argmin(D @ vt))]
        return f"c{i} sliding, force off its vertex" if np.linalg.norm(f - fn * g) > 10 * ftol else None
    wt = a - an * c.normal
    score = D @ wt
    ties = 1e-9 * np.linalg.norm(wt) if SPEED_TIES else tol
    best = range(len(D)) if np.linalg.norm(wt) <= tol else np.flatnonzero(score <= score.min() + ties)
    resid = nnls(np.array([c.normal + c.mu * D[j] for j in best]).T, f)[1]
    return f"c{i} outside its cone or not most dissipative: {resid:.3e}" if resid > 10 * ftol else None


def check(prob, qdd, forces, joint, dt, h0):
    """None if the answer is admissible, else the reason."""
    Hi = np.linalg.inv(prob.H)
    u = np.abs(Hi @ h0) + np.abs(Hi @ joint)  # the sizes of the terms that cancel in the rows
    u += sum((np.abs(Hi @ (c.J.T @ f)) for c, f in zip(prob.contacts, forces)), np.zeros(len(qdd)))
    scale_a = max([1.0, np.abs(qdd).max()] + [(np.abs(c.J) @ u).max() + np.abs(c.bias).max() for c in prob.contacts])
    fscale = max(1.0, np.abs(forces).max() if len(forces) else 1.0)
    for i, (c, f) in enumerate(zip(prob.contacts, forces)):
        why = _contact_violation(i, c, f, c.J @ qdd + c.bias, scale_a, fscale, dt)
        if why:
            return why
    jscale = max([scale_a, u.max()] + [abs(j.offset) for j in prob.joints])
    for j in prob.joints:
        t, row, tol = joint[j.index], qdd[j.index] + j.offset, 1e-8 * max(1.0, abs(joint[j.index]))
        if not j.lo - tol <= t <= j.hi + tol:
            return f"joint {j.index}: torque {t} outside [{j.lo}, {j.hi}]"
        if abs(row) > TOL * jscale and abs(t - (j.lo if row > 0 else j.hi)) > tol:
            return f"joint {j.index} slips (row {row:.3e}, {abs(row) / jscale:.1e} of its scale) off its bound"
    return None


def _supports(rng, model, data, frames, minv_h, dt, k, mu, spread, facets=(4,)):
    """k supports on random frames whose normals (with noise) oppose the points' free motion."""
    out = []
    for frame, seg in frames(rng, k):
        point = rng.normal(size=3) * spread
        J, bias, v = point_jacobian(model, data, frame, point)
        d = (J @ minv_h + bias) * (dt or 1.0) + v
        normal = -d / max(np.linalg.norm(d), 1e-9) + 0.2 * rng.normal(size=3)
        facet = int(rng.choice(facets))
        out.append((frame, vs.Contact(seg, point=point, normal=normal / np.linalg.norm(normal), mu=mu, facets=facet)))
    return out


def chain_case(rng):
    """A 4-8 joint chain at rest, creeping or moving, 1-8 supports, friction 0.5-1.5 x load, a task."""
    n = int(rng.integers(4, 9))
    rc = random_chain(rng, n, prismatic=False)
    q, qd = random_state(rng, rc, qd_scale=(1e-3 if rng.random() < 0.5 else 0.2))
    qd *= rng.random() < 0.5
    tau = rng.normal(size=n) * 3
    model, data = rc.model, rc.model.createData()
    pq, fs, minv_h = _free_motion(rng, rc, q, qd, tau, data)

    def frames(rng, k):
        return [(rc.tip_frames[s], int(s)) for s in rng.choice(np.arange(rc.n_segments), size=k)]

    k, mu = int(rng.integers(1, 9)), float(rng.choice([0.0, 0.3, 0.6, 0.8]))
    sup = _supports(rng, model, data, frames, minv_h, 0.0, k, mu, 0.1, (3, 4, 6))
    m = int(rng.choice([0, 0, 1, 2, 3]))
    alpha = rng.normal(size=(6, m))
    alpha /= np.maximum(np.linalg.norm(alpha, axis=0), 1e-12)
    task = dict(alpha=alpha, beta=alpha[:3].T @ -G_EARTH) if m else {}
    return rc.solver(), model, (q, qd, tau, fs), (pq, qd, tau, fs), sup, task, lambda x: x


def tree_case(rng, cases):
    """Baxter or an 8-joint random tree, 1-8 supports, friction on every joint, a 3-D task or none."""
    from support.trees import robot

    name = str(rng.choice(["baxter", "random_8"]))
    if name not in cases:
        cases[name] = robot(name)
    case = cases[name]
    model, names, n = case.model, list(case.tree.segment_names), case.n
    qs = float(rng.choice([0.0, 1e-3, 0.2]))
    q, qd = case.random_state(rng, qd_scale=max(qs, 1e-3))
    qd *= qs > 0
    tau, fs = rng.normal(size=n) * 2, rng.uniform(0.2, 2.0, size=n)
    pq, pqd, ptau = case.pin_q(q), case.pin_v(qd), case.pin_v(tau)
    data = model.createData()
    minv_h = np.linalg.solve(pin.crba(model, data, pq), ptau - pin.rnea(model, data, pq, pqd, np.zeros(n)))
    pin.computeJointJacobians(model, data, pq)
    pin.forwardKinematics(model, data, pq, pqd, np.zeros(n))

    def frames(rng, k):
        return [(model.getFrameId(names[s]), names[s]) for s in rng.choice(len(names), size=k, replace=False)]

    k, mu = int(rng.integers(1, 9)), float(rng.choice([0.0, 0.3, 0.6]))
    sup = _supports(rng, model, data, frames, minv_h, 0.0, k, mu, 0.05)
    task = {}
    if rng.random() < 0.5:
        alpha = np.zeros((6, 3))
        alpha[3:, :] = np.eye(3)
        task = dict(constraints={names[int(rng.integers(len(names)))]: (alpha, np.zeros(3))})
    return case.solver(), model, (q, qd, tau, fs), (pq, pqd, ptau, case.pin_v(fs)), sup, task, case.pin_v


def sliding_case(seed):
    """The sliding chains of the least-effort tests (their ``_sliding_chain``): 6 joints at about
    1 rad/s, five supports with mu 0.6 against the points' motion over dt 2 ms, no joint friction."""
    rc, q, qd, tau, contacts = _sliding_chain(seed)
    sup = [(rc.tip_frames[c.segment], c) for c in contacts]
    pq = pin_configuration(rc.model, q)
    return rc.solver(), rc.model, (q, qd, tau, None), (pq, qd, tau, None), sup, {}, lambda x: x


def run(kind, seed, cases):
    """(outcome, reason) of one random problem: 'ok', 'wrong' or 'error'."""
    if kind == "sliding":
        solver, model, state, pstate, sup, task, order = sliding_case(seed)
        use_friction, dt = False, 2e-3
    else:
        rng = np.random.default_rng([kind == "tree", seed])
        solver, model, state, pstate, sup, task, order = chain_case(rng) if kind == "chain" else tree_case(rng, cases)
        use_friction, dt = rng.random() < 0.6, float(rng.choice([0.0, 1e-3, 1e-2]))
    (q, qd, tau, fs), (pq, pqd, ptau, pfs) = state, pstate
    kw = dict(tau_ff=tau, contacts=[c for _, c in sup], **task)
    if use_friction:
        kw["friction"] = vs.Friction(static=fs, kinetic=0.7 * fs)
    if dt:
        kw["time_step"] = dt
    try:
        r = solver.solve(q, qd, **kw)
    except Exception as e:  # noqa: BLE001 (counted by message)
        return "error", f"{type(e).__name__}: {e}"
    specs = [dict(frame=f, point=c.point, normal=c.normal, mu=c.mu, facets=c.facets) for f, c in sup]
    fric = dict(static=pfs, kinetic=0.7 * pfs) if use_friction else None
    prob = contact_problem(model, model.createData(), pq, pqd, ptau, specs, friction=fric, time_step=dt or None)
    zero = np.zeros(model.nv)
    qdd = order(r.qdd)
    joint = order(
        (r.friction_torque if r.friction_torque is not None else zero)
        + (r.limit_torque if r.limit_torque is not None else zero)
    )
    cmd = order(r.tau_command) if r.tau_command.size else zero
    h0 = ptau - pin.rnea(model, model.createData(), pq, pqd, zero)
    gen = sum((c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)), joint + cmd)
    resid = np.linalg.norm(prob.H @ qdd - h0 - gen) / max(1.0, np.linalg.norm(gen), np.linalg.norm(h0))
    if resid > 1e-8:
        return "wrong", f"equation of motion off by {resid:.1e}"
    why = check(prob, qdd, r.contact_force, joint, dt, h0)
    return ("wrong", why) if why else ("ok", None)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    sizes = [int(a) for a in args[:3]] + [500, 250, 600][len(args[:3]) :]
    cases = {}
    for kind, count in zip(("chain", "tree", "sliding"), sizes):
        outcomes, errors, wrong = collections.Counter(), collections.Counter(), []
        first = 2000 if kind == "sliding" else 0  # (the sliding chains' seeds 2000 on: chain seed 2070 among them)
        for seed in range(first, first + count):
            out, why = run(kind, seed, cases)
            outcomes[out] += 1
            if out == "error":
                errors[re.sub(r"[-+0-9.e]{2,}|\d", "#", why)[:90]] += 1
            elif out == "wrong":
                wrong.append(f"  {kind} {seed}: {why}")
        print(f"{kind}s: {count} problems, {dict(outcomes)}")
        for msg, n in errors.most_common():
            print(f"  error x{n}: {msg}")
        print("\n".join(wrong))


if __name__ == "__main__":
    main()
