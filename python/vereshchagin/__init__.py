"""Popov-Vereshchagin constrained hybrid dynamics for robot arms.

Build a :class:`Chain`, wrap it in a :class:`Solver` and call :meth:`Solver.solve` with joint
positions, velocities and an optional partial task (``alpha``, ``beta``), external wrenches and
feed-forward torques. Conventions (frames, signs, units) are those of Orocos KDL's
``ChainHdSolver_Vereshchagin``; see :class:`Solver`.
"""
from ._core import Chain, Joint, SolveResult, SolverError
from . import robots, task
from .friction import Friction
from .solver import BatchResult, Solver

__all__ = ["BatchResult", "Chain", "Friction", "Joint", "SolveResult", "Solver", "SolverError", "robots", "task"]
from ._version import __version__ as __version__  # written once: CMakeLists.txt
