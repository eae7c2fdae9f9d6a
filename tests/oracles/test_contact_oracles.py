"""The contact oracles of :mod:`support.contact_oracle` checked against each other and against
Pinocchio before the solver's contact tests rely on them: a sticking point against
``pin.constraintDynamics`` with a 3-D contact, the mode enumeration against the frictionless QP
of Gauss's principle, and every enumerated solution against its own sign conditions."""

from __future__ import annotations

import numpy as np
import pytest

from support.chains import pin_configuration, random_chain, random_state
from support.contact_oracle import (
    _candidate,
    check_solution,
    contact_problem,
    enumerate_modes,
    frictionless_qp,
    pin_rigid_3d,
)

RTOL = 1e-9


def _resting_problem(rng, n, segments, contact):
    """A random n-joint chain at rest with a random torque and one contact (``contact()``'s keys,
    a random point) on each of ``segments``."""
    rc = random_chain(rng, n, prismatic=False)
    model, data = rc.model, rc.data()
    q, _ = random_state(rng, rc)
    tau = rng.normal(size=model.nv) * 3
    specs = [dict(frame=rc.tip_frames[k], point=rng.normal(size=3) * 0.1, **contact()) for k in segments]
    return contact_problem(model, data, pin_configuration(model, q), np.zeros(model.nv), tau, specs)


@pytest.mark.parametrize("seed", range(8))
def test_a_sticking_point_matches_pinocchio_constraint_dynamics(seed):
    rng = np.random.default_rng(seed)
    rc = random_chain(rng, 7, prismatic=False)
    model, data = rc.model, rc.data()
    q, qd = random_state(rng, rc)
    qp = pin_configuration(model, q)
    tau = rng.normal(size=model.nv)
    point = rng.normal(size=3) * 0.1
    spec = dict(frame=rc.tip_frames[-1], point=point, normal=[0.0, 0.0, 1.0], mu=100.0)
    prob = contact_problem(model, data, qp, qd, tau, [spec])
    sol, resid = _candidate(prob, ("stick",))
    expected, _ = pin_rigid_3d(model, model.createData(), qp, qd, tau, rc.tip_frames[-1], point)
    assert resid < 1e-12
    assert np.linalg.norm(sol.qdd - expected) <= RTOL * max(1.0, np.linalg.norm(expected))


@pytest.mark.parametrize("seed", range(8))
def test_frictionless_enumeration_is_the_gauss_qp(seed):
    rng = np.random.default_rng(100 + seed)
    prob = _resting_problem(rng, 7, (3, 6), lambda: dict(normal=rng.normal(size=3), mu=0.0))
    sols = enumerate_modes(prob)
    assert len(sols) == 1  # frictionless: the accelerations are unique
    x = frictionless_qp(prob)
    assert np.linalg.norm(sols[0].qdd - x) <= RTOL * max(1.0, np.linalg.norm(x))


@pytest.mark.parametrize("seed", range(6))
def test_frictional_solutions_meet_their_conditions(seed):
    rng = np.random.default_rng(200 + seed)
    prob = _resting_problem(rng, 6, (2, 5), lambda: dict(normal=[0, 0, 1], mu=0.5, facets=4))
    sols = enumerate_modes(prob)
    assert sols, "no consistent mode (a Painleve case): pick another seed"
    for sol in sols:
        assert check_solution(prob, sol)
        for c, f in zip(prob.contacts, sol.forces):
            fn = c.normal @ f
            assert fn >= -1e-9 and np.linalg.norm(f - fn * c.normal) <= c.mu * fn + 1e-9
