"""Run the use cases of W. K. Lau (2023) in simulation and write tables, figures and the comparison text.

:func:`run` is what ``python -m vereshchagin_experiments reproduce --case contact`` calls. Tables follow the
report's layout (Tables 6.1-6.3: per joint, contact next to contactless), as Markdown and CSV;
figures are PNG (:mod:`.report_figures`). Joints are counted from 0 everywhere, as in the report's
tables (0 .. 6; its "joint 1 (shoulder)", "joint 3 (elbow)", "joint 5 (wrist)"). The published
numbers are in :mod:`.lau2023`, the fixed text (setup, gains, differences) in :mod:`.report_notes`,
the model-error section in :mod:`.report_model_error`.
"""

from __future__ import annotations

import csv
import time
from functools import partial
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from . import metrics
from .elbow import VARIANTS as ELBOW_VARIANTS, elbow
from .lau2023 import KEY_JOINTS, LAU_2023, table_means
from .model_error import run_perturbed
from .report_figures import plot_effort, plot_grasp_path, plot_writing
from .report_model_error import model_error_section
from .report_notes import differences_lines, gains_lines, setup_lines
from .use_cases import Run, grasp, writing

__all__ = ["LAU_2023", "md_table", "run", "write_csv"]


def _bar(frac: float, width: int = 24) -> str:
    k = int(round(frac * width))
    return "[" + "#" * k + "-" * (width - k) + f"] {100 * frac:5.1f} %"


def md_table(header, rows) -> list[str]:
    """Lines of a Markdown table with ``header`` (strings) and ``rows`` (sequences, shown with str)."""
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


