"""The standing-quadruped case of issue 28 (vereshchagin_experiments.floating.quadruped).

What is checked: the plant (MuJoCo, Solo 12 on a free joint) and the controller's model
(``Tree.from_urdf(..., base="free")``) agree on the forward dynamics through the state maps of
:mod:`~vereshchagin_experiments.floating.solo_plant` (MuJoCo's (w, x, y, z) quaternion and world-axes
linear velocity against the library's (x, y, z, w) and LOCAL); a short run of the weight shift: the
base tracks, the model's forces stay in their cones, the plant's foot forces agree with the model's,
the load moves off the hind-right foot; the report is written.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin_experiments.floating import quadruped as qd
from vereshchagin_experiments.floating import quadruped_report
from vereshchagin_experiments.floating import solo_plant as sp

STEPS = 2600  # settle and the shift up to its end (0.5 s + 2 s) and a little of the hold


def test_plant_and_model_agree_on_the_dynamics():
    tree = vs.Tree.from_urdf(sp.solo12_urdf(), base="free")
    plant = sp.build(tree)
    data = mujoco.MjData(plant)
    rng = np.random.default_rng(5)
    quat = rng.normal(size=4)
    data.qpos[:] = np.r_[0.1, 0.2, 2.0, quat / np.linalg.norm(quat), rng.uniform(-1.0, 1.0, 12)]
    data.qvel[:] = rng.uniform(-1.0, 1.0, 18)
    data.ctrl[:] = rng.uniform(-1.0, 1.0, 12)
    mujoco.mj_forward(plant, data)
    assert data.ncon == 0  # 2 m above the floor
    q, v = sp.to_model(data)
    r = vs.Solver(tree, gravity=(0.0, 0.0, -9.81)).solve(q, v, tau_ff=np.r_[np.zeros(6), data.ctrl])
    expected = sp.model_acceleration(data)
    assert np.max(np.abs(r.qdd - expected)) < 1e-9 * max(1.0, np.max(np.abs(expected)))


@pytest.fixture(scope="module")
def run():
    return qd.run(STEPS)


def test_the_shift_is_tracked_with_forces_in_the_cones(run):
    m = qd.metrics(run)
    assert m["rms_position_error"] < 2e-3 and m["max_orientation_error"] < 1e-2
    assert m["max_ratio"] <= qd.MU_MODEL * (1.0 + 1e-9)
    assert np.all(run.model_force[:, :, 2] > 0.0)
    end = run.model_force[-1, :, 2]
    assert end[3] < 0.6 * run.model_force[0, 3, 2] and end[0] > 1.4 * run.model_force[0, 0, 2]
    # The weight is carried: the model's normal forces sum to m g (the base is nearly still).
    mass = 2.5
    assert abs(run.model_force[-1, :, 2].sum() - 9.81 * mass) < 0.05 * 9.81 * mass
    assert np.all(np.abs(run.plant_normal[-1] - end) <= 0.05 * end)
    assert run.info["saturated"] == 0.0


def test_report_is_written(tmp_path, monkeypatch):
    monkeypatch.setattr(quadruped_report, "run_stand", lambda: qd.run(STEPS))
    res = quadruped_report.run(tmp_path)
    assert "quadruped" in "\n".join(res["index"])
    for name in ("quadruped.csv", "quadruped.png", "quadruped.md"):
        assert (tmp_path / "quadruped" / name).stat().st_size > 0
