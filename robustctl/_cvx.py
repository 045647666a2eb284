"""The one place where :mod:`robustctl` solves a cvxpy problem.

:func:`solve_sdp` takes named linear-matrix-inequality blocks and plain
constraints, builds the cvxpy problem, runs the solver with explicit
tolerances, checks the status, and checks the *certificate*: the smallest
eigenvalue of every LMI block evaluated at the returned point. Nothing else in
the package calls ``Problem.solve``.

Conventions
-----------
* An LMI ``M >= 0`` is imposed as ``M - margin * I >> 0``: cvxpy's PSD
  constraint constrains the symmetric part ``(M + M') / 2`` (and passes the
  solver its lower triangle), so the blocks, symmetric by construction, are
  not symmetrised again (that doubled the expression tree that cvxpy
  canonicalises: a third of its compilation time). A block that is not
  symmetric does not pass silently: the asymmetry is checked after the
  solve, with the certificate.
* A status of ``optimal`` is accepted; ``optimal_inaccurate`` is accepted
  only if the certificate holds, and is recorded; ``infeasible`` (also
  ``infeasible_inaccurate``) raises :class:`~robustctl.errors.InfeasibleError`
  with the caller's explanation; anything else raises
  :class:`~robustctl.errors.ConvergenceError`.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .errors import ConvergenceError, InfeasibleError

if TYPE_CHECKING:  # cvxpy itself is imported on first use
    import cvxpy as cp

__all__ = ["LMI", "SolveReport", "solve_sdp", "check_solver", "SDP_SOLVERS", "certificate", "value", "totals",
           "SOLVER_TOL"]

# Clarabel settings (cvxpy passes them through). Tight on purpose: the
# H-infinity level must agree to 1e-5 relative with an independent Riccati
# computation, and the problems are small. The other settings are
# Clarabel's defaults (equilibration, faer's LDL, chordal decomposition
# unless the caller asks for whole blocks with ``decompose=False``): other
# values measured no better on the H-infinity level minimisation (measured in
# the documentation, Validation: Benchmarks), except the number of threads
# (SINGLE_THREAD_PSD).
SOLVER_TOL = 1e-10
#: Problems whose PSD blocks have at most this many free entries in total
#: (``sum k (k + 1) / 2``) are solved by Clarabel on one thread (its
#: ``max_threads``); larger ones on its default threads. On small
#: problems the thread pool's synchronisation costs more than the parallel
#: factorisation saves (a quarter of the process's time in the kernel's
#: scheduler at n = 20), and the experiment runner's processes already use
#: every core; the H-infinity level minimisation of n = 50 states (5460
#: entries) is faster in wall-clock time on two threads.
SINGLE_THREAD_PSD = 2500
_CLARABEL = dict(tol_gap_abs=SOLVER_TOL, tol_gap_rel=SOLVER_TOL, tol_feas=SOLVER_TOL,
                 tol_infeas_abs=1e-10, tol_infeas_rel=1e-10, tol_ktratio=1e-8,
                 reduced_tol_gap_abs=1e-7, reduced_tol_gap_rel=1e-7, reduced_tol_feas=1e-7,
                 max_iter=200)
# Certificate: an LMI block counts as satisfied if its smallest eigenvalue is
# at least -_CERT_TOL * max(1, largest |entry|) (solver rounding).
_CERT_TOL = 1e-7


@dataclass(frozen=True)
class LMI:
    """A named block ``M >= margin * I``.

    ``M`` is a square cvxpy expression (or, for :func:`certificate`, a
    constant array); ``margin`` a float or a scalar cvxpy expression (e.g. a
    variable that the objective maximises).
    """

    name: str
    M: cp.Expression | np.ndarray
    margin: float | cp.Expression = 0.0


@dataclass(frozen=True)
class SolveReport:
    """What a solve returned: status, value, timing, iterations and the certificate.

    ``certificate`` maps each LMI name to the smallest eigenvalue of its
    symmetrised block at the solution (before subtracting the margin).
    """

    status: str
    value: float
    solver: str
    tol: float
    solve_time: float
    setup_time: float | None
    iterations: int | None
    certificate: Mapping[str, float] = field(default_factory=dict)

    def as_dict(self, prefix: str = "") -> dict:
        return {f"{prefix}status": self.status, f"{prefix}value": self.value,
                f"{prefix}solver": self.solver, f"{prefix}tol": self.tol, f"{prefix}solve_time": self.solve_time,
                f"{prefix}iterations": self.iterations,
                f"{prefix}certificate": dict(self.certificate)}


def totals(solves: Sequence[Mapping]) -> dict:
    """``solve_time`` (s) and ``iterations`` summed over solves (each a ``SolveReport.as_dict()``)."""
    return {"solve_time": float(sum(s["solve_time"] for s in solves)),
            "iterations": int(sum(s["iterations"] or 0 for s in solves))}


def certificate(lmis: Sequence[LMI]) -> dict[str, float]:
    """Smallest eigenvalue of each (symmetrised) block at the current values, by name.

    For blocks built from constants (a candidate point) or from variables
    holding a solution. Raises ConvergenceError on non-finite values and
    ValueError on a block that is not symmetric.
    """
    return _evaluate(lmis, "the point has")[0]


def value(var: cp.Variable) -> np.ndarray:
    """The value of ``var`` after :func:`solve_sdp`; ConvergenceError if the solver left it unset."""
    val = var.value
    if val is None:
        raise ConvergenceError(f"the solver returned no value for the variable {var.name()!r}")
    return np.asarray(val, dtype=float)


def _evaluate(lmis: Sequence[LMI], who: str) -> tuple[dict[str, float], dict[str, float]]:
    """``(smallest eigenvalue, max(1, largest |entry|))`` of every block, by name."""
    cert, scales = {}, {}
    for lmi in lmis:
        val = np.asarray(getattr(lmi.M, "value", lmi.M), dtype=float)
        if not np.all(np.isfinite(val)):
            raise ConvergenceError(f"{who} non-finite values in LMI {lmi.name!r}")
        scale = max(1.0, float(np.max(np.abs(val))))
        asym = float(np.max(np.abs(val - val.T)))
        if asym > 1e-8 * scale:
            raise ValueError(f"internal error: LMI block {lmi.name!r} is not symmetric (asymmetry {asym:.3g})")
        cert[lmi.name] = float(np.linalg.eigvalsh(0.5 * (val + val.T)).min())
        scales[lmi.name] = scale
    return cert, scales


def _settings(solver: str, tol: float, refine: bool = True, decompose: bool = True, psd_size: int = 0) -> dict:
    if solver != "CLARABEL":
        return {}
    out = dict(_CLARABEL)
    out.update(tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, iterative_refinement_enable=refine,
               chordal_decomposition_enable=decompose, max_threads=1 if psd_size <= SINGLE_THREAD_PSD else 0)
    return out


#: The SDP solvers that cvxpy can call (:func:`check_solver` checks which are installed).
SDP_SOLVERS = ("CLARABEL", "SCS", "MOSEK", "CVXOPT", "COPT", "SDPA")


@functools.lru_cache(maxsize=1)
def _installed_sdp_solvers() -> tuple[str, ...]:
    import cvxpy as cp  # installed_solvers() tries every import: ask once

    return tuple(s for s in cp.installed_solvers() if s in SDP_SOLVERS)


def check_solver(solver, *, installed: bool = True) -> str:
    """Validate a cvxpy solver name (upper-cased); raise ValueError listing the valid ones.

    ``installed=False`` only checks that it names one of :data:`SDP_SOLVERS`
    (cvxpy is then not imported; the synthesis's fast path defers the rest).
    """
    if not isinstance(solver, str):
        raise TypeError(f"solver must be a string naming a cvxpy solver, got {type(solver).__name__}")
    name = solver.upper()
    if not installed:
        if name not in SDP_SOLVERS:
            raise ValueError(f"solver must name a cvxpy SDP solver, one of {list(SDP_SOLVERS)}; got {solver!r}")
        return name
    sdp = list(_installed_sdp_solvers())
    if name not in sdp:
        raise ValueError(f"solver must be an installed SDP solver, one of {sdp}; got {solver!r}")
    return name


def solve_sdp(objective, lmis: Sequence[LMI], constraints: Sequence = (), *, solver: str = "CLARABEL",
              tol: float = SOLVER_TOL, infeasible_msg: str = "the LMI problem is infeasible",
              fast: bool = False, decompose: bool = True) -> SolveReport:
    """Solve ``objective`` subject to the LMI blocks and the other constraints.

    Parameters
    ----------
    objective : cvxpy.Minimize or cvxpy.Maximize
    lmis : sequence of LMI
        Each block is imposed as ``M - margin I >> 0`` (cvxpy: the symmetric part of ``M``).
    constraints : sequence of cvxpy constraints
        Anything else (equalities, scalar bounds).
    solver : str
        A cvxpy solver name; Clarabel gets tight explicit tolerances.
    tol : float
        Clarabel's ``tol_gap_abs``, ``tol_gap_rel`` and ``tol_feas``.
    infeasible_msg : str
        Message of the :class:`InfeasibleError` raised if the problem is
        infeasible or the certificate fails.
    fast : bool
        Clarabel only: first try without iterative refinement of the KKT
        solves (about half the time on dense LMIs) and keep that result only
        if its status is ``optimal``. Suits problems whose solution is
        checked again (e.g. a level minimisation whose gain is certified
        separately); margins of centring problems come out smaller.
    decompose : bool
        Clarabel only: its chordal decomposition of the PSD blocks (the
        default). A block whose sparsity leaves one clique of nearly its own
        size (the discrete H-infinity block: ``2 n`` of ``2 n + p``) gains
        nothing from it but overlap variables that couple the cliques in the
        KKT system; ``False`` factors the block whole.

    Returns
    -------
    SolveReport
        The variables of the problem hold the solution (``var.value``).
    """
    import cvxpy as cp

    cons = list(constraints)
    for lmi in lmis:
        M = lmi.M
        cons.append(cp.PSD(M - lmi.margin * np.eye(M.shape[0])))
    prob = cp.Problem(objective, cons)
    # A solver failure ("insufficient progress" at tight tolerances on nearly
    # degenerate problems) is retried twice with 100x looser tolerances, after
    # the optional fast attempt. The tolerance used is reported; times and
    # iterations are summed over the attempts.
    schedule = [(True, tol)] if solver != "CLARABEL" else \
        ([(False, tol)] if fast else []) + [(True, tol), (True, 1e2 * tol), (True, 1e4 * tol)]
    failure, solve_time, iterations = None, 0.0, 0
    psd_size = sum(lmi.M.shape[0] * (lmi.M.shape[0] + 1) // 2 for lmi in lmis)
    for refine, attempt_tol in schedule:
        try:
            with warnings.catch_warnings():
                # cvxpy warns on 'optimal_inaccurate'; the status is checked below instead.
                warnings.simplefilter("ignore", UserWarning)
                prob.solve(solver=solver, **_settings(solver, attempt_tol, refine, decompose, psd_size))
        except cp.error.SolverError as exc:
            failure = f"{solver} failed ({exc})"
        except BaseException as exc:  # a Rust panic inside Clarabel surfaces as pyo3's PanicException
            if type(exc).__name__ != "PanicException":
                raise
            failure = f"{solver} crashed internally ({exc})"
        else:
            solve_time += float(prob.solver_stats.solve_time or 0.0)
            iterations += int(prob.solver_stats.num_iters or 0)
            if prob.status == cp.OPTIMAL or (refine and prob.status in (
                    cp.OPTIMAL_INACCURATE, cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE)):
                break
            failure = f"{solver} returned status {prob.status!r}"
    status = prob.status
    if status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE, cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        raise ConvergenceError(f"{failure or 'the solver failed'} on the LMI problem, also with relaxed "
                               f"tolerances; the problem is probably infeasible or nearly so: {infeasible_msg}")
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        raise InfeasibleError(f"{infeasible_msg} (solver status: {status})")
    cert, scales = _evaluate(lmis, f"{solver} returned")
    bad = [f"{name}: smallest eigenvalue {eig:.3g}" for name, eig in cert.items()
           if eig < -_CERT_TOL * scales[name]]
    if bad:
        raise InfeasibleError(f"{infeasible_msg}: {solver} reported {status!r} but the certificate "
                              f"fails ({'; '.join(bad)})")
    return SolveReport(status=status, value=float(prob.value), solver=solver, tol=attempt_tol,
                       solve_time=solve_time, setup_time=prob.solver_stats.setup_time, iterations=iterations,
                       certificate=cert)
