"""Joint position limits as a one-sided dissipative force in the friction optimisation.

Expected values are worked out by hand for the 1-DOF arm of Vukcevic 2018, ch. 6 (joint-axis inertia 2.25 kg m^2,
no gravity, f = 2 N m here): a joint resting on its limit and pushed further stays (the limit
reaction takes what friction cannot hold); pushed away it slips as usual.
"""

import numpy as np
import pytest

import vereshchagin as vs

INERTIA = 2.25
F = 2.0


def arm():
    chain = vs.Chain()
    tip = np.eye(4)
    tip[0, 3] = 1.0
    chain.add_segment("link", "rot_z", tip=tip, mass=1.0, com=[-0.5, 0, 0], inertia=np.diag([1.0, 1.0, 2.0]))
    return vs.Solver(chain, gravity=[0, 0, 0])


def solve(q, tau, **kw):
    friction = vs.Friction(static=[F], lower=[0.0], upper=[1.0])
    return arm().solve([q], [0.0], tau_ff=[tau], friction=friction, **kw)


def test_pushed_into_lower_limit_stays():
    r = solve(0.0, -4.9)
    assert abs(r.qdd[0]) < 1e-12
    assert r.friction_torque[0] == pytest.approx(F, abs=1e-12)
    assert r.limit_torque[0] == pytest.approx(4.9 - F, abs=1e-12)
    assert abs(r.tau_command[0]) < 1e-12


def test_pushed_away_from_lower_limit_slips():
    r = solve(0.0, 10.0)
    assert r.qdd[0] == pytest.approx((10.0 - F) / INERTIA, rel=1e-12)
    assert r.friction_torque[0] == pytest.approx(-F, abs=1e-12)
    assert r.limit_torque[0] == 0.0
    assert r.status[0] == 2


def test_pushed_into_upper_limit_stays():
    r = solve(1.0, 4.9)
    assert abs(r.qdd[0]) < 1e-12
    assert r.friction_torque[0] == pytest.approx(-F, abs=1e-12)
    assert r.limit_torque[0] == pytest.approx(-(4.9 - F), abs=1e-12)


def test_away_from_limits_friction_only():
    r = solve(0.5, -4.9)
    assert r.qdd[0] == pytest.approx((-4.9 + F) / INERTIA, rel=1e-12)
    assert r.limit_torque[0] == 0.0


def test_gauss_value_at_limit():
    # Z0 = 1/2 I (qdd - qdd_free)^2 with qdd = 0 and qdd_free = -4.9 / I; the limit adds nothing.
    r = solve(0.0, -4.9)
    assert r.gauss_value == pytest.approx(0.5 * INERTIA * (4.9 / INERTIA) ** 2, rel=1e-12)


def test_task_into_limit_is_an_error():
    alpha = np.zeros((6, 1))
    alpha[5, 0] = 1.0
    with pytest.raises(vs.SolverError, match="limit"):
        solve(0.0, 0.0, alpha=alpha, beta=[-1.0])


def test_chain_limits_from_urdf():
    urdf = """<robot name="r"><link name="base"/>
      <link name="l"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
        <inertia ixx="0" ixy="0" ixz="0" iyy="2" iyz="0" izz="2"/></inertial></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="l"/><axis xyz="0 0 1"/>
        <limit lower="0" upper="1" effort="10" velocity="1"/><dynamics friction="2"/></joint></robot>"""
    solver = vs.Solver(vs.Chain.from_urdf(urdf), gravity=[0, 0, 0])
    r = solver.solve([0.0], [0.0], tau_ff=[-4.9], friction=True)
    assert abs(r.qdd[0]) < 1e-12
    assert r.friction_torque[0] == pytest.approx(2.0, abs=1e-12)
    assert r.limit_torque[0] == pytest.approx(2.9, abs=1e-12)


def test_bad_limits_raise():
    with pytest.raises(vs.SolverError, match="lower <= upper"):
        arm().solve([0.0], [0.0], friction=vs.Friction(static=[F], lower=[1.0], upper=[0.0]))
    with pytest.raises(vs.SolverError, match="friction.lower"):
        arm().solve([0.0], [0.0], friction=vs.Friction(static=[F], lower=[0.0, 1.0]))
