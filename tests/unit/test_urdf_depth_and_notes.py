"""URDF loading at any depth, clear errors for bad paths, and the note on a root link with mass.

Deep documents: a serial revolute chain of 20,000 links (as a Tree and as a Chain) and a
20,000-link fixed side branch used to overflow the stack in the loaders' recursive walks. They are
loaded in a child process, so a crash fails the test instead of killing pytest. The values of a
200-link chain come from Pinocchio (``pin.aba`` and ``pin.rnea`` on the same URDF file); the total
mass of a lumped side branch from summing the URDF's own ``<mass>`` values (ElementTree).

Root link mass: example-robot-data's Solo 12 (a quadruped whose ``base_link`` floats in reality)
and a small generated URDF; the expected masses are read from the URDF text with ElementTree.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import textwrap
from xml.etree import ElementTree

import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

G = np.array([0.0, 0.0, -9.81])
RTOL = 1e-9


def _inertial(mass, com=(0.0, 0.0, 0.0), diag=(0.01, 0.02, 0.015)):
    return (
        f'<inertial><origin xyz="{com[0]} {com[1]} {com[2]}"/><mass value="{mass}"/>'
        f'<inertia ixx="{diag[0]}" ixy="0" ixz="0" iyy="{diag[1]}" iyz="0" izz="{diag[2]}"/></inertial>'
    )


def _link(name, mass=None, com=(0.0, 0.0, 0.0), diag=(0.01, 0.02, 0.015)):
    return f'<link name="{name}">{_inertial(mass, com, diag) if mass is not None else ""}</link>'


def _joint(name, kind, parent, child, xyz=(0.0, 0.0, 0.1), rpy=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0)):
    moving = kind != "fixed"
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
        + (f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>' if moving else "")
        + ('<limit lower="-3" upper="3" effort="100" velocity="2"/>' if moving else "")
        + "</joint>"
    )


def serial_urdf(n, seed=0):
    """A serial chain base - l1 - ... - ln of n revolute joints; varied axes, origins and inertias."""
    rng = np.random.default_rng(seed)
    parts = ['<robot name="serial">', _link("base")]
    axes = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.6, 0.0, 0.8))
    for k in range(1, n + 1):
        xyz = tuple(np.round(rng.uniform(-0.05, 0.05, 3) + (0.0, 0.0, 0.05), 6))
        rpy = tuple(np.round(rng.uniform(-0.4, 0.4, 3), 6))
        com = tuple(np.round(rng.uniform(-0.02, 0.02, 3), 6))
        parts.append(_link(f"l{k}", mass=round(0.1 + 0.01 * (k % 7), 6), com=com))
        parts.append(_joint(f"j{k}", "revolute", "base" if k == 1 else f"l{k - 1}", f"l{k}", xyz, rpy, axes[k % 4]))
    parts.append("</robot>")
    return "".join(parts)


def side_branch_urdf(n):
    """base -j1- a -j2- b (the tip), and n links hanging off ``a`` through fixed joints (0.01 kg each)."""
    parts = ['<robot name="branch">', _link("base"), _link("a", 1.0), _link("b", 0.5)]
    parts.append(_joint("j1", "revolute", "base", "a", axis=(0.0, 1.0, 0.0)))
    parts.append(_joint("j2", "revolute", "a", "b", axis=(1.0, 0.0, 0.0)))
    for k in range(1, n + 1):
        parts.append(_link(f"s{k}", 0.01, diag=(1e-5, 1e-5, 1e-5)))
        parts.append(_joint(f"f{k}", "fixed", "a" if k == 1 else f"s{k - 1}", f"s{k}", xyz=(0.0, 0.001, 0.0)))
    parts.append("</robot>")
    return "".join(parts)


def urdf_mass(text):
    """Sum of every link's <mass> in the URDF text (ElementTree, not our loader)."""
    root = ElementTree.fromstring(text)
    return sum(float(m.get("value")) for m in root.iter("mass"))


