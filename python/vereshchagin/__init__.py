"""Popov-Vereshchagin constrained hybrid dynamics for robot arms.

Build a :class:`Chain`, wrap it in a :class:`Solver` and call :meth:`Solver.solve` with joint
positions, velocities and an optional partial task (``alpha``, ``beta``), external wrenches and
feed-forward torques. Conventions (frames, signs, units) are those of Orocos KDL's
``ChainHdSolver_Vereshchagin``; see :class:`Solver`.
"""
from ._core import Chain, Joint, SolveResult, SolverError
from . import robots, task
from ._version import __version__ as __version__  # written once: CMakeLists.txt
from .friction import Friction
from .kdl_interop import chain_from_kdl as _chain_from_kdl, chain_to_kdl as _chain_to_kdl
from .solver import BatchResult, Solver

# PyKDL interoperability (kdl_interop.py), attached to the compiled class.
Chain.from_kdl = staticmethod(_chain_from_kdl)  # type: ignore[method-assign]
Chain.to_kdl = _chain_to_kdl  # type: ignore[method-assign,assignment]

__all__ = ["BatchResult", "Chain", "Friction", "Joint", "SolveResult", "Solver", "SolverError", "robots", "task"]
