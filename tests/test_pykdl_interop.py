"""Chain.from_kdl / Chain.to_kdl against Debian's python3-pykdl, for real.

Debian's PyKDL is built for the system interpreter /usr/bin/python3. If the interpreter running
pytest can import PyKDL, the checks of tests/pykdl_checks.py run in-process; otherwise they run in
/usr/bin/python3 (with Debian's python3-numpy) on a copy of the vereshchagin package installed
here, i.e. on the very extension module under test (CPython 3.11 on both sides). A missing PyKDL
is a failure, not a skip: .ci/setup installs python3-pykdl and python3-numpy.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

SYSTEM_PYTHON = "/usr/bin/python3"
CHECKS = Path(__file__).with_name("pykdl_checks.py")


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
        sys.path.insert(0, str(CHECKS.parent))
        import pykdl_checks

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
