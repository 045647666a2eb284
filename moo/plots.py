"""Figures of a results directory: hypervolume over evaluations, indicator box plots, final fronts, CD diagrams.

``python -m moo plot DIR --out FIGDIR`` calls :func:`plot_results`, which
writes, per problem ``P`` (the directory names of :mod:`moo.experiment`):

* ``hv_P``: hypervolume of the non-dominated set over the evaluations, one
  panel per MOEA, plain and MO-LSP: the median over the runs and the
  inter-quartile band (as the paper's HV figures). Each run's history is a
  step function (the HV after the last generation that ended at or before
  ``e`` evaluations), read on a common grid of evaluations;
* ``boxplots_P``: box plots of each indicator of :mod:`moo.stats` per MOEA,
  plain beside MO-LSP (boxes: quartiles; whiskers: 1.5 IQR; points beyond);
* ``fronts_P`` (two objectives: one panel per MOEA) or ``fronts_P_<MOEA>``
  (three or more: a scatter matrix, ``f_i`` against ``f_j`` off the diagonal,
  histograms on it): the final non-dominated set of the run with the median
  hypervolume of each variant, over the true front (grey) for ZDT/DTLZ;
* ``cd_P_<indicator>``: the critical-difference diagram of the Friedman and
  Nemenyi test of :func:`moo.stats.friedman` (Demsar 2006, Fig. 1): the
  variants on their mean-rank axis (1 = best, left), the CD bar, and thick
  bars joining groups whose mean ranks lie within CD of each other.

Each figure is a :class:`matplotlib.figure.Figure` drawn without pyplot (so
no global backend is touched) and saved in every format asked for.

References
----------
J. Demsar (2006), "Statistical comparisons of classifiers over multiple data
sets", JMLR 7, 1-30.
"""

from __future__ import annotations

import math
import os
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from moo.stats import (
    INDICATORS,
    LABELS,
    FriedmanResult,
    RunIndicators,
    friedman,
    registry_order,
    run_indicators,
    true_front,
)
from moo.store import atomic_path, is_import_path, problem_dir

__all__ = ["FORMATS", "check_formats", "hv_history", "indicator_boxplots", "fronts", "cd_diagram", "plot_results"]

#: File formats :func:`plot_results` writes.
FORMATS: tuple[str, ...] = ("png", "pdf", "svg")
_COLOURS = {False: "tab:blue", True: "tab:orange"}
_NAMES = {False: "plain", True: "MO-LSP"}
_GRID_POINTS = 200


def check_formats(formats: str | Sequence[str]) -> tuple[str, ...]:
    """File formats from ``"png,pdf"`` or a sequence; ``ValueError`` naming an unknown one."""
    items = formats.split(",") if isinstance(formats, str) else list(formats)
    out = tuple(dict.fromkeys(str(f).strip().lower().lstrip(".") for f in items if str(f).strip()))
    bad = [f for f in out if f not in FORMATS]
    if not out or bad:
        raise ValueError(f"format must be a comma-separated list of {', '.join(FORMATS)}, got {formats!r}")
    return out


def _key(rec: dict) -> str:
    return problem_dir(rec["problem"], int(rec["n_obj"]))


def _algorithms(names) -> list[str]:
    return sorted(set(names), key=registry_order)


def _panels(n: int, width: float = 3.2, height: float = 2.6, max_cols: int = 5):
    cols = min(max_cols, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(width * cols, height * rows + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False).ravel())
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, axes[:n]


# ---------------------------------------------------------------------------- hypervolume over evaluations

def _hv_on_grid(records: Sequence[dict], grid: np.ndarray) -> np.ndarray:
    """``(runs, len(grid))``: each run's HV after the last generation ending at or before each grid point."""
    out = np.full((len(records), len(grid)), np.nan)
    for i, rec in enumerate(records):
        evals = np.asarray(rec["hv_history"]["evaluations"], dtype=float)
        hv = np.asarray(rec["hv_history"]["hypervolume"], dtype=float)
        idx = np.searchsorted(evals, grid, side="right") - 1
        out[i, idx >= 0] = hv[idx[idx >= 0]]
    return out


