"""Command torques on trees with constraints on several branches and wrenches on several links,
against the dense Gauss oracle of tests/support/dense_oracle.py (issue 23: a mutation dropping one
branch's accumulated wrench was caught by one test only).

Per sample, with Pinocchio reading the same URDF (Baxter, Talos and random trees, tests/support/trees.py):

* the command torques are the Gauss-optimal ones: ``tau_command = -A^T nu`` with ``nu = K^-1 r``
  of the dense formulation (``K = A H^-1 A^T`` from ``pin.crba`` and frame Jacobians, ``r`` from
  ``pin.rnea``, the generalised external force and classical frame accelerations), compared to
  the solver's ``tau_command`` itself, not through its own ``nu``;
* ``pin.aba(tau_ff + tau_command, fext)`` gives the solver's ``qdd``;
* every constraint holds in Pinocchio's frame accelerations of that replayed ``qdd``;
* with damping, the damped dense solve ``(K^2 + d^2 I)^-1 K r`` (the damped policy on the tree's
  block-wise path).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import assert_close, fext_at_frames
from support.dense_oracle import dense_task, spatial_drift
from support.trees import ROBOTS, robot
from support.urdf_robots import G

UP = np.r_[-G, 0.0, 0.0, 0.0]
RTOL = 1e-9


def _multi_branch_tasks(case):
    return [t for t in case.tasks if len(case.tasks[t]) >= 2]


def _sample(case, rng, frames):
    """State, torques, wrenches on three links (two of them constrained ones) and a random task
    (1..3 unit columns per frame, at most the joints on the frame's path)."""
    q, qd = case.random_state(rng)
    pq, pv = case.pin_q(q), case.pin_v(qd)
    data = case.model.createData()
    tau = rng.normal(size=case.n) * 5.0
    links = [f.name for f in case.model.frames if f.type == pin.FrameType.BODY and f.parentJoint > 0]
    loaded = list(dict.fromkeys([frames[0], frames[-1], links[int(rng.integers(len(links)))]]))
    wrenches = {name: rng.normal(size=6) * 5.0 for name in loaded}
    cols, betas = {}, {}
    for f in frames:
        fid = case.model.getFrameId(f)
        J = pin.computeFrameJacobian(case.model, data, pq, fid, pin.LOCAL_WORLD_ALIGNED)
        reach = int(np.count_nonzero(np.abs(J).sum(axis=0)))
        m = int(rng.integers(1, min(3, reach) + 1))
        a = rng.normal(size=(6, m))
        cols[f], betas[f] = a / np.linalg.norm(a, axis=0), rng.normal(size=m) * 3.0
    fids = [case.model.getFrameId(name) for name in wrenches]
    dense = dense_task(
        case.model,
        fids,
        pq,
        pv,
        G,
        case.pin_v(tau),
        [(case.model.getFrameId(f), cols[f], betas[f]) for f in frames],
        f_ext=np.array(list(wrenches.values())),
    )
    return q, qd, pq, pv, tau, wrenches, cols, betas, dense


def _task_met(case, pq, pv, pa, frames, cols, betas, what):
    data = case.model.createData()
    pin.forwardKinematics(case.model, data, pq, pv, pa)
    pin.updateFramePlacements(case.model, data)
    for f in frames:
        acc = spatial_drift(case.model, data, case.model.getFrameId(f)) + UP
        assert_close(cols[f].T @ acc, betas[f], RTOL, f"{what}: alpha^T a({f}) = beta")


@pytest.mark.parametrize("name, task", [(n, t) for n in sorted(ROBOTS) for t in _multi_branch_tasks(robot(n))])
def test_tree_command_torques_are_gauss_optimal_with_wrenches(name, task):
    case = robot(name)
    frames = case.tasks[task]
    rng = np.random.default_rng([61, len(name), len(task)])
    done = 0
    for _ in range(40):
        q, qd, pq, pv, tau, wrenches, cols, betas, dense = _sample(case, rng, frames)
        lam = np.linalg.eigvalsh(dense.K)
        if lam.min() < 1e-4 * lam.max():
            continue  # near-singular: the comparison would measure the conditioning
        res = case.solver().solve(
            q, qd, tau_ff=tau, f_ext=wrenches, constraints={f: (cols[f], betas[f]) for f in frames}
        )
        what = f"{name} {task}"
        nu = np.linalg.solve(dense.K, dense.r)
        qdd, tau_cmd = dense.outputs(nu)
        assert_close(res.tau_command, case.ours(tau_cmd), RTOL, f"{what}: tau_command vs -A^T K^-1 r")
        assert_close(res.nu, nu, RTOL, f"{what}: nu vs K^-1 r")
        assert_close(res.qdd, case.ours(qdd), RTOL, f"{what}: qdd vs dense Gauss")
        # replay the command torques (and the wrenches) through Pinocchio's ABA
        data = case.model.createData()
        fext = fext_at_frames(case.model, data, pq, wrenches)
        replay = pin.aba(case.model, data, pq, pv, case.pin_v(tau + res.tau_command), fext)
        assert_close(case.ours(replay), res.qdd, RTOL, f"{what}: aba(tau_ff + tau_command, fext) vs qdd")
        _task_met(case, pq, pv, replay, frames, cols, betas, what)
        # every branch's columns carry torque: dropping one branch's wrench changes tau_command
        for f in frames:
            k = sum(cols[g].shape[1] for g in frames[: frames.index(f)])
            part = -dense.A[k : k + cols[f].shape[1]].T @ nu[k : k + cols[f].shape[1]]
            assert np.linalg.norm(part) > 1e3 * RTOL * max(np.linalg.norm(tau_cmd), 1.0), f
        done += 1
        if done == 2:
            break
    assert done == 2, "too few well-conditioned samples"


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_tree_damped_multi_branch_matches_dense_oracle(name):
    case = robot(name)
    task = _multi_branch_tasks(case)[-1]
    frames = case.tasks[task]
    rng = np.random.default_rng([67, len(name)])
    q, qd, pq, pv, tau, wrenches, cols, betas, dense = _sample(case, rng, frames)
    d = 1e-2 * np.linalg.eigvalsh(dense.K).max()
    solver = vs.Solver(case.tree, gravity=G, damping=d)
    res = solver.solve(q, qd, tau_ff=tau, f_ext=wrenches, constraints={f: (cols[f], betas[f]) for f in frames})
    nu = dense.damped(d)
    qdd, tau_cmd = dense.outputs(nu)
    what = f"{name} {task} damping {d:.3g}"
    assert_close(res.nu, nu, RTOL, f"{what}: nu")
    assert_close(res.qdd, case.ours(qdd), RTOL, f"{what}: qdd")
    assert_close(res.tau_command, case.ours(tau_cmd), RTOL, f"{what}: tau_command")
