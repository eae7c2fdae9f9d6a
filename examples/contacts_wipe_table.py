"""The Kinova Gen3 wipes a table with 15 N while its forearm rests on a support.

Three solves of the same instant (the arm still, the tool to accelerate along x at 0.5 m/s^2):

1. free space: the tool's position task alone (x accelerates, y and z held), the motors carry all;
2. the tool pressed on the table with a 15 N normal-force set-point (``vs.Contact(..., force=15)``:
   the tool stays on the surface, the table pushes back with exactly 15 N, friction mu = 0.3 drags
   on it), the tool's x and y tasks as before (z is the contact's);
3. as 2, with the forearm resting on a support (``vs.Contact(..., mu=0.6)``, force=None): the
   support pushes up with whatever the dynamics need (never pulls) and takes load off the
   shoulder and elbow motors.

For each it prints the motors' torques (``tau_command``: the motors only; the surfaces' forces are
reported separately), the contact forces and statuses, and checks that replaying the motors and the
contact forces through the companions' inverse dynamics gives back the same accelerations.

Run: ``python examples/contacts_wipe_table.py [out_dir]`` (writes contacts_wipe_table.png; about 2 s).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs

TOOL = vs.robots.GEN3_TIP_LINK


def solve_case(solver, chain, q, contacts, axes):
    """One solve: the tool's classical acceleration (0.5 m/s^2 along x, zero otherwise) along
    ``axes``, with ``contacts``."""
    a_desired = np.zeros(6)
    a_desired[0] = 0.5  # tool x, m/s^2
    return vs.task.Task(axes).solve(solver, chain, q, np.zeros(chain.n_joints), a_desired, contacts=contacts)


def replay_error(chain, q, res, contacts):
    """max |tau_needed - tau_applied|: inverse dynamics of qdd with the contact forces as wrenches
    (each about its link's origin: the moment of the force at the contact point)."""
    f_ext = {}
    for c, f in zip(contacts, res.contact_force):
        r = chain.fk(q, c.segment)[:3, :3] @ c.point  # the point from the link's origin, base axes
        f_ext[c.segment] = np.concatenate([f, np.cross(r, f)])
    tau = chain.inverse_dynamics(q, np.zeros(chain.n_joints), res.qdd, f_ext=f_ext or None)
    return float(np.max(np.abs(tau - res.tau_command)))


def main(out_dir: Path) -> None:
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    q = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])
    wipe = vs.Contact(TOOL, normal=[0, 0, 1], mu=0.3, force=15.0)
    forearm = vs.Contact("forearm_link", point=[0.0, 0.0, -0.1], normal=[0, 0, 1], mu=0.6)
    cases = {
        "free space": ([], ["x", "y", "z"]),
        "tool presses 15 N": ([wipe], ["x", "y"]),
        "and forearm rests": ([wipe, forearm], ["x", "y"]),
    }
    commands = {}
    for name, (contacts, axes) in cases.items():
        res = solve_case(solver, chain, q, contacts, axes)
        commands[name] = res.tau_command
        print(f"{name}: |tau_command| = {np.linalg.norm(res.tau_command):.3f} N m")
        print(f"  tau_command [N m] = {np.round(res.tau_command, 3)}")
        for c, f, s in zip(contacts, res.contact_force, res.contact_status):
            print(f"  {c.segment}: force {np.round(f, 3)} N, {vs.ContactStatus(s).name.lower()}")
        print(f"  replay error {replay_error(chain, q, res, contacts):.1e} N m; outcome {res.contact_outcome.name}")
    fig, ax = plt.subplots(figsize=(8, 4))
    width = 0.27
    joints = np.arange(chain.n_joints)
    for k, (name, tau) in enumerate(commands.items()):
        ax.bar(joints + (k - 1) * width, tau, width, label=name)
    ax.set_xticks(joints, [f"joint {j}" for j in joints])
    ax.set_ylabel("motor torque tau_command [N m]")
    ax.set_title("Gen3 wiping a table: what the surfaces take off the motors")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "contacts_wipe_table.png", dpi=120)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("."))
