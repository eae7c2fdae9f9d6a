"""Static joint friction holding the Kinova Gen3, and the friction torques while it lets go.

Part 1: the tool is held still (a 6-D task) with the arm at rest. Without friction the motors
carry the whole gravity load; with breakaway friction ``f`` the solver takes the least motor
command among the equally good friction splits (static friction holds what it can), so the
command falls with ``f`` and reaches zero once friction alone can hold the arm.

Part 2: a slow motion. The motors first hold the arm (``tau_ff`` = the holding torques) and then
ramp down to zero over two seconds; each joint sticks until the load exceeds its breakaway
friction, then slips with its kinetic friction. The plot shows every joint's friction torque and
stick/slip status over time (semi-implicit Euler, 2 ms steps).

Run: ``python examples/static_friction_hold.py [out_dir]`` (writes static_friction_hold.png; about 2 s).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs


def holding_torques(solver, q):
    """Joint torques (N m) that hold the arm at rest at ``q`` against gravity.

    With friction far above any load and every joint at rest, the max-min makes every joint stick
    (qdd = 0), so the friction torque (physical, acting on the joint) is exactly the torque that
    holds the arm; the motors must supply the same torque to hold it without friction.
    """
    n = solver.n_joints
    res = solver.solve(q, np.zeros(n), friction=vs.Friction(static=np.full(n, 1e6)))
    assert np.all(np.abs(res.qdd) < 1e-9)
    return res.friction_torque


def command_versus_friction(solver, chain, q, load):
    """Part 1: |tau_command| of a held tool for breakaway friction = scale * |holding torque|."""
    hold = vs.task.Task(["x", "y", "z", "rx", "ry", "rz"])
    qd = np.zeros(solver.n_joints)
    print("Part 1: tool held still (m = 6); breakaway friction f = scale * |holding torque|")
    print(f"{'scale':>6s} {'|tau_command| [N m]':>20s}   tau_command")
    for scale in (0.0, 0.25, 0.5, 0.75, 1.0, 1.25):
        friction = vs.Friction(static=scale * np.abs(load))
        res = hold.solve(solver, chain, q, qd, np.zeros(6), friction=friction)
        print(f"{scale:6.2f} {np.linalg.norm(res.tau_command):20.4f}   {np.round(res.tau_command, 3)}")
    return res


def let_go(solver, q0, load, seconds=2.5, dt=2e-3, ramp=2.0):
    """Part 2: motors ramp from holding to zero; returns times, friction torques and status."""
    static = 0.8 * np.abs(load) + 0.5
    friction = vs.Friction(static=static, kinetic=0.9 * static, velocity_tolerance=1e-4)
    q, qd = q0.copy(), np.zeros_like(q0)
    times, torques, status = [], [], []
    for k in range(int(round(seconds / dt))):
        t = k * dt
        share = max(0.0, 1.0 - t / ramp)
        res = solver.solve(q, qd, tau_ff=share * load, friction=friction)
        qd = qd + dt * res.qdd
        q = q + dt * qd
        times.append(t)
        torques.append(res.friction_torque)
        status.append(res.status)
    return np.array(times), np.array(torques), np.array(status), q


def plot(times, torques, status, out):
    """Friction torque and stick/slip status of every joint over time, saved to ``out``."""
    fig, (ax_tau, ax_st) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    for j in range(torques.shape[1]):
        ax_tau.plot(times, torques[:, j], label=f"joint {j + 1}")
        ax_st.plot(times, status[:, j] + 0.04 * j, label=f"joint {j + 1}")
    ax_tau.set_ylabel("friction torque [N m]")
    ax_tau.legend(ncol=4, fontsize=8)
    ax_tau.set_title("Gen3, motors ramping from holding to zero over 2 s")
    ax_st.set_yticks([0, 1, 2, 3], ["moving", "stick", "slip +", "slip -"])
    ax_st.set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def main(out_dir="."):
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    q = np.array(vs.robots.GEN3_START_POSE)
    load = holding_torques(solver, q)
    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    print(f"holding torques [N m]: {load}\n")
    res = command_versus_friction(solver, chain, q, load)
    assert np.linalg.norm(res.tau_command) < 1e-6, "friction above the load must hold the tool alone"

    times, torques, status, q_end = let_go(solver, q, load)
    broke = [times[np.argmax(status[:, j] != 1)] if np.any(status[:, j] != 1) else None for j in range(7)]
    print("\nPart 2: breakaway time per joint [s]:", ["-" if b is None else f"{b:.2f}" for b in broke])
    print(f"joint motion after 2.5 s [rad]: {q_end - q}")
    out = Path(out_dir) / "static_friction_hold.png"
    plot(times, torques, status, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
