"""Docstrings of the compiled module ``vereshchagin._core``, written once, here.

The bindings (``python/bindings``) attach ``DOCS[key]`` to the class, method or property named by
``key`` when the module is imported; the type stubs (``_core.pyi``) hold the signatures only.
"""

DOCS = {}

DOCS["_core.Solver.solve"] = r"""solve($self, /, q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None, friction=None, constraints=None, f_ext_pass_through=None, tau_ff_pass_through=None, out=None)
--

Constrained hybrid dynamics of one state: the motion that minimises Gauss' acceleration energy
subject to the acceleration constraints (Popov-Vereshchagin), with optional static friction.

Parameters
----------
q, qd : array_like, shape (n,)
    Joint positions (rad or m) and velocities (rad/s or m/s), in ``chain.joint_names`` order.
alpha : array_like, shape (6, m) or (6,), optional
    m <= 6 unit constraint wrenches on the **last** segment, one per column, rows
    ``[fx, fy, fz, mx, my, mz]``: base-frame axes, moment about the last segment's tip origin.
    A 1-D ``(6,)`` array is one column.
beta : array_like, shape (m,), or float when m = 1
    Acceleration set-points ``alpha.T @ a_N``, ``a_N`` the last segment's spatial acceleration
    ``[linear; angular]`` (base axes, tip origin) **including** ``-gravity``: holding the tip
    still along z against gravity needs ``beta = 9.81``, not 0 (the helpers in
    :mod:`vereshchagin.task` form beta for you). Required with ``alpha``.
f_ext : array_like, shape (n_segments, 6), or dict, optional
    External wrenches applied **on** the segments by the environment (N, N m). Array: row i is
    ``[fx, fy, fz, mx, my, mz]`` on segment i, base-frame axes, moment about segment i's tip
    origin (note: one row per segment, not KDL's one column per segment). Dict:
    ``{segment: wrench (6,)}`` keyed by segment name, link name or index; the moment is about
    the named frame's origin (a link merged into a segment by fixed joints, such as a tool
    frame, is moved to its segment at each solve). Gravity never goes here.
tau_ff : array_like, shape (n,), optional
    Feed-forward joint torques (N m or N), e.g. springs or known friction.
friction : None, bool or Friction, optional
    Static joint friction: ``True`` uses the chain's URDF friction and limits; a
    :class:`vereshchagin.Friction` sets them explicitly. Resting joints then get the exact
    max-min friction torques of Vukcevic (2018), and the least motor command among optima.
constraints : dict, optional
    ``{segment: (alpha_i (6, m_i), beta_i (m_i,))}``: acceleration constraints on any segments
    (Shakhimardanov's extension), keyed by segment or link name or index (negative from the
    end), with the end-segment conventions at that frame: base axes, moment about that frame's
    origin, ``beta_i`` including ``-gravity``. At most 6 columns per segment. Combines with
    ``alpha``/``beta``.
f_ext_pass_through, tau_ff_pass_through : array_like, shape (m_total,), optional
    Driver pass-through per constraint column, in the order of ``nu`` (Shakhimardanov 2015,
    eq. 3.42), each in [0, 1]: 0 (default) = the constraint compensates that driver (``f_ext``,
    respectively ``tau_ff``) along that column, as KDL does; 1 = the driver's own acceleration
    along that column passes through (``alpha^T a = beta + a_driver``: a commanded press on a
    table, a support); in between, linear. Friction is always compensated.
out : SolveResult, optional
    A result of an earlier solve with the same kind of arguments (same m, friction or not):
    its arrays are overwritten in place and it is returned (no allocation; for control loops).

Returns
-------
SolveResult
    ``qdd``, ``tau_command``, ``nu``, ``link_acc``, ``constraint_rank``,
    ``smallest_singular_value``; with friction also ``friction_torque``, ``limit_torque``,
    ``status``, ``gauss_value``, ``iterations``; with ``constraints`` also ``segment_nu``.

Raises
------
SolverError
    Wrong shapes or dtypes, NaN or Inf, unknown segment names, more than 6 columns on one
    segment, invalid friction, or a solve that fails (the message says why).

Notes
-----
The GIL is released during the solve. One solver serialises concurrent calls; use one solver
per thread (or :meth:`solve_batch` with ``threads=``) for parallel work.
"""

