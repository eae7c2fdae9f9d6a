"""The Python Simulator: a state (q, qd, t) advanced by the C++ velocity-level step, and rollouts."""

from __future__ import annotations

import numpy as np

from . import _core
from .solver import Solver

# What rollout(record=...) can record per step, besides the states t, q, qd.
_RECORDABLE = ("tau_command", "friction_torque", "contact_force", "status")
# Arguments of Solver.solve that the simulator sets itself.
_OWN_ARGS = frozenset(("q", "qd", "time_step", "out"))
# The integrators (C++: vereshchagin::Integrator).
_INTEGRATORS = ("semi_implicit_euler", "symplectic")


def _check_dt(dt) -> float:
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating, np.integer)):
        raise _core.SolverError(f"Simulator: dt must be a number > 0 (s), got {dt!r}")
    if not (np.isfinite(dt) and dt > 0.0):
        raise _core.SolverError(f"Simulator: dt must be finite and > 0 (s), got {dt!r}")
    return float(dt)


def _state(value, n: int, name: str) -> np.ndarray:
    v = np.array(value, dtype=np.float64)  # a copy: the caller's array is not tied to the state
    if v.shape != (n,):
        raise _core.SolverError(f"Simulator: {name} must have shape ({n},), got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise _core.SolverError(f"Simulator: {name} contains NaN or Inf")
    return v


class Simulator:
    """A robot simulated on the exact velocity-level step (docs: "Friction in discrete time", "Simulator").

    It owns a :class:`Solver`, the time step ``dt`` and the state ``(q, qd, t)``. Each
    :meth:`step` is the C++ ``step()`` (what :meth:`Solver.step` calls): the solve over the step
    with friction, joint limits and contacts on the end velocities, then semi-implicit Euler
    (``qd_next = qd + dt qdd``, exactly 0 for a joint friction holds; ``q_next = q + dt qd_next``).
    Nothing but ``(q, qd, t)`` carries from one step to the next.

    Parameters
    ----------
    model : Chain or Tree
        Copied (as by :class:`Solver`).
    dt : float
        The time step, s, finite and > 0.
    gravity, rcond, damping, inertia_check, max_constraints
        As in :class:`Solver`.
    q, qd : array_like, shape (n,), optional
        The initial state (default: zeros), rad or m and rad/s or m/s. On a floating base
        (``Tree.from_urdf(..., base='free' | 'planar')``, docs/floating-base.md) q has ``nq``
        entries and qd ``nv``, the base's first (default: the base at the world origin,
        unrotated); each step moves the base on SE(3) (SE(2)) by its LOCAL twist,
        ``q_next = model.integrate(q, dt * qd_next)``, as ``pin.integrate`` (both integrators).
    t : float
        The initial time, s (default 0).
    integrator : str
        ``"semi_implicit_euler"`` (default, C++ ``Integrator::SemiImplicitEuler``): the velocity
        terms at the start of the step, friction, limits and contacts at its end. ``"symplectic"``
        (C++ ``Integrator::Symplectic``, ``stepSymplectic()``): symplectic Euler in momentum form,
        ``H(q) qd_next = p + dt (tau - g(q) + dT/dq(q, qd_next))`` plus the impulses, solved by
        fixed-point iteration (each iteration one exact solve; one at rest); it carries the
        momentum :attr:`momentum`, and its passive energy error stays bounded where semi-implicit
        Euler gains energy (docs: "Friction in discrete time", "Passive energy").

    Raises
    ------
    SolverError
        A ``dt`` that is not a finite number > 0, an unknown integrator, a state of the wrong shape
        or not finite, or what :class:`Solver` raises.
    """

    def __init__(
        self,
        model,
        dt,
        *,
        gravity=(0.0, 0.0, -9.81),
        rcond=1e-12,
        damping=None,
        inertia_check=None,
        max_constraints=None,
        q=None,
        qd=None,
        t=0.0,
        integrator="semi_implicit_euler",
    ):
        if integrator not in _INTEGRATORS:
            raise _core.SolverError(f"Simulator: integrator must be one of {_INTEGRATORS}, got {integrator!r}")
        self._integrator = integrator
        self._dt = _check_dt(dt)
        self._solver = Solver(model, gravity, rcond, damping, inertia_check, max_constraints)
        self._model = self._solver.model  # the momentum H(q) qd at reset (symplectic), integrate
        self._base = getattr(self._model, "base", "fixed")
        nv = self._solver.n_joints  # nv: the base's entries first on a floating base
        nq = getattr(self._model, "nq", nv)
        if q is None:  # at rest, a floating base at the world origin, unrotated
            q = np.zeros(nq)
            if self._base != "fixed":
                q[6 if self._base == "free" else 2] = 1.0  # the quaternion's w, or cos(yaw)
        self.reset(q, np.zeros(nv) if qd is None else qd, t)

    def reset(self, q, qd, t=0.0):
        """Sets the state: positions ``q`` (rad or m), velocities ``qd`` (rad/s or m/s), time ``t`` (s).

        Raises
        ------
        SolverError
            ``q`` or ``qd`` not of shape (n,) or not finite, or ``t`` not a finite number; the state
            is then unchanged.
        """
        n = self._solver.n_joints
        q, qd = _state(q, getattr(self._model, "nq", n), "q"), _state(qd, n, "qd")
        if isinstance(t, bool) or not isinstance(t, (int, float, np.floating, np.integer)) or not np.isfinite(t):
            raise _core.SolverError(f"Simulator: t must be a finite number (s), got {t!r}")
        self._q, self._qd, self._t0, self._steps = q, qd, float(t), 0
        self._p = self._model.mass_matrix(q) @ qd if self._integrator == "symplectic" else None

    def step(self, **solve_args):
        """Advances the state by one step and returns the step's :class:`SolveResult`.

        Parameters
        ----------
        **solve_args
            What :meth:`Solver.solve` takes besides the state and the time step: ``tau_ff``,
            ``friction``, ``contacts``, a task (``alpha``, ``beta``, ``a_desired``,
            ``constraints``), ``f_ext``, pass-through weights, ``contact_velocity_tolerance``,
            ``contact_max_pivots``.

        Returns
        -------
        SolveResult
            The solve over the step: ``qdd`` the step's mean acceleration; ``friction_torque``,
            ``limit_torque``, ``contact_force`` the impulses over ``dt``; ``status`` 1 for a joint
            that ends the step at rest.

        Raises
        ------
        SolverError
            ``q``, ``qd``, ``time_step`` or ``out`` given (the simulator's own), or what
            :meth:`Solver.solve` raises; the state is then unchanged.
        """
        if _OWN_ARGS.intersection(solve_args):
            self._check_own(solve_args)
        return self._advance(solve_args)

    def _advance(self, args):
        if self._p is None:  # C++ step(): q (+) dt qd_next on a floating base too
            self._q, self._qd, result = self._solver.step(self._q, self._qd, self._dt, **args)
        else:
            step = self._solver._step_symplectic
            self._q, self._qd, self._p, result = step(self._q, self._qd, time_step=self._dt, out=self._p, **args)
        self._steps += 1
        return result

    def rollout(self, n_steps, controller=None, record=(), **solve_args):
        """Runs ``n_steps`` steps and returns their record.

        Parameters
        ----------
        n_steps : int
            Steps, >= 0.
        controller : callable, optional
            ``controller(t, q, qd) -> dict`` called before each step with the state at its start
            (copies); the dict's solve arguments (as :meth:`step` takes them) update the constant
            ``solve_args`` for that step (``None`` returned: the constant ones). None: every step
            with ``solve_args``.
        record : sequence of str
            Step outputs to record besides the states: ``"tau_command"``, ``"friction_torque"``
            (zeros in a step without friction), ``"contact_force"``, ``"status"`` (0 in a step
            without friction).
        **solve_args
            Solve arguments of every step (see :meth:`step`).

        Returns
        -------
        dict of ndarray
            ``t`` (n_steps + 1,), ``q``, ``qd`` (n_steps + 1, n): row 0 the start, row k the state
            after k steps; per recorded output n_steps rows: ``tau_command``, ``friction_torque``
            (n_steps, n), ``contact_force`` (n_steps, k, 3), ``status`` (n_steps, n) int32.
            Row k of an output is step k's, exactly what :meth:`step` returned.

        Raises
        ------
        SolverError
            A bad ``n_steps``, ``record`` name or ``controller``, or a failing step (the state is
            then the last good one; the record is lost).
        """
        if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or n_steps < 0:
            raise _core.SolverError(f"Simulator.rollout: n_steps must be an int >= 0, got {n_steps!r}")
        record = (record,) if isinstance(record, str) else tuple(record)
        unknown = [r for r in record if r not in _RECORDABLE]
        if unknown:
            raise _core.SolverError(f"Simulator.rollout: record names {unknown}; it can record {_RECORDABLE}")
        if controller is not None and not callable(controller):
            raise _core.SolverError("Simulator.rollout: controller must be a callable (t, q, qd) -> dict, or None")
        self._check_own(solve_args)
        n, dt = self._solver.n_joints, self._dt
        q_out, qd_out = np.empty((n_steps + 1, self._q.size)), np.empty((n_steps + 1, n))
        q_out[0], qd_out[0], first = self._q, self._qd, self._steps
        rows = {name: [] for name in record}
        for k in range(n_steps):
            args = solve_args if controller is None else self._controller_args(controller, solve_args)
            result = self._advance(args)
            q_out[k + 1], qd_out[k + 1] = self._q, self._qd
            for name in record:
                rows[name].append(getattr(result, name))
        t = self._t0 + np.arange(first, first + n_steps + 1) * dt  # as the property t: t0 + steps dt
        out = {"t": t, "q": q_out, "qd": qd_out}
        for name in record:
            out[name] = self._stack(rows[name], name, n)
        return out

    @staticmethod
    def _check_own(solve_args):
        if _OWN_ARGS.intersection(solve_args):
            own = ", ".join(sorted(_OWN_ARGS.intersection(solve_args)))
            raise _core.SolverError(f"Simulator: {own} are the simulator's own (use reset())")

    def _controller_args(self, controller, constant):
        args = controller(self.t, self._q.copy(), self._qd.copy())
        if args is None:
            return constant
        if not isinstance(args, dict):
            raise _core.SolverError(f"Simulator.rollout: the controller must return a dict, got {type(args).__name__}")
        self._check_own(args)
        return {**constant, **args}

    @staticmethod
    def _stack(rows, name, n):
        if rows and any(r is None for r in rows):  # steps without friction: zero torques, status 0
            dtype = np.int32 if name == "status" else np.float64
            rows = [np.zeros(n, dtype=dtype) if r is None else r for r in rows]
        if rows:
            return np.stack(rows)
        if name == "contact_force":
            return np.empty((0, 0, 3))
        return np.empty((0, n), dtype=np.int32 if name == "status" else np.float64)

    @property
    def q(self) -> np.ndarray:
        """Joint positions at the current time, rad or m (a copy)."""
        return self._q.copy()

    @property
    def qd(self) -> np.ndarray:
        """Joint velocities at the current time, rad/s or m/s (a copy)."""
        return self._qd.copy()

    @property
    def momentum(self):
        """The symplectic integrator's momentum ``p`` (N m s or N s, a copy), None for the other.

        ``H(q) qd`` after :meth:`reset`; after a step ``H(q_prev) qd``, the momentum the step left
        (``qd`` is the step's velocity, the one that moved ``q``); ``H(q)^-1 p`` is the velocity of
        the momentum state (the energy a symplectic step keeps bounded is the one of ``(q, H(q)^-1 p)``).
        """
        return None if self._p is None else self._p.copy()

    @property
    def t(self) -> float:
        """The current time, s: the t of the last reset plus dt times the steps since."""
        return self._t0 + self._steps * self._dt

    @property
    def dt(self) -> float:
        """The time step, s."""
        return self._dt

    @property
    def integrator(self) -> str:
        """The integrator's name (see the class description)."""
        return self._integrator

    @property
    def solver(self) -> Solver:
        """The simulator's Solver (its model, gravity, options)."""
        return self._solver
