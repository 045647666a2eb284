"""Steady state of the RLQR recursion for a batch.

Doubling, Newton refinement, the plain recursion, and the acceptance test that every result
passes (``robustctl.synthesis.rlqr``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from ... import _kkt
from ..._kkt import DIVERGED, healthy, relchange, solve, stein, sym
from ...systems.stability import is_schur_stable
from .model import Model
from .step import Step, kkt_step

#: Acceptance: one more recursion step changes ``P`` by less than this (relative, Frobenius norm).
DEFAULT_TOL = 1e-10
#: Most steps of the plain recursion.
DEFAULT_MAX_ITER = 10_000
#: Doubling converges quadratically, so it runs well past ``tol``: to ``min(DOUBLING_RATIO * tol, DOUBLING_TOL)``.
DOUBLING_RATIO = 1e-3
DOUBLING_TOL = 1e-13
#: Most doubling steps (``2**64`` recursion steps).
DOUBLING_MAX_STEPS = 64
#: Newton corrections of a doubling result that missed the acceptance test.
NEWTON_STEPS = 3

StepFunction = Callable[[np.ndarray, Model], Step]


class Evaluation(NamedTuple):
    """The acceptance test at ``X``.

    ``P = f(X)`` and its ``K``, ``L`` (NaN where ``X`` diverged),
    ``residual = ||f(X) - X|| / ||f(X)||`` and ``stable`` = ``rho(L) < 1 - STABILITY_MARGIN``.
    """

    P: np.ndarray
    K: np.ndarray
    L: np.ndarray
    residual: np.ndarray
    stable: np.ndarray

    def accepted(self, tol: float) -> np.ndarray:
        """Designs whose residual is below ``tol`` and whose closed loop is stable."""
        return (self.residual < tol) & self.stable

    def put(self, where: np.ndarray, other: Evaluation) -> None:
        """Overwrite the designs ``where`` (indices) with ``other``."""
        for mine, theirs in zip(self, other, strict=True):
            mine[where] = theirs


class SteadyState(NamedTuple):
    """Per design: ``P``, ``K``, ``L``, steps taken, residual and ``reason``.

    ``reason`` is one of ``{"ok", "diverged", "not converged"}``.
    """

    P: np.ndarray
    K: np.ndarray
    L: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    reason: np.ndarray


def evaluate(X: np.ndarray, d: Model, step: StepFunction) -> Evaluation:
    """One more recursion step from ``X`` for every design whose ``X`` is healthy."""
    B, n = X.shape[:2]
    ev = Evaluation(X.copy(), np.full((B, d.G.shape[1], n), np.nan), np.full_like(X, np.nan),
                    np.full(B, np.inf), np.zeros(B, dtype=bool))
    good = healthy(X)
    if good.any():
        idx = np.flatnonzero(good)
        new = step(X[idx], d.select(good))
        ev.put(idx, Evaluation(*new, relchange(new.P, X[idx]), np.asarray(is_schur_stable(new.L))))
    return ev


def recursion(d: Model, step: StepFunction, P0: np.ndarray, tol: float, max_iter: int):
    """The paper's recursion from ``P0`` until one step changes ``P`` by less than ``tol``.

    Returns ``(P, iterations, settled)``; ``settled`` False where it blew up or
    was still moving after ``max_iter`` steps.
    """
    B = d.size
    P = np.broadcast_to(P0, (B, *P0.shape[-2:])).copy()
    iterations = np.zeros(B, dtype=int)
    active = np.ones(B, dtype=bool)
    for it in range(1, max_iter + 1):
        idx = np.flatnonzero(active)
        P_new = step(P[idx], d.select(active)).P
        change = relchange(P_new, P[idx])
        P[idx] = P_new
        iterations[idx] = it
        active[idx[(change < tol) | ~healthy(P_new)]] = False  # converged, or diverging
        if not active.any():
            break
    return P, iterations, ~active & healthy(P)


def _compiled(step: StepFunction) -> StepFunction:
    """The compiled kernel's step for the numpy KKT step (the same step); any other step as it is."""
    if step is kkt_step:
        from . import kernel as _kernel
        return _kernel.kkt_step
    return step


