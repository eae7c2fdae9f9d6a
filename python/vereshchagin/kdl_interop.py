"""Conversion between :class:`vereshchagin.Chain` and PyKDL's ``Chain`` (Orocos KDL's Python API).

``Chain.from_kdl(kdl_chain)`` and ``chain.to_kdl()`` (attached in ``vereshchagin/__init__.py``) copy
segment by segment: name, joint (type, axis, origin, name, rotor inertia), tip frame at joint
position 0 and rigid-body inertia. Both libraries share KDL's semantics, so the converted chain
has the same kinematics and dynamics (up to the last bits of the inertia's parallel-axis shift).

PyKDL is imported only when a conversion runs. Debian's ``python3-pykdl`` is built for the system
interpreter ``/usr/bin/python3``; other interpreters cannot import it.

Not carried over: joint damping and stiffness (PyKDL does not expose them, and neither KDL's
dynamics solvers nor this library use them); a chain's URDF metadata (limits, friction, merged
link names), which a PyKDL chain does not have.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._core import Chain, Joint, SolverError

# PyKDL joint type name -> add_segment joint string (the axis types are handled separately).
_AXIS_TYPES = {
    "RotX": "rot_x",
    "RotY": "rot_y",
    "RotZ": "rot_z",
    "TransX": "trans_x",
    "TransY": "trans_y",
    "TransZ": "trans_z",
    "Fixed": "fixed",
}
_KDL_UNNAMED = "NoName"  # KDL's default segment and joint name


def _pykdl():
    try:
        import PyKDL  # noqa: N813 (the module's own name)
    except ImportError as err:
        raise ImportError(
            "PyKDL is not importable from this interpreter: install Debian's python3-pykdl "
            "(apt-get install python3-pykdl), which is built for /usr/bin/python3"
        ) from err
    return PyKDL


def _vec(v) -> np.ndarray:
    return np.array([v[0], v[1], v[2]], dtype=float)


def _frame_to_matrix(f) -> np.ndarray:
    T = np.eye(4)
    for r in range(3):
        for c in range(3):
            T[r, c] = f.M[r, c]
        T[r, 3] = f.p[r]
    return T


def _joint_type_name(kdl, joint) -> str:
    for name in ("RotAxis", "TransAxis", *_AXIS_TYPES):
        if joint.getType() == getattr(kdl.Joint, name):
            return name
    raise SolverError(f"joint '{joint.getName()}': unknown PyKDL joint type {joint.getType()}")


def _check_unit_scale_zero_offset(kdl, joint, where: str, revolute: bool) -> None:
    """KDL moves a joint by ``scale * q + offset``; a Chain has scale 1 and offset 0 only."""
    pose0 = joint.pose(0.0)
    axis = _vec(joint.JointAxis())
    rotation_at_zero = np.array([[pose0.M[r, c] for c in range(3)] for r in range(3)])
    t = joint.twist(1.0)
    rate = _vec(t.rot) if revolute else _vec(t.vel)
    offset_free = (
        np.array_equal(rotation_at_zero, np.eye(3))
        if revolute
        else np.array_equal(_vec(pose0.p), _vec(joint.JointOrigin()))
    )
    if not offset_free or not np.array_equal(rate, axis):
        raise SolverError(
            f"{where}: the joint has a PyKDL scale or offset (KDL moves it by scale * q + offset); "
            "vereshchagin.Chain supports scale 1 and offset 0 only"
        )


def _rotor_inertia(kdl, joint) -> float:
    """PyKDL hides Joint::getInertia(); KDL's mass matrix of the joint alone, on a massless body,
    is exactly that rotor inertia (0 + inertia on the diagonal)."""
    probe = kdl.Chain()
    probe.addSegment(kdl.Segment(kdl.Joint(joint), kdl.Frame(), kdl.RigidBodyInertia()))
    H = kdl.JntSpaceInertiaMatrix(1)
    kdl.ChainDynParam(probe, kdl.Vector(0.0, 0.0, 0.0)).JntToMass(kdl.JntArray(1), H)
    return float(H[0, 0])


def _inertia_about_com(body) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass (tip frame) and rotational inertia about the centre of mass of a
    PyKDL RigidBodyInertia, whose RotationalInertia is about the tip origin (parallel axes)."""
    m = body.getMass()
    c = _vec(body.getCOG())
    ri = body.getRotationalInertia()
    about_tip = np.array([ri[k] for k in range(9)], dtype=float).reshape(3, 3)
    about_com = about_tip - m * (c @ c * np.eye(3) - np.outer(c, c))
    return m, c, 0.5 * (about_com + about_com.T)