def write_csv(path: Path, header, rows) -> None:
    """Write ``header`` and ``rows`` to the CSV file ``path`` (UTF-8)."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def _f(x, digits=3) -> str:
    return f"{x:.{digits}f}"


def _effort_rows(efforts: dict) -> tuple[list, list]:
    """Rows: joint, then for each case mean tau, mean |tau|, mean power, energies."""
    labels = list(efforts)
    header = ["joint (from 0)"]
    for lab in labels:
        header += [
            f"{lab}: avg torque [N m]",
            f"{lab}: avg |torque| [N m]",
            f"{lab}: avg power [W]",
            f"{lab}: ∫|τ q̇| [J]",
            f"{lab}: ∫τ² [N² m² s]",
        ]
    rows = []
    n = len(next(iter(efforts.values()))["mean_tau"])
    for j in range(n):
        row = [str(j)]
        for lab in labels:
            e = efforts[lab]
            row += [
                _f(e["mean_tau"][j]),
                _f(e["mean_abs_tau"][j]),
                _f(e["mean_power"][j], 4),
                _f(e["energy_abs"][j], 4),
                _f(e["energy_tau2"][j], 2),
            ]
        rows.append(row)
    tot = ["all"]
    for lab in labels:
        e = efforts[lab]
        tot += [
            _f(e["mean_tau"].mean()),
            _f(e["mean_abs_tau"].mean()),
            _f(e["mean_power"].sum(), 4),
            _f(e["energy_abs"].sum(), 4),
            _f(e["energy_tau2"].sum(), 2),
        ]
    rows.append(tot)
    return header, rows


def _verdict(same: bool) -> str:
    return "**agrees**" if same else "**disagrees**"


def _grasp_comparison(e_c, e_n) -> list[str]:
    lines = []
    for j, name in KEY_JOINTS.items():
        rc, rn = abs(LAU_2023["torque_contact"][j]), abs(LAU_2023["torque_contactless"][j])
        sc, sn = e_c["mean_abs_tau"][j], e_n["mean_abs_tau"][j]
        sim_pct = 100.0 * (sn - sc) / sc
        rep_pct = 100.0 * (rn - rc) / rc
        lines.append(
            f"- Joint {j} ({name}): contactless/contact average |torque| "
            f"{sn:.3f}/{sc:.3f} N m = {sn / sc:.2f} ({sim_pct:+.0f} % without contact); "
            f"report (Table 6.2): {rn:.3f}/{rc:.3f} = {rn / rc:.2f} ({rep_pct:+.0f} %). "
            f"Direction {_verdict((sn > sc) == (rn > rc))}."
        )
    ec, en = e_c["energy_abs"], e_n["energy_abs"]
    lines.append(
        f"- Mechanical energy over the slide, all joints: contact {ec.sum():.3f} J, contactless {en.sum():.3f} J; "
        f"copper-loss proxy ∫τ²: contact {e_c['energy_tau2'].sum():.1f}, contactless {e_n['energy_tau2'].sum():.1f} N² m² s "
        f"({100 * (e_n['energy_tau2'].sum() / e_c['energy_tau2'].sum() - 1):+.0f} % without contact). "
        f"Report: higher current/power without contact at joints 1 and 5 (+68 %, +91 % current), lower at joint 3; "
        f"the overall copper-loss proxy {_verdict(e_n['energy_tau2'].sum() > e_c['energy_tau2'].sum())} "
        "with the report's hypothesis that contact saves energy."
    )
    lines.append(_all_joint_line(e_c, e_n))
    return lines


def _all_joint_line(e_c, e_n) -> str:
    """The all-joint average torque next to Table 6.2's own values (the report's text swaps them)."""
    mc, mn = e_c["mean_abs_tau"].mean(), e_n["mean_abs_tau"].mean()
    sc, sn = e_c["mean_tau"].mean(), e_n["mean_tau"].mean()
    means = table_means()
    (rc, rn), (rc_abs, rn_abs) = means["signed"], means["abs"]
    text = LAU_2023["text_all_joint_torque"]
    return (
        f"- Average torque over all seven joints. Table 6.2's values average to contact {rc:.4f}, contactless "
        f"{rn:.4f} N m signed (|τ|: {rc_abs:.3f}, {rn_abs:.3f}): contact {'higher' if rc > rn else 'lower'}. "
        f"(The report's text quotes contact {text['contact']}, contactless {text['contactless']} N: the two "
        f"swapped; the table is quoted here.) Here: signed {sc:.3f} / {sn:.3f}, |τ| {mc:.3f} / {mn:.3f} N m "
        f"(contact / contactless): contact {'higher' if mc > mn else 'lower'} in |τ|, "
        f"{_verdict((mc > mn) == (rc_abs > rn_abs))} with the table."
    )


def _power_rows(e_c, e_n) -> tuple[list, list]:
    """Table 6.1 per joint next to Table 6.2's torque and our signed average torque."""
    header = [
        "joint (from 0)",
        "report V·I contact [W]",
        "report V·I contactless [W]",
        "report contactless/contact V·I",
        "report contactless/contact τ",
        "ours contactless/contact τ",
        "report V·I / τ contact, contactless [W/(N m)]",
    ]
    rows = []
    for j in range(7):
        pc, pn = LAU_2023["power_contact"][j], LAU_2023["power_contactless"][j]
        tc, tn = LAU_2023["torque_contact"][j], LAU_2023["torque_contactless"][j]
        oc, on = e_c["mean_tau"][j], e_n["mean_tau"][j]
        rows.append(
            [
                str(j),
                f"{pc:.4f}",
                f"{pn:.4f}",
                f"{pn / pc:+.2f}",
                f"{tn / tc:+.2f}",
                f"{on / oc:+.2f}",
                f"{pc / tc:+.2f}, {pn / tn:+.2f}",
            ]
        )
    return header, rows


