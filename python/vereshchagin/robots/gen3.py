"""Kinova Gen3 7-DOF arm, optionally with a rigid Robotiq 2F-85 gripper, as a URDF we generate.

The numbers (kinematics, inertias, limits) come from ``data/kinova_gen3_7dof.json``, transcribed
from Kinova's ROS 2 description: repository ``Kinovarobotics/ros2_kortex``, file
``kortex_description/arms/gen3/7dof/urdf/gen3_macro.xacro`` (last changed in commit
``6a9960eb8c672ef32f7f12a90e12dad4d797df06``; repository snapshot
``1fdbef345954b326627dc3792981e18e2221450b``) and, for the gripper,
``kortex_description/robots/gen3_2f85.urdf`` (commit ``d6c92b0824f9405edf5dc2f585d6350c66489df4``;
gripper part from ``PickNikRobotics/ros2_robotiq_gripper``). The JSON's ``source`` field is the
authority and is repeated in the header comment of every generated file.

Modelling choices
-----------------
* Joints 1, 3, 5, 7 are ``continuous`` (``revolute`` with +-2 pi if ``use_external_cable``);
  joints 2, 4, 6 are ``revolute`` with the limits at the description's HEAD (Kinova commit
  7e0ac34, user-guide values): +-2.24, +-2.57, +-2.09 rad. Velocity 1.3963 rad/s (j1-j4) and
  1.2218 rad/s (j5-j7); effort 39 N m (j1-j4) and 9 N m (j5-j7), as in the URDF.
* The bracelet link is the variant without the vision module unless ``vision=True``.
* The gripper is rigid: every gripper joint is ``fixed`` at its zero position, which is the fully
  open 2F-85 (knuckle angle 0 rad; the description's closed end is about 0.8 rad). A loader that
  merges fixed joints lumps the whole gripper (0.921 kg) into ``bracelet_link``. Gripper links
  drop the ``gen3_`` name prefix of the source file (the arm uses the empty prefix).
* No meshes: collision and visual geometry are cylinders along each link and one box for the
  gripper, only roughly the size of the real parts.
* Kinova gives no joint friction, damping or rotor inertia; ``joint_friction`` and
  ``joint_damping`` (default 0) fill the URDF ``<dynamics>`` tags. The URDF ``friction`` is the
  static (breakaway) friction torque, N m; ``damping`` is viscous, N m s/rad.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np

__all__ = [
    "GEN3_JOINT_NAMES",
    "GEN3_START_POSE",
    "GEN3_START_POSE_REPORTED",
    "GEN3_TIP_LINK",
    "gen3",
    "gen3_data",
    "gen3_urdf",
]

DATA_FILE = Path(__file__).with_name("data") / "kinova_gen3_7dof.json"

GEN3_JOINT_NAMES = tuple(f"joint_{k}" for k in range(1, 8))
"""Names of the seven actuated joints, base to wrist."""

GEN3_TIP_LINK = "end_effector_link"
"""Link used as the chain tip by :func:`gen3` (the Kinova end-effector frame on the bracelet)."""

GEN3_START_POSE_REPORTED = (6.28318, 0.261895, 3.14159, 4.01417, 0.0, 0.959856, 0.57079)
"""Use-case-1 start pose of Lau 2023 as written there (rad; Kortex reports angles in 0..2 pi)."""

GEN3_START_POSE = tuple(math.remainder(q, 2.0 * math.pi) for q in GEN3_START_POSE_REPORTED)
"""The same pose with each angle wrapped to [-pi, pi] (rad).

