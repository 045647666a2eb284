"""Benchmark: H-infinity state feedback, both paths of robustctl.hinf, against an independent peer.

All run in the same process on the same plants. The peer is written here and
shares no code with robustctl: a geometric bisection (``rtol=1e-8``) on the
game Riccati equation solved by python-control's ``dare`` (SLICOT SG02AD
through slycot), feasibility read from its closed-loop eigenvalues, the
sign of the solution and the disturbance block (about 30 DARE solves).
``synthesis="riccati"`` is the fast path (validation, balancing, the
bisection, the saddle-point gain and its LMI certificate checked by
eigenvalues); ``synthesis="lmi"`` (the default) is one cvxpy/Clarabel solve
(minimise gamma) and a Riccati-built certificate of the optimum's gain at
the backed-off level, including cvxpy's compilation. ``norm/gamma`` is
python-control's ``linfnorm`` of the fast path's closed loop over its
guaranteed level (< 1).

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

``--before ROOT`` times only the SDP path (the whole ``hinf`` call, CPU time of the process and wall-clock time) of the
checkout at ROOT (e.g. the main branch) against this one, each in a fresh subprocess that imports
``robustctl`` from its own tree, alternating the two for ``--rounds`` rounds and taking medians (on a
shared machine the load changes between runs; interleaving spreads it over both).

Results are written to ``benchmarks/results/hinf.md`` (``--before``: ``hinf_before_after.md``; ``--out``
another file) and shown in the documentation as they are.

Usage: python -m benchmarks.bench_hinf [--sizes 4 10 20 50] [--reps 3] [--seeds 5] [--sdp-max-n 50] [--out FILE]
       python -m benchmarks.bench_hinf --before /work/main [--sizes 4 10 20] [--rounds 5] [--reps 3] [--out FILE]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import inspect  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import control  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks._report import header, write  # noqa: E402
from robustctl import (  # noqa: E402
    Plant,
    hinf,
    lq_output,
)


# ---------------------------------------------------------------- the independent peer
def peer_level(F, G, Bw, Cz, Dzu, Dzw, gamma):
    """One level of the peer: python-control's ``dare`` (SLICOT SG02AD) on the game Riccati equation.

    Feasible iff the stabilising solution exists, is >= 0, its closed loop is stable and the disturbance
    block ``Bw'PBw + Dzw'Dzw - gamma^2 I`` is negative definite (state feedback). Returns the gain or None.
    """
    m, q = G.shape[1], Bw.shape[1]
    B, D = np.hstack([G, Bw]), np.hstack([Dzu, Dzw])
    R = D.T @ D - np.diag(np.r_[np.zeros(m), np.full(q, gamma**2)])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            X, L, Kg = control.dare(F, B, Cz.T @ Cz, R, Cz.T @ D)
    except (ArithmeticError, ValueError, RuntimeError, Warning):  # slycot errors, results-as-warnings: none
        return None
    if not np.all(np.isfinite(X)) or np.max(np.abs(L)) >= 1.0:
        return None
    if np.linalg.eigvalsh(0.5 * (X + X.T)).min() < -1e-8 * max(1.0, float(np.abs(X).max())):
        return None
    if np.linalg.eigvalsh(Bw.T @ X @ Bw + Dzw.T @ Dzw - gamma**2 * np.eye(q)).max() >= 0.0:
        return None
    return -Kg[:m]


def peer_hinf(plant, Bw, Cz, Dzu, rtol=1e-8):
    """The peer: geometric bisection on ``gamma`` (start at 1, doubled until feasible) with :func:`peer_level`."""
    F, G = plant.F, plant.G
    Dzw = np.zeros((Cz.shape[0], Bw.shape[1]))
    lo, hi = 0.0, 1.0
    while (K := peer_level(F, G, Bw, Cz, Dzu, Dzw, hi)) is None:
        lo, hi = hi, 2.0 * hi
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        Km = peer_level(F, G, Bw, Cz, Dzu, Dzw, mid)
        if Km is None:
            lo = mid
        else:
            hi, K = mid, Km
    return hi, K


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
    from robustctl.models.morais2022 import authors_weights
    from robustctl.models.truck import truck_plant

    plant = truck_plant(0.0)
    Q, R = authors_weights()
    Bw, (Cz, Dzu) = np.ones((4, 1)), lq_output(Q, R)
    s = 1.0 / np.sqrt(R[0, 0])
    raw, t_raw = best_time(lambda: hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu), reps)
    by_hand, t_hand = best_time(lambda: hinf(plant, Bw=Bw, Cz=s * Cz, Dzu=s * Dzu), reps)
    ric, _ = peer_hinf(plant, Bw, Cz, Dzu)
    return dict(t_raw=t_raw, t_hand=t_hand, gamma_raw=raw.gamma_opt, gamma_hand=by_hand.gamma_opt / s,
                gamma_ric=ric)


def cl_norm(plant, K, Bw, Cz, Dzu) -> float:
    """||T_zw||_inf of the closed loop by python-control (SLICOT AB13DD)."""
    sys = control.ss(plant.F + plant.G @ K, Bw, Cz + Dzu @ K, np.zeros((Cz.shape[0], Bw.shape[1])), plant.dt)
    return float(control.linfnorm(sys, tol=1e-10)[0])


# The SDP path of one checkout, timed in a subprocess (``robustctl`` imported from ROOT via PYTHONPATH):
# the plants of ``case`` (its source, inserted below) rebuilt from the same seeds; prints the median CPU and
# wall-clock times per call and gamma_opt.
_TIMER = """
import json, sys, time
import numpy as np
from robustctl import Plant
from robustctl import hinf
n, seed, reps = (int(a) for a in sys.argv[1:4])
{case}
w = case(3, 0)
hinf(w[0], Bw=w[1], Cz=w[2], Dzu=w[3])
plant, Bw, Cz, Dzu = case(n, seed)
cpu, wall = [], []
for _ in range(reps):
    t0, w0 = time.process_time(), time.perf_counter()
    ctrl = hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    cpu.append(time.process_time() - t0)
    wall.append(time.perf_counter() - w0)
