"""Indicators per run and the statistics: the paper's ANOVA + Tukey HSD, Wilcoxon-Holm, Friedman-Nemenyi.

Pipeline (``python -m moo stats DIR``)::

    records = load_records(DIR)              # moo.store: one dict per run
    runs    = run_indicators(records)        # six indicators per run (RunIndicators)
    table   = compare(runs)                  # one Comparison per (problem, algorithm, indicator)
    to_markdown(table) / to_csv(...) / to_latex(...)
    ranks   = friedman(runs)                 # one FriedmanResult per (problem, indicator)
    ranks_to_markdown(ranks) / ranks_to_csv(...) / ranks_to_latex(...)

Indicators (:mod:`moo.indicators`) on each run's final non-dominated set ``F``:

* IGD, IGD+ and Spread need a reference set ``P*``. For the control-design MOPs
  (``generic``, ``applied``) the true front is unknown; ``P*`` is the
  non-dominated union of the final sets of *all* runs recorded for the problem
  (every algorithm, both variants, every seed), as PAPER_NOTES.md asks. It
  therefore depends on what the directory holds: adding runs can change every
  IGD (and IGD+). For ZDT1-6 and DTLZ1-7 ``P*`` is a dense sample of the true Pareto front
  from its closed form (:func:`true_front`).
* SP (Schott's spacing), HV (reference point ``problem.hv_ref_point``, the
  one stored in the record) and PD (pure diversity, greedy computation).

The first five are the paper's (its column order, :data:`INDICATORS`); IGD+
(Ishibuchi et al. 2015, the Pareto-compliant IGD) is ours, after them. The
paper-layout tables of ``paper_repro/moea_tables.py`` keep the paper's five:
:func:`to_markdown` and :func:`to_latex` show the indicators of the rows
they are given.

A run whose final set has fewer than two points has SP and Spread undefined
(NaN); a run with an empty set (no feasible point) has HV 0 and the others NaN.
NaNs are left out of means and tests, and counted (``n_plain``, ``n_molsp``).

Statistics, as the paper's Section 4.4: for each MOEA and indicator, a one-way
ANOVA (:func:`scipy.stats.f_oneway`) and Tukey's HSD at 95 %
(:func:`scipy.stats.tukey_hsd`) between the runs of the MOEA and those of its
MO-LSP version. With two groups both p-values equal that of the two-sided
pooled-variance t-test; both are reported. ``better`` is the variant with the
better mean (lower IGD, SP, Spread, IGD+; higher HV, PD; note that the paper's
tables bold the *larger* SP as the better one); ``significant`` is
``p_tukey < alpha``. If both groups are constant the tests are undefined: p is
1 when the two constants are equal and 0 otherwise.

Nonparametric statistics, as the EMO community reports them:

* **Wilcoxon rank-sum** (Mann-Whitney U, two-sided,
  :func:`scipy.stats.mannwhitneyu`; exact for small samples without ties,
  the normal approximation with tie correction otherwise) between each MOEA
  and its MO-LSP version, with **Holm's** step-down correction (:func:`holm`)
  over the family of the MOEAs compared on one problem and indicator (one
  column of the table): ``p_wilcoxon_holm``, ``significant_wilcoxon``.
* **Friedman** test (:func:`scipy.stats.friedmanchisquare`, chi-square with
  the tie correction) over all variants (every MOEA, plain and MO-LSP) on one
  problem and indicator, with the runs as blocks: run ``i`` of every variant
  shares its seed (common random numbers, :mod:`moo.experiment`), so the
  values of one seed form a block. Only seeds with a finite value for every
  variant count. Ranks are 1 for the best value of a block (ties share the
  mean rank). **Nemenyi** post-hoc: two variants differ when their mean ranks
  differ by more than the critical difference
  ``CD = q_alpha sqrt(k (k + 1) / (6 N))``, ``q_alpha`` the ``1 - alpha``
  quantile of the Studentized range for ``k`` groups and infinite degrees of
  freedom divided by ``sqrt(2)`` (:data:`scipy.stats.studentized_range`);
  :meth:`FriedmanResult.nemenyi_p` gives the pairwise p-values of the same
  test. Following Demsar, the post-hoc marks are shown only when the
  Friedman test rejects.

References
----------
J. W. Tukey (1949), "Comparing individual means in the analysis of variance",
Biometrics 5(2), 99-114; S. Holm (1979), "A simple sequentially rejective
multiple test procedure", Scand. J. Statist. 6(2), 65-70; M. Friedman (1937),
J. Amer. Statist. Assoc. 32(200), 675-701; P. Nemenyi (1963), "Distribution-free
multiple comparisons", PhD thesis, Princeton; J. Demsar (2006), "Statistical
comparisons of classifiers over multiple data sets", JMLR 7, 1-30;
Morais et al. (2022), Section 4.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import warnings
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, fields, replace

import moocore
import numpy as np
from numpy.typing import ArrayLike
from scipy import stats as sps

from moo import indicators as ind
from moo.algorithms import ALGORITHMS
from moo.store import is_import_path, problem_dir, write_text_atomic

__all__ = ["INDICATORS", "HIGHER_IS_BETTER", "LABELS", "RunIndicators", "Comparison", "FriedmanResult", "true_front",
           "reference_sets", "run_indicators", "pairwise_test", "rank_sum_test", "holm", "friedman_test",
           "nemenyi_cd", "registry_order", "compare", "friedman", "to_csv", "to_markdown", "to_latex", "ranks_to_csv",
           "ranks_to_markdown", "ranks_to_latex", "analyse"]

#: Indicator names: the paper's five in its column order, then IGD+. (A new indicator
#: is one entry here, in HIGHER_IS_BETTER and LABELS, a field of RunIndicators and
#: one line in run_indicators.)
INDICATORS: tuple[str, ...] = ("igd", "sp", "hv", "pd", "spread", "igd_plus")
#: Direction of each indicator (True: larger is better).
HIGHER_IS_BETTER: dict[str, bool] = {"igd": False, "sp": False, "hv": True, "pd": True, "spread": False,
                                     "igd_plus": False}
#: Column labels of the indicators.
LABELS: dict[str, str] = {"igd": "IGD", "sp": "SP", "hv": "HV", "pd": "PD", "spread": "Spread", "igd_plus": "IGD+"}
_LABELS = LABELS

_TRUE_FRONT_POINTS = 5000


@dataclass(frozen=True)
class RunIndicators:
    """The indicators of one run's final non-dominated set (:data:`INDICATORS`).

    One row of :func:`run_indicators` (and of :func:`moo.analyse`'s first
    result). ``igd_plus`` defaults to NaN, so that rows built with the
    paper's five values only stay valid.

    ===============  ==========================================================
    field            meaning
    ===============  ==========================================================
    ``problem``      the problem's name (or import path)
    ``n_obj``        its number of objectives
    ``algorithm``    the MOEA's registry name (or import path)
    ``molsp``        True for the MO-LSP variant
    ``seed``         the run's seed
    ``n_points``     points of the final non-dominated set
    ``igd``          inverted generational distance to ``P*`` (lower is better)
    ``sp``           Schott's spacing (lower is better; NaN below 2 points)
    ``hv``           hypervolume at the record's ``hv_ref_point`` (higher is better)
    ``pd``           pure diversity (higher is better)
    ``spread``       generalised spread to ``P*`` (lower is better; NaN below 2 points)
    ``igd_plus``     IGD+ to ``P*`` (lower is better)
    ===============  ==========================================================
    """

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
    igd_plus: float = float("nan")


@dataclass(frozen=True)
class Comparison:
    """One MOEA vs its MO-LSP version on one indicator (mean, std over runs; tests).

    One row of :func:`compare` (and of :func:`moo.analyse`'s second result);
    statistics of a variant without finite values are NaN.

    ================================  ================================================
    field                             meaning
    ================================  ================================================
    ``problem``, ``algorithm``        the problem and the MOEA compared
    ``indicator``                     a name of :data:`INDICATORS`
    ``n_plain``, ``n_molsp``          finite values of each variant (runs counted)
    ``mean_plain``, ``std_plain``     mean and sample standard deviation (ddof 1)
                                      of the plain runs
    ``mean_molsp``, ``std_molsp``     the same for the MO-LSP runs
    ``p_anova``                       one-way ANOVA p-value (:func:`scipy.stats.f_oneway`)
    ``p_tukey``                       Tukey HSD p-value (:func:`scipy.stats.tukey_hsd`)
    ``better``                        ``"molsp"``, ``"plain"`` or ``"tie"``: the better mean
    ``significant``                   ``p_tukey < alpha``
    ``p_wilcoxon``                    two-sided rank-sum p-value
                                      (:func:`scipy.stats.mannwhitneyu`)
    ``p_wilcoxon_holm``               the same, Holm-adjusted over the MOEAs of one
                                      problem and indicator
    ``significant_wilcoxon``          ``p_wilcoxon_holm < alpha``
    ``alpha``                         the significance level
    ================================  ================================================
    """

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
    significant: bool      # Tukey HSD at alpha
    p_wilcoxon: float = float("nan")          # rank-sum, two-sided
    p_wilcoxon_holm: float = float("nan")     # Holm-adjusted over the MOEAs of (problem, indicator)
    significant_wilcoxon: bool = False        # p_wilcoxon_holm < alpha
    alpha: float = 0.05


@dataclass(frozen=True)
class FriedmanResult:
    """Friedman test over the variants of one problem and indicator, with Nemenyi's critical difference.

    ``variants`` are ``name`` (plain) and ``name+molsp``; ``mean_ranks`` their
    mean ranks over the ``n_blocks`` runs (1 = best); ``statistic`` the
    tie-corrected chi-square and ``p_value`` its p; ``cd`` the Nemenyi
    critical difference at ``alpha``. NaN when fewer than two variants or two
    blocks are available.
    """

    problem: str
    indicator: str
    variants: tuple[str, ...]
    mean_ranks: tuple[float, ...]
    n_blocks: int
    statistic: float
    p_value: float
    cd: float
    alpha: float

    @property
    def rejects(self) -> bool:
        """The Friedman test rejects equal performance at ``alpha``."""
        return bool(np.isfinite(self.p_value) and self.p_value < self.alpha)

    def nemenyi_p(self) -> np.ndarray:
        """``(k, k)`` p-values of Nemenyi's test, ``p_ij < alpha`` exactly when ``|R_i - R_j| > cd``."""
        k, n = len(self.variants), self.n_blocks
        R = np.asarray(self.mean_ranks, dtype=float)
        if k < 2 or n < 2:
            return np.full((k, k), np.nan)
        q = np.abs(R[:, None] - R[None, :]) / math.sqrt(k * (k + 1) / (12.0 * n))
        p = np.ones((k, k))
        iu = np.triu_indices(k, 1)
        p[iu] = sps.studentized_range.sf(q[iu], k, np.inf)
        p.T[iu] = p[iu]
        return p

    def differs(self, a: str, b: str) -> bool:
        """Variants ``a`` and ``b`` differ by Nemenyi's test (mean ranks further apart than ``cd``)."""
        i, j = self.variants.index(a), self.variants.index(b)
        return bool(abs(self.mean_ranks[i] - self.mean_ranks[j]) > self.cd)


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
        if not is_import_path(problem) and problem.startswith(("zdt", "dtlz")):
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
    """The indicators of every run (see the module docstring for ``P*`` and NaNs)."""
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
            spread=ind.spread(F, R) if n >= 2 and len(R) else nan,
            igd_plus=ind.igd_plus(F, R) if n and len(R) else nan))
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


