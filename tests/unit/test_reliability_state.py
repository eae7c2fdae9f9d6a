"""Every call stands alone (issue 23): regression tests for per-call state that leaked into later
calls, re-entrant calls, thread counts, crafted pickle states and unvalidated helper inputs.

Each test here failed (or hung, or crashed the process) before its fix. The oracle of "no call
influences a later call" is a fresh solver given the same call: results must agree bitwise.
"""

import pickle
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GEN3_Q = np.array([0.1, 0.6, -0.2, 1.9, 0.3, 0.8, -0.4])
GEN3_TIP = "end_effector_link"
WRENCH = np.array([3.0, -2.0, 50.0, 0.4, -0.3, 0.2])


def fields(res):
    """Every array and scalar of a SolveResult, for bitwise comparison."""
    names = ["qdd", "tau_command", "nu", "link_acc", "constraint_rank", "smallest_singular_value"]
    return [np.asarray(getattr(res, k)).copy() for k in names]


def assert_bitwise(a, b):
    for x, y in zip(fields(a), fields(b)):
        np.testing.assert_array_equal(x, y)


# --- a dict f_ext outlived its call ------------------------------------------------------------


@pytest.mark.parametrize("key", [GEN3_TIP, -1, 3, "half_arm_2_link"])
def test_dict_f_ext_does_not_outlive_its_call_on_a_chain(gen3, key):
    s = vs.Solver(gen3)
    qd = np.linspace(-0.3, 0.3, 7)
    with_wrench = s.solve(GEN3_Q, qd, f_ext={key: WRENCH})
    fresh = vs.Solver(gen3).solve(GEN3_Q, qd)
    assert np.abs(with_wrench.qdd - fresh.qdd).max() > 1e-3  # the wrench acted
    assert_bitwise(s.solve(GEN3_Q, qd), fresh)
    s.solve(GEN3_Q, qd, f_ext={key: WRENCH})
    assert_bitwise(s.solve(GEN3_Q, qd, f_ext=None), fresh)
    s.solve(GEN3_Q, qd, f_ext={key: WRENCH})
    out = s.solve(GEN3_Q, qd)
    assert_bitwise(s.solve(GEN3_Q, qd, out=out), fresh)
    s.solve(GEN3_Q, qd, f_ext={key: WRENCH})
    assert_bitwise(s.solve(GEN3_Q, qd, f_ext={}), fresh)


def test_dict_f_ext_does_not_outlive_its_call_on_a_tree(baxter):
    s = vs.Solver(baxter)
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.5, 0.5, baxter.n_joints)
    qd = rng.uniform(-0.5, 0.5, baxter.n_joints)
    fresh = vs.Solver(baxter).solve(q, qd)
    for key in ("left_gripper_base_link", "right_wrist", 0):
        s.solve(q, qd, f_ext={key: WRENCH})
        assert_bitwise(s.solve(q, qd), fresh)


# --- a Friction was cached by identity ---------------------------------------------------------


def test_friction_arrays_cannot_be_made_writeable_again():
    fr = vs.Friction(static=np.ones(7), kinetic=0.5 * np.ones(7), lower=-np.ones(7), upper=np.ones(7))
    for a in (fr.static, fr.kinetic, fr.lower, fr.upper):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a.flags.writeable = True


def test_a_replaced_friction_attribute_is_read_again(gen3):
    s = vs.Solver(gen3)
    qd = np.zeros(7)
    fr = vs.Friction(static=np.full(7, 0.5))
    s.solve(GEN3_Q, qd, friction=fr)
    object.__setattr__(fr, "static", vs.Friction(static=np.full(7, 100.0)).static)
    fresh = vs.Solver(gen3).solve(GEN3_Q, qd, friction=vs.Friction(static=np.full(7, 100.0)))
    res = s.solve(GEN3_Q, qd, friction=fr)
    assert_bitwise(res, fresh)
    np.testing.assert_array_equal(res.friction_torque, fresh.friction_torque)
    object.__setattr__(fr, "velocity_tolerance", 1e3)  # every joint at rest within 1e3 rad/s
    moving = np.full(7, 0.2)
    fresh = vs.Solver(gen3).solve(
        GEN3_Q, moving, friction=vs.Friction(static=np.full(7, 100.0), velocity_tolerance=1e3)
    )
    np.testing.assert_array_equal(s.solve(GEN3_Q, moving, friction=fr).status, fresh.status)


