"""Checks of Chain.from_kdl / Chain.to_kdl against Debian's PyKDL (python3-pykdl).

Needs only numpy, PyKDL and vereshchagin, because Debian's PyKDL imports only in the system
interpreter /usr/bin/python3: tests/oracles/test_pykdl_interop.py runs this file there (or calls
``run_all`` in-process when its own interpreter has PyKDL). Oracle: KDL's own solvers
(``ChainDynParam``, ``ChainIdSolver_RNE``, ``ChainFkSolverPos_recursive``) on PyKDL chains.

Usage: ``python pykdl_checks.py PANDA_URDF UR5_URDF``; prints the largest relative differences and
exits non-zero on the first failed check.
"""

from __future__ import annotations

import sys

import numpy as np
import PyKDL as kdl

import vereshchagin as vs

RTOL = 1e-12
G = np.array([0.0, 0.0, -9.81])


def rel_err(actual, expected) -> float:
    """||a - e|| / max(||e||, 1), after checking the shapes agree."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, f"shape {actual.shape} != {expected.shape}"
    return float(np.linalg.norm(actual - expected) / max(np.linalg.norm(expected), 1.0))


class Report:
    """Collects the largest relative difference per quantity and fails above the tolerance."""

    def __init__(self):
        self.worst: dict[str, float] = {}

    def check(self, what, actual, expected, rtol=RTOL):
        err = rel_err(actual, expected)
        self.worst[what] = max(self.worst.get(what, 0.0), err)
        assert err <= rtol, f"{what}: relative error {err:.3e} > {rtol:.0e}\n{actual}\n{expected}"


# ------------------------------------------------------------------------------------------------
# PyKDL side
# ------------------------------------------------------------------------------------------------
def jnt_array(x):
    a = kdl.JntArray(len(x))
    for k, v in enumerate(x):
        a[k] = float(v)
    return a


def to_numpy(a, n):
    return np.array([a[k] for k in range(n)])


def kdl_dynamics(chain, q, qd, qdd, f_tip):
    """KDL's own M, g, C qd, RNE torques (f_tip: wrenches in each segment's tip frame) and the
    tip frames (4x4) of every segment."""
    n, ns = chain.getNrOfJoints(), chain.getNrOfSegments()
    dyn = kdl.ChainDynParam(chain, kdl.Vector(*G))
    H = kdl.JntSpaceInertiaMatrix(n)
    g, c, tau = kdl.JntArray(n), kdl.JntArray(n), kdl.JntArray(n)
    assert dyn.JntToMass(jnt_array(q), H) == 0
    assert dyn.JntToGravity(jnt_array(q), g) == 0
    assert dyn.JntToCoriolis(jnt_array(q), jnt_array(qd), c) == 0
    wrenches = [kdl.Wrench(kdl.Vector(*w[:3]), kdl.Vector(*w[3:])) for w in f_tip]
    rne = kdl.ChainIdSolver_RNE(chain, kdl.Vector(*G))
    assert rne.CartToJnt(jnt_array(q), jnt_array(qd), jnt_array(qdd), wrenches, tau) == 0
    fk = kdl.ChainFkSolverPos_recursive(chain)
    frames = []
    for i in range(ns):
        f = kdl.Frame()
        assert fk.JntToCart(jnt_array(q), f, i + 1) == 0
        frames.append(np.array([[f.M[r, k] for k in range(3)] + [f.p[r]] for r in range(3)] + [[0, 0, 0, 1.0]]))
    return {
        "M": np.array([[H[r, k] for k in range(n)] for r in range(n)]),
        "g": to_numpy(g, n),
        "c": to_numpy(c, n),
        "tau": to_numpy(tau, n),
        "frames": np.array(frames).reshape(ns, 4, 4),
    }


def random_kdl_rotation(rng):
    return kdl.Rotation.RPY(*rng.uniform(-np.pi, np.pi, 3))


def random_body(rng):
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    a, b, c = rng.uniform(0.02, 0.15, 3)  # second moments: principal moments of a rigid body
    I = R @ np.diag([b + c, a + c, a + b]) @ R.T
    Ic = kdl.RotationalInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
    return kdl.RigidBodyInertia(rng.uniform(0.2, 4.0), kdl.Vector(*rng.uniform(-0.3, 0.3, 3)), Ic)


def native_kdl_chain(rng):
    """A PyKDL chain with every joint type, joint origins, rotor inertias and fixed segments in
    the middle and at the end, built with PyKDL's API only."""
    chain = kdl.Chain()
    kinds = ["RotX", "TransY", "RotAxis", "Fixed", "RotZ", "TransAxis", "RotY", "TransX", "TransZ", "Fixed"]
    for i, kind in enumerate(kinds):
        rotor = 0.0 if kind == "Fixed" else float(rng.uniform(0.0, 0.3))
        if kind in ("RotAxis", "TransAxis"):
            axis, origin = kdl.Vector(*rng.normal(size=3)), kdl.Vector(*rng.uniform(-0.2, 0.2, 3))
            joint = kdl.Joint(f"j{i}", origin, axis, getattr(kdl.Joint, kind), 1.0, 0.0, rotor)
        else:
            joint = kdl.Joint(f"j{i}", getattr(kdl.Joint, kind), 1.0, 0.0, rotor)
        tip = kdl.Frame(random_kdl_rotation(rng), kdl.Vector(*rng.uniform(-0.4, 0.4, 3)))
        chain.addSegment(kdl.Segment(f"s{i}", joint, tip, random_body(rng)))
    return chain


