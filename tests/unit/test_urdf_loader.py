"""Chain.from_urdf on small hand-written URDFs: merging, frames, joint kinds, defaults and errors.

Expected values are computed here by hand with numpy (URDF origin: Trans(xyz) RotZ(y) RotY(p)
RotX(r); combined rigid bodies by the parallel-axis theorem) and observed through the chain's
kinematics and the solver's dynamics (for one revolute joint about the unit axis u through the
joint origin, at rest and without gravity, qdd = tau / (u^T I_O u) with I_O the body's inertia
about the joint origin; with gravity g and tau = 0, qdd = u . (c x m g) / (u^T I_O u)). A few
multi-joint checks use Pinocchio's URDF reader as the oracle.
"""

from __future__ import annotations

from xml.etree import ElementTree

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs

E3 = np.eye(3)


# ------------------------------------------------------------------------------------------------
# Hand geometry
# ------------------------------------------------------------------------------------------------
def rpy_matrix(rpy):
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def pose(xyz=(0, 0, 0), rpy=(0, 0, 0)):
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(rpy)
    T[:3, 3] = xyz
    return T


def rodrigues(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return E3 + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def rot4(axis, angle):
    T = np.eye(4)
    T[:3, :3] = rodrigues(axis, angle)
    return T


def trans4(v):
    T = np.eye(4)
    T[:3, 3] = v
    return T


def combine(bodies):
    """bodies: (mass, com, inertia about com), all in one frame -> combined (m, c, Ic)."""
    m = sum(b[0] for b in bodies)
    c = sum(b[0] * np.asarray(b[1]) for b in bodies) / m
    Ic = np.zeros((3, 3))
    for mi, ci, Ii in bodies:
        d = np.asarray(ci) - c
        Ic += Ii + mi * (d @ d * E3 - np.outer(d, d))
    return m, c, Ic


def about_point(m, c, Ic, p=(0.0, 0.0, 0.0)):
    d = np.asarray(c) - p
    return Ic + m * (d @ d * E3 - np.outer(d, d))


def body_in(T, mass, com, inertia):
    """A link's inertial (com, inertia about com in its inertial-frame axes) seen from frame T."""
    R = T[:3, :3]
    return mass, T[:3, :3] @ np.asarray(com) + T[:3, 3], R @ inertia @ R.T


# ------------------------------------------------------------------------------------------------
# URDF text
# ------------------------------------------------------------------------------------------------
def vec(v):
    return " ".join(repr(float(x)) for x in v)


def link(name, mass=None, com=(0, 0, 0), com_rpy=(0, 0, 0), inertia=None):
    if mass is None:
        return f'<link name="{name}"/>'
    I = np.zeros((3, 3)) if inertia is None else np.asarray(inertia, float)
    return (
        f'<link name="{name}"><inertial><origin xyz="{vec(com)}" rpy="{vec(com_rpy)}"/>'
        f'<mass value="{float(mass)!r}"/><inertia ixx="{float(I[0, 0])!r}" ixy="{float(I[0, 1])!r}" '
        f'ixz="{float(I[0, 2])!r}" iyy="{float(I[1, 1])!r}" iyz="{float(I[1, 2])!r}" '
        f'izz="{float(I[2, 2])!r}"/></inertial></link>'
    )


def joint(
    name,
    kind,
    parent,
    child,
    xyz=(0, 0, 0),
    rpy=(0, 0, 0),
    axis=(0, 0, 1),
    extra="",
    limit='<limit lower="-3" upper="3" effort="10" velocity="2"/>',
):
    body = f'<parent link="{parent}"/><child link="{child}"/><origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/>'
    if kind == "continuous" and "lower" in limit:
        limit = '<limit effort="10" velocity="2"/>'
    if kind != "fixed":
        body += f'<axis xyz="{vec(axis)}"/>' + limit
    return f'<joint name="{name}" type="{kind}">{body}{extra}</joint>'


_NUMERIC = {
    "xyz",
    "rpy",
    "value",
    "ixx",
    "ixy",
    "ixz",
    "iyy",
    "iyz",
    "izz",
    "lower",
    "upper",
    "effort",
    "velocity",
    "damping",
    "friction",
    "multiplier",
}


def robot(*parts):
    text = '<?xml version="1.0"?>\n<robot name="test">\n' + "\n".join(parts) + "\n</robot>\n"
    # Guard the test itself: urdfdom only logs bad numbers (and then uses zeros), so check them here.
    for el in ElementTree.fromstring(text).iter():
        for key, value in el.attrib.items():
            if key in _NUMERIC:
                [float(x) for x in value.split()]
    return text


def inertia_matrix(rng):
    """A random valid (PSD, triangle inequality) inertia tensor with products of inertia."""
    while True:  # principal moments with every triangle inequality (a margin of 1e-3)
        a, b, c = rng.uniform(0.02, 0.2, 3)
        if min(a + b - c, b + c - a, a + c - b) >= 1e-3:
            break
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Q @ np.diag([a, b, c]) @ Q.T
    return 0.5 * (I + I.T)


def qdd_one_joint(chain, gravity, q=0.0, tau=0.0):
    return vs.Solver(chain, gravity=gravity).solve([q], [0.0], tau_ff=[tau]).qdd[0]


AXES = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, 0, 1), (0, 1, 1), (0.3, -2.0, 0.7)]


