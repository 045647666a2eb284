"""Why MaOEA-DDFC converges slowly on DTLZ1 with 8 objectives: what its two selections reward.

Usage::

    python -m benchmarks.investigations.many_objectives_ddfc_dtlz1 [--seeds 10] [--first-seed 0] [--objectives 8]
                                       [--variants shipped,full-fc] [--peers nsga3,theta-dea]

DTLZ1 under bench_protocol's dense part (Deb & Jain budget: population 156 and
750 generations at M = 8, n_var = M + 4, protocol operators). Per run: the
dense-front IGD, the median distance ``sum f - 0.5`` of the final set, the
share of its points within 0.01 of the front, and bench_protocol's *failed* /
*collapsed* (a failure that is not a collapse is a non-convergence).

MaOEA-DDFC runs in the ``--variants`` chosen: ``shipped``; ``full-fc``, the
mating tournament comparing FC at full precision (the rule before commit
b71c238: FC values below the resolution 1e-6 no longer tie; the
environmental selection unchanged); ``true-norm``, DTLZ1's true ideal point
0 and nadir 0.5 instead of the estimates; ``greedy``,
``candidate_choice="best"``. Each is traced through generations 10-200
(means over the generations):

* mating: the share of tournaments between mutually non-dominated parents,
  the share of those won by the parent with the smaller ``sum f`` (0.5: FC
  says nothing about convergence), the share of those decided between two FC
  values below the resolution (a random winner);
* FC: the share of the population below the resolution, in the normalised
  units used here and, for comparison, in raw units translated by the ideal
  point (PlatEMO's ``CalFC``);
* survival: the points of the 2N merged population beyond the last front
  used (dominated: the only convergence pressure that does not go through
  FC), the median ``sum f`` of the survivors over that of the first front
  (below 1: the selection from the first front favours convergence), the
  mean number of objectives below 1e-4 of the point's sum among the
  survivors (raw objectives: closeness to a face of the simplex), the share of generations in
  which the hyperplane was accepted and the largest normalised range.

The traced classes are subclasses of the shipped ones that record and, for
``full-fc``, hand ``tournament_winners`` the ranks of FC instead of FC (same
order, no value below the resolution); the experiment, not library code.
"""

from __future__ import annotations

import argparse
import os
import sys

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting  # noqa: E402
from scipy.stats import rankdata  # noqa: E402

from benchmarks import bench_protocol as bp  # noqa: E402  (bench_protocol pins BLAS before numpy loads)
from moo.algorithms.maoea_ddfc import (  # noqa: E402
    DDFCMatingSelection,
    DDFCSurvival,
    favorable_convergence,
    tournament_winners,
)
from moo.algorithms.normalization import HyperplaneNormalization  # noqa: E402

RESOLUTION = 1e-6
WINDOW = (10, 200)


class TracedMating(DDFCMatingSelection):
    def __init__(self, full_precision: bool):
        super().__init__()
        self.full_precision = full_precision
        self.rows: list[tuple[float, ...]] = []

    def _do(self, problem, pop, n_select, n_parents, *args, random_state=None, algorithm=None, **kwargs):
        F = pop.get("F")
        norm = algorithm.survival.norm                     # set: the survival runs on the initial population first
        fc = favorable_convergence(norm.normalize(F))
        n = n_select * n_parents
        a = random_state.integers(0, len(pop), size=n)
        b = random_state.integers(0, len(pop), size=n)
        win = tournament_winners(F, rankdata(fc, method="min") if self.full_precision else fc, a, b)
        lose = np.where(win == a, b, a)
        s = F.sum(axis=1)
        nd = np.any(F[a] < F[b], axis=1) & np.any(F[a] > F[b], axis=1)
        tied = (fc[a] < RESOLUTION) & (fc[b] < RESOLUTION)
        if n < len(pop):                                   # a top-up for offspring lost as duplicates: not recorded
            return win.reshape(n_select, n_parents)
        self.rows.append((algorithm.n_gen, nd.mean(), np.mean(s[win[nd]] < s[lose[nd]]), tied[nd].mean(),
                          np.mean(fc < RESOLUTION), np.mean(favorable_convergence(F - norm.ideal_point) < RESOLUTION)))
        return win.reshape(n_select, n_parents)


