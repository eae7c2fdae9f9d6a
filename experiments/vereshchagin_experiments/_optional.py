"""Dependencies of the experiments that may be missing (installed with --no-deps, or broken)."""

from __future__ import annotations

import importlib.util

# module -> the PyPI package that provides it
PACKAGES = {"matplotlib": "matplotlib", "mujoco": "mujoco"}

# What each reproduce case imports beyond numpy; its keys are the command line's --case choices.
CASE_NEEDS = {
    "friction": ("matplotlib",),
    "demo": (),
    "contact": ("mujoco", "matplotlib"),
    "dual-arm": ("mujoco", "matplotlib"),
    "friction-energy": ("mujoco", "matplotlib"),
    "wiping": ("matplotlib",),
    "mobile": ("mujoco", "matplotlib"),
    "quadruped": ("mujoco", "matplotlib"),
}


def missing_message(modules) -> str | None:
    """A message naming the packages to install when one of ``modules`` cannot be imported, else None.

    Parameters
    ----------
    modules : iterable of str
        Top-level module names.

    Returns
    -------
    str or None
    """
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if not missing:
        return None
    packages = " ".join(PACKAGES.get(m, m) for m in missing)
    return (
        f"this needs {', '.join(missing)}, which is not installed: pip install {packages} "
        "(dependencies of vereshchagin-experiments)"
    )
