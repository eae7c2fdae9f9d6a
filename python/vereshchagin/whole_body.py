"""Whole-body least effort for underactuated robots: motor torques and support forces for a task.

On a floating base the base has no motor, and any tree may have joints without one (a mask). A
task on the base (``None`` as the segment: "base still" is ``alpha = I``, ``beta = [-gravity; 0]``
at rest), a hand or any segment is then realized only through the actuated joints and the
supports: :func:`least_effort` returns the torques with the least motor effort ``sum(tau^2)``
and the support forces (each in its polygonal friction cone, :class:`vereshchagin.Contact`'s
facets; where still not unique, the least ``sum |f|^2``), exactly (the C++
``WholeBodySolver``, whole_body.hpp), or raises :class:`vereshchagin.SolverError` naming what
fails when the task is not realizable with these supports. The math: docs "Floating and mobile
bases", section "Underactuation and whole-body least effort".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from ._core import SolverError
from .contacts import Contact


@dataclass(frozen=True)
class WholeBodyResult:
    """What :func:`least_effort` returns.

    Attributes
    ----------
    tau : numpy.ndarray, shape (nv,)
        Motor torques (N m or N): zero on a floating base's rows and on unactuated joints.
    contact_force : numpy.ndarray, shape (k, 3)
        Each support's force on the robot (N), base axes (world axes on a floating base).
    qdd : numpy.ndarray, shape (nv,)
        The accelerations (a floating base's first, base axes, as ``SolveResult.qdd``).
    effort : float
        ``sum(tau**2)``.
    residual : float
        Largest relative violation of the task rows, the supports and the cones (round-off).
    """

    tau: np.ndarray
    contact_force: np.ndarray
    qdd: np.ndarray
    effort: float
    residual: float


COM = "<centre of mass>"
"""The key of a centre-of-mass task in ``task`` (a free-flyer only): ``alpha`` (6, m) with zero
moment rows, against ``[c_ddot - gravity; 0]`` (world axes), so ``beta = alpha[:3].T @ (c_ddot -
gravity)`` for a desired centre-of-mass acceleration ``c_ddot``."""


def _frame(model: Any, key: Any, point: Any) -> tuple[int, np.ndarray]:
    """(segment index, the point in that segment's tip frame) for a segment or merged link name
    or index (None: the base, its own frame)."""
    point = np.zeros(3) if point is None else np.asarray(point, dtype=float).reshape(3)
    if key is None:
        return -1, point
    if isinstance(key, str) and key == COM:
        return -2, point
    try:
        index = int(model.segment_index(key))
        if isinstance(key, str):  # a merged link: its pose in the tip frame (constant)
            q0 = np.zeros(model.n_joints)
            offset = np.linalg.solve(model.fk(q0, index), model.fk(q0, key))
            point = offset[:3, :3] @ point + offset[:3, 3]
    except Exception as exc:  # an unknown name or index: say which
        raise SolverError(
            f"least_effort: unknown segment {key!r} (a segment or link name, an index, None: the base)"
        ) from exc
    return index, point


def _task_arrays(model: Any, task: Optional[Mapping[Any, Sequence[Any]]]) -> tuple[np.ndarray, list[np.ndarray]]:
    header, blocks = [], []
    for key, spec in (task or {}).items():
        alpha = np.asarray(spec[0], dtype=float)
        alpha = alpha.reshape(6, 1) if alpha.ndim == 1 else alpha
        beta = np.atleast_1d(np.asarray(spec[1], dtype=float)).reshape(-1, 1)
        segment, point = _frame(model, key, spec[2] if len(spec) > 2 else None)
        header.append([segment, *point])
        blocks += [alpha, beta]
    return np.asarray(header, dtype=float).reshape(-1, 4), blocks


def _support_rows(model: Any, supports: Sequence[Contact]) -> np.ndarray:
    rows = []
    for c in supports:
        if c.force is not None:
            raise SolverError("least_effort: supports only (a Contact without a force set-point)")
        segment, point = _frame(model, c.segment, c.point)
        rows.append([segment, *point, *c.normal, c.mu, c.facets])
    return np.asarray(rows, dtype=float).reshape(-1, 9)


def least_effort(
    solver: Any,
    q: Any,
    qd: Any,
    task: Optional[Mapping[Any, Sequence[Any]]] = None,
    supports: Sequence[Contact] = (),
    actuated: Optional[Any] = None,
    f_ext: Optional[Any] = None,
    tau_ff: Optional[Any] = None,
) -> WholeBodyResult:
    """Least motor effort realizing a task with sticking supports (see the module's description).

    Parameters
    ----------
    solver : vereshchagin.Solver
        Its model and gravity.
    q, qd : array_like, shape (nq,), (nv,)
        The state (a floating base's entries first, docs "Floating and mobile bases").
    task : dict, optional
        ``{segment: (alpha, beta)}`` or ``{segment: (alpha, beta, point)}``: ``alpha`` (6, m) unit
        constraint wrenches (base axes, moment about ``point``, a point in the named segment's or
        link's frame, default its origin), ``beta`` (m,) as in :meth:`Solver.solve` (spatial
        acceleration, ``-gravity`` included). ``None`` as the segment: the base body;
        :data:`COM`: the centre of mass (a free-flyer only).
    supports : sequence of vereshchagin.Contact
        Points that stick (zero classical acceleration), their forces in the friction cones.
        Segments by name (a merged link's frame too) or index (the segment's tip frame).
    actuated : array_like of bool, shape (n_joints,), optional
        Which joints have a motor (default: every joint; a floating base never).
    f_ext : array_like, shape (n_segments, 6), optional
        Wrenches on the segments by the environment (as :meth:`Solver.solve`).
    tau_ff : array_like, shape (nv,), optional
        Feed-forward torques (a floating base's rows: a wrench on the base).

    Returns
    -------
    WholeBodyResult

    Raises
    ------
    SolverError
        Wrong shapes or values, or the task is not realizable with these supports (the message
        says whether the rows contradict each other or the cones are too narrow).
    """
    model = solver.model
    nv = len(np.atleast_1d(qd))
    ns = solver.n_segments
    fe = np.zeros((ns, 6)) if f_ext is None else np.asarray(f_ext, dtype=float).reshape(ns, 6)
    ff = np.zeros(nv) if tau_ff is None else np.asarray(tau_ff, dtype=float).reshape(nv)
    act = np.zeros((0, 1)) if actuated is None else np.asarray(actuated, dtype=float).reshape(-1, 1)
    header, blocks = _task_arrays(model, task)
    args = [
        np.asarray(q, dtype=float).reshape(-1, 1),
        np.asarray(qd, dtype=float).reshape(-1, 1),
        np.ascontiguousarray(fe.T),
        ff.reshape(-1, 1),
        np.asarray(solver.gravity, dtype=float).reshape(3, 1),
        act,
        _support_rows(model, supports),
        header,
        *blocks,
    ]
    code, message, tau, forces, qdd, effort, residual = solver._whole_body(args)
    if code != 0:
        raise SolverError(f"least_effort: {message}")
    return WholeBodyResult(
        np.asarray(tau), np.asarray(forces).T.copy(), np.asarray(qdd), float(effort), float(residual)
    )
