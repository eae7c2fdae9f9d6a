"""Helpers to state a Cartesian task on the chain's tip as the solver's ``alpha`` and ``beta``.

The solver constrains ``alpha.T @ a_N = beta``, where ``a_N`` is the tip's *spatial* acceleration
(base-frame axes, tip origin) *including* the base acceleration ``-gravity`` (see
:class:`vereshchagin.Solver`). Controllers usually think in the *classical* acceleration of the
tip origin and in pose errors; these functions translate.

- :func:`directions`: ``alpha`` from axis names (``"x"``, ``"ry"``, ...) or 6-vectors, optionally
  along the axes of a rotated frame;
- :func:`beta_for`: ``beta`` from a desired classical acceleration and the tip twist;
- :func:`pose_error`, :func:`twist_error`: errors for a PD law, like KDL's ``diff``;
- :class:`Task`: the three steps together.

Everything is plain numpy.
"""

from __future__ import annotations

from typing import Sequence, Union

import numpy as np

from ._core import SolverError, _beta_for

__all__ = ["Task", "beta_for", "directions", "pose_error", "twist_error"]

_NAMES = {"x": 0, "y": 1, "z": 2, "rx": 3, "ry": 4, "rz": 5}
_G_EARTH = (0.0, 0.0, -9.81)


