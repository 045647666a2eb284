"""Stage 4 of the synthesis: the optimal level ``gamma_opt`` (minimise ``gamma^2`` subject to the LMIs).

The LMIs are non-strict here: the minimum is the infimum over strictly
feasible points. :func:`minimise_level` tries, in order:

1. the preferred coordinates (the LQR ones of a single plant, at
   ``LEVEL_TOL`` with a first attempt without iterative refinement and
   without Clarabel's chordal decomposition, over the projected blocks
   where :func:`projected_form` says so and the full block if that fails;
   otherwise the balanced ones at ``LEVEL_TOL_GENERAL``);
2. if that solver fails (``ConvergenceError``) in the LQR coordinates: the
   balanced ones;
3. if the extended (slack-variable) problem still fails: the standard one
   first (feasible implies the extended one is too), then the extended one
   in coordinates where the standard ``X`` is ~ I and with ``z`` scaled so
   that the extended level is at most 1;
4. if the accepted solve is only ``optimal_inaccurate``: the same problem
   again in coordinates where its own solution is ~ I (a *polish*); the
   lower of the two certified levels is kept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ... import _cvx
from ...errors import ConvergenceError, InfeasibleError
from . import tolerances as tol
from .coordinates import Coordinates, recentred
from .lmis import Point, blocks, projected_blocks, projected_gain, variables
from .problem import Problem

__all__ = ["Optimum", "Solved", "minimise_level", "solve_level", "projected_form"]


class Solved(NamedTuple):
    """One level minimisation: the point (arrays), the scaled level ``(level_scale z_scale gamma)^2``, the report."""

    point: Point
    level_sq: float
    report: _cvx.SolveReport


@dataclass(frozen=True, eq=False)
class Optimum:
    """The solution of the level minimisation.

    Attributes
    ----------
    point : Point
        The optimal ``(X, Y)`` (or ``(P, S, L)``) as arrays, in ``data``'s coordinates.
    data : Coordinates
        The coordinates of ``point``.
    centring : Coordinates
        Where centring problems are posed: the balanced coordinates, or those
        of the standard solution when the extended problem was restarted from it.
    gamma_opt : float
        The optimal level (unscaled).
    preconditioned : bool
        ``data`` are the LQR coordinates of a single plant.
    report : robustctl._cvx.SolveReport
        The accepted solve.
    solves : tuple of dict
        Every solve of the stage (``SolveReport.as_dict``), in order.
    """

    point: Point
    data: Coordinates
    centring: Coordinates
    gamma_opt: float
    preconditioned: bool
    report: _cvx.SolveReport
    solves: tuple[dict, ...]


def solve_level(problem: Problem, data: Coordinates, *, z_scale: float = 1.0, preconditioned: bool = False,
                extended: bool | None = None) -> Solved:
    """One minimisation of the scaled level ``(level_scale z_scale gamma)^2`` (``data.level_scale``).

    Raises InfeasibleError (no gain at any level, e.g. an input bound too
    tight or no common Lyapunov matrix) or ConvergenceError (solver failure).
    """
    import cvxpy as cp

    extended = problem.extended if extended is None else extended
    if preconditioned and not extended and projected_form(problem, data.n):
        found = _solve_projected(problem, data, z_scale)
        if found is not None:
            return found
    V = variables(data.n, data.m, len(data.F), extended, uncertain=problem.uncertainty is not None)
    level_sq = cp.Variable(name="level_sq")
    rep = _cvx.solve_sdp(cp.Minimize(level_sq),
                         blocks(problem, data, V, level_sq, z_scale=z_scale),
                         solver=problem.solver, tol=tol.LEVEL_TOL if preconditioned else tol.LEVEL_TOL_GENERAL,
                         infeasible_msg=f"no H-infinity state feedback: {problem.infeasibility()}",
                         fast=preconditioned, decompose=not preconditioned)
    return Solved(V.values(), float(_cvx.value(level_sq)), rep)


def projected_form(problem: Problem, n: int) -> bool:
    """Whether the level of ``problem`` is minimised over the projected blocks (:func:`.lmis.projected_blocks`).

    The plain discrete problem (one plant, standard LMI, no input bound,
    pole region or uncertainty) with a backoff, up to ``PROJECTED_MAX_N``
    states: there the two smaller blocks solve faster than the full one.
    """
    return problem.discrete and not problem.beyond_plain() and problem.backoff > 0 and n <= tol.PROJECTED_MAX_N


def _solve_projected(problem: Problem, data: Coordinates, z_scale: float) -> Solved | None:
    """The level over the projected blocks, with ``Y = K X`` from :func:`.lmis.projected_gain`; ``None`` on failure.

    The gain is the weighted least-squares one at the optimum ``(X, eta)``
    itself (``Phi`` floored where the optimum makes it singular): on the
    plants tried it is the gain ``Y X^-1`` of the full block's optimum to
    the accuracy of the solve, and like that one it is certified at the
    backed-off level by :func:`.gains.optimum_certified`. A failure
    (solver, certificate or ``Phi``) leaves the decision to the full block.
    """
    import cvxpy as cp

    X, level_sq = cp.Variable((data.n, data.n), symmetric=True, name="X"), cp.Variable(name="level_sq")
    try:
        rep = _cvx.solve_sdp(cp.Minimize(level_sq), projected_blocks(data, X, level_sq, z_scale),
                             solver=problem.solver, tol=tol.LEVEL_TOL, fast=True, decompose=False,
                             infeasible_msg=f"no H-infinity state feedback: {problem.infeasibility()}")
    except (ConvergenceError, InfeasibleError):
        return None
    X_opt, eta = _cvx.value(X), float(_cvx.value(level_sq))
    X_opt = 0.5 * (X_opt + X_opt.T)
    K = projected_gain(data, X_opt, eta, z_scale)
    if K is None:
        return None
    return Solved(Point(X=X_opt, Y=K @ X_opt), eta, rep)


def minimise_level(problem: Problem, balanced: Coordinates, lqr: Coordinates | None) -> Optimum:
    """The optimal level and point, with the fallbacks of the module docstring."""
    try:
        try:
            data, preconditioned = (lqr, True) if lqr is not None else (balanced, False)
            found = solve_level(problem, data, preconditioned=preconditioned)
        except ConvergenceError:
            if not preconditioned:
                raise
            data, preconditioned = balanced, False  # the LQR coordinates may not suit this problem
            found = solve_level(problem, data)
        centring, z_scale, solves = balanced, 1.0, []
    except ConvergenceError:
        if not problem.extended:
            raise
        start = _standard_start(problem, balanced)
        if start is None:
            raise
        centring, z_scale, standard_report = start
        data, preconditioned, solves = centring, False, [standard_report.as_dict()]
        found = solve_level(problem, data, z_scale=z_scale)
    solves.append(found.report.as_dict())
    if found.report.status != "optimal":
        polished = _polish(problem, data, found, z_scale, preconditioned)
        if polished is not None:
            solves.append(polished[1].report.as_dict())
            if polished[1].level_sq < found.level_sq:  # both certified: the lower is nearer the infimum
                data, found = polished
    gamma_opt = float(np.sqrt(max(found.level_sq, 0.0))) / (data.level_scale * z_scale)
    return Optimum(point=found.point, data=data, centring=centring, gamma_opt=gamma_opt,
                   preconditioned=preconditioned, report=found.report, solves=tuple(solves))


def _standard_start(problem: Problem, balanced: Coordinates):
    """Step 3: ``(coordinates, z_scale, report)`` from the standard problem for the extended one, or ``None``."""
    try:
        standard = solve_level(problem, balanced, extended=False)
    except (ConvergenceError, InfeasibleError):
        return None
    moved = recentred(balanced, standard.point.shape_matrix(), tol.POLISH_REG)
    if moved is None or not standard.level_sq > 0:
        return None
    return moved[0], 1.0 / float(np.sqrt(standard.level_sq)), standard.report


def _polish(problem: Problem, data: Coordinates, found: Solved, z_scale: float, preconditioned: bool):
    """Step 4: ``(coordinates, Solved)`` of the re-solve, or ``None`` if it fails."""
    moved = recentred(data, found.point.shape_matrix(), tol.POLISH_REG)
    if moved is None:
        return None
    try:
        return moved[0], solve_level(problem, moved[0], z_scale=z_scale, preconditioned=preconditioned)
    except (ConvergenceError, InfeasibleError):
        return None
