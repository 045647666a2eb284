"""Plain table writers: CSV, Markdown (GitHub pipe tables) and LaTeX ``tabular``.

The cells are given already formatted (strings, or values written with
``str``); the writers only lay them out, so a script keeps its number formats
and bold marks and shares the layout. :mod:`moo.stats` writes the paper's
MOEA tables with its own layout on top of the same formats.

References
----------
RFC 4180, *Common Format and MIME Type for Comma-Separated Values (CSV)
Files* (2005); GitHub Flavored Markdown, *Tables (extension)*,
https://github.github.com/gfm/#tables-extension-; L. Lamport, *LaTeX: A
Document Preparation System*, 2nd ed., Addison-Wesley 1994, Sec. C.10.2
(``tabular``).
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["write_csv", "markdown_table", "latex_tabular"]

_ALIGN = {"l": "---", "r": "---:", "c": ":---:"}


def write_csv(header: Sequence[str], rows: Iterable[Sequence[object]], path: str | os.PathLike | None = None,
              *, lineterminator: str = "\n") -> str:
    r"""The rows as CSV under ``header`` (Python's :mod:`csv` quoting); written to ``path`` if given.

    Parameters
    ----------
    header : sequence of str
        Column names.
    rows : iterable of sequences
        One sequence of cells per row (``str(cell)`` is written; quoted
        where a cell holds a comma, a quote or a line break).
    path : path-like, optional
        File to write (UTF-8, the text exactly as returned).
    lineterminator : str
        ``"\n"`` (default, as :mod:`moo.stats`) or ``"\r\n"`` (RFC 4180).

    Returns
    -------
    str
        The CSV text.
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator=lineterminator)
    w.writerow(list(header))
    for row in rows:
        w.writerow(list(row))
    text = buf.getvalue()
    if path is not None:
        with open(Path(path), "w", newline="", encoding="utf-8") as fh:
            fh.write(text)
    return text


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[object]], align: str | None = None) -> str:
    """A Markdown pipe table, one line per row (no trailing newline).

    Parameters
    ----------
    header : sequence of str
    rows : iterable of sequences
        Cells (``str(cell)``), as many as ``header``.
    align : str, optional
        One letter per column, ``l``, ``r`` or ``c`` (default: all ``l``,
        written ``---``).

    Returns
    -------
    str

    Examples
    --------
    >>> print(markdown_table(["name", "value"], [["a", 1.5]], align="lr"))
    | name | value |
    |---|---:|
    | a | 1.5 |
    """
    header = list(header)
    align = "l" * len(header) if align is None else align
    if len(align) != len(header) or set(align) - set(_ALIGN):
        raise ValueError(f"align must have one of l, r, c per column ({len(header)}), got {align!r}")
    lines = ["| " + " | ".join(header) + " |", "|" + "".join(_ALIGN[a] + "|" for a in align)]
    for row in rows:
        cells = [str(c) for c in row]
        if len(cells) != len(header):
            raise ValueError(f"every row must have {len(header)} cells (the header's), got {len(cells)}: {cells}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def latex_tabular(colspec: str, header: Sequence[str], groups: Iterable[Iterable[Sequence[object]]]) -> str:
    r"""A LaTeX ``tabular``: ``\hline``, the header lines, ``\hline``, each group of rows then ``\hline``.

    Parameters
    ----------
    colspec : str
        The column specification, e.g. ``"c c c"``.
    header : sequence of str
        Header lines, written as given (each ending in ``\\``, with any
        ``\multicolumn`` or ``\cline``).
    groups : iterable of iterables of rows
        Row groups separated by ``\hline``; a row's cells are joined by
        `` & `` and end with `` \\``.

    Returns
    -------
    str
        The table, one line per row (no trailing newline).

    Examples
    --------
    >>> print(latex_tabular("l r", [r"name & value \\"], [[["a", 1.5]]]))
    \begin{tabular}{l r}
    \hline
    name & value \\
    \hline
    a & 1.5 \\
    \hline
    \end{tabular}
    """
    lines = [rf"\begin{{tabular}}{{{colspec}}}", r"\hline", *header, r"\hline"]
    for group in groups:
        lines += [" & ".join(str(c) for c in row) + r" \\" for row in group]
        lines.append(r"\hline")
    lines.append(r"\end{tabular}")
    return "\n".join(lines)
