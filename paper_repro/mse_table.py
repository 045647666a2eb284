"""Reproduce the paper's MSE table (Section 4.5.2): four controllers x four payloads x f1..f4.

    python paper_repro/mse_table.py [--out DIR] [--z Z1 ... Z7] [--uncertainty printed|computed]
                                    [--measure tracking|regulation] [--duration SECONDS]
                                    [--controllers NAME ...] [--no-figures] [--no-extras]
                                    [--backend numba|numpy]

Controllers (one Q, R for all: :func:`robustctl.models.truck.lqr_weights`):

* ``RLQR_MOP`` - RLQR on the doubled steering column with the paper's printed
  z* = [EF (4), EG (2), (log10 mu)^2] (``--z`` takes another z).
* ``RLQR_A`` - RLQR on the doubled column with the algebraic uncertainty of
  the appendix (printed values; ``--uncertainty computed`` for the values
  computed from the model).
* ``Hinf`` - the LMI H-infinity state feedback designed on the nominal
  payload with the 0.45 rad steering limit as an input bound.
* ``LQR`` - discrete Riccati design on the nominal model.

Extra rows the paper does not have (``--no-extras`` drops them):
``Hinf_polytopic`` (the same H-infinity design made robust over the 0-300 %
payload polytope), ``Hinf_unbounded`` (the nominal H-infinity design without
the input bound: the aggressive, saturating controller the paper's figures
describe) and ``RLQR_A_computed`` / ``RLQR_A_printed`` (the RLQR^A
with the other uncertainty source).

Every controller drives the same truck along the same path
(:func:`robustctl.path.default_route`) from the same initial error (1 m to
the left of the path), with the same steady-state steering feedforward, at
0, 100, 200 and 300 % overload (true plant); all are designed on the nominal
(0 %) model.

Two measures of f1..f4 (``--measure`` picks the one printed and written to
``mse_table.*``; the other goes to ``mse_table_<measure>.csv/.md``):

* ``tracking`` (default): MSE of ``x - x_ref``, the error of each state from
  the nominal model's steady cornering along the path (yaw-rate reference
  ``v kappa``, see :func:`robustctl.pathfollow.simulate`).
* ``regulation``: MSE of the states themselves (``rho``, ``psidot``, ``ydot``,
  ``theta`` regulated to zero). The paper's f2-f4 magnitudes (e.g. LQR f3
  4.5e-2 .. 6.2e-1) match this reading far better than the tracking one, so
  it is probably what the paper measured.

Writes ``DIR/mse_table.csv`` (``objective,controller,overload,mse``),
``mse_table.md``, ``mse_table.tex``, ``mse_table.txt``, ``designs.txt`` and,
unless ``--no-figures``, ``response_<overload>.png`` (global position and
steering) and ``errors_<overload>.png`` (the four tracking-error signals).
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import robustctl as rc  # noqa: E402
from robustctl.models import truck  # noqa: E402
from robustctl.path import default_route  # noqa: E402
from robustctl.batchsim import BACKENDS  # noqa: E402
from robustctl.pathfollow import simulate  # noqa: E402

from paper_repro.paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS, PAPER_MSE  # noqa: E402

OBJECTIVE_LABELS = {
    "f1": ("lateral displacement error", "m"),
    "f2": ("yaw-rate error", "rad/s"),
    "f3": ("lateral-velocity error", "m/s"),
    "f4": ("orientation error", "rad"),
}
COLORS = {"RLQR_MOP": "tab:blue", "RLQR_A": "tab:orange", "Hinf": "tab:red", "LQR": "tab:green",
          "Hinf_polytopic": "tab:purple", "Hinf_unbounded": "tab:pink", "RLQR_A_computed": "tab:brown", "RLQR_A_printed": "tab:brown"}
# H-infinity disturbance channels (columns of Bw): a 1 m lateral-displacement
# impulse (the run's initial offset) and the path curvature scaled by the
# tightest curve of the route (1/200 m).
HINF_RHO_IMPULSE = 1.0
HINF_KAPPA_SCALE = 1.0 / 200.0


@dataclass(frozen=True)
class Design:
    """One controller of the comparison: name, gain (u = K e) and a one-line description."""

    name: str
    K: np.ndarray
    note: str

    @property
    def K_steer(self) -> np.ndarray:
        """The gain from error to steering angle, (1, 4): the sum of K's rows."""
        return self.K.sum(axis=0, keepdims=True)


