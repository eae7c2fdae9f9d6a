"""Our URDF loader + solver against Pinocchio 4.1 reading the same URDF files.

Robots: Franka Panda (example-robot-data, tip ``panda_hand``; Pinocchio's two finger joints are
locked at 0 with ``buildReducedModel`` because our loader lumps them rigidly at 0), UR5 (its tree
branches; tips ``tool0`` and ``ee_link``) and the shipped Kinova Gen3 with and without the rigid
Robotiq 2F-85 (continuous joints are (cos, sin) pairs in Pinocchio).

Every expected value comes from Pinocchio (see tests/oracles/test_pinocchio_oracle.py for the mapping):

* m = 0: ``qdd = pin.aba``;
* m > 0: ``qdd = pin.forwardDynamics(q, v, tau, alpha^T J, alpha^T (a0 + [-g; 0]) - beta)`` with J
  the LOCAL_WORLD_ALIGNED Jacobian of the tip link frame and a0 its LWA frame acceleration at
  ``qdd = 0``; ``nu = -lambda``;
* ``pin.aba(tau_ff + tau_command)`` gives ``qdd`` back;
* fk / jacobian / twist = frame placement / LWA frame Jacobian / LWA frame velocity;
* limits, friction and damping = the model's vectors.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import well_conditioned_task
from support.urdf_robots import BUILDERS, G, LWA, assert_rel, gen3_robot, minv, panda, ur5, with_rotors


# ------------------------------------------------------------------------------------------------
# Structure: the oracle models describe the same robots
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("robot", sorted(BUILDERS))
def test_same_joints_and_mass(robot):
    r = BUILDERS[robot]()
    assert r.model.nv == r.chain.n_joints
    assert list(r.chain.joint_names) == list(r.model.names[1:])
    assert r.chain.segment_names[-1] == r.tip
    # every mass not welded to the root ends up in a segment
    moving_mass = sum(r.model.inertias[i].mass for i in range(1, r.model.njoints))
    assert np.sum(r.chain.segment_masses) == pytest.approx(moving_mass, rel=1e-12)


def test_gen3_gripper_mass_is_on_the_last_segment():
    bare, grip = BUILDERS["gen3_bare"](), BUILDERS["gen3_gripper"]()
    extra = grip.model.inertias[7].mass - bare.model.inertias[7].mass
    assert extra > 0.9
    np.testing.assert_allclose(grip.chain.segment_masses[:-1], bare.chain.segment_masses[:-1], rtol=1e-14)
    assert grip.chain.segment_masses[-1] - bare.chain.segment_masses[-1] == pytest.approx(extra, rel=1e-12)


# ------------------------------------------------------------------------------------------------
# Limits, friction, damping
# ------------------------------------------------------------------------------------------------
LIMIT_CASES = {
    "panda": panda,
    "ur5_tool0": lambda: ur5("tool0"),
    "gen3_dyn": lambda: gen3_robot(
        True,
        joint_friction=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7],
        joint_damping=[0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07],
    ),
    "gen3_cable": lambda: gen3_robot(False, use_external_cable=True, joint_friction=0.25, joint_damping=0.5),
}


@pytest.mark.parametrize("case", sorted(LIMIT_CASES))
def test_limits_friction_damping(case):
    r = LIMIT_CASES[case]()
    m, c = r.model, r.chain
    lower, upper = np.asarray(c.lower), np.asarray(c.upper)
    n_continuous = 0
    for k, name in enumerate(c.joint_names):
        joint = m.joints[m.getJointId(name)]
        iq, iv = joint.idx_q, joint.idx_v
        if joint.nq == 2:  # continuous: Pinocchio bounds (cos, sin); we have no position limit
            n_continuous += 1
            assert c.joint_types[k] == "continuous"
            assert lower[k] == -np.inf and upper[k] == np.inf
        else:
            assert c.joint_types[k] in ("revolute", "prismatic")
            assert lower[k] == m.lowerPositionLimit[iq]
            assert upper[k] == m.upperPositionLimit[iq]
        assert c.velocity_limit[k] == m.velocityLimit[iv]
        assert c.effort_limit[k] == m.effortLimit[iv]
        assert c.friction[k] == m.friction[iv]
        assert c.damping[k] == m.damping[iv]
    assert n_continuous == (4 if case == "gen3_dyn" else 0)
    if case.startswith("gen3"):
        assert np.all(np.asarray(c.friction) > 0) and np.all(np.asarray(c.damping) > 0)


# ------------------------------------------------------------------------------------------------
# Kinematics of the tip and of merged links
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("robot", sorted(BUILDERS))
def test_fk_jacobian_twist(robot):
    r = BUILDERS[robot]()
    rng = np.random.default_rng([7, len(robot)])
    data = r.model.createData()
    frames = (None, r.tip) + r.links
    for _ in range(6):
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        pin.forwardKinematics(r.model, data, pq, qd)
        pin.updateFramePlacements(r.model, data)
        pin.computeJointJacobians(r.model, data, pq)
        for name in frames:
            fid = r.model.getFrameId(r.tip if name is None else name)
            assert fid < len(r.model.frames), name
            T = data.oMf[fid].homogeneous
            J = pin.getFrameJacobian(r.model, data, fid, LWA)
            V = pin.getFrameVelocity(r.model, data, fid, LWA).vector
            assert_rel(r.chain.fk(q, name), T, f"fk {name}", 1e-12)
            assert_rel(r.chain.jacobian(q, name), J, f"jacobian {name}", 1e-12)
            assert_rel(r.chain.twist(q, qd, name), V, f"twist {name}", 1e-12)


# ------------------------------------------------------------------------------------------------
# Dynamics
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("robot", sorted(BUILDERS))
def test_unconstrained_matches_aba(robot):
    r = BUILDERS[robot]()
    rng = np.random.default_rng([11, len(robot), robot.count("_")])
    data = r.model.createData()
    for _ in range(10):
        solver = with_rotors(r, rng)
        q, qd = r.random_state(rng)
        tau = rng.normal(size=r.chain.n_joints) * 5.0
        res = solver.solve(q, qd, tau_ff=tau)
        pq = r.pin_q(q)
        assert_rel(res.qdd, pin.aba(r.model, data, pq, qd, tau), "qdd vs pin.aba")
        assert res.nu.shape == (0,)
        np.testing.assert_array_equal(res.tau_command, np.zeros(r.chain.n_joints))


def test_rotor_inertia_matters():
    """Guards the comparison above: the armature really changes the answer."""
    r = BUILDERS["gen3_gripper"]()
    rng = np.random.default_rng(3)
    q, qd = r.random_state(rng)
    a = vs.Solver(r.chain, gravity=G).solve(q, qd).qdd
    r.chain.rotor_inertia = np.full(7, 0.3)
    b = vs.Solver(r.chain, gravity=G).solve(q, qd).qdd
    assert np.linalg.norm(a - b) > 1e-2 * np.linalg.norm(a)


@pytest.mark.parametrize("m", range(1, 7))
@pytest.mark.parametrize("robot", sorted(BUILDERS))
def test_constrained_matches_forward_dynamics(robot, m):
    r = BUILDERS[robot]()
    rng = np.random.default_rng([13, m, len(robot), robot.count("_")])
    data = r.model.createData()
    fid = r.model.getFrameId(r.tip)
    done = 0
    for _ in range(100):
        solver = with_rotors(r, rng)
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        alpha = rng.normal(size=(6, m))
        alpha /= np.linalg.norm(alpha, axis=0)
        J = pin.computeFrameJacobian(r.model, data, pq, fid, LWA)
        A = alpha.T @ J
        if not well_conditioned_task(A, minv(r.model, data, pq)):
            continue
        tau = rng.normal(size=r.chain.n_joints) * 5.0
        beta = rng.normal(size=m) * 3.0
        res = solver.solve(q, qd, alpha, beta, tau_ff=tau)

        pin.forwardKinematics(r.model, data, pq, qd, np.zeros(r.model.nv))
        pin.updateFramePlacements(r.model, data)
        a0 = pin.getFrameAcceleration(r.model, data, fid, LWA).vector
        gamma = alpha.T @ (a0 + np.r_[-G, 0.0, 0.0, 0.0]) - beta
        ddq = pin.forwardDynamics(r.model, data, pq, qd, tau, A, gamma)
        lam = np.array(data.lambda_c).reshape(-1)
        assert_rel(res.qdd, ddq, "qdd vs pin.forwardDynamics")
        assert_rel(res.nu, -lam, "nu vs -lambda")
        assert res.constraint_rank == m
        # tau_command replayed through unconstrained ABA gives the same motion
        replay = pin.aba(r.model, data, pq, qd, tau + res.tau_command)
        assert_rel(replay, res.qdd, "aba(tau_ff + tau_command) vs qdd")
        assert_rel(res.tau_command, -J.T @ alpha @ res.nu, "tau_command = -J^T alpha nu")
        # the task is met, in Pinocchio's frame acceleration
        pin.forwardKinematics(r.model, data, pq, qd, res.qdd)
        pin.updateFramePlacements(r.model, data)
        aN = pin.getFrameAcceleration(r.model, data, fid, LWA).vector + np.r_[-G, 0.0, 0.0, 0.0]
        assert_rel(alpha.T @ aN, beta, "alpha^T a_N = beta")
        done += 1
        if done == 6:
            break
    assert done == 6, "too few well-conditioned samples"


@pytest.mark.parametrize("robot", ["panda", "gen3_gripper"])
def test_tau_command_unconstrained_and_full_task(robot):
    """m = 6 with beta from the free motion: the constraint is inactive, nu = 0, tau_command = 0."""
    r = BUILDERS[robot]()
    rng = np.random.default_rng(17)
    solver = with_rotors(r, rng)
    data = r.model.createData()
    fid = r.model.getFrameId(r.tip)
    q, qd = r.random_state(rng)
    pq = r.pin_q(q)
    tau = rng.normal(size=r.chain.n_joints)
    free = pin.aba(r.model, data, pq, qd, tau)
    pin.forwardKinematics(r.model, data, pq, qd, free)
    pin.updateFramePlacements(r.model, data)
    aN = pin.getFrameAcceleration(r.model, data, fid, LWA).vector + np.r_[-G, 0.0, 0.0, 0.0]
    res = solver.solve(q, qd, np.eye(6), aN, tau_ff=tau)
    assert_rel(res.qdd, free, "qdd")
    assert np.linalg.norm(res.nu) < 1e-8 * max(1.0, np.linalg.norm(tau))
