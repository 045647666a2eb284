"""Reproduce the paper's MOEA tables (Section 4, Tables result_1 and result_2): MOEA vs MOEA/MO-LSP.

    python paper_repro/moea_tables.py --problem generic|applied [--runs 5] [--evals 2000]
                                      [--algorithms all|a,b,...] [--out DIR] [--workers 2] [--seed 0]
                                      [--max-leaders K] [--executor process|dask] [--scheduler ADDRESS]
                                      [--setup ours|authors] [--no-plots]

Runs the grid problem x algorithms x {plain, MO-LSP} x runs with
:func:`moo.experiment.run_experiment` into ``DIR`` (default
``out/moea_<problem>``, or ``out/moea_applied_<setup>`` with ``--setup``,
whose files are then named ``moea_applied_<setup>*``; resumable: rerunning with the same arguments skips
finished runs, raising ``--runs`` adds runs), computes the indicators and
the ANOVA/Tukey comparisons (:mod:`moo.stats`), and prints

1. our table in the paper's layout (the paper's five indicators; per MOEA a
   ``/MO-LSP`` row and a plain row; mean ± std; the better mean of a pair in
   bold, ``^a`` a significant difference in its favour (Tukey HSD, 95 %),
   ``^*`` the best over the table);
2. a cell-by-cell comparison with the paper's published table
   (``paper_moea_values.py``), for ``generic`` and ``applied``;
3. the mean Friedman ranks of all 20 variants per indicator (IGD+ too, as
   the library's statistics), with the Nemenyi critical difference
   (:func:`moo.stats.friedman`);

and draws the figures of :mod:`moo.plots` (hypervolume over evaluations,
box plots, fronts, critical-difference diagrams) into ``DIR/figures``.

What is compared. Our objective scales and HV reference points differ from
the paper's (its regulation errors and PlatEMO set-up are not fully
specified), so HV, IGD, PD magnitudes are not comparable. Compared per cell
(MOEA x indicator) are the *direction of the MO-LSP effect*, the sign of
``mean(MO-LSP) - mean(plain)``, and whether the difference is significant
(the paper's "a" on either row; ours Tukey p < 0.05). Comparing signs, not
"better" labels, sidesteps the paper's reading of SP (it bolds the larger SP,
see ``paper_moea_values.py``). The script counts the cells whose
direction agrees, and those whose direction and significance both agree.

Defaults (5 runs, 2000 evaluations, all ten MOEAs, 2 workers) take a few
minutes on 2 cores (``generic`` about 1 min, ``applied`` about 3-5 min);
``--runs 50 --evals 10000`` is the paper's setting. Files written to ``DIR``:
``moea_<problem>.md`` (both tables), ``moea_<problem>.tex``,
``moea_<problem>_stats.csv`` (one row per MOEA x indicator, IGD+ included),
``moea_<problem>_runs.csv`` (indicators per run), ``moea_<problem>_ranks.csv``
(Friedman ranks), ``moea_<problem>_vs_paper.csv`` and ``figures/*.png|pdf``.
The paper's experiment on a cluster: ``--executor dask --scheduler
tcp://HOST:8786`` (see the README's "Experiments and statistics").
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from paper_moea_values import INDICATORS, PAPER_LABELS, PAPER_MOEA, paper_cell

from moo.algorithms import ALGORITHMS
from moo.executors import open_executor
from moo.experiment import run_experiment
from moo.plots import plot_results
from moo.stats import (
    LABELS,
    Comparison,
    analyse,
    friedman,
    ranks_to_csv,
    ranks_to_latex,
    ranks_to_markdown,
    to_csv,
    to_latex,
    to_markdown,
)
from moo.store import load_records
from moo.tables import markdown_table, write_csv
from robustctl.models.morais2022 import SETUPS


@dataclass(frozen=True)
class CellAgreement:
    """Paper vs ours for one MOEA and indicator: sign of the MO-LSP effect and significance."""

    algorithm: str
    indicator: str
    paper_sign: int          # sign of mean(MO-LSP) - mean(plain) in the paper
    paper_significant: bool
    our_sign: int
    our_significant: bool
    our_p_tukey: float

    @property
    def direction_agrees(self) -> bool:
        return self.paper_sign == self.our_sign

    @property
    def full_agreement(self) -> bool:
        return self.direction_agrees and self.paper_significant == self.our_significant


def agreements(problem: str, table: Sequence[Comparison]) -> list[CellAgreement]:
    """One :class:`CellAgreement` per (MOEA, indicator) of ``table`` that the paper also reports."""
    if problem not in PAPER_MOEA:
        return []
    out = []
    for c in table:
        if (c.algorithm, True) not in PAPER_MOEA[problem] or c.indicator not in INDICATORS:
            continue
        molsp, plain = (paper_cell(problem, c.algorithm, v, c.indicator) for v in (True, False))
        ours = c.mean_molsp - c.mean_plain
        out.append(CellAgreement(
            algorithm=c.algorithm, indicator=c.indicator,
            paper_sign=int(np.sign(molsp.mean - plain.mean)),
            paper_significant="a" in molsp.marks or "a" in plain.marks,
            our_sign=int(np.sign(ours)) if np.isfinite(ours) else 0,
            our_significant=c.significant, our_p_tukey=c.p_tukey))
    return out


def _effect(sign: int, significant: bool) -> str:
    arrow = {1: "up", -1: "down", 0: "="}[sign]
    return f"{arrow} ({'sig' if significant else 'ns'})"


def comparison_markdown(problem: str, cells: Sequence[CellAgreement]) -> str:
    """Per MOEA and indicator: the paper's MO-LSP effect, ours, and whether they agree."""
    if not cells:
        return ""
    algs = list(dict.fromkeys(c.algorithm for c in cells))
    by = {(c.algorithm, c.indicator): c for c in cells}
    rows = []
    for alg in algs:
        cells_txt = []
        for name in INDICATORS:
            c = by.get((alg, name))
            if c is None:
                cells_txt.append("")
                continue
            tag = "=" if c.full_agreement else ("~" if c.direction_agrees else "x")
            cells_txt.append(f"paper {_effect(c.paper_sign, c.paper_significant)} / "
                             f"ours {_effect(c.our_sign, c.our_significant)} {tag}")
        rows.append([PAPER_LABELS.get(alg, alg), *cells_txt])
    lines = [(f"MO-LSP effect, paper vs ours ({problem}): sign of mean(MO-LSP) - mean(plain), "
              "sig = significant at 95 % (paper: mark 'a'; ours: Tukey p < 0.05); '=' agree, 'x' differ"), "",
             markdown_table(["MOEA", *(LABELS[n] for n in INDICATORS)], rows)]
    n = len(cells)
    nd = sum(c.direction_agrees for c in cells)
    nf = sum(c.full_agreement for c in cells)
    lines += ["", "('=': direction and significance agree; '~': direction only; 'x': direction differs)", "",
              f"Direction of the MO-LSP effect agrees in {nd}/{n} cells; direction and significance in {nf}/{n}."]
    per = []
    for name in INDICATORS:
        sub = [c for c in cells if c.indicator == name]
        if sub:
            per.append(f"{LABELS[name]} {sum(c.direction_agrees for c in sub)}/{len(sub)}"
                       f" ({sum(c.full_agreement for c in sub)}/{len(sub)})")
    lines.append("Per indicator, direction (and full) agreement: " + ", ".join(per) + ".")
    return "\n".join(lines) + "\n"