def _real_array(value, what: str) -> np.ndarray:
    """A float64 array of real numbers, finite (SolverError naming ``what`` otherwise)."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise SolverError(f"{what} must be an array of real numbers: {e}") from None
    if a.dtype.kind not in "iuf":
        raise SolverError(f"{what} must hold real numbers (int or float), got dtype {a.dtype}")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise SolverError(f"{what} must be finite (no NaN or Inf)")
    return a


def _proper_rotation(R: np.ndarray, what: str) -> np.ndarray:
    """R itself if it is a rotation matrix (orthonormal to 1e-6, det +1), else SolverError."""
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0.0:
        raise SolverError(f"{what}'s rotation part is not a rotation matrix (orthonormal, det +1)")
    return R


def _rotation_of(frame) -> np.ndarray:
    """The 3x3 rotation of a 3x3 rotation or 4x4 pose, validated."""
    F = _real_array(frame, "frame")
    if F.shape == (4, 4):
        R = F[:3, :3]
    elif F.shape == (3, 3):
        R = F
    else:
        raise SolverError(f"frame must be a 3x3 rotation or a 4x4 pose, got shape {F.shape}")
    return _proper_rotation(R, "frame")


def directions(names: Union[str, Sequence], frame=None) -> np.ndarray:
    """Constraint directions ``alpha`` (6, m) on the tip, base-frame axes.

    Parameters
    ----------
    names : str or sequence
        Each entry is ``"x"``, ``"y"``, ``"z"`` (unit force along that axis: constrains the linear
        acceleration), ``"rx"``, ``"ry"``, ``"rz"`` (unit moment: constrains the angular
        acceleration), or a 6-vector ``[force; moment]`` (normalised to unit length). A single
        string is one direction.
    frame : array_like, shape (3, 3) or (4, 4), optional
        Rotation, or pose, of a frame in the base frame. If given, the names refer to this frame's
        axes and 6-vectors are expressed in its axes; the result is rotated into base axes. Only
        the orientation is used: moments are always about the tip origin.

    Returns
    -------
    ndarray, shape (6, m)

    Raises
    ------
    SolverError
        Unknown name, a 6-vector of the wrong size, zero or non-finite, or an invalid frame.
    """
    if isinstance(names, str):
        names = [names]
    R = np.eye(3) if frame is None else _rotation_of(frame)
    cols = []
    for entry in names:
        if isinstance(entry, str):
            key = entry.strip().lower()
            if key not in _NAMES:
                raise SolverError(f"unknown direction {entry!r}; use one of {sorted(_NAMES)} or a 6-vector")
            v = np.zeros(6)
            v[_NAMES[key]] = 1.0
        else:
            v = np.asarray(entry, dtype=float).reshape(-1)
            if v.shape != (6,):
                raise SolverError(f"a direction vector must have 6 entries [force; moment], got {v.shape}")
            norm = np.linalg.norm(v)
            if not np.isfinite(norm) or norm == 0.0:
                raise SolverError(f"a direction vector must be finite and nonzero, got {v}")
            v = v / norm
        cols.append(np.concatenate([R @ v[:3], R @ v[3:]]))
    return np.ascontiguousarray(np.array(cols, dtype=float).reshape(-1, 6).T)  # C order: the solve views it in place


def beta_for(alpha, a_desired, twist, gravity=_G_EARTH) -> np.ndarray:
    """``beta`` that makes the tip reach a desired *classical* acceleration along ``alpha``.

    Parameters
    ----------
    alpha : array_like, shape (6, m) or (6,)
        Constraint directions (base axes, moments about the tip origin).
    a_desired : array_like, shape (6,)
        ``[a_lin; a_ang]``: classical acceleration of the tip origin (the second time derivative of
        its position, m/s^2) and angular acceleration (rad/s^2), base axes. Components outside the
        span of ``alpha`` are ignored.
    twist : array_like, shape (6,) or (N, 6)
        Tip twist ``[v; omega]`` (velocity of the tip origin, angular velocity), base axes, e.g.
        ``chain.twist(q, qd)``; N rows (``chain.twist`` of (N, n) states) give N rows of beta,
        with ``a_desired`` one (6,) for all or (N, 6).
    gravity : array_like, shape (3,)
        Physical gravity, the same as the solver's (default ``[0, 0, -9.81]``).

    Returns
    -------
    ndarray, shape (m,) or (N, m)
        ``alpha.T @ [a_lin - omega x v - gravity; a_ang]`` (computed in C++, vereshchagin/task.hpp).

    Raises
    ------
    SolverError
        Wrong shapes, NaN or Inf in any input, or a result that overflows.

    Notes
    -----
    The solver's ``a_N`` is a spatial acceleration: its linear part is the acceleration of the
    body point passing through the tip origin *at this instant*, not of the tip origin as it
    moves, so ``a_lin_spatial = a_classical - omega x v``. The angular parts agree. And the solver
    accelerates the base by ``-gravity`` instead of applying weights, which adds ``-gravity`` to
    every linear acceleration it reports or constrains. Holding the tip still (``a_desired = 0``)
    therefore needs ``beta = alpha.T @ [-omega x v - gravity; 0]``, not 0.
    """
    beta = _beta_for(alpha, a_desired, twist, gravity)  # None: not plainly valid, checked below
    if beta is not None:
        return beta
    A = _real_array(alpha, "alpha")
    if A.ndim == 1:
        A = A.reshape(6, 1) if A.shape == (6,) else A
    if A.ndim != 2 or A.shape[0] != 6:
        raise SolverError(f"alpha must have shape (6, m), got {A.shape}")
    a = _real_array(a_desired, "a_desired").reshape(-1)
    t = _real_array(twist, "twist").reshape(-1)
    g = _real_array(gravity, "gravity").reshape(-1)
    if a.shape != (6,) or t.shape != (6,) or g.shape != (3,):
        raise SolverError(f"a_desired and twist must have 6 entries and gravity 3, got {a.shape}, {t.shape}, {g.shape}")
    with np.errstate(over="ignore", invalid="ignore"):
        spatial = np.concatenate([a[:3] - np.cross(t[3:], t[:3]) - g, a[3:]])
        beta = A.T @ spatial
    if not np.all(np.isfinite(beta)):
        raise SolverError("beta_for: the result overflows the double range (inputs too large)")
    return beta


def _quaternion(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix (Shepperd's method)."""
    t = np.trace(R)
    d = np.diag(R)
    k = int(np.argmax([t, d[0], d[1], d[2]]))
    if k == 0:
        w = 0.5 * np.sqrt(max(1.0 + t, 0.0))
        s = 0.25 / w
        q = np.array([w, (R[2, 1] - R[1, 2]) * s, (R[0, 2] - R[2, 0]) * s, (R[1, 0] - R[0, 1]) * s])
    else:
        i = k - 1
        j, l = (i + 1) % 3, (i + 2) % 3
        r = 0.5 * np.sqrt(max(1.0 + 2.0 * d[i] - t, 0.0))
        s = 0.25 / r
        q = np.empty(4)
        q[0] = (R[l, j] - R[j, l]) * s
        q[1 + i] = r
        q[1 + j] = (R[j, i] + R[i, j]) * s
        q[1 + l] = (R[l, i] + R[i, l]) * s
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


