"""URDF robots loaded twice, by vereshchagin and by Pinocchio, for the tests against Pinocchio.

Franka Panda (example-robot-data, tip ``panda_hand``; Pinocchio's two finger joints are locked at 0
with ``buildReducedModel`` because our loader lumps them rigidly at 0), UR5 (its tree branches;
tips ``tool0`` and ``ee_link``) and the shipped Kinova Gen3 with and without the rigid Robotiq
2F-85 (continuous joints are (cos, sin) pairs in Pinocchio). ``BUILDERS[name]()`` gives a
:class:`Robot`; ``assert_rel`` is the norm-wise relative comparison of these tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from support.chains import assert_close, pin_configuration, symmetric
from vereshchagin.robots import example_robot_urdf, gen3, gen3_urdf

RTOL = 1e-8
LWA = pin.LOCAL_WORLD_ALIGNED
G = np.array([0.0, 0.0, -9.81])


def assert_rel(actual, expected, what, rtol=RTOL):
    """Norm-wise relative comparison ||a - e|| <= rtol * max(||e||, 1): chains.assert_close with
    this argument order and the default tolerance of the URDF tests."""
    assert_close(actual, expected, rtol, what)


@dataclass
class Robot:
    name: str
    chain: vs.Chain
    model: pin.Model
    tip: str
    links: tuple  # merged / base links whose frames we compare too

    def pin_q(self, q):
        return pin_configuration(self.model, q)

    def random_state(self, rng):
        lo = np.maximum(self.chain.lower, -np.pi)
        hi = np.minimum(self.chain.upper, np.pi)
        q = rng.uniform(lo, hi)
        qd = rng.uniform(-1.5, 1.5, self.chain.n_joints)
        return q, qd


def panda():
    path = example_robot_urdf("panda")
    full = pin.buildModelFromUrdf(path)
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    chain = vs.Chain.from_urdf(path, tip="panda_hand")
    return Robot(
        "panda",
        chain,
        model,
        "panda_hand",
        (
            "panda_link8",
            "panda_link7",
            "panda_link3",
            "panda_hand_tcp",
            "panda_leftfinger",
            "panda_rightfinger",
            "panda_link0",
        ),
    )


def ur5(tip):
    path = example_robot_urdf("ur5")
    model = pin.buildModelFromUrdf(path)
    chain = vs.Chain.from_urdf(path, tip=tip)
    other = "ee_link" if tip == "tool0" else "tool0"
    return Robot(f"ur5_{tip}", chain, model, tip, ("wrist_3_link", other, "upper_arm_link", "base_link"))


def gen3_robot(gripper, **kw):
    model = pin.buildModelFromXML(gen3_urdf(gripper, **kw))
    chain = gen3(gripper, **kw)
    links = ("bracelet_link", "spherical_wrist_1_link", "base_link")
    if gripper:
        links += ("robotiq_85_base_link", "robotiq_85_left_finger_tip_link", "robotiq_85_right_knuckle_link")
    return Robot(f"gen3_{'gripper' if gripper else 'bare'}", chain, model, "end_effector_link", links)


BUILDERS = {
    "panda": panda,
    "ur5_tool0": lambda: ur5("tool0"),
    "ur5_ee_link": lambda: ur5("ee_link"),
    "gen3_gripper": lambda: gen3_robot(True),
    "gen3_bare": lambda: gen3_robot(False),
}


def with_rotors(robot, rng):
    r = rng.uniform(0.0, 0.4, robot.chain.n_joints)
    robot.chain.rotor_inertia = r
    robot.model.armature = r
    robot.model.gravity = pin.Motion(np.r_[G, 0.0, 0.0, 0.0])
    return vs.Solver(robot.chain, gravity=G)


def minv(model, data, q):
    return symmetric(pin.computeMinverse(model, data, q))
