"""Independent oracles for static joint friction (the max-min stated in docs/friction.md).

Nothing here calls vereshchagin's solver. The problem is stated in Pinocchio's quantities:

    minimise   F(qdd) = Z0(qdd) + sum_{j resting} f_j |qdd_j|,
               Z0(qdd) = 1/2 (qdd - qdd_free)^T H (qdd - qdd_free)
    subject to A qdd = b

with H = pin.crba (armature included), qdd_free = pin.aba with tau_ff, f_ext and the kinetic friction
-fk_j sign(qd_j) of the moving joints (|qd_j| > velocity_tolerance), A = alpha^T J (J the
LOCAL_WORLD_ALIGNED Jacobian of the tip frame) and b = beta - alpha^T (a0 + [-g; 0]) (a0 the LWA frame
acceleration at qdd = 0), as in tests/oracles/test_pinocchio_oracle.py.

Stationarity with multipliers mu (box |mu_j| <= f_j, resting joints) and lam (task):

    H (qdd - qdd_free) + mu + A^T lam = 0,

so H qdd + C - J_ext^T f_ext = tau_ff + tau_command + friction_torque with friction_torque = -mu on
resting joints (-fk sign(qd) on moving ones) and tau_command = -A^T lam (= -J^T alpha nu, nu = lam).
Complementarity per resting joint: qdd_j = 0 and |mu_j| <= f_j (stick), or mu_j = f_j sign(qdd_j)
(slip). qdd* is unique (H > 0); (mu, lam) are unique only if the constraints [A; e_j^T (j stuck)] are
independent. Otherwise the tie-break of section 4 applies: among all valid multipliers, the one with
the smallest ||tau_command||; it is unique because tau_command = H (qdd* - qdd_free) + mu (given
qdd*) is injective in mu, and only the mu_j of joints with qdd*_j = 0 are free (a joint with
qdd*_j != 0 has mu_j = f_j sign(qdd*_j)).

Oracles:

(a) ``scipy_oracle``: the primal problem with qdd_j = p_j - n_j (p, n >= 0) for resting joints, by
    SLSQP; then POLISH: the stick/slip pattern read off the SLSQP point, the pattern's equality-
    constrained QP solved exactly, and optimality CERTIFIED by a bounded least-squares problem
    (scipy's BVLS, exact active set) for multipliers with |mu_j| <= f_j. Raises OracleFailure if no
    polished point is certified.
(b) ``enumeration_oracle``: all 3^k stick/slip+/slip- patterns of the k resting joints; each
    pattern's equality-constrained QP by a null-space solve; the lowest F among feasible,
    sign-consistent candidates is qdd* (every candidate is a feasible point of the convex problem,
    and the optimum is the candidate of its own pattern); then the exact tie-break (``tie_break``,
    again an enumeration of the box's active sets) gives mu, lam and certifies optimality.
(c) ``mujoco_qacc``: MuJoCo with ``frictionloss`` per joint, qvel = 0, main solver converged to
    tolerance 0 and the noslip post-processor (unregularised projected Gauss-Seidel on the friction
    rows) iterated to convergence. Only for tasks without alpha.

Joint position limits (docs/friction.md, "Joint limits"; Vukcevic 2018, sec. 5.2). A resting joint flagged
``at_lower`` (``at_upper``) may not accelerate further into its limit: the primal gains the one-sided
constraint qdd_j >= 0 (qdd_j <= 0); both flags: qdd_j = 0. The objective is unchanged (the limit does
no work). In the stationarity condition the limit's multiplier joins mu_j, whose bounds open on one
side: mu_j in (-inf, f_j] at a lower limit, [-f_j, +inf) at an upper one, (-inf, inf) at both
(``FrictionProblem.mu_bounds``). Complementarity of such a joint: qdd_j = 0 and mu_j in its bounds
(stick, the limit may push without bound), or it slips AWAY from the limit with mu_j = f_j sign(qdd_j).
The physical torques are split as friction = clip(-mu_j, -f_j, f_j) and limit = -mu_j - friction
(>= 0 at a lower limit, <= 0 at an upper one). The oracles: (a) bounds u_j >= 0 / <= 0 on the SLSQP
variables and the opened bounds in the BVLS certificate; (b) only the slip directions away from the
limit are enumerated and the tie-break uses the opened bounds. An infeasible primal (the task forces
a joint into its limit) is ``OracleInfeasible`` from (b) and a negative margin of ``limit_margin`` (an
LP by HiGHS).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from scipy.optimize import lsq_linear, minimize

from support.chains import symmetric

LWA = pin.LOCAL_WORLD_ALIGNED

MOVING, STICK, SLIP_POS, SLIP_NEG = 0, 1, 2, 3


class OracleFailure(AssertionError):
    """An oracle could not produce a certified answer (the test must not silently pass)."""


class OracleInfeasible(OracleFailure):
    """No stick/slip pattern is feasible: the task and the joint limits admit no acceleration."""


# ------------------------------------------------------------------------------------------------
# The problem
# ------------------------------------------------------------------------------------------------
@dataclass
class FrictionProblem:
    H: np.ndarray  # (n, n) joint-space inertia, symmetric positive definite
    qdd_free: np.ndarray  # (n,) unconstrained accelerations incl. the kinetic friction of moving joints
    A: np.ndarray  # (m, n)
    b: np.ndarray  # (m,)
    resting: np.ndarray  # (n,) bool
    static: np.ndarray  # (n,) breakaway friction f_j >= 0 (used for resting joints)
    kinetic_torque: np.ndarray = None  # (n,) -fk sign(qd) on moving joints, 0 on resting ones
    extra: dict = field(default_factory=dict)
    at_lower: np.ndarray = None  # (n,) bool: resting joint on its lower limit (qdd_j >= 0); default none
    at_upper: np.ndarray = None  # (n,) bool: resting joint on its upper limit (qdd_j <= 0); default none

    def __post_init__(self):
        self.H = 0.5 * (np.asarray(self.H, float) + np.asarray(self.H, float).T)
        self.qdd_free = np.asarray(self.qdd_free, float)
        n = self.qdd_free.size
        self.A = np.asarray(self.A, float).reshape(-1, n)
        self.b = np.asarray(self.b, float).reshape(-1)
        self.resting = np.asarray(self.resting, bool)
        self.static = np.asarray(self.static, float)
        if self.kinetic_torque is None:
            self.kinetic_torque = np.zeros(n)
        # limits act on resting joints only (a moving joint is not "on" its limit)
        self.at_lower = np.zeros(n, bool) if self.at_lower is None else np.asarray(self.at_lower, bool) & self.resting
        self.at_upper = np.zeros(n, bool) if self.at_upper is None else np.asarray(self.at_upper, bool) & self.resting

    @property
    def n(self):
        return self.qdd_free.size

    @property
    def rest_idx(self):
        return np.flatnonzero(self.resting)

    @property
    def on_limit(self):
        return self.at_lower | self.at_upper

    def mu_bounds(self):
        """(lo, hi), each (n,): the bounds of mu_j (friction torque -mu_j plus limit reaction):
        [-f_j, f_j], opened to -inf at a lower limit and to +inf at an upper one."""
        lo = np.where(self.at_lower, -np.inf, -self.static)
        hi = np.where(self.at_upper, np.inf, self.static)
        return lo, hi

    def slip_allowed(self, j, sign):
        """May resting joint j slip in direction sign (+1 / -1)? Not into a limit it rests on."""
        return not (self.at_lower[j] if sign < 0 else self.at_upper[j])

    def split_torque(self, mu):
        """Physical (friction, limit) torques of multipliers mu (n,) on resting joints: friction
        clip(-mu, -f, f) on limit joints (-mu elsewhere), the limit reaction the rest."""
        total = -np.asarray(mu, float)
        friction = np.where(self.on_limit, np.clip(total, -self.static, self.static), total)
        return friction, total - friction

    def gauss(self, qdd):
        d = np.asarray(qdd) - self.qdd_free
        return 0.5 * d @ self.H @ d

    def objective(self, qdd):
        qdd = np.asarray(qdd)
        r = self.rest_idx
        return self.gauss(qdd) + float(self.static[r] @ np.abs(qdd[r]))

    def accel_scale(self, qdd=None):
        s = max(1.0, np.linalg.norm(self.qdd_free))
        if qdd is not None:
            s = max(s, np.linalg.norm(qdd))
        return s

    def torque_scale(self, qdd=None):
        """Size of the torques: H qdd_free, H qdd and the friction of slipping joints (not the bound f_j
        of stuck ones, which may be huge while the friction they exert is not)."""
        s = max(1.0, np.linalg.norm(self.H @ self.qdd_free))
        if qdd is not None:
            qdd = np.asarray(qdd, float)
            s = max(s, np.linalg.norm(self.H @ qdd))
            R = self.rest_idx
            slipping = R[np.abs(qdd[R]) > 1e-12 * self.accel_scale(qdd)]
            if slipping.size:
                s = max(s, np.max(self.static[slipping]))
        return s

    def objective_scale(self, qdd):
        """Size of the round-off in F(qdd): |F|, or (gradient size) x (qdd size) if larger."""
        return max(1.0, abs(self.objective(qdd)), 1e-3 * self.torque_scale(qdd) * self.accel_scale(qdd))


@dataclass
class OracleResult:
    qdd: np.ndarray
    objective: float
    status: np.ndarray  # MOVING / STICK / SLIP_POS / SLIP_NEG per joint
    friction_torque: np.ndarray = None  # physical friction torque (-mu on resting joints), tie-broken
    tau_command: np.ndarray = None  # -A^T lam, tie-broken
    lam: np.ndarray = None
    info: dict = field(default_factory=dict)
    limit_torque: np.ndarray = None  # reactions of the joint limits (>= 0 lower, <= 0 upper), tie-broken


def pinocchio_problem(
    model,
    data,
    q,
    qd,
    *,
    tau_ff=None,
    fext_tau=None,
    static,
    kinetic=None,
    velocity_tolerance=1e-6,
    tip_frame=None,
    alpha=None,
    beta=None,
    at_lower=None,
    at_upper=None,
):
    """The friction problem of a Pinocchio model (gravity = model.gravity).

    q: Pinocchio configuration (nq); qd (nv); tau_ff (nv); fext_tau: generalised external force
    J_ext^T f_ext (nv) or None; static / kinetic: per joint; alpha (6 x m), beta (m) on tip_frame;
    at_lower / at_upper: (nv,) bool limit flags (see :func:`limit_flags`), default none.
    """
    nv = model.nv
    qd = np.asarray(qd, float)
    tau_ff = np.zeros(nv) if tau_ff is None else np.asarray(tau_ff, float)
    fext_tau = np.zeros(nv) if fext_tau is None else np.asarray(fext_tau, float)
    static = np.broadcast_to(np.asarray(static, float), (nv,)).copy()
    kinetic = static.copy() if kinetic is None else np.broadcast_to(np.asarray(kinetic, float), (nv,)).copy()
    resting = np.abs(qd) <= velocity_tolerance
    kin = np.where(resting, 0.0, -kinetic * np.sign(qd))
    H = symmetric(np.reshape(pin.crba(model, data, q), (nv, nv)))
    qdd_free = np.array(pin.aba(model, data, q, qd, tau_ff + fext_tau + kin)).reshape(nv)
    g = np.array(model.gravity.linear)
    if alpha is None or np.asarray(alpha).size == 0:
        A, b, J = np.zeros((0, nv)), np.zeros(0), None
    else:
        alpha = np.asarray(alpha, float).reshape(6, -1)
        J = np.reshape(pin.computeFrameJacobian(model, data, q, tip_frame, LWA), (6, nv))
        pin.forwardKinematics(model, data, q, qd, np.zeros(nv))
        pin.updateFramePlacements(model, data)
        a0 = pin.getFrameAcceleration(model, data, tip_frame, LWA).vector
        A = alpha.T @ J
        b = np.asarray(beta, float).reshape(-1) - alpha.T @ (a0 + np.r_[-g, 0.0, 0.0, 0.0])
    return FrictionProblem(
        H,
        qdd_free,
        A,
        b,
        resting,
        static,
        kin,
        extra=dict(J=J, tau_ff=tau_ff, fext_tau=fext_tau, g=g),
        at_lower=at_lower,
        at_upper=at_upper,
    )


def limit_flags(q, lower, upper, limit_tolerance=1e-9):
    """(at_lower, at_upper) of joint positions q: q_j <= lower_j + tol, q_j >= upper_j - tol
    (the rule of vereshchagin.Friction; +-inf limits never hold)."""
    q = np.asarray(q, float)
    return q <= np.asarray(lower, float) + limit_tolerance, q >= np.asarray(upper, float) - limit_tolerance


def limit_margin(prob, cap=1.0):
    """Largest t <= cap such that some qdd meets the task with qdd_j >= t at lower limits,
    qdd_j <= -t at upper limits and qdd_j = 0 at joints on both, by linear programming (HiGHS).
    > 0: the primal has a point strictly inside its one-sided constraints; < 0: it is infeasible
    (the task forces a joint into its limit); 0: feasible only on the boundary. qdd is measured in
    units of ``accel_scale()``. -inf if even the equalities (task, locked joints) are inconsistent;
    None if no joint is on a limit."""
    from scipy.optimize import linprog

    if not prob.on_limit.any():
        return None
    n, s = prob.n, prob.accel_scale()
    locked = prob.at_lower & prob.at_upper
    # variables [qdd / s (n), t]; maximise t
    rows = []
    for j in np.flatnonzero(prob.on_limit & ~locked):
        r = np.zeros(n + 1)
        r[j], r[n] = (-1.0 if prob.at_lower[j] else 1.0), 1.0  # t <= qdd_j (lower), t <= -qdd_j (upper)
        rows.append(r)
    E = np.zeros((int(locked.sum()), n))
    E[np.arange(E.shape[0]), np.flatnonzero(locked)] = 1.0
    Aeq = np.hstack([np.vstack([prob.A, E]), np.zeros((prob.A.shape[0] + E.shape[0], 1))])
    beq = np.r_[prob.b / s, np.zeros(E.shape[0])]
    res = linprog(
        np.r_[np.zeros(n), -1.0],
        A_ub=np.array(rows) if rows else None,
        b_ub=np.zeros(len(rows)) if rows else None,
        A_eq=Aeq if Aeq.shape[0] else None,
        b_eq=beq if Aeq.shape[0] else None,
        bounds=[(None, None)] * n + [(None, cap)],
        method="highs",
    )
    if res.status == 2:
        return -np.inf
    if res.status != 0:
        raise OracleFailure(f"limit_margin: linprog status {res.status}: {res.message}")
    return float(res.x[n])


def random_problem(rng, n, m, resting_fraction=1.0, friction="mixed"):
    """A synthetic problem (random SPD H, full-row-rank A) for checking the oracles against each other."""
    B = rng.normal(size=(n, n))
    H = B @ B.T + 0.1 * np.eye(n)
    x0 = rng.normal(size=n) * 3.0
    A = rng.normal(size=(m, n))
    b = rng.normal(size=m) * 3.0
    resting = rng.random(n) < resting_fraction
    static = random_friction(rng, n, kind=friction, scale=np.linalg.norm(H @ x0) / np.sqrt(n))
    return FrictionProblem(H, x0, A, b, resting, static)


def random_friction(rng, n, kind="mixed", scale=5.0):
    """Breakaway frictions: 0, small, comparable to the torques (scale) or large (holds anything)."""
    if kind == "zero":
        return np.zeros(n)
    if kind == "large":
        return np.full(n, 1e4)
    if kind == "moderate":
        return rng.uniform(0.1, 2.0, n) * scale
    choice = rng.integers(0, 4, n)
    out = rng.uniform(0.1, 2.0, n) * scale
    out[choice == 0] = 0.0
    out[choice == 1] = rng.uniform(0.0, 0.2, np.sum(choice == 1)) * scale
    out[choice == 3] = 1e4
    return out


# ------------------------------------------------------------------------------------------------
# Exact linear algebra
# ------------------------------------------------------------------------------------------------
def equality_qp_batch(P, p, C, d, rcond=1e-11, feas_rtol=1e-9, atol=0.0):
    """Columnwise argmin 1/2 x^T P x + p_k^T x  s.t. C x = d_k  (P symmetric positive definite).

    p: (nx, K), d: (mc, K). Null-space method with one SVD of C (any rank): x is affine in (p, d).
    Singular values of C up to max(rcond * largest, atol) count as zero (atol: when C's scale is
    known, e.g. rows of an orthonormal basis, a C made only of round-off has rank 0).
    Returns (X (nx, K), feasible (K,) bool); a column is infeasible if C x = d_k has no solution
    (relative residual above feas_rtol)."""
    nx, K = P.shape[0], p.shape[1]
    mc = C.shape[0]
    dn = np.linalg.norm(d, axis=0) if mc else np.zeros(K)
    if nx == 0:
        return np.zeros((0, K)), dn <= feas_rtol * np.maximum(1.0, dn)
    if mc == 0:
        return -np.linalg.solve(P, p), np.ones(K, bool)
    U, s, Vt = np.linalg.svd(C, full_matrices=True)
    r = int(np.sum(s > max(rcond * max(s[0], 1e-300), atol))) if s.size else 0
    xp = Vt[:r].T @ ((U[:, :r].T @ d) / s[:r, None])
    res = np.linalg.norm(C @ xp - d, axis=0)
    feasible = res <= feas_rtol * np.maximum.reduce([np.ones(K), dn, s[0] * np.linalg.norm(xp, axis=0)])
    Z = Vt[r:].T
    if Z.shape[1] == 0:
        return xp, feasible
    X = xp - Z @ np.linalg.solve(Z.T @ P @ Z, Z.T @ (P @ xp + p))
    return X, feasible


def equality_qp(P, p, C, d, rcond=1e-11, feas_rtol=1e-9):
    """Single right-hand side of :func:`equality_qp_batch`; None if infeasible."""
    X, ok = equality_qp_batch(P, np.reshape(p, (-1, 1)), C, np.reshape(d, (-1, 1)), rcond, feas_rtol)
    return X[:, 0] if ok[0] else None


def null_space(A, rcond=1e-11):
    n = A.shape[1]
    if A.shape[0] == 0:
        return np.eye(n)
    U, s, Vt = np.linalg.svd(A, full_matrices=True)
    r = int(np.sum(s > rcond * max(s[0], 1e-300))) if s.size else 0
    return Vt[r:].T


def _sign_table(k):
    """(k, 2^k) matrix of all +-1 columns."""
    if k == 0:
        return np.zeros((0, 1))
    return np.array(list(itertools.product((1.0, -1.0), repeat=k))).T


def _pattern_candidate(prob, pattern):
    """Exact solution of one pattern's QP; pattern[i] in (STICK, SLIP_POS, SLIP_NEG) for rest_idx[i]:
    minimise Z0 + sum_slip s_j f_j qdd_j s.t. A qdd = b, qdd_j = 0 (stick). None if infeasible."""
    n, R = prob.n, prob.rest_idx
    stick = np.zeros(n, bool)
    g = np.zeros(n)
    for j, s in zip(R, pattern):
        if s == STICK:
            stick[j] = True
        else:
            g[j] = prob.static[j] * (1.0 if s == SLIP_POS else -1.0)
    F = np.flatnonzero(~stick)
    Hx0 = prob.H @ prob.qdd_free
    xF = equality_qp(prob.H[np.ix_(F, F)], g[F] - Hx0[F], prob.A[:, F], prob.b)
    if xF is None:
        return None
    x = np.zeros(n)
    x[F] = xF
    return x


def classify(prob, qdd, zero_tol=0.0):
    """Status per joint from the accelerations (resting joints: STICK if |qdd_j| <= zero_tol)."""
    st = np.zeros(prob.n, int)
    for j in prob.rest_idx:
        st[j] = STICK if abs(qdd[j]) <= zero_tol else (SLIP_POS if qdd[j] > 0 else SLIP_NEG)
    return st


# ------------------------------------------------------------------------------------------------
# The tie-break (section 4): the valid multipliers with the smallest ||tau_command||
# ------------------------------------------------------------------------------------------------
def _tie_break_data(prob, qdd, zero_tol):
    R = prob.rest_idx
    Zj = np.array([j for j in R if abs(qdd[j]) <= zero_tol], int)  # free multipliers
    Sj = np.array([j for j in R if abs(qdd[j]) > zero_tol], int)  # slipping: mu = f sign(qdd)
    c = prob.H @ (qdd - prob.qdd_free)
    c[Sj] += prob.static[Sj] * np.sign(qdd[Sj])
    # tau_command = c + E_Z mu_Z must lie in range(A^T), i.e. N^T (c + E_Z mu_Z) = 0.
    N = null_space(prob.A)
    return Zj, Sj, c, N


def _bound_table(lo, hi):
    """(|B|, K) matrix of all choices of a finite bound (hi or lo) per entry; K = 0 if some entry
    has none (a joint at both limits cannot be held at a bound)."""
    choices = [[v for v in (h, l) if np.isfinite(v)] for l, h in zip(lo, hi)]
    if any(not c for c in choices):
        return np.zeros((len(choices), 0))
    if not choices:
        return np.zeros((0, 1))
    return np.array(list(itertools.product(*choices)), float).T


def tie_break(prob, qdd, zero_tol=None):
    """Exact tie-break by enumerating the active sets (free / hi / lo) of the free multipliers:

        minimise ||tau||^2,  tau = c + E_Z mu_Z,  N^T tau = 0,  lo_Z <= mu_Z <= hi_Z

    (bounds -+f_Z, opened at joint limits: ``FrictionProblem.mu_bounds``). Each active set is an
    equality-constrained least-squares problem (exact); the lowest value among the feasible ones is
    the optimum (strictly convex in mu_Z). Returns (mu (n,), tau_command (n,), lam (m,)). Raises
    OracleFailure if no valid multiplier exists (then qdd is not optimal)."""
    if zero_tol is None:
        zero_tol = 1e-12 * prob.accel_scale(qdd)
    Zj, Sj, c, N = _tie_break_data(prob, qdd, zero_tol)
    lo_all, hi_all = prob.mu_bounds()
    lo, hi = lo_all[Zj], hi_all[Zj]
    tscale = prob.torque_scale(qdd)
    best, best_val = None, np.inf
    kz = Zj.size
    for free_mask in itertools.product((True, False), repeat=kz):
        free_mask = np.array(free_mask, bool)
        free, bnd = np.flatnonzero(free_mask), np.flatnonzero(~free_mask)
        vals_b = _bound_table(lo[bnd], hi[bnd])  # (|B|, K)
        K = vals_b.shape[1]
        if K == 0:
            continue
        base = np.repeat(c[:, None], K, axis=1)  # (n, K)
        base[Zj[bnd], :] += vals_b
        # N is orthonormal: a direction of N_Z^T below 1e-10 does not constrain mu_Z (its effect on
        # N^T tau is below the 1e-9 tscale check), however small the whole of N_Z is.
        X, ok = equality_qp_batch(
            np.eye(free.size), base[Zj[free], :], N[Zj[free], :].T, -N.T @ base, feas_rtol=1e-10, atol=1e-10
        )
        slack_hi = np.where(np.isfinite(hi[free]), np.abs(hi[free]) * 1e-12, 0.0)[:, None] + 1e-14 * tscale
        slack_lo = np.where(np.isfinite(lo[free]), np.abs(lo[free]) * 1e-12, 0.0)[:, None] + 1e-14 * tscale
        ok &= np.all(X <= hi[free, None] + slack_hi, axis=0)
        ok &= np.all(X >= lo[free, None] - slack_lo, axis=0)
        tau = base
        tau[Zj[free], :] += X
        ok &= np.linalg.norm(N.T @ tau, axis=0) <= 1e-9 * tscale
        if not np.any(ok):
            continue
        vals = np.where(ok, np.sum(tau * tau, axis=0), np.inf)
        i = int(np.argmin(vals))
        if vals[i] < best_val:
            best_val = vals[i]
            mu = np.zeros(kz)
            mu[bnd] = vals_b[:, i]
            mu[free] = X[:, i]
            best = mu
    if best is None:
        raise OracleFailure("tie_break: no multipliers within their bounds satisfy stationarity: qdd is not optimal")
    mu_full = np.zeros(prob.n)
    mu_full[Sj] = prob.static[Sj] * np.sign(qdd[Sj])
    mu_full[Zj] = best
    tau = c.copy()
    tau[Zj] += best
    lam = np.linalg.lstsq(prob.A.T, -tau, rcond=None)[0] if prob.A.shape[0] else np.zeros(0)
    return mu_full, tau, lam


def tie_break_scipy(prob, qdd, zero_tol=None):
    """The same tie-break QP by SLSQP (approximate; only used to check ``tie_break``)."""
    if zero_tol is None:
        zero_tol = 1e-12 * prob.accel_scale(qdd)
    Zj, Sj, c, N = _tie_break_data(prob, qdd, zero_tol)
    f = prob.static[Zj]
    if Zj.size == 0:
        return c
    E = np.zeros((prob.n, Zj.size))
    E[Zj, np.arange(Zj.size)] = 1.0
    # independent rows of the equality N^T (c + E x) = 0 (SLSQP rejects redundant ones)
    M = N.T @ E
    cons = []
    if M.shape[0]:
        U, s, Vt = np.linalg.svd(M, full_matrices=False)
        r = int(np.sum(s > 1e-11 * max(s[0], 1e-300)))
        Ur = U[:, :r]
        if r:
            cons = [dict(type="eq", fun=lambda x: Ur.T @ (N.T @ c + M @ x), jac=lambda x: Ur.T @ M)]
    res = minimize(
        lambda x: 0.5 * np.sum((c + E @ x) ** 2),
        np.zeros(Zj.size),
        jac=lambda x: E.T @ (c + E @ x),
        bounds=list(zip(-f, f)),
        constraints=cons,
        method="SLSQP",
        options=dict(ftol=1e-13, maxiter=300),
    )
    return c + E @ res.x


def _finish(prob, qdd, objective, info, zero_tol=None):
    mu, tau, lam = tie_break(prob, qdd, zero_tol)
    friction = prob.kinetic_torque.copy()
    fr, limit = prob.split_torque(mu)
    R = prob.rest_idx
    friction[R] = fr[R]
    limit_torque = np.zeros(prob.n)
    limit_torque[R] = limit[R]
    zt = 1e-12 * prob.accel_scale(qdd) if zero_tol is None else zero_tol
    return OracleResult(qdd, objective, classify(prob, qdd, zt), friction, tau, lam, info, limit_torque)


# ------------------------------------------------------------------------------------------------
# (b) exhaustive enumeration
# ------------------------------------------------------------------------------------------------
def enumeration_oracle(prob, max_resting=7):
    """All 3^k patterns. Grouped by the stuck set S (2^k groups): with S fixed the pattern's QP
    solution is affine in the slip signs, so one SVD serves all 2^(k - |S|) sign choices."""
    n, R = prob.n, prob.rest_idx
    k = R.size
    if k > max_resting:
        raise ValueError(f"enumeration_oracle: {k} resting joints > {max_resting}")
    Hx0 = prob.H @ prob.qdd_free
    best, best_val, n_feasible, n_patterns = None, np.inf, 0, 0
    locked = prob.at_lower & prob.at_upper  # on both limits: cannot slip at all
    for stick_mask in itertools.product((True, False), repeat=k):
        stick_mask = np.array(stick_mask, bool)
        if np.any(locked[R[~stick_mask]]):
            continue
        stick = np.zeros(n, bool)
        stick[R[stick_mask]] = True
        F = np.flatnonzero(~stick)
        T = np.flatnonzero(np.isin(F, R))  # slipping resting joints, positions in F
        signs = _sign_table(T.size)
        # a joint on a limit slips only away from it
        allowed = np.array([all(prob.slip_allowed(F[t], s) for t, s in zip(T, col)) for col in signs.T], bool)
        signs = signs[:, allowed]
        K = signs.shape[1]
        n_patterns += K
        if K == 0:
            continue
        p = np.repeat(-Hx0[F][:, None], K, axis=1)
        p[T, :] += prob.static[F[T], None] * signs
        X, ok = equality_qp_batch(prob.H[np.ix_(F, F)], p, prob.A[:, F], np.repeat(prob.b[:, None], K, axis=1))
        if not np.any(ok):
            continue
        Xf = np.zeros((n, K))
        Xf[F, :] = X
        tol = 1e-12 * np.maximum(prob.accel_scale(), np.linalg.norm(Xf, axis=0))
        ok &= np.all(signs * X[T, :] >= -tol, axis=0)  # slip+ needs qdd >= 0, slip- qdd <= 0
        if not np.any(ok):
            continue
        n_feasible += int(np.sum(ok))
        D = Xf - prob.qdd_free[:, None]
        vals = 0.5 * np.sum(D * (prob.H @ D), axis=0) + prob.static[R] @ np.abs(Xf[R, :])
        vals = np.where(ok, vals, np.inf)
        i = int(np.argmin(vals))
        if vals[i] < best_val:
            best_val, best = vals[i], Xf[:, i].copy()
    if best is None:
        raise OracleInfeasible(
            f"enumeration_oracle: no feasible pattern among {n_patterns} (inconsistent task, "
            f"or the task forces a joint into its limit?)"
        )
    return _finish(prob, best, prob.objective(best), dict(patterns=n_patterns, feasible=n_feasible))


# ------------------------------------------------------------------------------------------------
# (a) scipy on the primal problem, polished and certified
# ------------------------------------------------------------------------------------------------
def _certify(prob, x, stick_joints):
    """Is there (lam, mu_stick) with mu_stick in its bounds and H (x - x0) + mu + A^T lam = 0 (mu of the
    other resting joints = f sign(x))? Bounded least squares by BVLS (an exact active-set method).
    Bounds opened at joint limits (``mu_bounds``). Returns (scaled residual, unconstrained
    least-squares multipliers of the stuck joints)."""
    R = prob.rest_idx
    S = np.array([j for j in R if j in stick_joints], int)
    P = np.array([j for j in R if j not in stick_joints], int)
    c = prob.H @ (x - prob.qdd_free)
    c[P] += prob.static[P] * np.sign(x[P])
    m = prob.A.shape[0]
    E = np.zeros((prob.n, S.size))
    E[S, np.arange(S.size)] = 1.0
    M = np.hstack([prob.A.T, E])
    if M.shape[1] == 0:
        return np.linalg.norm(c) / prob.torque_scale(x), np.zeros(0)
    free_mu = np.linalg.lstsq(M, -c, rcond=None)[0][m:]
    mlo, mhi = prob.mu_bounds()
    lo = np.r_[np.full(m, -np.inf), mlo[S]]
    hi = np.r_[np.full(m, np.inf), mhi[S]]
    hi = np.where(hi <= lo, lo + 1e-300, hi)  # f = 0: lsq_linear needs lo < hi
    sol = lsq_linear(M, -c, bounds=(lo, hi), method="bvls", tol=1e-15, max_iter=10000)
    return np.linalg.norm(M @ sol.x + c) / prob.torque_scale(x), free_mu


def _slsqp_primal(prob):
    n, R = prob.n, prob.rest_idx
    k = R.size
    H, x0, f = prob.H, prob.qdd_free, prob.static[R]
    Hx0 = H @ x0

    # variables y = [u (n), p (k), q (k)], u_R = p - q, p, q >= 0
    def fun(y):
        d = y[:n] - x0
        return 0.5 * d @ H @ d + f @ (y[n : n + k] + y[n + k :])

    def jac(y):
        return np.r_[H @ y[:n] - Hx0, f, f]

    m = prob.A.shape[0]
    Ceq = np.zeros((m + k, n + 2 * k))
    Ceq[:m, :n] = prob.A
    Ceq[m:, R] = np.eye(k)
    Ceq[m:, n : n + k] = -np.eye(k)
    Ceq[m:, n + k :] = np.eye(k)
    deq = np.r_[prob.b, np.zeros(k)]
    u0 = equality_qp(H, -Hx0, prob.A, prob.b)  # frictionless constrained motion (feasible start)
    if u0 is None:
        raise OracleFailure("scipy_oracle: inconsistent task")
    # a joint on a lower (upper) limit: u_j >= 0 (<= 0); the start is moved into these bounds
    u0 = np.where(prob.at_lower, np.maximum(u0, 0.0), u0)
    u0 = np.where(prob.at_upper, np.minimum(u0, 0.0), u0)
    y0 = np.r_[u0, np.maximum(u0[R], 0.0), np.maximum(-u0[R], 0.0)]
    cons = [dict(type="eq", fun=lambda y: Ceq @ y - deq, jac=lambda y: Ceq)] if m + k else []
    bounds = [(0.0 if prob.at_lower[j] else None, 0.0 if prob.at_upper[j] else None) for j in range(n)]
    bounds += [(0.0, None)] * (2 * k)
    res = minimize(
        fun, y0, jac=jac, bounds=bounds, constraints=cons, method="SLSQP", options=dict(ftol=1e-12, maxiter=300)
    )
    return res.x[:n], res


def _kkt_candidate(prob, pattern):
    """The pattern's QP through its full KKT system [[H, C^T], [C, 0]] (C = [A; e_j^T, j stuck]),
    solved by least squares (consistent but possibly singular when C loses rank; the qdd part of
    every solution is the same). Deliberately not the null-space code of the enumeration."""
    n = prob.n
    S = [j for j in prob.rest_idx if pattern[j] == STICK]
    g = np.zeros(n)
    for j in prob.rest_idx:
        if pattern[j] != STICK:
            g[j] = prob.static[j] * (1.0 if pattern[j] == SLIP_POS else -1.0)
    E = np.zeros((len(S), n))
    E[np.arange(len(S)), S] = 1.0
    C = np.vstack([prob.A, E])
    mc = C.shape[0]
    K = np.block([[prob.H, C.T], [C, np.zeros((mc, mc))]])
    rhs = np.r_[prob.H @ prob.qdd_free - g, prob.b, np.zeros(len(S))]
    sol = np.linalg.lstsq(K, rhs, rcond=1e-13)[0]
    if np.linalg.norm(K @ sol - rhs) > 1e-9 * max(1.0, np.linalg.norm(rhs), np.linalg.norm(K) * np.linalg.norm(sol)):
        return None
    x = sol[:n]
    x[S] = 0.0
    return x


def scipy_oracle(prob, thresholds=(1e-6, 1e-9, 1e-3), max_polish=None):
    """(a): SLSQP on the split primal, then POLISH and CERTIFY.

    Polish: the pattern read off the SLSQP point (|qdd_j| <= threshold -> stick, else the sign) is
    solved exactly; if a slipping joint then has the wrong sign it is made stuck, and if no
    multipliers |mu| <= f exist the stuck joint whose least-squares multiplier most exceeds its
    bound is released in the direction of that multiplier (a few active-set corrections; SLSQP is
    inaccurate when f_j is orders of magnitude above the other terms). The answer is returned only
    if it is certified optimal (sign conditions + BVLS certificate); otherwise OracleFailure."""
    R = prob.rest_idx
    u, res = _slsqp_primal(prob)
    scale = prob.accel_scale(u)
    max_polish = 2 * R.size + 2 if max_polish is None else max_polish
    log = []
    for thr in thresholds:
        pattern = {j: (STICK if abs(u[j]) <= thr * scale else (SLIP_POS if u[j] > 0 else SLIP_NEG)) for j in R}
        pattern = {
            j: (p if p == STICK or prob.slip_allowed(j, 1 if p == SLIP_POS else -1) else STICK)
            for j, p in pattern.items()
        }
        for step in range(max_polish + 1):
            x = _kkt_candidate(prob, pattern)
            if x is None:
                log.append((thr, step, "infeasible"))
                break
            wrong = [j for j in R if (pattern[j] == SLIP_POS and x[j] <= 0) or (pattern[j] == SLIP_NEG and x[j] >= 0)]
            if wrong:
                j = max(wrong, key=lambda j: abs(x[j]))
                pattern[j] = STICK
                log.append((thr, step, f"sign of joint {j}"))
                continue
            stick = {j for j in R if pattern[j] == STICK}
            resid, mu_ls = _certify(prob, x, stick)
            if resid <= 1e-10:
                return _finish(
                    prob,
                    x,
                    prob.objective(x),
                    dict(
                        slsqp_qdd=u,
                        slsqp_message=res.message,
                        threshold=thr,
                        polish_steps=step,
                        certificate_residual=resid,
                        polish_shift=np.linalg.norm(x - u) / scale,
                    ),
                    zero_tol=0.0,
                )
            S = sorted(stick)
            mlo, mhi = prob.mu_bounds()
            ratio = [max(mu_ls[i] - mhi[j], mlo[j] - mu_ls[i]) for i, j in enumerate(S)]
            if not S or max(ratio) <= 0:
                log.append((thr, step, f"certificate residual {resid:.2e}"))
                break
            i = int(np.argmax(ratio))
            pattern[S[i]] = SLIP_POS if mu_ls[i] > mhi[S[i]] else SLIP_NEG
            log.append((thr, step, f"release joint {S[i]}"))
    raise OracleFailure(f"scipy_oracle: no polished pattern certified optimal (SLSQP: {res.message}); log {log}")


# ------------------------------------------------------------------------------------------------
# (c) MuJoCo
# ------------------------------------------------------------------------------------------------
def _quat_wxyz(R):
    q = np.empty(4)
    import mujoco

    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, float).reshape(9))
    return q


def _fmt(v):
    return " ".join(repr(float(x)) for x in np.ravel(v))


# Settings found by experiment (30 random 2-7 joint chains at rest, frictionloss 0..1e3, vs
# enumeration_oracle; worst relative qdd error):
#   main solver only, default solreffriction/solimpfriction (soft constraint):        3.4e-1
#   main solver only, solreffriction "0.0002 1", solimpfriction "0.9999 0.9999 ...":  5.1e-4
#   + noslip_iterations 10: 1.9e-3;  100: 4.5e-15;  1000 / 20000: 4.5e-15
# The main solver's answer is regularised (soft constraints: impratio does not touch dof friction,
# and solref/solimp only shrink the regulariser R); the noslip post-processor then solves the
# friction rows without R by projected Gauss-Seidel on A = M^-1 (at qvel = 0 the reference
# acceleration of a frictionloss row is 0), i.e. exactly the dual box QP of the max-min. PGS
# converges linearly, so noslip_iterations is generous and noslip_tolerance = 0 (run them all).
MUJOCO_OPTIONS = dict(iterations=200, tolerance=0.0, noslip_iterations=1000, noslip_tolerance=0.0)


def mujoco_xml(segments, gravity, frictionloss, options=None):
    """MJCF of a chains.py chain (list of SegmentSpec): one body per segment, in the segment's tip frame.

    A body's frame is the segment's tip frame at q = 0 in the previous tip frame (KDL: the tip given
    at q = 0); the joint's axis and the point ``origin`` on it are re-expressed in the body frame;
    com/inertia are given in the tip frame already (fullinertia about the com); armature = rotor.
    Fixed segments are bodies without a joint.
    """
    opts = dict(MUJOCO_OPTIONS)
    opts.update(options or {})
    flist = iter(np.ravel(frictionloss))
    lines = []
    depth = 0
    for i, s in enumerate(segments):
        R, p = s.tip[:3, :3], s.tip[:3, 3]
        lines.append(f'<body name="b{i}" pos="{_fmt(p)}" quat="{_fmt(_quat_wxyz(R))}">')
        if s.moving:
            axis = R.T @ s.axis
            jpos = R.T @ (s.origin - p)
            kind = "hinge" if s.revolute else "slide"
            fl = next(flist)
            lines.append(
                f'<joint name="j{i}" type="{kind}" axis="{_fmt(axis)}" pos="{_fmt(jpos)}" '
                f'armature="{float(s.rotor)!r}" damping="0" frictionloss="{float(fl)!r}" '
                f'solreffriction="{opts.get("solref", "0.02 1")}" '
                f'solimpfriction="{opts.get("solimp", "0.9 0.95 0.001 0.5 2")}"/>'
            )
        I = s.inertia
        lines.append(
            f'<inertial pos="{_fmt(s.com)}" mass="{float(s.mass)!r}" '
            f'fullinertia="{_fmt([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>'
        )
        depth += 1
    lines += ["</body>"] * depth
    return f"""<mujoco>
  <compiler angle="radian" inertiafromgeom="false" balanceinertia="false" boundmass="0" boundinertia="0"/>
  <option gravity="{_fmt(gravity)}" timestep="0.001" iterations="{opts["iterations"]}" tolerance="{opts["tolerance"]!r}"
          noslip_iterations="{opts["noslip_iterations"]}" noslip_tolerance="{opts["noslip_tolerance"]!r}"
          impratio="1" cone="pyramidal" jacobian="dense" solver="Newton">
    <flag contact="disable"/>
  </option>
  <worldbody>
  {chr(10).join(lines)}
  </worldbody>
</mujoco>"""


def mujoco_qacc(segments, gravity, q, tau_ff, frictionloss, options=None):
    """MuJoCo's accelerations at rest (qvel = 0) with dry friction ``frictionloss`` on every joint."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(mujoco_xml(segments, gravity, frictionloss, options))
    data = mujoco.MjData(model)
    data.qpos[:] = q
    data.qvel[:] = 0.0
    data.qfrc_applied[:] = tau_ff
    mujoco.mj_forward(model, data)
    return np.array(data.qacc), model, data
