"""Benchmark: robust_stability (margin and certificate) against linfnorm of the same small-gain loop.

For a norm-bounded uncertainty the margin of :func:`robustctl.robust_stability`
equals ``1 / ||E (zI - A)^-1 H||_inf``, which python-control's ``linfnorm``
(SLICOT AB13DD) computes directly. Both run in the same process on the same
loops; the ratio is ``robust_stability`` time over ``linfnorm`` time
(building the ``StateSpace`` included). ``robust_stability`` also returns
the Lyapunov matrix ``P`` and its verified eigenvalue certificate, which
``linfnorm`` does not: the H-infinity norm (SLICOT AB13DD through slycot
when installed, as ``linfnorm``; the level-set iteration of
``robustctl.analysis._hinfnorm`` otherwise), one bounded-real Riccati solution and
the certificate eigenvalues (the SDP only where the Riccati certificate
fails; the table counts those). A second table forces the pure
numpy/scipy level-set norm (``--no-pure`` skips it).

1. One loop per call, n = 4, 10, 20, discrete (dt = 0.1) and continuous.
2. A batch: ``B`` gains of one plant (n = 4, discrete) in one call
   ``robust_stability((plant, K_stack), unc)`` against ``B`` calls of
   ``linfnorm``.
3. ``guaranteed_cost`` on a stack of gains against one SDP per gain.
4. Robust H-infinity synthesis for a norm-bounded payload model of the
   truck against the polytopic design (:func:`robust_vs_polytopic`).

Loops: random plants, ``m = 2`` inputs, LQR gains (python-control ``dlqr`` /
``lqr``), ``p = 2`` columns of ``H``, ``l = 3`` rows of ``E``, ``H`` scaled
so that the margin is 2; the batch perturbs the LQR gain by 5 % Gaussian
noise. Times are CPU times of this process (``time.process_time``, BLAS
threads pinned to 1 unless the environment says otherwise): the two
functions of a ratio are timed alternately, ``--reps`` rounds of
``number`` calls each after a warm-up, and each keeps its best round, so
that a load change on the shared machine hits both alike. The ratio per
loop is best over best; the table gives the median over the loops and the
largest. The machine load (1-minute load average) is recorded.

Usage: python -m benchmarks.bench_analysis [--sizes 4 10 20] [--seeds 5] [--reps 15] [--batch 92]
                                           [--no-pure] [--out benchmarks/results/analysis.md]
(quick look: ``--seeds 2 --reps 3 --out /tmp/analysis.md``)
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import timeit  # noqa: E402
from pathlib import Path  # noqa: E402

import control  # noqa: E402
import numpy as np  # noqa: E402

import robustctl as rc  # noqa: E402
from benchmarks._report import header, write  # noqa: E402
from robustctl.analysis import _hinfnorm  # noqa: E402


def case(n: int, seed: int, discrete: bool):
    rng = np.random.default_rng(seed)
    F, G = rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((n, 2))
    K = -np.asarray((control.dlqr if discrete else control.lqr)(F, G, np.eye(n), np.eye(2))[0])
    plant = rc.Plant(F, G, 0.1 if discrete else None)
    H, EF, EG = rng.standard_normal((n, 2)), rng.standard_normal((3, n)), 0.3 * rng.standard_normal((3, 2))
    H /= 2.0 * linfnorm(plant, K, H, EF + EG @ K)
    return plant, K, rc.NormBounded(H, EF, EG)


def linfnorm(plant, K, H, E) -> float:
    sys = control.ss(plant.F + plant.G @ K, H, E, np.zeros((E.shape[0], H.shape[1])),
                     plant.dt if plant.is_discrete else 0)
    return float(control.linfnorm(sys)[0])


def cpu(fn, reps: int, number: int = 1) -> float:
    """Best CPU time of ``reps`` runs of ``number`` calls, per call."""
    return min(timeit.repeat(fn, number=number, repeat=reps, timer=time.process_time)) / number


def paired(f, g, reps: int, number: int) -> tuple[float, float]:
    """Best CPU time per call of ``f`` and of ``g``, timed alternately (``reps`` rounds of ``number`` calls)."""
    tf, tg = np.inf, np.inf
    for _ in range(reps):
        tf = min(tf, timeit.timeit(f, number=number, timer=time.process_time) / number)
        tg = min(tg, timeit.timeit(g, number=number, timer=time.process_time) / number)
    return tf, tg


@contextlib.contextmanager
def pure_norm():
    """Single-loop calls without slycot's AB13DD (the level-set norm of robustctl.analysis._hinfnorm)."""
    saved = _hinfnorm.slicot_ab13dd
    _hinfnorm.slicot_ab13dd = lambda: None  # type: ignore[assignment]
    try:
        yield
    finally:
        _hinfnorm.slicot_ab13dd = saved


