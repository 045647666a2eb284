"""The paper's MSE table with the truck's sensors: the four controllers on an estimate of the state.

    python paper_repro/mse_table_sensors.py [--out DIR] [--setup authors|ours] [--draws N] [--seed S]
                                            [--duration SECONDS] [--mu MU] [--no-figures]

The truck measures its yaw rate (a MEMS gyroscope) and its lateral
displacement and orientation error (RTK GNSS with dual-antenna heading,
against the map of the path), not its lateral velocity
(:func:`robustctl.models.truck.sensor_plant`), with the data-sheet noise of
:class:`robustctl.models.truck.TruckSensors`. The paper's four controllers
(``mse_table.py``'s designs of the set-up, on the nominal model) steer on
an estimate, ``alpha = sat(K (xhat - x_ref))``, from
:meth:`robustctl.models.pathfollow.PathFollowing.run_estimated`; the
estimators run on the nominal (0 %) model at every overload:

* ``full_state``: the loop on the true state (``mse_table.py``'s table);
* ``kalman``: the steady-state Kalman filter (filter form,
  :func:`robustctl.kalman`), process noise
  :func:`robustctl.models.morais2022.sensor_filter_noise`;
* ``robust``: the robust filter (:func:`robustctl.robust_kalman`) of the
  same noise with the paper's uncertainty model, the appendix's printed
  ``H``, ``EF``, ``EG`` (RLQR^A's; ``truck_margins.appendix_uncertainty``),
  at the penalty ``mu`` chosen from the model alone: the decade in
  ``1 .. 1e9`` whose largest closed-loop spectral radius over the four
  controllers and the four payloads (the linear loop of truck, filter and
  controller, ``robustctl.observer_controller``) is smallest (``--mu``
  sets it);
* ``robust_paper_mu``: the same filter at the paper's ``mu = 1e9``.

Every estimator sees the same noise sequences (``--draws`` per overload,
seed ``--seed``). Writes ``DIR/mse_sensors.csv``
(``estimator,controller,objective,overload,mse,std,draws,diverged``: the
mean and the standard deviation over the draws, the draws that left the
divergence bound), ``DIR/mse_sensors_mu.csv`` (the penalty's choice), ``DIR/mse_sensors_radius.csv``
(``estimator,controller,overload,spectral_radius``: the linear loops' spectral radii),
``DIR/mse_sensors.md`` (the tables, the sensors, the filters and the run)
and, unless ``--no-figures``, ``DIR/mse_sensors.png``. The files kept in
``paper_repro/results/`` are ``--out paper_repro/results --no-figures``;
``docs/validation/sensors.rst`` shows them.
"""

from __future__ import annotations

import argparse
import datetime
import shlex
import subprocess
import sys
import time
from pathlib import Path

import mse_designs
import numpy as np
from mse_designs import DEFAULT_SETUP, TABLE_SETUPS, get_table_setup
from mse_figures import COLORS, OBJECTIVE_LABELS
from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS
from truck_margins import appendix_uncertainty

import robustctl as rc
from moo.tables import markdown_table, write_csv
from robustctl.models import morais2022, truck
from robustctl.models.pathfollow import PathFollowing

ESTIMATORS = ("full_state", "kalman", "robust", "robust_paper_mu")
MU_GRID = tuple(10.0**k for k in range(10))
PAPER_MU = morais2022.algebraic_uncertainty("printed").mu
ROOT = Path(__file__).resolve().parents[1]


def filters(path, designs, mu: float | None = None) -> tuple[dict[str, rc.Estimator], list[tuple[float, float]]]:
    """The Kalman and robust filters (module docstring) and ``(mu, worst closed-loop spectral radius)`` per mu."""
    plant = truck.sensor_plant(0.0)
    V = truck.TruckSensors().covariance(plant.dt)
    Bw, W = morais2022.sensor_filter_noise(path)
    unc = appendix_uncertainty("printed")

    def robust(m: float) -> rc.Estimator:
        return rc.robust_kalman(plant, W, V, Bw=Bw, H=unc.H, EF=unc.EF, EG=unc.EG, mu=m)

    radii = [(m, float(loop_radii(robust(m), designs).max())) for m in MU_GRID]
    chosen = min(radii, key=lambda r: r[1])[0] if mu is None else mu
    ests = {"kalman": rc.kalman(plant, W, V, Bw=Bw), "robust": robust(chosen), "robust_paper_mu": robust(PAPER_MU)}
    return ests, radii


def loop_radii(est: rc.Estimator | None, designs) -> np.ndarray:
    """Spectral radius (B, S) of the linear loop of each controller on ``est`` (None: the state) at each overload."""
    def radius(d, ov: float) -> float:
        if est is None:
            p = truck.truck_plant(ov)
            return rc.spectral_radius(p.F + p.G @ d.K_steer)
        return rc.spectral_radius(rc.observer_controller(d.K_steer, est).closed_loop(truck.sensor_plant(ov)))

    return np.array([[radius(d, float(ov)) for ov in OVERLOADS] for d in designs])