# --- response_columns after a solve that failed its argument checks ----------------------------


def test_response_columns_raises_after_a_failed_argument_check(gen3):
    s = vs.Solver(gen3)
    s.solve(GEN3_Q, np.zeros(7))
    s.response_columns([0])  # linearises around that solve
    with pytest.raises(vs.SolverError):
        s.solve(GEN3_Q[:3], np.zeros(7))
    with pytest.raises(vs.SolverError, match="last successful solve"):
        s.response_columns([0])
    s.solve(GEN3_Q, np.zeros(7))
    with pytest.raises(vs.SolverError):
        s.solve_batch(np.zeros((2, 3)), np.zeros((2, 7)))
    with pytest.raises(vs.SolverError, match="last successful solve"):
        s.response_columns([0])


# --- keys and indices beyond the C range, out= of another solver -------------------------------


@pytest.mark.parametrize("key", [2**70, -(2**70), np.int64(2**62)])
def test_huge_keys_are_out_of_range(gen3, key):
    s = vs.Solver(gen3)
    with pytest.raises(vs.SolverError, match="out of range"):
        s.solve(GEN3_Q, np.zeros(7), f_ext={key: WRENCH})
    with pytest.raises(vs.SolverError, match="out of range"):
        s.solve(GEN3_Q, np.zeros(7), constraints={key: (np.eye(6)[:, :1], [9.81])})
    s.solve(GEN3_Q, np.zeros(7))
    with pytest.raises(vs.SolverError, match="out of range"):
        s.response_columns([key])
    with pytest.raises(vs.SolverError, match="out of range"):
        gen3.fk(GEN3_Q, key)


def test_out_of_another_solver_names_the_sizes(gen3):
    six = vs.Chain.from_urdf(example_robot_urdf("ur5"), root="base_link", tip="tool0")
    out = vs.Solver(six).solve(np.zeros(6), np.zeros(6))
    with pytest.raises(vs.SolverError, match="n_joints = 6.*n_joints = 7"):
        vs.Solver(gen3).solve(GEN3_Q, np.zeros(7), out=out)


# --- threads ----------------------------------------------------------------------------------


@pytest.mark.parametrize("threads", [2.7, 2.0, float("nan"), True, "2", -1, 257, 10000, 2**70])
def test_bad_thread_counts_are_refused(gen3, threads):
    s = vs.Solver(gen3)
    with pytest.raises(vs.SolverError, match="threads"):
        s.solve_batch(np.tile(GEN3_Q, (8, 1)), np.zeros((8, 7)), threads=threads)


def test_integer_thread_counts_work_and_agree(gen3):
    s = vs.Solver(gen3)
    q = GEN3_Q + np.linspace(0, 1, 40)[:, None]
    ref = s.solve_batch(q, np.zeros((40, 7)), threads=1)
    for threads in (np.int64(3), 0, 256):
        got = s.solve_batch(q, np.zeros((40, 7)), threads=threads)
        np.testing.assert_array_equal(got.qdd, ref.qdd)


def run_python(code, timeout=120):
    """Runs `code` in a fresh interpreter; a crash or hang is a test failure, not a dead pytest."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout
    )


def test_a_thread_the_os_refuses_is_a_clean_error():
    # Address space limited so that thread stacks cannot be mapped: before the fix the process
    # aborted ("terminate called without an active exception").
    r = run_python(
        """
        import resource, numpy as np, vereshchagin as vs
        from vereshchagin.robots import gen3_urdf
        s = vs.Solver(vs.Chain.from_urdf(gen3_urdf(), tip="end_effector_link"))
        q = np.zeros((256, 7)); qd = np.zeros((256, 7))
        s.solve_batch(q, qd, threads=256)  # engines exist before the limit
        size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
        resource.setrlimit(resource.RLIMIT_AS, (size + (48 << 20), resource.RLIM_INFINITY))
        try:
            s.solve_batch(q, qd, threads=256)
            print("no error")
        except vs.SolverError as e:
            print("SolverError:", e)
        resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
        print("after:", np.abs(s.solve_batch(q, qd, threads=2).qdd - s.solve(q[0], qd[0]).qdd).max())
        """
    )
    assert r.returncode == 0, r.stderr
    assert "SolverError: solve_batch could not start thread" in r.stdout, r.stdout
    assert "after: 0.0" in r.stdout


# --- re-entrant calls -------------------------------------------------------------------------


REENTRY = """
import numpy as np, vereshchagin as vs
from vereshchagin.robots import gen3_urdf
s = vs.Solver(vs.Chain.from_urdf(gen3_urdf(), tip="end_effector_link"))

