"""The registry's MOEAs under the Deb & Jain (2014) DTLZ protocol, against NSGA-III's published and measured IGD.

Usage::

    python -m benchmarks.bench_protocol [--parts protocol,dense,paper,wfg] [--algorithms a,b,...] [--wfg-evals 25000]
                                        [--problems dtlz1,...] [--objectives 3,5,8] [--runs 20]
                                        [--processes 2] [--out benchmarks/results/protocol.md]

Parts (each a section of the Markdown written to ``--out``; the options select a
subset, which the output states):

``protocol``
    Deb & Jain (2014), Sec. V / Tables I-III, for the reference-direction
    algorithms (nsga3, theta-dea, mombi2, efr-rr, spea-r): DTLZ1-4 with
    ``n_var = M + k - 1`` (k = 5 for DTLZ1, 10 otherwise), M = 3, 5, 8;
    Das-Dennis directions with 12, 6 and (3 + 2 two-layer) divisions (91, 210,
    156); population 92, 212, 156; generations DTLZ1 400/600/750, DTLZ2
    250/350/500, DTLZ3 1000/1000/1000, DTLZ4 600/1000/1250; SBX pc = 1,
    eta_c = 30, polynomial mutation pm = 1/n, eta_m = 20 for every algorithm
    (``--operators protocol``; ``original`` / ``paper`` select each
    algorithm's own or the reproduced paper's). IGD (moocore) of the final
    non-dominated set to the *targets*, the intersections of the directions
    with the true front (``0.5 w`` on DTLZ1's plane, ``w / ||w||`` on the
    sphere), best / median / worst over ``--runs`` runs (Deb & Jain: 20), and
    the median against NSGA-III's published median (:data:`PUBLISHED`): the
    row of our NSGA-III is the calibration of the harness.
``dense``
    Every registry algorithm on the same cases (default M = 3, 5), IGD and
    IGD+ of the final non-dominated set to a dense sample of the true front
    (about 10,000 Das-Dennis points, :data:`DENSE_PARTITIONS`) relative to
    NSGA-III's in the same run (median over runs).
``paper``
    The reproduced paper's setting: population 92, 10,000 evaluations, the
    paper's operators, DTLZ2 (M = 3, 4) and DTLZ4 (M = 3), dense IGD relative
    to NSGA-III.
``wfg``
    WFG1-9 (``moo.problems``: k = 2(M-1), l = 20), M = 3, population 92,
    ``--wfg-evals`` evaluations (default 25,000), paper operators; IGD and
    IGD+ to pymoo's front sample (``pareto_front`` on 861 Das-Dennis
    directions) relative to NSGA-III.

In every part a run counts as *failed* when its dense-front IGD exceeds
:data:`FAIL_FACTOR` times that of the Das-Dennis set of its own population size
(a run that covers the whole front evenly scores about 1), and as *collapsed*
when it failed although its points lie on the front (mean distance below
:data:`ON_FRONT_TOL`): the run covers part of the front only (DTLZ4's known
failure). The counts are reported per algorithm and case.

Runs go to a pool of ``--processes`` worker processes (at most 2: the machine is
shared); BLAS is pinned to one thread per process. Ratios are against the peer
in the same invocation; wall time is not reported (the machine is shared).
"""

from __future__ import annotations

import argparse
import datetime
import multiprocessing as mp
import os
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import moocore  # noqa: E402
import numpy as np  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402
from pymoo.util.ref_dirs import get_reference_directions  # noqa: E402

from moo.algorithms import ALGORITHMS, POP_SIZE, make_algorithm  # noqa: E402
from moo.algorithms.nsga import NSGA3_ORIGINAL_OPERATORS  # noqa: E402
from moo.problems import make_problem  # noqa: E402

PARTS = ("protocol", "dense", "paper", "wfg")
DIRECTION_ALGORITHMS = ("nsga3", "theta-dea", "mombi2", "efr-rr", "spea-r")
DTLZ = ("dtlz1", "dtlz2", "dtlz3", "dtlz4")

