"""Benchmark: LMI H-infinity synthesis (robustctl.hinf) against the game-Riccati bisection.

Both run in the same process on the same plants. The peer is
``robustctl.hinf_riccati.hinf_riccati`` with ``rtol=1e-8`` (about the
accuracy of the LMI optimum at Clarabel's 1e-8 tolerance), i.e. ~35
Riccati solves with residual checks. For these discrete plants the LMI path
is one cvxpy/Clarabel solve (minimise gamma) and a Riccati-built certificate
of the optimum's gain at the backed-off level, including cvxpy's
compilation; the centring solve runs only when that certificate fails.

Plants: random discrete-time (``--seeds`` of them per size), slightly unstable, m = 2 inputs, q = 2
disturbances, p = 4 performance outputs (2 state combinations and the
inputs, Dzu' Cz = 0). Times are the best of ``--reps`` runs (after one
warm-up that imports cvxpy). BLAS threads are pinned to 1 unless the
environment says otherwise (on a shared 2-core machine multithreaded BLAS
makes the Riccati timings erratic).

Last lines: the truck polytope with the steering limit, and the truck with
the weights of the authors' code given unscaled against the same channels
scaled by hand (:func:`units`: the synthesis scales them inside, so both are
the same problem for the solver). Robust against polytopic H-infinity on the
truck is in ``bench_analysis.py``.

Usage: python benchmarks/bench_hinf.py [--sizes 4 10 20] [--reps 3] [--seeds 5]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from robustctl import Plant  # noqa: E402
from robustctl.hinf import hinf  # noqa: E402
from robustctl.hinf_riccati import hinf_riccati  # noqa: E402


def case(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    m, q, p = 2, 2, 4
    F = rng.normal(size=(n, n))
    F *= 1.05 / np.max(np.abs(np.linalg.eigvals(F)))
    G, Bw = rng.normal(size=(n, m)), rng.normal(size=(n, q))
    Cz = np.vstack([rng.normal(size=(p - m, n)), np.zeros((m, n))])
    Dzu = np.vstack([np.zeros((p - m, m)), np.eye(m)])
    return Plant(F, G, 0.1), Bw, Cz, Dzu


def best_time(fn, reps: int):
    out, best = None, np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def truck_case(reps: int):
    from robustctl.models.truck import STEER_LIMIT, truck_plant

    plants = [truck_plant(k) for k in (0.0, 100.0, 200.0, 300.0)]
    Cz = np.array([[0.0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0]])
    Dzu = np.array([[0.0], [0.0], [1.0]])
    return best_time(lambda: hinf(plants[0], Bw=plants[0].G, Cz=Cz, Dzu=Dzu, vertices=plants[1:],
                                  u_max=STEER_LIMIT, w_energy=1.0), reps)


def units(reps: int) -> dict:
    """The truck with ``Q = diag(1, 1, 25000, 100)``, ``R = 33535``, ``Bw = ones``: unscaled vs ``z / sqrt(r)``."""
    from robustctl.models.truck import authors_weights, truck_plant

    plant = truck_plant(0.0)
    Q, R = authors_weights()
    Bw, Cz, Dzu = np.ones((4, 1)), np.vstack([np.sqrt(Q), np.zeros((1, 4))]), np.vstack([np.zeros((4, 1)), np.sqrt(R)])
    s = 1.0 / np.sqrt(R[0, 0])
    raw, t_raw = best_time(lambda: hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu), reps)
    by_hand, t_hand = best_time(lambda: hinf(plant, Bw=Bw, Cz=s * Cz, Dzu=s * Dzu), reps)
    ric = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    return dict(t_raw=t_raw, t_hand=t_hand, gamma_raw=raw.gamma_opt, gamma_hand=by_hand.gamma_opt / s,
                gamma_ric=ric.gamma)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 10, 20])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=5, help="random plants per size (one for n > 10)")
    args = ap.parse_args(argv)

    warm = case(3)
    hinf(warm[0], Bw=warm[1], Cz=warm[2], Dzu=warm[3])  # import cvxpy, JIT nothing, fill caches

    print(f"{'n':>4} {'seed':>4} {'LMI [s]':>9} {'solver [s]':>10} {'Riccati [s]':>11} {'ratio':>7} "
          f"{'gamma LMI':>13} {'gamma Ric':>13} {'rel diff':>9}  gain from")
    summary = []
    for n in args.sizes:
        reps, seeds = (args.reps, args.seeds) if n <= 10 else (1, 1)
        ratios = []
        for seed in range(seeds):
            plant, Bw, Cz, Dzu = case(n, seed)
            ctrl, t_lmi = best_time(lambda: hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu), reps)
            ref, t_ric = best_time(lambda: hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-8), max(reps, 3))
            ratios.append(t_lmi / t_ric)
            print(f"{n:4d} {seed:4d} {t_lmi:9.3f} {ctrl.info['solve_time']:10.3f} {t_ric:11.3f} "
                  f"{t_lmi / t_ric:7.2f} {ctrl.gamma_opt:13.8g} {ref.gamma:13.8g} "
                  f"{ctrl.gamma_opt / ref.gamma - 1:9.1e}  {ctrl.info['gain_from']}")
        summary.append(f"n = {n}: ratio median {np.median(ratios):.2f}, max {max(ratios):.2f} "
                       f"over {seeds} plant{'s' if seeds > 1 else ''}")
    print("\n".join(summary))

    ctrl, t_truck = truck_case(args.reps)
    print(f"truck (n=4, m=1, 4 payload vertices, |alpha| <= 0.45 rad): {t_truck:.3f} s, "
          f"gamma = {ctrl.gamma:.6g}, guaranteed max |alpha| = {ctrl.info['u_bound'][0]:.4f} rad")
    un = units(args.reps)
    print(f"truck, authors' weights (R = 33535, Bw = ones), unscaled vs z / sqrt(r) by hand: time {un['t_raw']:.3f} s "
          f"vs {un['t_hand']:.3f} s (ratio {un['t_raw'] / un['t_hand']:.2f}); gamma_opt {un['gamma_raw']:.10g} vs "
          f"{un['gamma_hand']:.10g}, Riccati bisection (unscaled) {un['gamma_ric']:.10g}")


if __name__ == "__main__":
    main()