def run_child(code, timeout=600):
    """Runs ``code`` in a fresh interpreter; its last stdout line is JSON. A crash fails the test."""
    proc = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout
    )
    assert proc.returncode == 0, f"child process died (return code {proc.returncode}): {proc.stderr[-2000:]}"
    return json.loads(proc.stdout.strip().splitlines()[-1])


LOAD_CHILD = """
import json, pickle, sys, time
import vereshchagin as vs
path, kind, tip = sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else ""
t0 = time.perf_counter()
model = vs.Tree.from_urdf(path) if kind == "tree" else vs.Chain.from_urdf(path, tip=tip)
seconds = time.perf_counter() - t0
copy = pickle.loads(pickle.dumps(model.__copy__()))
print(json.dumps({"seconds": seconds, "n_joints": model.n_joints, "n_segments": model.n_segments,
                  "masses": [float(m) for m in model.segment_masses[:2]], "copy_joints": copy.n_joints}))
"""


def load_in_child(tmp_path, text, kind, tip=""):
    path = tmp_path / f"{kind}.urdf"
    path.write_text(text)
    code = f"import sys; sys.argv = ['child', {str(path)!r}, {kind!r}, {tip!r}]\n" + LOAD_CHILD
    return run_child(code)


@pytest.mark.parametrize("kind", ["tree", "chain"])
def test_serial_chain_of_20000_links_loads(tmp_path, kind):
    n = 20000
    out = load_in_child(tmp_path, serial_urdf(n), kind)
    assert out["n_joints"] == n and out["n_segments"] == n and out["copy_joints"] == n
    assert out["seconds"] < 60.0, f"{n} links took {out['seconds']:.1f} s"


@pytest.mark.parametrize("kind", ["tree", "chain"])
def test_fixed_side_branch_of_20000_links_is_lumped(tmp_path, kind):
    n = 20000
    text = side_branch_urdf(n)
    out = load_in_child(tmp_path, text, kind, tip="b")
    assert out["n_joints"] == 2
    # segment 0 holds a and the whole branch; segment 1 holds b.
    expected = [1.0 + 0.01 * n, 0.5]
    assert np.allclose(out["masses"], expected, rtol=1e-12), out["masses"]
    assert abs(sum(expected) - urdf_mass(text)) < 1e-9


def padded_chain_urdf(n, extra_root=False):
    """base link l00000000 and n continuous joints; zero-padded names make urdfdom's link map
    release the links from the leaf up, the order that used to release the model recursively."""
    parts = ["<robot name='padded'>", "<link name='extra'/>" if extra_root else "", "<link name='l00000000'/>"]
    for k in range(1, n + 1):
        parts.append(_link(f"l{k:08d}", 1.0))
        parts.append(_joint(f"j{k:08d}", "continuous", f"l{k - 1:08d}", f"l{k:08d}"))
    parts.append("</robot>")
    return "".join(parts)


def test_deep_chain_loads_on_a_256_kb_thread_stack(tmp_path):
    """Nothing in the loaders (nor in copying the result) recurses per link."""
    path = tmp_path / "padded.urdf"
    path.write_text(padded_chain_urdf(20000))
    code = f"""
    import json, threading
    import vereshchagin as vs
    out = []
    def run():
        tree = vs.Tree.from_urdf({str(path)!r})
        chain = vs.Chain.from_urdf({str(path)!r})
        out.append([tree.n_joints, chain.n_joints, tree.__copy__().n_joints])
    threading.stack_size(256 * 1024)
    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    print(json.dumps(out))
    """
    assert run_child(code) == [[20000, 20000, 20000]]


def test_the_longest_chain_below_the_link_limit(tmp_path):
    """50,000 links load; the same chain with a second root link is urdfdom's error, not a crash."""
    good, bad = tmp_path / "good.urdf", tmp_path / "bad.urdf"
    good.write_text(padded_chain_urdf(49999))
    bad.write_text(padded_chain_urdf(49998, extra_root=True))
    code = f"""
    import json
    import vereshchagin as vs
    tree = vs.Tree.from_urdf({str(good)!r})
    try:
        vs.Tree.from_urdf({str(bad)!r})
        message = "loaded"
    except vs.SolverError as e:
        message = str(e)
    print(json.dumps([tree.n_joints, message]))
    """
    n_joints, message = run_child(code)
    assert n_joints == 49999 and "Two root links" in message


