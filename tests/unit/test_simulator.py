"""vereshchagin.Simulator: its step is Solver.step's (the C++ step) bitwise, a rollout is a loop of
steps bitwise, the record's shapes, a controller callback, the messages for bad input; and one
oracle: a frictionless passive Gen3 swing against MuJoCo's semi-implicit Euler at the same dt."""

from __future__ import annotations

import numpy as np
import pytest

import vereshchagin as vs

GEN3_Q = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
DT = 1e-3


@pytest.fixture(scope="module")
def chain():
    return vs.robots.gen3()


def _holding(chain, q, extra=1.0):
    return vs.Friction(static=np.abs(chain.gravity_torques(q)) + extra)


def test_step_equals_solver_step_bitwise(chain):
    rng = np.random.default_rng(5)
    sim = vs.Simulator(chain, DT, q=GEN3_Q, qd=rng.normal(size=7) * 0.3)
    solver = vs.Solver(chain)
    q, qd = sim.q, sim.qd
    fr = vs.Friction(static=np.full(7, 1.5), kinetic=np.full(7, 1.0))
    for k in range(300):
        tau = rng.normal(size=7)
        r_sim = sim.step(tau_ff=tau, friction=fr)
        q, qd, r = solver.step(q, qd, DT, tau_ff=tau, friction=fr)
        assert np.array_equal(sim.q, q) and np.array_equal(sim.qd, qd), k
        assert np.array_equal(r_sim.qdd, r.qdd) and np.array_equal(r_sim.friction_torque, r.friction_torque)
    assert sim.t == 300 * DT


def test_solver_step_is_semi_implicit_euler_of_the_solve(chain):
    """The C++ step behind Solver.step integrates the solve over the step exactly as documented."""
    solver = vs.Solver(chain)
    rng = np.random.default_rng(6)
    fr = _holding(chain, GEN3_Q, extra=0.2)
    for _ in range(50):
        q, qd = GEN3_Q + rng.normal(size=7) * 0.1, rng.normal(size=7) * 0.05 * rng.integers(0, 2, 7)
        q1, qd1, r = solver.step(q, qd, DT, friction=fr)
        expect = qd + DT * r.qdd
        expect[r.status == 1] = 0.0
        assert np.array_equal(qd1, expect) and np.array_equal(q1, q + DT * expect)


def test_a_held_gen3_stays_bitwise(chain):
    sim = vs.Simulator(chain, DT, q=GEN3_Q)
    out = sim.rollout(2000, friction=_holding(chain, GEN3_Q), record=("status",))
    assert (out["q"] == GEN3_Q).all() and (out["qd"] == 0.0).all()
    assert (out["status"] == 1).all()


def test_rollout_equals_a_loop_of_steps_and_records_its_shapes(chain):
    contact = vs.Contact(-1, point=[0.0, 0.0, 0.05], normal=[0.0, 0.0, 1.0], mu=0.5)
    fr = vs.Friction(static=np.full(7, 0.8))
    a = vs.Simulator(chain, DT, q=GEN3_Q, t=1.0)
    b = vs.Simulator(chain, DT, q=GEN3_Q, t=1.0)
    record = ("tau_command", "friction_torque", "contact_force", "status")
    out = a.rollout(100, record=record, friction=fr, contacts=[contact], tau_ff=np.full(7, 0.5))
    n = 7
    assert out["t"].shape == (101,) and out["q"].shape == (101, n) and out["qd"].shape == (101, n)
    assert out["tau_command"].shape == (100, n) and out["friction_torque"].shape == (100, n)
    assert out["contact_force"].shape == (100, 1, 3) and out["status"].shape == (100, n)
    assert out["status"].dtype == np.int32
    assert out["t"][0] == 1.0 and out["t"][-1] == a.t == 1.0 + 100 * DT
    assert np.array_equal(out["q"][0], GEN3_Q)
    for k in range(100):
        r = b.step(friction=fr, contacts=[contact], tau_ff=np.full(7, 0.5))
        assert np.array_equal(out["q"][k + 1], b.q) and np.array_equal(out["qd"][k + 1], b.qd)
        assert np.array_equal(out["tau_command"][k], r.tau_command)
        assert np.array_equal(out["friction_torque"][k], r.friction_torque)
        assert np.array_equal(out["contact_force"][k], r.contact_force)
        assert np.array_equal(out["status"][k], r.status)
    # Only the states without record=; no friction: zero friction torques, status 0.
    plain = vs.Simulator(chain, DT, q=GEN3_Q).rollout(3, record="friction_torque")
    assert set(plain) == {"t", "q", "qd", "friction_torque"} and (plain["friction_torque"] == 0).all()
    empty = vs.Simulator(chain, DT).rollout(0, record=("status", "contact_force"))
    assert empty["q"].shape == (1, n) and empty["status"].shape == (0, n) and empty["contact_force"].shape[0] == 0


