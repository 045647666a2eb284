"""The benchmark result files as pages of the Validation part, unedited.

At ``config-inited`` every ``benchmarks/results/*.md`` (written by a script of
``benchmarks/``, never edited by hand) is copied byte for byte to
``validation/results/<name>.md``, which MyST parses, and
``validation/results/index.rst`` lists them. The explanations of the numbers
live in the hand-written pages beside it (``validation/*.rst``), so a rerun of a
benchmark replaces its file and loses nothing.
"""

from __future__ import annotations

from pathlib import Path

INDEX = """\
Result files
============

The files that the benchmarks and investigations of ``benchmarks/`` write into
``benchmarks/results/``, shown as they are (each states the command that made
it). The pages of this part explain them.

.. toctree::
   :maxdepth: 1

{entries}
"""


def _write(path: Path, text: str) -> None:
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def _config_inited(app, config) -> None:
    src = Path(app.srcdir)
    out = src / "validation" / "results"
    out.mkdir(parents=True, exist_ok=True)
    files = sorted((src.parent / "benchmarks" / "results").glob("*.md"))
    for stale in set(out.glob("*.md")) - {out / f.name for f in files}:
        stale.unlink()
    for f in files:
        _write(out / f.name, f.read_text(encoding="utf-8"))
    _write(out / "index.rst", INDEX.format(entries="\n".join(f"   {f.stem}" for f in files)))


def setup(app):
    app.connect("config-inited", _config_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
