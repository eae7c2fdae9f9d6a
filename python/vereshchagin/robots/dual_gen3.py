"""A dual-arm Kinova Gen3 platform: two Gen3 arms on a torso that turns about a vertical axis.

Kinova sells dual-Gen3 set-ups but publishes no torso; the torso here is a plausible choice,
stated in :data:`TORSO`. The arms are :func:`vereshchagin.robots.gen3_urdf` (rigid Robotiq 2F-85
by default) with every link and joint name prefixed ``left_`` / ``right_``, mounted upright on
the torso by fixed joints. Frames (m): the world (root link ``pedestal_link``) is the top of a
pedestal; ``torso_joint`` turns the ``torso_link`` about world z at the origin; the arms' base
links sit at ``(0, +-shoulder_y, shoulder_z)`` in the torso frame, axes parallel to it.

Joint order of a :class:`vereshchagin.Tree` loaded from the text (depth-first, children by joint
name): ``torso_joint``, ``left_joint_1`` .. ``left_joint_7``, ``right_joint_1`` ..
``right_joint_7`` (15 joints).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any, Optional

from .gen3 import gen3_urdf

__all__ = ["DUAL_GEN3_JOINT_NAMES", "TORSO", "dual_gen3_urdf"]

TORSO: dict[str, Any] = {
    "mass": 10.0,
    "size": (0.20, 0.50, 0.25),
    "effort": 80.0,
    "velocity": 1.0,
    "friction": 1.0,
    "damping": 0.5,
}
"""The torso link and joint (plausible choices, not a product's data sheet): a solid box of
``mass`` kg and ``size`` (x, y, z) m standing on the joint (centre of mass ``size[2] / 2`` above
it); effort limit N m (about twice the Gen3's largest actuator, 39 N m: the torso turns both
arms), velocity limit rad/s, static friction N m, viscous damping N m s/rad."""

DUAL_GEN3_JOINT_NAMES = ("torso_joint",) + tuple(f"{s}_joint_{k}" for s in ("left", "right") for k in range(1, 8))
"""The 15 joints in the order of :class:`vereshchagin.Tree` and of the MuJoCo plant."""


def _prefixed(arm_urdf: str, prefix: str, base_scale: float) -> list[ET.Element]:
    """The links and joints of ``arm_urdf`` with every link and joint name prefixed.

    The arm's ``base_link`` (fixed to the torso) gets its mass and inertia times ``base_scale``.
    """
    robot = ET.fromstring(arm_urdf)
    out = []
    for el in robot:
        if el.tag not in ("link", "joint"):
            continue
        if el.tag == "link" and el.get("name") == "base_link":
            _scale_inertial(el, base_scale)
        el.set("name", prefix + el.get("name", ""))
        for ref in el.iter():
            if ref.tag in ("parent", "child"):
                ref.set("link", prefix + ref.get("link", ""))
        out.append(el)
    return out


def _scale_inertial(link: ET.Element, factor: float) -> None:
    """Multiply the mass and every inertia entry of ``link`` by ``factor`` (same centre of mass)."""
    mass, inertia = link.find("inertial/mass"), link.find("inertial/inertia")
    if mass is None or inertia is None:
        raise ValueError(f"link {link.get('name')!r} has no inertial to scale")
    mass.set("value", repr(float(mass.get("value", "0")) * factor))
    for key, value in inertia.attrib.items():
        inertia.set(key, repr(float(value) * factor))


def _box_inertia(mass: float, size) -> tuple[float, float, float]:
    x, y, z = size
    return (mass * (y * y + z * z) / 12.0, mass * (x * x + z * z) / 12.0, mass * (x * x + y * y) / 12.0)


def dual_gen3_urdf(
    joint_friction=None,
    joint_damping=None,
    gripper: bool = True,
    shoulder_y: float = 0.25,
    shoulder_z: float = 0.20,
    torso_share: float = 1.0,
    torso_friction: Optional[float] = None,
    torso_damping: Optional[float] = None,
) -> str:
    """URDF text of the dual-arm Gen3 platform (module doc).

    Parameters
    ----------
    joint_friction, joint_damping : float or sequence of 7 floats, optional
        Static friction (N m) and viscous damping (N m s/rad) of each arm's joints 1-7 (both
        arms alike), as in :func:`vereshchagin.robots.gen3_urdf`; default 0.
    gripper : bool
        Attach the rigid Robotiq 2F-85 to each arm.
    shoulder_y, shoulder_z : float
        Mount points of the arms' base links in the torso frame, m: ``(0, +shoulder_y,
        shoulder_z)`` left, ``(0, -shoulder_y, shoulder_z)`` right.
    torso_share : float
        Factor in (0, 1] on the mass and inertia of the torso segment's rigid body (the torso
        link and the two arms' ``base_link``, fixed to it) and on the torso joint's friction and
        damping. 0.5 gives the half torso of the separate-chains shortcut
        (:mod:`vereshchagin_experiments.contact.dual_arm`): two chains each with half of it count it once.
    torso_friction, torso_damping : float, optional
        Torso joint static friction (N m) and damping (N m s/rad) before ``torso_share``;
        default :data:`TORSO`'s.

    Returns
    -------
    str
        The URDF XML; root link ``pedestal_link``; joints :data:`DUAL_GEN3_JOINT_NAMES`.

    Raises
    ------
    ValueError
        If ``torso_share`` is not in (0, 1] or a mount coordinate is not finite.
    """
    if not 0.0 < torso_share <= 1.0:
        raise ValueError(f"torso_share must be in (0, 1], got {torso_share!r}")
    if not all(abs(v) < float("inf") for v in (shoulder_y, shoulder_z)):
        raise ValueError(f"shoulder_y and shoulder_z must be finite, got {shoulder_y!r}, {shoulder_z!r}")
    friction = TORSO["friction"] if torso_friction is None else float(torso_friction)
    damping = TORSO["damping"] if torso_damping is None else float(torso_damping)
    mass = TORSO["mass"] * torso_share
    ixx, iyy, izz = _box_inertia(mass, TORSO["size"])
    sx, sy, sz = TORSO["size"]
    robot = ET.Element("robot", name="dual_kinova_gen3")
    ET.SubElement(robot, "link", name="pedestal_link")
    joint = ET.SubElement(robot, "joint", name="torso_joint", type="revolute")
    ET.SubElement(joint, "parent", link="pedestal_link")
    ET.SubElement(joint, "child", link="torso_link")
    ET.SubElement(joint, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(joint, "axis", xyz="0 0 1")
    ET.SubElement(
        joint, "limit", lower="-2.6", upper="2.6", effort=repr(TORSO["effort"]), velocity=repr(TORSO["velocity"])
    )
    ET.SubElement(joint, "dynamics", damping=repr(damping * torso_share), friction=repr(friction * torso_share))
    torso = ET.SubElement(robot, "link", name="torso_link")
    inertial = ET.SubElement(torso, "inertial")
    ET.SubElement(inertial, "origin", xyz=f"0 0 {sz / 2!r}", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=repr(mass))
    ET.SubElement(inertial, "inertia", ixx=repr(ixx), ixy="0", ixz="0", iyy=repr(iyy), iyz="0", izz=repr(izz))
    collision = ET.SubElement(torso, "collision")
    ET.SubElement(collision, "origin", xyz=f"0 0 {sz / 2!r}", rpy="0 0 0")
    ET.SubElement(ET.SubElement(collision, "geometry"), "box", size=f"{sx!r} {sy!r} {sz!r}")
    arm = gen3_urdf(gripper=gripper, joint_friction=joint_friction, joint_damping=joint_damping)
    for side, y in (("left", shoulder_y), ("right", -shoulder_y)):
        mount = ET.SubElement(robot, "joint", name=f"{side}_mount_joint", type="fixed")
        ET.SubElement(mount, "parent", link="torso_link")
        ET.SubElement(mount, "child", link=f"{side}_base_link")
        ET.SubElement(mount, "origin", xyz=f"0 {float(y)!r} {float(shoulder_z)!r}", rpy="0 0 0")
        robot.extend(_prefixed(arm, f"{side}_", torso_share))
    ET.indent(robot)
    header = (
        '<?xml version="1.0" encoding="utf-8"?>\n<!-- Dual-arm Kinova Gen3 on a turning torso. Generated by '
        "vereshchagin.robots.dual_gen3_urdf; arms from vereshchagin.robots.gen3_urdf; torso: plausible "
        f"choices (torso_share={torso_share!r}). -->\n"
    )
    return header + ET.tostring(robot, encoding="unicode") + "\n"
