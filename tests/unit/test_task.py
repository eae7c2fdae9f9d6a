"""vereshchagin.task: directions, beta from a classical acceleration, pose and twist errors.

Oracles: Pinocchio's classical frame acceleration (``getFrameClassicalAcceleration``,
LOCAL_WORLD_ALIGNED) of the tip link after our ``qdd``; scipy's Rotation for rotation vectors;
hand-written numpy for directions and small examples.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

import vereshchagin as vs
from support.urdf_robots import BUILDERS, G, LWA, assert_rel
from vereshchagin.task import Task, beta_for, directions, pose_error, twist_error


# ------------------------------------------------------------------------------------------------
# Robots (the models of tests/oracles/test_urdf_pinocchio.py)
# ------------------------------------------------------------------------------------------------
class Robot:
    """A robot of support.urdf_robots (the Gen3 with its gripper, or the Panda) with its solver."""

    def __init__(self, name):
        r = BUILDERS["gen3_gripper" if name == "gen3" else "panda"]()
        self.chain, self.model, self.tip = r.chain, r.model, r.tip
        self.pin_q, self.random_state = r.pin_q, r.random_state
        self.model.gravity = pin.Motion(np.r_[G, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        self.fid = self.model.getFrameId(self.tip)
        self.solver = vs.Solver(self.chain, gravity=G)

    def classical(self, q, qd, qdd):
        """Pinocchio: [classical acceleration of the tip origin; angular acceleration], base axes."""
        pq = self.pin_q(q)
        pin.forwardKinematics(self.model, self.data, pq, qd, qdd)
        pin.updateFramePlacements(self.model, self.data)
        acc = pin.getFrameClassicalAcceleration(self.model, self.data, self.fid, LWA).vector
        # oracle self-check: classical = spatial + [omega x v; 0]
        v = pin.getFrameVelocity(self.model, self.data, self.fid, LWA)
        spatial = pin.getFrameAcceleration(self.model, self.data, self.fid, LWA).vector
        np.testing.assert_allclose(acc, spatial + np.r_[np.cross(v.angular, v.linear), 0, 0, 0], atol=1e-9)
        return acc, v.vector


def random_rotation(rng):
    return Rotation.random(random_state=rng).as_matrix()


TASKS = {
    "z": lambda rng: directions(["z"]),
    "x_ry": lambda rng: directions(["x", "ry"]),
    "position": lambda rng: directions(["x", "y", "z"]),
    "full": lambda rng: directions(["x", "y", "z", "rx", "ry", "rz"]),
    "rotated": lambda rng: directions(["y", "rz", "x"], random_rotation(rng)),
    "vectors": lambda rng: directions([rng.normal(size=6), [0, 0, 2.0, 0, 0.5, 0]]),
}


# ------------------------------------------------------------------------------------------------
# beta_for: the requested classical acceleration is achieved
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("task", sorted(TASKS))
@pytest.mark.parametrize("name", ["gen3", "panda"])
def test_constrained_directions_get_the_classical_acceleration(name, task):
    r = Robot(name)
    rng = np.random.default_rng([21, len(task), len(name)])
    done = 0
    for _ in range(40):
        alpha = TASKS[task](rng)
        q, qd = r.random_state(rng)
        twist = r.chain.twist(q, qd)
        if np.linalg.norm(np.cross(twist[3:], twist[:3])) < 0.05:
            continue  # make the velocity term matter
        a_des = rng.normal(size=6) * 2.0
        tau = rng.normal(size=r.chain.n_joints)
        res = r.solver.solve(q, qd, alpha, beta_for(alpha, a_des, twist, G), tau_ff=tau)
        if res.constraint_rank < alpha.shape[1]:
            continue
        acc, v_pin = r.classical(q, qd, res.qdd)
        assert_rel(alpha.T @ acc, alpha.T @ a_des, "alpha^T classical acceleration")
        if alpha.shape[1] == 6:
            assert_rel(acc, a_des, "full classical acceleration")
        # guard: taking a_desired as the spatial acceleration (no omega x v, no gravity) misses
        wrong = r.solver.solve(q, qd, alpha, alpha.T @ a_des, tau_ff=tau)
        acc_wrong, _ = r.classical(q, qd, wrong.qdd)
        assert np.linalg.norm(alpha.T @ (acc_wrong - a_des)) > 1e-3
        done += 1
        if done == 5:
            break
    assert done == 5


@pytest.mark.parametrize("task", ["z", "position", "full", "rotated"])
@pytest.mark.parametrize("name", ["gen3", "panda"])
def test_held_directions_stay_still_under_gravity(name, task):
    r = Robot(name)
    rng = np.random.default_rng([22, len(task), len(name)])
    alpha = TASKS[task](rng)
    for k in range(4):
        q, qd = r.random_state(rng)
        if k == 0:
            qd = np.zeros_like(qd)  # at rest: the held directions do not move at all
        twist = r.chain.twist(q, qd)
        res = r.solver.solve(q, qd, alpha, beta_for(alpha, np.zeros(6), twist, G))
        assert res.constraint_rank == alpha.shape[1]
        acc, _ = r.classical(q, qd, res.qdd)
        assert np.linalg.norm(alpha.T @ acc) < 1e-8
        # guard: without the gravity term the held directions sag (when gravity acts along them)
        sag = r.solver.solve(q, qd, alpha, beta_for(alpha, np.zeros(6), twist, gravity=[0, 0, 0]))
        acc_sag, _ = r.classical(q, qd, sag.qdd)
        if np.linalg.norm(alpha[:3].T @ G) > 1.0:
            assert np.linalg.norm(alpha.T @ acc_sag) > 0.5


def test_task_class_solves_for_the_classical_acceleration():
    r = Robot("gen3")
    rng = np.random.default_rng(23)
    R = random_rotation(rng)
    task = Task(["x", "z", "ry"], R)
    np.testing.assert_allclose(
        task.alpha, np.c_[np.r_[R[:, 0], 0, 0, 0], np.r_[R[:, 2], 0, 0, 0], np.r_[0, 0, 0, R[:, 1]]], atol=1e-15
    )
    q, qd = r.random_state(rng)
    a_des = rng.normal(size=6)
    res = task.solve(r.solver, r.chain, q, qd, a_des, tau_ff=np.ones(7))
    acc, _ = r.classical(q, qd, res.qdd)
    assert_rel(task.alpha.T @ acc, task.alpha.T @ a_des, "Task.solve")


def test_solve_a_desired_reaches_the_classical_acceleration():
    """solve(..., a_desired=) against Pinocchio's classical tip acceleration, with friction and
    f_ext, in solve_batch row by row, and its argument errors."""
    r = Robot("gen3")
    rng = np.random.default_rng(24)
    alpha = np.c_[np.eye(6)[:, :3], [0, 0, 0, 0.6, 0.0, 0.8]]
    rows = []
    for k in range(6):
        q, qd = r.random_state(rng)
        a_des = rng.normal(size=6)
        kw = dict(tau_ff=rng.normal(size=7), f_ext={r.solver.n_segments - 2: rng.normal(size=6)})
        if k % 2:
            kw["friction"] = vs.Friction(static=np.full(7, 0.5))
        res = r.solver.solve(q, qd, alpha, a_desired=a_des, **kw)
        acc, _ = r.classical(q, qd, res.qdd)
        assert_rel(alpha.T @ acc, alpha.T @ a_des, "solve(a_desired=)")
        rows.append((q, qd, a_des, res.qdd))
    q, qd, a, qdd = (np.array(x) for x in zip(*rows))
    batch = r.solver.solve_batch(q, qd, alpha, a_desired=a)
    for b in range(len(rows)):
        np.testing.assert_array_equal(batch.qdd[b], r.solver.solve(q[b], qd[b], alpha, a_desired=a[b]).qdd)
    with pytest.raises(vs.SolverError, match="a_desired .*replaces beta"):
        r.solver.solve(q[0], qd[0], alpha, np.zeros(4), a_desired=a[0])
    with pytest.raises(vs.SolverError, match="a_desired given without alpha"):
        r.solver.solve(q[0], qd[0], a_desired=a[0])
    with pytest.raises(vs.SolverError, match=r"a_desired must have shape \(6,\)"):
        r.solver.solve(q[0], qd[0], alpha, a_desired=a[0, :3])
    with pytest.raises(vs.SolverError, match="a_desired must be finite"):
        r.solver.solve(q[0], qd[0], alpha, a_desired=np.r_[a[0, :5], np.inf])


def test_beta_for_by_hand():
    # tip at velocity v = (0, 1, 0) turning with omega = (0, 0, 2): omega x v = (-2, 0, 0)
    twist = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 2.0])
    a = np.array([0.5, -1.0, 0.25, 0.1, 0.2, 0.3])
    alpha = np.eye(6)
    expected = np.array([0.5 + 2.0, -1.0, 0.25 + 9.81, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(beta_for(alpha, a, twist), expected, rtol=1e-15)
    np.testing.assert_allclose(
        beta_for(alpha, a, twist, gravity=[1.0, 0.0, 0.0]), expected - [1.0, 0, 9.81, 0, 0, 0], rtol=1e-15
    )
    # a single (6,) direction, tilted 45 degrees in the x-z plane
    d = np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0]) / np.sqrt(2.0)
    np.testing.assert_allclose(beta_for(d, a, twist), [(2.5 + 10.06) / np.sqrt(2.0)], rtol=1e-15)
    # holding still at rest needs +9.81 along z, not 0
    np.testing.assert_allclose(beta_for(directions("z"), np.zeros(6), np.zeros(6)), [9.81], rtol=1e-15)
    with pytest.raises(ValueError):
        beta_for(np.eye(5), a, twist)
    with pytest.raises(ValueError):
        beta_for(alpha, a[:3], twist)


# ------------------------------------------------------------------------------------------------
# directions
# ------------------------------------------------------------------------------------------------
def test_directions_base_frame():
    np.testing.assert_array_equal(directions(["x", "y", "z", "rx", "ry", "rz"]), np.eye(6))
    np.testing.assert_array_equal(directions(["rz", "x"]), np.eye(6)[:, [5, 0]])
    np.testing.assert_array_equal(directions("z"), np.eye(6)[:, [2]])
    assert directions([]).shape == (6, 0)
    v = directions([[3.0, 0, 4.0, 0, 0, 0], [0, 0, 0, 0, -2.0, 0]])
    np.testing.assert_allclose(v, np.array([[0.6, 0, 0.8, 0, 0, 0], [0, 0, 0, 0, -1.0, 0]]).T, rtol=1e-15)


@pytest.mark.parametrize("seed", range(5))
def test_directions_in_a_rotated_frame(seed):
    rng = np.random.default_rng(seed)
    R = random_rotation(rng)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, rng.normal(size=3)  # the translation does not matter
    for frame in (R, T):
        a = directions(["x", "y", "z", "rx", "ry", "rz"], frame)
        for k in range(3):
            np.testing.assert_allclose(a[:, k], np.r_[R[:, k], 0, 0, 0], atol=1e-15)
            np.testing.assert_allclose(a[:, 3 + k], np.r_[0, 0, 0, R[:, k]], atol=1e-15)
        w = rng.normal(size=6)
        np.testing.assert_allclose(
            directions([w], frame)[:, 0], np.r_[R @ w[:3], R @ w[3:]] / np.linalg.norm(w), atol=1e-15
        )
    # a direction along the frame's z axis, 90 degrees about base x: base -y
    Rx = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    np.testing.assert_allclose(directions("z", Rx)[:, 0], [0, -1.0, 0, 0, 0, 0], atol=1e-16)


@pytest.mark.parametrize("bad", [["w"], ["x", "q"], [np.zeros(6)], [[1.0, 2.0, 3.0]], [[np.nan] * 6]])
def test_directions_rejects(bad):
    with pytest.raises(ValueError):
        directions(bad)


@pytest.mark.parametrize("frame", [np.eye(2), np.diag([1.0, 1.0, -1.0]), 2.0 * np.eye(3), np.full((4, 4), np.nan)])
def test_directions_rejects_bad_frames(frame):
    with pytest.raises(ValueError):
        directions(["x"], frame)


# ------------------------------------------------------------------------------------------------
# pose_error / twist_error
# ------------------------------------------------------------------------------------------------
def _T(R, p):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


@pytest.mark.parametrize("seed", range(20))
def test_pose_error_matches_scipy(seed):
    rng = np.random.default_rng(seed)
    Tc = _T(random_rotation(rng), rng.normal(size=3))
    Td = _T(random_rotation(rng), rng.normal(size=3))
    e = pose_error(Tc, Td)
    np.testing.assert_allclose(e[:3], Td[:3, 3] - Tc[:3, 3], rtol=1e-15, atol=1e-15)
    expected = Rotation.from_matrix(Td[:3, :3] @ Tc[:3, :3].T).as_rotvec()
    np.testing.assert_allclose(e[3:], expected, atol=1e-12)
    assert np.linalg.norm(e[3:]) <= np.pi + 1e-15
    # the error rotation turns the current orientation into the desired one (base axes)
    np.testing.assert_allclose(Rotation.from_rotvec(e[3:]).as_matrix() @ Tc[:3, :3], Td[:3, :3], atol=1e-12)


@pytest.mark.parametrize(
    "angle", [0.0, 1e-14, 1e-9, 1e-6, 1e-3, 0.5, 2.0, np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9, np.pi - 1e-12, np.pi]
)
@pytest.mark.parametrize("seed", range(4))
def test_pose_error_small_and_near_pi(angle, seed):
    rng = np.random.default_rng([seed, 31])
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    Rc = random_rotation(rng)
    Rd = Rotation.from_rotvec(axis * angle).as_matrix() @ Rc
    e = pose_error(_T(Rc, np.zeros(3)), _T(Rd, np.zeros(3)))[3:]
    np.testing.assert_array_equal(pose_error(_T(Rc, np.zeros(3)), _T(Rd, np.zeros(3)))[:3], np.zeros(3))
    scipy_vec = Rotation.from_matrix(Rd @ Rc.T).as_rotvec()
    if angle == np.pi:  # axis sign is arbitrary at exactly pi
        assert min(np.linalg.norm(e - axis * np.pi), np.linalg.norm(e + axis * np.pi)) < 1e-7
        assert min(np.linalg.norm(e - scipy_vec), np.linalg.norm(e + scipy_vec)) < 1e-7
    else:
        # matrix entries carry ~1e-16 rounding, which limits the axis near pi to ~1e-8
        tol = 1e-7 if angle > 3.0 else 1e-12
        np.testing.assert_allclose(e, axis * angle, atol=tol)
        np.testing.assert_allclose(e, scipy_vec, atol=tol)
    assert np.linalg.norm(e) == pytest.approx(angle, abs=1e-12)


def test_pose_error_by_hand():
    Tc = _T(np.eye(3), [1.0, 2.0, 3.0])
    Rz = np.array([[0.0, -1.0, 0], [1.0, 0.0, 0], [0, 0, 1.0]])  # +90 degrees about z
    Td = _T(Rz, [1.5, 2.0, 2.0])
    np.testing.assert_allclose(pose_error(Tc, Td), [0.5, 0, -1.0, 0, 0, np.pi / 2], atol=1e-15)
    # the rotation error is about base axes: with Rc = Rx(90), Rd = Rz(90) Rx(90) the error is about base z
    Rx = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    np.testing.assert_allclose(
        pose_error(_T(Rx, np.zeros(3)), _T(Rz @ Rx, np.zeros(3)))[3:], [0, 0, np.pi / 2], atol=1e-15
    )
    with pytest.raises(ValueError):
        pose_error(np.eye(3), np.eye(4))


def test_twist_error():
    tc = np.arange(6.0)
    td = np.array([1.0, -1.0, 0.5, 2.0, 0.0, -3.0])
    np.testing.assert_array_equal(twist_error(tc, td), td - tc)
    with pytest.raises(ValueError):
        twist_error(tc[:5], td)
