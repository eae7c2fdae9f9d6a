"""The friction experiments of Vukcevic (2018) on the 1-DOF arm (figures 5.2, 5.5, 6.2-6.7) and their optimum.

The arm (report sec. 6.1): one revolute joint about z, link length 1 m, mass 1 kg, centre of mass
at 0.5 m, joint-axis inertia 2.25 kg m^2 (2.0 about the centre of mass), no gravity, at rest,
breakaway friction f = 10 N m. Cases:

- scenario 1 (sec. 6.2, figs. 6.2-6.4): force -5 N at the tip (joint torque -5 N m), no task;
- scenario 2 (sec. 6.3, figs. 6.5-6.7): force -11 N at the tip (-11 N m), no task;
- fully constrained (sec. 5.6, fig. 5.5): task angular acceleration 5 rad/s^2.

For every friction torque on a grid over [-f, f] the frictionless solver gives the motion, the
motor command and the Gauss function g (:mod:`.gauss`, the report's sampling); the optimum marked
in the figures and listed in the table is the exact one of ``Solver.solve(..., friction=...)``.
Sign convention: the plotted friction torque is the physical one, ``-mu`` (``friction_torque``).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from vereshchagin.friction import Friction
from vereshchagin import Solver
from vereshchagin import Chain
from .gauss import brute_force_grid, evaluate, free_accelerations, gauss_function, vertex_enumeration

__all__ = ["CASES", "Case", "F_BREAKAWAY", "arm_1dof", "run"]

F_BREAKAWAY = 10.0  # N m
STATUS_NAMES = {0: "moving", 1: "stick", 2: "slip +", 3: "slip -"}
ATOL = 1e-9  # agreement with the report's exact numbers


def arm_1dof() -> Chain:
    """The report's 1-DOF arm: rot_z, length 1 m, mass 1 kg, COM 0.5 m, I_zz(COM) = 2 kg m^2."""
    chain = Chain()
    tip = np.eye(4)
    tip[0, 3] = 1.0
    chain.add_segment(
        name="link1", joint="rot_z", tip=tip, mass=1.0, com=[-0.5, 0.0, 0.0], inertia=np.diag([1.0, 1.0, 2.0])
    )
    return chain


@dataclass(frozen=True)
class Case:
    """One experiment of the report on the 1-DOF arm at rest and its published numbers.

    Attributes
    ----------
    key : str
        Short name, used in file names (``"scenario1"``, ...).
    label : str
        Human-readable title for figures and tables.
    tip_force : float
        Force at the tip (N) along the link's tangential direction (base y at ``q = 0``); the
        joint torque it makes is ``tip_force * 1 m``. 0: none.
    task_qdd : float or None
        Task: angular acceleration of the tip about base z (rad/s^2), a one-column constraint;
        None: no task (the joint moves freely).
    figures : dict of str to str
        Kind of figure (``"energy"``, ``"acceleration"``, ``"torques"``, ``"surface"``) -> the
        report's figure number (``""``: drawn, but no figure in the report).
    friction : float or None
        Published friction torque at the optimum (N m, physical sign, i.e. ``-mu``, acting on
        the joint like a motor torque). None in this and the following fields: not published.
    qdd : float or None
        Published joint acceleration at the optimum (rad/s^2).
    qdd_digits : int or None
        Decimals to which the report rounds ``qdd`` (None: exact, compared at 1e-9).
    tau_command : float or None
        Published motor command at the optimum (N m).
    net : float or None
        Published net joint torque, load + friction + command (N m).
    """

    key: str
    label: str
    tip_force: float = 0.0
    task_qdd: Optional[float] = None
    figures: dict = field(default_factory=dict)
    friction: Optional[float] = None
    qdd: Optional[float] = None
    qdd_digits: Optional[int] = None
    tau_command: Optional[float] = None
    net: Optional[float] = None

    @property
    def f_ext(self) -> Optional[np.ndarray]:
        """External wrench on the link, shape (1, 6), or None without a tip force.

        ``[force; moment]`` (N, N m) applied on the link by the environment, base-frame axes,
        moment about the tip origin (the :meth:`Solver.solve` convention): ``tip_force`` along y.
        """
        if not self.tip_force:
            return None
        return np.array([[0.0, self.tip_force, 0.0, 0.0, 0.0, 0.0]])

    @property
    def alpha(self) -> Optional[np.ndarray]:
        """Task direction, shape (6, 1): angular base z (``[0 0 0 0 0 1]``); None without a task."""
        if self.task_qdd is None:
            return None
        a = np.zeros((6, 1))
        a[5, 0] = 1.0
        return a

    @property
    def beta(self) -> Optional[np.ndarray]:
        """Task right-hand side, shape (1,): ``[task_qdd]`` (rad/s^2); None without a task.

        The solver imposes ``alpha.T @ a_tip = beta`` on the tip's spatial acceleration; without
        gravity and at rest that is the angular acceleration about z itself.
        """
        return None if self.task_qdd is None else np.array([self.task_qdd])


