"""Indicators per run and the paper's statistics (ANOVA + Tukey HSD, MOEA vs MOEA/MO-LSP).

Pipeline (``python -m moo stats DIR``)::

    records = load_records(DIR)              # moo.experiment: one dict per run
    runs    = run_indicators(records)        # five indicators per run (RunIndicators)
    table   = compare(runs)                  # one Comparison per (problem, algorithm, indicator)
    to_markdown(table) / to_csv(...) / to_latex(...)

Indicators (:mod:`moo.indicators`) on each run's final non-dominated set ``F``:

* IGD and Spread need a reference set ``P*``. For the control-design MOPs
  (``generic``, ``applied``) the true front is unknown; ``P*`` is the
  non-dominated union of the final sets of *all* runs recorded for the problem
  (every algorithm, both variants, every seed), as PAPER_NOTES.md asks. It
  therefore depends on what the directory holds: adding runs can change every
  IGD. For ZDT1-6 and DTLZ1-7 ``P*`` is a dense sample of the true Pareto front
  from its closed form (:func:`true_front`).
* SP (Schott's spacing), HV (reference point ``problem.hv_ref_point``, the
  one stored in the record) and PD (pure diversity, greedy computation).

A run whose final set has fewer than two points has SP and Spread undefined
(NaN); a run with an empty set (no feasible point) has HV 0 and the others NaN.
NaNs are left out of means and tests, and counted (``n_plain``, ``n_molsp``).

Statistics, as the paper's Section 4.4: for each MOEA and indicator, a one-way
ANOVA (:func:`scipy.stats.f_oneway`) and Tukey's HSD at 95 %
(:func:`scipy.stats.tukey_hsd`) between the runs of the MOEA and those of its
MO-LSP version. With two groups both p-values equal that of the two-sided
pooled-variance t-test; both are reported. ``better`` is the variant with the
better mean (lower IGD, SP, Spread; higher HV, PD; note that the paper's
tables bold the *larger* SP as the better one); ``significant`` is
``p_tukey < alpha``. If both groups are constant the tests are undefined: p is
1 when the two constants are equal and 0 otherwise.

References
----------
J. W. Tukey (1949), "Comparing individual means in the analysis of variance",
Biometrics 5(2), 99-114; Morais et al. (2022), Section 4.
"""

from __future__ import annotations

import csv
import io
import math
import os
import warnings
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import moocore
import numpy as np
from numpy.typing import ArrayLike
from scipy import stats as sps

from moo import indicators as ind

__all__ = ["INDICATORS", "HIGHER_IS_BETTER", "RunIndicators", "Comparison", "true_front", "reference_sets",
           "run_indicators", "pairwise_test", "compare", "to_csv", "to_markdown", "to_latex", "analyse"]

#: Indicator names in the paper's column order.
INDICATORS: tuple[str, ...] = ("igd", "sp", "hv", "pd", "spread")
#: Direction of each indicator (True: larger is better).
HIGHER_IS_BETTER: dict[str, bool] = {"igd": False, "sp": False, "hv": True, "pd": True, "spread": False}
_LABELS = {"igd": "IGD", "sp": "SP", "hv": "HV", "pd": "PD", "spread": "Spread"}

_TRUE_FRONT_POINTS = 5000


@dataclass(frozen=True)
class RunIndicators:
    """The five indicators of one run's final non-dominated set."""

    problem: str
    n_obj: int
    algorithm: str
    molsp: bool
    seed: int
    n_points: int
    igd: float
    sp: float
    hv: float
    pd: float
    spread: float


@dataclass(frozen=True)
class Comparison:
    """One MOEA vs its MO-LSP version on one indicator (mean, std over runs; tests)."""

    problem: str
    algorithm: str
    indicator: str
    n_plain: int
    n_molsp: int
    mean_plain: float
    std_plain: float
    mean_molsp: float
    std_molsp: float
    p_anova: float
    p_tukey: float
    better: str            # "molsp", "plain" or "tie"
    significant: bool


# ---------------------------------------------------------------------------- reference sets

def _simplex_grid(M: int, n_points: int) -> np.ndarray:
    """Das-Dennis points on the unit simplex, about ``n_points`` of them."""
    from pymoo.util.ref_dirs import get_reference_directions

    H = 1
    while math.comb(H + 1 + M - 1, M - 1) <= n_points:
        H += 1
    return get_reference_directions("das-dennis", M, n_partitions=H)


def _cube_grid(dim: int, n_points: int) -> np.ndarray:
    k = max(2, int(np.floor(n_points ** (1.0 / dim))))
    axes = np.meshgrid(*[np.linspace(0.0, 1.0, k)] * dim, indexing="ij")
    return np.stack([a.ravel() for a in axes], axis=1)


