"""Tables, figures and the ``results/index.md`` section of the friction-energy experiment.

:func:`run` is what ``python -m vereshchagin_experiments reproduce --case friction-energy`` calls: it runs
:func:`vereshchagin_experiments.friction_energy.run_all` and writes into ``out_dir/friction_energy``

- ``summary.csv``: one row per task, controller and friction scale (every metric of
  :func:`~vereshchagin_experiments.friction_energy.outcome`);
- ``context.csv``: per joint at the held poses, the plant's gravity torque ``g_j`` and friction
  ``f_j``, and what friction could hold in principle;
- ``<task>.png``: per task (nominal friction) the controllers' joint torques, the number of joints
  the plant's friction holds, the task error over time and a bar chart of the savings.

Savings are relative to the friction-unaware controller: ``100 (x / x_unaware - 1)`` %, negative =
less effort.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from .contact.report import md_table, write_csv
from .contact.use_cases import JOINT_DAMPING, JOINT_FRICTION
from . import friction_energy as fe

__all__ = ["run"]

BASE = "none"
"""The reference controller of the savings."""
SAVES = -1.0
"""% change of the integral of tau^2 below which a controller counts as saving effort."""
LOSES = (1.5, 2e-5)
"""A controller loses accuracy if its RMS task error exceeds ``1.5 x`` the unaware one's plus 0.02 mm."""
FAILS = (1e-3, 1e-2)
"""A run does not complete its task if the final error exceeds 1 mm or the RMS rotation error 10 mrad."""
FREE_DRIFT = 5e-3
"""m: drift in the free directions of the partial task reported as "the arm moved away"."""


WORK_FLOOR = 0.05
"""J: below this the unaware run's mechanical work is too small for a relative change (holding)."""


def _pct(x: float, ref: float) -> float:
    return 100.0 * (x / ref - 1.0) if ref > 0 else float("nan")


def _pct_work(x: float, ref: float) -> str:
    """Relative change of the mechanical work, or a dash when the reference is about zero."""
    return f"{_pct(x, ref):+.1f} %" if ref > WORK_FLOOR else "–"


def _select(results, task: str, scale: float) -> dict:
    """``{controller: result}`` of one task and friction scale."""
    return {r["controller"]: r for r in results if r["task"] == task and r["scale"] == scale}


# -- context: friction against gravity ----------------------------------------------------------------
def ideal_saving(g, f) -> float:
    """Share of the holding ∫τ² friction ``f`` (n,) could take over against gravity torques ``g`` (n,).

    ``1 - sum max(|g_j| - f_j, 0)^2 / sum g_j^2``: every joint held by friction at its bound.
    """
    g = np.asarray(g, float)
    return float(1.0 - np.sum(np.maximum(np.abs(g) - np.asarray(f, float), 0.0) ** 2) / np.sum(g**2))


def context(quick: bool) -> tuple[list, list, list]:
    """Per joint at the held poses: gravity torque, friction, their ratio; and the ideal holding saving.

    The ideal saving (:func:`ideal_saving`) is what the least-command rule promises when every joint
    sticks: motors supply ``max(|g_j| - f_j, 0)`` instead of ``|g_j|``.

    Returns
    -------
    header, rows, lines
        CSV/Markdown table and summary sentences.
    """
    header = ["pose", "joint", "gravity torque g_j [N m]", "friction f_j [N m]", "f_j / |g_j|"]
    rows, lines = [], []
    for task in fe.tasks(quick):
        if task.name not in ("hold", "hold_payload", "partial"):
            continue
        g, f = fe.gravity_torques(task, task.q0)
        for j in range(len(g)):
            ratio = f[j] / abs(g[j]) if abs(g[j]) > 1e-6 else float("inf")
            rows.append(
                [
                    task.name,
                    f"joint_{j + 1}",
                    f"{g[j]:.3f}",
                    f"{f[j]:.2f}",
                    "inf" if not np.isfinite(ratio) else f"{ratio:.3f}",
                ]
            )
        ideal = {s: ideal_saving(g, s * f) for s in fe.FRICTION_SCALES}
        big = np.argsort(-np.abs(g))[:3]
        lines.append(
            f"- {task.name}: gravity torques {', '.join(f'joint_{j + 1} {abs(g[j]):.2f}' for j in big)} N m "
            f"(the rest below {np.sort(np.abs(g))[-4]:.2f}); friction could supply "
            f"{', '.join(f'{100 * min(f[j] / abs(g[j]), 1):.0f} %' for j in big)} of those; "
            f"ideal holding saving of ∫τ² with every joint stuck: "
            + ", ".join(f"{100 * ideal[s]:.1f} % (friction x{s:g})" for s in fe.FRICTION_SCALES)
            + "."
        )
    return header, rows, lines