def _power_section(e_c, e_n, out: Path) -> list[str]:
    """Table 6.1 of the report, printed, and compared with signed torque (its power follows the signed current)."""
    header, rows = _power_rows(e_c, e_n)
    write_csv(out / "grasp_power_table_6_1.csv", header, rows)
    lines = []
    for j, name in KEY_JOINTS.items():
        rp = LAU_2023["power_contactless"][j] / LAU_2023["power_contact"][j]
        ours = e_n["mean_tau"][j] / e_c["mean_tau"][j]
        same = (abs(rp) > 1.0) == (abs(ours) > 1.0) and np.sign(rp) == np.sign(ours)
        lines.append(
            f"- Joint {j} ({name}): report V·I contactless/contact {rp:+.2f}, our signed torque {ours:+.2f}: "
            f"{_verdict(same)} (same sign and same side of 1 in size)."
        )
    sc, sn = e_c["mean_tau"][1], e_n["mean_tau"][1]
    if np.sign(sc) != np.sign(sn):
        lines.append(
            f"- Our shoulder (joint 1) torque changes sign in contact ({sc:+.2f} vs {sn:+.2f} N m contactless): the "
            "table's reaction at the tool more than carries the arm there, so the shoulder presses down; the "
            "report's keeps its sign (Table 6.2: +9.85, +16.76 N m)."
        )
    pc, pn = np.array(LAU_2023["power_contact"]), np.array(LAU_2023["power_contactless"])
    tc, tn = np.array(LAU_2023["torque_contact"]), np.array(LAU_2023["torque_contactless"])
    keeps = [str(j) for j in range(7) if np.sign(pc[j] / tc[j]) == np.sign(pn[j] / tn[j])]
    return [
        "The report's Table 6.1 (average power consumption) is bus voltage (about 23.3 V on every joint) times "
        "the signed current, not an energy: it follows the signed motor torque (current ~ torque, with a sign "
        "convention of its own per joint). The last column shows it: V·I / τ of Table 6.1 over Table 6.2 has "
        f"the same sign in both cases on joints {', '.join(keeps)}. So it is compared with our signed average "
        "torque, not with mechanical power:",
        "",
        *md_table(header, rows),
        "",
        *lines,
        "",
        f"CSV: [{_rel(out / 'grasp_power_table_6_1.csv')}]({_rel(out / 'grasp_power_table_6_1.csv')})",
        "",
    ]


def _rel(p: Path) -> str:
    return f"contact/{p.name}"


def _run_jobs(quick: bool, say: Callable[[str], None]) -> dict:
    """Simulate every use case and variant; keys (case, variant)."""
    jobs: list[tuple[str, str, Callable[[], Run]]] = [
        ("grasp", "contact", partial(grasp, True, quick)),
        ("grasp", "contactless", partial(grasp, False, quick)),
        ("writing", "contact", partial(writing, True, quick)),
        ("writing", "contactless", partial(writing, False, quick)),
    ]
    jobs += [("elbow", v, partial(elbow, v, quick)) for v in ELBOW_VARIANTS]
    runs = {}
    for k, (case, variant, job) in enumerate(jobs):
        t0 = time.perf_counter()
        runs[(case, variant)] = job()
        say(
            f"[contact] {_bar((k + 1) / len(jobs))} {case} {variant} "
            f"({runs[(case, variant)].t[-1]:.1f} s simulated in {time.perf_counter() - t0:.1f} s)"
        )
    return runs


def _intro_lines(quick: bool) -> list[str]:
    """The section's heading, the plant and controller, the gains and the differences from the report."""
    return [
        "## Exploiting contact surfaces: the use cases of W. K. Lau (2023) in simulation",
        "",
        *setup_lines(quick),
        *gains_lines(),
        *differences_lines(),
    ]