def true_front(problem: str, n_obj: int | None = None, n_points: int = _TRUE_FRONT_POINTS) -> np.ndarray:
    """A dense sample of the true Pareto front of a ZDT or DTLZ problem (closed forms).

    ZDT1/4: ``f2 = 1 - sqrt(f1)``; ZDT2: ``f2 = 1 - f1^2``; ZDT3: ``f2 = 1 - sqrt(f1)
    - f1 sin(10 pi f1)``, non-dominated part; ZDT6: ``f2 = 1 - f1^2`` for ``f1`` in
    ``[0.2808, 1]``; ZDT5 (normalised as pymoo): pymoo's own front. DTLZ1: the
    simplex ``sum f = 0.5``; DTLZ2-4: the unit sphere's positive orthant (points
    ``w / ||w||`` for Das-Dennis ``w``); DTLZ5/6 (a curve) and DTLZ7 (disconnected):
    the problem evaluated at its Pareto-optimal decision vectors (distance
    variables at their optimum: 0.5 for DTLZ5, 0 for DTLZ6/7), non-dominated part.

    References
    ----------
    Zitzler, Deb & Thiele (2000); Deb, Thiele, Laumanns & Zitzler (2005).
    """
    from moo.problems import make_problem, true_front_bounds

    key = problem.lower()
    if key.startswith("zdt"):
        if key == "zdt5":
            return np.asarray(make_problem("zdt5").pareto_front(), dtype=float)
        lo = float(true_front_bounds(key)[0][0])
        f1 = np.linspace(lo, 1.0, n_points)
        f2 = {"zdt1": 1 - np.sqrt(f1), "zdt4": 1 - np.sqrt(f1), "zdt2": 1 - f1**2, "zdt6": 1 - f1**2,
              "zdt3": 1 - np.sqrt(f1) - f1 * np.sin(10 * np.pi * f1)}[key]
        F = np.column_stack([f1, f2])
    elif key.startswith("dtlz"):
        prob = make_problem(key, n_obj)
        M = prob.n_obj
        if key == "dtlz1":
            return 0.5 * _simplex_grid(M, n_points)
        if key in ("dtlz2", "dtlz3", "dtlz4"):
            W = _simplex_grid(M, n_points)
            return W / np.linalg.norm(W, axis=1, keepdims=True)
        k = prob.n_var - (M - 1)
        if key in ("dtlz5", "dtlz6"):
            pos = np.column_stack([np.linspace(0, 1, n_points)] + [np.full(n_points, 0.5)] * (M - 2))
        else:
            pos = _cube_grid(M - 1, n_points)
        tail = 0.5 if key == "dtlz5" else 0.0
        X = np.hstack([pos, np.full((len(pos), k), tail)])
        F = np.asarray(prob.evaluate(X, return_values_of=["F"]), dtype=float)
    else:
        raise ValueError(f"true_front knows ZDT and DTLZ problems only, got {problem!r}")
    return F[moocore.is_nondominated(F, keep_weakly=False)]


def _front(rec: dict) -> np.ndarray:
    F = np.asarray(rec["F"], dtype=float)
    return F.reshape(-1, int(rec["n_obj"])) if F.size == 0 else F


def reference_sets(records: Iterable[dict]) -> dict[tuple[str, int], np.ndarray]:
    """``P*`` per ``(problem, n_obj)``: the true front (ZDT/DTLZ) or the non-dominated union of all runs."""
    union: dict[tuple[str, int], list[np.ndarray]] = defaultdict(list)
    for rec in records:
        union[(rec["problem"], int(rec["n_obj"]))].append(_front(rec))
    out = {}
    for (problem, m), parts in union.items():
        if problem.startswith(("zdt", "dtlz")):
            out[(problem, m)] = true_front(problem, m)
            continue
        P = np.vstack(parts)
        P = P[np.all(np.isfinite(P), axis=1)]
        if len(P):
            P = np.unique(P, axis=0)
            P = P[moocore.is_nondominated(P, keep_weakly=False)]
        out[(problem, m)] = P
    return out


# ---------------------------------------------------------------------------- indicators per run

def run_indicators(records: Sequence[dict], ref_sets: dict[tuple[str, int], np.ndarray] | None = None
                   ) -> list[RunIndicators]:
    """The five indicators of every run (see the module docstring for ``P*`` and NaNs)."""
    records = list(records)
    if ref_sets is None:
        ref_sets = reference_sets(records)
    rows = []
    for rec in records:
        F = _front(rec)
        key = (rec["problem"], int(rec["n_obj"]))
        R = ref_sets[key]
        n = len(F)
        nan = float("nan")
        hv = ind.hypervolume(F, rec["hv_ref_point"]) if n else 0.0
        rows.append(RunIndicators(
            problem=rec["problem"], n_obj=int(rec["n_obj"]), algorithm=rec["algorithm"], molsp=bool(rec["molsp"]),
            seed=int(rec["seed"]), n_points=n,
            igd=ind.igd(F, R) if n and len(R) else nan,
            sp=ind.spacing(F) if n >= 2 else nan,
            hv=hv,
            pd=ind.pure_diversity(F) if n else nan,
            spread=ind.spread(F, R) if n >= 2 and len(R) else nan))
    return rows


