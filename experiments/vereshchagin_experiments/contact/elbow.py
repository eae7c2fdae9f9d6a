"""Use case 3 (W. K. Lau (2023), sec. 6.4): the end-effector moves while the elbow rests on a support.

Pose: the report does not give one (the elbow rested on a stack of books). With the tool held
fixed, the Gen3's elbow (joint 4's centre, the tip of the ``forearm_link`` segment) can only move
on the self-motion circle around the shoulder-wrist axis; at the circle's lowest point a support
cannot carry anything to first order (the elbow's height does not change with the self-motion
there), so the elbow is swung 50 degrees sideways from that point: :data:`ELBOW_POSE`, elbow at
about (0.374, 0.150, 0.163) m, tool at (0.745, 0, 0.187) m pointing forward-down. There gravity
turns the self-motion so that the elbow goes down. The task: hold the pose, move the
end-effector 0.10 m towards the base (-x) in the air (all six directions constrained), hold.

Variants:

- ``unsupported``: no support. The controller holds the elbow's height with a segment
  constraint on ``forearm_link``: ``alpha_e = e_z`` (base z, 1 column), ``beta_e`` the vertical
  acceleration of the controller's cascaded P towards the start height (zero while the elbow
  rests there; including ``-gravity``, :func:`elbow_constraint`). Seven
  constraints (6 at the tool, 1 at the elbow) fix all seven joint accelerations; the motors
  carry the whole arm;
- ``plant``: a support box touches the elbow sphere from below; the controller does not know it
  (tool task only, the self-motion left to nature, posture damping only), so the elbow settles on
  the support and the plant's contact carries what gravity puts on it;
- ``constraint``: the same support and the same segment constraint as ``unsupported``; the
  elbow constraint's share of the command, ``-J_e^T alpha_e nu_e`` (the torque of the upward
  force ``-nu_e`` at the elbow), is left to the support when that force pushes up (``nu_e < 0``).
  The plant's contact then supplies it: the motors carry the rest.

Variants with the surfaces as the solver's contacts (:data:`CONTACT_VARIANTS`, :mod:`.surfaces`),
the same support, no elbow constraint, no share removed by hand:

- ``support``: the lowest point of the elbow sphere is a support (friction of the scene) in the
  solve; the self-motion is left to the dynamics, and the support holds it;
- ``elbow+wrist``: also a table under the gripper (its lowest edge rests on it and slides along
  with the tool): two resting points at once. The tool's task releases z (the table holds it, as
  in the grasp), the discrete-time mode and a hold band end the slide (:data:`ELBOW_WRIST_CONFIG`), and the
  gripper's friction is set against the desired motion (``reference``, :mod:`.surfaces`). Holding
  z as well made the wrist's support redundant with the task: the P loop's corrections then asked
  the held point to accelerate into the table, which the solve refuses (no forces meet the
  conditions), from the second cycle on.
"""

from __future__ import annotations

import numpy as np

from vereshchagin import Solver
from vereshchagin.task import beta_for
from .controller import CascadedController, ControllerConfig
from vereshchagin import robots
from .mujoco_plant import ELBOW_RADIUS, Scene, build_model
from .surfaces import BAND_CONFIG, CONTACT_CONFIG, SceneContacts, elbow_support, wrist_support
from .use_cases import SLIDE, Phase, _plant, _shifted, gen3_model, run_loop

__all__ = ["CONTACT_VARIANTS", "ELBOW_POSE", "ELBOW_SEGMENT", "VARIANTS", "elbow"]

ELBOW_POSE = (-0.4012, 1.876, 2.2002, 1.1816, 0.5691, -1.2336, 1.3689)
"""Joint angles (rad) of the resting-elbow posture (least squares: tool pose and elbow point, module doc)."""
ELBOW_SEGMENT = "forearm_link"
"""The segment whose tip origin is the elbow (joint 4's centre)."""
VARIANTS = ("unsupported", "plant", "constraint")
CONTACT_VARIANTS = ("support", "elbow+wrist")
WRIST_DIRECTIONS = ("x", "y", "rx", "ry", "rz")
"""The tool's task directions in ``elbow+wrist``: z is the wrist table's."""
"""The variants with the surfaces as the solver's contacts (module doc)."""
ELBOW_DX = -SLIDE
"""The end-effector moves 0.10 m towards the base (-x): the elbow circle widens, the elbow presses down."""
ALPHA_ELBOW = np.array([[0.0], [0.0], [1.0], [0.0], [0.0], [0.0]])
"""Elbow constraint direction: linear base z (6, 1)."""
N_TOOL = 6
"""Columns of the tool's ``alpha`` in free space; the elbow's ``nu`` follows them in ``result.nu``."""


