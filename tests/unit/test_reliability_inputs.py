"""Input validation at the boundary (issue 7): each invalid argument raises vs.SolverError (a
ValueError) whose message names the argument and what was expected, before any computation, and
the objects stay usable. Complements test_api.py's shape / NaN cases with the model, friction,
scalar-option and URDF checks."""

import numpy as np
import pytest

import vereshchagin as vs
from support import ROOT
from vereshchagin.models import seven_joint_arm


def raises(fn, *fragments):
    with pytest.raises(vs.SolverError) as ei:
        fn()
    msg = str(ei.value)
    for f in fragments:
        assert f in msg, f"{f!r} not in {msg!r}"
    return msg


# Chain model --------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kw,fragments",
    [
        (dict(mass=-1.0), ["segment 'link3'", "mass", ">= 0", "-1"]),
        (dict(mass=np.nan), ["segment 'link3'", "mass"]),
        (dict(mass="heavy"), ["segment 'link3'", "mass", "real number", "str"]),
        (dict(mass=None), ["segment 'link3'", "mass", "real number"]),
        (dict(mass=True), ["segment 'link3'", "mass", "real number", "bool"]),
        (dict(rotor_inertia=-0.5), ["segment 'link3'", "rotor_inertia", ">= 0"]),
        (dict(rotor_inertia=[1.0]), ["segment 'link3'", "rotor_inertia", "real number"]),
        (dict(inertia=np.diag([1.0, -1.0, 1.0])), ["segment 'link3'", "inertia", "positive semi-definite"]),
        (
            dict(inertia=np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])),
            ["segment 'link3'", "inertia", "symmetric"],
        ),
        (dict(com=[0.0, np.inf, 0.0]), ["segment 'link3'", "com"]),
        (dict(tip=np.diag([1.0, 1.0, -1.0, 1.0])), ["segment 'link3'", "tip", "rotation"]),
    ],
)
def test_segment_errors_name_segment_and_argument(kw, fragments):
    chain = vs.Chain()
    args = dict(name="link3", joint="rot_z", mass=1.0, inertia=np.eye(3) * 0.01)
    args.update(kw)
    raises(lambda: chain.add_segment(**args), *fragments)
    assert chain.n_segments == 0


def test_numpy_scalars_are_accepted():
    chain = vs.Chain()
    chain.add_segment("a", "rot_z", mass=np.float32(1.5), rotor_inertia=np.int64(0), inertia=np.eye(3) * 0.01)
    assert chain.segment_masses[0] == 1.5


def test_duplicate_names_raise():
    chain = vs.Chain()
    chain.add_segment("a", "rot_z", mass=1.0, inertia=np.eye(3) * 0.01)
    raises(lambda: chain.add_segment("a", "rot_x", mass=1.0), "name", "'a'", "already exists")
    raises(
        lambda: chain.add_segment("b", "rot_x", mass=1.0, joint_name="a_joint"),
        "joint_name",
        "'a_joint'",
        "already exists",
    )
    raises(lambda: chain.add_segment("", "rot_x", mass=1.0), "name", "non-empty")
    assert chain.n_segments == 1


def test_unknown_segment_names_raise():
    chain = seven_joint_arm()
    q = np.zeros(7)
    for fn in (chain.fk, chain.jacobian):
        raises(lambda fn=fn: fn(q, "link9"), "segment", "'link9'")
    raises(lambda: chain.twist(q, q, "nope"), "segment", "'nope'")
    raises(lambda: chain.segment_index("nope"), "segment", "'nope'")


# Solver options -----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kw,fragments",
    [
        (dict(rcond="small"), ["rcond", "real number"]),
        (dict(rcond=1.0), ["rcond", "[0, 1)"]),
        (dict(damping="x"), ["damping", "real number"]),
        (dict(damping=np.nan), ["damping"]),
    ],
)
def test_solver_option_errors(kw, fragments):
    raises(lambda: vs.Solver(seven_joint_arm(), **kw), *fragments)


# Friction -----------------------------------------------------------------------------------------
N = 7
ONES = np.ones(N)