# ---------------------------------------------------------------------------- tests

def _sample(values: ArrayLike, name: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    return arr[np.isfinite(arr)]


def pairwise_test(plain: ArrayLike, molsp: ArrayLike) -> tuple[float, float]:
    """p-values of one-way ANOVA and Tukey's HSD between two samples (NaNs dropped).

    Returns ``(p_anova, p_tukey)``. NaN when a sample has fewer than two values
    or both together fewer than three; if both samples are constant, 1.0 when
    the constants are equal and 0.0 otherwise (the tests divide by a zero
    within-group variance).
    """
    a, b = _sample(plain, "plain"), _sample(molsp, "molsp")
    if len(a) < 2 or len(b) < 2:
        return float("nan"), float("nan")
    if np.ptp(a) == 0 and np.ptp(b) == 0:
        p = 1.0 if a[0] == b[0] else 0.0
        return p, p
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        p_anova = float(sps.f_oneway(a, b).pvalue)
        p_tukey = float(sps.tukey_hsd(a, b).pvalue[0, 1])
    return p_anova, p_tukey


def _better(mean_plain: float, mean_molsp: float, higher: bool) -> str:
    if not (np.isfinite(mean_plain) and np.isfinite(mean_molsp)) or mean_plain == mean_molsp:
        return "tie"
    molsp_wins = mean_molsp > mean_plain if higher else mean_molsp < mean_plain
    return "molsp" if molsp_wins else "plain"


def _mean_std(x: np.ndarray) -> tuple[float, float]:
    if len(x) == 0:
        return float("nan"), float("nan")
    return float(np.mean(x)), float(np.std(x, ddof=1)) if len(x) > 1 else float("nan")


def compare(runs: Sequence[RunIndicators], alpha: float = 0.05) -> list[Comparison]:
    """Mean, sample std (ddof 1) and tests of each MOEA vs its MO-LSP version, per indicator.

    Rows are ordered by problem, algorithm (registry order, then others by name) and
    :data:`INDICATORS`. An algorithm with runs of one variant only gets NaN
    statistics for the missing one and no test.
    """
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    groups: dict[tuple[str, str], dict[bool, list[RunIndicators]]] = {}
    for r in runs:
        groups.setdefault((_pkey(r), r.algorithm), {False: [], True: []})[r.molsp].append(r)
    from moo.algorithms import ALGORITHMS

    order = {name: i for i, name in enumerate(ALGORITHMS)}
    rows = []
    for (problem, algorithm), by_variant in sorted(
            groups.items(), key=lambda kv: (kv[0][0], order.get(kv[0][1], len(order)), kv[0][1])):
        for name in INDICATORS:
            a = _sample([getattr(r, name) for r in by_variant[False]], "plain")
            b = _sample([getattr(r, name) for r in by_variant[True]], "molsp")
            mp, sp_ = _mean_std(a)
            mm, sm = _mean_std(b)
            p_anova, p_tukey = pairwise_test(a, b)
            rows.append(Comparison(problem=problem, algorithm=algorithm, indicator=name, n_plain=len(a),
                                   n_molsp=len(b), mean_plain=mp, std_plain=sp_, mean_molsp=mm, std_molsp=sm,
                                   p_anova=p_anova, p_tukey=p_tukey,
                                   better=_better(mp, mm, HIGHER_IS_BETTER[name]),
                                   significant=bool(np.isfinite(p_tukey) and p_tukey < alpha)))
    return rows


def _pkey(r: RunIndicators) -> str:
    return f"{r.problem}-m{r.n_obj}" if r.problem.startswith("dtlz") else r.problem


def analyse(results_dir: str | os.PathLike, alpha: float = 0.05) -> tuple[list[RunIndicators], list[Comparison]]:
    """Indicators of every run under ``results_dir`` and the comparison table."""
    from moo.experiment import load_records

    records = load_records(results_dir)
    if not records:
        raise ValueError(f"no run records (*/*/seed_*.json) under {str(results_dir)!r}")
    runs = run_indicators(records)
    return runs, compare(runs, alpha)


# ---------------------------------------------------------------------------- output

def to_csv(rows: Sequence[Comparison] | Sequence[RunIndicators], path: str | os.PathLike | None = None) -> str:
    """The rows as CSV (header from the dataclass fields); written to ``path`` if given."""
    rows = list(rows)
    buf = io.StringIO()
    if rows:
        writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(rows[0])], lineterminator="\n")
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in asdict(r).items()})
    text = buf.getvalue()
    if path is not None:
        Path(path).write_text(text, encoding="utf-8")
    return text


