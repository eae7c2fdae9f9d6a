"""Per-joint effort metrics and task outcomes of a :class:`~.use_cases.Run`.

For the samples of a window (sample period dt = 1 ms), per joint j:

- ``mean_tau``: average torque (N m), signed, as Table 6.2 of W. K. Lau (2023);
- ``mean_abs_tau``: average |torque| (N m);
- ``mean_power``: average mechanical power tau * qd (W), signed (negative: the joint brakes);
- ``energy_abs``: integral of |tau * qd| dt (J), the mechanical work the motor moves in either
  direction (no regeneration credited);
- ``energy_tau2``: integral of tau^2 dt (N^2 m^2 s). Copper-loss proxy: with motor current
  i = tau / (k_t * gear) the winding loss is R i^2, so the dissipated energy is
  ``R / (k_t * gear)^2 * energy_tau2``; Kinova publishes no R or k_t, so the constant is left
  out and only ratios between cases are meaningful.

Torque is the motor torque the plant applied (after saturation), qd the measured velocity.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["STROKE_END", "dual_arm_outcome", "effort", "elbow_outcome", "grasp_outcome", "writing_accuracy"]


def effort(run, mask=None) -> dict:
    """Effort metrics (see module doc) over some samples of a run.

    Parameters
    ----------
    run : Run
        The run (k samples, n joints).
    mask : array_like of bool, shape (k,), optional
        Samples to use (e.g. ``run.window("slide")``); None: all.

    Returns
    -------
    dict
        ``mean_tau``, ``mean_abs_tau`` (N m), ``mean_power`` (W), ``energy_abs`` (J),
        ``energy_tau2`` (N^2 m^2 s): ndarrays of shape (n,); ``duration``: the masked time (s).
    """
    m = np.ones(len(run.t), bool) if mask is None else np.asarray(mask, bool)
    tau, qd = run.tau[m], run.qd[m]
    dt = float(np.median(np.diff(run.t))) if len(run.t) > 1 else 1e-3
    p = tau * qd
    return dict(
        mean_tau=tau.mean(0),
        mean_abs_tau=np.abs(tau).mean(0),
        mean_power=p.mean(0),
        energy_abs=np.abs(p).sum(0) * dt,
        energy_tau2=(tau**2).sum(0) * dt,
        duration=m.sum() * dt,
    )


def grasp_outcome(run, phase: str = "slide") -> dict:
    """Outcome of a grasp run over its ``phase`` (the tool's contact point, base frame).

    Parameters
    ----------
    run : Run
        A :func:`~.use_cases.grasp` run.
    phase : str
        The sliding phase's name.

    Returns
    -------
    dict
        ``contact_detected`` (bool) and ``contact_time`` (s or None); ``distance_x``: the tool's
        x travel over the phase (m, + towards +x); ``contact_fraction``: share of the phase's
        samples with a table force; ``touched``: arm geoms that touched the table;
        ``final_error_x``: final x minus the goal (start x + 0.10 m), m; ``final_drift_yz``:
        distance the tool left the line in y and z (m); ``mean_table_force``: N.
    """
    m = run.window(phase)
    tool = run.tool[m]
    touching = run.table_force[m] > 0.0
    goal_x = tool[0, 0] + 0.10
    return dict(
        contact_detected=run.contact_time is not None,
        contact_time=run.contact_time,
        distance_x=float(tool[-1, 0] - tool[0, 0]),
        contact_fraction=float(touching.mean()),
        touched=list(run.table_touch),
        final_error_x=float(tool[-1, 0] - goal_x),
        final_drift_yz=float(np.hypot(tool[-1, 1] - tool[0, 1], tool[-1, 2] - tool[0, 2])),
        mean_table_force=float(run.table_force[m].mean()),
    )


STROKE_END = 0.005
"""m: the last part of the 0.10 m line counted as the stroke's end (stopping and standing still)."""


def writing_accuracy(run, phase: str = "write") -> dict:
    """Displacement of the pen tip in y from the reference line (y = y at the start, along +x).

    Parameters
    ----------
    run : Run
        A :func:`~.use_cases.writing` run.
    phase : str
        The drawing phase's name.

    Returns
    -------
    dict
        ``max_displacement``: max |dy| and ``mean_displacement``: signed mean dy (m, base y) over
        the drawn part (x between the start and start + 0.10 m), as Table 6.3 of W. K. Lau (2023);
        NaN if nothing was drawn; ``length``: final x minus start x (m); ``contact_fraction``:
        share of the drawn samples in which the plant reports table contact. The same over the
        stroke without its end (x below start + 0.10 m - :data:`STROKE_END`, where the pen still
        moves): ``max_displacement_stroke``, ``mean_displacement_stroke`` (m, NaN if none);
        ``max_at``: x of the largest |dy| from the start (m).
    """
    m = run.window(phase)
    tool = run.tool[m]
    x0, y0 = tool[0, 0], tool[0, 1]
    drawn = (tool[:, 0] >= x0 + 1e-4) & (tool[:, 0] <= x0 + 0.10)
    dy = tool[drawn, 1] - y0
    stroke = tool[drawn, 0] < x0 + 0.10 - STROKE_END
    nan = float("nan")
    return dict(
        max_displacement=float(np.abs(dy).max()) if dy.size else nan,
        mean_displacement=float(dy.mean()) if dy.size else nan,
        length=float(tool[-1, 0] - x0),
        contact_fraction=float((run.table_force[m][drawn] > 0).mean()) if dy.size else 0.0,
        max_displacement_stroke=float(np.abs(dy[stroke]).max()) if stroke.any() else nan,
        mean_displacement_stroke=float(dy[stroke].mean()) if stroke.any() else nan,
        max_at=float(tool[drawn, 0][np.argmax(np.abs(dy))] - x0) if dy.size else nan,
    )


def elbow_outcome(run, phase: str = "slide", dx: float = -0.10) -> dict:
    """Task and support outcome of a resting-elbow run (:mod:`.elbow`).

    ``final_error_x``: end-effector x at the end of the run minus its goal (x at the start of
    ``phase`` + ``dx``), m; ``drift_z``: end-effector z change over the run, m;
    ``support_fraction``: share of the ``phase`` samples in which the plant's support pushes;
    ``support_force``: its mean normal force over ``phase`` (N); ``model_support_force``: the
    solver's mean constraint force ``-nu_e`` over ``phase`` (N, NaN without the constraint).
    """
    m = run.window(phase)
    model = np.asarray(run.info.get("support_force_model", np.full(len(run.t), np.nan)))[m]
    return dict(
        final_error_x=float(run.tip[-1, 0] - (run.tip[m][0, 0] + dx)),
        drift_z=float(run.tip[-1, 2] - run.tip[0, 2]),
        support_fraction=float((run.support_force[m] > 0.0).mean()),
        support_force=float(run.support_force[m].mean()),
        model_support_force=float(model.mean()) if np.all(np.isfinite(model)) else float("nan"),
    )


def dual_arm_outcome(run, phase: str = "slide", dx: float = 0.10) -> dict:
    """Task, table and open-loop outcome of a dual-arm run (:mod:`.dual_arm`).

    Parameters
    ----------
    run : Run
        A :func:`~.dual_arm.dual_arm` run.
    phase : str
        The sliding phase's name.
    dx : float
        The sliding hand's travel along base x (m).

    Returns
    -------
    dict
        Closed loop (plant): ``final_error_x`` the sliding hand's x at the end minus its goal (x
        at the start of ``phase`` + ``dx``, m); ``max_off_line`` its largest distance from the
        line along x through its start (y and z, m) from ``phase`` on; ``rest_drift`` the largest
        displacement of the resting hand's frame from its start (m); ``table_fraction`` the share
        of ``phase`` samples with a table force; ``table_force`` / ``table_force_model`` the mean
        table force over ``phase`` in the plant / the model's upward share (N). Open loop, over all
        samples, per hand (``rest``, ``task``): ``open_loop_rms`` / ``open_loop_max`` of the
        linear rows (m/s^2), ``open_loop_ang_rms`` / ``open_loop_ang_max`` of the angular rows
        (rad/s^2).
    """
    m = run.window(phase)
    start = np.argmax(m)
    after = np.arange(len(run.t)) >= start
    tip = run.tip
    off = np.hypot(tip[after, 1] - tip[start, 1], tip[after, 2] - tip[start, 2])
    rest = np.asarray(run.info["rest"])
    out: dict[str, Any] = dict(
        final_error_x=float(tip[-1, 0] - (tip[start, 0] + dx)),
        max_off_line=float(off.max()),
        rest_drift=float(np.linalg.norm(rest - rest[0], axis=1).max()),
        table_fraction=float((run.table_force[m] > 0.0).mean()),
        table_force=float(run.table_force[m].mean()),
        table_force_model=float(np.asarray(run.info["table_force_model"])[m].mean()),
    )
    for key, rows in (("open_loop", run.info["open_loop"]), ("open_loop_ang", run.info["open_loop_ang"])):
        rows = np.asarray(rows)
        out[key + "_rms"] = dict(zip(("rest", "task"), np.sqrt(np.mean(rows**2, axis=0)).tolist()))
        out[key + "_max"] = dict(zip(("rest", "task"), rows.max(axis=0).tolist()))
    return out
