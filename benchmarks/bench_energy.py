#!/usr/bin/env python3
"""Passive energy: how much energy each integrator gains or loses on a frictionless swinging arm.

The Kinova Gen3 7-DoF (``vereshchagin.robots.gen3_urdf(gripper=False, use_external_cable=True)``),
loaded by us, by Pinocchio (the energy meter) and by MuJoCo (``MjSpec`` of the same URDF: no
collisions, no joint limits, no damping, no armature, ``frictionloss`` 0), falls from the contact
experiments' start pose (``vereshchagin.robots.GEN3_START_POSE``) with 0.5 rad/s at every joint,
no motor torques, 2 s. The light distal joints spin up to over 100 rad/s, the hard case for a
first-order step.

Integrators, each at dt = 1 ms and 0.1 ms:
  ours, semi-implicit     ``Solver.step``: qd+ = qd + dt qdd(q, qd), q+ = q + dt qd+
  ours, symplectic        ``Simulator(..., integrator="symplectic")``: symplectic Euler in momentum
                          form (docs/time-step.md, "Passive energy")
  RK4 (reference)         classical Runge-Kutta on ``Solver.solve``'s qdd
  MuJoCo Euler / implicitfast / implicit / RK4   ``mj_step`` with ``option.integrator`` set

The energy of every state is measured the same way: Pinocchio's kinetic plus potential energy
of (q, qd) (for the symplectic step, qd = H(q)^-1 p, the velocity of its momentum state).
Reported: E0, E after 2 s, the largest E - E0 and the largest |E - E0| / E0.

Usage: python benchmarks/bench_energy.py [--out FILE] [--seconds S]
Markdown to stdout (and FILE). Exit code 2 if the symplectic step's energy error exceeds 10 % of
E0 at 1 ms or semi-implicit Euler does not gain more than it (the behaviour docs/time-step.md
states).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

import vereshchagin as vs
from vereshchagin.robots import GEN3_START_POSE

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_hold_creep import G, Models  # noqa: E402
from bench_output import publish  # noqa: E402

V0 = 0.5  # rad/s at every joint


class Arm(Models):
    """The Gen3 of the hold test (ours, Pinocchio), its swing's start state and the energy meter."""

    def __init__(self):
        super().__init__()
        self.q0 = np.array(GEN3_START_POSE, dtype=float)
        self.v0 = np.full(7, V0)

    def energy(self, q, v):
        return pin.computeKineticEnergy(self.pin, self.data, q, v) + pin.computePotentialEnergy(self.pin, self.data, q)

    def velocity_of_momentum(self, q, p):
        M = pin.crba(self.pin, self.data, q)
        M = np.triu(M) + np.triu(M, 1).T
        return np.linalg.solve(M, p)


def run_semi_implicit(arm, dt, steps):
    q, v = arm.q0.copy(), arm.v0.copy()
    for _ in range(steps):
        q, v, _ = arm.solver.step(q, v, dt)
        yield q, v


def run_symplectic(arm, dt, steps):
    sim = vs.Simulator(arm.chain, dt, gravity=G, integrator="symplectic")
    sim.reset(arm.q0, arm.v0)
    for _ in range(steps):
        sim.step()
        yield sim.q, arm.velocity_of_momentum(sim.q, sim.momentum)


def run_rk4(arm, dt, steps):
    def f(q, v):
        return v, arm.solver.solve(q, v).qdd

    q, v = arm.q0.copy(), arm.v0.copy()
    for _ in range(steps):
        k1 = f(q, v)
        k2 = f(q + dt / 2 * k1[0], v + dt / 2 * k1[1])
        k3 = f(q + dt / 2 * k2[0], v + dt / 2 * k2[1])
        k4 = f(q + dt * k3[0], v + dt * k3[1])
        q = q + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        yield q, v


