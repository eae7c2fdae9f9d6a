"""The dynamics companions of Chain (KDL's RNE, ChainDynParam, JntToJacDot and FK, wrapped) against
Pinocchio 4.1.

Robots: Franka Panda and UR5 (example-robot-data) and the shipped Kinova Gen3 with its Robotiq
gripper, loaded by Pinocchio from the same URDF (tests/oracles/test_urdf_pinocchio.py), with random rotor
inertias (Pinocchio's ``armature``); plus random chains of every joint kind with fixed segments
anywhere (tests/support/chains.py). Every expected value comes from Pinocchio:

* ``inverse_dynamics`` = ``pin.rnea(q, v, a, fext)``, our f_ext (base axes, moment about each
  segment's tip origin, applied ON the segment) converted to Pinocchio's joint-local forces;
* ``mass_matrix`` = ``pin.crba`` (upper triangle, symmetrised);
* ``gravity_torques`` = ``pin.computeGeneralizedGravity``;
* ``coriolis_torques`` = ``pin.computeCoriolisMatrix(q, v) @ v``;
* ``jacobian_dot_times_qd`` = ``getFrameJacobianTimeVariation(..., LOCAL_WORLD_ALIGNED) @ v``, whose
  linear part is Pinocchio's classical frame acceleration at ``a = 0``;
* ``fk_all`` = the placements ``oMf`` of the segments' frames.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import (
    assert_close,
    fext_at_frames,
    fext_to_pinocchio,
    moving_frames,
    random_chain,
    random_state,
    symmetric,
)
from support.urdf_robots import BUILDERS, with_rotors

RTOL = 1e-9
LWA = pin.LOCAL_WORLD_ALIGNED
ROBOTS = ("panda", "ur5_tool0", "gen3_gripper")


def _robot(name, seed):
    """A URDF robot with random rotor inertias, plus a description of its segments in Pinocchio:
    segment i's tip frame is the Pinocchio frame of the same name (the child link of its joint,
    or the chain's tip link for the last segment)."""
    r = BUILDERS[name]()
    rng = np.random.default_rng(seed)
    with_rotors(r, rng)
    frames = [r.model.getFrameId(s) for s in r.chain.segment_names]
    assert all(f < len(r.model.frames) for f in frames)
    segs = SimpleNamespace(
        model=r.model,
        tip_frames=frames,
        n_segments=len(frames),
        seg_joint=[r.model.frames[f].parentJoint for f in frames],
    )
    return r, segs, rng


def _random_chain_case(seed):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, int(rng.integers(1, 8)), fixed_prob=0.3)
    return rc, rng


# ------------------------------------------------------------------------------------------------
# URDF robots
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ROBOTS)
def test_inverse_dynamics_matches_rnea(name):
    r, segs, rng = _robot(name, [1, len(name)])
    data = r.model.createData()
    for _ in range(8):
        q, qd = r.random_state(rng)
        qdd = rng.normal(size=r.chain.n_joints) * 3.0
        f_ext = rng.uniform(-20.0, 20.0, (r.chain.n_segments, 6))
        pq = r.pin_q(q)
        fext = fext_to_pinocchio(segs, data, pq, f_ext)
        assert_close(
            r.chain.inverse_dynamics(q, qd, qdd, f_ext),
            pin.rnea(r.model, data, pq, qd, qdd, fext),
            RTOL,
            "inverse_dynamics with f_ext vs pin.rnea",
        )
        assert_close(
            r.chain.inverse_dynamics(q, qd, qdd),
            pin.rnea(r.model, data, pq, qd, qdd),
            RTOL,
            "inverse_dynamics vs pin.rnea",
        )


@pytest.mark.parametrize("name", ROBOTS)
def test_inverse_dynamics_reads_an_f_ext_dict_as_pinocchio(name):
    """f_ext as {frame: wrench}, the moment about that frame's origin (links merged into a segment
    included, e.g. the Gen3's gripper links), as Pinocchio's fext on the frame's parent joint."""
    r, _, rng = _robot(name, [4, len(name)])
    data = r.model.createData()
    frames = moving_frames(r.chain)
    for k in range(4):
        q, qd = r.random_state(rng)
        qdd = rng.normal(size=r.chain.n_joints) * 3.0
        wrenches = {f: rng.uniform(-20.0, 20.0, 6) for f in frames[k::4][:5]}
        pq = r.pin_q(q)
        assert_close(
            r.chain.inverse_dynamics(q, qd, qdd, wrenches),
            pin.rnea(r.model, data, pq, qd, qdd, fext_at_frames(r.model, data, pq, wrenches)),
            RTOL,
            f"inverse_dynamics with f_ext {sorted(wrenches)} vs pin.rnea",
        )