def best_time(fn, reps: int):
    """``(fn(), best CPU time of reps calls)``."""
    out = fn()
    return out, cpu(fn, reps)


def robust_vs_polytopic(reps: int) -> dict:
    """Robust H-infinity for a norm-bounded payload model against the polytopic design, on the truck.

    Polytopic: ``vertices`` at 0, 100, 200 and 300 % overload (ZOH plants).
    Robust: the mid plant ``(P0 + P300) / 2`` with ``[dF dG] = H Delta [EF
    EG]`` from the SVD of ``(P300 - P0) / 2`` (rank 2: the two dynamic rows),
    so ``Delta = delta I`` spans the segment between the extreme payloads
    and every ``||Delta|| <= 1`` is covered. Both without input bound, Bw = G
    (steering disturbance), z = (rho, theta, alpha). Each design's level is
    checked on the ZOH plants at 0..300 % (13 points) with linfnorm.
    """
    from robustctl.models.truck import truck_plant

    lo, hi = truck_plant(0.0), truck_plant(300.0)
    vertices = [truck_plant(k) for k in (0.0, 100.0, 200.0, 300.0)]
    mid = rc.Plant(0.5 * (lo.F + hi.F), 0.5 * (lo.G + hi.G), lo.dt)
    U, sv, Vt = np.linalg.svd(0.5 * np.hstack([hi.F - lo.F, hi.G - lo.G]))
    r = int(np.sum(sv > 1e-12 * sv[0]))
    EFG = np.sqrt(sv[:r])[:, None] * Vt[:r]
    unc = rc.NormBounded(U[:, :r] * np.sqrt(sv[:r]), EFG[:, :4], EFG[:, 4:])
    Cz = np.array([[0.0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0]])
    Dzu = np.array([[0.0], [0.0], [1.0]])
    Bw = lo.G
    poly, t_poly = best_time(lambda: rc.hinf(vertices[0], Bw=Bw, Cz=Cz, Dzu=Dzu, vertices=vertices[1:]), reps)
    rob, t_rob = best_time(lambda: rc.hinf(mid, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=unc), reps)

    def worst(K):
        return max(float(control.linfnorm(control.ss(p.F + p.G @ K, Bw, Cz + Dzu @ K, np.zeros((3, 1)), p.dt),
                                           tol=1e-10)[0]) for p in (truck_plant(k) for k in np.linspace(0, 300, 13)))

    return dict(t_poly=t_poly, t_rob=t_rob, gamma_poly=poly.gamma, gamma_rob=rob.gamma, worst_poly=worst(poly.K),
                worst_rob=worst(rob.K), rank=r)


