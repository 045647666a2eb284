"""The batched data of a filter recursion: the Kalman filter and the robust filter in one form.

Both filters run the same recursion (:mod:`robustctl.estimation._recursion`)
on a :class:`FilterModel`; the Kalman filter is the robust filter without
uncertainty rows and with ``mu = inf``, plus an optional cross-covariance
``N`` between the process and the measurement noise. What the robust filter
adds (Ishihara, Terra & Cerri 2015; Sayed 2001, the estimation dual of the
RLQR) is, with ``lambda = (1 + alpha) mu max(||H'H||, ||HC'HC||)``:

* extra process noise ``Phi1 = mu^-1 I - lambda^-1 H H'`` and measurement noise
  ``Phi2 = mu^-1 I - lambda^-1 HC HC'`` (both zero at ``mu = inf``, positive
  semidefinite for ``alpha > 0``);
* a pseudo-measurement ``0 = EF x[k] + EG u[k] + EBw w[k] + eta`` of the state
  and the process noise of each step, with ``cov(eta) = lambda^-1 I``;
* a pseudo-measurement ``0 = EC x[k] + eta'`` of the state, ``cov(eta') = lambda^-1 I``.

A zero ``H`` (``HC``) means no uncertainty in the dynamics (the output): the
pseudo-measurement of that block carries no information and is dropped (as
the RLQR drops ``EF``, ``EG`` when ``H = 0``); without any uncertainty the
``lambda -> 0`` limit leaves ``Phi1 = Phi2 = mu^-1 I``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: A row of ``[EF, EBw W^1/2]`` (``EC``) carries information when its singular value exceeds this times the largest.
RANK_TOL = 1e-12


@dataclass(frozen=True, eq=False)
class FilterModel:
    """Batched filter data: the plant shared, noise and uncertainty per design (leading axis ``B``).

    ``Q = Bw W Bw' + Phi1`` (process noise), ``R = V + Phi2`` (measurement
    noise), ``S = Bw N`` (cross-covariance, Kalman filter only), the
    pseudo-measurement rows ``EF``, ``EG`` with ``X = Bw W EBw'`` and ``Y =
    EBw W EBw'`` (their correlation with the process noise and their noise
    from ``w``), ``EC``, and ``li = 1 / lambda`` (0 at ``mu = inf``).
    """

    F: np.ndarray          # (n, n)
    G: np.ndarray          # (n, m)
    C: np.ndarray          # (p, n)
    D: np.ndarray          # (p, m)
    Q: np.ndarray          # (B, n, n)
    R: np.ndarray          # (B, p, p)
    S: np.ndarray | None   # (B, n, p)
    EF: np.ndarray         # (B, q, n)
    EG: np.ndarray         # (B, q, m)
    X: np.ndarray          # (B, n, q)
    Y: np.ndarray          # (B, q, q)
    EC: np.ndarray         # (B, q2, n)
    li: np.ndarray         # (B,)
    ell: np.ndarray        # (B, q): the EF rows' noise, li where the row is live, 1 where it carries no information
    # the raw noise and uncertainty data, for the block (KKT) form
    Bw: np.ndarray         # (n, nw)
    W: np.ndarray          # (B, nw, nw)
    V: np.ndarray          # (B, p, p)
    EBw: np.ndarray        # (B, q, nw)
    Phi1: np.ndarray       # (B, n, n)
    Phi2: np.ndarray       # (B, p, p)

    @property
    def size(self) -> int:
        return self.Q.shape[0]

    @property
    def uncertain(self) -> bool:
        """Some pseudo-measurement row (``EF`` or ``EC``) exists."""
        return self.EF.shape[1] + self.EC.shape[1] > 0

    def select(self, mask: np.ndarray) -> FilterModel:
        """The designs selected by ``mask`` (bool (B,) or indices)."""
        if mask.dtype == bool and mask.all():
            return self
        return FilterModel(self.F, self.G, self.C, self.D, self.Q[mask], self.R[mask],
                           None if self.S is None else self.S[mask], self.EF[mask], self.EG[mask],
                           self.X[mask], self.Y[mask], self.EC[mask], self.li[mask], self.ell[mask], self.Bw,
                           self.W[mask], self.V[mask], self.EBw[mask], self.Phi1[mask], self.Phi2[mask])


def _stack(a: np.ndarray, B: int) -> np.ndarray:
    return np.broadcast_to(a, (B, *a.shape[-2:]))


def kalman_model(F, G, C, D, Bw, W, V, N=None) -> FilterModel:
    """The Kalman filter's data: ``W`` (B, nw, nw), ``V`` (B, p, p), ``N`` (B, nw, p) or None."""
    B, n, m, p, nw = W.shape[0], F.shape[0], G.shape[1], C.shape[0], Bw.shape[1]
    Q = Bw @ W @ Bw.T
    S = None if N is None else Bw @ N
    return FilterModel(F, G, C, D, Q, V, S, np.zeros((B, 0, n)), np.zeros((B, 0, m)), np.zeros((B, n, 0)),
                       np.zeros((B, 0, 0)), np.zeros((B, 0, n)), np.zeros(B), np.zeros((B, 0)), Bw, W, V,
                       np.zeros((B, 0, nw)),
                       np.zeros((B, n, n)), np.zeros((B, p, p)))