def plain(d: Model, step: StepFunction, P0: np.ndarray, tol: float, max_iter: int):
    """:func:`recursion` and the :func:`evaluate` of its result: ``(iterations, settled, Evaluation)``.

    With :func:`~robustctl.synthesis._rlqr.step.kkt_step` both run in the compiled kernel
    (:mod:`robustctl.synthesis._rlqr.kernel`, the same step and stopping rule; the numpy
    :func:`recursion` is the reference its tests compare with).
    """
    if step is kkt_step:
        from . import kernel as _kernel
        X, iterations, active = _kernel.recursion(d, P0, tol, max_iter, DIVERGED)
        settled = ~active & healthy(X)
    else:
        X, iterations, settled = recursion(d, step, P0, tol, max_iter)
    return iterations, settled, evaluate(X, d, _compiled(step))


def doubling(d: Model, tol: float):
    """Stabilising solution of the steady-state RLQR Riccati equation by doubling.

    Eliminating the cross term of the penalty ``lambda ||EF x + EG u||^2``
    with Woodbury's identity (``Gam = (lambda^-1 I + EG R^-1 EG')^-1``, finite
    for every ``mu`` when ``EG`` has full row rank) gives the standard form

        X = Qs + As' X (I + Gs X)^-1 As,
        As = F - G R^-1 EG' Gam EF,   Qs = Q + EF' Gam EF,
        Gs = G (R^-1 - R^-1 EG' Gam EG R^-1) G' + S,

    solved by the structure-preserving doubling algorithm (Chu, Fan & Lin
    2005): ``H_k -> X`` quadratically. Returns ``(X, steps, settled)``;
    ``settled`` is False where ``H_k`` blew up or kept changing for
    ``DOUBLING_MAX_STEPS`` doublings (no stabilising fixed point). The
    standard form is built with numpy, the doubling steps run in the compiled
    kernel shared with the robust filter (``robustctl._kkt.doubling``;
    :func:`doubling_loop` is their numpy reference).
    """
    A, Gs, H = standard_form(d)
    return _kkt.doubling(A, Gs, H, tol, DOUBLING_MAX_STEPS, healthy(H) & healthy(Gs))


