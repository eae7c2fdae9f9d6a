"""Before / after tables of the contact cases: hand surgery on the solver's results vs the solver's contacts.

"Before" are the runs the main job always made (the table's force estimated into ``f_ext`` with z
released, the elbow's segment constraint with its upward share removed by hand, the dual-arm
resting hand's share removed by hand); "after" the same tasks with the surfaces passed to the
solve as point contacts (:mod:`.surfaces`). Added: two resting points at once (elbow and wrist,
:data:`~.elbow.CONTACT_VARIANTS`) and a comparison of table surfaces (friction coefficients
:data:`SURFACES` on the grasp's slide).

Measures per run, over the task's window (grasp ``slide``, writing ``write``, elbow and dual-arm
``slide``): task accuracy (the report's own: slide / final x error, the pen's largest y
displacement), motor effort (the copper-loss proxy ∫τ² of :func:`~.metrics.effort` and the
shoulder's average |τ|), the table's (support's) mean normal force in the MuJoCo plant next to
the model's (the ``f_ext`` estimate, ``-nu`` of the constraint, or the solver's contact force)
and the command chatter: the mean |τ_k+1 - τ_k| of the commanded torques (N m per 1 ms step),
averaged over the joints.

:func:`section` is called by :func:`.report.run` (``--case contact``), :func:`dual_arm_section` by
:func:`.dual_arm_report.run` (``--case dual-arm``).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

import numpy as np

from . import metrics
from .dual_arm import BAND_CONFIG as DUAL_BAND_CONFIG, CONTACT_VARIANT, dual_arm
from .elbow import CONTACT_VARIANTS, elbow
from .report import md_table, write_csv
from .surfaces import BAND_CONFIG, WRITING_FORCE
from .use_cases import grasp, writing

__all__ = ["SURFACES", "chatter", "dual_arm_section", "section"]

SURFACES = (0.1, 0.3, 0.6)
"""Friction coefficients of the table compared on the grasp's slide (plant and contact alike)."""
WINDOWS = {"grasp": "slide", "writing": "write", "elbow": "slide", "dual-arm": "slide"}
WRIST_LIMIT = 9.0
"""N m: the effort limit of joints 5-7 (the plant clips the command there)."""
FORCE_RATIO = (0.5, 2.0)
"""Accepted range of plant / model mean force for the contact variants' checks."""
SHOULDER = {"grasp": 1, "writing": 1, "elbow": 1, "dual-arm": 2}  # joint index of the (left) shoulder


def chatter(run, window: str) -> float:
    """Mean |τ_k+1 - τ_k| of the commanded torques over ``window``'s samples and all joints (N m per step)."""
    cmd = np.asarray(run.info["command"])[run.window(window)]
    return float(np.abs(np.diff(cmd, axis=0)).mean()) if len(cmd) > 1 else float("nan")


def _forces(run, window: str) -> tuple[float, float]:
    """Mean normal force of the plant's table (or elbow support) and the model's, over ``window`` (N)."""
    m = run.window(window)
    if run.case == "elbow":
        return float(run.support_force[m].mean()), float(np.asarray(run.info["support_force_model"])[m].mean())
    return float(run.table_force[m].mean()), float(np.asarray(run.info["table_force_model"])[m].mean())


def _accuracy(run) -> tuple[str, float]:
    """The case's accuracy measure (label, mm)."""
    if run.case == "grasp":
        return "slide x error", 1e3 * metrics.grasp_outcome(run)["final_error_x"]
    if run.case == "writing":
        return "pen max y displacement", 1e3 * metrics.writing_accuracy(run)["max_displacement"]
    if run.case == "elbow":
        return "tool x error", 1e3 * metrics.elbow_outcome(run)["final_error_x"]
    return "sliding hand x error", 1e3 * metrics.dual_arm_outcome(run)["final_error_x"]


def _numbers(run) -> dict:
    """Accuracy, effort, forces and chatter of one run over its case's window."""
    w = WINDOWS[run.case]
    e = metrics.effort(run, run.window(w))
    label, acc = _accuracy(run)
    plant, model = _forces(run, w)
    return dict(
        accuracy_label=label,
        accuracy=acc,
        tau2=float(e["energy_tau2"].sum()),
        shoulder=float(e["mean_abs_tau"][SHOULDER[run.case]]),
        plant=plant,
        model=model,
        chatter=chatter(run, w),
    )