@pytest.mark.parametrize("name", ROBOTS)
def test_mass_matrix_gravity_coriolis(name):
    r, _, rng = _robot(name, [2, len(name)])
    data = r.model.createData()
    assert np.all(r.chain.rotor_inertia > 0.0)
    for _ in range(8):
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        M = r.chain.mass_matrix(q)
        np.testing.assert_array_equal(M, M.T)
        assert_close(M, symmetric(pin.crba(r.model, data, pq)), RTOL, "mass_matrix vs pin.crba")
        assert_close(
            r.chain.gravity_torques(q),
            pin.computeGeneralizedGravity(r.model, data, pq),
            RTOL,
            "gravity_torques vs computeGeneralizedGravity",
        )
        C = pin.computeCoriolisMatrix(r.model, data, pq, qd)
        assert_close(r.chain.coriolis_torques(q, qd), C @ qd, RTOL, "coriolis_torques vs C(q, v) v")


def test_gravity_argument_is_physical_gravity():
    r, _, rng = _robot("gen3_gripper", 3)
    g = np.array([1.5, -2.0, -7.0])
    r.model.gravity = pin.Motion(np.r_[g, 0.0, 0.0, 0.0])
    data = r.model.createData()
    q, qd = r.random_state(rng)
    qdd = rng.normal(size=7)
    pq = r.pin_q(q)
    assert_close(r.chain.gravity_torques(q, g), pin.computeGeneralizedGravity(r.model, data, pq), RTOL, "g(q)")
    assert_close(r.chain.inverse_dynamics(q, qd, qdd, gravity=g), pin.rnea(r.model, data, pq, qd, qdd), RTOL, "rnea")


@pytest.mark.parametrize("name", ROBOTS)
def test_jacobian_dot_times_qd(name):
    r, _, rng = _robot(name, [4, len(name)])
    data = r.model.createData()
    names = list(r.chain.segment_names) + list(r.links)
    for _ in range(6):
        q, qd = r.random_state(rng)
        pq = r.pin_q(q)
        pin.computeJointJacobiansTimeVariation(r.model, data, pq, qd)
        pin.forwardKinematics(r.model, data, pq, qd, np.zeros(r.model.nv))
        pin.updateFramePlacements(r.model, data)
        for link in names:
            fid = r.model.getFrameId(link)
            expected = pin.getFrameJacobianTimeVariation(r.model, data, fid, LWA) @ qd
            actual = r.chain.jacobian_dot_times_qd(q, qd, link)
            assert_close(actual, expected, RTOL, f"Jdot qd at {link}")
            classical = pin.getFrameClassicalAcceleration(r.model, data, fid, LWA).vector
            assert_close(actual, classical, RTOL, f"Jdot qd = classical acceleration at qdd = 0, {link}")
        assert_close(r.chain.jacobian_dot_times_qd(q, qd), r.chain.jacobian_dot_times_qd(q, qd, r.tip), 0.0)


@pytest.mark.parametrize("name", ROBOTS)
def test_fk_all(name):
    r, segs, rng = _robot(name, [5, len(name)])
    data = r.model.createData()
    q, _ = r.random_state(rng)
    pin.framesForwardKinematics(r.model, data, r.pin_q(q))
    poses = r.chain.fk_all(q)
    assert poses.shape == (r.chain.n_segments, 4, 4)
    for i, fid in enumerate(segs.tip_frames):
        assert_close(poses[i], data.oMf[fid].homogeneous, 1e-12, f"fk_all[{i}]")
        np.testing.assert_array_equal(poses[i], r.chain.fk(q, i))