#: NSGA-III's published IGD (best, median, worst of 20 runs), Deb & Jain (2014), Table III.
PUBLISHED: dict[tuple[str, int], tuple[float, float, float]] = {
    ("dtlz1", 3): (4.880e-4, 1.308e-3, 4.880e-3), ("dtlz1", 5): (5.116e-4, 9.799e-4, 1.979e-3),
    ("dtlz1", 8): (2.044e-3, 3.979e-3, 8.721e-3),
    ("dtlz2", 3): (1.262e-3, 1.357e-3, 2.114e-3), ("dtlz2", 5): (4.254e-3, 4.982e-3, 5.862e-3),
    ("dtlz2", 8): (1.371e-2, 1.571e-2, 1.811e-2),
    ("dtlz3", 3): (9.751e-4, 4.007e-3, 6.665e-3), ("dtlz3", 5): (3.086e-3, 5.960e-3, 1.196e-2),
    ("dtlz3", 8): (1.244e-2, 2.375e-2, 9.649e-2),
    ("dtlz4", 3): (2.915e-4, 5.970e-4, 4.286e-1), ("dtlz4", 5): (9.849e-4, 1.255e-3, 1.721e-3),
    ("dtlz4", 8): (5.079e-3, 7.054e-3, 6.051e-1),
}
#: Deb & Jain (2014), Table I: population and Das-Dennis divisions (boundary, inside layer) per M.
POPULATION = {3: 92, 5: 212, 8: 156}
DIVISIONS = {3: (12, 0), 5: (6, 0), 8: (3, 2)}
#: Deb & Jain (2014), Table III: generations per problem and M.
GENERATIONS = {"dtlz1": {3: 400, 5: 600, 8: 750}, "dtlz2": {3: 250, 5: 350, 8: 500},
               "dtlz3": {3: 1000, 5: 1000, 8: 1000}, "dtlz4": {3: 600, 5: 1000, 8: 1250}}
#: Das-Dennis divisions of the dense front samples (10011, 9880, 10626, 11440 points).
DENSE_PARTITIONS = {3: 140, 4: 37, 5: 20, 8: 9}
#: Das-Dennis divisions of pymoo's WFG front sample (861 points for M = 3).
WFG_PARTITIONS = 40
FAIL_FACTOR = 3.0
ON_FRONT_TOL = 1e-2
PAPER_EVALS = 10000
PAPER_CASES = (("dtlz2", 3), ("dtlz2", 4), ("dtlz4", 3))


@dataclass(frozen=True)
class Task:
    part: str
    algorithm: str
    problem: str
    n_obj: int
    seed: int
    operators: str
    evals: int = 0          # the budget of the paper and wfg parts


@dataclass(frozen=True)
class Result:
    task: Task
    igd_targets: float
    igd_dense: float
    igdp_dense: float
    dist: float
    failed: bool
    collapsed: bool
    cpu: float


def protocol_directions(n_obj: int) -> np.ndarray:
    """Deb & Jain's reference directions: one layer for M = 3, 5, two layers (inside scaled by 1/2) for M = 8."""
    outer, inner = DIVISIONS[n_obj]
    W = get_reference_directions("das-dennis", n_obj, n_partitions=outer)
    if inner:
        W = np.vstack([W, get_reference_directions("das-dennis", n_obj, n_partitions=inner, scaling=0.5)])
    return W


def on_front(problem: str, W: np.ndarray) -> np.ndarray:
    """Points of the true DTLZ1-4 front along the directions ``W`` (plane sum f = 0.5, unit sphere)."""
    if problem == "dtlz1":
        return 0.5 * W / W.sum(axis=1, keepdims=True)
    return W / np.linalg.norm(W, axis=1, keepdims=True)


def front_distance(problem: str, F: np.ndarray) -> np.ndarray:
    """Closed-form distance of each row of ``F`` to the true DTLZ1 (plane) / DTLZ2-4 (sphere) front."""
    if problem == "dtlz1":
        return np.abs(F.sum(axis=1) - 0.5) / np.sqrt(F.shape[1])
    return np.abs(np.linalg.norm(F, axis=1) - 1.0)


_CACHE: dict = {}


def dense_front(problem: str, n_obj: int) -> np.ndarray:
    key = ("dense", problem, n_obj)
    if key not in _CACHE:
        if problem.startswith("wfg"):
            W = get_reference_directions("das-dennis", n_obj, n_partitions=WFG_PARTITIONS)
            _CACHE[key] = make_problem(problem, n_obj=n_obj).pareto_front(W)
        else:
            W = get_reference_directions("das-dennis", n_obj, n_partitions=DENSE_PARTITIONS[n_obj])
            _CACHE[key] = on_front(problem, W)
    return _CACHE[key]


