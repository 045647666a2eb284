"""Compiled (numba) kernels of the RLQR step and the plain recursion.

:func:`kkt_step` and :func:`recursion` compute, design by design in one
compiled loop, what ``robustctl.synthesis._rlqr.step.kkt_step`` and
``robustctl.synthesis._rlqr.steady.recursion`` compute with stacked numpy
calls (those stay the references the tests compare with); the doubling steps
are the compiled ``robustctl._kkt.doubling``, shared with the robust filter
(its numpy reference is ``robustctl.synthesis._rlqr.steady.doubling_loop``).
On the small systems of the MOPs (``n = 3`` or 4, ``m = l = 1`` or 2)
numpy's cost is its per-call overhead, about 75 us per step whatever the
batch; the kernel takes about 1 us per design and recursion step
(``benchmarks/bench_rlqr.py``).

Same arithmetic, same rules:

* the step is the penalty/KKT form of ``robustctl.synthesis.rlqr``, with the same
  operations in the same order (``Pt = sym((I + P S)^-1 P)`` only when the
  batch is ``soft``, the KKT solve, ``L = (I + S P)^-1 Lc``,
  ``P = sym(Q + K'RK + lambda^-1 nu'nu + Lc' Pt Lc)``); only the rounding of
  the sums and the solves differs from numpy/LAPACK (a few ulps per step);
* the solves are ``robustctl._kkt.lu_solve``, LU with partial pivoting (as
  LAPACK's ``getrf``: the first largest pivot, multipliers scaled by the
  pivot's reciprocal); an exactly zero pivot is a singular system and gives
  NaN for that solve's result of that design only, as
  ``robustctl._kkt.solve`` does;
* the recursion stops a design when one step changes ``P`` by less than
  ``tol`` (relative Frobenius norm) or ``P`` is not healthy (an entry not
  below ``robustctl._kkt.DIVERGED`` in magnitude, or NaN), after at most
  ``max_iter`` steps.

Compilation: ``cache=True``, ``nogil=True`` (:func:`robustctl._jit.jit`),
one entry point (``_recursion``, whose single step is ``max_iter = 1``),
compiled once on a fresh clone (slice assignments cost twice as much to
compile and are written as loops), then loaded from the cache in each new
process (``benchmarks/bench_experiment.py`` measures both).
"""

from __future__ import annotations

import numpy as np

from ..._jit import jit
from ..._kkt import copy_into, eye_plus_product, fill, healthy_one, lu_solve, product, relchange_one
from .model import Model
from .step import Step

__all__ = ["kkt_step", "recursion"]

_TINY = np.finfo(float).tiny


@jit
def _step(P, F, G, Q, R, EF, EG, S, li, soft, Pn, K, L, Pt, M, GP, kkt, sol, Lc):
    """One step ``P -> (Pn, K, L)`` for one design (``li = lambda^-1``); the rest are work arrays.

    ``Pt``, ``Lc`` (n, n), ``M`` (n, max(n, m)), ``GP`` (m, n), ``kkt`` (m + l, m + l), ``sol`` (m + l, n).
    """
    n, m = G.shape
    l = EF.shape[0]
    if soft:                                            # Pt = sym((I + P S)^-1 P)
        eye_plus_product(P, S, M)
        copy_into(P, Lc)
        if not lu_solve(M, Lc):
            fill(Lc, np.nan)
        for i in range(n):
            for j in range(n):
                Pt[i, j] = 0.5 * (Lc[i, j] + Lc[j, i])
    else:
        copy_into(P, Pt)
    product(G.T, Pt, GP)                               # GP = G'Pt
    for a in range(m):                                  # kkt = [[R + G'Pt G, EG'], [EG, -li I]]
        for c in range(m):                              # sol = -[G'Pt F; EF]
            s = 0.0
            for j in range(n):
                s += GP[a, j] * G[j, c]
            kkt[a, c] = R[a, c] + s
        for r in range(l):
            kkt[a, m + r] = EG[r, a]
            kkt[m + r, a] = EG[r, a]
        for j in range(n):
            s = 0.0
            for i in range(n):
                s += GP[a, i] * F[i, j]
            sol[a, j] = -s
    for r in range(l):
        for q in range(l):
            kkt[m + r, m + q] = -li * (1.0 if r == q else 0.0)
        for j in range(n):
            sol[m + r, j] = -EF[r, j]
    if not lu_solve(kkt, sol):
        fill(sol, np.nan)
    copy_into(sol, K)
    for i in range(n):                                  # Lc = F + G K
        for j in range(n):
            s = 0.0
            for a in range(m):
                s += G[i, a] * K[a, j]
            Lc[i, j] = F[i, j] + s
    copy_into(Lc, L)
    if soft:                                            # L = (I + S P)^-1 Lc
        eye_plus_product(S, P, M)
        if not lu_solve(M, L):
            fill(L, np.nan)
    # Pn = sym(((Q + (K'R) K) + li (nu'nu)) + (Lc' Pt) Lc); M holds K'R, then Lc'Pt; Pt, last read
    # for Lc'Pt, then takes (Lc'Pt) Lc
    product(K.T, R, M)
    product(M[:, :m], K, Pn)
    for i in range(n):
        for j in range(n):
            v = 0.0
            for r in range(l):
                v += sol[m + r, i] * sol[m + r, j]
            Pn[i, j] = (Q[i, j] + Pn[i, j]) + li * v
    product(Lc.T, Pt, M)
    product(M[:, :n], Lc, Pt)
    for i in range(n):
        for j in range(n):
            Pn[i, j] += Pt[i, j]
    for i in range(n):
        for j in range(i + 1, n):
            v = 0.5 * (Pn[i, j] + Pn[j, i])
            Pn[i, j] = v
            Pn[j, i] = v
        Pn[i, i] = 0.5 * (Pn[i, i] + Pn[i, i])


