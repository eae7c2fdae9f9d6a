"""Joint friction parameters for friction-aware solves."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np


@dataclass(frozen=True)
class Friction:
    """Per-joint friction for ``Solver.solve(..., friction=Friction(...))``.

    Parameters
    ----------
    static : array_like, shape (n,)
        Breakaway (static) friction torque f_j >= 0 (N m or N). Joints at rest get the friction
        torque of Vereshchagin's max-min, |torque| <= f_j.
    kinetic : array_like, shape (n,), optional
        Coulomb friction 0 <= fk_j <= f_j of moving joints (default: equal to ``static``).
    velocity_tolerance : float
        A joint with |qd_j| at or below this is at rest (rad/s or m/s).
    lower, upper : array_like, shape (n,), optional
        Joint position limits (+-inf: none). A resting joint within ``limit_tolerance`` of a limit
        gets a one-sided reaction (``limit_torque`` in the result) in the same optimisation.
        ``friction=True`` uses the chain's URDF limits.
    limit_tolerance : float
        Distance to a limit (rad or m) at which the joint counts as on it.
    """

    static: np.ndarray
    kinetic: Optional[np.ndarray] = None
    velocity_tolerance: float = 1e-6
    lower: Optional[np.ndarray] = None
    upper: Optional[np.ndarray] = None
    limit_tolerance: float = 1e-9
