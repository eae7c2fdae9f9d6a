"""Whole-body least effort (vereshchagin.whole_body, C++ WholeBodySolver) against Pinocchio, 1e-9.

Standing: solo12 on four point feet and Talos (reduced) on two feet of four corner points each,
base still (6 task rows on the base, qd = 0), least motor effort with the support forces in
their friction cones (mu 0.7, 4 and 8 facets); then each balancing a load (a wrench on the base
for solo12, a weight in Talos's left hand). The oracle is a QP in (qdd, tau, lambda) written from
Pinocchio's pieces (``pin.crba``, ``pin.rnea`` with the external forces, frame Jacobians and the
classical accelerations of the contact points):

    M qdd + h = S^T tau + J^T lambda,   J qdd + Jdot qd = 0,   qdd_base = 0,   D lambda >= 0,

solved by scipy's SLSQP (min |tau|^2, then min |lambda|^2 with that tau), then polished exactly:
its active cone rows and the equalities as a KKT system (numpy least squares; the multipliers of
the active rows checked non-negative). Also: a centre-of-mass acceleration task (through
``pin.jacobianCenterOfMass``), solo12 with its hip abduction joints unactuated (the mask), our
answer's dynamics residual in Pinocchio, a task
that no support forces realize (solo12 on one foot, every other foot and the base held still), a
cone too narrow, and a fixed-base Gen3 whose 7 task rows determine qdd: tau equals the plain
solve's tau_command.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize

import vereshchagin as vs
from support.trees import pin_q_free, pin_v_index, pin_v_scatter
from vereshchagin.robots import example_robot_urdf

RTOL = 1e-9
GRAVITY = np.array([0.0, 0.0, -9.81])
BASE_STILL = (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0])


def assert_rel(actual, expected, what, rtol=RTOL):
    scale = max(1.0, float(np.max(np.abs(expected))))
    err = float(np.max(np.abs(np.asarray(actual) - expected))) / scale
    assert err <= rtol, f"{what}: relative error {err:.3e} > {rtol:g}"


def cone_rows(normal, mu, facets):
    """The polygon's facet rows of docs/contacts.md (written here independently): n.f >= 0 and
    mu cos(pi/k) n.f - m_j.f >= 0 with m_j the outward normal of the edge between vertices j, j+1."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    e = np.eye(3)[int(np.argmin(np.abs(n)))]
    t1 = np.cross(e, n)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    verts = [np.cos(2 * np.pi * j / facets) * t1 + np.sin(2 * np.pi * j / facets) * t2 for j in range(facets)]
    rows = [n]
    for j in range(facets):
        mid = verts[j] + verts[(j + 1) % facets]
        m = mid / np.linalg.norm(mid)
        rows.append(mu * np.cos(np.pi / facets) * n - m)
    return np.array(rows)


