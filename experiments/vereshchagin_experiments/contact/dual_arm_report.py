"""The dual-arm case of issue 17 in ``results/``: runs, table, CSV, figure and verdict.

:func:`run` is what ``python -m vereshchagin_experiments reproduce --case dual-arm`` calls: the three variants
of :mod:`.dual_arm` (tree solver with the table, tree solver unsupported, separate chains with
the table), per-joint effort, the copper-loss proxy, the open-loop task error of the
separate-chains shortcut and the closed-loop outcome in the MuJoCo plant.
"""

from __future__ import annotations

import re

import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from . import metrics
from .contact_report import dual_arm_section
from .controller import ControllerConfig
from .dual_arm import BAND_CONFIG, CONFIG, VARIANTS, dual_arm, dual_arm_model
from .report import _bar, md_table, write_csv

__all__ = ["run"]

TREE_EXACT = 1e-9
"""Largest open-loop task error (m/s^2, rad/s^2) accepted for the tree solver's command."""
TABLE_FORCE_TOLERANCE = 0.15
"""Relative gap accepted between the plant's mean table force and the model's upward share."""
KEY_JOINTS = (0, 2, 4, 6, 9)  # torso, left shoulder / elbow / wrist, right shoulder
CHATTER_BOUND = 0.01
"""Largest command chatter (mean |τ_k+1 - τ_k| over joints and slide steps, N m) accepted for
:data:`~.dual_arm.CONFIG` (the discrete-time mode) in the ``table`` variant (issue 27's target;
measured 0.004 quick; at the instant 0.18 quick and 0.21 full without the hold band, 0.10 and
0.11 with it)."""
OPTIONS = {
    "max-min over the step (chosen)": CONFIG,
    "max-min at the instant + hold band (before)": BAND_CONFIG,
    "max-min at the instant, no hold band": ControllerConfig(),
    "smooth f tanh(qd/eps), no max-min": ControllerConfig(friction_mode="smooth"),
    "no friction compensation": ControllerConfig(friction_mode="none"),
}
"""Friction handling compared on the ``table`` variant (label -> controller settings)."""


def chatter(run, mask=None) -> np.ndarray:
    """Command chatter per joint: mean |τ_k+1 - τ_k| (N m per 1 ms step) over ``mask`` (default all)."""
    m = np.ones(len(run.t), bool) if mask is None else np.asarray(mask, bool)
    return np.abs(np.diff(run.tau[m], axis=0)).mean(axis=0)


def _options_table(option_runs: dict) -> tuple[list, list, dict]:
    """Header, rows and per-option numbers of the friction-handling comparison (slide window)."""
    header = ["friction handling (table variant)", "∫τ² [N² m² s]", "chatter mean / worst joint [N m/step]"]
    header += ["table force std [N]", "table force plant / model [N]", "sliding hand x error / off line [mm]"]
    header += ["resting hand drift [mm]"]
    rows, nums = [], {}
    for label, r in option_runs.items():
        m = r.window("slide")
        o, ch = metrics.dual_arm_outcome(r), chatter(r, m)
        nums[label] = dict(
            tau2=metrics.effort(r, m)["energy_tau2"].sum(), chatter=ch.mean(), chatter_joints=ch, outcome=o
        )
        rows.append(
            [
                label,
                f"{nums[label]['tau2']:.1f}",
                f"{ch.mean():.4f} / {ch.max():.4f}",
                f"{r.table_force[m].std():.2f}",
                f"{o['table_force']:.1f} / {o['table_force_model']:.1f}",
                f"{1e3 * o['final_error_x']:+.2f} / {1e3 * o['max_off_line']:.2f}",
                f"{1e3 * o['rest_drift']:.2f}",
            ]
        )
    return header, rows, nums


def _effort_table(joint_names, efforts: dict) -> tuple[list, list]:
    """Header and rows: per joint the average |torque| and the copper-loss proxy of each variant."""
    header = ["joint"] + [f"{v}: avg abs torque [N m]" for v in efforts] + [f"{v}: ∫τ² [N² m² s]" for v in efforts]
    rows = []
    for j, name in enumerate(joint_names):
        rows.append(
            [joint_label(name)]
            + [f"{e['mean_abs_tau'][j]:.3f}" for e in efforts.values()]
            + [f"{e['energy_tau2'][j]:.2f}" for e in efforts.values()]
        )
    rows.append(
        ["all"]
        + [f"{e['mean_abs_tau'].mean():.3f}" for e in efforts.values()]
        + [f"{e['energy_tau2'].sum():.2f}" for e in efforts.values()]
    )
    return header, rows