def hv_history(records: Sequence[dict], title: str = "") -> Figure:
    """Median and inter-quartile band of the hypervolume over evaluations, one panel per MOEA."""
    by_alg: dict[str, dict[bool, list[dict]]] = defaultdict(lambda: {False: [], True: []})
    for rec in records:
        by_alg[rec["algorithm"]][bool(rec["molsp"])].append(rec)
    algs = _algorithms(by_alg)
    top = max(max(rec["hv_history"]["evaluations"]) for rec in records)
    grid = np.linspace(0, top, _GRID_POINTS)
    fig, axes = _panels(len(algs))
    for ax, alg in zip(axes, algs, strict=True):
        for molsp, recs in by_alg[alg].items():
            if not recs:
                continue
            H = _hv_on_grid(recs, grid)
            ok = np.sum(np.isfinite(H), axis=0) > 0
            q1, med, q3 = np.nanpercentile(H[:, ok], [25, 50, 75], axis=0)
            ax.plot(grid[ok], med, color=_COLOURS[molsp], lw=1.5, label=f"{_NAMES[molsp]} (median, {len(recs)} runs)")
            ax.fill_between(grid[ok], q1, q3, color=_COLOURS[molsp], alpha=0.25, lw=0)
        ax.set_title(alg, fontsize=10)
        ax.set_xlabel("evaluations", fontsize=8)
        ax.set_ylabel("HV", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
        ax.legend(fontsize=7, loc="lower right")
    fig.suptitle(f"{title}hypervolume over evaluations: median and inter-quartile band")
    return fig


# ---------------------------------------------------------------------------- box plots

def indicator_boxplots(runs: Sequence[RunIndicators], title: str = "") -> Figure:
    """One row per indicator; per MOEA the plain box beside the MO-LSP box."""
    algs = _algorithms(r.algorithm for r in runs)
    fig = Figure(figsize=(max(6.0, 1.0 * len(algs) + 1.5), 2.3 * len(INDICATORS) + 0.6), layout="constrained")
    axes = fig.subplots(len(INDICATORS), 1, squeeze=False)[:, 0]
    for ax, name in zip(axes, INDICATORS, strict=True):
        for molsp in (False, True):
            data = [np.array([getattr(r, name) for r in runs if r.algorithm == a and r.molsp == molsp]) for a in algs]
            data = [d[np.isfinite(d)] for d in data]
            pos = [i + (0.2 if molsp else -0.2) for i in range(len(algs))]
            keep = [i for i, d in enumerate(data) if len(d)]
            if not keep:
                continue
            box = ax.boxplot([data[i] for i in keep], positions=[pos[i] for i in keep], widths=0.35,
                             patch_artist=True, manage_ticks=False, flierprops={"markersize": 3})
            for patch in box["boxes"]:
                patch.set(facecolor=_COLOURS[molsp], alpha=0.6)
            if ax is axes[0]:
                ax.plot([], [], "s", color=_COLOURS[molsp], alpha=0.6, label=_NAMES[molsp])
        ax.set_xticks(range(len(algs)), algs, fontsize=8, rotation=20)
        ax.set_ylabel(LABELS[name])
        ax.tick_params(axis="y", labelsize=7)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=8)
    fig.suptitle(f"{title}indicators of the final sets (per MOEA: plain, MO-LSP)")
    return fig


# ---------------------------------------------------------------------------- fronts

