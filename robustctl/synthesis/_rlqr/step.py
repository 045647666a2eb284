"""One RLQR recursion step ``P[k+1] -> (P[k], K[k], L[k])``.

The batched penalty/KKT form and the paper's block system (the reference).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..._kkt import DEFAULT_ALPHA, solve, sym
from ..._validation import as_matrix, check_spd
from ...systems.plant import Plant
from .model import Model, _norm2, build


class Step(NamedTuple):
    """One step for a batch: ``P`` (B, n, n) ``= P[k]``, ``K`` (B, m, n), ``L`` (B, n, n)."""

    P: np.ndarray
    K: np.ndarray
    L: np.ndarray


def kkt_step(P: np.ndarray, d: Model) -> Step:
    """The penalty/KKT form of the step (``robustctl.synthesis.rlqr``) for every design of ``d``."""
    n, m = d.G.shape
    l = d.EF.shape[1]
    eye = np.eye(n)
    soft = d.soft
    Pt = sym(solve(eye + P @ d.S, P)) if soft else P
    GtPt = d.G.T @ Pt                                              # (B, m, n)
    kkt = np.zeros((P.shape[0], m + l, m + l))
    kkt[:, :m, :m] = d.R + GtPt @ d.G
    kkt[:, :m, m:] = d.EG.swapaxes(1, 2)
    kkt[:, m:, :m] = d.EG
    kkt[:, m:, m:] = -d.lam_inv[:, None, None] * np.eye(l)
    sol = solve(kkt, -np.concatenate([GtPt @ d.F, d.EF], axis=1))  # (B, m + l, n)
    K, nu = sol[:, :m], sol[:, m:]
    Lc = d.F + d.G @ K
    L = solve(eye + d.S @ P, Lc) if soft else Lc
    # Q + K'RK + lambda^-1 nu'nu (= Q + K'RK + lambda ||EF + EG K||^2) + Lc' Pt Lc
    stage = d.Q + K.swapaxes(1, 2) @ d.R @ K + d.lam_inv[:, None, None] * (nu.swapaxes(1, 2) @ nu)
    return Step(sym(stage + Lc.swapaxes(1, 2) @ Pt @ Lc), K, L)


def block_step(P_next, F, G, EF, EG, Q, R, H, mu: float, alpha: float) -> Step:
    """The block system of Theorem 1 for one design (float arrays); ``P``, ``K``, ``L`` without batch axis."""
    n, m = G.shape
    hh = _norm2(H)
    if hh == 0.0:
        EF, EG = EF[:0], EG[:0]
    l = EF.shape[0]
    Sigma = np.zeros((n + l, n + l))
    if not np.isinf(mu):
        lam = (1.0 + alpha) * mu * hh
        Sigma[:n, :n] = np.eye(n) / mu - (H @ H.T / lam if l else 0.0)
        Sigma[n:, n:] = np.eye(l) / lam if l else 0.0
    Fh, Gh = np.vstack([F, EF]), np.vstack([G, EG])
    Ih = np.vstack([np.eye(n), np.zeros((l, n))])
    off = np.concatenate([[0], np.cumsum([n, m, n, n + l, n, m])])
    Xi = np.zeros((off[-1], off[-1]))
    for i, j, blk in ((0, 0, np.linalg.inv(P_next)), (0, 4, np.eye(n)),
                      (1, 1, np.linalg.inv(R)), (1, 5, np.eye(m)),
                      (2, 2, np.linalg.inv(Q)),
                      (3, 3, Sigma), (3, 4, Ih), (3, 5, -Gh),
                      (4, 0, np.eye(n)), (4, 3, Ih.T),
                      (5, 1, np.eye(m)), (5, 3, -Gh.T)):
        Xi[off[i]:off[i + 1], off[j]:off[j + 1]] = blk
    b = np.zeros((off[-1], n))
    b[off[2]:off[3]] = -np.eye(n)
    b[off[3]:off[4]] = Fh
    sol = np.linalg.solve(Xi, b)
    return Step(sym(b.T @ sol), sol[off[5]:off[6]], sol[off[4]:off[5]])


def block_steps(P: np.ndarray, d: Model) -> Step:
    """:func:`block_step` for every design of ``d`` (a loop: the reference, for small batches).

    A numerically singular system (``P`` no longer invertible: divergence) gives NaN.
    """
    B, n = P.shape[:2]
    out = Step(np.full_like(P, np.nan), np.full((B, d.G.shape[1], n), np.nan), np.full_like(P, np.nan))
    for i in range(B):
        try:
            step = block_step(P[i], d.F, d.G, d.EF[i], d.EG[i], d.Q, d.R, d.H, float(d.mu[i]), d.alpha)
        except np.linalg.LinAlgError:
            continue
        for arr, value in zip(out, step, strict=True):
            arr[i] = value
    return out


def _checked(P_next, F, G, EF, EG, Q, R, H, mu, alpha, definite: bool):
    """The arguments of the single-step functions, validated like :func:`robustctl.rlqr`'s."""
    d = build(Plant(F, G, 1.0), EF, EG, mu, Q=Q, R=R, H=H, alpha=alpha, batch=False)
    n = d.F.shape[0]
    P_next = check_spd(as_matrix(P_next, "P_next", rows=n, cols=n), "P_next", semidefinite=not definite)
    if definite:
        check_spd(d.Q, "Q")
    return P_next, d