class Reenter:
    def __array__(self, dtype=None, copy=None):
        s.solve(np.zeros(7), np.zeros(7))
        return np.zeros(7)

class DuckFriction:
    kinetic = None
    @property
    def static(self):
        s.solve(np.zeros(7), np.zeros(7))
        return np.ones(7)

for name, call in [
    ("q", lambda: s.solve(Reenter(), np.zeros(7))),
    ("friction", lambda: s.solve(np.zeros(7), np.zeros(7), friction=DuckFriction())),
    ("batch", lambda: s.solve_batch(Reenter(), np.zeros(7))),
]:
    try:
        call()
        print(name, "no error")
    except vs.SolverError as e:
        print(name, "SolverError:", e)
print("then", np.array_equal(s.solve(np.zeros(7), np.zeros(7)).qdd,
                             vs.Solver(s.chain).solve(np.zeros(7), np.zeros(7)).qdd))
"""


def test_reentrant_calls_raise_instead_of_deadlocking():
    r = run_python(REENTRY, timeout=60)  # before the fix: a hang, killed by the timeout
    assert r.returncode == 0, r.stderr
    lines = dict(line.split(" ", 1) for line in r.stdout.splitlines())
    for name in ("q", "friction", "batch"):
        assert lines[name].startswith("SolverError:"), r.stdout
        assert "a Solver call re-entered the same Solver" in lines[name], r.stdout
    assert "then True" in r.stdout


# --- crafted pickle states --------------------------------------------------------------------


def test_chain_state_with_a_joint_record_out_of_range_is_refused(gen3):
    state = gen3.__getstate__()
    joints = [list(j) for j in state[2]]
    joints[0][8] = 10**6
    bad = (state[0], state[1], [tuple(j) for j in joints], state[3], state[4], state[5])
    with pytest.raises(vs.SolverError, match="joint record"):
        vs.Chain.__new__(vs.Chain).__setstate__(bad)


@pytest.mark.parametrize(
    "mutate",
    [
        lambda s: (s[0], s[1][:-1], *s[2:]),  # one segment fewer than joint records
        lambda s: (s[0], [s[1][0][:2] + (99,) + s[1][0][3:], *s[1][1:]], *s[2:]),  # joint type 99
        lambda s: (s[0], [s[1][0][:9] + ((np.nan,) * 13,), *s[1][1:]], *s[2:]),  # NaN inertia
        lambda s: (s[0], [s[1][0][:8] + ((1.0,) * 5,) + s[1][0][9:], *s[1][1:]], *s[2:]),  # short frame
        lambda s: (s[0], s[1], s[2], [("x", 10**6, s[3][0][2])], *s[4:]),  # link on no segment
        lambda s: (s[0], s[1], s[2], [("x", 2**80, s[3][0][2])], *s[4:]),  # beyond int
        lambda s: (s[0], "segments", *s[2:]),
    ],
)
def test_crafted_chain_states_are_refused(gen3, mutate):
    with pytest.raises(vs.SolverError, match="Chain state"):
        vs.Chain.__new__(vs.Chain).__setstate__(mutate(gen3.__getstate__()))


def test_crafted_tree_states_are_refused(baxter):
    state = baxter.__getstate__()
    joints = [list(j) for j in state[3]]
    joints[-1][8] = 10**6
    with pytest.raises(vs.SolverError, match="Tree state"):
        vs.Tree.__new__(vs.Tree).__setstate__((*state[:3], [tuple(j) for j in joints], *state[4:]))
    segments = list(state[2])
    segments[0] = (segments[0][0], 2**70)
    with pytest.raises(vs.SolverError, match="Tree state"):
        vs.Tree.__new__(vs.Tree).__setstate__((*state[:2], segments, *state[3:]))
    # The honest state still round-trips.
    assert pickle.loads(pickle.dumps(baxter)).segment_names == baxter.segment_names


@pytest.mark.parametrize(
    "sizes",
    [(2**31 - 1, 1, 0), (2**30, 2**30, 0), (7, 8, 2**31), (-1, 8, 0), (7, 2**40, 0), (7, 8, 49)],
)
def test_crafted_result_states_are_refused(gen3, sizes):
    res = vs.Solver(gen3).solve(GEN3_Q, np.zeros(7))
    reduce_fn, state = res.__reduce__()
    nj, ns, m = sizes
    with pytest.raises(ValueError):
        reduce_fn(nj, ns, m, *state[3:])
    assert reduce_fn(*state).qdd.tolist() == res.qdd.tolist()


def test_crafted_result_segment_layout_is_refused(gen3):
    res = vs.Solver(gen3).solve(GEN3_Q, np.zeros(7), constraints={GEN3_TIP: (np.eye(6)[:, :2], [0.0, 9.81])})
    reduce_fn, state = res.__reduce__()
    with pytest.raises(ValueError):
        reduce_fn(*state[:10], (10**6,), state[11])
    assert reduce_fn(*state).segment_nu.keys() == res.segment_nu.keys()


# --- the task helpers and companions validate like solve --------------------------------------


@pytest.mark.parametrize(
    "args",
    [
        (np.eye(6)[:, :1], np.full(6, np.nan), np.zeros(6)),
        (np.eye(6)[:, :1], np.zeros(6), np.array([np.inf, 0, 0, 0, 0, 0])),
        (np.full((6, 1), np.nan), np.zeros(6), np.zeros(6)),
        (np.eye(6)[:, :1], np.zeros(6), np.array([1e200, 0, 0, 0, 1e200, 0])),  # omega x v overflows
        (np.eye(6)[:, :1], np.array([1.7e308, 0, 0, 0, 0, 0]), np.zeros(6)),  # a - g overflows? no: a + 9.81
        (np.ones((6, 1)) * 1e308, np.array([1e308, 1e308, 0, 0, 0, 0]), np.zeros(6)),  # alpha^T a overflows
    ],
)
def test_beta_for_never_returns_nan_or_inf(args):
    try:
        beta = vs.task.beta_for(*args)
    except vs.SolverError:
        return
    assert np.all(np.isfinite(beta))


def test_task_helpers_refuse_non_real_dtypes():
    with pytest.raises(vs.SolverError, match="real numbers"):
        vs.task.beta_for(np.eye(6)[:, :1], np.zeros(6), np.zeros(6, dtype=complex))
    with pytest.raises(vs.SolverError, match="real numbers"):
        vs.task.pose_error(np.eye(4, dtype=complex), np.eye(4))


def test_beta_for_refuses_nan_and_overflow():
    with pytest.raises(vs.SolverError, match="finite"):
        vs.task.beta_for(np.eye(6)[:, :1], np.full(6, np.nan), np.zeros(6))
    with pytest.raises(vs.SolverError, match="overflow"):
        vs.task.beta_for(np.ones((6, 1)) * 1e308, np.array([1e308, 1e308, 0, 0, 0, 0]), np.zeros(6))


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((4, 4)),
        np.diag([2.0, 2.0, 2.0, 1.0]),
        np.diag([1.0, 1.0, -1.0, 1.0]),
        np.eye(4) * 1.0 + np.eye(4, k=-3),
    ],
)
def test_pose_error_refuses_matrices_that_are_not_poses(bad):
    with pytest.raises(vs.SolverError):
        vs.task.pose_error(bad, np.eye(4))
    with pytest.raises(vs.SolverError):
        vs.task.pose_error(np.eye(4), bad)


def test_twist_reports_overflow_like_the_other_companions(gen3, baxter):
    with pytest.raises(vs.SolverError, match="overflow"):
        gen3.twist(GEN3_Q, np.full(7, 1e308))
    with pytest.raises(vs.SolverError, match="overflow"):
        baxter.twist(np.zeros(baxter.n_joints), np.full(baxter.n_joints, 1e308), "left_wrist")
    with pytest.raises(vs.SolverError, match="overflow"):
        vs.task.twist_error(np.full(6, 1.7e308), np.full(6, -1.7e308))


# --- URDF paths -------------------------------------------------------------------------------


def test_a_directory_is_not_a_urdf(tmp_path):
    with pytest.raises(vs.SolverError, match="is a directory"):
        vs.Chain.from_urdf(str(tmp_path))
    with pytest.raises(vs.SolverError, match="is a directory"):
        vs.Tree.from_urdf(tmp_path)
