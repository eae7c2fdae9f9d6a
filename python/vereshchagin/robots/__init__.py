"""Robot models: the Kinova Gen3 7-DOF we ship, and URDFs from the example-robot-data package.

:func:`gen3_urdf` writes the Gen3 (optionally with a rigid Robotiq 2F-85) as URDF text from the
numbers of Kinova's ``ros2_kortex`` description (see :mod:`vereshchagin.robots.gen3`);
:func:`gen3` loads it as a :class:`vereshchagin.Chain`; :func:`dual_gen3_urdf` writes two of them
on a turning torso (a kinematic tree, :class:`vereshchagin.Tree`).
"""

from __future__ import annotations

from pathlib import Path

from .dual_gen3 import DUAL_GEN3_JOINT_NAMES, TORSO, dual_gen3_urdf
from .gen3 import (
    GEN3_JOINT_NAMES,
    GEN3_START_POSE,
    GEN3_START_POSE_REPORTED,
    GEN3_TIP_LINK,
    gen3,
    gen3_data,
    gen3_urdf,
)

__all__ = [
    "DUAL_GEN3_JOINT_NAMES",
    "GEN3_JOINT_NAMES",
    "GEN3_START_POSE",
    "GEN3_START_POSE_REPORTED",
    "GEN3_TIP_LINK",
    "TORSO",
    "dual_gen3_urdf",
    "example_robot_urdf",
    "gen3",
    "gen3_data",
    "gen3_urdf",
]

# Short names for URDFs whose file stem is not the robot's usual name.
_ALIASES = {"ur3": "ur3_robot", "ur5": "ur5_robot", "ur10": "ur10_robot"}


def example_robot_urdf(name: str) -> str:
    """Path of a URDF shipped by the PyPI package ``example-robot-data`` (``pip install example-robot-data``).

    Parameters
    ----------
    name : str
        File stem such as ``"panda"``, ``"ur5_robot"``, ``"xarm7"`` (aliases ``"ur3"``, ``"ur5"``,
        ``"ur10"``), or a path relative to the package's ``robots/`` folder such as
        ``"panda_description/urdf/panda.urdf"``.

    Returns
    -------
    str
        Absolute path of the ``.urdf`` file (meshes, if any, are referenced as
        ``package://example-robot-data/...``).

    Raises
    ------
    ModuleNotFoundError
        If ``example-robot-data`` is not installed.
    FileNotFoundError
        If no URDF, or more than one, matches ``name``.
    """
    from importlib import metadata

    try:
        dist = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        raise ModuleNotFoundError(
            "example_robot_urdf needs the PyPI package example-robot-data: pip install example-robot-data"
        ) from None
    robots = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    if not robots.is_dir():
        raise ModuleNotFoundError(f"example-robot-data is installed but {robots} is missing")
    if "/" in name:
        matches = [robots / name] if (robots / name).is_file() else []
    else:
        stem = _ALIASES.get(name, name)
        matches = sorted(robots.glob(f"*/*/{stem}.urdf"))
    if len(matches) != 1:
        found = (
            "several: " + ", ".join(str(m.relative_to(robots)) for m in matches)
            if matches
            else "none; available: " + ", ".join(sorted(p.stem for p in robots.glob("*/*/*.urdf")))
        )
        raise FileNotFoundError(f"example-robot-data URDF {name!r}: {found}")
    return str(matches[0])
