r"""One step of the filter recursion for a batch: the closed form, and the block (KKT) system it equals.

Notation: ``P`` is the a-priori covariance of ``x[k]`` (before ``y[k]``),
``Pf`` the filtered one (after ``y[k]``); ``e = y[k] - C xhat - D u[k]`` the
innovation. One step of the robust filter (Ishihara, Terra & Cerri 2015) is
the regularised least-squares problem, over ``z = (x[k-1], w[k-1], v[k],
x[k])``,

.. math::

    \min_z \|x_{k-1} - \hat x_{k-1|k-1}\|^2_{P_{k-1|k-1}^{-1}} + \|w\|^2_{W^{-1}} + \|v\|^2_{V^{-1}}
    + \|r\|^2_{\Phi^{-1}} + \lambda \|E z - e_b\|^2,

``r`` the residuals of the dynamics and the measurement equations, ``Phi =
blkdiag(Phi1, Phi2)``, ``E z - e_b = (EF x[k-1] + EBw w[k-1] + EG u[k-1], EC
x[k])``: Sayed's (2001) solution of the min-max problem for ``lambda >
mu ||blkdiag(H'H, HC'HC)||``. :func:`block_step` solves it as one KKT system
(:func:`robustctl._kkt.weighted_lsq`), the reference. Its solution is the
conditional mean of a linear Gaussian model in which the uncertainty rows are
pseudo-measurements with noise ``lambda^-1 I``, so it splits into three
updates, each a Kalman update (the closed form, :func:`measurement`,
:func:`prediction`, :func:`constraint`):

1. measurement: ``Re = C P C' + R``, ``Lf = P C' Re^-1``, ``Pf = P - Lf Re Lf'``;
2. prediction, jointly in ``(x[k], w[k])`` with the pseudo-measurement ``EF x + EBw w``
   (covariance ``blkdiag(Pf, W)``): ``SE = EF Pf EF' + EBw W EBw' + lambda^-1 I``,
   ``J = (F Pf EF' + Bw W EBw') SE^-1``, ``Fe = F - J EF``, ``Ge = G - J EG``,
   ``P+ = F Pf F' + Q - J SE J'`` (Kalman filter with ``N``: ``- F Lf S' - S Lf' F'
   - S Re^-1 S'``, ``Je = S Re^-1``);
3. the output pseudo-measurement ``EC x[k+1]``: ``SC = EC P+ EC' + lambda^-1 I``,
   ``KE = P+ EC' SC^-1``, ``P+ <- P+ - KE SC KE'``.

The estimates follow: ``xf = xhat + Lf e``, ``xhat+ = (I - KE EC)(Fe xf + Ge u + Je e)``.
Every term is a covariance or a gain: nothing grows with ``mu`` or
``lambda``, so the step is accurate for every ``mu`` and exact at ``mu = inf``
(the pseudo-measurements become exact constraints; ``SE`` and ``SC`` must then
be invertible). No inverse of ``P``, ``W`` or ``V`` is needed.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from .._kkt import solve, sym, weighted_lsq
from ._model import FilterModel


def _T(a: np.ndarray) -> np.ndarray:
    return a.swapaxes(-1, -2)


def measurement(P: np.ndarray, d: FilterModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Pf, Lf, Re)`` from the a-priori ``P`` (B, n, n)."""
    CP = d.C @ P
    Re = CP @ d.C.T + d.R
    Lf = _T(solve(Re, CP))
    return sym(P - Lf @ CP), Lf, Re                      # Lf Re Lf' = Lf C P


def prediction(Pf: np.ndarray, Lf: np.ndarray, Re: np.ndarray, d: FilterModel):
    """``(P+, Fe, Ge, Je)``: the a-priori covariance of the next state (before ``EC``) and the estimator's model."""
    FPf = d.F @ Pf
    P = FPf @ d.F.T + d.Q
    Je = np.zeros_like(Lf)
    if d.EF.shape[1]:
        SE = d.EF @ Pf @ _T(d.EF) + d.Y + d.ell[:, :, None] * np.eye(d.EF.shape[1])
        cross = FPf @ _T(d.EF) + d.X                                   # cov(x+, EF x + EBw w)
        J = _T(solve(SE, _T(cross)))
        Fe, Ge = d.F - J @ d.EF, d.G - J @ d.EG
        P = P - J @ _T(cross)                                          # J SE J' = J cross'
    else:
        Fe, Ge = np.repeat(d.F[None], P.shape[0], axis=0), np.repeat(d.G[None], P.shape[0], axis=0)
    if d.S is not None:
        Je = _T(solve(Re, _T(d.S)))
        cross = d.F @ Lf @ _T(d.S)
        P = P - cross - _T(cross) - Je @ Re @ _T(Je)
    return sym(P), Fe, Ge, Je


