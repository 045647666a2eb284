r"""Robust linear quadratic regulator (RLQR) for norm-bounded uncertainty.

System (paper Eq. statespaceDT, RLQRuncertainties)::

    x[k+1] = (F + H Delta EF) x[k] + (G + H Delta EG) u[k],   ||Delta|| <= 1,

with ``H`` (n x p), ``EF`` (l x n), ``EG`` (l x m). The RLQR (Cerri, Terra &
Ishihara 2009; Cerri et al. 2014; paper Section 2.2) solves, at each step, the
regularised min-max problem with penalty ``mu`` and gives ``u = K x`` and the
closed loop ``x[k+1] = L x[k]``.

Three equivalent forms of one recursion step ``P[k+1] -> (L[k], K[k], P[k])``
are implemented:

* **Block system** (Theorem 1 as corrected in PAPER_NOTES.md),
  :func:`rlqr_step_block`: ``L``, ``K`` are blocks 5 and 6 of ``Xi^-1 b`` and
  ``P = b' Xi^-1 b``. The reference implementation used by the tests.
* **W form** of PAPER_NOTES.md: ``W = Sigma + Ihat P^-1 Ihat' + Ghat R^-1 Ghat'``,
  ``K = -R^-1 Ghat' W^-1 Fhat``, ``P = Q + Fhat' W^-1 Fhat``. Used in tests only.
* **Penalty / KKT form** (the fast path, :func:`rlqr_step`). With
  ``lambda = (1 + alpha) ||mu H'H||`` and ``S = mu^-1 I - lambda^-1 H H'``
  (positive definite for ``alpha > 0``), Woodbury's identity turns the W form into

  .. math::

      \tilde P &= (I + P S)^{-1} P = (P^{-1} + S)^{-1}, \\
      \begin{bmatrix} R + G'\tilde P G & E_G' \\ E_G & -\lambda^{-1} I \end{bmatrix}
      \begin{bmatrix} K \\ \nu \end{bmatrix} &=
      -\begin{bmatrix} G'\tilde P F \\ E_F \end{bmatrix}, \\
      L_c = F + G K, \quad L &= (I + S P)^{-1} L_c, \\
      P_{new} &= Q + K' R K + L_c' \tilde P L_c + \lambda^{-1} \nu'\nu .

  Here ``nu = lambda (EF + EG K)``. Every term is a sum of positive
  semidefinite matrices, nothing is multiplied by ``lambda`` and no inverse of
  ``P`` or ``Q`` is needed, so the step stays accurate for ``mu`` up to 1e22
  and is exact at ``mu = inf`` (``S = 0``, ``lambda^-1 = 0``: the KKT system
  then enforces ``EF + EG K = 0`` and ``L = F + G K``; it is solvable iff
  ``EG`` has full row rank, i.e. ``[I -G; 0 -EG]`` has full row rank).

Steady state. The steady-state recursion is the Riccati equation of an
ordinary LQ problem with the augmented input ``(u, v)``, ``x+ = F x + G u + v``
and stage cost ``x'Qx + u'Ru + lambda ||EF x + EG u||^2 + v' S^-1 v``; its
closed loop is ``L``. The fixed point ``P = f(P)`` is found either by
iterating ``f`` from ``P = Q`` (or ``P_N``) - the paper's recursion,
``accelerate=False`` - or, much faster, by the structure-preserving doubling
algorithm on that Riccati equation written without cross terms (Woodbury
again keeps it finite for every ``mu``; see ``_sda``), which converges
quadratically (about 10 doubling steps where the recursion takes hundreds).
Either way the result is accepted only when one more step of the recursion
changes ``P`` by less than ``tol`` (relative, Frobenius norm) and ``L`` is
stable, which singles out the stabilising solution; a design on which
doubling fails is redone with the plain recursion.

``lambda`` with no uncertainty. With ``H = 0`` the bound ``lambda >
||mu H'H|| = 0`` leaves ``lambda`` free, but any finite ``lambda > 0`` adds a
spurious penalty ``lambda ||EF x + EG u||^2`` although ``dF = dG = 0``. We
take the exact limit ``lambda -> 0``, in which the min-max problem no longer
depends on ``EF, EG``: the design is the nominal regulator (``S = mu^-1 I``),
equal to the LQR as ``mu -> inf``. With ``EF = EG = 0`` and ``H != 0``,
``lambda`` has no effect.

References
----------
Cerri, J. P., Terra, M. H., & Ishihara, J. Y. (2009). Recursive robust
regulator for discrete-time state-space systems. ACC 2009, 3077-3082.
Sayed, A. H. (2001). A framework for state-space estimation with uncertain
models. IEEE TAC 46(7), 998-1013.
Chu, E. K.-W., Fan, H.-Y., & Lin, W.-W. (2005). A structure-preserving
doubling algorithm for continuous-time algebraic Riccati equations. Linear
Algebra Appl. 396, 55-80 (and its discrete-time form, ibid.).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ._validation import as_batch, as_matrix, check_positive_scalar, check_spd
from .controller import Controller
from .errors import ConvergenceError, RankConditionError
from .lqr import _weights
from .plant import Plant, _frozen

__all__ = ["rlqr", "rlqr_gains", "rlqr_step", "rlqr_step_block", "RLQRBatch", "RLQRSchedule"]

_DEFAULT_ALPHA = 0.1
_DEFAULT_TOL = 1e-10
_DEFAULT_MAX_ITER = 10_000
_MU_MIN = 1e-100  # smallest accepted penalty (mu^-1 enters products with P)
_DIVERGED = 1e250  # |P| beyond this: the recursion is diverging
_STABILITY_MARGIN = 1e-9  # accepted closed loops have rho(L) < 1 - margin


# --------------------------------------------------------------------------- #
# Problem data, batched                                                        #
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _Data:
    """Batched problem data: F, G, Q, R shared; EF, EG, S, lam_inv per design."""

    F: np.ndarray       # (n, n)
    G: np.ndarray       # (n, m)
    Q: np.ndarray       # (n, n)
    R: np.ndarray       # (m, m)
    EF: np.ndarray      # (B, l, n)  (zeros when H = 0: the lambda -> 0 limit)
    EG: np.ndarray      # (B, l, m)
    S: np.ndarray       # (B, n, n)  mu^-1 I - lambda^-1 H H'
    lam_inv: np.ndarray  # (B,)      1 / lambda (0 at mu = inf)
    soft: bool          # any finite mu (S != 0)


def _penalty_scale(H: np.ndarray) -> float:
    """||H'H||_2 (= ||H||_2^2)."""
    return float(np.linalg.norm(H, 2) ** 2) if H.size else 0.0


