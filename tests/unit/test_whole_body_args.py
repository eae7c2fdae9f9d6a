"""vereshchagin.whole_body.least_effort's arguments (issue 28): the ones it shares with
:meth:`Solver.solve` (q, qd, f_ext as an array or a dict, tau_ff, the supports as contacts) are
read by the solve's own parser, so a bad one raises :class:`SolverError` with the solve's message;
the task, the supports and the actuated mask raise SolverError naming them; and the C++ solver kept
with the Python Solver carries nothing from one call to the next (calls in either order give the
same bits, also across the rebuild that more supports than its room cause).

Correctness against Pinocchio: tests/oracles/test_whole_body.py.
"""

from __future__ import annotations

import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GRAVITY = np.array([0.0, 0.0, -9.81])
BASE_STILL = (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0])
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def solo():
    tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
    legs = {"FL": (0.1, 0.8, -1.6), "FR": (-0.1, 0.8, -1.6), "HL": (0.1, -0.8, 1.6), "HR": (-0.1, -0.8, 1.6)}
    joints = {f"{leg}_{j}": v for leg, vals in legs.items() for j, v in zip(("HAA", "HFE", "KFE"), vals)}
    q = np.r_[0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0, [joints[n] for n in tree.joint_names]]
    return tree, q


def feet(mu=0.7, facets=4, spread=0.0):
    """The four feet; with spread > 0 five points per foot (20 supports: more than the default room of 16)."""
    if spread == 0.0:
        return [vs.Contact(f, normal=[0, 0, 1], mu=mu, facets=facets) for f in FEET]
    offsets = [(0, 0, 0), (spread, 0, 0), (-spread, 0, 0), (0, spread, 0), (0, -spread, 0)]
    return [vs.Contact(f, point=o, normal=[0, 0, 1], mu=mu, facets=facets) for f in FEET for o in offsets]


def call(solver, q, **kw):
    args = dict(task={None: BASE_STILL}, supports=feet())
    args.update(kw)
    return vs.whole_body.least_effort(solver, q, np.zeros(solver.model.nv), **args)


def same_message(solver, q, least_effort_args, solve_args):
    """least_effort raises SolverError with exactly the message Solver.solve raises for the same argument."""
    with pytest.raises(vs.SolverError) as ours:
        call(solver, q, **least_effort_args)
    with pytest.raises(vs.SolverError) as theirs:
        solver.solve(q, np.zeros(solver.model.nv), **solve_args)
    assert str(ours.value) == str(theirs.value)
    return str(ours.value)


def test_shared_arguments_raise_the_solve_messages(solo):
    tree, q = solo
    solver = vs.Solver(tree, gravity=GRAVITY)
    ns, nv = tree.n_segments, tree.nv
    nan_fext = np.zeros((ns, 6))
    nan_fext[2, 4] = np.nan
    cases = [
        ({"f_ext": np.zeros((ns, 5))}, "f_ext must have shape"),
        ({"f_ext": np.zeros(6)}, "f_ext must have shape"),
        ({"f_ext": nan_fext}, "f_ext contains NaN or Inf"),
        ({"f_ext": {"no_such_link": np.zeros(6)}}, "no_such_link"),
        ({"f_ext": {FEET[0]: np.zeros(5)}}, "f_ext['FL_FOOT'] must have shape (6,)"),
        ({"f_ext": {FEET[0]: [0, 0, np.inf, 0, 0, 0]}}, "NaN or Inf"),
        ({"f_ext": "heavy"}, "f_ext"),
        ({"tau_ff": np.zeros(nv - 1)}, "tau_ff must have shape (18,)"),
        ({"tau_ff": np.full(nv, np.nan)}, "tau_ff contains NaN or Inf"),
    ]
    for kw, fragment in cases:
        assert fragment in same_message(solver, q, kw, kw)
    for bad_q in (q[:-1], np.r_[q[:-1], np.nan]):
        with pytest.raises(vs.SolverError) as ours:
            vs.whole_body.least_effort(solver, bad_q, np.zeros(nv), supports=feet())
        with pytest.raises(vs.SolverError) as theirs:
            solver.solve(bad_q, np.zeros(nv))
        assert str(ours.value) == str(theirs.value)
    with pytest.raises(vs.SolverError, match=r"qd must have shape \(18,\)"):
        vs.whole_body.least_effort(solver, q, np.zeros(nv + 1))


def test_dict_f_ext_is_the_array_f_ext(solo):
    """A wrench on a segment given as {segment name: wrench} equals that row of the (n_segments, 6) array."""
    tree, q = solo
    solver = vs.Solver(tree, gravity=GRAVITY)
    name = tree.segment_names[3]
    wrench = np.array([1.0, -2.0, 0.5, 0.1, 0.0, -0.2])
    rows = np.zeros((tree.n_segments, 6))
    rows[3] = wrench
    by_dict = call(solver, q, f_ext={name: wrench})
    by_rows = call(solver, q, f_ext=rows)
    plain = call(solver, q)
    for field in ("tau", "contact_force", "qdd"):
        assert np.array_equal(getattr(by_dict, field), getattr(by_rows, field))
    assert not np.array_equal(by_dict.contact_force, plain.contact_force)