def rank_sum_test(plain: ArrayLike, molsp: ArrayLike) -> float:
    """Two-sided p-value of the Wilcoxon rank-sum (Mann-Whitney U) test between two samples.

    NaNs are dropped; NaN when a sample has fewer than two values; 1.0 when
    every value of both samples is the same (no ranks to compare).
    """
    a, b = _sample(plain, "plain"), _sample(molsp, "molsp")
    if len(a) < 2 or len(b) < 2:
        return float("nan")
    if np.ptp(np.concatenate([a, b])) == 0:
        return 1.0
    return float(sps.mannwhitneyu(a, b, alternative="two-sided").pvalue)


def holm(p_values: ArrayLike) -> np.ndarray:
    """Holm's step-down adjusted p-values (NaN entries stay NaN and do not count in the family).

    With the ``m`` finite p-values sorted, ``p_(1) <= ... <= p_(m)``, the
    adjusted ones are ``max_{j <= i} min(1, (m - j + 1) p_(j))``; rejecting
    those below ``alpha`` is Holm's procedure at family-wise level ``alpha``.
    """
    p = np.asarray(p_values, dtype=float)
    if p.ndim != 1:
        raise ValueError(f"p_values must be 1-D, got shape {p.shape}")
    out = np.full_like(p, np.nan)
    ok = np.flatnonzero(np.isfinite(p))
    if np.any((p[ok] < 0) | (p[ok] > 1)):
        raise ValueError("p_values must lie in [0, 1]")
    order = ok[np.argsort(p[ok], kind="stable")]
    m = len(order)
    out[order] = np.minimum(1.0, np.maximum.accumulate((m - np.arange(m)) * p[order]))
    return out