def _markdown_cell(mean: float, std: float, bold: bool, marks: str) -> str:
    text = "n/a" if not np.isfinite(mean) else f"{mean:.4E} ± {std:.2E}"
    return (f"**{text}**" if bold else text) + (f"^{marks}" if marks else "")


def _latex_cell(mean: float, std: float, bold: bool, marks: str) -> str:
    text = "n/a" if not np.isfinite(mean) else f"{mean:.4E} $\\pm$ {std:.2E}"
    return (rf"\textbf{{{text}}}" if bold else text) + (f"$^{{{marks}}}$" if marks else "")


def _layout(rows: Sequence[Comparison]):
    """Per (problem, algorithm): {indicator: Comparison}, plus best variant overall per indicator."""
    table: dict[tuple[str, str], dict[str, Comparison]] = {}
    for c in rows:
        table.setdefault((c.problem, c.algorithm), {})[c.indicator] = c
    best: dict[tuple[str, str], tuple[str, bool]] = {}
    for problem in {p for p, _ in table}:
        for name in INDICATORS:
            cands = [(c.mean_plain, a, False) for (p, a), cs in table.items() if p == problem and name in cs
                     for c in [cs[name]]] + \
                    [(c.mean_molsp, a, True) for (p, a), cs in table.items() if p == problem and name in cs
                     for c in [cs[name]]]
            cands = [x for x in cands if np.isfinite(x[0])]
            if cands:
                top = max(x[0] for x in cands) if HIGHER_IS_BETTER[name] else min(x[0] for x in cands)
                best[(problem, name)] = {(a, v) for value, a, v in cands if value == top}
    return table, best


def _marks(c: Comparison, molsp: bool, best: dict) -> tuple[bool, str]:
    """(bold, superscript marks) of one cell: better of the pair; a = significantly better, * = best."""
    is_better = c.better == ("molsp" if molsp else "plain")
    marks = []
    if is_better and c.significant:
        marks.append("a")
    if (c.algorithm, molsp) in best.get((c.problem, c.indicator), ()):
        marks.append("*")
    return is_better, ",".join(marks)


def _rows(table: dict, best: dict, problem: str, cell: Callable[[float, float, bool, str], str]):
    """``(algorithm, molsp, cell texts)`` of each MOEA of ``problem``: its MO-LSP row, then its plain row.

    ``cell(mean, std, bold, marks)`` writes one cell; a missing indicator is ``""``.
    """
    for (p, alg), cs in table.items():
        if p != problem:
            continue
        for molsp in (True, False):
            cells = []
            for name in INDICATORS:
                c = cs.get(name)
                if c is None:
                    cells.append("")
                    continue
                mean, std = (c.mean_molsp, c.std_molsp) if molsp else (c.mean_plain, c.std_plain)
                cells.append(cell(mean, std, *_marks(c, molsp, best)))
            yield alg, molsp, cells


def to_markdown(rows: Sequence[Comparison]) -> str:
    """The paper's layout: per MOEA a ``/MO-LSP`` row and a plain row, five indicator columns.

    The better mean of each pair is bold; ``^a`` marks a significant
    difference (Tukey, 95 %) in its favour, ``^*`` the best value over the table
    (every cell sharing it, on ties).
    """
    table, best = _layout(rows)
    lines = []
    for problem in dict.fromkeys(p for p, _ in table):
        lines += [f"**{problem}**", "",
                  "| MOEA | " + " | ".join(_LABELS[n] for n in INDICATORS) + " |",
                  "|---|" + "---|" * len(INDICATORS)]
        for alg, molsp, cells in _rows(table, best, problem, _markdown_cell):
            lines.append(f"| {alg}{'/MO-LSP' if molsp else ''} | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines)


def to_latex(rows: Sequence[Comparison]) -> str:
    """The same layout as :func:`to_markdown` as a LaTeX ``tabular`` (one per problem)."""
    table, best = _layout(rows)
    out = []
    for problem in dict.fromkeys(p for p, _ in table):
        out += [f"% {problem}", r"\begin{tabular}{l" + "c" * len(INDICATORS) + "}", r"\hline",
                "MOEA & " + " & ".join(_LABELS[n] for n in INDICATORS) + r" \\", r"\hline"]
        for alg, molsp, cells in _rows(table, best, problem, _latex_cell):
            name = alg.replace("_", r"\_") + ("/MO-LSP" if molsp else "")
            out.append(f"{name} & " + " & ".join(cells) + r" \\")
        out += [r"\hline", r"\end{tabular}", ""]
    return "\n".join(out)