def test_task_supports_and_mask_raise_naming_them(solo):
    tree, q = solo
    solver = vs.Solver(tree, gravity=GRAVITY)
    nan_beta = BASE_STILL[1].copy()
    nan_beta[2] = np.nan
    cases = [
        ({"task": {None: (np.eye(3), np.zeros(3))}}, r"task\[None\] alpha must have shape \(6, m\)"),
        ({"task": {None: (np.eye(6), np.zeros(5))}}, r"task\[None\] beta must have shape \(6,\)"),
        ({"task": {None: (np.eye(6), nan_beta)}}, r"task\[None\] beta contains NaN or Inf"),
        ({"task": {None: (np.eye(6), "up")}}, r"task\[None\] beta"),
        ({"task": {None: (np.eye(6),)}}, r"task\[None\] must be a pair"),
        ({"task": {"no_such_link": BASE_STILL}}, r"task\['no_such_link'\]: .*no_such_link"),
        ({"task": {tree.segment_names[2]: (*BASE_STILL, [0.0, 0.1])}}, r"point must have shape \(3,\)"),
        ({"task": [BASE_STILL]}, "task must be a dict"),
        ({"supports": [1.0]}, r"supports\[0\] must be a vereshchagin.Contact, got float"),
        ({"supports": feet()[0]}, "supports must be a list of vereshchagin.Contact"),
        ({"supports": [vs.Contact("no_such_link", normal=[0, 0, 1])]}, r"supports\[0\]: .*no_such_link"),
        ({"supports": [vs.Contact(FEET[0], normal=[0, 0, 1], force=5.0)]}, "no force set-point"),
        ({"actuated": np.ones(11, dtype=bool)}, r"actuated must have shape \(12,\), got \(11,\)"),
        ({"actuated": np.full(12, np.nan)}, "actuated contains NaN or Inf"),
        ({"actuated": ["yes"] * 12}, "actuated must hold real numbers"),
        ({"actuated": [[1, 0], [1]]}, "actuated"),
    ]
    for kw, pattern in cases:
        with pytest.raises(vs.SolverError, match=pattern):
            call(solver, q, **kw)


def test_calls_in_either_order_give_the_same_bits(solo):
    """Two different calls (A: four feet, base still, a load and the hip abduction joints without
    motors; B: 20 supports, which rebuild the kept C++ solver larger, and a push on the base) on fresh solvers in the orders A B A and
    B A B, and after failing calls: every A equals every A, every B every B, bit for bit."""
    tree, q = solo
    actuated = np.array(["HAA" not in n for n in tree.joint_names])

    def a(solver):
        return call(solver, q, f_ext={FEET[1]: [0.0, 0.0, -3.0, 0.0, 0.0, 0.0]}, actuated=actuated)

    def b(solver):
        return call(
            solver, q, supports=feet(0.9, 8, spread=0.01), tau_ff=np.r_[2.0, -1.0, 0.0, 0.0, 0.0, 0.3, np.zeros(12)]
        )

    def fail(solver):
        with pytest.raises(vs.SolverError):
            call(solver, q, supports=feet(mu=0.01), tau_ff=np.r_[30.0, np.zeros(17)])

    first, second = vs.Solver(tree, gravity=GRAVITY), vs.Solver(tree, gravity=GRAVITY)
    runs = [a(first), b(first), a(first)]
    fail(second)
    runs += [b(second), a(second), b(second)]
    results_a, results_b = [runs[0], runs[2], runs[4]], [runs[1], runs[3], runs[5]]
    for results in (results_a, results_b):
        for r in results[1:]:
            for field in ("tau", "contact_force", "qdd"):
                assert np.array_equal(getattr(r, field), getattr(results[0], field)), field
            assert r.effort == results[0].effort and r.residual == results[0].residual
    assert results_b[0].contact_force.shape == (20, 3)
    # A plain solve in between does not change a least-effort call either (the shared argument parser).
    solver = vs.Solver(tree, gravity=GRAVITY)
    solver.solve(q, np.zeros(tree.nv), contacts=feet(0.5), tau_ff=np.r_[1.0, np.zeros(17)])
    assert np.array_equal(a(solver).tau, results_a[0].tau)


def test_gravity_changes_are_seen(solo):
    """The kept C++ solver reads the Solver's gravity at each call."""
    tree, q = solo
    solver = vs.Solver(tree, gravity=GRAVITY)
    earth = call(solver, q)
    solver.gravity = [0.0, 0.0, -1.62]
    moon = vs.whole_body.least_effort(
        solver, q, np.zeros(tree.nv), task={None: (np.eye(6), np.r_[0.0, 0.0, 1.62, 0.0, 0.0, 0.0])}, supports=feet()
    )
    assert np.allclose(moon.contact_force[:, 2].sum() * 9.81, earth.contact_force[:, 2].sum() * 1.62, rtol=1e-9)
