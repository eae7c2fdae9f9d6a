"""The seam between a control loop and a robot: what the loop may read and write each cycle.

A backend (the MuJoCo plant in :mod:`.mujoco_plant`, later a driver of the real Kinova Gen3 such
as robif2b's ``kinova_gen3`` ports of W. K. Lau (2023), Listing 5.1) implements :class:`RobotInterface`.
The loop in :mod:`.use_cases` uses nothing else, so it runs unchanged against any backend.

Contract
--------
- ``n_joints``: number of actuated joints, ordered as the controller's chain (base to tip).
- ``period``: control period in s (1e-3 for the Gen3's 1 kHz low-level servoing).
- ``read()`` -> :class:`JointState`: measured joint positions (rad), velocities (rad/s), joint
  torques (N m; for the simulator the motor torque actually applied after saturation) and the
  robot clock (s) at the sample.
- ``write(tau)``: joint torque command (N m), shape (n_joints,), held for one period. Backends
  saturate at their effort limits; the applied value is what the next ``read()`` reports.
- ``wait()``: block until the next cycle (simulator: advance the physics by one period; real
  robot: exchange the command and wait for the next sample).
- ``set_gripper(position)``: optional gripper command, 0 (open) .. 1 (closed); backends without a
  gripper record it only.

Nothing in the interface exposes the backend's internals; diagnostics only a simulator can give
(contact forces, which bodies touch) live on the backend class itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["JointState", "RobotInterface"]


@dataclass(frozen=True)
class JointState:
    """One sample of the robot's joints.

    Attributes
    ----------
    q, qd, tau : ndarray, shape (n,)
        Positions (rad), velocities (rad/s), joint torques (N m).
    time : float
        Robot clock at the sample (s).
    """

    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    time: float


@runtime_checkable
class RobotInterface(Protocol):
    """Read joints, write torques, keep time: everything the control loop needs (see module doc)."""

    n_joints: int
    period: float

    def read(self) -> JointState:
        """The latest joint sample."""
        ...

    def write(self, tau) -> None:
        """Command joint torques (N m) for the next period."""
        ...

    def wait(self) -> None:
        """Advance to the next control cycle."""
        ...

    def set_gripper(self, position: float) -> None:
        """Gripper command, 0 = open .. 1 = closed."""
        ...
