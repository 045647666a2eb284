"""sphinx-gallery image scraper for matplotlib Figures made without pyplot.

:mod:`moo.plots` draws on :class:`matplotlib.figure.Figure` objects it
creates itself (no pyplot, so no global backend is touched). sphinx-gallery's
own matplotlib scraper only sees the figures pyplot manages, so an example
that shows ``fig = moo.plots.cd_diagram(...)`` would lose the figure. This
scraper saves every ``Figure`` that a code block leaves in the example's
global variables and that pyplot does not manage, once, after the block that
created it. It must run before sphinx-gallery's ``"matplotlib"`` scraper
(conf.py's ``image_scrapers`` order): that one closes the pyplot figures it
saves, after which they too have no manager; this scraper marks every figure
it sees open under pyplot as seen, and so never saves one twice.
"""

from __future__ import annotations

from matplotlib.figure import Figure
from sphinx_gallery.scrapers import figure_rst

_SEEN = "_figure_scraper_seen"          # per-example record of the figures already saved


def figure_scraper(block, block_vars, gallery_conf) -> str:
    """Save the example's new pyplot-free figures; return their reST (sphinx-gallery's scraper API)."""
    seen: list = block_vars.setdefault(_SEEN, [])          # the figures themselves: ids are reused
    paths = []
    for value in list(block_vars["example_globals"].values()):
        if not isinstance(value, Figure) or any(f is value for f in seen):
            continue
        seen.append(value)
        if value.canvas.manager is not None:              # pyplot's: the "matplotlib" scraper saves it
            continue
        path = block_vars["image_path_iterator"].next()          # the next free image file name
        value.savefig(path)
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
