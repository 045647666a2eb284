"""
MO-LSP vs plain NSGA-II on ZDT1
===============================

MO-LSP (Morais et al. 2022, Section 3.2) is a local search added to a host
MOEA: every generation it mutates the individuals of the first two
non-dominated fronts towards the *leader*, the one with the largest box to a
reference point, and lets the host's survival choose among population and
mutants. The mutants cost evaluations, so a fair comparison plots the
hypervolume against the *evaluations used*.

:func:`moo.runner.run` runs a registered MOEA to an evaluation budget and
records the hypervolume after every generation. Three variants, three seeds
each: NSGA-II, NSGA-II/MO-LSP as in the paper, and MO-LSP capped at five
leaders per generation (``max_leaders=5``).
"""

# %%
# Hypervolume over evaluations
# ----------------------------
import matplotlib.pyplot as plt
import numpy as np

from moo.runner import run

EVALS = 10000                                  # the paper's budget
SEEDS = (0, 1, 2)
variants = {"NSGA-II": {}, "NSGA-II/MO-LSP": {"molsp": True},
            "NSGA-II/MO-LSP, 5 leaders": {"molsp": True, "max_leaders": 5}}

results = {name: [run("zdt1", "nsga2", seed=s, evals=EVALS, **kw) for s in SEEDS]
           for name, kw in variants.items()}

grid = np.linspace(92, EVALS, 200)
fig, ax = plt.subplots(figsize=(7, 3.6), layout="constrained")
for name, runs in results.items():
    curves = np.array([np.interp(grid, r.hv_history[:, 0], r.hv_history[:, 1]) for r in runs])
    line, = ax.plot(grid, curves.mean(axis=0), label=name)
    ax.fill_between(grid, curves.min(axis=0), curves.max(axis=0), color=line.get_color(), alpha=0.2)
ax.set(xlabel="evaluations", ylabel="hypervolume", title="ZDT1 (mean and range of 3 seeds)")
ax.legend(loc="lower right")

for name, runs in results.items():
    hv = [r.hv for r in runs]
    share = np.mean([r.molsp_evals / r.n_evals for r in runs])
    print(f"{name:26s} final HV {np.mean(hv):.4f} +- {np.std(hv):.4f}, "
          f"{100 * share:.0f} % of the evaluations spent on mutants")

# %%
# Wrapping any pymoo algorithm
# ----------------------------
# :func:`moo.molsp.molsp` takes a configured pymoo algorithm that selects by
# survival and returns a copy with MO-LSP added; everything else (mating,
# termination, callbacks) stays the host's own. Here pymoo's own NSGA-II,
# run with pymoo's ``minimize``.
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.optimize import minimize

from moo.molsp import molsp
from moo.problems import make_problem

problem = make_problem("zdt1")                 # pymoo's ZDT1 with its reference points
host = NSGA2(pop_size=92)
wrapped = molsp(host, ref_point=problem.molsp_ref_point)
print(type(wrapped).__name__, isinstance(wrapped, NSGA2))

fronts = {"NSGA2": minimize(problem, host, ("n_eval", EVALS), seed=1),
          "NSGA2 + MO-LSP": minimize(problem, wrapped, ("n_eval", EVALS), seed=1)}

fig, ax = plt.subplots(figsize=(4.5, 4), layout="constrained")
f1 = np.linspace(0, 1, 200)
ax.plot(f1, 1 - np.sqrt(f1), "k-", lw=0.8, label="Pareto front")
for name, res in fronts.items():
    ax.plot(res.F[:, 0], res.F[:, 1], ".", label=f"{name} ({res.algorithm.evaluator.n_eval} evals)")
ax.set(xlabel="$f_1$", ylabel="$f_2$", title=f"ZDT1 after {EVALS} evaluations")
ax.legend()
