"""Command line: ``python -m vereshchagin_experiments demo`` and ``python -m vereshchagin_experiments reproduce``."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ._optional import CASE_NEEDS, missing_message


def _say(line: str) -> None:
    print(line, flush=True)


def _rel(path: Path, root: Path) -> str:
    return Path(os.path.relpath(path, root)).as_posix()


def _section(label: str, run, out: Path, quick: bool, index: list) -> bool:
    """Run one experiment section: ``run(out, quick=, progress=)`` returns ``index`` (Markdown lines,
    appended to ``index``), ``ok`` and ``seconds``. Returns ``ok``."""
    _say(f"[reproduce] {label}{' (quick)' if quick else ''}")
    res = run(out, quick=quick, progress=_say)
    index += res["index"]
    _say(f"[reproduce] {label}: {'ok' if res['ok'] else 'FAILED'} ({res['seconds']:.1f} s)")
    return bool(res["ok"])


def reproduce(out_dir, quick: bool = False, case: str = "all") -> int:
    """Run the selected experiments, write their outputs and ``index.md`` into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
    quick : bool
        Coarser sampling of the friction figures (the optimum is exact either way).
    case : {"friction", "demo", "contact", "dual-arm", "friction-energy", "wiping", "mobile", "quadruped", "all"}
        ``contact``: the three use cases of W. K. Lau (2023) in MuJoCo (:mod:`vereshchagin_experiments.contact.report`);
        ``dual-arm``: one hand of a dual-arm Gen3 resting on a table while the other slides, tree
        solver against separate chains (:mod:`vereshchagin_experiments.contact.dual_arm_report`);
        ``friction-energy``: the motor effort exact static friction saves on the Gen3
        (:mod:`vereshchagin_experiments.friction_energy_report`).
        ``mobile``: a Gen3 on a holonomic base, base locked vs base helping
        (:mod:`vereshchagin_experiments.floating.mobile_report`); ``quadruped``: Solo 12 shifting
        its weight under whole-body least effort (:mod:`vereshchagin_experiments.floating.quadruped_report`).

    Returns
    -------
    int
        0 if every check passed, 1 otherwise.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    index = [
        "# vereshchagin: reproduced results",
        "",
        f"Command: `python -m vereshchagin_experiments reproduce --out {out_dir}{' --quick' if quick else ''} --case {case}`",
        "",
    ]
    ok = True
    if case in ("friction", "all"):
        from .friction_figures import run as run_friction

        _say(f"[reproduce] Vukcevic (2018) friction figures -> {out}{' (quick)' if quick else ''}")
        res = run_friction(out, quick=quick, progress=_say)
        ok &= bool(res["ok"])
        index += [
            "## Static joint friction on the 1-DOF arm (D. Vukcevic (2018), chapters 5-6)",
            "",
            f"Table: [{_rel(res['table_md'], out)}]({_rel(res['table_md'], out)}) "
            f"(CSV: [{_rel(res['table_csv'], out)}]({_rel(res['table_csv'], out)}))",
            "",
        ]
        table = res["table_md"].read_text(encoding="utf-8").splitlines()
        index += [line for line in table if line.startswith("|")] + [""]
        index += [
            "Figures (friction torque = -mu over [-f, f], f = 10 N m; the star is the exact optimum of "
            "`Solver.solve(..., friction=...)`):",
            "",
        ]
        for num, what, path in res["figures"]:
            ref = f"report fig. {num}" if num else "no report figure"
            index.append(f"- [{_rel(path, out)}]({_rel(path, out)}): {what} ({ref})")
        index.append("")
        _say(f"[reproduce] friction checks: {'ok' if res['ok'] else 'MISMATCH'}")
    if case in ("demo", "all"):
        from .demo import run as run_demo

        _say("[reproduce] demo: three tasks on a 7-joint arm")
        lines = []

        def out_line(s=""):
            lines.append(str(s))
            _say(str(s))

        run_demo(out=out_line)
        demo_path = out / "demo.txt"
        demo_path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        index += [
            "## Demonstration (7-joint arm)",
            "",
            f"Output: [{_rel(demo_path, out)}]({_rel(demo_path, out)})",
            "",
            "```text",
            *lines,
            "```",
            "",
        ]
    if case in ("contact", "all"):
        from .contact.report import run as run_contact

        ok &= _section("Lau (2023) contact use cases (MuJoCo plant)", run_contact, out, quick, index)
    if case in ("dual-arm", "all"):
        from .contact.dual_arm_report import run as run_dual

        ok &= _section("dual-arm case on a tree robot (MuJoCo plant)", run_dual, out, quick, index)
    if case in ("friction-energy", "all"):
        from .friction_energy_report import run as run_energy

        ok &= _section("friction-energy experiment (MuJoCo Gen3)", run_energy, out, quick, index)
    if case in ("wiping", "all"):
        from .contact.wiping_report import run as run_wiping

        ok &= _section("wiping case (discrete time)", run_wiping, out, quick, index)
    if case in ("mobile", "all"):
        from .floating.mobile_report import run as run_mobile

        ok &= _section("mobile manipulation on a holonomic base (MuJoCo plant)", run_mobile, out, quick, index)
    if case in ("quadruped", "all"):
        from .floating.quadruped_report import run as run_quadruped

        ok &= _section("standing quadruped shifting its weight (MuJoCo plant)", run_quadruped, out, quick, index)
    index_path = out / "index.md"
    index_path.write_text("\n".join(index), encoding="utf-8")
    _say(f"[reproduce] wrote {index_path}")
    return 0 if ok else 1


def main(argv=None) -> int:
    """The command line (``python -m vereshchagin_experiments demo | reproduce [--out DIR] [--quick] [--case CASE]``).

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; None: ``sys.argv[1:]``.

    Returns
    -------
    int
        Exit status: 0 on success, 1 if a reproduced result failed its checks.
    """
    parser = argparse.ArgumentParser(prog="vereshchagin-experiments", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("demo", help="solve three tasks on a 7-joint arm and print the results")
    rep = sub.add_parser(
        "reproduce",
        help="reproduce the friction figures of Vukcevic (2018), the demo, the contact "
        "use cases of Lau (2023), the dual-arm case and the friction-energy experiment into a folder",
    )
    rep.add_argument("--out", default="results", help="output folder (default: ./results)")
    rep.add_argument("--quick", action="store_true", help="coarser sampling of the figures, shorter contact runs")
    rep.add_argument(
        "--case",
        choices=(*CASE_NEEDS, "all"),
        default="all",
        help="which experiments to run (default: all)",
    )
    args = parser.parse_args(argv)
    if args.command == "demo":
        from .demo import run

        run()
        return 0
    if args.command == "reproduce":
        cases = CASE_NEEDS if args.case == "all" else {args.case: CASE_NEEDS[args.case]}
        message = missing_message(sorted({m for needs in cases.values() for m in needs}))
        if message:
            print(f"vereshchagin-experiments reproduce --case {args.case}: {message}", file=sys.stderr)
            return 2
        return reproduce(args.out, quick=args.quick, case=args.case)
    return 2  # pragma: no cover


if __name__ == "__main__":
    sys.exit(main())