def _make_data(F, G, Q, R, H, EF, EG, mu, alpha) -> _Data:
    n = F.shape[0]
    hh = _penalty_scale(H)
    with np.errstate(divide="ignore"):
        mu_inv = np.where(np.isinf(mu), 0.0, 1.0 / mu)
    if hh == 0.0:  # no uncertainty: lambda -> 0 limit, EF and EG drop out
        EF, EG = np.zeros_like(EF), np.zeros_like(EG)
        lam_inv = np.ones_like(mu)
        S = mu_inv[:, None, None] * np.eye(n)
    else:
        # lambda = (1 + alpha) mu ||H'H||;  S = mu^-1 (I - H H' / ((1 + alpha) ||H'H||)) >= 0
        lam_inv = mu_inv / ((1.0 + alpha) * hh)
        S = mu_inv[:, None, None] * (np.eye(n) - H @ H.T / ((1.0 + alpha) * hh))
    return _Data(F, G, Q, R, EF, EG, S, lam_inv, bool(np.any(mu_inv > 0)))


def _sym(P: np.ndarray) -> np.ndarray:
    return 0.5 * (P + np.swapaxes(P, -1, -2))


def _policy(P: np.ndarray, d: _Data):
    """The step's policy from ``P`` (B, n, n): ``(K, nu, Pt, Lc, L)`` of the KKT form."""
    n, m = d.G.shape
    l = d.EF.shape[1]
    eye = np.eye(n)
    Pt = _sym(_solve(eye + P @ d.S, P)) if d.soft else P
    GtPt = d.G.T @ Pt                                              # (B, m, n)
    B = P.shape[0]
    kkt = np.zeros((B, m + l, m + l))
    kkt[:, :m, :m] = d.R + GtPt @ d.G
    kkt[:, :m, m:] = np.swapaxes(d.EG, 1, 2)
    kkt[:, m:, :m] = d.EG
    kkt[:, m:, m:] = -d.lam_inv[:, None, None] * np.eye(l)
    rhs = -np.concatenate([GtPt @ d.F, d.EF], axis=1)              # (B, m + l, n)
    sol = _solve(kkt, rhs)
    K, nu = sol[:, :m], sol[:, m:]
    Lc = d.F + d.G @ K
    L = _solve(eye + d.S @ P, Lc) if d.soft else Lc
    return K, nu, Pt, Lc, L


