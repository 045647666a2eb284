"""Why pymoo's NSGA-III regains a lost DTLZ4 region: the stretch of a tiny-range objective.

Usage::

    python -m benchmarks.investigations.dtlz4_regain [--seeds 10] [--part protocol|paper]

DTLZ4 (3 objectives): once the points off the ``f_1`` axis in one direction are
lost, every survivor has, say, ``f_3 = (1 + g) sin(x_1^100 pi / 2)`` of order
``1e-30`` or less. pymoo's normalisation (Blank, Deb & Roy 2019, as shipped in
``pymoo.algorithms.moo.nsga3.get_nadir_point``) then rejects the hyperplane,
takes the worst of the front and, because that range is still ``<= 1e-6``, the
worst of the population: ``f_3`` is divided by its own tiny range, so the
survivors with the largest ``f_3`` (the largest ``x_1``) sit at the ``f_3`` end
of the normalised cube, take niches of their own and are kept; ``x_1`` is
selected upwards until the region is back.

The experiment runs pymoo's NSGA-III (the registry's ``nsga3``) on DTLZ4, 3
objectives, under the Deb & Jain budget (600 generations, population 92,
``--part protocol``) or the reproduced paper's (10,000 evaluations,
``--part paper``) twice per seed: as shipped, and with every range still
``<= 1e-6`` after pymoo's fall-backs set to 1 (no stretch; nothing else
changed). Per variant: the runs collapsed at the end (``bench_protocol``'s
definition), the runs in which a region (max ``f_2`` or max ``f_3`` of the
population ``>= 0.1``) was missing in some generation, and those that got it
back. It patches a pymoo module function for the second variant and restores
it afterwards; the experiment, not library code.
"""

from __future__ import annotations

import argparse
import os
import sys

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import moocore  # noqa: E402
import numpy as np  # noqa: E402
import pymoo.algorithms.moo.nsga3 as pymoo_nsga3  # noqa: E402
from pymoo.core.callback import Callback  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402

from benchmarks import bench_protocol as bp  # noqa: E402  (bench_protocol pins BLAS before numpy loads)

SHIPPED = pymoo_nsga3.get_nadir_point
REGION = 0.1


def unstretched_nadir(extreme_points, ideal_point, worst_point, worst_of_front, worst_of_population):
    """pymoo's nadir estimate, then every range still ``<= 1e-6`` set to 1."""
    nadir = np.array(SHIPPED(extreme_points, ideal_point, worst_point, worst_of_front, worst_of_population))
    tiny = nadir - ideal_point <= 1e-6
    nadir[tiny] = ideal_point[tiny] + 1.0
    return nadir


class RegionTrack(Callback):
    """Per generation: is a region (max f_2 or max f_3 below ``REGION``) missing from the population?"""

    def __init__(self):
        super().__init__()
        self.missing: list[bool] = []

    def notify(self, algorithm):
        F = algorithm.pop.get("F")
        self.missing.append(bool(F[:, 1].max() < REGION or F[:, 2].max() < REGION))


def run(part: str, seed: int, stretch: bool) -> dict:
    task = bp.Task(part, "nsga3", "dtlz4", 3, seed, "protocol" if part == "protocol" else "paper",
                   bp.PAPER_EVALS if part == "paper" else 0)
    problem, algorithm, termination = bp.build(task)
    pymoo_nsga3.get_nadir_point = SHIPPED if stretch else unstretched_nadir
    try:
        track = RegionTrack()
        res = minimize(problem, algorithm, termination, seed=seed, callback=track)
    finally:
        pymoo_nsga3.get_nadir_point = SHIPPED
    igd = float(moocore.igd(np.asarray(res.F), ref=bp.dense_front("dtlz4", 3)))
    missing = np.array(track.missing)
    return {"seed": seed, "collapsed": igd > bp.FAIL_FACTOR * bp.even_igd("dtlz4", 3, len(res.pop)),
            "lost": bool(missing.any()), "back": bool(missing.any() and not missing[-1]),
            "gens_missing": int(missing.sum())}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10, help="seeds 0 .. n-1")
    ap.add_argument("--part", default="protocol", choices=("protocol", "paper"), help="budget")
    args = ap.parse_args(argv)
    for stretch in (True, False):
        rows = [run(args.part, s, stretch) for s in range(args.seeds)]
        name = "as shipped" if stretch else "no stretch"
        lost = [r["seed"] for r in rows if r["lost"]]
        print(f"{args.part}, {name}: collapsed {sum(r['collapsed'] for r in rows)}/{len(rows)}; a region missing "
              f"in some generation: seeds {lost}, back at the end: {[r['seed'] for r in rows if r['back']]}; "
              f"generations missing {[r['gens_missing'] for r in rows if r['lost']]}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