ELBOW_WRIST_CONFIG = {**CONTACT_CONFIG, **BAND_CONFIG}
"""Controller settings of ``elbow+wrist``: the discrete-time mode of the contact runs and, unlike the
others, still the hold band. Its command chatters about 0.2 N m per step over the whole slide in
every mode (two points in contact, the gripper sliding); what the band adds is the end of the
slide: without it the gripper's sliding friction flips against the arrival's corrections and the
chatter there rises to 1 N m per step (quick run, measured with the step mode alone)."""


def elbow_constraint(chain, seg: int, z_ref: float, gains=(40.0, 30.0), v_max: float = 0.05):
    """``constraints=`` callable for the controller: hold the elbow at height ``z_ref`` (m).

    The elbow's vertical acceleration is the controller's cascaded P (free-space linear gains
    ``(k_pos, k_vel)``, desired velocity saturated at ``v_max``):
    ``a_z = k_vel (sat(k_pos (z_ref - z)) - v_z)``, zero once the elbow rests at ``z_ref``;
    ``beta_e`` adds ``-gravity`` and the velocity product (:func:`vereshchagin.task.beta_for`).
    """
    k_pos, k_vel = gains

    def constraints(q, qd):
        z = float(np.asarray(chain.fk(q, segment=seg))[2, 3])
        tw = np.asarray(chain.twist(q, qd, segment=seg))
        v_d = float(np.clip(k_pos * (z_ref - z), -v_max, v_max))
        a = np.zeros(6)
        a[2] = k_vel * (v_d - tw[2])
        return {ELBOW_SEGMENT: (ALPHA_ELBOW, beta_for(ALPHA_ELBOW, a, tw))}

    return constraints


def support_share(chain, seg: int):
    """Torque the support supplies: ``-J_e^T alpha_e nu_e`` when it pushes up (``nu_e < 0``), else 0."""

    def share(res, q):
        nu_e = float(np.asarray(res.nu, float)[N_TOOL])
        if nu_e >= 0.0:
            return np.zeros(chain.n_joints)
        J = np.asarray(chain.jacobian(q, segment=seg))
        return -(J.T @ ALPHA_ELBOW[:, 0]) * nu_e

    return share


def _wrist_table(urdf: str, chain, q0, support) -> tuple[np.ndarray, Scene]:
    """The gripper box's lowest corner (end-effector frame, m) and a scene with a table under it (and ``support``).

    The tool points forward-down, so the box touches with a corner (not the middle of an edge, as
    in the grasp). The table's top is at the corner's height; it reaches 0.16 m towards the base
    (the tool moves 0.10 m that way) and 0.06 m beyond, 0.08 m to either side.
    """
    import mujoco

    T0 = np.asarray(chain.fk(q0))
    model = build_model(urdf, chain, Scene())
    d = mujoco.MjData(model)
    d.qpos[:] = q0
    mujoco.mj_forward(model, d)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "bracelet_link")
    g = next(
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == body and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
    )
    R = d.geom_xmat[g].reshape(3, 3)
    p = d.geom_xpos[g] - R @ (np.sign(R[2]) * model.geom_size[g])
    low = (np.linalg.inv(T0) @ np.append(p, 1.0))[:3]
    table = dict(table_top=float(p[2]), table_x=(p[0] - 0.16, p[0] + 0.06), table_y=(p[1] - 0.08, p[1] + 0.08))
    return low, Scene(support=support, **table)


def _logger(variant: str, log: dict):
    """``on_cycle`` for :func:`~.use_cases.run_loop`: the command, ``-nu_e`` or the contacts' upward forces into ``log``."""

    def on_cycle(k, command, info) -> None:
        log["command"].append(np.array(command, float))
        if variant in ("unsupported", "constraint"):
            log["nu"].append(-float(np.asarray(info.result.nu)[N_TOOL]))
        elif variant in CONTACT_VARIANTS:
            log["contact"].append(np.array(info.result.contact_force)[:, 2])

    return on_cycle


