"""The conventions figure: base frame, segment tip frames, gravity and the task on a planar arm.

Drawn from the package's own forward kinematics (``Chain.fk``), so the figure shows what the
solver means by each frame. ``draw(path)`` writes a PNG.
"""

import matplotlib.pyplot as plt
import numpy as np

import vereshchagin as vs


def _arm():
    """Three links swinging about y (x-z plane); tips 0.5, 0.4, 0.2 m along x of each joint frame."""
    chain = vs.Chain()
    for k, length in enumerate((0.5, 0.4, 0.2)):
        tip = np.eye(4)
        tip[0, 3] = length
        chain.add_segment(
            name=f"link{k + 1}",
            joint="rot_y",
            tip=tip,
            mass=1.0,
            com=[-length / 2, 0, 0],
            inertia=np.diag([1e-3, 1e-2, 1e-2]),
        )
    return chain


def _axes(ax, T, label, scale=0.12, color="k"):
    """Draw the x and z axes of pose T (x-z plane of the base) and a label at its origin."""
    o = T[:3, 3]
    for col, name in ((0, "x"), (2, "z")):
        d = T[:3, col] * scale
        ax.annotate(
            "",
            xy=(o[0] + d[0], o[2] + d[2]),
            xytext=(o[0], o[2]),
            arrowprops=dict(arrowstyle="->", color=color, lw=1.4),
        )
        ax.text(o[0] + 1.15 * d[0], o[2] + 1.15 * d[2], name, color=color, fontsize=8, ha="center", va="center")
    ax.text(o[0] - 0.02, o[2] - 0.05, label, fontsize=8, ha="right", va="top", color=color)


def _arrow(ax, start, delta, color, text_offset, text):
    """A thick arrow from ``start`` by ``delta`` (x, z) and a label at ``start + text_offset``."""
    ax.annotate(
        "",
        xy=(start[0] + delta[0], start[1] + delta[1]),
        xytext=start,
        arrowprops=dict(arrowstyle="-|>", color=color, lw=2),
    )
    ax.text(start[0] + text_offset[0], start[1] + text_offset[1], text, color=color, fontsize=8, va="top")


def draw(path):
    """Write the figure to ``path`` (PNG)."""
    chain = _arm()
    q = np.array([-0.7, 0.9, 1.0])
    poses = [np.eye(4)] + [chain.fk(q, k) for k in range(chain.n_segments)]
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    pts = np.array([T[:3, 3] for T in poses])
    ax.plot(pts[:, 0], pts[:, 2], "-o", color="0.6", lw=6, ms=9, zorder=0)
    _axes(ax, poses[0], "base frame\n(segment index -,\nlink_acc row 0)", color="tab:blue")
    for k in range(1, len(poses)):
        _axes(ax, poses[k], f"tip of segment {k - 1}\n'{chain.segment_names[k - 1]}'\n(link_acc row {k})")
    tool, mid = poses[-1][:3, 3], poses[2][:3, 3]
    _arrow(
        ax,
        (tool[0], tool[2]),
        (0.0, 0.22),
        "tab:red",
        (0.2, 0.12),
        "alpha = z: unit force along base z\nat the last tip origin;\nhold height: beta = +9.81",
    )
    _arrow(
        ax,
        (-0.25, 0.5),
        (0.0, -0.25),
        "tab:green",
        (0.02, -0.05),
        "gravity = [0, 0, -9.81]\n(solver: base accelerates\nby -gravity = +9.81 z)",
    )
    _arrow(
        ax,
        (mid[0], mid[2]),
        (0.18, 0.0),
        "tab:purple",
        (0.2, 0.1),
        "f_ext of segment 1:\nbase axes, moment\nabout its tip origin",
    )
    ax.text(0.3, -0.25, "joints rotate about y (into the page); q > 0 turns x towards -z", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(-0.35, 1.45)
    ax.set_ylim(-0.3, 0.75)
    ax.set_xlabel("base x [m]")
    ax.set_ylabel("base z [m]")
    ax.set_title("Frames, signs and indices (three segments, rot_y joints)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    draw("frames.png")