def _rows(pairs) -> tuple[list, list, dict]:
    """Header, rows and numbers for ``pairs`` of ``(case label, variant label, run)``."""
    header = ["case", "variant", "accuracy [mm]", "∫τ² [N² m² s]", "shoulder avg |τ| [N m]"]
    header += ["surface force plant / model [N]", "command chatter [N m/step]"]
    rows, nums = [], {}
    for case, variant, run in pairs:
        n = _numbers(run)
        nums[(case, variant)] = n
        rows.append(
            [
                case,
                variant,
                f"{n['accuracy_label']} {n['accuracy']:+.2f}",
                f"{n['tau2']:.1f}",
                f"{n['shoulder']:.2f}",
                f"{n['plant']:.1f} / {n['model']:.1f}",
                f"{n['chatter']:.4f}",
            ]
        )
    return header, rows, nums


def _force_ok(n: dict) -> bool:
    lo, hi = FORCE_RATIO
    return n["model"] > 0.0 and lo < n["plant"] / n["model"] < hi


def _timed(say: Callable[[str], None], label: str, job: Callable):
    t0 = time.perf_counter()
    run = job()
    say(f"[contacts] {label} ({run.t[-1]:.1f} s simulated in {time.perf_counter() - t0:.1f} s)")
    return run


def _after_runs(quick: bool, say) -> dict:
    """The runs with the solver's contacts, keyed like the report's ``(case, variant)``."""
    jobs = {
        ("grasp", "solver-contacts"): lambda: grasp(True, quick, solver_contacts=True),
        ("writing", "solver-contacts"): lambda: writing(True, quick, solver_contacts=True),
        ("grasp", "instant + band"): lambda: grasp(True, quick, solver_contacts=True, settings=BAND_CONFIG),
        ("writing", "instant + band"): lambda: writing(True, quick, solver_contacts=True, settings=BAND_CONFIG),
    }
    jobs.update({("elbow", v): (lambda v=v: elbow(v, quick)) for v in CONTACT_VARIANTS})
    for mu in SURFACES:
        if mu != 0.3:
            jobs[("grasp", f"mu {mu}")] = lambda mu=mu: grasp(True, quick, solver_contacts=True, mu=mu)
    return {key: _timed(say, " ".join(key), job) for key, job in jobs.items()}


def _surface_rows(runs: dict) -> tuple[list, list, dict]:
    """The grasp's slide on each table surface: accuracy, effort, forces, the model's friction force."""
    header = ["table μ", "slid [mm]", "in contact [%]", "∫τ² [N² m² s]", "elbow avg |τ| [N m]"]
    header += ["table force plant / model [N]", "model friction force [N]", "command chatter [N m/step]"]
    header += ["joint 5 at its limit [%]"]  # the wrist, counted from 0 as in the report
    rows, nums = [], {}
    for mu in SURFACES:
        r = runs[("grasp", "solver-contacts" if mu == 0.3 else f"mu {mu}")]
        m = r.window("slide")
        o, e, n = metrics.grasp_outcome(r), metrics.effort(r, m), _numbers(r)
        ft = np.asarray(r.info.get("friction_force_model", np.zeros(len(r.t))))[m].mean()
        sat = float((np.abs(np.asarray(r.info["command"])[m, 5]) >= WRIST_LIMIT).mean())
        nums[mu] = dict(
            n, distance=o["distance_x"], fraction=o["contact_fraction"], elbow=e["mean_abs_tau"][3], sat=sat
        )
        rows.append(
            [
                f"{mu}",
                f"{1e3 * o['distance_x']:.1f}",
                f"{100 * o['contact_fraction']:.1f}",
                f"{n['tau2']:.1f}",
                f"{e['mean_abs_tau'][3]:.2f}",
                f"{n['plant']:.1f} / {n['model']:.1f}",
                f"{ft:.1f}",
                f"{n['chatter']:.3f}",
                f"{100 * sat:.1f}",
            ]
        )
    return header, rows, nums


def _smooth(x, n: int = 50) -> np.ndarray:
    """Moving mean over ``n`` samples (the plant's contact force bounces at 1 kHz)."""
    x = np.asarray(x, float)
    return np.convolve(x, np.ones(n) / n, mode="same") if len(x) > n else x