def test_loading_time_grows_linearly(tmp_path):
    """20,000 links cost about 4x 5,000 links (an O(n^2) walk would cost 16x)."""
    seconds = {}
    for n in (5000, 20000):
        best = min(load_in_child(tmp_path, serial_urdf(n), "tree")["seconds"] for _ in range(2))
        seconds[n] = best
    assert seconds[20000] < 9.0 * seconds[5000] + 0.5, seconds


def test_more_links_than_the_limit_is_a_clear_error(tmp_path):
    text = "<robot name='r'>" + "".join(f"<link name='l{k}'/>" for k in range(50001)) + "</robot>"
    for load in (vs.Tree.from_urdf, vs.Chain.from_urdf):
        with pytest.raises(vs.SolverError, match="more than 50000 links"):
            load(text)


def test_deeply_nested_xml_is_a_clear_error_not_a_crash(tmp_path):
    """urdfdom's XML reader recurses per nesting level: 100,000 levels used to crash the process."""
    path = tmp_path / "nested.urdf"
    path.write_text(
        "<robot name='r'><link name='a'/><link name='b'/>"
        + _joint("j", "revolute", "a", "b")
        + "<x>" * 100000
        + "</x>" * 100000
        + "</robot>"
    )
    code = f"""
    import json
    import vereshchagin as vs
    try:
        vs.Tree.from_urdf({str(path)!r})
        print(json.dumps("loaded"))
    except vs.SolverError as e:
        print(json.dumps(str(e)))
    """
    message = run_child(code, timeout=120)
    assert "nested more than 1000 levels" in message


def test_nesting_up_to_the_limit_still_loads():
    text = (
        "<robot name='r'>"
        + _link("a")
        + _link("b", 1.0)
        + _joint("j", "revolute", "a", "b")
        + "<x>" * 999
        + "</x>" * 999
        + "<!-- <y><y><y> --><![CDATA[ <z> ]]>"
        + "</robot>"
    )
    assert vs.Tree.from_urdf(text).n_joints == 1
    with pytest.raises(vs.SolverError, match="nested more than 1000"):
        vs.Tree.from_urdf(text.replace("<x>", "<x><x>", 1).replace("</x>", "</x></x>", 1))


def _pin_model(path):
    model = pin.buildModelFromUrdf(str(path))
    model.gravity.linear = G
    return model


def test_200_link_chain_matches_pinocchio(tmp_path):
    n = 200
    path = tmp_path / "serial200.urdf"
    path.write_text(serial_urdf(n, seed=3))
    model = _pin_model(path)
    data = model.createData()
    rng = np.random.default_rng(7)
    q, qd, tau = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    qdd_pin = pin.aba(model, data, q, qd, tau)
    tau_pin = pin.rnea(model, data, q, qd, qdd_pin)
    for ours in (vs.Tree.from_urdf(path), vs.Chain.from_urdf(path)):
        assert ours.joint_names == [f"j{k}" for k in range(1, n + 1)]
        qdd = vs.Solver(ours, gravity=G).solve(q, qd, tau_ff=tau).qdd
        assert np.linalg.norm(qdd - qdd_pin) <= RTOL * np.linalg.norm(qdd_pin)
        tau_ours = ours.inverse_dynamics(q, qd, qdd_pin, gravity=G)
        assert np.linalg.norm(tau_ours - tau_pin) <= RTOL * np.linalg.norm(tau_pin)