# ------------------------------------------------------------------------------------------------
# Fixed joints merge into their parent
# ------------------------------------------------------------------------------------------------
def _two_link_case(axis, seed=0):
    rng = np.random.default_rng(seed)
    l1 = dict(mass=2.0, com=(0.05, -0.02, 0.1), com_rpy=(0.2, 0.4, -0.3), inertia=inertia_matrix(rng))
    l2 = dict(mass=1.5, com=(0.01, 0.03, -0.04), com_rpy=(-0.5, 0.1, 0.9), inertia=inertia_matrix(rng))
    j1 = dict(xyz=(0.1, 0.2, 0.3), rpy=(0.3, -0.2, 0.5))
    fx = dict(xyz=(0.0, 0.15, 0.25), rpy=(1.0, 0.2, -0.7))
    text = robot(
        link("base"),
        link("l1", **l1),
        link("l2", **l2),
        joint("j1", "revolute", "base", "l1", axis=axis, **j1),
        joint("weld", "fixed", "l1", "l2", **fx),
    )
    # Hand: everything in the l1 (joint) frame.
    b1 = body_in(pose(l1["com"], l1["com_rpy"]), l1["mass"], (0, 0, 0), l1["inertia"])
    b2 = body_in(pose(fx["xyz"], fx["rpy"]) @ pose(l2["com"], l2["com_rpy"]), l2["mass"], (0, 0, 0), l2["inertia"])
    m, c, Ic = combine([b1, b2])
    return text, dict(m=m, c=c, Ic=Ic, T_joint=pose(**j1), T_fixed=pose(**fx))


@pytest.mark.parametrize("axis", AXES)
def test_fixed_joint_merged_parallel_axis(axis):
    text, h = _two_link_case(axis)
    chain = vs.Chain.from_urdf(text)
    assert chain.n_joints == 1 and chain.n_segments == 1
    assert chain.segment_names == ["l2"]
    assert set(chain.link_names) == {"base", "l1", "l2"}
    assert chain.segment_masses[0] == pytest.approx(3.5, rel=1e-14)
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    I_O = about_point(h["m"], h["c"], h["Ic"])
    # inertia about the joint axis (through the joint origin)
    assert qdd_one_joint(chain, [0, 0, 0], tau=1.0) == pytest.approx(1.0 / (u @ I_O @ u), rel=1e-12)
    # centre of mass: the gravity torque about the axis, for three gravity directions
    R0 = h["T_joint"][:3, :3]
    for g in ([0, 0, -9.81], [3.0, -4.0, 1.0], [-2.0, 0.5, 6.0]):
        g = np.asarray(g)
        expected = (R0 @ u) @ np.cross(R0 @ h["c"], h["m"] * g) / (u @ I_O @ u)
        assert qdd_one_joint(chain, g) == pytest.approx(expected, rel=1e-10, abs=1e-12)
    # and rotor inertia adds on the joint's diagonal
    chain.rotor_inertia = [0.25]
    assert qdd_one_joint(chain, [0, 0, 0], tau=1.0) == pytest.approx(1.0 / (u @ I_O @ u + 0.25), rel=1e-12)


