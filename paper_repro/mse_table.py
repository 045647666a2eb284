"""Reproduce the paper's MSE table (Section 4.5.2): four controllers x four payloads x f1..f4.

    python paper_repro/mse_table.py [--out DIR] [--setup authors|ours] [--course route|code]
                                    [--z Z1 ... Z7] [--uncertainty printed|computed]
                                    [--measure tracking|regulation] [--duration SECONDS]
                                    [--controllers NAME ...] [--no-figures] [--no-extras]
                                    [--no-margins] [--compare-setups] [--backend numba|numpy]

Set-ups (``--setup``; the paper states neither its weights, its reference,
its initial state nor its H-infinity formulation):

* ``authors`` (default): the choices of the authors' published code
  (Barbosa et al. 2019, GitHub ``barbosafilipe/robust_lqr``), read there and
  mapped to the 4-state truck: ``Q = diag(1, 1, 25000, 100)``, ``R = 67070
  I2`` on the doubled column (``standard_formulation/parameters.m``,
  ``alternative_formulation/model.m``), the initial state ``[0, 0, 0.3,
  -0.1]`` (same files), the loop ``u = K (x - x_ref)`` without steering
  feedforward, ``x_ref = [0, 0, rho_ref, theta_ref]`` (``main.m``) from the
  nominal truck driven open loop by a smooth steering command
  (``parameters.m``; here the route's steady-cornering steering, see
  :mod:`robustctl.models.pathfollow`), and the H-infinity design with the same Q and
  R in its performance output, the disturbance entering through ``H`` and no
  input bound (``standard_formulation/h_infinity.m``; there a game-Riccati
  law, here our LMI synthesis, and the code's law as the extra row
  ``Hinf_game``). It is the default because it reproduces the paper better
  (printed by the script: winners, pairwise order and magnitudes), and the
  default of every ``paper_repro`` script (``design_selection.py`` takes
  :data:`DEFAULT_SETUP` too, so the chain selection -> table runs in one
  set-up). The library's applied MOP (``make_problem("applied")``,
  ``moo run --problem applied``) defaults to ``ours``: give it ``--setup
  authors`` to feed this table's default.
* ``ours``: the engineering set-up: Bryson's weights
  (:func:`robustctl.models.truck.lqr_weights`), steady-cornering tracking
  with feedforward, a 1 m initial offset, and an H-infinity design against a
  lateral-displacement impulse and the path curvature with the 0.45 rad
  steering limit as an input bound. Its reasons: every state is a tracking
  error (the yaw rate of a bend is not an error), the feedforward takes the
  steady steering off the feedback, and the weights say what error is
  acceptable.

Course (``--course``): ``route`` (default, both set-ups), the 9 km route
(:func:`robustctl.models.path.default_route`); ``code``, the code's 30 s manoeuvre
(two 5 s sine steering lane changes, :func:`robustctl.models.morais2022.code_manoeuvre`).

Controllers, all designed on the nominal (0 %) model with the set-up's Q, R:

* ``RLQR_MOP`` - RLQR on the doubled steering column with the paper's printed
  z* = [EF (4), EG (2), (log10 mu)^2] (``--z`` takes another z).
* ``RLQR_A`` - RLQR on the doubled column with the algebraic uncertainty of
  the appendix (printed values; ``--uncertainty computed`` for the values
  computed from the model).
* ``Hinf`` - the set-up's LMI H-infinity state feedback (above).
* ``LQR`` - discrete Riccati design.

Extra rows the paper does not have (``--no-extras`` drops them):
``RLQR_A_code_EG`` (RLQR^A with the code's ``E_G = [-6.67e-2, -6.67e-3]``
instead of the printed equal entries), ``RLQR_A_computed`` /
``RLQR_A_printed`` (the other uncertainty source), ``Hinf_polytopic`` (the
set-up's H-infinity made robust over the 0-300 % payload polytope),
``Hinf_robust`` (robust H-infinity for the appendix's printed norm-bounded
model, :func:`robustctl.hinf` with ``uncertainty``; the computed model is
infeasible), ``Hinf_unbounded`` (``ours``: without the input bound) and
``Hinf_game`` (``authors``: the code's finite-horizon game-Riccati law at
``gamma = 14350``, :mod:`robustctl.synthesis.hinf_game`, stationary gains, realised as
in the code with the previous input fed back).

Every controller drives the same truck along the same course from the same
initial state at 0, 100, 200 and 300 % overload (true plant),
:class:`robustctl.models.pathfollow.PathFollowing` in the set-up's loop.

Two measures of f1..f4 (``--measure`` picks the one printed and written to
``mse_table.*``; the other goes to ``mse_table_<measure>.csv/.md``):
``tracking`` (default), the MSE of ``x - x_ref`` (in the ``authors`` loop this
is the code's error: rho and theta against the open-loop reference, the
velocities against zero); ``regulation``, the MSE of the states themselves.

Agreement with the paper, printed and written (``agreement.md``) for both
set-ups: the winners matched (of 16 cells), the pairwise-order agreement
(over the 6 pairs of the four controllers in each of the 16 cells; chance
0.5) and the ours/paper ratio of the 64 values (median and range).
``--compare-setups`` also switches one choice at a time between the set-ups
(weights, loop, x0, H-infinity law, RLQR^A's EG, course) and writes
``setup_comparison.md``.

Robust-stability margins (``margins.md``/``.csv``, ``--no-margins`` skips
them): for every controller, the certified margin
(:func:`robustctl.robust_stability`) against the payload polytope (vertices at
0, 100, 200 and 300 %; margin >= 1 certifies the whole range) and the
appendix's norm-bounded model (printed and computed values).

Writes ``DIR/mse_table.csv`` (``objective,controller,overload,mse``),
``mse_table.md``, ``mse_table.tex``, ``mse_table.txt``, ``designs.txt``,
``agreement.md``, ``margins.md``, ``margins.csv`` and, unless
``--no-figures``, ``response_<overload>.png`` (global position and steering)
and ``errors_<overload>.png`` (the four error signals).

The script's sibling modules: ``mse_designs.py`` (set-ups and designs),
``mse_outputs.py`` (tables and agreement), ``mse_figures.py`` and
``truck_margins.py`` (the models of the margins report).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import mse_designs
import numpy as np
from mse_designs import (
    CHOICES,
    COURSES,
    DEFAULT_SETUP,
    TABLE_SETUPS,
    Design,
    TableSetup,
    get_table_setup,
    limit_text,
    rlqr_a_limit,
)
from mse_figures import make_figures
from mse_outputs import (
    Agreement,
    agreement,
    compared_controllers,
    format_table,
    winner_agreement,
    write_agreement,
    write_comparison,
    write_tables,
)
from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS
from truck_margins import MARGINS_NOTE, truck_margins

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.pathfollow import PathFollowing, PathFollowingResult
from robustctl.sim.simulator import BACKENDS


def design_controllers(z=morais2022.RLQR_MOP_Z, uncertainty: str = "printed",
                       controllers: tuple[str, ...] | list[str] | None = None,
                       setup: str | TableSetup = DEFAULT_SETUP) -> list[Design]:
    """:func:`mse_designs.design_controllers` (every controller of the set-up by default) on the nominal model."""
    return mse_designs.design_controllers(setup, z, uncertainty, controllers)


def simulate_designs(designs: list[Design], ts: TableSetup, path, *, keep_trajectories: bool = True,
                     backend: str = "numba") -> PathFollowingResult:
    """All designs at the four payloads in the set-up's loop."""
    sim = PathFollowing(path, list(map(float, OVERLOADS)), setup=ts.loop)
    return sim.run_laws([d.law for d in designs], keep_trajectories=keep_trajectories, backend=backend)


