"""No call's arguments influence a later call (issue 23), as a property.

Hypothesis draws sequences of calls of every public entry point (``solve``, ``solve_batch``,
``response_columns`` after a solve, the model companions, the task helpers), each with a random
subset of its optional arguments (including bad ones that must raise), and runs them one after
the other on ONE solver and model. Every call is also run on a fresh solver built for it alone.
The two must agree bitwise: the same arrays, or the same exception with the same message.
Gravity is set on both for each call (it is the one documented setting of a solver).
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import vereshchagin as vs

KINDS = ["solve", "solve_out", "batch", "response", "companion", "task"]


@pytest.fixture(scope="module")
def models(gen3, baxter):
    """The Gen3 chain and the Baxter tree of tests/conftest.py."""
    return {"chain": gen3, "tree": baxter}


def frame_keys(model):
    """Segment names, merged link names and indices: every way a frame is addressed."""
    merged = [name for name in model.link_names if name not in model.segment_names and name != model.root_link]
    return list(model.segment_names) + merged[:4] + [0, -1, model.n_segments - 1]


def draw_arguments(rng, model, is_tree, flags):
    """Arguments of one solve: q and qd always, each optional one when its flag is set."""
    n, ns = model.n_joints, model.n_segments
    args = {"q": rng.uniform(-1.5, 1.5, n), "qd": rng.uniform(-1, 1, n) * (rng.random(n) < 0.7)}
    keys = frame_keys(model)
    m = 0
    if flags["alpha"] and not is_tree:
        m = int(rng.integers(1, 4))
        args["alpha"] = rng.normal(size=(6, m))
        args["beta"] = rng.normal(size=m)
    if flags["constraints"]:
        picked = rng.choice(len(keys), size=int(rng.integers(1, 3)), replace=False)
        constraints = {}
        for k in picked:
            mk = int(rng.integers(1, 3))
            constraints[keys[k]] = (rng.normal(size=(6, mk)), rng.normal(size=mk))
            m += mk
        args["constraints"] = constraints
    if flags["f_ext"]:
        if rng.random() < 0.5:
            args["f_ext"] = rng.normal(size=(ns, 6))
        else:
            args["f_ext"] = {keys[int(rng.integers(len(keys)))]: rng.normal(size=6) * 20}
    if flags["tau_ff"]:
        args["tau_ff"] = rng.normal(size=n)
    if flags["friction"]:
        choice = rng.integers(3)
        args["friction"] = True if choice == 0 else vs.Friction(static=rng.uniform(0, 2, n))
        if choice == 2:
            args["friction"] = vs.Friction(static=rng.uniform(0, 2, n), kinetic=rng.uniform(0, 0.5, n))
    if flags["pass_through"] and m > 0:
        args["f_ext_pass_through"] = rng.uniform(0, 1, m)
        args["tau_ff_pass_through"] = rng.uniform(0, 1, m)
    if flags["bad"]:  # an argument check fails: nothing of it may stay behind
        bad = rng.integers(3)
        if bad == 0:
            args["qd"] = np.full(n + 1, 0.1)
        elif bad == 1:
            args["f_ext"] = {"no such frame": np.ones(6)}
        else:
            args["tau_ff"] = np.full(n, np.nan)
    return args


def outcome(fn):
    """The result of a call as comparable values: arrays, or the exception type and message."""
    try:
        value = fn()
    except vs.SolverError as e:
        return ("error", type(e).__name__, str(e))
    return ("value", flatten(value))


def flatten(value):
    if isinstance(value, vs.SolveResult):
        names = ["qdd", "tau_command", "nu", "link_acc", "constraint_rank", "smallest_singular_value"]
        names += ["friction_torque", "limit_torque", "status", "gauss_value", "iterations"]
        out = [np.asarray(getattr(value, k)) for k in names]
        segment_nu = value.segment_nu
        if segment_nu is not None:
            out += [np.asarray(list(map(str, segment_nu)))] + [np.asarray(v) for v in segment_nu.values()]
        return out
    if dataclasses.is_dataclass(value):  # BatchResult
        value = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return [np.asarray(list(map(str, value)))] + [flatten(v) for v in value.values()]
    if isinstance(value, (tuple, list)):
        return [flatten(v) for v in value]
    return np.asarray(value)


def assert_same(a, b, context):
    assert a[0] == b[0], (context, a, b)
    if a[0] == "error":
        assert a == b, context
        return
    check_equal(a[1], b[1], context)


def check_equal(x, y, context):
    if isinstance(x, list):
        assert isinstance(y, list) and len(x) == len(y), context
        for u, v in zip(x, y):
            check_equal(u, v, context)
        return
    assert x.shape == y.shape, context
    np.testing.assert_array_equal(x, y, err_msg=str(context))


def make_call(kind, rng, model, is_tree, flags):
    """A function of (solver, model) performing one call, drawn from rng."""
    args = draw_arguments(rng, model, is_tree, flags)
    gravity = rng.normal(size=3) * 5 if flags["gravity"] else np.array([0.0, 0.0, -9.81])
    n = model.n_joints
    if kind in ("solve", "solve_out"):

        def call(solver, mdl):
            solver.gravity = gravity
            if kind == "solve":
                return solver.solve(**args)
            out = solver.solve(args["q"], args["qd"], friction=args.get("friction"))  # an out= to reuse
            return solver.solve(**args, out=out if out.friction_torque is None or "friction" in args else None)

        return call
    if kind == "batch":
        rows = int(rng.integers(1, 6))
        threads = int(rng.integers(0, 3))
        batch = dict(args)
        batch["q"] = args["q"] + rng.normal(size=(rows, n)) * 0.1
        batch["qd"] = np.tile(args["qd"], (rows, 1))

        def call(solver, mdl):
            solver.gravity = gravity
            return solver.solve_batch(**batch, threads=threads)

        return call
    if kind == "response":
        joints = list(rng.choice(n, size=int(rng.integers(1, 4)), replace=False))
        hold = bool(rng.integers(2))

        def call(solver, mdl):
            solver.gravity = gravity
            solver.solve(**args)
            return solver.response_columns(joints, hold_sticking=hold)

        return call
    if kind == "companion":
        frame = frame_keys(model)[int(rng.integers(len(frame_keys(model))))]
        qdd = rng.normal(size=n)
        f_ext = args.get("f_ext")

        def call(solver, mdl):
            q, qd = args["q"], args["qd"]
            return [
                mdl.fk(q, frame),
                mdl.jacobian(q, frame),
                mdl.twist(q, qd, frame),
                mdl.inverse_dynamics(q, qd, qdd, f_ext=f_ext, gravity=gravity),
                mdl.mass_matrix(q),
                mdl.gravity_torques(q, gravity),
                mdl.coriolis_torques(q, qd),
                mdl.jacobian_dot_times_qd(q, qd, frame),
                mdl.fk_all(q),
            ]

        return call
    # kind == "task": the helpers of vereshchagin.task (chain tip) or beta_for on a tree frame
    names = ["x", "y", "z", "rx", "ry", "rz"]
    picked = [names[k] for k in sorted(rng.choice(6, size=int(rng.integers(1, 4)), replace=False))]
    a_desired = rng.normal(size=6)
    task_kwargs = {k: args[k] for k in ("f_ext", "tau_ff", "friction") if k in args}

    def call(solver, mdl):
        solver.gravity = gravity
        task = vs.task.Task(picked)
        if is_tree:
            twist = mdl.twist(args["q"], args["qd"], "left_wrist")
            return vs.task.beta_for(task.alpha, a_desired, twist, gravity)
        return task.solve(solver, mdl, args["q"], args["qd"], a_desired, **task_kwargs)

    return call


FLAG_NAMES = ["alpha", "constraints", "f_ext", "tau_ff", "friction", "pass_through", "gravity", "bad"]

calls = st.lists(
    st.tuples(
        st.sampled_from(KINDS),
        st.integers(0, 2**32 - 1),
        st.fixed_dictionaries({k: st.booleans() for k in FLAG_NAMES}),
    ),
    min_size=2,
    max_size=7,
)


def check_sequence(models, which, sequence):
    model = models[which]
    is_tree = which == "tree"
    shared = vs.Solver(model)
    for step, (kind, seed, flags) in enumerate(sequence):
        call = make_call(kind, np.random.default_rng(seed), model, is_tree, flags)
        got = outcome(lambda: call(shared, model))  # noqa: B023 (called at once)
        fresh_model = model.__copy__()
        expected = outcome(lambda: call(vs.Solver(fresh_model), fresh_model))  # noqa: B023
        assert_same(got, expected, (which, step, kind, flags))


SETTINGS = settings(
    max_examples=60, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@SETTINGS
@given(sequence=calls)
def test_calls_on_one_chain_solver_equal_fresh_calls(models, sequence):
    check_sequence(models, "chain", sequence)


@SETTINGS
@given(sequence=calls)
def test_calls_on_one_tree_solver_equal_fresh_calls(models, sequence):
    check_sequence(models, "tree", sequence)


def test_the_property_sees_a_stale_argument(models):
    """The comparison is not vacuous: a wrench left over from an earlier call would be caught."""
    chain = models["chain"]
    solver = vs.Solver(chain)
    q, qd = np.full(7, 0.3), np.zeros(7)
    with_wrench = outcome(lambda: solver.solve(q, qd, f_ext={"end_effector_link": np.full(6, 10.0)}))
    without = outcome(lambda: vs.Solver(chain).solve(q, qd))
    with pytest.raises(AssertionError):
        assert_same(with_wrench, without, "stale")
