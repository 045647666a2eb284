"""Benchmark: output-feedback H-infinity, both paths of robustctl.hinf, against python-control's hinfsyn.

All in one process on the same plants. The peer is python-control's
``hinfsyn`` (SLICOT SB10AD through slycot, its bisection started at
``gamma = 1e100``) on the generalised plant ``[[Dzw, Dzu], [Dyw, D]]``.
``synthesis="riccati"`` is the gamma-iteration on the two Riccati equations
with the central controller and its closed-loop certificate (validation,
scalings and the final checks included); ``synthesis="lmi"`` (the default)
is the shaping Riccati bisection, two cvxpy/Clarabel solves (the level, then
a centring at the backed-off level) and the reconstruction, cvxpy's
compilation included. ``norm / gamma`` is python-control's ``linfnorm`` of
the returned controller's closed loop (assembled by python-control) over the
guaranteed level (< 1); ``hinfsyn CL / gamma`` the same for hinfsyn's own
controller and level, which shows where hinfsyn's answer is not consistent
(its level is then not a reference).

Plants: random continuous, ``case(n, seed)``: ``A`` random and shifted to a
spectral abscissa of 0.1 (unstable), m = 2 inputs, p = 2 measured outputs,
``w`` = 2 process and 2 measurement noises (``Dyw = [0 I]``), ``z`` = 2
state combinations and the inputs (``Dzu = [0; I]``): regular problems.
Times are the best of ``--reps`` runs (one above n = 20) after a warm-up
that imports cvxpy; BLAS on one thread unless the environment says
otherwise.

Results are written to ``benchmarks/results/hinf_output.md`` (``--out``
another file) and shown in the documentation as they are.

Usage: python -m benchmarks.bench_hinf_output [--sizes 4 10 20 50] [--seeds 3] [--reps 3] [--lmi-max-n 20]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import control  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks._report import header, write  # noqa: E402
from robustctl import Plant, hinf  # noqa: E402


def case(n: int, seed: int = 0):
    """``(plant, channel)`` of a random regular continuous problem (module docstring)."""
    rng = np.random.default_rng(seed)
    m = p = q = 2
    A = rng.normal(size=(n, n)) / np.sqrt(n)
    A += (0.1 - np.max(np.linalg.eigvals(A).real)) * np.eye(n)
    plant = Plant(A, rng.normal(size=(n, m)), None, C=rng.normal(size=(p, n)))
    ch = dict(Bw=np.hstack([rng.normal(size=(n, q)), np.zeros((n, p))]),
              Cz=np.vstack([rng.normal(size=(2, n)), np.zeros((m, n))]),
              Dzu=np.vstack([np.zeros((2, m)), np.eye(m)]), Dyw=np.hstack([np.zeros((p, q)), np.eye(p)]))
    return plant, ch


def generalised(plant: Plant, Bw, Cz, Dzu, Dyw):
    """python-control's generalised plant ``[w; u] -> [z; y]``."""
    C, D = plant.output_matrices()
    return control.ss(plant.F, np.hstack([Bw, plant.G]), np.vstack([Cz, C]),
                      np.block([[np.zeros((Cz.shape[0], Bw.shape[1])), Dzu], [Dyw, D]]))