def _agreement_csv(cells: Sequence[CellAgreement], path: Path) -> None:
    write_csv(["algorithm", "indicator", "paper_sign", "paper_significant", "our_sign", "our_significant",
               "our_p_tukey", "direction_agrees", "full_agreement"],
              ([c.algorithm, c.indicator, c.paper_sign, c.paper_significant, c.our_sign, c.our_significant,
                repr(c.our_p_tukey), c.direction_agrees, c.full_agreement] for c in cells), path)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description="The paper's MOEA vs MOEA/MO-LSP tables (Section 4).")
    ap.add_argument("--problem", choices=("generic", "applied"), required=True)
    ap.add_argument("--runs", type=int, default=5, help="runs per MOEA and variant (default 5; paper 50)")
    ap.add_argument("--evals", type=int, default=2000, help="evaluations per run (default 2000; paper 10000)")
    ap.add_argument("--algorithms", default="all", help="'all' (default) or a comma-separated list")
    ap.add_argument("--out", type=Path, default=None, help="results directory (default out/moea_<problem>)")
    ap.add_argument("--workers", type=int, default=None,
                    help="processes of the local pool or local Dask cluster (default 2 without --scheduler)")
    ap.add_argument("--seed", type=int, default=0, help="base seed (default 0)")
    ap.add_argument("--max-leaders", type=int, default=None, help="MO-LSP cap (default: none, the paper's)")
    ap.add_argument("--molsp-max-leaders", type=int, dest="max_leaders", help=argparse.SUPPRESS)  # old name
    ap.add_argument("--executor", choices=("process", "dask"), default="process",
                    help="'process' (default) or 'dask' (a local cluster, or the one at --scheduler)")
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler (with --executor dask)")
    ap.add_argument("--setup", choices=tuple(SETUPS), default=None,
                    help="applied MOP set-up (robustctl.models.morais2022.SETUPS; default: the MOP's own)")
    ap.add_argument("--no-plots", action="store_true", help="do not draw the figures")
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    ap = _parser()
    args = ap.parse_args(argv)
    if args.runs < 2:
        ap.error(f"--runs must be >= 2, got {args.runs}")
    names = [a.strip().lower() for a in args.algorithms.split(",")] if args.algorithms != "all" else list(ALGORITHMS)
    unknown = [a for a in names if a not in ALGORITHMS]
    if unknown:
        ap.error(f"unknown algorithm(s) {', '.join(unknown)}; valid: {', '.join(ALGORITHMS)}")
    if args.setup is not None and args.problem != "applied":
        ap.error("--setup applies to --problem applied only")
    stem = f"moea_{args.problem}" + ("" if args.setup is None else f"_{args.setup}")
    out = args.out if args.out is not None else Path("out") / stem
    workers = 2 if args.workers is None and args.scheduler is None else args.workers
    try:
        with open_executor(args.executor, workers=workers, scheduler=args.scheduler) as ex:
            report = run_experiment(args.problem, names, runs=args.runs, evals=args.evals, out=out,
                                    base_seed=args.seed, max_leaders=args.max_leaders, executor=ex,
                                    setup=args.setup)
    except (ValueError, TypeError) as exc:
        ap.error(str(exc).splitlines()[0])
    print(f"{report!r}\n")
    runs, table = analyse(out)
    keep = set(names)
    runs = [r for r in runs if r.problem == args.problem and r.algorithm in keep]
    table = [c for c in table if c.problem == args.problem and c.algorithm in keep]
    paper_table = [c for c in table if c.indicator in INDICATORS]      # the paper's layout: its five indicators
    ours = to_markdown(paper_table)
    cells = agreements(args.problem, table)
    versus = comparison_markdown(args.problem, cells)
    print(f"Our results ({args.runs} runs x {args.evals} evaluations; IGD/Spread reference set: the "
          "non-dominated union of all runs in the directory):\n")
    ranks = friedman(runs)
    ranks_md = ranks_to_markdown(ranks)
    print(ours)
    print(versus)
    print(ranks_md)
    (out / f"{stem}.md").write_text(ours + "\n" + versus + "\n" + ranks_md, encoding="utf-8")
    (out / f"{stem}.tex").write_text(to_latex(paper_table) + "\n" + ranks_to_latex(ranks), encoding="utf-8")
    to_csv(table, out / f"{stem}_stats.csv")
    to_csv(runs, out / f"{stem}_runs.csv")
    ranks_to_csv(ranks, out / f"{stem}_ranks.csv")
    _agreement_csv(cells, out / f"{stem}_vs_paper.csv")
    print(f"written: {out}/{stem}.md, .tex, _stats.csv, _runs.csv, _ranks.csv, _vs_paper.csv")
    if not args.no_plots:
        records = [r for r in load_records(out) if r["problem"] == args.problem and r["algorithm"] in keep]
        figures = plot_results(records, out / "figures")
        print(f"figures: {len(figures)} files in {out / 'figures'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
