r"""Output-feedback H-infinity by the two Riccati equations (Glover & Doyle 1988), on plain arrays.

Continuous time, one channel, ``D22 = 0``, *regular*: ``D12`` of full
column rank and ``D21`` of full row rank. :func:`normalise` makes
``D12 = [0; I]`` and ``D21 = [0 I]`` (orthogonal changes of ``z`` and ``w``,
invertible ones of ``u`` and ``y``: the level is unchanged), and partitions
``D11 = [D1111 D1112; D1121 D1122]`` (rows ``nz - m, m``, columns
``nw - p, p``). At a level ``gamma``, with ``B = [B1 B2]``,
``D1. = [D11 D12]``, ``C = [C1; C2]``, ``D.1 = [D11; D21]``,
``R = D1.'D1. - diag(gamma^2 I, 0)`` and ``Rt = D.1 D.1' - diag(gamma^2 I, 0)``,
``X`` is the stabilising solution of
``A'X + XA + C1'C1 - (XB + C1'D1.) R^-1 (B'X + D1.'C1) = 0`` and ``Y`` that of
the dual equation (``A -> A'``, ``B -> C'``, ``C1 -> B1'``, ``D1. -> D.1'``).
A controller with ``||T_zw||_inf < gamma`` exists iff (Zhou, Doyle & Glover
1996, Thm 17.1; Glover & Doyle 1988)

1. ``gamma > max(sigma_max[D1111 D1112], sigma_max[D1111' D1121'])``;
2. ``X`` exists (the Hamiltonian has no imaginary-axis eigenvalue and its
   stable subspace a graph) and ``X >= 0``;
3. the same for ``Y``;
4. ``rho(X Y) < gamma^2``.

The central controller (ibid.) with ``F = -R^-1 (D1.'C1 + B'X) = [F11; F12; F2]``
(rows ``nw - p, p, m``), ``L = -(B1 D.1' + Y C') Rt^-1 = [L11 L12 L2]``
(columns ``nz - m, m, p``) and ``Z = (I - Y X / gamma^2)^-1``::

    Dh11 = -D1121 D1111' (gamma^2 I - D1111 D1111')^-1 D1112 - D1122
    Dh12 Dh12' = I - D1121 (gamma^2 I - D1111' D1111)^-1 D1121'   (Cholesky)
    Dh21' Dh21 = I - D1112' (gamma^2 I - D1111 D1111')^-1 D1112
    Bh2 = Z (B2 + L12) Dh12,          Ch2 = -Dh21 (C2 + F12)
    Bh1 = -Z L2 + Bh2 Dh12^-1 Dh11,   Ch1 = F2 + Dh11 Dh21^-1 Ch2
    Ak = A + B F + Bh1 Dh21^-1 Ch2,   K = (Ak, Bh1, Ch1, Dh11)   (u = K y)

Discrete time goes through the bilinear (Tustin) transform
``s = (z - 1) / (z + 1)``, which maps the unit disk onto the left half-plane,
preserves the H-infinity norm of every system and commutes with the
interconnection: the discrete problem and its continuous image have the
same optimal level, and a continuous controller maps back to a discrete one
with the same closed-loop norm (the image has a ``D11`` and a ``D22`` even
when the discrete plant has none: both are handled).

:func:`bisect_level` is the gamma-iteration (bisection until both Riccati
solutions exist, then Brent's method on the coupling margin);
:func:`central_controller` the controller at a level above the optimum;
:func:`regular_controller` that controller in the caller's ``u``, ``y``
and ``D22`` (through the Tustin image for a discrete plant).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from .generalised import Channel, DynamicGain, Generalised, loop_shift

__all__ = ["Normalised", "normalise", "is_regular", "level_riccati", "bisect_level", "central_controller",
           "bilinear", "tustin", "tustin_controller_back", "regular_controller", "RANK_TOL"]

#: ``D12`` (``D21``) counts as rank-deficient when its smallest singular value is below
#: ``RANK_TOL`` times the norm of the channel (unit-sized in the solver's coordinates).
RANK_TOL = 1e-8
#: A Hamiltonian eigenvalue with ``|Re| <= AXIS_TOL * ||H||_1`` is on the imaginary axis.
AXIS_TOL = 1e-10
#: ``X = U2 U1^-1`` is accepted when ``max |X - X'| <= GRAPH_ASYM max(1, max |X|)`` (else ``U1`` is too ill
#: conditioned for the stable subspace to be taken as a graph).
GRAPH_ASYM = 1e-8
#: Relative tolerance of ``X >= 0`` and of the residual checks.
PSD_TOL = 1e-9


@dataclass(frozen=True, eq=False)
class Normalised:
    """The plant with ``D12 = [0; I]``, ``D21 = [0 I]`` and the maps back: ``u = Ru u~``, ``y~ = Ry y``."""

    plant: Generalised
    Ru: np.ndarray
    Ry: np.ndarray

    def back(self, K: DynamicGain) -> DynamicGain:
        """The controller of the original ``u`` and ``y``: ``Ru K Ry``."""
        Ak, Bk, Ck, Dk = K
        return DynamicGain(Ak, Bk @ self.Ry, self.Ru @ Ck, self.Ru @ Dk @ self.Ry)


def _range_last(M: np.ndarray, rows: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SVD of ``M`` as ``(U, s, R)``: an orthogonal ``U`` whose last columns span the range (``rows``: of ``M'``)."""
    if rows:
        U, s, Vt = np.linalg.svd(M.T)
    else:
        U, s, Vt = np.linalg.svd(M)
    r = s.size
    U = np.hstack([U[:, r:], U[:, :r]])
    return U, s, (s[:, None] * Vt)