def nemenyi_cd(k: int, n_blocks: int, alpha: float = 0.05) -> float:
    """Nemenyi's critical difference ``q_alpha sqrt(k (k + 1) / (6 N))`` for ``k`` groups and ``N`` blocks."""
    if k < 2 or n_blocks < 1:
        return float("nan")
    q_alpha = sps.studentized_range.ppf(1.0 - alpha, k, np.inf) / math.sqrt(2.0)
    return float(q_alpha * math.sqrt(k * (k + 1) / (6.0 * n_blocks)))


def friedman_test(values: ArrayLike, *, higher_is_better: bool = False, alpha: float = 0.05
                  ) -> tuple[np.ndarray, float, float, float]:
    """Friedman test of a ``(N blocks, k treatments)`` table; returns ``(mean_ranks, chi2, p, cd)``.

    Ranks within each block: 1 for the best value (the smallest, or the
    largest when ``higher_is_better``), ties sharing the mean rank. ``chi2``
    and ``p`` come from :func:`scipy.stats.friedmanchisquare` (tie-corrected);
    ``cd`` is :func:`nemenyi_cd`. Needs ``N >= 2``, ``k >= 2`` and finite values;
    if every block is constant the test is undefined: ``chi2 = 0``, ``p = 1``.
    """
    X = np.asarray(values, dtype=float)
    if X.ndim != 2 or X.shape[0] < 2 or X.shape[1] < 2:
        raise ValueError(f"values must be a (blocks, treatments) table with at least 2 of each, got shape {X.shape}")
    if not np.all(np.isfinite(X)):
        raise ValueError("values must be finite (drop blocks with NaN first)")
    ranks = sps.rankdata(-X if higher_is_better else X, axis=1)
    n, k = X.shape
    cd = nemenyi_cd(k, n, alpha)
    if np.all(np.ptp(X, axis=1) == 0):
        return ranks.mean(axis=0), 0.0, 1.0, cd
    if k == 2:      # scipy needs three treatments; with two, the tie-corrected statistic directly
        chi2 = float(12.0 / (n * k * (k + 1)) * np.sum(ranks.sum(axis=0) ** 2) - 3.0 * n * (k + 1))
        ties = sum(np.sum(c ** 3 - c) for row in X for c in [np.unique(row, return_counts=True)[1]])
        chi2 /= 1.0 - ties / (n * k * (k * k - 1))
        return ranks.mean(axis=0), chi2, float(sps.chi2.sf(chi2, k - 1)), cd
    res = sps.friedmanchisquare(*X.T)
    return ranks.mean(axis=0), float(res.statistic), float(res.pvalue), cd


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
    rows = []
    for (problem, algorithm), by_variant in sorted(groups.items(),
                                                   key=lambda kv: (kv[0][0], *registry_order(kv[0][1]))):
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
                                   significant=bool(np.isfinite(p_tukey) and p_tukey < alpha),
                                   p_wilcoxon=rank_sum_test(a, b), alpha=alpha))
    families: dict[tuple[str, str], list[int]] = defaultdict(list)
    for i, c in enumerate(rows):
        families[(c.problem, c.indicator)].append(i)
    for members in families.values():
        adjusted = holm([rows[i].p_wilcoxon for i in members])
        for i, p in zip(members, adjusted, strict=True):
            rows[i] = replace(rows[i], p_wilcoxon_holm=float(p), significant_wilcoxon=bool(p < alpha))
    return rows