# -- tables ------------------------------------------------------------------------------------------
SUMMARY_HEADER = [
    "task",
    "friction scale",
    "controller",
    "∫τ² [N² m² s]",
    "Δ∫τ² [%]",
    "∫|τ q̇| [J]",
    "Δ∫|τ q̇| [%]",
    "peak |τ| [N m]",
    "RMS error [mm]",
    "final error [mm]",
    "RMS rotation error [mrad]",
    "drift while holding [mm]",
    "joints stuck (plant)",
    "joints friction holds (max-min model)",
    "friction share of holding torque [%]",
    "samples saturated [%]",
    "command chatter [N m/step]",
]


def summary_rows(results) -> list[list]:
    """One row per run in :data:`SUMMARY_HEADER` order, savings against the unaware run."""
    rows = []
    for r in results:
        o = r["outcome"]
        base = _select(results, r["task"], r["scale"])[BASE]["outcome"]
        rows.append(
            [
                r["task"],
                f"{r['scale']:g}",
                r["controller"],
                f"{o['tau2']:.2f}",
                f"{_pct(o['tau2'], base['tau2']):+.1f}",
                f"{o['work']:.4f}",
                f"{_pct(o['work'], base['work']):+.1f}",
                f"{o['peak']:.2f}",
                f"{1e3 * o['rms_error']:.3f}",
                f"{1e3 * o['final_error']:.3f}",
                f"{1e3 * o['rms_rot']:.2f}",
                f"{1e3 * o['drift']:.3f}",
                f"{o['stick_plant']:.2f}",
                f"{o['stick_model']:.2f}",
                f"{100 * o['friction_share']:.1f}",
                f"{100 * o['saturated']:.1f}",
                f"{o['chatter']:.4f}",
            ]
        )
    return rows


def task_table(results, task: str) -> list[str]:
    """Markdown table of one task at the nominal friction (the key columns)."""
    runs = _select(results, task, 1.0)
    base = runs[BASE]["outcome"]
    header = [
        "controller",
        "∫τ² [N² m² s]",
        "Δ∫τ²",
        "∫\\|τ q̇\\| [J]",
        "Δ∫\\|τ q̇\\|",
        "peak \\|τ\\| [N m]",
        "RMS / final error [mm]",
        "RMS rot. error [mrad]",
        "drift [mm]",
        "joints stuck (plant)",
        "friction's share of holding",
        "chatter [N m/step]",
    ]
    rows = []
    for c, r in runs.items():
        o = r["outcome"]
        rows.append(
            [
                fe.CONTROLLERS[c],
                f"{o['tau2']:.1f}",
                f"{_pct(o['tau2'], base['tau2']):+.1f} %",
                f"{o['work']:.3f}",
                _pct_work(o["work"], base["work"]),
                f"{o['peak']:.2f}",
                f"{1e3 * o['rms_error']:.3f} / {1e3 * o['final_error']:.3f}",
                f"{1e3 * o['rms_rot']:.2f}",
                f"{1e3 * o['drift']:.2f}",
                f"{o['stick_plant']:.1f}",
                f"{100 * o['friction_share']:.1f} %",
                f"{o['chatter']:.4f}",
            ]
        )
    return md_table(header, rows)


