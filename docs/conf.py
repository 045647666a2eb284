"""Sphinx configuration of the robustctl + moo documentation (``make docs``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import robustctl  # noqa: E402  (after the path set-up)

project = "robustctl + moo"
author = "the robustctl developers"
copyright = "2026, the robustctl developers"  # noqa: A001 - the name Sphinx reads
release = version = robustctl.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",     # MathJax 3 shipped in _static/mathjax: no page loads maths from the network
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "apipages",
    "papertables",
    "benchresults",
    "myst_parser",                # the benchmark result files (Markdown) in validation/results/
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}

root_doc = "index"
exclude_patterns = ["_build", "_generated", "**.ipynb_checkpoints", "examples/README.rst", "README.md",
                    "_intersphinx"]
templates_path = ["_templates"]
nitpicky = True

# -- API reference: autodoc + autosummary + numpydoc ----------------------------------
autosummary_generate = True          # apipages names the pages it writes
autosummary_ignore_module_all = False
autodoc_default_options = {"member-order": "bysource"}
# Types are in the numpydoc Parameters/Returns sections; signatures without annotations
# (as numpy's and scipy's) avoid cross-referencing the expansions of aliases such as
# ArrayLike (a Union of numpy-private protocols) and dataclass-generated annotations.
autodoc_typehints = "none"

numpydoc_show_class_members = False       # the class template lists members through autodoc
numpydoc_xref_param_type = False          # types like "(B, n, n) ndarray" stay text
numpydoc_validation_checks: set[str] = set()

# -- cross-references to other projects (inventories shipped in _intersphinx/) --------
# CI has no internet: every inventory is a file here. docs/_intersphinx/README.md says
# where each one comes from and how to refresh it.
_INV = HERE / "_intersphinx"
intersphinx_mapping = {
    "python": ("https://docs.python.org/3.11", str(_INV / "python.inv")),
    "numpy": ("https://numpy.org/doc/stable", str(_INV / "numpy.inv")),
    "scipy": ("https://docs.scipy.org/doc/scipy", str(_INV / "scipy.inv")),
    "control": ("https://python-control.readthedocs.io/en/0.10.2", str(_INV / "control.inv")),
    "pymoo": ("https://pymoo.org", str(_INV / "pymoo.inv")),
    "matplotlib": ("https://matplotlib.org/stable", str(_INV / "matplotlib.inv")),
    "cvxpy": ("https://www.cvxpy.org", str(_INV / "cvxpy.inv")),
    "moocore": ("https://multi-objective.github.io/moocore/python", str(_INV / "moocore.inv")),
    "distributed": ("https://distributed.dask.org/en/stable", str(_INV / "distributed.inv")),
}

# Genuine gaps of other projects' inventories, each with its reason (never our own names).
nitpick_ignore = [
    # pymoo's API reference (pymoo.org/api) documents the core classes only, not these
    # bases of our MOEAs and helpers (checked against pymoo's docs/source/api/*.rst)
    ("py:class", "pymoo.algorithms.base.genetic.GeneticAlgorithm"),
    ("py:class", "pymoo.util.nds.non_dominated_sorting.NonDominatedSorting"),
]

# -- executed examples (sphinx-gallery; docs/examples/*.py, see docs/examples/README.rst) -
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "remove_config_comments": True,
    "download_all_examples": False,
    "within_subsection_order": "gallery_order.ExampleOrder",   # the user guide's order
    "matplotlib_animations": False,
    # moo.plots draws Figures without pyplot; _ext/figure_scraper.py shows them too (it runs
    # first, while the pyplot figures it must leave to "matplotlib" are still open)
    "image_scrapers": ("figure_scraper.figure_scraper", "matplotlib"),
    # the examples print what they show; no repr of a block's last value (``<Legend ...>``)
    "capture_repr": (),
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "min_reported_time": 1,
}
if os.environ.get("DOCS_NO_EXAMPLES"):        # API-only build (tests/test_docs.py)
    sphinx_gallery_conf["plot_gallery"] = "False"

# -- HTML ------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = "robustctl + moo"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_static_path: list[str] = []
html_show_sourcelink = False
