"""Joint friction parameters for friction-aware solves."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
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


def _real(value, name: str) -> float:
    """``value`` as a float (its range is the solve's to check).

    Raises
    ------
    SolverError
        ``value`` is a bool, str, bytes or None, or has no float value.
    """
    if not isinstance(value, (bool, str, bytes)) and value is not None:
        try:
            return float(value)
        except Exception:  # any failing __float__ counts as "not a real number"
            pass
    raise SolverError(f"friction.{name} must be a real number, got {type(value).__name__}")


def _iteration_bound(value) -> int:
    """``max_iterations`` as an int: -1 (the real-time default), 0 (exhaustive) or a positive count.

    Raises
    ------
    SolverError
        A bool, a non-integer, or a value outside [-1, 2**31 - 1].
    """
    if value is None:
        return -1
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool) and -1 <= value < 2**31:
        return int(value)
    raise SolverError(
        f"friction.max_iterations must be an int: -1 (default), 0 (exhaustive) or a positive count, got {value!r}"
    )


# The fields of Friction in declaration order: the order of its constructor's arguments and of
# ``_fields_of``'s.
_FIELD_NAMES = ("static", "kinetic", "velocity_tolerance", "lower", "upper", "limit_tolerance", "max_iterations")


def _fields_of(static, kinetic, velocity_tolerance, lower, upper, limit_tolerance, max_iterations=None) -> tuple:
    """What a solver reads of a friction model: ``(static, kinetic, velocity_tolerance, lower,
    upper, limit_tolerance, max_iterations)``, the arrays as given (the solver checks their shapes
    and values), the tolerances as floats: None gives the default, and without limits
    ``limit_tolerance`` is not read (0.0); ``max_iterations`` as an int (None: -1).

    Raises
    ------
    SolverError
        A tolerance that is not a real number, or a ``max_iterations`` that is not an int >= -1.
    """
    limits = lower is not None or upper is not None
    vt = 1e-6 if velocity_tolerance is None else _real(velocity_tolerance, "velocity_tolerance")
    lt = 1e-9 if limit_tolerance is None else _real(limit_tolerance, "limit_tolerance")
    return (static, kinetic, vt, lower, upper, lt if limits else 0.0, _iteration_bound(max_iterations))


def _friction_fields(obj) -> tuple:
    """``_fields_of`` any ``friction=`` object: a Friction's (cached) or the attributes of any object
    that has ``static`` (``kinetic``, ``velocity_tolerance``, ``lower``, ``upper``,
    ``limit_tolerance`` and ``max_iterations`` are optional). The solvers call it for objects that are not exactly a Friction.

    Raises
    ------
    SolverError
        ``obj`` has no ``static`` attribute, or a tolerance is not a real number.
    """
    if isinstance(obj, Friction):
        return obj._fields
    try:
        static = obj.static
    except AttributeError:
        raise SolverError(
            "friction must be None, True or a vereshchagin.Friction(static=..., kinetic=..., velocity_tolerance=...)"
        ) from None
    rest = [getattr(obj, name, None) for name in _FIELD_NAMES[1:]]
    return _fields_of(static, *rest)


class _Field(property):
    """A field of Friction, kept in the instance dict. Setting it (the constructor, or
    ``object.__setattr__`` past the frozen guard) drops the cached ``_fields``, so that the next
    solve reads the new value; a solver reuses what it parsed while ``_fields`` is the same tuple.
    A property, as which type checkers and documentation tools see it; on the class it is the
    field's default, as the dataclass had it (no default: no class attribute)."""

    def __init__(self, name: str, default):
        def get(obj):
            return obj.__dict__.get(name, default)

        def put(obj, value) -> None:
            obj.__dict__[name] = value
            obj.__dict__.pop("_fields", None)

        super().__init__(get, put)
        self.name = name
        self.default = default

    def __get__(self, obj, owner=None):
        if obj is not None:
            return super().__get__(obj, owner)
        if self.default is _Field:
            raise AttributeError(self.name)
        return self.default


@dataclass(frozen=True)
class Friction:
    """Per-joint friction for ``Solver.solve(..., friction=Friction(...))``.

    Immutable: the arrays are stored as float64 copies that cannot be written (views of immutable
    bytes: ``flags.writeable`` cannot be switched back on), so a solver may reuse a parsed
    ``Friction`` across calls (pass the same object in a control loop). A solver reparses it if
    an attribute was replaced (``object.__setattr__``).

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
    max_iterations : int
        Real-time bound on the active-set iterations of each friction optimisation stage of one
        solve, at the instant and over a step: -1 (default) for 6 k + 16 (k the joints whose
        friction is unknown), 0 for the exhaustive bound 5 (k + 1) 3^k + 4, or a positive count.
        At the bound the solve returns the documented fallback (friction torques within their
        bounds that do no positive work in sum; docs/friction.md, "Real-time bound") and warns
        with a ``RuntimeWarning``.

    Raises
    ------
    SolverError
        Non-numeric or non-1-D arrays, NaN (or Inf in ``static``/``kinetic``), a
        ``max_iterations`` that is not an int >= -1. Sizes and signs are checked against the chain
        by the solve.
    """

    static: np.ndarray
    kinetic: Optional[np.ndarray] = None
    velocity_tolerance: float = 1e-6
    lower: Optional[np.ndarray] = None
    upper: Optional[np.ndarray] = None
    limit_tolerance: float = 1e-9
    max_iterations: int = -1

    def __post_init__(self):
        object.__setattr__(self, "static", _frozen_vector(self.static, "static"))
        object.__setattr__(self, "kinetic", _frozen_vector(self.kinetic, "kinetic"))
        object.__setattr__(self, "lower", _frozen_vector(self.lower, "lower", allow_inf=True))
        object.__setattr__(self, "upper", _frozen_vector(self.upper, "upper", allow_inf=True))

    def _values(self) -> tuple:
        """The field values in ``_FIELD_NAMES`` order (the constructor's argument order)."""
        return tuple(getattr(self, name) for name in _FIELD_NAMES)

    @cached_property
    def _fields(self) -> tuple:
        """What solvers read (``_fields_of``), cached until a field is replaced."""
        return _fields_of(*self._values())

    def __reduce__(self):
        # Rebuilt through the constructor, so copies and unpickled objects stay read-only.
        return (Friction, self._values())


# The fields become _Field descriptors once the dataclass has made its methods (whose defaults stay
# those above).
for _name in _FIELD_NAMES:
    setattr(Friction, _name, _Field(_name, Friction.__dict__.get(_name, _Field)))