@jit
def _work(n, m, l):
    """Work arrays of ``_step``: ``Pt, M, GP, kkt, sol, Lc``."""
    return (np.empty((n, n)), np.empty((n, max(n, m))), np.empty((m, n)), np.empty((m + l, m + l)),
            np.empty((m + l, n)), np.empty((n, n)))


@jit
def _recursion(P, F, G, Q, R, EF, EG, S, lam_inv, soft, tol, max_iter, bound, tiny, K, L, iterations, active):
    """The recursion from ``P`` (B, n, n, overwritten with the result) for every design.

    ``K``, ``L`` (B, m, n), (B, n, n) receive those of each design's last step (one entry point
    for the recursion and the single step, ``max_iter = 1``: the kernel is compiled once).
    """
    n, m = G.shape
    Pt, M, GP, kkt, sol, Lc = _work(n, m, EF.shape[1])
    Pn = np.empty((n, n))
    for b in range(P.shape[0]):
        Pb = P[b]
        it, act = 0, True
        while act and it < max_iter:
            it += 1
            _step(Pb, F, G, Q, R, EF[b], EG[b], S[b], lam_inv[b], soft, Pn, K[b], L[b], Pt, M, GP, kkt, sol, Lc)
            change = relchange_one(Pn, Pb, tiny)
            copy_into(Pn, Pb)
            act = not change < tol and healthy_one(Pn, bound)
        iterations[b] = it
        active[b] = act


def _args(d: Model):
    """The model's arrays as C-contiguous, writable float64 arrays (one compiled signature)."""
    return tuple(np.array(a, dtype=float, order="C") for a in (d.F, d.G, d.Q, d.R, d.EF, d.EG, d.S, d.lam_inv))


def _run(d: Model, P: np.ndarray, tol: float, max_iter: int, diverged: float):
    """``_recursion`` from ``P`` (B, n, n): ``(P, K, L, iterations, active)``."""
    B, (n, m) = d.size, d.G.shape
    P = np.array(np.broadcast_to(P, (B, n, n)), dtype=float, order="C")
    K, L = np.empty((B, m, n)), np.empty((B, n, n))
    iterations, active = np.zeros(B, dtype=np.int64), np.ones(B, dtype=bool)
    _recursion(P, *_args(d), bool(d.soft), float(tol), int(max_iter), float(diverged), _TINY, K, L,
               iterations, active)
    return P, K, L, iterations, active


def kkt_step(P: np.ndarray, d: Model) -> Step:
    """The numpy ``robustctl.synthesis._rlqr.step.kkt_step``, compiled: one step for every design of ``d``."""
    P, K, L, _, _ = _run(d, P, 0.0, 1, np.inf)
    return Step(P, K, L)


def recursion(d: Model, P0: np.ndarray, tol: float, max_iter: int, diverged: float):
    """The plain recursion with :func:`kkt_step` from ``P0`` for every design of ``d``.

    ``diverged``: ``P`` is not healthy once an entry reaches it in magnitude.
    Returns ``(P, iterations, active)``; ``active`` True where the design was
    still moving after ``max_iter`` steps.
    """
    P, _, _, iterations, active = _run(d, P0, tol, max_iter, diverged)
    return P, iterations.astype(int), active
