"""Quality and speed of the registry's MOEAs on DTLZ1/DTLZ2, against pymoo's NSGA-III and NSGA-II.

Usage::

    python -m benchmarks.bench_moeas [--algorithms a,b,...] [--seeds 10] [--evals 10000]
                                     [--dtlz1-evals 60000] [--out benchmarks/results/moeas.md]

Each algorithm of :data:`moo.algorithms.ALGORITHMS` (or those named) runs,
serially, ``--seeds`` times (seeds 0, 1, ...) with the paper's settings
(population :data:`~moo.algorithms.operators.POP_SIZE` = 92,
``make_algorithm(name, n_obj=M)``) on the problems of :mod:`moo.problems`
(Deb et al.'s ``n_var = M + k - 1``; pymoo's own default is 10 variables for
any ``M``):

* DTLZ2 with 3 and 4 objectives (``n_var`` 12 and 13), ``--evals``
  evaluations (10000, the paper's budget);
* DTLZ1 with 3 objectives (``n_var = 7``), ``--dtlz1-evals`` evaluations:
  DTLZ1's multimodal distance function needs about 20000 evaluations at
  population 92 for NSGA-III itself to reach the linear front, and some
  seeds of the slower-converging algorithms are still on a local front
  at 30000 (10 seeds: one of MaOEA-DDFC's entirely, a fifth or more of the
  points of one SPEA/R and one BiGE run; all reach the front by 60000), so
  the default budget there is 60000 (use ``--dtlz1-evals 10000`` for the
  paper's).

Reported per algorithm and problem (NSGA-II and NSGA-III, the peers, always run):

* mean (and standard deviation) over the seeds of the IGD of the final
  non-dominated set (pymoo's ``IGD``) against the true front,
  ``problem.pareto_front(ref_dirs)`` on a dense Das-Dennis set (5050 points
  for 3 objectives, 5456 for 4);
* ``IGD / NSGA-III``: the ratio of that mean to NSGA-III's mean in the same run;
* ``dist. to front``: mean over the seeds of the mean distance of the final
  points to the true front in closed form (``|sum f - 0.5| / sqrt(M)`` for
  DTLZ1's hyperplane, ``| ||f|| - 1 |`` for DTLZ2's sphere): convergence alone;
  ``on front``: the share of final points within 0.01 of it (robust to the
  few dominance-resistant boundary points DTLZ1 is known for);
* ``time / NSGA-II``: mean wall time per run relative to NSGA-II's in the
  same run, and ``CPU / NSGA-II`` the same with the process CPU time, which
  other jobs on a shared machine disturb less. The algorithms run
  interleaved (seed 0 of each, then seed 1, ...), after one untimed
  warm-up run each, so that load drifts hit them alike.

A second table checks the issue-6 criteria per algorithm: IGD / NSGA-III <= 1.5
and time / NSGA-II <= 3 on both DTLZ2 cases, and at least 90% of the final
points on DTLZ1's front.

A registered algorithm whose factory is not available yet
(``make_algorithm`` raises NotImplementedError) is listed as missing. The
Markdown table is printed and written to ``--out``.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymoo.indicators.igd import IGD
from pymoo.optimize import minimize
from pymoo.util.ref_dirs import get_reference_directions

from moo.algorithms import ALGORITHMS, POP_SIZE, make_algorithm
from moo.problems import make_problem

PEERS = ("nsga2", "nsga3")
DENSE_PARTITIONS = {3: 99, 4: 30}


@dataclass(frozen=True)
class Case:
    problem: str
    n_obj: int
    evals: int

    @property
    def label(self) -> str:
        return f"{self.problem.upper()} M={self.n_obj}"


@dataclass(frozen=True)
class Row:
    algorithm: str
    case: Case
    igd_mean: float = np.nan
    igd_std: float = np.nan
    dist_mean: float = np.nan
    on_front: float = np.nan
    wall_mean: float = np.nan
    cpu_mean: float = np.nan
    status: str = "ok"


ON_FRONT_TOL = 1e-2
ON_FRONT_MIN = 0.9


def distances_to_front(problem: str, F: np.ndarray) -> np.ndarray:
    """Closed-form distance of each point of ``F`` to the true DTLZ1 (plane) / DTLZ2 (sphere) front."""
    if problem == "dtlz1":
        return np.abs(F.sum(axis=1) - 0.5) / np.sqrt(F.shape[1])
    return np.abs(np.linalg.norm(F, axis=1) - 1.0)


def available(name: str, n_obj: int) -> bool:
    """Whether the registry can build ``name`` (False when its factory raises NotImplementedError)."""
    try:
        make_algorithm(name, n_obj=n_obj)
    except NotImplementedError:
        return False
    return True


def run_case(names: list[str], case: Case, seeds: int, pf: np.ndarray) -> list[Row]:
    """All algorithms on one case, interleaved seed by seed so that load drifts hit them alike."""
    problem = make_problem(case.problem, n_obj=case.n_obj)
    indicator = IGD(pf)
    ok = [n for n in names if available(n, case.n_obj)]
    for name in ok:  # untimed two-generation warm-up: first-call costs (imports, caches) stay out of the timings
        minimize(problem, make_algorithm(name, n_obj=case.n_obj), ("n_eval", 2 * POP_SIZE), seed=seeds)
    igd, dist, near, wall, cpu = ({n: [] for n in ok} for _ in range(5))
    for seed in range(seeds):
        for name in ok:
            algorithm = make_algorithm(name, n_obj=case.n_obj)
            w0, c0 = time.perf_counter(), time.process_time()
            res = minimize(problem, algorithm, ("n_eval", case.evals), seed=seed)
            wall[name].append(time.perf_counter() - w0)
            cpu[name].append(time.process_time() - c0)
            igd[name].append(indicator(res.F))
            d = distances_to_front(case.problem, res.F)
            dist[name].append(float(np.mean(d)))
            near[name].append(float(np.mean(d < ON_FRONT_TOL)))
    rows = []
    for name in names:
        if name not in ok:
            rows.append(Row(name, case, status="missing"))
        else:
            rows.append(Row(name, case, float(np.mean(igd[name])), float(np.std(igd[name])),
                            float(np.mean(dist[name])), float(np.mean(near[name])),
                            float(np.mean(wall[name])), float(np.mean(cpu[name]))))
        r = rows[-1]
        print(f"{case.label:12s} {name:12s} IGD {r.igd_mean:.4f}  {r.wall_mean:.2f} s/run wall  "
              f"{r.cpu_mean:.2f} s/run cpu  {r.status}", file=sys.stderr, flush=True)
    return rows


def markdown(rows: list[Row], args: argparse.Namespace) -> str:
    peer = {(r.algorithm, r.case): r for r in rows if r.algorithm in PEERS}
    lines = [
        "# MOEA benchmark: DTLZ1 / DTLZ2 against pymoo's NSGA-III (quality) and NSGA-II (speed)",
        "",
        (f"Generated by `benchmarks/bench_moeas.py` on {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, "
         f"Python {platform.python_version()}, {args.seeds} seeds (0..{args.seeds - 1}), population {POP_SIZE}, "
         f"{args.evals} evaluations on DTLZ2 and {args.dtlz1_evals} on DTLZ1. "
         "IGD: pymoo's, against a dense sample of the true front. Ratios are against the peer in the same run; "
         "wall and CPU times are from a shared 2-core machine and are noisy (CPU time less so)."),
        "",
        ("| algorithm | problem | evals | mean IGD | std IGD | IGD / NSGA-III | dist. to front | on front "
         "| time / NSGA-II | CPU / NSGA-II | status |"),
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in rows:
        if r.status != "ok":
            lines.append(f"| {r.algorithm} | {r.case.label} | {r.case.evals} |{' - |' * 7} {r.status} |")
            continue
        n3, n2 = peer.get(("nsga3", r.case)), peer.get(("nsga2", r.case))
        q = r.igd_mean / n3.igd_mean if n3 and n3.status == "ok" else np.nan
        t = r.wall_mean / n2.wall_mean if n2 and n2.status == "ok" else np.nan
        c = r.cpu_mean / n2.cpu_mean if n2 and n2.status == "ok" else np.nan
        lines.append(f"| {r.algorithm} | {r.case.label} | {r.case.evals} | {r.igd_mean:.4f} | {r.igd_std:.4f} | "
                     f"{q:.2f} | {r.dist_mean:.2e} | {100 * r.on_front:.0f}% | {t:.2f} | {c:.2f} | {r.status} |")
    lines += ["", ("`dist. to front`: mean closed-form distance of the final points to the true front; `on front`: "
                   f"share of them within {ON_FRONT_TOL:g} of it (both averaged over the seeds)."), ""]
    lines += summary(rows, peer)
    return "\n".join(lines)


def summary(rows: list[Row], peer: dict) -> list[str]:
    """Per algorithm: the issue-6 criteria (worst case over DTLZ2 M=3/4, DTLZ1 convergence) and a verdict."""
    lines = ["## Criteria of issue 6", "",
             ("IGD / NSGA-III <= 1.5 and time / NSGA-II <= 3 on DTLZ2 (worst of M = 3, 4); on DTLZ1, "
              f"at least {100 * ON_FRONT_MIN:.0f}% of the final points on the linear front."), "",
             ("| algorithm | worst IGD / NSGA-III | worst time / NSGA-II | worst CPU / NSGA-II | DTLZ1 on front "
              "| verdict |"),
             "|---|---:|---:|---:|---:|---|"]
    for name in dict.fromkeys(r.algorithm for r in rows):
        mine = [r for r in rows if r.algorithm == name]
        if any(r.status != "ok" for r in mine):
            lines.append(f"| {name} | - | - | - | - | missing |")
            continue
        q, t, c, near = [], [], [], np.nan
        for r in mine:
            n3, n2 = peer.get(("nsga3", r.case)), peer.get(("nsga2", r.case))
            if r.case.problem == "dtlz2":
                q.append(r.igd_mean / n3.igd_mean)
                t.append(r.wall_mean / n2.wall_mean)
                c.append(r.cpu_mean / n2.cpu_mean)
            else:
                near = r.on_front
        fails = [label for label, bad in (("quality", max(q) > 1.5), ("speed", max(t) > 3.0),
                                          ("DTLZ1", not near >= ON_FRONT_MIN)) if bad]
        verdict = "meets all" if not fails else "fails: " + ", ".join(fails)
        lines.append(f"| {name} | {max(q):.2f} | {max(t):.2f} | {max(c):.2f} | {100 * near:.0f}% | {verdict} |")
    return [*lines, ""]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--algorithms", default=",".join(ALGORITHMS),
                    help="comma-separated registry names (default: all); nsga2 and nsga3 always run as peers")
    ap.add_argument("--seeds", type=int, default=10, help="independent runs per algorithm and problem")
    ap.add_argument("--evals", type=int, default=10000, help="evaluations per run on DTLZ2")
    ap.add_argument("--dtlz1-evals", type=int, default=60000, help="evaluations per run on DTLZ1")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "moeas.md"), help="Markdown output file")
    args = ap.parse_args(argv)
    names = [a.strip().lower() for a in args.algorithms.split(",") if a.strip()]
    unknown = [a for a in names if a not in ALGORITHMS]
    if unknown:
        ap.error(f"unknown algorithm(s) {', '.join(unknown)}; valid: {', '.join(ALGORITHMS)}")
    if args.seeds < 1 or args.evals < 2 * POP_SIZE or args.dtlz1_evals < 2 * POP_SIZE:
        ap.error(f"--seeds must be >= 1 and --evals, --dtlz1-evals >= {2 * POP_SIZE} (two generations)")
    args.names = list(PEERS) + [a for a in names if a not in PEERS]
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    cases = [Case("dtlz2", 3, args.evals), Case("dtlz2", 4, args.evals), Case("dtlz1", 3, args.dtlz1_evals)]
    rows = []
    for case in cases:
        M = case.n_obj
        pf = make_problem(case.problem, n_obj=M).pareto_front(
            get_reference_directions("das-dennis", M, n_partitions=DENSE_PARTITIONS[M]))
        rows += run_case(args.names, case, args.seeds, pf)
    table = markdown(rows, args)
    print(table)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(table)
    return 0


if __name__ == "__main__":
    sys.exit(main())