def _rotvec(R: np.ndarray) -> np.ndarray:
    """Axis * angle of a rotation matrix, angle in [0, pi]."""
    q = _quaternion(R)
    w, v = q[0], q[1:]
    s = np.linalg.norm(v)
    if s < 1e-8:  # angle = 2 atan2(s, w) ~ 2 s / w (1 - s^2 / (3 w^2)), w ~ 1
        return v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w))
    return v * (2.0 * np.arctan2(s, w) / s)


def _pose(T, what: str) -> np.ndarray:
    """A finite 4x4 homogeneous pose with a proper rotation (SolverError otherwise)."""
    T = _real_array(T, what)
    if T.shape != (4, 4):
        raise SolverError(f"{what} must be a finite 4x4 pose, got shape {T.shape}")
    if np.any(T[3] != (0.0, 0.0, 0.0, 1.0)):
        raise SolverError(f"{what} must be a homogeneous pose: its last row must be [0, 0, 0, 1], got {T[3]}")
    _proper_rotation(T[:3, :3], what)
    return T


def pose_error(T_current, T_desired) -> np.ndarray:
    """Pose error ``[p_d - p_c; axis * angle of R_d R_c^T]``, base axes (KDL's ``diff(current, desired)``).

    Parameters
    ----------
    T_current, T_desired : array_like, shape (4, 4)
        Poses in the base frame: finite, last row ``[0, 0, 0, 1]``, rotation part orthonormal
        (to 1e-6) with determinant +1; anything else raises :class:`SolverError`.

    Returns
    -------
    ndarray, shape (6,)
        Translation difference, then the rotation vector (angle in [0, pi]) that turns the current
        orientation into the desired one, about base axes. Accurate near 0 and pi (computed via a
        unit quaternion); at exactly pi the sign of the axis is arbitrary.
    """
    Tc = _pose(T_current, "T_current")
    Td = _pose(T_desired, "T_desired")
    return np.concatenate([Td[:3, 3] - Tc[:3, 3], _rotvec(Td[:3, :3] @ Tc[:3, :3].T)])


def twist_error(t_current, t_desired) -> np.ndarray:
    """Twist error ``t_desired - t_current``, (6,), both ``[v; omega]`` in base axes."""
    c = _real_array(t_current, "t_current").reshape(-1)
    d = _real_array(t_desired, "t_desired").reshape(-1)
    if c.shape != (6,) or d.shape != (6,):
        raise SolverError(f"twists must have 6 entries, got {c.shape} and {d.shape}")
    with np.errstate(over="ignore"):
        e = d - c
    if not np.all(np.isfinite(e)):
        raise SolverError("twist_error: the result overflows the double range")
    return e


class Task:
    """Constrained directions on the tip, solved for a desired classical acceleration.

    Parameters
    ----------
    names, frame
        As in :func:`directions`.

    Attributes
    ----------
    alpha : ndarray, shape (6, m)
    """

    def __init__(self, names, frame=None):
        self.alpha = directions(names, frame)

    def solve(self, solver, chain, q, qd, a_desired, **kwargs):
        """Solve for the tip's classical acceleration ``a_desired`` along this task's directions.

        ``solver.solve(q, qd, self.alpha, a_desired=a_desired, **kwargs)``: the solve forms
        ``beta`` (what :func:`beta_for` computes, from the tip twist at ``(q, qd)`` and the
        solver's gravity) inside its own sweep. ``chain`` is the chain the solver was built from
        (kept for compatibility: the solver's own model is used); ``kwargs`` (``f_ext``,
        ``tau_ff``, ``friction`` ...) go to :meth:`Solver.solve`.
        """
        return solver.solve(q, qd, self.alpha, a_desired=a_desired, **kwargs)
