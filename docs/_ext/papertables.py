"""The paper's tables rebuilt from the result files in ``paper_repro/results/``, as reST for the pages.

At ``config-inited`` it writes into ``_generated/``:

* ``<name>.rst`` for every ``moea_*_vs_paper.csv``: the MO-LSP effect, paper vs
  ours (a list-table: MOEAs x indicators); ``reproducing.rst`` includes them.
  Each cell is ``paper / ours``: the sign of mean(MO-LSP) - mean(plain)
  (down or up arrow), ``*`` when significant at 95 %, then ``=`` (direction
  and significance agree), ``~`` (direction only) or ``x`` (direction differs);
* ``mse_sensors_<objective>.rst``, ``mse_sensors_radius.rst`` and
  ``mse_sensors_mu.rst`` from ``mse_sensors.csv``, ``mse_sensors_radius.csv`` and
  ``mse_sensors_mu.csv`` (``paper_repro/mse_table_sensors.py``): the MSE table
  with the truck's sensors, one list-table per objective (controllers x
  estimators, the overloads as columns), the linear loops' spectral radii in
  the same layout, and the choice of the robust filter's penalty;
  ``validation/sensors.rst`` includes them.
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


ESTIMATOR_LABELS = {"full_state": "full state", "kalman": "Kalman filter", "robust": "robust filter",
                    "robust_paper_mu": "robust filter, paper's mu"}


def _by_overload(rows: list[dict], cell) -> str:
    """A list-table of ``rows`` (controller, estimator, overload): one row per controller and estimator (every pair)."""
    overloads = list(dict.fromkeys(r["overload"] for r in rows))
    cells: dict[tuple[str, str], dict[str, str]] = {}
    for r in rows:
        cells.setdefault((r["controller"], r["estimator"]), {})[r["overload"]] = cell(r)
    lines = [".. list-table::", "   :header-rows: 1", "", "   * - controller", "     - estimator",
             *(f"     - {ov} %" for ov in overloads)]
    controllers = dict.fromkeys(c for c, _ in cells)
    estimators = dict.fromkeys(e for _, e in cells)
    for controller in controllers:                     # grouped by controller, the estimators in the file's order
        for estimator in estimators:
            by = cells[controller, estimator]
            lines += [f"   * - {controller}", f"     - {ESTIMATOR_LABELS.get(estimator, estimator)}",
                      *(f"     - {by[ov]}" for ov in overloads)]
    return "\n".join(lines) + "\n"


def _mse_cell(r: dict) -> str:
    text = f"{float(r['mse']):.3e}"
    if int(r["draws"]) > 1:
        text += f" ± {float(r['std']):.1e}"
    if int(r["diverged"]):
        text += f" ({r['diverged']} of {r['draws']} diverged)"
    return text


def sensor_tables(path: Path) -> dict[str, str]:
    """``{objective: list-table}`` of ``mse_sensors.csv``: the mean (± std over the draws) per overload."""
    rows = list(csv.DictReader(path.open()))
    return {obj: _by_overload([r for r in rows if r["objective"] == obj], _mse_cell)
            for obj in dict.fromkeys(r["objective"] for r in rows)}


def radius_table(path: Path) -> str:
    """``mse_sensors_radius.csv`` as a list-table."""
    return _by_overload(list(csv.DictReader(path.open())), lambda r: f"{float(r['spectral_radius']):.4f}")


def mu_table(path: Path) -> str:
    """``mse_sensors_mu.csv`` as a list-table: each penalty's worst closed-loop spectral radius, the chosen one."""
    lines = [".. list-table::", "   :header-rows: 1", "", "   * - mu", "     - worst closed-loop spectral radius",
             "     - chosen"]
    for r in csv.DictReader(path.open()):
        lines += [f"   * - {r['mu']}", f"     - {float(r['worst_spectral_radius']):.4f}",
                  f"     - {'yes' if r['chosen'] == 'True' else ''}"]
    return "\n".join(lines) + "\n"


def _write(target: Path, text: str) -> None:
    if not target.exists() or target.read_text() != text:
        target.write_text(text)


def _config_inited(app, config) -> None:
    src = Path(app.srcdir)
    out = src / "_generated"
    out.mkdir(exist_ok=True)
    results = src.parent / "paper_repro" / "results"
    for path in sorted(results.glob("moea_*_vs_paper.csv")):
        _write(out / f"{path.stem}.rst", table(path))
    if (results / "mse_sensors.csv").exists():
        for obj, text in sensor_tables(results / "mse_sensors.csv").items():
            _write(out / f"mse_sensors_{obj}.rst", text)
        _write(out / "mse_sensors_radius.rst", radius_table(results / "mse_sensors_radius.csv"))
        _write(out / "mse_sensors_mu.rst", mu_table(results / "mse_sensors_mu.csv"))


def setup(app):
    app.connect("config-inited", _config_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
