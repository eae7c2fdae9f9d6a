"""The Python face of the C++ solver: documentation and the batch result type."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core


@dataclass(frozen=True)
class BatchResult:
    """Results of :meth:`Solver.solve_batch`, one row per input row.

    Attributes
    ----------
    qdd, tau_command : ndarray, shape (B, n)
    nu : ndarray, shape (B, m_max)
        Rows with fewer constraints are padded with NaN.
    link_acc : ndarray, shape (B, n_segments + 1, 6)
    constraint_rank : ndarray of int, shape (B,)
    smallest_singular_value : ndarray, shape (B,)
    """

    qdd: np.ndarray
    tau_command: np.ndarray
    nu: np.ndarray
    link_acc: np.ndarray
    constraint_rank: np.ndarray
    smallest_singular_value: np.ndarray


class Solver(_core.Solver):
    """Acceleration-constrained hybrid dynamics (Popov-Vereshchagin) of a serial chain.

    Parameters
    ----------
    chain : Chain
        Copied; later changes to ``chain`` do not affect the solver.
    gravity : array_like, shape (3,)
        Physical gravity in the base frame, m/s^2 (default ``[0, 0, -9.81]``). Internally the base
        accelerates by ``-gravity``, so ``beta`` and ``link_acc`` include that acceleration.
    rcond : float
        Eigenvalues of the constraint coupling matrix below ``rcond`` times the largest are
        treated as zero (truncated pseudo-inverse; the rank is reported).
    damping : float, optional
        If given, use damped least squares ``lambda / (lambda^2 + damping^2)`` instead.

    Notes
    -----
    ``solve(q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None)`` returns a
    :class:`SolveResult`:

    - ``q``, ``qd``: (n,) joint positions (rad or m) and velocities.
    - ``alpha``: (6, m), m <= 6, unit constraint wrenches on the last segment, rows
      ``[force; moment]``, base-frame axes, moment about the last segment's tip origin.
    - ``beta``: (m,) acceleration set-points ``alpha.T @ a_N`` where ``a_N`` is the last segment's
      spatial acceleration (base axes, tip origin) *including* ``-gravity``: holding the tip still
      along z needs ``beta = 9.81``, not 0.
    - ``f_ext``: (n_segments, 6) wrench ``[force, moment]`` applied to each segment by the
      environment, base-frame axes, moment about that segment's tip origin (N, N m).
    - ``tau_ff``: (n,) feed-forward joint torques (N m or N).
    - ``constraints``: ``{segment: (alpha_i (6, m_i), beta_i (m_i,))}`` acceleration constraints on
      any segments (Shakhimardanov's extension), keyed by segment name or index (negative counts
      from the end), with the end-segment conventions at that segment: base-frame axes, moment
      about *that segment's* tip origin, ``beta_i`` including ``-gravity``. At most 6 columns per
      segment; any number of segments. Combines with ``alpha``/``beta`` (the last segment).

    Result fields: ``qdd`` (n,); ``tau_command`` (n,) the torques the motors must add to
    ``tau_ff`` to realise ``qdd`` (``-sum_i J_i^T alpha_i nu_i`` over constrained segments);
    ``nu`` (m,) constraint magnitudes (the wrench on the last segment is ``-alpha @ nu``), with
    ``constraints`` the end-segment ``alpha`` columns first, then each entry's in dict order
    (``segment_nu`` maps each ``constraints`` key to its own part); ``link_acc`` (n_segments + 1, 6) spatial
    accelerations ``[linear, angular]`` of the base and each segment's tip (base axes, tip
    origin, including ``-gravity``); ``constraint_rank``; ``smallest_singular_value``.

    ``friction=Friction(...)`` (or ``True`` for the chain's URDF values) adds static friction:
    the exact max-min of report 000. Then also ``friction_torque`` (physical, opposes motion),
    ``limit_torque`` (reactions of joint limits), ``status`` (0 moving, 1 stick, 2 slip +,
    3 slip -), ``gauss_value`` (Z0(qdd) + sum f |qdd| over resting joints) and ``iterations``;
    ``tau_command`` is what the motors add to ``tau_ff`` with friction acting, and the least such
    command when friction could hold in several ways.
    The GIL is released while solving; use one solver per thread for parallel work.
    """

    def solve_batch(self, q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None) -> BatchResult:
        """Solve B states at once.

        Parameters
        ----------
        q, qd : array_like, shape (B, n)
        alpha, beta, f_ext, tau_ff : array_like, optional
            Either one value for all rows (shapes as in :meth:`solve`) or with a leading axis B.

        Returns
        -------
        BatchResult
        """
        return BatchResult(**super().solve_batch(q, qd, alpha, beta, f_ext, tau_ff))

    def response_columns(self, joints):
        """Affine response of the last solve to unit joint torques.

        Parameters
        ----------
        joints : sequence of int, length k

        Returns
        -------
        dqdd, dtau_command : ndarray, shape (n, k)
            Column c is the change of ``qdd`` and of ``tau_command`` per unit of ``tau_ff`` at
            joint ``joints[c]`` (columns of the constrained inverse inertia G).
        """
        return super().response_columns(joints)