def _rlqr(name: str, EF, EG, mu, note: str) -> Design:
    Q, R2 = truck.lqr_weights(doubled=True)
    ctrl = rc.design("rlqr", truck.truck_plant(0.0, doubled=True), np.atleast_2d(EF), np.atleast_2d(EG),
                     float(mu), Q=Q, R=R2, H=np.ones((4, 1)))
    return Design(name, ctrl.K, note)


def _hinf(name: str, vertices: list, note: str, input_bound: bool = True) -> Design:
    Q, R = truck.lqr_weights()
    _, _, Gk = truck.discretise(0.0)
    Bw = np.column_stack([[0.0, 0.0, HINF_RHO_IMPULSE, 0.0], Gk[0] * HINF_KAPPA_SCALE])
    Cz = np.vstack([np.sqrt(Q), np.zeros((1, 4))])
    Dzu = np.vstack([np.zeros((4, 1)), np.sqrt(R)])
    bound = dict(u_max=truck.STEER_LIMIT, w_energy=1.0) if input_bound else {}
    ctrl = rc.design("hinf", truck.truck_plant(0.0), Bw=Bw, Cz=Cz, Dzu=Dzu, vertices=vertices or None, **bound)
    if not input_bound:
        return Design(name, ctrl.K, f"{note}; gamma = {ctrl.gamma:.4g}")
    return Design(name, ctrl.K, f"{note}; gamma = {ctrl.gamma:.4g}, guaranteed |alpha| <= "
                                f"{float(np.max(ctrl.info['u_bound'])):.3g} rad for unit-energy w")


def available_controllers(uncertainty: str = "printed") -> tuple[str, ...]:
    """Names :func:`design_controllers` accepts: the paper's four, then the extra rows."""
    other = "RLQR_A_computed" if uncertainty == "printed" else "RLQR_A_printed"
    return CONTROLLERS + ("Hinf_polytopic", "Hinf_unbounded", other)


def design_controllers(z=truck.RLQR_MOP_Z, uncertainty: str = "printed",
                       controllers: tuple[str, ...] | list[str] | None = None) -> list[Design]:
    """Design the named controllers (default: all of :func:`available_controllers`) on the nominal model."""
    if uncertainty not in ("printed", "computed"):
        raise ValueError(f"uncertainty must be 'printed' or 'computed', got {uncertainty!r}")
    valid = available_controllers(uncertainty)
    names = list(valid) if controllers is None else list(controllers)
    unknown = [c for c in names if c not in valid]
    if unknown or not names:
        raise ValueError(f"unknown controller name(s) {unknown or names}; valid: {', '.join(valid)}")
    Q, R = truck.lqr_weights()
    designs = []
    for name in valid:
        if name not in names:
            continue
        if name == "RLQR_MOP":
            EF, EG, mu = truck.uncertainty_from_z(z)
            designs.append(_rlqr(name, EF[0], EG[0], mu[0], "RLQR, doubled column, z = "
                                 + np.array2string(np.asarray(z, float), precision=5)))
        elif name.startswith("RLQR_A"):
            src = uncertainty if name == "RLQR_A" else name.split("_")[-1]
            u = truck.algebraic_uncertainty(src)
            designs.append(_rlqr(name, u.EF, u.EG, u.mu,
                                 f"RLQR, doubled column, Appendix A uncertainty ({src}): "
                                 f"EF = {np.array2string(u.EF[0], precision=4)}, "
                                 f"EG = {np.array2string(u.EG[0], precision=4)}, mu = {u.mu:.3g}"))
        elif name == "Hinf":
            designs.append(_hinf(name, [], "LMI H-infinity, nominal payload, |alpha| <= 0.45 rad input bound"))
        elif name == "Hinf_unbounded":
            designs.append(_hinf(name, [], "LMI H-infinity, nominal payload, no input bound",
                                 input_bound=False))
        elif name == "Hinf_polytopic":
            designs.append(_hinf(name, [truck.truck_plant(300.0)],
                                 "LMI H-infinity over the 0-300 % payload polytope, |alpha| <= 0.45 rad bound"))
        elif name == "LQR":
            designs.append(Design(name, rc.design("lqr", truck.truck_plant(0.0), Q=Q, R=R).K,
                                  "LQR, nominal model"))
    return designs


