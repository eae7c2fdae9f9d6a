"""One call for a whole trajectory: ``Solver.solve_batch`` over 2000 states of the Gen3.

The joints follow a smooth sinusoidal trajectory; at every state the tool must keep a zero
vertical (classical) acceleration. ``beta`` differs per row (it holds the velocity term
``-omega x v``), so it is passed with a leading batch axis; ``alpha`` is shared. The script
checks the batch against a loop of ``solve`` calls, prints both timings and plots the motor
commands and the vertical constraint force over time.

Run: ``python examples/batch_trajectory.py [out_dir]`` (writes batch_trajectory.png; about 2 s).
"""

import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs


def trajectory(q0, samples=2000, period=4.0):
    """Times (B,), positions and velocities (B, n) of q0 + a sin(2 pi t / period)."""
    t = np.linspace(0.0, period, samples)
    amplitude = np.array([0.4, 0.2, 0.3, 0.3, 0.5, 0.3, 0.6])
    w = 2.0 * np.pi / period
    q = q0 + amplitude * np.sin(w * t)[:, None]
    qd = amplitude * w * np.cos(w * t)[:, None]
    return t, q, qd


def main(out_dir="."):
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    t, Q, QD = trajectory(np.array(vs.robots.GEN3_START_POSE))
    alpha = vs.task.directions("z")
    beta = np.array([vs.task.beta_for(alpha, np.zeros(6), chain.twist(q, qd)) for q, qd in zip(Q, QD)])  # (B, 1)

    start = time.perf_counter()
    batch = solver.solve_batch(Q, QD, alpha, beta)
    t_batch = time.perf_counter() - start
    start = time.perf_counter()
    loop = [solver.solve(q, qd, alpha, b) for q, qd, b in zip(Q, QD, beta)]
    t_loop = time.perf_counter() - start
    np.testing.assert_allclose(batch.qdd, [r.qdd for r in loop], rtol=1e-12, atol=1e-12)
    print(f"{len(t)} states: solve_batch {t_batch * 1e3:.1f} ms, loop of solve {t_loop * 1e3:.1f} ms")
    print(
        f"largest |tau_command| {np.abs(batch.tau_command).max():.2f} N m, "
        f"constraint force {(-batch.nu[:, 0]).min():.2f} .. {(-batch.nu[:, 0]).max():.2f} N"
    )

    fig, (ax_tau, ax_nu) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    ax_tau.plot(t, batch.tau_command)
    ax_tau.set_ylabel("tau_command [N m]")
    ax_tau.legend([f"joint {j + 1}" for j in range(chain.n_joints)], ncol=4, fontsize=8)
    ax_tau.set_title("Gen3 on a sinusoidal trajectory, tool height acceleration held at 0")
    ax_nu.plot(t, -batch.nu[:, 0])
    ax_nu.set_ylabel("vertical force on the tool [N]")
    ax_nu.set_xlabel("time [s]")
    fig.tight_layout()
    out = Path(out_dir) / "batch_trajectory.png"
    fig.savefig(out, dpi=100)
    plt.close(fig)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
