"""Performance bounds for every admissible ``Delta``: guaranteed LQ cost and robust H-infinity bound.

:func:`robustctl.guaranteed_cost` (one SDP for one gain; batched Riccati
equations and a search over the multiplier for a stack of gains) and
:func:`robustctl.robust_hinf_bound` (one SDP).
"""

from __future__ import annotations

import math
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike

from .. import _cvx
from .._validation import as_batch, as_matrix, check_performance, check_spd, frozen
from ..errors import InfeasibleError
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.stability import is_stable, stability_of_eigenvalues
from ..systems.uncertainty import NormBounded
from . import _hinfnorm
from ._common import (
    _COST_LMI_TOL,
    _block,
    _blocks,
    _controller_plant,
    _Coordinates,
    _diag,
    _lyapunov_factor,
    _radius,
    _solve_info,
    _uncertain_loop,
)
from .results import CostBound, CostBoundBatch, HinfBound, _ro


def _robust_loop(controller, uncertainty, what: str):
    """``(plant, K, A, H, E)`` after checking that the loop is robustly stable (small gain < 1)."""
    plant, K, unc = _uncertain_loop(controller, uncertainty)
    discrete = plant.is_discrete
    A, H, E = plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K
    if not is_stable(A, discrete=discrete):
        kind = "spectral radius" if discrete else "spectral abscissa"
        raise InfeasibleError(f"no {what}: the nominal closed loop F + G K is unstable ({kind} "
                              f"{_radius(A, discrete):.6g})")
    if not (np.any(H) and np.any(E)):
        # the uncertainty does not reach the loop: drop its channel (else the
        # S-procedure multiplier would have to go to infinity)
        return plant, K, A, np.zeros((plant.n, 0)), np.zeros((0, plant.n))
    gain = float(_hinfnorm.hinf_norm(A[None], H[None], E[None], discrete=discrete)[0][0])
    if gain >= 1.0:
        raise InfeasibleError(f"no {what}: the closed loop is not quadratically stable for every "
                              f"||Delta|| <= 1 (||E (zI - A)^-1 H||_inf = {gain:.6g} >= 1, stability "
                              f"margin {1.0 / gain:.6g}; see robust_stability)")
    return plant, K, A, H, E


