"""Stage 3 of the synthesis: the decision variables and the named LMI blocks.

The blocks (each ``M >= margin I``, see :class:`robustctl._cvx.LMI`) are
built from a :class:`Point`, which holds either cvxpy variables (to solve)
or arrays (to evaluate a candidate's certificate with the very same code).
The maths is in the docstring of ``robustctl.synthesis.hinf``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from ... import _cvx
from ...systems.regions import region_lmi
from . import tolerances as tol
from .coordinates import Coordinates, lifted

__all__ = ["Point", "variables", "blocks", "hinf_blocks", "projected_blocks", "projected_gain", "lyapunov_blocks",
           "input_bound_blocks", "region_blocks", "is_strict"]


@dataclass(frozen=True, eq=False)
class Point:
    """Decision variables of the LMIs (cvxpy variables) or their values (arrays).

    Standard LMI: the Lyapunov matrix ``X`` and ``Y = K X``. Extended
    (slack-variable) LMI: ``P`` (one per vertex), the slack ``S`` (not
    symmetric) and ``L = K S``. With a norm-bounded uncertainty: one
    S-procedure multiplier ``eps`` per vertex.
    """

    X: Any = None
    Y: Any = None
    P: tuple = ()
    S: Any = None
    L: Any = None
    eps: tuple = ()

    @property
    def extended(self) -> bool:
        return self.S is not None

    def values(self) -> Point:
        """The solution held by the cvxpy variables, as arrays."""
        if self.extended:
            return Point(P=tuple(_cvx.value(P) for P in self.P), S=_cvx.value(self.S), L=_cvx.value(self.L))
        X = _cvx.value(self.X)
        return Point(X=0.5 * (X + X.T), Y=_cvx.value(self.Y), eps=tuple(float(_cvx.value(e)) for e in self.eps))

    def shape_matrix(self) -> np.ndarray:
        """The matrix whose shape defines recentred coordinates: ``X``, or the symmetric part of ``S``."""
        M = self.S if self.extended else self.X
        return 0.5 * (M + M.T)

    def nominal_lyapunov(self) -> np.ndarray:
        """``X``, or ``P`` of the nominal vertex."""
        return self.P[0] if self.extended else self.X

    def lyapunov_matrices(self) -> tuple[np.ndarray, ...]:
        """One Lyapunov matrix per vertex (the common ``X`` once)."""
        return self.P if self.extended else (self.X,)

    def gain(self) -> np.ndarray:
        """``K = Y X^-1`` (``L S^-1``) in the point's coordinates."""
        if self.extended:
            return np.linalg.solve(self.S.T, self.L.T).T
        return np.linalg.solve(self.X, self.Y.T).T


def variables(n: int, m: int, vertices: int, extended: bool, uncertain: bool = False) -> Point:
    """Fresh cvxpy variables for ``vertices`` plants with ``n`` states and ``m`` inputs."""
    import cvxpy as cp

    if extended:
        return Point(P=tuple(cp.Variable((n, n), symmetric=True, name=f"P{i}") for i in range(vertices)),
                     S=cp.Variable((n, n), name="S"), L=cp.Variable((m, n), name="L"))
    eps = tuple(cp.Variable(name=f"eps{i}") for i in range(vertices)) if uncertain else ()
    return Point(X=cp.Variable((n, n), symmetric=True, name="X"), Y=cp.Variable((m, n), name="Y"), eps=eps)


def _bmat(rows):
    """``np.block`` when every entry is a number or an array (a candidate point), else ``cvxpy.bmat``.

    Evaluating a certificate at arrays then needs no cvxpy (nor its import).
    """
    if all(isinstance(x, (np.ndarray, float, int, np.floating)) for row in rows for x in row):
        return np.block(rows)
    import cvxpy as cp

    return cp.bmat(rows)