def _grasp_section(runs: dict, out: Path) -> tuple[list[str], bool]:
    """Use case 1: tables, figures and index lines; whether its physical checks pass."""
    gc, gn = runs[("grasp", "contact")], runs[("grasp", "contactless")]
    oc, on = metrics.grasp_outcome(gc), metrics.grasp_outcome(gn)
    e_c, e_n = metrics.effort(gc, gc.window("slide")), metrics.effort(gn, gn.window("slide"))
    header, rows = _effort_rows({"contact": e_c, "contactless": e_n})
    write_csv(out / "grasp_effort.csv", header, rows)
    p1, p2 = out / "grasp_torque_power.png", out / "grasp_trajectories.png"
    reference = {"contact": LAU_2023["torque_contact"], "contactless": LAU_2023["torque_contactless"]}
    plot_effort(p1, {"contact": gc, "contactless": gn}, "slide", "Use case 1, slide: torque and power", reference)
    plot_grasp_path(p2, {"contact": gc, "contactless": gn}, "Use case 1: where the gripper goes")
    grasp_ok = (
        oc["contact_detected"]
        and abs(oc["distance_x"] - 0.10) <= 0.005
        and oc["contact_fraction"] > 0.95
        and not gn.table_touch
        and not metrics.grasp_outcome(gn)["contact_detected"]
    )
    (out / "grasp_effort.md").write_text("\n".join(md_table(header, rows)) + "\n", encoding="utf-8")
    lines = [
        "### Use case 1: grasp by sliding (cf. report Tables 6.1, 6.2)",
        "",
        f"Contact: detected at t = {oc['contact_time']:.3f} s; slid {1e3 * oc['distance_x']:.1f} mm along x "
        f"in contact for {100 * oc['contact_fraction']:.1f} % of the slide (mean normal force "
        f"{oc['mean_table_force']:.1f} N); arm parts touching the table: {', '.join(oc['touched']) or 'none'}; "
        f"final x error {1e3 * oc['final_error_x']:+.2f} mm. Contactless: slid {1e3 * on['distance_x']:.1f} mm, "
        f"table touched: {'yes (' + ', '.join(gn.table_touch) + ')' if gn.table_touch else 'never'}. "
        f"Checks: {'ok' if grasp_ok else 'FAILED'}.",
        "",
        "Per joint over the slide (avg torque signed as in Table 6.2; power = τ q̇ is mechanical; the "
        "report's Table 6.1 follows below):",
        "",
        *md_table(header, rows),
        "",
        f"CSV: [{_rel(out / 'grasp_effort.csv')}]({_rel(out / 'grasp_effort.csv')}); figures: "
        f"[{_rel(p1)}]({_rel(p1)}), [{_rel(p2)}]({_rel(p2)})",
        "",
        "How contact changes torque and energy, next to the report's measurements (section 6.2):",
        "",
        *_grasp_comparison(e_c, e_n),
        f"- Why the wrist (joint 5) differs: with z released the table carries the arm's weight along the released "
        f"direction, here {oc['mean_table_force']:.0f} N at the gripper's lowest edge; its moment about joint 5 "
        f"keeps the wrist near its 9 N m limit in contact (avg |τ| {e_c['mean_abs_tau'][5]:.2f} N m). The report's "
        "shoulder drop (6.9 N m) suggests a much smaller pressing force on the real arm (about 12 N at a 0.55 m "
        "lever), whose own joint controllers are not modelled here.",
        "",
        *_power_section(e_c, e_n, out),
    ]
    return lines, grasp_ok


def _writing_rows(ac: dict, an: dict) -> tuple[list, list]:
    """Table 6.3's layout (m), with the maximum's place and the stroke without its end added."""
    header = [
        "case",
        "maximum displacement (m)",
        "at x (mm)",
        f"maximum before the last {1e3 * metrics.STROKE_END:g} mm (m)",
        "average displacement (m)",
        f"average before the last {1e3 * metrics.STROKE_END:g} mm (m)",
        "line length (m)",
        "in contact",
        "report max (m)",
        "report average (m)",
    ]
    rows = []
    for name, a, key in (("Contact", ac, "writing_contact"), ("Contactless", an, "writing_contactless")):
        rows.append(
            [
                name,
                f"{a['max_displacement']:.8f}",
                f"{1e3 * a['max_at']:.1f}",
                f"{a['max_displacement_stroke']:.8f}",
                f"{a['mean_displacement']:.8f}",
                f"{a['mean_displacement_stroke']:.8f}",
                f"{a['length']:.4f}",
                f"{100 * a['contact_fraction']:.1f} %",
                *map(str, LAU_2023[key]),
            ]
        )
    return header, rows


