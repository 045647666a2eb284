"""The regularised least-squares (KKT) kernel shared by the robust regulator and the robust filter.

One step of the robust LQR (:func:`robustctl.rlqr`) and of the robust filter
are each the solution of a regularised least-squares problem, written as one
symmetric indefinite (KKT) linear system per design; a population of designs
is a stack of such systems. This module holds what both solve them with:
:func:`solve`, a stacked solve in which a numerically singular system spoils
only its own design, :func:`sym`, the symmetric part of a stack, and
:func:`weighted_lsq`, the KKT form of a weighted least-squares problem whose
weight may be infinite on some rows (hard constraints, the ``mu -> inf``
limit of the penalty method). Their steady states are fixed points of a
Riccati recursion: :func:`doubling` (the structure-preserving doubling
algorithm), :func:`stein` (Smith's iteration, for Newton's method),
:func:`relchange` and :func:`healthy` serve both.

References
----------
A. H. Sayed, "A framework for state-space estimation with uncertain models",
IEEE TAC 46(7), 2001.
E. K.-W. Chu, H.-Y. Fan and W.-W. Lin, "A structure-preserving doubling
algorithm for continuous-time algebraic Riccati equations", Linear Algebra
Appl. 396, 2005 (and its discrete-time form).
"""

from __future__ import annotations

import contextlib

import numpy as np

from ._jit import jit
from ._validation import as_float_array

__all__ = ["solve", "sym", "weighted_lsq", "fixed_point", "doubling", "stein", "relchange", "healthy", "check_penalty",
           "DIVERGED", "DEFAULT_ALPHA", "MU_MIN"]

#: Default margin of ``lambda = (1 + alpha) mu ||H'H||`` (Sayed's approximation of the optimal ``lambda``).
DEFAULT_ALPHA = 0.1
#: Smallest accepted penalty ``mu`` (``1/mu`` enters products with ``P``).
MU_MIN = 1e-100
#: ``|P|`` beyond this: a recursion is diverging.
DIVERGED = 1e250
#: Smith iteration for a Stein equation: stop when the increment is below this, relative to the largest entry.
STEIN_TOL = 1e-17
STEIN_MAX_SQUARINGS = 60
_TINY = np.finfo(float).tiny


def sym(P: np.ndarray) -> np.ndarray:
    """The symmetric part ``(P + P') / 2`` of every matrix of a stack ``(..., n, n)``."""
    return 0.5 * (P + P.swapaxes(-1, -2))


def solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Stacked solve ``A[i] x[i] = b[i]``; a numerically singular system gives NaN for that design only.

    (``np.linalg.solve`` fails the whole stack if one matrix is singular, e.g.
    ``R + G' Pt G`` with two identical input columns and ``Pt ~ mu ~ 1e20``.)
    """
    try:
        return np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        out = np.full(b.shape, np.nan)
        for i in range(A.shape[0]):  # rare fallback, only when some system is singular
            with contextlib.suppress(np.linalg.LinAlgError):
                out[i] = np.linalg.solve(A[i], b[i])
        return out


def weighted_lsq(Winv: np.ndarray, A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Weighted least squares in KKT form, for a stack: the minimiser and its covariance.

    .. math::

        \hat z = \arg\min_z \|A z - b\|^2_{W^{-1}_{inv}}, \qquad
        \begin{bmatrix} W_{inv} & A \\ A' & 0 \end{bmatrix}
        \begin{bmatrix} r & \cdot \\ \hat z & \Pi \end{bmatrix} =
        \begin{bmatrix} b & 0 \\ 0 & -I \end{bmatrix},

    so that ``Pi = (A' Winv^-1 A)^-1``. ``Winv`` (the inverse weight: a
    covariance) may be singular: its zero rows are constraints met exactly
    (the ``mu -> inf`` limit of a penalty). Solvable when those rows of ``A``
    have full row rank and ``A`` has full column rank.

    Parameters
    ----------
    Winv : (B, r, r) symmetric positive semidefinite
    A : (B, r, N)
    b : (B, r, c)

    Returns
    -------
    z : (B, N, c)
    Pi : (B, N, N)
        NaN for a design whose KKT matrix is singular.
    """
    B, r, N = A.shape
    kkt = np.zeros((B, r + N, r + N))
    kkt[:, :r, :r] = Winv
    kkt[:, :r, r:] = A
    kkt[:, r:, :r] = A.swapaxes(1, 2)
    rhs = np.zeros((B, r + N, b.shape[2] + N))
    rhs[:, :r, :b.shape[2]] = b
    rhs[:, r:, b.shape[2]:] = -np.eye(N)
    sol = solve(kkt, rhs)[:, r:]
    return sol[..., :b.shape[2]], sym(sol[..., b.shape[2]:])


def _fro(X: np.ndarray) -> np.ndarray:
    """Batched Frobenius norm (``np.linalg.norm(X, axis=(1, 2))`` without its Python overhead)."""
    return np.sqrt(np.add.reduce(X * X, axis=(1, 2)))


def relchange(new: np.ndarray, old: np.ndarray) -> np.ndarray:
    """``||new - old||_F / ||new||_F`` per matrix of a stack (NaN stays NaN)."""
    return _fro(new - old) / np.maximum(_fro(new), _TINY)


def healthy(P: np.ndarray, bound: float = DIVERGED) -> np.ndarray:
    """Per matrix of a stack: every entry finite and below ``bound`` in magnitude."""
    return np.abs(P).max(axis=(1, 2)) < bound


def fixed_point(advance, P0: np.ndarray, size: int, tol: float, max_iter: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plain Riccati recursion of a stack: ``P <- advance(P[active], active)`` until each design settles.

    A design stops when one step changes ``P`` by less than ``tol`` (:func:`relchange`) or ``P`` stops being
    :func:`healthy`, after at most ``max_iter`` steps. Returns ``(P, iterations, active)``; ``active`` is True
    where a design was still moving when ``max_iter`` ran out.
    """
    P = np.broadcast_to(P0, (size, *P0.shape[-2:])).copy()
    iterations = np.zeros(size, dtype=int)
    active = np.ones(size, dtype=bool)
    for it in range(1, max_iter + 1):
        idx = np.flatnonzero(active)
        P_new = advance(P[idx], active)
        change = relchange(P_new, P[idx])
        P[idx] = P_new
        iterations[idx] = it
        active[idx[(change < tol) | ~healthy(P_new)]] = False      # converged, or diverging
        if not active.any():
            break
    return P, iterations, active


@jit
def lu_solve(A, b):
    """Solve ``A x = b`` in place (``A`` (k, k) becomes its LU factors, ``b`` (k, c) the solution).

    Partial pivoting; returns False (``b`` then unspecified) when a pivot is exactly zero.
    """
    k, c = b.shape
    for j in range(k):
        p, big = j, abs(A[j, j])
        for i in range(j + 1, k):
            if abs(A[i, j]) > big:
                p, big = i, abs(A[i, j])
        if A[p, j] == 0.0:
            return False
        if p != j:
            for q in range(k):
                A[j, q], A[p, q] = A[p, q], A[j, q]
            for q in range(c):
                b[j, q], b[p, q] = b[p, q], b[j, q]
        r = 1.0 / A[j, j]
        for i in range(j + 1, k):
            f = A[i, j] * r
            A[i, j] = f
            for q in range(j + 1, k):
                A[i, q] -= f * A[j, q]
            for q in range(c):
                b[i, q] -= f * b[j, q]
    for j in range(k - 1, -1, -1):
        r = 1.0 / A[j, j]
        for q in range(c):
            s = b[j, q]
            for t in range(j + 1, k):
                s -= A[j, t] * b[t, q]
            b[j, q] = s * r
    return True


@jit
def fill(A, value):
    """``A[i, j] = value`` everywhere."""
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            A[i, j] = value


@jit
def copy_into(A, out):
    """``out[i, j] = A[i, j]`` over ``out``'s shape."""
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            out[i, j] = A[i, j]


@jit
def product(A, B, out):
    """``out = A B`` (A (i, t), B (t, j); views such as ``A.T`` too) into ``out[:i, :j]``."""
    for i in range(A.shape[0]):
        for j in range(B.shape[1]):
            s = 0.0
            for t in range(A.shape[1]):
                s += A[i, t] * B[t, j]
            out[i, j] = s


@jit
def eye_plus_product(A, B, out):
    """``out = I + A B`` (A (k, t), B (t, k)) into ``out[:k, :k]``."""
    product(A, B, out)
    for i in range(A.shape[0]):
        for j in range(B.shape[1]):
            out[i, j] = (1.0 if i == j else 0.0) + out[i, j]


@jit
def relchange_one(new, old, tiny):
    """``||new - old||_F / max(||new||_F, tiny)`` (NaN stays NaN)."""
    num, den = 0.0, 0.0
    for i in range(new.shape[0]):
        for j in range(new.shape[1]):
            num += (new[i, j] - old[i, j]) ** 2
            den += new[i, j] * new[i, j]
    den = np.sqrt(den)
    return np.sqrt(num) / (tiny if den < tiny else den)  # noqa: FURB136 (NaN stays NaN, as np.maximum)


@jit
def healthy_one(P, bound):
    """Every entry of ``P`` below ``bound`` in magnitude (NaN is not)."""
    for i in range(P.shape[0]):
        for j in range(P.shape[1]):
            if not abs(P[i, j]) < bound:
                return False
    return True


@jit
def _doubling(A, G, H, tol, max_steps, bound, tiny, steps, settled, active):
    """The steps of :func:`doubling` for every ``active`` design; ``A``, ``G``, ``H`` (B, n, n) are overwritten.

    Per step ``W = I + G H``, ``[WA, WG] = W^-1 [A, G]``, ``H <- sym(H + (A'H) WA)``, ``A <- A WA``,
    ``G <- sym(G + (A WG) A')``, until ``H`` changes by less than ``tol`` or is not healthy.
    """
    n = H.shape[1]
    W, sol, AH, AW, hn = np.empty((n, n)), np.empty((n, 2 * n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n))
    for b in range(H.shape[0]):
        a, g, h = A[b], G[b], H[b]
        k = 0
        while active[b] and k < max_steps:
            k += 1
            eye_plus_product(g, h, W)
            for i in range(n):
                for j in range(n):
                    sol[i, j] = a[i, j]
                    sol[i, n + j] = g[i, j]
            if not lu_solve(W, sol):
                fill(sol, np.nan)
            product(a.T, h, AH)                           # h_new = sym(h + (a'h) WA)
            product(AH, sol[:, :n], hn)
            for i in range(n):
                for j in range(n):
                    hn[i, j] = h[i, j] + hn[i, j]
            for i in range(n):
                for j in range(i, n):
                    v = 0.5 * (hn[i, j] + hn[j, i])
                    hn[i, j] = v
                    hn[j, i] = v
            ok = healthy_one(hn, bound)
            change = relchange_one(hn, h, tiny) if ok else np.inf
            product(a, sol[:, n:], AW)                    # g = sym(g + (a WG) a')
            product(AW, a.T, W)
            for i in range(n):
                for j in range(n):
                    W[i, j] = g[i, j] + W[i, j]
            for i in range(n):
                for j in range(n):
                    g[i, j] = 0.5 * (W[i, j] + W[j, i])
            product(a, sol[:, :n], AW)                    # a = a WA
            copy_into(AW, a)
            copy_into(hn, h)
            steps[b] += 1
            settled[b] |= change < tol
            active[b] = change >= tol and ok


def doubling(A: np.ndarray, G: np.ndarray, H: np.ndarray, tol: float, max_steps: int,
             active: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Stabilising solution of ``X = H + A' X (I + G X)^-1 A`` by doubling, for a stack (compiled).

    The structure-preserving doubling algorithm (Chu, Fan & Lin 2005): with
    ``W = I + G_k H_k``,

    .. math::

        A_{k+1} = A_k W^{-1} A_k, \quad G_{k+1} = G_k + A_k W^{-1} G_k A_k', \quad
        H_{k+1} = H_k + A_k' H_k W^{-1} A_k,

    ``H_k`` is the ``2^k``-step iterate of the Riccati recursion from ``H``
    and converges quadratically to the stabilising solution (``G``, ``H``
    symmetric positive semidefinite). A design stops when ``H`` changes by
    less than ``tol`` (relative Frobenius norm) or stops being
    :func:`healthy`. ``active`` (bool (B,)) selects the designs to iterate.
    The steps run design by design in a compiled loop (numba; ``W`` by LU
    with partial pivoting, an exactly singular ``W`` gives NaN for that
    design): for the small systems of a population numpy's cost is its
    per-call overhead (about 30 times the compiled loop for one 4-state design).

    Returns
    -------
    H : (B, n, n)
        The last iterate of each design.
    steps : (B,) int
    settled : (B,) bool
        The design met ``tol`` (False: it blew up or was still moving after ``max_steps``).
    """
    A, G, H = (np.array(x, dtype=float, order="C") for x in (A, G, H))
    B = H.shape[0]
    steps, settled = np.zeros(B, dtype=np.int64), np.zeros(B, dtype=bool)
    active = np.ones(B, dtype=bool) if active is None else np.array(active, dtype=bool)
    _doubling(A, G, H, float(tol), int(max_steps), DIVERGED, _TINY, steps, settled, active)
    return H, steps.astype(int), settled


def stein(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Solve ``X = A' X A + C`` for a stack (``rho(A) < 1``) by Smith's doubling iteration."""
    X, Ak = C.copy(), A.copy()
    for _ in range(STEIN_MAX_SQUARINGS):
        inc = Ak.swapaxes(1, 2) @ X @ Ak
        X = X + inc
        Ak = Ak @ Ak
        if np.all(np.abs(inc) <= STEIN_TOL * np.abs(X).max(axis=(1, 2), keepdims=True)):
            break
    return sym(X)


def check_penalty(mu, name: str = "mu", *, batch: bool = False, what: str = "this design") -> np.ndarray:
    """Penalties in ``[MU_MIN, inf]`` as a 1-D array: a scalar, or (``batch``) a scalar or a 1-D array.

    ``mu`` is required (``None`` is a ``TypeError``); NaN, ``mu <= 0`` and
    ``mu < MU_MIN`` are ``ValueError``; ``np.inf`` is the penalty method's limit.
    """
    if mu is None:
        raise TypeError(f"{name} is required: a positive number (np.inf allowed)")
    arr = as_float_array(mu, name)
    if np.any(np.isnan(arr)):
        raise ValueError(f"{name} must not be NaN")
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 (np.inf allowed), got min {arr.min():g}")
    if np.any(arr < MU_MIN):
        raise ValueError(f"{name} must be >= {MU_MIN:g} (or np.inf), got min {arr.min():g}")
    if not batch and arr.shape != ():
        raise TypeError(f"{name} must be a scalar for {what}, got shape {arr.shape}")
    if arr.ndim > 1:
        raise ValueError(f"{name} must be a scalar or a 1-D array of shape (B,), got shape {arr.shape}")
    return np.atleast_1d(arr)