def simulate(ts, path, designs, ests: dict, draws: int, seed: int, keep: bool) -> dict:
    """``{estimator: (mse (B, S, 4), std (B, S, 4), diverged draws (B, S), result)}``, the same noise for each."""
    runs = PathFollowing(path, [float(ov) for ov in OVERLOADS], setup=ts.loop)
    K = np.stack([d.K_steer for d in designs])
    full = runs.run(K, keep_trajectories=keep)
    out = {"full_state": (full.mse(), np.zeros_like(full.mse()), full.diverged.astype(int), full)}
    for name, est in ests.items():
        res = runs.run_estimated(K, est, draws=draws, rng=seed, keep_trajectories=keep)
        m = res.mse_by_draw()
        out[name] = (m.mean(axis=2), m.std(axis=2), res.diverged.reshape(len(designs), len(OVERLOADS), draws).sum(2),
                     res)
    return out


def rows(results: dict, designs) -> list[list]:
    """The CSV rows (module docstring)."""
    return [[e, d.name, obj, ov, f"{results[e][0][b, s, j]:.10e}", f"{results[e][1][b, s, j]:.4e}",
             1 if e == "full_state" else results["kalman"][3].draws, int(results[e][2][b, s])]
            for e in ESTIMATORS for b, d in enumerate(designs) for j, obj in enumerate(OBJECTIVES)
            for s, ov in enumerate(OVERLOADS)]


def markdown(results: dict, designs, ests: dict, radii, radii_of: dict, header: str) -> str:
    """The tables of ``mse_sensors.md``: one per objective (controller x estimator), then the penalty's choice."""
    parts = [header]
    for j, obj in enumerate(OBJECTIVES):
        label, unit = OBJECTIVE_LABELS[obj]
        body = [[d.name, e, *(f"{results[e][0][b, s, j]:.3e}" + (f" ({results[e][2][b, s]} div.)"
                                                                   if results[e][2][b, s] else "")
                              for s in range(len(OVERLOADS)))]
                for b, d in enumerate(designs) for e in ESTIMATORS]
        parts.append(f"**{obj}**, {label} [{_squared(unit)}]\n\n"
                     + markdown_table(["controller", "estimator", *(f"{ov} %" for ov in OVERLOADS)], body,
                                      align="ll" + "r" * len(OVERLOADS)))
    body = [[d.name, e, *(f"{r:.4f}" for r in radii_of[e][b])] for b, d in enumerate(designs) for e in ESTIMATORS]
    parts.append("Spectral radius of the linear loop (truck at the overload, controller and filter of the nominal "
                 "model; no saturation, no noise; above 1: unstable)\n\n"
                 + markdown_table(["controller", "estimator", *(f"{ov} %" for ov in OVERLOADS)], body,
                                  align="ll" + "r" * len(OVERLOADS)))
    chosen = ests["robust"].info["mu"]
    parts.append("Penalty of the robust filter: the largest closed-loop spectral radius over the four controllers "
                 "and the four payloads (linear loop, no saturation)\n\n"
                 + markdown_table(["mu", "worst spectral radius", "chosen"],
                                  [[f"{m:.0e}", f"{r:.4f}", "yes" if m == chosen else ""] for m, r in radii],
                                  align="lrl"))
    return "\n\n".join(parts) + "\n"