def _writing_findings(ac: dict, an: dict) -> list[str]:
    """Maximum and average displacement, contact against contactless, next to Table 6.3."""
    (rmc, rac), (rmn, ran) = LAU_2023["writing_contact"], LAU_2023["writing_contactless"]
    end = 1e3 * (0.10 - metrics.STROKE_END)
    less = ac["max_displacement"] > an["max_displacement"]
    less_stroke = ac["max_displacement_stroke"] > an["max_displacement_stroke"]
    ratio = abs(ac["mean_displacement"]) / abs(an["mean_displacement"])
    ratio_stroke = abs(ac["mean_displacement_stroke"]) / abs(an["mean_displacement_stroke"])
    return [
        f"- Maximum displacement: the report found contact less accurate ({1e3 * rmc:.2f} mm vs {1e3 * rmn:.2f} mm). "
        f"Here contact {1e3 * ac['max_displacement']:.3f} mm (at x = {1e3 * ac['max_at']:.1f} mm) vs contactless "
        f"{1e3 * an['max_displacement']:.3f} mm (at x = {1e3 * an['max_at']:.1f} mm): contact is "
        f"{'less' if less else 'more'} accurate, which {_verdict(less)} with the report. A maximum beyond "
        f"x = {end:.0f} mm is a spike at the stroke's end, where the pen stops (and, short of 100 mm, keeps being "
        f"counted while it stands 1.5 s); before it: contact {1e3 * ac['max_displacement_stroke']:.3f} mm vs "
        f"contactless {1e3 * an['max_displacement_stroke']:.3f} mm, contact {'less' if less_stroke else 'more'} "
        f"accurate: {_verdict(less_stroke)}.",
        f"- Average displacement: the report's was {abs(rac) / abs(ran):.1f}× larger in contact "
        f"({1e3 * rac:+.3f} mm vs {1e3 * ran:+.3f} mm). Here contact {1e3 * ac['mean_displacement']:+.3f} mm vs "
        f"contactless {1e3 * an['mean_displacement']:+.3f} mm: {ratio:.2f}× in size, "
        f"{'larger' if ratio > 1 else 'smaller'} in contact, {_verdict(ratio > 1)}; before the stroke's end "
        f"{1e3 * ac['mean_displacement_stroke']:+.3f} vs {1e3 * an['mean_displacement_stroke']:+.3f} mm "
        f"({ratio_stroke:.2f}×): {_verdict(ratio_stroke > 1)}.",
        "- The simulated table is flat and uniform (the report blamed surface unevenness and friction): the "
        f"largest displacement here, {1e3 * max(ac['max_displacement'], an['max_displacement']):.2f} mm, is "
        f"{100 * max(ac['max_displacement'], an['max_displacement']) / rmc:.0f} % of the report's contact maximum.",
    ]