def hinf_blocks(data: Coordinates, V: Point, level_sq, *, discrete: bool, margin=0.0,
                z_scale: float = 1.0) -> list[_cvx.LMI]:
    """The bounded-real-lemma block of every vertex, ``hinf[i]``, at the scaled level ``level_sq``.

    ``level_sq`` is ``(level_scale z_scale gamma)^2`` (a float or a cvxpy
    variable); ``z_scale`` multiplies ``z``. The constant disturbance block
    ``I`` is eliminated by a Schur complement (``q`` rows smaller, still
    linear). With an uncertainty in ``data`` (and multipliers in ``V``) the
    block is the robust one of ``robustctl.synthesis.hinf`` (S-procedure).
    """
    Ip = np.eye(data.p)
    Cz, Dzu, Dzw = z_scale * data.Cz, z_scale * data.Dzu, z_scale * data.Dzw
    Bw = data.Bw
    BB, BD, DD = Bw @ Bw.T, Bw @ Dzw.T, Dzw @ Dzw.T
    out = []
    for i, (F, G) in enumerate(zip(data.F, data.G, strict=True)):
        if V.extended:
            P, S, L = V.P[i], V.S, V.L
            AS, CS = F @ S + G @ L, Cz @ S + Dzu @ L
            M = _bmat([[P - BB, AS, -BD],
                       [AS.T, S + S.T - P, CS.T],
                       [-BD.T, CS, level_sq * Ip - DD]])
        else:
            X, Y = V.X, V.Y
            AX, CX = F @ X + G @ Y, Cz @ X + Dzu @ Y
            if V.eps:
                M = _robust_block(data, V.eps[i], X, Y, AX, CX, level_sq * Ip - DD, BB, BD, discrete)
            elif discrete:
                M = _bmat([[X - BB, AX, -BD],
                           [AX.T, X, CX.T],
                           [-BD.T, CX, level_sq * Ip - DD]])
            else:  # -(continuous bounded-real lemma) >= 0
                M = _bmat([[-(AX + AX.T) - BB, -CX.T - BD],
                           [-CX - BD.T, level_sq * Ip - DD]])
        out.append(_cvx.LMI(f"hinf[{i}]", M, margin))
    return out


def projected_blocks(data: Coordinates, X, level_sq, z_scale: float = 1.0) -> list[_cvx.LMI]:
    r"""The discrete H-infinity block of one plant with ``Y`` eliminated (projection lemma): two smaller blocks.

    With ``Abar = [F; Cz]``, ``Bbar = [G; Dzu]``, ``Wbar = [Bw; Dzw]``,
    ``eta = level_sq`` and ``Phi(X, eta) = diag(X, eta I) - Wbar Wbar'``, the
    block of :func:`hinf_blocks` is (rows reordered) ``[[Phi, Abar X + Bbar
    Y], [*, X]] >= 0``. ``Y`` enters only through ``Bbar Y [0 I]``, so by the
    projection lemma (Gahinet & Apkarian 1994) some ``Y`` satisfies it
    exactly when both of its projections do, onto the null space of
    ``[Bbar' 0]`` and of ``[0 I]``:

    * ``hinf_projected[0]``: ``N'(Phi - Abar X Abar')N >= 0`` (order ``n + p - m``,
      after a Schur complement on ``X``), ``N`` an orthonormal basis of the
      null space of ``Bbar'``;
    * ``hinf_phi[0]``: ``Phi >= 0`` (order ``n + p``).

    Instead of one block of order ``2 n + p`` and ``m n`` variables fewer; the
    gain is recovered by :func:`projected_gain`. ``X`` (a cvxpy variable or
    an array) and ``level_sq`` are in ``data``'s coordinates, with ``z``
    multiplied by ``z_scale`` as in :func:`hinf_blocks`.
    """
    Abar, Bbar, Wbar = _stacked(data, z_scale)
    N = scipy.linalg.null_space(Bbar.T)
    NA, NW = N.T @ Abar, N.T @ Wbar
    Nx, Nz = N[:data.n], N[data.n:]
    projected = Nx.T @ X @ Nx + level_sq * (Nz.T @ Nz) - NA @ X @ NA.T - NW @ NW.T
    return [_cvx.LMI("hinf_projected[0]", projected), _cvx.LMI("hinf_phi[0]", _phi(Wbar, X, level_sq))]


