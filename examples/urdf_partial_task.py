"""A partial task on a URDF robot from ``example-robot-data``: the Franka Panda.

Loads the Panda's URDF from root link to hand (the fixed joints link7 -> link8 -> hand are merged,
the fingers are lumped into the hand, and ``chain.notes`` says so), then asks the hand to keep its
orientation and its height while the arm moves with some joint velocity, and to accelerate 0.5 m/s^2
along x; the remaining direction (y) is left to the dynamics. The tip's classical acceleration is
checked against the task by finite differences of the forward kinematics.

Run: ``python examples/urdf_partial_task.py`` (needs ``pip install example-robot-data``; about 1 s).
"""

import numpy as np

import vereshchagin as vs


def tip_position(chain, q):
    """Position of the chain's tip origin in the base frame (m)."""
    return chain.fk(q)[:3, 3]


def main():
    path = vs.robots.example_robot_urdf("panda")
    chain = vs.Chain.from_urdf(path, root="panda_link0", tip="panda_hand")
    print(f"{chain.n_joints} joints {chain.joint_names}")
    print(f"segments {chain.segment_names}")
    for note in chain.notes:
        print(f"note: {note}")

    solver = vs.Solver(chain)  # gravity [0, 0, -9.81] by default
    q = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.6, 0.8])
    qd = np.array([0.3, -0.2, 0.1, 0.4, -0.1, 0.2, 0.0])
    task = vs.task.Task(["x", "z", "rx", "ry", "rz"])  # y stays free
    a_desired = np.array([0.5, 0.0, 0.0, 0.0, 0.0, 0.0])
    res = task.solve(solver, chain, q, qd, a_desired)

    # Classical tip acceleration from the motion itself: second difference of the tip position
    # along q(t) = q + qd t + qdd t^2 / 2.
    h = 1e-4
    p = [tip_position(chain, q + qd * t + 0.5 * res.qdd * t * t) for t in (-h, 0.0, h)]
    acc = (p[0] - 2.0 * p[1] + p[2]) / (h * h)
    np.set_printoptions(precision=4, suppress=True)
    print(f"\nqdd [rad/s^2]            {res.qdd}")
    print(f"tau_command [N m]        {res.tau_command}")
    print(f"tip acceleration [m/s^2] {acc}  (asked: x 0.5, z 0; y free)")
    print(f"constraint rank {res.constraint_rank}, smallest singular value {res.smallest_singular_value:.3g}")
    assert abs(acc[0] - 0.5) < 1e-3 and abs(acc[2]) < 1e-3


if __name__ == "__main__":
    main()