@pytest.mark.parametrize("axis", [(0, 0, 1), (0.3, -2.0, 0.7)])
def test_merged_frames_and_any_axis(axis):
    text, h = _two_link_case(axis)
    chain = vs.Chain.from_urdf(text)
    for q in (0.0, 0.8, -2.5):
        T_l1 = h["T_joint"] @ rot4(axis, q)
        T_l2 = T_l1 @ h["T_fixed"]
        np.testing.assert_allclose(chain.fk([q]), T_l2, atol=1e-14)  # tip = l2's frame
        np.testing.assert_allclose(chain.fk([q], "l2"), T_l2, atol=1e-14)
        np.testing.assert_allclose(chain.fk([q], "l1"), T_l1, atol=1e-14)  # merged link
        np.testing.assert_allclose(chain.fk([q], "base"), np.eye(4), atol=0)
        w = T_l1[:3, :3] @ (np.asarray(axis, float) / np.linalg.norm(axis))  # axis in base axes
        for name, T in (("l1", T_l1), ("l2", T_l2)):
            r = T[:3, 3] - h["T_joint"][:3, 3]
            np.testing.assert_allclose(chain.jacobian([q], name)[:, 0], np.r_[np.cross(w, r), w], atol=1e-14)
            np.testing.assert_allclose(chain.twist([q], [1.7], name), 1.7 * np.r_[np.cross(w, r), w], atol=1e-13)


def test_fixed_subtree_beyond_the_tip_is_merged():
    rng = np.random.default_rng(5)
    L = {
        k: dict(mass=m, com=rng.uniform(-0.1, 0.1, 3), inertia=inertia_matrix(rng))
        for k, m in (("a", 1.0), ("b", 0.5), ("c", 0.25), ("d", 0.75), ("e", 0.4))
    }
    fb, fc, fd, je = (
        pose((0, 0, 0.2), (0.3, 0, 0)),
        pose((0.1, 0, 0.05), (0, 0.5, 0)),
        pose((0, -0.1, 0), (0, 0, 1.2)),
        pose((0.05, 0.05, 0), (0.1, 0.2, 0.3)),
    )
    text = robot(
        link("base"),
        *(link(k, **v) for k, v in L.items()),
        joint("ja", "revolute", "base", "a", xyz=(0, 0, 0.1), axis=(1, 0, 0)),
        joint("fb", "fixed", "a", "b", xyz=fb[:3, 3], rpy=(0.3, 0, 0)),
        joint("fc", "fixed", "b", "c", xyz=fc[:3, 3], rpy=(0, 0.5, 0)),
        joint("fd", "fixed", "a", "d", xyz=fd[:3, 3], rpy=(0, 0, 1.2)),
        joint("je", "revolute", "d", "e", xyz=je[:3, 3], rpy=(0.1, 0.2, 0.3), axis=(0, 1, 0)),
    )
    chain = vs.Chain.from_urdf(text, tip="a")
    assert chain.n_joints == 1 and chain.segment_names == ["a"]
    assert chain.segment_masses[0] == pytest.approx(2.9, rel=1e-14)
    assert any("je" in note for note in chain.notes)  # the moving joint beyond the tip is lumped at 0
    poses = {"a": np.eye(4), "b": fb, "c": fb @ fc, "d": fd, "e": fd @ je}
    bodies = [body_in(poses[k], v["mass"], v["com"], v["inertia"]) for k, v in L.items()]
    m, c, Ic = combine(bodies)
    I_O = about_point(m, c, Ic)
    assert qdd_one_joint(chain, [0, 0, 0], tau=2.0) == pytest.approx(2.0 / I_O[0, 0], rel=1e-12)
    g = np.array([0.0, 0.0, -9.81])
    assert qdd_one_joint(chain, g) == pytest.approx(np.cross(c, m * g)[0] / I_O[0, 0], rel=1e-10)
    q = 0.6
    T_a = trans4((0, 0, 0.1)) @ rot4((1, 0, 0), q)
    np.testing.assert_allclose(chain.fk([q]), T_a, atol=1e-14)
    for k in ("b", "c", "d", "e"):
        np.testing.assert_allclose(chain.fk([q], k), T_a @ poses[k], atol=1e-14)