def projected_gain(data: Coordinates, X: np.ndarray, level_sq: float, z_scale: float = 1.0) -> np.ndarray | None:
    r"""The gain of a point ``(X, eta)`` of :func:`projected_blocks`: ``K = -(Bbar' Phi^-1 Bbar)^+ Bbar' Phi^-1 Abar``.

    With ``Y = K X`` and ``Phi > 0`` the block of :func:`hinf_blocks` is, by
    Schur complements, ``X^-1 - (Abar + Bbar K)' Phi^-1 (Abar + Bbar K) >= 0``.
    The weighted least-squares ``K`` minimises ``(Abar + Bbar K)' Phi^-1 (Abar
    + Bbar K)`` in the positive semidefinite order (it is ``Abar' (Phi^-1 -
    Phi^-1 Bbar (Bbar' Phi^-1 Bbar)^+ Bbar' Phi^-1) Abar`` there), so it
    satisfies the block whenever any gain does.

    At an optimum ``Phi`` can be singular (``X - Bw Bw'`` is, on some
    plants): a direction ``v`` with ``Phi v = 0`` forces ``v'(Abar + Bbar K)
    = 0``. ``Phi`` is therefore lifted to at least ``PHI_FLOOR`` of its
    largest eigenvalue first, and the weighted least squares keeps that
    constraint up to the floor. ``None`` if ``Phi`` is not finite or not
    positive anywhere.
    """
    Abar, Bbar, Wbar = _stacked(data, z_scale)
    phi = lifted(_phi(Wbar, X, level_sq), tol.PHI_FLOOR)
    if phi is None:
        return None
    L = np.linalg.cholesky(phi)
    LA, LB = scipy.linalg.solve_triangular(L, Abar, lower=True), scipy.linalg.solve_triangular(L, Bbar, lower=True)
    return -np.linalg.lstsq(LB, LA, rcond=None)[0]