def elbow(variant: str, quick: bool = False, progress=None, perturb=None):
    """Run use case 3 in one of :data:`VARIANTS` (see module doc).

    Parameters
    ----------
    variant : {"unsupported", "plant", "constraint", "support", "elbow+wrist"}
        Who carries the elbow: the motors (segment constraint), the plant's support unknown to
        the controller, the support stated as the segment constraint, or the support as the
        solver's contact (with the wrist's table as a second one).
    quick : bool
        Shorter settle, slide and hold phases.
    progress : callable, optional
        ``progress(fraction)``, see :func:`~.use_cases.run_loop`.
    perturb : callable, optional
        Model error of the plant, as in :func:`~.use_cases.grasp` (``info["plant_error"]``).

    Returns
    -------
    Run
        Phases ``settle``, ``slide``, ``hold``; ``run.info``: ``elbow_z`` (elbow height per
        sample, m, base z), ``support_top`` (m or None) and ``support_force_model`` (the solver's
        ``-nu_e`` per sample, N, positive pushing up; the elbow contact's upward force in the
        contact variants; NaN otherwise), ``table_force_model`` (the wrist contact's upward
        force, N; zeros without it) and ``command`` ((k, n) the commands, N m).

    Raises
    ------
    ValueError
        If ``variant`` is not one of :data:`VARIANTS`.
    """
    if variant not in VARIANTS + CONTACT_VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS + CONTACT_VARIANTS}, got {variant!r}")
    urdf, chain = gen3_model()
    q0 = np.array(ELBOW_POSE)
    seg = chain.segment_index(ELBOW_SEGMENT)
    p_e = np.asarray(chain.fk(q0, segment=seg))[:3, 3]
    support = None
    if variant != "unsupported":
        top = p_e[2] - ELBOW_RADIUS
        support = ((p_e[0], p_e[1], top / 2.0), (0.05, 0.06, top / 2.0))
    scene, low = Scene(support=support), None
    if variant == "elbow+wrist":
        low, scene = _wrist_table(urdf, chain, q0, support)
    robot, plant_error = _plant(urdf, chain, scene, q0, perturb)
    solver = Solver(chain, gravity=[0.0, 0.0, -9.81])
    config = ControllerConfig(posture_gains=(0.0, 3.0))
    if variant == "support":  # the solver's contacts: the discrete-time mode of the contact runs
        config = ControllerConfig(posture_gains=(0.0, 3.0), **CONTACT_CONFIG)
    if variant == "elbow+wrist":  # the table holds the gripper's height: the task the other five
        config = ControllerConfig(posture_gains=(0.0, 3.0), free_directions=WRIST_DIRECTIONS, **ELBOW_WRIST_CONFIG)
    ctl = CascadedController(chain, solver, config)
    if variant in ("unsupported", "constraint"):
        g = ctl.config.free_gains
        ctl.extra_constraints = elbow_constraint(chain, seg, float(p_e[2]), (g.k_pos[0], g.k_vel[0]), ctl.config.v_max)
    if variant == "constraint":
        ctl.support_share = support_share(chain, seg)
    if variant in CONTACT_VARIANTS:
        points = [elbow_support(ELBOW_SEGMENT, ELBOW_RADIUS, scene.friction)]
        if low is not None:
            points.append(wrist_support(robots.GEN3_TIP_LINK, low, scene.friction))
        reference = (lambda: ctl.v_des[:3]) if low is not None else None
        ctl.contacts = SceneContacts(chain, points, reference=reference)
    R0 = np.asarray(chain.fk(q0))[:3, :3]
    v = ctl.config.v_max
    duration = 0.5 if quick else 1.0
    phases = [
        Phase("settle", lambda T: _shifted(T, R=R0), duration, contact=False),
        Phase("slide", lambda T: _shifted(T, dx=ELBOW_DX, R=R0), SLIDE / v + (1.0 if quick else 1.5)),
        Phase("hold", lambda T: _shifted(T, R=R0), duration),
    ]
    log: dict[str, list] = {"nu": [], "contact": [], "command": []}
    run = run_loop(robot, ctl, phases, "elbow", variant, (0.0, 0.0, 0.0), progress, on_cycle=_logger(variant, log))
    nu_log = log["nu"]
    if log["contact"]:
        forces = np.array(log["contact"])
        nu_log = list(forces[:, 0])
        run.info["table_force_model"] = forces[:, 1] if forces.shape[1] > 1 else np.zeros(len(forces))
    run.info["command"] = np.array(log["command"])
    elbow_z = np.array([np.asarray(chain.fk(q, segment=seg))[2, 3] for q in run.q])
    run.info.update(
        elbow_z=elbow_z,
        support_top=None if support is None else 2 * support[0][2],
        support_force_model=np.array(nu_log[: len(run.t)]) if nu_log else np.full(len(run.t), np.nan),
        plant_error=plant_error,
    )
    return run