def test_fixed_joints_between_moving_joints_and_before_the_first():
    """base -fixed-> mount -rev-> a -fixed-> b -rev-> c: two segments, tip frames b and c; the
    second joint's axis is in b's frame. Checked against Pinocchio at random states."""
    rng = np.random.default_rng(8)
    parts = [
        link("base", 3.0, inertia=np.eye(3)),
        link("mount"),
        link("a", 1.2, (0.1, 0, 0), inertia=inertia_matrix(rng)),
        link("b", 0.7, (0, 0.05, 0.02), (0.3, 0.1, 0.2), inertia_matrix(rng)),
        link("c", 0.9, (0.02, 0.0, 0.1), inertia=inertia_matrix(rng)),
        joint("f0", "fixed", "base", "mount", (0.0, 0.1, 0.2), (0.1, 0.0, 0.4)),
        joint("j1", "revolute", "mount", "a", (0.0, 0.0, 0.1), (0.0, 0.3, 0.0), axis=(0, 1, 1)),
        joint("f1", "fixed", "a", "b", (0.3, 0.0, 0.0), (0.0, 0.0, 0.5)),
        joint("j2", "continuous", "b", "c", (0.0, 0.2, 0.0), (0.2, 0.0, 0.0), axis=(1, 0, 0.5)),
    ]
    text = robot(*parts)
    chain = vs.Chain.from_urdf(text)
    assert chain.segment_names == ["b", "c"]
    assert chain.root_link == "base"
    assert np.allclose(chain.segment_masses, [1.9, 0.9])
    model = pin.buildModelFromXML(text)
    data = model.createData()
    g = np.array([1.0, -2.0, -9.0])
    model.gravity = pin.Motion(np.r_[g, 0, 0, 0])
    solver = vs.Solver(chain, gravity=g)
    for _ in range(5):
        q = rng.uniform(-2, 2, 2)
        qd = rng.normal(size=2)
        tau = rng.normal(size=2)
        pq = np.array([q[0], np.cos(q[1]), np.sin(q[1])])
        np.testing.assert_allclose(
            solver.solve(q, qd, tau_ff=tau).qdd, pin.aba(model, data, pq, qd, tau), rtol=1e-10, atol=1e-10
        )
        pin.framesForwardKinematics(model, data, pq)
        for name in ("mount", "a", "b", "c"):
            np.testing.assert_allclose(chain.fk(q, name), data.oMf[model.getFrameId(name)].homogeneous, atol=1e-14)


# ------------------------------------------------------------------------------------------------
# Prismatic and continuous joints, limits
# ------------------------------------------------------------------------------------------------
def test_prismatic_joint_any_axis():
    axis = np.array([1.0, -2.0, 0.5])
    u = axis / np.linalg.norm(axis)
    rpy, xyz = (0.4, -0.3, 1.1), (0.2, 0.0, 0.5)
    text = robot(
        link("base"),
        link("slider", 2.5, (0.1, 0.2, 0.0), inertia=np.diag([0.1, 0.2, 0.3])),
        joint(
            "p",
            "prismatic",
            "base",
            "slider",
            xyz,
            rpy,
            axis,
            limit='<limit lower="-0.2" upper="0.4" effort="50" velocity="0.5"/>',
            extra='<dynamics damping="3.5" friction="1.25"/>',
        ),
    )
    chain = vs.Chain.from_urdf(text)
    assert chain.joint_types == ["prismatic"]
    w = rpy_matrix(rpy) @ u  # axis in base axes
    for q in (-0.2, 0.0, 0.33):
        np.testing.assert_allclose(chain.fk([q]), trans4(w * q) @ pose(xyz, rpy), atol=1e-14)
        np.testing.assert_allclose(chain.jacobian([q])[:, 0], np.r_[w, 0, 0, 0], atol=1e-15)
    assert qdd_one_joint(chain, [0, 0, 0], tau=5.0) == pytest.approx(2.0, rel=1e-12)  # tau / m
    g = np.array([0.5, 1.0, -9.81])
    assert qdd_one_joint(chain, g, q=0.1) == pytest.approx(w @ g, rel=1e-12)  # free fall
    np.testing.assert_array_equal(chain.lower, [-0.2])
    np.testing.assert_array_equal(chain.upper, [0.4])
    np.testing.assert_array_equal(chain.velocity_limit, [0.5])
    np.testing.assert_array_equal(chain.effort_limit, [50.0])
    np.testing.assert_array_equal(chain.friction, [1.25])
    np.testing.assert_array_equal(chain.damping, [3.5])


