"""The solve over a time step (``solve(..., time_step=dt)``, ``Solver.step``) against the
velocity-level enumeration of contact and joint-friction modes (:mod:`support.contact_oracle`
with ``time_step``), written independently of the solver, at 1e-9 relative; and its properties:
a friction-held arm keeps ``q`` bitwise, a moving arm friction can stop comes to exact rest and
stays, friction and contact impulses never do positive work, and the step's mean acceleration
converges to the instant's qdd as dt -> 0 (with polygonal friction it equals it once dt is
small enough that no joint stops and no contact changes its mode within the step)."""

from __future__ import annotations

import numpy as np
import pytest

import vereshchagin as vs
from support.chains import pin_configuration, random_chain, random_state
from support.contact_oracle import contact_problem, enumerate_modes

RTOL = 1e-9
GEN3_Q = np.array([0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57])


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


def _problem(rc, q, qd, tau, contacts, friction, dt):
    specs = [
        dict(frame=rc.tip_frames[c.segment], point=c.point, normal=c.normal, mu=c.mu, facets=c.facets) for c in contacts
    ]
    model = rc.model
    return contact_problem(
        model, model.createData(), pin_configuration(model, q), qd, tau, specs, friction=friction, time_step=dt
    )


@pytest.mark.parametrize("seed", range(10))
def test_a_step_meets_an_enumerated_velocity_level_mode(seed):
    """Random 7-joint chains moving, breakaway friction on three joints (kinetic 0.7 of it), 0 to 2
    supports with friction anywhere (moving towards, along or away from their surfaces)."""
    rng = np.random.default_rng(1100 + seed)
    n, k, dt = 7, seed % 3, (1e-3, 1e-2)[seed % 2]
    rc = random_chain(rng, n, prismatic=False)
    q, qd = random_state(rng, rc, qd_scale=0.5)
    qd[rng.choice(n, size=3, replace=False)] = 0.0  # some joints at rest
    fs = np.zeros(n)
    fs[rng.choice(n, size=3, replace=False)] = rng.uniform(0.3, 3.0, size=3)
    fk = 0.7 * fs
    tau = rng.normal(size=n) * 3
    contacts = []
    for s in rng.choice(np.arange(4, rc.n_segments), size=k, replace=False):
        normal = rng.normal(size=3)
        contacts.append(
            vs.Contact(int(s), point=rng.normal(size=3) * 0.1, normal=normal / np.linalg.norm(normal), mu=0.6)
        )
    r = rc.solver().solve(
        q, qd, tau_ff=tau, friction=vs.Friction(static=fs, kinetic=fk), contacts=contacts, time_step=dt
    )
    prob = _problem(rc, q, qd, tau, contacts, dict(static=fs, kinetic=fk), dt)
    found = enumerate_modes(prob)
    assert found, "the enumeration found no consistent answer"
    best = min(found, key=lambda s: _rel(r.qdd, s.qdd))
    assert _rel(r.qdd, best.qdd) <= RTOL
    # The environment's generalised force (every joint with friction is an unknown over a step).
    gen = sum(c.J.T @ f for c, f in zip(prob.contacts, r.contact_force)) + r.friction_torque + r.limit_torque
    assert _rel(gen, sum(c.J.T @ f for c, f in zip(prob.contacts, best.forces)) + best.joint_torques) <= RTOL
    qd_next = qd + dt * r.qdd
    for j in prob.joints:  # bounded, and against the end velocity when it is not zero
        t = r.friction_torque[j.index]
        assert abs(t) <= j.hi * (1 + 1e-12)
        if abs(qd_next[j.index]) > 1e-9:
            assert t == pytest.approx(-np.sign(qd_next[j.index]) * j.hi, rel=1e-9)


def test_a_friction_held_arm_keeps_q_bitwise():
    gen3 = vs.robots.gen3()
    solver = vs.Solver(gen3)
    fr = vs.Friction(static=np.abs(gen3.gravity_torques(GEN3_Q)) * 1.2 + 0.1)
    q, qd = GEN3_Q.copy(), np.zeros(7)
    for _ in range(10_000):
        q, qd, r = solver.step(q, qd, 1e-3, friction=fr)
    assert np.array_equal(q, GEN3_Q) and not qd.any()
    assert (r.status == 1).all()  # sticking


def test_a_moving_arm_friction_can_stop_comes_to_exact_rest_and_stays():
    gen3 = vs.robots.gen3()
    solver = vs.Solver(gen3)
    fr = vs.Friction(static=np.abs(gen3.gravity_torques(GEN3_Q)) * 1.5 + 2.0)
    q, qd = GEN3_Q.copy(), np.full(7, 0.05)
    stopped_at = None
    for step in range(2000):
        q, qd, r = solver.step(q, qd, 1e-3, friction=fr)
        if stopped_at is None and not qd.any():
            stopped_at, q_rest = step, q.copy()
    assert stopped_at is not None and stopped_at < 200
    assert np.array_equal(q, q_rest) and not qd.any()