def _plot(path: Path, pairs, surfaces: dict) -> None:
    """Plant vs model surface force over each task window (before dashed, after solid) and ∫τ² per μ."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [c for c in ("grasp", "writing", "elbow") if any(p[0] == c for p in pairs)]
    fig, axes = plt.subplots(1, len(cases) + 1, figsize=(4.2 * (len(cases) + 1), 3.6))
    for ax, case in zip(axes, cases):
        for k, (_c, variant, run) in enumerate(p for p in pairs if p[0] == case):
            m = run.window(WINDOWS[case])
            t = run.t[m] - run.t[m][0]
            plant = (run.support_force if case == "elbow" else run.table_force)[m]
            model = np.asarray(run.info["support_force_model" if case == "elbow" else "table_force_model"])[m]
            ls = "--" if k == 0 else "-"
            ax.plot(t, _smooth(plant), ls, color="C0", lw=1, label=f"plant (50 ms mean), {variant}")
            ax.plot(t, _smooth(model), ls, color="C3", lw=1, label=f"model (50 ms mean), {variant}")
        ax.set_title(f"{case}: surface force")
        ax.set_xlabel("time in the task [s]")
        ax.set_ylabel("N")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    mus = sorted(surfaces)
    axes[-1].bar([str(m) for m in mus], [surfaces[m]["tau2"] for m in mus], color="C2")
    axes[-1].set_title("grasp slide: ∫τ² per table μ")
    axes[-1].set_xlabel("table friction coefficient μ")
    axes[-1].set_ylabel("N² m² s")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _text(nums: dict, surf: dict, checks: dict, quick: bool) -> list[str]:
    """The comparison's bullet points."""
    g0, g1 = nums[("grasp", "before")], nums[("grasp", "after")]
    w0, w1 = nums[("writing", "before")], nums[("writing", "after")]
    e0, e1, e2 = nums[("elbow", "before")], nums[("elbow", "after")], nums[("elbow", "elbow+wrist")]
    gb, wb = nums[("grasp", "after, instant + band")], nums[("writing", "after, instant + band")]
    lo, hi = min(surf), max(surf)
    return [
        f"- Grasp: slide x error {g0['accuracy']:+.2f} -> {g1['accuracy']:+.2f} mm, ∫τ² {g0['tau2']:.1f} -> "
        f"{g1['tau2']:.1f} N² m² s; the table's force in the plant {g0['plant']:.1f} N against the f_ext estimate "
        f"{g0['model']:.1f} N before, {g1['plant']:.1f} N against the solver's support force {g1['model']:.1f} N after; "
        f"chatter {g0['chatter']:.3f} -> {g1['chatter']:.3f} N m/step.",
        f"- Writing (pen set-point {WRITING_FORCE:.0f} N after; before, the arm's weight pressed along the released z): "
        f"largest y displacement {w0['accuracy']:.2f} -> {w1['accuracy']:.2f} mm, ∫τ² {w0['tau2']:.1f} -> "
        f"{w1['tau2']:.1f} N² m² s, table force plant / model {w0['plant']:.1f} / {w0['model']:.1f} -> "
        f"{w1['plant']:.1f} / {w1['model']:.1f} N, chatter {w0['chatter']:.3f} -> {w1['chatter']:.3f} N m/step.",
        f"- Elbow: tool x error {e0['accuracy']:+.2f} -> {e1['accuracy']:+.2f} mm, ∫τ² {e0['tau2']:.1f} -> "
        f"{e1['tau2']:.1f} N² m² s, support force plant / model {e0['plant']:.1f} / {e0['model']:.1f} -> "
        f"{e1['plant']:.1f} / {e1['model']:.1f} N, chatter {e0['chatter']:.3f} -> {e1['chatter']:.3f} N m/step.",
        f"- Two resting points (elbow on its support and the gripper on a table under the wrist, both contacts in "
        f"the solve): ∫τ² {e2['tau2']:.1f} N² m² s against {e1['tau2']:.1f} with the elbow alone, shoulder avg |τ| "
        f"{e2['shoulder']:.2f} vs {e1['shoulder']:.2f} N m; elbow support plant / model {e2['plant']:.1f} / "
        f"{e2['model']:.1f} N, wrist table {e2['wrist_plant']:.1f} / {e2['wrist_model']:.1f} N; tool x error "
        f"{e2['accuracy']:+.2f} mm.",
        "- The discrete-time mode (the after runs' friction-aware solve posed over the next 1 ms control period, "
        "`time_step=`) against the same runs at the instant with a hold band of 1 mm / 0.01 rad (the before of "
        f"issue 27): chatter grasp {gb['chatter']:.3f} -> {g1['chatter']:.3f}, writing {wb['chatter']:.3f} -> "
        f"{w1['chatter']:.3f} N m/step; accuracy grasp {gb['accuracy']:+.2f} -> {g1['accuracy']:+.2f} mm, writing "
        f"{wb['accuracy']:.2f} -> {w1['accuracy']:.2f} mm. The elbow with the wrist on a table keeps its band "
        "(`elbow.ELBOW_WRIST_CONFIG`).",
        f"- Surfaces: sliding the gripper on a table of μ = {lo} costs ∫τ² {surf[lo]['tau2']:.1f} N² m² s, on μ = "
        f"{hi} {surf[hi]['tau2']:.1f} (slid {1e3 * surf[lo]['distance']:.1f} and {1e3 * surf[hi]['distance']:.1f} mm); "
        "the solver's support carries the friction μ f_n against the sliding, the motors the rest. "
        + _short_slides(surf),
        "",
        "Checks: " + "; ".join(f"{k} {'ok' if v else 'FAILED'}" for k, v in checks.items()) + ".",
        "",
    ]


