"""Numerically hard but valid inputs give finite outputs and a diagnostic (issue 7): singular arm
configurations, duplicated or linearly dependent constraint directions, zero-mass distal
segments, extreme scales (masses 1e-6..1e4 kg, lengths 1e-4..1e2 m), velocities at the at-rest
tolerance and friction of 0 or very large. Every success is also checked physically: the
command torques reproduce qdd through an unconstrained solve."""

import numpy as np
import pytest

import vereshchagin as vs
from support.chains import homogeneous, random_alpha
from vereshchagin.models import seven_joint_arm

FIELDS = ("qdd", "tau_command", "nu", "link_acc")


def finite(res):
    for name in FIELDS:
        assert np.all(np.isfinite(getattr(res, name))), name
    assert np.isfinite(res.smallest_singular_value)


def reproduces(chain, q, qd, res, tau_ff=None, rtol=1e-8, gravity=(0.0, 0.0, -9.81)):
    tau = (np.zeros(len(q)) if tau_ff is None else tau_ff) + res.tau_command
    free = vs.Solver(chain, gravity=gravity).solve(q, qd, tau_ff=tau)
    scale = max(1.0, np.abs(res.qdd).max())
    assert np.abs(free.qdd - res.qdd).max() <= rtol * scale, (free.qdd, res.qdd)


def scaled_arm(n, mass, length):
    """n revolute joints alternating y / z, slender links of ``length`` along x."""
    chain = vs.Chain()
    r = 0.1 * length
    for k in range(n):
        inertia = np.diag([mass * r * r / 2] + [mass * (3 * r * r + length * length) / 12] * 2)
        chain.add_segment(
            f"l{k}",
            "rot_y" if k % 2 == 0 else "rot_z",
            tip=homogeneous(None, [length, 0, 0]),
            mass=mass,
            com=[-length / 2, 0, 0],
            inertia=inertia,
        )
    return chain


@pytest.mark.parametrize("damping", [None, 1e-6])
def test_singular_configuration_full_task(damping):
    # q = 0: the seven-joint arm stands straight up; a full 6-D task on its tip is singular there.
    chain = seven_joint_arm()
    kw = {} if damping is None else dict(damping=damping)
    res = vs.Solver(chain, **kw).solve(np.zeros(7), np.zeros(7), alpha=np.eye(6), beta=np.arange(6.0))
    finite(res)
    assert res.constraint_rank < 6  # the diagnostic
    assert res.smallest_singular_value < 1e-10
    reproduces(chain, np.zeros(7), np.zeros(7), res)


@pytest.mark.parametrize("combo", ["duplicate", "combination", "opposite"])
def test_dependent_constraint_directions(combo):
    chain = seven_joint_arm()
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 7)
    a = random_alpha(rng, 2)
    extra = {"duplicate": a[:, 0], "combination": a @ [0.6, -0.8], "opposite": -a[:, 1]}[combo]
    extra = extra / np.linalg.norm(extra)
    solver = vs.Solver(chain)
    base = solver.solve(q, qd, alpha=a, beta=[1.0, -2.0])
    beta3 = np.r_[1.0, -2.0, extra @ solver.solve(q, qd, alpha=a, beta=[1.0, -2.0]).link_acc[-1]]
    res = vs.Solver(chain).solve(q, qd, alpha=np.c_[a, extra], beta=beta3)
    finite(res)
    assert res.constraint_rank == 2
    np.testing.assert_allclose(res.qdd, base.qdd, rtol=1e-8, atol=1e-8)
    reproduces(chain, q, qd, res)


def test_zero_mass_distal_segments():
    chain = scaled_arm(3, 1.0, 0.4)
    chain.add_segment("massless", "rot_x", mass=0.0, rotor_inertia=1e-4)
    chain.add_segment("massless_fixed", vs.Joint.fixed(), tip=homogeneous(None, [0.1, 0, 0]), mass=0.0)
    q, qd = np.full(4, 0.3), np.full(4, 0.2)
    res = vs.Solver(chain).solve(q, qd, alpha=np.eye(6)[:, [2]], beta=[9.81])
    finite(res)
    reproduces(chain, q, qd, res)


