#!/usr/bin/env python3
"""Build and run both benchmarks and write BENCHMARKS.md at the repository root.

  python benchmarks/run_all.py [--build-dir DIR] [--out FILE]

1. configures and builds the C++ benchmarks (Release, benchmarks on, tests off) in DIR
   (default: build/bench under the repository) with CMake and Ninja;
2. runs DIR/benchmarks/bench_solver (ours vs KDL, about 35 s);
3. runs benchmarks/bench_pinocchio.py (ours vs Pinocchio from Python, about 25 s);
4. runs DIR/benchmarks/bench_friction (static friction: ours vs our plain solve, KDL and the
   report's vertex enumeration, about 30 s) and benchmarks/bench_friction_pinocchio.py (static
   friction vs Pinocchio's JointFrictionConstraintModel + ADMM, about 10 s);
5. runs benchmarks/bench_segments.py (constraints on 1, 2, 3 segments vs Pinocchio's KKT solve, from
   Python, about 15-20 s) and benchmarks/bench_python_face.py (the Python call's overhead over the C++
   solve, out=, solve_batch per row and with threads=2, about 15 s) and benchmarks/bench_tree.py
   (trees: Baxter with one or two hands constrained and random trees of 15-60 joints vs Pinocchio's
   pipeline, from Python, about 60 s) and DIR/benchmarks/bench_contacts (the Gen3 with 4 point
   contacts and a 3-D task vs plain solves, about 15 s) and DIR/benchmarks/bench_step and
   benchmarks/bench_step.py (the time step and the Simulator vs friction-aware solves, C++ and
   Python, about 10 s each);
   and, when CMake found Pinocchio's C++ headers, DIR/benchmarks/bench_tree_kkt (Baxter: our
   TreeHdSolver vs a dense KKT solve from Pinocchio's C++ pieces, about 20 s) and
   DIR/benchmarks/bench_pv (Gen3, tip held: ours vs Pinocchio's pv and constrainedABA, about 5 s)
   and DIR/benchmarks/bench_contacts_pinocchio (the contacts of bench_contacts vs Pinocchio's ADMM
   and PGS at 1e-10, about 70 s); then benchmarks/bench_contacts_pinocchio.py (the same from
   Python, about 3 min) and benchmarks/bench_hold_creep.py (a friction-held Gen3's creep: ours
   against MuJoCo and Pinocchio's ADMM, about 5 s), benchmarks/bench_energy.py (passive energy of a
   swinging Gen3: our integrators against MuJoCo's, about 5 s) and DIR/benchmarks/bench_realtime (the friction
   stage's iteration counts over 10^6 instant solves and 5.2 10^6 steps, about 1 min);
6. writes FILE (default: BENCHMARKS.md) with the machine, compiler, flags, library versions,
   the method, the target checks and all reports.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

REPO = Path(__file__).resolve().parent.parent
TARGET = 0.35  # issue target: our m = 6 solve at most 0.35x KDL's time at n = 7


def loadavg():
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


def cpu_model():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "(unknown)"


def run(cmd, **kw):
    print("+", " ".join(map(str, cmd)), file=sys.stderr, flush=True)
    return subprocess.run(list(map(str, cmd)), **kw)


def kdl_version():
    out = run(["dpkg-query", "-W", "-f", "${Package} ${Version}\\n", "liborocos-kdl*"], capture_output=True, text=True)
    pkgs = [l for l in out.stdout.splitlines() if len(l.split()) == 2]  # installed packages only
    return ", ".join(pkgs) if pkgs else "(dpkg-query found no liborocos-kdl package)"


def extension_note():
    """Where the installed Python extension is, when it was built, and whether sources are newer."""
    import vereshchagin._core as core

    so = Path(core.__file__)
    sources = [p for d in ("cpp/src", "cpp/include", "python/bindings") for p in (REPO / d).rglob("*") if p.is_file()]
    newest = max((p.stat().st_mtime for p in sources), default=0.0)
    built = datetime.datetime.fromtimestamp(so.stat().st_mtime, datetime.timezone.utc)
    note = f"`{so}` (file time {built:%Y-%m-%d %H:%M UTC}"
    if newest > so.stat().st_mtime:
        note += (
            "; **older than the newest library/binding source in the repository: reinstall to time the current code**"
        )
    note += ")"
    # pip builds it with scikit-build-core in build/<wheel tag>/; report that CMake cache if present.
    for cache_file in (REPO / "build").glob("*/CMakeCache.txt"):
        if (cache_file.parent / ".skbuild-info.json").exists():
            cache = {}
            for line in cache_file.read_text().splitlines():
                if "=" in line and not line.startswith(("//", "#")):
                    key, value = line.split("=", 1)
                    cache[key.split(":")[0]] = value
            flags = f"{cache.get('CMAKE_CXX_FLAGS', '')} {cache.get('CMAKE_CXX_FLAGS_RELEASE', '')}".strip()
            note += (
                f"; pip build cache `{cache_file.parent.relative_to(REPO)}`: build type "
                f"{cache.get('CMAKE_BUILD_TYPE', '?')}, `{cache.get('CMAKE_CXX_COMPILER', '?')}`, flags `{flags}`"
            )
            break
    return note


def target_lines(cpp_md):
    """The n = 7, m = 6 rows of the C++ table: (chain, entry point, ratio) with the verdict."""
    lines, met = [], True
    for row in cpp_md.splitlines():
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        if len(cells) >= 7 and cells[0].startswith("7 ") and cells[1] == "6":
            for name, col in (("`solve()`", 6), ("`CartToJnt`", 5)):
                ratio = float(cells[col])  # as printed, 2 decimals
                ok = ratio <= TARGET
                met &= ok
                verdict = "met" if ok else "NOT met"
                if ratio == TARGET:
                    verdict += " (borderline: equal to the target at the printed precision)"
                lines.append(f"  - n = {cells[0]}, m = 6, ours {name} / KDL = {cells[col]}: {verdict}")
    if not lines:
        return ["- Target: could not find the n = 7, m = 6 rows in the C++ report."], False
    head = (
        f"- **Target: our m = 6 solve at most {TARGET}x KDL's time at n = 7: "
        f"{'met' if met else 'NOT met'} in this run** (all n = 7, m = 6 ratios below):"
    )
    return [head] + lines, met


def friction_summary(fr_file):
    """The static-friction target lines of bench_friction's report, for the summary at the top."""
    if not fr_file.exists():
        return ["- Static-friction targets: bench_friction produced no report (see the Static friction section)."]
    lines = [l for l in fr_file.read_text().splitlines() if l.startswith("- **Target:")]
    return [
        "- Static-friction targets (section Static friction; friction-aware solve on a 7-joint arm, all joints "
        "at rest, m = 0, 1, 6):"
    ] + ["  " + l.replace("- **Target: ", "- **", 1) for l in lines]


