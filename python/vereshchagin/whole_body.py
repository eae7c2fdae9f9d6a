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


def _task_blocks(task: Optional[Mapping[Any, Sequence[Any]]]) -> list[tuple]:
    """The task as (label, segment, key, point, alpha, beta) tuples: segment -1 (the base) or -2
    (:data:`COM`) with key None, else 0 and the key, resolved by the C++ call as
    :meth:`Solver.solve` resolves ``constraints`` keys (a merged link's point moved into its
    segment's tip frame); the arrays are checked there too."""
    if task is None:
        return []
    if not isinstance(task, Mapping):
        raise SolverError("task must be a dict {segment: (alpha, beta)} or {segment: (alpha, beta, point)}")
    blocks = []
    for key, spec in task.items():
        label = f"task[{key!r}]"
        if not isinstance(spec, (tuple, list)) or len(spec) not in (2, 3):
            raise SolverError(f"{label} must be a pair (alpha (6, m), beta (m,)) or a triple (alpha, beta, point)")
        point = spec[2] if len(spec) > 2 else _ORIGIN
        special = key is None or (isinstance(key, str) and key == COM)
        segment = (-1 if key is None else -2) if special else 0
        blocks.append((label, segment, None if special else key, point, spec[0], spec[1]))
    return blocks


_ORIGIN = np.zeros(3)
_ORIGIN.flags.writeable = False


def _mask(actuated: Any) -> Any:
    """``actuated`` as numbers (bool arrays as 0/1); shape and values are checked by the C++ call."""
    if actuated is None:
        return None
    try:
        mask = np.asarray(actuated)
    except (TypeError, ValueError) as exc:
        raise SolverError(f"actuated must be an array of bool, one per joint: {exc}") from None
    return mask.astype(np.float64) if mask.dtype == bool else actuated


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
    supports : list or tuple of vereshchagin.Contact
        Points that stick (zero classical acceleration), their forces in the friction cones; no
        force set-points. Segments by name (a merged link's frame too) or index (the segment's tip
        frame). Read as :meth:`Solver.solve` reads ``contacts`` (messages name ``supports[k]``).
    actuated : array_like of bool, shape (n_joints,), optional
        Which joints have a motor (default: every joint; a floating base never).
    f_ext : array_like, shape (n_segments, 6), or dict, optional
        Wrenches on the segments by the environment, exactly as :meth:`Solver.solve` takes them:
        one row ``[force, moment]`` per segment (base axes, moment about the segment's tip
        origin), or ``{segment or link name or index: wrench (6,)}`` (moment about that frame's
        origin).
    tau_ff : array_like, shape (nv,), optional
        Feed-forward torques (a floating base's rows: a wrench on the base), as :meth:`Solver.solve`.

    Returns
    -------
    WholeBodyResult

    Raises
    ------
    SolverError
        Wrong shapes or values (``q``, ``qd``, ``f_ext``, ``tau_ff`` and ``supports`` with the
        messages of :meth:`Solver.solve`), or the task is not realizable with these supports (the
        message says whether the rows contradict each other or the cones are too narrow).

    Notes
    -----
    The C++ ``WholeBodySolver`` is kept with ``solver`` (built at the first call, rebuilt larger
    for more supports or task rows than it has room for); nothing of one call influences the next.
    Calls on one ``solver`` are serialized like its solves (the GIL is released while solving).
    """
    tau, forces, qdd, effort, residual = solver._whole_body(
        q, qd, f_ext, tau_ff, _mask(actuated), supports, _task_blocks(task)
    )
    return WholeBodyResult(tau, forces.T.copy(), qdd, float(effort), float(residual))
