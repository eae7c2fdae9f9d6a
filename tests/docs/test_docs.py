"""The documentation stays true: the Sphinx site builds without a warning, and every ``python``
code block of README.md and of the docs pages runs.

Blocks of one file run in order in one namespace (a page is a tutorial), in a fresh interpreter
with a non-interactive matplotlib backend and a temporary working directory. A block fenced as
``python`` is executed; output-only or illustrative text uses ``text`` or ``pycon``.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from support import ROOT

DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md"] + sorted(p for p in DOCS.rglob("*.md") if "_generated" not in p.parts)
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)


def python_blocks(path: Path) -> list:
    """The ``python`` fenced code blocks of a Markdown file, in order."""
    return FENCE.findall(path.read_text(encoding="utf-8"))


def test_readme_has_the_tour():
    blocks = python_blocks(ROOT / "README.md")
    assert len(blocks) >= 6
    text = "\n".join(blocks)
    for needle in ("Chain.from_urdf", "task.Task", "friction=", "constraints=", "solve_batch", "chain.notes"):
        assert needle in text, needle


@pytest.mark.parametrize("page", [p for p in PAGES if python_blocks(p)], ids=lambda p: str(p.relative_to(ROOT)))
def test_code_blocks_run(page, tmp_path):
    script = "\n\n".join(f"# --- block {k + 1} of {page.name}\n{b}" for k, b in enumerate(python_blocks(page)))
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, f"{page.name}:\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}"


def test_sphinx_builds_without_warnings(tmp_path):
    """``sphinx-build -W``: any warning (a broken reference, a bad docstring) fails."""
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(tmp_path / "html")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        env=dict(os.environ, MPLBACKEND="Agg"),
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-6000:]
    index = (tmp_path / "html" / "index.html").read_text(encoding="utf-8")
    assert "vereshchagin" in index
    for page in ("conventions", "friction", "api/python", "api/cpp"):
        assert (tmp_path / "html" / f"{page}.html").is_file(), page
