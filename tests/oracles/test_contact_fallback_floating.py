"""The contact stage's real-time fallback on a floating base, checked with Pinocchio's dynamics.

solo12 (example-robot-data, free-flyer) on its four feet, mu 0.3, pushed sideways on the base hard
enough that the feet cannot all stick: the contact stage needs its complementarity problem (Lemke's
pivoting). Forced to 1 and 3 pivots (``contact_max_pivots``) the solve warns with the documented
fallback (docs "Friction", "Real-time bound", "Contact fallback"); the result is then checked with
nothing of ours but the numbers it returns:

* the equations of motion in Pinocchio, ``rnea(q, qd, qdd) = tau_ff + tau_command + sum J_k^T f_k``
  (``J_k`` the foot points' LOCAL_WORLD_ALIGNED Jacobians), 1e-9 relative;
* nothing penetrates: every foot's normal acceleration (``J qdd + Jdot qd``, Pinocchio's classical
  acceleration), over a time step its end velocity ``v + dt a``, is >= 0 within round-off;
* the forces are admissible: along the normal (no friction in the fallback), pushing (n.f >= 0),
  and they do no positive work on that motion.

The same state with the default bound is solved without a warning, and afterwards the default
again gives that exact answer bit for bit (nothing of the degraded call is kept).
"""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.trees import pin_q_free, pin_v_index, pin_v_scatter
from vereshchagin.robots import example_robot_urdf

UP = np.array([0.0, 0.0, 1.0])
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
GRAVITY = np.array([0.0, 0.0, -9.81])


class Solo:
    """solo12 in both libraries: our Tree and Solver, Pinocchio's model, the state maps."""

    def __init__(self):
        urdf = example_robot_urdf("solo_description/robots/solo12.urdf")
        self.tree = vs.Tree.from_urdf(urdf, base="free")
        self.solver = vs.Solver(self.tree, gravity=GRAVITY)
        self.model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        self.model.gravity = pin.Motion(np.r_[GRAVITY, 0.0, 0.0, 0.0])
        self.data = self.model.createData()
        self.v_index = np.r_[np.arange(6), pin_v_index(self.model, self.tree.joint_names)]
        self.feet = [self.model.getFrameId(f) for f in FEET]

    def standing(self):
        legs = {"FL": (0.1, 0.8, -1.6), "FR": (-0.1, 0.8, -1.6), "HL": (0.1, -0.8, 1.6), "HR": (-0.1, -0.8, 1.6)}
        joints = {f"{leg}_{j}": v for leg, vals in legs.items() for j, v in zip(("HAA", "HFE", "KFE"), vals)}
        return np.r_[0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0, [joints[n] for n in self.tree.joint_names]]

    def pin_q(self, q):
        return pin_q_free(self.model, self.tree.joint_names, q)

    def pin_v(self, v):
        return pin_v_scatter(self.model, self.v_index, v)

    def feet_rows(self, q, qd, qdd):
        """Per foot (Pinocchio's numbers): Jacobian (3, nv), velocity (3,), classical acceleration (3,)."""
        qp, vp, ap = self.pin_q(q), self.pin_v(qd), self.pin_v(qdd)
        pin.computeJointJacobians(self.model, self.data, qp)
        pin.forwardKinematics(self.model, self.data, qp, vp, ap)
        pin.updateFramePlacements(self.model, self.data)
        lwa = pin.LOCAL_WORLD_ALIGNED
        out = []
        for fid in self.feet:
            J = pin.getFrameJacobian(self.model, self.data, fid, lwa)[:3]
            v = pin.getFrameVelocity(self.model, self.data, fid, lwa).linear
            a = pin.getFrameClassicalAcceleration(self.model, self.data, fid, lwa).linear
            out.append((J, v, a))
        return out


def supports(mu=0.3):
    return [vs.Contact(foot, normal=UP, mu=mu, facets=4) for foot in FEET]


def check_fallback(solo, q, qd, tau_ff, res, dt):
    rows = solo.feet_rows(q, qd, res.qdd)
    forces = res.contact_force
    lhs = pin.rnea(solo.model, solo.data, solo.pin_q(q), solo.pin_v(qd), solo.pin_v(res.qdd)).copy()
    rhs = solo.pin_v(tau_ff + res.tau_command) + sum(J.T @ f for (J, _, _), f in zip(rows, forces))
    scale = max(1.0, float(np.max(np.abs(lhs))))
    assert np.max(np.abs(lhs - rhs)) <= 1e-9 * scale, "equations of motion (Pinocchio's rnea)"
    work, work_scale = 0.0, 1.0
    for (J, v, a), f in zip(rows, forces):
        row = a + (v / dt if dt > 0.0 else 0.0)  # the acceleration, or the end velocity over dt
        terms = max(
            1.0, np.linalg.norm(J @ solo.pin_v(res.qdd)), np.linalg.norm(a), np.linalg.norm(v) / max(dt, 1e-300)
        )
        assert UP @ row >= -1e-8 * terms, "a foot moves into the ground"
        fn = UP @ f
        assert np.linalg.norm(f - fn * UP) <= 1e-12 * max(1.0, np.linalg.norm(f)), "friction in the fallback"
        assert fn >= -1e-9 * max(1.0, np.max(np.abs(forces))), "a foot pulls on the ground"
        work += f @ row
        work_scale = max(work_scale, abs(f @ row))
    assert work <= 1e-8 * work_scale, "the contact forces do positive work"


@pytest.mark.parametrize("dt", [0.0, 1e-3])
def test_forced_pivot_bounds_on_solo12(dt):
    solo = Solo()
    q = solo.standing()
    rng = np.random.default_rng(5)
    qd = np.zeros(solo.tree.nv) if dt == 0.0 else np.r_[0.05 * rng.normal(size=6), 0.2 * rng.normal(size=12)]
    tau_ff = np.r_[25.0, 8.0, 0.0, 0.0, 0.0, 1.5, rng.normal(scale=0.5, size=12)]  # a sideways push on the base
    args = dict(tau_ff=tau_ff, contacts=supports(), time_step=dt or None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the default bound is not reached
        exact = solo.solver.solve(q, qd, **args)
    assert np.any(exact.contact_status == vs.ContactStatus.SLIDING), "the feet must not all stick"
    for bound in (1, 3):
        with pytest.warns(RuntimeWarning, match="real-time bound of %d pivots" % bound):
            res = solo.solver.solve(q, qd, contact_max_pivots=bound, **args)
        check_fallback(solo, q, qd, tau_ff, res, dt)
        assert not np.array_equal(res.qdd, exact.qdd)
    again = solo.solver.solve(q, qd, **args)
    for name in ("qdd", "tau_command", "contact_force", "contact_status"):
        assert np.array_equal(getattr(again, name), getattr(exact, name))