def best_time(fn, reps: int):
    out, best = None, np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def norm_ratio(P, ctrl) -> float:
    """``linfnorm`` of the closed loop assembled by python-control over the guaranteed level."""
    return float(control.linfnorm(P.lft(ctrl.controller_statespace()), tol=1e-10)[0]) / ctrl.gamma


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 10, 20, 50])
    ap.add_argument("--seeds", type=int, default=3, help="random plants per size (one above n = 20)")
    ap.add_argument("--reps", type=int, default=3, help="runs per timing, the best kept (one above n = 20)")
    ap.add_argument("--lmi-max-n", type=int, default=20, help="largest n for the LMI path")
    ap.add_argument("--out", type=Path, help="result file (default benchmarks/results/hinf_output.md)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")          # slycot's and cvxpy's warnings would interleave with the table

    warm, wch = case(3)
    for synthesis in ("lmi", "riccati"):     # import cvxpy, fill caches
        hinf(warm, **wch, synthesis=synthesis)
    control.hinfsyn(generalised(warm, **wch), 2, 2)

    lines = header("Output-feedback H-infinity: the Riccati path and the LMI path against python-control's hinfsyn",
                    f"python -m benchmarks.bench_hinf_output --sizes {' '.join(map(str, args.sizes))} "
                    f"--seeds {args.seeds} --reps {args.reps} --lmi-max-n {args.lmi_max_n}")
    lines += [(f"Random regular continuous plants `case(n, seed)` ({args.seeds} per n up to 20, one above; m = 2, "
               "p = 2, w = 2 process + 2 measurement noises, z = 2 state combinations + u). Wall-clock times of "
               f"the whole call, best of {args.reps} runs (one above n = 20), BLAS on one thread; ratios per plant "
               "against hinfsyn timed beside it. **hinfsyn**: `control.hinfsyn` (SLICOT SB10AD); **riccati**: "
               "`hinf(plant, ..., synthesis=\"riccati\")`; **LMI**: `hinf(plant, ...)` (cvxpy + Clarabel, "
               "compilation included). rel: `gamma_opt` / hinfsyn's level - 1. norm / gamma: python-control's "
               "`linfnorm` of the returned controller's closed loop over its guaranteed level. hinfsyn CL / gamma: "
               "the same for hinfsyn's own controller (far from 1: hinfsyn's level is not consistent with its "
               "controller on that plant)."), "",
              ("| n | seed | hinfsyn [s] | riccati [s] | **riccati / hinfsyn** | LMI [s] | **LMI / hinfsyn** | "
               "gamma (hinfsyn) | hinfsyn CL / gamma | rel riccati | rel LMI | norm / gamma riccati | "
               "norm / gamma LMI | LMI solves |"),
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    summary = ["", "| n | plants | riccati / hinfsyn: median (max) | LMI / hinfsyn: median (max) |",
               "|---|---|---|---|"]
    for n in args.sizes:
        reps, seeds = (args.reps, args.seeds) if n <= 20 else (1, 1)
        r_fast, r_lmi = [], []
        for seed in range(seeds):
            plant, ch = case(n, seed)
            P = generalised(plant, **ch)
            (_, CL, gam, _), t_peer = best_time(lambda: control.hinfsyn(P, plant.p, plant.m), reps)
            peer_ratio = float(control.linfnorm(CL, tol=1e-10)[0]) / gam
            fast, t_fast = best_time(lambda: hinf(plant, **ch, synthesis="riccati"), max(reps, 3))
            r_fast.append(t_fast / t_peer)
            cols_lmi = ["-"] * 5
            if n <= args.lmi_max_n:
                lmi, t_lmi = best_time(lambda: hinf(plant, **ch), reps)
                r_lmi.append(t_lmi / t_peer)
                cols_lmi = [f"{t_lmi:.3g}", f"**{t_lmi / t_peer:.2f}**", f"{lmi.gamma_opt / gam - 1:.1e}",
                            f"{norm_ratio(P, lmi):.6f}",
                            ", ".join(f"{s['status']} ({s['iterations']})" for s in lmi.info["solves"])]
            cols = [n, seed, f"{t_peer:.3g}", f"{t_fast:.3g}", f"**{t_fast / t_peer:.3f}**", *cols_lmi[:2],
                    f"{gam:.8g}", f"{peer_ratio:.4f}", f"{fast.gamma_opt / gam - 1:.1e}", cols_lmi[2],
                    f"{norm_ratio(P, fast):.6f}" + ("" if fast.info["synthesis"] == "riccati" else " (fell back)"),
                    *cols_lmi[3:]]
            lines.append(f"| {' | '.join(map(str, cols))} |")
            print(lines[-1], flush=True)
        lmi_sum = f"**{np.median(r_lmi):.2f}** ({max(r_lmi):.2f})" if r_lmi else "-"
        summary.append(f"| {n} | {seeds} | **{np.median(r_fast):.3f}** ({max(r_fast):.3f}) | {lmi_sum} |")
    lines += summary
    print("\n".join(summary), flush=True)
    write(lines, args.out or Path(__file__).parent / "results" / "hinf_output.md")


if __name__ == "__main__":
    main()