def friction_section(fr_file, fr_rc, frpy_file, frpy_rc):
    """The "Static friction" section: bench_friction's report and bench_friction_pinocchio.py's."""
    md = [
        "## Static friction",
        "",
        "Issue targets for the friction-aware solve (`vereshchagin::FrictionSolver`, the exact max-min of Vukcevic 2018 "
        "by one solve, the response columns of the resting joints and a box QP by an active-set method) on a 7-joint "
        "arm with every joint at rest, m = 0, 1, 6: at most 2.5x our plain solve (`ChainHdSolver::solve`, same "
        "inputs, no friction) and faster than one KDL plain solve (`ChainHdSolver_Vereshchagin::CartToJnt`); at "
        "least 100x faster than the report's vertex enumeration (2^7 KDL solves and Gauss-function evaluations). "
        "Pinocchio 4.1's joint friction (`JointFrictionConstraintModel` with its ADMM solver) is compared from "
        "Python, m = 0 only.",
        "",
    ]
    for name, f, rc in (("bench_friction", fr_file, fr_rc), ("bench_friction_pinocchio.py", frpy_file, frpy_rc)):
        if rc:
            md += [
                f"**{name} exited with code {rc}"
                + (": see its report below.**" if f.exists() else " and wrote no report.**"),
                "",
            ]
        if f.exists():
            md += ["##" + l if l.startswith("#") else l for l in f.read_text().rstrip().splitlines()]
            md += [""]
    return md


