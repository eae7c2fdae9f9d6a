"""The package version, read from the one place it is written: CMakeLists.txt's ``project()``.

An installed package (wheel or ``pip install .``) has it in its metadata, which scikit-build-core
fills from CMakeLists.txt at build time. A source or build tree that is imported without being
installed reads CMakeLists.txt directly; anything else reports ``0+unknown``.
"""

from __future__ import annotations

import re
from importlib import metadata
from pathlib import Path

_PROJECT = re.compile(r"project\(vereshchagin VERSION ([0-9]+\.[0-9]+\.[0-9]+)")


def _from_source_tree() -> str | None:
    """The version in ``CMakeLists.txt`` two levels above this package, if that file exists."""
    cmake = Path(__file__).resolve().parents[2] / "CMakeLists.txt"
    try:
        match = _PROJECT.search(cmake.read_text(encoding="utf-8"))
    except OSError:
        return None
    return match.group(1) if match else None


def _version() -> str:
    """The source tree's version if this package lives in one, else the installed metadata's."""
    found = _from_source_tree()
    if found is not None:
        return found
    try:
        return metadata.version("vereshchagin")
    except metadata.PackageNotFoundError:
        return "0+unknown"


__version__ = _version()