DOCS["_core.Solver.solve_batch"] = r"""solve_batch(q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None, friction=None, constraints=None, f_ext_pass_through=None, tau_ff_pass_through=None, threads=1)

Solve B states; see :meth:`vereshchagin.Solver.solve_batch` for the documented wrapper.
"""

DOCS["_core.Solver.response_columns"] = r"""Affine response of the last solve to unit feed-forward torques (see the wrapper in vereshchagin.Solver)."""

DOCS["_core.Solver.gravity"] = r"""Physical gravity in the base frame, shape (3,), m/s^2 (settable).

The base is accelerated by ``-gravity`` internally, so ``beta`` and ``link_acc`` include that
acceleration.
"""

DOCS["_core.Solver"] = r"""C++ core of :class:`vereshchagin.Solver` (use that class)."""

DOCS["SolveResult"] = r"""Result of :meth:`Solver.solve`.

All arrays are float64 (``status``: int32). Frames: base-frame axes; moments and spatial
accelerations about each segment's tip origin. Results pickle and deep-copy.
"""

DOCS["SolveResult.qdd"] = r"""ndarray, shape (n,): joint accelerations, rad/s^2 or m/s^2."""

DOCS["SolveResult.tau_command"] = r"""ndarray, shape (n,): torques the motors add to ``tau_ff`` to realise ``qdd``, N m or N.

``-sum_i J_i^T alpha_i nu_i`` over the constrained segments; applied with ``tau_ff`` (and, with
friction, the friction torques acting) to the unconstrained arm under the same gravity and
``f_ext`` it reproduces ``qdd``. With friction: the least such command among the optima.
"""

DOCS["SolveResult.nu"] = r"""ndarray, shape (m,): constraint force magnitudes (N or N m per unit of alpha).

The wrench the constraints apply on their segment is ``-alpha @ nu``. Order: the end-segment
``alpha`` columns first, then each ``constraints`` entry's columns in dict order.
"""

DOCS["SolveResult.link_acc"] = r"""ndarray, shape (n_segments + 1, 6): spatial accelerations ``[linear, angular]``.

Row 0 is the base (its acceleration is ``-gravity``); row ``k + 1`` is segment k's tip frame:
base-frame axes, tip origin, including ``-gravity`` (m/s^2, rad/s^2).
"""

DOCS["SolveResult.constraint_rank"] = r"""int: rank of the coupling matrix ``K = A H^-1 A^T`` (``A = alpha^T J``) under the singularity policy."""

DOCS["SolveResult.smallest_singular_value"] = r"""float: smallest eigenvalue of ``K`` (0 when m = 0); small values flag a near-singular task."""

DOCS["SolveResult.friction_torque"] = r"""ndarray, shape (n,) or None: physical friction torques acting on the joints (N m or N).

Opposes motion on moving joints (kinetic friction); on resting joints the max-min value with
``|torque| <= static``. None for solves without ``friction``.
"""

DOCS["SolveResult.limit_torque"] = r"""ndarray, shape (n,) or None: reactions of joint position limits on resting joints at a limit (N m or N)."""

DOCS["SolveResult.status"] = r"""ndarray of int32, shape (n,) or None: 0 moving, 1 sticking, 2 slipping +, 3 slipping - (joints at rest)."""

DOCS["SolveResult.gauss_value"] = r"""float or None: Gauss' function at the optimum, ``Z0(qdd) + sum f_j |qdd_j|`` over resting joints."""

DOCS["SolveResult.iterations"] = r"""int or None: iterations of the friction max-min (bounded; see the docs)."""

DOCS["SolveResult.segment_nu"] = r"""dict or None: ``{key: nu_i}`` for each ``constraints`` key, views into ``nu``."""
