"""Reference H-infinity state feedback by bisection on the game Riccati equation.

This module is the *independent* reference that the LMI synthesis in
:func:`robustctl.hinf` is tested and benchmarked against. It shares no code
with it: no cvxpy, no LMI, only Riccati equations and eigenvalue problems.

Plant (discrete time, ``dt > 0``; continuous time when ``dt is None``)::

    x+ = F x + Bw w + G u,        z = Cz x + Dzw w + Dzu u,       u = K x.

For a level ``gamma`` the zero-sum game ``sum |z|^2 - gamma^2 |w|^2`` gives
the Riccati equation (``B = [G Bw]``, ``Q = Cz' Cz``, ``S = Cz' [Dzu Dzw]``)

* discrete:   ``P = F'PF + Q - (F'PB + S)(R + B'PB)^-1 (B'PF + S')``
* continuous: ``0 = F'P + PF + Q - (PB + S) R^-1 (B'P + S')``

with the indefinite ``R = [[Dzu'Dzu, Dzu'Dzw], [Dzw'Dzu, Dzw'Dzw - gamma^2 I]]``.
A static gain ``u = K x`` with ``||T_zw||_inf < gamma`` exists iff a
stabilising solution ``P >= 0`` exists and, in discrete time, the disturbance
block is concave, ``Dzw'Dzw + Bw' P Bw < gamma^2 I`` (the minimising player
does not see the current ``w``: this is the *state-feedback* condition, which
is stronger than the full-information one where ``u`` may depend on ``w``).
In continuous time the condition is ``Dzw'Dzw < gamma^2 I``. The gain is the
``u``-part of the saddle point, ``K = -[I 0] (R + B'PB)^-1 (B'PF + S')``
(continuous: ``-[I 0] R^-1 (B'P + S')``). The optimal level is found by
bisection on ``gamma``.

References
----------
T. Basar and P. Bernhard, *H-infinity Optimal Control and Related Minimax
Design Problems*, 2nd ed., Birkhaeuser 1995, Ch. 3 (discrete) and 4
(continuous). A. A. Stoorvogel, *The H-infinity Control Problem*, Prentice
Hall 1992. J. C. Doyle, K. Glover, P. P. Khargonekar, B. A. Francis,
"State-space solutions to standard H2 and H-infinity control problems",
IEEE TAC 34(8), 1989 (continuous-time Hamiltonian test).

Notes
-----
The discrete equation is solved by SLICOT's ``SG02AD`` (through slycot, the
optional ``robustctl[slycot]`` extra) when it is installed, by
``scipy.linalg.solve_discrete_are`` otherwise or when SG02AD fails; scipy's
Python-level QZ reordering made the bisection two to three times slower.
:func:`bisect_level` is the library's one bisection on this equation: the
``synthesis="riccati"`` path of :func:`robustctl.hinf` uses it too (the LMI
path does not, so the tests can still compare the two).
``scipy.linalg.solve_discrete_are`` may return a wrong matrix for an
indefinite ``R`` without raising; every solution is therefore accepted only
after its relative residual, symmetry, sign and the closed-loop spectrum are
checked (the closed loop of the saddle point must be stable with the margin
of :mod:`robustctl.systems.stability`, like every stability test of the library:
this module shares that definition, not the LMI code). The continuous case builds the Hamiltonian
and its ordered Schur form directly (imaginary-axis eigenvalues mean ``gamma`` is too small).

The equations are solved in unit-sized channels, ``w~ = ||Bw|| w`` and
``z~ = z / ||[Cz Dzu Dzw~]||`` (the level is homogeneous in both scalings
and the gain does not depend on them); ``gamma`` and ``P`` are reported in
the caller's units. scipy's solver is not scale invariant: on the truck
with the authors' weights (``R = 33535``, so ``gamma^2 ~ 1e8`` in the
indefinite weight) its genuine solutions had relative residuals of 1e-10
to 3e-10 at every level between the optimum and 3.2 times it, so the
residual check rejected them and the bisection ended at 3.2 times the
optimum; with unit-sized channels the residuals are ~1e-14.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from .._validation import check_performance, check_positive_scalar
from ..errors import InfeasibleError
from ..systems.plant import Plant, check_plant
from ..systems.stability import is_stable

__all__ = ["RiccatiHinf", "hinf_riccati", "riccati_level", "bisect_level", "level_gain"]

try:  # SLICOT's generalised DARE solver (the optional robustctl[slycot] extra): no Python-level QZ reordering
    from slycot import sg02ad as _SG02AD
except ImportError:  # pragma: no cover - scipy is used instead
    _SG02AD = None

# Relative residual accepted from scipy's DARE. A genuine stabilising solution
# has ~1e-14; just below the optimal level scipy still returns a matrix with
# residual 1e-9..1e-7 whose gain misses the level (seen on a random n = 20
# plant: gamma 8e-6 too low with 1e-7 here).
_RES_TOL = 1e-10

# (F, G, Bw, Cz, Dzu, Dzw)
_Data = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True, eq=False)
class RiccatiHinf:
    """Result of :func:`hinf_riccati`: the optimal level and a gain for a level just above it.

    Attributes
    ----------
    gamma : float
        Smallest level found feasible (upper end of the final bracket).
    gamma_low : float
        Largest level found infeasible (lower end of the final bracket).
    K : (m, n) ndarray
        Gain ``u = K x`` achieving ``||T_zw||_inf < gamma``.
    P : (n, n) ndarray
        The stabilising Riccati solution at ``gamma``.
    iterations : int
        Number of Riccati solves.
    """

    gamma: float
    gamma_low: float
    K: np.ndarray
    P: np.ndarray
    iterations: int


def _data(plant, Bw, Cz, Dzu, Dzw) -> tuple[_Data, float, float]:
    """``(F, G, Bw~, Cz~, Dzu~, Dzw~), b, c``: ``w~ = b w`` and ``z~ = z / c`` of unit size (1 for zero matrices).

    A level of the scaled data is ``gamma / (b c)``, its Riccati solution ``P / c^2``; the gain is the same.
    """
    check_plant(plant)
    Bw, Cz, Dzu, Dzw = check_performance(plant.n, plant.m, Bw, Cz, Dzu, Dzw)
    b = float(np.linalg.norm(Bw, 2)) or 1.0
    Bw, Dzw = Bw / b, Dzw / b
    c = float(np.linalg.norm(np.hstack([Cz, Dzu, Dzw]), 2)) or 1.0
    return (plant.F, plant.G, Bw, Cz / c, Dzu / c, Dzw / c), b, c


def _game_matrices(G, Bw, Cz, Dzu, Dzw, gamma):
    B = np.hstack([G, Bw])
    D = np.hstack([Dzu, Dzw])
    q = Bw.shape[1]
    R = D.T @ D
    R[-q:, -q:] -= gamma**2 * np.eye(q)
    return B, Cz.T @ Cz, R, Cz.T @ D


def _dare(F, B, Q, R, S) -> np.ndarray | None:
    """Stabilising solution of the DARE with indefinite ``R``: SLICOT ``SG02AD`` if slycot is installed, else scipy.

    ``None`` if the solver fails or returns non-finite values. Either answer is
    checked by the caller (residual, sign, closed loop), not trusted.
    """
    n, k = B.shape
    if _SG02AD is not None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out = _SG02AD("D", "B", "N", "U", "N", "N", "S", "R", n, k, 0, F, np.eye(n), B, Q, R, S)
            P = np.asarray(out[1], dtype=float)
            return P if np.all(np.isfinite(P)) else None
        except (ArithmeticError, ValueError, RuntimeError, np.linalg.LinAlgError):
            pass  # slycot's errors and warnings-as-errors: try scipy
    try:
        with np.errstate(all="ignore"):
            P = scipy.linalg.solve_discrete_are(F, B, Q, R, s=S)
    except (np.linalg.LinAlgError, ValueError):
        return None
    return P if np.all(np.isfinite(P)) else None


def _level_discrete(F, G, Bw, Cz, Dzu, Dzw, gamma):
    _n, m = G.shape
    B, Q, R, S = _game_matrices(G, Bw, Cz, Dzu, Dzw, gamma)
    P = _dare(F, B, Q, R, S)
    if P is None:
        return None
    P = 0.5 * (P + P.T)
    H = R + B.T @ P @ B
    try:
        L = -np.linalg.solve(H, B.T @ P @ F + S.T)
    except np.linalg.LinAlgError:
        return None
    res = F.T @ P @ F + Q + (F.T @ P @ B + S) @ L - P
    scale = max(1.0, float(np.linalg.norm(P)), float(np.linalg.norm(Q)))
    if not np.linalg.norm(res) <= _RES_TOL * scale:
        return None
    if np.linalg.eigvalsh(P).min() < -1e-9 * scale:
        return None
    if not is_stable(F + B @ L, discrete=True):
        return None
    Hww = H[m:, m:]
    if np.linalg.eigvalsh(0.5 * (Hww + Hww.T)).max() >= 0.0:
        return None
    return L[:m], P


def _level_continuous(F, G, Bw, Cz, Dzu, Dzw, gamma):
    n, m = G.shape
    if np.linalg.norm(Dzw, 2) >= gamma:
        return None
    B, Q, R, S = _game_matrices(G, Bw, Cz, Dzu, Dzw, gamma)
    try:
        Rinv = np.linalg.inv(R)
    except np.linalg.LinAlgError:
        return None
    A = F - B @ Rinv @ S.T
    Ham = np.block([[A, -B @ Rinv @ B.T], [-(Q - S @ Rinv @ S.T), -A.T]])
    eig = np.linalg.eigvals(Ham)
    scale = max(1.0, float(np.linalg.norm(Ham, 1)))
    if np.min(np.abs(eig.real)) <= 1e-10 * scale:
        return None  # eigenvalue on the imaginary axis: gamma too small
    _T, U, sdim = scipy.linalg.schur(Ham, output="real", sort="lhp")
    if sdim != n:
        return None
    U1, U2 = U[:n, :n], U[n:, :n]
    if np.linalg.cond(U1) > 1e12:
        return None
    P = np.linalg.solve(U1.T, U2.T).T
    P = 0.5 * (P + P.T)
    L = -Rinv @ (B.T @ P + S.T)
    res = F.T @ P + P @ F + Q + (P @ B + S) @ L
    pscale = max(1.0, float(np.linalg.norm(P)), float(np.linalg.norm(Q)))
    if not np.linalg.norm(res) <= 1e-6 * pscale * max(1.0, float(np.linalg.norm(F))):
        return None
    if np.linalg.eigvalsh(P).min() < -1e-9 * pscale:
        return None
    if not is_stable(F + B @ L, discrete=False):
        return None
    return L[:m], P


def level_gain(data: _Data, gamma: float, *, discrete: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`riccati_level` on validated arrays ``(F, G, Bw, Cz, Dzu, Dzw)`` (no rescaling)."""
    return (_level_discrete if discrete else _level_continuous)(*data, gamma)