def single_rows(sizes, seeds: int, reps: int) -> list[str]:
    rows = []
    for discrete in (True, False):
        for n in sizes:
            t_rs, t_ref, ratios, diffs, sdp, how = [], [], [], [], 0, set()
            for seed in range(seeds):
                plant, K, unc = case(n, seed, discrete)
                E = unc.EF + unc.EG @ K
                res = rc.robust_stability((plant, K), unc)
                assert res.certified and min(res.certificate.values()) > 0, "margin 2 must be certified"
                sdp += res.info["path"] == "sdp"
                how.add(f"{res.info['norm']}, {res.info['riccati']}")
                gain = linfnorm(plant, K, unc.H, E)
                number = 20 if n <= 10 else 5
                t, t_l = paired(lambda: rc.robust_stability((plant, K), unc),
                                lambda: linfnorm(plant, K, unc.H, E), reps, number)
                t_rs.append(t)
                t_ref.append(t_l)
                ratios.append(t / t_l)
                diffs.append(abs(res.margin * gain - 1.0))
            row = (f"| {'discrete' if discrete else 'continuous'} | {n} | {1e3 * np.median(t_rs):.3f} "
                   f"| {1e3 * np.median(t_ref):.3f} | **{np.median(ratios):.2f}**, {max(ratios):.2f} "
                   f"| {max(diffs):.1e} | {sdp} | {'; '.join(sorted(how))} |")
            print(row, flush=True)
            rows.append(row)
    return rows


SINGLE_HEADER = [("| time | n | robust_stability [ms] | linfnorm [ms] | **ratio** (median, max) "
                  "| max rel. margin difference | SDP fallbacks | norm, Riccati |"),
                 "|---|---|---|---|---|---|---|---|"]


def batch_row(B: int, reps: int) -> tuple[str, float]:
    plant, K, unc = case(4, 0, True)
    rng = np.random.default_rng(1)
    Ks = K + 0.05 * np.abs(K).max() * rng.standard_normal((B, *K.shape))
    res = rc.robust_stability((plant, Ks), unc)
    E = unc.EF + unc.EG @ Ks
    gains = np.array([linfnorm(plant, Ks[b], unc.H, E[b]) for b in range(B)])
    diff = float(np.max(np.abs(res.margin * gains - 1.0)))
    t, t_l = paired(lambda: rc.robust_stability((plant, Ks), unc).margin,
                    lambda: [linfnorm(plant, Ks[b], unc.H, E[b]) for b in range(B)], reps, 1)
    t_c = cpu(lambda: rc.robust_stability((plant, Ks), unc).certified, reps)
    row = (f"| {B} | {1e3 * t:.2f} | {1e3 * t_c:.2f} | {1e3 * t_l:.2f} | **{t / t_l:.2f}** | {t_c / t_l:.2f} "
           f"| {diff:.1e} | {int(res.certified.sum())} | {res.info['sdp_solves']} |")
    print(row, flush=True)
    return row, t / t_l


