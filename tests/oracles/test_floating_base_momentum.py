"""Centre of mass and momentum companions (``center_of_mass``, ``center_of_mass_jacobian``,
``center_of_mass_velocity``, ``centroidal_momentum``) against Pinocchio, 1e-9 relative.

Floating bases (free-flyer on solo12, ANYmal, Talos reduced and random trees; a Gen3 on a planar
base) against ``pin.centerOfMass``, ``pin.jacobianCenterOfMass`` and
``pin.computeCentroidalMomentum`` (``data.hg``: the momentum about the centre of mass, world
axes); fixed bases (a Gen3 Tree and Chain) against the same on a fixed Pinocchio model.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.trees import pin_q, pin_v_index
from test_floating_base import FREE, assert_rel, case
from vereshchagin.robots import gen3_urdf

ALL = FREE + ["gen3_planar"]


@pytest.mark.parametrize("name", ALL)
def test_floating_center_of_mass_and_momentum(name):
    c = case(name)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, v = c.random_state(rng)
        pq, pv = c.pin_q(q), c.pin_v(v)
        assert_rel(c.tree.center_of_mass(q), pin.centerOfMass(c.model, c.data, pq), f"{name}: com")
        J = pin.jacobianCenterOfMass(c.model, c.data, pq)
        assert_rel(c.tree.center_of_mass_jacobian(q), J[:, c.v_index], f"{name}: J_com")
        assert_rel(c.tree.center_of_mass_velocity(q, v), J @ pv, f"{name}: com velocity")
        hg = pin.computeCentroidalMomentum(c.model, c.data, pq, pv)
        assert_rel(c.tree.centroidal_momentum(q, v), hg.vector, f"{name}: centroidal momentum")


def test_fixed_base_center_of_mass_and_momentum():
    text = gen3_urdf()
    model = pin.buildModelFromXML(text)
    data = model.createData()
    tree = vs.Tree.from_urdf(text)
    order = pin_v_index(model, tree.joint_names)
    rng = np.random.default_rng(8)
    for _ in range(3):
        q, v = rng.uniform(-1.0, 1.0, tree.n_joints), rng.uniform(-1.0, 1.0, tree.n_joints)
        pq, pv = pin_q(model, tree.joint_names, q), np.zeros(model.nv)
        pv[order] = v
        J = pin.jacobianCenterOfMass(model, data, pq)
        hg = pin.computeCentroidalMomentum(model, data, pq, pv).vector
        assert_rel(tree.center_of_mass(q), pin.centerOfMass(model, data, pq), "com")
        assert_rel(tree.center_of_mass_jacobian(q), J[:, order], "J_com")
        assert_rel(tree.center_of_mass_velocity(q, v), J @ pv, "com velocity")
        assert_rel(tree.centroidal_momentum(q, v), hg, "centroidal momentum")


def test_chain_center_of_mass_is_consistent():
    # A Chain shares the Tree's code: its velocity is J_c qd and the derivative of its position.
    chain = vs.Chain.from_urdf(gen3_urdf(), tip="robotiq_85_left_finger_tip_link")
    rng = np.random.default_rng(10)
    q, v = rng.uniform(-1.0, 1.0, chain.n_joints), rng.uniform(-1.0, 1.0, chain.n_joints)
    velocity = chain.center_of_mass_velocity(q, v)
    assert_rel(chain.center_of_mass_jacobian(q) @ v, velocity, "J_c qd")
    h = 1e-6
    numeric = (chain.center_of_mass(q + h * v) - chain.center_of_mass(q - h * v)) / (2 * h)
    assert_rel(numeric, velocity, "d com / dt", 1e-7)
    mass = chain.centroidal_momentum(q, v)[:3] / velocity
    assert np.allclose(mass, mass[0], rtol=1e-9) and mass[0] > 0


def test_momentum_sizes_and_messages():
    c = case("solo12")
    q, v = c.random_state(np.random.default_rng(9))
    assert c.tree.center_of_mass_jacobian(q).shape == (3, c.tree.nv)
    with pytest.raises(vs.SolverError, match=r"q must have shape \(19,\)"):
        c.tree.center_of_mass(q[:-1])
    with pytest.raises(vs.SolverError, match=r"qd must have shape \(18,\)"):
        c.tree.centroidal_momentum(q, v[:-1])
