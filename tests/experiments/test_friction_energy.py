"""The friction-energy experiment (vereshchagin_experiments.friction_energy), quick mode.

What is checked: every controller runs every task to its end with a bounded error; each
controller's command is exactly what its definition says, recomputed from the logged solver inputs
with a fresh solver (the max-min: the solver's ``tau_command`` with friction at every step); the
plant's friction diagnostics and gravity torques agree with MuJoCo's own dynamics and with our
chain of the same URDF (payload included); the outputs are written. Which controller saves more is
not asserted: the experiment reports what happens.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

import vereshchagin as vs
from vereshchagin import robots
from vereshchagin_experiments.contact.controller import CascadedController, ControllerConfig
from vereshchagin_experiments.contact.mujoco_plant import MujocoGen3, Scene, build_model
from vereshchagin_experiments.contact.use_cases import gen3_model
from vereshchagin_experiments import friction_energy as fe
from vereshchagin_experiments import friction_energy_report as report

FINAL_ERROR_BOUND = 0.02
"""m: final translational task error (constrained directions) every run stays below; a run that
diverges, saturates or falls fails it. The report's own "completes the task" is stricter (1 mm)."""
ROT_ERROR_BOUND = 0.2
"""rad: RMS rotational task error every run stays below."""


@pytest.fixture(scope="module")
def experiment(tmp_path_factory):
    out = tmp_path_factory.mktemp("energy")
    return out, report.run(out, quick=True, workers=2)


def test_every_controller_completes_every_task_in_quick_mode(experiment):
    _, res = experiment
    done = {(r["task"], r["controller"]) for r in res["results"]}
    assert done == {(t.name, c) for t in fe.tasks(True) for c in fe.CONTROLLERS}
    for r in res["results"]:
        o = r["outcome"]
        assert all(np.isfinite(v) for v in o.values()), r["task"]
        assert o["final_error"] < FINAL_ERROR_BOUND, (r["task"], r["controller"], o["final_error"])
        assert o["rms_rot"] < ROT_ERROR_BOUND, (r["task"], r["controller"], o["rms_rot"])
        assert o["saturated"] == 0.0  # the motors never hit their effort limits
    assert res["ok"]


def test_outputs_are_written(experiment):
    out, res = experiment
    folder = out / "friction_energy"
    with open(folder / "summary.csv", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0] == report.SUMMARY_HEADER and len(rows) == 1 + len(fe.tasks(True)) * len(fe.CONTROLLERS)
    with open(folder / "context.csv", encoding="utf-8") as f:
        assert len(list(csv.reader(f))) == 1 + 3 * 7  # three held poses, seven joints
    for task in fe.tasks(True):
        png = folder / f"{task.name}.png"
        assert png.stat().st_size > 10_000
        assert f"### {task.title}" in res["index"]
    text = "\n".join(res["index"])
    assert "**These are assumptions**" in text and "Findings" in text
    for label in fe.CONTROLLERS.values():
        assert f"| {label} |" in text


def _expected_command(run, k: int, solver, friction) -> np.ndarray:
    """The command of ``run``'s controller at step ``k`` from its logged inputs, by its definition."""
    log = run.info["log"]
    inp = log.inputs[k]
    args = dict(alpha=inp["alpha"], beta=inp["beta"], f_ext=inp["f_ext"], tau_ff=inp["tau_ff"])
    if "time_step" in inp:  # the discrete-time mode: the same solve over the control period
        assert inp["time_step"] == 1e-3
        args["time_step"] = inp["time_step"]
    mode = run.info["config"].friction_mode
    res = solver.solve(inp["q"], inp["qd"], friction=friction if mode == "maxmin" else None, **args)
    f, eps, qd = np.asarray(run.info["chain"].friction), fe.REST_TOLERANCE, inp["qd"]
    extra = {
        "none": 0.0,
        "maxmin": 0.0,
        "smooth": f * np.tanh(qd / eps),
        "sign": f * np.where(np.abs(qd) > eps, np.sign(qd), np.sign(res.qdd)),
    }[mode]
    return np.asarray(res.tau_command) + inp["motor_ff"] + extra