print(json.dumps({{"cpu": float(np.median(cpu)), "wall": float(np.median(wall)), "gamma_opt": ctrl.gamma_opt,
                  "iterations": ctrl.info["iterations"]}}))
"""


def sdp_times(root: str, n: int, seed: int, reps: int) -> dict:
    """Median CPU and wall-clock times of ``reps`` SDP-path calls of the checkout at ``root`` (a fresh subprocess)."""
    env = dict(os.environ, PYTHONPATH=str(Path(root).resolve()))
    code = _TIMER.format(case=inspect.getsource(case))
    out = subprocess.run([sys.executable, "-c", code, str(n), str(seed), str(reps)], env=env, cwd=root,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def before_after(before: str, sizes, rounds: int, reps: int, out: Path) -> None:
    """The SDP path of ``before`` against this checkout, alternating in fresh subprocesses; medians over rounds."""
    here = Path(__file__).resolve().parents[1]
    lines = header("H-infinity SDP path: another checkout against this one",
                    f"python -m benchmarks.bench_hinf --before {before} --sizes {' '.join(map(str, sizes))} "
                    f"--rounds {rounds} --reps {reps}")
    lines += [(f"The whole `rc.hinf(...)` call (default `synthesis=\"lmi\"`) on the plant `case(n, 0)`: CPU time per "
               f"call (of the process, all threads), median of {reps} calls per round, median over {rounds} rounds, "
               "the two checkouts alternating, each in a fresh process importing its own tree; the same for the "
               f"wall-clock time. Before: `{before}` (commit {_commit(before)}); after: this checkout (commit "
               f"{_commit(str(here))})."), "",
              ("| n | before [s] | after [s] | **before / after** | per-round range before / after | "
               "wall: before / after [s] (ratio) | iterations before / after | `gamma_opt` after / before - 1 |"),
              "|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    for n in sizes:
        b, a = [], []
        for _ in range(rounds):
            b.append(sdp_times(before, n, 0, reps))
            a.append(sdp_times(str(here), n, 0, reps))
        tb, ta = np.median([r["cpu"] for r in b]), np.median([r["cpu"] for r in a])
        wb, wa = np.median([r["wall"] for r in b]), np.median([r["wall"] for r in a])
        spread = " / ".join(f"{min(r['cpu'] for r in x):.3g}-{max(r['cpu'] for r in x):.3g}" for x in (b, a))
        lines.append(f"| {n} | {tb:.3g} | {ta:.3g} | **{tb / ta:.2f}** | {spread} | {wb:.3g} / {wa:.3g} "
                     f"({wb / wa:.2f}) | {b[0]['iterations']} / {a[0]['iterations']} | "
                     f"{a[0]['gamma_opt'] / b[0]['gamma_opt'] - 1:.1e} |")
        print(lines[-1], flush=True)
    write(lines, out)


def _commit(root: str) -> str:
    """The short commit of the checkout at ``root`` (``?`` if git cannot tell)."""
    try:
        return subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 10, 20, 50])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=5, help="random plants per size (one for n > 10)")
    ap.add_argument("--sdp-max-n", type=int, default=50, help="largest n for the SDP path (about 90 s at n = 50)")
    ap.add_argument("--before", help="another checkout: time its SDP path against this one's (only that)")
    ap.add_argument("--rounds", type=int, default=5, help="alternating rounds for --before")
    ap.add_argument("--out", type=Path, help="result file (default benchmarks/results/hinf.md, with --before "
                                             "benchmarks/results/hinf_before_after.md)")
    args = ap.parse_args(argv)
    results = Path(__file__).parent / "results"
    if args.before:
        before_after(args.before, args.sizes, args.rounds, args.reps, args.out or results / "hinf_before_after.md")
        return

    warm = case(3)
    for synthesis in ("lmi", "riccati"):  # import cvxpy, fill caches
        hinf(warm[0], Bw=warm[1], Cz=warm[2], Dzu=warm[3], synthesis=synthesis)
    peer_hinf(*warm)

    lines = header("H-infinity state feedback: the riccati fast path and the SDP against an independent peer",
                    f"python -m benchmarks.bench_hinf --sizes {' '.join(map(str, args.sizes))} --reps {args.reps} "
                    f"--seeds {args.seeds} --sdp-max-n {args.sdp_max_n}")
    lines += [(f"Random discrete plants `case(n, seed)` ({args.seeds} per n up to 10, one above; m = 2, q = 2, p = 4, "
               "F scaled to spectral radius 1.05). Wall-clock times, best of "
               f"{args.reps} runs (at least 3 for the peer and the fast path; one run above n = 10), BLAS on one "
               "thread; ratios per plant against the peer timed beside it. **peer**: the game-Riccati bisection "
               "of this script on python-control's `dare`; **riccati**: `hinf(..., synthesis=\"riccati\")`; "
               "**SDP**: `hinf(...)` (cvxpy + Clarabel). rel: `gamma_opt` / the peer's - 1. norm / gamma: "
               "`linfnorm` of the fast path's closed loop over its guaranteed level."), "",
              ("| n | seed | peer [s] | riccati [s] | riccati / peer | SDP [s] | SDP / peer | gamma (peer) | "
               "rel riccati | rel SDP | norm / gamma | fast path |"),
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    summary = ["", "| n | plants | riccati / peer: median (max) | SDP / peer: median (max) |", "|---|---|---|---|"]
    for n in args.sizes:
        reps, seeds = (args.reps, args.seeds) if n <= 10 else (1, 1)
        r_fast, r_sdp = [], []
        for seed in range(seeds):
            plant, Bw, Cz, Dzu = case(n, seed)
            (g_peer, _), t_peer = best_time(lambda: peer_hinf(plant, Bw, Cz, Dzu), max(reps, 3))
            fast, t_fast = best_time(lambda: hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, synthesis="riccati"), max(reps, 3))
            r_fast.append(t_fast / t_peer)
            t_sdp_s = ratio_s = rel_s = "-"
            if n <= args.sdp_max_n:
                sdp, t_sdp = best_time(lambda: hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu), reps)
                r_sdp.append(t_sdp / t_peer)
                t_sdp_s, ratio_s, rel_s = f"{t_sdp:.3g}", f"{t_sdp / t_peer:.3g}", f"{sdp.gamma_opt / g_peer - 1:.1e}"
            norm = cl_norm(plant, fast.K, Bw, Cz, Dzu)
            cols = [n, seed, f"{t_peer:.3g}", f"{t_fast:.3g}", f"{t_fast / t_peer:.2f}", t_sdp_s, ratio_s,
                    f"{g_peer:.8g}", f"{fast.gamma_opt / g_peer - 1:.1e}", rel_s, f"{norm / fast.gamma:.6f}",
                    fast.info["synthesis"]]
            lines.append(f"| {' | '.join(map(str, cols))} |")
            print(lines[-1], flush=True)
        sdp_sum = f"{np.median(r_sdp):.3g} ({max(r_sdp):.3g})" if r_sdp else "-"
        summary.append(f"| {n} | {seeds} | **{np.median(r_fast):.2f}** ({max(r_fast):.2f}) | **{sdp_sum}** |")
    lines += summary
    ctrl, t_truck = truck_case(args.reps)
    un = units(args.reps)
    lines += ["", (f"Truck (n = 4, m = 1, 4 payload vertices, steering bound 0.45 rad), SDP path: {t_truck:.3f} s, "
                   f"gamma = {ctrl.gamma:.6g}, guaranteed max |alpha| = {ctrl.info['u_bound'][0]:.4f} rad."), "",
              (f"Truck with the authors' weights (R = 33535, Bw = ones), unscaled against z / sqrt(r) by hand: time "
               f"{un['t_raw']:.3f} s against {un['t_hand']:.3f} s (ratio {un['t_raw'] / un['t_hand']:.2f}); "
               f"gamma_opt {un['gamma_raw']:.10g} against {un['gamma_hand']:.10g}, peer bisection (unscaled) "
               f"{un['gamma_ric']:.10g}.")]
    print("\n".join(lines[-len(summary) - 4:]), flush=True)
    write(lines, args.out or results / "hinf.md")


if __name__ == "__main__":
    main()