def _variant(algorithm: str, molsp: bool) -> str:
    return f"{algorithm}+molsp" if molsp else algorithm


def friedman(runs: Sequence[RunIndicators], alpha: float = 0.05) -> list[FriedmanResult]:
    """Friedman test and Nemenyi's CD over all variants, per problem and indicator (see the module docstring).

    Variants are ordered as the tables' rows (registry order; for each MOEA
    the MO-LSP version first). Blocks are the seeds run by every variant
    with a finite value of the indicator.
    """
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    by_problem: dict[str, dict[str, dict[int, RunIndicators]]] = defaultdict(lambda: defaultdict(dict))
    for r in runs:
        by_problem[_pkey(r)][_variant(r.algorithm, r.molsp)][r.seed] = r
    out = []
    for problem in sorted(by_problem):
        cells = by_problem[problem]
        algs = sorted({v.removesuffix("+molsp") for v in cells}, key=registry_order)
        variants = tuple(v for a in algs for v in (_variant(a, True), a) if v in cells)
        for name in INDICATORS:
            seeds = sorted(set.intersection(*(set(cells[v]) for v in variants)))
            table = np.array([[getattr(cells[v][s], name) for v in variants] for s in seeds]).reshape(-1, len(variants))
            table = table[np.all(np.isfinite(table), axis=1)]
            if len(variants) < 2 or len(table) < 2:
                nan = float("nan")
                out.append(FriedmanResult(problem, name, variants, (nan,) * len(variants), len(table), nan, nan,
                                          nan, alpha))
                continue
            ranks, chi2, p, cd = friedman_test(table, higher_is_better=HIGHER_IS_BETTER[name], alpha=alpha)
            out.append(FriedmanResult(problem, name, variants, tuple(float(x) for x in ranks), len(table), chi2,
                                      p, cd, alpha))
    return out


