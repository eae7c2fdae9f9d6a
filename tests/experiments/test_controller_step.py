"""The discrete-time controller mode (``ControllerConfig.time_step``, issue 27) on the Gen3.

What is checked: a correction that flips a creeping joint's friction at the instant (the command
jumps by 2 f) leaves the command over the step continuous; a joint that must move still gets its
friction compensated (the command, with friction acting over the step, realises the task: checked
by the forward dynamics over the step, and a frictionless command does not); the controller passes
``time_step`` to its solve and the dual-arm / contact settings use the mode.
"""

from __future__ import annotations

import numpy as np

import vereshchagin as vs
from vereshchagin import robots
from vereshchagin.task import beta_for, directions
from vereshchagin_experiments.contact import dual_arm, surfaces
from vereshchagin_experiments.contact.controller import CONTROL_PERIOD, CascadedController, ControllerConfig
from vereshchagin_experiments.contact.use_cases import gen3_model

G = [0.0, 0.0, -9.81]
DT = 1e-3
ALPHA = directions(("x", "y", "z", "rx", "ry", "rz"))
QD0 = np.array([2e-3, -1e-3, 1.5e-3, 2e-3, -2e-3, 1e-3, 1e-3])  # creep, all below the rest tolerance


def _setup():
    _, chain = gen3_model()
    solver = vs.Solver(chain, gravity=G)
    q = np.array(robots.GEN3_START_POSE)
    fr = vs.Friction(static=np.asarray(chain.friction), velocity_tolerance=1e-2)
    return chain, solver, q, fr


def _command(solver, chain, q, eps, fr, dt):
    a = np.zeros(6)
    a[0] = eps
    beta = beta_for(ALPHA, a, np.asarray(chain.twist(q, QD0)), G)
    return solver.solve(q, QD0, ALPHA, beta, friction=fr, time_step=dt), beta


def _tau(solver, chain, q, eps, fr, dt):
    return np.asarray(_command(solver, chain, q, eps, fr, dt)[0].tau_command)


def test_a_correction_that_flips_the_instants_friction_leaves_the_step_command_continuous():
    chain, solver, q, fr = _setup()
    grid = np.linspace(-3.0, 3.0, 601)  # x corrections (m/s^2); the instant's command jumps in one cell
    taus = np.array([_tau(solver, chain, q, e, fr, None) for e in grid])
    k = int(np.argmax(np.abs(np.diff(taus, axis=0)).max(axis=1)))
    lo, hi = grid[k], grid[k + 1]
    for _ in range(45):  # bisection on the instant's jump
        mid = 0.5 * (lo + hi)
        jump_lo = np.abs(_tau(solver, chain, q, mid, fr, None) - _tau(solver, chain, q, lo, fr, None)).max()
        lo, hi = (lo, mid) if jump_lo > 0.5 else (mid, hi)
    assert hi - lo < 1e-12
    f = np.asarray(chain.friction)
    instant = np.abs(_tau(solver, chain, q, hi, fr, None) - _tau(solver, chain, q, lo, fr, None))
    assert instant.max() > 1.9 * f.min()  # the full breakaway friction flips: 2 f at some joint
    step = np.abs(_tau(solver, chain, q, hi, fr, DT) - _tau(solver, chain, q, lo, fr, DT))
    assert step.max() < 1e-9  # over the step: continuous (a Lipschitz map, over 1e-12 m/s^2)
    wide = np.abs(_tau(solver, chain, q, hi + 1e-4, fr, DT) - _tau(solver, chain, q, lo - 1e-4, fr, DT))
    assert wide.max() < 1e-2  # and no jump nearby


def test_a_joint_that_must_move_gets_its_friction_compensated_over_the_step():
    chain, solver, q, fr = _setup()
    res, beta = _command(solver, chain, q, 3.0, fr, DT)
    moving = np.asarray(res.status) != 1
    assert moving.sum() >= 5
    f = np.asarray(chain.friction)
    assert np.allclose(np.abs(np.asarray(res.friction_torque))[moving], f[moving], rtol=1e-12)
    # the plant over the step (forward dynamics, friction acting) with the command: the task is met
    plant = solver.solve(q, QD0, tau_ff=np.asarray(res.tau_command), friction=fr, time_step=DT)
    assert np.abs(np.asarray(plant.qdd) - np.asarray(res.qdd)).max() <= 1e-9 * np.abs(res.qdd).max()
    # a frictionless command in the same plant falls short by the friction it did not compensate
    plain = solver.solve(q, QD0, ALPHA, beta)
    short = solver.solve(q, QD0, tau_ff=np.asarray(plain.tau_command), friction=fr, time_step=DT)
    assert np.abs(np.asarray(short.qdd) - np.asarray(res.qdd)).max() > 0.1


def test_the_controller_passes_its_period_and_the_experiments_use_the_mode():
    chain, solver, q, _ = _setup()
    for dt in (None, DT):
        ctl = CascadedController(chain, solver, ControllerConfig(time_step=dt))
        goal = np.asarray(chain.fk(q))
        goal[0, 3] += 0.01
        ctl.set_goal(goal)
        tau, info = ctl.command(q, QD0)
        x = info.inputs
        assert x.get("time_step") == dt
        fr = vs.Friction(static=np.asarray(chain.friction), velocity_tolerance=1e-2)
        want = solver.solve(q, QD0, x["alpha"], x["beta"], tau_ff=x["tau_ff"], friction=fr, time_step=dt)
        assert np.allclose(tau, np.asarray(want.tau_command) + x["motor_ff"], rtol=1e-12, atol=1e-12)
    assert CONTROL_PERIOD == DT
    assert dual_arm.CONFIG.time_step == CONTROL_PERIOD and dual_arm.CONFIG.hold_band is None
    assert surfaces.CONTACT_CONFIG == {"time_step": CONTROL_PERIOD}
