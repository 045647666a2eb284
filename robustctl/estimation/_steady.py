r"""Steady state of the filter recursion for a batch: doubling, Newton refinement, the plain recursion.

The a-priori covariance of the filter (before ``EC``) is the stabilising
solution of the filter Riccati equation of a Kalman filter whose measurement
stacks ``y``, the output pseudo-measurement ``EC x`` and the dynamics'
pseudo-measurement ``EF x + EBw w`` (whose noise is correlated with the
process noise); removing the correlations gives the standard form

.. math::

    P = \bar Q + \bar A P (I + \bar G P)^{-1} \bar A', \quad
    \bar A = F - S R^{-1} C - X \bar Y^{-1} E_F, \quad
    \bar Q = Q - S R^{-1} S' - X \bar Y^{-1} X', \\
    \bar G = C' R^{-1} C + \ell^{-1} E_C' E_C + E_F' \bar Y^{-1} E_F, \quad
    \bar Y = Y + \ell I

(``ell = 1/lambda``; module :mod:`robustctl.estimation._model` for ``Q``,
``R``, ``S``, ``X``, ``Y``), solved by doubling
(:func:`robustctl._kkt.doubling`), which converges quadratically. ``Gbar``
grows like ``lambda``: for large ``mu`` (and at ``mu = inf``, where it is
infinite) the doubling runs with ``ell`` floored at ``FLOOR`` times the size
of the terms it is added to, and the result, within about ``FLOOR`` of the
fixed point, is refined by Newton's method on the exact step
(:mod:`robustctl.estimation._recursion`, finite for every ``mu``): the step's
derivative at ``P`` is ``dP -> A dP A'`` with ``A`` the estimator's closed
loop, so each Newton step solves one Stein equation ``Z = A Z A' + f(P) -
P`` (Smith's iteration). A design on which this fails is redone with the
plain recursion. Every result passes the same test: one more step of the
exact recursion changes ``P`` by less than ``tol`` (relative Frobenius norm)
and the estimator's own loop is stable (``rho(A) < 1 - 1e-9``), which
singles out the stabilising solution.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._kkt import DIVERGED, doubling, healthy, relchange, solve, stein, sym
from ..systems.stability import is_schur_stable, stability_of_eigenvalues
from ._model import FilterModel
from ._recursion import Gains, constraint, step

#: Acceptance: one more step changes ``P`` by less than this (relative Frobenius norm).
DEFAULT_TOL = 1e-10
#: Most steps of the plain recursion.
DEFAULT_MAX_ITER = 10_000
#: The doubling runs to ``DOUBLING_TOL`` (it converges quadratically) with at most ``DOUBLING_MAX_STEPS`` steps.
DOUBLING_TOL = 1e-13
DOUBLING_MAX_STEPS = 64
#: ``lambda^-1`` is floored at this times the size of the terms it is added to, for the doubling only.
FLOOR = 1e-8
#: Newton corrections of a doubling result at most.
NEWTON_STEPS = 4
#: Stacks of at most this many matrices are tested for stability by their eigenvalues.
SMALL = 8


class Evaluation(NamedTuple):
    """The acceptance test at ``P`` (B, n, n): one exact step, its residual and the estimator's stability."""

    P: np.ndarray
    gains: Gains
    residual: np.ndarray
    stable: np.ndarray

    def accepted(self, tol: float) -> np.ndarray:
        return (self.residual < tol) & self.stable


class SteadyState(NamedTuple):
    """Per design: the a-priori ``P`` (after ``EC``), the step's gains at it, and the verdict.

    ``reason`` is ``"ok"``, ``"diverged"`` or ``"not converged"``.
    """

    P: np.ndarray
    gains: Gains
    iterations: np.ndarray
    residual: np.ndarray
    stable: np.ndarray
    reason: np.ndarray


def _T(a: np.ndarray) -> np.ndarray:
    return a.swapaxes(-1, -2)


def _size(a: np.ndarray) -> np.ndarray:
    return np.abs(a).max(axis=(1, 2), initial=0.0)


