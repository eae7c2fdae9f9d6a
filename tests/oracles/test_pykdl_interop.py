"""Chain.from_kdl / Chain.to_kdl against Debian's python3-pykdl, for real.

Debian's PyKDL is built for the system interpreter /usr/bin/python3. If the interpreter running
pytest can import PyKDL, the checks of tests/support/pykdl_checks.py run in-process; otherwise they run in
/usr/bin/python3 (with Debian's python3-numpy) on a copy of the vereshchagin package installed
here, i.e. on the very extension module under test (CPython 3.11 on both sides). A missing PyKDL
is a failure, not a skip: .ci/setup installs python3-pykdl and python3-numpy.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

import vereshchagin as vs
from support import ROOT
from vereshchagin.robots import example_robot_urdf

SYSTEM_PYTHON = "/usr/bin/python3"
CHECKS = ROOT / "tests" / "support" / "pykdl_checks.py"


def _has_pykdl_in_process():
    try:
        import PyKDL  # noqa: F401
    except ImportError:
        return False
    return True


def _urdfs():
    return [str(example_robot_urdf("panda")), str(example_robot_urdf("ur5"))]


def test_from_kdl_to_kdl_against_debian_pykdl(tmp_path):
    if _has_pykdl_in_process():
        from support import pykdl_checks

        worst = pykdl_checks.run_all(*_urdfs())
        assert worst and max(worst.values()) <= pykdl_checks.RTOL
        return
    probe = subprocess.run([SYSTEM_PYTHON, "-c", "import PyKDL, numpy"], capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.fail(
            f"Debian's PyKDL is not importable by {SYSTEM_PYTHON} (apt-get install python3-pykdl "
            f"python3-numpy; .ci/setup does it):\n{probe.stderr}"
        )
    package = Path(vs.__file__).parent
    shutil.copytree(package, tmp_path / "vereshchagin", ignore=shutil.ignore_patterns("__pycache__"))
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "PYTHONPATH": str(tmp_path), "PYTHONNOUSERSITE": "1"}
    run = subprocess.run(
        [SYSTEM_PYTHON, str(CHECKS), *_urdfs()], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600
    )
    assert run.returncode == 0, f"{SYSTEM_PYTHON} {CHECKS.name} failed:\n{run.stdout}\n{run.stderr}"
    assert "PYKDL CHECKS PASSED" in run.stdout
    print(run.stdout)


def test_to_kdl_without_pykdl_says_how_to_get_it():
    if _has_pykdl_in_process():
        pytest.skip("PyKDL is importable here; the message is for interpreters without it")
    with pytest.raises(ImportError, match="python3-pykdl"):
        vs.robots.gen3().to_kdl()


# The README's recipe for PyKDL and vereshchagin in one interpreter, run as written.
RECIPE_MARK = "<!-- pykdl-venv-recipe -->"
SOURCES = ("CMakeLists.txt", "pyproject.toml", "README.md", "LICENSE", "cpp", "python")


def readme_recipe() -> str:
    """The ``bash`` block that follows the recipe marker in README.md."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert RECIPE_MARK in text, "README.md lost the PyKDL venv recipe"
    block = text.split(RECIPE_MARK, 1)[1].lstrip()
    assert block.startswith("```bash\n"), block[:40]
    return block[len("```bash\n") :].split("```", 1)[0]


def test_readme_venv_recipe_gets_pykdl_and_vereshchagin_into_one_interpreter(tmp_path):
    """``/usr/bin/python3 -m venv --system-site-packages`` then ``pip install .`` in a copy of the
    sources (a full build of the package, with pip's isolated build environment), then the
    recipe's own import line; afterwards the venv's interpreter passes pykdl_checks.py."""
    recipe = readme_recipe()
    assert "/usr/bin/python3 -m venv --system-site-packages" in recipe and "/bin/pip install ." in recipe
    src = tmp_path / "src"
    src.mkdir()
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(path, src / name)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env["PYTHONNOUSERSITE"] = "1"
    run = subprocess.run(
        ["bash", "-euo", "pipefail", "-c", recipe], cwd=src, env=env, capture_output=True, text=True, timeout=3600
    )
    assert run.returncode == 0, f"README recipe failed:\n{recipe}\n{run.stdout[-3000:]}\n{run.stderr[-6000:]}"
    assert run.stdout.strip().splitlines()[-1] == "0"
    venv_python = next(src.glob(".venv*/bin/python"))
    checks = subprocess.run(
        [str(venv_python), str(CHECKS), *_urdfs()], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600
    )
    assert checks.returncode == 0, f"pykdl_checks.py in the recipe's venv:\n{checks.stdout}\n{checks.stderr}"
    assert "PYKDL CHECKS PASSED" in checks.stdout
