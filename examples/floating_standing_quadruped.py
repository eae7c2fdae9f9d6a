"""A solo12 quadruped standing on its four feet, its base held still by the leg motors alone
(``vs.whole_body.least_effort``), then with its base moved and its legs re-posed.

The base of a free-flyer has no motor: a task on it (here "base still", six rows) is realized only
through the twelve leg joints and the feet, which stick to the ground with their forces in
friction cones (mu 0.7, square pyramids). Among all torques that do it, the solver returns those
of least motor effort ``sum(tau^2)`` and the feet's forces with them, exactly. The script prints
the vertical foot forces and the effort standing symmetrically, then with the base moved 4 cm
forward and 3 cm to the left and the legs re-posed (the weight shifts between the feet), and
what the solver says when the base is pushed sideways harder than the cones allow. A load on a leg
is given as ``Solver.solve`` takes it (``f_ext={segment or link: wrench}``). Last, the forward
dynamics of the same stance pushed sideways (``Solver.solve`` with the feet as contacts, mu 0.3):
the feet slide, and with the contact stage's real-time bound forced to one pivot
(``contact_max_pivots=1``) the solve returns its safe fallback (the feet held along their normals,
no friction) with a ``RuntimeWarning``.

Run: ``python examples/floating_standing_quadruped.py [out_dir]`` (prints only; under 1 s).
"""

import warnings

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GRAVITY = np.array([0.0, 0.0, -9.81])
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")

tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
solver = vs.Solver(tree, gravity=GRAVITY)


def feet(q):
    """Supports at the feet's origins (the feet are links merged into the lower legs)."""
    return [vs.Contact(foot, normal=[0, 0, 1], mu=0.7, facets=4) for foot in FEET]


def stand(q, push=None, f_ext=None):
    push = np.zeros(6) if push is None else push
    base_still = (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0])  # at rest: beta = [-gravity; 0]
    tau_ff = np.r_[push, np.zeros(tree.n_joints)]  # a wrench on the base (base axes)
    return vs.whole_body.least_effort(
        solver, q, np.zeros(tree.nv), task={None: base_still}, supports=feet(q), tau_ff=tau_ff, f_ext=f_ext
    )


q = np.zeros(tree.nq)
q[2], q[6] = 0.25, 1.0
q[7:] = [0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6]
r = stand(q)
print("standing on four feet: vertical forces (N)", np.round(r.contact_force[:, 2], 3))
print(f"  effort sum(tau^2) = {r.effort:.4f} N^2 m^2, base rows of tau {r.tau[:6]}")

# Shift the weight: the base moves and the legs lean (the feet move with them: this is another
# stance, solved the same way).
shifted = q.copy()
shifted[0], shifted[1] = 0.04, 0.03
shifted[7:] = [0.15, 0.65, -1.45, 0.25, 0.95, -1.75, 0.15, -0.95, 1.75, 0.25, -0.65, 1.45]
r2 = stand(shifted)
print("base shifted, legs re-posed: vertical forces (N)", np.round(r2.contact_force[:, 2], 3))
print(f"  effort {r2.effort:.4f}, the most loaded foot carries {r2.contact_force[:, 2].max():.2f} N")

try:
    stand(q, push=np.array([60.0, 0.0, 0.0, 0.0, 0.0, 0.0]))
except vs.SolverError as exc:
    print("pushed sideways with 60 N:", exc)

# A 15 N load pressing down on the front-left upper leg (base axes, about that link's origin).
r3 = stand(q, f_ext={"FL_UPPER_LEG": [0.0, 0.0, -15.0, 0.0, 0.0, 0.0]})
print("15 N on the front-left upper leg: vertical forces (N)", np.round(r3.contact_force[:, 2], 3))

# Forward dynamics, no task: the same stance, the legs' motors at their standing torques, pushed
# sideways on the base (20 N), the feet as contacts on slippery ground.
slippery = [vs.Contact(foot, normal=[0, 0, 1], mu=0.3) for foot in FEET]
push = np.r_[20.0, 0.0, 0.0, 0.0, 0.0, 0.0, r.tau[6:]]
exact = solver.solve(q, np.zeros(tree.nv), tau_ff=push, contacts=slippery)
print("pushed on slippery ground: contact status", exact.contact_status, "(2: sliding)")
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    held = solver.solve(q, np.zeros(tree.nv), tau_ff=push, contacts=slippery, contact_max_pivots=1)
print("with contact_max_pivots=1:", caught[0].message if caught else "no warning")
print("  fallback forces along the normals (N)", np.round(held.contact_force[:, 2], 3))
