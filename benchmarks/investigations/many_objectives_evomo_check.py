"""SPEA/R and EFR-RR at 8 objectives (Deb & Jain budget): EvoMO's runs against ours, scored by bench_protocol.

Two halves, two environments (neither imports the other's code; final populations go through ``.npz``):

    # EvoMO's algorithm, from the separate EvoMO venv (evomo 0.3.1, evox 1.4.0, torch CPU):
    <evomo-venv>/bin/python -m benchmarks.investigations.many_objectives_evomo_check run \
        --algorithm spear --problem dtlz3 \
        --seeds 0-4 [--variant shipped|n-offspring] [--operators protocol|evomo] [--dtype float64] --out X.npz
    # score those files, and run ours on the same seed numbers, from the project's venv:
    .venv/bin/python -m benchmarks.investigations.many_objectives_evomo_check score X.npz ...
        [--ours spea-r:dtlz3:0-4 ...] [--out md]

``run`` drives EvoMO's own ``SPEAR`` / ``EFRRR`` through evox's ``StdWorkflow``
on EvoMO's DTLZ problems (``n_var = M + k - 1``, k = 10), population 156 (EvoMO's
``uniform_sampling(156, 8)`` gives the same 120 + 36 two-layer Das-Dennis set as
Deb & Jain, zeros read as 1e-6), for Deb & Jain's generation count. Nothing of
EvoMO is copied: an option swaps one ingredient by rebinding a name EvoMO's
module looks up:

``--operators protocol`` (default)
    SBX pc = 1, eta_c = 30 and polynomial mutation 1/n per variable, eta_m = 20
    (``bench_protocol``'s operators); ``evomo``: as shipped (SPEA/R: eta_c = 20;
    EFR-RR: eta_c = 20 and 1/n^2 per variable, it passes ``pro_m = 1/D`` to a
    mutation that divides by ``D`` again). evox's SBX is the unbounded form, clipped.
``--variant n-offspring``
    SPEA/R with N offspring per generation (the first child of each of its N
    pairs) instead of EvoMO's 2N: the evaluation budget of Deb & Jain and ours.

``--ours name:problem:seeds[:variant]`` runs the registry's algorithm under
``bench_protocol``'s protocol with EvoMO's ingredients (``+``-joined) put into
the objects it builds, never into library code: ``clipped-sbx`` (evox's SBX
form, :class:`~moo.algorithms.operators.ClippedSBX`), ``evomo-norm`` (SPEA/R's
min/max of the non-dominated set, skipped when one range is below 5 % of the
largest), ``2n-offspring`` (2N offspring per generation), ``2x-gens`` (twice the
generations: EvoMO's evaluations with N offspring), ``tournament`` (EFR-RR's
rank tournament).

``score`` takes the non-dominated set of each final population, recomputes
its objectives from ``X`` with the project's problem, and scores it with
``bench_protocol``'s functions: IGD to the 156 targets, the median distance to
the true front, and the *fail* rule (dense-front IGD over 3x an even set's).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

N_OBJ, POP = 8, 156
#: Deb & Jain (2014), Table III at M = 8; ``score`` checks them against ``bench_protocol.GENERATIONS``.
GENERATIONS = {"dtlz1": 750, "dtlz2": 500, "dtlz3": 1000, "dtlz4": 1250}


def seed_list(text: str) -> list[int]:
    a, _, b = text.partition("-")
    return list(range(int(a), int(b or a) + 1)) if "," not in text else [int(s) for s in text.split(",")]


def run_evomo(args: argparse.Namespace) -> None:
    import torch

    torch.set_num_threads(1)
    torch.set_default_dtype(getattr(torch, args.dtype))
    import evomo.algorithms.efr_rr as efr_mod
    import evomo.algorithms.spear as spear_mod
    import evomo.problems.numerical as problems
    from evox.workflows import StdWorkflow

    mod = spear_mod if args.algorithm == "spear" else efr_mod
    sbx, pm = mod.simulated_binary, mod.polynomial_mutation
    if args.operators == "protocol":
        mod.simulated_binary = lambda x, pro_c=1.0, dis_c=30.0: sbx(x, pro_c=1.0, dis_c=30.0)
        mod.polynomial_mutation = lambda x, lb, ub, pro_m=1.0, dis_m=20.0: pm(x, lb, ub, pro_m=1.0, dis_m=20.0)
    if args.variant == "n-offspring":
        inner = mod.simulated_binary
        mod.simulated_binary = lambda x, **kw: inner(x, **kw)[: x.size(0) // 2]
    n_var = N_OBJ + (5 if args.problem == "dtlz1" else 10) - 1
    gens = args.gens or GENERATIONS[args.problem]
    cls = spear_mod.SPEAR if args.algorithm == "spear" else efr_mod.EFRRR
    out: dict[str, np.ndarray] = {"gens": np.array(gens), "seeds": np.array(seed_list(args.seeds)),
                                  "meta": np.array(f"{args.algorithm} {args.problem} variant={args.variant} "
                                                   f"operators={args.operators} dtype={args.dtype}")}
    for s in seed_list(args.seeds):
        torch.manual_seed(s)
        c0 = time.process_time()
        algo = cls(pop_size=POP, n_objs=N_OBJ, lb=torch.zeros(n_var), ub=torch.ones(n_var))
        wf = StdWorkflow(algo, getattr(problems, args.problem.upper())(d=n_var, m=N_OBJ))
        wf.init_step()
        for _ in range(gens - 1):          # the initial population is generation 1 (pymoo's n_gen)
            wf.step()
        out[f"X{s}"] = algo.pop.detach().to(torch.float64).numpy()
        out[f"F{s}"] = algo.fit.detach().to(torch.float64).numpy()
        out[f"cpu{s}"] = np.array(time.process_time() - c0)
        print(f"seed {s}: pop {len(out[f'X{s}'])}, cpu {float(out[f'cpu{s}']):.0f}s", flush=True)
        np.savez(args.out, **out)


def score_set(bp, problem: str, F: np.ndarray, n_pop: int) -> tuple[float, float, bool]:
    """IGD to the targets, median distance to the front and *failed* of a final non-dominated set."""
    import moocore

    igd = float(moocore.igd(F, ref=bp.on_front(problem, bp.protocol_directions(N_OBJ))))
    failed = bp.dense_score(problem, N_OBJ, F, n_pop)[2]
    return igd, float(np.median(bp.front_distance(problem, F))), bool(failed)


def evomo_normalization(F: np.ndarray, nondominated: np.ndarray) -> np.ndarray:
    """EvoMO's SPEA/R normalisation: min/max of the non-dominated set, skipped if one range is < 5 % of the largest."""
    lo, hi = F[nondominated].min(axis=0), F[nondominated].max(axis=0)
    rng = hi - lo
    return (F - lo) / (rng + 1e-6) if 0.05 * rng.max() < rng.min() else F