def even_igd(problem: str, n_obj: int, n_points: int) -> float:
    """Dense-front IGD of the largest one-layer Das-Dennis set of at most ``n_points`` points on the front."""
    key = ("even", problem, n_obj, n_points)
    if key not in _CACHE:
        p = 1
        while len(get_reference_directions("das-dennis", n_obj, n_partitions=p + 1)) <= n_points:
            p += 1
        W = get_reference_directions("das-dennis", n_obj, n_partitions=p)
        if problem.startswith("wfg"):
            pf = make_problem(problem, n_obj=n_obj).pareto_front(W)
        else:
            pf = on_front(problem, W)
        _CACHE[key] = float(moocore.igd(pf, ref=dense_front(problem, n_obj)))
    return _CACHE[key]


def operator_setting(name: str):
    return NSGA3_ORIGINAL_OPERATORS if name == "protocol" else name


def build(task: Task):
    """Problem, algorithm and termination of a task."""
    problem = make_problem(task.problem, n_obj=task.n_obj)
    options = {"operators": operator_setting(task.operators)}
    if task.part in ("protocol", "dense"):
        pop_size = POPULATION[task.n_obj]
        if task.algorithm in DIRECTION_ALGORITHMS:
            options["ref_dirs"] = protocol_directions(task.n_obj)
        termination = ("n_gen", GENERATIONS[task.problem][task.n_obj])
    else:
        pop_size = POP_SIZE
        termination = ("n_eval", task.evals)
    return problem, make_algorithm(task.algorithm, n_obj=task.n_obj, pop_size=pop_size, **options), termination


def dense_score(problem: str, n_obj: int, F: np.ndarray, n_pop: int) -> tuple[float, float, bool, bool]:
    """Dense-front IGD, mean distance to the front (NaN for WFG), *failed* and *collapsed* of a final set ``F``."""
    igd_dense = float(moocore.igd(F, ref=dense_front(problem, n_obj)))
    failed = igd_dense > FAIL_FACTOR * even_igd(problem, n_obj, n_pop)
    if problem.startswith("wfg"):
        return igd_dense, np.nan, failed, False
    dist = float(np.mean(front_distance(problem, F)))
    return igd_dense, dist, failed, failed and dist < ON_FRONT_TOL


def run_task(task: Task) -> Result:
    problem, algorithm, termination = build(task)
    c0 = time.process_time()
    res = minimize(problem, algorithm, termination, seed=task.seed)
    cpu = time.process_time() - c0
    F = np.asarray(res.F, dtype=float)
    igd_targets = np.nan
    if task.part == "protocol":
        igd_targets = float(moocore.igd(F, ref=on_front(task.problem, protocol_directions(task.n_obj))))
    igd_dense, dist, failed, collapsed = dense_score(task.problem, task.n_obj, F, len(res.pop))
    return Result(task, igd_targets, igd_dense, float(moocore.igd_plus(F, ref=dense_front(task.problem, task.n_obj))),
                  dist, bool(failed), bool(collapsed), cpu)


def tasks_for(args: argparse.Namespace) -> list[Task]:
    tasks = []
    for part in args.parts:
        if part == "protocol":
            algs = [a for a in args.names if a in DIRECTION_ALGORITHMS]
            cases = [(p, M) for p in args.problems for M in args.objectives if (p, M) in PUBLISHED]
        elif part == "dense":
            algs = args.names
            cases = [(p, M) for p in args.problems for M in args.dense_objectives if p in GENERATIONS
                     and M in POPULATION]
        elif part == "paper":
            algs = args.names
            cases = list(PAPER_CASES)
        else:
            algs = args.names
            cases = [(f"wfg{i}", 3) for i in range(1, 10)]
        ops = args.operators if part in ("protocol", "dense") else "paper"
        evals = {"paper": PAPER_EVALS, "wfg": args.wfg_evals}.get(part, 0)
        tasks += [Task(part, a, p, M, s, ops, evals) for (p, M) in cases for s in range(args.runs_for[part])
                  for a in algs]
    return tasks


def parse_seeds(text: str) -> list[int]:
    """Seeds given as ``first-last`` or a comma-separated list."""
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi) + 1)) if hi else [int(s) for s in text.split(",")]


def print_collapses(variants: list[str], seeds: list[int], run) -> None:
    """Markdown rows of collapsed runs per variant; ``run(variant, seed)`` returns ``(dense IGD, collapsed)``."""
    print("| variant | collapsed | seeds collapsed | median dense-front IGD |\n|---|---|---|---|")
    for variant in variants:
        rows = [(s, *run(variant, s)) for s in seeds]
        hit = [s for s, _, c in rows if c]
        print(f"| {variant} | {len(hit)} of {len(seeds)} | {', '.join(map(str, hit)) or '-'} | "
              f"{np.median([r[1] for r in rows]):.4f} |", flush=True)


