"""The symplectic Simulator (``integrator="symplectic"``, C++ ``stepSymplectic()``) against an
independent dense symplectic Euler in momentum form built from Pinocchio, and its energy.

The scheme (docs: "Friction in discrete time", "Passive energy"): with the momentum p carried,
    H(q) u+ = p + dt (tau - g(q) + dT/dq(q, u+)),   q+ = q + dt u+,   p+ = H(q) u+,
where dT/dq(q, u) = C(q, u)^T u for Pinocchio's Coriolis matrix (H_dot - 2 C skew). The oracle
solves it with ``pin.crba``, ``pin.computeGeneralizedGravity``, ``pin.computeCoriolisMatrix`` and
numpy by fixed-point iteration to 1e-15, nothing of ours; compared at 1e-9 relative over 200
steps of a frictionless Gen3 swing with torques. Then: the momentum after ``reset`` is H(q) qd
(Pinocchio's crba); a Gen3 held by friction keeps q bitwise with zero momentum; a rollout is a
loop of steps bitwise; the passive swing's energy (Pinocchio's, of (q, H(q)^-1 p)) stays within
10 % of E0 at 1 ms over 2 s while semi-implicit Euler (``Solver.step``) gains more than 100 %
(benchmarks/bench_energy.py measures 8.4 % and 147 %).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from vereshchagin.robots import GEN3_START_POSE, gen3_urdf

DT = 1e-3


@pytest.fixture(scope="module")
def arm():
    urdf = gen3_urdf(gripper=False, use_external_cable=True)
    chain = vs.Chain.from_urdf(urdf)
    model = pin.buildModelFromXML(urdf)
    model.gravity = pin.Motion(np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0]))
    return chain, model, model.createData()


def _mass(model, data, q):
    M = pin.crba(model, data, q)
    return np.triu(M) + np.triu(M, 1).T


def _dense_step(model, data, q, u, p, tau, dt):
    H = _mass(model, data, q)
    g = pin.computeGeneralizedGravity(model, data, q)
    it = u.copy()
    for _ in range(500):
        nxt = np.linalg.solve(H, p + dt * (tau - g + pin.computeCoriolisMatrix(model, data, q, it).T @ it))
        if np.max(np.abs(nxt - it)) <= 1e-15 * max(1.0, np.max(np.abs(nxt))):
            break
        it = nxt
    return q + dt * nxt, nxt, H @ nxt


def _energy(model, data, q, v):
    return pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(model, data, q)


def test_symplectic_step_equals_a_dense_symplectic_euler_from_pinocchio(arm):
    chain, model, data = arm
    rng = np.random.default_rng(11)
    q, u = np.array(GEN3_START_POSE), rng.uniform(-1.0, 1.0, 7)
    sim = vs.Simulator(chain, DT, integrator="symplectic", q=q, qd=u)
    p = _mass(model, data, q) @ u
    np.testing.assert_allclose(sim.momentum, p, rtol=1e-12, atol=1e-12)
    worst = 0.0
    for _ in range(200):
        tau = rng.uniform(-2.0, 2.0, 7)
        sim.step(tau_ff=tau)
        q, u, p = _dense_step(model, data, q, u, p, tau, DT)
        scale = max(1.0, np.max(np.abs(u)))
        worst = max(worst, np.max(np.abs(sim.qd - u)) / scale, np.max(np.abs(sim.q - q)))
        np.testing.assert_allclose(sim.momentum, p, rtol=1e-9, atol=1e-9 * max(1.0, np.max(np.abs(p))))
    assert worst < 1e-9, worst


def test_a_gen3_held_by_friction_keeps_q_bitwise_and_zero_momentum(arm):
    chain = arm[0]
    q0 = np.array(GEN3_START_POSE)
    fr = vs.Friction(static=np.abs(chain.gravity_torques(q0)) + 0.5)
    sim = vs.Simulator(chain, DT, integrator="symplectic", q=q0)
    out = sim.rollout(2000, friction=fr, record=("status",))
    assert np.array_equal(out["q"][-1], q0) and not out["qd"].any()
    assert not sim.momentum.any() and (out["status"] == 1).all()


def test_a_symplectic_rollout_is_a_loop_of_steps_bitwise(arm):
    chain = arm[0]
    rng = np.random.default_rng(12)
    q0, v0 = np.array(GEN3_START_POSE), rng.uniform(-0.5, 0.5, 7)
    fr = vs.Friction(static=np.full(7, 0.8), kinetic=np.full(7, 0.5))
    a = vs.Simulator(chain, DT, integrator="symplectic", q=q0, qd=v0)
    b = vs.Simulator(chain, DT, integrator="symplectic", q=q0, qd=v0)
    out = a.rollout(100, friction=fr, record=("friction_torque",))
    for k in range(100):
        r = b.step(friction=fr)
        assert np.array_equal(out["q"][k + 1], b.q) and np.array_equal(out["qd"][k + 1], b.qd)
        assert np.array_equal(out["friction_torque"][k], r.friction_torque)
    assert np.array_equal(a.momentum, b.momentum)


def test_passive_energy_stays_bounded_where_semi_implicit_euler_gains(arm):
    chain, model, data = arm
    q0, v0 = np.array(GEN3_START_POSE), np.full(7, 0.5)
    E0 = _energy(model, data, q0, v0)
    sim = vs.Simulator(chain, DT, integrator="symplectic", q=q0, qd=v0)
    solver = vs.Solver(chain)
    q, v = q0.copy(), v0.copy()
    sym, semi = 0.0, 0.0
    for _ in range(2000):
        sim.step()
        v_p = np.linalg.solve(_mass(model, data, sim.q), sim.momentum)
        sym = max(sym, abs(_energy(model, data, sim.q, v_p) - E0))
        q, v, _ = solver.step(q, v, DT)
        semi = max(semi, _energy(model, data, q, v) - E0)
    assert sym < 0.10 * E0, (sym, E0)
    assert semi > 1.0 * E0, (semi, E0)


def test_the_momentum_is_none_for_semi_implicit_euler_and_bad_integrators_are_refused(arm):
    chain = arm[0]
    assert vs.Simulator(chain, DT).momentum is None
    with pytest.raises(vs.SolverError, match="integrator"):
        vs.Simulator(chain, DT, integrator="rk4")
