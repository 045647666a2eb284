"""Reproduce the paper's Monte Carlo design selection (Sections 4.4.1 and 4.5.1, Figs. fl-generic / fl-applied).

    .venv/bin/python paper_repro/design_selection.py --problem generic|applied [--setup authors|ours]
        [--algorithm nsga2] [--molsp | --no-molsp] [--evals 3000] [--seed 1] [--sims N]
        [--horizon-steps N] [--pop-size 92] [--out DIR]

1. One MOEA run (:func:`moo.runner.run`, NSGA-II/MO-LSP by default as in the
   paper, population 92, ``--evals`` evaluations) gives a Pareto front.
2. The candidate designs are the front's decision vectors, sorted by the first
   objective (design 1 has the smallest f1), then the paper's extra designs:
   *nominal* (LQR with the same Q, R), [*RLQR^A* (appendix, applied problem only),]
   *random* (a uniformly random z); see :mod:`moo.problems.selection`.
3. ``--sims`` realisations ``Delta ~ U(-1, 1)`` (default 1000 generic, 200
   applied; the paper used 1000 for both): every design is simulated on every
   realisation and the one with the least cumulative error wins
   (:func:`moo.problems.selection.select_design`). Generic: ``Delta`` is the plant's
   uncertainty, the error the summed regulation error of the three states.
   Applied: ``Delta`` is the payload overload ``150 (1 + Delta)`` in [0, 300] %,
   the error the squared tracking error weighted by the set-up's ``Q``, summed
   over time.
4. The most frequent winner is ``z*``; its certified robust-stability margin
   (:func:`robustctl.robust_stability`) is reported: applied, against the
   payload polytope (0-300 %) and the appendix's norm-bounded model
   (:func:`robustctl.analysis.margins_report` with the models of
   ``truck_margins.py``); generic, against the problem's
   true norm-bounded uncertainty ``H Delta [EF_true EG_true]``.

``--setup`` (applied problem only): ``authors`` (default) or ``ours``, the
loop, initial state and weights of :data:`robustctl.models.morais2022.SETUPS`, for
the MOEA, the candidate designs and the selection alike
(``make_problem("applied", setup=...)``). The default is that of
``paper_repro/mse_table.py`` (``DEFAULT_SETUP`` of ``mse_designs.py``,
one constant for both scripts), so the chain selection -> MSE table runs in
one set-up: every script of ``paper_repro`` reproduces the paper, and the
authors' set-up reproduces its MSE table better (``mse_table.py`` prints the
agreement of both). ``ours`` is the engineering set-up; the printed MSE-table
command always names the set-up explicitly.

``--horizon-steps N`` shortens the selection's simulations only (generic:
regulation horizon N steps instead of 200; applied: the first N samples of
the route, N * 0.1 s, instead of 5400); the MOEA always uses the problem's
defaults. The default settings take well under a minute on 2 cores
(measured on the loaded 2-core machine: generic about 6 s, applied about
8 s in all, imports and the MOEA included; the simulations run on the
compiled kernel, :mod:`robustctl.sim.simulator`).

Writes ``DIR/selection.json`` (settings, z*, win counts of every design, the
winner's margins, the front's objectives, timings) and
``DIR/selection_histogram.png`` (default ``DIR``: ``out/selection_generic``,
``out/selection_applied_<setup>``). For the applied problem it also prints the
command that feeds ``z*`` to the MSE table (``paper_repro/mse_table.py --setup
<setup> --z``), run with the interpreter running this script (``sys.executable``).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np
from mse_designs import DEFAULT_SETUP
from truck_margins import truck_margins

import robustctl as rc
from moo.algorithms import ALGORITHMS
from moo.problems.applied import AppliedRLQRProblem
from moo.problems.generic import GenericRLQRProblem
from moo.problems.selection import DesignSelection, error_scales, select_design
from moo.runner import run as run_moea
from robustctl.models.morais2022 import SETUPS

DEFAULT_SIMS = {"generic": 1000, "applied": 200}
PAPER = {"generic": "paper: design 49 of 92 won 222/1000; random 1, nominal 0",
         "applied": "paper: design 31 of 92 won 319/1000 (design 41: 310); RLQR^A 205, nominal 0, random 0"}
EXTRA_COLORS = {"nominal": "tab:green", "rlqr_a": "tab:orange", "random": "tab:gray"}


def _algorithm_name(algorithm: str, molsp: bool) -> str:
    name = {"nsga2": "NSGA-II", "nsga3": "NSGA-III"}.get(algorithm, algorithm.upper())
    return name + ("/MO-LSP" if molsp else "")


def _problem(name: str, horizon_steps: int | None, setup: str | None):
    """The problem the selection simulates on, and the path for the applied one."""
    if name == "generic":
        if setup is not None:
            raise ValueError("--setup applies to the applied problem only")
        prob = GenericRLQRProblem() if horizon_steps is None else GenericRLQRProblem(horizon=horizon_steps)
        return prob, None
    prob = AppliedRLQRProblem(setup=setup or DEFAULT_SETUP)
    path = prob.path if horizon_steps is None else prob.path.truncated(horizon_steps * prob.path.dt)
    return prob, path


def winner_margins(problem, K: np.ndarray) -> dict[str, float | None]:
    """Certified robust-stability margins of the selected gain ``K`` (module docstring, step 4)."""
    if not np.all(np.isfinite(K)):
        return {}
    if isinstance(problem, AppliedRLQRProblem):
        steer = rc.InputMemoryFeedback(K.sum(axis=0, keepdims=True))       # alpha = u1 + ... + um
        found = dict(truck_margins({"winner": steer}).results["winner"])
    else:
        unc = rc.NormBounded(problem.H, problem.EF_true, problem.EG_true)
        found = {"true norm-bounded uncertainty": rc.robust_stability((problem.plant, K), unc)}
    return {k: (None if isinstance(m, str) else float(m.margin)) for k, m in found.items()}


def histogram(sel: DesignSelection, title: str, out: Path) -> None:
    """Bar chart of the win counts in the paper's style: x design index 1..D, y number of wins."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    d = sel.designs
    counts = sel.result.counts
    D, N = len(d), d.n_front
    x = np.arange(1, D + 1)
    colors = ["tab:blue" if k == "front" else EXTRA_COLORS[k] for k in d.kinds]
    colors[sel.best] = "tab:red"
    fig, ax = plt.subplots(figsize=(11, 4.5))
    ax.bar(x, counts, width=0.8, color=colors)
    top = max(int(counts.max()), 1)
    ax.set_ylim(0, top * 1.25)
    # ticks: every 10th front design and the last index; the extra designs are
    # marked under the axis and named in the legend with their index and wins
    step = 10 if N > 30 else (5 if N > 10 else 1)
    ticks = sorted({1, D, *(t for t in range(step, D + 1, step) if D - t > step // 3)})
    ax.set_xticks(ticks)
    handles = [Patch(color="tab:blue", label=f"Pareto-front designs 1-{N}"),
               Patch(color="tab:red", label=f"winner z* = design {d.labels[sel.best]} "
                                            f"({int(counts[sel.best])} wins)")]
    for i, k in enumerate(d.kinds):
        if k != "front":
            ax.plot(i + 1, 0, marker="^", ms=8, color=EXTRA_COLORS[k], clip_on=False, zorder=3)
            handles.append(Line2D([], [], ls="", marker="^", ms=8, color=EXTRA_COLORS[k],
                                  label=f"{i + 1}: {d.labels[i].replace('^A', '$^A$')} ({int(counts[i])} wins)"))
    ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.9)
    ax.annotate(f"z* = design {d.labels[sel.best]}: {int(counts[sel.best])} wins",
                (sel.best + 1, counts[sel.best]), textcoords="offset points", xytext=(8, 4),
                fontsize=9, color="tab:red")
    ax.axvline(N + 0.5, color="0.6", lw=0.8, ls="--")
    ax.set_xlim(0.3, D + 0.7)
    ax.set_xlabel(f"design index (1-{N}: Pareto-front designs sorted by f1; then the extra designs)")
    ax.set_ylabel("number of wins (least cumulative error)")
    ax.set_title(title, fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--problem", choices=("generic", "applied"), required=True)
    ap.add_argument("--setup", choices=tuple(SETUPS), default=None,
                    help=f"applied problem: the set-up (default {DEFAULT_SETUP}, as paper_repro/mse_table.py; "
                         "robustctl.models.morais2022.SETUPS)")
    ap.add_argument("--algorithm", choices=tuple(ALGORITHMS), default="nsga2", help="MOEA (default nsga2)")
    ap.add_argument("--molsp", action=argparse.BooleanOptionalAction, default=True,
                    help="wrap the MOEA with MO-LSP (default on)")
    ap.add_argument("--evals", type=int, default=3000, help="evaluation budget of the MOEA (default 3000)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the MOEA run and of the selection (default 1)")
    ap.add_argument("--sims", type=int, default=None,
                    help="Monte Carlo simulations (default 1000 generic, 200 applied)")
    ap.add_argument("--horizon-steps", type=int, default=None,
                    help="shorten the selection's simulations to N steps (default: the problem's)")
    ap.add_argument("--pop-size", type=int, default=92, help="MOEA population size (default 92)")
    ap.add_argument("--out", type=Path, default=None,
                    help="output directory (default out/selection_generic, out/selection_applied_<setup>)")
    args = ap.parse_args(argv)
    sims = DEFAULT_SIMS[args.problem] if args.sims is None else args.sims
    if args.problem == "applied" and args.setup is None:
        args.setup = DEFAULT_SETUP
    tag = args.problem if args.problem == "generic" else f"{args.problem}_{args.setup}"
    out = Path("out") / f"selection_{tag}" if args.out is None else args.out
    for name, value, low in (("--evals", args.evals, 1), ("--sims", sims, 1), ("--pop-size", args.pop_size, 4),
                             ("--seed", args.seed, 0)):
        if value < low:
            ap.error(f"{name} must be >= {low}, got {value}")
    if args.horizon_steps is not None and args.horizon_steps < 1:
        ap.error(f"--horizon-steps must be >= 1, got {args.horizon_steps}")
    try:
        problem, path = _problem(args.problem, args.horizon_steps, args.setup)
        t0 = time.perf_counter()
        moea = run_moea(args.problem, args.algorithm, seed=args.seed, evals=args.evals, molsp=args.molsp,
                        pop_size=args.pop_size, setup=args.setup)
        t_moea = time.perf_counter() - t0
    except (ValueError, TypeError) as exc:
        ap.error(str(exc))
    if len(moea.X) == 0:
        print("the MOEA returned an empty front; nothing to select", file=sys.stderr)
        return 1
    order = np.lexsort(moea.F.T[::-1])             # by f1, then f2, ...
    X, F = moea.X[order], moea.F[order]
    t0 = time.perf_counter()
    sel = select_design(problem, X, n_sims=sims, seed=args.seed, path=path)
    t_sel = time.perf_counter() - t0

    d, res = sel.designs, sel.result
    alg = _algorithm_name(args.algorithm, args.molsp)
    steps = (problem.horizon if args.problem == "generic" else path.T)
    setup = getattr(getattr(problem, "setup", None), "name", None)
    print(f"{alg} on {args.problem}" + (f" (set-up {setup})" if setup else "")
          + f": {moea.n_evals} evaluations, front of {len(X)} designs ({t_moea:.1f} s)")
    print(f"{len(d)} designs x {sims} simulations, {steps} steps each ({t_sel:.1f} s)")
    print("top designs (wins):")
    for i in res.ranking()[:8]:
        if res.counts[i] == 0:
            break
        print(f"  {d.labels[i]:>8}  {int(res.counts[i]):5d}")
    print("extra designs (wins): " + ", ".join(f"{d.labels[i]} {int(res.counts[i])}"
                                              for i, k in enumerate(d.kinds) if k != "front"))
    if res.n_no_winner:
        print(f"{res.n_no_winner} simulations without a winner (every design unstable)")
    print(PAPER[args.problem])
    z = sel.z
    z_txt = " ".join(f"{v:.8g}" for v in z)
    print(f"winner: design {sel.label} ({int(res.counts[sel.best])}/{sims} wins), z* = [{z_txt}]")
    t0 = time.perf_counter()
    winner_m = winner_margins(problem, d.K[sel.best])
    print("winner's certified robust-stability margin (>= 1: certified): "
          + (", ".join(f"{k} {'n/a' if v is None else f'{v:.3g}'}" for k, v in winner_m.items()) or "n/a (no gain)")
          + f" ({time.perf_counter() - t0:.1f} s)")
    if args.problem == "applied":
        if np.all(np.isfinite(z)):
            print(f"feed it to the MSE table:\n  {shlex.quote(sys.executable)} paper_repro/mse_table.py "
                  f"--setup {setup} --z {z_txt}")
        else:
            print("the winner is the nominal LQR (no z): the MSE table's LQR row already shows it")

    out.mkdir(parents=True, exist_ok=True)
    title = (f"Monte Carlo design selection: {args.problem} problem"
             + (f" (set-up {setup})" if setup else "") + f", {alg}, {moea.n_evals} evaluations, "
             f"{sims} simulations ($\\Delta \\sim U(-1, 1)$)")
    histogram(sel, title, out / "selection_histogram.png")
    winner_F = F[sel.best].tolist() if d.kinds[sel.best] == "front" else None
    record = {
        "problem": args.problem, "setup": setup, "algorithm": args.algorithm, "molsp": args.molsp,
        "seed": args.seed,
        "evals": args.evals, "n_evals": moea.n_evals, "pop_size": moea.pop_size, "sims": sims,
        "horizon_steps": steps,
        "scenario": ("Delta ~ U(-1, 1) held constant, true plant F + H Delta EF_true, G + H Delta EG_true"
                     if args.problem == "generic" else
                     "Delta ~ U(-1, 1) -> payload overload 150 (1 + Delta) % in [0, 300]"),
        "error": ("sum over the three states of the regulation error sum_i sum_k x_j[k]^2 (unit initial states)"
                  if args.problem == "generic" else
                  "sum_k sum_i (e_i[k] / sigma_i)^2, tracking errors of rho, psidot, ydot, theta"),
        "scales": None if args.problem == "generic" else error_scales(problem.setup).tolist(),
        "winner": {"index": sel.best + 1, "label": sel.label, "kind": d.kinds[sel.best],
                   "wins": int(res.counts[sel.best]), "z": [None if not np.isfinite(v) else float(v) for v in z],
                   "objectives": winner_F, "margins": winner_m},
        "designs": [{"index": i + 1, "label": d.labels[i], "kind": d.kinds[i], "wins": int(res.counts[i]),
                     "ok": bool(d.ok[i])} for i in range(len(d))],
        "no_winner": res.n_no_winner,
        "front": {"X": X.tolist(), "F": F.tolist()},
        "wall_time_s": {"moea": t_moea, "selection": t_sel},
    }
    with open(out / "selection.json", "w") as fh:
        json.dump(record, fh, indent=1)
    print(f"wrote {out / 'selection.json'} and {out / 'selection_histogram.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
