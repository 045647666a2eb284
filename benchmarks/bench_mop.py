"""Speed of the two control-design MOPs: batched evaluation and whole NSGA-II runs.

Usage::

    python benchmarks/bench_mop.py [--pop 92] [--elementwise 16] [--evals 10000] [--seed 1]
                                   [--repeats 2] [--skip-runs] [--out benchmarks/results/mop.md]

Measured in one run, on the same machine (timings on a shared machine are noisy):

1. **Batched vs elementwise, applied MOP.** Evaluations per second of
   :class:`moo.problems.applied.AppliedRLQRProblem` on a seeded random population
   of ``--pop`` individuals (one batched RLQR design and one batched simulation
   per call; best of 3 calls), against the *same* MOP written as a pymoo
   ``ElementwiseProblem`` (:class:`ElementwiseApplied` below) that designs
   (``robustctl.design("rlqr", ...)``) and simulates one individual at a time,
   timed on the first ``--elementwise`` individuals. The two must agree on those
   individuals (checked, relative 1e-6). Target: ratio >= 30.
2. **NSGA-II runs.** Wall time of one ``--evals``-evaluation NSGA-II run
   (``moo.algorithms.make_algorithm("nsga2")``, the paper's operators and
   population 92) on each MOP, without and with MO-LSP
   (``moo.molsp.molsp(..., ref_point=problem.molsp_ref_point)``), same seed and
   budget; each configuration ``--repeats`` times, the fastest kept (the machine
   is shared). Reported: seconds, evaluations done, MO-LSP's extra time in
   percent (target <= 10 %), the mutants it evaluated, and the time spent inside
   the problem's evaluation (the rest is the algorithm's own work, MO-LSP's
   included). At equal budget the two runs evaluate different designs, whose
   cost differs (slowly converging RLQR designs, simulator runs that diverge),
   so part of the difference is not MO-LSP's own work.
3. **Objective scales** behind the reference points: for a seeded sample of
   random designs, the share that is stable and the share of those that
   dominate ``hv_ref_point`` / ``molsp_ref_point``.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # run from a checkout without install

from pymoo.core.problem import ElementwiseProblem
from pymoo.optimize import minimize

import robustctl as rc
from moo.algorithms import make_algorithm
from moo.molsp import molsp
from moo.problems.applied import AppliedRLQRProblem
from moo.problems.generic import GenericRLQRProblem
from robustctl.models import truck
from robustctl.pathfollow import simulate


class ElementwiseApplied(ElementwiseProblem):
    """The applied MOP one individual at a time (the peer of the batched version).

    Same model, weights, path, payloads, penalty rule and objectives as
    ``batched`` (an :class:`AppliedRLQRProblem`), but each call designs one gain
    with ``robustctl.design("rlqr", ...)``, checks its closed-loop stability
    and runs one simulation (B = 1).
    """

    def __init__(self, batched: AppliedRLQRProblem):
        self.b = batched
        self.F_s, self.G_s, _ = truck.discretise(batched.overloads)
        super().__init__(n_var=batched.n_var, n_obj=batched.n_obj, xl=batched.xl, xu=batched.xu)

    def _evaluate(self, x, out, *args, **kwargs):
        b = self.b
        pen = b.penalty
        try:
            K = rc.design("rlqr", b.plant, x[None, :4], x[None, 4:6], 10.0 ** np.sqrt(x[6]),
                          Q=b.Q, R=b.R, H=b.H, alpha=b.alpha, max_iter=b.max_iter, check_stability=False).K
        except (rc.ConvergenceError, rc.RankConditionError):
            out["F"] = np.full(b.n_obj, 2.0 * pen)
            return
        rho = max(np.max(np.abs(np.linalg.eigvals(Fs + Gs @ K.sum(axis=0, keepdims=True))))
                  for Fs, Gs in zip(self.F_s, self.G_s, strict=True))
        if rho >= 1.0:
            out["F"] = np.full(b.n_obj, pen * min(rho, 2.0))
            return
        e = simulate(K, b.path, tuple(b.overloads), keep_trajectories=False,
                     input_map=truck.DOUBLED_INPUT_MAP).mse()[0]
        f = e.mean(axis=0) if b.aggregate == "mean" else e.max(axis=0)
        out["F"] = np.minimum(f, pen)


def batched_vs_elementwise(pop: int, n_elem: int, seed: int) -> dict:
    p = AppliedRLQRProblem()
    Z = np.random.default_rng(seed).uniform(p.xl, p.xu, (pop, p.n_var))
    t_batch = []
    for _ in range(3):
        t0 = time.perf_counter()
        F_batch = p.evaluate(Z)
        t_batch.append(time.perf_counter() - t0)
    q = ElementwiseApplied(p)
    t0 = time.perf_counter()
    F_elem = q.evaluate(Z[:n_elem])
    t_elem = time.perf_counter() - t0
    np.testing.assert_allclose(F_elem, F_batch[:n_elem], rtol=1e-6)
    rate_b = pop / min(t_batch)
    rate_e = n_elem / t_elem
    return dict(pop=pop, n_elem=n_elem, rate_batched=rate_b, rate_elementwise=rate_e,
                ratio=rate_b / rate_e, n_penalised=int(np.sum(F_batch[:, 0] >= p.penalty)))


def nsga2_runs(evals: int, seed: int, repeats: int) -> list[dict]:
    """Each configuration ``repeats`` times (same seed, so the same work), alternating; the fastest counts."""
    rows = []
    for name, cls in (("generic", GenericRLQRProblem), ("applied", AppliedRLQRProblem)):
        problem = cls()
        evaluate = problem._evaluate
        spent = [0.0]

        def timed(x, out, *args, **kwargs):           # time spent evaluating (design + simulation)
            t = time.perf_counter()
            evaluate(x, out, *args, **kwargs)
            spent[0] += time.perf_counter() - t

        problem._evaluate = timed
        best = {}
        for _ in range(repeats):
            for with_molsp in (False, True):
                alg = make_algorithm("nsga2", n_obj=problem.n_obj)
                if with_molsp:
                    alg = molsp(alg, ref_point=problem.molsp_ref_point)
                spent[0] = 0.0
                t0 = time.perf_counter()
                res = minimize(problem, alg, ("n_eval", evals), seed=seed, verbose=False)
                dt = time.perf_counter() - t0
                if with_molsp not in best or dt < best[with_molsp]["seconds"]:
                    best[with_molsp] = dict(
                        problem=name, molsp=with_molsp, seconds=dt, eval_seconds=spent[0],
                        n_eval=res.algorithm.evaluator.n_eval, n_gen=res.algorithm.n_gen,
                        mutants=res.algorithm.data.get("molsp_n_eval", 0) if with_molsp else 0)
        best[True]["overhead"] = 100.0 * (best[True]["seconds"] / best[False]["seconds"] - 1.0)
        rows += [best[False], best[True]]
    return rows


def scales(seed: int, n: int = 460) -> list[dict]:
    rows = []
    for name, cls in (("generic", GenericRLQRProblem), ("applied", AppliedRLQRProblem)):
        p = cls()
        Z = np.random.default_rng(seed).uniform(p.xl, p.xu, (n, p.n_var))
        F = p.evaluate(Z)
        ok = F[:, 0] < p.penalty
        rows.append(dict(problem=name, n=n, stable=ok.mean(),
                         dom_hv=np.mean(np.all(F[ok] < p.hv_ref_point, axis=1)),
                         dom_molsp=np.mean(np.all(F[ok] < p.molsp_ref_point, axis=1)),
                         z_star=p.evaluate(p.paper_optimum[None])[0], hv_ref=p.hv_ref_point,
                         molsp_ref=p.molsp_ref_point))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pop", type=int, default=92)
    ap.add_argument("--elementwise", type=int, default=16)
    ap.add_argument("--evals", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=2, help="runs per NSGA-II configuration (fastest kept)")
    ap.add_argument("--skip-runs", action="store_true", help="skip the NSGA-II runs")
    ap.add_argument("--out", type=Path, default=None, help="also write the report (Markdown) here")
    args = ap.parse_args(argv)

    lines = [(f"# bench_mop ({datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, "
              f"{platform.processor() or platform.machine()}, Python {platform.python_version()})"), ""]
    b = batched_vs_elementwise(args.pop, args.elementwise, args.seed)
    lines += ["## Applied MOP: batched vs elementwise", "",
              "| evaluation | evals/s |", "|---|---|",
              f"| batched, population {b['pop']} ({b['n_penalised']} penalised) | {b['rate_batched']:.1f} |",
              f"| ElementwiseProblem, {b['n_elem']} individuals | {b['rate_elementwise']:.2f} |",
              f"| **ratio** (target >= 30) | **{b['ratio']:.0f}x** |", ""]
    print("\n".join(lines), flush=True)
    if not args.skip_runs:
        rows = nsga2_runs(args.evals, args.seed, args.repeats)
        part = [f"## NSGA-II, {args.evals} evaluations, seed {args.seed}, fastest of {args.repeats}", "",
                ("| problem | MO-LSP | seconds | of which evaluating | evaluations | generations | mutants "
                 "| MO-LSP extra time |"),
                "|---|---|---|---|---|---|---|---|"]
        for r in rows:
            extra = f"{r['overhead']:+.1f} %" if "overhead" in r else ""
            part.append(f"| {r['problem']} | {'yes' if r['molsp'] else 'no'} | {r['seconds']:.1f} "
                        f"| {r['eval_seconds']:.1f} | {r['n_eval']} | {r['n_gen']} | {r['mutants']} | {extra} |")
        print("\n".join([*part, ""]), flush=True)
        lines += [*part, ""]
    part = ["## Objective scales (random designs)", "",
            "| problem | sample | stable | dominate hv_ref | dominate molsp_ref | f(z*) |", "|---|---|---|---|---|---|"]
    for r in scales(args.seed + 1):
        part.append(f"| {r['problem']} | {r['n']} | {100 * r['stable']:.0f} % | {100 * r['dom_hv']:.0f} % "
                    f"| {100 * r['dom_molsp']:.0f} % | {np.array2string(r['z_star'], precision=3)} |")
    print("\n".join(part), flush=True)
    lines += part
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