class TracedSurvival(DDFCSurvival):
    def __init__(self, n_obj: int):
        super().__init__(n_obj)
        self.rows: list[tuple[float, ...]] = []

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        out = super()._do(problem, pop, *args, n_survive=n_survive, random_state=random_state, **kwargs)
        fronts = NonDominatedSorting().do(pop.get("F"), n_stop_if_ranked=n_survive)
        F = out.get("F")                                   # DTLZ1: ideal point 0, so F / sum F is the direction
        share = F / np.maximum(F.sum(axis=1, keepdims=True), 1e-300)
        rng = self.norm.nadir_point - self.norm.ideal_point
        ratio = np.median(F.sum(axis=1)) / np.median(pop.get("F")[fronts[0]].sum(axis=1))
        self.rows.append((kwargs["algorithm"].n_gen, len(pop) - sum(map(len, fronts)), ratio,
                          np.mean((share < 1e-4).sum(axis=1)), float(self.norm.hyperplane_ok), rng.max()))
        return out


class TrueNormalization(HyperplaneNormalization):
    """DTLZ1's true ideal point 0 and nadir 0.5 instead of the estimates."""

    def update(self, F, nondominated=None):
        self.ideal_point, self.nadir_point, self.hyperplane_ok = np.zeros(self.n_obj), np.full(self.n_obj, 0.5), True


#: MaOEA-DDFC variants: label -> (full-precision mating FC, true normalisation, candidate_choice).
VARIANTS = {"shipped": (False, False, "roulette"), "full-fc": (True, False, "roulette"),
            "true-norm": (False, True, "roulette"), "greedy": (False, False, "best")}


def run(algorithm: str, n_obj: int, seed: int, variant: str | None = None) -> dict:
    """One run; ``variant`` (a key of :data:`VARIANTS`) traces MaOEA-DDFC."""
    problem, algo, termination = bp.build(bp.Task("dense", algorithm, "dtlz1", n_obj, seed, "protocol"))
    if variant is not None:
        full, true_norm, choice = VARIANTS[variant]
        algo.mating.selection = TracedMating(full)
        algo.survival = TracedSurvival(n_obj)
        algo.survival.candidate_choice = choice
        if true_norm:
            algo.survival.norm = TrueNormalization(n_obj)
    res = minimize(problem, algo, termination, seed=seed)
    F = np.asarray(res.F)
    igd, _, failed, collapsed = bp.dense_score("dtlz1", n_obj, F, len(res.pop))
    d = F.sum(axis=1) - 0.5
    row = {"igd": igd, "median_d": float(np.median(d)), "on": float(np.mean(d < 0.01)),
           "kind": "collapse" if collapsed else "non-convergence" if failed else "-"}
    if variant is not None:
        for key, rows in (("mating", res.algorithm.mating.selection.rows), ("survival", res.algorithm.survival.rows)):
            R = np.array(rows)
            row[key] = R[(R[:, 0] >= WINDOW[0]) & (R[:, 0] < WINDOW[1]), 1:].mean(axis=0)
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10, help="number of seeds")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--objectives", type=int, default=8, choices=sorted(bp.POPULATION))
    ap.add_argument("--variants", default="shipped,full-fc", help=f"MaOEA-DDFC variants, of {','.join(VARIANTS)}")
    ap.add_argument("--peers", default="nsga3,theta-dea", help="comma-separated registry names ('' for none)")
    args = ap.parse_args(argv)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    M = args.objectives
    print(f"DTLZ1, M = {M}, {bp.GENERATIONS['dtlz1'][M]} generations x {bp.POPULATION[M]}, seeds {list(seeds)}\n")
    print("| algorithm | seed | dense IGD | median sum f - 0.5 | share within 0.01 | failure |")
    print("|---|---:|---:|---:|---:|---|")
    cases = [("maoea-ddfc", v) for v in args.variants.split(",") if v] + [(p, None) for p in args.peers.split(",") if p]
    traced = []
    for name, variant in cases:
        label = name if variant is None else f"maoea-ddfc ({variant})"
        rows = [run(name, M, s, variant) for s in seeds]
        for s, r in zip(seeds, rows, strict=True):
            print(f"| {label} | {s} | {r['igd']:.3e} | {r['median_d']:.3g} | {r['on']:.2f} | {r['kind']} |", flush=True)
        if variant is not None:
            traced.append((label, rows))
    lo, hi = WINDOW
    print(f"\nTraced, generations {lo}-{hi} (mean over seeds of the means over generations):\n")
    print("| variant | non-dominated pairs | won by smaller sum f | both FC < 1e-6 | FC < 1e-6 (normalised) "
          "| FC < 1e-6 (raw) | dominated of 2N | survivors / first front | objectives < 1e-4 of sum "
          "| hyperplane accepted | max range |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for label, rows in traced:
        m = np.mean([r["mating"] for r in rows], axis=0)
        v = np.mean([r["survival"] for r in rows], axis=0)
        print(f"| {label} | {m[0]:.2f} | {m[1]:.2f} | {m[2]:.2f} | {m[3]:.2f} | {m[4]:.2f} | {v[0]:.0f} | {v[1]:.2f} "
              f"| {v[2]:.2f} | {v[3]:.2f} | {v[4]:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
