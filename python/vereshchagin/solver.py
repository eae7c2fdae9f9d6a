"""The Python face of the C++ solver: documentation and the batch result type."""

from __future__ import annotations

import operator
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Optional

import numpy as np

from . import _core

# The most threads solve_batch starts (threads= beyond it is refused): each costs an OS thread and
# a workspace (a solver's Data), and no machine gains from more.
_MAX_BATCH_THREADS = 256


def _int_option(value, name: str, lo: int, hi: int, bound: str, hint: str, with_type: bool) -> int:
    """``value`` as an int in ``lo .. hi`` (an int or anything with ``__index__``, not a bool).

    Raises
    ------
    SolverError
        "<name> must be an int<bound> <hint>, got [type] repr" or "<name> must be in lo .. hi
        <hint>, got value"; a failing ``__index__`` raises its own error.
    """
    if isinstance(value, bool) or not hasattr(type(value), "__index__"):
        kind = f"{type(value).__name__} " if with_type else ""
        raise _core.SolverError(f"{name} must be an int{bound} {hint}, got {kind}{value!r}")
    index = operator.index(value)
    if not lo <= index <= hi:
        raise _core.SolverError(f"{name} must be in {lo} .. {hi} {hint}, got {value}")
    return index


@dataclass(frozen=True)
class BatchResult:
    """Results of :meth:`Solver.solve_batch`: the fields of :class:`SolveResult` with a leading row axis.

    Row ``b`` equals ``Solver.solve`` of row ``b``'s arguments bit for bit.

    Attributes
    ----------
    qdd : ndarray, shape (B, n)
        Joint accelerations, rad/s^2 or m/s^2.
    tau_command : ndarray, shape (B, n)
        Motor torques added to ``tau_ff`` that realise ``qdd`` (N m or N).
    nu : ndarray, shape (B, m)
        Constraint magnitudes (end-segment ``alpha`` columns first, then each ``constraints``
        entry's).
    link_acc : ndarray, shape (B, n_segments + 1, 6)
        Spatial accelerations ``[linear, angular]`` of the base and each segment tip (base axes,
        tip origins, including ``-gravity``).
    constraint_rank : ndarray of int32, shape (B,)
        Rank of each row's coupling matrix.
    smallest_singular_value : ndarray, shape (B,)
        Smallest eigenvalue of each row's coupling matrix.
    friction_torque, limit_torque : ndarray, shape (B, n), or None
        With ``friction``: physical friction torques and joint-limit reactions (NaN in rows
        solved without friction). None when no row has friction.
    status : ndarray of int32, shape (B, n), or None
        0 moving, 1 sticking, 2 slipping +, 3 slipping - (-1 in rows without friction).
    gauss_value : ndarray, shape (B,), or None
        Gauss' function at each row's optimum (NaN in rows without friction).
    iterations : ndarray of int32, shape (B,), or None
        Iterations of each row's friction max-min (-1 in rows without friction).
    segment_nu : dict or None
        ``{key: (B, m_i) view of nu}`` for each ``constraints`` key.
    contact_force : ndarray, shape (B, k, 3)
        With ``contacts`` (k of them, every row's): the force each surface applies to the robot,
        base axes, N (k = 0 without contacts).
    contact_status : ndarray of int32, shape (B, k)
        :class:`ContactStatus` codes: 0 separating, 1 sticking, 2 sliding.
    contact_outcome : ndarray of int32, shape (B,)
        :class:`ContactOutcome` codes: 0 none, 1 unique, 2 consistent.
    """

    qdd: np.ndarray
    tau_command: np.ndarray
    nu: np.ndarray
    link_acc: np.ndarray
    constraint_rank: np.ndarray
    smallest_singular_value: np.ndarray
    friction_torque: Optional[np.ndarray] = None
    limit_torque: Optional[np.ndarray] = None
    status: Optional[np.ndarray] = None
    gauss_value: Optional[np.ndarray] = None
    iterations: Optional[np.ndarray] = None
    segment_nu: Optional[dict] = None
    contact_force: Optional[np.ndarray] = None
    contact_status: Optional[np.ndarray] = None
    contact_outcome: Optional[np.ndarray] = None


