"""A solo12 on a free-flyer base (docs/floating-base.md) dropped onto flat ground in the Simulator,
its four feet supports with friction once they touch (z <= 0) and its joints held by friction:
it lands, every joint and foot sticks, and from then on it stands exactly still (qd exactly zero,
q unchanged) while the ground carries its weight."""

from __future__ import annotations

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
GRAVITY = np.array([0.0, 0.0, -9.81])


def _rotation(quat):
    x, y, z, w = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _feet_heights(tree, q):
    """The feet's heights in the world (the base pose from q, the legs by fk in the base frame)."""
    R = _rotation(q[3:7])
    return np.array([(q[:3] + R @ tree.fk(q[7:], foot)[:3, 3])[2] for foot in FEET])


def test_solo12_dropped_on_the_ground_comes_to_rest_standing():
    tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
    q = np.zeros(tree.nq)
    q[6] = 1.0
    q[7:] = np.tile([0.0, 0.8, -1.6], 4)
    q[2] = -_feet_heights(tree, q).min() + 0.01  # the lowest foot 1 cm above the ground
    sim = vs.Simulator(tree, 1e-3, gravity=GRAVITY, q=q)
    friction = vs.Friction(static=np.full(tree.n_joints, 3.0))
    feet = [tree.segment_names.index(f) for f in FEET]
    mass = np.linalg.norm(tree.centroidal_momentum(q, np.r_[1.0, np.zeros(tree.nv - 1)])[:3])  # |p| at |v| = 1
    rest_from = None
    for k in range(600):
        down = _feet_heights(tree, sim.q) <= 0.0
        contacts = [vs.Contact(s, normal=[0.0, 0.0, 1.0], mu=0.9) for s, d in zip(feet, down) if d]
        r = sim.step(friction=friction, contacts=contacts)
        if rest_from is None and len(contacts) == 4 and not sim.qd.any():
            rest_from = k
            q_rest = sim.q.copy()
    assert rest_from is not None and rest_from < 400, "solo12 did not come to rest on its feet"
    assert len(contacts) == 4 and list(r.contact_status) == [vs.ContactStatus.STICKING] * 4
    assert np.all(r.status[6:] == 1)  # every joint held by its friction (JointStatus::Stick)
    assert not sim.qd.any() and np.array_equal(sim.q, q_rest)  # exactly still
    # The ground carries the weight (over the step: the impulses over dt are the forces).
    weight = 9.81 * mass
    np.testing.assert_allclose(r.contact_force.sum(axis=0), [0.0, 0.0, weight], rtol=0, atol=1e-9 * weight)
    assert -0.002 < _feet_heights(tree, sim.q).min() <= 0.0  # landed, not sunk