@pytest.mark.parametrize("controller", list(fe.CONTROLLERS))
def test_commands_follow_each_controllers_definition(controller):
    """Max-min: the command is the solver's tau_command with friction (+ the posture term) at every step."""
    task = fe.task_named("slow", quick=True)  # moving and resting joints
    run = fe.simulate(task, controller, keep_inputs=True)
    log, chain = run.info["log"], run.info["chain"]
    solver = vs.Solver(chain, gravity=[0.0, 0.0, -9.81])
    friction = vs.Friction(static=np.asarray(chain.friction), velocity_tolerance=fe.REST_TOLERANCE)
    assert len(log.inputs) == len(run.t) > 1000
    for k in range(len(run.t)):
        want = _expected_command(run, k, solver, friction)
        assert np.abs(log.command[k] - want).max() <= 1e-9 * max(1.0, np.abs(want).max()), k
    limit = np.asarray(chain.effort_limit)
    assert np.array_equal(run.tau, np.clip(log.command, -limit, limit))  # what the plant applied
    if controller.startswith("maxmin"):
        motor_ff = np.array([i["motor_ff"] for i in log.inputs])
        assert np.allclose(log.model_command + motor_ff, log.command, rtol=0.0, atol=1e-12)


def test_plant_friction_state_matches_mujoco_dynamics():
    """Motors short of gravity by less than f: every joint sticks, friction = the shortfall; more: slip at f."""
    urdf, chain = gen3_model()
    q = np.array(robots.GEN3_START_POSE)
    for share, slipping in ((0.97, set()), (0.90, {1})):  # joint_2 (index 1) lacks 1.27 N m > 0.5 N m
        plant = MujocoGen3(build_model(urdf, chain, Scene()), q)
        g = plant.data.qfrc_bias.copy()
        plant.write(share * g)
        for _ in range(200):
            plant.wait()
        stick, torque = plant.joint_friction_state()
        f = np.asarray(chain.friction)
        assert np.all(np.abs(torque) <= f * (1 + 1e-9))
        assert set(np.flatnonzero(~stick)) == slipping
        if not slipping:  # all at rest, the joint torques balance: motor + friction = gravity (bias force)
            assert np.allclose(torque, (1 - share) * g, atol=2e-3)
        for j in slipping:
            assert abs(abs(torque[j]) - f[j]) < 1e-6 and abs(plant.data.qvel[j]) > 0.01


@pytest.mark.parametrize("payload", [None, fe.PAYLOAD])
def test_gravity_torques_equal_our_chain_with_and_without_payload(payload):
    """MuJoCo's bias force at rest (the context numbers) equals -H qdd of our unconstrained solve."""
    task = fe.TaskSpec("t", "t", lambda T0: [], payload=payload is not None)
    urdf, chain = gen3_model(1.0, payload)
    solver = vs.Solver(chain, gravity=[0.0, 0.0, -9.81])
    rng = np.random.default_rng(15)
    for q in [np.array(fe.PARTIAL_POSE)] + [rng.uniform(-2.0, 2.0, 7) for _ in range(3)]:
        g, f = fe.gravity_torques(task, q)
        res = solver.solve(q, np.zeros(7))
        G, _ = solver.response_columns(list(range(7)))
        mine = -np.linalg.solve(G, np.asarray(res.qdd))
        assert np.abs(g - mine).max() <= 1e-9 * max(1.0, np.abs(g).max())
        assert np.allclose(f, chain.friction)
    if payload is not None:  # the payload is there: 1 kg more at the arm's tip
        g0, _ = fe.gravity_torques(fe.TaskSpec("t", "t", lambda T0: []), fe.PARTIAL_POSE)
        g1, _ = fe.gravity_torques(task, fe.PARTIAL_POSE)
        assert abs(g1[1] - g0[1]) > 1.0


def test_bad_controller_names_are_rejected():
    urdf, chain = gen3_model()
    with pytest.raises(ValueError, match="friction_mode"):
        CascadedController(chain, vs.Solver(chain), ControllerConfig(friction_mode="coulomb"))
    with pytest.raises(ValueError, match="controller"):
        fe.simulate(fe.tasks(True)[0], "coulomb")
    with pytest.raises(ValueError, match="unknown task"):
        fe.task_named("wave")
    with pytest.raises(ValueError, match="joint_friction"):
        fe.simulate(fe.tasks(True)[0], "none", friction_scale=-1.0)
