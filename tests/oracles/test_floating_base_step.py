"""The position update on a floating base (docs/floating-base.md): ``Tree.integrate`` against
``pin.integrate`` (free-flyer on SE(3), planar on SE(2)), one Simulator step against ``pin.aba``
then ``pin.integrate(model, q, dt * v_next)`` (1e-12), a free-floating robot in zero gravity
keeping its momentum, and a free fall whose base follows the parabola.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from test_floating_base import GRAVITY, assert_rel, case, f_ext_rows, random_wrenches

ALL = ["solo12", "talos", "random2", "gen3_planar"]


@pytest.mark.parametrize("name", ALL)
def test_integrate_matches_pinocchio(name):
    c = case(name)
    rng = np.random.default_rng(11)
    for scale in (1e-7, 1e-3, 0.3, 2.0):  # the series and the closed forms of the exponential
        q, v = c.random_state(rng)
        v *= scale
        expected = pin.integrate(c.model, c.pin_q(q), c.pin_v(v))
        assert_rel(c.pin_q(c.tree.integrate(q, v)), expected, f"{name}: q (+) v", 1e-12)


@pytest.mark.parametrize("name", ALL)
def test_one_step_matches_aba_then_integrate(name):
    c = case(name)
    rng = np.random.default_rng(12)
    dt = 1e-3
    for trial in range(3):
        q, v = c.random_state(rng)
        tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
        wrenches = random_wrenches(c, rng) if trial else {}
        pq = c.pin_q(q)
        a = pin.aba(c.model, c.data, pq, c.pin_v(v), c.pin_v(tau), c.pin_fext(pq, wrenches))
        v_next = c.pin_v(v) + dt * a
        sim = vs.Simulator(c.tree, dt, gravity=GRAVITY, q=q, qd=v)
        sim.step(tau_ff=tau, f_ext=f_ext_rows(c, wrenches) if wrenches else None)
        assert_rel(sim.qd, c.ours(v_next), f"{name}: qd_next", 1e-12)
        assert_rel(c.pin_q(sim.q), pin.integrate(c.model, pq, dt * v_next), f"{name}: q_next", 1e-12)
        assert sim.q.shape == (c.tree.nq,) and sim.qd.shape == (c.tree.nv,)


def test_step_with_a_segment_constraint():
    c = case("solo12")
    q, v = c.random_state(np.random.default_rng(13))
    dt = 1e-3
    foot = "FL_FOOT" if "FL_FOOT" in c.tree.segment_names else c.tree.segment_names[-1]
    cons = {foot: (np.eye(6), np.zeros(6))}
    r = c.solver.solve(q, v, constraints=cons)
    sim = vs.Simulator(c.tree, dt, gravity=GRAVITY, q=q, qd=v)
    sim.step(constraints=cons)
    v_next = v + dt * r.qdd
    np.testing.assert_array_equal(sim.qd, v_next)
    np.testing.assert_array_equal(sim.q, c.tree.integrate(q, dt * v_next))


@pytest.mark.parametrize("name", ["solo12", "gen3_planar"])
def test_free_floating_robot_keeps_its_momentum(name):
    # Zero gravity, no torques: the centroidal momentum (world axes) is a constant of the motion
    # (on a planar base only p_x, p_y and L_z: the plane's reactions are normal to it); the step
    # keeps it to first order in dt (the drift halves with dt).
    c = case(name)
    rows = slice(None) if c.nb == 6 else [0, 1, 5]
    q, v = c.random_state(np.random.default_rng(14))
    h0 = c.tree.centroidal_momentum(q, v)[rows]
    drift = []
    for dt in (2e-3, 1e-3):
        sim = vs.Simulator(c.tree, dt, gravity=(0.0, 0.0, 0.0), q=q, qd=v)
        out = sim.rollout(round(0.2 / dt))
        h = np.array([c.tree.centroidal_momentum(a, b)[rows] for a, b in zip(out["q"], out["qd"])])
        drift.append(np.max(np.abs(h - h0)) / max(1.0, np.max(np.abs(h0))))
    assert drift[1] < 2e-3, drift
    assert drift[1] < 0.6 * drift[0], drift


@pytest.mark.parametrize("name", ["solo12", "talos"])
def test_free_fall_follows_the_parabola(name):
    # At rest in gravity, joints free: every body falls with g, nothing turns. Semi-implicit Euler
    # gives p_k = p_0 + g dt^2 k (k + 1) / 2 exactly: the parabola p_0 + g t^2 / 2 plus g dt t / 2.
    c = case(name)
    q, _ = c.random_state(np.random.default_rng(15))
    dt, steps = 1e-3, 300
    sim = vs.Simulator(c.tree, dt, gravity=GRAVITY, q=q)
    com0 = c.tree.center_of_mass(q)
    out = sim.rollout(steps)
    k = np.arange(steps + 1)[:, None]
    expected = q[:3] + GRAVITY * dt**2 * k * (k + 1) / 2
    assert_rel(out["q"][:, :3], expected, f"{name}: base origin", 1e-12)
    assert_rel(out["q"][:, 3:], np.broadcast_to(q[3:], out["q"][:, 3:].shape), f"{name}: orientation, joints", 1e-12)
    t = out["t"][-1]
    com = c.tree.center_of_mass(out["q"][-1])
    assert_rel(com, com0 + 0.5 * GRAVITY * t**2, f"{name}: COM parabola", np.linalg.norm(GRAVITY) * dt * t)


def test_floating_simulator_sizes_and_refusals():
    c = case("solo12")
    sim = vs.Simulator(c.tree, 1e-3)
    assert sim.q.shape == (c.tree.nq,) and sim.q[6] == 1.0 and sim.qd.shape == (c.tree.nv,)
    with pytest.raises(vs.SolverError, match="q must have shape"):
        sim.reset(np.zeros(c.tree.nv), np.zeros(c.tree.nv))


def _dense_symplectic(c, q, u, p, tau, dt):
    # H(q) u+ = p + dt (tau - g(q) + C(q, u+)^T u+), q+ = q (+) dt u+, p+ = H(q) u+: Pinocchio's C
    # satisfies H_dot = C + C^T in its velocity coordinates (LOCAL base twist), so p_dot = tau - g
    # + C^T v there too. Fixed-point iteration to 1e-15 with numpy; nothing of ours.
    M = pin.crba(c.model, c.data, q)
    H = np.triu(M) + np.triu(M, 1).T
    g = pin.computeGeneralizedGravity(c.model, c.data, q)
    it = u.copy()
    for _ in range(500):
        nxt = np.linalg.solve(H, p + dt * (tau - g + pin.computeCoriolisMatrix(c.model, c.data, q, it).T @ it))
        if np.max(np.abs(nxt - it)) <= 1e-15 * max(1.0, np.max(np.abs(nxt))):
            break
        it = nxt
    return pin.integrate(c.model, q, dt * nxt), nxt, H @ nxt


@pytest.mark.parametrize("name", ["solo12", "gen3_planar"])
def test_symplectic_simulator_matches_a_dense_symplectic_euler(name):
    c = case(name)
    rng = np.random.default_rng(16)
    q, v = c.random_state(rng)
    dt = 1e-3
    sim = vs.Simulator(c.tree, dt, gravity=GRAVITY, q=q, qd=v, integrator="symplectic")
    pq, pv = c.pin_q(q), c.pin_v(v)
    M = pin.crba(c.model, c.data, pq)
    pp = (np.triu(M) + np.triu(M, 1).T) @ pv
    assert_rel(sim.momentum, c.ours(pp), f"{name}: momentum at reset", 1e-12)
    for _ in range(50):
        tau = np.r_[np.zeros(c.nb), rng.uniform(-2.0, 2.0, c.tree.n_joints)]
        sim.step(tau_ff=tau)
        pq, pv, pp = _dense_symplectic(c, pq, pv, pp, c.pin_v(tau), dt)
        assert_rel(sim.qd, c.ours(pv), f"{name}: u_next", 1e-9)
        assert_rel(c.pin_q(sim.q), pq, f"{name}: q_next", 1e-9)
        assert_rel(sim.momentum, c.ours(pp), f"{name}: momentum", 1e-9)