def segments_section(seg_file, seg_rc):
    """The "Constraints on several segments" section: bench_segments.py's report (it has the heading)."""
    if not seg_file.exists():
        return [
            "## Constraints on several segments",
            "",
            f"**bench_segments.py exited with code {seg_rc} and wrote no report.**",
            "",
        ]
    heading, *body = seg_file.read_text().rstrip().splitlines()
    warn = ["", f"**bench_segments.py exited with code {seg_rc}: see the table below.**"] if seg_rc else []
    return [heading, *warn, *body, ""]


@dataclass(frozen=True)
class Bench:
    """One benchmark run by ``main``: a C++ executable in DIR/benchmarks or, for a name ending in
    ``.py``, a script in benchmarks/ run with ``--out``; it writes its Markdown report to DIR/``report``."""

    name: str
    report: str
    args: Callable[[], list] = list  # C++: arguments before the report file, made only when it runs
    optional: bool = False  # C++ built only when CMake found Pinocchio's C++ headers; not run otherwise
    counted: bool = True  # its exit code counts in run_all's

    def command(self, build: Path) -> list:
        """The command line that runs it with its report in ``build``."""
        if self.name.endswith(".py"):
            return [sys.executable, REPO / "benchmarks" / self.name, "--out", build / self.report]
        return [build / "benchmarks" / self.name, *self.args(), build / self.report]

    def missing(self, rc: int) -> str:
        """The line BENCHMARKS.md has in place of a report the benchmark did not write."""
        if self.optional:
            return (
                f"**{self.name} was not built (Pinocchio's C++ headers not found) or wrote no report "
                f"(exit code {rc}).**"
            )
        return f"**{self.name} exited with code {rc} and wrote no report.**"


def _baxter_urdf() -> list:
    from vereshchagin.robots import example_robot_urdf

    return [example_robot_urdf("baxter")]


def _floating_urdfs() -> list:
    from vereshchagin.robots import example_robot_urdf

    names = (
        "talos_data/robots/talos_reduced.urdf",
        "solo_description/robots/solo12.urdf",
        "anymal_b_simple_description/robots/anymal.urdf",
    )
    return [example_robot_urdf(u) for u in names]


# The two benchmarks without whose reports there is no BENCHMARKS.md.
SOLVER, PINOCCHIO = Bench("bench_solver", "bench_cpp.md"), Bench("bench_pinocchio.py", "bench_pinocchio.md")
# The others, in the order they run.
BENCHES = (
    Bench("bench_friction", "bench_friction.md"),
    Bench("bench_friction_pinocchio.py", "bench_friction_pinocchio.md"),
    Bench("bench_segments.py", "bench_segments.md"),
    Bench("bench_python_face.py", "bench_python_face.md"),
    Bench("bench_companions.py", "bench_companions.md"),
    Bench("bench_tree.py", "bench_tree.md"),
    Bench("bench_tree_kkt", "bench_tree_kkt.md", args=_baxter_urdf, optional=True),
    Bench("bench_contacts", "bench_contacts.md"),
    Bench("bench_step", "bench_step.md"),
    Bench("bench_step.py", "bench_step_py.md"),
    Bench("bench_pv", "bench_pv.md", optional=True),
    Bench("bench_contacts_pinocchio", "bench_contacts_pinocchio.md", optional=True),
    Bench("bench_contacts_pinocchio.py", "bench_contacts_pinocchio_py.md"),
    Bench("bench_energy.py", "bench_energy.md"),
    Bench("bench_hold_creep.py", "bench_hold_creep.md"),
    Bench("bench_realtime", "bench_realtime.md", args=lambda: ["1000000", "600", "5000"]),
    Bench("bench_floating_pinocchio", "bench_floating_pinocchio.md", args=_floating_urdfs, optional=True),
    Bench("bench_floating.py", "bench_floating.md"),
)
# The reports after the segments section, in their order in BENCHMARKS.md; "#" starts a heading.
REPORT_ORDER = (
    "bench_python_face.py",
    "bench_companions.py",
    "bench_tree.py",
    "bench_tree_kkt",
    "bench_contacts",
    "bench_contacts_pinocchio",
    "bench_contacts_pinocchio.py",
    "## Time step",
    "bench_step",
    "bench_step.py",
    "bench_pv",
    "## Floating bases",
    "bench_floating_pinocchio",
    "bench_floating.py",
    "bench_hold_creep.py",
    "bench_energy.py",
    "bench_realtime",
)