def test_continuous_joint_has_no_position_limits():
    text = robot(
        link("base"),
        link("a", 1.0, inertia=np.eye(3) * 0.1),
        joint("c", "continuous", "base", "a", limit='<limit effort="7" velocity="3"/>'),
    )
    chain = vs.Chain.from_urdf(text)
    assert chain.joint_types == ["continuous"]
    np.testing.assert_array_equal(chain.lower, [-np.inf])
    np.testing.assert_array_equal(chain.upper, [np.inf])
    np.testing.assert_array_equal(chain.velocity_limit, [3.0])
    np.testing.assert_array_equal(chain.effort_limit, [7.0])
    np.testing.assert_array_equal(chain.friction, [0.0])
    np.testing.assert_array_equal(chain.damping, [0.0])
    np.testing.assert_array_equal(chain.rotor_inertia, [0.0])


# ------------------------------------------------------------------------------------------------
# Root and tip
# ------------------------------------------------------------------------------------------------
def _tree():
    return robot(
        link("world"),
        link("base", 1.0, inertia=np.eye(3)),
        link("a", 1.0, inertia=np.eye(3) * 0.1),
        link("b1", 0.5, inertia=np.eye(3) * 0.1),
        link("b2", 0.6, inertia=np.eye(3) * 0.1),
        link("c1", 0.2, inertia=np.eye(3) * 0.1),
        joint("fw", "fixed", "world", "base", (0, 0, 1.0)),
        joint("ja", "revolute", "base", "a", (0, 0, 0.3)),
        joint("jb1", "revolute", "a", "b1", (0.2, 0, 0), axis=(0, 1, 0)),
        joint("jb2", "revolute", "a", "b2", (-0.2, 0, 0), axis=(0, 1, 0)),
        joint("jc1", "prismatic", "b1", "c1", (0, 0, 0.2), axis=(0, 0, 1)),
    )


def test_default_root_and_tip():
    text = robot(
        link("r"),
        link("a", 1.0, inertia=np.eye(3)),
        link("b", 1.0, inertia=np.eye(3)),
        joint("j1", "revolute", "r", "a"),
        joint("j2", "revolute", "a", "b", (0, 0, 0.5), axis=(1, 0, 0)),
    )
    chain = vs.Chain.from_urdf(text)
    assert chain.root_link == "r"
    assert chain.segment_names == ["a", "b"]
    assert chain.joint_names == ["j1", "j2"]
    explicit = vs.Chain.from_urdf(text, root="r", tip="b")
    q = [0.3, -0.7]
    np.testing.assert_array_equal(chain.fk(q), explicit.fk(q))


def test_branching_tree_without_tip_names_the_leaves():
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_tree())
    msg = str(info.value)
    assert "c1" in msg and "b2" in msg and "tip" in msg


def test_branch_selected_by_tip_and_other_branch_lumped():
    chain = vs.Chain.from_urdf(_tree(), tip="c1")
    assert chain.root_link == "world"
    assert chain.joint_names == ["ja", "jb1", "jc1"]
    assert chain.joint_types == ["revolute", "revolute", "prismatic"]
    # b2 hangs off 'a' through a moving joint: lumped into a's segment at position 0
    np.testing.assert_allclose(chain.segment_masses, [1.6, 0.5, 0.2], rtol=1e-14)
    assert any("jb2" in note for note in chain.notes)
    # the base link 'base' (welded to the root) carries no segment; the chain starts 1 m up
    T = chain.fk([0.0, 0.0, 0.0], 0)
    np.testing.assert_allclose(T[:3, 3], [0, 0, 1.3], atol=1e-15)
    np.testing.assert_allclose(chain.fk([0.0, 0.0, 0.0], "base"), trans4((0, 0, 1.0)), atol=1e-15)


def test_root_in_the_middle():
    chain = vs.Chain.from_urdf(_tree(), root="a", tip="c1")
    assert chain.root_link == "a"
    assert chain.joint_names == ["jb1", "jc1"]
    q = [0.4, 0.05]
    expected = trans4((0.2, 0, 0)) @ rot4((0, 1, 0), 0.4) @ trans4((0, 0, 0.2 + 0.05))
    np.testing.assert_allclose(chain.fk(q), expected, atol=1e-14)