def table_for(ts: TableSetup, *, z=morais2022.RLQR_MOP_Z, uncertainty: str = "printed", measure: str = "tracking",
              duration: float | None = None, backend: str = "numba") -> dict:
    """The paper's four controllers in set-up ``ts``: ``{objective: {controller: (4,)}}`` (no outputs)."""
    designs = design_controllers(z, uncertainty, list(CONTROLLERS), ts)
    res = simulate_designs(designs, ts, ts.path(duration), keep_trajectories=False, backend=backend)
    m = res.mse(MEASURES[measure])
    return {obj: {d.name: m[b, :, j] for b, d in enumerate(designs)} for j, obj in enumerate(OBJECTIVES)}


def compare_setups(*, duration: float | None = None, measure: str = "tracking", backend: str = "numba",
                   log=print) -> list[tuple[str, str, Agreement]]:
    """Each set-up, then one choice of the other set-up at a time (and, from ``authors``, the game law)."""
    rows = []
    for base_name, other_name in (("ours", "authors"), ("authors", "ours")):
        base, other = TABLE_SETUPS[base_name], TABLE_SETUPS[other_name]
        variants = [("(as is)", base)] + [(choice, switch(base, other)) for choice, switch in CHOICES.items()]
        if base_name == "authors":
            variants.append(("H-infinity = the code's game law", dataclasses.replace(base, hinf="game")))
        for label, ts in variants:
            a = agreement(table_for(ts, measure=measure, duration=duration, backend=backend))
            rows.append((base_name, label, a))
            log(f"  {base_name:>7} | {label:<32} | {a.line()}")
    return rows


