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

:func:`bisect_level` is the gamma-iteration (geometric bisection on the four
conditions); :func:`central_controller` the controller at a level above it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .generalised import Channel, DynamicGain, Generalised, loop_shift

__all__ = ["Normalised", "normalise", "is_regular", "level_riccati", "bisect_level", "central_controller",
           "tustin", "tustin_controller_back", "regular_controller", "RANK_TOL"]

#: ``D12`` (``D21``) counts as rank-deficient when its smallest singular value is below
#: ``RANK_TOL`` times the norm of the channel (unit-sized in the solver's coordinates).
RANK_TOL = 1e-8
#: A Hamiltonian eigenvalue with ``|Re| <= AXIS_TOL * ||H||_1`` is on the imaginary axis.
AXIS_TOL = 1e-10
#: The stable subspace ``[U1; U2]`` is a graph when ``cond(U1)`` is below this.
GRAPH_COND = 1e12
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
    """``X = U2 U1^-1`` of the stable invariant subspace of the Hamiltonian ``H``, or ``None``."""
    n = H.shape[0] // 2
    scale = max(1.0, float(np.linalg.norm(H, 1)))
    try:
        T, U, sdim = scipy.linalg.schur(H, output="real", sort="lhp")
    except (np.linalg.LinAlgError, ValueError):  # eigenvalues too close to the axis to be ordered
        return None
    if sdim != n:
        return None
    if np.min(np.abs(np.diag(T))) <= AXIS_TOL * scale:   # the real parts (standardised real Schur form)
        return None
    U1, U2 = U[:n, :n], U[n:, :n]
    if np.linalg.cond(U1) > GRAPH_COND:
        return None
    X = np.linalg.solve(U1.T, U2.T).T
    return 0.5 * (X + X.T)


def _game(A, B, C1, D1, R) -> np.ndarray | None:
    """Stabilising ``X >= 0`` of ``A'X + XA + C1'C1 - (XB + C1'D1) R^-1 (B'X + D1'C1) = 0``, or ``None``."""
    try:
        Ri = np.linalg.inv(R)
    except np.linalg.LinAlgError:
        return None
    S = C1.T @ D1
    Af = A - B @ Ri @ S.T
    H = np.block([[Af, -B @ Ri @ B.T], [-(C1.T @ C1 - S @ Ri @ S.T), -Af.T]])
    X = _stable_graph(H)
    if X is None:
        return None
    if np.linalg.eigvalsh(X).min() < -PSD_TOL * max(1.0, float(np.abs(X).max())):
        return None
    return X


def level_riccati(norm: Normalised, gamma: float):
    """``(X, Y)`` if the four conditions hold at ``gamma`` (normalised plant), else ``None``."""
    g = norm.plant
    c = g.channels[0]
    if gamma <= _d11_bound(c, g.m, g.p):
        return None
    nw, nz = c.nw, c.nz
    D1 = np.hstack([c.D11, c.D12])
    R = D1.T @ D1
    R[:nw, :nw] -= gamma**2 * np.eye(nw)
    X = _game(g.A, np.hstack([c.B1, g.B2]), c.C1, D1, R)
    if X is None:
        return None
    Dd = np.vstack([c.D11, c.D21])
    Rt = Dd @ Dd.T
    Rt[:nz, :nz] -= gamma**2 * np.eye(nz)
    Y = _game(g.A.T, np.vstack([c.C1, g.C2]).T, c.B1.T, Dd.T, Rt)
    if Y is None:
        return None
    if np.max(np.abs(np.linalg.eigvals(X @ Y))) >= gamma**2:
        return None
    return X, Y


def bisect_level(norm: Normalised, *, rtol: float, gamma_max: float) -> tuple[float, float, int]:
    """``(gamma_high, gamma_low, iterations)``: the smallest feasible level to ``rtol`` (geometric bisection).

    The bracket starts at ``[d11, max(1, 2 d11)]`` (``d11`` condition 1's
    bound; unit-sized channels) and its upper end is doubled until
    feasible. ``(inf, ., .)`` if no level up to ``gamma_max`` is.
    """
    lo = _d11_bound(norm.plant.channels[0], norm.plant.m, norm.plant.p)
    hi = max(1.0, 2.0 * lo)
    its = 0
    while True:
        its += 1
        if level_riccati(norm, hi) is not None:
            break
        lo, hi = hi, 2.0 * hi
        if hi > gamma_max:
            return float("inf"), lo, its
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        its += 1
        if level_riccati(norm, mid) is None:
            lo = mid
        else:
            hi = mid
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


def tustin(plant: Generalised, D22: np.ndarray) -> tuple[Generalised, np.ndarray] | None:
    """The continuous image of a discrete plant under ``s = (z - 1) / (z + 1)``: ``(plant, D22)``.

    With ``E = (I + A)^-1``: ``A~ = E (A - I)``, ``B~ = sqrt(2) E B``,
    ``C~ = sqrt(2) C E``, ``D~ = D - C E B`` for the stacked inputs and
    outputs. ``None`` if ``A`` has an eigenvalue at ``-1`` (to rounding).
    """
    n = plant.n
    c = plant.channels[0]
    Ip = np.eye(n) + plant.A
    if np.linalg.cond(Ip) > 1e12:
        return None
    E = np.linalg.inv(Ip)
    B = np.hstack([c.B1, plant.B2])
    C = np.vstack([c.C1, plant.C2])
    D = np.block([[c.D11, c.D12], [c.D21, D22]])
    Ac, Bc, Cc, Dc = E @ (plant.A - np.eye(n)), np.sqrt(2.0) * E @ B, np.sqrt(2.0) * C @ E, D - C @ E @ B
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

