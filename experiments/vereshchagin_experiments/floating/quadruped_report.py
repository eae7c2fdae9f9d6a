"""The standing-quadruped case of issue 28 in ``results/``: a table, a CSV, a figure and checks.

:func:`run` is what ``python -m vereshchagin_experiments reproduce --case quadruped`` calls
(:mod:`.quadruped`: Solo 12 shifting its weight in MuJoCo, whole-body least effort).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np


from ..contact.report import md_table, write_csv
from ._common import save
from . import solo_plant as sp
from .quadruped import MU_MODEL, SHIFT, TIMES, metrics, run as run_stand

__all__ = ["run"]

JOINTS = ("HAA", "HFE", "KFE")


def _tables(m: dict) -> tuple[list, list, list, list]:
    legs = [f.removesuffix("_FOOT") for f in sp.FEET]
    h1 = ["leg"] + [f"RMS torque {j} [N m]" for j in JOINTS]
    h1 += ["least model normal force [N]", "held: model normal force [N]", "held: plant normal force [N]"]
    r1 = []
    for k, leg in enumerate(legs):
        r1.append(
            [leg]
            + [f"{x:.3f}" for x in m["rms_torque"][3 * k : 3 * k + 3]]
            + [f"{m['min_normal'][k]:.2f}", f"{m['held_model_normal'][k]:.2f}", f"{m['held_plant_normal'][k]:.2f}"]
        )
    h2 = ["base position error RMS / max [mm]", "orientation error max [mrad]", "∫τ² [N² m² s]"]
    h2 += ["largest |f_t| / f_n (model)", "largest foot speed in the plant [mm/s]"]
    r2 = [
        [
            f"{1e3 * m['rms_position_error']:.3f} / {1e3 * m['max_position_error']:.3f}",
            f"{1e3 * m['max_orientation_error']:.3f}",
            f"{m['tau2']:.2f}",
            f"{m['max_ratio']:.3f}",
            f"{1e3 * m['max_foot_speed']:.2f}",
        ]
    ]
    return h1, r1, h2, r2


def _plot(path: Path, r) -> None:
    """Base path, each foot's normal force (model and plant), each motor's torque."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    ax = axes[0]
    ax.plot(r.t, 1e3 * (r.base[:, 0] - r.base[0, 0]), label="base x")
    ax.plot(r.t, 1e3 * (r.base[:, 1] - r.base[0, 1]), label="base y")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("base displacement [mm]")
    ax.set_title("weight shift toward FL, FR, HL")
    ax.legend(fontsize=8)
    ax = axes[1]
    for k, foot in enumerate(sp.FEET):
        ax.plot(r.t, r.model_force[:, k, 2], color=f"C{k}", lw=1.5, label=f"{foot.removesuffix('_FOOT')} model")
        ax.plot(r.t, r.plant_normal[:, k], color=f"C{k}", lw=0.8, ls=":", label=f"{foot.removesuffix('_FOOT')} plant")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("foot normal force [N]")
    ax.set_title("support forces: least effort vs MuJoCo")
    ax.legend(fontsize=7, ncol=2)
    ax = axes[2]
    for k, foot in enumerate(sp.FEET):
        for j, ls in zip(range(3), ("-", "--", ":")):
            lbl = f"{foot.removesuffix('_FOOT')}" if j == 0 else None
            ax.plot(r.t, r.torque[:, 3 * k + j], color=f"C{k}", ls=ls, lw=1, label=lbl)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("motor torque [N m] (HAA -, HFE --, KFE :)")
    ax.set_title("motor torques")
    ax.legend(fontsize=7, loc="center right")
    save(fig, path)


def run(out_dir, quick: bool = False, progress: Optional[Callable[[str], None]] = None) -> dict:
    """Run the weight shift and write ``quadruped/quadruped.md``, ``.csv`` and ``.png`` into
    ``out_dir``; the arguments and the returned dict as :func:`.mobile_report.run`'s (``quick``
    unused, ``progress`` called once).
    """
    t0 = time.perf_counter()
    out = Path(out_dir) / "quadruped"
    out.mkdir(parents=True, exist_ok=True)
    (progress or (lambda s: None))("[quadruped] Solo 12 weight shift, whole-body least effort")
    r = run_stand()
    m = metrics(r)
    h1, r1, h2, r2 = _tables(m)
    write_csv(out / "quadruped.csv", h1, r1)
    t1, t2 = md_table(h1, r1), md_table(h2, r2)
    (out / "quadruped.md").write_text("\n".join(t1 + [""] + t2) + "\n", encoding="utf-8")
    _plot(out / "quadruped.png", r)
    checks = {
        "base tracked (RMS error < 2 mm)": m["rms_position_error"] < 2e-3,
        f"model forces in their cones (|f_t| / f_n <= {MU_MODEL})": m["max_ratio"] <= MU_MODEL * (1 + 1e-9),
        "feet hold in the plant (speed < 1 cm/s)": m["max_foot_speed"] < 1e-2,
        "the shift moves load off HR (held model force below 60 % of its start)": m["held_model_normal"][3]
        < 0.6 * r.model_force[0, 3, 2],
        "plant and model agree on the held foot forces (within 5 %)": bool(
            np.all(np.abs(m["held_plant_normal"] - m["held_model_normal"]) <= 0.05 * m["held_model_normal"])
        ),
        "motors within their limits": r.info["saturated"] == 0.0,
    }
    index = [
        "## A standing quadruped shifts its weight (issue 28, Solo 12, MuJoCo plant)",
        "",
        "Solo 12 (example-robot-data, 2.5 kg) stands on four point feet; the base moves "
        f"{SHIFT:.0%} of the way toward the centroid of the feet FL, FR, HL and back "
        f"({TIMES[1]:.0f} s each way, {TIMES[2]:.0f} s hold), height and orientation held. Each period the "
        'controller calls `vereshchagin.whole_body.least_effort` on `Tree.from_urdf(..., base="free")`: the '
        "base's pose as six task rows, the feet as supports in friction cones "
        f"(mu {MU_MODEL}, the plant's {sp.MU}), no motor on the base: the twelve joint torques of least "
        "effort, sent to the plant's motors. The plant uses MuJoCo's elliptic cone, impratio 10 and "
        f"{sp.NOSLIP} noslip iterations: with its default contacts the feet creep outward at about 16 mm/s "
        "under the tangential forces least effort uses. Least effort does not unload a foot: it "
        "shifts the load as far as that saves torque (HR's model force in the table). "
        "Module `vereshchagin_experiments.floating.quadruped`.",
        "",
        *t2,
        "",
        *t1,
        "",
        "Figure: [quadruped/quadruped.png](quadruped/quadruped.png); table: "
        "[quadruped/quadruped.csv](quadruped/quadruped.csv).",
        "",
        "Checks: " + "; ".join(f"{k}: {'ok' if v else 'FAILED'}" for k, v in checks.items()),
        "",
    ]
    return {"index": index, "ok": all(checks.values()), "checks": checks, "seconds": time.perf_counter() - t0}
