"""The architecture page's picture: the layers of the library, drawn as boxes.

``draw(path)`` writes one PNG. The boxes name the real headers and modules; the page
(``docs/architecture.md``) says what each layer owns.
"""

from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.patches import FancyBboxPatch

# (x, y, width, height, title, detail, colour): one box per layer or part, in axes units.
BOXES = [
    (
        0.02,
        0.83,
        0.46,
        0.13,
        "vereshchagin_experiments",
        "reports' reproductions, MuJoCo plant,\nfigures, reproduce CLI",
        "#f2e6d9",
    ),
    (0.52, 0.83, 0.46, 0.13, "your code", "controllers, planners, notebooks", "#eeeeee"),
    (
        0.02,
        0.62,
        0.96,
        0.15,
        "vereshchagin (Python)",
        "Chain, Tree, Solver, SolveResult, Friction, task helpers, robots, KDL interop\n"
        "python/bindings: conversion, GIL release, error translation only",
        "#dde8f5",
    ),
    (0.02, 0.41, 0.30, 0.15, "facades", "ChainHdSolver, TreeHdSolver,\nFrictionSolver, kdl_compat", "#e3f0dd"),
    (0.35, 0.41, 0.30, 0.15, "solve(model, data, input)", "sweeps, coupling matrix,\nfriction max-min", "#e3f0dd"),
    (
        0.68,
        0.41,
        0.30,
        0.15,
        "kinematics, dynamics",
        "FK, Jacobians, twists, RNEA,\nmass matrix, gravity, Coriolis",
        "#e3f0dd",
    ),
    (0.02, 0.20, 0.30, 0.15, "Model", "immutable, shared by threads:\nsegments, parents, names", "#fbf3d0"),
    (0.35, 0.20, 0.30, 0.15, "Data", "one per thread: workspace\nand results, sized once", "#fbf3d0"),
    (0.68, 0.20, 0.30, 0.15, "SolveInput", "state, constraints, wrenches,\ntorques, friction, gravity", "#fbf3d0"),
    (
        0.02,
        0.02,
        0.96,
        0.12,
        "Orocos KDL types, Eigen 3, urdfdom",
        "KDL::Chain / KDL::Tree / KDL::Segment in, URDF loaders",
        "#eeeeee",
    ),
]


def draw(path):
    """Write the layer picture to ``path`` (PNG)."""
    fig, ax = plt.subplots(figsize=(9.0, 6.2))
    ax.set_axis_off()
    for x, y, w, h, title, detail, colour in BOXES:
        ax.add_patch(
            FancyBboxPatch((x, y), w, h, boxstyle="round,pad=0.005,rounding_size=0.015", fc=colour, ec="#555555")
        )
        ax.text(x + w / 2, y + h * 0.70, title, ha="center", va="center", fontsize=10.5, weight="bold")
        ax.text(x + w / 2, y + h * 0.32, detail, ha="center", va="center", fontsize=8.5)
    for y in (0.80, 0.59, 0.38, 0.17):  # "uses" arrows between the rows
        ax.annotate(
            "", xy=(0.5, y - 0.015), xytext=(0.5, y + 0.015), arrowprops={"arrowstyle": "-|>", "color": "#555555"}
        )
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
