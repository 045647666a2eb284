"""SPEA2+SDE on DTLZ4 (3 objectives) against two SPEA2 skeletons: collapsed runs per seed range.

Usage::

    python -m benchmarks.investigations.dtlz4_spea2_peer [--seeds 0-29] [--budget paper|protocol]
        [--variants sde,sde-raw,euclidean,pymoo,pymoo-normalized]

Ours collapses on DTLZ4 more often than an independent implementation did in
5 runs (issue 17). This asks whether the collapses come from SDE or from the
SPEA2 skeleton it sits on, by running, on the same seeds and operators:

``sde``
    the registry's SPEA2+SDE as shipped (normalised shifted distances);
``sde-raw``
    the same on the raw objectives (``normalize=False``, PlatEMO's form);
``euclidean``
    ours with the shifted distance replaced by the Euclidean one on the raw
    objectives, i.e. plain SPEA2 (Zitzler et al. 2001) in our code;
``pymoo``
    pymoo's own ``SPEA2`` (``SPEA2Survival(normalize=False)``), an
    independent SPEA2 with the same operators;
``pymoo-normalized``
    pymoo's default, which normalises by its hyperplane and gives the extreme
    points the best fitness.

Budgets: ``paper`` (population 92, 10,000 evaluations, the paper's
operators) or ``protocol`` (Deb & Jain's 600 generations, their operators).
Each run is scored as :mod:`bench_protocol` scores it (dense-front IGD of the
final set; *collapsed*: failed although on the front). ``euclidean`` swaps
``moo.algorithms.spea2_sde.shifted_distances`` for the duration of a run and
puts it back; nothing else is changed.
"""

from __future__ import annotations

import argparse
import os
import sys
from contextlib import contextmanager

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from pymoo.algorithms.moo.spea2 import SPEA2, SPEA2Survival  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402
from pymoo.util.misc import vectorized_cdist  # noqa: E402

import moo.algorithms.spea2_sde as spea2_sde  # noqa: E402
from benchmarks import bench_protocol as bp  # noqa: E402  (bench_protocol pins BLAS before numpy loads)

VARIANTS = ("sde", "sde-raw", "euclidean", "pymoo", "pymoo-normalized")


@contextmanager
def euclidean_distances():
    """Plain SPEA2: Euclidean instead of shifted distances inside :mod:`moo.algorithms.spea2_sde`."""
    shipped = spea2_sde.shifted_distances
    spea2_sde.shifted_distances = lambda F: vectorized_cdist(F, F, fill_diag_with_inf=True)
    try:
        yield
    finally:
        spea2_sde.shifted_distances = shipped


def run(variant: str, seed: int, budget: str) -> tuple[float, bool]:
    """Dense-front IGD and *collapsed* of one run."""
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {', '.join(VARIANTS)}, got {variant!r}")
    task = (bp.Task("paper", "spea2-sde", "dtlz4", 3, seed, "paper", bp.PAPER_EVALS) if budget == "paper"
            else bp.Task("dense", "spea2-sde", "dtlz4", 3, seed, "protocol", 0))
    problem, algorithm, termination = bp.build(task)
    if variant in ("sde-raw", "euclidean"):
        algorithm.survival.normalize = False
    if variant.startswith("pymoo"):
        algorithm = SPEA2(pop_size=bp.POPULATION[3],
                          sampling=algorithm.initialization.sampling, crossover=algorithm.mating.crossover,
                          mutation=algorithm.mating.mutation,
                          survival=SPEA2Survival(normalize=variant == "pymoo-normalized"))
    if variant == "euclidean":
        with euclidean_distances():
            res = minimize(problem, algorithm, termination, seed=seed)
    else:
        res = minimize(problem, algorithm, termination, seed=seed)
    igd, _, _, collapsed = bp.dense_score("dtlz4", 3, np.asarray(res.F, dtype=float), len(res.pop))
    return igd, collapsed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-29", help="first-last or a comma-separated list")
    ap.add_argument("--budget", choices=("paper", "protocol"), default="paper")
    ap.add_argument("--variants", default=",".join(VARIANTS))
    args = ap.parse_args(argv)
    seeds = bp.parse_seeds(args.seeds)
    print(f"DTLZ4 (M = 3), population 92, budget {args.budget}, seeds {args.seeds}\n")
    bp.print_collapses(args.variants.split(","), seeds, lambda v, s: run(v, s, args.budget))
    return 0


if __name__ == "__main__":
    sys.exit(main())