def _pkey(r: RunIndicators) -> str:
    return problem_dir(r.problem, r.n_obj)


def registry_order(algorithm: str) -> tuple[int, str]:
    """Sort key of an algorithm name: its place in :data:`moo.algorithms.ALGORITHMS`, others after, by name."""
    names = list(ALGORITHMS)
    return (names.index(algorithm) if algorithm in ALGORITHMS else len(names), algorithm)


def analyse(results_dir: str | os.PathLike, alpha: float = 0.05) -> tuple[list[RunIndicators], list[Comparison]]:
    r"""Indicators of every run under ``results_dir`` and the comparison table.

    The pipeline of ``python -m moo stats`` (module docstring):
    :func:`~moo.experiment.load_records`, :func:`run_indicators`, :func:`compare`.

    Parameters
    ----------
    results_dir : path-like
        A results directory of :func:`moo.run_experiment`.
    alpha : float
        Significance level of the tests, in (0, 1).

    Returns
    -------
    runs : list of RunIndicators
        The indicators (IGD, SP, HV, PD, Spread, IGD+) of each run's final set.
    comparisons : list of Comparison
        Per problem, MOEA and indicator: mean and standard deviation of each
        variant, ANOVA and Tukey HSD p-values, the Wilcoxon rank-sum p-value
        with Holm's correction, the better variant.

    Raises
    ------
    ValueError
        No run records under ``results_dir``, ``alpha`` outside (0, 1).

    See Also
    --------
    friedman : the Friedman test and Nemenyi's critical difference over all variants.
    to_markdown, to_csv, to_latex : the comparison table as text.

    Notes
    -----
    For each MOEA and indicator, the runs :math:`a` of the plain variant and
    :math:`b` of the MO-LSP variant are compared by a one-way ANOVA [1]_; with
    two groups its F statistic is the square of the pooled-variance t statistic

    .. math::

        t = \frac{\bar a - \bar b}{s_p \sqrt{1/n_a + 1/n_b}}, \qquad
        s_p^2 = \frac{(n_a - 1) s_a^2 + (n_b - 1) s_b^2}{n_a + n_b - 2},

    so the two p-values are equal; Tukey's HSD [2]_ gives the same for two
    groups too.

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Section 4.4.
    .. [2] J. W. Tukey, "Comparing individual means in the analysis of
       variance", Biometrics 5(2), 99-114, 1949.

    Examples
    --------
    The ANOVA p-value of the hypervolumes equals that of the t-test of
    :func:`scipy.stats.ttest_ind`:

    >>> import tempfile
    >>> import numpy as np
    >>> from scipy.stats import ttest_ind
    >>> import moo
    >>> with tempfile.TemporaryDirectory() as out:
    ...     _ = moo.run_experiment("dtlz2", "nsga2", n_obj=2, runs=3, evals=200, pop_size=20, out=out)
    ...     runs, table = moo.analyse(out)
    >>> hv = next(c for c in table if c.indicator == "hv")
    >>> plain = [r.hv for r in runs if not r.molsp]
    >>> molsp = [r.hv for r in runs if r.molsp]
    >>> bool(np.isclose(hv.p_anova, ttest_ind(plain, molsp).pvalue))
    True
    """
    from moo.experiment import load_records

    records = load_records(results_dir)
    if not records:
        raise ValueError(f"no run records (*/*/seed_*.json) under {str(results_dir)!r}")
    runs = run_indicators(records)
    return runs, compare(runs, alpha)


