"""vs.Tree (URDF trees) against Pinocchio and against the URDF text read with xml.etree.

Robots: Baxter (example-robot-data: head, two 7-joint arms, two-finger grippers, 19 joints; the
mimic finger joints are independent joints, as in Pinocchio's default parser), Talos
(``talos_reduced``: all 32 joints below its ``base_link``, the floating base not modelled) and
random trees written as URDF text (tests/support/trees.py). Both libraries load the same URDF; Pinocchio
without a free-flyer. Joints are matched by name. Tolerances: 1e-9 relative (norm-wise).
"""

from __future__ import annotations

import copy
import pickle
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from support.chains import assert_close
from support.trees import pin_model, pin_q, pin_v_index, random_tree_urdf
from vereshchagin.robots import example_robot_urdf

RTOL = 1e-9
LWA = pin.LOCAL_WORLD_ALIGNED
SEEDS = (1, 2, 3, 4, 5, 6)


def assert_rel(actual, expected, what, rtol=RTOL):
    """chains.assert_close with this file's tolerance and argument order."""
    assert_close(actual, expected, rtol, what)


def _source(name: str) -> str:
    if name.startswith("random"):
        return random_tree_urdf(int(name[len("random") :])).urdf
    return example_robot_urdf(name)


CASES = ["baxter", "talos_reduced"] + [f"random{s}" for s in SEEDS]


def _load(name):
    source = _source(name)
    return vs.Tree.from_urdf(source), pin_model(source), source


def _urdf_joints(source: str) -> dict[str, ET.Element]:
    text = source if "<" in source else Path(source).read_text()
    return {j.get("name"): j for j in ET.fromstring(text).findall("joint")}  # not <transmission>'s


def _random_q(tree, rng):
    lo = np.maximum(tree.lower, -np.pi)
    hi = np.minimum(tree.upper, np.pi)
    return rng.uniform(lo, hi), rng.uniform(-1.5, 1.5, tree.n_joints)


@pytest.mark.parametrize("name", CASES)
def test_joints_order_and_masses(name):
    tree, model, source = _load(name)
    pin_names = list(model.names)[1:]
    assert sorted(tree.joint_names) == sorted(pin_names)
    assert tree.joint_names == pin_names  # same preorder, children by joint name
    assert tree.n_joints == tree.n_segments == model.nv
    parent = tree.parent
    assert parent.dtype == np.int64 and parent.shape == (tree.n_segments,)
    for i, name_i in enumerate(tree.joint_names):
        assert parent[i] < i
        pin_parent = model.parents[model.getJointId(name_i)]
        expected = -1 if pin_parent == 0 else tree.joint_names.index(model.names[pin_parent])
        assert parent[i] == expected, name_i
    total = pin.computeTotalMass(model)
    assert_rel(tree.segment_masses.sum(), total, "total mass")
    for i, joint in enumerate(tree.joint_names):
        assert_rel(tree.segment_masses[i], model.inertias[model.getJointId(joint)].mass, f"mass of {joint}")


@pytest.mark.parametrize("seed", SEEDS)
def test_random_tree_mass_and_joints_from_the_drawn_values(seed):
    drawn = random_tree_urdf(seed)
    tree = vs.Tree.from_urdf(drawn.urdf)
    assert_rel(tree.segment_masses.sum(), drawn.total_mass, "total mass")
    assert sorted(tree.joint_names) == sorted(j.name for j in drawn.moving)
    assert sorted(tree.link_names) == sorted(drawn.links)
    by_name = {j.name: j for j in drawn.moving}
    assert tree.joint_types == [by_name[n].type for n in tree.joint_names]


@pytest.mark.parametrize("name", CASES)
def test_limits_friction_damping_against_the_urdf_text(name):
    tree, _, source = _load(name)
    joints = _urdf_joints(source)
    for k, jname in enumerate(tree.joint_names):
        j = joints[jname]
        limit, dyn = j.find("limit"), j.find("dynamics")
        continuous = j.get("type") == "continuous"
        lower = -np.inf if limit is None or continuous else float(limit.get("lower", 0.0))
        upper = np.inf if limit is None or continuous else float(limit.get("upper", 0.0))
        vel = float(limit.get("velocity", 0.0)) if limit is not None else 0.0
        eff = float(limit.get("effort", 0.0)) if limit is not None else 0.0
        assert tree.lower[k] == lower and tree.upper[k] == upper, jname
        assert tree.velocity_limit[k] == (vel if vel > 0 else np.inf), jname
        assert tree.effort_limit[k] == (eff if eff > 0 else np.inf), jname
        assert tree.friction[k] == (float(dyn.get("friction", 0.0)) if dyn is not None else 0.0), jname
        assert tree.damping[k] == (float(dyn.get("damping", 0.0)) if dyn is not None else 0.0), jname
        assert tree.joint_index(jname) == k