def is_regular(c: Channel) -> bool:
    """``D12`` of full column rank and ``D21`` of full row rank (relative ``RANK_TOL``)."""
    size = max(float(np.linalg.norm(np.hstack([c.C1, c.D11, c.D12]), 2)),
               float(np.linalg.norm(np.vstack([c.B1, c.D21]), 2)), 1e-300)
    m, p = c.D12.shape[1], c.D21.shape[0]
    if c.D12.shape[0] < m or c.D21.shape[1] < p:
        return False
    s12 = np.linalg.svd(c.D12, compute_uv=False)
    s21 = np.linalg.svd(c.D21, compute_uv=False)
    return bool((m == 0 or s12[-1] > RANK_TOL * size) and (p == 0 or s21[-1] > RANK_TOL * size))


def normalise(plant: Generalised) -> Normalised:
    """The normalised plant (module docstring) of a regular one-channel plant."""
    c = plant.channels[0]
    U, _, R12 = _range_last(c.D12, rows=False)        # U' D12 = [0; R12]
    V, _, R21t = _range_last(c.D21, rows=True)        # D21 V = [0, R21]
    R21 = R21t.T
    Ru, Ry = np.linalg.inv(R12), np.linalg.inv(R21)
    m, p = plant.m, plant.p
    nz, nw = c.nz, c.nw
    D12 = np.vstack([np.zeros((nz - m, m)), np.eye(m)])
    D21 = np.hstack([np.zeros((p, nw - p)), np.eye(p)])
    chan = Channel(c.B1 @ V, U.T @ c.C1, U.T @ c.D11 @ V, D12, D21)
    return Normalised(Generalised(plant.A, plant.B2 @ Ru, Ry @ plant.C2, (chan,), plant.discrete), Ru, Ry)


def _d11_bound(c: Channel, m: int, p: int) -> float:
    """Condition 1: ``max(sigma_max[D1111 D1112], sigma_max[D1111' D1121'])`` (0 for empty blocks)."""
    nz, nw = c.nz, c.nw
    top, left = c.D11[:nz - m, :], c.D11[:, :nw - p]
    return max([float(np.linalg.norm(M, 2)) for M in (top, left) if M.size] + [0.0])