def rlqr_step_block(P_next, F, G, EF, EG, Q, R, H, mu: float, alpha: float = DEFAULT_ALPHA):
    r"""One RLQR step by the paper's block system (Theorem 1, PAPER_NOTES reading).

    The reference implementation of the step that :func:`rlqr_step` computes
    in its penalty/KKT form: a dense ``(4n + 2m + l)``-square solve, for tests
    and small problems, not for batches.

    Parameters
    ----------
    P_next : (n, n) array_like
        ``P[k+1]``, symmetric positive definite.
    F : (n, n) array_like
        Nominal state matrix.
    G : (n, m) array_like
        Nominal input matrix.
    EF : (l, n) array_like
        State part of the uncertainty.
    EG : (l, m) array_like
        Input part of the uncertainty.
    Q : (n, n) array_like
        State weight, symmetric positive definite.
    R : (m, m) array_like
        Input weight, symmetric positive definite.
    H : (n, p) array_like
        Input matrix of the uncertainty (``H = 0``: none).
    mu : float
        Penalty in ``[1e-100, inf]``.
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||``.

    Returns
    -------
    L : (n, n) ndarray
        Closed loop of the step, ``x*[k+1] = L x*[k]``.
    K : (m, n) ndarray
        Gain, ``u[k] = K x[k]``.
    P : (n, n) ndarray
        ``P[k]``.

    Raises
    ------
    ValueError
        Arguments checked like :func:`robustctl.rlqr`'s (shapes, weights,
        ``mu``); ``P_next`` or ``Q`` not positive definite.

    See Also
    --------
    rlqr_step : the same step by the penalty/KKT form.

    Notes
    -----
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
    ``lambda -> 0`` limit). The system is the optimality condition of the
    regularised least-squares problem of the step [1]_ [2]_,

    .. math::

        \Xi \begin{bmatrix} \cdot \\ \cdot \\ \cdot \\ \cdot \\ L \\ K \end{bmatrix} = b,
        \qquad P = b^T \Xi^{-1} b .

    References
    ----------
    .. [1] J. P. Cerri, M. H. Terra, J. Y. Ishihara, "Recursive robust
       regulator for discrete-time state-space systems", American Control
       Conference 2009, 3077-3082.
    .. [2] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Theorem 1.

    Examples
    --------
    With no uncertainty and a large ``mu`` the step is one step of the LQR
    Riccati recursion, written out here:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> F, G = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    >>> Q, R, P_next = np.eye(2), np.eye(1), np.diag([2.0, 3.0])
    >>> L, K, P = rc.rlqr_step_block(P_next, F, G, [[0.0, 0.0]], [[0.0]], Q, R, [[0.0], [0.0]], 1e12)
    >>> K_lqr = -np.linalg.solve(R + G.T @ P_next @ G, G.T @ P_next @ F)
    >>> bool(np.allclose(K, K_lqr) and np.allclose(P, Q + F.T @ P_next @ (F + G @ K_lqr)))
    True
    >>> bool(np.allclose(L, F + G @ K_lqr))
    True
    """
    P_next, d = _checked(P_next, F, G, EF, EG, Q, R, H, mu, alpha, definite=True)
    P, K, L = block_step(P_next, d.F, d.G, d.EF[0], d.EG[0], d.Q, d.R, d.H, float(d.mu[0]), d.alpha)
    return L, K, P


