"""Stage 2 of the synthesis: the state coordinates in which the LMIs are posed.

Every change here is a similarity ``x = T x^`` or a recorded scaling of
``w`` and ``z``: levels and input bounds are unchanged up to the recorded
factors, only the solver's path (iterations, accuracy) changes.

* :func:`channel_scales`: the units of ``w`` and ``z``. The level is
  homogeneous, ``gamma(a z, b w) = a b gamma(z, w)``, and the optimal gain
  does not depend on ``a, b``; scaling both channels to a unit size first
  makes every later stage see the same data whatever units the user chose
  (the authors' truck weights ``R = 33535`` put ``gamma^2 ~ 1e8`` beside
  ``X ~ 1`` and Clarabel failed).
* :func:`normalised`: ``w`` and ``z`` scaled, then the states balanced by a
  diagonal similarity (SLICOT ``TB01ID`` on ``[[F, [Bw~ G]], [Cz~, 0]]``)
  and scaled so that ``||Bw~|| = 1``; ``[Cz~ Dzu~ Dzw~]`` replaced by a
  factor with the same Gram matrix when that has fewer rows.
* :func:`lqr_coordinates`: coordinates in which the inverse of the LQR
  Riccati solution of the nominal vertex is ~ I.
* :func:`recentred`: coordinates in which a given Lyapunov matrix is ~ I;
* :func:`lifted`: the eigenvalue floor that both of the last two, and the
  gain of the projected blocks, put under a matrix before factoring it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg

from . import tolerances as tol

__all__ = ["Coordinates", "channel_scales", "normalised", "lqr_coordinates", "recentred", "lifted"]


@dataclass(frozen=True, eq=False)
class Coordinates:
    """The synthesis data in the solver's state coordinates ``x = T x^``.

    ``F``, ``G`` hold one matrix per vertex. ``Bw`` and ``Dzw`` include the
    disturbance scaling ``w = w_scale w~``, and ``Cz``, ``Dzu``, ``Dzw`` the
    output scaling ``z = z_unit z~``: a level ``gamma`` of the user's
    ``T_zw`` is ``level_scale gamma`` here. ``Cz``, ``Dzu``, ``Dzw`` may be
    the compressed factor (``p`` rows, see :func:`normalised`). ``H``,
    ``EF``, ``EG`` are the norm-bounded uncertainty ``[dF dG] = H Delta [EF
    EG]`` (``None`` without one). ``original`` is ``(F, G, Bw, Cz, H, EF)``
    at ``T = I`` (channels scaled); ``balancing`` the diagonal similarity of
    :func:`normalised` (reported in ``info["scaling"]``).
    """

    F: tuple[np.ndarray, ...]
    G: tuple[np.ndarray, ...]
    Bw: np.ndarray
    Cz: np.ndarray
    Dzu: np.ndarray
    Dzw: np.ndarray
    T: np.ndarray
    original: tuple
    w_scale: float
    balancing: np.ndarray
    H: np.ndarray | None = None
    EF: np.ndarray | None = None
    EG: np.ndarray | None = None
    z_unit: float = 1.0

    @property
    def level_scale(self) -> float:
        """``w_scale / z_unit``: a level of the user's ``T_zw`` times this is the level of these data."""
        return self.w_scale / self.z_unit

    @property
    def n(self) -> int:
        return self.T.shape[0]

    @property
    def m(self) -> int:
        return self.Dzu.shape[1]

    @property
    def p(self) -> int:
        return self.Cz.shape[0]

    def to(self, T: np.ndarray) -> Coordinates:
        """The same data in the coordinates ``x = T x^`` (``T`` relative to the original states)."""
        Fs, Gs, Bw, Cz, H, EF = self.original
        return replace(self, T=T, F=tuple(np.linalg.solve(T, F @ T) for F in Fs),
                       G=tuple(np.linalg.solve(T, G) for G in Gs), Bw=np.linalg.solve(T, Bw), Cz=Cz @ T,
                       H=None if H is None else np.linalg.solve(T, H), EF=None if EF is None else EF @ T)

    def from_original(self, X: np.ndarray) -> np.ndarray:
        """A Lyapunov matrix of the original states in these coordinates, ``T^-1 X T^-T``."""
        return np.linalg.solve(self.T, np.linalg.solve(self.T, X).T)

    def to_original(self, K: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A gain and a Lyapunov matrix of these coordinates in the original ones, ``(K T^-1, T X T')``."""
        return np.linalg.solve(self.T.T, K.T).T, self.T @ X @ self.T.T


def channel_scales(Bw: np.ndarray, Cz: np.ndarray, Dzu: np.ndarray, Dzw: np.ndarray,
                   w_energy: float | None = None) -> tuple[float, float]:
    """``(w_scale, z_unit)``: the units of ``w = w_scale w~`` and ``z = z_unit z~`` for :func:`normalised`.

    ``w_scale = sqrt(w_energy)`` with an input bound (``w~`` then has unit
    energy, and the set of disturbances ``Bw sqrt(w_energy) w~`` is what the
    later stages see), otherwise ``1 / ||Bw||_2`` (the energy is immaterial
    without a bound); ``z_unit = ||[Cz Dzu Dzw w_scale]||_2``. Both are 1 for
    a zero matrix. Scaling ``z`` by ``a`` scales ``z_unit`` by ``a``, and
    scaling ``w`` by ``b`` (``Bw``, ``Dzw`` by ``b`` and ``w_energy`` by
    ``1 / b^2``) scales ``w_scale`` by ``1 / b``: the scaled data, hence the
    solver's problem and the gain, do not change (up to rounding).
    """
    if w_energy is None:
        bw = float(np.linalg.norm(Bw, 2))
        w_scale = 1.0 / bw if bw > 0 else 1.0
    else:
        w_scale = float(np.sqrt(w_energy))
    size = float(np.linalg.norm(np.hstack([Cz, Dzu, Dzw * w_scale]), 2))
    z_unit = size if size > 0 else 1.0
    w_name, w_what = ("Bw", "1 / ||Bw||_2") if w_energy is None else ("w_energy", "sqrt(w_energy)")
    for name, value, what in ((w_name, w_scale, w_what), ("Cz, Dzu, Dzw", z_unit, "||[Cz Dzu Dzw]||_2")):
        if not tol.CHANNEL_RANGE[0] <= value <= tol.CHANNEL_RANGE[1]:
            raise ValueError(f"{name} is scaled out of range: {what} = {value:.3g}; the level and the Lyapunov "
                             f"matrix scale with its square, which float64 cannot hold (allowed "
                             f"{tol.CHANNEL_RANGE[0]:g} to {tol.CHANNEL_RANGE[1]:g}); rescale the channel")
    return w_scale, z_unit


def normalised(F: Sequence[np.ndarray], G: Sequence[np.ndarray], Bw: np.ndarray, Cz: np.ndarray,
               Dzu: np.ndarray, Dzw: np.ndarray, w_scale: float = 1.0, uncertainty=None, *,
               z_unit: float = 1.0) -> Coordinates:
    """Balanced, ``||Bw~|| = 1`` coordinates of the vertices ``(F[i], G[i])``, with ``z`` scaled and compressed.

    ``w = w_scale w~`` and ``z = z_unit z~`` (:func:`channel_scales`) are
    applied first, so that the balancing too sees the scaled channels.
    ``uncertainty`` (a :class:`~robustctl.NormBounded` or ``None``) is
    carried along (``H`` and ``EF`` change with the coordinates).

    Only ``z'z`` matters to every synthesis here, so ``[Cz Dzu Dzw]`` is
    replaced by ``R`` with ``R'R = [Cz Dzu Dzw]'[Cz Dzu Dzw]`` (full row
    rank, from the SVD) when ``R`` has fewer rows.
    """
    Fs, Gs = tuple(F), tuple(G)
    n, m = Cz.shape[1], Dzu.shape[1]
    Bw, Dzw = Bw * w_scale, Dzw * w_scale
    Cz, Dzu, Dzw = Cz / z_unit, Dzu / z_unit, Dzw / z_unit
    d = _balance(Fs[0], Bw, Gs[0], Cz)
    bw = np.linalg.norm(Bw / d[:, None], 2)
    if bw > 0 and np.isfinite(bw):
        d = d * bw
    CD = np.hstack([Cz, Dzu, Dzw])
    _, sv, Vt = np.linalg.svd(CD, full_matrices=False)
    r = int(np.sum(sv > tol.Z_RANK * (sv[0] if sv.size else 0.0)))
    if 0 < r < CD.shape[0]:
        CD = sv[:r, None] * Vt[:r]
        Cz, Dzu, Dzw = CD[:, :n], CD[:, n:n + m], CD[:, n + m:]
    H, EF, EG = (None, None, None) if uncertainty is None else (uncertainty.H, uncertainty.EF, uncertainty.EG)
    base = Coordinates(F=Fs, G=Gs, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, T=np.eye(n), original=(Fs, Gs, Bw, Cz, H, EF),
                       w_scale=float(w_scale), balancing=d, H=H, EF=EF, EG=EG, z_unit=float(z_unit))
    return base.to(np.diag(d))


def _balance(F, Bw, G, Cz) -> np.ndarray:
    """Diagonal state scaling ``d`` (x = diag(d) x~) balancing ``[[F, [Bw G]], [Cz, 0]]``; ones without slycot."""
    n = F.shape[0]
    B = np.hstack([Bw, G])
    try:
        from slycot import tb01id

        _, _, _, _, d = tb01id(n, B.shape[1], Cz.shape[0], 0.0, F.copy(), B.copy(), Cz.copy(), job="A")
        d = np.asarray(d, dtype=float)
    except (ImportError, RuntimeError, ValueError, ArithmeticError):  # slycot missing or failed: no scaling
        return np.ones(n)
    if d.shape != (n,) or not np.all(np.isfinite(d)) or np.any(d <= 0):
        return np.ones(n)
    # TB01ID returns D with A~ = D^-1 A D, i.e. x = D x~.
    return d


def lqr_coordinates(data: Coordinates, discrete: bool) -> Coordinates | None:
    """Coordinates in which the LQR storage of the nominal vertex is ~ I, or ``None``.

    The optimal Lyapunov matrix ``X`` has roughly the shape of ``P^-1``,
    ``P`` the stabilising Riccati solution of the LQR problem with the
    weight ``[Cz Dzu]'[Cz Dzu]`` (both diagonal blocks regularised by
    ``LQR_REG`` of their norm; ``P`` lifted to at least ``LQR_SHIFT`` of its
    largest eigenvalue). In coordinates where ``P^-1 ~ I`` (then
    scaled so that ``||Bw|| = 1`` again) the optimum is usually well
    conditioned: fewer interior-point iterations, rarely
    ``optimal_inaccurate``. ``None`` if the Riccati solve fails.
    """
    F, G, C, D = data.F[0], data.G[0], data.Cz, data.Dzu
    n, m = data.n, data.m
    Q, R, S = C.T @ C, D.T @ D, C.T @ D
    Q = Q + tol.LQR_REG * max(1.0, float(np.linalg.norm(Q, 2))) * np.eye(n)
    R = R + tol.LQR_REG * max(1.0, float(np.linalg.norm(R, 2))) * np.eye(m)
    are = scipy.linalg.solve_discrete_are if discrete else scipy.linalg.solve_continuous_are
    try:
        with np.errstate(all="ignore"):
            P = lifted(are(F, G, Q, R, s=S), tol.LQR_SHIFT)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if P is None:
        return None
    moved = recentred(data, np.linalg.inv(P), tol.LQR_SHIFT)  # P^-1 > 0 by construction
    if moved is None:
        return None
    bw = float(np.linalg.norm(moved[0].Bw, 2))
    if not (bw > 0 and np.isfinite(bw)):  # no disturbance: nothing to normalise by
        return None
    return moved[0].to(moved[0].T * bw)


def recentred(data: Coordinates, X: np.ndarray, reg: float) -> tuple[Coordinates, float] | None:
    """Coordinates in which the Lyapunov matrix ``X`` (given in ``data``'s coordinates) becomes ~ I.

    With ``X + reg lambda_max(X) I = R R'`` (Cholesky; the shift only if
    needed to reach that floor) the new coordinates are ``x^ = R^-1 x~``:
    margins of the next solve are then measured relative to the shape of
    ``X``. Returns the new coordinates and ``lambda_max`` of ``X`` in them
    (<= 1), or ``None`` if ``X`` is unusable (not finite, or ``lambda_max <= 0``).
    """
    X_lifted = lifted(X, reg)
    if X_lifted is None:
        return None
    R = np.linalg.cholesky(X_lifted)
    X = 0.5 * (X + X.T)
    Xh = np.linalg.solve(R, np.linalg.solve(R, X).T)
    return data.to(data.T @ R), float(np.linalg.eigvalsh(0.5 * (Xh + Xh.T))[-1])


def lifted(M: np.ndarray, floor: float) -> np.ndarray | None:
    """``M`` symmetrised and shifted, ``M + s I``, so that its smallest eigenvalue is at least ``floor lambda_max(M)``.

    The shift ``s = max(0, floor lambda_max - lambda_min)`` is zero when ``M``
    already meets the floor. With ``0 < floor`` the result is positive
    definite (its Cholesky factor exists). ``None`` if ``M`` is not finite or
    ``lambda_max(M) <= 0`` (nothing to take the shape from).
    """
    M = 0.5 * (M + M.T)
    if not np.all(np.isfinite(M)):
        return None
    lam = np.linalg.eigvalsh(M)
    if not lam[-1] > 0:
        return None
    return M + max(0.0, floor * lam[-1] - lam[0]) * np.eye(M.shape[0])