@pytest.mark.parametrize("mass", [1e-6, 1e-3, 1.0, 1e4])
@pytest.mark.parametrize("length", [1e-4, 1e-2, 1.0, 1e2])
def test_extreme_scales(mass, length):
    chain = scaled_arm(6, mass, length)
    q, qd = np.linspace(0.3, -1.2, 6), np.linspace(0.5, -0.5, 6)
    tau = np.linspace(1.0, -1.0, 6) * mass * length**2
    res = vs.Solver(chain).solve(q, qd, alpha=np.eye(6)[:, [2, 4]], beta=[9.81, 0.0], tau_ff=tau)
    finite(res)
    assert res.constraint_rank == 2
    reproduces(chain, q, qd, res, tau_ff=tau)
    # the task is met: z acceleration 9.81 (holding against gravity), no rotation about y
    np.testing.assert_allclose(res.link_acc[-1][[2, 4]], [9.81, 0.0], rtol=1e-8, atol=1e-8 * 9.81)
    # friction at the same scale: finite, bounded, reproduces
    fr = vs.Friction(static=np.full(6, 0.5 * mass * length * 9.81))
    resf = vs.Solver(chain).solve(q, np.zeros(6), tau_ff=tau, friction=fr)
    finite(resf)
    assert np.all(np.abs(resf.friction_torque) <= fr.static * (1 + 1e-12))


def test_velocities_around_the_rest_tolerance():
    chain = seven_joint_arm()
    q = np.full(7, 0.5)
    tol = 1e-6
    fr = vs.Friction(static=np.full(7, 2.0), kinetic=np.full(7, 1.0), velocity_tolerance=tol)
    for v in (0.0, tol * (1 - 1e-12), tol, tol * (1 + 1e-12), np.nextafter(tol, 1.0), -tol, 1e-300, 5e-324):
        qd = np.full(7, v)
        res = vs.Solver(chain).solve(q, qd, friction=fr)
        finite(res)
        resting = np.abs(qd) <= tol
        assert np.all((res.status == 0) == ~resting), (v, res.status)
        assert np.all(np.abs(res.friction_torque) <= np.where(resting, 2.0, 1.0) * (1 + 1e-12))
        reproduces(chain, q, qd, res, tau_ff=res.friction_torque + res.limit_torque)


@pytest.mark.parametrize("f", [0.0, 1e-300, 1e6, 1e12, 1e300])
def test_friction_zero_and_huge(f):
    chain = seven_joint_arm()
    q, qd = np.full(7, 0.5), np.zeros(7)
    res = vs.Solver(chain).solve(q, qd, friction=vs.Friction(static=np.full(7, f)))
    finite(res)
    free = vs.Solver(chain).solve(q, qd)
    if f >= 1e6:  # holds gravity: everything sticks, friction balances the free motion's torque
        assert np.all(res.status == 1)
        assert np.abs(res.qdd).max() <= 1e-9
    else:
        np.testing.assert_allclose(res.qdd, free.qdd, rtol=1e-12, atol=1e-12)
    assert np.all(np.abs(res.friction_torque) <= f)
    reproduces(chain, q, qd, res, tau_ff=res.friction_torque)


@pytest.mark.parametrize("fixed_segments", [0, 2])
def test_chain_without_moving_joints(fixed_segments):
    # Regression: the friction solve read the maximum of an empty vector (a crash).
    chain = vs.Chain()
    for k in range(fixed_segments):
        chain.add_segment(f"plate{k}", vs.Joint.fixed(), tip=homogeneous(None, [0, 0, 0.1]), mass=1.0)
    solver = vs.Solver(chain)
    for kw in (
        dict(),
        dict(friction=vs.Friction(static=np.zeros(0))),
        dict(friction=True),
        dict(alpha=np.eye(6)[:, [2]], beta=[1.0], friction=vs.Friction(static=[])),
    ):
        res = solver.solve(np.zeros(0), np.zeros(0), **kw)
        finite(res)
        assert res.qdd.shape == (0,)


@pytest.mark.parametrize("huge", [1e6, 1e12, 1e100])
def test_one_huge_friction_bound_does_not_mask_the_others(huge):
    # One huge bound next to small ones: the small ones still act in full (the QP's gradient
    # tolerance once scaled with the largest bound; the fuzz regression solver-qp-huge-bound
    # replays the input that exposed it).
    chain = seven_joint_arm()
    q, qd = np.full(7, 0.5), np.zeros(7)
    fs = np.r_[huge, np.full(6, 0.05)]
    res = vs.Solver(chain).solve(q, qd, friction=vs.Friction(static=fs))
    finite(res)
    assert res.status[0] == 1  # the huge one sticks
    slipping = np.isin(res.status, (2, 3))
    assert slipping.any()  # 0.05 N m cannot hold this arm against gravity
    np.testing.assert_allclose(res.friction_torque[slipping], -fs[slipping] * np.sign(res.qdd[slipping]), rtol=1e-9)
    reproduces(chain, q, qd, res, tau_ff=res.friction_torque)
