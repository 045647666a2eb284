"""The paper's operators with pymoo's bound-aware SBX against PlatEMO's clipped SBX, on the paper's two MOPs.

Usage::

    python -m benchmarks.investigations.operators_sbx_form_mops --problem generic|applied
        [--algorithms nsga2,nsga3] [--seeds 10]

The reproduced study ran on PlatEMO, whose SBX is the unbounded form with the
children clipped to the box (:class:`moo.algorithms.operators.ClippedSBX`);
the project's default is pymoo's bound-aware SBX. The clipped form puts
variables exactly on a bound, which matters at 8 objectives on DTLZ
(``benchmarks/results/evomo_m8_check.md``). This measures whether it matters
for the paper's control-design problems: each algorithm runs 10,000
evaluations per seed with both forms (everything else the paper's), and the
final fronts are scored by hypervolume after a common normalisation (ideal
point and 90 % quantile of all final points of the problem pooled, reference
point 1.1 in every objective; points beyond it count nothing). Reported: the
median and mean hypervolume, the share of final variables exactly on a bound,
and the two-sided rank-sum p-value between the forms.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import moocore  # noqa: E402
import numpy as np  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402
from scipy.stats import mannwhitneyu  # noqa: E402

from moo.algorithms import make_algorithm  # noqa: E402
from moo.algorithms.operators import PAPER_OPERATORS  # noqa: E402
from moo.problems import make_problem  # noqa: E402

FORMS = {"bounded": PAPER_OPERATORS, "clipped": dataclasses.replace(PAPER_OPERATORS, crossover_form="clipped")}


def final_front(problem_name: str, algorithm: str, form: str, seed: int) -> tuple[np.ndarray, float]:
    """Finite final objectives of one run and the share of its variables exactly on a bound."""
    problem = make_problem(problem_name)
    res = minimize(problem, make_algorithm(algorithm, n_obj=problem.n_obj, operators=FORMS[form]),
                   ("n_eval", 10000), seed=seed)
    F = np.atleast_2d(np.asarray(res.F, dtype=float))
    dec = np.atleast_2d(np.asarray(res.X, dtype=float))
    on_bound = float(np.mean((dec <= problem.xl) | (dec >= problem.xu)))
    return F[np.all(np.isfinite(F), axis=1)], on_bound


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problem", choices=("generic", "applied"), required=True)
    ap.add_argument("--algorithms", default="nsga2,nsga3,spea2-sde,theta-dea")
    ap.add_argument("--seeds", type=int, default=10, help="seeds 0 .. n-1")
    args = ap.parse_args(argv)
    algorithms = args.algorithms.split(",")
    runs = {(a, f, s): final_front(args.problem, a, f, s)
            for a in algorithms for f in FORMS for s in range(args.seeds)}
    pooled = np.vstack([F for F, _ in runs.values()])
    ideal, top = pooled.min(axis=0), np.quantile(pooled, 0.9, axis=0)
    ref = np.full(pooled.shape[1], 1.1)

    def hv(F: np.ndarray) -> float:
        scaled = (F - ideal) / (top - ideal)
        inside = scaled[np.all(scaled < ref, axis=1)]
        return float(moocore.hypervolume(inside, ref=ref)) if len(inside) else 0.0

    print(f"{args.problem}, 10000 evaluations, seeds 0-{args.seeds - 1}\n")
    print("| algorithm | SBX form | median HV | mean HV | variables on a bound | rank-sum p |\n"
          "|---|---|---:|---:|---:|---:|")
    for a in algorithms:
        h = {f: [hv(runs[(a, f, s)][0]) for s in range(args.seeds)] for f in FORMS}
        p = mannwhitneyu(h["bounded"], h["clipped"]).pvalue
        for f in FORMS:
            share = np.mean([runs[(a, f, s)][1] for s in range(args.seeds)])
            p_text = f"{p:.2f}" if f == "clipped" else ""
            print(f"| {a} | {f} | {np.median(h[f]):.4f} | {np.mean(h[f]):.4f} | {share:.3f} | {p_text} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
