"""Dynamics companions on a floating base (docs/floating-base.md) against Pinocchio, 1e-9 relative.

``Tree.mass_matrix`` (nv x nv), ``inverse_dynamics`` (nv: the base rows are the wrench the base
needs, base axes), ``gravity_torques`` and ``coriolis_torques`` of a tree loaded with
``base="free"`` against ``pin.crba``, ``pin.rnea`` (with f_ext), ``pin.computeGeneralizedGravity``
and ``pin.nonLinearEffects`` on a model built with ``pin.JointModelFreeFlyer()`` (solo12, ANYmal,
Talos reduced, random trees), and a Gen3 on ``pin.JointModelPlanar()``. f_ext rows and gravity
are in world axes, as the solver's; ``inverse_dynamics`` at the solver's qdd gives back tau_ff.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs

from test_floating_base import FREE, GRAVITY, assert_rel, case, f_ext_rows, random_wrenches

ALL = FREE + ["gen3_planar"]


def states(c, seed, k=3):
    rng = np.random.default_rng(seed)
    for _ in range(k):
        q, v = c.random_state(rng)
        yield rng, q, v, c.pin_q(q)


@pytest.mark.parametrize("name", ALL)
def test_mass_matrix_matches_crba(name):
    c = case(name)
    for _, q, _, pq in states(c, 1):
        M = pin.crba(c.model, c.data, pq)
        M = np.triu(M) + np.triu(M, 1).T
        assert_rel(c.tree.mass_matrix(q), M[np.ix_(c.v_index, c.v_index)], f"{name}: H")


@pytest.mark.parametrize("name", ALL)
def test_inverse_dynamics_matches_rnea(name):
    c = case(name)
    for rng, q, v, pq in states(c, 2):
        a = rng.uniform(-2.0, 2.0, c.tree.nv)
        wrenches = random_wrenches(c, rng)
        expected = pin.rnea(c.model, c.data, pq, c.pin_v(v), c.pin_v(a), c.pin_fext(pq, wrenches))
        tau = c.tree.inverse_dynamics(q, v, a, f_ext_rows(c, wrenches), gravity=GRAVITY)
        assert_rel(tau, c.ours(expected), f"{name}: rnea")
        by_frame = c.tree.inverse_dynamics(q, v, a, wrenches, gravity=GRAVITY)
        assert_rel(by_frame, c.ours(expected), f"{name}: rnea, f_ext as a dict")


@pytest.mark.parametrize("name", ALL)
def test_gravity_and_coriolis_match_pinocchio(name):
    c = case(name)
    for _, q, v, pq in states(c, 3):
        g = pin.computeGeneralizedGravity(c.model, c.data, pq)
        assert_rel(c.tree.gravity_torques(q, gravity=GRAVITY), c.ours(g), f"{name}: g")
        nle = pin.nonLinearEffects(c.model, c.data, pq, c.pin_v(v))
        assert_rel(c.tree.coriolis_torques(q, v), c.ours(nle - g), f"{name}: C v")


@pytest.mark.parametrize("name", ["solo12", "gen3_planar"])
def test_inverse_dynamics_inverts_the_solve(name):
    c = case(name)
    for rng, q, v, _ in states(c, 4):
        tau = rng.uniform(-3.0, 3.0, c.tree.nv)
        wrenches = random_wrenches(c, rng)
        f = f_ext_rows(c, wrenches)
        r = c.solver.solve(q, v, tau_ff=tau, f_ext=f)
        assert_rel(c.tree.inverse_dynamics(q, v, r.qdd, f, gravity=GRAVITY), tau, f"{name}: tau_ff")


def test_floating_sizes_and_messages():
    c = case("solo12")
    q, v = c.random_state(np.random.default_rng(5))
    with pytest.raises(vs.SolverError, match=r"q must have shape \(19,\)"):
        c.tree.mass_matrix(q[1:])
    with pytest.raises(vs.SolverError, match=r"qd must have shape \(18,\)"):
        c.tree.coriolis_torques(q, v[1:])
    bad = q.copy()
    bad[3:7] *= 1.1
    with pytest.raises(vs.SolverError, match="unit quaternion"):
        c.tree.gravity_torques(bad)
