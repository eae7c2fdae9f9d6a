"""Small built-in chains for demonstrations and tests."""

from __future__ import annotations

import numpy as np

from ._core import Chain


def _tip(xyz, rpy=(0.0, 0.0, 0.0)) -> np.ndarray:
    """4x4 transform from a translation and fixed-axis roll-pitch-yaw angles (rad)."""
    r, p, y = rpy
    cx, sx, cy, sy, cz, sz = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rot_x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    rot_y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rot_z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3] = rot_z @ rot_y @ rot_x
    T[:3, 3] = xyz
    return T


def seven_joint_arm() -> Chain:
    """A 7-joint anthropomorphic arm (alternating z / y axes, about 1.1 m reach, 7.5 kg).

    Returns
    -------
    Chain
        Segments ``link1`` .. ``link7``; each joint rotates about its segment's root z axis and
        the tips alternate the next axis between z and y by a quarter turn about x.
    """
    lengths = [0.16, 0.13, 0.21, 0.21, 0.21, 0.11, 0.12]
    masses = [1.4, 1.2, 1.2, 0.9, 0.7, 0.7, 0.5]
    chain = Chain()
    for k, (length, mass) in enumerate(zip(lengths, masses)):
        roll = -np.pi / 2 if k % 2 == 0 else np.pi / 2
        if k == len(lengths) - 1:
            roll = 0.0
        radius = 0.04
        inertia = np.diag(
            [
                mass * (3 * radius**2 + length**2) / 12,
                mass * (3 * radius**2 + length**2) / 12,
                mass * radius**2 / 2,
            ]
        )
        # The link is a cylinder along the joint axis (z before the tip rotation).
        tip = _tip([0.0, 0.0, length], [roll, 0.0, 0.0])
        com_joint = np.array([0.0, 0.0, length / 2])
        R = tip[:3, :3]
        com_tip = R.T @ (com_joint - tip[:3, 3])
        inertia_tip = R.T @ inertia @ R
        chain.add_segment(
            name=f"link{k + 1}", joint="rot_z", tip=tip, mass=mass, com=com_tip, inertia=inertia_tip, rotor_inertia=0.02
        )
    return chain