def _stable_graph(H: np.ndarray) -> np.ndarray | None:
    """``X = U2 U1^-1`` of the stable invariant subspace of the Hamiltonian ``H``, or ``None``.

    Refused: an eigenvalue within ``AXIS_TOL ||H||_1`` of the imaginary axis,
    a stable subspace of the wrong dimension, or ``U1`` so ill conditioned
    that ``X`` is not symmetric to ``GRAPH_ASYM`` (the solution of a
    Hamiltonian's stable subspace is symmetric).
    """
    n = H.shape[0] // 2
    scale = max(1.0, float(np.abs(H).sum(axis=0).max()))
    try:
        T, U, sdim = scipy.linalg.schur(H, output="real", sort="lhp")
    except (np.linalg.LinAlgError, ValueError):  # eigenvalues too close to the axis to be ordered
        return None
    if sdim != n or np.min(np.abs(np.diag(T))) <= AXIS_TOL * scale:   # real parts (standardised Schur form)
        return None
    try:
        X = np.linalg.solve(U[:n, :n].T, U[n:, :n].T).T
    except np.linalg.LinAlgError:
        return None
    size = float(np.abs(X).max()) if np.all(np.isfinite(X)) else np.inf
    if not size < np.inf or float(np.abs(X - X.T).max()) > GRAPH_ASYM * max(1.0, size):
        return None
    return 0.5 * (X + X.T)


class _Game:
    """One of the two Riccati equations at any level: ``A'X + XA + Q - (XB + S) R^-1 (B'X + S') = 0``.

    ``R = DD - gamma^2 diag(I_k, 0)``; the constant matrices are formed once.
    """

    def __init__(self, A, B, C1, D1, k: int):
        self.A, self.B, self.k = A, B, k
        self.Q, self.S, self.DD = C1.T @ C1, C1.T @ D1, D1.T @ D1

    def solve(self, gamma: float) -> np.ndarray | None:
        """The stabilising solution ``X >= 0`` at ``gamma``, or ``None``."""
        R = self.DD.copy()
        R[:self.k, :self.k] -= gamma**2 * np.eye(self.k)
        try:
            Ri = np.linalg.inv(R)
        except np.linalg.LinAlgError:
            return None
        BRi = self.B @ Ri
        Af = self.A - BRi @ self.S.T
        H = np.block([[Af, -BRi @ self.B.T], [self.S @ Ri @ self.S.T - self.Q, -Af.T]])
        X = _stable_graph(H)
        if X is None or np.linalg.eigvalsh(X)[0] < -PSD_TOL * max(1.0, float(np.abs(X).max())):
            return None
        return X


class Levels:
    """The four conditions of the module docstring at any level, for one normalised plant."""

    def __init__(self, norm: Normalised):
        g = norm.plant
        c = g.channels[0]
        self.d11 = _d11_bound(c, g.m, g.p)
        self.x = _Game(g.A, np.hstack([c.B1, g.B2]), c.C1, np.hstack([c.D11, c.D12]), c.nw)
        self.y = _Game(g.A.T, np.vstack([c.C1, g.C2]).T, c.B1.T, np.vstack([c.D11, c.D21]).T, c.nz)

    def at(self, gamma: float):
        """``(X, Y, margin)``, ``margin = 1 - rho(X Y) / gamma^2`` (feasible iff > 0); ``None`` if 1-3 fail."""
        if gamma <= self.d11:
            return None
        X = self.x.solve(gamma)
        Y = None if X is None else self.y.solve(gamma)
        if X is None or Y is None:
            return None
        return X, Y, 1.0 - float(np.max(np.abs(np.linalg.eigvals(X @ Y)))) / gamma**2


def level_riccati(norm: Normalised, gamma: float):
    """``(X, Y)`` if the four conditions hold at ``gamma`` (normalised plant), else ``None``."""
    sol = Levels(norm).at(gamma)
    return None if sol is None or not sol[2] > 0 else sol[:2]


