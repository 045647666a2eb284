"""The regularised least-squares (KKT) kernel shared by the robust regulator and the robust filter.

One step of the robust LQR (:func:`robustctl.rlqr`) and of the robust filter
are each the solution of a regularised least-squares problem, written as one
symmetric indefinite (KKT) linear system per design; a population of designs
is a stack of such systems. This module holds what both solve them with:
:func:`solve`, a stacked solve in which a numerically singular system spoils
only its own design, and :func:`sym`, the symmetric part of a stack.

References
----------
A. H. Sayed, "A framework for state-space estimation with uncertain models",
IEEE TAC 46(7), 2001.
"""

from __future__ import annotations

import contextlib

import numpy as np

__all__ = ["solve", "sym"]


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
