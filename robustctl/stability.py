"""Schur stability of discrete-time closed loops, batched.

A discrete-time linear system ``x[k+1] = A x[k]`` is asymptotically stable
(``A`` is Schur) iff its spectral radius ``rho(A) = max_i |lambda_i(A)|`` is
below 1 (e.g. K. J. Astrom & B. Wittenmark, *Computer-Controlled Systems*,
3rd ed., 1997, Sec. 3.2). These two functions are the one stability test of
the package's batched code paths: stacks of matrices in, one value per matrix
out, and a matrix with non-finite entries (a failed design) reported as
unstable instead of raising.

:func:`is_schur_stable` first tries a cheap certificate: since
``rho(A) = rho(A^k)^(1/k) <= ||A^k||`` for any sub-multiplicative norm, a
Frobenius norm ``||A^(2^j)||_F < 1`` for some ``j`` proves ``rho(A) < 1``
(R. A. Horn & C. R. Johnson, *Matrix Analysis*, 2nd ed., 2013, Cor. 5.6.14);
``j`` squarings of a whole stack are a few batched matrix products. Only the
matrices it leaves undecided (unstable ones, and stable ones whose powers
are still large after ``2^SQUARINGS`` steps) get an eigenvalue computation,
whose ``rho < 1`` then decides.
"""

from __future__ import annotations

import numbers

import numpy as np

from ._validation import as_float_array

__all__ = ["spectral_radius", "is_schur_stable", "SQUARINGS"]

#: Squarings of the norm certificate of :func:`is_schur_stable` (powers up to 2**10 = 1024).
SQUARINGS = 10


def _as_square_stack(A, name: str) -> np.ndarray:
    arr = as_float_array(A, name)
    if arr.ndim < 2 or arr.shape[-1] != arr.shape[-2] or arr.shape[-1] == 0:
        raise ValueError(f"{name} must be a square matrix or a stack (..., n, n) of them, got shape {arr.shape}")
    return arr


def spectral_radius(A) -> np.ndarray:
    """``max_i |lambda_i(A)|`` of each matrix of a stack.

    Parameters
    ----------
    A : (n, n) or (..., n, n) array_like

    Returns
    -------
    ndarray of shape ``A.shape[:-2]`` (a 0-d array for one matrix)
        ``inf`` for a matrix with a NaN or infinite entry.
    """
    A = _as_square_stack(A, "A")
    rho = np.full(A.shape[:-2], np.inf)
    finite = np.isfinite(A).all(axis=(-2, -1))
    if finite.any():
        rho[finite] = np.abs(np.linalg.eigvals(A[finite])).max(axis=-1)
    return rho


def is_schur_stable(A, *, margin: float = 0.0) -> np.ndarray:
    """``spectral_radius(A) < 1 - margin`` for each matrix of a stack (False for non-finite ones).

    Decided by the norm certificate of the module docstring where it applies,
    by the eigenvalues otherwise (same answer; cheaper for stacks of stable
    matrices).

    Parameters
    ----------
    A : (n, n) or (..., n, n) array_like
    margin : float
        Required distance of the eigenvalues from the unit circle, in ``[0, 1)``.

    Returns
    -------
    bool ndarray of shape ``A.shape[:-2]``
    """
    if isinstance(margin, bool) or not isinstance(margin, numbers.Real):
        raise TypeError(f"margin must be a real number, got {type(margin).__name__}")
    if not 0.0 <= float(margin) < 1.0:
        raise ValueError(f"margin must lie in [0, 1), got {margin!r}")
    A = _as_square_stack(A, "A")
    n = A.shape[-1]
    flat = A.reshape(-1, n, n)
    level = 1.0 - float(margin)
    stable = np.zeros(flat.shape[0], dtype=bool)
    idx = np.flatnonzero(np.isfinite(flat).all(axis=(1, 2)))
    M = flat[idx] / level
    with np.errstate(over="ignore", invalid="ignore"):
        for j in range(SQUARINGS + 1):                              # M = (A / level)^(2^j)
            proven = np.einsum("bij,bij->b", M, M) < 1.0                # ||M||_F^2 < 1
            stable[idx[proven]] = True
            idx, M = idx[~proven], M[~proven]
            if idx.size == 0 or j == SQUARINGS:
                break
            M = M @ M
    if idx.size:
        stable[idx] = spectral_radius(flat[idx]) < level
    return stable.reshape(A.shape[:-2])