def test_200_link_fixed_side_branch_matches_pinocchio(tmp_path):
    """Pinocchio merges the fixed links into a's body on its own; our walk lumps them the same."""
    path = tmp_path / "branch200.urdf"
    path.write_text(side_branch_urdf(200))
    model = _pin_model(path)
    data = model.createData()
    q, qd, tau = np.array([0.4, -0.7]), np.array([0.3, 0.9]), np.array([0.2, -0.1])
    qdd_pin = pin.aba(model, data, q, qd, tau)
    for ours in (vs.Tree.from_urdf(path), vs.Chain.from_urdf(path, tip="b")):
        qdd = vs.Solver(ours, gravity=G).solve(q, qd, tau_ff=tau).qdd
        assert np.linalg.norm(qdd - qdd_pin) <= RTOL * np.linalg.norm(qdd_pin)
        assert np.allclose(ours.segment_masses, [1.0 + 0.01 * 200, 0.5], rtol=1e-12)


def test_directory_path_says_it_is_a_directory(tmp_path):
    for load in (vs.Tree.from_urdf, vs.Chain.from_urdf):
        with pytest.raises(vs.SolverError, match="is a directory"):
            load(tmp_path)
        with pytest.raises(vs.SolverError, match="is a directory"):
            load(str(tmp_path))


def test_missing_file_is_named(tmp_path):
    missing = tmp_path / "missing.urdf"
    for load in (vs.Tree.from_urdf, vs.Chain.from_urdf):
        with pytest.raises(vs.SolverError, match="missing.urdf"):
            load(missing)


def test_unreadable_file_is_named(tmp_path):
    """A path that exists but cannot be opened for reading (a Unix socket: not even root reads it)."""
    path = tmp_path / "socket.urdf"
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as sock:
        sock.bind(str(path))
        for load in (vs.Tree.from_urdf, vs.Chain.from_urdf):
            with pytest.raises(vs.SolverError, match="socket.urdf"):
                load(path)


def _base_notes(model):
    return [note for note in model.notes if note.startswith("root link")]


def _assert_base_note(note, link, kg):
    assert f"root link '{link}' carries {kg:.6g} kg" in note, note
    assert "welded to the world" in note and 'a floating base (base="free") is not supported yet' in note


def test_solo12_root_link_mass_is_noted():
    path = example_robot_urdf("solo12")
    root = ElementTree.parse(path).getroot()
    base = next(link for link in root.iter("link") if link.get("name") == "base_link")
    kg = float(base.find("inertial/mass").get("value"))
    fixed_to_base = [
        j for j in root.iter("joint") if j.get("type") == "fixed" and j.find("parent").get("link") == "base_link"
    ]
    assert kg > 1.0 and not fixed_to_base  # the note's mass is base_link's own
    tree = vs.Tree.from_urdf(path)
    chain = vs.Chain.from_urdf(path, tip="FL_FOOT")
    for model in (tree, chain):
        notes = _base_notes(model)
        assert len(notes) == 1
        _assert_base_note(notes[0], "base_link", kg)
        assert "(with the links fixed to it)" not in notes[0]
    # Pickles and copies keep the note.
    assert tree.__copy__().notes == tree.notes


def _small_robot(root_mass, fixed_mass):
    return (
        '<robot name="small">'
        + _link("torso", root_mass)
        + _link("imu", fixed_mass)
        + _joint("imu_joint", "fixed", "torso", "imu")
        + _link("leg", 1.0)
        + _joint("hip", "revolute", "torso", "leg")
        + "</robot>"
    )


def test_generated_root_mass_is_noted_with_links_fixed_to_it():
    text = _small_robot(3.25, 0.5)
    for model in (vs.Tree.from_urdf(text), vs.Chain.from_urdf(text, tip="leg")):
        notes = _base_notes(model)
        assert len(notes) == 1
        _assert_base_note(notes[0], "torso", 3.75)
        assert "(with the links fixed to it)" in notes[0]


def test_massless_root_gives_no_note():
    text = _small_robot(None, None)
    for model in (vs.Tree.from_urdf(text), vs.Chain.from_urdf(text, tip="leg")):
        assert _base_notes(model) == [] and model.notes == []
