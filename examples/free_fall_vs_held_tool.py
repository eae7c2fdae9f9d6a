"""Free fall vs. a held tool on the Kinova Gen3: what the partial task changes.

The arm starts at rest in a bent pose with its motors off (``tau_ff = 0``). Without a task it
falls; with the task "the tool's height does not accelerate" the solver returns the motion of
least acceleration energy that keeps the height, and the motor torques that realise it. The task
helpers (``vereshchagin.task``) state the task in the classical acceleration a controller thinks
in, so nobody has to remember that holding the height against gravity needs ``beta = +9.81``.

Run: ``python examples/free_fall_vs_held_tool.py`` (prints a table, about 1 s).
"""

import numpy as np

import vereshchagin as vs


def main():
    chain = vs.robots.gen3()  # 7 joints, base_link -> end_effector_link
    solver = vs.Solver(chain, gravity=[0.0, 0.0, -9.81])
    q = np.array(vs.robots.GEN3_START_POSE)  # rad
    qd = np.zeros(chain.n_joints)  # rad/s

    free = solver.solve(q, qd)
    hold_z = vs.task.Task("z")  # one constraint: tool z, base axes
    held = hold_z.solve(solver, chain, q, qd, a_desired=np.zeros(6))
    hold_pose = vs.task.Task(["x", "y", "z", "rx", "ry", "rz"])
    fixed = hold_pose.solve(solver, chain, q, qd, a_desired=np.zeros(6))

    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    print(f"Kinova Gen3 at rest, q = {q} rad, gravity -z\n")
    rows = [("free fall (m = 0)", free), ("tool height held (m = 1)", held), ("tool pose held (m = 6)", fixed)]
    print(f"{'task':26s} {'tool acc. z [m/s^2]':>20s} {'|qdd| [rad/s^2]':>16s}  tau_command [N m]")
    for name, res in rows:
        # link_acc includes the base acceleration -gravity: subtract it for the classical value.
        a_z = res.link_acc[-1, 2] - 9.81
        print(f"{name:26s} {a_z:20.3f} {np.linalg.norm(res.qdd):16.3f}  {res.tau_command}")
    print(
        f"\nbeta used for the held height: {vs.task.beta_for(hold_z.alpha, np.zeros(6), chain.twist(q, qd))} "
        "(= +g: the base accelerates upwards by g in the solver's convention)"
    )
    print(f"constraint force on the tool when held: {-held.nu[0]:.2f} N along z")
    assert abs(held.link_acc[-1, 2] - 9.81) < 1e-9 and free.link_acc[-1, 2] < 9.81


if __name__ == "__main__":
    main()