# ---------------------------------------------------------------------------- output

def to_csv(rows: Sequence[Comparison] | Sequence[RunIndicators], path: str | os.PathLike | None = None) -> str:
    """The rows as CSV (header from the dataclass fields); written to ``path`` if given."""
    items: list[Comparison | RunIndicators] = list(rows)
    buf = io.StringIO()
    if items:
        writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(items[0])], lineterminator="\n")
        writer.writeheader()
        for r in items:
            writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in asdict(r).items()})
    text = buf.getvalue()
    if path is not None:
        write_text_atomic(path, text)
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
    best: dict[tuple[str, str], set[tuple[str, bool]]] = {}   # (problem, indicator) -> {(algorithm, molsp)}
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
    """(bold, superscript marks) of one cell.

    Bold: better of the pair; a = significantly better (Tukey), w = significantly better
    (Wilcoxon-Holm), * = best.
    """
    is_better = c.better == ("molsp" if molsp else "plain")
    marks = []
    if is_better and c.significant:
        marks.append("a")
    if is_better and c.significant_wilcoxon:
        marks.append("w")
    if (c.algorithm, molsp) in best.get((c.problem, c.indicator), ()):
        marks.append("*")
    return is_better, ",".join(marks)


def _columns(items: Iterable[Comparison] | Iterable[FriedmanResult]) -> tuple[str, ...]:
    """The indicators ``items`` are about, in the order of :data:`INDICATORS`: a table's columns."""
    present = {x.indicator for x in items}
    return tuple(n for n in INDICATORS if n in present)


def _rows(table: dict, best: dict, problem: str, columns: Sequence[str],
          cell: Callable[[float, float, bool, str], str]):
    """``(algorithm, molsp, cell texts)`` of each MOEA of ``problem``: its MO-LSP row, then its plain row.

    ``cell(mean, std, bold, marks)`` writes one cell; a missing indicator is ``""``.
    """
    for (p, alg), cs in table.items():
        if p != problem:
            continue
        for molsp in (True, False):
            cells = []
            for name in columns:
                c = cs.get(name)
                if c is None:
                    cells.append("")
                    continue
                mean, std = (c.mean_molsp, c.std_molsp) if molsp else (c.mean_plain, c.std_plain)
                cells.append(cell(mean, std, *_marks(c, molsp, best)))
            yield alg, molsp, cells


def _legend(rows: Sequence[Comparison], columns: Sequence[str]) -> str:
    alpha = rows[0].alpha if rows else 0.05
    level = f"{100 * (1 - alpha):g} %"
    directions = "; ".join(f"{word} {', '.join(LABELS[n] for n in columns if HIGHER_IS_BETTER[n] is higher)}"
                           for word, higher in (("lower", False), ("higher", True))
                           if any(HIGHER_IS_BETTER[n] is higher for n in columns))
    return (f"Mean ± standard deviation over the runs (n/a: no finite value). Bold: the better mean of the "
            f"pair MOEA / MOEA with MO-LSP ({directions}). "
            f"^a: the difference is significant at {level} by one-way ANOVA and Tukey's HSD (the paper's test), "
            f"in favour of this row. ^w: significant at {level} by the two-sided Wilcoxon rank-sum test with "
            f"Holm's correction over the MOEAs of the column, in favour of this row. "
            f"^*: the best mean of the column.")


