"""Constraints on two segments at once: the Gen3's elbow rests on a support while the tool holds
its height and orientation.

KDL's solver constrains only the last segment; ``constraints={segment: (alpha_i, beta_i)}`` puts
acceleration constraints on any segments (same conventions as for the last one: unit wrenches in
base axes, moments about *that segment's* tip origin, ``beta`` including ``-gravity``). The
example compares three cases: the tool task alone, the elbow support alone, both; it prints the
support force and the motor commands, and checks that the elbow does not accelerate downwards.

Run: ``python examples/segment_constraints.py`` (about 1 s).
"""

import numpy as np

import vereshchagin as vs

G = 9.81


def main():
    chain = vs.robots.gen3()
    solver = vs.Solver(chain, gravity=[0.0, 0.0, -G])
    q = np.array(vs.robots.GEN3_START_POSE)
    qd = np.zeros(chain.n_joints)
    elbow = "forearm_link"  # segment 4 (index 3)

    tool_alpha = vs.task.directions(["z", "rx", "ry", "rz"])  # tool: height and orientation
    tool_beta = vs.task.beta_for(tool_alpha, np.zeros(6), chain.twist(q, qd))
    elbow_alpha = vs.task.directions("z")  # elbow: no vertical acceleration
    elbow_beta = vs.task.beta_for(elbow_alpha, np.zeros(6), chain.twist(q, qd, elbow))

    cases = {
        "tool task only": {"alpha": tool_alpha, "beta": tool_beta},
        "elbow support only": {"constraints": {elbow: (elbow_alpha, elbow_beta)}},
        "tool task + elbow support": {
            "alpha": tool_alpha,
            "beta": tool_beta,
            "constraints": {elbow: (elbow_alpha, elbow_beta)},
        },
    }
    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    elbow_index = chain.segment_index(elbow)
    for name, kwargs in cases.items():
        res = solver.solve(q, qd, **kwargs)
        # link_acc row 0 is the base; row i + 1 is segment i's tip. Subtract the base's +g.
        elbow_az = res.link_acc[elbow_index + 1, 2] - G
        tool_az = res.link_acc[-1, 2] - G
        print(f"{name}: rank {res.constraint_rank}")
        print(f"  elbow / tool vertical acceleration [m/s^2]: {elbow_az:8.3f} / {tool_az:8.3f}")
        if res.segment_nu:
            # The wrench on a constrained segment is -alpha_i @ nu_i: here a vertical force.
            print(f"  support force on the elbow [N]: {-res.segment_nu[elbow][0]:.3f}")
        print(f"  tau_command [N m]: {res.tau_command}")
    assert abs(elbow_az) < 1e-9 and abs(tool_az) < 1e-9


if __name__ == "__main__":
    main()