# ------------------------------------------------------------------------------------------------
# Random chains: every joint kind, joint origins, fixed segments anywhere
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(12))
def test_random_chains(seed):
    rc, rng = _random_chain_case([6, seed])
    data = rc.data()
    for _ in range(3):
        q, qd = random_state(rng, rc)
        qdd = rng.normal(size=rc.n_joints)
        f_ext = rng.uniform(-5.0, 5.0, (rc.n_segments, 6))
        fext = fext_to_pinocchio(rc, data, q, f_ext)
        assert_close(
            rc.chain.inverse_dynamics(q, qd, qdd, f_ext),
            pin.rnea(rc.model, data, q, qd, qdd, fext),
            RTOL,
            "inverse_dynamics",
        )
        assert_close(rc.chain.mass_matrix(q), symmetric(pin.crba(rc.model, data, q)), RTOL, "mass_matrix")
        assert_close(rc.chain.gravity_torques(q), pin.computeGeneralizedGravity(rc.model, data, q), RTOL, "gravity")
        assert_close(
            rc.chain.coriolis_torques(q, qd), pin.computeCoriolisMatrix(rc.model, data, q, qd) @ qd, RTOL, "coriolis"
        )
        pin.computeJointJacobiansTimeVariation(rc.model, data, q, qd)
        pin.updateFramePlacements(rc.model, data)
        poses = rc.chain.fk_all(q)
        for i, fid in enumerate(rc.tip_frames):
            dJ = np.reshape(pin.getFrameJacobianTimeVariation(rc.model, data, fid, LWA), (6, rc.n_joints))
            assert_close(rc.chain.jacobian_dot_times_qd(q, qd, i), dJ @ qd, RTOL, f"Jdot qd segment {i}")
            assert_close(poses[i], data.oMf[fid].homogeneous, 1e-12, f"fk_all[{i}]")


def test_inverse_dynamics_inverts_the_solver():
    """The hybrid solver's unconstrained motion, fed back, needs exactly its torques."""
    rc, rng = _random_chain_case(7)
    solver = rc.solver()
    q, qd = random_state(rng, rc)
    tau = rng.normal(size=rc.n_joints)
    f_ext = rng.uniform(-5.0, 5.0, (rc.n_segments, 6))
    qdd = solver.solve(q, qd, f_ext=f_ext, tau_ff=tau).qdd
    assert_close(rc.chain.inverse_dynamics(q, qd, qdd, f_ext), tau, RTOL, "RNE(FD(tau)) = tau")


# ------------------------------------------------------------------------------------------------
# Bad input
# ------------------------------------------------------------------------------------------------
def test_bad_input_raises():
    c = vs.robots.gen3()
    q, z = np.full(7, 0.2), np.zeros(7)
    cases = [
        (lambda: c.mass_matrix(np.zeros(6)), "q must have shape (7,)"),
        (lambda: c.inverse_dynamics(q, z, [np.nan] + [0.0] * 6), "qdd contains NaN"),
        (lambda: c.inverse_dynamics(q, z, z, np.zeros((7, 3))), "f_ext must have shape (7, 6)"),
        (lambda: c.inverse_dynamics(q, z, z, np.full((7, 6), np.inf)), "f_ext contains NaN or Inf"),
        (lambda: c.gravity_torques(q, [0.0, -9.81]), "gravity must have shape (3,)"),
        (lambda: c.coriolis_torques(q, "fast"), "qd must hold real numbers"),
        (lambda: c.jacobian_dot_times_qd(q, z, "no_such_link"), "no segment or link named"),
        (lambda: c.jacobian_dot_times_qd(q, z, 7), "out of range"),
        (lambda: c.coriolis_torques(q, np.full(7, 1e160)), "overflow"),
        (lambda: c.fk_all(None), "q must be a real array, got None"),
    ]
    for call, message in cases:
        with pytest.raises(vs.SolverError, match=message.replace("(", r"\(").replace(")", r"\)")):
            call()


def test_empty_chain_and_base_link():
    c = vs.Chain()
    assert c.mass_matrix([]).shape == (0, 0)
    assert c.inverse_dynamics([], [], []).shape == (0,)
    assert c.fk_all([]).shape == (0, 4, 4)
    r = BUILDERS["ur5_tool0"]()
    np.testing.assert_array_equal(r.chain.jacobian_dot_times_qd(np.ones(6), np.ones(6), "base_link"), np.zeros(6))