class Solver(_core.Solver):
    """Acceleration-constrained hybrid dynamics (Popov-Vereshchagin) of a serial chain or a tree.

    Parameters
    ----------
    model : Chain or Tree
        Copied; later changes to it do not affect the solver. On a :class:`Tree` the segments
        and joints follow the tree's order (depth-first preorder, see :class:`Tree`); constraints
        go through ``constraints=`` (a tree has no last segment for ``alpha``/``beta``), on any
        segments or merged links of any branches, coupled through their common ancestors.
    gravity : array_like, shape (3,)
        Physical gravity in the base frame, m/s^2 (default ``[0, 0, -9.81]``). Internally the base
        accelerates by ``-gravity``, so ``beta`` and ``link_acc`` include that acceleration.
    rcond : float
        Eigenvalues of the constraint coupling matrix below ``rcond`` times its scale are
        treated as zero (truncated pseudo-inverse; the rank is reported).
    damping : float, optional
        If given, use damped least squares ``lambda / (lambda^2 + damping^2)`` instead.
    inertia_check : {None, 'physical', 'joint_space'}
        'physical': every body must be a rigid body (checked once). 'joint_space': identified
        models (e.g. the published KUKA LWR 4 parameters) whose link inertias need not be
        positive semi-definite; each solve then checks that every articulated joint inertia is
        positive (H(q) positive definite) and names the joint when not. None (default): the
        check the model was built with (``model.inertia_check``: 'joint_space' for a chain from
        ``Chain.from_kdl``, as KDL accepts it, or built with that option; else 'physical').
    max_constraints : int, optional
        Constraint columns one solve may have in all; the coupling workspace is sized for them
        once (memory O(n m + m^2), n segments). Default: the smaller of 6 per segment and 256.
        A solve with more columns raises :class:`SolverError` naming this argument.

    Notes
    -----
    :meth:`solve` solves one state and returns a :class:`SolveResult`; :meth:`solve_batch`
    solves many (optionally on several threads); :meth:`response_columns` gives the affine
    response of the last solve to feed-forward torques.

    Conventions (those of Orocos KDL's ``ChainHdSolver_Vereshchagin``): spatial vectors are
    ``[linear; angular]`` and wrenches ``[force; moment]``, in base-frame axes with moments and
    accelerations about each segment's tip origin; ``beta`` includes ``-gravity``; ``f_ext`` is one
    row per segment. Segments are addressed by segment name, by the name of a link merged into a
    segment by fixed joints (tool frames), or by index (negative from the end); the base only by
    its link name. Solvers, chains and results pickle and deep-copy. The GIL is released while
    solving.
    """

    def __init__(
        self, model, gravity=(0.0, 0.0, -9.81), rcond=1e-12, damping=None, inertia_check=None, max_constraints=None
    ):
        if not isinstance(model, (_core.Chain, _core.Tree)):
            kind = type(model).__name__
            raise TypeError(f"Solver(model): model must be a vereshchagin.Chain or vereshchagin.Tree, got {kind}")
        if max_constraints is not None:
            max_constraints = _int_option(
                max_constraints, "max_constraints", 1, 1 << 24, " >= 1", "(None: the default)", False
            )
        if inertia_check is None:  # the check the model was built with
            inertia_check = model.inertia_check
        super().__init__(model, gravity, rcond, damping, inertia_check, max_constraints)
        self._options = (float(rcond), damping, max_constraints)  # what __reduce__ needs besides the properties

    def solve_batch(
        self,
        q,
        qd,
        alpha=None,
        beta=None,
        f_ext=None,
        tau_ff=None,
        friction=None,
        constraints=None,
        f_ext_pass_through=None,
        tau_ff_pass_through=None,
        threads=1,
        a_desired=None,
        contacts=None,
        time_step=None,
        contact_velocity_tolerance=None,
        contact_max_pivots=None,
    ) -> BatchResult:
        """Solve B states at once (each row exactly as :meth:`solve` would).

        Every argument is either shared by all rows (the shape :meth:`solve` takes) or has a
        leading batch axis of B rows; arguments without a batch axis are broadcast.

        Parameters
        ----------
        q, qd : array_like, shape (B, n) or (n,)
        alpha : array_like, shape (B, 6, m), (6, m) or (6,), optional
        beta : array_like, shape (B, m) or (m,); for m = 1 also (B,) or a float
        f_ext : array_like, shape (B, n_segments, 6) or (n_segments, 6), or dict, optional
            A dict maps segments (names, merged link names or indices) to ``(6,)`` or ``(B, 6)``
            wrenches.
        tau_ff : array_like, shape (B, n) or (n,), optional
        friction : None, bool, Friction, or a sequence of B of them, optional
        constraints : dict, optional
            ``{segment: (alpha_i, beta_i)}`` with ``alpha_i`` (6, m_i) or (B, 6, m_i) and
            ``beta_i`` (m_i,) or (B, m_i).
        f_ext_pass_through, tau_ff_pass_through : array_like, shape (B, m) or (m,), optional
            Driver pass-through weights in [0, 1] per constraint column (see :meth:`solve`).
        threads : int
            Rows are split into ``threads`` contiguous chunks solved in parallel with the GIL
            released (0: one per core; at most 256, and never more than B). Results do not
            depend on it. If the operating system refuses to start a thread, the started ones
            are joined and :class:`SolverError` says so.
        a_desired : array_like, shape (B, 6) or (6,), optional
            Instead of ``beta``: the last segment's classical acceleration (see :meth:`solve`).
        contacts : list of Contact, optional
            Point contacts of every row (see :meth:`solve`).
        time_step : float, optional
            Every row over a time step (see :meth:`solve`).
        contact_velocity_tolerance : float, optional
            As in :meth:`solve`.
        contact_max_pivots : int, optional
            The contact stage's real-time bound, as in :meth:`solve` (a row that reaches it gets
            the fallback; no warning is raised per row).

        Returns
        -------
        BatchResult

        Raises
        ------
        SolverError
            Shapes that do not fit (the message names the argument and its batch axis), a
            ``threads`` that is not an int in 0 .. 256, or the first failing row
            (``"batch row 3: ..."``).
        """
        threads = _int_option(threads, "threads", 0, _MAX_BATCH_THREADS, "", "(0: one per core)", True)
        out = super().solve_batch(
            q,
            qd,
            alpha,
            beta,
            f_ext,
            tau_ff,
            friction,
            constraints,
            f_ext_pass_through,
            tau_ff_pass_through,
            threads,
            a_desired,
            contacts,
            time_step,
            contact_velocity_tolerance,
            contact_max_pivots,
        )
        if not out.pop("any_friction"):
            for key in ("friction_torque", "limit_torque", "status", "gauss_value", "iterations"):
                out[key] = None
        layout = out.pop("segment_nu")  # (key, first column, columns) per constraints= entry
        segment_nu = {key: out["nu"][:, start : start + count] for key, start, count in layout}
        return BatchResult(**out, segment_nu=segment_nu or None)

    @property
    def chain(self) -> _core.Chain:
        """A copy of the solver's Chain.

        Raises
        ------
        SolverError
            The solver is for a :class:`Tree` (use ``solver.tree`` or ``solver.model``).
        """
        model = self.model
        if isinstance(model, _core.Tree):
            raise _core.SolverError("this Solver is for a Tree: use solver.tree (or solver.model)")
        return model

    @property
    def tree(self) -> _core.Tree:
        """A copy of the solver's Tree.

        Raises
        ------
        SolverError
            The solver is for a :class:`Chain` (use ``solver.chain`` or ``solver.model``).
        """
        model = self.model
        if not isinstance(model, _core.Tree):
            raise _core.SolverError("this Solver is for a Chain: use solver.chain (or solver.model)")
        return model

    def __reduce__(self):
        # Rebuilt through the constructor from its arguments (model, gravity, rcond, damping,
        # inertia_check, max_constraints), so copies and unpickled solvers are checked as new ones.
        rcond, damping, max_constraints = self._options
        return (type(self), (self.model, self.gravity, rcond, damping, self.inertia_check, max_constraints))

    def response_columns(self, joints, hold_sticking=True):
        """Affine response of the last solve to unit feed-forward joint torques.

        ``qdd`` and ``tau_command`` are affine in ``tau_ff``; column c is the change of each per
        unit of ``tau_ff`` at joint ``joints[c]`` (columns of the constrained inverse inertia
        ``G = H^-1 - H^-1 A^T K^+ A H^-1``, ``A = alpha^T J``), computed in O(n) per column.

        After a friction-aware solve, by default the joints that stick (``status == 1``) are
        held: a small change of torque is absorbed by their static friction (or limit reaction),
        so their ``qdd`` stays 0 and the others respond as in the arm with those joints locked,
        ``G - G[:, S] G[S, S]^+ G[S, :]``. This is the linearisation a controller needs around a
        sticking state (valid while the friction stays inside its bound). Moving and slipping
        joints keep their friction torque fixed. ``hold_sticking=False`` gives the columns of
        the frictionless problem at that state (friction torques as fixed inputs).

        It refers to the last successful :meth:`solve`, or to the last row of the last
        successful :meth:`solve_batch` (whatever ``threads``); after a failed solve or batch
        it raises :class:`SolverError` until the next successful one.

        Parameters
        ----------
        joints : sequence of int or str, length k
            Joint indices (negative from the end) or joint names.
        hold_sticking : bool
            Hold the sticking joints of the last friction-aware solve (no effect after a solve
            without friction).

        Returns
        -------
        dqdd, dtau_command : ndarray, shape (n, k)
            ``(tree.nv, k)`` on a floating base: the base's rows first (docs/floating-base.md).
        """
        return super().response_columns(_joint_indices(self.model, joints), hold_sticking)


def _joint_indices(model, joints) -> list:
    """The joint indices of ``joints`` (names or int indices, negative from the end).

    Raises
    ------
    SolverError
        ``joints`` is not a sequence or 1-D array of names or ints, or names no joint of ``model``
        (the message of ``model.joint_index``, naming ``joints[c]``).
    """
    what = "joints must be a sequence of joint names or int indices"
    if isinstance(joints, np.ndarray):
        if joints.ndim != 1 or (joints.size > 0 and joints.dtype.kind not in "iuU"):
            raise _core.SolverError(f"{what}, got an array of shape {joints.shape} and dtype {joints.dtype}")
        joints = joints.tolist()
    elif joints is None or isinstance(joints, (str, bytes)) or not isinstance(joints, Sequence):
        raise _core.SolverError(what)
    indices = []
    for c, joint in enumerate(joints):
        try:
            indices.append(model.joint_index(joint))
        except _core.SolverError as e:  # "joint_index: ..." names the argument instead
            raise _core.SolverError(f"joints[{c}]" + str(e).removeprefix("joint_index")) from None
    return indices
