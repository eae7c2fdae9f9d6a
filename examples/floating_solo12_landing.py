"""A solo12 quadruped on a free-flyer base (``Tree.from_urdf(..., base="free")``) dropped from a few
centimetres onto flat ground and simulated by ``vs.Simulator`` with its feet as supports
(``vs.Contact``, friction 0.9) once they touch and its joints held by static friction.

The step is the velocity-level one (docs/time-step.md): a foot that reaches the ground stops
there (an inelastic impact, no bounce), the joints slip under the impact and then stick, and once
every joint and every foot sticks the robot stands exactly still: ``qd`` is exactly zero and ``q``
no longer changes, while the ground carries the robot's weight. The script prints the base height,
the feet in contact, the contact forces' sum and the largest velocity every 25 ms.

Run: ``python examples/floating_solo12_landing.py [out_dir]`` (prints only; about 1 s).
"""

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GRAVITY = np.array([0.0, 0.0, -9.81])
DT, DURATION, DROP = 1e-3, 0.4, 0.03  # s, s, m
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


def rotation(quat):
    """The rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def feet_heights(tree, q):
    """The feet's heights in the world: the base pose from q, the legs by fk in the base frame."""
    R = rotation(q[3:7])
    return np.array([(q[:3] + R @ tree.fk(q[7:], foot)[:3, 3])[2] for foot in FEET])


tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
q = np.zeros(tree.nq)
q[3:7] = [0.02, -0.03, 0.0, 1.0]  # tilted a little: one foot lands first
q[3:7] /= np.linalg.norm(q[3:7])
q[7:] = np.tile([0.0, 0.8, -1.6], 4)  # the legs folded
q[2] = -feet_heights(tree, q).min() + DROP
sim = vs.Simulator(tree, DT, gravity=GRAVITY, q=q)
friction = vs.Friction(static=np.full(tree.n_joints, 3.0))  # N m: enough to hold the stance
feet = [tree.segment_names.index(f) for f in FEET]
weight = -GRAVITY[2] * np.linalg.norm(tree.centroidal_momentum(q, np.r_[1.0, np.zeros(tree.nv - 1)])[:3])  # m g

print(f"solo12 dropped from {DROP * 100:.0f} cm; weight {weight:.3f} N")
print("   t (s)   base z (m)   feet down   sum f_z (N)   max |qd|")
rest = None
for k in range(round(DURATION / DT)):
    down = feet_heights(tree, sim.q) <= 0.0
    contacts = [vs.Contact(s, normal=[0.0, 0.0, 1.0], mu=0.9) for s, d in zip(feet, down) if d]
    r = sim.step(friction=friction, contacts=contacts)
    if rest is None and len(contacts) == 4 and not sim.qd.any():
        rest = sim.t
    if k % 25 == 24:
        fz = r.contact_force[:, 2].sum() if len(contacts) else 0.0
        print(f"{sim.t:8.3f}   {sim.q[2]:10.5f}   {int(down.sum()):9d}   {fz:11.4f}   {np.abs(sim.qd).max():.2e}")
if rest is None:
    print("not at rest yet")
else:
    print(f"at rest from t = {rest:.3f} s: qd exactly zero, the feet sticking: {list(r.contact_status)}")