Physically identical to :data:`GEN3_START_POSE_REPORTED`, but inside the URDF limits: joint 4
reads 4.01417 rad in the report, outside its +-2.57 rad range, and is -2.26902 rad here.
"""

Number = Union[float, int]


@lru_cache(maxsize=1)
def _load() -> dict:
    with open(DATA_FILE, encoding="utf-8") as f:
        return json.load(f)


def gen3_data() -> dict:
    """The reference numbers of the Gen3 7-DOF and the Robotiq 2F-85 (a fresh copy of the JSON)."""
    return json.loads(json.dumps(_load()))


def _version() -> str:
    from .. import __version__

    return __version__


def _num(x: Number) -> str:
    return repr(float(x))


def _vec(v: Sequence[Number]) -> str:
    return " ".join(_num(x) for x in v)


def _per_joint(value, what: str) -> np.ndarray:
    arr = np.zeros(7) if value is None else np.broadcast_to(np.asarray(value, float), (7,)).copy()
    if arr.shape != (7,) or not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ValueError(f"{what} must be None, a scalar or 7 finite values >= 0, got {value!r}")
    return arr


def _comment(text: str) -> str:
    return "<!-- " + text.replace("--", "- -") + " -->"


def _limit_text(j: dict, use_external_cable: bool) -> str:
    if j["type"] == "continuous" and not use_external_cable:
        pos = "continuous"
    elif j["type"] == "continuous":
        pos = f"[{j['lower_if_use_external_cable']:.6g}, {j['upper_if_use_external_cable']:.6g}] rad"
    else:
        pos = f"[{j['lower']:g}, {j['upper']:g}] rad"
    return f"{j['name']} {pos}, {j['velocity']:g} rad/s, {j['effort']:g} N m"


def _inertial(link: dict, indent: str) -> list[str]:
    i = link["inertia"]
    rpy = link.get("inertial_rpy", [0.0, 0.0, 0.0])
    return [
        f"{indent}<inertial>",
        f'{indent}  <origin xyz="{_vec(link["com_xyz"])}" rpy="{_vec(rpy)}"/>',
        f'{indent}  <mass value="{_num(link["mass"])}"/>',
        f'{indent}  <inertia ixx="{_num(i["ixx"])}" ixy="{_num(i["ixy"])}" ixz="{_num(i["ixz"])}"'
        f' iyy="{_num(i["iyy"])}" iyz="{_num(i["iyz"])}" izz="{_num(i["izz"])}"/>',
        f"{indent}</inertial>",
    ]


def _cylinder_between(end: Sequence[float], radius: float) -> tuple[str, str, str]:
    """Origin xyz, rpy and geometry of a cylinder from the link origin to ``end``."""
    d = np.asarray(end, float)
    length = float(np.linalg.norm(d))
    u = d / length
    pitch = math.acos(max(-1.0, min(1.0, u[2])))
    yaw = math.atan2(u[1], u[0]) if math.hypot(u[0], u[1]) > 1e-12 else 0.0
    xyz = " ".join(f"{x:.6g}" for x in d / 2)
    rpy = f"0 {pitch:.6g} {yaw:.6g}"
    return xyz, rpy, f'<cylinder radius="{radius:g}" length="{length:.6g}"/>'


def _shape(xyz: str, rpy: str, geometry: str, indent: str) -> list[str]:
    lines = []
    for tag in ("visual", "collision"):
        lines += [
            f"{indent}<{tag}>",
            f'{indent}  <origin xyz="{xyz}" rpy="{rpy}"/>',
            f"{indent}  <geometry>{geometry}</geometry>",
            f"{indent}</{tag}>",
        ]
    return lines


# Rough radii (m) of the primitive shapes; the Gen3 actuators are about 0.09-0.1 m across.
_RADIUS = {
    "base_link": 0.05,
    "shoulder_link": 0.05,
    "half_arm_1_link": 0.05,
    "half_arm_2_link": 0.05,
    "forearm_link": 0.045,
    "spherical_wrist_1_link": 0.04,
    "spherical_wrist_2_link": 0.04,
    "bracelet_link": 0.045,
}


def gen3_urdf(
    gripper: bool = True,
    path: Optional[Union[str, Path]] = None,
    joint_friction=None,
    joint_damping=None,
    use_external_cable: bool = False,
    vision: bool = False,
) -> str:
    """URDF text of the Kinova Gen3 7-DOF, optionally with a rigid Robotiq 2F-85.

    Parameters
    ----------
    gripper : bool
        Attach the Robotiq 2F-85 to ``end_effector_link`` with fixed joints (fully open fingers).
    path : str or Path, optional
        If given, also write the text to this file (UTF-8).
    joint_friction, joint_damping : float or sequence of 7 floats, optional
        Static friction (N m) and viscous damping (N m s/rad) written to each joint's
        ``<dynamics>`` tag; default 0.
    use_external_cable : bool
        Make joints 1, 3, 5, 7 ``revolute`` with +-2 pi limits instead of ``continuous``.
    vision : bool
        Use the bracelet inertia with the vision module (0.5 kg instead of 0.364 kg).

    Returns
    -------
    str
        The URDF XML. Root link ``base_link``; actuated joints :data:`GEN3_JOINT_NAMES`.
    """
    data = _load()
    friction = _per_joint(joint_friction, "joint_friction")
    damping = _per_joint(joint_damping, "joint_damping")
    src = data["source"]
    ee = data["end_effector_fixed_joint"]

    out = ['<?xml version="1.0" encoding="utf-8"?>']
    out.append(
        _comment(
            "Kinova Gen3 7-DOF"
            + (" with a rigid Robotiq 2F-85 gripper" if gripper else "")
            + f". Generated by vereshchagin {_version()} (vereshchagin.robots.gen3_urdf); "
            "do not edit by hand."
        )
    )
    out.append(
        _comment(
            f"Source: https://github.com/{src['repo']} {src['arm_path']} "
            f"(last changed in commit {src['arm_file_last_commit']}, "
            f"repository snapshot {src['repo_snapshot_commit']})"
            + (f"; gripper: {src['gripper_path']}, commit {src['gripper_file_last_commit']}" if gripper else "")
            + "."
        )
    )
    out.append(
        _comment(
            f"Options: gripper={gripper}, use_external_cable={use_external_cable}, vision={vision}. "
            "Limits used (values at the description's HEAD, Kinova commit 7e0ac34 'as per the "
            "values in the User Guides'; not the older ones of the pre-expanded gen3_2f85.urdf): "
            + "; ".join(_limit_text(j, use_external_cable) for j in data["joints"])
            + ". dynamics: friction = static friction (N m), damping = viscous (N m s/rad). "
            "Geometry: rough primitives, no meshes."
        )
    )
    out.append('<robot name="kinova_gen3_7dof">')

    def link_block(link: dict, shape_end: Optional[Sequence[float]]) -> None:
        out.append(f'  <link name="{link["name"]}">')
        out.extend(_inertial(link, "    "))
        if shape_end is not None:
            out.extend(_shape(*_cylinder_between(shape_end, _RADIUS[link["name"]]), "    "))
        out.append("  </link>")

    joints = data["joints"]
    link_block(data["base_link"], joints[0]["origin_xyz"])
    for k, j in enumerate(joints):
        child = j["child_link"]
        if "name" not in child:
            child = child["vision" if vision else "no_vision"]
        continuous = j["type"] == "continuous" and not use_external_cable
        jtype = "continuous" if continuous else "revolute"
        if j["type"] == "continuous":
            lower, upper = j["lower_if_use_external_cable"], j["upper_if_use_external_cable"]
        else:
            lower, upper = j["lower"], j["upper"]
        limit = (
            f'<limit effort="{_num(j["effort"])}" velocity="{_num(j["velocity"])}"/>'
            if continuous
            else f'<limit lower="{_num(lower)}" upper="{_num(upper)}" '
            f'effort="{_num(j["effort"])}" velocity="{_num(j["velocity"])}"/>'
        )
        out += [
            f'  <joint name="{j["name"]}" type="{jtype}">',
            f'    <parent link="{j["parent"]}"/>',
            f'    <child link="{j["child"]}"/>',
            f'    <origin xyz="{_vec(j["origin_xyz"])}" rpy="{_vec(j["origin_rpy"])}"/>',
            f'    <axis xyz="{_vec(j["axis"])}"/>',
            f"    {limit}",
            f'    <dynamics damping="{_num(damping[k])}" friction="{_num(friction[k])}"/>',
            "  </joint>",
        ]
        end = joints[k + 1]["origin_xyz"] if k + 1 < len(joints) else ee["origin_xyz"]
        link_block(child, end)

    out += [
        f'  <joint name="{ee["name"]}" type="fixed">',
        f'    <parent link="{ee["parent"]}"/>',
        f'    <child link="{ee["child"]}"/>',
        f'    <origin xyz="{_vec(ee["origin_xyz"])}" rpy="{_vec(ee["origin_rpy"])}"/>',
        "  </joint>",
        f'  <link name="{ee["child"]}"/>',
    ]

    if gripper:
        g = data["robotiq_2f85"]
        rename = {n: n.removeprefix("gen3_") for n in g["links"]}
        rename[g["attach"]["parent"]] = ee["child"]
        out.append(
            "  "
            + _comment(
                "Robotiq 2F-85, rigid: all gripper joints fixed at 0 rad (fingers fully open); "
                "the source's revolute / continuous / mimic finger joints are not modelled."
            )
        )
        for lname, link in g["links"].items():
            out.append(f'  <link name="{rename[lname]}">')
            out.extend(_inertial(link, "    "))
            if lname == g["attach"]["child"]:
                # One box for the whole open gripper (about 0.12 x 0.06 x 0.15 m).
                out.extend(_shape("0 0 0.075", "0 0 0", '<box size="0.12 0.06 0.15"/>', "    "))
            out.append("  </link>")
        fixed = [("robotiq_85_base_joint", g["attach"])]
        fixed += [(n.removeprefix("gen3_"), jj) for n, jj in g["joints"].items()]
        for name, jj in fixed:
            out += [
                f'  <joint name="{name}" type="fixed">',
                f'    <parent link="{rename[jj["parent"]]}"/>',
                f'    <child link="{rename[jj["child"]]}"/>',
                f'    <origin xyz="{_vec(jj["origin_xyz"])}" rpy="{_vec(jj["origin_rpy"])}"/>',
                "  </joint>",
            ]
    out.append("</robot>")
    text = "\n".join(out) + "\n"
    if path is not None:
        Path(path).write_text(text, encoding="utf-8")
    return text


def gen3(gripper: bool = True, **kwargs):
    """The Kinova Gen3 7-DOF as a :class:`vereshchagin.Chain` (via ``Chain.from_urdf``).

    Parameters
    ----------
    gripper : bool
        Include the rigid Robotiq 2F-85 (its mass is merged into ``bracelet_link``).
    **kwargs
        Passed to :func:`gen3_urdf` (``joint_friction``, ``joint_damping``,
        ``use_external_cable``, ``vision``, ``path``).

    Returns
    -------
    Chain
        Seven revolute joints :data:`GEN3_JOINT_NAMES`, from ``base_link`` to
        :data:`GEN3_TIP_LINK`.
    """
    import vereshchagin

    return vereshchagin.Chain.from_urdf(gen3_urdf(gripper, **kwargs), root="base_link", tip=GEN3_TIP_LINK)
