"""The mobile-manipulation case of issue 28 in ``results/``: both variants on both paths, a table,
a CSV, a figure and checks.

:func:`run` is what ``python -m vereshchagin_experiments reproduce --case mobile`` calls
(:mod:`.mobile`: the Gen3 on a holonomic base in MuJoCo, base locked vs base helping).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from ..contact.report import md_table, write_csv
from ._common import save
from .mobile import BASE_MASS, MU, PATHS, PRESS, TABLE_TOP, VARIANTS, metrics, run_variant

__all__ = ["run"]

LABELS = {"arm": "base locked (arm alone)", "base": "base helping (planar base)"}


def _table(nums: dict) -> tuple[list, list]:
    header = ["path", "variant", "tool error RMS / max [mm]", "motors saturated [% of steps]"]
    header += [f"RMS torque joint_{j} [N m]" for j in range(1, 8)]
    header += ["arm ∫τ² [N² m² s]", "base force RMS [N]", "base travel [m]"]
    header += [f"table force, plant mean (set-point {PRESS:.0f}) [N]", "10 ms means off the model, RMS [N]"]
    header += ["ball off the table in the plant [% of periods]"]
    rows = []
    for (path, v), (m, info) in nums.items():
        rows.append(
            [
                path,
                LABELS[v],
                f"{1e3 * m['rms_error']:.3f} / {1e3 * m['max_error']:.3f}",
                f"{100 * info['saturated']:.1f}",
            ]
            + [f"{x:.2f}" for x in m["rms_torque"]]
            + [f"{m['tau2']:.0f}", f"{m['base_rms_force']:.2f}", f"{m['base_travel']:.3f}"]
            + [f"{m['plant_normal']:.2f}", f"{m['normal_deviation']:.2f}", f"{100 * m['contact_lost']:.1f}"]
        )
    return header, rows


def _plot(path: Path, runs: dict, nums: dict) -> None:
    """Top view of the tool and base paths, per-joint RMS torque on the near path, tool error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    ax = axes[0]
    ax.add_patch(plt.Rectangle((0.75, -0.6), 0.6, 1.2, color="0.85", label=f"table (top {TABLE_TOP} m)"))
    for c, p in enumerate(PATHS):
        r = runs[(p, "base")]
        ax.plot(r.tool[:, 0], r.tool[:, 1], color=f"C{c}", lw=1.5, label=f"tool, {p} path")
        ax.plot(r.base_pose[:, 0], r.base_pose[:, 1], color=f"C{c}", lw=1.5, ls="--", label=f"base, {p} path")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("base helping: tool and base (top view)")
    ax.legend(fontsize=7, loc="lower left")
    ax = axes[1]
    x = np.arange(1, 8)
    for c, v in enumerate(VARIANTS):
        ax.bar(x + (c - 0.5) * 0.38, nums[("near", v)][0]["rms_torque"], width=0.38, color=f"C{c + 2}", label=LABELS[v])
    ax.set_xticks(x, [f"joint_{j}" for j in x], fontsize=7)
    ax.set_ylabel("RMS torque [N m]")
    ax.set_title("near path: arm motor effort")
    ax.legend(fontsize=7)
    ax = axes[2]
    for (p, v), r in runs.items():
        ax.semilogy(
            r.t, np.maximum(1e3 * r.error, 1e-6), lw=1, ls="-" if v == "base" else ":", label=f"{p}, {LABELS[v]}"
        )
    ax.set_xlabel("t [s]")
    ax.set_ylabel("tool position error [mm]")
    ax.set_title("tracking")
    ax.legend(fontsize=7)
    save(fig, path)