def kuka_lwr4_kdl():
    """KDL's own KUKA LWR 4 test model (orocos_kdl/tests/solvertest.cpp, KDL 1.5.1), built with
    PyKDL's API: the identified parameters of Jubien, Gautier and Janot (IFAC 2014), modified DH
    frames, 2 kg per link, rotor inertias. Several link inertias are not positive semi-definite."""
    h = 1.5707963  # the published model's pi / 2
    # alpha, d, rotor, (cx, cy, cz), (ixx, iyy, izz, iyz) in each link's DH frame
    links = [
        (h, 0.0, 3.19, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0115343, 0.0)),
        (-h, 0.4, 3.05, (0.0, -0.3120511, -0.0038871), (-0.5471572, -0.0000302, -0.5423253, 0.0018828)),
        (-h, 0.0, 1.98, (0.0, -0.0015515, 0.0), (0.0063507, 0.0, 0.0107804, -0.0005147)),
        (h, 0.39, 2.05, (0.0, 0.5216809, 0.0), (-1.0436952, 0.0, -1.0392780, 0.0005324)),
        (h, 0.0, 0.787, (0.0, 0.0119891, 0.0), (0.0036654, 0.0, 0.0060429, 0.0004226)),
        (-h, 0.0, 0.391, (0.0, 0.0080787, 0.0), (0.0010431, 0.0, 0.0036376, 0.0000101)),
        (0.0, 0.0, 0.394, (0.0, 0.0, 0.0), (0.000001, 0.0, 0.0001203, 0.0)),
    ]
    chain = kdl.Chain()
    for k, (alpha, d, rotor, com, (ixx, iyy, izz, iyz)) in enumerate(links):
        frame = kdl.Frame.DH_Craig1989(0.0, alpha, d, 0.0) if k < 6 else kdl.Frame()
        in_dh = kdl.RigidBodyInertia(2.0, kdl.Vector(*com), kdl.RotationalInertia(ixx, iyy, izz, 0.0, 0.0, iyz))
        joint = kdl.Joint(f"lwr_j{k + 1}", kdl.Joint.RotZ, 1.0, 0.0, rotor)
        chain.addSegment(kdl.Segment(f"lwr_link{k + 1}", joint, frame, frame.Inverse() * in_dh))
    return chain


# ------------------------------------------------------------------------------------------------
# Checks
# ------------------------------------------------------------------------------------------------
def check_kdl_lwr(report, rng):
    """KDL's LWR 4 comes through from_kdl as KDL takes it (the physical check on request), and
    solves like KDL: companions against KDL's solvers, forward dynamics against KDL's M, C, g."""
    lwr = kuka_lwr4_kdl()
    chain = vs.Chain.from_kdl(lwr)  # default: accepted, as by KDL and the C++ drop-in
    try:
        vs.Chain.from_kdl(lwr, inertia_check="physical")
    except vs.SolverError as err:
        assert "joint_space" in str(err), err
    else:
        raise AssertionError("inertia_check='physical' accepted the LWR's non-rigid-body inertias")
    compare_with_kdl(report, chain, lwr, rng, "KDL's LWR 4")
    solver = vs.Solver(chain, gravity=G, inertia_check="joint_space")
    n = chain.n_joints
    for _ in range(4):
        q, qd, tau = rng.uniform(-1.5, 1.5, n), rng.uniform(-2, 2, n), rng.normal(size=n) * 10.0
        ref = kdl_dynamics(lwr, q, qd, np.zeros(n), np.zeros((n, 6)))
        expected = np.linalg.solve(ref["M"], tau - ref["c"] - ref["g"])
        report.check(
            "KDL's LWR 4: Solver qdd vs KDL M^-1 (tau - C qd - g)", solver.solve(q, qd, tau_ff=tau).qdd, expected, 1e-10
        )


