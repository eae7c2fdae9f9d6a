"""The wiping case of issue 27 (vereshchagin_experiments.contact.wiping): short runs of both variants.

What is checked: before (the instant solve integrated explicitly) a joint's velocity changes sign
in most steps; after (the step controller and ``Solver.step``) only at the stroke's reversals, a
held joint's velocity is exactly zero, the command chatters far less at the same tracking; the
report is written.
"""

from __future__ import annotations

import numpy as np
import pytest

from vereshchagin_experiments.contact import wiping as wp
from vereshchagin_experiments.contact import wiping_report

STEPS = 600  # 0.6 s: one reversal of the stroke (at 0.25 s)


@pytest.fixture(scope="module")
def runs():
    return {v: wp.wiping(v, STEPS) for v in wp.VARIANTS}


def test_before_velocities_flip_every_step_after_only_at_the_reversal(runs):
    before, after = wp.metrics(runs["instant"]), wp.metrics(runs["step"])
    assert before["sign_changes"].max() > 0.25 * wp.STEPS  # per 2000 steps
    flips = (np.sign(runs["step"].qd[1:]) * np.sign(runs["step"].qd[:-1]) < 0).sum(axis=0)
    assert flips.max() <= 1  # the one reversal in 0.6 s
    held = np.asarray(runs["step"].regime) == 0
    assert held.any() and np.all(runs["step"].qd[held] == 0.0)  # a sticking joint: exactly at rest
    assert after["chatter"] < 0.1 * before["chatter"]
    assert after["switches"].sum() < 0.05 * before["switches"].sum()
    assert abs(after["rms_x_error"] / before["rms_x_error"] - 1.0) < 0.1
    assert after["normal_force"] > wp.PRESS  # the table carries the press and part of the arm


def test_bad_variant_raises():
    with pytest.raises(ValueError, match="variant"):
        wp.wiping("implicit")


def test_report_is_written(tmp_path, monkeypatch):
    monkeypatch.setattr(wiping_report, "wiping", lambda v: wp.wiping(v, STEPS))
    res = wiping_report.run(tmp_path)
    assert res["ok"], res["checks"]
    text = "\n".join(res["index"])
    assert "Wiping" in text and "FAILED" not in text
    for name in ("wiping.csv", "wiping.png"):
        assert (tmp_path / "wiping" / name).stat().st_size > 0 and f"wiping/{name}" in text