# -- main ---------------------------------------------------------------------------------
MEASURES = {"tracking": "reference", "regulation": "zero"}


def _write_designs(out: Path, ts: TableSetup, path, designs: list[Design], limit: dict) -> None:
    with open(out / "designs.txt", "w") as fh:
        fh.write(ts.describe() + "\n")
        fh.write(f"({ts.loop.source})\npath: {path!r}\n\n")
        for d in designs:
            fh.write(f"{d.name}: {d.note}\n  K = {np.array2string(d.K, precision=5)}\n"
                     f"  steering gain K1+...+Km = {np.array2string(d.K_steer[0], precision=5)}\n")
            for ov in OVERLOADS:
                A = d.law.closed_loop(truck.truck_plant(float(ov)))
                fh.write(f"  closed-loop spectral radius at {ov:3d} %: {float(rc.spectral_radius(A)):.5f}\n")
        fh.write("\n" + limit_text(limit) + "\n")


def run(out: Path, *, setup: str | TableSetup = DEFAULT_SETUP, course: str | None = None, z=morais2022.RLQR_MOP_Z,
        uncertainty: str = "printed", measure: str = "tracking", duration: float | None = None,
        figures: bool = True, controllers: tuple[str, ...] | list[str] | None = None, backend: str = "numba",
        with_margins: bool = True, compare: bool = False, log=print) -> dict:
    """Design, simulate, write the tables (and figures); return ``{objective: {controller: (4,)}}``."""
    if measure not in MEASURES:
        raise ValueError(f"measure must be one of {sorted(MEASURES)}, got {measure!r}")
    ts = get_table_setup(setup)
    if course is not None:
        ts = dataclasses.replace(ts, course=course)
    t0 = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    path = ts.path(duration)
    log(f"{ts.describe()}")
    log("[1/5] designing controllers (nominal payload) ...")
    designs = design_controllers(z, uncertainty, controllers, ts)
    names = [d.name for d in designs]
    limit = rlqr_a_limit(ts)
    _write_designs(out, ts, path, designs, limit)
    log(f"      {', '.join(names)}  ({time.perf_counter() - t0:.1f} s)")
    log(f"[2/5] simulating {len(designs)} controllers x {len(OVERLOADS)} payloads x {path.T} steps "
        f"({path.duration:.0f} s, {path.T * path.dt * path.speed / 1000:.1f} km) ...")
    t1 = time.perf_counter()
    res = simulate_designs(designs, ts, path, keep_trajectories=figures, backend=backend)
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
            flags.append("DIVERGED at "
                         + ", ".join(f"{ov} %" for ov, dv in zip(OVERLOADS, res.diverged[b], strict=True) if dv))
        sat = res.saturated_steps[b]
        if sat.any():
            flags.append("saturated steps " + "/".join(str(int(x)) for x in sat))
        if flags:
            log(f"      {d.name}: {'; '.join(flags)}")
    diverged = [f"{d.name} at {ov} %" for b, d in enumerate(designs)
                for ov, dv in zip(OVERLOADS, res.diverged[b], strict=True) if dv]
    div_note = ("Diverged runs (stopped at the divergence bound; their MSE is large but finite): "
                + ", ".join(diverged) + ".") if diverged else ""
    log("[3/5] writing tables ...")
    write_tables(out, "mse_table", mse, names)
    table = format_table(mse, names, measure) + ("\n" + div_note if div_note else "")
    (out / "mse_table.txt").write_text(table + "\n")
    if div_note:
        with open(out / "mse_table.md", "a") as fh:
            fh.write("\n" + div_note + "\n")
    other = next(m for m in MEASURES if m != measure)
    write_tables(out, f"mse_table_{other}", tables[other], names, latex=False)
    (out / f"mse_table_{other}.txt").write_text(format_table(tables[other], names, other) + "\n")
    log("")
    log(table)
    log("")
    log(f"With {other} errors instead (mse_table_{other}.*): the best controller agrees with the "
        f"paper in {winner_agreement(tables[other])} of 16 cells.")
    log(limit_text(limit))
    if len(compared_controllers(mse)) == len(CONTROLLERS):
        rows = [(ts.name, agreement(mse))]
        for name, other_ts in TABLE_SETUPS.items():
            if name != ts.name:
                rows.append((name, agreement(table_for(other_ts, z=z, uncertainty=uncertainty, measure=measure,
                                                       duration=duration, backend=backend))))
        write_agreement(out, rows, measure)
        log("")
        for name, a in rows:
            log(f"Agreement, set-up {name:>7}: {a.line()}")
    log("")
    if with_margins:
        log("[4/5] robust-stability margins (LMI certificates) ...")
        t2 = time.perf_counter()
        report = truck_margins({d.name: d.law for d in designs})
        report.to_csv(out / "margins.csv")
        (out / "margins.md").write_text(report.to_markdown() + "\n" + MARGINS_NOTE + "\n")
        log(report.to_text())
        log(f"      ({time.perf_counter() - t2:.1f} s)")
    else:
        log("[4/5] margins skipped (--no-margins)")
    if compare:
        log("      one choice at a time (setup_comparison.md):")
        write_comparison(out, compare_setups(duration=duration, measure=measure, backend=backend, log=log))
    if figures:
        log("[5/5] drawing figures ...")
        files = make_figures(out, res, designs, path, ts)
        log(f"      {len(files)} PNG files in {out}")
    else:
        log("[5/5] figures skipped (--no-figures)")
    log(f"total {time.perf_counter() - t0:.1f} s; outputs in {out.resolve()}")
    return mse


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out"), help="output directory (default: out)")
    ap.add_argument("--setup", choices=tuple(TABLE_SETUPS), default=DEFAULT_SETUP,
                    help=f"weights, loop, x0 and H-infinity formulation (default {DEFAULT_SETUP})")
    ap.add_argument("--course", choices=COURSES, default=None,
                    help="the 9 km route (default) or the authors' code's 30 s manoeuvre")
    ap.add_argument("--z", type=float, nargs=7, metavar="Z", default=None,
                    help="RLQR^MOP decision vector EF1..EF4 EG1 EG2 (log10 mu)^2 (default: the paper's z*)")
    ap.add_argument("--uncertainty", choices=("printed", "computed"), default="printed",
                    help="RLQR^A uncertainty: the paper's printed values or computed from the model")
    ap.add_argument("--measure", choices=tuple(MEASURES), default="tracking",
                    help="f1..f4 as MSE of x - x_ref (tracking, default) or of x (regulation)")
    ap.add_argument("--duration", type=float, default=None,
                    help="simulate only the first DURATION seconds of the course (default: all)")
    ap.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    ap.add_argument("--no-margins", action="store_true", help="skip the robust-stability margins")
    ap.add_argument("--compare-setups", action="store_true",
                    help="also switch one choice at a time between the set-ups (setup_comparison.md)")
    ap.add_argument("--backend", choices=BACKENDS, default="numba",
                    help="simulator: the compiled kernel (default) or the numpy reference")
    ap.add_argument("--no-extras", action="store_true", help="only the paper's four controllers")
    ap.add_argument("--controllers", nargs="+", metavar="NAME", default=None,
                    help="controllers to run (default all): RLQR_MOP RLQR_A Hinf LQR and the set-up's extras "
                         "(module docstring)")
    args = ap.parse_args(argv)
    z = morais2022.RLQR_MOP_Z if args.z is None else tuple(args.z)
    try:
        morais2022.uncertainty_from_z(z)
        if args.duration is not None and not args.duration > 0:
            raise ValueError(f"--duration must be > 0 seconds, got {args.duration}")
        controllers = args.controllers
        if controllers is None and args.no_extras:
            controllers = list(CONTROLLERS)
        run(args.out, setup=args.setup, course=args.course, z=z, uncertainty=args.uncertainty,
            measure=args.measure, duration=args.duration, figures=not args.no_figures, controllers=controllers,
            backend=args.backend, with_margins=not args.no_margins, compare=args.compare_setups)
    except (ValueError, TypeError) as exc:
        ap.error(str(exc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