def to_markdown(rows: Sequence[Comparison]) -> str:
    """The paper's layout: per MOEA a ``/MO-LSP`` row and a plain row, one column per indicator.

    The columns are the indicators of ``rows`` (all of :data:`INDICATORS`
    for a :func:`compare` table; pass the rows of the paper's five for its
    layout), in that order. The better mean of each pair is bold; ``^a``
    marks a significant difference (Tukey, 95 %) in its favour, ``^w`` one by
    the Wilcoxon rank-sum test with Holm's correction, ``^*`` the best value
    over the table (every cell sharing it, on ties). A legend explaining the
    marks follows.
    """
    table, best = _layout(rows)
    columns = _columns(rows)
    lines = []
    for problem in dict.fromkeys(p for p, _ in table):
        lines += [f"**{problem}**", "",
                  "| MOEA | " + " | ".join(_LABELS[n] for n in columns) + " |",
                  "|---|" + "---|" * len(columns)]
        for alg, molsp, cells in _rows(table, best, problem, columns, _markdown_cell):
            lines.append(f"| {alg}{'/MO-LSP' if molsp else ''} | " + " | ".join(cells) + " |")
        lines.append("")
    if rows:
        lines += [_legend(rows, columns), ""]
    return "\n".join(lines)


def _latex_text(text: str) -> str:
    text = text.replace("±", r"$\pm$").replace("%", r"\%").replace("_", r"\_")
    return re.sub(r"\^([a-z*]+)", r"$^{\1}$", text)


def to_latex(rows: Sequence[Comparison]) -> str:
    """The same layout as :func:`to_markdown` as a LaTeX ``tabular`` (one per problem), legend below."""
    table, best = _layout(rows)
    columns = _columns(rows)
    out = []
    for problem in dict.fromkeys(p for p, _ in table):
        out += [f"% {problem}", r"\begin{tabular}{l" + "c" * len(columns) + "}", r"\hline",
                "MOEA & " + " & ".join(_LABELS[n] for n in columns) + r" \\", r"\hline"]
        for alg, molsp, cells in _rows(table, best, problem, columns, _latex_cell):
            name = alg.replace("_", r"\_") + ("/MO-LSP" if molsp else "")
            out.append(f"{name} & " + " & ".join(cells) + r" \\")
        out += [r"\hline", r"\end{tabular}", ""]
    if rows:
        out += [r"\par\smallskip\noindent{\footnotesize " + _latex_text(_legend(rows, columns)) + "}", ""]
    return "\n".join(out)


# ---------------------------------------------------------------------------- Friedman ranks tables

def _ranks_layout(results: Sequence[FriedmanResult]):
    """Per problem: variants in order and {indicator: FriedmanResult}."""
    table: dict[str, dict[str, FriedmanResult]] = {}
    for r in results:
        table.setdefault(r.problem, {})[r.indicator] = r
    return table


def _rank_cell(r: FriedmanResult, variant: str) -> tuple[str, bool, str]:
    """(rank text, bold, marks) of one variant: bold = best mean rank; n = worse than the best (Nemenyi)."""
    if variant not in r.variants or not np.isfinite(r.mean_ranks[r.variants.index(variant)]):
        return "n/a", False, ""
    rank = r.mean_ranks[r.variants.index(variant)]
    top = min(r.mean_ranks)
    best_variant = r.variants[r.mean_ranks.index(top)]
    marks = "n" if r.rejects and r.differs(variant, best_variant) else ""
    return f"{rank:.2f}", rank == top, marks


def _ranks_legend(results: Sequence[FriedmanResult]) -> str:
    alpha = results[0].alpha if results else 0.05
    return (f"Mean Friedman rank over the N runs of every variant (blocks: the runs sharing a seed; rank 1 is "
            f"the best value of a run, ties share the mean rank). Bold: the best mean rank of the column. "
            f"^n: worse than the best-ranked variant by Nemenyi's test at alpha = {alpha:g} (mean ranks "
            f"further apart than the critical difference CD), shown only when the Friedman test rejects "
            f"(p < {alpha:g}). Last rows: the Friedman chi-square p-value, CD and N of each column.")


