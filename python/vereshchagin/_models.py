"""Python-side members of the compiled Chain and Tree (``python/bindings/model_bindings.cpp``).

Their repr, and the joint properties (``joint_names``, ``joint_types``, ``lower``, ``upper``,
``velocity_limit``, ``effort_limit``, ``friction``, ``damping``) read from the compiled
``_joints`` records: one (name, type, lower, upper, velocity_limit, effort_limit, friction,
damping, segment) tuple per moving joint, in q order.

Their pickle states (``__getstate__``, ``__setstate__``: ``python/bindings/model_state.cpp``, which
calls ``_state`` and ``_records`` below for the layout; the C++ library checks the records) are
Chain: ``(1, segments, joints, links, root_link, notes, inertia_check)``; Tree: ``(1, root_link,
[(segment, parent)], joints, links, notes, inertia_check)`` and, on a floating base, ``(kind, the
13 stored doubles of the base inertia)`` last. A segment: ``(name, joint name, joint
type, origin, axis, rotor inertia, damping, stiffness, tip frame (12), the 13 stored inertia
doubles)``, restored bit for bit; a joint: ``(name, type, lower, upper, velocity_limit,
effort_limit, friction, damping, segment)``; a link: ``(name, segment, frame (12))``; lists hold
the records, the vectors of 3, 12 and 13 doubles are lists (any sequence loads). States of six
entries (no inertia_check) load as 'physical'.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from ._core import Chain, SolverError, Tree
from ._docstrings import DOCS

# The joint properties in the order of the fields of a ``_joints`` record; the first two are lists
# of str, the others float64 arrays of shape (n_joints,).
_JOINT_FIELDS = (
    "joint_names",
    "joint_types",
    "lower",
    "upper",
    "velocity_limit",
    "effort_limit",
    "friction",
    "damping",
)


def _state(model: Chain | Tree, records: tuple, base=None) -> tuple:
    """The pickle state of ``model`` from the C++ library's records of it.

    Parameters
    ----------
    model : Chain or Tree
        The model (its type picks the layout; its ``inertia_check`` ends the state).
    records : tuple
        ``(root_link, [(segment, parent)], joints, links, notes)`` (``robot_state.hpp``'s
        ``StateRecords``; a chain's parent indices are dropped).
    base : tuple or None
        A Tree's base ``(kind, the 13 stored doubles of its inertia)`` (``base_state.hpp``); on a
        floating base it is the state's eighth entry (a fixed base's state keeps seven).
    """
    root, segments, joints, links, notes = records
    if isinstance(model, Tree):
        state = (1, root, segments, joints, links, notes, model.inertia_check)
        return state if base is None or base[0] == "fixed" else (*state, (base[0], list(base[1])))
    return (1, [segment for segment, _ in segments], joints, links, root, notes, model.inertia_check)


def _records(state: tuple, what: str) -> tuple:
    """The inverse of ``_state``: ``(records, inertia_check, base)`` of a Chain or Tree state.

    Parameters
    ----------
    state : tuple
        A state of either layout (``what`` says which), of six entries (no inertia_check: loads
        as 'physical') or seven; a Tree's on a floating base eight (its base last).
    what : str
        "Chain state" or "Tree state": the start of every message.

    Raises
    ------
    SolverError
        "<what>: unknown format" for another length or version, or a malformed base entry; the
        other entries are checked by the caller (``model_bindings.cpp``) and the C++ library.
    """
    lengths = (6, 7, 8) if what == "Tree state" else (6, 7)
    if len(state) not in lengths or not isinstance(state[0], int) or state[0] != 1:
        raise SolverError(f"{what}: unknown format")
    check = state[6] if len(state) >= 7 else "physical"
    if what == "Tree state":
        base = state[7] if len(state) == 8 else None
        if base is not None:
            try:
                base = (str(base[0]), [float(x) for x in base[1]])
            except (TypeError, ValueError, IndexError):
                base = None, []
            if len(base) != 2 or not isinstance(base[0], str) or len(base[1]) != 13:
                raise SolverError(f"{what}: malformed base entry (kind, 13 inertia doubles)")
        return (state[1], state[2], state[3], state[4], state[5]), check, base
    segments = state[1]
    if isinstance(segments, Sequence) and not isinstance(segments, (str, bytes)):
        segments = [(segment, -1) for segment in segments]  # a chain's parent index is unused
    return (state[4], segments, state[2], state[3], state[5]), check, None


def _urdf_text(source) -> str:
    """``from_urdf``'s ``source`` (URDF XML text or a file path: str or os.PathLike) as a str.

    Raises
    ------
    SolverError
        For any other type.
    """
    if not isinstance(source, str) and not hasattr(source, "__fspath__"):
        raise SolverError("source must be URDF XML text or a file path")
    return str(os.fspath(source))


def _chain_repr(self: Chain) -> str:
    """``<vereshchagin.Chain with 7 segments, 7 joints>``."""
    return f"<vereshchagin.Chain with {self.n_segments} segments, {self.n_joints} joints>"


def _tree_repr(self: Tree) -> str:
    """``<vereshchagin.Tree with 19 segments, 19 joints, base 'base'>``."""
    return f"<vereshchagin.Tree with {self.n_segments} segments, {self.n_joints} joints, base '{self.root_link}'>"


def _joint_property(model: str, field: int) -> property:
    """The property of field ``field`` of every joint record of a ``model`` ("Chain" or "Tree")."""

    def get(self):
        values = [record[field] for record in self._joints]
        return values if field < 2 else np.array(values, dtype=np.float64)

    return property(get, doc=DOCS[f"{model}.{_JOINT_FIELDS[field]}"])


# setattr because a type checker rejects assigning to a declared method.
setattr(Chain, "__repr__", _chain_repr)  # noqa: B010
setattr(Tree, "__repr__", _tree_repr)  # noqa: B010
for _cls in (Chain, Tree):
    for _field, _name in enumerate(_JOINT_FIELDS):
        setattr(_cls, _name, _joint_property(_cls.__name__, _field))

# State sizes of a model's base (docs/floating-base.md): (nq, nv) entries the base adds.
_BASE_SIZES = {"fixed": (0, 0), "free": (7, 6), "planar": (4, 3)}


def _tree_nq(self: Tree) -> int:
    return self.n_joints + _BASE_SIZES[self.base][0]


def _tree_nv(self: Tree) -> int:
    return self.n_joints + _BASE_SIZES[self.base][1]


setattr(Tree, "nq", property(_tree_nq, doc=DOCS["Tree.nq"]))  # noqa: B010
setattr(Tree, "nv", property(_tree_nv, doc=DOCS["Tree.nv"]))  # noqa: B010
