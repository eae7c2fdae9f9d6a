"""Project files stay consistent: one version, lint clean, license shipped, no paths outside the repo."""

import re
import subprocess
import sys

import vereshchagin as vs
from support import ROOT


def _cmake_version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    return re.search(r"project\(vereshchagin VERSION ([0-9.]+)", text).group(1)


def test_version_is_written_once():
    """CMakeLists.txt holds the version; the package and its metadata report that one."""
    from importlib import metadata

    version = _cmake_version()
    assert vs.__version__ == version
    assert metadata.version("vereshchagin") == version
    assert re.search(r"^version\s*=", (ROOT / "pyproject.toml").read_text(encoding="utf-8"), re.M) is None
    init = (ROOT / "python" / "vereshchagin" / "__init__.py").read_text(encoding="utf-8")
    assert version not in init
    assert f"## [{version}]" in (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")


PY_DIRS = ("python", "experiments", "tests", "benchmarks", "examples", "docs", "tools")
"""The folders with Python files (as tools/check_format.sh checks them)."""


def test_ruff_lint_clean():
    """The lint rules of pyproject.toml's [tool.ruff.lint] hold on every Python file of the repository."""
    proc = subprocess.run(
        [sys.executable, "-m", "ruff", "check", *PY_DIRS],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_license_matches_declared():
    assert "GNU LESSER GENERAL PUBLIC LICENSE" in (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "LGPL-2.1-or-later" in (ROOT / "pyproject.toml").read_text(encoding="utf-8")


def test_nothing_points_outside_the_repository():
    """No file cites notes outside the repository (a reader of a clone cannot follow them)."""
    pattern = re.compile(r"/work/|\.\./shared|shared/reference|shared/seeds")
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    offending = []
    for name in tracked:
        path = ROOT / name
        if name.startswith("cpp/fuzz/") or not path.is_file() or name == "tests/docs/test_project_files.py":
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        offending += [f"{name}:{i + 1}" for i, line in enumerate(text.splitlines()) if pattern.search(line)]
    assert not offending, offending
