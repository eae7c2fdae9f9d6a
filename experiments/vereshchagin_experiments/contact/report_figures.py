"""Figures of the contact report (PNG): one question per panel, at most three traces per panel.

Joints are counted from 0 as in W. K. Lau (2023) (joint 1 shoulder, 3 elbow, 5 wrist); each
variant (contact, contactless, ...) keeps one colour in every panel, and one legend per figure
sits below the panels, outside the data. Where a table is in the scene it is drawn (brown band
below its surface), heights are given above it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

from .lau2023 import KEY_JOINTS
from .metrics import STROKE_END
from .mujoco_plant import PEN_RADIUS

__all__ = ["plot_effort", "plot_grasp_path", "plot_writing"]

TABLE_COLOUR = "#a0724a"


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _finish(fig, path: Path, handles, labels, ncol: int) -> None:
    """One legend below the panels (outside the data), then save and close."""
    fig.legend(handles, labels, loc="lower center", ncol=ncol, fontsize=9, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(fig)


def _draw_table(ax, label: bool = True) -> None:
    """The table: a band below height 0 (heights are drawn above the table's surface)."""
    lo, hi = ax.get_ylim()
    depth = max(0.08 * (hi - lo), 1.0)
    bottom = min(lo, -depth)
    ax.axhspan(bottom, 0.0, color=TABLE_COLOUR, alpha=0.35, lw=0, label="table" if label else None)
    ax.axhline(0.0, color=TABLE_COLOUR, lw=1.5)
    ax.set_ylim(bottom, hi)


def plot_effort(path: Path, runs: dict, window: str, title: str, reference: Optional[dict] = None) -> None:
    """Effort over the phase ``window`` of each run: six panels, one question each.

    Parameters
    ----------
    path : Path
        PNG file.
    runs : dict
        ``{variant label: Run}`` (two or three).
    window : str
        Phase name (``Run.window``).
    title : str
        Figure title.
    reference : dict, optional
        ``{variant label: (7,) average |torque| (N m)}`` published for the same variants,
        drawn as black marks on the bars.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(2, 3, figsize=(14, 7.5))
    labels = list(runs)
    width = 0.8 / len(labels)
    for k, (label, run) in enumerate(runs.items()):
        m = run.window(window)
        t = run.t[m] - run.t[m][0]
        tau, qd = run.tau[m], run.qd[m]
        joints = np.arange(tau.shape[1])
        ax[0, 0].bar(joints + (k - (len(labels) - 1) / 2) * width, np.abs(tau).mean(0), width, color=f"C{k}")
        if reference is not None and label in reference:
            ref = np.abs(np.asarray(reference[label]))
            ax[0, 0].plot(joints + (k - (len(labels) - 1) / 2) * width, ref, "k_", ms=12, mew=2)
        ax[0, 1].plot(t, (tau * qd).sum(1), color=f"C{k}", lw=1)
        ax[0, 2].plot(t, np.cumsum((tau**2).sum(1)) * 1e-3, color=f"C{k}", lw=1.5)
        for c, (j, name) in enumerate(KEY_JOINTS.items()):
            ax[1, c].plot(t, tau[:, j], color=f"C{k}", lw=1)
            ax[1, c].set_title(f"Joint {j} ({name}): how does its torque change?", fontsize=10)
            ax[1, c].set_ylabel("motor torque [N m]")
    ax[0, 0].set_title("Which joints need less torque?", fontsize=10)
    ax[0, 0].set_xlabel("joint (counted from 0, as the report)")
    ax[0, 0].set_ylabel("average |torque| [N m]")
    ax[0, 1].set_title(r"What mechanical power $\sum_j \tau_j \dot q_j$ do the motors give?", fontsize=10)
    ax[0, 1].set_ylabel("power [W]")
    ax[0, 2].set_title(r"Where does the copper-loss proxy $\int \sum_j \tau_j^2$ build up?", fontsize=10)
    ax[0, 2].set_ylabel(r"$\int \sum_j \tau_j^2\,dt$ [N² m² s]")
    for a in list(ax[0, 1:]) + list(ax[1]):
        a.set_xlabel(f"time in phase '{window}' [s]")
    for a in ax.flat:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    handles = [plt.Line2D([], [], color=f"C{k}", lw=3) for k in range(len(labels))]
    names = list(labels)
    if reference is not None:
        handles.append(plt.Line2D([], [], color="k", marker="_", ms=12, mew=2, ls=""))
        names.append("report, Table 6.2 (|average torque|)")
    _finish(fig, path, handles, names, len(names))


def plot_grasp_path(path: Path, runs: dict, title: str) -> None:
    """Where the tool goes in use case 1: height above the table, slide along x, side view."""
    plt = _pyplot()
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.5))
    for k, run in enumerate(runs.values()):
        top = run.info["table_top"]
        h = 1e3 * (run.tool[:, 2] - top)
        ax[0].plot(run.t, h, color=f"C{k}")
        s = run.window("slide")
        x0 = run.tool[s][0, 0]
        ax[1].plot(run.t, 1e3 * (run.tool[:, 0] - x0), color=f"C{k}")
        ax[2].plot(1e3 * (run.tool[:, 0] - x0), h, color=f"C{k}")
        if run.contact_time is not None:
            ax[0].axvline(run.contact_time, color=f"C{k}", ls=":", lw=1)
    ax[0].set_title("How high is the gripper's lowest point above the table?", fontsize=10)
    ax[0].set_xlabel("time [s] (dotted: contact detected)")
    ax[1].set_title("How far does it slide along x?", fontsize=10)
    ax[1].set_xlabel("time [s]")
    ax[1].set_ylabel("x from the slide's start [mm]")
    ax[1].axhline(100.0, color="k", ls="--", lw=1)
    ax[2].set_title("Side view of its path", fontsize=10)
    ax[2].set_xlabel("x from the slide's start [mm]")
    for a in (ax[0], ax[2]):
        a.set_ylabel("height above the table [mm]")
        _draw_table(a, label=a is ax[0])
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    handles = [plt.Line2D([], [], color=f"C{k}", lw=2) for k in range(len(runs))]
    handles += [plt.Rectangle((0, 0), 1, 1, color=TABLE_COLOUR, alpha=0.35), plt.Line2D([], [], color="k", ls="--")]
    _finish(fig, path, handles, [*runs, "table", "goal: 100 mm"], len(runs) + 2)


def plot_writing(path: Path, runs: dict, title: str) -> None:
    """Use case 2: the line's y displacement along x, and the pen tip's height above the paper."""
    plt = _pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(13, 4.5))
    for k, run in enumerate(runs.values()):
        m = run.window("write")
        tool = run.tool[m]
        ax[0].plot(1e3 * (tool[:, 0] - tool[0, 0]), 1e3 * (tool[:, 1] - tool[0, 1]), color=f"C{k}")
        ax[1].plot(run.t, 1e3 * (run.tool[:, 2] - PEN_RADIUS - run.info["table_top"]), color=f"C{k}")
    ax[0].axhline(0.0, color="k", ls="--", lw=1)
    ax[0].axvspan(1e3 * (0.10 - STROKE_END), 100.0, color="0.85", lw=0)
    ax[0].set_title("How far does the pen leave the straight line?", fontsize=10)
    ax[0].set_xlabel("x from the start [mm] (grey: the stroke's end, the pen stops)")
    ax[0].set_ylabel("y displacement [mm]")
    ax[1].set_title("Is the pen tip on the paper?", fontsize=10)
    ax[1].set_xlabel("time [s]")
    ax[1].set_ylabel("pen tip's lowest point above the table [mm]")
    _draw_table(ax[1])
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    handles = [plt.Line2D([], [], color=f"C{k}", lw=2) for k in range(len(runs))]
    handles += [plt.Line2D([], [], color="k", ls="--"), plt.Rectangle((0, 0), 1, 1, color=TABLE_COLOUR, alpha=0.35)]
    _finish(fig, path, handles, [*runs, "reference line", "table"], len(runs) + 2)