@pytest.mark.parametrize("seed", range(4))
def test_friction_and_contact_impulses_never_do_positive_work(seed):
    """Over many steps of a Gen3 with joint friction and its forearm sliding on a table: the
    friction torques times the end velocities, and the contact forces times the points' end
    velocities, are never positive (to round-off)."""
    rng = np.random.default_rng(1200 + seed)
    gen3 = vs.robots.gen3()
    solver = vs.Solver(gen3)
    fr = vs.Friction(static=rng.uniform(0.2, 2.0, size=7))
    elbow = vs.Contact("forearm_link", normal=[0, 0, 1], mu=0.4)  # at the forearm's tip origin
    q, qd, dt = GEN3_Q.copy(), rng.normal(size=7) * 0.3, 1e-3
    pushed = 0
    for _ in range(300):
        q_next, qd_next, r = solver.step(q, qd, dt, friction=fr, contacts=[elbow], tau_ff=rng.normal(size=7))
        assert r.friction_torque @ qd_next <= 1e-9 * max(1.0, np.abs(r.friction_torque).sum())
        # The point's end velocity to first order, v + dt a (the step's own measure).
        J = gen3.jacobian(q, "forearm_link")[:3]
        v_end = J @ qd + dt * (J @ r.qdd + gen3.jacobian_dot_times_qd(q, qd, "forearm_link")[:3])
        f = r.contact_force[0]
        assert f @ v_end <= 1e-9 * max(1.0, np.linalg.norm(f)) * max(1e-3, np.linalg.norm(v_end))
        pushed += f[2] > 0.0
        q, qd = q_next, qd_next
    assert pushed > 10  # the table did carry the forearm in some steps


@pytest.mark.parametrize("case", ["friction", "sliding contact"])
def test_the_step_converges_to_the_instant_as_dt_goes_to_zero(case):
    gen3 = vs.robots.gen3()
    solver = vs.Solver(gen3)
    rng = np.random.default_rng(5)
    qd = rng.normal(size=7) * 0.4
    fr = vs.Friction(static=np.full(7, 0.8))
    kw = dict(friction=fr)
    if case == "sliding contact":
        # the forearm's tip origin sliding on a surface whose normal is perpendicular to its velocity
        v = gen3.twist(GEN3_Q, qd, "forearm_link")[:3]
        normal = np.cross(v, [1.0, 0.0, 0.0])
        normal /= np.linalg.norm(normal)
        for side in (1.0, -1.0):  # the side on which the surface carries the point
            kw["contacts"] = [vs.Contact("forearm_link", normal=side * normal, mu=0.3)]
            if solver.solve(GEN3_Q, qd, **kw).contact_status[0] == vs.ContactStatus.SLIDING:
                break
        else:
            raise AssertionError("the point does not slide on either side")
    inst = solver.solve(GEN3_Q, qd, **kw)
    dts = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
    errors = np.array([np.abs(solver.solve(GEN3_Q, qd, time_step=dt, **kw).qdd - inst.qdd).max() for dt in dts])
    scale = max(1.0, np.abs(inst.qdd).max())
    # Once no joint stops and no contact changes its mode (or its polygon's vertex) within the step,
    # the step's conditions are the instant's: the mean acceleration is the instant's qdd.
    assert errors[-1] <= 1e-8 * scale, errors
    assert np.all(np.diff(errors) <= 1e-8 * scale), errors


def test_step_call_takes_three_positionals_and_out():
    solver = vs.Solver(vs.robots.gen3())
    qd = np.full(7, 0.1)
    q1, qd1, r1 = solver.step(GEN3_Q, qd, 1e-3, tau_ff=np.ones(7))
    q2, qd2, r2 = solver.step(q=GEN3_Q, qd=qd, time_step=1e-3, tau_ff=np.ones(7), out=r1)
    assert r2 is r1  # the result written in place, as solve(out=) does
    assert np.array_equal(q1, q2) and np.array_equal(qd1, qd2)
    assert np.array_equal(qd1, qd + 1e-3 * r2.qdd) and np.array_equal(q1, GEN3_Q + 1e-3 * qd1)
    with pytest.raises(TypeError, match="time_step"):
        solver.step(GEN3_Q, qd)
    with pytest.raises(TypeError, match="at most 3 positional"):
        solver.step(GEN3_Q, qd, 1e-3, None)
    with pytest.raises(TypeError, match="unexpected keyword argument 'dt'"):
        solver.step(GEN3_Q, qd, dt=1e-3)


@pytest.mark.parametrize("bad", [0.0, -1e-3, float("nan"), float("inf"), True, "1e-3", None])
def test_a_bad_time_step_is_refused_with_a_message(bad):
    solver = vs.Solver(vs.robots.gen3())
    with pytest.raises(vs.SolverError, match="time_step"):
        solver.step(GEN3_Q, np.zeros(7), bad)
    if bad is not None and not isinstance(bad, str) and not (isinstance(bad, float) and bad == 0.0):
        with pytest.raises(vs.SolverError, match="time_step"):
            solver.solve(GEN3_Q, np.zeros(7), time_step=bad)