def make_figure(out: Path, results: dict, designs, ts) -> Path:
    """``mse_sensors.png``: the MSE against the overload, one panel per objective (the paper's mu left out)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    styles = {"full_state": "-", "kalman": "--", "robust": ":"}
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), layout="constrained")
    for ax, (j, obj) in zip(axes.ravel(), enumerate(OBJECTIVES), strict=True):
        for b, d in enumerate(designs):
            for e, ls in styles.items():
                ax.plot(OVERLOADS, results[e][0][b, :, j], color=COLORS[d.name], ls=ls, marker="o", ms=3)
        label, unit = OBJECTIVE_LABELS[obj]
        ax.set(yscale="log", xlabel="overload [%]", ylabel=f"MSE [{_squared(unit)}]", title=f"{obj}: {label}",
               xticks=OVERLOADS)
        ax.grid(alpha=0.3, which="both")
    axes[0, 0].legend([Line2D([], [], color=COLORS[d.name]) for d in designs], [d.name for d in designs],
                      fontsize=8, loc="upper left")
    axes[0, 1].legend([Line2D([], [], color="k", ls=ls) for ls in styles.values()],
                      ["full state", "Kalman filter", "robust filter"], fontsize=8, loc="upper left")
    fig.suptitle(f"MSE of the tracking errors with the truck's sensors (set-up {ts.name}, mean over the noise "
                 "draws; the robust filter at the paper's mu is in the table)")
    f = out / "mse_sensors.png"
    fig.savefig(f, dpi=110)
    plt.close(fig)
    return f


def _squared(unit: str) -> str:
    return f"({unit})^2" if "/" in unit else f"{unit}^2"


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def run(out: Path, *, setup: str = DEFAULT_SETUP, draws: int = 20, seed: int = 0, duration: float | None = None,
        mu: float | None = None, figures: bool = True, argv=(), log=print) -> dict:
    """Design, simulate, write the files; return :func:`simulate`'s results."""
    t0 = time.perf_counter()
    ts = get_table_setup(setup)
    path = ts.path(duration)
    designs = mse_designs.design_controllers(ts, controllers=list(CONTROLLERS))
    if any(d.K_input is not None for d in designs):
        raise ValueError("the estimated loop takes static steering laws; this set-up's H-infinity law feeds back "
                         "the previous steering angle")
    ests, radii = filters(ts.path(), designs, mu)                # the whole course's tightest bend sizes W
    results = simulate(ts, path, designs, ests, draws, seed, keep=figures)
    elapsed = time.perf_counter() - t0
    out.mkdir(parents=True, exist_ok=True)
    write_csv(["estimator", "controller", "objective", "overload", "mse", "std", "draws", "diverged"],
              rows(results, designs), out / "mse_sensors.csv", lineterminator="\r\n")
    chosen = ests["robust"].info["mu"]
    write_csv(["mu", "worst_spectral_radius", "chosen"], ([f"{m:.0e}", f"{r:.6f}", m == chosen] for m, r in radii),
              out / "mse_sensors_mu.csv", lineterminator="\r\n")
    radii_of = {e: loop_radii(ests.get(e), designs) for e in ESTIMATORS}
    write_csv(["estimator", "controller", "overload", "spectral_radius"],
              ([e, d.name, ov, f"{radii_of[e][b, s]:.6f}"] for e in ESTIMATORS for b, d in enumerate(designs)
               for s, ov in enumerate(OVERLOADS)), out / "mse_sensors_radius.csv", lineterminator="\r\n")
    s_gyro, s_rho, s_theta = truck.TruckSensors().std(truck.PAPER_PARAMETERS.dt)
    W = morais2022.sensor_filter_noise(ts.path())[1]
    header = (
        "# The paper's MSE table with the truck's sensors\n\n"
        f"Command: `python paper_repro/mse_table_sensors.py {shlex.join(argv)}` "
        f"({datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, commit {_commit()}, "
        f"{elapsed:.1f} s). {ts.describe()}; {path.duration:.0f} s of the course; {draws} noise draws per overload, "
        f"seed {seed}, the same draws for every estimator.\n\n"
        f"Sensors (1 sigma per 0.1 s sample): yaw rate {s_gyro:.3g} rad/s, lateral displacement {s_rho:.3g} m, "
        f"orientation {s_theta:.3g} rad. Filters on the nominal model: process noise on the steering input, "
        f"sigma = {np.sqrt(W[0, 0]):.3g} rad; robust filter with the appendix's printed H, EF, EG at mu = "
        f"{chosen:.0e} (robust) and {PAPER_MU:.0e} (robust_paper_mu). MSE: mean over the draws (tracking errors; "
        "`div.`: draws that left the divergence bound).")
    text = markdown(results, designs, ests, radii, radii_of, header)
    (out / "mse_sensors.md").write_text(text)
    log(text)
    if figures:
        log(f"figure: {make_figure(out, results, designs, ts)}")
    return results


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out"), help="output directory (default: out)")
    ap.add_argument("--setup", choices=tuple(TABLE_SETUPS), default=DEFAULT_SETUP,
                    help=f"mse_table.py's set-up (default {DEFAULT_SETUP})")
    ap.add_argument("--draws", type=int, default=20, help="noise draws per overload (default 20)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the noise draws (default 0)")
    ap.add_argument("--duration", type=float, default=None,
                    help="simulate only the first DURATION seconds of the course (default: all)")
    ap.add_argument("--mu", type=float, default=None,
                    help="the robust filter's penalty (default: chosen from the model, module docstring)")
    ap.add_argument("--no-figures", action="store_true", help="skip the PNG figure")
    args = ap.parse_args(argv)
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        if args.draws < 1:
            raise ValueError(f"--draws must be >= 1, got {args.draws}")
        if args.duration is not None and not args.duration > 0:
            raise ValueError(f"--duration must be > 0 seconds, got {args.duration}")
        run(args.out, setup=args.setup, draws=args.draws, seed=args.seed, duration=args.duration, mu=args.mu,
            figures=not args.no_figures, argv=argv)
    except (ValueError, TypeError) as exc:
        ap.error(str(exc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