# -- tables -------------------------------------------------------------------------------
def _winner(values: dict[str, float]) -> str:
    return min(values, key=values.get)


def _compared(mse: dict) -> list[str]:
    """The paper's controllers present in ``mse`` (winners are taken among these, in both tables)."""
    return [c for c in CONTROLLERS if c in mse[OBJECTIVES[0]]]


def winner_agreement(mse: dict) -> int:
    """Cells (of 16) whose best controller among the paper's four is the same as in the paper."""
    cs = _compared(mse)
    return sum(_winner({c: mse[o][c][i] for c in cs}) == _winner({c: PAPER_MSE[o][c][i] for c in cs})
               for o in OBJECTIVES for i in range(len(OVERLOADS)))


def format_table(mse: dict, names: list[str], measure: str = "tracking") -> str:
    """The paper's layout, ours beside the paper's, and the winner of each cell in both."""
    lines = [f"MSE ({measure} errors) - ours beside the paper's published values"]
    head = f"{'obj':<4}{'controller':<17}" + "".join(f"{f'{ov}% ours':>12}{'paper':>11}" for ov in OVERLOADS)
    lines += [head, "-" * len(head)]
    agree = 0
    for obj in OBJECTIVES:
        for name in names:
            row = f"{obj:<4}{name:<17}"
            for i, ov in enumerate(OVERLOADS):
                paper = PAPER_MSE[obj].get(name, (None,) * 4)[i]
                row += f"{mse[obj][name][i]:>12.4e}" + (f"{paper:>11.3e}" if paper is not None else f"{'':>11}")
            lines.append(row)
        cs = _compared(mse)
        if not cs:
            continue
        ours = [_winner({c: mse[obj][c][i] for c in cs}) for i in range(4)]
        paper = [_winner({c: PAPER_MSE[obj][c][i] for c in cs}) for i in range(4)]
        agree += sum(a == b for a, b in zip(ours, paper))
        lines.append(f"{'':<4}{'best (ours/paper)':<17}" + "".join(f"{f'{a}/{b}':>23}" for a, b in zip(ours, paper)))
        lines.append("")
    lines.append(f"Best controller agrees with the paper in {agree} of 16 cells "
                 f"(winners among {', '.join(_compared(mse))}).")
    return "\n".join(lines)


def write_csv(path: Path, mse: dict, names: list[str]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["objective", "controller", "overload", "mse"])
        for obj in OBJECTIVES:
            for name in names:
                for i, ov in enumerate(OVERLOADS):
                    w.writerow([obj, name, ov, f"{mse[obj][name][i]:.10e}"])


def _sci_tex(x: float, bold: bool = False) -> str:
    m, e = f"{x:.3e}".split("e")
    body = f"{m}\\times10^{{{int(e)}}}"
    return f"$\\mathbf{{{body}}}$" if bold else f"${body}$"