def cost_row(B: int, reps: int) -> str:
    """``guaranteed_cost`` on a stack of ``B`` gains (Riccati search) against ``B`` single-gain SDP calls."""
    plant, K, unc = case(4, 0, True)
    rng = np.random.default_rng(2)
    Ks = K + 0.05 * np.abs(K).max() * rng.standard_normal((B, *K.shape))
    Q, R = np.eye(4), np.eye(2)
    res, t = best_time(lambda: rc.guaranteed_cost((plant, Ks), unc, Q, R), reps)
    start = time.process_time()
    ones = [rc.guaranteed_cost((plant, Ks[b]), unc, Q, R) for b in range(B)]
    t_s = time.process_time() - start
    diff = max(abs(res.bound[b] / ones[b].bound - 1.0) for b in range(B))
    row = (f"| {B} | {1e3 * t:.1f} | {1e3 * t_s:.0f} | **{t / t_s:.3f}** | {diff:.1e} "
           f"| {int((res.reason == 'ok').sum())} |")
    print(row, flush=True)
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 10, 20])
    ap.add_argument("--seeds", type=int, default=5, help="random loops per size and time domain")
    ap.add_argument("--reps", type=int, default=15, help="alternating timing rounds per loop")
    ap.add_argument("--cost-batch", type=int, default=20, help="gains in the guaranteed-cost row")
    ap.add_argument("--no-pure", dest="pure", action="store_false",
                    help="skip the table with the pure numpy/scipy level-set norm")
    ap.add_argument("--batch", type=int, default=92, help="gains of one plant in the batch row")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "analysis.md")
    args = ap.parse_args(argv)

    warm = case(3, 0, True)
    rc.robust_stability((warm[0], warm[1]), warm[2])  # fill caches
    command = "python -m benchmarks.bench_analysis " + " ".join(sys.argv[1:] if argv is None else argv)
    lines = [*header("bench_analysis: robust analysis against linfnorm (CPU times)", command.strip()),
             ("`robust_stability` of one loop with its certificate (H-infinity norm, bounded-real Riccati "
              "certificate verified by eigenvalues) against python-control's `linfnorm` of the same loop "
              "`E (zI - A)^-1 H`; p = 2, l = 3, m = 2, margin 2. CPU times, the two timed alternately: best of "
              f"{args.reps} rounds each per loop, ratio per loop, median and largest over {args.seeds} loops; "
              "target ratio <= 3. Norm: AB13DD through slycot when installed (the default)."), "",
             *SINGLE_HEADER]
    print("\n".join(lines), flush=True)
    lines += single_rows(args.sizes, args.seeds, args.reps)
    if args.pure:
        lines += ["", "The same with the pure numpy/scipy level-set norm (slycot's AB13DD switched off):", "",
                  *SINGLE_HEADER]
        print("\n".join(lines[-5:]), flush=True)
        with pure_norm():
            lines += single_rows(args.sizes, args.seeds, args.reps)
    lines += ["", (f"One call on a stack of {args.batch} gains of one plant (n = 4, discrete) against "
                   f"{args.batch} `linfnorm` calls; target ratio <= 0.5. The margins come with the call; the "
                   "certificates (`certified`, `P`, ...) are computed on first access, timed separately."), "",
              ("| B | margins, one call [ms] | with certificates [ms] | linfnorm, B calls [ms] | **ratio** margins "
               "| ratio with certificates | max rel. margin difference | certified | SDP fallbacks |"),
              "|---|---|---|---|---|---|---|---|---|"]
    row, _ = batch_row(args.batch, args.reps)
    lines.append(row)
    lines += ["", ("`guaranteed_cost` (n = 4, discrete, Q = I, R = I, worst unit x0) on a stack of "
                   f"{args.cost_batch} gains (bounded-real Riccati solutions, golden-section search over the "
                   "multiplier, all designs at once) "
                   f"against {args.cost_batch} single-gain calls (one SDP each, Clarabel, timed once), best of "
                   f"{min(args.reps, 5)}:"), "",
              "| B | stack, one call [ms] | single calls [ms] | **ratio** | max rel. bound difference | bounds |",
              "|---|---|---|---|---|---|"]
    lines.append(cost_row(args.cost_batch, min(args.reps, 5)))
    rb = robust_vs_polytopic(min(args.reps, 3))
    lines += ["", ("Robust H-infinity synthesis (`hinf(..., uncertainty=)`: a norm-bounded payload model of the truck, "
                   f"rank {rb['rank']}) against the polytopic design (4 payload vertices), no input bound, best of "
                   f"{min(args.reps, 3)}:"), "",
              "| design | time [s] | gamma | worst linfnorm on 0-300 % (13 plants) |", "|---|---|---|---|",
              f"| polytopic | {rb['t_poly']:.3f} | {rb['gamma_poly']:.5g} | {rb['worst_poly']:.5g} |",
              f"| robust (norm-bounded) | {rb['t_rob']:.3f} | {rb['gamma_rob']:.5g} | {rb['worst_rob']:.5g} |",
              f"| **ratio** robust / polytopic | **{rb['t_rob'] / rb['t_poly']:.2f}** | | |"]
    print("\n".join(lines[-7:]), flush=True)
    write(lines, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