def test_a_controller_callback_drives_the_rollout(chain):
    """A PD controller towards GEN3_Q, gravity compensated, called with (t, q, qd) before each step."""
    calls = []
    solver = vs.Solver(chain)
    KP, KD = 20.0, 1.0  # N m/rad, N m s/rad: stable at 1 kHz for the wrist's small inertias

    def pd(t, q, qd):
        calls.append(t)
        return {"tau_ff": chain.gravity_torques(q) + KP * (GEN3_Q - q) - KD * qd}

    start = GEN3_Q + 0.05
    sim = vs.Simulator(chain, DT, q=start)
    out = sim.rollout(1500, controller=pd, record=("tau_command",))
    assert np.allclose(calls, np.arange(1500) * DT, rtol=0, atol=1e-12)
    assert np.abs(out["q"][-1] - GEN3_Q).max() < 0.5 * np.abs(start - GEN3_Q).max()  # pulled towards GEN3_Q
    assert (out["tau_command"] == 0).all()  # unconstrained: the motors add nothing to tau_ff
    # The same by hand through Solver.step, bitwise.
    q, qd = start.copy(), np.zeros(7)
    for _ in range(1500):
        q, qd, _ = solver.step(q, qd, DT, tau_ff=chain.gravity_torques(q) + KP * (GEN3_Q - q) - KD * qd)
    assert np.array_equal(q, out["q"][-1])
    # A controller returning None uses the constant arguments; its dict overrides them.
    held = vs.Simulator(chain, DT, q=GEN3_Q).rollout(
        10, controller=lambda t, q, qd: None, friction=_holding(chain, GEN3_Q)
    )
    assert (held["q"] == GEN3_Q).all()


def test_reset_and_properties(chain):
    sim = vs.Simulator(chain, 2e-3)
    assert sim.dt == 2e-3 and sim.t == 0.0 and (sim.q == 0).all() and isinstance(sim.solver, vs.Solver)
    sim.reset(GEN3_Q, np.ones(7), t=3.0)
    q = sim.q
    q[0] = 99.0  # a copy
    assert sim.q[0] == 0.0 and sim.t == 3.0 and (sim.qd == 1).all()
    sim.step()
    assert sim.t == 3.0 + 2e-3


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf"), "0.001", True, None])
def test_a_bad_dt_is_refused_with_a_message(chain, dt):
    with pytest.raises(vs.SolverError, match="dt must be"):
        vs.Simulator(chain, dt)