def _short_slides(surf: dict) -> str:
    """A sentence on the surfaces whose slide fell short of 10 cm (and the wrist's limit then)."""
    short = [mu for mu, s in surf.items() if abs(s["distance"] - 0.10) > 0.005]
    if not short:
        return "Every surface: the 10 cm slide done."
    return (
        "Slide short of 10 cm on μ = "
        + ", ".join(
            f"{mu} ({1e3 * surf[mu]['distance']:.1f} mm; joint 5 at its 9 N m limit {100 * surf[mu]['sat']:.0f} % of the slide)"
            for mu in short
        )
        + ": the wrist cannot hold the tool's orientation under that load, and the task crawls."
    )


def section(runs: dict, out: Path, quick: bool = False, say: Callable[[str], None] = lambda s: None):
    """The contact cases before / after, two resting points and the surfaces; ``(index lines, ok)``.

    Parameters
    ----------
    runs : dict
        The report's runs, keyed ``(case, variant)``: ``("grasp", "contact")``, ``("writing",
        "contact")`` and ``("elbow", "constraint")`` are the "before".
    out : Path
        Folder for ``contacts_before_after.csv``, ``contacts_surfaces.csv`` and
        ``contacts_before_after.png``.
    quick : bool
        The report's mode (the new runs use the same).
    say : callable
        Progress lines.
    """
    after = _after_runs(quick, say)
    pairs = [
        ("grasp", "before", runs[("grasp", "contact")]),
        ("grasp", "after", after[("grasp", "solver-contacts")]),
        ("writing", "before", runs[("writing", "contact")]),
        ("writing", "after", after[("writing", "solver-contacts")]),
        ("elbow", "before", runs[("elbow", "constraint")]),
        ("elbow", "after", after[("elbow", "support")]),
        ("elbow", "elbow+wrist", after[("elbow", "elbow+wrist")]),
        ("grasp", "after, instant + band", after[("grasp", "instant + band")]),
        ("writing", "after, instant + band", after[("writing", "instant + band")]),
    ]
    header, rows, nums = _rows(pairs)
    two = after[("elbow", "elbow+wrist")]
    m = two.window("slide")
    nums[("elbow", "elbow+wrist")].update(
        wrist_plant=float(two.table_force[m].mean()), wrist_model=float(two.info["table_force_model"][m].mean())
    )
    sheader, srows, surf = _surface_rows(after)
    write_csv(out / "contacts_before_after.csv", header, rows)
    write_csv(out / "contacts_surfaces.csv", sheader, srows)
    fig = out / "contacts_before_after.png"
    _plot(fig, pairs[:6], surf)
    checks = _checks(nums, surf, after)
    return [
        "### Contacts in the solver: before and after",
        "",
        "Before: the hand surgery (table force estimated into f_ext with z released; the elbow's segment "
        "constraint with its upward share left to the support by hand). After: the surfaces as the solver's "
        "point contacts (`vs.Contact`): the gripper's lowest edge a support with the table's μ, the pen tip a "
        f"normal-force set-point of {WRITING_FORCE:.0f} N, the lowest point of the elbow sphere a support; the "
        "commanded torque is the solver's `tau_command` (plus the posture term), nothing removed by hand. "
        "Accuracy: grasp final x error of the slide, writing largest y displacement (Table 6.3), elbow final x "
        "error of the tool; effort and chatter over the task's window.",
        "",
        *md_table(header, rows),
        "",
        "Table surfaces, grasp slide with the solver's contacts:",
        "",
        *md_table(sheader, srows),
        "",
        *_text(nums, surf, checks, quick),
        "CSV: [contact/contacts_before_after.csv](contact/contacts_before_after.csv), "
        "[contact/contacts_surfaces.csv](contact/contacts_surfaces.csv); figure: "
        "[contact/contacts_before_after.png](contact/contacts_before_after.png)",
        "",
    ], all(checks.values())


