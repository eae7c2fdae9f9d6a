"""The dual-arm case of issue 17 (vereshchagin_experiments.contact.dual_arm): robot, plant, runs and report.

Oracles: Pinocchio (``pin.aba``, ``pin.crba``, ``pin.rnea`` and frame accelerations) for the
dual-arm tree, the open-loop task error and the torso split; MuJoCo (an independent physics
engine compiled from the same URDF) for the closed-loop runs and their table force.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

import vereshchagin as vs
from vereshchagin_experiments.contact import dual_arm as da
from vereshchagin_experiments.contact import dual_arm_report, metrics
from vereshchagin_experiments.contact.controller import ControllerConfig
from vereshchagin_experiments.contact.mujoco_plant import MujocoGen3, Scene, build_model

from support.trees import pin_model, pin_q, pin_v_index

G = np.array([0.0, 0.0, -9.81])


@pytest.fixture(scope="module")
def model():
    urdf, tree = da.dual_arm_model()
    pm = pin_model(urdf)
    return urdf, tree, pm


@pytest.fixture(scope="module")
def runs():
    return {v: da.dual_arm(v, quick=True) for v in da.VARIANTS}


@pytest.fixture(scope="module")
def report(runs, tmp_path_factory):
    out = tmp_path_factory.mktemp("results")
    return dual_arm_report.run(out, quick=True, runs=runs), out / "dual_arm"


def _random_state(tree, rng):
    q = da.start_pose() + rng.uniform(-0.4, 0.4, tree.n_joints)
    return q, rng.uniform(-0.8, 0.8, tree.n_joints)


def test_robot_is_15_joints_in_the_documented_order(model):
    _, tree, pm = model
    assert tuple(tree.joint_names) == vs.robots.DUAL_GEN3_JOINT_NAMES
    assert list(pm.names)[1:] == list(tree.joint_names)
    assert tree.parent[1] == 0 and tree.parent[8] == 0  # both shoulders hang on the torso
    with pytest.raises(ValueError):
        vs.robots.dual_gen3_urdf(torso_share=0.0)


def test_tree_forward_dynamics_equals_pinocchio_aba(model):
    _, tree, pm = model
    data = pm.createData()
    solver = vs.Solver(tree, gravity=G)
    iv = pin_v_index(pm, tree.joint_names)
    rng = np.random.default_rng(17)
    for _ in range(5):
        q, qd = _random_state(tree, rng)
        tau = rng.uniform(-10.0, 10.0, tree.n_joints)
        v, t = np.zeros(pm.nv), np.zeros(pm.nv)
        v[iv], t[iv] = qd, tau
        ref = pin.aba(pm, data, pin_q(pm, tree.joint_names, q), v, t)[iv]
        ours = solver.solve(q, qd, tau_ff=tau).qdd
        assert np.abs(ours - ref).max() <= 1e-9 * max(1.0, np.abs(ref).max())


def test_plant_mass_matrix_and_bias_equal_pinocchio(model):
    urdf, tree, pm = model
    plant = MujocoGen3(build_model(urdf, tree, Scene()), da.start_pose())
    m, d = plant.model, plant.data
    assert [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)] == list(tree.joint_names)
    assert np.allclose(m.dof_frictionloss, tree.friction) and np.allclose(m.dof_damping, tree.damping)
    assert np.allclose(m.actuator_ctrlrange[:, 1], tree.effort_limit)
    data = pm.createData()
    iv = pin_v_index(pm, tree.joint_names)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd = _random_state(tree, rng)
        d.qpos[:], d.qvel[:] = q, qd
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        qp = pin_q(pm, tree.joint_names, q)
        v = np.zeros(pm.nv)
        v[iv] = qd
        M_ref = pin.crba(pm, data, qp)
        M_ref = np.triu(M_ref) + np.triu(M_ref, 1).T
        bias_ref = pin.rnea(pm, data, qp, v, np.zeros(pm.nv))
        assert np.abs(M - M_ref[np.ix_(iv, iv)]).max() < 1e-9 * np.abs(M_ref).max()
        assert np.abs(d.qfrc_bias - bias_ref[iv]).max() < 1e-9 * np.abs(bias_ref).max()


def test_half_torso_chains_count_the_torso_once(model):
    _, tree, _ = model
    _, half = da.dual_arm_model(0.5)
    torso = tree.segment_masses[0]
    chains = [half.chain(f) for f in (da.REST_FRAME, da.TASK_FRAME)]
    assert sum(c.segment_masses[0] for c in chains) == pytest.approx(torso, rel=1e-12)
    assert sum(c.friction[0] for c in chains) == pytest.approx(tree.friction[0], rel=1e-12)
    assert sum(c.damping[0] for c in chains) == pytest.approx(tree.damping[0], rel=1e-12)
    assert [c.segment_masses[1:] for c in chains][0] == pytest.approx(tree.segment_masses[1:8], rel=1e-12)


def _pin_task_error(pm, tree, q, qd, torque, constraints):
    """alpha^T Xdd - beta of each frame after pin.aba with ``torque`` (Pinocchio only)."""
    data = pm.createData()
    iv = pin_v_index(pm, tree.joint_names)
    qp = pin_q(pm, tree.joint_names, q)
    v, t = np.zeros(pm.nv), np.zeros(pm.nv)
    v[iv], t[iv] = qd, torque
    a = pin.aba(pm, data, qp, v, t)
    pin.forwardKinematics(pm, data, qp, v, a)
    pin.updateFramePlacements(pm, data)
    out = {}
    for frame, (alpha, beta) in constraints.items():
        fid = pm.getFrameId(frame)
        acc = pin.getFrameClassicalAcceleration(pm, data, fid, pin.LOCAL_WORLD_ALIGNED)
        vel = pin.getFrameVelocity(pm, data, fid, pin.LOCAL_WORLD_ALIGNED)
        xdd = np.concatenate([acc.linear - np.cross(vel.angular, vel.linear) - G, acc.angular])
        out[frame] = alpha.T @ xdd - beta
    return out


@pytest.mark.parametrize("variant", ["table", "separate"])
def test_open_loop_task_error_equals_pinocchio(model, variant):
    _, tree, pm = model
    truth = vs.Solver(tree, gravity=G)
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(3):
        q, qd = _random_state(tree, rng)
        ctl = da.DualArmController(tree, variant)
        goal = ctl.pose(q)
        goal[:3, 3] += [0.05, 0.0, 0.0]  # the sliding hand accelerates towards a goal 5 cm ahead
        ctl.set_goal(goal)
        _, info = ctl.command(q, qd)
        x = info.inputs
        ours = da.open_loop_error(tree, truth, q, qd, x["model_torque"], x["constraints"])
        ref = _pin_task_error(pm, tree, q, qd, x["model_torque"], x["constraints"])
        for frame in ours:
            scale = max(1.0, np.abs(x["constraints"][frame][1]).max())
            assert np.abs(ours[frame] - ref[frame]).max() < 1e-9 * scale
            worst = max(worst, np.abs(ref[frame]).max())
    if variant == "table":
        assert worst < 1e-9  # the tree solver's command meets both hands' tasks exactly
    else:
        assert worst > 1e-2  # the separate chains miss them: the coupling through the torso


def test_table_carries_the_hand_and_saves_copper_loss(runs):
    e = {v: metrics.effort(r, r.window("slide")) for v, r in runs.items()}
    o = {v: metrics.dual_arm_outcome(r) for v, r in runs.items()}
    assert e["table"]["energy_tau2"].sum() < 0.9 * e["unsupported"]["energy_tau2"].sum()
    assert e["table"]["mean_abs_tau"][2] < 0.6 * e["unsupported"]["mean_abs_tau"][2]  # left shoulder
    for v in ("table", "separate"):
        assert o[v]["table_fraction"] > 0.99
        assert o[v]["table_force"] > 20.0
        # the plant's soft contact against the model's upward share -nu_z: within 15 %
        assert abs(o[v]["table_force"] - o[v]["table_force_model"]) < 0.15 * o[v]["table_force_model"]
    assert not runs["unsupported"].table_force.any()
    for v in da.VARIANTS:
        assert abs(o[v]["final_error_x"]) < 2e-3 and o[v]["max_off_line"] < 2e-3 and o[v]["rest_drift"] < 2e-3


def test_shortcut_task_error_well_above_the_tree_solver(runs):
    o = {v: metrics.dual_arm_outcome(r) for v, r in runs.items()}
    for v in ("table", "unsupported"):
        assert max(o[v]["open_loop_max"].values()) < 1e-9
        assert max(o[v]["open_loop_ang_max"].values()) < 1e-9
    assert max(o["separate"]["open_loop_max"].values()) > 1e-2
    assert max(o["separate"]["open_loop_ang_max"].values()) > 1e-1


def test_report_section_table_csv_and_figure(report, tmp_path, monkeypatch):
    res, folder = report
    assert res["ok"], res["checks"]
    text = "\n".join(res["index"])
    assert "Dual-arm" in text and "Checks:" in text and "FAILED" not in text
    for name in ("dual_arm_effort.csv", "dual_arm_errors.csv", "dual_arm_friction.csv", "dual_arm.png"):
        path = folder / name
        assert path.is_file() and path.stat().st_size > 0
        assert f"dual_arm/{name}" in text
    # the CLI wires the case into results/index.md (the runs reused)
    from vereshchagin_experiments.__main__ import main

    monkeypatch.setattr(dual_arm_report, "run", lambda out, quick, progress: res)
    assert main(["reproduce", "--out", str(tmp_path), "--quick", "--case", "dual-arm"]) == 0
    assert "Dual-arm Gen3 on a torso" in (tmp_path / "index.md").read_text(encoding="utf-8")


def test_step_mode_keeps_the_command_from_chattering(report, runs):
    """Chosen setting (max-min over the step): chatter below the bound; at the instant above it, band or not."""
    opts = report[0]["options"]
    chosen, band, plain, smooth, none = (opts[k] for k in dual_arm_report.OPTIONS)
    assert band["chatter"] < 0.7 * plain["chatter"]  # the hold band (before) helps at the instant ...
    assert chosen["chatter"] < 0.1 * band["chatter"] and dual_arm_report.CHATTER_BOUND < band["chatter"]  # ... far less
    assert chosen["chatter_joints"].max() < 5 * dual_arm_report.CHATTER_BOUND
    ch = dual_arm_report.chatter(runs["table"], runs["table"].window("slide"))
    assert ch.mean() == pytest.approx(chosen["chatter"], rel=1e-12)  # the module-scoped run is the chosen one
    assert chosen["chatter"] < dual_arm_report.CHATTER_BOUND < plain["chatter"]
    assert chosen["chatter"] < 0.7 * plain["chatter"]
    assert chosen["tau2"] < plain["tau2"]  # the band also saves copper loss: friction holds the resting arm
    assert smooth["chatter"] < 0.1 * plain["chatter"]  # the tanh compensation is about chatter-free ...
    assert smooth["outcome"]["max_off_line"] > 2.0 * chosen["outcome"]["max_off_line"]  # ... and tracks worse
    assert none["outcome"]["final_error_x"] < -0.02  # no compensation: the slide stalls
    # the plant's table force follows the model more closely with the chosen setting than at the instant
    # without the band (the band itself is closer still: inside it the task asks for zero acceleration)
    gap = {k: abs(o["outcome"]["table_force"] - o["outcome"]["table_force_model"]) for k, o in opts.items()}
    assert gap[next(iter(opts))] < gap[list(opts)[2]]


def test_bad_variant_and_contact_mode_raise(model):
    _, tree, _ = model
    with pytest.raises(ValueError):
        da.dual_arm("floating")
    with pytest.raises(ValueError):
        da.DualArmController(tree, "floating")
    with pytest.raises(ValueError):
        da.DualArmController(tree, "table").set_contact(True)
    with pytest.raises(ValueError):
        da.DualArmController(tree, "table", ControllerConfig(friction_mode="sign"))
