"""Compact tables of the MO-LSP effect, paper vs ours, from ``paper_repro/results/*_vs_paper.csv``.

Writes ``_generated/<name>.rst`` (a list-table: MOEAs x indicators) for every
``moea_*_vs_paper.csv`` at ``config-inited``; ``reproducing.rst`` includes
them. Each cell is ``paper / ours``: the sign of mean(MO-LSP) - mean(plain)
(down or up arrow), ``*`` when significant at 95 %, then ``=`` (direction and
significance agree), ``~`` (direction only) or ``x`` (direction differs).
"""

from __future__ import annotations

import csv
from pathlib import Path

INDICATORS = (("igd", "IGD"), ("sp", "SP"), ("hv", "HV"), ("pd", "PD"), ("spread", "Spread"))
ARROW = {"-1": "▼", "1": "▲", "0": "="}


def _cell(row: dict) -> str:
    def side(sign, sig):
        return ARROW.get(sign, "?") + ("*" if sig == "True" else "")
    mark = "=" if row["full_agreement"] == "True" else ("~" if row["direction_agrees"] == "True" else "x")
    paper, ours = side(row["paper_sign"], row["paper_significant"]), side(row["our_sign"], row["our_significant"])
    return f"{paper} / {ours} {mark}"


def table(path: Path) -> str:
    rows = list(csv.DictReader(path.open()))
    algorithms = list(dict.fromkeys(r["algorithm"] for r in rows))
    cells = {(r["algorithm"], r["indicator"]): _cell(r) for r in rows}
    agree = sum(r["direction_agrees"] == "True" for r in rows)
    full = sum(r["full_agreement"] == "True" for r in rows)
    lines = [".. list-table::", "   :header-rows: 1", "",
             "   * - MOEA", *(f"     - {label}" for _, label in INDICATORS)]
    for alg in algorithms:
        lines.append(f"   * - {alg}")
        lines += [f"     - {cells.get((alg, key), '')}" for key, _ in INDICATORS]
    lines += ["", (f"Direction agrees in {agree} of {len(rows)} cells; direction and significance in "
                   f"{full} of {len(rows)}."), ""]
    return "\n".join(lines)


def _config_inited(app, config) -> None:
    src = Path(app.srcdir)
    out = src / "_generated"
    out.mkdir(exist_ok=True)
    for path in sorted((src.parent / "paper_repro" / "results").glob("moea_*_vs_paper.csv")):
        target = out / f"{path.stem}.rst"
        text = table(path)
        if not target.exists() or target.read_text() != text:
            target.write_text(text)


def setup(app):
    app.connect("config-inited", _config_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
