"""BiGE on DTLZ4 (3 objectives): collapsed runs with EvoMO's ingredients put into ours one at a time.

Usage::

    python -m benchmarks.investigations.dtlz4_bige_ingredients [--seeds 0-29] [--variants shipped,float32,...]
        [--algorithm bige]

EvoMO's own BiGE (``evomo`` 0.3.1 on ``evox`` 1.4.0, torch 2.13.0 on the
CPU, its defaults, seeds 0-29) collapsed in 0 of 30 runs where ours does in
11 (``benchmarks/results/dtlz4_bige_ingredients.md``; it was run in a
separate environment, the project does not depend on EvoMO). This script
finds which of EvoMO's departures from ours carries that difference.

The reproduced paper's setting (population 92, 10,000 evaluations, 12
variables); each run is scored as :mod:`bench_protocol` scores it (dense-front
IGD of the final non-dominated set; *collapsed*: failed although on the front).
A variant is a ``+``-joined set of ingredients applied to the registry's BiGE:

``shipped``
    nothing changed (the paper's operators);
``original``
    BiGE's own operators (SBX pc = 1, eta_c = 20, pm = 1/n, eta_m = 20; pymoo's bounded SBX);
``evomo-ops``
    EvoMO's variation: SBX pc = 1, eta_c = 20 in the unbounded form with the
    children clipped (:class:`~moo.algorithms.operators.ClippedSBX`), and
    polynomial mutation with a per-variable probability of ``1/n^2`` (EvoMO's
    BiGE passes ``pro_m = 1/n`` to a mutation that divides it by ``n`` again:
    one mutated variable in 12 offspring);
``no-dedup``
    no elimination of duplicate offspring (EvoMO has none);
``crowding-mating``
    the mating tournament won by the smaller crowding degree, ties by the
    smaller proximity, then the first candidate (EvoMO's ``lexsort`` of
    ``(f_pr, f_cd)``, whose last key is the primary one), instead of bi-goal
    Pareto dominance and a coin (BiGE's Alg. 2);
``float32``
    the objectives computed in single precision (EvoMO's default dtype):
    ``x^100`` underflows to exactly 0 for ``x < 0.37``, so the meaningless
    ``1e-300 < 1e-100`` comparisons of double precision become ties.

``--algorithm`` runs another registry algorithm (all ingredients but
``crowding-mating``). The experiment patches the algorithm and problem
objects it builds, not library code.
"""

from __future__ import annotations

import argparse
import os
import sys

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from pymoo.core.duplicate import NoDuplicateElimination  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402

from benchmarks import bench_protocol as bp  # noqa: E402  (bench_protocol pins BLAS before numpy loads)
from moo.algorithms.base import BinaryTournament  # noqa: E402
from moo.algorithms.bige import bige_estimation, niche_radius  # noqa: E402
from moo.algorithms.operators import OperatorSettings  # noqa: E402

INGREDIENTS = ("shipped", "original", "evomo-ops", "no-dedup", "crowding-mating", "float32")
#: EvoMO's BiGE variation as it acts (see the module docstring).
EVOMO_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=20.0, mutation_rate=1.0 / 12, mutation_eta=20.0,
                                   source="EvoMO's BiGE (pro_m = 1/n divided by n again)", crossover_form="clipped")


def crowding_first_tournament(pop, P, random_state=None, **kwargs):
    """Binary tournament won by the smaller crowding degree, then the smaller proximity, then the first."""
    F = pop.get("F").astype(np.float64, copy=False)
    f_pr, f_cd = bige_estimation(F, niche_radius(*F.shape), random_state)
    a, b = P[:, 0], P[:, 1]
    a_wins = (f_cd[a] < f_cd[b]) | ((f_cd[a] == f_cd[b]) & (f_pr[a] <= f_pr[b]))
    return np.where(a_wins, a, b)[:, None].astype(int)


def single_precision(problem) -> None:
    """Evaluate ``problem`` in float32 (the objectives handed back as float64)."""
    shipped = problem._evaluate

    def _evaluate(x, out, *args, **kwargs):
        shipped(np.asarray(x, dtype=np.float32), out, *args, **kwargs)
        out["F"] = np.asarray(out["F"], dtype=np.float64)

    problem._evaluate = _evaluate


def run(variant: str, seed: int, algorithm_name: str = "bige") -> tuple[float, bool]:
    parts = set(variant.split("+"))
    unknown = parts.difference(INGREDIENTS)
    if unknown:
        raise ValueError(f"unknown ingredients {sorted(unknown)}; valid: {', '.join(INGREDIENTS)}")
    if algorithm_name != "bige" and "crowding-mating" in parts:
        raise ValueError(f"crowding-mating is BiGE's tournament, got algorithm {algorithm_name!r}")
    ops = EVOMO_OPERATORS if "evomo-ops" in parts else "original" if "original" in parts else "paper"
    task = bp.Task("paper", algorithm_name, "dtlz4", 3, seed, ops, bp.PAPER_EVALS)
    problem, algorithm, termination = bp.build(task)
    if "no-dedup" in parts:
        algorithm.initialization.eliminate_duplicates = NoDuplicateElimination()
        algorithm.mating.eliminate_duplicates = NoDuplicateElimination()
    if "crowding-mating" in parts:
        algorithm.mating.selection = BinaryTournament(crowding_first_tournament)
    if "float32" in parts:
        single_precision(problem)
    res = minimize(problem, algorithm, termination, seed=seed)
    igd, _, _, collapsed = bp.dense_score("dtlz4", 3, np.asarray(res.F, dtype=float), len(res.pop))
    return igd, collapsed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-9", help="first-last or a comma-separated list")
    ap.add_argument("--variants", default="shipped,original,evomo-ops+no-dedup,float32,crowding-mating,"
                    "crowding-mating+float32,evomo-ops+no-dedup+crowding-mating+float32")
    ap.add_argument("--algorithm", default="bige", help="a registry name (crowding-mating: bige only)")
    args = ap.parse_args(argv)
    seeds = bp.parse_seeds(args.seeds)
    print(f"{args.algorithm}, DTLZ4 (M = 3), population 92, {bp.PAPER_EVALS} evaluations, seeds {args.seeds}\n")
    bp.print_collapses(args.variants.split(","), seeds, lambda v, s: run(v, s, args.algorithm))
    return 0


if __name__ == "__main__":
    sys.exit(main())