def build_ours(bp, name: str, problem: str, seed: int, variant: str):
    """Our algorithm under the protocol with EvoMO's ingredients (``+``-joined) put in, one object patched each."""
    import dataclasses

    from moo.algorithms.nsga import NSGA3_ORIGINAL_OPERATORS
    from moo.algorithms.operators import OperatorSettings

    parts = set(filter(None, variant.split("+")))
    ops: str | OperatorSettings = "protocol"
    if "clipped-sbx" in parts:           # evox's SBX: unbounded spread, children clipped to the box
        ops = dataclasses.replace(NSGA3_ORIGINAL_OPERATORS, crossover_form="clipped")
    prob, algorithm, termination = bp.build(bp.Task("protocol", name, problem, N_OBJ, seed, ops))
    for part in parts - {"clipped-sbx"}:
        if part == "2n-offspring":       # EvoMO's SPEA/R keeps both children of its N pairs
            algorithm.n_offsprings = 2 * POP
        elif part == "evomo-norm":
            algorithm.survival._normalized = evomo_normalization
        elif part == "raw":              # no normalisation at all
            algorithm.survival._normalized = lambda F, nondominated: F
        elif part == "2x-gens":          # twice Deb & Jain's generations: EvoMO's evaluations with N offspring
            termination = ("n_gen", 2 * termination[1])
        elif part == "tournament":       # EvoMO's EFR-RR mating: binary tournament on the rank
            from moo.algorithms.efr_rr import RankTournament

            algorithm.mating.selection = RankTournament()
        else:
            raise ValueError(f"unknown variant {part!r}")
    return prob, algorithm, termination


