"""A branched robot as one kinematic tree: Baxter from ``example-robot-data``.

Loads the whole robot (head, two 7-joint arms, two-finger grippers: 19 joints) with
``vs.Tree.from_urdf``, prints its segment order and parent array, then moves both arms and checks
each gripper's Jacobian against finite differences of its forward kinematics: a joint of one arm
has a zero column in the other gripper's Jacobian. Finally it extracts the left arm as a serial
``Chain`` (``tree.chain``), as one would to solve the arms separately.

Run: ``python examples/tree_kinematics.py`` (needs ``pip install example-robot-data``; under 1 s).
"""

import numpy as np

import vereshchagin as vs


def position_jacobian_fd(tree, q, frame, h=1e-6):
    """Central differences of the frame origin's position (base frame), shape (3, n)."""
    cols = []
    for k in range(tree.n_joints):
        dq = np.zeros(tree.n_joints)
        dq[k] = h
        cols.append((tree.fk(q + dq, frame)[:3, 3] - tree.fk(q - dq, frame)[:3, 3]) / (2 * h))
    return np.array(cols).T


def main():
    tree = vs.Tree.from_urdf(vs.robots.example_robot_urdf("baxter"))
    print(tree)
    width = max(len(n) for n in tree.segment_names)
    print(f"{'segment':<{width}}  {'parent':<{width}}  joint")
    for i, (seg, joint) in enumerate(zip(tree.segment_names, tree.joint_names)):
        parent = "base" if tree.parent[i] < 0 else tree.segment_names[tree.parent[i]]
        print(f"{seg:<{width}}  {parent:<{width}}  {joint} ({tree.joint_types[i]})")
    for note in tree.notes:
        print("note:", note)

    rng = np.random.default_rng(1)
    q = rng.uniform(np.maximum(tree.lower, -1.0), np.minimum(tree.upper, 1.0))
    for gripper in ("left_gripper", "right_gripper"):
        J = tree.jacobian(q, gripper)
        err = np.abs(J[:3] - position_jacobian_fd(tree, q, gripper)).max()
        moving = [tree.joint_names[k] for k in np.flatnonzero(np.abs(J).sum(axis=0) > 0)]
        print(
            f"{gripper}: position {tree.fk(q, gripper)[:3, 3].round(3)} m, moved by {len(moving)} joints, "
            f"Jacobian vs finite differences {err:.1e}"
        )
        assert err < 1e-6

    left = tree.chain("left_gripper")
    idx = [tree.joint_index(n) for n in left.joint_names]
    print(
        f"left arm as a chain: {left.joint_names}, mass {left.segment_masses.sum():.2f} kg "
        f"of the tree's {tree.segment_masses.sum():.2f} kg"
    )
    assert np.allclose(left.fk(q[idx], "left_gripper"), tree.fk(q, "left_gripper"))


if __name__ == "__main__":
    main()