def rlqr_step(P_next, F, G, EF, EG, Q, R, H, mu: float, alpha: float = DEFAULT_ALPHA):
    r"""One RLQR step ``P[k+1] -> (L[k], K[k], P[k])`` by the penalty/KKT form.

    The step that :func:`robustctl.rlqr` iterates to its steady state (the
    docstring of the module ``robustctl.synthesis.rlqr`` gives the derivation).

    Parameters
    ----------
    P_next : (n, n) array_like
        ``P[k+1]``, symmetric positive semidefinite.
    F : (n, n) array_like
        Nominal state matrix.
    G : (n, m) array_like
        Nominal input matrix.
    EF : (l, n) array_like
        State part of the uncertainty.
    EG : (l, m) array_like
        Input part of the uncertainty.
    Q : (n, n) array_like
        State weight, symmetric positive semidefinite.
    R : (m, m) array_like
        Input weight, symmetric positive definite.
    H : (n, p) array_like
        Input matrix of the uncertainty (``H = 0``: none).
    mu : float
        Penalty in ``[1e-100, inf]``.
    alpha : float
        ``lambda = (1 + alpha) ||mu H'H||``.

    Returns
    -------
    L : (n, n) ndarray
        Closed loop of the step.
    K : (m, n) ndarray
        Gain, ``u[k] = K x[k]``.
    P : (n, n) ndarray
        ``P[k]``.

    Raises
    ------
    ValueError
        Arguments checked like :func:`robustctl.rlqr`'s.

    See Also
    --------
    rlqr_step_block : the paper's block system (the reference).

    Notes
    -----
    With ``S = mu^-1 I - lambda^-1 H H'`` and ``P~ = (P^-1 + S)^-1``
    (computed as ``(I + P S)^-1 P``) [1]_:

    .. math::

        \begin{bmatrix} R + G^T\tilde P G & E_G^T \\ E_G & -\lambda^{-1} I \end{bmatrix}
        \begin{bmatrix} K \\ \nu \end{bmatrix} =
        -\begin{bmatrix} G^T\tilde P F \\ E_F \end{bmatrix}, \qquad
        L = (I + S P)^{-1} (F + G K),

        P_k = Q + K^T R K + (F + G K)^T \tilde P (F + G K) + \lambda^{-1} \nu^T \nu .

    References
    ----------
    .. [1] M. H. Terra, J. P. Cerri, J. Y. Ishihara, "Optimal robust linear
       quadratic regulator for systems subject to uncertainties", IEEE Trans.
       Automatic Control 59(9), 2586-2591, 2014.

    Examples
    --------
    The penalty/KKT form and the paper's block system give the same step:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> F, G = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    >>> args = (F, G, [[0.1, 0.0]], [[0.3]], np.eye(2), np.eye(1), [[0.0], [0.1]], 1e4)
    >>> L, K, P = rc.rlqr_step(np.eye(2), *args)
    >>> L_ref, K_ref, P_ref = rc.rlqr_step_block(np.eye(2), *args)
    >>> bool(np.allclose(K, K_ref) and np.allclose(P, P_ref) and np.allclose(L, L_ref))
    True
    """
    P_next, d = _checked(P_next, F, G, EF, EG, Q, R, H, mu, alpha, definite=False)
    P, K, L = kkt_step(P_next[None], d)
    return L[0], K[0], P[0]