def _balanced(Hh: np.ndarray, Eh: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(H^ c, E^ / c, c)`` with equal norms (``H Delta E`` unchanged)."""
    h, e = float(np.linalg.norm(Hh, 2)), float(np.linalg.norm(Eh, 2))
    c = float(np.sqrt(e / h)) if h > 0 and e > 0 else 1.0
    return Hh * c, Eh / c, c


def _multiplier(lam, p: int, c: float) -> float:
    """The multiplier in the plant's scaling: ``lam^ (|E^ x^|^2 - |q^|^2) = lam^ (|E x|^2 - |q|^2) / c^2``."""
    return float(_cvx.value(lam)) / c**2 if p else 0.0


def _psd_factor(M: np.ndarray) -> np.ndarray:
    """``L`` with ``L'L = M`` for a symmetric positive semidefinite ``M`` (rows ``sqrt(w_i) v_i'``)."""
    w, V = np.linalg.eigh(M)
    return np.sqrt(np.clip(w, 0.0, None))[:, None] * V.T


def _cost_objective(P: np.ndarray, x0: np.ndarray | None) -> np.ndarray:
    """``x0' P x0`` or ``lambda_max(P)`` of a stack."""
    if x0 is not None:
        return np.einsum("i,bij,j->b", x0, P, x0)
    return np.linalg.eigvalsh(0.5 * (P + P.mT))[:, -1]


def _cost_lmi_eigs(A, H, E, QK, P, lam, discrete: bool) -> np.ndarray:
    """Eigenvalues (S, n + p), ascending, of the guaranteed-cost LMI at ``(P, lam)`` for stacks."""
    M = _blocks(A, H, P, QK + lam[:, None, None] * (E.mT @ E), lam, discrete)
    return np.linalg.eigvalsh(0.5 * (M + M.mT))


def _guaranteed_cost_batch(plant: Plant, K: np.ndarray, unc: NormBounded, Q: np.ndarray, R: np.ndarray,
                           x0: np.ndarray | None) -> CostBoundBatch:
    """:func:`robustctl.guaranteed_cost` of a stack of gains by Riccati equations and a search over the multiplier.

    For a fixed ``lam`` the smallest ``P`` of the guaranteed-cost LMI is the
    stabilising solution ``P_lam`` of the bounded-real Riccati equation of
    ``(A, H, C_lam)`` at the level ``sqrt(lam)``, ``C_lam'C_lam = Q_K + lam
    E'E`` (the LMI's Schur complement at equality); both objectives grow
    with ``P``, so the bound is ``min over lam`` of ``f(lam) = x0'P_lam x0``
    (or ``lambda_max(P_lam)``), a convex function (the partial minimum of the
    convex SDP) on ``lam > lam*``. With ``q = ||C_Q (zI - A)^-1 H||_inf``
    (``C_Q'C_Q = Q_K``) and ``g = ||E (zI - A)^-1 H||_inf < 1``,
    ``q^2 <= lam* <= q^2 / (1 - g^2)``; from ``P_lam >= P_Q + lam P_E``
    (Lyapunov solutions of ``Q_K`` and ``E'E``) the minimiser is at most
    ``(f(lam_1) - f_Q) / f_E`` for any feasible ``lam_1``. A golden-section
    search on ``log lam`` over that bracket, all designs at once (one
    batched Riccati solve per step), finds it.
    """
    discrete = plant.is_discrete
    B, n = K.shape[0], plant.n
    finite = np.isfinite(K).all(axis=(1, 2))
    Kf = np.where(finite[:, None, None], K, 0.0)
    A = plant.F + plant.G @ Kf
    E = unc.EF + unc.EG @ Kf
    H = unc.H
    lam_A = _hinfnorm.eigvals(A)
    _, stable = stability_of_eigenvalues(lam_A, discrete=discrete)
    stable &= finite
    reason = np.where(finite, np.where(stable, "ok", "unstable"), "not finite").astype("<U20")
    bound = np.where(finite, np.inf, np.nan)
    P_out = np.full((B, n, n), np.nan)
    mult = np.full(B, np.nan)
    cert = {"cost": np.full(B, np.nan), "P": np.full(B, np.nan)}
    steps = failures = 0
    idx = np.flatnonzero(stable)
    if idx.size:
        A, E = A[idx], E[idx]
        S = idx.size
        CQ = np.concatenate([np.broadcast_to(_psd_factor(Q), (S, n, n)), _psd_factor(R) @ Kf[idx]], axis=1)
        QK = CQ.mT @ CQ
        Hs = np.broadcast_to(H, (S, *H.shape))
        reach = bool(np.any(H)) & (np.abs(E).max(axis=(1, 2)) > 0)
        g = _hinfnorm.hinf_norm(A, Hs, E, discrete=discrete, poles=lam_A[idx])[0]
        robust = ~reach | (g < 1.0)
        reason[idx[~robust]] = "not robustly stable"
        zero = np.zeros_like(Hs)
        one = np.ones(S)
        # Lyapunov solutions (the Riccati equation without H): P_Q, and P_E for the bracket
        P_Q, ok_Q = _hinfnorm.bounded_real_riccati(A, zero, CQ, one, discrete=discrete)
        f_Q = np.where(ok_Q, _cost_objective(P_Q, x0), np.inf)
        best_f, best_P, best_lam = np.where(reach, np.inf, f_Q), P_Q.copy(), np.zeros(S)
        live = np.flatnonzero(reach & robust)
        if live.size:
            Al, El, CQl, Hl, QKl = A[live], E[live], CQ[live], Hs[live], QK[live]
            P_E, ok_E = _hinfnorm.bounded_real_riccati(Al, zero[live], El, one[live], discrete=discrete)
            f_E = np.where(ok_E, _cost_objective(P_E, x0), 0.0)
            q = _hinfnorm.hinf_norm(Al, Hl, CQl, discrete=discrete, poles=lam_A[idx[live]])[0]
            gl = g[live]

            def f(lam):
                C = np.concatenate([CQl, np.sqrt(lam)[:, None, None] * El], axis=1)
                P, ok = _hinfnorm.bounded_real_riccati(Al, Hl, C, np.sqrt(lam), discrete=discrete)
                ok &= np.isfinite(P).all(axis=(1, 2))
                P = np.where(ok[:, None, None], P, 0.0)
                # a level at or below the norm can pass the eigenvalue count with imaginary-axis
                # eigenvalues split by rounding: keep only P that satisfy the LMI (up to rounding)
                ev = _cost_lmi_eigs(Al, H, El, QKl, P, lam, discrete)
                ok &= ev[:, 0] >= -_COST_LMI_TOL * np.maximum(1.0, np.abs(ev).max(axis=1))
                val = _cost_objective(P, x0)
                val = np.where(ok & np.isfinite(val), val, np.inf)
                better = val < best_f[live]
                sel = live[better]
                best_f[sel], best_P[sel], best_lam[sel] = val[better], P[better], lam[better]
                return val

            scale = np.where(q > 0, q * q, np.maximum(f_Q[live], 1e-300) / np.maximum(f_E, 1e-300))
            lam1 = np.maximum(2.0 * q * q / (1.0 - gl * gl), 1e-12 * scale)
            f1 = f(lam1)
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(f_E > 0, (f1 - f_Q[live]) / f_E, 1e6 * lam1)
            up = np.where(np.isfinite(up) & (up > lam1), up, lam1)
            lo = np.where(q > 0, q * q, 1e-12 * up)
            a, b = np.log(lo), np.log(up) + 1e-12
            gr = (math.sqrt(5.0) - 1.0) / 2.0
            c, d = b - gr * (b - a), a + gr * (b - a)
            fc, fd = f(np.exp(c)), f(np.exp(d))
            width = float((b - a).max())
            steps = max(0, math.ceil(math.log(1e-9 / width) / math.log(gr))) if width > 1e-9 else 0
            for _ in range(min(steps, 100)):
                left = fc < fd
                b = np.where(left, d, b)
                a = np.where(left, a, c)
                c_new = np.where(left, b - gr * (b - a), d)
                d_new = np.where(left, c, a + gr * (b - a))
                x = np.where(left, c_new, d_new)
                fx = f(np.exp(x))
                fc, fd = np.where(left, fx, fd), np.where(left, fc, fx)
                c, d = c_new, d_new
        found = np.isfinite(best_f) & robust
        failures = int((robust & ~found).sum())
        rows = idx[found]
        Pf, lf = best_P[found], best_lam[found]
        bound[rows], P_out[rows], mult[rows] = best_f[found], Pf, lf
        if rows.size:   # the LMI blocks at (P, lam), in the plant's coordinates
            cert["cost"][rows] = _cost_lmi_eigs(A[found], H, E[found], QK[found], Pf, lf, discrete)[:, 0]
            cert["P"][rows] = np.linalg.eigvalsh(Pf)[:, 0]
    info = {"path": "riccati", "search_steps": steps, "riccati_failures": failures}
    return CostBoundBatch(frozen(bound), frozen(P_out), frozen(mult), _ro(reason),
                          None if x0 is None else frozen(x0),
                          MappingProxyType({k: frozen(v) for k, v in cert.items()}), MappingProxyType(info))


def guaranteed_cost(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, Q: ArrayLike,
                    R: ArrayLike, x0: ArrayLike | None = None) -> CostBound | CostBoundBatch:
    r"""Upper bound on the LQ cost of ``u = K x`` valid for every ``||Delta|| <= 1``.

    The guaranteed-cost LMI of Petersen & McFarlane [1]_ for a fixed gain
    (Notes) bounds ``sum_k x_k'Q x_k + u_k'R u_k <= x0'P x0`` (continuous:
    the integral) for every admissible ``Delta``, also time-varying. The
    bound minimises ``x0'P x0``, or ``lambda_max(P)`` (one ``P`` for every
    unit initial state) if ``x0`` is not given.

    One gain: one SDP. A stack of gains (B, m, n) is answered at once
    without an SDP (:class:`CostBoundBatch`): for a fixed ``lam`` the
    smallest ``P`` is the stabilising solution of a bounded-real Riccati
    equation and the bound is convex in ``lam``, so a golden-section search
    over ``log lam`` with batched Riccati solves gives every design's bound
    (``_guaranteed_cost_batch``); designs that are unstable, not
    robustly stable or not finite are flagged (``reason``) instead of
    raising.

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) or (B, m, n) array_like)
        The gain ``K`` (``u = K x``) and the nominal plant, or a stack of
        ``B`` gains (non-finite ones are flagged).
    uncertainty : NormBounded
        ``[dF dG] = H Delta [EF EG]``.
    Q : (n, n) array_like
        State weight, symmetric positive semidefinite.
    R : (m, m) array_like
        Input weight, symmetric positive semidefinite.
    x0 : (n,) array_like, optional
        Initial state; without it the bound holds for every unit initial state.

    Returns
    -------
    CostBound or CostBoundBatch
        The latter for a stack of gains. A :class:`CostBound`'s ``info``
        holds the solver's ``"solve_time"`` [s], ``"iterations"`` and
        ``"solves"`` (one report: status, value, solver, tol, solve_time,
        iterations, certificate); a :class:`CostBoundBatch`'s is described
        there.

    Raises
    ------
    InfeasibleError
        One gain: the nominal loop is unstable or not quadratically stable
        for ``||Delta|| <= 1`` (no bound exists); the message gives the
        small-gain value.
    ValueError
        Weights or ``x0`` of the wrong shape, weights that are not
        symmetric positive semidefinite.

    See Also
    --------
    robust_stability : the quadratic-stability margin the bound needs above 1.
    robust_hinf_bound : the robust H-infinity bound.

    Notes
    -----
    With ``A = F + G K``, ``E = EF + EG K`` and ``Q_K = Q + K'RK``, find
    ``P >= 0`` and ``lam >= 0`` with (discrete time)

    .. math::

        \begin{bmatrix} P - A^T P A - Q_K - \lambda E^T E & -A^T P H \\
                        -H^T P A & \lambda I - H^T P H \end{bmatrix} \succeq 0 ,

    (continuous time: ``-(A'P + PA) - Q_K - lam E'E``, ``-PH`` and
    ``lam I``). For ``V = x'Px`` and every ``q = Delta E x`` it implies
    ``V(x+) - V(x) <= -x'Q_K x`` (the S-procedure [2]_), hence the bound.
    The stack's Riccati form: for fixed ``lam`` the smallest ``P`` solves
    the bounded-real Riccati equation of ``(A, H, C_lam)``,
    ``C_lam'C_lam = Q_K + lam E'E``, at level ``sqrt(lam)``.

    References
    ----------
    .. [1] I. R. Petersen, D. C. McFarlane, "Optimal guaranteed cost control
       and filtering for uncertain linear systems", IEEE Trans. Automatic
       Control 39(9), 1971-1977, 1994.
    .. [2] S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix
       Inequalities in System and Control Theory*, SIAM 1994, Sec. 6.3.

    Examples
    --------
    A scalar loop ``x+ = (a + b k + h Delta e) x`` has the worst case
    ``|a + b k| + |h e|`` at every step, so the guaranteed cost is
    ``(q + r k^2) x0^2 / (1 - (|a + b k| + |h e|)^2)``, attained:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> a, b, h, e, q, r = 0.5, 1.0, 1.0, 0.2, 1.0, 2.0
    >>> plant = rc.Plant([[a]], [[b]], dt=0.1)
    >>> unc = rc.NormBounded([[h]], [[e]], [[0.0]])
    >>> res = rc.guaranteed_cost((plant, [[-0.2]]), unc, Q=[[q]], R=[[r]], x0=[1.0])
    >>> res
    CostBound(bound=1.44, multiplier=3.6, x0='given')
    >>> def closed_form(k):
    ...     return (q + r * k * k) / (1.0 - (abs(a + b * k) + abs(h * e)) ** 2)
    >>> bool(np.isclose(res.bound, closed_form(-0.2), rtol=1e-6))
    True

    A stack of gains, without an SDP; the last one destabilises the loop:

    >>> batch = rc.guaranteed_cost((plant, [[[-0.2]], [[-0.4]], [[0.5]]]), unc, Q=[[q]], R=[[r]], x0=[1.0])
    >>> batch.reason.tolist()
    ['ok', 'ok', 'unstable']
    >>> bool(np.allclose(batch.bound[:2], [closed_form(-0.2), closed_form(-0.4)], rtol=1e-6))
    True
    """
    import cvxpy as cp

    plant, K, unc = _uncertain_loop(controller, uncertainty, batch=True)
    base = _controller_plant(controller)
    n, m, order = base.n, base.m, plant.n - base.n
    Q = check_spd(as_matrix(Q, "Q", rows=n, cols=n, rows_what="the number of states",
                            cols_what="the number of states"), "Q", semidefinite=True)
    R = check_spd(as_matrix(R, "R", rows=m, cols=m, rows_what="the number of inputs",
                            cols_what="the number of inputs"), "R", semidefinite=True)
    if x0 is not None:
        x0 = as_batch(x0, "x0", (n,), ("the number of states",))
    if order:   # a dynamic controller: its states start at 0 and its own update is not weighted
        Q, R = _diag(Q, np.zeros((order, order))), _diag(R, np.zeros((order, order)))
        x0 = None if x0 is None else np.concatenate([x0, np.zeros(order)])
    if K.ndim == 3:
        return _guaranteed_cost_batch(plant, K, unc, Q, R, x0)
    plant, K, A, H, E = _robust_loop(controller, uncertainty, "guaranteed cost")
    n, p = plant.n, H.shape[1]
    QK = Q + K.T @ R @ K
    T = _Coordinates(_lyapunov_factor(A, QK, plant.is_discrete))
    Ah, QKh = T.A(A), T.Q(QK)
    Hh, Eh, c = _balanced(T.B(H), T.C(E))
    P, lam = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="lam")
    N = _diag(QKh, np.zeros((p, p))) + lam * _diag(Eh.T @ Eh, -np.eye(p))
    lmis = [_cvx.LMI("cost", _block(Ah, Hh, P, N, plant.is_discrete)), _cvx.LMI("P", P)]
    if x0 is None:
        s = cp.Variable(name="s")
        # lambda_max(L P^ L') <= s / c  <=>  s (L L')^-1 / c - P^ >= 0, c = ||(L L')^-1|| (s of unit size)
        M = T.Q(np.eye(n))
        lmis.append(_cvx.LMI("P_upper", s * (M / np.linalg.norm(M, 2)) - P))
        objective = cp.Minimize(s)
    else:
        xh = T.L.T @ x0
        xh = xh / (np.linalg.norm(xh) or 1.0)   # x0' P x0 = |L' x0|^2 xh' P^ xh: the direction only
        objective = cp.Minimize(xh @ P @ xh)
    rep = _cvx.solve_sdp(objective, lmis, infeasible_msg="the guaranteed-cost LMI is infeasible")
    P_orig = T.P(_cvx.value(P))
    bound = float(x0 @ P_orig @ x0) if x0 is not None else float(np.linalg.eigvalsh(P_orig)[-1])
    return CostBound(bound, frozen(P_orig), _multiplier(lam, p, c), None if x0 is None else frozen(x0),
                     MappingProxyType(dict(rep.certificate)), MappingProxyType(_solve_info([rep])))