def _writing_section(runs: dict, out: Path) -> tuple[list[str], bool]:
    """Use case 2: tables, figures and index lines; whether its physical checks pass."""
    wc, wn = runs[("writing", "contact")], runs[("writing", "contactless")]
    ac, an = metrics.writing_accuracy(wc), metrics.writing_accuracy(wn)
    w_ok = (
        wc.contact_time is not None
        and ac["contact_fraction"] > 0.95
        and not wn.table_touch
        and abs(ac["length"] - 0.10) < 0.005
        and abs(an["length"] - 0.10) < 0.005
    )
    wh, wrows = _writing_rows(ac, an)
    write_csv(out / "writing_accuracy.csv", wh, wrows)
    (out / "writing_accuracy.md").write_text("\n".join(md_table(wh, wrows)) + "\n", encoding="utf-8")
    ew_c, ew_n = metrics.effort(wc, wc.window("write")), metrics.effort(wn, wn.window("write"))
    wheader, wrows2 = _effort_rows({"contact": ew_c, "contactless": ew_n})
    write_csv(out / "writing_effort.csv", wheader, wrows2)
    p3, p4 = out / "writing_line.png", out / "writing_torque_power.png"
    plot_writing(p3, {"contact": wc, "contactless": wn}, "Use case 2: the pen tip")
    plot_effort(p4, {"contact": wc, "contactless": wn}, "write", "Use case 2, writing: torque and power")
    lines = [
        "### Use case 2: writing a 10 cm line (cf. report Table 6.3)",
        "",
        *md_table(wh, wrows),
        "",
        f"Pen on the paper for {100 * ac['contact_fraction']:.1f} % of the drawn line; contactless pen "
        f"{'touched the table' if wn.table_touch else 'never touched the table'}. Checks: {'ok' if w_ok else 'FAILED'}.",
        "",
        *_writing_findings(ac, an),
        f"- Effort while writing, all joints: ∫τ² contact {ew_c['energy_tau2'].sum():.1f}, contactless "
        f"{ew_n['energy_tau2'].sum():.1f} N² m² s; ∫|τ q̇| contact {ew_c['energy_abs'].sum():.3f} J, contactless "
        f"{ew_n['energy_abs'].sum():.3f} J.",
        "",
        f"Tables: [{_rel(out / 'writing_accuracy.csv')}]({_rel(out / 'writing_accuracy.csv')}), "
        f"[{_rel(out / 'writing_effort.csv')}]({_rel(out / 'writing_effort.csv')}); figures: "
        f"[{_rel(p3)}]({_rel(p3)}), [{_rel(p4)}]({_rel(p4)})",
        "",
    ]
    return lines, w_ok


def _elbow_section(runs: dict, out: Path) -> tuple[list[str], bool]:
    """Use case 3: tables, figures and index lines; whether its physical checks pass."""
    er = {v: runs[("elbow", v)] for v in ELBOW_VARIANTS}
    ee = {v: metrics.effort(r, r.window("slide")) for v, r in er.items()}
    eo = {v: metrics.elbow_outcome(r) for v, r in er.items()}
    eheader, erows = _effort_rows(ee)
    write_csv(out / "elbow_effort.csv", eheader, erows)
    p5 = out / "elbow_torque_power.png"
    plot_effort(p5, er, "slide", "Use case 3, resting elbow: torque and power")
    lines3 = []
    for v, r in er.items():
        o = eo[v]
        model = (
            f" (solver's constraint force -nu_e {o['model_support_force']:.1f} N)"
            if np.isfinite(o["model_support_force"])
            else ""
        )
        lines3.append(
            f"- {v}: end-effector x error at the end {1e3 * o['final_error_x']:+.1f} mm, z drift "
            f"{1e3 * o['drift_z']:+.1f} mm; elbow height {r.info['elbow_z'][0]:.4f} -> "
            f"{r.info['elbow_z'][-1]:.4f} m; support touched in {100 * o['support_fraction']:.1f} % of the "
            f"slide, mean support force {o['support_force']:.1f} N{model}; "
            f"∫τ² {ee[v]['energy_tau2'].sum():.1f} N² m² s, ∫|τ q̇| {ee[v]['energy_abs'].sum():.3f} J, "
            f"avg |τ| joint 1 (shoulder) {ee[v]['mean_abs_tau'][1]:.2f} N m."
        )
    eu, ep, ec = ee["unsupported"], ee["plant"], ee["constraint"]
    ou, op, oc3 = eo["unsupported"], eo["plant"], eo["constraint"]
    c_saves = ec["energy_tau2"].sum() < eu["energy_tau2"].sum()
    c_done = abs(oc3["final_error_x"]) < 0.005
    lines3.append(
        f"- Hypothesis (report 6.4: resting the elbow saves energy; the report could not measure it): with the "
        f"support known to the solver as a segment constraint the copper-loss proxy ∫τ² is "
        f"{100 * (ec['energy_tau2'].sum() / eu['energy_tau2'].sum() - 1):+.0f} % and the shoulder's average |τ| "
        f"{100 * (ec['mean_abs_tau'][1] / eu['mean_abs_tau'][1] - 1):+.0f} % against the unsupported arm doing the "
        f"same motion, and the task {'is' if c_done else 'is not'} completed: the simulation "
        f"{_verdict(c_saves and c_done)} with the hypothesis. The mechanical work ∫|τ q̇| is "
        f"{ec['energy_abs'].sum():.3f} J vs {eu['energy_abs'].sum():.3f} J unsupported."
    )
    lines3.append(
        f"- Support known only to the plant: ∫τ² {100 * (ep['energy_tau2'].sum() / eu['energy_tau2'].sum() - 1):+.0f} % "
        f"vs unsupported, but the support's force, unknown to the solver, also pushes the arm along the task "
        f"directions, so the end-effector ends {1e3 * op['final_error_x']:+.1f} mm from its goal along x: resting "
        "on a support without telling the solver saves less and costs accuracy; modelling it as a constraint "
        "keeps the task."
    )
    elbow_ok = (
        oc3["support_fraction"] > 0.9
        and c_done
        and c_saves
        and not er["unsupported"].support_force.any()
        and abs(ou["final_error_x"]) < 0.005
    )
    lines = [
        "### Use case 3: resting elbow (report section 6.4)",
        "",
        "A task of its own, not the report's (which gave no pose and no numbers for its failed run): the "
        "end-effector moves 0.10 m towards the base in the air (all six directions constrained); the elbow "
        "(joint 3) swung 50° sideways from the lowest point of its self-motion circle rests on a box. Variants: "
        "unsupported (no box; a segment constraint on forearm_link holds the elbow's height, the motors carry "
        "everything), plant (box; the controller does not know it and leaves the self-motion to nature), "
        "constraint (box; the same segment constraint, its upward share -J_eᵀ α_e ν_e left to the box).",
        "",
        *md_table(eheader, erows),
        "",
        *lines3,
        "",
        f"Checks: {'ok' if elbow_ok else 'FAILED'}.",
        "",
        f"CSV: [{_rel(out / 'elbow_effort.csv')}]({_rel(out / 'elbow_effort.csv')}); figure: [{_rel(p5)}]({_rel(p5)})",
        "",
    ]
    return lines, elbow_ok