def compare_with_kdl(report, chain, kdl_chain, rng, tag):
    """Our companions on ``chain`` against KDL's solvers on ``kdl_chain`` (the same robot)."""
    n, ns = chain.n_joints, chain.n_segments
    assert (kdl_chain.getNrOfJoints(), kdl_chain.getNrOfSegments()) == (n, ns)
    for _ in range(4):
        q, qd, qdd = rng.uniform(-1.5, 1.5, n), rng.uniform(-2, 2, n), rng.normal(size=n)
        f_tip = rng.uniform(-10, 10, (ns, 6))
        ref = kdl_dynamics(kdl_chain, q, qd, qdd, f_tip)
        R = ref["frames"][:, :3, :3]
        f_base = np.concatenate(
            [np.einsum("sij,sj->si", R, f_tip[:, :3]), np.einsum("sij,sj->si", R, f_tip[:, 3:])], axis=1
        )
        report.check(f"{tag}: mass_matrix vs KDL ChainDynParam", chain.mass_matrix(q), ref["M"])
        report.check(f"{tag}: gravity_torques vs KDL", chain.gravity_torques(q), ref["g"])
        report.check(f"{tag}: coriolis_torques vs KDL", chain.coriolis_torques(q, qd), ref["c"])
        report.check(
            f"{tag}: inverse_dynamics(f_ext) vs KDL RNE", chain.inverse_dynamics(q, qd, qdd, f_base), ref["tau"]
        )
        report.check(f"{tag}: fk_all vs KDL FK", chain.fk_all(q), ref["frames"])


def solve_outputs(chain, q, qd, alpha, beta, f_ext, tau):
    res = vs.Solver(chain, gravity=G).solve(q, qd, alpha, beta, f_ext=f_ext, tau_ff=tau)
    return np.concatenate([res.qdd, res.tau_command, res.nu, res.link_acc.ravel()])


def check_round_trip(report, chain, rng, tag):
    """from_kdl(to_kdl(chain)) describes the same chain and solves the same."""
    back = vs.Chain.from_kdl(chain.to_kdl())
    assert list(back.segment_names) == list(chain.segment_names), tag
    assert list(back.joint_names) == list(chain.joint_names), tag
    for i in range(chain.n_segments):
        a, b = chain.segment_spec(i), back.segment_spec(i)
        assert a["joint_type"] == b["joint_type"] and a["name"] == b["name"], (tag, i)
        for key in ("tip", "mass", "com", "inertia", "rotor_inertia", "origin"):
            report.check(f"{tag}: segment_spec {key} round trip", b[key], a[key])
    n = chain.n_joints
    for m in (0, 3):
        q, qd, tau = rng.uniform(-1.5, 1.5, n), rng.uniform(-2, 2, n), rng.normal(size=n)
        alpha = rng.normal(size=(6, m))
        alpha, beta = (alpha / np.linalg.norm(alpha, axis=0), rng.normal(size=m)) if m else (None, None)
        f_ext = rng.uniform(-5, 5, (chain.n_segments, 6))
        report.check(
            f"{tag}: solve after round trip",
            solve_outputs(back, q, qd, alpha, beta, f_ext, tau),
            solve_outputs(chain, q, qd, alpha, beta, f_ext, tau),
        )


def check_rejections():
    """Joints with a KDL scale or offset and non-chains fail with SolverError."""
    for joint in (
        kdl.Joint("off", kdl.Joint.RotZ, 1.0, 0.1),
        kdl.Joint("scaled", kdl.Joint.TransX, 2.0),
        kdl.Joint("axis_off", kdl.Vector(0, 0, 0.1), kdl.Vector(0, 1, 0), kdl.Joint.RotAxis, 1.0, 0.2),
    ):
        chain = kdl.Chain()
        chain.addSegment(kdl.Segment("s", joint, kdl.Frame(), kdl.RigidBodyInertia(1.0)))
        try:
            vs.Chain.from_kdl(chain)
        except vs.SolverError as err:
            assert "scale or offset" in str(err), err
        else:
            raise AssertionError(f"joint {joint} with a scale or offset was accepted")
    try:
        vs.Chain.from_kdl("not a chain")
    except vs.SolverError as err:
        assert "must be a PyKDL.Chain" in str(err), err
    else:
        raise AssertionError("a string was accepted as a PyKDL chain")


def run_all(panda_urdf, ur5_urdf):
    """Every check; returns the largest relative difference per quantity."""
    report = Report()
    rng = np.random.default_rng(2024)
    native = native_kdl_chain(rng)
    ours = vs.Chain.from_kdl(native)
    assert list(ours.segment_names) == [f"s{i}" for i in range(10)]
    assert list(ours.joint_names) == [f"j{i}" for i in range(10) if i not in (3, 9)]
    compare_with_kdl(report, ours, native, rng, "native PyKDL chain")
    check_round_trip(report, ours, rng, "native PyKDL chain")
    robots = {
        "gen3+gripper": vs.robots.gen3(True),
        "panda": vs.Chain.from_urdf(panda_urdf, tip="panda_hand"),
        "ur5": vs.Chain.from_urdf(ur5_urdf, tip="tool0"),
    }
    for tag, chain in robots.items():
        chain.rotor_inertia = rng.uniform(0.0, 0.4, chain.n_joints)
        compare_with_kdl(report, chain, chain.to_kdl(), rng, tag)
        check_round_trip(report, chain, rng, tag)
    check_kdl_lwr(report, rng)
    check_rejections()
    return report.worst


if __name__ == "__main__":
    worst = run_all(sys.argv[1], sys.argv[2])
    for what, err in sorted(worst.items()):
        print(f"{err:.2e}  {what}")
    print("PYKDL CHECKS PASSED")
