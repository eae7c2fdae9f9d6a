"""A Kinova Gen3 held by its joints' static friction, released by a load on its tool that grows
with time, simulated by ``vs.Simulator.rollout`` with a controller callback.

The controller is a function of the time only here: it returns the tool load of that step, a force
pulling the tool down that grows at 5 N/s, as the ``f_ext`` solve argument. The joints' breakaway
friction holds the arm exactly still (each step ends at exactly zero velocity while a joint's
holding torque stays within its friction) until the load is large enough; the rollout records the
states and the friction torques, and the script prints when and where the arm broke away, and the
load the statics predict for it (the smallest load at which some joint's holding torque reaches
its breakaway friction).

Run: ``python examples/simulator_rollout.py [out_dir]`` (prints only; about 1 s).
"""

import sys
from pathlib import Path

import numpy as np

import vereshchagin as vs

TOOL = vs.robots.GEN3_TIP_LINK
DT, RATE, DURATION = 1e-3, 5.0, 3.0  # s; N/s of tool load growth; s


def holding_torques(chain, q, load):
    """Torques the joints hold with the arm still and ``load`` N pulling the tool down."""
    J = np.asarray(chain.jacobian(q, TOOL))[:3]
    return chain.gravity_torques(q) - J.T @ np.array([0.0, 0.0, -load])


def predicted_breakaway(chain, q, friction):
    """The smallest load at which some joint's holding torque reaches its breakaway friction (bisection)."""
    lo, hi = 0.0, 500.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.all(np.abs(holding_torques(chain, q, mid)) < friction) else (lo, mid)
    return hi


def main(out_dir: Path) -> None:
    chain = vs.robots.gen3()
    q0 = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
    f = np.abs(chain.gravity_torques(q0)) + np.array([4.0, 4.0, 4.0, 4.0, 1.5, 1.5, 1.5])  # N m
    friction = vs.Friction(static=f, kinetic=0.8 * f)

    def tool_load(t, q, qd):
        return {"f_ext": {TOOL: [0.0, 0.0, -RATE * t, 0.0, 0.0, 0.0]}}

    sim = vs.Simulator(chain, DT, q=q0)
    rec = sim.rollout(int(DURATION / DT), controller=tool_load, friction=friction, record=("friction_torque", "status"))
    moving = np.flatnonzero(np.any(rec["qd"] != 0.0, axis=1))
    k = int(moving[0])  # the first state with a joint moving: the end of step k - 1
    t_break = rec["t"][k - 1]  # that step's start, where its load was set
    joint = int(np.argmax(np.abs(rec["qd"][k])))
    held = rec["q"][:k]
    print(
        f"{len(rec['t']) - 1} steps of {DT * 1e3:.0f} ms recorded: t {rec['t'].shape}, q {rec['q'].shape}, "
        f"friction_torque {rec['friction_torque'].shape}"
    )
    print(f"held exactly still for {k - 1} steps (q bitwise q0: {bool(np.all(held == q0))})")
    print(f"broke away at t = {t_break:.3f} s, tool load {RATE * t_break:.3f} N, joint {joint} first")
    print(f"statics predict {predicted_breakaway(chain, q0, f):.3f} N (steps of {RATE * DT:.3f} N)")
    print(
        f"friction torque of joint {joint} in the step before: {rec['friction_torque'][k - 2, joint]:+.3f} N m "
        f"(breakaway {f[joint]:.3f} N m); after {DURATION:.0f} s the arm has fallen "
        f"{np.degrees(np.abs(rec['q'][-1] - q0).max()):.1f} deg at its most moved joint"
    )
    assert np.all(held == q0) and abs(RATE * t_break - predicted_breakaway(chain, q0, f)) <= RATE * DT + 1e-9


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("."))
