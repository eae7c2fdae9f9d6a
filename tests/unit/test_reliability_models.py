"""Models the physical inertia check must accept or refuse (issue 23), against Pinocchio.

* iCub (example-robot-data ``icub.urdf``): several links (``l_ankle_2``, ``r_hip_2``, ``head``, ...)
  have rotational inertias made of round-off, e.g. principal moments (-1.4e-20, 0, 1.4e-20) kg m^2
  for a 0.27 kg link. They are not violations of the triangle inequality: the whole robot loads as
  a Tree with the default ``inertia_check`` and solves like ``pin.aba`` on the same URDF to 1e-9
  (relative, norm-wise).
* Allegro hand (``allegro_right_hand.urdf``): ``link_3.0`` has moments (2.3e-6, 3.5e-6, 7.3e-6)
  kg m^2, a real violation (by 1.5e-6): still refused, with a message that names the link and the
  option ``inertia_check`` / ``joint_space``; with ``inertia_check="joint_space"`` it loads.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.trees import pin_model, pin_q, pin_v_index
from vereshchagin.robots import example_robot_urdf

RTOL = 1e-9
G = np.array([0.0, 0.0, -9.81])


def _rel(actual, expected):
    return np.linalg.norm(np.asarray(actual) - expected) / max(np.linalg.norm(expected), 1.0)


def test_icub_round_off_inertias_are_accepted_and_solve_like_pinocchio():
    path = example_robot_urdf("icub_description/robots/icub.urdf")
    tree = vs.Tree.from_urdf(path)  # default inertia_check="physical"
    model = pin_model(path)
    assert sorted(tree.joint_names) == sorted(list(model.names)[1:])
    solver = vs.Solver(tree, gravity=G)
    data = model.createData()
    cols = pin_v_index(model, tree.joint_names)
    rng = np.random.default_rng(23)
    for _ in range(4):
        lo = np.maximum(tree.lower, -np.pi)
        hi = np.minimum(tree.upper, np.pi)
        q = rng.uniform(lo, hi)
        qd = rng.uniform(-1.0, 1.0, tree.n_joints)
        tau = rng.normal(size=tree.n_joints)
        res = solver.solve(q, qd, tau_ff=tau)
        v = np.zeros(model.nv)
        t = np.zeros(model.nv)
        v[cols] = qd
        t[cols] = tau
        expected = pin.aba(model, data, pin_q(model, tree.joint_names, q), v, t)[cols]
        err = _rel(res.qdd, expected)
        assert err <= RTOL, f"iCub qdd vs pin.aba: relative error {err:.3e}"


def test_allegro_real_violation_is_still_refused_with_the_option_named():
    path = example_robot_urdf("allegro_hand_description/urdf/allegro_right_hand.urdf")
    with pytest.raises(vs.SolverError) as info:
        vs.Tree.from_urdf(path)
    text = str(info.value)
    assert any(f"'link_{k}.0'" in text for k in (3, 7, 11, 15)), text
    assert "triangle" in text and "inertia_check" in text and "joint_space" in text, text
    tree = vs.Tree.from_urdf(path, inertia_check="joint_space")
    assert tree.n_joints == 16