def write_markdown(path: Path, mse: dict, names: list[str]) -> None:
    lines = ["| Objective | Controller | " + " | ".join(f"{ov} % (ours)" for ov in OVERLOADS) + " | "
             + " | ".join(f"{ov} % (paper)" for ov in OVERLOADS) + " |",
             "|---|---|" + "---:|" * 8]
    for obj in OBJECTIVES:
        cs = _compared(mse) or names
        best = [_winner({c: mse[obj][c][i] for c in cs}) for i in range(4)]
        pbest = [_winner({c: PAPER_MSE[obj][c][i] for c in cs if c in PAPER_MSE[obj]} or {"-": 0.0})
                 for i in range(4)]
        for name in names:
            ours = [(f"**{mse[obj][name][i]:.3e}**" if best[i] == name else f"{mse[obj][name][i]:.3e}")
                    for i in range(4)]
            if name in PAPER_MSE[obj]:
                pap = [(f"**{v:.3e}**" if pbest[i] == name else f"{v:.3e}")
                       for i, v in enumerate(PAPER_MSE[obj][name])]
            else:
                pap = ["-"] * 4
            lines.append(f"| {obj} | {name} | " + " | ".join(ours) + " | " + " | ".join(pap) + " |")
    lines.append("")
    lines.append("Bold: smallest MSE among RLQR_MOP, RLQR_A, Hinf and LQR in that column. "
                 "f1 [m^2], f2 [(rad/s)^2], f3 [(m/s)^2], f4 [rad^2].")
    path.write_text("\n".join(lines) + "\n")


def write_latex(path: Path, mse: dict, names: list[str]) -> None:
    tex_name = {"RLQR_MOP": r"RLQR$^{MOP}$", "RLQR_A": r"RLQR$^{A}$", "Hinf": r"$\mathcal{H}_\infty$",
                "LQR": "LQR", "Hinf_polytopic": r"$\mathcal{H}_\infty$ polytopic",
                "Hinf_unbounded": r"$\mathcal{H}_\infty$ without input bound",
                "RLQR_A_computed": r"RLQR$^{A}$ (computed)", "RLQR_A_printed": r"RLQR$^{A}$ (printed)"}
    lines = [r"\begin{tabular}{c c c c c c}", r"\hline",
             r"Objective & Controller & \multicolumn{4}{c}{Overload} \\",
             r"\cline{3-6} & & 0\% & 100\% & 200\% & 300\% \\", r"\hline"]
    for obj in OBJECTIVES:
        cs = _compared(mse) or names
        best = [_winner({c: mse[obj][c][i] for c in cs}) for i in range(4)]
        for j, name in enumerate(names):
            cells = []
            for i in range(4):
                cells.append(_sci_tex(mse[obj][name][i], bold=best[i] == name))
            first = rf"\multirow{{{len(names)}}}{{*}}{{$f_{obj[1]}$}}" if j == 0 else ""
            lines.append(f"{first} & {tex_name.get(name, name)} & " + " & ".join(cells) + r" \\")
        lines.append(r"\hline")
    lines.append(r"\end{tabular}")
    path.write_text("\n".join(lines) + "\n")