@pytest.mark.parametrize(
    "kw,fragments",
    [
        (dict(static=-ONES), ["friction.static[0]", ">= 0", "-1"]),
        (dict(static=np.r_[1.0, np.nan, ONES[2:]]), ["friction.static", "NaN"]),
        (dict(static=np.ones(N + 1)), ["friction.static", "shape (7,)", "(8,)"]),
        (dict(static=ONES, kinetic=2 * ONES), ["friction.kinetic[0]", "kinetic <= static", "got 2"]),
        (dict(static=ONES, kinetic=-ONES), ["friction.kinetic[0]", "[0, friction.static[0] = 1]"]),
        (dict(static=ONES, kinetic=np.ones(3)), ["friction.kinetic", "shape (7,)"]),
        (dict(static=ONES, velocity_tolerance=-1e-3), ["friction.velocity_tolerance", ">= 0"]),
        (dict(static=ONES, velocity_tolerance=np.inf), ["friction.velocity_tolerance", "finite"]),
        (dict(static=ONES, velocity_tolerance="tiny"), ["friction.velocity_tolerance", "real number"]),
        (dict(static=ONES, lower=ONES, upper=-ONES), ["friction.lower[0]", "friction.upper[0]", "1 > -1"]),
        (dict(static=ONES, lower=np.r_[np.nan, ONES[1:]]), ["friction.lower", "NaN"]),
        (dict(static=ONES, lower=np.zeros(2)), ["friction.lower", "shape (7,)"]),
        (dict(static=ONES, lower=-ONES, limit_tolerance="x"), ["friction.limit_tolerance", "real number"]),
        (dict(static=ONES, lower=-ONES, limit_tolerance=-1.0), ["friction.limit_tolerance", ">= 0"]),
    ],
)
def test_friction_errors(kw, fragments):
    solver = vs.Solver(seven_joint_arm())
    ok = solver.solve(np.full(N, 0.3), np.zeros(N), friction=vs.Friction(static=ONES))
    raises(lambda: solver.solve(np.full(N, 0.3), np.zeros(N), friction=vs.Friction(**kw)), *fragments)
    again = solver.solve(np.full(N, 0.3), np.zeros(N), friction=vs.Friction(static=ONES))
    np.testing.assert_array_equal(ok.qdd, again.qdd)


# Finite inputs whose results overflow ------------------------------------------------------------
@pytest.mark.parametrize(
    "kw",
    [
        dict(qd=np.full(N, 1e160)),
        dict(tau_ff=np.full(N, 1e308)),
        dict(f_ext=np.full((N, 6), 1e308)),
        dict(alpha=np.eye(6)[:, :1], beta=[1e308]),
        dict(alpha=np.full((6, 2), 1e200), beta=[1.0, 2.0]),
    ],
)  # K overflows
def test_overflowing_inputs_raise_instead_of_nan(kw):
    solver = vs.Solver(seven_joint_arm())
    args = dict(q=np.full(N, 0.4), qd=np.zeros(N))
    args.update(kw)
    raises(lambda: solver.solve(**args), "overflow")
    raises(lambda: solver.response_columns([0]), "solve")  # no stale solution is offered
    assert np.all(np.isfinite(solver.solve(np.full(N, 0.4), np.zeros(N)).qdd))


# URDF ---------------------------------------------------------------------------------------------
def urdf(
    joint_extra="",
    origin='xyz="0 0 0.1" rpy="0 0 0"',
    mass="1.0",
    inertial_origin='xyz="0 0 0.1"',
    ixx="0.01",
    axis="0 0 1",
    jtype="continuous",
):
    return f"""<robot name="r">
  <link name="base"/>
  <link name="l1"><inertial><origin {inertial_origin}/><mass value="{mass}"/>
    <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j1" type="{jtype}"><parent link="base"/><child link="l1"/><origin {origin}/>
    <axis xyz="{axis}"/>{joint_extra}</joint>
</robot>"""


def test_valid_urdf_loads():
    chain = vs.Chain.from_urdf(urdf('<limit lower="-1" upper="1" effort="1" velocity="1"/>', jtype="revolute"))
    assert chain.n_joints == 1


@pytest.mark.parametrize(
    "kw,fragments",
    [
        (dict(mass="-2"), ["l1", "mass"]),
        (dict(ixx="-1"), ["l1", "inertia", "positive semi-definite"]),
        (dict(origin='xyz="nan 0 0"'), ["j1", "origin", "nan"]),  # urdfdom rejects NaN / Inf text,
        (dict(origin='xyz="0 0 0" rpy="0 inf 0"'), ["j1", "origin"]),  # the loader overflowing values
        (dict(origin='xyz="1e400 0 0"'), ["j1", "origin"]),
        (dict(inertial_origin='xyz="0 nan 0"'), ["l1", "inertial"]),
        (dict(inertial_origin='xyz="0 1e999 0"'), ["l1", "inertial"]),
        (dict(mass="1e999"), ["l1", "mass"]),
        (dict(axis="0 0 0"), ["j1", "axis"]),
        (
            dict(jtype="revolute", joint_extra='<limit lower="1" upper="-1" effort="1" velocity="1"/>'),
            ["j1", "lower limit above upper"],
        ),
        (dict(joint_extra='<dynamics friction="-0.5"/>'), ["j1", "friction", ">= 0"]),
        (dict(joint_extra='<dynamics damping="-0.5"/>'), ["j1", "damping", ">= 0"]),
    ],
)
def test_invalid_urdf_values(kw, fragments):
    raises(lambda: vs.Chain.from_urdf(urdf(**kw)), *fragments)


def test_urdf_unknown_links_raise():
    raises(lambda: vs.Chain.from_urdf(urdf(), root="nope"), "root link 'nope'")
    raises(lambda: vs.Chain.from_urdf(urdf(), tip="nope"), "tip link 'nope'")


def test_urdf_link_cycle_raises():
    # Regression (fuzzing): urdfdom accepts this document (a joint whose parent and child are the
    # same link, next to a malformed element); the loader's recursive walks never ended (stack
    # overflow).
    path = str(ROOT / "cpp" / "fuzz" / "regressions" / "urdf-self-loop-accepted")
    raises(lambda: vs.Chain.from_urdf(path), "j2", "to itself")