@pytest.mark.parametrize("name", CASES)
def test_fk_jacobian_twist_of_every_segment_and_link(name):
    tree, model, _ = _load(name)
    data = model.createData()
    rng = np.random.default_rng([11, len(name)])
    cols = pin_v_index(model, tree.joint_names)
    frames = list(tree.segment_names) + [n for n in tree.link_names if n not in tree.segment_names]
    for _ in range(3):
        q, qd = _random_q(tree, rng)
        pq = pin_q(model, tree.joint_names, q)
        v = np.zeros(model.nv)
        v[cols] = qd
        pin.forwardKinematics(model, data, pq, v)
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, pq)
        for frame in frames:
            fid = model.getFrameId(frame, pin.BODY)
            assert fid < len(model.frames), frame
            assert_rel(tree.fk(q, frame), data.oMf[fid].homogeneous, f"fk {frame}")
            J = pin.getFrameJacobian(model, data, fid, LWA)[:, cols]
            assert_rel(tree.jacobian(q, frame), J, f"jacobian {frame}")
            V = pin.getFrameVelocity(model, data, fid, LWA).vector
            assert_rel(tree.twist(q, qd, frame), V, f"twist {frame}")
        for i in (0, -1):  # indices address segments
            assert np.array_equal(tree.fk(q, i), tree.fk(q, tree.segment_names[i]))


def test_talos_root_and_sub_tree():
    path = example_robot_urdf("talos_reduced")
    tree = vs.Tree.from_urdf(Path(path))  # os.PathLike as well as str
    assert tree.root_link == tree.base_name == "base_link" and tree.n_joints == 32
    arm = vs.Tree.from_urdf(path, root="arm_left_1_link")
    assert arm.root_link == "arm_left_1_link" and arm.n_joints == 7
    assert arm.joint_names == [f"arm_left_{k}_joint" for k in range(2, 8)] + ["gripper_left_joint"]


def test_baxter_mimic_fingers_are_independent_joints_with_notes():
    tree = vs.Tree.from_urdf(example_robot_urdf("baxter"))
    assert tree.n_joints == 19
    mimic = [n for n in tree.notes if "mimics joint" in n]
    assert len(mimic) == 2
    # The only other note: Baxter's heavy base is welded to the world (issue 23).
    (base,) = [n for n in tree.notes if n not in mimic]
    assert base.startswith("root link 'base' carries") and "floating base" in base
    assert base in tree.chain("left_wrist").notes  # a path keeps the tree's base


def test_chain_of_a_path():
    tree = vs.Tree.from_urdf(example_robot_urdf("baxter"))
    chain = tree.chain("left_gripper")
    assert chain.joint_names == ["left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"]
    assert chain.root_link == tree.root_link and "left out" in chain.notes[-1]
    rng = np.random.default_rng(5)
    q, qd = _random_q(tree, rng)
    idx = [tree.joint_index(n) for n in chain.joint_names]
    for frame in ("left_gripper", "left_wrist", "left_upper_shoulder", "torso"):
        assert np.array_equal(chain.fk(q[idx], frame), tree.fk(q, frame)), frame
        assert_rel(chain.jacobian(q[idx], frame), tree.jacobian(q, frame)[:, idx], frame, 1e-14)
    seg = tree.segment_index("left_gripper")
    assert_rel(chain.segment_masses, tree.segment_masses[[tree.segment_index(n) for n in chain.segment_names]], "m", 0)
    assert chain.segment_names[-1] == tree.segment_names[seg]