def _solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Stacked solve; a numerically singular system gives NaN for that design only.

    (``np.linalg.solve`` fails the whole stack if one matrix is singular, e.g.
    ``R + G' Pt G`` with two identical input columns and ``Pt ~ mu ~ 1e20``.)
    """
    try:
        return np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        out = np.full(b.shape, np.nan)
        for i in range(A.shape[0]):  # rare fallback, only when some system is singular
            try:
                out[i] = np.linalg.solve(A[i], b[i])
            except np.linalg.LinAlgError:
                pass
        return out


def _step(P: np.ndarray, d: _Data):
    """One recursion step ``P[k+1] -> (P[k], K[k], L[k])`` (penalty/KKT form)."""
    K, nu, Pt, Lc, L = _policy(P, d)
    return _sym(_stage_cost(K, nu, d) + np.swapaxes(Lc, 1, 2) @ Pt @ Lc), K, L


def _stage_cost(K: np.ndarray, nu: np.ndarray, d: _Data) -> np.ndarray:
    """``Q + K'RK + lambda^-1 nu'nu`` (= ``Q + K'RK + lambda ||EF + EG K||^2``)."""
    return (d.Q + np.swapaxes(K, 1, 2) @ d.R @ K
            + d.lam_inv[:, None, None] * (np.swapaxes(nu, 1, 2) @ nu))


def _stein(A: np.ndarray, Qc: np.ndarray, steps: int = 60) -> np.ndarray:
    """Solve ``X = A' X A + Qc`` (batched, rho(A) < 1) by Smith doubling."""
    X, Ak = Qc.copy(), A.copy()
    for _ in range(steps):
        AkT = np.swapaxes(Ak, 1, 2)
        inc = AkT @ X @ Ak
        X = X + inc
        Ak = Ak @ Ak
        if np.all(np.abs(inc) <= 1e-17 * np.abs(X).max(axis=(1, 2), keepdims=True)):
            break
    return _sym(X)


def _relchange(P_new: np.ndarray, P: np.ndarray) -> np.ndarray:
    num = np.linalg.norm(P_new - P, axis=(1, 2))
    den = np.maximum(np.linalg.norm(P_new, axis=(1, 2)), np.finfo(float).tiny)
    return num / den


def _spectral_radius(A: np.ndarray) -> np.ndarray:
    """Batched spectral radius; ``inf`` for matrices with non-finite entries."""
    rho = np.full(A.shape[0], np.inf)
    finite = np.isfinite(A).all(axis=(1, 2))
    if finite.any():
        rho[finite] = np.abs(np.linalg.eigvals(A[finite])).max(axis=1)
    return rho


def _schur_stable(A: np.ndarray, bound: float = 1.0, squarings: int = 10) -> np.ndarray:
    """Batched test ``rho(A) < bound``.

    Certificate first: ``rho(M) <= ||M^k||_F``, so if ``||(A/bound)^(2^j)||_F < 1``
    for some ``j <= squarings`` the matrix is stable (a few stacked matmuls).
    Only the undecided matrices get an eigenvalue computation.
    """
    M = A / bound
    stable = np.zeros(A.shape[0], dtype=bool)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(squarings):
            stable |= np.linalg.norm(M, axis=(1, 2)) < 1.0
            M = M @ M
    undecided = ~stable
    if undecided.any():
        stable[undecided] = _spectral_radius(A[undecided]) < bound
    return stable


def _healthy(P: np.ndarray) -> np.ndarray:
    """Designs whose ``P`` is finite and not diverging."""
    with np.errstate(invalid="ignore"):
        return np.abs(P).max(axis=(1, 2)) < _DIVERGED


def _sda(d: _Data, tol: float, max_steps: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Stabilising solution of the steady-state RLQR Riccati equation by doubling.

    Eliminating the cross term of the penalty ``lambda ||EF x + EG u||^2``
    with Woodbury's identity (``Gam = (lambda^-1 I + EG R^-1 EG')^-1``, finite
    for every ``mu`` when ``EG`` has full row rank) gives the standard form

        X = Qs + As' X (I + Gs X)^-1 As,
        As = F - G R^-1 EG' Gam EF,   Qs = Q + EF' Gam EF,
        Gs = G (R^-1 - R^-1 EG' Gam EG R^-1) G' + S,

    solved by the structure-preserving doubling algorithm (Chu, Fan & Lin
    2005, Linear Algebra Appl. 396, 55-80): ``H_k -> X`` quadratically.
    Returns ``(X, steps, converged)``. If ``H_k`` blows up or keeps changing
    after ``max_steps`` doublings (``2**64`` recursion steps), the recursion
    has no stabilising fixed point: ``converged`` is False.
    """
    B = d.EF.shape[0]
    n = d.F.shape[0]
    l = d.EF.shape[1]
    Rinv = np.linalg.inv(d.R)
    EGR = d.EG @ Rinv                                                  # (B, l, m)
    Gam = _solve(d.lam_inv[:, None, None] * np.eye(l) + EGR @ np.swapaxes(d.EG, 1, 2),
                 np.broadcast_to(np.eye(l), (B, l, l)))
    EFT = np.swapaxes(d.EF, 1, 2)
    A = d.F - d.G @ (np.swapaxes(EGR, 1, 2) @ Gam @ d.EF)
    H = _sym(d.Q + EFT @ Gam @ d.EF)
    Gs = _sym(d.G @ (Rinv - np.swapaxes(EGR, 1, 2) @ Gam @ EGR) @ d.G.T + d.S)
    steps = np.zeros(B, dtype=int)
    converged = np.zeros(B, dtype=bool)
    active = _healthy(H) & _healthy(Gs)
    eye = np.eye(n)
    for _ in range(max_steps):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        a, g, h = A[idx], Gs[idx], H[idx]
        sol = _solve(eye + g @ h, np.concatenate([a, g], axis=2))     # W^-1 [A, G]
        WA, WG = sol[..., :n], sol[..., n:]
        aT = np.swapaxes(a, 1, 2)
        h_new = _sym(h + aT @ h @ WA)
        A[idx], Gs[idx], H[idx] = a @ WA, _sym(g + a @ WG @ aT), h_new
        steps[idx] += 1
        change = np.full(idx.size, np.inf)
        ok = _healthy(h_new)
        change[ok] = _relchange(h_new[ok], h[ok])
        converged[idx[change < tol]] = True
        active[idx[(change < tol) | ~ok]] = False
    return H, steps, converged


def _steady_state(d: _Data, P0: np.ndarray, tol: float, max_iter: int, accelerate: bool):
    """Stabilising fixed point of the recursion for every design.

    ``accelerate=True``: doubling (:func:`_sda`) on the equivalent standard
    Riccati equation; ``False``: the paper's recursion from ``P0``. Either way
    one more recursion step gives ``K``, ``L`` and the residual.

    Returns ``(P, K, L, iterations, residual, stable, settled)``. A design is
    acceptable iff ``residual < tol`` and ``stable`` (``rho(L) < 1 - 1e-9``),
    which singles out the stabilising solution. ``settled``: the iteration
    itself converged (False: it blew up or never settled, so no stabilising
    fixed point exists). Diverging designs come back with ``residual = inf``
    and NaN ``K``, ``L``.
    """
    B = d.EF.shape[0]
    n, m = d.G.shape
    if accelerate:  # doubling converges quadratically: run it well past tol
        P, iterations, settled = _sda(d, min(1e-3 * tol, 1e-13))
    else:
        P = np.broadcast_to(P0, (B, n, n)).copy()
        iterations = np.zeros(B, dtype=int)
        active = np.ones(B, dtype=bool)
        for it in range(1, max_iter + 1):
            idx = np.flatnonzero(active)
            P_new, _, _ = _step(P[idx], d_sub(d, active))
            change = _relchange(P_new, P[idx])
            P[idx] = P_new
            iterations[idx] = it
            active[idx[(change < tol) | ~_healthy(P_new)]] = False  # converged, or diverging
            if not active.any():
                break
        settled = ~active & _healthy(P)
    K = np.full((B, m, n), np.nan)
    L = np.full((B, n, n), np.nan)
    residual = np.full(B, np.inf)
    stable = np.zeros(B, dtype=bool)
    good = _healthy(P)
    if good.any():
        idx = np.flatnonzero(good)
        P_new, K[idx], L[idx] = _step(P[idx], d_sub(d, good))
        residual[idx] = _relchange(P_new, P[idx])
        P[idx] = P_new
        stable[idx] = _schur_stable(L[idx], 1.0 - _STABILITY_MARGIN)
    return P, K, L, iterations, residual, stable, settled


def d_sub(d: _Data, mask: np.ndarray) -> _Data:
    """The designs of ``d`` selected by ``mask``."""
    if mask.all():
        return d
    return _Data(d.F, d.G, d.Q, d.R, d.EF[mask], d.EG[mask], d.S[mask], d.lam_inv[mask], d.soft)


def _design_batch(d: _Data, P0: np.ndarray, tol: float, max_iter: int, accelerate: bool):
    """Steady state of every design with its verdict.

    Returns ``(P, K, L, iterations, residual, reason)``, ``reason`` in
    ``{"ok", "diverged", "not converged"}``. Designs on which doubling settled
    but missed the acceptance test (ill-conditioned ones, residual at the
    rounding floor) are redone with the plain recursion, the reference path.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        P, K, L, it, res, stable, settled = _steady_state(d, P0, tol, max_iter, accelerate)
        retry = settled & _healthy(P) & ~((res < tol) & stable)
        if accelerate and retry.any():
            sub = np.flatnonzero(retry)
            it_sda = it[sub].copy()
            out = _steady_state(d_sub(d, retry), P0, tol, max_iter, accelerate=False)
            for arr, new in zip((P, K, L, it, res, stable, settled), out):
                arr[sub] = new
            it[sub] += it_sda
    diverged = ~_healthy(P) | ~np.isfinite(K).all(axis=(1, 2))
    reason = np.full(len(P), "ok", dtype="<U13")
    reason[diverged] = "diverged"
    reason[~diverged & ~((res < tol) & stable)] = "not converged"
    return P, K, L, it, res, reason


# --------------------------------------------------------------------------- #
# Reference: the paper's block system (Theorem 1)                              #
# --------------------------------------------------------------------------- #
def rlqr_step_block(P_next, F, G, EF, EG, Q, R, H, mu: float, alpha: float = _DEFAULT_ALPHA):
    """One RLQR step by the paper's block system (Theorem 1, PAPER_NOTES reading).

    ``Xi`` has block rows of sizes (n, m, n, n + l, n, m)::

        Xi = [[P^-1, 0,    0,    0,      I,     0     ],
              [0,    R^-1, 0,    0,      0,     I     ],
              [0,    0,    Q^-1, 0,      0,     0     ],
              [0,    0,    0,    Sigma,  Ihat,  -Ghat ],
              [I,    0,    0,    Ihat',  0,     0     ],
              [0,    I,    0,    -Ghat', 0,     0     ]]

    ``b = [0; 0; -I; Fhat; 0; 0]``; ``L`` is block 5 and ``K`` block 6 of
    ``Xi^-1 b``, ``P = b' Xi^-1 b``. ``Sigma = blkdiag(mu^-1 I - lambda^-1 H H',
    lambda^-1 I)`` with ``lambda = (1 + alpha) ||mu H'H||`` (``Sigma = 0`` at
    ``mu = inf``; with ``H = 0`` the EF/EG rows are dropped, the
    ``lambda -> 0`` limit). Needs ``P_next`` and ``Q`` positive definite.

    Returns ``(L, K, P)``. Dense ``(4n + 2m + l)``-square solve: for tests and
    small problems, not for batches.
    """
    F, G, Q, R = (np.asarray(a, float) for a in (F, G, Q, R))
    EF, EG, H = np.atleast_2d(EF).astype(float), np.atleast_2d(EG).astype(float), np.asarray(H, float)
    n, m = G.shape
    hh = _penalty_scale(H)
    if hh == 0.0:
        EF, EG = EF[:0], EG[:0]
    l = EF.shape[0]
    if np.isinf(mu):
        Sigma = np.zeros((n + l, n + l))
    else:
        lam = (1.0 + alpha) * mu * hh
        Sigma = np.zeros((n + l, n + l))
        Sigma[:n, :n] = np.eye(n) / mu - (H @ H.T / lam if l else 0.0)
        Sigma[n:, n:] = np.eye(l) / lam if l else 0.0
    Fh, Gh = np.vstack([F, EF]), np.vstack([G, EG])
    Ih = np.vstack([np.eye(n), np.zeros((l, n))])
    sizes = [n, m, n, n + l, n, m]
    off = np.concatenate([[0], np.cumsum(sizes)])
    N = off[-1]
    Xi = np.zeros((N, N))

    def put(i, j, blk):
        Xi[off[i]:off[i + 1], off[j]:off[j + 1]] = blk

    put(0, 0, np.linalg.inv(P_next)); put(0, 4, np.eye(n))
    put(1, 1, np.linalg.inv(R)); put(1, 5, np.eye(m))
    put(2, 2, np.linalg.inv(Q))
    put(3, 3, Sigma); put(3, 4, Ih); put(3, 5, -Gh)
    put(4, 0, np.eye(n)); put(4, 3, Ih.T)
    put(5, 1, np.eye(m)); put(5, 3, -Gh.T)
    b = np.zeros((N, n))
    b[off[2]:off[3]] = -np.eye(n)
    b[off[3]:off[4]] = Fh
    sol = np.linalg.solve(Xi, b)
    L, K = sol[off[4]:off[5]], sol[off[5]:off[6]]
    return L, K, _sym(b.T @ sol)


def rlqr_step(P_next, F, G, EF, EG, Q, R, H, mu: float, alpha: float = _DEFAULT_ALPHA):
    """One RLQR step by the penalty/KKT form (see the module docstring). Returns ``(L, K, P)``.

    Same arguments as :func:`rlqr_step_block`; ``P_next`` and ``Q`` may be
    only positive semidefinite.
    """
    F, G, Q, R, H = (np.asarray(a, float) for a in (F, G, Q, R, H))
    EF, EG = np.atleast_2d(EF).astype(float), np.atleast_2d(EG).astype(float)
    d = _make_data(F, G, Q, R, H, EF[None], EG[None], np.array([float(mu)]), alpha)
    P, K, L = _step(np.asarray(P_next, float)[None], d)
    return L[0], K[0], P[0]


# --------------------------------------------------------------------------- #
# Public API                                                                   #
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, eq=False, repr=False)
class RLQRBatch:
    """Steady-state RLQR designs for a batch of ``B`` uncertainty models.

    Attributes
    ----------
    K : (B, m, n) ndarray
        Gains, ``u = K x``. Rows of designs that failed (``ok`` False) are NaN.
    P : (B, n, n) ndarray
        Steady-state Riccati matrices (NaN where ``ok`` is False).
    L : (B, n, n) ndarray
        Closed-loop matrices of the RLQR (``F + G K`` at ``mu = inf``).
    ok : (B,) bool ndarray
        The design converged to a finite fixed point with ``residual < tol``.
    reason : (B,) str ndarray
        ``"ok"``, ``"rank"`` (``mu = inf`` and ``EG`` not of full row rank),
        ``"not converged"`` or ``"diverged"`` (no stabilising steady state).
    stabilizing : (B,) bool ndarray
        ``F + G K`` is Schur stable (the nominal closed loop). For finite
        ``mu`` the RLQR stabilises its own closed loop ``L``, not necessarily
        ``F + G K``: a converged design (``ok``) can still destabilise the
        nominal plant.
    iterations : (B,) int ndarray
        Doubling steps (plus recursion steps where the plain recursion was needed).
    residual : (B,) ndarray
        Relative change of ``P`` in one more recursion step at the returned ``P``.
    """

    K: np.ndarray
    P: np.ndarray
    L: np.ndarray
    ok: np.ndarray
    reason: np.ndarray
    stabilizing: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray

    def __len__(self) -> int:
        return self.K.shape[0]

    def __repr__(self) -> str:
        return (f"RLQRBatch(B={len(self)}, m={self.K.shape[1]}, n={self.K.shape[2]}, "
                f"ok={int(self.ok.sum())}/{len(self)}, max_iterations={int(self.iterations.max(initial=0))})")


@dataclass(frozen=True, eq=False, repr=False)
class RLQRSchedule:
    """Finite-horizon RLQR: time-varying gains ``u[k] = K[k] x[k]``, ``k = 0..N-1``.

    Attributes
    ----------
    K : (N, m, n), L : (N, n, n), P : (N + 1, n, n) ndarrays
        ``P[N]`` is the terminal weight ``P_N``; ``x*[k+1] = L[k] x*[k]``.
    plant : Plant
    info : Mapping
    """

    K: np.ndarray
    L: np.ndarray
    P: np.ndarray
    plant: Plant
    info: Mapping[str, Any] = field(default_factory=dict)

    @property
    def horizon(self) -> int:
        return self.K.shape[0]

    def controller(self, k: int) -> Controller:
        """The gain of step ``k`` as a :class:`Controller`."""
        return Controller(self.K[k], "rlqr", self.plant, {"step": k, "L": self.L[k], "P": self.P[k]})

    def __repr__(self) -> str:
        return f"RLQRSchedule(horizon={self.horizon}, plant={self.plant!r})"


def _check_mu(mu, name: str = "mu") -> np.ndarray:
    arr = np.asarray(mu, dtype=float) if not isinstance(mu, (str, bytes)) else None
    if arr is None or arr.dtype.kind not in "fiu":
        raise TypeError(f"{name} must be a positive number or array of them (np.inf allowed)")
    if np.any(np.isnan(arr)):
        raise ValueError(f"{name} must not be NaN")
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 (np.inf allowed), got min {arr.min():g}")
    if np.any(arr < _MU_MIN):  # 1/mu would overflow the products of the recursion
        raise ValueError(f"{name} must be >= {_MU_MIN:g} (or np.inf), got min {arr.min():g}")
    return arr


def _common(plant, Q, R, H, alpha, l):
    if not isinstance(plant, Plant):
        raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
    if not plant.is_discrete:
        raise ValueError("plant must be discrete-time (dt > 0) for the RLQR; discretise it first")
    Q, R = _weights(plant, Q, R)
    n = plant.n
    H = np.ones((n, l)) if H is None else as_matrix(
        H, "H", rows=n, cols=1 if np.ndim(H) == 1 else None, rows_what="the number of states")
    alpha = check_positive_scalar(alpha, "alpha")
    return Q, R, H, alpha


def _rank_ok(EG: np.ndarray, mu: np.ndarray, H: np.ndarray) -> np.ndarray:
    """At mu = inf (and H != 0) EG (l x m) must have full row rank l."""
    ok = np.ones(EG.shape[0], dtype=bool)
    inf = np.isinf(mu)
    if inf.any() and _penalty_scale(H) > 0:
        l = EG.shape[1]
        if l > EG.shape[2]:
            ok[inf] = False
        else:
            sv = np.linalg.svd(EG[inf], compute_uv=False)
            ok[inf] = sv[:, -1] > 1e-12 * np.maximum(sv[:, 0], 1e-300)
    return ok


def rlqr_gains(plant: Plant, EF, EG, mu, *, Q=None, R=None, H=None, alpha: float = _DEFAULT_ALPHA,
               tol: float = _DEFAULT_TOL, max_iter: int = _DEFAULT_MAX_ITER, P0=None) -> RLQRBatch:
    """Steady-state RLQR gains for ``B`` uncertainty models at once (vectorised).

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant (shared by the batch).
    EF : (B, l, n) array_like
    EG : (B, l, m) array_like
    mu : (B,) array_like
        Penalty parameters in ``[1e-100, inf]``; ``np.inf`` gives the limit form.
        Any of ``EF``, ``EG``, ``mu`` may omit the batch axis to be shared.
    Q, R : weights (defaults identity); ``H`` (n, p), default ``ones((n, l))``.
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||``.
    tol, max_iter :
        Convergence: relative change of ``P`` in one recursion step
        ``< tol`` and ``rho(L) < 1``; at most ``max_iter`` steps of the plain
        recursion where doubling fails.
    P0 : (n, n) array_like, optional
        Starting point of the plain recursion where it is needed (default
        ``Q``; the steady state does not depend on it).

    Returns
    -------
    RLQRBatch
        Gains and per-design flags; failed designs are flagged, never silently
        NaN: check ``ok``/``reason``.

    Notes
    -----
    All designs are solved together with stacked ``(B, k, k)`` solves by
    doubling (module docstring); no Python loop over designs.
    """
    if not isinstance(plant, Plant):
        raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
    EF = as_batch(EF if np.ndim(EF) == 3 else np.atleast_2d(EF)[None], "EF", (None, None, plant.n),
                  ("", "", "the number of states"))
    l = EF.shape[1]
    EG = as_batch(EG if np.ndim(EG) == 3 else np.atleast_2d(EG)[None], "EG", (None, l, plant.m),
                  ("", "the rows of EF", "the number of inputs"))
    mu = np.atleast_1d(_check_mu(mu))
    if mu.ndim != 1:
        raise ValueError(f"mu must be a scalar or 1-D array of shape (B,), got shape {mu.shape}")
    sizes = {EF.shape[0], EG.shape[0], mu.shape[0]} - {1}
    if len(sizes) > 1:
        raise ValueError(f"batch sizes differ: EF {EF.shape[0]}, EG {EG.shape[0]}, mu {mu.shape[0]}")
    B = sizes.pop() if sizes else 1
    EF, EG = np.broadcast_to(EF, (B,) + EF.shape[1:]), np.broadcast_to(EG, (B,) + EG.shape[1:])
    mu = np.broadcast_to(mu, (B,))
    Q, R, H, alpha = _common(plant, Q, R, H, alpha, l)
    tol = check_positive_scalar(tol, "tol")
    if not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    P0 = Q if P0 is None else check_spd(as_matrix(P0, "P0", rows=plant.n, cols=plant.n), "P0",
                                         semidefinite=True)

    rank_ok = _rank_ok(EG, mu, H)
    n, m = plant.n, plant.m
    K = np.full((B, m, n), np.nan)
    P = np.full((B, n, n), np.nan)
    L = np.full((B, n, n), np.nan)
    iterations = np.zeros(B, dtype=int)
    residual = np.full(B, np.inf)
    reason = np.where(rank_ok, "ok", "rank").astype("<U13")
    if rank_ok.any():
        d = _make_data(plant.F, plant.G, Q, R, H, EF[rank_ok], EG[rank_ok], mu[rank_ok], alpha)
        idx = np.flatnonzero(rank_ok)
        P[idx], K[idx], L[idx], iterations[idx], residual[idx], reason[idx] = _design_batch(
            d, P0, tol, int(max_iter), accelerate=True)
    ok = reason == "ok"
    K[~ok], P[~ok], L[~ok] = np.nan, np.nan, np.nan
    stabilizing = np.zeros(B, dtype=bool)
    stabilizing[ok] = _schur_stable(plant.F + plant.G @ K[ok])
    return RLQRBatch(*(_frozen(a) for a in (K, P, L)), ok, reason, stabilizing, iterations, residual)


def rlqr(plant: Plant, EF, EG, mu, *, Q=None, R=None, H=None, alpha: float = _DEFAULT_ALPHA,
         horizon: int | None = None, P_N=None, tol: float = _DEFAULT_TOL,
         max_iter: int = _DEFAULT_MAX_ITER, accelerate: bool = True,
         implementation: str = "kkt") -> Controller | RLQRSchedule:
    """Robust LQR for ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1`` (paper Theorem 1).

    Parameters
    ----------
    plant : Plant
        Nominal discrete-time plant ``(F, G)``.
    EF : (l, n) array_like
    EG : (l, m) array_like
    mu : float
        Penalty parameter in ``[1e-100, inf]``; ``np.inf`` gives Algorithm 1 (``Sigma = 0``),
        which forces ``EF + EG K = 0`` and ``L = F + G K`` and needs ``EG`` of
        full row rank.
    Q : (n, n) symmetric PSD, default identity (PD for ``implementation="block"``)
    R : (m, m) symmetric PD, default identity
    H : (n, p), default ``ones((n, l))``; ``H = 0`` means no uncertainty
        (``lambda -> 0`` limit: ``EF``, ``EG`` are then ignored).
    alpha : float, default 0.1
        ``lambda = (1 + alpha) ||mu H'H||``.
    horizon : int, optional
        If given, the finite-horizon time-varying gains ``K_0 .. K_{N-1}``
        from the terminal weight ``P_N`` (an :class:`RLQRSchedule`).
    P_N : (n, n), optional
        Terminal weight / starting point of the recursion (default ``Q``).
    tol, max_iter :
        Steady state: stop when one recursion step changes ``P`` by less than
        ``tol`` (relative Frobenius norm); :class:`ConvergenceError` after
        ``max_iter`` steps.
    accelerate : bool, default True
        Find the steady state by doubling (same fixed point, same acceptance
        test, far fewer steps). ``False``: the paper's plain recursion.
    implementation : {"kkt", "block"}
        Step formula: the penalty/KKT form (default) or the paper's block
        system (reference; plain recursion, needs ``Q`` and ``P_N`` PD).

    Returns
    -------
    Controller (steady state; ``info`` holds ``P``, ``L``, ``lambda``,
    ``iterations``, ``residual``) or :class:`RLQRSchedule` (``horizon`` given).
    For finite ``mu`` the RLQR stabilises its closed loop ``L``; check
    ``ctrl.is_stabilizing()`` for the nominal ``F + G K``.

    Raises
    ------
    RankConditionError
        ``mu = inf`` and ``EG`` is not of full row rank (``[I -G; 0 -EG]`` is
        then not of full row rank and ``EF + EG K = 0`` may have no solution).
    ConvergenceError
        The steady-state recursion did not converge in ``max_iter`` steps.
    """
    if not isinstance(plant, Plant):
        raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
    EF = as_matrix(EF, "EF", cols=plant.n, cols_what="the number of states")
    l = EF.shape[0]
    EG = as_matrix(EG, "EG", rows=l, cols=plant.m, rows_what="the rows of EF",
                   cols_what="the number of inputs")
    mu_arr = _check_mu(mu)
    if mu_arr.shape != ():
        raise TypeError(f"mu must be a scalar for rlqr (use rlqr_gains for batches), got shape {mu_arr.shape}")
    mu = float(mu_arr)
    Q, R, H, alpha = _common(plant, Q, R, H, alpha, l)
    if implementation not in ("kkt", "block"):
        raise ValueError(f"implementation must be 'kkt' or 'block', got {implementation!r}")
    if implementation == "block":
        check_spd(Q, "Q")
    tol = check_positive_scalar(tol, "tol")
    if not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    P_N = Q if P_N is None else check_spd(as_matrix(P_N, "P_N", rows=plant.n, cols=plant.n), "P_N",
                                           semidefinite=implementation == "kkt")
    if not _rank_ok(EG[None], np.array([mu]), H)[0]:
        raise RankConditionError(
            f"mu = inf needs EG ({l}x{plant.m}) to have full row rank {l} "
            f"(equivalently [I -G; 0 -EG] of full row rank), got rank {np.linalg.matrix_rank(EG)}; "
            "use a finite mu or change EG")
    hh = _penalty_scale(H)
    lam = 0.0 if hh == 0 else (np.inf if np.isinf(mu) else (1 + alpha) * mu * hh)
    info = {"mu": mu, "alpha": alpha, "lambda": lam, "implementation": implementation}

    if implementation == "block":
        def step(P):
            L, K, Pn = rlqr_step_block(P, plant.F, plant.G, EF, EG, Q, R, H, mu, alpha)
            return Pn, K, L
    else:
        d = _make_data(plant.F, plant.G, Q, R, H, EF[None], EG[None], np.array([mu]), alpha)

        def step(P):
            Pn, K, L = _step(P[None], d)
            return Pn[0], K[0], L[0]

    if horizon is not None:
        if not isinstance(horizon, (int, np.integer)) or horizon < 1:
            raise ValueError(f"horizon must be a positive integer, got {horizon!r}")
        Ps, Ks, Ls = [P_N], [], []
        for _ in range(int(horizon)):
            Pk, Kk, Lk = step(Ps[0])
            Ps.insert(0, Pk); Ks.insert(0, Kk); Ls.insert(0, Lk)
        K, L, P = (_frozen(np.array(a)) for a in (Ks, Ls, Ps))
        if not (np.isfinite(K).all() and np.isfinite(P).all()):
            raise ConvergenceError("the finite-horizon recursion produced non-finite values")
        return RLQRSchedule(K, L, P, plant, info)

    with np.errstate(over="ignore", invalid="ignore"):
        if implementation == "kkt":
            Ps, Ks, Ls, its, ress, reasons = _design_batch(d, P_N, tol, int(max_iter), accelerate)
            P, K, L, it, res, verdict = Ps[0], Ks[0], Ls[0], int(its[0]), float(ress[0]), reasons[0]
        else:
            P, it, res = P_N, 0, np.inf
            for it in range(1, int(max_iter) + 1):
                try:
                    P_new, K, L = step(P)
                except np.linalg.LinAlgError:  # P became numerically singular: divergence
                    P = np.full_like(P, np.inf)
                    break
                res = float(_relchange(P_new[None], P[None])[0])
                P = P_new
                if res < tol or not np.abs(P).max() < _DIVERGED:
                    break
            if not (np.abs(P).max() < _DIVERGED and np.isfinite(K).all()):
                verdict = "diverged"
            elif res < tol and _schur_stable(L[None], 1.0 - _STABILITY_MARGIN)[0]:
                verdict = "ok"
            else:
                verdict = "not converged"
    if verdict == "diverged":
        why = (" At mu = inf the gain must satisfy EF + EG K = 0; the closed loop F + G K it forces "
               "may be unstable." if np.isinf(mu) else "")
        raise ConvergenceError(f"the RLQR recursion diverged (P grows without bound): no stabilising "
                               f"steady state for this plant and uncertainty.{why}")
    if verdict != "ok":
        raise ConvergenceError(f"the RLQR recursion did not reach a stabilising steady state in "
                               f"max_iter={max_iter} steps (relative change of P {res:.3g}, tol={tol:g})")
    info.update(P=P, L=L, iterations=it, residual=res)
    return Controller(K, "rlqr", plant, info)