class Standing:
    """A URDF on a free-flyer in both libraries, supports at points of frames, the oracle QP."""

    def __init__(self, urdf):
        self.tree = vs.Tree.from_urdf(urdf, base="free")
        self.model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        self.model.gravity = pin.Motion(np.r_[GRAVITY, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        self.solver = vs.Solver(self.tree, gravity=GRAVITY, max_constraints=48)
        names = self.tree.joint_names
        self.v_index = np.r_[np.arange(6), pin_v_index(self.model, names)]
        root = ET.parse(str(urdf)).getroot()
        self.child = {j.get("name"): j.find("child").get("link") for j in root.findall("joint")}
        self.points = []  # (pin frame id, segment name, point in the segment's frame)

    def pin_q(self, q):
        return pin_q_free(self.model, self.tree.joint_names, q)

    def pin_v(self, v):
        return pin_v_scatter(self.model, self.v_index, v)

    def add_point(self, frame, offset=(0.0, 0.0, 0.0)):
        f = self.model.frames[self.model.getFrameId(frame)]
        placement = f.placement * pin.SE3(np.eye(3), np.asarray(offset, float))
        fid = self.model.addFrame(pin.Frame(f"{frame}_{len(self.points)}", f.parentJoint, placement, pin.OP_FRAME))
        self.data = self.model.createData()
        segment = self.child[self.model.names[f.parentJoint]]
        self.points.append((fid, segment, placement.translation.copy()))

    def supports(self, mu=0.7, facets=4):
        return [vs.Contact(seg, point=p, normal=[0, 0, 1], mu=mu, facets=facets) for _, seg, p in self.points]

    def fext(self, q, segment_wrenches):
        """Our f_ext (n_segments, 6) and Pinocchio's per-joint forces (LOCAL) for the same wrenches."""
        ours = np.zeros((self.tree.n_segments, 6))
        pins = [pin.Force.Zero() for _ in range(self.model.njoints)]
        pin.forwardKinematics(self.model, self.data, self.pin_q(q))
        R_base = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
        for joint, wrench in segment_wrenches.items():
            index = self.tree.segment_index(self.child[joint])
            tip = q[:3] + R_base @ self.tree.fk(q[7:], index)[:3, 3]  # the segment's tip (merged links)
            at = self.data.oMi[self.model.getJointId(joint)].translation  # the wrench's reference point
            ours[index] = np.r_[wrench[:3], wrench[3:] + np.cross(at - tip, wrench[:3])]
            R = self.data.oMi[self.model.getJointId(joint)].rotation
            pins[self.model.getJointId(joint)] = pin.Force(R.T @ wrench[:3], R.T @ wrench[3:])
        return ours, pins

    def pieces(self, q, tau_ff_base, pin_fext):
        """M, h (rnea with qdd = 0 and the external forces, minus the base wrench), J (3k x nv),
        drift (3k): Pinocchio's."""
        qp, vp = self.pin_q(q), np.zeros(self.model.nv)
        M = pin.crba(self.model, self.data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.rnea(self.model, self.data, qp, vp, np.zeros(self.model.nv), pin_fext).copy()
        h[:6] -= tau_ff_base
        pin.computeJointJacobians(self.model, self.data, qp)
        pin.forwardKinematics(self.model, self.data, qp, vp, np.zeros(self.model.nv))
        pin.updateFramePlacements(self.model, self.data)
        J, drift = [], []
        for fid, _, _ in self.points:
            J.append(pin.getFrameJacobian(self.model, self.data, fid, pin.LOCAL_WORLD_ALIGNED)[:3])
            acc = pin.getFrameClassicalAcceleration(self.model, self.data, fid, pin.LOCAL_WORLD_ALIGNED)
            drift.append(acc.linear)
        return M, h, np.vstack(J), np.concatenate(drift)


def oracle(M, h, J, drift, D, n_base=6, task=None, actuated=None):
    """min |tau|^2, then min |lambda|^2, over (qdd, tau, lambda): SLSQP, then the exact KKT polish.
    task: rows (T, t) with T qdd = t (default: the base still, qdd_base = 0); actuated: the
    velocity indices with a motor (default: every joint)."""
    nv, k3 = M.shape[0], J.shape[0]
    T, t = task if task is not None else (np.eye(n_base, nv), np.zeros(n_base))
    actuated = np.arange(n_base, nv) if actuated is None else np.asarray(actuated)
    na = actuated.size
    S = np.eye(nv)[:, actuated]
    # Equalities A z = b, z = (qdd, tau, lambda).
    A = np.block(
        [
            [M, -S, -J.T],
            [J, np.zeros((k3, na)), np.zeros((k3, k3))],
            [T, np.zeros((T.shape[0], na + k3))],
        ]
    )
    b = np.r_[-h, -drift, t]
    G = np.hstack([np.zeros((D.shape[0], nv + na)), D])
    sl_t, sl_l = slice(nv, nv + na), slice(nv + na, None)
    z0 = np.linalg.lstsq(A, b, rcond=None)[0]

    def run(obj, grad, A_eq, b_eq, z_init):
        cons = [
            {"type": "eq", "fun": lambda z: A_eq @ z - b_eq, "jac": lambda z: A_eq},
            {"type": "ineq", "fun": lambda z: G @ z, "jac": lambda z: G},
        ]
        res = minimize(obj, z_init, jac=grad, constraints=cons, method="SLSQP", options={"maxiter": 500, "ftol": 1e-14})
        return res.x

    def polish(H, A_eq, b_eq, z):
        """KKT of min 1/2 z^T H z s.t. A_eq z = b_eq and the active rows of G z >= 0."""
        g = G @ z
        active = g <= 1e-6 * max(1.0, np.max(np.abs(z[sl_l])))
        Aa = np.vstack([A_eq, G[active]])
        ba = np.r_[b_eq, np.zeros(int(active.sum()))]
        n = z.size
        K = np.block([[H, -Aa.T], [Aa, np.zeros((Aa.shape[0], Aa.shape[0]))]])
        sol = np.linalg.lstsq(K, np.r_[np.zeros(n), ba], rcond=None)[0]
        z_exact, mult = sol[:n], sol[n:]
        assert np.all(G @ z_exact >= -1e-9 * max(1.0, np.max(np.abs(z_exact)))), "polished point leaves a cone"
        return z_exact, mult[A_eq.shape[0] :]

    H1 = np.zeros((A.shape[1],) * 2)
    H1[sl_t, sl_t] = np.eye(na)
    z1 = run(lambda z: z[sl_t] @ z[sl_t], lambda z: 2 * H1 @ z, A, b, z0)
    z1, mult1 = polish(H1, A, b, z1)
    assert np.all(mult1 >= -1e-6 * max(1.0, np.max(np.abs(z1)))), "a negative multiplier: wrong active set"
    # Second stage: tau fixed at its unique optimum, the least forces.
    A2 = np.vstack([A, np.hstack([np.zeros((na, nv)), np.eye(na), np.zeros((na, k3))])])
    b2 = np.r_[b, z1[sl_t]]
    H2 = np.zeros_like(H1)
    H2[sl_l, sl_l] = np.eye(k3)
    z2 = run(lambda z: z[sl_l] @ z[sl_l], lambda z: 2 * H2 @ z, A2, b2, z1)
    z2, _ = polish(H2, A2, b2, z2)
    return z2[:nv], z2[sl_t], z2[sl_l].reshape(-1, 3)


def check_against_oracle(st, q, mu, facets, tau_ff_base=None, wrenches=None):
    tau_ff_base = np.zeros(6) if tau_ff_base is None else tau_ff_base
    f_ext, pin_fext = st.fext(q, wrenches or {})
    tau_ff = np.r_[tau_ff_base, np.zeros(st.tree.n_joints)]
    ours = vs.whole_body.least_effort(
        st.solver,
        q,
        np.zeros(st.tree.nv),
        task={None: BASE_STILL},
        supports=st.supports(mu, facets),
        f_ext=f_ext,
        tau_ff=tau_ff,
    )
    M, h, J, drift = st.pieces(q, tau_ff_base, pin_fext)
    D = np.kron(np.eye(len(st.points)), cone_rows([0, 0, 1], mu, facets))
    qdd, tau, lam = oracle(M, h, J, drift, D)
    assert_rel(ours.tau[:6], np.zeros(6), "base rows of tau")
    assert_rel(st.pin_v(ours.tau), np.r_[np.zeros(6), tau], "tau")
    assert_rel(ours.contact_force, lam, "contact forces")
    assert_rel(st.pin_v(ours.qdd), qdd, "qdd")
    assert abs(ours.effort - tau @ tau) <= RTOL * max(1.0, tau @ tau)
    # Our answer replayed in Pinocchio: the dynamics hold, the supports stick, the base is still.
    qp = st.pin_q(q)
    lhs = pin.rnea(st.model, st.data, qp, np.zeros(st.model.nv), st.pin_v(ours.qdd), pin_fext).copy()
    lhs[:6] -= tau_ff_base
    rhs = st.pin_v(ours.tau) + J.T @ ours.contact_force.ravel()
    assert_rel(lhs, rhs, "dynamics residual")
    assert_rel(J @ st.pin_v(ours.qdd) + drift, np.zeros(J.shape[0]), "support accelerations")
    assert np.all(D @ ours.contact_force.ravel() >= -RTOL * np.max(np.abs(ours.contact_force)))
    return ours


SOLO = "solo_description/robots/solo12.urdf"
TALOS = "talos_data/robots/talos_reduced.urdf"


def solo_standing():
    st = Standing(example_robot_urdf(SOLO))
    for foot in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"):
        st.add_point(foot)
    legs = {"FL": (0.1, 0.8, -1.6), "FR": (-0.1, 0.8, -1.6), "HL": (0.1, -0.8, 1.6), "HR": (-0.1, -0.8, 1.6)}
    joints = {f"{leg}_{j}": v for leg, vals in legs.items() for j, v in zip(("HAA", "HFE", "KFE"), vals)}
    q = np.r_[0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0, [joints[n] for n in st.tree.joint_names]]
    return st, q


def talos_standing():
    st = Standing(example_robot_urdf(TALOS))
    for sole in ("left_sole_link", "right_sole_link"):
        for x, y in ((0.1, 0.05), (0.1, -0.05), (-0.1, 0.05), (-0.1, -0.05)):
            st.add_point(sole, (x, y, 0.0))
    half = {"leg_left_3_joint": -0.4, "leg_left_4_joint": 0.8, "leg_left_5_joint": -0.4}
    half.update({k.replace("left", "right"): v for k, v in half.items()})
    half.update({"arm_left_2_joint": 0.3, "arm_right_2_joint": -0.3, "arm_left_4_joint": -0.6})
    q = np.r_[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, [half.get(n, 0.0) for n in st.tree.joint_names]]
    return st, q


@pytest.mark.parametrize("facets", [4, 8])
def test_solo12_standing_and_base_load(facets):
    st, q = solo_standing()
    standing = check_against_oracle(st, q, 0.7, facets)
    assert np.all(standing.contact_force[:, 2] > 0.0)
    # A load on the base: a wrench on it (base axes), through tau_ff's base rows.
    load = check_against_oracle(st, q, 0.7, facets, tau_ff_base=np.array([4.0, -2.0, -10.0, 0.3, 0.5, -0.2]))
    assert not np.allclose(load.tau, standing.tau)


@pytest.mark.parametrize("facets", [4, 8])
def test_talos_standing_and_hand_load(facets):
    st, q = talos_standing()
    check_against_oracle(st, q, 0.7, facets)
    check_against_oracle(st, q, 0.7, facets, wrenches={"arm_left_7_joint": np.array([0.0, 0.0, -30.0, 0.0, 0.0, 0.0])})


def test_solo12_centre_of_mass_task():
    """The centre of mass accelerated (0.3, -0.2, 0.1) m/s^2 with the base's orientation still."""
    st, q = solo_standing()
    c_ddot = np.array([0.3, -0.2, 0.1])
    task = {vs.whole_body.COM: (np.eye(6, 3), c_ddot - GRAVITY), None: (np.eye(6)[:, 3:], np.zeros(3))}
    supports = st.supports(0.7, 8)
    ours = vs.whole_body.least_effort(st.solver, q, np.zeros(st.tree.nv), task=task, supports=supports)
    _, pin_fext = st.fext(q, {})
    M, h, J, drift = st.pieces(q, np.zeros(6), pin_fext)
    Jcom = pin.jacobianCenterOfMass(st.model, st.data, st.pin_q(q))
    T = np.vstack([Jcom, np.eye(6, st.model.nv, 3)[:3]])
    D = np.kron(np.eye(len(st.points)), cone_rows([0, 0, 1], 0.7, 8))
    qdd, tau, lam = oracle(M, h, J, drift, D, task=(T, np.r_[c_ddot, np.zeros(3)]))
    assert_rel(st.pin_v(ours.tau), np.r_[np.zeros(6), tau], "tau")
    assert_rel(ours.contact_force, lam, "contact forces")
    assert_rel(st.pin_v(ours.qdd), qdd, "qdd")
    pin.centerOfMass(st.model, st.data, st.pin_q(q), np.zeros(st.model.nv), st.pin_v(ours.qdd))
    assert_rel(st.data.acom[0], c_ddot, "centre-of-mass acceleration")


def test_solo12_with_unactuated_hips():
    """The four HAA joints without motors (the mask): their torque is zero, the rest as the QP."""
    st, q = solo_standing()
    actuated = np.array(["HAA" not in n for n in st.tree.joint_names])
    ours = vs.whole_body.least_effort(
        st.solver, q, np.zeros(st.tree.nv), task={None: BASE_STILL}, supports=st.supports(), actuated=actuated
    )
    _, pin_fext = st.fext(q, {})
    M, h, J, drift = st.pieces(q, np.zeros(6), pin_fext)
    D = np.kron(np.eye(len(st.points)), cone_rows([0, 0, 1], 0.7, 4))
    motors = st.v_index[6:][actuated]  # Pinocchio's velocity indices of the actuated joints
    qdd, tau, lam = oracle(M, h, J, drift, D, actuated=np.sort(motors))
    expected = np.zeros(st.model.nv)
    expected[np.sort(motors)] = tau
    assert np.all(ours.tau[6:][~actuated] == 0.0)
    assert_rel(st.pin_v(ours.tau), expected, "tau")
    assert_rel(ours.contact_force, lam, "contact forces")
    assert_rel(st.pin_v(ours.qdd), qdd, "qdd")


def test_not_realizable_solo12_on_one_foot():
    st, q = solo_standing()
    task = {None: BASE_STILL}
    for foot in ("FR_FOOT", "HL_FOOT", "HR_FOOT"):  # the other feet held still in the air (tasks, not supports)
        fid = st.model.getFrameId(foot)
        f = st.model.frames[fid]
        task[st.child[st.model.names[f.parentJoint]]] = (np.eye(6, 3), -GRAVITY, f.placement.translation)
    one = st.supports()[:1]
    with pytest.raises(vs.SolverError, match="not realizable"):
        vs.whole_body.least_effort(st.solver, q, np.zeros(st.tree.nv), task=task, supports=one)
    # Four feet, cones too narrow for a sideways push on the base.
    with pytest.raises(vs.SolverError, match="friction cones"):
        vs.whole_body.least_effort(
            st.solver,
            q,
            np.zeros(st.tree.nv),
            task={None: BASE_STILL},
            supports=st.supports(mu=0.05),
            tau_ff=np.r_[30.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.zeros(12)],
        )


def test_fixed_base_arm_matches_plain_solve():
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    rng = np.random.default_rng(3)
    q, qd = rng.uniform(-1, 1, 7), rng.uniform(-0.5, 0.5, 7)
    # 6 rows on the tool and 1 on the forearm: qdd is determined, so is the motors' torque.
    alpha2 = np.array([[0.0], [0.0], [0.0], [0.3], [0.4], [0.5]])
    constraints = {chain.n_segments - 1: (np.eye(6), rng.normal(size=6)), 3: (alpha2, np.array([0.7]))}
    plain = solver.solve(q, qd, constraints=constraints)
    ours = vs.whole_body.least_effort(solver, q, qd, task=constraints)
    assert_rel(ours.tau, plain.tau_command, "tau")
    assert_rel(ours.qdd, plain.qdd, "qdd")
