"""The quadruped plant: Solo 12 (example-robot-data) on a free joint in MuJoCo, standing on a floor.

:func:`build` compiles the example-robot-data URDF (meshes dropped) with MuJoCo's URDF reader, the
same text the controller's ``Tree.from_urdf(..., base="free")`` reads, and adds a free joint on
``base_link``, a sphere of :data:`FOOT_RADIUS` at each foot frame (``*_FOOT``, the only geoms that
touch anything), a floor (z = 0, friction :data:`MU`), one torque motor per joint (limit
:data:`TORQUE_LIMIT`). 1 ms, ``implicitfast``, MuJoCo's soft contacts with an elliptic cone,
``impratio`` 10 and :data:`NOSLIP` noslip iterations. The maps between MuJoCo's free-joint state and the library's
(docs/floating-base.md) are :func:`to_model` and :func:`model_acceleration`.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np

from vereshchagin import Tree, robots

__all__ = [
    "FEET",
    "FOOT_RADIUS",
    "MU",
    "TORQUE_LIMIT",
    "base_rotation",
    "build",
    "model_acceleration",
    "solo12_urdf",
    "to_model",
]

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
FOOT_RADIUS = 0.016
"""m: the feet's contact spheres."""
MU = 0.8
"""Foot-floor friction coefficient."""
TORQUE_LIMIT = 2.7
"""N m: each joint motor's limit (Solo 12's actuators: about 2.7 N m peak)."""
DT = 1e-3
NOSLIP = 20
"""MuJoCo's noslip iterations."""


def solo12_urdf() -> str:
    """example-robot-data's Solo 12 URDF text without its visual and collision meshes."""
    text = open(robots.example_robot_urdf("solo_description/robots/solo12.urdf"), encoding="utf-8").read()
    return re.sub(r"<(visual|collision)>.*?</\1>", "", text, flags=re.S)


def build(model: Tree, gravity=(0.0, 0.0, -9.81)) -> mujoco.MjModel:
    """The plant; its joint order is checked against ``model``'s (a ``ValueError`` otherwise)."""
    spec = mujoco.MjSpec.from_string(solo12_urdf())
    spec.option.timestep = DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = list(gravity)
    # Feet hold by friction with tangential loads (least effort uses them): MuJoCo's soft contacts
    # creep under such loads (issue 27's hold test); the elliptic cone, impratio 10 and the
    # noslip pass keep the creep small.
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    spec.option.noslip_iterations = NOSLIP
    spec.body("base_link").add_freejoint()
    for foot in FEET:
        spec.body(foot).add_geom(
            name=foot, type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[FOOT_RADIUS, 0, 0], mass=0.0,
            friction=[MU, 0.005, 1e-4], contype=1, conaffinity=0,
        )  # fmt: skip
    spec.worldbody.add_geom(
        name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], contype=0, conaffinity=1,
        friction=[MU, 0.005, 1e-4],
    )  # fmt: skip
    for j in spec.joints:
        if j.type == mujoco.mjtJoint.mjJNT_HINGE:
            spec.add_actuator(
                name=f"motor_{j.name}", target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT,
                ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE, ctrlrange=[-TORQUE_LIMIT, TORQUE_LIMIT],
            )  # fmt: skip
    plant = spec.compile()
    names = [plant.joint(i).name for i in range(1, plant.njnt)]
    if names != list(model.joint_names):
        raise ValueError(f"the plant's joints {names} are not the model's {list(model.joint_names)}")
    return plant


def base_rotation(q: np.ndarray) -> np.ndarray:
    """The base's rotation (base axes to world axes) of the library's free-flyer q (quaternion
    (x, y, z, w) at q[3:7])."""
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.r_[q[6], q[3:6]])
    return R.reshape(3, 3)


def _rotation(data) -> np.ndarray:
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, data.qpos[3:7])
    return R.reshape(3, 3)


def to_model(data) -> tuple[np.ndarray, np.ndarray]:
    """The library's ``(q, qd)`` (nq = 19, nv = 18) of the plant's state: MuJoCo's quaternion is
    (w, x, y, z) and its free joint's linear velocity in world axes; ours (x, y, z, w) and LOCAL."""
    R = _rotation(data)
    w, x, y, z = data.qpos[3:7]
    q = np.r_[data.qpos[:3], x, y, z, w, data.qpos[7:]]
    qd = np.r_[R.T @ data.qvel[:3], data.qvel[3:]]
    return q, qd


def model_acceleration(data) -> np.ndarray:
    """The plant's ``qacc`` as the library's qdd: the time derivative of the LOCAL linear velocity
    ``R^T v`` is ``R^T a - omega x R^T v``."""
    R = _rotation(data)
    v, w = R.T @ data.qvel[:3], data.qvel[3:6]
    return np.r_[R.T @ data.qacc[:3] - np.cross(w, v), data.qacc[3:]]