def _stacked(data: Coordinates, z_scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Abar = [F; Cz]``, ``Bbar = [G; Dzu]``, ``Wbar = [Bw; Dzw]`` of the nominal plant, ``z`` times ``z_scale``."""
    return (np.vstack([data.F[0], z_scale * data.Cz]), np.vstack([data.G[0], z_scale * data.Dzu]),
            np.vstack([data.Bw, z_scale * data.Dzw]))


def _phi(Wbar: np.ndarray, X, level_sq):
    """``Phi(X, eta) = diag(X, eta I) - Wbar Wbar'`` for a variable or an array ``X`` (as one matrix)."""
    n = X.shape[0]
    WW = Wbar @ Wbar.T
    return _bmat([[X - WW[:n, :n], -WW[:n, n:]], [-WW[n:, :n], level_sq * np.eye(WW.shape[0] - n) - WW[n:, n:]]])


def _robust_block(data: Coordinates, eps, X, Y, AX, CX, W, BB, BD, discrete: bool):
    """The bounded-real block for ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1``, with multiplier ``eps``.

    With ``EX = EF X + EG Y`` and ``W = gamma^2 I - Dzw Dzw'``, discrete:
    ``[[X - BB' - eps HH', AX, -BD', 0], [*, X, CX', EX'], [*, *, W, 0],
    [*, *, *, eps I]] >= 0``; continuous: ``[[-He(AX) - BB' - eps HH',
    -CX' - BD', -EX'], [*, W, 0], [*, *, eps I]] >= 0``.
    """
    import cvxpy as cp

    assert data.H is not None and data.EF is not None and data.EG is not None  # V.eps: an uncertainty was given
    EX = data.EF @ X + data.EG @ Y
    n, p, l = data.n, W.shape[0], EX.shape[0]
    epsHH, epsI = eps * (data.H @ data.H.T), eps * np.eye(l)
    if discrete:
        return cp.bmat([[X - BB - epsHH, AX, -BD, np.zeros((n, l))],
                        [AX.T, X, CX.T, EX.T],
                        [-BD.T, CX, W, np.zeros((p, l))],
                        [np.zeros((l, n)), EX, np.zeros((l, p)), epsI]])
    return cp.bmat([[-(AX + AX.T) - BB - epsHH, -CX.T - BD, -EX.T],
                    [-CX - BD.T, W, np.zeros((p, l))],
                    [-EX, np.zeros((l, p)), epsI]])


def lyapunov_blocks(V: Point, x_margin, x_upper: float) -> list[_cvx.LMI]:
    """``X >= x_margin I`` and ``X <= x_upper I`` (extended: ``sym(S) >= x_margin I``, every ``P_i <= x_upper I``)."""
    n_eye = np.eye((V.S if V.extended else V.X).shape[0])
    if V.extended:
        return ([_cvx.LMI("S", 0.5 * (V.S + V.S.T), x_margin)]
                + [_cvx.LMI(f"P_upper[{i}]", x_upper * n_eye - P) for i, P in enumerate(V.P)])
    return [_cvx.LMI("X", V.X, x_margin), _cvx.LMI("X_upper", x_upper * n_eye - V.X)]


def input_bound_blocks(V: Point, u_max: np.ndarray) -> list[_cvx.LMI]:
    """``|u_j| <= u_max_j`` on the unit-energy reachable set: ``y_j X^-1 y_j' <= u_max_j^2``.

    The textbook block ``[[u_max_j^2, y_j], [y_j', X]] >= 0`` (Boyd et al.
    1994, Sec. 7.2.3) after the congruence ``diag(1 / s_j, I)`` with
    ``s_j = max(1, u_max_j)``: ``[[(u_max_j / s_j)^2, y_j / s_j], [*, X]]``.
    For ``u_max_j <= 1`` that is the textbook block; a looser bound keeps
    every entry of the order of ``X`` (written with ``u_max_j^2``, a bound of
    1e5 put 1e10 beside ``X ~ 1`` and the solver reported infeasibility).
    Extended: ``S + S' - P_i`` instead of ``X`` and ``l_j`` instead of
    ``y_j``, at every vertex (``S + S' - P <= S' P^-1 S``). The constant is
    reduced by the relative ``U_SLACK`` so that solver rounding cannot
    exceed the bound.
    """
    import cvxpy as cp

    out = []
    for j, umax in enumerate(u_max):
        s = max(1.0, float(umax))
        c = np.array([[(umax / s) ** 2 * (1.0 - tol.U_SLACK)]])
        if V.extended:
            lj = V.L[j:j + 1, :] / s
            out += [_cvx.LMI(f"u_max[{j}][{i}]", cp.bmat([[c, lj], [lj.T, V.S + V.S.T - P]]), 0.0)
                    for i, P in enumerate(V.P)]
        else:
            yj = V.Y[j:j + 1, :] / s
            out.append(_cvx.LMI(f"u_max[{j}]", cp.bmat([[c, yj], [yj.T, V.X]]), 0.0))
    return out


def region_blocks(regions, data: Coordinates, V: Point, margin=0.0) -> list[_cvx.LMI]:
    """``poles[k][i]``: the closed loop of vertex ``i`` has its poles in region ``k`` (same ``X``)."""
    return [_cvx.LMI(f"poles[{k}][{i}]", region_lmi(region, F @ V.X + G @ V.Y, V.X), margin)
            for k, region in enumerate(regions) for i, (F, G) in enumerate(zip(data.F, data.G, strict=True))]


def blocks(problem, data: Coordinates, V: Point, level_sq, *, margin=0.0, z_scale: float = 1.0,
           x_bounds: tuple[Any, float] | None = None) -> list[_cvx.LMI]:
    """Every LMI block of one H-infinity synthesis problem (a :class:`.problem.Problem`), named.

    The H-infinity and pole-region blocks get ``margin``. With ``x_bounds =
    (x_margin, x_upper)`` the Lyapunov (or slack) matrix is also bounded,
    ``x_margin I <= X <= x_upper I``; otherwise continuous time adds ``X >=
    margin I`` (discrete time implies ``X > 0``). An input bound adds its blocks.
    """
    out = hinf_blocks(data, V, level_sq, discrete=problem.discrete, margin=margin, z_scale=z_scale)
    if x_bounds is not None:
        out += lyapunov_blocks(V, *x_bounds)
    elif not problem.discrete:
        out.append(_cvx.LMI("X", V.X, margin))
    out += region_blocks(problem.regions, data, V, margin)
    if problem.u_max is not None:
        out += input_bound_blocks(V, problem.u_max)
    return out


def is_strict(certificate) -> bool:
    """Every H-infinity and pole-region block and the Lyapunov (slack) matrix strictly positive definite."""
    return all(v > 0 for k, v in certificate.items() if k.startswith(("hinf", "X", "S", "poles")) and k != "X_upper")

