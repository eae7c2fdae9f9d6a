"""The linearised (affine) response of a solve: predict the next step without solving again.

With the state and the task fixed, ``qdd`` and ``tau_command`` are affine in the feed-forward
torques: ``qdd(tau_ff + d) = qdd(tau_ff) + G d`` where ``G`` is the constrained inverse inertia.
``Solver.response_columns(joints)`` returns the columns of ``G`` (and of ``d tau_command``) for
the last solve, O(n) each. A controller can use them to predict, for any candidate torque
correction ``d``, the accelerations and the next velocities after one step ``dt``, and to pick the
correction it wants; the script checks the prediction against fresh solves.

Run: ``python examples/linearised_response.py`` (about 1 s).
"""

import numpy as np

import vereshchagin as vs


def main():
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    rng = np.random.default_rng(0)
    q = np.array(vs.robots.GEN3_START_POSE)
    qd = rng.normal(scale=0.3, size=chain.n_joints)
    tau_ff = rng.normal(scale=2.0, size=chain.n_joints)
    task = vs.task.Task("z")  # the tool keeps its height
    base = task.solve(solver, chain, q, qd, np.zeros(6), tau_ff=tau_ff)
    joints = list(range(chain.n_joints))
    G, dcmd = solver.response_columns(joints)  # both (n, n), per N m of tau_ff

    dt = 1e-3
    np.set_printoptions(precision=4, suppress=True, linewidth=120)
    print("G (constrained inverse inertia) is symmetric:", np.allclose(G, G.T, atol=1e-12))
    print(f"eigenvalues of G: {np.linalg.eigvalsh(G)}  (one zero: the task's direction)\n")
    worst = 0.0
    for k in range(3):
        d = rng.normal(scale=1.0, size=chain.n_joints)  # a candidate correction, N m
        predicted_qdd = base.qdd + G @ d
        predicted_cmd = base.tau_command + dcmd @ d
        exact = task.solve(solver, chain, q, qd, np.zeros(6), tau_ff=tau_ff + d)
        err = max(np.abs(predicted_qdd - exact.qdd).max(), np.abs(predicted_cmd - exact.tau_command).max())
        worst = max(worst, err)
        print(f"correction {k}: predicted qd after {dt * 1e3:.0f} ms {qd + dt * predicted_qdd}")
        print(f"              largest deviation from a fresh solve: {err:.2e}")
    # The smallest correction (2-norm) that adds 1 rad/s^2 at joint 2: one row of G, one equation.
    row = G[1]
    d = row / (row @ row)
    print(f"\nsmallest correction for +1 rad/s^2 at joint 2: {d} N m")
    print(f"resulting change of qdd (joint 2 exactly +1, the others follow through G): {G @ d}")
    assert worst < 1e-9


if __name__ == "__main__":
    main()