def standard_form(d: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(As, Gs, Qs)`` of :func:`doubling`'s standard form, for every design (B, n, n)."""
    B, l = d.EF.shape[:2]
    Rinv = np.linalg.inv(d.R)
    EGR = d.EG @ Rinv                                                  # (B, l, m)
    Gam = solve(d.lam_inv[:, None, None] * np.eye(l) + EGR @ d.EG.swapaxes(1, 2),
                np.broadcast_to(np.eye(l), (B, l, l)))
    A = d.F - d.G @ (EGR.swapaxes(1, 2) @ Gam @ d.EF)
    H = sym(d.Q + d.EF.swapaxes(1, 2) @ Gam @ d.EF)
    Gs = sym(d.G @ (Rinv - EGR.swapaxes(1, 2) @ Gam @ EGR) @ d.G.T + d.S)
    return A, Gs, H


def doubling_loop(A: np.ndarray, Gs: np.ndarray, H: np.ndarray, tol: float, active: np.ndarray):
    """The doubling steps of :func:`doubling` from :func:`standard_form`, with stacked numpy calls.

    The reference of the compiled loop (``robustctl._kkt.doubling``, same
    operations in the same order). Returns ``(H, steps, settled)``.
    """
    A, Gs, H, active = A.copy(), Gs.copy(), H.copy(), active.copy()
    B, n = H.shape[:2]
    steps = np.zeros(B, dtype=int)
    settled = np.zeros(B, dtype=bool)
    eye = np.eye(n)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for _ in range(DOUBLING_MAX_STEPS):
            if not active.any():
                break
            idx = slice(None) if active.all() else np.flatnonzero(active)  # no copies while all run
            a, g, h = A[idx], Gs[idx], H[idx]
            sol = solve(eye + g @ h, np.concatenate([a, g], axis=2))      # W^-1 [A, G]
            WA, WG = sol[..., :n], sol[..., n:]
            aT = a.swapaxes(1, 2)
            h_new = sym(h + aT @ h @ WA)
            ok = healthy(h_new)
            change = np.where(ok, relchange(h_new, h), np.inf)
            A[idx], Gs[idx], H[idx] = a @ WA, sym(g + a @ WG @ aT), h_new
            steps[idx] += 1
            settled[idx] |= change < tol
            active[idx] &= (change >= tol) & ok
    return H, steps, settled


def newton(d: Model, P: np.ndarray, tol: float) -> tuple[Evaluation, np.ndarray]:
    """Newton (Kleinman-Hewer) refinement of approximate fixed points ``P ~ f(P)``.

    ``f``'s derivative at ``P`` is ``X -> L' X L`` (``L`` the closed loop of
    the step at ``P``), so a Newton step solves the Stein equation
    ``X = L' X L + (f(P) - P)`` and moves to ``P + X``; it needs ``L`` stable
    and converges quadratically to the stabilising fixed point. Up to
    ``NEWTON_STEPS`` corrections are made (the doubling result of an
    ill-conditioned design, about 1e-8 off, reaches the rounding floor of
    ``f`` in one or two) and the evaluation with the smallest residual is
    kept. Returns it and the number of evaluations per design.
    """
    B = P.shape[0]
    best = Evaluation(np.full_like(P, np.nan), np.full((B, *d.G.shape[::-1]), np.nan), np.full_like(P, np.nan),
                      np.full(B, np.inf), np.zeros(B, dtype=bool))
    evaluations = np.zeros(B, dtype=int)
    active = np.ones(B, dtype=bool)
    P = P.copy()
    for k in range(NEWTON_STEPS + 1):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        P_old = P[idx]
        new = kkt_step(P_old, d.select(active))
        ev = Evaluation(*new, relchange(new.P, P_old), np.asarray(is_schur_stable(new.L)))  # a stack: an array
        evaluations[idx] += 1
        better = ev.residual < best.residual[idx]
        best.put(idx[better], Evaluation(*(a[better] for a in ev)))
        refine = ev.stable & healthy(new.P) & (k < NEWTON_STEPS)
        P[idx[refine]] = sym(P_old[refine] + stein(new.L[refine], new.P[refine] - P_old[refine]))
        active[idx[~refine]] = False
    return best, evaluations


def steady_state(d: Model, P0: np.ndarray, tol: float, max_iter: int, *, accelerate: bool = True,
                 fallback: str = "recursion", step: StepFunction = kkt_step) -> SteadyState:
    """Stabilising fixed point of the recursion for every design of ``d``, with its verdict.

    ``accelerate``: doubling; designs on which it settles but misses the
    acceptance test are refined by Newton (``fallback="newton"``) and, where
    they still miss it (or ``fallback="recursion"``), redone with the plain
    recursion from ``P0``. Otherwise: the plain recursion with ``step``.
    A design is ``"ok"`` iff one more step changes ``P`` by less than
    ``tol`` and ``L`` is stable; ``"diverged"`` if ``P`` blew up;
    ``"not converged"`` otherwise.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if accelerate:
            X, iterations, settled = doubling(d, min(DOUBLING_RATIO * tol, DOUBLING_TOL))
            ev = evaluate(X, d, _compiled(step))
        else:
            iterations, settled, ev = plain(d, step, P0, tol, max_iter)

        def missed():
            return np.flatnonzero(settled & healthy(ev.P) & ~ev.accepted(tol))

        if accelerate and fallback == "newton" and (sub := missed()).size:
            refined, evaluations = newton(d.select(sub), ev.P[sub], tol)
            ev.put(sub, refined)
            iterations[sub] += evaluations
        if accelerate and (sub := missed()).size:
            steps, settled[sub], redone = plain(d.select(sub), step, P0, tol, max_iter)
            ev.put(sub, redone)
            iterations[sub] += steps
    diverged = ~healthy(ev.P) | ~np.isfinite(ev.K).all(axis=(1, 2))
    reason = np.full(d.size, "ok", dtype="<U13")
    reason[diverged] = "diverged"
    reason[~diverged & ~ev.accepted(tol)] = "not converged"
    return SteadyState(ev.P, ev.K, ev.L, iterations, ev.residual, reason)