def run(out_dir, quick: bool = False, progress: Optional[Callable[[str], None]] = None) -> dict:
    """Run both variants on both paths and write ``mobile/mobile.md``, ``mobile.csv``, ``mobile.png``.

    Parameters
    ----------
    out_dir : str or Path
        The results directory (the files go to its ``mobile/``).
    quick : bool
        Unused (the runs are short); for the common signature.
    progress : callable, optional
        Called with one line per run.

    Returns
    -------
    dict
        ``index`` (Markdown lines for results/index.md), ``ok`` (all checks passed), ``checks``
        (name -> bool), ``seconds``.
    """
    t0 = time.perf_counter()
    out = Path(out_dir) / "mobile"
    out.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda s: None)
    runs, nums = {}, {}
    for p in PATHS:
        for v in VARIANTS:
            say(f"[mobile] {p} path, {LABELS[v]}")
            runs[(p, v)] = run_variant(v, p)
            nums[(p, v)] = (metrics(runs[(p, v)]), runs[(p, v)].info)
    header, rows = _table(nums)
    write_csv(out / "mobile.csv", header, rows)
    table = md_table(header, rows)
    (out / "mobile.md").write_text("\n".join(table) + "\n", encoding="utf-8")
    _plot(out / "mobile.png", runs, nums)
    near_arm, near_base = nums[("near", "arm")][0], nums[("near", "base")][0]
    far_arm, far_base = nums[("far", "arm")][0], nums[("far", "base")][0]
    checks = {
        "near path tracked by both (RMS error < 1 mm)": near_arm["rms_error"] < 1e-3 and near_base["rms_error"] < 1e-3,
        "the base lowers the arm's effort on the near path": near_base["tau2"] < near_arm["tau2"],
        "far path: the locked arm saturates and loses the path (max error > 5 cm)": far_arm["max_error"] > 0.05,
        "far path: tracked with the base helping (RMS error < 1 mm)": far_base["rms_error"] < 1e-3,
        "the plant's table force averages the set-point (within 2 %)": all(
            abs(nums[(p, "base")][0]["plant_normal"] - PRESS) < 0.02 * PRESS for p in PATHS
        ),
    }
    ok = all(checks.values())
    saving = 100.0 * (1.0 - near_base["tau2"] / near_arm["tau2"])
    index = [
        "## Mobile manipulation: a Gen3 on a holonomic base (issue 28, MuJoCo plant)",
        "",
        f"The Gen3 on a {BASE_MASS:.0f} kg holonomic base reaches ahead until its tool's ball touches a "
        f"table, then presses with {PRESS:.0f} N and slides along the table and back (7 s at 1 kHz). The "
        "press is a force set-point contact (`vs.Contact(..., mu=MU, force=PRESS)`: the table pushes with "
        f"exactly that force, its friction, mu {MU}, opposes the sliding), the task the tool's x, y and "
        'orientation. Base helping: the controller\'s model is `Tree.from_urdf(urdf, base="planar")` and '
        "the base rows of the command drive the base's three motors; base locked: the same URDF welded "
        "to the world. Motors saturate at their limits. Module `vereshchagin_experiments.floating.mobile`.",
        "",
        *table,
        "",
        f"On the near path, which the arm alone can follow, the base takes over part of the work: the "
        f"arm's ∫τ² falls by {saving:.0f} % ({near_arm['tau2']:.0f} -> {near_base['tau2']:.0f} N² m² s). "
        "On the far path the locked arm saturates and leaves the path; with the base helping it is "
        f"tracked to {1e3 * far_base['rms_error']:.3f} mm RMS. The plant's table force averages the "
        "set-point; MuJoCo's soft contact drops the sliding ball's contact for single periods (the "
        "last column), so its per-period force scatters around the model's.",
        "",
        "Figure: [mobile/mobile.png](mobile/mobile.png); table: [mobile/mobile.csv](mobile/mobile.csv).",
        "",
        "Checks: " + "; ".join(f"{k}: {'ok' if v else 'FAILED'}" for k, v in checks.items()),
        "",
    ]
    return {"index": index, "ok": ok, "checks": checks, "seconds": time.perf_counter() - t0}
