"""Every script in examples/ runs to completion, headless, and produces its output.

Each runs in a fresh interpreter (as a user would run it) with a non-interactive matplotlib
backend and a temporary folder as the working and output directory. The C++ example is built
and run by .ci/test against the installed library (it needs the install prefix).
"""

import os
import subprocess
import sys

import pytest

from support import ROOT

EXAMPLES = ROOT / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))


def test_examples_exist():
    assert len(SCRIPTS) >= 7
    assert (EXAMPLES / "cpp" / "CMakeLists.txt").is_file()


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_example_runs(script, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
    proc = subprocess.run(
        [sys.executable, str(script), str(tmp_path)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert proc.stdout.strip(), "an example must print something a person would look at"
    text = script.read_text(encoding="utf-8")
    if "savefig" in text:
        pngs = list(tmp_path.glob("*.png"))
        assert pngs and all(p.stat().st_size > 10_000 for p in pngs), pngs