def scale_table(results) -> list[str]:
    """Δ∫τ² against the unaware controller per task and friction scale (Markdown)."""
    scales = sorted({r["scale"] for r in results})
    header = ["task", "friction"] + [fe.CONTROLLERS[c] for c in fe.CONTROLLERS if c != BASE]
    rows = []
    for task in fe.tasks():
        for s in scales:
            runs = _select(results, task.name, s)
            if not runs:
                continue
            base = runs[BASE]["outcome"]["tau2"]
            rows.append(
                [task.name, f"x{s:g}"]
                + [f"{_pct(runs[c]['outcome']['tau2'], base):+.1f} %" for c in fe.CONTROLLERS if c != BASE]
            )
    return md_table(header, rows)


# -- verdicts -----------------------------------------------------------------------------------------
def _completes(o: dict) -> bool:
    return o["final_error"] <= FAILS[0] and o["rms_rot"] <= FAILS[1]


def verdicts(results, task: str, scale: float = 1.0) -> list[str]:
    """Plain sentences per controller: saves or not, loses accuracy or not, completes or not."""
    runs = _select(results, task, scale)
    base = runs[BASE]["outcome"]
    lines = []
    for c, r in runs.items():
        o = r["outcome"]
        words = []
        if not _completes(o):
            words.append(
                f"does not complete the task (final error {1e3 * o['final_error']:.2f} mm, RMS rotation "
                f"error {1e3 * o['rms_rot']:.1f} mrad)"
            )
        if c != BASE:
            d = _pct(o["tau2"], base["tau2"])
            words.append(f"saves {-d:.1f} % of ∫τ²" if d < SAVES else f"saves nothing (∫τ² {d:+.1f} %)")
            if o["rms_error"] > LOSES[0] * base["rms_error"] + LOSES[1]:
                words.append(
                    f"loses accuracy (RMS error {1e3 * o['rms_error']:.3f} mm vs {1e3 * base['rms_error']:.3f} mm)"
                )
        if task == "partial" and o["drift"] > FREE_DRIFT:
            words.append(
                f"lets the arm move {1e3 * o['drift']:.0f} mm in the free x-y directions (lower gravity "
                "torques there, not a saving by friction)"
            )
        if words:
            lines.append(f"- {fe.CONTROLLERS[c]}: " + "; ".join(words) + ".")
    return lines


def findings(results) -> list[str]:
    """Sentences explaining the mechanisms behind the nominal-friction numbers."""
    hold = _select(results, "hold", 1.0)
    lines = []
    mm, step = hold["maxmin"]["outcome"], hold["maxmin_step"]["outcome"]
    base = hold[BASE]["outcome"]
    ideal = ideal_saving(*fe.gravity_torques(fe.tasks()[0], fe.tasks()[0].q0))
    lines.append(
        f"- Holding, the exact max-min at the instant changes ∫τ² by {_pct(mm['tau2'], base['tau2']):+.1f} % (the "
        f"ideal with every joint held by friction: {-100 * ideal:+.1f} %): it lets friction hold only joints whose "
        "commanded acceleration is exactly zero; the P loop's corrections never are, so it let friction hold on "
        f"average {mm['stick_model']:.1f} of 7 joints and added the full friction towards each correction to the "
        f"others, the naive scheme's command (chatter {mm['chatter']:.3f} N m per step). Over the step (the "
        "discrete-time mode: the same solve with `time_step=` 1 ms, friction on the end-of-period velocities) "
        f"∫τ² changes by {_pct(step['tau2'], base['tau2']):+.1f} %, the command chatters {step['chatter']:.4f} N m "
        f"per step, friction holds {step['stick_model']:.1f} of 7 joints in the model, at an RMS error of "
        f"{1e3 * step['rms_error']:.3f} mm (instant {1e3 * mm['rms_error']:.3f} mm, unaware "
        f"{1e3 * base['rms_error']:.3f} mm)."
    )
    stalls = [
        t.name
        for t in fe.tasks()
        if t.name != "partial"
        and t.name in {r["task"] for r in results}
        and not _completes(_select(results, t.name, 1.0)[BASE]["outcome"])
    ]
    if stalls:
        lines.append(
            f"- The friction-unaware controller does not complete the moving tasks ({', '.join(stalls)}). With the "
            "desired twist saturated, the cascaded P asks for at most k_vel v_max = 1.5 m/s^2 (slow task) and "
            "k_vel w_max = 20 rad/s^2 in rotation: at the shoulder (joint_2, slow task) and the last wrist joint "
            "(joint_7, reach) that is less torque than static friction, so the joint stays stuck and the error "
            "grows; every friction-aware command breaks it free."
        )
    part = _select(results, "partial", 1.0)
    if part:
        pm, pb = part["maxmin"]["outcome"], part[BASE]["outcome"]
        lines.append(
            f"- Partial task: the max-min lets friction hold {pm['stick_model']:.1f} joints (the free "
            f"directions) and keeps the arm within {1e3 * pm['drift']:.2f} mm in x-y; the plain solve predicts the "
            f"self-motion gravity would cause, which the plant's friction prevents, so its commands are wrong "
            f"in the constrained directions too (RMS error {1e3 * pb['rms_error']:.2f} mm vs {1e3 * pm['rms_error']:.3f} mm)."
        )
    return lines


