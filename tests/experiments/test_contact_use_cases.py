"""The contact use cases of Lau (2023) in MuJoCo (vereshchagin_experiments.contact), quick mode: physical outcomes.

The plant is MuJoCo (independent physics); the checks are on what it reports -- contact forces
on the table, which arm geoms touched it, where the tool went -- not on controller internals.
The mass-matrix test compares MuJoCo's mj_fullM of the plant compiled from our URDF with the
inverse of the solver's unconstrained response columns (H^-1) at random configurations.
"""

from __future__ import annotations

import matplotlib  # noqa: F401  (the reproduce command draws figures; a broken import must fail, not skip)
import mujoco  # noqa: F401  (the plant's engine: a broken import must fail, not skip)
import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin_experiments.contact import metrics
from vereshchagin_experiments.contact.elbow import elbow
from vereshchagin_experiments.contact.mujoco_plant import ELBOW_RADIUS, MujocoGen3, Scene, build_model
from vereshchagin_experiments.contact.robot_interface import RobotInterface
from vereshchagin_experiments.contact.use_cases import gen3_model, grasp, writing


@pytest.fixture(scope="module")
def grasp_runs():
    return grasp(True, quick=True), grasp(False, quick=True)


@pytest.fixture(scope="module")
def writing_runs():
    return writing(True, quick=True), writing(False, quick=True)


def test_plant_mass_matrix_equals_chain():
    urdf, chain = gen3_model()
    plant = MujocoGen3(build_model(urdf, chain, Scene(table_top=0.1, pen_direction=(0.0, 0.0, 1.0))), np.zeros(7))
    solver = vs.Solver(chain)
    rng = np.random.default_rng(6)
    for _ in range(5):
        q = rng.uniform(-2.0, 2.0, 7)
        solver.solve(q, np.zeros(7))
        G, _ = solver.response_columns(list(range(7)))
        H = np.linalg.inv(G)
        M = plant.mass_matrix(q)
        assert np.abs(M - H).max() < 1e-9 * max(1.0, np.abs(M).max())
    assert np.allclose(plant.model.dof_frictionloss, chain.friction)
    assert np.allclose(plant.model.dof_damping, chain.damping)
    assert np.allclose(plant.model.actuator_ctrlrange[:, 1], chain.effort_limit)
    assert plant.model.opt.timestep == 1e-3


def test_plant_is_a_robot_interface():
    urdf, chain = gen3_model()
    plant = MujocoGen3(build_model(urdf, chain), np.zeros(7))
    assert isinstance(plant, RobotInterface)
    with pytest.raises(ValueError):
        plant.write(np.full(7, np.nan))


def test_grasp_contact_detected_and_slides_10cm_in_contact(grasp_runs):
    run, _ = grasp_runs
    out = metrics.grasp_outcome(run)
    assert out["contact_detected"]
    # The plant saw the table only once the controller approached it, and the controller switched then.
    first_touch = run.t[np.argmax(run.table_force > 0)]
    assert first_touch <= run.contact_time + 1e-9
    assert abs(out["distance_x"] - 0.10) <= 0.005
    assert out["contact_fraction"] > 0.95  # the table pushes back during the slide
    assert run.contact_mode[run.window("slide")].all()
    assert len(run.table_touch) == 1 and "elbow" not in run.table_touch  # only the gripper touches


def test_grasp_after_the_full_25cm_descent_still_slides_10cm():
    """The report's full approach: the arm's weight presses with ~50 N; the slide must not stall."""
    run = grasp(True, quick=False)
    out = metrics.grasp_outcome(run)
    assert out["contact_detected"] and abs(out["distance_x"] - 0.10) <= 0.005
    assert out["contact_fraction"] > 0.95 and out["mean_table_force"] > 30.0


def test_grasp_contactless_never_touches_the_table(grasp_runs):
    _, run = grasp_runs
    assert run.table_touch == []
    assert np.all(run.table_force == 0.0)
    assert run.contact_time is None and not run.contact_mode.any()
    assert abs(metrics.grasp_outcome(run)["distance_x"] - 0.10) <= 0.005