def build_benchmarks(build: Path) -> None:
    """Configure and build the C++ benchmarks in ``build``; exit on failure."""
    for cmd in (
        [
            "cmake",
            "-S",
            REPO,
            "-B",
            build,
            "-G",
            "Ninja",
            "-DCMAKE_BUILD_TYPE=Release",
            "-DVERESHCHAGIN_BUILD_TESTS=OFF",
            "-DVERESHCHAGIN_BUILD_BENCHMARKS=ON",
        ],
        ["cmake", "--build", build],
    ):
        res = run(cmd, capture_output=True, text=True)
        if res.returncode:
            sys.exit(f"build failed:\n{res.stdout}\n{res.stderr}")


def run_required(bench: Bench, build: Path) -> tuple[Path, int]:
    """Run ``bench``; exit when it wrote no report. Returns (report file, exit code)."""
    rc = run(bench.command(build), stdout=subprocess.DEVNULL).returncode
    if not (build / bench.report).exists():
        sys.exit(f"{bench.name} failed (exit code {rc})")
    return build / bench.report, rc


def run_bench(bench: Bench, build: Path) -> tuple[Path, int]:
    """Run ``bench`` after removing an old report (an optional one not built: exit code 0).
    Returns (report file, exit code)."""
    report = build / bench.report
    report.unlink(missing_ok=True)
    if bench.optional and not (build / "benchmarks" / bench.name).exists():
        return report, 0
    return report, run(bench.command(build), stdout=subprocess.DEVNULL).returncode


def header(date, loads, cpp_md, fr_file):
    """BENCHMARKS.md up to the C++ report: the run's conditions, the targets and the method.
    Returns (lines, whether the KDL target was met)."""
    bullets = [l for l in cpp_md.splitlines() if l.startswith(("- Compiler:", "- Build type:"))]
    import numpy
    import pinocchio

    target, met = target_lines(cpp_md)
    md = [
        "# Benchmarks",
        "",
        "Written by `python benchmarks/run_all.py` (see `benchmarks/README.md`). Absolute times move by tens of "
        "percent between runs on this shared machine; the ratios are steadier.",
        "",
        f"- Date: {date}",
        f"- Machine: {cpu_model()}, nproc {len(os.sched_getaffinity(0))}, Linux {platform.release()}; load average "
        f"(1, 5, 15 min) {loads[0]} at start, {loads[1]} at end (the machine may be running other work)",
        *[b.replace("- ", "- C++ benchmark: ", 1) for b in bullets],
        f"- Python extension (for the Python table): {extension_note()}",
        f"- Versions: KDL {kdl_version()} (Debian); pinocchio {pinocchio.__version__} "
        f"(`{Path(pinocchio.__file__).parent}`); numpy {numpy.__version__}; Python {platform.python_version()}",
        *target,
        *friction_summary(fr_file),
        "",
        "## Method",
        "",
        METHOD,
        "",
        "- C++ (`bench_solver`): ours (`vereshchagin::ChainHdSolver`, through `CartToJnt` with KDL types and "
        "through `solve()` with Eigen types) against Debian's `KDL::ChainHdSolver_Vereshchagin::CartToJnt` (the "
        "same algorithm), and KDL's recursive Newton-Euler solvers for scale.",
        "- Python (`bench_pinocchio.py`): our `Solver.solve` (and `solve_batch` per row) against Pinocchio's "
        "`forwardDynamics` with the constraint Jacobian J = alpha^T J_tip and drift gamma (alone, J and gamma "
        "precomputed), and against the full Pinocchio pipeline that computes J and gamma from alpha and beta, as "
        "our solve does (the like-for-like comparison); `pin.aba` for m = 0. Both libraries pay Python call "
        "overhead here, so the Python ratios are not C++ ratios.",
        "",
    ]
    return md, met