def bisect_level(norm: Normalised, *, rtol: float, gamma_max: float) -> tuple[float, float, int]:
    """``(gamma_high, gamma_low, iterations)``: the smallest feasible level to ``rtol``.

    The bracket starts at ``[d11, max(1, 2 d11)]`` (``d11`` condition 1's
    bound; unit-sized channels) and its upper end is doubled until
    feasible; geometric bisection then shrinks it until both Riccati
    solutions exist at its lower end. From there the coupling margin
    ``1 - rho(X Y) / gamma^2`` is defined and continuous on the bracket (the
    solutions exist at every higher level), increases with ``gamma`` and is
    negative at the lower end: its zero, the optimum, is found by Brent's
    method on ``log gamma`` (``scipy.optimize.brentq``), which keeps a
    bracket and converges superlinearly where the bisection would take ~30
    steps. ``(inf, ., .)`` if no level up to ``gamma_max`` is feasible.
    """
    levels = Levels(norm)
    lo, f_lo = levels.d11, None
    hi = max(1.0, 2.0 * lo)
    its = 0
    while True:
        its += 1
        sol = levels.at(hi)
        if sol is not None and sol[2] > 0:
            f_hi = sol[2]
            break
        lo, f_lo, hi = hi, None if sol is None else sol[2], 2.0 * hi
        if hi > gamma_max:
            return float("inf"), lo, its
    while hi - lo > rtol * hi and f_lo is None:
        mid = float(np.sqrt(lo * hi)) if lo > 0 else 0.5 * hi
        its += 1
        sol = levels.at(mid)
        if sol is not None and sol[2] > 0:
            hi, f_hi = mid, sol[2]
        else:
            lo, f_lo = mid, None if sol is None else sol[2]
    if hi - lo > rtol * hi:
        bracket, known = [lo, hi], {np.log(lo): f_lo, np.log(hi): f_hi}

        def margin(t: float) -> float:
            nonlocal its
            if t in known:                              # brentq starts with the ends, already evaluated
                return known[t]
            its += 1
            g = float(np.exp(t))
            found = levels.at(g)
            f = -1.0 if found is None else found[2]     # a failure inside the bracket would be infeasible
            bracket[int(f > 0)] = min(bracket[1], g) if f > 0 else max(bracket[0], g)
            return f

        scipy.optimize.brentq(margin, np.log(lo), np.log(hi), xtol=0.25 * rtol, rtol=4 * np.finfo(float).eps)
        lo, hi = bracket
        while hi - lo > rtol * hi:             # brentq's last points may straddle the root unevenly
            mid = float(np.sqrt(lo * hi))
            its += 1
            sol = levels.at(mid)
            if sol is not None and sol[2] > 0:
                hi = mid
            else:
                lo = mid
    return float(hi), float(lo), its


def central_controller(norm: Normalised, gamma: float) -> DynamicGain | None:
    """The central controller at ``gamma`` (module docstring), for the normalised plant; ``None`` if infeasible."""
    sol = level_riccati(norm, gamma)
    if sol is None:
        return None
    X, Y = sol
    g = norm.plant
    c = g.channels[0]
    n, m, p, nw, nz = g.n, g.m, g.p, c.nw, c.nz
    A, B1, B2, C1, C2 = g.A, c.B1, g.B2, c.C1, g.C2
    g2 = gamma**2
    D1111, D1112 = c.D11[:nz - m, :nw - p], c.D11[:nz - m, nw - p:]
    D1121, D1122 = c.D11[nz - m:, :nw - p], c.D11[nz - m:, nw - p:]
    D1, Dd = np.hstack([c.D11, c.D12]), np.vstack([c.D11, c.D21])
    R = D1.T @ D1
    R[:nw, :nw] -= g2 * np.eye(nw)
    Rt = Dd @ Dd.T
    Rt[:nz, :nz] -= g2 * np.eye(nz)
    B, C = np.hstack([B1, B2]), np.vstack([C1, C2])
    F = -np.linalg.solve(R, D1.T @ C1 + B.T @ X)
    L = -np.linalg.solve(Rt.T, (B1 @ Dd.T + Y @ C.T).T).T
    F12, F2 = F[nw - p:nw], F[nw:]
    L12, L2 = L[:, nz - m:nz], L[:, nz:]
    Wl = g2 * np.eye(nz - m) - D1111 @ D1111.T
    Wr = g2 * np.eye(nw - p) - D1111.T @ D1111
    Dh11 = -D1121 @ D1111.T @ np.linalg.solve(Wl, D1112) - D1122
    try:
        Dh12 = np.linalg.cholesky(np.eye(m) - D1121 @ np.linalg.solve(Wr, D1121.T))
        Dh21 = np.linalg.cholesky(np.eye(p) - D1112.T @ np.linalg.solve(Wl, D1112)).T
        Z = np.linalg.inv(np.eye(n) - Y @ X / g2)
    except np.linalg.LinAlgError:
        return None
    Bh2 = Z @ (B2 + L12) @ Dh12
    Ch2 = -Dh21 @ (C2 + F12)
    Bh1 = -Z @ L2 + Bh2 @ np.linalg.solve(Dh12, Dh11)
    Ch1 = F2 + Dh11 @ np.linalg.solve(Dh21, Ch2)
    Ak = A + B @ F + Bh1 @ np.linalg.solve(Dh21, Ch2)
    K = DynamicGain(Ak, Bh1, Ch1, Dh11)
    return K if K.is_finite() else None