# -- figures ------------------------------------------------------------------------------
def make_figures(out: Path, res, designs: list[Design], path) -> list[Path]:
    """``response_<ov>.png`` (global position, steering) and ``errors_<ov>.png`` per overload."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    X, Y, _ = res.pose()
    t = path.t
    lim = truck.STEER_LIMIT
    files = []
    t_zoom = min(20.0, t[-1])
    zoom = t <= t_zoom
    # the tightest bend, for a close-up of the path
    k_bend = int(np.argmax(np.abs(path.kappa)))
    shown = [b for b, d in enumerate(designs) if not res.diverged[b].any()]
    hidden = [d.name for b, d in enumerate(designs) if b not in shown]
    note = f" ({', '.join(hidden)} not drawn: diverges at some payload, see the table)" if hidden else ""
    start = path.s <= 300.0
    for s, ov in enumerate(OVERLOADS):
        fig = plt.figure(figsize=(14, 9), layout="constrained")
        gs = fig.add_gridspec(2, 6)
        ax_xy = fig.add_subplot(gs[0, :2])
        ax_start = fig.add_subplot(gs[0, 2:4])
        ax_bend = fig.add_subplot(gs[0, 4:])
        ax_u = fig.add_subplot(gs[1, :4])
        ax_u0 = fig.add_subplot(gs[1, 4:])
        win = np.abs(np.arange(path.T) - k_bend) < 150
        for ax, sel in ((ax_xy, slice(None)), (ax_start, start), (ax_bend, win)):
            ax.plot(path.X[sel], path.Y[sel], color="k", lw=3, alpha=0.3, label="reference path")
        for b in shown:
            d = designs[b]
            c = COLORS.get(d.name, None)
            ls = "--" if d.name not in CONTROLLERS else "-"
            ax_xy.plot(X[b, s], Y[b, s], color=c, lw=1, ls=ls, label=d.name)
            ax_start.plot(X[b, s, start], Y[b, s, start], color=c, lw=1.3, ls=ls, label=d.name)
            ax_bend.plot(X[b, s, win], Y[b, s, win], color=c, lw=1.3, ls=ls, label=d.name)
            ax_u.plot(t, res.steering[b, s], color=c, lw=0.8, ls=ls, label=d.name)
            ax_u0.plot(t[zoom], res.steering[b, s, zoom], color=c, lw=1.3, ls=ls, label=d.name)
        ax_xy.set(xlabel="X [m]", ylabel="Y [m]", title="Global position, whole route")
        ax_xy.set_aspect("equal", adjustable="datalim")
        ax_start.set(xlabel="X [m]", ylabel="Y [m]",
                     title="Start: 1 m initial offset (axes not to scale)")
        ax_bend.set(xlabel="X [m]", ylabel="Y [m]",
                    title=f"Tightest bend, R = {1 / abs(path.kappa[k_bend]):.0f} m (t = {t[k_bend]:.0f} s)")
        ax_bend.set_aspect("equal", adjustable="datalim")
        for ax, title in ((ax_u, "Steering angle"), (ax_u0, f"Steering angle, first {t_zoom:.0f} s")):
            ax.axhline(lim, color="k", ls=":", lw=1.2, label="saturation ±0.45 rad")
            ax.axhline(-lim, color="k", ls=":", lw=1.2)
            ax.set(xlabel="time [s]", ylabel="steering angle α [rad]", title=title, ylim=(-0.5, 0.5))
        for ax in (ax_xy, ax_start, ax_bend, ax_u, ax_u0):
            ax.grid(alpha=0.3)
        ax_start.legend(loc="upper right", fontsize=8)
        ax_u0.legend(loc="lower right", fontsize=8)
        fig.suptitle(f"Path following at {ov} % overload (controllers designed for 0 %)"
                     + (f"\n{note.strip()}" if note else ""))
        f = out / f"response_{ov}.png"
        fig.savefig(f, dpi=110)
        plt.close(fig)
        files.append(f)

        fig, axes = plt.subplots(4, 1, figsize=(12, 10), sharex=True, layout="constrained")
        for ax, obj in zip(axes, OBJECTIVES):
            idx = truck.OBJECTIVE_STATES[OBJECTIVES.index(obj)]
            for b in shown:
                d = designs[b]
                ax.plot(t, res.errors[b, s, :, idx], color=COLORS.get(d.name), lw=0.8,
                        ls="--" if d.name not in CONTROLLERS else "-", label=d.name)
            label, unit = OBJECTIVE_LABELS[obj]
            peaks = {designs[b].name: float(np.max(np.abs(res.errors[b, s, :, idx]))) for b in shown}
            ranked = sorted(peaks.values())
            if len(ranked) >= 3 and ranked[-1] > 4 * ranked[-2] > 0:      # one outlier hides the rest
                top = 1.3 * ranked[-2]
                ax.set_ylim(-top, top)
                out_name = max(peaks, key=peaks.get)
                ax.text(0.01, 0.95, f"{out_name} leaves the axis (peak {ranked[-1]:.3g} {unit})",
                        transform=ax.transAxes, va="top", fontsize=8,
                        bbox=dict(facecolor="white", alpha=0.8, edgecolor="none"))
            ax.set_ylabel(f"{obj}: {label}\n[{unit}]", fontsize=9)
            ax.grid(alpha=0.3)
        axes[0].legend(loc="upper right", fontsize=8, ncol=3)
        axes[-1].set_xlabel("time [s]")
        fig.suptitle(f"Path-following errors x - x_ref at {ov} % overload "
                     "(their MSEs are f1..f4, tracking measure)" + (f"\n{note.strip()}" if note else ""))
        f = out / f"errors_{ov}.png"
        fig.savefig(f, dpi=110)
        plt.close(fig)
        files.append(f)
    return files


# -- main ---------------------------------------------------------------------------------
MEASURES = {"tracking": "reference", "regulation": "zero"}


def run(out: Path, *, z=truck.RLQR_MOP_Z, uncertainty: str = "printed", measure: str = "tracking",
        duration: float | None = None, figures: bool = True,
        controllers: tuple[str, ...] | list[str] | None = None, backend: str = "numba", log=print) -> dict:
    """Design, simulate, write the tables (and figures); return ``{objective: {controller: (4,)}}``."""
    if measure not in MEASURES:
        raise ValueError(f"measure must be one of {sorted(MEASURES)}, got {measure!r}")
    t0 = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    path = default_route() if duration is None else default_route(duration=duration)
    log("[1/4] designing controllers (nominal payload) ...")
    designs = design_controllers(z, uncertainty, controllers)
    names = [d.name for d in designs]
    with open(out / "designs.txt", "w") as fh:
        Q, R = truck.lqr_weights()
        fh.write(f"Q = diag({np.diag(Q).tolist()}), R = {R[0, 0]:g} (doubled column: R = {2 * R[0, 0]:g} I2)\n")
        fh.write(f"path: {path!r}\n\n")
        for d in designs:
            fh.write(f"{d.name}: {d.note}\n  K = {np.array2string(d.K, precision=5)}\n"
                     f"  steering gain K1+...+Km = {np.array2string(d.K_steer[0], precision=5)}\n")
            for ov in OVERLOADS:
                F, G, _ = truck.discretise(ov)
                rad = float(rc.spectral_radius(F[0] + G[0] @ d.K_steer))
                fh.write(f"  closed-loop spectral radius at {ov:3d} %: {rad:.5f}\n")
    log(f"      {', '.join(names)}  ({time.perf_counter() - t0:.1f} s)")
    log(f"[2/4] simulating {len(designs)} controllers x {len(OVERLOADS)} payloads x {path.T} steps "
        f"({path.duration:.0f} s, {path.T * path.dt * path.speed / 1000:.1f} km) ...")
    t1 = time.perf_counter()
    K = np.stack([d.K_steer for d in designs])
    res = simulate(K, path, list(map(float, OVERLOADS)), keep_trajectories=figures, backend=backend)
    tables = {}
    for meas, target in MEASURES.items():
        m = res.mse(target)                                          # (B, S, 4)
        tables[meas] = {obj: {d.name: m[b, :, j] for b, d in enumerate(designs)}
                        for j, obj in enumerate(OBJECTIVES)}
    mse = tables[measure]
    log(f"      done ({time.perf_counter() - t1:.2f} s)")
    for b, d in enumerate(designs):
        flags = []
        if res.diverged[b].any():
            flags.append("DIVERGED at " + ", ".join(f"{ov} %" for ov, dv in zip(OVERLOADS, res.diverged[b]) if dv))
        sat = res.saturated_steps[b]
        if sat.any():
            flags.append("saturated steps " + "/".join(str(int(x)) for x in sat))
        if flags:
            log(f"      {d.name}: {'; '.join(flags)}")
    diverged = [f"{d.name} at {ov} %" for b, d in enumerate(designs)
                for ov, dv in zip(OVERLOADS, res.diverged[b]) if dv]
    div_note = ("Diverged runs (stopped at the divergence bound; their MSE is large but finite): "
                + ", ".join(diverged) + ".") if diverged else ""
    log("[3/4] writing tables ...")
    write_csv(out / "mse_table.csv", mse, names)
    write_markdown(out / "mse_table.md", mse, names)
    write_latex(out / "mse_table.tex", mse, names)
    table = format_table(mse, names, measure) + ("\n" + div_note if div_note else "")
    (out / "mse_table.txt").write_text(table + "\n")
    if div_note:
        with open(out / "mse_table.md", "a") as fh:
            fh.write("\n" + div_note + "\n")
    other = next(m for m in MEASURES if m != measure)
    write_csv(out / f"mse_table_{other}.csv", tables[other], names)
    write_markdown(out / f"mse_table_{other}.md", tables[other], names)
    (out / f"mse_table_{other}.txt").write_text(format_table(tables[other], names, other) + "\n")
    log("")
    log(table)
    log("")
    log(f"With {other} errors instead (mse_table_{other}.*): the best controller agrees with the "
        f"paper in {winner_agreement(tables[other])} of 16 cells.")
    log("")
    if figures:
        log("[4/4] drawing figures ...")
        files = make_figures(out, res, designs, path)
        log(f"      {len(files)} PNG files in {out}")
    else:
        log("[4/4] figures skipped (--no-figures)")
    log(f"total {time.perf_counter() - t0:.1f} s; outputs in {out.resolve()}")
    return mse


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out"), help="output directory (default: out)")
    ap.add_argument("--z", type=float, nargs=7, metavar="Z", default=None,
                    help="RLQR^MOP decision vector EF1..EF4 EG1 EG2 (log10 mu)^2 (default: the paper's z*)")
    ap.add_argument("--uncertainty", choices=("printed", "computed"), default="printed",
                    help="RLQR^A uncertainty: the paper's printed values or computed from the model")
    ap.add_argument("--measure", choices=tuple(MEASURES), default="tracking",
                    help="f1..f4 as MSE of x - x_ref (tracking, default) or of x (regulation)")
    ap.add_argument("--duration", type=float, default=None,
                    help="simulate only the first DURATION seconds of the route (default: all, ~540 s)")
    ap.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    ap.add_argument("--backend", choices=BACKENDS, default="numba",
                    help="simulator: the compiled kernel (default) or the numpy reference")
    ap.add_argument("--no-extras", action="store_true",
                    help="only the paper's four controllers (no polytopic H-infinity, no other RLQR^A)")
    ap.add_argument("--controllers", nargs="+", metavar="NAME", default=None,
                    help="controllers to run (default all): RLQR_MOP RLQR_A Hinf LQR Hinf_polytopic "
                         "Hinf_unbounded RLQR_A_computed (RLQR_A_printed with --uncertainty computed)")
    args = ap.parse_args(argv)
    z = truck.RLQR_MOP_Z if args.z is None else tuple(args.z)
    try:
        truck.uncertainty_from_z(z)
        if args.duration is not None and not args.duration > 0:
            raise ValueError(f"--duration must be > 0 seconds, got {args.duration}")
        controllers = args.controllers
        if controllers is None and args.no_extras:
            controllers = list(CONTROLLERS)
        run(args.out, z=z, uncertainty=args.uncertainty, measure=args.measure, duration=args.duration,
            figures=not args.no_figures, controllers=controllers, backend=args.backend)
    except (ValueError, TypeError) as exc:
        ap.error(str(exc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