def test_grasp_effort_finite_positive_and_contact_unloads_the_shoulder(grasp_runs):
    c, n = grasp_runs
    ec, en = metrics.effort(c, c.window("slide")), metrics.effort(n, n.window("slide"))
    for e in (ec, en):
        for key in ("energy_abs", "energy_tau2", "mean_abs_tau"):
            assert np.all(np.isfinite(e[key])) and np.all(e[key] > 0.0)
    # The table carries part of the arm: the shoulder (joint_2) needs less torque in contact.
    assert ec["mean_abs_tau"][1] < en["mean_abs_tau"][1]


def test_writing_pen_stays_on_the_paper(writing_runs):
    c, n = writing_runs
    ac, an = metrics.writing_accuracy(c), metrics.writing_accuracy(n)
    assert c.contact_time is not None
    assert ac["contact_fraction"] > 0.95
    assert abs(ac["length"] - 0.10) < 0.005 and abs(an["length"] - 0.10) < 0.005
    assert n.table_touch == [] and an["contact_fraction"] == 0.0
    # both lines within the report's contact accuracy (2.11 mm); before the friction solver's rest
    # tolerance sat above the plant's creep (1e-3 -> 1e-2 rad/s) they wandered by 6-12 mm
    for a in (ac, an):
        assert np.isfinite(a["max_displacement"]) and a["max_displacement"] < 0.002


@pytest.fixture(scope="module")
def elbow_runs():
    return {v: elbow(v, quick=True) for v in ("unsupported", "plant", "constraint")}


def test_elbow_support_carries_load_and_saves_effort(elbow_runs):
    free, rest = elbow_runs["unsupported"], elbow_runs["plant"]
    assert np.all(free.support_force == 0.0)
    m = rest.window("slide")
    assert rest.support_force[m].mean() > 1.0  # the support pushes on the elbow
    # Resting on it, not sinking through (elbow sphere radius 0.055 m, soft contact: a few mm).
    assert rest.info["elbow_z"].min() > rest.info["support_top"] + ELBOW_RADIUS - 0.005
    ef, er = metrics.effort(free, free.window("slide")), metrics.effort(rest, m)
    for e in (ef, er):
        assert np.all(np.isfinite(e["energy_tau2"])) and np.all(e["energy_tau2"] > 0.0)
    assert er["mean_abs_tau"][1] < ef["mean_abs_tau"][1]  # shoulder unloaded by the support


def test_elbow_segment_constraint_rests_on_the_support_and_keeps_the_task(elbow_runs):
    """Support modelled as a segment constraint (zero vertical elbow acceleration), carried by the plant.

    Unsupported, the same constraint holds the elbow's height with the motors alone: same motion,
    so the effort difference is what the support carries.
    """
    free, rest = elbow_runs["unsupported"], elbow_runs["constraint"]
    of, oc = metrics.elbow_outcome(free), metrics.elbow_outcome(rest)
    m = rest.window("slide")
    # the end-effector task is done in both (0.10 m towards the base, 5 mm)
    assert abs(of["final_error_x"]) < 0.005 and abs(oc["final_error_x"]) < 0.005
    # the elbow stays on the support: the plant's support pushes for most of the slide ...
    assert oc["support_fraction"] > 0.9 and oc["support_force"] > 5.0
    # ... without sinking into it or lifting off (soft contact: < 2 mm), and unsupported it is held too
    top = rest.info["support_top"] + ELBOW_RADIUS
    assert np.all(np.abs(rest.info["elbow_z"] - top) < 0.002)
    assert np.all(np.abs(free.info["elbow_z"] - free.info["elbow_z"][0]) < 0.002)
    # the solver's constraint force (-nu_e, support pushing up) matches MuJoCo's contact force in size
    assert oc["model_support_force"] > 0.0 and 0.5 < oc["support_force"] / oc["model_support_force"] < 2.0
    ef, ec = metrics.effort(free, free.window("slide")), metrics.effort(rest, m)
    for e in (ef, ec):
        for key in ("energy_abs", "energy_tau2"):
            assert np.all(np.isfinite(e[key])) and np.all(e[key] > 0.0)
    # the support lowers the shoulder torque and the copper-loss proxy of the whole arm
    assert ec["mean_abs_tau"][1] < 0.75 * ef["mean_abs_tau"][1]
    assert ec["energy_tau2"].sum() < 0.75 * ef["energy_tau2"].sum()