def bilinear(A, B, C, D) -> tuple[np.ndarray, ...] | None:
    """The continuous image of a discrete ``(A, B, C, D)`` under ``s = (z - 1) / (z + 1)``, or ``None``.

    With ``E = (I + A)^-1``: ``(E (A - I), sqrt(2) E B, sqrt(2) C E, D - C E B)``,
    the same transfer function at ``z = (1 + s) / (1 - s)`` (the unit circle
    onto the imaginary axis: every H-infinity norm is kept). ``None`` if
    ``A`` has an eigenvalue at ``-1`` (to rounding).
    """
    n = A.shape[0]
    Ip = np.eye(n) + A
    if np.linalg.cond(Ip) > 1e12:
        return None
    E = np.linalg.inv(Ip)
    return E @ (A - np.eye(n)), np.sqrt(2.0) * E @ B, np.sqrt(2.0) * C @ E, D - C @ E @ B


def tustin(plant: Generalised, D22: np.ndarray) -> tuple[Generalised, np.ndarray] | None:
    """The continuous image (:func:`bilinear`) of a discrete plant: ``(plant, D22)``; ``None`` as there."""
    c = plant.channels[0]
    image = bilinear(plant.A, np.hstack([c.B1, plant.B2]), np.vstack([c.C1, plant.C2]),
                     np.block([[c.D11, c.D12], [c.D21, D22]]))
    if image is None:
        return None
    Ac, Bc, Cc, Dc = image
    nw, nz = c.nw, c.nz
    chan = Channel(Bc[:, :nw], Cc[:nz], Dc[:nz, :nw], Dc[:nz, nw:], Dc[nz:, :nw])
    return Generalised(Ac, Bc[:, nw:], Cc[nz:], (chan,), False), Dc[nz:, nw:]


def tustin_controller_back(K: DynamicGain) -> DynamicGain | None:
    """The discrete controller whose Tustin image is ``K``; ``None`` if ``Ak`` has an eigenvalue at 1.

    With ``E = (I - Ak)^-1``: ``(E (I + Ak), sqrt(2) E Bk, sqrt(2) Ck E, Dk + Ck E Bk)``.
    """
    Ak, Bk, Ck, Dk = K
    n = Ak.shape[0]
    Im = np.eye(n) - Ak
    if np.linalg.cond(Im) > 1e12:
        return None
    E = np.linalg.inv(Im)
    return DynamicGain(E @ (np.eye(n) + Ak), np.sqrt(2.0) * E @ Bk, np.sqrt(2.0) * Ck @ E, Dk + Ck @ E @ Bk)


def regular_controller(plant: Generalised, D22: np.ndarray, gamma: float) -> DynamicGain | None:
    """The central controller of a regular plant (``D22`` included, discrete through Tustin) at ``gamma``."""
    if plant.discrete:
        image = tustin(plant, D22)
        if image is None:
            return None
        K = regular_controller(*image, gamma)
        return None if K is None else tustin_controller_back(K)
    norm = normalise(plant)
    K = central_controller(norm, gamma)
    return None if K is None else loop_shift(norm.back(K), D22)

