"""What the floating-base cases share: the minimum-jerk profile of their references and the
figure's last steps."""

from __future__ import annotations

from pathlib import Path


def min_jerk(s: float) -> tuple[float, float, float]:
    """The minimum-jerk blend and its first two derivatives at ``s`` (clamped to [0, 1])."""
    s = min(max(s, 0.0), 1.0)
    return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 - 60 * s**3 + 30 * s**4, 60 * s - 180 * s**2 + 120 * s**3


def save(fig, path: Path) -> None:
    """Lay out, write (120 dpi) and close a matplotlib figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
