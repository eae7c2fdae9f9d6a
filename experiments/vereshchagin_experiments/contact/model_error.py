"""Model error for the contact use cases: the plant's inertias and joint friction perturbed, seeded.

Every other run of :mod:`.report` drives a plant compiled from the controller's own URDF, so the
controller's model is exact apart from MuJoCo's soft contacts and friction. Here the plant is
changed after compiling (the controller keeps the nominal chain): each moving body's mass and
rotational inertia (one factor per body, the inertia tensor scaled as a whole so that it stays
physical) and each joint's dry friction ``frictionloss`` are multiplied by independent factors
drawn uniformly from ``[1 - spread, 1 + spread]`` (default +-10 %) by ``numpy``'s
``default_rng(seed)``. Centres of mass, geometry, damping and the motors are unchanged.

:func:`run_perturbed` repeats the grasp and writing cases (contact and contactless) and the resting
elbow (unsupported and with the support as a constraint) for a few seeds so that the report can
show whether the contact findings survive a model the controller does not know exactly
(:func:`.report_model_error.model_error_section`).
"""

from __future__ import annotations

from functools import partial
from typing import Callable, Optional

import numpy as np

from .elbow import elbow
from .use_cases import Run, grasp, writing

__all__ = ["SEEDS", "SPREAD", "perturb_plant", "run_perturbed"]

SPREAD = 0.10
"""Half-width of the factors' range (0.10: each factor in [0.9, 1.1])."""
SEEDS = (1, 2, 3)
"""Seeds of the perturbed plants the report runs."""


def perturb_plant(model, seed: int, spread: float = SPREAD) -> dict:
    """Scale the plant's body masses, inertias and joint friction in place by random factors.

    Parameters
    ----------
    model : mujoco.MjModel
        A compiled plant (:func:`~.mujoco_plant.build_model`); body 0 (the world) is left alone.
    seed : int
        Seed of ``numpy.random.default_rng``.
    spread : float
        The factors are uniform in ``[1 - spread, 1 + spread]`` (0 <= spread < 1).

    Returns
    -------
    dict
        ``seed``, ``spread``; ``mass_factor`` (n_bodies - 1,) per moving body (mass and inertia
        tensor, in MuJoCo's body order); ``friction_factor`` (n_dof,) per joint (joint order).
    """
    if not 0.0 <= spread < 1.0:
        raise ValueError(f"spread must be in [0, 1), got {spread!r}")
    rng = np.random.default_rng(seed)
    mass = rng.uniform(1.0 - spread, 1.0 + spread, model.nbody - 1)
    friction = rng.uniform(1.0 - spread, 1.0 + spread, model.nv)
    model.body_mass[1:] *= mass
    model.body_inertia[1:] *= mass[:, None]
    model.dof_frictionloss[:] *= friction
    return dict(seed=seed, spread=spread, mass_factor=mass, friction_factor=friction)


def run_perturbed(
    quick: bool = False,
    seeds=SEEDS,
    spread: float = SPREAD,
    say: Optional[Callable[[str], None]] = None,
) -> dict:
    """Grasp and writing (contact and contactless) and the resting elbow (unsupported and
    constraint) on a perturbed plant per seed.

    Returns
    -------
    dict
        ``{(seed, case, variant): Run}``: ``case`` ``"grasp"`` or ``"writing"`` with ``variant``
        ``"contact"`` / ``"contactless"``; ``case`` ``"elbow"`` with ``"unsupported"`` /
        ``"constraint"``.
    """
    runs: dict[tuple, Run] = {}
    for seed in seeds:
        hook = partial(perturb_plant, seed=seed, spread=spread)
        for contact in (True, False):
            variant = "contact" if contact else "contactless"
            runs[(seed, "grasp", variant)] = grasp(contact, quick, perturb=hook)
            runs[(seed, "writing", variant)] = writing(contact, quick, perturb=hook)
        for variant in ("unsupported", "constraint"):
            runs[(seed, "elbow", variant)] = elbow(variant, quick, perturb=hook)
        if say is not None:
            say(f"[contact] model error: seed {seed} done")
    return runs