def robust_hinf_bound(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, *,
                      Bw: ArrayLike, Cz: ArrayLike, Dzu: ArrayLike, Dzw: ArrayLike | None = None) -> HinfBound:
    r"""Upper bound on ``||T_zw||_inf`` of ``u = K x`` over every ``||Delta|| <= 1``.

    Closed loop ``x+ = (A + H Delta E) x + Bw w``, ``z = (Cz + Dzu K) x + Dzw w``
    (the plant convention of :func:`robustctl.hinf`). The bound is the
    smallest ``gamma`` of the robust dissipation LMI (Notes; S-procedure on
    ``q = Delta E x``): ``V(x+) - V(x) <= gamma^2 |w|^2 - |z|^2`` for every
    admissible ``Delta``, also time-varying. One SDP.

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) array_like)
        The gain ``K`` and the nominal plant.
    uncertainty : NormBounded
        ``[dF dG] = H Delta [EF EG]``.
    Bw : (n, q) array_like
        Disturbance input (a 1-D array is one column).
    Cz : (pz, n) array_like
        State part of the performance output.
    Dzu : (pz, m) array_like
        Input part of the performance output.
    Dzw : (pz, q) array_like, optional
        Feedthrough from ``w`` to ``z`` (default zero).

    Returns
    -------
    HinfBound
        ``gamma``, the storage ``P``, the multiplier and the certificate;
        ``info`` holds the solver's ``"solve_time"`` [s], ``"iterations"``
        and ``"solves"``.

    Raises
    ------
    InfeasibleError
        The nominal loop is unstable or not quadratically stable for
        ``||Delta|| <= 1``, or the SDP failed.
    ValueError
        Matrices whose shapes do not agree (named).

    See Also
    --------
    robustctl.hinf : the synthesis for the same criterion.
    guaranteed_cost : the LQ-cost counterpart.

    Notes
    -----
    With ``A = F + G K``, ``E = EF + EG K``, ``C_K = Cz + Dzu K`` and the
    inputs ``(q, w)``, find ``P``, ``lam >= 0`` and the smallest ``gamma``
    with (discrete time) [1]_

    .. math::

        \operatorname{diag}(P, 0, 0) - [A\; H\; B_w]^T P [A\; H\; B_w]
        - \lambda \operatorname{diag}(E^T E, -I, 0)
        - [C_K\; 0\; D_{zw}]^T [C_K\; 0\; D_{zw}]
        + \operatorname{diag}(0, 0, \gamma^2 I) \succeq 0 ,

    which implies ``V(x+) - V(x) <= gamma^2 |w|^2 - |z|^2`` for
    ``V = x'Px`` and every ``Delta``, hence ``||T_zw||_inf <= gamma``.
    Continuous time replaces ``diag(P, 0, 0) - [A H Bw]'P[A H Bw]`` by
    ``-He([I 0 0]' P [A H Bw])``.

    References
    ----------
    .. [1] S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix
       Inequalities in System and Control Theory*, SIAM 1994, Sec. 6.3.

    Examples
    --------
    A scalar loop ``x+ = (a + h Delta e) x + w``, ``z = x``: the bound is the
    worst case over ``|Delta| <= 1``, ``1 / (1 - |a| - |h e|)``, the gain at
    ``z = 1`` with the pole at ``|a| + |h e|``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[0.5]], [[1.0]], dt=0.1)
    >>> unc = rc.NormBounded([[1.0]], [[0.2]], [[0.0]])
    >>> res = rc.robust_hinf_bound((plant, [[-0.2]]), unc, Bw=[[1.0]], Cz=[[1.0]], Dzu=[[0.0]])
    >>> res
    HinfBound(gamma=2, multiplier=10)
    >>> bool(np.isclose(res.gamma, 1.0 / (1.0 - abs(0.5 - 0.2) - 0.2), rtol=1e-6))
    True
    """
    import cvxpy as cp

    plant, K, A, H, E = _robust_loop(controller, uncertainty, "robust H-infinity bound")
    base = _controller_plant(controller)
    n, p, order = plant.n, H.shape[1], plant.n - base.n
    Bw, Cz, Dzu, Dzw = check_performance(base.n, base.m, Bw, Cz, Dzu, Dzw)
    if order:   # a dynamic controller: w and z act on the plant's states and inputs only
        Bw = np.vstack([Bw, np.zeros((order, Bw.shape[1]))])
        Cz, Dzu = (np.hstack([M, np.zeros((M.shape[0], order))]) for M in (Cz, Dzu))
    C = Cz + Dzu @ K
    q = Bw.shape[1]
    T = _Coordinates(_lyapunov_factor(A, C.T @ C, plant.is_discrete))
    Ah, Ch = T.A(A), T.C(C)
    Hh, Eh, c = _balanced(T.B(H), T.C(E))
    Bh = T.B(Bw)
    b = float(np.linalg.norm(Bh, 2)) or 1.0  # w = w^ / b: gamma = b gamma^
    Bh, Dh = Bh / b, Dzw / b
    P, lam, mu = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="lam"), cp.Variable(name="mu")
    CD = np.hstack([Ch, np.zeros((C.shape[0], p)), Dh])
    N = (CD.T @ CD + lam * _diag(Eh.T @ Eh, -np.eye(p), np.zeros((q, q)))
         - mu * _diag(np.zeros((n + p, n + p)), np.eye(q)))
    lmis = [_cvx.LMI("hinf", _block(Ah, np.hstack([Hh, Bh]), P, N, plant.is_discrete)), _cvx.LMI("P", P)]
    rep = _cvx.solve_sdp(cp.Minimize(mu), lmis, infeasible_msg="the robust H-infinity LMI is infeasible")
    gamma = b * float(np.sqrt(max(float(_cvx.value(mu)), 0.0)))
    return HinfBound(gamma, frozen(T.P(_cvx.value(P))), _multiplier(lam, p, c),
                     MappingProxyType(dict(rep.certificate)), MappingProxyType(_solve_info([rep])))