METHOD = (
    "Both benchmarks use a Kinova Gen3 7-DoF arm (the same joint origins and inertias in both) and seeded "
    "random chains with n = 7, 15, 30, 60 revolute joints, 64 seeded random states per chain (q, q_dot, "
    "feed-forward torques, gravity 9.81 m/s^2 along -z, no external forces) and m = 0, 1, 6 unit, orthonormal "
    "constraint directions alpha on the last segment with set-points beta. The C++ and the Python random "
    "chains and states follow the same recipe but come from different generators (std::mt19937_64, numpy). "
    "Each variant is warmed up and calibrated to batches of about 8 ms (C++) or 10 ms (Python); the "
    "variants of one (chain, m) case run in interleaved batches (A B C A B C ...), the tables give the median "
    "per-call time in microseconds and, for each ratio, the median of the per-batch ratios (below 1: ours is "
    "faster). Before timing, each case compares the joint accelerations of all solvers on all states (C++: the "
    "largest difference from KDL is reported; Python: the relative difference from Pinocchio must be below 1e-8)."
)


def main():
    ap = argparse.ArgumentParser(description="Build and run the benchmarks, write BENCHMARKS.md.")
    ap.add_argument("--build-dir", type=Path, default=REPO / "build" / "bench")
    ap.add_argument("--out", type=Path, default=REPO / "BENCHMARKS.md")
    args = ap.parse_args()
    build = args.build_dir.resolve()
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    load_start = loadavg()

    build_benchmarks(build)
    cpp_file, cpp_rc = run_required(SOLVER, build)
    py_file, py_rc = run_required(PINOCCHIO, build)
    results = {b.name: run_bench(b, build) for b in BENCHES}
    load_end = loadavg()

    cpp_md, py_md = cpp_file.read_text(), py_file.read_text()
    md, met = header(date, (load_start, load_end), cpp_md, results["bench_friction"][0])
    if cpp_rc:
        md += [f"**bench_solver exited with code {cpp_rc}: some solver calls returned an error (see below).**", ""]
    if py_rc:
        md += [f"**bench_pinocchio.py exited with code {py_rc}: some results disagree (see below).**", ""]
    md += ["#" + l if l.startswith("#") else l for l in cpp_md.rstrip().splitlines()]
    md += ["", py_md.rstrip(), ""]
    md += friction_section(*results["bench_friction"], *results["bench_friction_pinocchio.py"])
    md += segments_section(*results["bench_segments.py"])
    md += [""]
    benches = {b.name: b for b in BENCHES}
    for name in REPORT_ORDER:
        if name.startswith("#"):
            md += [name, ""]
            continue
        report, rc = results[name]
        md += [report.read_text().rstrip() if report.exists() else benches[name].missing(rc), ""]
    args.out.write_text("\n".join(md))
    print(f"wrote {args.out} (target {'met' if met else 'NOT met'})", file=sys.stderr)
    counted = [cpp_rc, py_rc] + [results[b.name][1] for b in BENCHES if b.counted]
    return 0 if all(rc == 0 for rc in counted) else 1


if __name__ == "__main__":
    sys.exit(main())