def robust_model(F, G, C, D, Bw, W, V, *, H, EF, EG, EBw, HC, EC, mu, alpha: float) -> FilterModel:
    """The robust filter's data for ``B`` designs.

    ``W``, ``V`` are shared (nw, nw), (p, p); ``EF`` (B, q, n), ``EG`` (B, q,
    m), ``EBw`` (B, q, nw), ``EC`` (q2, n) and ``mu`` (B,) (``inf`` allowed);
    ``H`` (n, k), ``HC`` (p, k2) (``k2 = 0``: no output uncertainty).
    """
    B, n, p = mu.shape[0], F.shape[0], C.shape[0]
    hF = float(np.linalg.norm(H, 2)) ** 2 if H.size else 0.0
    hC = float(np.linalg.norm(HC, 2)) ** 2 if HC.size else 0.0
    if hF == 0.0:  # no uncertainty in the dynamics: its pseudo-measurement carries no information
        EF, EG, EBw = EF[:, :0], EG[:, :0], EBw[:, :0]
    if hC == 0.0:
        EC = EC[:0]
    h = max(hF, hC)
    with np.errstate(divide="ignore"):
        mu_inv = np.where(np.isinf(mu), 0.0, 1.0 / mu)
    if h == 0.0:  # no uncertainty at all: the lambda -> 0 limit, Phi = mu^-1 I
        li = np.ones(B)
        Phi1 = mu_inv[:, None, None] * np.eye(n)
        Phi2 = mu_inv[:, None, None] * np.eye(p)
    else:  # Phi = mu^-1 (I - H H' / ((1 + alpha) h)) >= 0
        li = mu_inv / ((1.0 + alpha) * h)
        Phi1 = mu_inv[:, None, None] * (np.eye(n) - H @ H.T / ((1.0 + alpha) * h))
        Phi2 = mu_inv[:, None, None] * (np.eye(p) - HC @ HC.T / ((1.0 + alpha) * h))
    Q = Bw @ W @ Bw.T + Phi1
    R = V + Phi2
    EF, EG, EBw, live = _compress(EF, EG, EBw, W)
    ell = np.where(live, li[:, None], 1.0)
    if EC.shape[0]:  # EC -> U' EC = S V', its rows without information dropped (as in _compress)
        _, s, Vt = np.linalg.svd(EC, full_matrices=False)
        keep = s > RANK_TOL * s[0]
        EC = s[keep, None] * Vt[keep]
    BwW = Bw @ W
    X = BwW @ EBw.swapaxes(1, 2)
    Y = EBw @ W @ EBw.swapaxes(1, 2)
    return FilterModel(F, G, C, D, Q, R, None, EF, EG, X, Y, np.broadcast_to(EC, (B, *EC.shape)), li, ell, Bw,
                       _stack(W, B), _stack(V, B), EBw, Phi1, Phi2)


def _compress(EF, EG, EBw, W):
    """The uncertainty rows rotated to the row space of ``[EF, EBw W^1/2]`` (B, q, .), rows outside it zeroed.

    ``[EF EG EBw] -> U' [EF EG EBw]`` with ``[EF, EBw W^1/2] = U S V'`` (an
    orthogonal ``U``: ``H Delta [EF EG EBw] = H (Delta U) (U' [EF EG EBw])``
    with ``Delta U`` a contraction as well, the same uncertain model and the
    same cost). A row with a zero singular value (relative ``RANK_TOL``) then
    says nothing about ``x`` and ``w``: it is zeroed (``EG`` included) and
    ``live`` is False, so that at ``mu = inf`` no rank condition is needed.
    Returns ``(EF, EG, EBw, live)``.
    """
    B, q = EF.shape[:2]
    if q == 0:
        return EF, EG, EBw, np.zeros((B, 0), dtype=bool)
    w, Qw = np.linalg.eigh(W)
    root = Qw * np.sqrt(np.clip(w, 0.0, None))
    U, s, _ = np.linalg.svd(np.concatenate([EF, EBw @ root], axis=2))
    live = np.zeros((B, q), dtype=bool)
    live[:, :s.shape[1]] = s > RANK_TOL * np.maximum(s[:, :1], np.finfo(float).tiny)
    Ut = U.swapaxes(1, 2) * live[:, :, None]
    return Ut @ EF, Ut @ EG, Ut @ EBw, live
