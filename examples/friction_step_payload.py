"""A Kinova Gen3 held by its joints' static friction while a payload on its tool grows slowly: it
holds, exactly still, then breaks away at the load the statics predict.

The simulation steps the arm with ``Solver.step`` (semi-implicit Euler, dt = 1 ms) with breakaway
friction on every joint: each step solves the friction impulses exactly at the end velocities (a
joint whose holding torque stays within its breakaway friction ends the step at exactly zero
velocity). The payload pulls the tool straight down with a force growing at 2 N/s.

The prediction: while every joint sticks, joint j must hold tau_j(F) = g_j(q) + J_j^T (F e_z) (the
gravity torques plus the payload's, the arm still); the arm breaks away at the smallest F where
some |tau_j(F)| reaches its breakaway friction f_j. The script finds that F by bisection on the
statics, runs the steps, and prints the load at which the first joint moved, which joint, and
how far q drifted while held (0: bitwise).

Run: ``python examples/friction_step_payload.py [out_dir]`` (writes friction_step_payload.png;
about 2 s).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs

TOOL = vs.robots.GEN3_TIP_LINK
DT, RATE = 1e-3, 2.0  # s; N/s of payload growth


def holding_torques(chain, q, load):
    """Torques the joints must hold with the arm still and ``load`` N pulling the tool down."""
    J = np.asarray(chain.jacobian(q, TOOL))[:3]
    return chain.gravity_torques(q) - J.T @ np.array([0.0, 0.0, -load])


def predicted_breakaway(chain, q, friction):
    """The smallest load at which some joint's holding torque reaches its breakaway friction."""
    lo, hi = 0.0, 200.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if np.all(np.abs(holding_torques(chain, q, mid)) < friction):
            lo = mid
        else:
            hi = mid
    return hi, int(np.argmax(np.abs(holding_torques(chain, q, hi)) / friction))


def main(out_dir: Path) -> None:
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    q0 = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
    # Breakaway friction with 3 N m (1 N m on the wrist) of margin over the unloaded holding torques.
    f = np.abs(chain.gravity_torques(q0)) + np.array([3.0, 3.0, 3.0, 3.0, 1.0, 1.0, 1.0])
    friction = vs.Friction(static=f, kinetic=0.8 * f)
    load_pred, joint_pred = predicted_breakaway(chain, q0, f)

    q, qd = q0.copy(), np.zeros(7)
    loads, angles, moved_at = [], [], None
    for k in range(int((load_pred + 2.0) / RATE / DT)):
        load = RATE * DT * k
        f_ext = {TOOL: [0.0, 0.0, -load, 0.0, 0.0, 0.0]}
        q_next, qd_next, r = solver.step(q, qd, DT, friction=friction, f_ext=f_ext)
        if moved_at is None and qd_next.any():
            moved_at = (load, int(np.argmax(np.abs(qd_next))), np.abs(q - q0).max())
        q, qd = q_next, qd_next
        loads.append(load)
        angles.append(q - q0)
    load_obs, joint_obs, drift = moved_at
    print(f"predicted breakaway: {load_pred:.3f} N, joint {joint_pred} first")
    print(f"simulated breakaway: {load_obs:.3f} N (within one step's {RATE * DT:.3f} N), joint {joint_obs} first")
    print(f"drift of q while held: {drift:.1e} rad (bitwise still: {drift == 0.0})")
    assert abs(load_obs - load_pred) <= RATE * DT + 1e-9 and joint_obs == joint_pred and drift == 0.0

    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(loads, np.degrees(np.array(angles)), lw=1)
    ax.axvline(load_pred, color="k", ls="--", lw=0.8, label=f"predicted breakaway {load_pred:.2f} N")
    ax.set_xlabel("payload [N]")
    ax.set_ylabel("q - q0 [deg]")
    ax.set_title("Gen3 held by static friction under a growing payload (dt = 1 ms)")
    ax.legend([f"joint {j}" for j in range(7)] + [f"predicted breakaway {load_pred:.2f} N"], fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out_dir / "friction_step_payload.png", dpi=120)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("."))