CASES = (
    Case(
        "scenario1",
        "Scenario 1: tip force -5 N, no task",
        tip_force=-5.0,
        figures={"energy": "6.2", "acceleration": "6.3", "torques": "6.4", "surface": "5.2"},
        friction=5.0,
        qdd=0.0,
        net=0.0,
    ),
    Case(
        "scenario2",
        "Scenario 2: tip force -11 N, no task",
        tip_force=-11.0,
        figures={"energy": "6.5", "acceleration": "6.6", "torques": "6.7"},
        friction=10.0,
        qdd=-0.444,
        qdd_digits=3,
        net=-1.0,
    ),
    Case(
        "constrained",
        "Fully constrained: task qdd = 5 rad/s²",
        task_qdd=5.0,
        figures={"energy": "5.5", "acceleration": "", "torques": ""},
        friction=-10.0,
        qdd=5.0,
        tau_command=21.25,
    ),
)

_KIND_TITLES = {
    "energy": "Acceleration energy vs friction torque",
    "acceleration": "Joint acceleration vs friction torque",
    "torques": "Joint torques vs friction torque",
    "surface": "Acceleration energy Z(qdd, friction torque) and its max-min",
}
_XLABEL = r"friction torque on the joint $-\mu$ [N m]"
_GLABEL = r"acceleration energy $g = Z_0(\ddot q) + \mu\,\ddot q$ [J/s$^2$]"
_QLABEL = r"joint acceleration $\ddot q$ [rad/s$^2$]"


def _lower_first(s: str) -> str:
    return s[:1].lower() + s[1:]


def _fig_title(case: Case, kind: str) -> str:
    num = case.figures.get(kind, "")
    ref = f"Fig. {num}" if num else "cf. Fig. 5.5" if case.key == "constrained" else ""
    head = f"{ref}: " if ref else ""
    return f"{head}{_KIND_TITLES[kind]}\n{case.label}"


def _load_torque(chain: Chain, q: np.ndarray, f_ext) -> np.ndarray:
    """Joint torque of the external wrenches, sum_i J_i^T f_i (tip Jacobians, base axes)."""
    tau = np.zeros(chain.n_joints)
    if f_ext is None:
        return tau
    for i, w in enumerate(np.asarray(f_ext, float)):
        tau += np.asarray(chain.jacobian(q, segment=i)).T @ w
    return tau


def _sweep(solver, chain, case: Case, points: int) -> dict:
    """Sample the friction torque over [-f, f]: g, qdd and the torques (the report's figures)."""
    q = qd = np.zeros(1)
    f_ext = case.f_ext
    free = free_accelerations(solver, q, qd, f_ext)
    phi = np.linspace(-F_BREAKAWAY, F_BREAKAWAY, points)
    g = np.empty(points)
    qdd = np.empty(points)
    cmd = np.empty(points)
    for i, p in enumerate(phi):
        s = evaluate(solver, q, qd, [-p], [0], case.alpha, case.beta, f_ext, qdd_free=free)
        g[i], qdd[i], cmd[i] = s.g, s.qdd[0], s.tau_command[0]
    load = float(_load_torque(chain, q, f_ext)[0])
    return dict(phi=phi, g=g, qdd=qdd, command=cmd, load=load, net=load + phi + cmd, qdd_free=float(free[0]))


