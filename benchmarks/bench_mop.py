"""Speed of the two control-design MOPs: batched evaluation and whole NSGA-II runs.

Usage::

    python -m benchmarks.bench_mop [--pop 92] [--elementwise 16] [--evals 10000] [--seed 1]
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
3. **TuningProblem vs the frozen pre-tuning evaluation.** The applied MOP is
   now a :class:`moo.tuning.TuningProblem` (``RLQRFamily`` + goals sharing one
   simulation). Its time per population (``--pop`` seeded random designs;
   the two alternate, ``--tuning-repeats`` calls each, the fastest counts)
   against :class:`FrozenApplied` below, a frozen copy of the evaluation the
   problem had before (the private ``RLQRTuningProblem`` base class, deleted
   from the package): the same batched RLQR, stability screen, penalty rule
   and simulation, written inline. The objectives must be bit-identical.
   Target: ratio <= 1.1.
4. **Objective scales** behind the reference points: for a seeded sample of
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
from pymoo.core.problem import ElementwiseProblem, Problem
from pymoo.optimize import minimize

import robustctl as rc
from moo.algorithms import make_algorithm
from moo.molsp import molsp
from moo.problems.applied import AppliedRLQRProblem
from moo.problems.generic import GenericRLQRProblem
from robustctl.models import truck
from robustctl.models.pathfollow import simulate


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


class FrozenApplied(Problem):
    """The applied MOP's evaluation as it was before ``moo.tuning`` (frozen here as the speed peer).

    A copy of the deleted ``moo.problems._rlqr_problem.RLQRTuningProblem._evaluate`` specialised to
    the applied MOP: decode, one batched :func:`robustctl.rlqr_gains`, the Schur screen of
    ``F_s + G_s M K`` per payload, one path-following simulation of the stable designs, the
    penalty rule. Parameters (plant, weights, simulator) are read from ``new``.
    """

    def __init__(self, new: AppliedRLQRProblem):
        self.b = new
        F_s, G_s, _ = truck.discretise(new.overloads)
        self._F_s = F_s
        self._G_s_steer = G_s @ np.asarray(truck.DOUBLED_INPUT_MAP, dtype=float)
        super().__init__(n_var=new.n_var, n_obj=new.n_obj, xl=new.xl, xu=new.xu, vtype=float)

    def _evaluate(self, x, out, *args, **kwargs):
        b = self.b
        z = np.asarray(x, dtype=float)
        if z.ndim != 2 or z.shape[1] != self.n_var or not np.all(np.isfinite(z)) or np.any(z[:, -1] < 0):
            raise ValueError("X")
        n, m = b.plant.n, b.plant.m
        EF, EG, mu = z[:, None, :n].copy(), z[:, None, n:n + m].copy(), 10.0 ** np.sqrt(z[:, n + m])
        batch = rc.rlqr_gains(b.plant, EF, EG, mu, Q=b.Q, R=b.R, H=b.H, alpha=b.alpha, max_iter=b.max_iter,
                              fallback=b.fallback)
        ok = np.asarray(batch.ok, dtype=bool) & np.all(np.isfinite(batch.K), axis=(1, 2))
        K = np.where(ok[:, None, None], batch.K, np.nan)
        A = self._F_s[None] + self._G_s_steer[None] @ K[:, None]
        stable = np.asarray(rc.is_schur_stable(A))
        rho = np.full(A.shape[0], np.nan)
        bad = ~stable.all(axis=1)
        if bad.any():
            rho[bad] = np.asarray(rc.spectral_radius(A[bad])).max(axis=1)
        run = ok & stable.all(axis=1)
        J = np.full((z.shape[0], self.n_obj), np.inf)
        if run.any():
            e = b._sim.run(K[run], keep_trajectories=False, backend=b.backend).mse()
            J[run] = e.mean(axis=1) if b.aggregate == "mean" else e.max(axis=1)
        pen = b.penalty
        F = np.where(np.isfinite(J), np.minimum(J, pen), pen)
        unstable = ok & ~run
        F[unstable] = (pen * np.minimum(np.nan_to_num(rho[unstable], nan=2.0), 2.0))[:, None]
        F[~ok] = 2.0 * pen
        out["F"] = F


def tuning_vs_frozen(pop: int, seed: int, repeats: int) -> dict:
    """Time per population of the TuningProblem-based applied MOP and of :class:`FrozenApplied` (alternating)."""
    new = AppliedRLQRProblem()
    old = FrozenApplied(new)
    Z = np.random.default_rng(seed).uniform(new.xl, new.xu, (pop, new.n_var))
    F_new, F_old = new.evaluate(Z), old.evaluate(Z)
    np.testing.assert_array_equal(F_new, F_old)                # bit-identical objectives
    wall: dict[str, list[float]] = {"new": [], "old": []}
    cpu: dict[str, list[float]] = {"new": [], "old": []}
    for r in range(repeats):                                   # ABBA: neither always goes first
        order = (("new", new), ("old", old)) if r % 2 == 0 else (("old", old), ("new", new))
        for key, prob in order:
            w0, c0 = time.perf_counter(), time.process_time()
            prob.evaluate(Z)
            wall[key].append(time.perf_counter() - w0)
            cpu[key].append(time.process_time() - c0)
    med = {k: float(np.median(v)) for k, v in cpu.items()}
    return dict(pop=pop, repeats=repeats, new_ms=1e3 * min(wall["new"]), old_ms=1e3 * min(wall["old"]),
                new_cpu_ms=1e3 * med["new"], old_cpu_ms=1e3 * med["old"],
                ratio=min(wall["new"]) / min(wall["old"]), cpu_ratio=med["new"] / med["old"],
                n_penalised=int(np.sum(F_new[:, 0] >= new.penalty)))


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
    ap.add_argument("--tuning-repeats", type=int, default=30, help="calls per problem in the TuningProblem row")
    ap.add_argument("--only-tuning", action="store_true", help="measure the TuningProblem row only")
    ap.add_argument("--out", type=Path, default=None, help="also write the report (Markdown) here")
    args = ap.parse_args(argv)

    lines = [(f"# bench_mop ({datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, "
              f"{platform.processor() or platform.machine()}, Python {platform.python_version()})"), ""]
    t = tuning_vs_frozen(args.pop, args.seed, args.tuning_repeats)
    lines += ["## TuningProblem equal to the applied MOP vs today's AppliedRLQRProblem (frozen copy)", "",
              (f"Population {t['pop']} ({t['n_penalised']} penalised), objectives bit-identical; "
               f"{t['repeats']} calls each, alternating ABBA; wall time (fastest call) and CPU time "
               "(median call, less sensitive to other load on a shared machine)."), "",
              "| evaluation | fastest wall ms | median CPU ms |", "|---|---|---|",
              f"| TuningProblem (AppliedRLQRProblem on moo.tuning) | {t['new_ms']:.2f} | {t['new_cpu_ms']:.2f} |",
              f"| frozen pre-tuning evaluation (FrozenApplied) | {t['old_ms']:.2f} | {t['old_cpu_ms']:.2f} |",
              f"| **ratio new / old** (target <= 1.1) | **{t['ratio']:.3f}** | **{t['cpu_ratio']:.3f}** |", ""]
    print("\n".join(lines), flush=True)
    if args.only_tuning:
        if args.out is not None:
            args.out.parent.mkdir(parents=True, exist_ok=True)
            args.out.write_text("\n".join(lines) + "\n")
        return 0
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
