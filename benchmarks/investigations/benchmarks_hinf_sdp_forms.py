r"""The H-infinity level SDP of one discrete plant: the standard LMI against its eliminated form.

Usage::

    python -m benchmarks.investigations.benchmarks_hinf_sdp_forms [--sizes 20 30 40 50] [--reps 3]
        [--shift 1e-6] [--one-rep-from 50] [--out benchmarks/results/hinf_sdp_forms.md]

(quick look: ``--sizes 4 --reps 1 --out /tmp/forms.md``)

``rc.hinf`` (``synthesis="lmi"``) minimises ``eta = gamma^2`` subject to the
discrete bounded-real LMI in one cvxpy/Clarabel solve. This asks whether a
smaller SDP, the one in which the projection (elimination) lemma removes
``Y = K X``, solves faster, and up to which size. (The library's level
minimisation of one plant uses the eliminated form,
``robustctl.synthesis._hinf.lmis.projected_blocks``, up to the size where this
measures it faster.) Both forms are posed here, on the same data, written
out independently of the library:

``standard`` (variables ``X`` symmetric, ``Y``, ``eta``; one PSD block of order ``2n + p``)::

    [ X - Bw Bw'   F X + G Y   -Bw Dzw'          ]
    [ *            X           (Cz X + Dzu Y)'   ]  >= 0
    [ *            *           eta I - Dzw Dzw'  ]

``eliminated`` (variables ``X``, ``eta``). With ``Abar = [F; Cz]``,
``Bbar = [G; Dzu]``, ``BD = [Bw; Dzw]``, ``N`` an orthonormal basis of the
null space of ``Bbar'`` (``scipy.linalg.null_space``), ``N_x = N[:n]``,
``N_z = N[n:]``::

    E1 = N_x' X N_x + eta N_z' N_z - (N' Abar) X (N' Abar)' - N' BD BD' N  >= 0    (order n + p - m)
    E2 = Phi = [ X - Bw Bw'   -Bw Dzw'         ]  >= 0                              (order n + p)
               [ *            eta I - Dzw Dzw' ]

The standard block is, by a Schur complement on its middle ``X``,
``Phi - (Abar X + Bbar Y) X^-1 (Abar X + Bbar Y)' >= 0``; the projection
lemma removes ``Y``. When ``E1, E2 > 0`` the gain
``K = -(Bbar' Phi^-1 Bbar)^-1 Bbar' Phi^-1 Abar`` satisfies the standard
LMI. Checked at the eliminated optimum with ``eta`` raised by the factor
``1 + 1e-3``: python-control's ``linfnorm`` of the closed loop
``(F + G K, Bw, Cz + Dzu K, Dzw)`` over ``sqrt(eta)`` (< 1 when the gain
holds the level).

Data: ``benchmarks.bench_hinf.case(n, 0)`` (m = 2, q = 2, p = 4,
``Dzw = 0``), in well-scaled coordinates built here, a simple version of
what the library does: ``w`` and ``z`` scaled so that ``||Bw|| = 1`` and
``||[Cz Dzu Dzw]|| = 1``; the states balanced by
``scipy.linalg.matrix_balance(F)`` (diagonal scaling, no permutation); then
``x = T x^`` with ``T T' = (P + s I)^-1``, ``P`` the stabilising solution
of the discrete LQR Riccati equation of the weight ``[Cz Dzu]'[Cz Dzu]``
(1e-9 of its norm added on the diagonal), ``s >= 0`` the least shift that
lifts its smallest eigenvalue to ``--shift`` (default 1e-6, the library's
``LQR_SHIFT``) times its largest, ``T`` the Cholesky factor, scaled so that
``||Bw|| = 1`` again. (The weight has rank 2, so ``P`` has eigenvalues
near the regularisation; without a shift ``P^-1`` is not numerically
positive definite at n = 50.) ``eta`` is the level of these scaled data.

Solves: Clarabel through cvxpy with ``tol_gap_abs = tol_gap_rel = tol_feas
= 1e-8``, ``chordal_decomposition_enable=False``,
``iterative_refinement_enable=False``, ``max_threads=1`` (*tuned*; the
library runs Clarabel on one thread when the PSD blocks have at most 2500
free entries, the full LMI up to n = 30 and the eliminated form up to
n = 40, and on its default threads above), the same on Clarabel's
default threads (``max_threads=0``), and at the first size also with
Clarabel's defaults; both forms also with CVXOPT when it is
importable (it is not a dependency), with its defaults (``abstol = 1e-7,
reltol = 1e-6, feastol = 1e-7``; at 1e-8 it stops short of its tolerances
on some of these plants). Each timing is the whole ``problem.solve`` call
(cvxpy's compilation included) on a freshly built problem: CPU time of the
process (``time.process_time``, all threads) and wall-clock time, the best
of ``--reps`` runs (one run from ``--one-rep-from`` states on), the forms
alternating; beside them the solve time the solver reports to cvxpy.
Reported besides: the PSD cones (order and svec dimension), the scalar
decision variables, the nonzeros of the constraint matrix ``A`` that cvxpy
passes to Clarabel, the iterations and the optimal ``eta`` of each form
with its relative error against ``eta_peer``, the square of the level that
the Riccati bisection ``benchmarks.bench_hinf.peer_hinf`` (``rtol = 1e-8``)
finds on the same data.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import datetime  # noqa: E402
import importlib.metadata  # noqa: E402
import importlib.util  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import control  # noqa: E402
import cvxpy as cp  # noqa: E402
import numpy as np  # noqa: E402
import scipy.linalg  # noqa: E402

from benchmarks.bench_hinf import case, peer_hinf  # noqa: E402

TUNED = dict(tol_gap_abs=1e-8, tol_gap_rel=1e-8, tol_feas=1e-8, chordal_decomposition_enable=False,
             iterative_refinement_enable=False, max_threads=1)
FORMS = ("standard", "eliminated")
BACKOFF = 1e-3


@dataclass(frozen=True)
class Data:
    """One discrete plant ``x+ = F x + Bw w + G u``, ``z = Cz x + Dzw w + Dzu u`` (solver coordinates)."""

    F: np.ndarray
    G: np.ndarray
    Bw: np.ndarray
    Cz: np.ndarray
    Dzu: np.ndarray
    Dzw: np.ndarray
    dt: float

    def to(self, T: np.ndarray) -> Data:
        """The same plant in the coordinates ``x = T x^``."""
        return Data(np.linalg.solve(T, self.F @ T), np.linalg.solve(T, self.G), np.linalg.solve(T, self.Bw),
                    self.Cz @ T, self.Dzu, self.Dzw, self.dt)


def scaled(n: int, shift: float = 1e-6, seed: int = 0) -> Data:
    """``case(n, seed)`` with unit channels, balanced, in LQR coordinates, ``||Bw|| = 1`` (module docstring).

    ``shift``: the smallest eigenvalue of the Riccati solution is lifted to ``shift`` times its largest
    before the inversion (the library's ``LQR_SHIFT``: 1e-6).
    """
    if not 0 < shift < 1:
        raise ValueError(f"shift must be in (0, 1), got {shift!r}")
    plant, Bw, Cz, Dzu = case(n, seed)
    Dzw = np.zeros((Cz.shape[0], Bw.shape[1]))
    Bw = Bw / np.linalg.norm(Bw, 2)
    z_unit = np.linalg.norm(np.hstack([Cz, Dzu, Dzw]), 2)
    data = Data(np.asarray(plant.F, dtype=float), np.asarray(plant.G, dtype=float), Bw, Cz / z_unit,
                Dzu / z_unit, Dzw / z_unit, float(plant.dt))
    _, (scale, _) = scipy.linalg.matrix_balance(data.F, permute=False, separate=True)
    data = data.to(np.diag(scale))
    C, D = data.Cz, data.Dzu
    Q, R = C.T @ C, D.T @ D
    Q = Q + 1e-9 * max(1.0, float(np.linalg.norm(Q, 2))) * np.eye(n)
    R = R + 1e-9 * max(1.0, float(np.linalg.norm(R, 2))) * np.eye(R.shape[0])
    P = scipy.linalg.solve_discrete_are(data.F, data.G, Q, R, s=C.T @ D)
    P = 0.5 * (P + P.T)
    lam = np.linalg.eigvalsh(P)
    T = np.linalg.cholesky(np.linalg.inv(P + max(0.0, shift * lam[-1] - lam[0]) * np.eye(n)))
    data = data.to(T)
    return data.to(np.linalg.norm(data.Bw, 2) * np.eye(n))


def standard(d: Data) -> tuple[cp.Problem, cp.Variable, dict]:
    """The standard form: minimise ``eta`` subject to one block of order ``2n + p``."""
    n, m = d.G.shape
    p = d.Cz.shape[0]
    X, Y, eta = cp.Variable((n, n), symmetric=True), cp.Variable((m, n)), cp.Variable()
    AX, CX = d.F @ X + d.G @ Y, d.Cz @ X + d.Dzu @ Y
    block = cp.bmat([[X - d.Bw @ d.Bw.T, AX, -d.Bw @ d.Dzw.T],
                     [AX.T, X, CX.T],
                     [-d.Dzw @ d.Bw.T, CX, eta * np.eye(p) - d.Dzw @ d.Dzw.T]])
    return cp.Problem(cp.Minimize(eta), [cp.PSD(block)]), eta, {"X": X, "eta": eta}


def phi(d: Data, X, eta):
    """``Phi = [[X - Bw Bw', -Bw Dzw'], [-Dzw Bw', eta I - Dzw Dzw']]`` for variables or arrays."""
    p = d.Cz.shape[0]
    rows = [[X - d.Bw @ d.Bw.T, -d.Bw @ d.Dzw.T], [-d.Dzw @ d.Bw.T, eta * np.eye(p) - d.Dzw @ d.Dzw.T]]
    return cp.bmat(rows) if isinstance(X, cp.Expression) else np.block(rows)


def eliminated(d: Data) -> tuple[cp.Problem, cp.Variable, dict]:
    """The eliminated form: ``Y`` removed by the projection lemma, blocks ``E1`` and ``E2 = Phi``."""
    n = d.F.shape[0]
    N = scipy.linalg.null_space(np.vstack([d.G, d.Dzu]).T)
    Nx, Nz = N[:n], N[n:]
    NA, NB = N.T @ np.vstack([d.F, d.Cz]), N.T @ np.vstack([d.Bw, d.Dzw])
    X, eta = cp.Variable((n, n), symmetric=True), cp.Variable()
    E1 = Nx.T @ X @ Nx + eta * (Nz.T @ Nz) - NA @ X @ NA.T - NB @ NB.T
    return cp.Problem(cp.Minimize(eta), [cp.PSD(E1), cp.PSD(phi(d, X, eta))]), eta, {"X": X, "eta": eta}


BUILD = {"standard": standard, "eliminated": eliminated}


def sizes(d: Data, form: str) -> tuple[list[int], int]:
    """Orders of the PSD blocks and the number of scalar decision variables."""
    n, m = d.G.shape
    p = d.Cz.shape[0]
    if form == "standard":
        return [2 * n + p], n * (n + 1) // 2 + m * n + 1
    return [n + p - m, n + p], n * (n + 1) // 2 + 1


def nnz_a(problem: cp.Problem) -> int:
    """Nonzeros of the constraint matrix ``A`` that cvxpy passes to Clarabel."""
    data, _, _ = problem.get_problem_data(cp.CLARABEL)
    return int(data["A"].nnz)


def gain_check(d: Data, run: Run) -> float:
    """``linfnorm`` of the closed loop of the eliminated form's gain at ``eta (1 + BACKOFF)``, over ``sqrt`` of it."""
    if run.X is None:
        return np.nan
    eta = run.eta * (1 + BACKOFF)
    X = 0.5 * (run.X + run.X.T)
    Abar, Bbar = np.vstack([d.F, d.Cz]), np.vstack([d.G, d.Dzu])
    PiB, PiA = np.linalg.solve(phi(d, X, eta), Bbar), np.linalg.solve(phi(d, X, eta), Abar)
    K = -np.linalg.solve(Bbar.T @ PiB, Bbar.T @ PiA)
    loop = control.ss(d.F + d.G @ K, d.Bw, d.Cz + d.Dzu @ K, d.Dzw, d.dt)
    norm, _ = control.linfnorm(loop)
    return float(norm) / np.sqrt(eta)


@dataclass
class Run:
    """Best times of one (form, solver, settings) over the repetitions, and the last solve's results."""

    cpu: float = np.inf
    wall: float = np.inf
    solver_wall: float = np.inf
    iterations: int | None = None
    eta: float = np.nan
    status: str = ""
    X: np.ndarray | None = None


def solve_once(d: Data, form: str, run: Run, solver: str, options: dict) -> None:
    """Build ``form`` afresh and time its whole ``problem.solve`` call; update ``run``."""
    problem, eta, variables = BUILD[form](d)
    c0, w0 = time.process_time(), time.perf_counter()
    try:
        problem.solve(solver=solver, **options)
    except cp.error.SolverError:
        run.status = "solver failed"
        return
    run.cpu, run.wall = min(run.cpu, time.process_time() - c0), min(run.wall, time.perf_counter() - w0)
    run.status, run.eta = problem.status, float(eta.value) if eta.value is not None else np.nan
    stats = problem.solver_stats
    run.iterations = stats.num_iters
    if stats.solve_time is not None:
        run.solver_wall = min(run.solver_wall, float(stats.solve_time))
    run.X = variables["X"].value


def row(d: Data, form: str, label: str, run: Run, reference: Run, check: float | None, nnz: int | str,
        eta_peer: float) -> str:
    """One table row; ratios and differences are taken to ``reference`` (the standard form, Clarabel tuned)."""
    orders, nvar = sizes(d, form)
    blocks = ", ".join(f"{k} ({k * (k + 1) // 2})" for k in orders)
    status = "" if run.status == "optimal" else f" ({run.status})"
    solved = np.isfinite(run.cpu)
    diff, ratio = ("", "") if run is reference or not solved else (
        f"{abs(run.eta - reference.eta) / reference.eta:.1e}", f"{reference.cpu / run.cpu:.2f}")
    iterations = "n/a" if run.iterations is None else run.iterations
    inside = f"{run.solver_wall:.3g}" if np.isfinite(run.solver_wall) else "n/a"
    times, eta, error = ((f"{run.cpu:.3g} ({run.wall:.3g})", f"{run.eta:.10g}",
                          f"{(run.eta - eta_peer) / eta_peer:.1e}") if solved else ("", "", ""))
    return (f"| {d.F.shape[0]} | {form} | {label} | {blocks} | {nvar} | {nnz} | {iterations}{status} | "
            f"{times} | {inside} | {eta} | {error} | {diff} | {ratio} | "
            f"{'' if check is None else f'{check:.7f}'} |")


def versions(with_cvxopt: bool) -> str:
    """The solver stack's versions, CVXOPT marked as not a dependency."""
    text = (f"cvxpy {cp.__version__}, Clarabel {importlib.metadata.version('clarabel')}, "
            f"python-control {control.__version__}")
    if with_cvxopt:
        text += f", CVXOPT {importlib.metadata.version('cvxopt')} (installed separately, not a dependency)"
    return text + "."


def ratio(a: float, b: float) -> str:
    """``a / b`` to two decimals, or "failed" when ``b`` was not measured (the solver failed)."""
    return f"{a / b:.2f}" if np.isfinite(b) else "failed"


def summary(found: dict[int, dict], with_cvxopt: bool) -> str:
    """The closing paragraph: the measured ratios, sizes and gain checks per n (Clarabel tuned)."""
    def each(fmt) -> str:
        return "; ".join(f"n = {n}: {fmt(f)}" for n, f in found.items())

    return (
        "Clarabel tuned, CPU time of the standard form over that of the eliminated form: "
        + each(lambda f: f"{ratio(f['std'], f['elim'])} ({f['std']:.3g} s against {f['elim']:.3g} s)") + ". "
        "Wall-clock time on one thread against Clarabel's default threads, standard form; eliminated form: "
        + each(lambda f: "; ".join(f"{f['wall'][form]:.3g} s against {f['threads'][form]:.3g} s" for form in FORMS))
        + ". "
        "Total svec dimension of the PSD blocks, standard against eliminated: "
        + each(lambda f: f"{f['svec']['standard']} against {f['svec']['eliminated']}") + "; "
        "nonzeros of the constraint matrix: "
        + each(lambda f: f"{f['nnz']['standard']} against {f['nnz']['eliminated']}")
        + " (every entry of E1 depends on every entry of X). "
        "Relative error of eta against the Riccati peer, standard and eliminated: "
        + each(lambda f: f"{f['error']['standard']:.1e} and {f['error']['eliminated']:.1e}") + ". "
        "Gain check of the eliminated form (< 1: the recovered gain holds the level): "
        + each(lambda f: f"{f['check']:.7f}") + ". "
        + ("CVXOPT (defaults), CPU time of the standard form with Clarabel tuned over that of CVXOPT on the "
           "standard and on the eliminated form: "
           + each(lambda f: " and ".join(ratio(f["std"], f["cvxopt"][form]) for form in FORMS))
           + ". " if with_cvxopt else "CVXOPT: not installed. ")
        + f"Load average at the end: {os.getloadavg()[0]:.2f}.")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[20, 30, 40, 50], help="numbers of states n")
    ap.add_argument("--reps", type=int, default=3, help="timed runs per form (best taken)")
    ap.add_argument("--shift", type=float, default=1e-6,
                    help="lift of the Riccati solution's smallest eigenvalue, relative to its largest (library: 1e-6)")
    ap.add_argument("--one-rep-from", type=int, default=50, help="one timed run from this n on")
    ap.add_argument("--out", type=Path,
                    default=Path(__file__).resolve().parents[1] / "results" / "hinf_sdp_forms.md")
    args = ap.parse_args(argv)
    if args.reps < 1:
        raise ValueError(f"--reps must be >= 1, got {args.reps}")
    with_cvxopt = importlib.util.find_spec("cvxopt") is not None
    warm = scaled(3, args.shift)
    for form in FORMS:  # imports and first-call costs of cvxpy and Clarabel out of the timings
        BUILD[form](warm)[0].solve(solver="CLARABEL", **TUNED)
    now, load = datetime.datetime.now(datetime.UTC), os.getloadavg()
    command = "python -m benchmarks.investigations.benchmarks_hinf_sdp_forms " + " ".join(
        sys.argv[1:] if argv is None else argv)
    lines = [("# The H-infinity level SDP of one discrete plant: standard LMI against the eliminated form"), "",
             (f"{now:%Y-%m-%d %H:%M} UTC, {platform.machine()} ({platform.platform()}), Python "
              f"{platform.python_version()}, {os.cpu_count()} cores, load average {load[0]:.2f} {load[1]:.2f} "
              f"{load[2]:.2f} at start (shared machine). Command: `{command.strip()}`. {versions(with_cvxopt)}"), "",
             ("Plant `benchmarks.bench_hinf.case(n, 0)` (m = 2, q = 2, p = 4, `Dzw = 0`) in the scaled LQR "
              f"coordinates described in the script's docstring (shift {args.shift:g}); `eta = gamma^2` of the scaled "
              "data. "
              "*Clarabel tuned*: `tol_gap_abs = tol_gap_rel = tol_feas = 1e-8`, chordal decomposition and "
              "iterative refinement off, one thread; *default threads*: the same on Clarabel's default threads; "
              "*defaults*: the solver's defaults. Time: the whole `problem.solve` call (cvxpy's compilation "
              "included), CPU time of the process with the wall-clock time in "
              f"brackets, best of {args.reps} run(s) (one run from n = {args.one_rep_from} on), the forms "
              "alternating. Solver wall: the solve time the solver reports to cvxpy (best run). "
              "PSD blocks: order (svec dimension). nnz(A): nonzeros of the constraint matrix passed to the "
              "solver. eta rel. error: `(eta - eta_peer) / eta_peer`, `eta_peer` the square of the level found by "
              "the Riccati bisection of `benchmarks.bench_hinf.peer_hinf` (rtol 1e-8) on the same data. "
              "eta rel. diff. and CPU ratio: against the standard form with Clarabel tuned at the same n "
              "(its CPU time over this row's). Gain check: `linfnorm` of the closed loop with the eliminated "
              f"form's gain at `eta (1 + {BACKOFF:g})`, over the square root of that level."), "",
             ("| n | form | solver | PSD blocks | variables | nnz(A) | iterations | CPU [s] (wall) | solver wall [s] "
              "| eta | eta rel. error | eta rel. diff. | CPU ratio | gain check |"),
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    found: dict[int, dict] = {}
    for i, n in enumerate(args.sizes):
        d = scaled(n, args.shift)
        eta_peer = float(peer_hinf(d, d.Bw, d.Cz, d.Dzu)[0]) ** 2  # Dzw = 0, as the peer assumes
        nnz = {form: nnz_a(BUILD[form](d)[0]) for form in FORMS}
        svec = {form: sum(k * (k + 1) // 2 for k in sizes(d, form)[0]) for form in FORMS}
        reps = args.reps if n < args.one_rep_from else 1
        settings = [("Clarabel tuned", "CLARABEL", TUNED),
                    ("Clarabel tuned, default threads", "CLARABEL", {**TUNED, "max_threads": 0})]
        if i == 0:
            settings.append(("Clarabel defaults", "CLARABEL", {}))
        for label, solver, options in settings:
            runs = {form: Run() for form in FORMS}
            for _ in range(reps):
                for form in FORMS:
                    solve_once(d, form, runs[form], solver, options)
            check = None
            if label == "Clarabel tuned":
                reference, check = runs["standard"], gain_check(d, runs["eliminated"])
                found[n] = dict(std=reference.cpu, elim=runs["eliminated"].cpu, check=check, nnz=nnz, svec=svec,
                                error={form: (runs[form].eta - eta_peer) / eta_peer for form in FORMS},
                                wall={form: runs[form].wall for form in FORMS})
            elif label == "Clarabel tuned, default threads":
                found[n]["threads"] = {form: runs[form].wall for form in FORMS}
            for form in FORMS:
                lines.append(row(d, form, label, runs[form], reference, check if form == "eliminated" else None,
                                 nnz[form], eta_peer))
                print(lines[-1], flush=True)
        if with_cvxopt:
            runs = {form: Run() for form in FORMS}
            for _ in range(reps):
                for form in FORMS:
                    solve_once(d, form, runs[form], "CVXOPT", {})
            found[n]["cvxopt"] = {form: runs[form].cpu for form in FORMS}
            for form in FORMS:
                lines.append(row(d, form, "CVXOPT defaults", runs[form], reference, None, "", eta_peer))
                print(lines[-1], flush=True)
    lines += ["", summary(found, with_cvxopt)]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines) + "\n")
    print(lines[-1])
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