def _ranks_rows(results: Sequence[FriedmanResult], columns: Sequence[str], bold, sup):
    """(problem, [(label, cells)], footer rows) for each problem, cells written with bold(text) and sup(marks)."""
    for problem, by_ind in _ranks_layout(results).items():
        variants = next(iter(by_ind.values())).variants
        def cell(r: FriedmanResult | None, v: str) -> str:
            if r is None:
                return ""
            text, is_best, marks = _rank_cell(r, v)
            return (bold(text) if is_best else text) + (sup(marks) if marks else "")

        rows = [(v.replace("+molsp", "/MO-LSP"), [cell(by_ind.get(n), v) for n in columns]) for v in variants]
        footer = [("Friedman p", [f"{by_ind[n].p_value:.3g}" if n in by_ind else "" for n in columns]),
                  ("CD", [f"{by_ind[n].cd:.3g}" if n in by_ind else "" for n in columns]),
                  ("N", [str(by_ind[n].n_blocks) if n in by_ind else "" for n in columns])]
        yield problem, rows, footer


def ranks_to_markdown(results: Sequence[FriedmanResult]) -> str:
    """Mean Friedman ranks, one row per variant and one column per indicator, per problem, legend below.

    The columns are the indicators of ``results``, in the order of :data:`INDICATORS`.
    """
    columns = _columns(results)
    lines = []
    for problem, rows, footer in _ranks_rows(results, columns, lambda t: f"**{t}**", lambda m: f"^{m}"):
        lines += [f"**{problem}: mean ranks (Friedman, Nemenyi)**", "",
                  "| variant | " + " | ".join(_LABELS[n] for n in columns) + " |",
                  "|---|" + "---|" * len(columns)]
        lines += [f"| {label} | " + " | ".join(cells) + " |" for label, cells in rows + footer]
        lines.append("")
    if results:
        lines += [_ranks_legend(results), ""]
    return "\n".join(lines)


def ranks_to_latex(results: Sequence[FriedmanResult]) -> str:
    """The table of :func:`ranks_to_markdown` as a LaTeX ``tabular`` per problem, legend below."""
    columns = _columns(results)
    out = []
    for problem, rows, footer in _ranks_rows(results, columns, lambda t: rf"\textbf{{{t}}}",
                                             lambda m: f"$^{{{m}}}$"):
        out += [f"% {problem}: mean Friedman ranks", r"\begin{tabular}{l" + "c" * len(columns) + "}",
                r"\hline", "variant & " + " & ".join(_LABELS[n] for n in columns) + r" \\", r"\hline"]
        out += [f"{label.replace('_', chr(92) + '_')} & " + " & ".join(cells) + r" \\" for label, cells in rows]
        out.append(r"\hline")
        out += [f"{label} & " + " & ".join(cells) + r" \\" for label, cells in footer]
        out += [r"\hline", r"\end{tabular}", ""]
    if results:
        out += [r"\par\smallskip\noindent{\footnotesize " + _latex_text(_ranks_legend(results)) + "}", ""]
    return "\n".join(out)


def ranks_to_csv(results: Sequence[FriedmanResult], path: str | os.PathLike | None = None) -> str:
    """One CSV row per (problem, indicator, variant).

    Columns: mean rank, Friedman statistic and p, CD, N, and whether Nemenyi's test separates
    the variant from the best-ranked one.
    """
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["problem", "indicator", "variant", "mean_rank", "n_blocks", "statistic", "p_friedman",
                     "cd", "alpha", "worse_than_best"])
    for r in results:
        for v, rank in zip(r.variants, r.mean_ranks, strict=True):
            _, _, marks = _rank_cell(r, v)
            writer.writerow([r.problem, r.indicator, v, repr(rank), r.n_blocks, repr(r.statistic),
                             repr(r.p_value), repr(r.cd), repr(r.alpha), marks == "n"])
    text = buf.getvalue()
    if path is not None:
        write_text_atomic(path, text)
    return text