def constraint(P: np.ndarray, d: FilterModel) -> tuple[np.ndarray, np.ndarray]:
    """``(P, KE)`` after the output pseudo-measurement ``EC x`` (``KE`` (B, n, q2); unchanged without ``EC``)."""
    q2 = d.EC.shape[1]
    if not q2:
        return P, np.zeros((*P.shape[:2], 0))
    ECP = d.EC @ P
    SC = ECP @ _T(d.EC) + d.li[:, None, None] * np.eye(q2)
    KE = _T(solve(SC, ECP))
    return sym(P - KE @ ECP), KE                                       # KE SC KE' = KE EC P


class Gains(NamedTuple):
    """One step for a batch, from the a-priori ``P`` of ``x[k]`` (after ``EC``).

    ``Pf``, ``Lf``, ``Re``: filtered covariance, filter gain, innovation covariance;
    ``P_next`` the a-priori covariance of ``x[k+1]`` (after ``EC``), and the
    estimator's model ``xhat+ = Fe xf + Ge u + Je e`` (``EC`` folded in).
    """

    Pf: np.ndarray
    Lf: np.ndarray
    Re: np.ndarray
    P_next: np.ndarray
    Fe: np.ndarray
    Ge: np.ndarray
    Je: np.ndarray

    def closed_loop(self, C: np.ndarray) -> np.ndarray:
        """``A = Fe (I - Lf C) - Je C`` (B, n, n): the estimator's own dynamics, ``xhat+ = A xhat + ...``."""
        return self.Fe - (self.Fe @ self.Lf + self.Je) @ C


def step(P: np.ndarray, d: FilterModel) -> Gains:
    """One step of the closed form from the a-priori ``P`` (after ``EC``) of every design."""
    Pf, Lf, Re = measurement(P, d)
    P_pre, Fe, Ge, Je = prediction(Pf, Lf, Re, d)
    P_next, KE = constraint(P_pre, d)
    if KE.shape[2]:
        M = np.eye(P.shape[1]) - KE @ d.EC
        Fe, Ge, Je = M @ Fe, M @ Ge, M @ Je
    return Gains(Pf, Lf, Re, P_next, Fe, Ge, Je)


def block_step(x: np.ndarray, Pf: np.ndarray, u_prev: np.ndarray, u: np.ndarray, y: np.ndarray,
               d: FilterModel, *, measure: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The step as one KKT system (the reference), for the first design of ``d``.

    From the filtered ``x[k-1|k-1]`` (n,) and ``Pf = P[k-1|k-1]``, the inputs
    ``u[k-1]``, ``u[k]`` and ``y[k]``, returns ``(x[k|k], P[k|k])``; with
    ``measure=False`` the rows of ``y[k]`` are left out and it returns the
    a-priori ``(x[k|k-1], P[k|k-1])``. Needs a model built with the raw
    noise data (``d.W``, ``d.V``, ``d.Bw``, ``d.EBw``, ``d.Phi1``, ``d.Phi2``).
    """
    n, nw, p = d.F.shape[0], d.Bw.shape[1], d.C.shape[0] if measure else 0
    q, q2, li = d.EF.shape[1], d.EC.shape[1], float(d.li[0])
    N = n + nw + p + n
    zeros = np.zeros
    rows = [np.hstack([np.eye(n + nw + p), zeros((n + nw + p, n))]),      # the prior of (x[k-1], w, v)
            np.hstack([d.F, d.Bw, zeros((n, p)), -np.eye(n)])]             # the dynamics
    rhs = [np.concatenate([x, zeros(nw + p)]), -d.G @ u_prev]
    cov = [Pf, d.W[0]] + ([d.V[0]] if p else []) + [d.Phi1[0]]
    if p:                                                                   # the measurement
        rows.append(np.hstack([zeros((p, n + nw)), np.eye(p), d.C]))
        rhs.append(y - d.D @ u)
        cov.append(d.Phi2[0])
    if q:                                                                   # uncertainty of the dynamics
        rows.append(np.hstack([d.EF[0], d.EBw[0], zeros((q, p + n))]))
        rhs.append(-d.EG[0] @ u_prev)
        cov.append(np.diag(d.ell[0]))
    if q2:                                                                  # uncertainty of the output
        rows.append(np.hstack([zeros((q2, n + nw + p)), d.EC[0]]))
        rhs.append(zeros(q2))
        cov.append(li * np.eye(q2))
    z, Pi = weighted_lsq(scipy.linalg.block_diag(*cov)[None], np.vstack(rows)[None],
                         np.concatenate(rhs)[None, :, None])
    return z[0, N - n:, 0], Pi[0, N - n:, N - n:]
