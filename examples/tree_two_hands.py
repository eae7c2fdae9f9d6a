"""Both hands of a humanoid held still: the whole tree against two separate arm chains.

Talos (example-robot-data's ``talos_reduced``, 32 joints below a fixed ``base_link``): both
grippers must keep still (6-D each) at rest under gravity. The tree solver couples the two tasks
through the shared torso; solving each arm as a separate chain (base -> torso -> arm, the other
arm and the legs left out) gives each chain's command torques, and the torso gets the left chain's.
Both torque sets are then replayed on the whole tree (plain forward dynamics) and the hands'
accelerations compared with the task: the tree's torques meet it to round-off, the separate
chains' do not (the torso carries both arms, which neither chain knows).

Run: python examples/tree_two_hands.py
"""

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

HANDS = ("gripper_left_base_link", "gripper_right_base_link")
UP = np.array([0.0, 0.0, 9.81, 0.0, 0.0, 0.0])  # beta includes -gravity: "still" is alpha^T UP


def hand_task_error(tree, q, tau):
    """Replay tau on the whole tree at rest; the hands' spatial acceleration minus "still" (m/s^2, rad/s^2)."""
    qdd = vs.Solver(tree).solve(q, np.zeros(tree.n_joints), tau_ff=tau).qdd
    return {h: np.linalg.norm(tree.jacobian(q, h) @ qdd) for h in HANDS}  # at rest: Xdd - UP = J qdd


def main():
    tree = vs.Tree.from_urdf(example_robot_urdf("talos_reduced"))
    n = tree.n_joints
    rng = np.random.default_rng(0)
    q = rng.uniform(np.maximum(tree.lower, -0.5), np.minimum(tree.upper, 0.5))
    still = {h: (np.eye(6), UP) for h in HANDS}

    whole = vs.Solver(tree).solve(q, np.zeros(n), constraints=still)
    tau_tree = whole.tau_command

    tau_chains = np.zeros(n)
    for hand in reversed(HANDS):  # the left chain's torso torques are the ones kept
        chain = tree.chain(hand)
        idx = [tree.joint_index(j) for j in chain.joint_names]
        res = vs.Solver(chain).solve(q[idx], np.zeros(len(idx)), np.eye(6), UP)
        tau_chains[idx] = res.tau_command

    print(f"Talos, {n} joints, both hands held still at rest")
    for label, tau in (("whole tree", tau_tree), ("separate chains", tau_chains)):
        err = hand_task_error(tree, q, tau)
        print(f"  {label:16s} hand acceleration error: " + ", ".join(f"{h} {e:.2e}" for h, e in err.items()))
    torso = [tree.joint_index(j) for j in tree.joint_names if j.startswith("torso")]
    print(f"  torso torques: tree {np.round(tau_tree[torso], 2)}, separate chains {np.round(tau_chains[torso], 2)} N m")
    assert max(hand_task_error(tree, q, tau_tree).values()) < 1e-8


if __name__ == "__main__":
    main()