# ------------------------------------------------------------------------------------------------
# Errors
# ------------------------------------------------------------------------------------------------
def _simple(kind="revolute", extra="", mass=1.0, inertia=None, second=True):
    I = np.eye(3) * 0.1 if inertia is None else inertia
    parts = [link("base"), link("a", mass, inertia=I), joint("j", kind, "base", "a", extra=extra)]
    if second:
        parts += [link("b", 1.0, inertia=np.eye(3) * 0.1), joint("k", "revolute", "a", "b", axis=(1, 0, 0))]
    return robot(*parts)


@pytest.mark.parametrize(
    "text, words",
    [
        ("<robot name='r'><link name='a'></robot>", ["malformed"]),
        ("<robot name='r'><link name='a'/><joint name='j' type='revolute'>", ["malformed"]),
        ("<notarobot/>", ["malformed"]),
    ],
)
def test_malformed_xml(text, words):
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(text)
    for w in words:
        assert w in str(info.value).lower()


@pytest.mark.parametrize(
    "root, tip, words",
    [
        ("nowhere", "", ["root", "nowhere", "not found"]),
        ("", "nowhere", ["tip", "nowhere", "not found"]),
        ("b1", "b2", ["b2", "b1", "not below"]),
        ("c1", "a", ["a", "c1", "not below"]),
    ],
)
def test_bad_root_or_tip(root, tip, words):
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_tree(), root=root, tip=tip)
    for w in words:
        assert w in str(info.value)


@pytest.mark.parametrize("kind", ["floating", "planar"])
def test_floating_or_planar_joint_on_the_path(kind):
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_simple(kind))
    assert "'j'" in str(info.value) and kind in str(info.value)


def test_mimic_joint_on_the_path():
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_simple(extra='<mimic joint="k" multiplier="2"/>'))
    assert "'j'" in str(info.value) and "mimic" in str(info.value)


def test_negative_mass():
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_simple(mass=-0.5))
    assert "'a'" in str(info.value) and "negative mass" in str(info.value)


@pytest.mark.parametrize("inertia", [np.diag([0.1, 0.1, -0.1]), np.array([[0.1, 0.3, 0], [0.3, 0.1, 0], [0, 0, 0.1]])])
def test_inertia_not_positive_semidefinite(inertia):
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(_simple(inertia=inertia))
    assert "'a'" in str(info.value) and "positive semi-definite" in str(info.value)


def test_bad_inertial_beyond_the_tip_is_reported_too():
    text = robot(
        link("base"),
        link("a", 1.0, inertia=np.eye(3) * 0.1),
        link("x", -1.0, inertia=np.eye(3)),
        joint("j", "revolute", "base", "a"),
        joint("f", "fixed", "a", "x"),
    )
    with pytest.raises(vs.SolverError, match="negative mass"):
        vs.Chain.from_urdf(text, tip="a")


def test_missing_file(tmp_path):
    missing = str(tmp_path / "does_not_exist.urdf")
    with pytest.raises(vs.SolverError) as info:
        vs.Chain.from_urdf(missing)
    assert "does_not_exist.urdf" in str(info.value)


def test_no_moving_joint():
    text = robot(link("base"), link("a", 1.0, inertia=np.eye(3)), joint("f", "fixed", "base", "a"))
    with pytest.raises(vs.SolverError, match="no moving joint"):
        vs.Chain.from_urdf(text)


# ------------------------------------------------------------------------------------------------
# From a file
# ------------------------------------------------------------------------------------------------
def test_from_file_path(tmp_path):
    text, h = _two_link_case((0.3, -2.0, 0.7), seed=3)
    path = tmp_path / "two_links.urdf"
    path.write_text(text, encoding="utf-8")
    from_file = vs.Chain.from_urdf(str(path))
    from_text = vs.Chain.from_urdf(text)
    assert from_file.segment_names == from_text.segment_names == ["l2"]
    np.testing.assert_array_equal(from_file.segment_masses, [3.5])
    q = [1.1]
    T = h["T_joint"] @ rot4((0.3, -2.0, 0.7), 1.1) @ h["T_fixed"]
    np.testing.assert_allclose(from_file.fk(q), T, atol=1e-14)
    u = np.array([0.3, -2.0, 0.7]) / np.linalg.norm([0.3, -2.0, 0.7])
    I_O = about_point(h["m"], h["c"], h["Ic"])
    assert qdd_one_joint(from_file, [0, 0, 0], tau=1.0) == pytest.approx(1.0 / (u @ I_O @ u), rel=1e-12)
