"""Floating bases (docs/floating-base.md) against Pinocchio, 1e-9 relative.

Free-flyer: ``Tree.from_urdf(..., base="free")`` against ``pin.aba`` on a model built with
``pin.JointModelFreeFlyer()`` (solo12, ANYmal, Talos reduced, random trees): random q (unit
quaternion), v, tau (zero on the base, then non-zero: a wrench on the base), f_ext on several
links. Segment constraints against a KKT system from ``pin.crba``, ``pin.rnea`` and frame
Jacobians (6-D constraints on feet: the frame's spatial acceleration zero), and ``tau_command``
read as a generalized force: ``pin.aba`` with it reproduces the constrained qdd. Planar base: a
Gen3 on ``pin.JointModelPlanar()``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import G_EARTH as G
from support.trees import pin_q, pin_v_index, random_solvable_tree
from vereshchagin.robots import example_robot_urdf, gen3_urdf

RTOL = 1e-9
GRAVITY = np.asarray(G, dtype=float)
ROBOTS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
}


def assert_rel(actual, expected, what, rtol=RTOL):
    scale = max(1.0, float(np.max(np.abs(expected))))
    err = float(np.max(np.abs(np.asarray(actual) - expected))) / scale
    assert err <= rtol, f"{what}: relative error {err:.3e} > {rtol:g}"


class Floating:
    """One URDF loaded by both libraries on a floating base, with the maps between the states."""

    def __init__(self, source, base="free", inertia_check="physical"):
        self.tree = vs.Tree.from_urdf(source, base=base, inertia_check=inertia_check)
        root = pin.JointModelFreeFlyer() if base == "free" else pin.JointModelPlanar()
        text = str(source)
        self.model = pin.buildModelFromXML(text, root) if "<" in text else pin.buildModelFromUrdf(text, root)
        self.model.gravity = pin.Motion(np.r_[GRAVITY, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        self.nb = 6 if base == "free" else 3
        self.nbq = 7 if base == "free" else 4
        names = self.tree.joint_names
        self.v_index = np.r_[np.arange(self.nb), pin_v_index(self.model, names)]
        self.solver = vs.Solver(self.tree, gravity=GRAVITY, max_constraints=48, inertia_check=inertia_check)
        assert self.tree.nq == self.tree.n_joints + self.nbq and self.tree.nv == self.model.nv

    def random_state(self, rng):
        n = self.tree.n_joints
        q = np.r_[rng.uniform(-0.5, 0.5, self.nbq), rng.uniform(-1.0, 1.0, n)]
        if self.nb == 6:
            q[3:7] /= np.linalg.norm(q[3:7])
        else:
            yaw = rng.uniform(-np.pi, np.pi)
            q[2:4] = np.cos(yaw), np.sin(yaw)
        return q, rng.uniform(-1.0, 1.0, self.tree.nv)

    def pin_q(self, q):
        out = pin_q(self.model, self.tree.joint_names, q[self.nbq :])
        out[: self.nbq] = q[: self.nbq]
        return out

    def pin_v(self, v):
        out = np.zeros(self.model.nv)
        out[self.v_index] = v
        return out

    def ours(self, pin_vector):
        return np.asarray(pin_vector)[self.v_index]

    def frame(self, name):
        return self.model.getFrameId(name)

    def pin_fext(self, pq, wrenches):
        """Pinocchio's f_ext (per joint, local frame) of our {segment tip link: wrench} (world axes,
        moment about the tip origin)."""
        pin.framesForwardKinematics(self.model, self.data, pq)
        fext = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for link, w in wrenches.items():
            fid = self.frame(link)
            jid = self.model.frames[fid].parentJoint
            oMf, oMj = self.data.oMf[fid], self.data.oMi[jid]
            f, n = w[:3], w[3:] + np.cross(oMf.translation - oMj.translation, w[:3])
            fext[jid] += pin.Force(oMj.rotation.T @ f, oMj.rotation.T @ n)
        return fext


def random_wrenches(case, rng, k=3):
    names = case.tree.segment_names
    picks = rng.choice(len(names), size=min(k, len(names)), replace=False)
    return {names[i]: rng.uniform(-5.0, 5.0, 6) for i in picks}


def f_ext_rows(case, wrenches):
    rows = np.zeros((case.tree.n_segments, 6))
    for name, w in wrenches.items():
        rows[case.tree.segment_names.index(name)] = w
    return rows


CASES = {}


def case(name):
    if name not in CASES:
        if name.startswith("random"):
            CASES[name] = Floating(random_solvable_tree(int(name[6:])).urdf)
        elif name == "gen3_planar":
            CASES[name] = Floating(gen3_urdf(), base="planar")
        else:  # ANYmal's dummy link 'base' has inertia (0, 0, 3e-6): no rigid body has it
            check = "joint_space" if name == "anymal" else "physical"
            CASES[name] = Floating(example_robot_urdf(ROBOTS[name]), inertia_check=check)
    return CASES[name]


FREE = ["solo12", "anymal", "talos", "random1", "random2", "random3"]


@pytest.mark.parametrize("name", FREE + ["gen3_planar"])
def test_free_motion_matches_aba(name):
    c = case(name)
    rng = np.random.default_rng(28)
    for trial in range(4):
        q, v = c.random_state(rng)
        tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
        if trial >= 2:
            tau[: c.nb] = rng.uniform(-2.0, 2.0, c.nb)  # a wrench on the base (base axes)
        wrenches = random_wrenches(c, rng) if trial % 2 else {}
        pq = c.pin_q(q)
        expected = pin.aba(c.model, c.data, pq, c.pin_v(v), c.pin_v(tau), c.pin_fext(pq, wrenches))
        r = c.solver.solve(q, v, tau_ff=tau, f_ext=f_ext_rows(c, wrenches) if wrenches else None)
        assert_rel(r.qdd, c.ours(expected), f"{name} trial {trial}: qdd")


def _kkt(c, q, v, tau, feet):
    """Pinocchio's constrained qdd: M qdd + b = tau + J^T lambda, J qdd + dJ v = 0 (the feet's
    spatial accelerations in their own frames zero)."""
    pq, pv, ptau = c.pin_q(q), c.pin_v(v), c.pin_v(tau)
    M = pin.crba(c.model, c.data, pq)
    M = np.triu(M) + np.triu(M, 1).T
    b = pin.rnea(c.model, c.data, pq, pv, np.zeros(c.model.nv))
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq, pv, np.zeros(c.model.nv))
    pin.updateFramePlacements(c.model, c.data)
    J = np.vstack([pin.getFrameJacobian(c.model, c.data, c.frame(f), pin.LOCAL) for f in feet])
    drift = np.concatenate([pin.getFrameAcceleration(c.model, c.data, c.frame(f), pin.LOCAL).vector for f in feet])
    k = J.shape[0]
    kkt = np.block([[M, J.T], [J, np.zeros((k, k))]])
    sol = np.linalg.solve(kkt, np.r_[ptau - b, -drift])
    return c.ours(sol[: c.model.nv])


FEET = {
    "solo12": ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"],
    "anymal": ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"],
    "talos": ["leg_left_6_link", "leg_right_6_link"],
}


@pytest.mark.parametrize("name", list(FEET))
@pytest.mark.parametrize("n_feet", [1, 2])
def test_feet_constraints_match_kkt(name, n_feet):
    c = case(name)
    rng = np.random.default_rng(280 + n_feet)
    feet = FEET[name][:n_feet]
    for trial in range(3):
        q, v = c.random_state(rng)
        tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
        expected = _kkt(c, q, v, tau, feet)
        # Each foot: alpha = identity (world axes, moment about the foot frame's origin); the
        # spatial acceleration zero means alpha^T xdd = alpha^T [-gravity; 0].
        cons = {f: (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0]) for f in feet}
        r = c.solver.solve(q, v, tau_ff=tau, constraints=cons)
        assert_rel(r.qdd, expected, f"{name} {feet} trial {trial}: qdd")
        # tau_command is the generalized force of the constraints (nv, base rows included):
        # applied as torques and a base wrench it gives the same motion.
        free = pin.aba(c.model, c.data, c.pin_q(q), c.pin_v(v), c.pin_v(tau + r.tau_command))
        assert_rel(c.ours(free), expected, f"{name} {feet} trial {trial}: aba(tau + tau_command)", 1e-8)


def _kkt_points(c, q, v, tau, feet, fext):
    """Pinocchio's qdd with the feet's origins held (3-D: classical linear accelerations zero)."""
    pq, pv, ptau = c.pin_q(q), c.pin_v(v), c.pin_v(tau)
    M = pin.crba(c.model, c.data, pq)
    M = np.triu(M) + np.triu(M, 1).T
    zero = np.zeros(c.model.nv)
    b = pin.rnea(c.model, c.data, pq, pv, zero, fext) if fext else pin.rnea(c.model, c.data, pq, pv, zero)
    pin.computeJointJacobians(c.model, c.data, pq)
    pin.forwardKinematics(c.model, c.data, pq, pv, np.zeros(c.model.nv))
    pin.updateFramePlacements(c.model, c.data)
    J = np.vstack([pin.getFrameJacobian(c.model, c.data, c.frame(f), pin.LOCAL)[:3] for f in feet])
    drift = np.concatenate(
        [pin.getFrameClassicalAcceleration(c.model, c.data, c.frame(f), pin.LOCAL).linear for f in feet]
    )
    k = J.shape[0]
    sol = np.linalg.solve(np.block([[M, J.T], [J, np.zeros((k, k))]]), np.r_[ptau - b, -drift])
    return c.ours(sol[: c.model.nv])


@pytest.mark.parametrize("name", ["solo12", "anymal"])
def test_point_contacts_with_f_ext_match_kkt(name):
    # Every foot's origin held (3 columns each: forces along the world axes) with wrenches on
    # other links: the classical acceleration zero is the spatial one -omega x v, so
    # beta = -omega x v - gravity (world axes, at the foot's origin).
    c = case(name)
    rng = np.random.default_rng(2800)
    feet = FEET[name]
    for trial in range(3):
        q, v = c.random_state(rng)
        tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
        wrenches = random_wrenches(c, rng)
        pq = c.pin_q(q)
        expected = _kkt_points(c, q, v, tau, feet, c.pin_fext(pq, wrenches))
        pin.forwardKinematics(c.model, c.data, pq, c.pin_v(v))
        cons = {}
        for f in feet:
            tw = pin.getFrameVelocity(c.model, c.data, c.frame(f), pin.LOCAL_WORLD_ALIGNED)
            cons[f] = (np.eye(6)[:, :3], -np.cross(tw.angular, tw.linear) - GRAVITY)
        r = c.solver.solve(q, v, tau_ff=tau, f_ext=f_ext_rows(c, wrenches), constraints=cons)
        assert_rel(r.qdd, expected, f"{name} trial {trial}: qdd")


def test_planar_base_constraint_matches_kkt():
    # The Gen3 on a planar base, its last segment's spatial acceleration zero.
    c = case("gen3_planar")
    rng = np.random.default_rng(2801)
    tool = c.tree.segment_names[-1]
    for trial in range(3):
        q, v = c.random_state(rng)
        tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
        expected = _kkt(c, q, v, tau, [tool])
        r = c.solver.solve(q, v, tau_ff=tau, constraints={tool: (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0])})
        assert_rel(r.qdd, expected, f"gen3 planar trial {trial}: qdd")


@pytest.mark.parametrize("name", ["solo12", "talos", "gen3_planar"])
def test_response_columns_are_the_exact_affine_response(name):
    # qdd and tau_command are affine in tau_ff: each response column equals the difference of two
    # solves, the base's rows included, free and with foot constraints.
    c = case(name)
    rng = np.random.default_rng(2803)
    q, v = c.random_state(rng)
    tau = np.r_[np.zeros(c.nb), rng.uniform(-3.0, 3.0, c.tree.n_joints)]
    feet = FEET.get(name, [c.tree.segment_names[-1]])[:2]
    for cons in ({}, {f: (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0]) for f in feet}):
        joints = [0, c.tree.n_joints // 2, c.tree.n_joints - 1]
        base = c.solver.solve(q, v, tau_ff=tau, constraints=cons)
        qdd0, cmd0 = base.qdd.copy(), base.tau_command.copy()
        dqdd, dcmd = c.solver.response_columns(joints)
        assert dqdd.shape == (c.tree.nv, 3)
        for col, j in enumerate(joints):
            unit = np.zeros(c.tree.nv)
            unit[c.nb + j] = 1.0
            r = c.solver.solve(q, v, tau_ff=tau + unit, constraints=cons)
            assert_rel(dqdd[:, col], r.qdd - qdd0, f"{name} joint {j}: dqdd", 1e-8)
            assert_rel(dcmd[:, col], r.tau_command - cmd0, f"{name} joint {j}: dtau_command", 1e-8)


def test_sizes_and_messages():
    c = case("solo12")
    q, v = c.random_state(np.random.default_rng(1))
    with pytest.raises(vs.SolverError, match="q"):
        c.solver.solve(q[1:], v)
    bad = q.copy()
    bad[3:7] *= 1.1
    with pytest.raises(vs.SolverError, match="unit quaternion"):
        c.solver.solve(bad, v)
    assert c.tree.base == "free" and vs.Tree.from_urdf(example_robot_urdf(ROBOTS["solo12"])).base == "fixed"