def riccati_level(plant: Plant, gamma: float, *, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike,
                  Dzw: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """Test one level: ``(K, P)`` if a gain with ``||T_zw||_inf < gamma`` exists, else ``None``.

    See the module docstring for the equations and the checks applied.
    """
    data, b, c = _data(plant, Bw, Cz, Dzu, Dzw)
    gamma = check_positive_scalar(gamma, "gamma")
    sol = level_gain(data, gamma / (b * c), discrete=plant.is_discrete)
    return None if sol is None else (sol[0], c**2 * sol[1])


def hinf_riccati(plant: Plant, *, Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None,
                 rtol: float = 1e-9, gamma_max: float = 1e10) -> RiccatiHinf:
    """Optimal state-feedback H-infinity level by bisection on the game Riccati equation.

    Parameters
    ----------
    plant : Plant
        Discrete (``dt > 0``) or continuous (``dt=None``) plant ``(F, G)``.
    Bw, Cz, Dzu, Dzw : array_like
        Disturbance input, performance output and feedthroughs (``Dzw``
        defaults to zero); ``Dzu`` should have full column rank.
    rtol : float
        Stop when ``gamma_high / gamma_low - 1 < rtol``.
    gamma_max : float
        Give up (``InfeasibleError``) if no level up to ``gamma_max`` in the
        unit-sized channels of the module notes is feasible, i.e. up to
        ``gamma_max ||Bw|| ||[Cz Dzu Dzw / ||Bw||]||`` in the caller's units
        (relative, so that the answer does not depend on the units of ``w``
        and ``z``).

    Returns
    -------
    RiccatiHinf

    Notes
    -----
    The bracket starts at ``[||Dzw~||, 1]`` in the unit-sized channels of
    the module notes (``[||Dzw||, ||Bw|| ||[Cz Dzu Dzw / ||Bw||]||]`` in the
    caller's units) and the upper end is doubled until feasible. The
    bisection is geometric (on ``log gamma``). Near the optimum the Riccati
    solution may become ill conditioned; a level whose solution
    fails the residual checks is treated as infeasible, so the returned
    ``gamma`` is an upper bound of the optimum, tight to ``rtol`` unless the
    checks fail early (compare ``gamma`` with ``gamma_low``).
    """
    data, b, c = _data(plant, Bw, Cz, Dzu, Dzw)
    rtol = check_positive_scalar(rtol, "rtol")
    gamma_max = check_positive_scalar(gamma_max, "gamma_max")
    try:
        hi, lo, K, P, its = bisect_level(data, discrete=plant.is_discrete, rtol=rtol, gamma_max=gamma_max)
    except InfeasibleError as exc:
        raise InfeasibleError(f"no stabilising game-Riccati solution for gamma up to {gamma_max * b * c:g} "
                              f"(gamma_max = {gamma_max:g} times the size of the channels; is (F, G) "
                              "stabilisable?)") from exc
    return RiccatiHinf(gamma=float(hi * b * c), gamma_low=float(lo * b * c), K=K, P=c**2 * P, iterations=its)


def bisect_level(data: _Data, *, discrete: bool, rtol: float, gamma_max: float
                 ) -> tuple[float, float, np.ndarray, np.ndarray, int]:
    """The bisection of :func:`hinf_riccati` on validated arrays ``(F, G, Bw, Cz, Dzu, Dzw)``.

    The channels should be of unit size (the bracket starts at
    ``[||Dzw||, max(1, 2 ||Dzw||)]``). Returns ``(gamma_high, gamma_low, K,
    P, iterations)``: ``K`` and ``P`` of the level ``gamma_high``, the smallest
    found feasible. Raises InfeasibleError if no level up to ``gamma_max`` is.
    """
    lo = float(np.linalg.norm(data[-1], 2))
    hi = max(1.0, 2.0 * lo)
    its = 0
    while True:
        its += 1
        sol = level_gain(data, hi, discrete=discrete)
        if sol is not None:
            break
        lo, hi = hi, 2.0 * hi
        if hi > gamma_max:
            raise InfeasibleError(f"no stabilising game-Riccati solution for gamma up to {gamma_max:g}")
    best = sol
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        its += 1
        sol = level_gain(data, mid, discrete=discrete)
        if sol is None:
            lo = mid
        else:
            hi, best = mid, sol
    return float(hi), float(lo), best[0], best[1], its