def _median_run(recs: Sequence[dict]) -> dict | None:
    """The run with the median hypervolume (the lower middle one for an even count)."""
    if not recs:
        return None
    order = sorted(recs, key=lambda r: (r["hv"], r["seed"]))
    return order[(len(order) - 1) // 2]


def _reference(problem: str, n_obj: int) -> np.ndarray | None:
    known = not is_import_path(problem) and problem.startswith(("zdt", "dtlz"))
    return true_front(problem, n_obj) if known else None


def fronts(records: Sequence[dict], algorithm: str | None = None, title: str = "") -> Figure:
    """Final fronts of the median-HV runs, plain and MO-LSP.

    Two objectives: one panel per MOEA (``algorithm=None``). Three or more: the
    scatter matrix of ``algorithm``'s two runs.
    """
    rec0 = records[0]
    M = int(rec0["n_obj"])
    ref = _reference(rec0["problem"], M)

    def runs_of(alg):
        return {v: _median_run([r for r in records if r["algorithm"] == alg and bool(r["molsp"]) == v])
                for v in (False, True)}

    if M == 2:
        algs = _algorithms(r["algorithm"] for r in records)
        fig, axes = _panels(len(algs), width=3.0, height=2.8)
        for ax, alg in zip(axes, algs, strict=True):
            if ref is not None:
                ax.plot(ref[:, 0], ref[:, 1], ".", color="0.75", ms=1, label="true front")
            for v, rec in runs_of(alg).items():
                if rec is not None and len(rec["F"]):
                    F = np.asarray(rec["F"], dtype=float)
                    ax.plot(F[:, 0], F[:, 1], "o", ms=3, color=_COLOURS[v], alpha=0.8, mfc="none",
                            label=f"{_NAMES[v]} (seed {rec['seed']})")
            ax.set_title(alg, fontsize=10)
            ax.set_xlabel("$f_1$", fontsize=8)
            ax.set_ylabel("$f_2$", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=6)
        fig.suptitle(f"{title}final non-dominated sets of the median-HV runs")
        return fig

    if algorithm is None:
        raise ValueError("algorithm is needed for the scatter matrix of three or more objectives")
    chosen = runs_of(algorithm)
    fig = Figure(figsize=(2.0 * M + 0.8, 2.0 * M + 0.8), layout="constrained")
    axes = fig.subplots(M, M, squeeze=False)
    for i in range(M):
        for j in range(M):
            ax = axes[i, j]
            ax.tick_params(labelsize=6)
            for v, rec in chosen.items():
                if rec is None or not len(rec["F"]):
                    continue
                F = np.asarray(rec["F"], dtype=float)
                if i == j:
                    ax.hist(F[:, i], bins=15, color=_COLOURS[v], alpha=0.5)
                else:
                    ax.plot(F[:, j], F[:, i], "o", ms=2, color=_COLOURS[v], alpha=0.7, mfc="none")
            if ref is not None and i != j:
                ax.plot(ref[:, j], ref[:, i], ".", color="0.8", ms=0.5, zorder=0)
            if i == M - 1:
                ax.set_xlabel(f"$f_{j + 1}$", fontsize=8)
            if j == 0:
                ax.set_ylabel(f"$f_{i + 1}$", fontsize=8)
    for v, rec in chosen.items():
        if rec is not None:
            axes[0, -1].plot([], [], "o", color=_COLOURS[v], mfc="none", label=f"{_NAMES[v]} (seed {rec['seed']})")
    axes[0, -1].legend(fontsize=6, loc="upper right")
    fig.suptitle(f"{title}{algorithm}: final non-dominated sets of the median-HV runs")
    return fig


# ---------------------------------------------------------------------------- critical-difference diagram

def _cliques(ranks: np.ndarray, cd: float) -> list[tuple[int, int]]:
    """Maximal runs ``[i, j]`` (indices into the sorted ranks) whose ranks lie within ``cd``; length >= 2."""
    k = len(ranks)
    spans: list[tuple[int, int]] = []
    for i in range(k):
        j = i
        while j + 1 < k and ranks[j + 1] - ranks[i] <= cd:
            j += 1
        if j > i and not (spans and spans[-1][1] >= j):
            spans.append((i, j))
    return spans


def cd_diagram(result: FriedmanResult) -> Figure:
    """Demsar's critical-difference diagram of one :class:`~moo.stats.FriedmanResult`."""
    ranks = np.asarray(result.mean_ranks, dtype=float)
    if len(ranks) < 2 or not np.all(np.isfinite(ranks)):
        raise ValueError(f"no mean ranks to draw for {result.problem}/{result.indicator}")
    order = np.argsort(ranks, kind="stable")
    names = [result.variants[i].replace("+molsp", "/MO-LSP") for i in order]
    r = ranks[order]
    k = len(r)
    half = math.ceil(k / 2)
    step = 0.32
    height = 1.1 + step * max(half, k - half)
    fig = Figure(figsize=(8.0, height), layout="constrained")
    ax = fig.subplots()
    ax.set_axis_off()
    ax.set_xlim(1 - 0.45 * (k - 1) - 0.1, k + 0.45 * (k - 1) + 0.1)
    bottom = -(0.6 + step * max(half, k - half))
    ax.set_ylim(bottom, 0.9)
    ax.plot([1, k], [0, 0], color="k", lw=1)
    for t in range(1, k + 1):
        ax.plot([t, t], [0, 0.08], color="k", lw=1)
        ax.text(t, 0.12, str(t), ha="center", va="bottom", fontsize=8)
    if np.isfinite(result.cd):
        ax.plot([1, 1 + result.cd], [0.55, 0.55], color="k", lw=2)
        for x in (1, 1 + result.cd):
            ax.plot([x, x], [0.5, 0.6], color="k", lw=1)
        ax.text(1 + result.cd / 2, 0.62, f"CD = {result.cd:.2f}", ha="center", va="bottom", fontsize=8)
    left_x, right_x = 1 - 0.4 * (k - 1), k + 0.4 * (k - 1)
    for idx in range(k):
        if idx < half:
            y, x_end, align = -(0.5 + step * idx), left_x, "right"
        else:
            y, x_end, align = -(0.5 + step * (k - 1 - idx)), right_x, "left"
        ax.plot([r[idx], r[idx], x_end], [0, y, y], color="k", lw=0.8)
        label = f"{names[idx]} ({r[idx]:.2f})"
        ax.text(x_end + (-0.05 if align == "right" else 0.05), y, label, ha=align, va="center", fontsize=8)
    for n, (i, j) in enumerate(_cliques(r, result.cd)):
        y = -0.15 - 0.12 * n
        ax.plot([r[i] - 0.03, r[j] + 0.03], [y, y], color="k", lw=3, solid_capstyle="round")
    verdict = "rejects" if result.rejects else "does not reject"
    fig.suptitle(f"{result.problem}, {LABELS.get(result.indicator, result.indicator)}: mean ranks over "
                 f"{result.n_blocks} runs; Friedman p = {result.p_value:.3g} ({verdict} at {result.alpha:g}); "
                 f"bars: within CD (Nemenyi)", fontsize=9)
    return fig


# ---------------------------------------------------------------------------- everything

def _save(fig: Figure, stem: Path, formats: Sequence[str]) -> list[Path]:
    paths = []
    for fmt in formats:
        path = stem.with_name(f"{stem.name}.{fmt}")
        with atomic_path(path) as tmp:           # a full disk leaves no truncated figure
            fig.savefig(tmp, format=fmt, dpi=150)
        paths.append(path)
    return paths


def plot_results(records: Sequence[dict], out: str | os.PathLike, *, formats: str | Sequence[str] = ("png", "pdf"),
                 alpha: float = 0.05) -> list[Path]:
    """Every figure of the module docstring for the records of a results directory; returns the files."""
    formats = check_formats(formats)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    by_problem: dict[str, list[dict]] = defaultdict(list)
    for rec in records:
        by_problem[_key(rec)].append(rec)
    runs = run_indicators(records)
    ranks = friedman(runs, alpha=alpha)
    paths: list[Path] = []
    for key, recs in sorted(by_problem.items()):
        title = f"{key}: "
        paths += _save(hv_history(recs, title), out / f"hv_{key}", formats)
        paths += _save(indicator_boxplots([r for r in runs if problem_dir(r.problem, r.n_obj) == key], title),
                       out / f"boxplots_{key}", formats)
        if int(recs[0]["n_obj"]) == 2:
            paths += _save(fronts(recs, title=title), out / f"fronts_{key}", formats)
        else:
            for alg in _algorithms(r["algorithm"] for r in recs):
                paths += _save(fronts(recs, alg, title=title), out / f"fronts_{key}_{alg}", formats)
        for res in ranks:
            if res.problem == key and len(res.variants) >= 2 and np.all(np.isfinite(res.mean_ranks)):
                paths += _save(cd_diagram(res), out / f"cd_{key}_{res.indicator}", formats)
    return paths