def _checks(nums: dict, surf: dict, after: dict) -> dict:
    """Named pass/fail checks of the runs with the solver's contacts (in the MuJoCo plant)."""
    g = metrics.grasp_outcome(after[("grasp", "solver-contacts")])
    w = metrics.writing_accuracy(after[("writing", "solver-contacts")])
    e1 = metrics.elbow_outcome(after[("elbow", "support")])
    e2 = metrics.elbow_outcome(after[("elbow", "elbow+wrist")])
    two = after[("elbow", "elbow+wrist")]
    return {
        "grasp slides 10 cm on the table": abs(g["distance_x"] - 0.10) <= 0.005 and g["contact_fraction"] > 0.95,
        "pen on the paper, 10 cm line": w["contact_fraction"] > 0.95 and abs(w["length"] - 0.10) < 0.005,
        "elbow rests, task done": e1["support_fraction"] > 0.9 and abs(e1["final_error_x"]) < 0.005,
        "elbow and wrist rest, task done": e2["support_fraction"] > 0.9
        and (two.table_force[two.window("slide")] > 0).mean() > 0.9
        and abs(e2["final_error_x"]) < 0.005,
        "plant vs model force within x0.5..2": all(
            _force_ok(nums[k]) for k in (("grasp", "after"), ("writing", "after"), ("elbow", "after"))
        ),
        "every surface: on the table, plant vs model force within x0.5..2": all(
            s["fraction"] > 0.95 and _force_ok(s) for s in surf.values()
        ),
    }


def dual_arm_section(before, quick: bool = False, say: Callable[[str], None] = lambda s: None):
    """The dual-arm case before (``table``: share removed by hand) and after (``contacts``); ``(lines, ok, run)``."""
    after = _timed(say, "dual-arm contacts", lambda: dual_arm(CONTACT_VARIANT, quick))
    band = _timed(
        say, "dual-arm contacts, instant + band", lambda: dual_arm(CONTACT_VARIANT, quick, config=DUAL_BAND_CONFIG)
    )
    pairs = [("dual-arm", "before", before), ("dual-arm", "after", after), ("dual-arm", "after, instant + band", band)]
    header, rows, nums = _rows(pairs)
    o = metrics.dual_arm_outcome(after)
    ok = o["table_fraction"] > 0.99 and abs(o["final_error_x"]) < 0.005 and o["rest_drift"] < 0.005
    ok = ok and _force_ok(nums[("dual-arm", "after")])
    n0, n1 = nums[("dual-arm", "before")], nums[("dual-arm", "after")]
    lines = [
        "Contacts in the solver: the resting hand before (6-D hold, the upward share -J_rᵀ e_z ν_z removed by "
        "hand) and after (the hand's point a support with the table's μ in the tree solve, the task holding only "
        "the hand's orientation: the table holds its position; module doc of `dual_arm` for why):",
        "",
        *md_table(header, rows),
        "",
        f"Resting hand drift {1e3 * o['rest_drift']:.2f} mm after; ∫τ² {n0['tau2']:.1f} -> {n1['tau2']:.1f} N² m² s; "
        f"chatter {n0['chatter']:.3f} -> {n1['chatter']:.3f} N m/step (the after run at the instant with the "
        f"hold band: {nums[('dual-arm', 'after, instant + band')]['chatter']:.3f}). Check (hand on the table, slide done, "
        f"resting hand within 5 mm, plant vs model force within x0.5..2): {'ok' if ok else 'FAILED'}.",
        "",
    ]
    return lines, ok, after
