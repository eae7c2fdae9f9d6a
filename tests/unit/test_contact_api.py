"""vs.Contact: construction checks with their messages, immutability, equality, pickling, and the
contacts= argument's shapes and messages in solve()."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import vereshchagin as vs


def test_contact_stores_checked_values():
    c = vs.Contact("link3", point=[0.1, 0, 0], normal=[0, 0, 1], mu=0.5, facets=8, force=3)
    assert c.segment == "link3"
    np.testing.assert_array_equal(c.point, [0.1, 0.0, 0.0])
    np.testing.assert_array_equal(c.normal, [0.0, 0.0, 1.0])
    assert (c.mu, c.facets, c.force) == (0.5, 8, 3.0)
    assert vs.Contact(2).force is None
    with pytest.raises(ValueError):
        c.point[0] = 1.0  # read-only
    with pytest.raises(AttributeError):
        c.mu = 1.0


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(segment=True), "Contact.segment"),
        (dict(segment=1.5), "Contact.segment"),
        (dict(segment=0, point=[0, 0]), "Contact.point must have shape (3,)"),
        (dict(segment=0, point=[0, np.nan, 0]), "Contact.point must be finite"),
        (dict(segment=0, normal=[0, 0, 2]), "Contact.normal must be a unit vector"),
        (dict(segment=0, mu=-0.1), "Contact.mu must be finite and >= 0"),
        (dict(segment=0, mu="0.5"), "Contact.mu must be a real number"),
        (dict(segment=0, facets=2), "Contact.facets must be an int in 3 .. 64"),
        (dict(segment=0, facets=4.0), "Contact.facets must be an int in 3 .. 64"),
        (dict(segment=0, force=-1.0), "Contact.force (a normal-force set-point, N) must be finite and >= 0"),
        (dict(segment=0, force=np.inf), "Contact.force"),
    ],
)
def test_contact_refuses_bad_values(kwargs, fragment):
    with pytest.raises(vs.SolverError, match=None) as e:
        vs.Contact(**kwargs)
    assert fragment in str(e.value)


def test_contact_equality_hash_pickle_copy():
    c = vs.Contact(-1, point=[0, 0.1, 0], mu=0.3, force=None)
    d = pickle.loads(pickle.dumps(c))
    assert d == c and hash(d) == hash(c)
    assert copy.deepcopy(c) == c
    assert vs.Contact(-1, point=[0, 0.1, 0], mu=0.4) != c
    assert "Contact(-1" in repr(c) and "mu=0.3" in repr(c)
    assert "force=2.0" in repr(vs.Contact(0, force=2.0))


def test_contact_status_and_outcome_codes():
    assert [int(s) for s in vs.ContactStatus] == [0, 1, 2]
    assert [int(s) for s in vs.ContactOutcome] == [0, 1, 2]


def _arm():
    chain = vs.robots.gen3()
    return chain, vs.Solver(chain), np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57]), np.zeros(7)


def test_contacts_argument_messages():
    chain, solver, q, qd = _arm()
    with pytest.raises(vs.SolverError, match="contacts must be a list of vereshchagin.Contact"):
        solver.solve(q, qd, contacts=vs.Contact(3))
    with pytest.raises(vs.SolverError, match=r"contacts\[1\] must be a vereshchagin.Contact, got dict"):
        solver.solve(q, qd, contacts=[vs.Contact(3), {"segment": 3}])
    with pytest.raises(vs.SolverError, match=r"contacts\[0\]"):
        solver.solve(q, qd, contacts=[vs.Contact("no_such_link")])
    with pytest.raises(vs.SolverError, match="fixed base"):
        solver.solve(q, qd, contacts=[vs.Contact("base_link")])
    # With contacts the friction model is checked as without them.
    bad = vs.Friction(static=-np.ones(chain.n_joints))
    with pytest.raises(vs.SolverError, match=r"friction.static\[0\].*must be finite and >= 0"):
        solver.solve(q, qd, friction=bad, contacts=[vs.Contact(3)])
    with pytest.raises(vs.SolverError, match=r"friction.static must have shape \(7,\), got \(3,\)"):
        solver.solve(q, qd, friction=vs.Friction(static=np.ones(3)), contacts=[vs.Contact(3)])


def test_results_carry_contact_outputs_and_pickle_them():
    chain, solver, q, qd = _arm()
    plain = solver.solve(q, qd)
    assert plain.contact_force.shape == (0, 3) and plain.contact_status.shape == (0,)
    assert plain.contact_outcome == vs.ContactOutcome.NONE
    contacts = [vs.Contact("forearm_link", point=[0, 0, -0.1], mu=0.5), vs.Contact(6, force=2.0)]
    res = solver.solve(q, qd, contacts=contacts)
    assert res.contact_force.shape == (2, 3) and res.contact_status.dtype == np.int32
    assert abs(res.contact_force[1] @ [0, 0, 1] - 2.0) <= 1e-12
    assert res.contact_outcome in (vs.ContactOutcome.UNIQUE, vs.ContactOutcome.CONSISTENT)
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.contact_force, res.contact_force)
    np.testing.assert_array_equal(back.contact_status, res.contact_status)
    assert back.contact_outcome == res.contact_outcome
    # out= reuses a result of the same layout only; a 12-entry state (before contacts) still loads.
    assert solver.solve(q, qd, contacts=contacts, out=res) is res
    with pytest.raises(vs.SolverError, match="2 contacts"):
        solver.solve(q, qd, out=res)
    state = plain.__reduce__()[1]
    assert len(state) == 14
    old = type(plain).__reduce__(plain)[0](*state[:12])
    np.testing.assert_array_equal(old.qdd, plain.qdd)


def test_solve_batch_reports_contact_outputs():
    chain, solver, q, qd = _arm()
    contacts = [vs.Contact("forearm_link", point=[0, 0, -0.1], mu=0.5)]
    batch = solver.solve_batch(np.stack([q, q]), qd, contacts=contacts)
    assert batch.contact_force.shape == (2, 1, 3) and batch.contact_status.shape == (2, 1)
    assert batch.contact_outcome.shape == (2,)
    single = solver.solve(q, qd, contacts=contacts)
    np.testing.assert_array_equal(batch.contact_force[1], single.contact_force)
    assert solver.solve_batch(np.stack([q, q]), qd).contact_force.shape == (2, 0, 3)