def run(out_dir, quick: bool = False, progress: Optional[Callable[[str], None]] = None) -> dict:
    """Run the three use cases (both/all variants), write tables and figures into ``out_dir/contact``.

    Returns
    -------
    dict
        ``index``: Markdown lines for results/index.md; ``runs``: the runs ``{(case, variant):
        Run}``; ``perturbed``: the model-error runs ``{(seed, case, variant): Run}``; ``ok``: all
        physical checks passed; ``seconds``: wall time.
    """
    say = progress or (lambda s: None)
    out = Path(out_dir) / "contact"
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    runs = _run_jobs(quick, say)
    idx = _intro_lines(quick)
    ok = True
    for section in (_grasp_section, _writing_section, _elbow_section):
        lines, passed = section(runs, out)
        idx += lines
        ok &= passed
    perturbed = run_perturbed(quick, say=say)
    lines, passed = model_error_section(runs, perturbed, out, md_table, write_csv)
    idx += lines
    ok &= passed
    from .contact_report import section as contacts_section  # imports this module: here, not at the top

    lines, passed = contacts_section(runs, out, quick, say)
    idx += lines
    ok &= passed
    secs = time.perf_counter() - t_start
    n_runs = len(runs) + len(perturbed)
    simulated = sum(r.t[-1] for r in runs.values()) + sum(r.t[-1] for r in perturbed.values())
    idx += [
        f"Contact experiments: {n_runs} runs ({len(perturbed)} of them on perturbed plants), {simulated:.1f} s "
        f"simulated in {secs:.1f} s wall time.",
        "",
    ]
    return dict(index=idx, runs=runs, perturbed=perturbed, ok=ok, seconds=secs)
