"""A dense, independent oracle of the constrained solve and its singularity policies (issue 23).

Built only from Pinocchio's pieces and numpy, with the documented math (docs/algorithm.md, "The
coupling matrix and singular tasks"; the ``vs.Solver`` docstring):

* ``M = pin.crba`` (with the armature), ``b = pin.rnea(q, qd, 0)`` (velocity products and gravity,
  Pinocchio's ``model.gravity`` = our physical gravity ``g``), the generalised external force
  ``sum_i J_i^T w_i`` (our ``f_ext`` rows, base axes, moment about each tip origin):
  ``qdd_free = M^-1 (tau + tau_ext - b)``;
* per constrained tip frame: ``J`` the LOCAL_WORLD_ALIGNED frame Jacobian (twist of the tip
  origin in base axes) and the drift at ``qdd = 0`` from ``pin.getFrameClassicalAcceleration``.
  The solver's accelerations are KDL's spatial ones: linear part ``a_classical - w x v`` (see
  tests/unit/test_api.py, the stretched arm), plus the base acceleration ``[-g; 0]`` that ``beta``
  includes;
* ``A = [alpha_i^T J_i]``, ``r = A qdd_free + [alpha_i^T (a0_i + [-g; 0]) - beta_i]``,
  ``K = A M^-1 A^T``; the policy gives ``nu = P(K) r``, then ``qdd = qdd_free - M^-1 A^T nu`` and
  ``tau_command = -A^T nu``;
* policies: damped least squares ``P(K) = (K^2 + d^2 I)^-1 K`` (the same matrix as every eigenvalue
  ``lambda`` inverted as ``lambda / (lambda^2 + d^2)``, written without an eigen-decomposition);
  truncated pseudo-inverse ``P(K) = sum_{lambda_k > cut} v_k v_k^T / lambda_k`` (``numpy.linalg.eigh``).

Nothing here calls the code under test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from support.chains import symmetric

LWA = pin.LOCAL_WORLD_ALIGNED


@dataclass
class DenseTask:
    M: np.ndarray  # (n, n) mass matrix with armature
    qdd_free: np.ndarray  # (n,) unconstrained forward dynamics
    A: np.ndarray  # (m, n) task rows alpha^T J, stacked in nu's order
    r: np.ndarray  # (m,) right-hand side: K nu = r
    K: np.ndarray  # (m, m) coupling matrix A M^-1 A^T
    drift: np.ndarray  # (m,) alpha^T (a0 + [-g; 0]): task acceleration at qdd = 0
    beta: np.ndarray  # (m,)

    def outputs(self, nu):
        """(qdd, tau_command) of the multipliers nu."""
        qdd = self.qdd_free - np.linalg.solve(self.M, self.A.T @ nu)
        return qdd, -self.A.T @ nu

    def task_acc(self, qdd):
        """alpha^T a of every task row at the joint accelerations qdd (beta when the task is met)."""
        return self.A @ qdd + self.drift

    def damped(self, d):
        """nu of damped least squares: (K^2 + d^2 I)^-1 K r."""
        K = self.K
        return np.linalg.solve(K @ K + d * d * np.eye(len(K)), K @ self.r)

    def truncated(self, cut):
        """nu of the truncated pseudo-inverse: eigenvalues <= cut dropped. Returns (nu, rank)."""
        lam, V = np.linalg.eigh(self.K)
        keep = lam > cut
        Vk = V[:, keep]
        return Vk @ ((Vk.T @ self.r) / lam[keep]), int(keep.sum())


def spatial_drift(model, data, fid):
    """The KDL spatial acceleration [linear; angular] of frame fid (base axes, frame origin) at
    the kinematics already computed in data (forwardKinematics with q, qd, qdd = 0)."""
    v = pin.getFrameVelocity(model, data, fid, LWA)
    ac = pin.getFrameClassicalAcceleration(model, data, fid, LWA)
    return np.concatenate([ac.linear - np.cross(v.angular, v.linear), ac.angular])


def dense_task(model, frames, q, qd, g, tau, tasks, f_ext=None):
    """The dense problem of a solve.

    Parameters
    ----------
    model : pin.Model
        Its gravity is set to ``g`` here.
    frames : sequence of int
        Pinocchio frame id of each of our segments' tip frames (``f_ext`` rows in this order).
    q, qd, tau : ndarray (n,)
        Pinocchio configuration / velocity / feed-forward torque.
    g : array_like (3,)
        Physical gravity, base axes.
    tasks : sequence of (frame id, alpha (6, m_i), beta (m_i,))
        Constrained tip frames in nu's order.
    f_ext : ndarray (len(frames), 6) or None
    """
    g = np.asarray(g, float)
    model.gravity = pin.Motion(np.concatenate([g, np.zeros(3)]))
    data = model.createData()
    nv = model.nv
    M = symmetric(pin.crba(model, data, q))
    b = np.array(pin.rnea(model, data, q, qd, np.zeros(nv)))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    tau_ext = np.zeros(nv)
    if f_ext is not None:
        for fid, w in zip(frames, f_ext):
            J = np.reshape(pin.getFrameJacobian(model, data, fid, LWA), (6, nv))
            tau_ext += J.T @ w
    qdd_free = np.linalg.solve(M, tau + tau_ext - b)
    pin.forwardKinematics(model, data, q, qd, np.zeros(nv))
    pin.updateFramePlacements(model, data)
    base = np.concatenate([-g, np.zeros(3)])
    rows, drift, beta = [], [], []
    for fid, alpha, bet in tasks:
        alpha = np.asarray(alpha, float).reshape(6, -1)
        J = np.reshape(pin.getFrameJacobian(model, data, fid, LWA), (6, nv))
        rows.append(alpha.T @ J)
        drift.append(alpha.T @ (spatial_drift(model, data, fid) + base))
        beta.append(np.atleast_1d(np.asarray(bet, float)))
    A = np.vstack(rows)
    drift, beta = np.concatenate(drift), np.concatenate(beta)
    Minv_At = np.linalg.solve(M, A.T)
    K = A @ Minv_At
    K = 0.5 * (K + K.T)
    r = A @ qdd_free + drift - beta
    return DenseTask(M=M, qdd_free=qdd_free, A=A, r=r, K=K, drift=drift, beta=beta)
