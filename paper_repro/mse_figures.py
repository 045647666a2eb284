"""Figures of the MSE table (``paper_repro/mse_table.py``): the responses and the error signals per overload.

Imported by ``mse_table.py`` as a sibling module (run from the repository:
``python paper_repro/mse_table.py``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS

from robustctl.models import truck

OBJECTIVE_LABELS = {
    "f1": ("lateral displacement error", "m"),
    "f2": ("yaw-rate error", "rad/s"),
    "f3": ("lateral-velocity error", "m/s"),
    "f4": ("orientation error", "rad"),
}
COLORS = {"RLQR_MOP": "tab:blue", "RLQR_A": "tab:orange", "Hinf": "tab:red", "LQR": "tab:green",
          "Hinf_polytopic": "tab:purple", "Hinf_unbounded": "tab:pink", "Hinf_robust": "tab:olive",
          "Hinf_game": "tab:cyan", "RLQR_A_computed": "tab:brown", "RLQR_A_printed": "tab:brown",
          "RLQR_A_code_EG": "tab:gray", "RLQR_A_printed_EG": "tab:gray"}


def make_figures(out: Path, res, designs, path, ts) -> list[Path]:
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
    X_ref, Y_ref = res.reference_pose()                 # the path itself, or the open-loop reference on it
    x0 = ts.loop.x0
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
            ax.plot(X_ref[sel], Y_ref[sel], color="k", lw=3, alpha=0.3, label="reference")
        for b in shown:
            d = designs[b]
            c = COLORS.get(d.name)
            ls = "--" if d.name not in CONTROLLERS else "-"
            ax_xy.plot(X[b, s], Y[b, s], color=c, lw=1, ls=ls, label=d.name)
            ax_start.plot(X[b, s, start], Y[b, s, start], color=c, lw=1.3, ls=ls, label=d.name)
            ax_bend.plot(X[b, s, win], Y[b, s, win], color=c, lw=1.3, ls=ls, label=d.name)
            ax_u.plot(t, res.steering[b, s], color=c, lw=0.8, ls=ls, label=d.name)
            ax_u0.plot(t[zoom], res.steering[b, s, zoom], color=c, lw=1.3, ls=ls, label=d.name)
        ax_xy.set(xlabel="X [m]", ylabel="Y [m]", title="Global position, whole route")
        ax_xy.set_aspect("equal", adjustable="datalim")
        ax_start.set(xlabel="X [m]", ylabel="Y [m]",
                     title=f"Start: rho0 = {x0[2]:g} m, theta0 = {x0[3]:g} rad (axes not to scale)")
        ax_bend.set(xlabel="X [m]", ylabel="Y [m]",
                    title=(f"Sharpest curvature, R = {1 / abs(path.kappa[k_bend]):.0f} m (t = {t[k_bend]:.0f} s)"
                           if path.kappa[k_bend] else "A straight path"))
        ax_bend.set_aspect("equal", adjustable="datalim")
        for ax, title in ((ax_u, "Steering angle"), (ax_u0, f"Steering angle, first {t_zoom:.0f} s")):
            ax.axhline(lim, color="k", ls=":", lw=1.2, label="saturation ±0.45 rad")
            ax.axhline(-lim, color="k", ls=":", lw=1.2)
            ax.set(xlabel="time [s]", title=title, ylim=(-0.5, 0.5),
                   ylabel="steering angle α [rad]")  # noqa: RUF001 (the Greek letter is meant)
        for ax in (ax_xy, ax_start, ax_bend, ax_u, ax_u0):
            ax.grid(alpha=0.3)
        ax_start.legend(loc="upper right", fontsize=8)
        ax_u0.legend(loc="lower right", fontsize=8)
        fig.suptitle(f"Path following at {ov} % overload (controllers designed for 0 %; set-up {ts.name})"
                     + (f"\n{note.strip()}" if note else ""))
        f = out / f"response_{ov}.png"
        fig.savefig(f, dpi=110)
        plt.close(fig)
        files.append(f)

        fig, axes = plt.subplots(4, 1, figsize=(12, 10), sharex=True, layout="constrained")
        for ax, obj in zip(axes, OBJECTIVES, strict=True):
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
        fig.suptitle(f"Path-following errors x - x_ref at {ov} % overload, set-up {ts.name} "
                     "(their MSEs are f1..f4, tracking measure)" + (f"\n{note.strip()}" if note else ""))
        f = out / f"errors_{ov}.png"
        fig.savefig(f, dpi=110)
        plt.close(fig)
        files.append(f)
    return files