def mujoco_model(arm, dt, integrator):
    spec = mujoco.MjSpec.from_string(arm.urdf)
    spec.option.timestep = dt
    spec.option.gravity = G
    spec.option.integrator = integrator
    for g in spec.geoms:
        g.contype = g.conaffinity = 0
    for name in arm.chain.joint_names:  # our swing has no joint limits (Solver without friction=)
        spec.joint(name).limited = mujoco.mjtLimited.mjLIMITED_FALSE
    m = spec.compile()
    assert [m.joint(i).name for i in range(m.njnt)] == list(arm.chain.joint_names)
    for field in (m.dof_damping, m.dof_armature, m.dof_frictionloss):
        assert not field.any(), "the URDF gives MuJoCo damping, armature or friction"
    return m


def run_mujoco(arm, dt, steps, integrator):
    m = mujoco_model(arm, dt, integrator)
    d = mujoco.MjData(m)
    d.qpos[:] = arm.q0
    d.qvel[:] = arm.v0
    for _ in range(steps):
        mujoco.mj_step(m, d)
        yield d.qpos.copy(), d.qvel.copy()


RUNS = {
    "ours, semi-implicit (`Solver.step`)": run_semi_implicit,
    'ours, symplectic (`Simulator`, `integrator="symplectic"`)': run_symplectic,
    "RK4 on `Solver.solve` (reference)": run_rk4,
    "MuJoCo Euler": lambda a, dt, n: run_mujoco(a, dt, n, mujoco.mjtIntegrator.mjINT_EULER),
    "MuJoCo implicitfast": lambda a, dt, n: run_mujoco(a, dt, n, mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
    "MuJoCo implicit": lambda a, dt, n: run_mujoco(a, dt, n, mujoco.mjtIntegrator.mjINT_IMPLICIT),
    "MuJoCo RK4": lambda a, dt, n: run_mujoco(a, dt, n, mujoco.mjtIntegrator.mjINT_RK4),
}


def measure(arm, run, dt, seconds):
    steps = int(round(seconds / dt))
    E0 = arm.energy(arm.q0, arm.v0)
    worst_gain, worst_abs, E, vmax = 0.0, 0.0, E0, 0.0
    t0 = time.perf_counter()
    for q, v in run(arm, dt, steps):
        E = arm.energy(q, v)
        worst_gain = max(worst_gain, E - E0)
        worst_abs = max(worst_abs, abs(E - E0))
        vmax = max(vmax, float(np.abs(v).max()))
    return dict(E0=E0, E=E, gain=worst_gain, rel=worst_abs / E0, vmax=vmax, wall=time.perf_counter() - t0)


def report(results, seconds):
    lines = [
        "## Passive energy: a frictionless Gen3 swinging for %g s" % seconds,
        "",
        "`benchmarks/bench_energy.py`; mujoco %s, pinocchio %s. The Gen3 from the start pose with 0.5 rad/s"
        " at every joint, no torques, no friction; energy (kinetic + potential, Pinocchio's) of every"
        " state. E0 = %.3f J." % (mujoco.__version__, pin.__version__, next(iter(results.values()))["E0"]),
        "",
        "| integrator | dt | E after %g s [J] | largest gain E - E0 [J] | largest \\|E - E0\\| / E0 | largest \\|qd\\| [rad/s] |"
        % seconds,
        "|---|---|---|---|---|---|",
    ]
    for (name, dt), r in results.items():
        lines.append(
            f"| {name} | {dt * 1e3:g} ms | {r['E']:.3f} | {r['gain']:.3f} | {100 * r['rel']:.2f} % | {r['vmax']:.1f} |"
        )
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--seconds", type=float, default=2.0)
    args = ap.parse_args()
    arm = Arm()
    results = {}
    for dt in (1e-3, 1e-4):
        for name, run in RUNS.items():
            if dt < 1e-3 and name.startswith("RK4"):
                continue  # the reference at 1 ms is already converged to 1e-5 J
            print(f"{name} dt={dt}", file=sys.stderr, flush=True)
            results[(name, dt)] = measure(arm, run, dt, args.seconds)
    text = report(results, args.seconds)
    publish(text, args.out)
    sym = results[('ours, symplectic (`Simulator`, `integrator="symplectic"`)', 1e-3)]
    semi = results[("ours, semi-implicit (`Solver.step`)", 1e-3)]
    return 0 if sym["rel"] < 0.10 and semi["gain"] > sym["gain"] else 2


if __name__ == "__main__":
    sys.exit(main())