def _segment_arguments(kdl, segment, index: int) -> dict[str, Any]:
    """add_segment keyword arguments of one PyKDL Segment."""
    name = segment.getName()
    if name == _KDL_UNNAMED:
        name = f"segment{index}"
    joint = segment.getJoint()
    kind = _joint_type_name(kdl, joint)
    where = f"segment {index} ('{name}')"
    spec: Joint | str
    if kind in ("RotAxis", "TransAxis"):
        make = Joint.revolute if kind == "RotAxis" else Joint.prismatic
        spec = make(_vec(joint.JointAxis()), _vec(joint.JointOrigin()))
    else:
        spec = _AXIS_TYPES[kind]
    moving = kind != "Fixed"
    if moving:
        _check_unit_scale_zero_offset(kdl, joint, where, revolute=kind.startswith("Rot"))
    mass, com, inertia = _inertia_about_com(segment.getInertia())
    joint_name = joint.getName()
    return dict(
        name=name,
        joint=spec,
        tip=_frame_to_matrix(segment.getFrameToTip()),
        mass=mass,
        com=com,
        inertia=inertia,
        rotor_inertia=_rotor_inertia(kdl, joint) if moving else 0.0,
        joint_name="" if joint_name == _KDL_UNNAMED else joint_name,
    )


def chain_from_kdl(kdl_chain, inertia_check: str = "joint_space") -> Chain:
    """Build a :class:`Chain` from a PyKDL ``Chain``.

    Parameters
    ----------
    kdl_chain : PyKDL.Chain
        Any serial KDL chain whose moving joints have KDL's default scale 1 and offset 0. Segment
        tips, centres of mass and inertias are read in KDL's frames (the same as ours: tip frame
        at joint position 0 in the root frame; inertia in the tip frame, converted from KDL's
        reference point, the tip origin, to the centre of mass). Rotor inertias
        (``Joint::getInertia()``) are carried over. Segments and joints named KDL's default
        ``'NoName'`` become ``'segment<i>'`` and ``'segment<i>_joint'``.
    inertia_check : {'joint_space', 'physical'}
        As in :meth:`Chain.add_segment`. 'joint_space' (default) accepts every inertia KDL accepts,
        e.g. the identified (non-rigid-body) link inertias of KDL's own KUKA LWR 4 model, as the
        C++ drop-in ``kdl_compat::ChainHdSolver_Vereshchagin`` does; the chain remembers it
        (``chain.inertia_check``), so ``Solver(chain)`` checks at each solve that the joint-space
        inertia is positive definite. 'physical' additionally requires every body to
        be a rigid body (positive semi-definite inertia obeying the triangle inequality) and
        names the offending segment.

    Returns
    -------
    Chain
        Same segments, joints and inertias; no joint limits or friction (PyKDL has none).

    Raises
    ------
    SolverError
        ``kdl_chain`` is not a PyKDL chain, a joint has a scale or offset, or a segment fails
        :meth:`Chain.add_segment`'s checks (e.g. duplicate names).
    ImportError
        PyKDL is not importable.
    """
    kdl = _pykdl()
    if not isinstance(kdl_chain, kdl.Chain):
        raise SolverError(f"kdl_chain must be a PyKDL.Chain, got {type(kdl_chain).__name__}")
    chain = Chain()
    for i in range(kdl_chain.getNrOfSegments()):
        chain.add_segment(**_segment_arguments(kdl, kdl_chain.getSegment(i), i), inertia_check=inertia_check)
    return chain


def _kdl_joint(kdl, spec: dict[str, Any]):
    name, kind, rotor = spec["joint_name"], spec["joint_type"], spec["rotor_inertia"]
    if kind in ("revolute", "prismatic"):
        jtype = kdl.Joint.RotAxis if kind == "revolute" else kdl.Joint.TransAxis
        return kdl.Joint(name, kdl.Vector(*spec["origin"]), kdl.Vector(*spec["axis"]), jtype, 1.0, 0.0, rotor)
    kdl_name = {v: k for k, v in _AXIS_TYPES.items()}[kind]
    return kdl.Joint(name, getattr(kdl.Joint, kdl_name), 1.0, 0.0, rotor)


def _kdl_frame(kdl, T: np.ndarray):
    R = T[:3, :3]
    return kdl.Frame(kdl.Rotation(*R.reshape(-1)), kdl.Vector(*T[:3, 3]))


def _kdl_inertia(kdl, spec: dict[str, Any]):
    I = spec["inertia"]
    about_com = kdl.RotationalInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
    return kdl.RigidBodyInertia(spec["mass"], kdl.Vector(*spec["com"]), about_com)


def chain_to_kdl(chain: Chain):
    """The chain as a PyKDL ``Chain`` (Orocos KDL's Python API).

    Parameters
    ----------
    chain : Chain
        Any chain; its segments are copied with their names, joints (type, unit axis, origin,
        name, rotor inertia as ``Joint::getInertia()``), tip frames at joint position 0 and
        inertias (PyKDL ``RigidBodyInertia(mass, com, inertia about the com)``, tip frame).

    Returns
    -------
    PyKDL.Chain
        A chain on which KDL's own solvers (``ChainDynParam``, ``ChainIdSolver_RNE``, ...) give
        this chain's dynamics. URDF metadata (limits, friction, merged links) is not carried over.

    Raises
    ------
    ImportError
        PyKDL is not importable.
    """
    kdl = _pykdl()
    out = kdl.Chain()
    for i in range(chain.n_segments):
        spec = chain.segment_spec(i)
        out.addSegment(
            kdl.Segment(spec["name"], _kdl_joint(kdl, spec), _kdl_frame(kdl, spec["tip"]), _kdl_inertia(kdl, spec))
        )
    return out