def _error_table(outcomes: dict) -> tuple[list, list]:
    """Header and rows: open-loop and closed-loop task errors and the table force per variant."""
    header = [
        "variant",
        "open loop: resting hand RMS / max [m/s²]",
        "sliding hand RMS / max [m/s²]",
        "angular, both hands max [rad/s²]",
        "closed loop: sliding hand x error [mm]",
        "off its line, max [mm]",
        "resting hand drift, max [mm]",
        "table force plant / model [N]",
    ]
    rows = []
    for v, o in outcomes.items():
        rms, mx, ang = o["open_loop_rms"], o["open_loop_max"], o["open_loop_ang_max"]
        rows.append(
            [
                v,
                f"{rms['rest']:.2e} / {mx['rest']:.2e}",
                f"{rms['task']:.2e} / {mx['task']:.2e}",
                f"{max(ang.values()):.2e}",
                f"{1e3 * o['final_error_x']:+.3f}",
                f"{1e3 * o['max_off_line']:.3f}",
                f"{1e3 * o['rest_drift']:.3f}",
                f"{o['table_force']:.1f} / {o['table_force_model']:.1f}",
            ]
        )
    return header, rows


def joint_label(name: str) -> str:
    """A joint's name as the report counts: ``left_joint_5`` (the URDF's, from 1) -> ``left joint 4``."""
    m = re.fullmatch(r"(left|right)_joint_(\d+)", name)
    return f"{m.group(1)} joint {int(m.group(2)) - 1}" if m else name.replace("_", " ")


def _legend_below(ax) -> None:
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, frameon=False)


