"""Use case 3 (report 003 sec. 6.4): the end-effector slides while the elbow rests on a support.

Pose: report 003 does not give one (the elbow rested on a stack of books); at its start pose the
Gen3's elbow is the arm's highest point. We use :data:`ELBOW_POSE`, a "V" posture with the elbow
(joint 4, the ``forearm_link`` segment's tip) as the arm's lowest point, at about (0.376, 0,
0.095) m, and the tool pointing forward-down at (0.745, 0, 0.187) m. The task: hold the pose,
then move the end-effector 0.10 m along +x in the air (all six directions constrained), hold.

Variants:

- ``unsupported``: no support; the joint posture term of the controller holds the self-motion
  (the elbow) up -- the motors carry the whole arm;
- ``plant``: a support box touches the elbow sphere from below; the controller does not know it
  and leaves the self-motion to nature (posture damping only), so the elbow settles on the
  support and the plant's contact carries what gravity puts on it;
- ``constraint``: the same support, modelled in the solver as a segment constraint on the elbow
  (``constraints={"forearm_link": (e_z, [9.81])}``, zero vertical acceleration of joint 4's
  centre, beta including -gravity) -- needs the segment-constraint API; the support's share
  ``-J_e^T alpha_e nu_e`` of the command is left to the support when it pushes (``nu_e < 0``).
"""
from __future__ import annotations

import numpy as np

from .. import robots  # noqa: F401  (documentation cross-reference)
from .controller import CascadedController, ControllerConfig
from .mujoco_plant import ELBOW_RADIUS, MujocoGen3, Scene, build_model
from .use_cases import SLIDE, Phase, _shifted, gen3_model, run_loop
from ..solver import Solver
from ..task import beta_for

__all__ = ["ELBOW_POSE", "ELBOW_SEGMENT", "VARIANTS", "elbow", "segment_constraints_available"]

ELBOW_POSE = (-0.009, 2.0383, 3.1261, 1.1587, 0.0169, -1.3965, 0.84)
"""Joint angles (rad) of the resting-elbow posture (found by least squares, see module doc)."""
ELBOW_SEGMENT = "forearm_link"
"""The segment whose tip origin is the elbow (joint 4's centre)."""
VARIANTS = ("unsupported", "plant", "constraint")
ELBOW_DX = -SLIDE
"""The end-effector moves 0.10 m towards the base (-x): the elbow bends and presses down."""


def segment_constraints_available(solver) -> bool:
    """Whether ``solver.solve`` accepts ``constraints=`` (the segment-constraint API)."""
    q = np.zeros(solver.n_joints)
    try:
        solver.solve(q, q, constraints={})
    except TypeError:
        return False
    return True


def _support_share(chain, seg: int, m: int):
    """Torque the support supplies: ``-J_e^T alpha_e nu_e`` when it pushes up (``nu_e < 0``)."""

    def share(res, q):
        nu = np.asarray(res.nu, float)
        nu_e = float(nu[m]) if nu.size > m else 0.0
        if nu_e >= 0.0:
            return np.zeros(chain.n_joints)
        J = np.asarray(chain.jacobian(q, segment=seg))
        return -J.T @ np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]) * nu_e

    return share


def elbow(variant: str, quick: bool = False, progress=None):
    """Run use case 3 in one of :data:`VARIANTS` (see module doc); returns a :class:`~.use_cases.Run`."""
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    urdf, chain = gen3_model()
    q0 = np.array(ELBOW_POSE)
    seg = chain.segment_index(ELBOW_SEGMENT)
    p_e = np.asarray(chain.fk(q0, segment=seg))[:3, 3]
    support = None
    if variant != "unsupported":
        top = p_e[2] - ELBOW_RADIUS
        support = ((p_e[0], p_e[1], top / 2.0 - 0.0), (0.05, 0.06, top / 2.0))
    scene = Scene(support=support)
    robot = MujocoGen3(build_model(urdf, chain, scene), q0)
    solver = Solver(chain, gravity=[0.0, 0.0, -9.81])
    posture = (20.0, 3.0) if variant == "unsupported" else (0.0, 3.0)
    ctl = CascadedController(chain, solver, ControllerConfig(posture_gains=posture))
    if variant == "constraint":
        if not segment_constraints_available(solver):
            raise NotImplementedError("the 'constraint' variant needs Solver.solve(..., constraints=...) "
                                      "(segment constraints); this build does not have it")
        alpha_e = np.array([[0.0], [0.0], [1.0], [0.0], [0.0], [0.0]])
        ctl.extra_constraints = lambda q, qd: {  # zero vertical acceleration of the elbow (incl. -g)
            ELBOW_SEGMENT: (alpha_e, beta_for(alpha_e, np.zeros(6), chain.twist(q, qd, segment=seg)))}
        ctl.support_share = _support_share(chain, seg, 6)
    R0 = np.asarray(chain.fk(q0))[:3, :3]
    v = ctl.config.v_max
    duration = 0.5 if quick else 1.0
    phases = [Phase("settle", lambda T: _shifted(T, R=R0), duration, contact=False),
              Phase("slide", lambda T: _shifted(T, dx=ELBOW_DX, R=R0), SLIDE / v + (1.0 if quick else 1.5)),
              Phase("hold", lambda T: _shifted(T, R=R0), duration)]
    run = run_loop(robot, ctl, phases, "elbow", variant, (0.0, 0.0, 0.0), progress)
    elbow_z = np.array([np.asarray(chain.fk(q, segment=seg))[2, 3] for q in run.q])
    run.info.update(elbow_z=elbow_z, support_top=None if support is None else 2 * support[0][2])
    return run
