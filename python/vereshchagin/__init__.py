"""Popov-Vereshchagin constrained hybrid dynamics for robot arms.

Build a :class:`Chain`, wrap it in a :class:`Solver` and call :meth:`Solver.solve` with joint
positions, velocities and an optional partial task (``alpha``, ``beta``), external wrenches and
feed-forward torques. Conventions (frames, signs, units) are those of Orocos KDL's
``ChainHdSolver_Vereshchagin``; see :class:`Solver`. Branched robots load as a :class:`Tree`
(``Tree.from_urdf``).
"""

from ._core import Chain, Joint, SolveResult, SolverError, Tree
from . import _models, _results, robots, task, whole_body  # noqa: F401 (_models, _results: members in Python)
from ._version import __version__ as __version__  # written once: CMakeLists.txt
from .contacts import Contact, ContactOutcome, ContactStatus
from .friction import Friction
from .kdl_interop import chain_from_kdl as _chain_from_kdl, chain_to_kdl as _chain_to_kdl
from .simulator import Simulator
from .solver import BatchResult, Solver


def _to_kdl(self: Chain):
    """This chain as a PyKDL ``Chain`` (see :func:`vereshchagin.kdl_interop.chain_to_kdl`).

    Returns
    -------
    PyKDL.Chain
        Segments with names, joints, tip frames at joint position 0 and inertias.

    Raises
    ------
    ImportError
        PyKDL is not importable.
    """
    return _chain_to_kdl(self)


# PyKDL interoperability (kdl_interop.py), attached to the compiled class (its stub declares both;
# setattr because a type checker rejects assigning to a declared method).
setattr(Chain, "from_kdl", staticmethod(_chain_from_kdl))  # noqa: B010
setattr(Chain, "to_kdl", _to_kdl)  # noqa: B010

__all__ = [
    "BatchResult",
    "Chain",
    "Contact",
    "ContactOutcome",
    "ContactStatus",
    "Friction",
    "Joint",
    "Simulator",
    "SolveResult",
    "Solver",
    "SolverError",
    "Tree",
    "robots",
    "task",
]
