"""Reference evaluations of Vereshchagin's max-min for static joint friction (Vukcevic 2018, ch. 5; docs/friction.md).

The friction-aware solve ``Solver.solve(..., friction=...)`` finds the optimum exactly (one solve,
response columns, a small box QP). The functions here are the slow references it is checked
against and the data behind the report's figures:

- :func:`gauss_function`: g(mu) = Z0(qdd(mu)) + mu^T W qdd(mu) by one frictionless solve with
  ``tau = tau_ff - W^T mu`` (report eq. 5.9);
- :func:`brute_force_grid`: the report's implementation, sampling mu on a grid over the box;
- :func:`vertex_enumeration`: the report's first hypothesis, the 2^k vertices mu_j = +-f_j
  (right only when the task leaves no freedom to the resting joints, report sec. 5.6).

Sign convention: mu is Vereshchagin's multiplier; the physical friction torque on joint j is
``-mu_j`` (what ``SolveResult.friction_torque`` reports).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import NamedTuple, Optional

import numpy as np

__all__ = [
    "Best",
    "GaussSample",
    "brute_force_grid",
    "evaluate",
    "free_accelerations",
    "gauss_function",
    "vertex_enumeration",
]


@dataclass(frozen=True)
class GaussSample:
    """One evaluation of the Gauss function at a friction multiplier.

    Attributes
    ----------
    mu : ndarray, shape (k,)
        Multipliers of the resting joints (physical friction torque ``-mu``).
    g : float
        g(mu) = Z0(qdd) + mu^T W qdd.
    z0 : float
        Frictionless acceleration energy Z0(qdd) = 1/2 (qdd - qdd_free)^T H (qdd - qdd_free).
    qdd : ndarray, shape (n,)
        qdd(mu), the solve with ``tau = tau_ff - W^T mu``.
    tau_command : ndarray, shape (n,)
        What the motors add to ``tau_ff - W^T mu`` to realise the task.
    """

    mu: np.ndarray
    g: float
    z0: float
    qdd: np.ndarray
    tau_command: np.ndarray


class Best(NamedTuple):
    """The best multiplier found by a search and its Gauss value.

    Attributes
    ----------
    mu : ndarray, shape (k,)
        Multipliers of the resting joints (N m; physical friction torque ``-mu``) with the largest
        g among the candidates searched.
    g : float
        Its Gauss value g(mu) (J/s^2, like the acceleration energy Z0).
    """

    mu: np.ndarray
    g: float


def _n_joints(solver) -> int:
    return int(solver.n_joints)


def _tau_ff(solver, tau_ff) -> np.ndarray:
    n = _n_joints(solver)
    return np.zeros(n) if tau_ff is None else np.asarray(tau_ff, float).reshape(n)


def _resting(solver, resting) -> np.ndarray:
    idx = np.atleast_1d(np.asarray(resting, dtype=int))
    n = _n_joints(solver)
    if idx.ndim != 1 or np.any(idx < 0) or np.any(idx >= n) or len(set(idx.tolist())) != idx.size:
        raise ValueError(f"resting must be distinct joint indices in [0, {n}), got {resting!r}")
    return idx


def _bounds(solver, f, resting: np.ndarray) -> np.ndarray:
    """Breakaway friction of the resting joints: ``f`` is a scalar, per joint (n,) or per resting
    joint (k,)."""
    n, k = _n_joints(solver), resting.size
    f = np.asarray(f, float)
    if f.ndim == 0:
        out = np.full(k, float(f))
    elif f.size == n:
        out = f.reshape(n)[resting]
    elif f.size == k:
        out = f.reshape(k)
    else:
        raise ValueError(f"f must be a scalar or have {n} (joints) or {k} (resting joints) entries")
    if np.any(out < 0):
        raise ValueError("breakaway friction must be >= 0")
    return out


def free_accelerations(solver, q, qd, f_ext=None, tau_ff=None) -> np.ndarray:
    """Unconstrained accelerations ``qdd_free`` (no task, no friction) with ``tau_ff``.

    Parameters
    ----------
    solver : Solver
    q, qd : array_like, shape (n,)
    f_ext : array_like, shape (n_segments, 6), optional
    tau_ff : array_like, shape (n,), optional

    Returns
    -------
    ndarray, shape (n,)
    """
    return np.asarray(solver.solve(q, qd, f_ext=f_ext, tau_ff=_tau_ff(solver, tau_ff)).qdd, float)


def evaluate(
    solver, q, qd, mu, resting, alpha=None, beta=None, f_ext=None, tau_ff=None, qdd_free: Optional[np.ndarray] = None
) -> GaussSample:
    """Evaluate g(mu) and the motion it gives by one frictionless solve.

    Parameters
    ----------
    solver : Solver
    q, qd : array_like, shape (n,)
    mu : array_like, shape (k,)
        Friction multipliers of the joints in ``resting`` (physical friction torque ``-mu``).
    resting : sequence of int, length k
        The joints selected by W (those at rest).
    alpha, beta, f_ext, tau_ff : optional
        As in :meth:`Solver.solve`. If joints move, ``tau_ff`` should already contain their
        kinetic friction ``-fk sign(qd)`` (the friction-aware solve adds it before optimising).
    qdd_free : ndarray, shape (n,), optional
        :func:`free_accelerations` for the same state, to save a solve when sampling.

    Returns
    -------
    GaussSample

    Notes
    -----
    With ``tau = tau_ff - W^T mu`` the task solve gives ``H qdd + C = tau + tau_cmd``, and the
    free motion ``H qdd_free + C = tau_ff``, so ``H (qdd - qdd_free) = tau_cmd - W^T mu`` and
    ``Z0 = 1/2 (qdd - qdd_free)^T (tau_cmd - W^T mu)`` needs no mass matrix.
    """
    idx = _resting(solver, resting)
    mu = np.atleast_1d(np.asarray(mu, float)).reshape(idx.size)
    tff = _tau_ff(solver, tau_ff)
    if qdd_free is None:
        qdd_free = free_accelerations(solver, q, qd, f_ext, tff)
    wtmu = np.zeros_like(tff)
    wtmu[idx] = mu
    res = solver.solve(q, qd, alpha=alpha, beta=beta, f_ext=f_ext, tau_ff=tff - wtmu)
    qdd = np.asarray(res.qdd, float)
    tau_cmd = np.asarray(res.tau_command, float)
    z0 = 0.5 * float((qdd - qdd_free) @ (tau_cmd - wtmu))
    g = z0 + float(mu @ qdd[idx])
    return GaussSample(mu=mu, g=g, z0=z0, qdd=qdd, tau_command=tau_cmd)


def gauss_function(solver, q, qd, mu, resting, alpha=None, beta=None, f_ext=None, tau_ff=None) -> float:
    """The Gauss function of the max-min, g(mu) = Z0(qdd(mu)) + mu^T W qdd(mu) (report eq. 5.9).

    Parameters
    ----------
    solver : Solver
    q, qd : array_like, shape (n,)
    mu : array_like, shape (k,)
        Friction multipliers of the joints in ``resting`` (physical friction torque ``-mu``).
    resting : sequence of int, length k
    alpha, beta, f_ext, tau_ff : optional
        As in :meth:`Solver.solve`.

    Returns
    -------
    float
        g(mu); concave in mu, its maximum over the box |mu_j| <= f_j equals the
        ``gauss_value`` of the friction-aware solve.

    See Also
    --------
    evaluate : the same with the motion and the motor command.
    """
    return evaluate(solver, q, qd, mu, resting, alpha, beta, f_ext, tau_ff).g


def _best(solver, q, qd, candidates, resting, alpha, beta, f_ext, tau_ff) -> Best:
    tff = _tau_ff(solver, tau_ff)
    free = free_accelerations(solver, q, qd, f_ext, tff)
    best_mu, best_g = None, -np.inf
    for mu in candidates:
        g = evaluate(solver, q, qd, mu, resting, alpha, beta, f_ext, tff, qdd_free=free).g
        if g > best_g:
            best_mu, best_g = np.asarray(mu, float), g
    if best_mu is None:
        raise ValueError("no candidate multiplier has a Gauss value above -inf (empty set or NaN values)")
    return Best(best_mu, best_g)


def brute_force_grid(
    solver, q, qd, f, resting, alpha=None, beta=None, f_ext=None, tau_ff=None, points: int = 201
) -> Best:
    """Maximise g over a regular grid of the box |mu_j| <= f_j (the report's implementation).

    Parameters
    ----------
    solver : Solver
    q, qd : array_like, shape (n,)
    f : float or array_like
        Breakaway friction, per joint (n,) or per resting joint (k,).
    resting : sequence of int
        One or two resting joints (the grid has ``points ** k`` nodes).
    alpha, beta, f_ext, tau_ff : optional
        As in :meth:`Solver.solve`.
    points : int
        Grid nodes per joint, end points included.

    Returns
    -------
    Best
        ``(mu, g)`` of the best node (the first one on ties). It is off the optimum by up to
        the grid step.
    """
    idx = _resting(solver, resting)
    if idx.size not in (1, 2):
        raise ValueError("grid sampling is for 1 or 2 resting joints")
    if points < 2:
        raise ValueError("points must be >= 2")
    fb = _bounds(solver, f, idx)
    axes = [np.linspace(-fj, fj, points) for fj in fb]
    return _best(solver, q, qd, itertools.product(*axes), idx, alpha, beta, f_ext, tau_ff)


def vertex_enumeration(solver, q, qd, f, resting, alpha=None, beta=None, f_ext=None, tau_ff=None) -> Best:
    """Maximise g over the 2^k vertices mu_j = +-f_j of the box (the report's sec. 5.6 hypothesis).

    Exact only when g is linear on the box (the task fixes the resting joints' accelerations,
    e.g. the fully constrained case of report fig. 5.5); otherwise the optimum may be inside.

    Parameters
    ----------
    solver : Solver
    q, qd : array_like, shape (n,)
    f : float or array_like
        Breakaway friction, per joint (n,) or per resting joint (k,).
    resting : sequence of int, length k
    alpha, beta, f_ext, tau_ff : optional
        As in :meth:`Solver.solve`.

    Returns
    -------
    Best
        ``(mu, g)`` of the best vertex (the first one on ties, ``-f`` before ``+f``).
    """
    idx = _resting(solver, resting)
    fb = _bounds(solver, f, idx)
    vertices = itertools.product(*[(-fj, fj) for fj in fb])
    return _best(solver, q, qd, vertices, idx, alpha, beta, f_ext, tau_ff)