def _plot_chatter(axes, option_runs: dict, joint_names) -> None:
    """Right column: rolling command chatter per option, and one resting joint's command close up."""
    j = joint_names.index("left_joint_5")
    for c, (label, r) in enumerate(option_runs.items()):
        d = np.abs(np.diff(r.tau, axis=0)).mean(axis=1)
        axes[0].plot(r.t[1:], np.convolve(d, np.ones(50) / 50, mode="same"), color=f"C{c}", lw=1, label=label)
        m = r.window("slide")
        t0 = r.t[m][len(r.t[m]) // 2]
        near = (r.t >= t0) & (r.t < t0 + 0.1)
        axes[1].plot(r.t[near], r.tau[near, j], color=f"C{c}", lw=1, label=label)
    axes[0].set_ylabel("mean |Δτ| per step, 50 ms mean [N m]")
    axes[1].set_ylabel(f"{joint_label(joint_names[j])} motor torque [N m]")


RELIEVED = (2, 4, 9)  # left shoulder and elbow (the resting arm), right shoulder (the sliding one)


def _plot(path: Path, runs: dict, joint_names, option_runs: dict) -> None:
    """Six panels, one question each; joints counted from 0 per arm as in Lau (2023)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, grid = plt.subplots(2, 3, figsize=(17, 10))
    _plot_chatter(grid[:, 2], option_runs, list(joint_names))
    styles = dict(zip(VARIANTS, ["-", "--", ":"]))
    # Which joints does the table relieve? (the table variant against the unsupported one)
    for c, j in enumerate(RELIEVED):
        for v in ("table", "unsupported"):
            if v in runs:
                r = runs[v]
                grid[0, 0].plot(
                    r.t, r.tau[:, j], styles[v], color=f"C{c}", lw=1, label=f"{joint_label(joint_names[j])}, {v}"
                )
    for v, r in runs.items():
        style = styles.get(v, "-.")
        ol = np.maximum(np.asarray(r.info["open_loop"]).max(axis=1), 1e-17)
        grid[0, 1].semilogy(r.t, ol, style, color="k", lw=1, label=v)
        tip, rest = r.tip, np.asarray(r.info["rest"])
        grid[1, 0].plot(
            r.t,
            1e3 * np.hypot(tip[:, 1] - tip[0, 1], tip[:, 2] - tip[0, 2]),
            style,
            color="C0",
            label=f"sliding hand off its line, {v}",
        )
        grid[1, 0].plot(
            r.t, 1e3 * np.linalg.norm(rest - rest[0], axis=1), style, color="C3", label=f"resting hand drift, {v}"
        )
        if r.info["table_top"] is not None:
            grid[1, 1].plot(r.t, r.table_force, style, color="C2", label=f"plant, {v}")
            grid[1, 1].plot(r.t, r.info["table_force_model"], style, color="C4", label=f"model, {v}")
    grid[0, 0].set_ylabel("motor torque [N m]")
    grid[0, 1].set_ylabel("linear RMS [m/s²]")
    grid[1, 0].set_ylabel("error [mm]")
    grid[1, 1].set_ylabel("table force [N]")
    titles = [
        "which joints does the table relieve? (solid: table, dashed: unsupported)",
        "how far off is each shortcut's task? (open loop, hand acceleration error)",
        "how much does the command chatter? (friction handling, table variant)",
        "how well do the hands track in the MuJoCo plant?",
        "does the model's table force match the plant's?",
        "a resting joint's command over 0.1 s of the slide",
    ]
    for a, title in zip(grid.flat, titles):
        a.set_title(title, fontsize=9)
        a.set_xlabel("time [s]")
        a.grid(alpha=0.3)
        _legend_below(a)
    fig.tight_layout()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def _checks(efforts: dict, outcomes: dict, chosen_chatter: float) -> dict:
    """Named pass/fail checks of the dual-arm runs (``chosen_chatter``: N m per step, table variant)."""
    ot, os_, ou = outcomes["table"], outcomes["separate"], outcomes["unsupported"]
    tree_err = max(max(o[k].values()) for o in (ot, ou) for k in ("open_loop_max", "open_loop_ang_max"))
    gap = abs(ot["table_force"] - ot["table_force_model"]) / max(ot["table_force_model"], 1e-9)
    return {
        "table saves copper loss": efforts["table"]["energy_tau2"].sum() < efforts["unsupported"]["energy_tau2"].sum(),
        f"tree solver open-loop error < {TREE_EXACT:g}": tree_err < TREE_EXACT,
        "shortcut open-loop error > 1e3 x tree's": max(os_["open_loop_max"].values()) > 1e3 * max(tree_err, 1e-15),
        f"table force plant vs model within {100 * TABLE_FORCE_TOLERANCE:.0f} %": gap < TABLE_FORCE_TOLERANCE,
        "hand on the table all slide": ot["table_fraction"] > 0.99 and os_["table_fraction"] > 0.99,
        "all variants slide 10 cm (< 5 mm off)": all(abs(o["final_error_x"]) < 5e-3 for o in outcomes.values()),
        f"command chatter < {CHATTER_BOUND:g} N m per step": chosen_chatter < CHATTER_BOUND,
    }


def _options_text(header, rows, options: dict) -> list:
    """Markdown lines of the friction-handling comparison and the choice."""
    step, band, plain, smooth, none = (options[k] for k in OPTIONS)
    worst = {k: float(o["chatter_joints"].max()) for k, o in options.items()}
    return [
        "Friction handling, compared on the table variant over the slide (chatter: mean |τ_k+1 - τ_k| "
        "per 1 ms step over joints, and of the worst joint):",
        "",
        *md_table(header, rows),
        "",
        f"- At the instant and without the hold band the command chatters ({plain['chatter']:.3f} N m per step): "
        "the joints that the task does not move are at rest (|qd| ≤ 0.01 rad/s), and the P loop's tiny "
        "corrections (on the resting hand, and through the torso from the sliding one) give each a commanded "
        "acceleration whose sign changes almost every cycle; the exact max-min at the instant charges the full "
        "breakaway friction against it (stick ↔ slip + ↔ slip -), so the command jumps by up to 2 f. The hold "
        "band (zero task acceleration while a hand is within 1 mm / 0.01 rad of its goal; the before) brings it "
        f"to {band['chatter']:.3f} (worst joint {worst[list(OPTIONS)[1]]:.3f}).",
        "- The discrete-time mode (chosen): the same friction-aware solve posed over the next 1 ms control period "
        "(`time_step=`): friction acts on the joint velocities at the end of the period, so a joint that stays "
        "at rest gets the friction that holds it, continuous in the correction. Chatter "
        f"{step['chatter']:.4f} N m per step (worst joint {worst[list(OPTIONS)[0]]:.4f}; "
        f"{band['chatter'] / max(step['chatter'], 1e-12):.0f}x less than with the band), ∫τ² "
        f"{100 * (step['tau2'] / band['tau2'] - 1):+.1f} % of the band's; the sliding hand ends "
        f"{1e3 * step['outcome']['final_error_x']:+.2f} mm from its goal, at most "
        f"{1e3 * step['outcome']['max_off_line']:.2f} mm off its line (band: "
        f"{1e3 * band['outcome']['final_error_x']:+.2f} / {1e3 * band['outcome']['max_off_line']:.2f} mm).",
        f"- Smooth compensation f tanh(qd/eps) does not chatter much ({smooth['chatter']:.3f}) but gives up "
        "friction as a holding resource and lets the sliding hand leave its line by "
        f"{1e3 * smooth['outcome']['max_off_line']:.1f} mm. No compensation has the least ∫τ² "
        f"({none['tau2']:.1f}) only because it does not do the task: the slide stalls "
        f"{-1e3 * none['outcome']['final_error_x']:.0f} mm short of its 100 mm. Chosen: the max-min over the step.",
        "",
    ]


def _option_runs(table_run, quick: bool, say) -> dict:
    """Runs of the ``table`` variant for each of :data:`OPTIONS` (the chosen one is ``table_run``)."""
    out = {}
    for label, cfg in OPTIONS.items():
        if cfg == CONFIG:
            out[label] = table_run
            continue
        t0 = time.perf_counter()
        out[label] = dual_arm("table", quick, config=cfg)
        say(f"[dual-arm] table, {label} ({time.perf_counter() - t0:.1f} s)")
    return out


def _variant_runs(runs: dict, quick: bool, say) -> dict:
    """The runs of every variant of :data:`~.dual_arm.VARIANTS` not in ``runs`` yet, made here."""
    for k, v in enumerate(VARIANTS):
        if v in runs:
            continue
        t0 = time.perf_counter()
        runs[v] = dual_arm(v, quick)
        say(
            f"[dual-arm] {_bar((k + 1) / len(VARIANTS))} {v} ({runs[v].t[-1]:.1f} s simulated in {time.perf_counter() - t0:.1f} s)"
        )
    return runs


def _index_lines(quick: bool, efforts: dict, outcomes: dict, tables: dict, checks: dict) -> list:
    """The case's Markdown section for results/index.md (without the wall-time line)."""
    header, rows = tables["effort"]
    eheader, erows = tables["errors"]
    oheader, orows, options = tables["options"]
    tau2 = {v: e["energy_tau2"].sum() for v, e in efforts.items()}
    ot, os_ = outcomes["table"], outcomes["separate"]
    return [
        "## Dual-arm Gen3 on a torso: one hand rests on a table, the other slides (issue 17)",
        "",
        "Robot: two Kinova Gen3 arms (rigid Robotiq 2F-85) mounted upright at y = ±0.25 m on a torso turning "
        "about the vertical (10 kg, plausible choice), 15 joints, one kinematic tree; the MuJoCo plant is "
        "compiled from the same URDF. The left hand rests on a table: a 6-D segment constraint holds the "
        "pose of a frame at its gripper's lowest edge, and the upward share of that constraint "
        "(-J_rᵀ e_z ν_z when ν_z < 0) is left to the table. The right hand slides 0.10 m along +x in the air "
        "(six directions constrained), cascaded P gains of the contact use cases, posture damping in the 3 "
        "redundant DOF, friction-aware solve over the next 1 ms control period (the discrete-time mode, below). Variants: **table** (tree solver), **unsupported** (tree "
        "solver, no table: the motors hold the resting hand), **separate** (the shortcut: torso + left arm "
        "and torso + right arm as two chains, each with half the torso segment's mass and inertia (torso "
        "link and both arm bases), half the torso joint's friction and damping and only its own hand's constraint; the torso joint gets the sum of both chains' torso "
        "torques, the arms their chain's; the coupling through the torso is ignored).",
        "",
        f"Mode: {'quick' if quick else 'full'}. Per joint over the slide:",
        "",
        *md_table(header, rows),
        "",
        f"- Copper-loss proxy ∫τ² over the slide, all joints: table {tau2['table']:.1f}, unsupported "
        f"{tau2['unsupported']:.1f}, separate {tau2['separate']:.1f} N² m² s: the table saves "
        f"{100 * (1 - tau2['table'] / tau2['unsupported']):.0f} % against the unsupported arms (left "
        f"shoulder avg |τ| {efforts['table']['mean_abs_tau'][2]:.2f} vs "
        f"{efforts['unsupported']['mean_abs_tau'][2]:.2f} N m); the shortcut's ∫τ² is "
        f"{100 * (tau2['separate'] / tau2['table'] - 1):+.1f} % of the tree solver's with the table.",
        "",
        "Task error: open loop = the torques each variant's solves intend (motors, the table's share, the "
        "joint friction they predict, damping) applied to the true tree dynamics (forward dynamics of the "
        "whole tree), hands' accelerations minus the commanded ones (per-sample RMS over the 3 linear rows, "
        "then RMS / max over the run); closed loop = the MuJoCo plant.",
        "",
        *md_table(eheader, erows),
        "",
        f"- The separate-chains shortcut misses the commanded hand accelerations by up to "
        f"{max(os_['open_loop_max'].values()):.3f} m/s² and {max(os_['open_loop_ang_max'].values()):.3f} rad/s² "
        f"(tree solver: {max(ot['open_loop_max'].values()):.1e} m/s², round-off): neither chain knows the other "
        "arm's inertia about the torso axis. In closed loop the P feedback absorbs most of it: the sliding "
        f"hand leaves its line by at most {1e3 * os_['max_off_line']:.2f} mm (tree: {1e3 * ot['max_off_line']:.2f} mm), "
        f"the resting hand drifts {1e3 * os_['rest_drift']:.2f} mm (tree: {1e3 * ot['rest_drift']:.2f} mm).",
        "",
        *_options_text(oheader, orows, options),
        "Checks: " + "; ".join(f"{name} {'ok' if passed else 'FAILED'}" for name, passed in checks.items()) + ".",
        "",
        "CSV: [dual_arm/dual_arm_effort.csv](dual_arm/dual_arm_effort.csv), "
        "[dual_arm/dual_arm_errors.csv](dual_arm/dual_arm_errors.csv), "
        "[dual_arm/dual_arm_friction.csv](dual_arm/dual_arm_friction.csv); figure: [dual_arm/dual_arm.png](dual_arm/dual_arm.png)",
        "",
    ]


def run(
    out_dir,
    quick: bool = False,
    progress: Optional[Callable[[str], None]] = None,
    runs: Optional[dict] = None,
    option_runs: Optional[dict] = None,
) -> dict:
    """Run the three dual-arm variants, write table, CSV and figure into ``out_dir/dual_arm``.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (``dual_arm/`` is created in it).
    quick : bool
        Shorter phases (:func:`~.dual_arm.dual_arm`).
    progress : callable, optional
        ``progress(line)`` after each run.
    runs : dict, optional
        Runs already made, ``{variant: Run}`` for every variant of :data:`~.dual_arm.VARIANTS`
        (with the same ``quick``); None: run them here.
    option_runs : dict, optional
        Runs of the ``table`` variant for each label of :data:`OPTIONS`; None: run them here.

    Returns
    -------
    dict
        ``index``: Markdown lines for results/index.md; ``runs``: the runs by variant;
        ``option_runs``: by label of :data:`OPTIONS`; ``options``: per label ``tau2`` (N² m² s),
        ``chatter`` (N m per step, mean over joints), ``chatter_joints`` (per joint) and ``outcome`` (:func:`~.metrics.dual_arm_outcome`) over the
        slide; ``ok``: all checks passed; ``checks``: the named checks; ``seconds``: wall time.
    """
    say = progress or (lambda s: None)
    out = Path(out_dir) / "dual_arm"
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    runs = _variant_runs(dict(runs or {}), quick, say)
    option_runs = dict(option_runs or _option_runs(runs["table"], quick, say))
    names = dual_arm_model()[1].joint_names
    efforts = {v: metrics.effort(r, r.window("slide")) for v, r in runs.items()}
    outcomes = {v: metrics.dual_arm_outcome(r) for v, r in runs.items()}
    header, rows = _effort_table(names, efforts)
    write_csv(out / "dual_arm_effort.csv", header, rows)
    eheader, erows = _error_table(outcomes)
    write_csv(out / "dual_arm_errors.csv", eheader, erows)
    oheader, orows, options = _options_table(option_runs)
    write_csv(out / "dual_arm_friction.csv", oheader, orows)
    fig = out / "dual_arm.png"
    _plot(fig, runs, names, option_runs)
    chosen = options[next(iter(OPTIONS))]
    checks = _checks(efforts, outcomes, chosen["chatter"])
    ok = all(checks.values())
    tables = dict(effort=(header, rows), errors=(eheader, erows), options=(oheader, orows, options))
    idx = _index_lines(quick, efforts, outcomes, tables, checks)
    lines, passed, _ = dual_arm_section(runs["table"], quick, say)
    idx += lines
    ok &= passed
    secs = time.perf_counter() - t_start
    idx += [f"Dual-arm case: {len(runs)} runs in {secs:.1f} s wall time.", ""]
    return dict(index=idx, runs=runs, option_runs=option_runs, options=options, ok=ok, checks=checks, seconds=secs)