def score(args: argparse.Namespace) -> None:
    import moocore
    from pymoo.optimize import minimize

    from benchmarks import bench_protocol as bp
    from moo.problems import make_problem

    rows = []   # (label, problem, seed, igd, median distance, failed, cpu)
    for path in args.files:
        d = np.load(path)
        label = f"EvoMO {d['meta']}"
        problem = str(d["meta"]).split()[1]
        assert int(d["gens"]) == bp.GENERATIONS[problem][N_OBJ]
        for s in d["seeds"]:
            if f"X{s}" not in d:
                continue
            X = d[f"X{s}"]
            F = make_problem(problem, n_obj=N_OBJ).evaluate(X)
            assert np.allclose(F, d[f"F{s}"], rtol=1e-4, atol=1e-4), "EvoMO's and our DTLZ disagree"
            rows.append((label, problem, int(s), *score_set(bp, problem, F[moocore.is_nondominated(F)], len(X)),
                         float(d[f"cpu{s}"])))
    for spec in args.ours:
        name, problem, seeds, *variant = spec.split(":")
        for s in seed_list(seeds):
            prob, algorithm, termination = build_ours(bp, name, problem, s, "".join(variant))
            c0 = time.process_time()
            res = minimize(prob, algorithm, termination, seed=s)
            label = f"ours {name} {problem} {''.join(variant) or 'shipped'}"
            rows.append((label, problem, s, *score_set(bp, problem, res.F, len(res.pop)), time.process_time() - c0))
    lines = ["| run | seed | IGD to targets | / NSGA-III published | median distance to front | fail | cpu s |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    summary = ["| run | problem | runs | median IGD | / NSGA-III published | median distance | fail |",
               "|---|---|---:|---:|---:|---:|---:|"]
    for label in dict.fromkeys(r[0] for r in rows):
        group = [r for r in rows if r[0] == label]
        pub = bp.PUBLISHED[(group[0][1], N_OBJ)][1]
        lines += [f"| {r[0]} | {r[2]} | {r[3]:.3e} | {r[3] / pub:.2f} | {r[4]:.2e} | {'x' if r[5] else ''} "
                  f"| {r[6]:.0f} |" for r in group]
        med = float(np.median([r[3] for r in group]))
        summary.append(f"| {label} | {group[0][1]} | {len(group)} | {med:.3e} | {med / pub:.2f} | "
                       f"{np.median([r[4] for r in group]):.2e} | {sum(r[5] for r in group)} |")
    text = "\n".join(["## Medians", "", *summary, "", "## Per run", "", *lines, ""])
    print(text)
    if args.out:
        Path(args.out).write_text(text)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="EvoMO's algorithm (EvoMO venv)")
    r.add_argument("--algorithm", choices=("spear", "efrrr"), required=True)
    r.add_argument("--problem", choices=tuple(GENERATIONS), required=True)
    r.add_argument("--seeds", default="0-2")
    r.add_argument("--variant", choices=("shipped", "n-offspring"), default="shipped")
    r.add_argument("--operators", choices=("protocol", "evomo"), default="protocol")
    r.add_argument("--dtype", choices=("float32", "float64"), default="float64")
    r.add_argument("--gens", type=int, default=0, help="default: Deb & Jain's")
    r.add_argument("--out", required=True)
    s = sub.add_parser("score", help="score .npz files, run ours (project venv)")
    s.add_argument("files", nargs="*")
    s.add_argument("--ours", action="append", default=[],
                   help="algorithm:problem:seeds[:variant], e.g. spea-r:dtlz3:0-4:2n-offspring+evomo-norm")
    s.add_argument("--out")
    args = ap.parse_args(argv)
    run_evomo(args) if args.cmd == "run" else score(args)


if __name__ == "__main__":
    main()