def _fmt(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{x:.3e}"


def markdown(results: list[Result], args: argparse.Namespace, elapsed: float) -> str:
    when = datetime.datetime.now(datetime.UTC)
    lines = ["# MOEAs under the Deb & Jain (2014) DTLZ protocol, the paper's setting and WFG", "",
             f"Generated by `benchmarks/bench_protocol.py {' '.join(args.argv)}` on {when:%Y-%m-%d %H:%M} UTC, "
             f"Python {platform.python_version()}, {args.processes} worker process(es), {elapsed / 60:.0f} min "
             "on a shared 2-core machine. Subset run: " + subset(args) + ".",
             "", (f"`fail`: runs whose dense-front IGD exceeds {FAIL_FACTOR:g} x that of an even Das-Dennis set of "
                  f"the population's size; `coll.`: failed runs whose points are on the front (mean distance < "
                  f"{ON_FRONT_TOL:g}) but cover part of it only."), ""]
    by_part: dict[str, list[Result]] = {}
    for r in results:
        by_part.setdefault(r.task.part, []).append(r)
    for part in PARTS:
        if part in by_part:
            lines += SECTIONS[part](by_part[part])
    return "\n".join(lines)


def subset(args: argparse.Namespace) -> str:
    """What this invocation ran, in words."""
    parts = []
    for part in args.parts:
        what = {"protocol": f"{', '.join(args.problems)} at M = {', '.join(map(str, args.objectives))}, "
                            f"operators `{args.operators}`",
                "dense": f"{', '.join(args.problems)} at M = {', '.join(map(str, args.dense_objectives))}, "
                         f"operators `{args.operators}`",
                "paper": ", ".join(f"{p} M={m}" for p, m in PAPER_CASES),
                "wfg": f"WFG1-9 M=3, {args.wfg_evals} evaluations"}[part]
        parts.append(f"{part} ({what}; {args.runs_for[part]} runs)")
    return "; ".join(parts) + f"; algorithms {', '.join(args.names)}"


def _groups(results: list[Result]):
    cases = list(dict.fromkeys((r.task.problem, r.task.n_obj) for r in results))
    algs = list(dict.fromkeys(r.task.algorithm for r in results))
    for case in cases:
        yield case, {a: [r for r in results if (r.task.problem, r.task.n_obj) == case and r.task.algorithm == a]
                     for a in algs}


def protocol_section(results: list[Result]) -> list[str]:
    lines = ["## Deb & Jain protocol: IGD to the targets", "",
             ("| problem | M | gens | algorithm | runs | best | median | worst | median / NSGA-III published "
              "| median / our NSGA-III | fail | coll. |"),
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for (prob, M), per in _groups(results):
        pub = PUBLISHED[(prob, M)]
        ours_n3 = np.median([r.igd_targets for r in per.get("nsga3", [])]) if per.get("nsga3") else np.nan
        lines.append(f"| {prob.upper()} | {M} | {GENERATIONS[prob][M]} | NSGA-III published (Deb & Jain 2014) | 20 "
                     f"| {_fmt(pub[0])} | {_fmt(pub[1])} | {_fmt(pub[2])} | 1.00 | - | - | - |")
        for alg, rs in per.items():
            v = np.array([r.igd_targets for r in rs])
            med = float(np.median(v))
            lines.append(f"| {prob.upper()} | {M} | {GENERATIONS[prob][M]} | {alg} | {len(v)} | {_fmt(v.min())} | "
                         f"{_fmt(med)} | {_fmt(v.max())} | {med / pub[1]:.2f} | {med / ours_n3:.2f} | "
                         f"{sum(r.failed for r in rs)} | {sum(r.collapsed for r in rs)} |")
    return [*lines, ""]


def _relative_section(title: str, results: list[Result], budget) -> list[str]:
    lines = [title, "", ("| problem | M | budget | algorithm | runs | median IGD | IGD / NSGA-III | median IGD+ "
                         "| IGD+ / NSGA-III | fail | coll. |"), "|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for (prob, M), per in _groups(results):
        peer = per.get("nsga3") or []
        p_igd = np.median([r.igd_dense for r in peer]) if peer else np.nan
        p_igdp = np.median([r.igdp_dense for r in peer]) if peer else np.nan
        for alg, rs in per.items():
            igd = float(np.median([r.igd_dense for r in rs]))
            igdp = float(np.median([r.igdp_dense for r in rs]))
            lines.append(f"| {prob.upper()} | {M} | {budget(prob, M)} | {alg} | {len(rs)} | {_fmt(igd)} | "
                         f"{igd / p_igd:.2f} | {_fmt(igdp)} | {igdp / p_igdp:.2f} | {sum(r.failed for r in rs)} | "
                         f"{sum(r.collapsed for r in rs)} |")
    return [*lines, ""]


def dense_section(results: list[Result]) -> list[str]:
    return _relative_section("## Protocol budgets, every algorithm: dense-front IGD relative to NSGA-III", results,
                             lambda p, M: f"{GENERATIONS[p][M]} gens x {POPULATION[M]}")


def paper_section(results: list[Result]) -> list[str]:
    return _relative_section("## The paper's setting (population 92, 10,000 evaluations, paper operators)", results,
                             lambda p, M: f"{PAPER_EVALS} evals")


def wfg_section(results: list[Result]) -> list[str]:
    return _relative_section("## WFG1-9, M = 3 (population 92, paper operators; IGD to pymoo's 861-point front)",
                             results, lambda p, M: f"{results[0].task.evals} evals")


SECTIONS = {"protocol": protocol_section, "dense": dense_section, "paper": paper_section, "wfg": wfg_section}


def _csv(text: str) -> list[str]:
    return [t.strip().lower() for t in text.split(",") if t.strip()]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--parts", default="protocol,dense,paper", help=f"comma-separated subset of {', '.join(PARTS)}")
    ap.add_argument("--algorithms", default=",".join(ALGORITHMS),
                    help="comma-separated registry names (nsga3, the peer, always runs)")
    ap.add_argument("--problems", default=",".join(DTLZ), help="DTLZ problems of the protocol and dense parts")
    ap.add_argument("--objectives", default="3,5,8", help="numbers of objectives of the protocol part")
    ap.add_argument("--dense-objectives", default="3,5", help="numbers of objectives of the dense part")
    ap.add_argument("--runs", type=int, default=None,
                    help="runs per case (default: 20 for protocol, 10 for the other parts)")
    ap.add_argument("--operators", default="protocol", choices=("protocol", "original", "paper"),
                    help="variation settings of the protocol and dense parts")
    ap.add_argument("--wfg-evals", type=int, default=25000, help="evaluations per WFG run")
    ap.add_argument("--processes", type=int, default=2, help="worker processes (1 or 2)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "protocol.md"), help="Markdown output")
    args = ap.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    args.parts = _csv(args.parts)
    bad = [p for p in args.parts if p not in PARTS]
    names = _csv(args.algorithms)
    unknown = [a for a in names if a not in ALGORITHMS]
    if bad or unknown:
        ap.error(f"unknown part(s) {bad} or algorithm(s) {unknown}; parts: {PARTS}, algorithms: {list(ALGORITHMS)}")
    args.names = ["nsga3"] + [a for a in names if a != "nsga3"]
    args.problems = _csv(args.problems)
    if any(p not in DTLZ for p in args.problems):
        ap.error(f"--problems must be among {DTLZ}")
    args.objectives = [int(m) for m in _csv(args.objectives)]
    args.dense_objectives = [int(m) for m in _csv(args.dense_objectives)]
    if any(m not in POPULATION for m in args.objectives + args.dense_objectives):
        ap.error(f"numbers of objectives must be among {tuple(POPULATION)}")
    if not 1 <= args.processes <= 2:
        ap.error("--processes must be 1 or 2 (the machine is shared)")
    if args.runs is not None and args.runs < 1:
        ap.error("--runs must be >= 1")
    args.runs_for = {p: args.runs or (20 if p == "protocol" else 10) for p in args.parts}
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    tasks = tasks_for(args)
    print(f"{len(tasks)} runs on {args.processes} process(es)", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    results = []
    with mp.get_context("fork").Pool(args.processes) as pool:
        for i, r in enumerate(pool.imap_unordered(run_task, tasks, chunksize=1), 1):
            results.append(r)
            t = r.task
            print(f"[{i}/{len(tasks)}] {t.part} {t.problem} M={t.n_obj} {t.algorithm} seed {t.seed}: IGD "
                  f"{r.igd_targets if t.part == 'protocol' else r.igd_dense:.3e}{' FAILED' if r.failed else ''}",
                  file=sys.stderr, flush=True)
    order = {t: i for i, t in enumerate(tasks)}
    results.sort(key=lambda r: order[r.task])
    table = markdown(results, args, time.perf_counter() - t0)
    print(table)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