def test_pickle_and_copies_are_exact():
    tree = vs.Tree.from_urdf(random_tree_urdf(3).urdf)
    q, qd = _random_q(tree, np.random.default_rng(0))
    for other in (pickle.loads(pickle.dumps(tree)), copy.deepcopy(tree), copy.copy(tree)):
        assert other.joint_names == tree.joint_names and np.array_equal(other.parent, tree.parent)
        assert other.link_names == tree.link_names and other.notes == tree.notes
        for s in range(tree.n_segments):
            assert np.array_equal(other.fk(q, s), tree.fk(q, s))
            assert np.array_equal(other.twist(q, qd, s), tree.twist(q, qd, s))
        assert other.__getstate__() == tree.__getstate__()
    assert repr(tree).startswith("<vereshchagin.Tree with ")


# ------------------------------------------------------------------------------------------------
# Errors
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["floating", "planar"])
def test_floating_or_planar_joint_names_a_sub_tree_root(kind):
    drawn = random_tree_urdf(2)
    # A moving joint with moving joints below it, made floating / planar.
    victim = next(j for j in drawn.moving[1:] if any(b.type != "fixed" for b in drawn.below(j.child)))
    text = drawn.urdf.replace(
        f"<joint name='{victim.name}' type='{victim.type}'", f"<joint name='{victim.name}' type='{kind}'"
    )
    with pytest.raises(vs.SolverError, match=rf"joint '{victim.name}'.*{kind}.*root='{victim.child}'"):
        vs.Tree.from_urdf(text)
    below = vs.Tree.from_urdf(text, root=victim.child)
    assert below.root_link == victim.child
    assert sorted(below.joint_names) == sorted(b.name for b in drawn.below(victim.child) if b.type != "fixed")


def test_unknown_root_and_bad_sources():
    text = random_tree_urdf(1).urdf
    with pytest.raises(vs.SolverError, match="root link 'nowhere' not found"):
        vs.Tree.from_urdf(text, root="nowhere")
    with pytest.raises(vs.SolverError, match="neither XML text nor a readable file"):
        vs.Tree.from_urdf("/nonexistent/robot.urdf")
    with pytest.raises(vs.SolverError, match="malformed URDF"):
        vs.Tree.from_urdf("<robot name='x'><link name='a'>")
    with pytest.raises(vs.SolverError, match="source must be"):
        vs.Tree.from_urdf(3)  # type: ignore[arg-type]
    with pytest.raises(vs.SolverError, match="inertia_check"):
        vs.Tree.from_urdf(text, inertia_check="nope")


def _message(call) -> str:
    with pytest.raises(vs.SolverError) as err:
        call()
    return str(err.value)


def test_unknown_names_give_the_chain_messages():
    text = random_tree_urdf(4).urdf
    tree = vs.Tree.from_urdf(text)
    q, qd = _random_q(tree, np.random.default_rng(1))
    for call in (
        lambda: tree.fk(q, "nope"),
        lambda: tree.jacobian(q, "nope"),
        lambda: tree.twist(q, qd, "nope"),
        lambda: tree.chain("nope"),
        lambda: tree.segment_index("nope"),
    ):
        assert "no segment or link named 'nope' (segments: '" in _message(call)
    assert "joint_index: no joint named 'nope' (joints: '" in _message(lambda: tree.joint_index("nope"))
    n = tree.n_segments
    assert f"segment index {n} out of range for {n} segments" in _message(lambda: tree.fk(q, n))
    assert "is (part of) the fixed base" in _message(lambda: tree.segment_index("base"))
    assert "a segment is named by a str" in _message(lambda: tree.fk(q, 1.5))
    # The same words as a Chain's (one addressing rule).
    chain = tree.chain(-1)
    chain_msg = _message(lambda: chain.segment_index("nope"))
    assert chain_msg.split(" (segments:")[0] == _message(lambda: tree.segment_index("nope")).split(" (segments:")[0]
    assert np.array_equal(tree.fk(q, "base"), np.eye(4)) and not tree.jacobian(q, "base").any()


def test_bad_q_shapes():
    tree = vs.Tree.from_urdf(random_tree_urdf(5).urdf)
    n = tree.n_joints
    for bad in (np.zeros(n - 1), np.zeros((n, 1)), np.full(n, np.nan), "abc"):
        with pytest.raises(vs.SolverError, match="q"):
            tree.fk(bad, 0)
        with pytest.raises(vs.SolverError, match="q"):
            tree.jacobian(bad, 0)
    with pytest.raises(vs.SolverError, match="qd"):
        tree.twist(np.zeros(n), np.zeros(n + 1), 0)