def _optimum(solver, chain, case: Case, grid_points: int) -> dict:
    """The exact optimum (friction-aware solve) and the slow references next to it."""
    q = qd = np.zeros(1)
    res = solver.solve(
        q, qd, alpha=case.alpha, beta=case.beta, f_ext=case.f_ext, friction=Friction(static=np.array([F_BREAKAWAY]))
    )
    phi = float(res.friction_torque[0])
    load = float(_load_torque(chain, q, case.f_ext)[0])
    grid = brute_force_grid(solver, q, qd, F_BREAKAWAY, [0], case.alpha, case.beta, case.f_ext, points=grid_points)
    vert = vertex_enumeration(solver, q, qd, F_BREAKAWAY, [0], case.alpha, case.beta, case.f_ext)
    return dict(
        friction_torque=phi,
        qdd=float(res.qdd[0]),
        tau_command=float(res.tau_command[0]),
        net_torque=load + phi + float(res.tau_command[0]),
        gauss_value=float(res.gauss_value),
        g_reference=gauss_function(solver, q, qd, [-phi], [0], case.alpha, case.beta, case.f_ext),
        status=STATUS_NAMES.get(int(res.status[0]), str(int(res.status[0]))),
        grid_friction_torque=float(-grid.mu[0]),
        grid_g=float(grid.g),
        grid_points=grid_points,
        vertex_friction_torque=float(-vert.mu[0]),
        vertex_g=float(vert.g),
    )


def _checks(case: Case, opt: dict) -> list:
    """Differences from the report's published numbers and internal consistency; [] if all hold."""
    bad = []
    if case.friction is not None and abs(opt["friction_torque"] - case.friction) > ATOL:
        bad.append("friction torque")
    if case.qdd is not None:
        if case.qdd_digits is not None:
            if round(opt["qdd"], case.qdd_digits) != case.qdd:
                bad.append("qdd")
        elif abs(opt["qdd"] - case.qdd) > ATOL:
            bad.append("qdd")
    if case.tau_command is not None and abs(opt["tau_command"] - case.tau_command) > ATOL:
        bad.append("motor command")
    if case.net is not None and abs(opt["net_torque"] - case.net) > ATOL:
        bad.append("net torque")
    scale = max(1.0, abs(opt["gauss_value"]))
    if abs(opt["g_reference"] - opt["gauss_value"]) > ATOL * scale:
        bad.append("gauss_value vs g(mu*)")
    if opt["grid_g"] > opt["gauss_value"] + ATOL * scale:
        bad.append("grid exceeds optimum")
    return bad


# ------------------------------------------------------------------------------------------------
# Figures
# ------------------------------------------------------------------------------------------------
def _new_figure(three_d: bool = False):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 4.8), dpi=120, layout="constrained")
    ax = fig.add_subplot(projection="3d") if three_d else fig.add_subplot()
    return fig, ax


def _mark_report(ax, case: Case):
    if case.friction is not None:
        ax.axvline(
            case.friction, color="0.45", ls="--", lw=1.0, label=f"report: friction torque {case.friction:+g} N m"
        )


