"""Stage 5 of the synthesis: a gain with a strictly feasible certificate at the returned level.

At the optimum ``X`` can be nearly singular and ``K = Y X^-1`` huge (in
continuous time the optimum is often reached only as ``|K| -> inf``), so
the gain is certified at ``gamma = (1 + backoff) gamma_opt``. The
strategies, each a function ``(problem, optimum, backoff) -> Attempt``, are
tried in this order (:func:`gain_near_optimum`):

1. :func:`optimum_certified` (discrete time, one plant, standard LMI): the
   optimum's own gain, with a strictly feasible ``(X, K X)`` at the level
   built from a Riccati equation of the closed loop (no second solve);
2. :func:`centred`: a second problem at the level maximising the smallest
   eigenvalue ``t`` of every block (a well-centred strictly feasible point);
3. :func:`conditioned`: maximise ``lambda_min(X)`` (``S`` for the extended
   LMI) under ``X <= X_UPPER lambda_max(X_opt)`` with the H-infinity blocks
   at least a margin that scales with the backoff: the best-conditioned
   ``X``, hence a moderate ``K``;
4. :func:`conditioned_recentred`: the same in coordinates where the optimal
   ``X`` is ~ I;

then 2-4 again with the backoff raised by the factors ``BACKOFF_STEPS``.
A candidate is accepted only on the eigenvalues of every LMI block
evaluated at it (:func:`robustctl._cvx.certificate` or the solver's
certificate). ``backoff=0`` returns the optimal point itself
(:func:`at_optimum`); a fixed ``gamma`` is :func:`gain_at_level`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ... import _cvx
from ...errors import ConvergenceError, InfeasibleError
from . import tolerances as tol
from .coordinates import Coordinates, recentred
from .level import Optimum
from .lmis import Point, blocks, is_strict, variables
from .problem import Problem

__all__ = ["Gain", "Attempt", "gain_near_optimum", "gain_at_level", "at_optimum", "optimum_certified",
           "riccati_certified",
           "centred", "conditioned", "conditioned_recentred", "STRATEGIES"]


@dataclass(frozen=True, eq=False)
class Gain:
    """A certified point: ``point`` (arrays) in ``data``'s coordinates.

    ``certificate`` maps every LMI block to its smallest eigenvalue at the
    point; ``margin`` is the strictness margin of the route (``t``, relative
    to ``x_upper`` for the conditioned routes); ``route`` is reported as
    ``info["gain_from"]``.
    """

    point: Point
    data: Coordinates
    certificate: dict
    margin: float
    route: str


@dataclass(frozen=True, eq=False)
class Attempt:
    """What one strategy produced: a gain, or a failure (either may come with solves)."""

    gain: Gain | None = None
    solves: tuple[dict, ...] = ()
    failure: Exception | None = None


def at_optimum(problem: Problem, opt: Optimum) -> Gain:
    """``backoff=0``: the optimal point, with the eigenvalues of ``X`` floored at ``OPTIMUM_X_FLOOR lambda_max``.

    At a singular optimum the smallest eigenvalue of the solver's ``X`` is
    rounding noise of either sign, and its sign decides the direction of the
    unbounded part of ``K = Y X^-1``: a negative one gives a destabilising
    gain. The floor makes ``K`` the member of the optimal family with
    ``X > 0``, independent of the last bits; a well-conditioned ``X`` is
    unchanged. (The extended LMI's slack ``S`` is not symmetric and is kept.)
    """
    point = opt.point
    if not point.extended:
        lam, U = np.linalg.eigh(point.X)
        point = Point(X=(U * np.maximum(lam, tol.OPTIMUM_X_FLOOR * lam[-1])) @ U.T, Y=point.Y)
    return Gain(point, opt.data, dict(opt.report.certificate), 0.0, "optimum")


def optimum_certified(problem: Problem, opt: Optimum, backoff: float) -> Attempt:
    """The optimum's gain ``K`` with a Riccati-built strictly feasible ``(X, K X)`` at the backed-off level.

    Discrete time, one vertex, standard LMI, no uncertainty (otherwise not
    applicable); :func:`riccati_certified` builds and checks the point.
    """
    if not problem.discrete or problem.extended or problem.polytopic or problem.uncertainty is not None:
        return Attempt()
    gain = riccati_certified(problem, opt.data, opt.point.gain(), opt.gamma_opt * (1.0 + backoff), backoff,
                             "optimum-certified")
    return Attempt(gain)


def riccati_certified(problem: Problem, data: Coordinates, K: np.ndarray, gamma: float, backoff: float,
                      route: str) -> Gain | None:
    """A strictly feasible ``(X, K X)`` of the LMI blocks at the level ``gamma`` for a given gain, or ``None``.

    One plant, standard LMI, no uncertainty. With
    ``(A, B, C, D) = (F + G K, Bw, b (Cz + Dzu K), b Dzw)`` at the output
    scaling ``b`` of level 1, the Schur complement of the H-infinity block
    with respect to its last block row is, in discrete time, ``X - A X A' -
    B B' - (A X C' + B D') (I - C X C' - D D')^-1 (.)'`` and in continuous
    time ``-(A X + X A') - B B' - (X C' + B D') (I - D D')^-1 (.)'``; the
    stabilising solution of the Riccati equation setting it to ``eps I``
    (scipy's ``solve_discrete_are`` / ``solve_continuous_are`` with the
    indefinite weight ``D D' - I``) makes every block strictly positive
    when ``||T_zw(K)||_inf`` is below the level. ``eps`` is tried at
    ``CERTIFY_EPS`` times ``backoff``. The point is accepted only if the
    smallest eigenvalue of *every* LMI block (input bounds included)
    evaluated at it exceeds ``STRICT``: the certificate does not rely on the
    Riccati solver. The margin is the smallest eigenvalue of the
    H-infinity block.
    """
    z_scale = 1.0 / (data.level_scale * gamma)
    A = data.F[0] + data.G[0] @ K
    B, C, D = data.Bw, z_scale * (data.Cz + data.Dzu @ K), z_scale * data.Dzw
    are = scipy.linalg.solve_discrete_are if problem.discrete else scipy.linalg.solve_continuous_are
    for eps in tol.CERTIFY_EPS:
        try:
            with np.errstate(all="ignore"):
                X = are(A.T, C.T, B @ B.T + eps * backoff * np.eye(data.n), D @ D.T - np.eye(data.p), s=B @ D.T)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if not np.all(np.isfinite(X)):
            continue
        X = 0.5 * (X + X.T)
        point = Point(X=X, Y=K @ X)
        cert = _cvx.certificate(blocks(problem, data, point, 1.0, z_scale=z_scale))
        if min(cert.values()) > tol.STRICT:
            return Gain(point, data, cert, cert["hinf[0]"], route)
    return None


def centred(problem: Problem, opt: Optimum, backoff: float) -> Attempt:
    """Maximise the common margin ``t <= 1`` of every block at the backed-off level (centring coordinates)."""
    return _centring(problem, opt.centring, opt, backoff, "margin")


def conditioned(problem: Problem, opt: Optimum, backoff: float) -> Attempt:
    """Maximise ``lambda_min(X)`` below ``X_UPPER lambda_max(X_opt)`` at the backed-off level."""
    return _centring(problem, opt.centring, opt, backoff, "conditioned")


def conditioned_recentred(problem: Problem, opt: Optimum, backoff: float) -> Attempt:
    """:func:`conditioned` in coordinates where the optimal ``X`` is ~ I (not applicable if it is unusable)."""
    moved = recentred(opt.centring.to(np.eye(opt.data.n)), _optimal_lyapunov(opt), tol.RECENTRE_REG)
    if moved is None:
        return Attempt()
    return _centring(problem, moved[0], opt, backoff, "conditioned-recentred")


#: The strategies repeated at every backoff step, in order.
STRATEGIES: tuple[Callable[[Problem, Optimum, float], Attempt], ...] = (centred, conditioned, conditioned_recentred)


def _attempts(backoff: float) -> Iterator[tuple[Callable[[Problem, Optimum, float], Attempt], float]]:
    yield optimum_certified, backoff
    for factor in tol.BACKOFF_STEPS:
        for strategy in STRATEGIES:
            yield strategy, backoff * factor


def gain_near_optimum(problem: Problem, opt: Optimum) -> tuple[Gain, float, tuple[dict, ...]]:
    """The first gain of the strategies in order: ``(gain, backoff used, solves)``; the last failure if none."""
    if problem.backoff == 0:
        return at_optimum(problem, opt), 0.0, ()
    solves: list[dict] = []
    failure: Exception | None = None
    for strategy, backoff in _attempts(problem.backoff):
        attempt = strategy(problem, opt, backoff)
        solves += attempt.solves
        if attempt.gain is not None:
            return attempt.gain, backoff, tuple(solves)
        failure = attempt.failure or failure
    raise failure or ConvergenceError("no gain strategy applied")  # the centring ones always report why


def gain_at_level(problem: Problem, data: Coordinates, gamma: float) -> tuple[Gain, tuple[dict, ...]]:
    """A fixed level: the largest common margin ``t <= 1`` of every block; InfeasibleError unless ``t > STRICT``.

    An always-feasible problem (``t`` may be negative) whose sign decides feasibility.
    """
    infeasible = f"no gain achieves gamma={gamma:.6g}: {problem.infeasibility()} at this level"
    V, t, rep = _max_margin(problem, data, gamma, infeasible)
    if not t > tol.STRICT:
        raise InfeasibleError(f"{infeasible} (largest strictness margin {t:.3g})")
    return Gain(V.values(), data, dict(rep.certificate), t, "margin"), (rep.as_dict(),)


# ---------------------------------------------------------------- helpers
def _optimal_lyapunov(opt: Optimum) -> np.ndarray:
    """The optimal ``X`` (``P`` of the nominal vertex) in the original coordinates."""
    T = opt.data.T
    return T @ opt.point.nominal_lyapunov() @ T.T


def _max_margin(problem: Problem, data: Coordinates, gamma: float, infeasible_msg: str,
                x_upper: float | None = None, margin: float = 0.0):
    """Maximise ``t`` at level ``gamma``; returns ``(V, t, report)``.

    ``t`` is the margin of every block (``t <= 1``), or with ``x_upper`` the smallest
    eigenvalue of ``X`` (blocks ``>= margin``).
    """
    import cvxpy as cp

    V = variables(data.n, data.m, len(data.F), problem.extended, uncertain=problem.uncertainty is not None)
    t = cp.Variable(name="t")
    z_scale = 1.0 / (data.level_scale * gamma)  # the scaled level is then 1
    if x_upper is None:
        lmis = blocks(problem, data, V, 1.0, margin=t, z_scale=z_scale)
        cons = [t <= 1.0]
    else:
        lmis = blocks(problem, data, V, 1.0, margin=margin, z_scale=z_scale, x_bounds=(t, x_upper))
        cons = []
    rep = _cvx.solve_sdp(cp.Maximize(t), lmis, cons, solver=problem.solver, tol=tol.CENTRE_TOL,
                         infeasible_msg=infeasible_msg)
    return V, float(_cvx.value(t)), rep


def _centring(problem: Problem, data: Coordinates, opt: Optimum, backoff: float, variant: str) -> Attempt:
    gamma = opt.gamma_opt * (1.0 + backoff)
    at = f"gamma={gamma:.6g} = (1 + {backoff:g}) gamma_opt"
    if variant == "margin":
        x_upper, margin, scale = None, 0.0, 1.0
    else:
        Xc = data.from_original(_optimal_lyapunov(opt))
        x_upper = tol.X_UPPER * float(np.max(np.abs(np.linalg.eigvalsh(0.5 * (Xc + Xc.T)))))
        margin, scale = max(tol.STRICT, tol.CONDITIONED_MARGIN * backoff), x_upper
    try:
        V, t, rep = _max_margin(problem, data, gamma, f"could not find a strictly feasible gain at {at}; "
                                                      "increase backoff", x_upper=x_upper, margin=margin)
    except (ConvergenceError, InfeasibleError) as exc:
        return Attempt(failure=exc)
    solve = {**rep.as_dict(), "centring": variant}
    if not is_strict(rep.certificate):
        return Attempt(solves=(solve,), failure=ConvergenceError(
            f"the gain at {at} has no strictly positive certificate (smallest eigenvalues "
            f"{rep.certificate}); increase backoff"))
    return Attempt(Gain(V.values(), data, dict(rep.certificate), t / scale, variant), (solve,))