def test_bad_input_messages(chain):
    with pytest.raises(vs.SolverError, match="integrator must be one of"):
        vs.Simulator(chain, DT, integrator="rk4")
    assert vs.Simulator(chain, DT).integrator == "semi_implicit_euler"
    sim = vs.Simulator(chain, DT, q=GEN3_Q)
    with pytest.raises(vs.SolverError, match=r"q must have shape \(7,\)"):
        sim.reset(np.zeros(6), np.zeros(7))
    with pytest.raises(vs.SolverError, match="qd contains NaN or Inf"):
        sim.reset(np.zeros(7), np.full(7, np.nan))
    with pytest.raises(vs.SolverError, match="t must be a finite number"):
        sim.reset(np.zeros(7), np.zeros(7), t=float("inf"))
    assert np.array_equal(sim.q, GEN3_Q)  # unchanged by the refused resets
    with pytest.raises(vs.SolverError, match="time_step are the simulator.s own"):
        sim.step(time_step=0.1)
    with pytest.raises(vs.SolverError, match="tau_ff"):
        sim.step(tau_ff=np.zeros(3))
    with pytest.raises(vs.SolverError, match="contains NaN"):
        sim.step(tau_ff=np.full(7, np.nan))
    assert sim.t == 0.0 and np.array_equal(sim.q, GEN3_Q)  # a failing step leaves the state
    with pytest.raises(vs.SolverError, match="n_steps must be an int >= 0"):
        sim.rollout(-1)
    with pytest.raises(vs.SolverError, match="record names"):
        sim.rollout(2, record=("qdd",))
    with pytest.raises(vs.SolverError, match="controller must be a callable"):
        sim.rollout(2, controller=3)
    with pytest.raises(vs.SolverError, match="controller must return a dict"):
        sim.rollout(2, controller=lambda t, q, qd: [1.0])
    with pytest.raises(TypeError, match="unexpected keyword argument 'torque'"):
        sim.step(torque=np.zeros(7))


def _mujoco_gen3(dt):
    """MuJoCo's model of the same URDF text, frictionless, undamped, no contacts, semi-implicit Euler."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(vs.robots.gen3_urdf())
    model.opt.timestep = dt
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    model.opt.gravity[:] = (0.0, 0.0, -9.81)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    model.dof_frictionloss[:] = 0.0
    model.dof_damping[:] = 0.0
    model.dof_armature[:] = 0.0
    model.jnt_limited[:] = 0
    return mujoco, model


def _mujoco_swing(q0, dt, steps):
    mujoco, model = _mujoco_gen3(dt)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = q0, 0.0
    out = [np.array(data.qpos)]
    for _ in range(steps):
        mujoco.mj_step(model, data)
        out.append(np.array(data.qpos))
    return np.array(out), np.array(data.qvel)


def test_oracle_mujoco_passive_swing(chain):
    """A frictionless passive Gen3 released at rest from GEN3_Q under gravity, 0.2 s.

    Compared: the joint positions after every step and the final velocities, Simulator vs MuJoCo's
    ``mjINT_EULER`` (qvel += dt qacc, then qpos += dt qvel: the same semi-implicit Euler) on the
    same URDF text, same dt = 1 ms, friction, damping, armature, limits and contacts off.
    Both then compute the same discrete map; they differ only by the round-off of the
    forward dynamics (about 1e-13 relative per step: the models agree to the URDF's digits, the
    mass matrices to 1e-12), which the swing amplifies at most by a small factor over 200 steps:
    1e-9 rad bounds that with margin, and any modelling difference (a frame, an inertia) shows
    at 1e-4 or more. The integrator's order shows the other way: against MuJoCo at dt / 4 (a
    finer solution of the same ODE) the difference is O(dt), halving with dt.
    """
    mujoco, model = _mujoco_gen3(DT)
    data = mujoco.MjData(model)
    assert model.nq == 7
    data.qpos[:] = GEN3_Q
    mujoco.mj_forward(model, data)
    M = np.zeros((7, 7))
    mujoco.mj_fullM(model, data, M)
    assert np.allclose(M, chain.mass_matrix(GEN3_Q), rtol=0, atol=1e-10)  # the same robot

    steps = 200
    sim = vs.Simulator(chain, DT, q=GEN3_Q)
    ours = sim.rollout(steps)
    theirs, qd_mj = _mujoco_swing(GEN3_Q, DT, steps)
    assert np.abs(ours["q"] - theirs).max() < 1e-9
    assert np.abs(sim.qd - qd_mj).max() < 1e-8
    assert np.abs(ours["q"][-1] - GEN3_Q).max() > 0.05  # it did swing

    # First order: the error against a 4x finer MuJoCo run halves when dt halves.
    err = []
    for dt in (2e-3, 1e-3):
        n = int(round(0.2 / dt))
        q_end = vs.Simulator(chain, dt, q=GEN3_Q).rollout(n)["q"][-1]
        fine, _ = _mujoco_swing(GEN3_Q, dt / 4, 4 * n)
        err.append(np.abs(q_end - fine[-1]).max())
    assert 1.6 < err[0] / err[1] < 2.5, err