def standard_form(d: FilterModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A, G, H)`` of the doubling, ``X = H + A' X (I + G X)^-1 A`` with ``A = Abar'`` (module docstring).

    ``G`` and ``H`` are symmetric up to rounding (the doubling symmetrises its iterates).
    """
    n = d.F.shape[0]
    Rinv_C = solve(d.R, d.C[None] if d.size == 1 else np.broadcast_to(d.C, (d.size, *d.C.shape)))  # R^-1 C
    A = d.F.T[None] if d.size == 1 else np.broadcast_to(d.F.T, (d.size, n, n))   # A = Abar'
    Gm = d.C.T @ Rinv_C
    H = d.Q
    if d.S is not None:
        A = A - _T(d.S @ Rinv_C)
        H = H - d.S @ solve(d.R, _T(d.S))
    if d.uncertain:  # lambda^-1 floored for the doubling (module docstring)
        size = np.maximum(_size(d.EF @ d.Q @ _T(d.EF)), _size(d.Y))
        size = np.maximum(size, _size(d.EC @ d.Q @ _T(d.EC)))
        floor = FLOOR * np.where(size > 0, size, 1.0)
        if d.EF.shape[1]:
            Ybar = d.Y + np.maximum(d.ell, floor[:, None])[:, :, None] * np.eye(d.EF.shape[1])
            sol = solve(Ybar, np.concatenate([d.EF, _T(d.X)], axis=2))     # Ybar^-1 [EF, X']
            A = A - _T(d.X @ sol[..., :n])
            H = H - d.X @ sol[..., n:]
            Gm = Gm + _T(d.EF) @ sol[..., :n]
        if d.EC.shape[1]:
            Gm = Gm + _T(d.EC) @ d.EC / np.maximum(d.li, floor)[:, None, None]
    return A, Gm, H


def _stable(A: np.ndarray) -> np.ndarray:
    """``rho(A) < 1 - STABILITY_MARGIN`` per matrix of a stack (:func:`~robustctl.systems.stability.is_schur_stable`).

    A few finite matrices (one design) take their eigenvalues directly
    (:func:`~robustctl.systems.stability.stability_of_eigenvalues`), without
    the argument checks that cost a single design as much as the eigenvalues.
    """
    if A.shape[0] <= SMALL and np.isfinite(A).all():
        return stability_of_eigenvalues(np.linalg.eigvals(A), discrete=True)[1]
    return np.asarray(is_schur_stable(A), dtype=bool)


def evaluate(P: np.ndarray, d: FilterModel) -> Evaluation:
    """One exact step from ``P`` (a-priori, after ``EC``) for every design; NaN where ``P`` is not healthy."""
    everywhere = bool(np.abs(P).max(initial=0.0) < DIVERGED)     # the usual case, in one reduction
    good = np.ones(P.shape[0], dtype=bool) if everywhere else healthy(P)
    g = step(P if everywhere else np.where(good[:, None, None], P, np.eye(P.shape[1])), d)
    residual = relchange(g.P_next, P)
    stable = _stable(g.closed_loop(d.C))
    if not everywhere:
        residual[~good] = np.inf
        stable &= good
    return Evaluation(P, g, residual, stable)


def _rows(ev: Evaluation, idx: np.ndarray) -> Evaluation:
    """The designs ``idx`` (indices or bool) of ``ev``."""
    return Evaluation(ev.P[idx], Gains(*(a[idx] for a in ev.gains)), ev.residual[idx], ev.stable[idx])


def _put(ev: Evaluation, where: np.ndarray, other: Evaluation) -> Evaluation:
    """``ev`` with the designs ``where`` (indices) replaced by ``other``."""
    out = []
    for a, b in zip((ev.P, *ev.gains, ev.residual, ev.stable), (other.P, *other.gains, other.residual, other.stable),
                    strict=True):
        a = a.copy()  # noqa: PLW2901 (a copy of each field, then written)
        a[where] = b
        out.append(a)
    return Evaluation(out[0], Gains(*out[1:-2]), out[-2], out[-1])


def newton(ev: Evaluation, d: FilterModel, tol: float) -> tuple[Evaluation, np.ndarray]:
    """Newton refinement of approximate fixed points, from their evaluation ``ev`` (after ``EC``).

    Up to ``NEWTON_STEPS`` steps ``P <- P + Z``, ``Z = A Z A' + f(P) - P``,
    while the design's loop is stable and its residual above ``tol``; the
    evaluation with the smallest residual is kept. Returns it and the
    number of steps per design.
    """
    best = ev
    count = np.zeros(ev.P.shape[0], dtype=int)
    for _ in range(NEWTON_STEPS):
        go = np.flatnonzero(ev.stable & ~(ev.residual < tol) & healthy(ev.gains.P_next))
        if not go.size:
            break
        A = ev.gains.closed_loop(d.C)[go]
        Z = stein(_T(A), ev.gains.P_next[go] - ev.P[go])             # Z = A Z A' + f(P) - P
        new = evaluate(sym(ev.P[go] + Z), d.select(go))
        count[go] += 1
        ev = _put(ev, go, new)
        better = new.residual < best.residual[go]
        best = _put(best, go[better], _rows(new, better))
    return best, count


def recursion(d: FilterModel, P0: np.ndarray, tol: float, max_iter: int) -> tuple[np.ndarray, np.ndarray]:
    """The plain recursion from ``P0`` until one step changes ``P`` by less than ``tol``: ``(P, iterations)``."""
    B = d.size
    P = np.broadcast_to(P0, (B, *P0.shape[-2:])).copy()
    iterations = np.zeros(B, dtype=int)
    active = np.ones(B, dtype=bool)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for it in range(1, max_iter + 1):
            idx = np.flatnonzero(active)
            P_new = step(P[idx], d.select(idx)).P_next
            change = relchange(P_new, P[idx])
            P[idx] = P_new
            iterations[idx] = it
            active[idx[(change < tol) | ~healthy(P_new)]] = False
            if not active.any():
                break
    return P, iterations


def start(d: FilterModel) -> np.ndarray:
    """Starting point of the plain recursion: ``Q`` plus its size times ``I`` (positive definite)."""
    size = np.maximum(_size(d.Q), 1.0)
    return d.Q + size[:, None, None] * np.eye(d.F.shape[0])


def steady_state(d: FilterModel, tol: float = DEFAULT_TOL, max_iter: int = DEFAULT_MAX_ITER, *,
                 accelerate: bool = True) -> SteadyState:
    """The stabilising fixed point of the recursion for every design of ``d``, with its verdict.

    ``accelerate``: doubling, Newton refinement, then the plain recursion
    where both miss the test; otherwise the plain recursion only (from :func:`start`).
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if accelerate:
            X, iterations, settled = doubling(*standard_form(d), DOUBLING_TOL, DOUBLING_MAX_STEPS)
            ev = evaluate(constraint(X, d)[0], d)
            if not ev.accepted(tol).all():
                sub = np.flatnonzero(settled & ev.stable & ~ev.accepted(tol))
                if sub.size:                                   # Newton, then the recursion where it misses
                    refined, count = newton(_rows(ev, sub), d.select(sub), tol)
                    ev = _put(ev, sub, refined)
                    iterations[sub] += count
                todo = np.flatnonzero(~ev.accepted(tol))
                if todo.size:
                    sub_d = d.select(todo)
                    P, steps = recursion(sub_d, start(sub_d), tol, max_iter)
                    ev = _put(ev, todo, evaluate(P, sub_d))
                    iterations[todo] += steps
        else:
            P, iterations = recursion(d, start(d), tol, max_iter)
            ev = evaluate(P, d)
    accepted = ev.accepted(tol)
    if accepted.all():
        reason = np.full(accepted.shape, "ok", dtype="<U13")
    else:
        diverged = ~healthy(ev.gains.P_next) | ~np.isfinite(ev.gains.Lf).all(axis=(1, 2))
        reason = np.where(diverged, "diverged", np.where(accepted, "ok", "not converged")).astype("<U13")
    return SteadyState(ev.P, ev.gains, iterations, ev.residual, ev.stable, reason)
