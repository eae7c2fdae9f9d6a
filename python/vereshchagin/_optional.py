"""Optional dependencies: which extra of the package brings a missing module."""

from __future__ import annotations

import importlib.util

# module -> (PyPI package, extra of vereshchagin that installs it)
OPTIONAL = {
    "matplotlib": ("matplotlib", "experiments"),
    "mujoco": ("mujoco", "experiments"),
    "scipy": ("scipy", "test"),
    "pinocchio": ("pin", "test"),
    "example_robot_data": ("example-robot-data", "examples"),
    "dask": ("dask", "examples"),
}

# What each reproduce case imports beyond numpy.
CASE_NEEDS = {
    "friction": ("matplotlib",),
    "demo": (),
    "contact": ("mujoco", "matplotlib"),
    "dual-arm": ("mujoco", "matplotlib"),
    "friction-energy": ("mujoco", "matplotlib"),
}


def missing_message(modules) -> str | None:
    """A message naming the extra to install when one of ``modules`` cannot be imported, else None.

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
    extras = sorted({OPTIONAL[m][1] for m in missing if m in OPTIONAL})
    packages = ", ".join(OPTIONAL.get(m, (m,))[0] for m in missing)
    hint = " ".join(f"pip install 'vereshchagin[{e}]'" for e in extras) or f"pip install {packages}"
    return f"this needs the optional package(s) {packages}, which are not installed: {hint}"
