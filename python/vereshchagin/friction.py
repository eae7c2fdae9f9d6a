"""Joint friction parameters for friction-aware solves."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ._core import SolverError


def _frozen_vector(value, name: str, allow_inf: bool = False) -> Optional[np.ndarray]:
    """A read-only float64 copy of a 1-D real array (None stays None)."""
    if value is None:
        return None
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as e:  # ragged nested sequences and the like
        raise SolverError(f"friction.{name} must be a 1-D array of real numbers: {e}") from None
    if a.dtype.kind not in "iuf":
        raise SolverError(f"friction.{name} must hold real numbers (int or float), got dtype {a.dtype}")
    if a.ndim != 1:
        raise SolverError(f"friction.{name} must be a 1-D array (one value per joint), got shape {a.shape}")
    a = np.array(a, dtype=np.float64)
    if np.isnan(a).any() or (not allow_inf and not np.isfinite(a).all()):
        raise SolverError(f"friction.{name} contains {'NaN' if allow_inf else 'NaN or Inf'}")
    # A view of immutable bytes: its WRITEABLE flag cannot be switched back on, so the values of a
    # Friction never change after construction (solvers may reuse a parsed Friction).
    return np.frombuffer(a.tobytes(), dtype=np.float64)


@dataclass(frozen=True)
class Friction:
    """Per-joint friction for ``Solver.solve(..., friction=Friction(...))``.

    Immutable: the arrays are stored as float64 copies that cannot be written (views of immutable
    bytes: ``flags.writeable`` cannot be switched back on), so a solver may reuse a parsed
    ``Friction`` across calls (pass the same object in a control loop). A solver reparses it if
    an attribute was replaced.

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

    Raises
    ------
    SolverError
        Non-numeric or non-1-D arrays, NaN (or Inf in ``static``/``kinetic``). Sizes and signs
        are checked against the chain by the solve.
    """

    static: np.ndarray
    kinetic: Optional[np.ndarray] = None
    velocity_tolerance: float = 1e-6
    lower: Optional[np.ndarray] = None
    upper: Optional[np.ndarray] = None
    limit_tolerance: float = 1e-9

    def __post_init__(self):
        object.__setattr__(self, "static", _frozen_vector(self.static, "static"))
        object.__setattr__(self, "kinetic", _frozen_vector(self.kinetic, "kinetic"))
        object.__setattr__(self, "lower", _frozen_vector(self.lower, "lower", allow_inf=True))
        object.__setattr__(self, "upper", _frozen_vector(self.upper, "upper", allow_inf=True))

    def __reduce__(self):
        # Rebuilt through the constructor, so copies and unpickled objects stay read-only.
        return (
            Friction,
            (self.static, self.kinetic, self.velocity_tolerance, self.lower, self.upper, self.limit_tolerance),
        )