# -- figures -------------------------------------------------------------------------------------------
def plot_task(path: Path, results, task: fe.TaskSpec) -> None:
    """Torques of every controller, joints stuck, task error, savings bar chart (nominal friction)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = _select(results, task.name, 1.0)
    fig, axes = plt.subplots(3, 3, figsize=(14, 10))
    flat = axes.ravel()
    for ax, (c, r) in zip(flat[:5], runs.items()):
        tr = r["trace"]
        for j in range(tr["tau"].shape[1]):
            ax.plot(tr["t"], tr["tau"][:, j], color=f"C{j}", lw=0.8, label=f"joint_{j + 1}")
        ax.set_title(fe.CONTROLLERS[c], fontsize=9)
        ax.set_ylabel("motor torque [N m]")
    flat[0].legend(fontsize=6, ncol=2)
    for k, (c, r) in enumerate(runs.items()):
        tr = r["trace"]
        flat[5].plot(tr["t"], tr["stick"] + 0.05 * k, color=f"C{k}", lw=0.8, label=fe.CONTROLLERS[c])
        flat[6].semilogy(tr["t"], np.maximum(1e3 * tr["error"], 1e-4), color=f"C{k}", lw=0.8, label=fe.CONTROLLERS[c])
    flat[5].set_ylabel("joints the plant's friction holds")
    flat[6].set_ylabel("task error (constrained linear) [mm]")
    flat[5].legend(fontsize=6)
    base = runs[BASE]["outcome"]
    others = [c for c in runs if c != BASE]
    x = np.arange(len(others))
    flat[7].bar(x - 0.2, [_pct(runs[c]["outcome"]["tau2"], base["tau2"]) for c in others], 0.4, label="∫τ²")
    if base["work"] > WORK_FLOOR:
        flat[7].bar(x + 0.2, [_pct(runs[c]["outcome"]["work"], base["work"]) for c in others], 0.4, label="∫|τ q̇|")
    flat[7].axhline(0.0, color="k", lw=0.8)
    flat[7].set_yscale("symlog", linthresh=10.0)  # ±10 % linear, larger changes logarithmic
    flat[7].set_xticks(x, [fe.CONTROLLERS[c].replace(" ", "\n", 2) for c in others], fontsize=6)
    flat[7].set_ylabel("change vs friction-unaware [%] (< 0: saves)")
    flat[7].legend(fontsize=7)
    flat[8].bar(np.arange(len(runs)), [1e3 * r["outcome"]["rms_error"] for r in runs.values()], color="C7")
    flat[8].set_xticks(np.arange(len(runs)), [c for c in runs], fontsize=7)
    flat[8].set_ylabel("RMS task error [mm]")
    for ax in flat[:7]:
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
    fig.suptitle(f"{task.title} (nominal friction)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# -- the whole section ------------------------------------------------------------------------------
def _intro(quick: bool) -> list[str]:
    return [
        "## How much motor effort does exact static friction save? (Gen3, MuJoCo)",
        "",
        "Vukcevic (TR 03-2018) motivates the static-friction max-min by energy: motors should not fight what "
        "friction can hold. Measured here in closed loop: the MuJoCo Gen3 + rigid gripper of the contact "
        "experiments (1 kHz), our solver inside the same cascaded P controller with the same gains "
        "(k_pos {40, 80}, k_vel {30, 40}, desired twist saturated at 0.05 m/s (reach: 0.5 m/s) and 0.5 rad/s, "
        "joint posture term (20, 3) except in the partial task), controllers differing only in how joint friction "
        "enters: friction-unaware (plain solve), naive sign compensation (+f sign(q̇), at rest the sign of the "
        "commanded q̈), smoothed compensation (+f tanh(q̇/0.01 rad/s): the chatter-free scheme a reviewer "
        'would ask for; it separates "do not fight friction at rest" from "let friction hold"), the exact '
        "max-min with the least-command rule (`friction=`, rest below 0.01 rad/s) at the instant (the before of "
        "issue 27), and the same max-min over the next 1 ms control period (`time_step=`, the discrete-time mode, "
        "the after).",
        "",
        f"Joint friction (plant frictionloss and model): {list(JOINT_FRICTION)} N m (joints 1-4, 5-7), viscous damping "
        f"{list(JOINT_DAMPING)} N m s/rad. **These are assumptions**: Kinova publishes no friction, damping or rotor "
        "inertia for the Gen3 (its URDF has none); the values are plausible for harmonic-drive actuators of this "
        "size and are the contact experiments' choice, hence the runs with friction x0.5 and x2. Plant and model "
        "have the same friction (a correct friction model). Mode: "
        + ("quick (shorter tasks, nominal friction only)." if quick else "full."),
        "",
    ]


def run(out_dir, quick: bool = False, progress: Optional[Callable[[str], None]] = None, workers: int = 2) -> dict:
    """Run the experiment and write its outputs into ``out_dir/friction_energy``.

    Returns
    -------
    dict
        ``index``: Markdown lines for results/index.md; ``results``: :func:`fe.run_all`'s list;
        ``files``: paths written; ``ok``: every run finished with finite values; ``seconds``: wall time.
    """
    t0 = time.perf_counter()
    out = Path(out_dir) / "friction_energy"
    out.mkdir(parents=True, exist_ok=True)
    results = fe.run_all(quick, workers, progress)
    files = [out / "summary.csv", out / "context.csv"]
    write_csv(files[0], SUMMARY_HEADER, summary_rows(results))
    c_header, c_rows, c_lines = context(quick)
    write_csv(files[1], c_header, c_rows)
    idx = _intro(quick) + [
        "### Friction against gravity at the held poses",
        "",
        *c_lines,
        "",
        "Per joint: [friction_energy/context.csv](friction_energy/context.csv).",
        "",
    ]
    for task in fe.tasks(quick):
        png = out / f"{task.name}.png"
        plot_task(png, results, task)
        files.append(png)
        idx += [
            f"### {task.title}",
            "",
            *task_table(results, task.name),
            "",
            *verdicts(results, task.name),
            "",
            f"Figure: [friction_energy/{png.name}](friction_energy/{png.name})",
            "",
        ]
    idx += ["### Findings (nominal friction)", "", *findings(results), ""]
    idx += [
        "### Δ∫τ² against the friction-unaware controller, per friction scale",
        "",
        *scale_table(results),
        "",
        "All metrics of every run: [friction_energy/summary.csv](friction_energy/summary.csv).",
        "",
    ]
    ok = all(np.isfinite(list(r["outcome"].values())).all() for r in results)
    secs = time.perf_counter() - t0
    idx += [
        f"Friction-energy experiment: {len(results)} runs, {sum(r['simulated'] for r in results):.1f} s simulated "
        f"in {secs:.1f} s wall time.",
        "",
    ]
    return dict(index=idx, results=results, files=files, ok=ok, seconds=secs)
