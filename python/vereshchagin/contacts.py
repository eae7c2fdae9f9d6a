"""Point contacts for ``Solver.solve(..., contacts=[...])``: supports and force set-points.

A contact is a point moving with a segment (or a link merged into one) that touches a surface. As a
*support* (``force=None``) the surface pushes with whatever normal force the dynamics need, never
pulls (the point lifts off instead), and friction holds the point or opposes its sliding within a
polygonal Coulomb cone. With a *force set-point* (``force=F``) the point stays on the surface and
the surface pushes with exactly ``F`` newtons along the normal; the motors supply whatever that
takes. The solve finds the contact forces exactly (see the docs' "Contacts" page); its result
reports them (``contact_force``, ``contact_status``, ``contact_outcome``).
"""

from __future__ import annotations

import enum
import math
from typing import Optional, Union

import numpy as np

from ._core import SolverError


class ContactStatus(enum.IntEnum):
    """What a contact does in the solved motion (``SolveResult.contact_status`` holds these codes)."""

    SEPARATING = 0
    """No force: the point leaves the surface (or already moves away from it)."""
    STICKING = 1
    """At rest tangentially, the force inside the friction polygon."""
    SLIDING = 2
    """Sliding or starting to slide, the force on the polygon's boundary (a frictionless point in
    touch counts as sliding: nothing holds it tangentially)."""


class ContactOutcome(enum.IntEnum):
    """How the contact forces of a solve were determined (``SolveResult.contact_outcome``)."""

    NONE = 0
    """The solve had no contacts."""
    UNIQUE = 1
    """No touching support has friction: a convex problem, whose accelerations are unique."""
    CONSISTENT = 2
    """Supports with friction: one consistent answer by the documented rule (others may exist)."""


def _vector3(value, name: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (ValueError, TypeError) as e:
        raise SolverError(f"Contact.{name} must be 3 real numbers: {e}") from None
    if a.shape != (3,):
        raise SolverError(f"Contact.{name} must have shape (3,), got {a.shape}")
    if not np.isfinite(a).all():
        raise SolverError(f"Contact.{name} must be finite, got {a.tolist()}")
    return a


def _real(value, name: str) -> float:
    if isinstance(value, (bool, str, bytes)) or value is None:
        raise SolverError(f"Contact.{name} must be a real number, got {type(value).__name__}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise SolverError(f"Contact.{name} must be a real number, got {type(value).__name__}") from None


class Contact:
    """A point contact for ``Solver.solve(..., contacts=[...])`` and ``solve_batch``.

    Immutable: its values are checked and stored once, so a control loop can pass the same list to
    every solve.

    Parameters
    ----------
    segment : str or int
        The segment the point moves with, by name or index (negative from the end), or a link
        merged into a segment by fixed joints, by name (not the fixed base).
    point : array_like, shape (3,), optional
        The contact point in that segment's (or link's) own frame, m. Default: its origin.
    normal : array_like, shape (3,), optional
        Unit vector in base axes along which the surface pushes the robot (from the surface into
        the robot). Default: +z, a horizontal table under the robot.
    mu : float, optional
        Coulomb friction coefficient >= 0 (default 0: frictionless).
    facets : int, optional
        Vertices of the friction polygon inscribed in the circular cone, 3 .. 64 (default 4).
    force : float or None, optional
        None (default): a support, whose normal force (>= 0) the solve finds. A number >= 0: a
        normal-force set-point in N; the point stays on the surface (the motors hold its normal
        acceleration at zero) and the surface pushes with exactly this force.

    Raises
    ------
    SolverError
        A point or normal that is not 3 finite numbers, a normal that is not a unit vector (to
        1e-6), mu or force negative or not finite, facets not an int in 3 .. 64. The segment is
        resolved by the solve (its messages name ``contacts[k]``).

    Notes
    -----
    The polygon's vertices are ``mu f_n d_j``, ``d_j = cos(2 pi j / k) t1 + sin(2 pi j / k) t2``
    (j = 0 .. k-1), ``t1 = unit(e x n)`` for the base axis ``e`` least aligned with the normal (the
    first on ties), ``t2 = n x t1``.
    """

    __slots__ = ("_segment", "_values")
    _segment: Union[str, int]
    _values: np.ndarray

    def __init__(
        self,
        segment: Union[str, int],
        point=(0.0, 0.0, 0.0),
        normal=(0.0, 0.0, 1.0),
        mu: float = 0.0,
        facets: int = 4,
        force: Optional[float] = None,
    ):
        if not isinstance(segment, (str, int, np.integer)) or isinstance(segment, bool):
            raise SolverError(f"Contact.segment must be a segment or link name or an int index, got {segment!r}")
        p = _vector3(point, "point")
        n = _vector3(normal, "normal")
        if abs(float(np.linalg.norm(n)) - 1.0) > 1e-6:
            raise SolverError(f"Contact.normal must be a unit vector, its norm is {np.linalg.norm(n):g}")
        m = _real(mu, "mu")
        if not (math.isfinite(m) and m >= 0.0):
            raise SolverError(f"Contact.mu must be finite and >= 0, got {m:g}")
        if isinstance(facets, bool) or not isinstance(facets, (int, np.integer)) or not 3 <= facets <= 64:
            raise SolverError(f"Contact.facets must be an int in 3 .. 64, got {facets!r}")
        f = math.nan
        if force is not None:
            f = _real(force, "force")
            if not (math.isfinite(f) and f >= 0.0):
                raise SolverError(f"Contact.force (a normal-force set-point, N) must be finite and >= 0, got {f:g}")
        values = np.array([*p, *n, m, float(facets), f], dtype=np.float64)
        object.__setattr__(self, "_segment", segment if isinstance(segment, str) else int(segment))
        # Read-only: a view of immutable bytes (the solve reads it in place).
        object.__setattr__(self, "_values", np.frombuffer(values.tobytes(), dtype=np.float64))

    def __setattr__(self, name, value):
        raise AttributeError("Contact is immutable: make a new one")

    @property
    def segment(self) -> Union[str, int]:
        """The segment or link the point moves with (name or index, as given)."""
        return self._segment

    @property
    def point(self) -> np.ndarray:
        """The point in the segment's (link's) own frame, m, shape (3,) (read-only)."""
        return self._values[0:3]

    @property
    def normal(self) -> np.ndarray:
        """Unit normal in base axes, from the surface into the robot, shape (3,) (read-only)."""
        return self._values[3:6]

    @property
    def mu(self) -> float:
        """Coulomb friction coefficient."""
        return float(self._values[6])

    @property
    def facets(self) -> int:
        """Vertices of the friction polygon."""
        return int(self._values[7])

    @property
    def force(self) -> Optional[float]:
        """The normal-force set-point in N, or None for a support."""
        f = float(self._values[8])
        return None if math.isnan(f) else f

    def __repr__(self) -> str:
        kind = "" if self.force is None else f", force={self.force!r}"
        return (
            f"Contact({self.segment!r}, point={self.point.tolist()}, normal={self.normal.tolist()}, "
            f"mu={self.mu!r}, facets={self.facets}{kind})"
        )

    def __eq__(self, other) -> bool:
        if not isinstance(other, Contact):
            return NotImplemented
        return self._segment == other._segment and np.array_equal(self._values, other._values, equal_nan=True)

    def __hash__(self) -> int:
        return hash((self._segment, self._values.tobytes()))

    def __reduce__(self):
        return (Contact, (self.segment, self.point.copy(), self.normal.copy(), self.mu, self.facets, self.force))
