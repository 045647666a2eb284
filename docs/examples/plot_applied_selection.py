"""
Pareto front of the applied MOP and the Monte Carlo design selection
====================================================================

The paper's applied problem (Morais et al. 2022, Section 4.5): tune the
RLQR's uncertainty model ``z = [EF (4), EG (2), (log10 mu)^2]`` of the truck
so that the four path-following errors (MSE of lateral displacement, yaw rate,
lateral velocity and heading, at 0 and 100 % overload) are small. One
NSGA-II/MO-LSP run gives a front of designs; then, as in the paper, every
design is simulated on random payloads (``Delta ~ U(-1, 1)``, overload
``150 (1 + Delta)`` % in [0, 300] %) and the one with the least cumulative
error most often is ``z*``.

This example is shortened for the documentation build: 2000 evaluations
instead of 10000, 100 simulations on the first 120 s of the route instead of
1000 on the whole route (``python paper_repro/design_selection.py --problem
applied`` runs the longer version).
"""

# %%
# One MOEA run on the applied problem
# -----------------------------------
import matplotlib.pyplot as plt
import numpy as np

from moo.problems.applied import AppliedRLQRProblem
from moo.problems.selection import select_design
from moo.runner import run

moea = run("applied", "nsga2", molsp=True, seed=1, evals=2000)
order = np.lexsort(moea.F.T[::-1])                 # designs numbered by f1
X, F = moea.X[order], moea.F[order]
print(f"{len(F)} non-dominated designs after {moea.n_evals} evaluations")

names = [r"$f_1$ ($\rho$)", r"$f_2$ ($\dot\psi$)", r"$f_3$ ($\dot y$)", r"$f_4$ ($\theta$)"]
fig, axes = plt.subplots(1, 3, figsize=(11, 3.4), layout="constrained")
for ax, (i, j) in zip(axes, [(0, 1), (0, 2), (0, 3)], strict=True):
    sc = ax.scatter(F[:, i], F[:, j], c=np.arange(len(F)), cmap="viridis", s=14)
    ax.set(xlabel=names[i], ylabel=names[j])
fig.colorbar(sc, ax=axes, label="design index (by $f_1$)")
fig.suptitle("front of the applied MOP (MSE, averaged over 0 and 100 % overload)")

# %%
# Monte Carlo selection
# ---------------------
# The candidates are the front plus the paper's extra designs (the nominal
# LQR, RLQR^A of the appendix, a random z); each realisation is one payload.
problem = AppliedRLQRProblem()
sel = select_design(problem, X, n_sims=100, seed=1, path=problem.path.truncated(120.0))
d, counts = sel.designs, sel.result.counts
print(sel)

colors = ["tab:blue" if k == "front" else "tab:orange" for k in d.kinds]
colors[sel.best] = "tab:red"
x = np.arange(1, len(d) + 1)
fig, ax = plt.subplots(figsize=(9, 3.2), layout="constrained")
ax.bar(x, counts, color=colors)
ax.set_xticks([1, *range(10, d.n_front + 1, 10)])
extras = ", ".join(f"{lab} ({int(counts[i])})" for i, (lab, k) in enumerate(zip(d.labels, d.kinds, strict=True))
                   if k != "front")
ax.set(xlabel=f"design: 1-{d.n_front} the front by $f_1$; then, in orange, {extras} wins",
       ylabel="wins", title=f"z* = design {d.labels[sel.best]}: {int(counts[sel.best])} of {len(sel.deltas)} wins")
print("z* =", np.array2string(sel.z, precision=4))
