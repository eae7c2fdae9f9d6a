"""The landing page's figures: what the solver computes, drawn from its own results.

A Kinova Gen3 starts at rest and is released for 0.4 s: once with no task (it falls), once with
one constraint, "the tool's height stays put" (``vs.task.Task("z")`` with a PD term on the height
so that integration drift is corrected). The solver returns the joint
accelerations of least acceleration energy that meet the constraint and the motor torques that
realise them; integrating them gives the motions drawn here. ``draw(out_dir)`` writes
``task_motion.png`` (stick figures and the tool's height) and ``task_torques.png`` (the torques).
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs

Q0 = np.array([0.0, 0.5, 0.0, 1.6, 0.0, -0.6, 0.0])  # rad: the arm reaching forward
DT, STEPS = 1e-3, 400
KP, KD = 400.0, 40.0  # 1/s^2, 1/s: the height loop of the held run


def simulate(chain, task):
    """Semi-implicit Euler over STEPS steps; returns q (STEPS+1, n), tau_command (STEPS, n)."""
    solver = vs.Solver(chain)
    q, qd = Q0.copy(), np.zeros(chain.n_joints)
    z0 = chain.fk(q)[2, 3]
    qs, taus = [q.copy()], []
    for _ in range(STEPS):
        if task is None:
            res = solver.solve(q, qd)
        else:
            a = np.zeros(6)
            a[2] = KP * (z0 - chain.fk(q)[2, 3]) - KD * chain.twist(q, qd)[2]
            res = task.solve(solver, chain, q, qd, a_desired=a)
        qd = qd + DT * res.qdd
        q = q + DT * qd
        qs.append(q.copy())
        taus.append(res.tau_command.copy())
    return np.array(qs), np.array(taus)


def _stick(ax, chain, q, **style):
    """The arm in the x-z plane: base, then every segment tip (fk_all: (n_segments, 4, 4))."""
    points = np.vstack([np.zeros(3), chain.fk_all(q)[:, :3, 3]])
    ax.plot(points[:, 0], points[:, 2], "-o", markersize=2.5, **style)


def draw(out_dir):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    chain = vs.robots.gen3()
    runs = {"no task: falls": simulate(chain, None), "task z: tool height held": simulate(chain, vs.task.Task("z"))}
    colors = {"no task: falls": "tab:red", "task z: tool height held": "tab:blue"}

    fig, (arm, height) = plt.subplots(1, 2, figsize=(9.5, 3.6), gridspec_kw={"width_ratios": [1.1, 1]})
    _stick(arm, chain, Q0, color="0.5", label="start (at rest)")
    for label, (qs, _) in runs.items():
        for k in (STEPS // 2, STEPS):
            alpha = 0.45 + 0.55 * k / STEPS
            _stick(arm, chain, qs[k], color=colors[label], alpha=alpha, label=label if k == STEPS else None)
        z = [chain.fk(q)[2, 3] for q in qs]
        height.plot(np.arange(STEPS + 1) * DT, z, color=colors[label], label=label)
    arm.set_aspect("equal")
    arm.set_xlabel("x (m)")
    arm.set_ylabel("z (m)")
    arm.set_title("Gen3 released from rest (0.2 s, 0.4 s)")
    arm.legend(loc="lower left", fontsize=8)
    height.set_xlabel("time (s)")
    height.set_ylabel("tool height z (m)")
    height.set_title("The constrained direction only")
    height.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "task_motion.png", dpi=110)
    plt.close(fig)

    _, taus = runs["task z: tool height held"]
    fig, ax = plt.subplots(figsize=(7, 3.2))
    for j in range(chain.n_joints):
        ax.plot(np.arange(STEPS) * DT, taus[:, j], label=f"joint {j + 1}")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("tau_command (N m)")
    ax.set_title("Motor torques that hold only the tool's height (least acceleration energy)")
    ax.legend(ncol=4, fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "task_torques.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    draw(Path(__file__).resolve().parents[1] / "_generated")