def _plot_energy(case, sw, opt, path):
    fig, ax = _new_figure()
    ax.plot(sw["phi"], sw["g"], color="tab:red", lw=2, label=r"$g$ (one frictionless solve per sample)")
    _mark_report(ax, case)
    ax.plot(
        opt["friction_torque"],
        opt["gauss_value"],
        "k*",
        ms=14,
        zorder=5,
        label=f"optimum (solver): {opt['friction_torque']:+.4g} N m, g = {opt['gauss_value']:.4g}",
    )
    ax.set_xlim(-1.04 * F_BREAKAWAY, 1.04 * F_BREAKAWAY)
    ax.set_xlabel(_XLABEL)
    ax.set_ylabel(_GLABEL)
    ax.set_title(_fig_title(case, "energy"), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.savefig(path)


def _plot_acceleration(case, sw, opt, path):
    fig, ax = _new_figure()
    ax.plot(sw["phi"], sw["qdd"], color="tab:orange", lw=2, label=r"$\ddot q(\mu)$ (characteristic line)")
    ax.axhline(0.0, color="0.7", lw=0.8)
    _mark_report(ax, case)
    if case.qdd is not None and case.friction is not None:
        ax.plot(
            case.friction,
            case.qdd,
            "o",
            mfc="none",
            mec="0.3",
            ms=11,
            mew=1.5,
            label=f"report: qdd = {case.qdd:+g} rad/s$^2$",
        )
    ax.plot(
        opt["friction_torque"],
        opt["qdd"],
        "k*",
        ms=14,
        zorder=5,
        label=f"optimum (solver): qdd = {opt['qdd']:+.4g} rad/s$^2$",
    )
    ax.set_xlim(-1.04 * F_BREAKAWAY, 1.04 * F_BREAKAWAY)
    ax.set_xlabel(_XLABEL)
    ax.set_ylabel(_QLABEL)
    ax.set_title(_fig_title(case, "acceleration"), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.savefig(path)


def _plot_torques(case, sw, opt, path):
    fig, ax = _new_figure()
    phi = sw["phi"]
    ax.plot(phi, phi, color="tab:blue", lw=2, label=r"friction torque $-\mu$")
    ax.plot(phi, sw["command"], color="tab:green", lw=2, label="motor command (tau_command)")
    ax.plot(
        phi,
        np.full_like(phi, sw["load"]),
        color="tab:purple",
        lw=1.5,
        ls=":",
        label=f"external load {sw['load']:+g} N m",
    )
    ax.plot(phi, sw["net"], color="black", lw=1.5, ls="-.", label=r"net = load + friction + command ($= H\ddot q$)")
    ax.axhline(0.0, color="0.7", lw=0.8)
    _mark_report(ax, case)
    x = opt["friction_torque"]
    ax.plot(
        [x, x, x],
        [x, opt["tau_command"], opt["net_torque"]],
        "k*",
        ms=13,
        zorder=5,
        label=(
            f"optimum (solver): friction {x:+.4g}, command {opt['tau_command']:+.4g}, net {opt['net_torque']:+.4g} N m"
        ),
    )
    ax.set_xlim(-1.04 * F_BREAKAWAY, 1.04 * F_BREAKAWAY)
    ax.set_xlabel(_XLABEL)
    ax.set_ylabel("joint torque [N m]")
    ax.set_title(_fig_title(case, "torques"), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, loc="best")
    fig.savefig(path)


def _plot_surface(case, solver, sw, opt, path):
    """Fig. 5.2 / 5.4: Z(qdd, mu) = Z0(qdd) + mu qdd over (friction torque, qdd), the red curve of its
    minima over qdd (g) and the orange characteristic line qdd(mu). Unconstrained 1-DOF only."""
    q = qd = np.zeros(1)
    solver.solve(q, qd, f_ext=case.f_ext)
    dqdd, _ = solver.response_columns([0])
    h = 1.0 / float(dqdd[0, 0])  # unconstrained: G = H^-1
    phi = np.linspace(-F_BREAKAWAY, F_BREAKAWAY, 41)
    lo, hi = min(sw["qdd"].min(), 0.0), max(sw["qdd"].max(), 0.0)
    pad = 0.2 * (hi - lo) + 0.5
    qdd = np.linspace(lo - pad, hi + pad, phi.size)
    P, A = np.meshgrid(phi, qdd)
    Z = 0.5 * h * (A - sw["qdd_free"]) ** 2 + (-P) * A
    fig, ax = _new_figure(three_d=True)
    ax.plot_wireframe(P, A, Z, color="0.55", lw=0.5, rstride=2, cstride=2, label=r"$Z(\ddot q, \mu)$")
    ax.plot(sw["phi"], sw["qdd"], sw["g"], color="tab:red", lw=3, label=r"$g(\mu) = \min_{\ddot q} Z$")
    ax.plot(
        sw["phi"],
        sw["qdd"],
        np.full_like(sw["phi"], Z.min()),
        color="tab:orange",
        lw=2,
        label=r"characteristic line $\ddot q(\mu)$ (projected)",
    )
    ax.plot(
        [opt["friction_torque"]],
        [opt["qdd"]],
        [opt["gauss_value"]],
        "k*",
        ms=14,
        label=f"max-min (solver): {opt['friction_torque']:+.4g} N m, qdd = {opt['qdd']:+.3f} rad/s$^2$",
    )
    ax.set_xticks(np.linspace(-F_BREAKAWAY, F_BREAKAWAY, 5))
    ax.view_init(elev=22, azim=-50)
    ax.set_xlabel(r"friction torque $-\mu$ [N m]", fontsize=8)
    ax.set_ylabel(r"$\ddot q$ [rad/s$^2$]", fontsize=8)
    ax.set_zlabel(r"$Z$ [J/s$^2$]", fontsize=8)
    ax.set_title(_fig_title(case, "surface"), fontsize=10)
    ax.legend(fontsize=7.5, loc="upper left")
    fig.savefig(path)


# ------------------------------------------------------------------------------------------------
# Tables
# ------------------------------------------------------------------------------------------------
_CSV_FIELDS = [
    "case",
    "report_figure",
    "friction_torque",
    "friction_torque_report",
    "qdd",
    "qdd_report",
    "tau_command",
    "tau_command_report",
    "net_torque",
    "net_torque_report",
    "gauss_value",
    "g_reference",
    "status",
    "grid_friction_torque",
    "grid_g",
    "grid_points",
    "vertex_friction_torque",
    "vertex_g",
    "check",
]


def _fmt(x, spec="+.6f"):
    return "—" if x is None else format(x, spec)


def _write_tables(rows: list, out: Path) -> tuple:
    csv_path = out / "friction_optimum.csv"
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=_CSV_FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow(
                {k: ("" if r[k] is None else repr(r[k]) if isinstance(r[k], float) else r[k]) for k in _CSV_FIELDS}
            )
    md = [
        "# Static friction on the 1-DOF arm of Vukcevic (2018): the optimum",
        "",
        "Arm: rot_z, 1 m, 1 kg, COM 0.5 m, joint-axis inertia 2.25 kg m^2, no gravity, at rest; "
        f"breakaway friction f = {F_BREAKAWAY:g} N m. Optimum from `Solver.solve(..., friction=...)`; "
        '"report" columns are the report\'s published values (— not published). Friction torque is the '
        "physical one, −μ (μ: Vereshchagin's multiplier). Net torque = external load + friction + motor "
        "command (= H qdd here). g(μ*) reference: `vereshchagin_experiments.gauss.gauss_function` (one frictionless "
        "solve); grid: the report's sampling; vertex: the best of the box vertices ±f.",
        "",
        "| case | report fig. | friction torque [N m] | report | qdd [rad/s²] | report | motor command [N m] "
        "| report | net torque [N m] | report | Gauss value [J/s²] | g(μ*) reference | status "
        "| grid best friction [N m] | best vertex [N m] | check |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|",
    ]
    for r in rows:
        qrep = (
            None
            if r["qdd_report"] is None
            else (format(r["qdd_report"], f"+.{r['_qdd_digits']}f") if r["_qdd_digits"] else _fmt(r["qdd_report"]))
        )
        md.append(
            f"| {r['_label']} | {r['report_figure']} | {_fmt(r['friction_torque'])} "
            f"| {_fmt(r['friction_torque_report'])} | {_fmt(r['qdd'])} | {qrep if qrep else '—'} "
            f"| {_fmt(r['tau_command'])} | {_fmt(r['tau_command_report'])} | {_fmt(r['net_torque'])} "
            f"| {_fmt(r['net_torque_report'])} | {_fmt(r['gauss_value'], '.6f')} | {_fmt(r['g_reference'], '.6f')} "
            f"| {r['status']} | {_fmt(r['grid_friction_torque'], '+.3f')} ({r['grid_points']} pts) "
            f"| {_fmt(r['vertex_friction_torque'], '+g')} | {r['check']} |"
        )
    md += [
        "",
        "Checks: friction torque, motor command and net torque within 1e-9 of the report; qdd "
        "within 1e-9, or equal after rounding to the report's digits (scenario 2: -0.444); "
        "gauss_value = g(μ*) within 1e-9; no grid sample above the exact optimum.",
        "",
    ]
    md_path = out / "friction_optimum.md"
    md_path.write_text("\n".join(md), encoding="utf-8")
    return md_path, csv_path


# ------------------------------------------------------------------------------------------------
# Entry point
# ------------------------------------------------------------------------------------------------
def expected_figures() -> list:
    """File names :func:`run` writes, in order."""
    names = []
    for case in CASES:
        names += [f"{case.key}_{kind}.png" for kind in ("energy", "acceleration", "torques")]
        if "surface" in case.figures:
            names.append(f"{case.key}_surface.png")
    return names


def run(out_dir, quick: bool = False, progress: Optional[Callable[[str], None]] = None) -> dict:
    """Reproduce the friction figures of Vukcevic (2018) and tabulate the optimum.

    Parameters
    ----------
    out_dir : str or Path
        Created if missing; receives the PNG figures, ``friction_optimum.md`` and
        ``friction_optimum.csv``.
    quick : bool
        Coarser sampling (81 instead of 401 samples per curve, a 41- instead of 201-point grid);
        the optimum is exact either way.
    progress : callable, optional
        Called with one line of text per step (e.g. ``print``).

    Returns
    -------
    dict
        ``figures``: list of (report figure, description, Path); ``table_md``, ``table_csv``:
        Paths; ``rows``: one dict per case (the CSV fields); ``ok``: all checks passed.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda s: None)
    points = 81 if quick else 401
    grid_points = 41 if quick else 201
    chain = arm_1dof()
    solver = Solver(chain, gravity=[0.0, 0.0, 0.0])
    figures, rows = [], []
    for case in CASES:
        say(f"[friction] {case.label}")
        sw = _sweep(solver, chain, case, points)
        opt = _optimum(solver, chain, case, grid_points)
        for kind, plot in (("energy", _plot_energy), ("acceleration", _plot_acceleration), ("torques", _plot_torques)):
            path = out / f"{case.key}_{kind}.png"
            plot(case, sw, opt, path)
            figures.append((case.figures.get(kind, ""), f"{case.label}: {_lower_first(_KIND_TITLES[kind])}", path))
            say(f"[friction]   wrote {path}")
        if "surface" in case.figures:
            path = out / f"{case.key}_surface.png"
            _plot_surface(case, solver, sw, opt, path)
            figures.append((case.figures["surface"], f"{case.label}: {_lower_first(_KIND_TITLES['surface'])}", path))
            say(f"[friction]   wrote {path}")
        bad = _checks(case, opt)
        rows.append(
            dict(
                case=case.key,
                report_figure=", ".join(v for v in case.figures.values() if v) or "—",
                friction_torque_report=case.friction,
                qdd_report=case.qdd,
                tau_command_report=case.tau_command,
                net_torque_report=case.net,
                check="ok" if not bad else "MISMATCH: " + ", ".join(bad),
                _label=case.label,
                _qdd_digits=case.qdd_digits,
                **opt,
            )
        )
        say(
            f"[friction]   optimum: friction {opt['friction_torque']:+.6g} N m, qdd {opt['qdd']:+.6g} rad/s^2, "
            f"command {opt['tau_command']:+.6g} N m, g {opt['gauss_value']:.6g} -> {rows[-1]['check']}"
        )
    md_path, csv_path = _write_tables(rows, out)
    say(f"[friction] wrote {md_path} and {csv_path}")
    public = [{k: v for k, v in r.items() if not k.startswith("_")} for r in rows]
    return dict(
        figures=figures, table_md=md_path, table_csv=csv_path, rows=public, ok=all(r["check"] == "ok" for r in rows)
    )
