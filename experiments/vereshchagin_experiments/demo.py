"""A short demonstration on a 7-joint arm: free fall, a held tool, a fully constrained tool."""

from __future__ import annotations

import numpy as np

from vereshchagin.models import seven_joint_arm
from vereshchagin import Solver


def run(out=print) -> dict:
    """Solve three tasks on the 7-joint arm and print what the solver returns.

    Returns
    -------
    dict
        Task name -> :class:`SolveResult`.
    """
    chain = seven_joint_arm()
    solver = Solver(chain, gravity=[0.0, 0.0, -9.81])
    q = np.array([0.0, 0.6, 0.0, -1.2, 0.0, 0.8, 0.0])
    qd = np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.1, 0.2])
    g = 9.81
    tasks = {
        "free (m=0)": (None, None),
        # Hold the tool's height: the tip accelerates with the base (+g up) along z.
        "hold z (m=1)": (np.eye(6)[:, [2]], np.array([g])),
        # Tool fully constrained: zero spatial acceleration apart from the root (gravity) term.
        "hold pose (m=6)": (np.eye(6), np.array([0.0, 0.0, g, 0.0, 0.0, 0.0])),
    }
    results = {}
    np.set_printoptions(precision=4, suppress=True, linewidth=110)
    out(f"7-joint arm, q = {q}, qd = {qd}, gravity -z")
    for name, (alpha, beta) in tasks.items():
        res = solver.solve(q, qd, alpha=alpha, beta=beta)
        results[name] = res
        out(f"\n{name}: rank {res.constraint_rank}")
        out(f"  qdd         [rad/s^2] {res.qdd}")
        out(f"  tau_command [N m]     {res.tau_command}")
        out(f"  nu                    {res.nu}")
        out(f"  tip acceleration (base axes, incl. +g up) {res.link_acc[-1]}")
    return results
