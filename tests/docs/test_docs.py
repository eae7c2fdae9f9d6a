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


@pytest.fixture(scope="module")
def sphinx_html(tmp_path_factory):
    """One ``sphinx-build -W`` of the site for this module: the process and its output folder."""
    html = tmp_path_factory.mktemp("docs") / "html"
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(html)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        env=dict(os.environ, MPLBACKEND="Agg"),
    )
    return proc, html


def test_sphinx_builds_without_warnings(sphinx_html):
    """``sphinx-build -W``: any warning (a broken reference, a bad docstring, an undocumented public
    C++ member reported by Doxygen) fails."""
    proc, html = sphinx_html
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-6000:]
    index = (html / "index.html").read_text(encoding="utf-8")
    assert "vereshchagin" in index
    for page in ("conventions", "friction", "api/python", "api/cpp"):
        assert (html / f"{page}.html").is_file(), page


CLASS = re.compile(r"^\s*(?:class|struct)\s+(?:\[\[.*?\]\]\s+)?(\w+)\s*(?::[^:]|\{)", re.M)


def test_cpp_reference_has_every_public_header(sphinx_html):
    """api/cpp has a section per header of cpp/include/vereshchagin (found by a glob at build time,
    so a new header appears without editing the page), with the header's file documentation and
    every class or struct it defines, rendered from Doxygen's XML by breathe."""
    proc, html = sphinx_html
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-6000:]
    page = (html / "api" / "cpp.html").read_text(encoding="utf-8")
    headers = sorted((ROOT / "cpp" / "include" / "vereshchagin").glob("*.hpp"))
    assert len(headers) >= 12
    for header in headers:
        anchor = '<section id="' + header.name.replace("_", "-").replace(".", "-") + '">'
        assert anchor in page, f"api/cpp has no section for {header.name}"
        section = page.split(anchor, 1)[1].split("<section id=", 1)[0]
        assert "<p>" in section, f"{header.name}: no file documentation rendered"
        for name in CLASS.findall(header.read_text(encoding="utf-8")):
            assert f'<span class="n"><span class="pre">{name}</span></span>' in section, f"{header.name}: {name}"
