"""
An experiment grid, its statistics and its figures
==================================================

What ``python -m moo experiment``, ``stats`` and ``plot`` do, in Python and
at a tiny budget: two MOEAs, each plain and with MO-LSP, 8 independent runs
of 1500 evaluations on ZDT1; then the paper's test (one-way ANOVA + Tukey HSD),
the Wilcoxon rank-sum test with Holm's correction, the Friedman test with
Nemenyi's critical difference, and the figures. :doc:`../user_guide/experiments`
explains every step; the paper's setting is 50 runs of 10000 evaluations.
"""

# %%
# Run the grid
# ------------
# One JSON record per run under ``out/<problem>/<variant>/seed_<s>.json``
# (here a temporary directory). Run ``i`` of every variant shares its seed,
# so plain and MO-LSP start from the same population.
import tempfile
from pathlib import Path

from moo import plots, stats
from moo.experiment import run_experiment
from moo.store import load_records

tmp = tempfile.TemporaryDirectory(prefix="moo-example-")  # removed at the end
out = Path(tmp.name)
grid = dict(problem="zdt1", algorithms="nsga2,theta-dea", runs=8, evals=1500,
            out=out)


def summary(report):
    """What a grid run did, without its (temporary) directory and timing."""
    return f"{report.total} runs, {report.skipped} already done, {report.completed} run now"


print(summary(run_experiment(**grid)))
files = sorted(str(p.relative_to(out)) for p in out.glob("*/*/*.json"))
print(len(files), "records:", files[:2], "...")

# %%
# A rerun finds every record and runs nothing; a larger ``runs`` would run
# only the new seeds, and another budget is refused (the store never mixes
# settings).
print(summary(run_experiment(**grid)))
try:
    run_experiment(**{**grid, "evals": 3000})
except ValueError as exc:
    print("refused:", str(exc).replace(str(out), "out")[:110], "...")

# %%
# The paper's table and the rank-sum tests
# ----------------------------------------
# :func:`moo.stats.run_indicators` computes IGD, SP, HV, PD and Spread of
# every run (IGD and Spread against the true ZDT1 front);
# :func:`moo.stats.compare` tests each MOEA against its MO-LSP version.
# ``^a`` marks a significant difference by Tukey's HSD, ``^w`` by the
# Wilcoxon rank-sum test after Holm's correction over the MOEAs of a column.
# The tables are Markdown, as ``python -m moo stats`` prints them
# (:func:`moo.stats.to_latex` and :func:`moo.stats.to_csv` write the others).
records = load_records(out)
runs = stats.run_indicators(records)
table = stats.compare(runs)
print(stats.to_markdown(table))
print(f"{'HV, p-values':12s} {'ANOVA':>8s} {'Tukey':>8s} {'Wilcoxon':>9s} "
      f"{'Holm':>8s}")
for c in table:
    if c.indicator == "hv":
        print(f"{c.algorithm:12s} {c.p_anova:8.2g} {c.p_tukey:8.2g} "
              f"{c.p_wilcoxon:9.2g} {c.p_wilcoxon_holm:8.2g}")

# %%
# Friedman and Nemenyi over all variants
# --------------------------------------
# The runs sharing a seed form a block; the four variants are ranked within
# each block (1 = best) and compared by their mean ranks.
ranks = stats.friedman(runs)
print(stats.ranks_to_markdown(ranks))

# %%
# Figures
# -------
# ``python -m moo plot DIR --out FIGDIR`` writes every figure of
# :mod:`moo.plots` as PNG and PDF; each is also a function returning a
# :class:`matplotlib.figure.Figure`. The hypervolume over the evaluations,
# median and inter-quartile band of the 8 runs:
fig_hv = plots.hv_history(records, title="ZDT1: ")       # title: a prefix

# %%
# The indicators' box plots, plain beside MO-LSP:
fig_box = plots.indicator_boxplots(runs, title="ZDT1: ")

# %%
# The critical-difference diagram of HV (Demsar 2006): the variants on their
# mean-rank axis, the CD bar, and thick bars joining variants that Nemenyi's
# test does not separate.
fig_cd = plots.cd_diagram(next(r for r in ranks if r.indicator == "hv"))
tmp.cleanup()
