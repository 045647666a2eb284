"""The documentation site builds and has the API pages of the main entry points.

Needs the docs extra (``make docs`` installs it into .venv); skipped without it.
Builds the API reference alone (examples not executed) into a temporary folder.
"""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
MISSING = [m for m in ("sphinx", "numpydoc", "pydata_sphinx_theme", "sphinx_gallery")
           if importlib.util.find_spec(m) is None]
pytestmark = pytest.mark.skipif(bool(MISSING), reason=f"docs extra not installed (no {', '.join(MISSING)}): "
                                                      "run `make docs` once")

# page -> (object id on it, a phrase of its docstring)
PAGES = {
    "robustctl.design": ("robustctl.design", "Design a controller"),
    "robustctl.rlqr_gains": ("robustctl.rlqr_gains", "Steady-state RLQR gains"),
    "robustctl.hinf": ("robustctl.hinf", "H-infinity"),
    "moo.molsp.molsp": ("moo.molsp.molsp", "MO-LSP"),
}


@pytest.fixture(scope="module")
def html(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("html")
    env = {**os.environ, "DOCS_NO_EXAMPLES": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-q", "-d", str(out / ".doctrees"),
                           str(DOCS), str(out)], env=env, capture_output=True, text=True, timeout=600,
                          check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return out


@pytest.mark.parametrize("page", PAGES)
def test_api_page(html, page):
    path = html / "api" / "generated" / f"{page}.html"
    assert path.is_file(), f"no API page {path.name}"
    text = path.read_text(encoding="utf-8")
    anchor, phrase = PAGES[page]
    assert f'id="{anchor}"' in text, f"{path.name} does not document {anchor}"
    body = re.sub(r"<[^>]+>", "", text)
    assert phrase in body, f"{path.name} lacks its docstring ({phrase!r})"


def test_api_index_links_every_package(html):
    text = (html / "api.html").read_text(encoding="utf-8")
    for page in ("api/robustctl.html", "api/moo.html"):
        assert page in text


SCRIPT_SRC = re.compile(r"<script\b[^>]*\bsrc=\"([^\"]+)\"", re.IGNORECASE)
# sphinx-gallery's computation-time pages sort their table with DataTables from a CDN (no maths on them)
REMOTE_OK = "sg_execution_times.html"


def test_maths_renderer_is_bundled(html):
    """No page loads MathJax (or any script but the timing table's) from the network; MathJax is in _static."""
    pages = sorted(html.rglob("*.html"))
    remote = {(p.relative_to(html).as_posix(), src) for p in pages if p.name != REMOTE_OK
              for src in SCRIPT_SRC.findall(p.read_text(encoding="utf-8"))
              if re.match(r"(https?:)?//", src)}
    assert not remote, f"pages load scripts from the network: {sorted(remote)[:5]}"
    maths = [p for p in pages if 'class="math' in p.read_text(encoding="utf-8")]
    assert maths, "no page has maths (the check would be empty)"
    for page in maths[:3]:
        srcs = SCRIPT_SRC.findall(page.read_text(encoding="utf-8"))
        mathjax = [s for s in srcs if "mathjax" in s.lower()]
        assert mathjax, f"{page.name} has maths but no MathJax script"
        for src in mathjax:
            assert (page.parent / src.split("?")[0]).resolve().is_file(), f"{page.name}: {src} not in the build"
