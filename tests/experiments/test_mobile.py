"""The mobile-manipulation case of issue 28 (vereshchagin_experiments.floating.mobile).

What is checked: the plant (MuJoCo, planar joints under the base) and the controller's model
(``Tree.from_urdf(..., base="planar")``) agree on the forward dynamics (a random state and random
motor commands, the base's force rotated into world axes); short runs: the tool follows its path
in both variants, the base moves and the arm's effort is lower when the base helps, the plant's
table force averages the press set-point; the report is
written.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin_experiments.floating import mobile as mb
from vereshchagin_experiments.floating import mobile_report

STEPS = 2600  # the reach (2 s) and 0.6 s of pressing and sliding on the table


def test_plant_and_model_agree_on_the_dynamics():
    model = vs.Tree.from_urdf(mb.mobile_urdf(), base="planar")
    plant = mb._plant(True, model)
    data = mujoco.MjData(plant)
    rng = np.random.default_rng(3)
    x, y, yaw, qa = 0.3, -0.2, 0.7, rng.uniform(-1.0, 1.0, 7)
    vel = np.r_[0.2, -0.1, 0.3, rng.uniform(-1.0, 1.0, 7)]
    force = np.r_[5.0, -3.0, 2.0, rng.uniform(-3.0, 3.0, 7)]  # world x, y force, moment, joints
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = np.r_[x, y, yaw, qa], vel, force
    mujoco.mj_forward(plant, data)
    R = mb._rz(yaw)[:2, :2]
    v_local = R.T @ vel[:2]
    tau = np.r_[R.T @ force[:2], force[2:]]
    r = vs.Solver(model, gravity=mb.GRAVITY).solve(
        np.r_[x, y, np.cos(yaw), np.sin(yaw), qa], np.r_[v_local, vel[2:]], tau_ff=tau
    )
    # MuJoCo's world-frame base acceleration as the derivative of the base-axes velocity.
    a_local = R.T @ data.qacc[:2] - vel[2] * np.array([-v_local[1], v_local[0]])
    expected = np.r_[a_local, data.qacc[2:]]
    # The plant's two massless links carry 1e-6 kg each: agreement to that order.
    assert np.max(np.abs(r.qdd - expected)) < 1e-5 * max(1.0, np.max(np.abs(expected)))


@pytest.fixture(scope="module")
def runs():
    return {v: mb.run_variant(v, "near", STEPS) for v in mb.VARIANTS}


def test_both_track_and_the_base_takes_arm_effort(runs):
    arm, base = mb.metrics(runs["arm"]), mb.metrics(runs["base"])
    assert arm["rms_error"] < 1e-3 and base["rms_error"] < 1e-3
    assert base["tau2"] < 0.95 * arm["tau2"]
    assert base["base_travel"] > 0.05 and arm["base_travel"] == 0.0
    assert np.all(runs["arm"].base_force == 0.0)
    for r in runs.values():  # the set-point contact: the plant's table force averages it
        m = mb.metrics(r)
        assert abs(m["plant_normal"] - mb.PRESS) < 0.05 * mb.PRESS and m["normal_deviation"] < 0.2 * mb.PRESS
        assert np.all(r.model_normal[r.t < mb.TIMES[0]] == 0.0)


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="variant"):
        mb.run_variant("wheels")
    with pytest.raises(ValueError, match="path"):
        mb.run_variant("base", "moon")


def test_report_is_written(tmp_path, monkeypatch):
    monkeypatch.setattr(mobile_report, "run_variant", lambda v, p: mb.run_variant(v, p, STEPS))
    res = mobile_report.run(tmp_path)
    text = "\n".join(res["index"])
    assert "holonomic base" in text
    for name in ("mobile.csv", "mobile.png", "mobile.md"):
        assert (tmp_path / "mobile" / name).stat().st_size > 0
