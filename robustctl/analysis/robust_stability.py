"""Robust stability (:func:`robustctl.robust_stability`) of one gain or a stack of gains.

Norm-bounded: the margin is the small-gain value (level-set H-infinity
norm, or AB13DD for one gain), the certificate a bounded-real Riccati
solution checked by eigenvalues, the SDP the fallback. Polytopes: a
bisection of SDPs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import lapack

from .. import _cvx
from .._validation import frozen
from ..errors import ConvergenceError, InfeasibleError
from ..systems.controller import Controller
from ..systems.plant import Plant, check_vertices
from ..systems.stability import is_stable, stability_of_eigenvalues
from ..systems.uncertainty import NormBounded
from . import _hinfnorm
from ._common import (
    _BACKOFF,
    _EPS_TRIES,
    _POLY_RMAX,
    _POLY_RTOL,
    _POLY_STEPS,
    _POLY_T,
    _SDA_MIN_N,
    _STRICT,
    _augmented_plant,
    _block,
    _blocks,
    _controller_plant,
    _Coordinates,
    _diag,
    _loop,
    _lyapunov_factor,
    _min_eig,
    _radius,
    _solve_info,
    _uncertain_loop,
)
from .results import RobustStability, RobustStabilityBatch, _ro


def _stability_blocks(A, H, E, P, r, discrete) -> dict[str, np.ndarray]:
    """Blocks of the quadratic-stability certificate at radius ``r`` (multiplier 1)."""
    return {"P": P, "lyapunov": _block(A, r * H, P, _diag(E.T @ E, -np.eye(H.shape[1])), discrete)}


def _relative_min_eig(blocks: Mapping[str, np.ndarray]) -> float:
    return min(_min_eig(M) / max(1.0, float(np.linalg.norm(M, 2))) for M in blocks.values())


def _norm_bounded_sdp(plant: Plant, K: np.ndarray, unc: NormBounded) -> RobustStability:
    """The margin and certificate by one SDP (the fallback of :func:`_norm_bounded_batch`)."""
    import cvxpy as cp

    discrete = plant.is_discrete
    A = plant.F + plant.G @ K
    H, E = unc.H, unc.EF + unc.EG @ K
    n, p = H.shape
    nominal = _radius(A, discrete)
    if not is_stable(A, discrete=discrete):
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "norm-bounded",
                               MappingProxyType({"nominal_radius": nominal}))
    e = float(np.linalg.norm(E, 2))
    En = E / e if e > 0 else E
    T = _Coordinates(_lyapunov_factor(A, En.T @ En, discrete))
    # x = L'^-1 x^ with H^ and E^ of unit norm: the scaled loop's radius is r hh eh
    Ah, Hh, Eh = T.A(A), T.B(H), T.C(E)
    hh, eh = (float(np.linalg.norm(M, 2)) or 1.0 for M in (Hh, Eh))
    Hh, Eh = Hh / hh, Eh / eh
    P = cp.Variable((n, n), symmetric=True, name="P")
    mu = cp.Variable(name="mu")
    N = _diag(Eh.T @ Eh, np.zeros((p, p))) - mu * _diag(np.zeros((n, n)), np.eye(p))
    lmis = [_cvx.LMI("lyapunov", _block(Ah, Hh, P, N, discrete)), _cvx.LMI("P", P)]
    rep = _cvx.solve_sdp(cp.Minimize(mu), lmis, infeasible_msg="the bounded-real LMI of the uncertainty loop is "
                                                               "infeasible")
    mu_opt = max(float(_cvx.value(mu)), 0.0)
    no_reach = not (np.any(H) and np.any(E))
    margin = np.inf if no_reach or mu_opt == 0.0 else 1.0 / (np.sqrt(mu_opt) * hh * eh)
    radius = 1.0 if margin > 1.0 else margin / (1.0 + _BACKOFF)
    # Strict certificate at `radius` without a second solve: P^* + eps I (I
    # solves the Lyapunov equation of A^ with a positive definite weight) is
    # strictly feasible for small eps > 0 at any radius below the margin; the
    # LMI gains delta = 1 / (radius hh eh)^2 - mu_opt in its q block. The
    # plant's coordinates with multiplier 1 need P = eh^2 L (P^* + eps I) L'.
    P_val = _cvx.value(P)
    P_opt = 0.5 * (P_val + P_val.T)
    delta = 1.0 / (radius * hh * eh) ** 2 - mu_opt
    candidates = []
    for eps in max(delta, 1e-12) * 10.0 ** -np.arange(7.0):
        P_c = eh**2 * T.P(P_opt + eps * np.eye(n))
        blocks = _stability_blocks(A, H, E, P_c, radius, discrete)
        candidates.append((_relative_min_eig(blocks), P_c, blocks))
    score, P_c, blocks = max(candidates, key=lambda c: c[0])  # the first of the best scores
    cert = {k: _min_eig(M) for k, M in blocks.items()}
    info = {"nominal_radius": nominal, "mu": mu_opt, **_solve_info([rep])}
    return RobustStability(bool(radius == 1.0 and score > _STRICT), float(margin), float(radius), frozen(P_c),
                           MappingProxyType(cert), "norm-bounded", MappingProxyType(info))


def _batched_blocks(A, Hr, E, P, discrete: bool) -> dict[str, np.ndarray]:
    """:func:`_stability_blocks` for stacks (``Hr`` (B, n, p) already scaled by the radius)."""
    return {"P": P, "lyapunov": _blocks(A, Hr, P, E.mT @ E, 1.0, discrete)}


def _verify(blocks: Mapping[str, np.ndarray]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Relative score (smallest of ``lambda_min / max(1, ||M||)`` over the blocks) and smallest eigenvalues."""
    cert, rel = {}, []
    for key, M in blocks.items():
        ev = _hinfnorm.eigvalsh(0.5 * (M + M.mT))
        cert[key] = ev[:, 0]
        rel.append(ev[:, 0] / np.maximum(1.0, np.maximum(np.abs(ev[:, 0]), np.abs(ev[:, -1]))))
    return np.minimum.reduce(rel), cert


def _riccati_certificates(A, H, E, g, peak, discrete: bool):
    """``(radius, P, certificate, verified)`` from the bounded-real Riccati equation (stacks).

    For ``g = ||E (zI - A)^-1 H||_inf`` the target radius is ``r = 1`` if
    ``g < 1`` (margin above 1), else ``r = margin / (1 + 1e-3)``. With
    ``gr = r g`` and ``gamma^2 = (1 + gr^2) / 2`` the stabilising solution
    ``P`` of the Riccati equation of ``(A, r H, [E; sqrt(eps) I])`` at level
    ``gamma`` (:mod:`robustctl.analysis._hinfnorm`) makes the certificate LMI at
    radius ``r`` strictly positive: its Schur complement is
    ``eps I + A'PH_r ((gamma^2 I - H_r'PH_r)^-1 - (I - H_r'PH_r)^-1) H_r'PA``
    (continuous alike), provided the level exceeds the norm of the
    regularised loop: ``eps = (gamma^2 - gr^2) / (4 h^2)`` with ``h`` the
    Frobenius norm of ``(zI - A)^-1 H_r`` at the peak frequency (``H_r`` and
    ``E`` balanced); a design whose ``P`` fails the check is retried with
    ``eps / 100``.
    """
    n = A.shape[-1]
    with np.errstate(divide="ignore"):
        margin = 1.0 / g
    r = np.where(margin > 1.0, 1.0, margin / (1.0 + _BACKOFF))
    Hr = r[:, None, None] * H
    gr = r * g
    gam = np.sqrt(0.5 * (1.0 + gr * gr))
    # H_r and E of equal norms (c): P = c^2 P~ of the balanced problem
    hn, en = np.sqrt((Hr * Hr).sum(axis=(1, 2))), np.sqrt((E * E).sum(axis=(1, 2)))
    reach = (hn > 0) & (en > 0)
    c = np.sqrt(en / hn) if reach.all() else np.where(reach, np.sqrt(en / np.where(reach, hn, 1.0)), 1.0)
    c2 = (c * c)[:, None, None]
    Hb, Eb = Hr * c[:, None, None], E / c[:, None, None]
    z = np.exp(1j * peak) if discrete else 1j * peak
    X = _hinfnorm.solve(z[:, None, None] * np.eye(n) - A, Hb.astype(complex))
    h2 = (X.real ** 2 + X.imag ** 2).sum(axis=(1, 2))
    eps = np.minimum((gam * gam - gr * gr) / (4.0 * np.where(h2 > 0, h2, 1.0)),
                     np.maximum(1.0, (Eb * Eb).sum(axis=(1, 2))))
    eye = np.eye(n)

    def attempt(idx):
        Ea = np.concatenate([Eb[idx], np.sqrt(eps[idx])[:, None, None] * eye], axis=1)
        P, ok = _hinfnorm.bounded_real_riccati(A[idx], Hb[idx], Ea, gam[idx], discrete=discrete)
        P = P * c2[idx]
        ok &= np.isfinite(P).all(axis=(1, 2))
        if ok.all():
            score, cert = _verify(_batched_blocks(A[idx], Hr[idx], E[idx], P, discrete))
            return P, score, cert
        score = np.full(P.shape[0], -np.inf)
        cert = {"P": np.full(P.shape[0], np.nan), "lyapunov": np.full(P.shape[0], np.nan)}
        if ok.any():
            sel = np.flatnonzero(ok) if isinstance(idx, slice) else idx[ok]
            score[ok], cert_ok = _verify(_batched_blocks(A[sel], Hr[sel], E[sel], P[ok], discrete))
            for key, v in cert_ok.items():
                cert[key][ok] = v
        return P, score, cert

    everyone = slice(None)
    P, score, cert = attempt(everyone)
    bad = np.flatnonzero(~(score > _STRICT))
    for _ in range(_EPS_TRIES - 1):
        if not bad.size:
            break
        eps[bad] *= 1e-2
        P2, s2, c2b = attempt(bad)
        up = s2 > score[bad]
        sel = bad[up]
        P[sel], score[sel] = P2[up], s2[up]
        for key in cert:
            cert[key][sel] = c2b[key][up]
        bad = bad[~(s2 > _STRICT)]
    return r, P, cert, score > _STRICT


def _norm_bounded_batch(plant: Plant, K: np.ndarray, unc: NormBounded) -> RobustStabilityBatch:
    """Margins (small-gain values by the level-set H-infinity norm) and Riccati certificates of a stack of gains."""
    discrete = plant.is_discrete
    B, n = K.shape[0], plant.n
    finite = np.isfinite(K).all(axis=(1, 2))
    all_finite = bool(finite.all())
    Kf = K if all_finite else np.where(finite[:, None, None], K, 0.0)
    A = plant.F + plant.G @ Kf
    E = unc.EF + unc.EG @ Kf
    lam = _hinfnorm.eigvals(A)
    nominal, stable = stability_of_eigenvalues(lam, discrete=discrete)
    margin = np.zeros(B)
    if not all_finite:
        stable &= finite
        nominal[~finite] = np.nan
        margin[~finite] = np.nan
    reason = np.where(stable, "ok", "unstable").astype("<U10")
    if not all_finite:
        reason[~finite] = "not finite"
    if stable.all():
        idx = None
        As, Es, lam_s = A, E, lam
    else:
        idx = np.flatnonzero(stable)
        As, Es, lam_s = A[idx], E[idx], lam[idx]
    S = As.shape[0]
    g = peak = np.zeros(0)
    iterations = 0
    Hs = np.broadcast_to(unc.H, (S, *unc.H.shape))
    if S:
        g, peak, iterations = _hinfnorm.hinf_norm(As, Hs, Es, discrete=discrete, poles=lam_s)
        with np.errstate(divide="ignore"):
            m = 1.0 / g
        if idx is None:
            margin = m
        else:
            margin[idx] = m

    def certify() -> tuple:
        radius = np.zeros(B)
        certified = np.zeros(B, dtype=bool)
        path = np.full(B, "", dtype="<U7")
        P = np.full((B, n, n), np.nan)
        cert = {"P": np.full(B, np.nan), "lyapunov": np.full(B, np.nan)}
        sdp = 0
        if S:
            r, Ps, cs, ok = _riccati_certificates(As, Hs, Es, g, peak, discrete)
            how = np.where(ok, "riccati", "")
            for j in np.flatnonzero(~ok):   # rare: the SDP, one design at a time
                sdp += 1
                b = j if idx is None else int(idx[j])
                try:
                    res = _norm_bounded_sdp(plant, Kf[b], unc)
                except (InfeasibleError, ConvergenceError):
                    continue
                if res.P is None:
                    continue
                score, cs_b = _verify(_batched_blocks(As[j:j + 1], (r[j] * unc.H)[None], Es[j:j + 1],
                                                      res.P[None], discrete))
                if score[0] > _STRICT or not np.isfinite(Ps[j]).all():
                    Ps[j] = res.P
                    for key in cs:
                        cs[key][j] = cs_b[key][0]
                    ok[j] = score[0] > _STRICT
                    how[j] = "sdp" if ok[j] else ""
            if idx is None:
                radius, P, cert, path = r, Ps, cs, how
                certified = ok & (r == 1.0)
            else:
                radius[idx], P[idx], path[idx] = r, Ps, how
                for key in cs:
                    cert[key][idx] = cs[key]
                certified[idx] = ok & (r == 1.0)
        info = {"path": _ro(path), "nominal_radius": frozen(nominal), "norm": "level-set",
                "norm_iterations": iterations, "sdp_solves": sdp}
        return (_ro(certified), frozen(radius), frozen(P), MappingProxyType({k: frozen(v) for k, v in cert.items()}),
                MappingProxyType(info))

    return RobustStabilityBatch(frozen(margin), _ro(reason), "norm-bounded", certify)


def _norm_bounded_stability(plant: Plant, K: np.ndarray, unc: NormBounded, *,
                            norm: str = "auto") -> RobustStability:
    """One gain: what :func:`_norm_bounded_batch` does for a stack, on 2-D arrays (less overhead).

    ``norm`` chooses the H-infinity norm (:func:`robustctl.analysis._hinfnorm.norm_one`):
    SLICOT AB13DD when slycot is installed (``"auto"``) or the level-set
    iteration of :mod:`robustctl.analysis._hinfnorm` (``"level-set"``).
    """
    discrete = plant.is_discrete
    n = plant.n
    A = plant.F + plant.G @ K
    H, E = unc.H, unc.EF + unc.EG @ K
    lam = _hinfnorm.eigvals(A[None])[0]
    radius, stable = stability_of_eigenvalues(lam, discrete=discrete)
    nominal = float(radius)
    if not stable:
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "norm-bounded",
                               MappingProxyType({"nominal_radius": nominal}))
    g, peak, iterations, h2, method = _hinfnorm.norm_one(A, H, E, lam, discrete=discrete, method=norm)
    margin = 1.0 / g if g > 0 else math.inf
    r = 1.0 if margin > 1.0 else margin / (1.0 + _BACKOFF)
    gr = r * g
    gam = math.sqrt(0.5 * (1.0 + gr * gr))
    hn2, en2 = r * r * float(np.vdot(H, H)), float(np.vdot(E, E))
    c = (en2 / hn2) ** 0.25 if hn2 > 0 and en2 > 0 else 1.0
    Hb, Eb = (r * c) * H, E / c
    if h2 == 0.0:   # the norm did not evaluate the resolvent (AB13DD, or E = 0): do it at the peak
        z = np.exp(1j * peak) if discrete else 1j * peak
        _, _, X, info = lapack.zgesv(z * _hinfnorm.eye(n) - A, H)
        h2 = float(np.vdot(X, X).real) if info == 0 else 0.0
    h2 *= (r * c) ** 2   # ||(zI - A)^-1 H_b||_F^2 at the peak
    eps = min((gam * gam - gr * gr) / (4.0 * h2 if h2 > 0 else 1.0), max(1.0, en2 / c**2))
    best: tuple = (-np.inf, None, {})
    path = solver = None
    Ea = np.empty((Eb.shape[0] + n, n))
    Ea[:Eb.shape[0]] = Eb
    solvers = ("doubling", "eigenvectors") if n >= _SDA_MIN_N else ("eigenvectors",)
    for _ in range(_EPS_TRIES):
        Ea[Eb.shape[0]:] = math.sqrt(eps) * _hinfnorm.eye(n)
        for solver in solvers:
            if solver == "doubling":
                Pt = _hinfnorm.riccati_doubling(A, Hb, Ea, gam, lam, discrete=discrete)
            else:
                Pt = _hinfnorm.riccati_one(A, Hb, Ea, gam, discrete=discrete)
            if Pt is None:
                continue
            P = (c * c) * Pt
            score, cert = _certify_one(A, r * H, E, P, discrete)
            if score > best[0]:
                best = (score, P, cert)
            if score > _STRICT:
                path = "riccati"
                break
        if path is not None:
            break
        eps *= 1e-2
    if path is None:   # rare: the SDP
        try:
            res = _norm_bounded_sdp(plant, K, unc)
        except (InfeasibleError, ConvergenceError):
            res = None
        if res is not None and res.P is not None:
            scores, certs = _verify(_batched_blocks(A[None], (r * H)[None], E[None], res.P[None], discrete))
            score, cert = float(scores[0]), {key: float(v[0]) for key, v in certs.items()}
            if score > _STRICT or best[1] is None:
                best = (score, res.P, cert)
                path = "sdp" if score > _STRICT else None
    score, P, cert = best
    if P is not None:
        P.flags.writeable = False
    info = {"path": path, "nominal_radius": nominal, "norm_iterations": iterations, "norm": method,
            "riccati": solver if path == "riccati" else None}
    return RobustStability(path is not None and r == 1.0, margin, r, P, MappingProxyType(cert), "norm-bounded",
                           MappingProxyType(info))


def _certify_one(A, Hr, E, P, discrete: bool) -> tuple[float, dict[str, float]]:
    """:func:`_verify` of :func:`_batched_blocks` for one design (``P`` symmetric), with fewer array operations."""
    n, p = A.shape[0], Hr.shape[1]
    M = np.empty((n + p, n + p))
    if discrete:
        PA, PH = P @ A, P @ Hr
        M[:n, :n] = P - A.T @ PA - E.T @ E
        M[n:, :n] = -(Hr.T @ PA)
        M[n:, n:] = _hinfnorm.eye(p) - Hr.T @ PH
    else:
        PA = P @ A
        M[:n, :n] = -(PA + PA.T) - E.T @ E
        M[n:, :n] = -(Hr.T @ P)
        M[n:, n:] = _hinfnorm.eye(p)
    score, cert = np.inf, {}
    for key, S in (("P", P), ("lyapunov", M)):   # dsyevd reads the lower triangle
        w, _, info = lapack.dsyevd(S, compute_v=0, lower=1)
        if info != 0:
            w = np.linalg.eigvalsh(S)
        lo, hi = float(w[0]), float(w[-1])
        cert[key] = lo
        score = min(score, lo / max(1.0, abs(lo), abs(hi)))
    return score, cert


def _polytope_stability(plants: list[Plant], K: np.ndarray) -> RobustStability:
    import cvxpy as cp

    discrete = plants[0].is_discrete
    A0 = plants[0].F + plants[0].G @ K
    D = [p.F + p.G @ K - A0 for p in plants]
    n = A0.shape[0]
    nominal = _radius(A0, discrete)
    if not is_stable(A0, discrete=discrete):
        return RobustStability(False, 0.0, 0.0, None, MappingProxyType({}), "polytope",
                               MappingProxyType({"nominal_radius": nominal}))
    T = _Coordinates(_lyapunov_factor(A0, np.eye(n), discrete))
    Ah0, Dh = T.A(A0), [T.A(Di) for Di in D]
    empty = np.zeros((n, 0))
    reports = []

    def feasible(r: float):
        """``P^`` with every scaled vertex's Lyapunov block >= t I, P^ >= t I, P^ <= I and t > 0, or None."""
        if any(not is_stable(A0 + r * Di, discrete=discrete) for Di in D):
            return None  # a vertex of the scaled polytope is unstable: no solve needed
        P, t = cp.Variable((n, n), symmetric=True, name="P"), cp.Variable(name="t")
        lmis = [_cvx.LMI(f"vertex[{i}]", _block(Ah0 + r * Di, empty, P, np.zeros((n, n)), discrete), t)
                for i, Di in enumerate(Dh)]
        lmis += [_cvx.LMI("P", P, t), _cvx.LMI("P_upper", np.eye(n) - P)]
        try:
            rep = _cvx.solve_sdp(cp.Maximize(t), lmis, infeasible_msg="")
        except (InfeasibleError, ConvergenceError):
            return None
        reports.append(rep)
        P_val = _cvx.value(P)
        return 0.5 * (P_val + P_val.T) if float(_cvx.value(t)) > _POLY_T else None

    if not any(np.any(Di) for Di in D):
        margin, (lo, P_lo) = np.inf, (1.0, np.eye(n))
    else:
        # bracket [lo, hi] (lo certified, hi not), then bisection; conv at r' < r
        # lies inside conv at r because the nominal plant is a vertex
        lo, P_lo, hi = 0.0, np.eye(n), None
        r = 1.0
        while hi is None:
            P_r = feasible(r)
            if P_r is None:
                hi = r
            else:
                lo, P_lo = r, P_r
                if r >= _POLY_RMAX:
                    break
                r = min(2.0 * r, _POLY_RMAX)
        for _ in range(_POLY_STEPS):
            if hi is None or hi - lo <= _POLY_RTOL * hi:
                break
            mid = 0.5 * (lo + hi)
            P_mid = feasible(mid)
            if P_mid is None:
                hi = mid
            else:
                lo, P_lo = mid, P_mid
        margin = lo
    radius = min(lo, 1.0)
    P_c = T.P(P_lo)
    blocks = {"P": P_c}
    for i, Di in enumerate(D):
        blocks[f"vertex[{i}]"] = _block(A0 + radius * Di, empty, P_c, np.zeros((n, n)), discrete)
    score = _relative_min_eig(blocks) if radius > 0 else -np.inf
    cert = {k: _min_eig(M) for k, M in blocks.items()}
    info = {"nominal_radius": nominal, **_solve_info(reports)}
    return RobustStability(bool(radius == 1.0 and score > _STRICT), float(margin), float(radius), frozen(P_c),
                           MappingProxyType(cert), "polytope", MappingProxyType(info))


def robust_stability(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded | None = None, *,
                     vertices: Sequence[Plant] | None = None) -> RobustStability | RobustStabilityBatch:
    r"""Quadratic-stability certificate and margin of ``u = K x`` under norm-bounded or polytopic uncertainty.

    Norm-bounded (``uncertainty``): stability of ``A + H Delta E`` for every
    ``||Delta|| <= r``, ``A = F + G K``, ``E = EF + EG K``, by the
    S-procedure LMI of the module docstring. Its ``margin`` equals the
    small-gain value ``1 / ||E (zI - A)^-1 H||_inf`` (continuous time:
    ``s``), computed by a level-set H-infinity norm (for one gain SLICOT's
    AB13DD when slycot is installed); the certificate ``P`` comes from the
    bounded-real Riccati equation at a level between the norm and 1 and is
    verified by eigenvalues (the SDP is the fallback).
    A stack of gains (B, m, n) is analysed at once (eigenvalue problems on
    (B, 2n, 2n) arrays, one level-set iteration for all); its certificates
    are computed when first asked for (:class:`RobustStabilityBatch`).

    Polytope (``vertices``): a common Lyapunov matrix of
    ``A_i = F_i + G_i K`` for the controller's plant and every vertex
    (``A_i' P A_i < P``, or ``A_i' P + P A_i < 0``), hence stability of every
    (even time-varying) plant in their convex hull. ``margin`` scales the
    polytope about the controller's plant (bisection, one SDP per step).

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) or (B, m, n) array_like)
        The gain ``K`` (``u = K x``) and the nominal plant (discrete if
        ``plant.dt`` is set, else continuous). A stack of ``B`` gains may
        hold non-finite entries: those designs are flagged
        (``reason == "not finite"``, margin NaN), the others answered; a
        single gain must be finite.
    uncertainty : NormBounded, optional
        ``[dF dG] = H Delta [EF EG]``.
    vertices : list of Plant, optional
        Further plants (same ``n``, ``m``, ``dt``); the polytope is the convex
        hull of the controller's plant and these. Give exactly one of
        ``uncertainty`` and ``vertices``. (A stack of gains is analysed
        design by design here: a bisection of SDPs each.)

    Returns
    -------
    RobustStability or RobustStabilityBatch
        ``certified``, ``margin``, ``radius``, ``P`` and its ``certificate``
        for one gain; the same as (B,) arrays (``P`` (B, n, n)) and a
        per-design ``reason`` for a stack. Their ``info`` holds:

        ======================  ===========================  ===================================================
        key                     given for                    value
        ======================  ===========================  ===================================================
        ``"nominal_radius"``    every result                 spectral radius (abscissa) of ``F + G K``;
                                                             (B,) for a stack
        ``"path"``              norm-bounded; every stack    ``"riccati"`` or ``"sdp"``: which computation
                                                             certified ``P`` (None, or ``""`` in a stack, if
                                                             neither passed the check)
        ``"norm"``              norm-bounded                 ``"ab13dd"`` or ``"level-set"``: which computed
                                                             the H-infinity norm
        ``"norm_iterations"``   norm-bounded                 level-set steps (0 for AB13DD)
        ``"riccati"``           norm-bounded, one gain       ``"doubling"`` or ``"eigenvectors"``: how the
                                                             certifying Riccati solution was computed (None
                                                             unless ``path`` is ``"riccati"``)
        ``"sdp_solves"``        every stack                  designs that needed the SDP
        ``"solve_time"``        polytope, one gain           solver time of the bisection's SDPs [s]
        ``"iterations"``        polytope, one gain           their interior-point iterations
        ``"solves"``            polytope, one gain           one report per SDP (status, value, solver, tol,
                                                             solve_time, iterations, certificate)
        ======================  ===========================  ===================================================

        A single gain whose nominal loop is unstable gets
        ``"nominal_radius"`` only (margin 0, ``P`` None).

    Raises
    ------
    ValueError
        Both or neither of ``uncertainty`` and ``vertices``; sizes that do
        not match the plant (named); a single gain with non-finite entries;
        a polytope without a vertex besides the controller's plant.
    TypeError
        ``controller`` neither a Controller nor ``(Plant, K)``; an
        uncertainty that is not a NormBounded, vertices that are not plants.

    See Also
    --------
    worst_case : a destabilising ``Delta``, the lower side of the margin.
    guaranteed_cost : a cost bound for every admissible ``Delta``.
    robustctl.margins_report : margins and certificates of several controllers.

    Notes
    -----
    With ``A = F + G K``, ``E = EF + EG K`` and the S-procedure on
    ``q = Delta E x`` (lossless for one full block [1]_), the loop is
    quadratically stable for every ``||Delta|| <= r`` iff some ``P > 0`` has
    (discrete time)

    .. math::

        \begin{bmatrix} P - A^T P A - E^T E & -r A^T P H \\
                        -r H^T P A & I - r^2 H^T P H \end{bmatrix} \succ 0 ,

    (continuous time: ``-(A'P + PA) - E'E`` and ``-r PH``, ``I`` in the
    blocks). By the bounded-real lemma this holds iff ``A`` is stable and
    ``r ||E (zI - A)^-1 H||_inf < 1`` [2]_, so

    .. math::

        \text{margin} = \frac{1}{\|E (zI - A)^{-1} H\|_\infty},

    computed by a level-set iteration on the imaginary-axis eigenvalues of a
    Hamiltonian [3]_ (SLICOT's AB13DD for one gain with slycot). A polytope
    ``conv{A_i}`` is certified by one ``P`` with ``A_i' P A_i - P < 0`` (or
    ``A_i' P + P A_i < 0``) at every vertex [1]_.

    References
    ----------
    .. [1] S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix
       Inequalities in System and Control Theory*, SIAM 1994, Sec. 5.1.
    .. [2] P. P. Khargonekar, I. R. Petersen, K. Zhou, "Robust stabilization
       of uncertain linear systems: quadratic stabilizability and
       H-infinity control theory", IEEE Trans. Automatic Control 35(3),
       356-361, 1990.
    .. [3] N. A. Bruinsma, M. Steinbuch, "A fast algorithm to compute the
       H-infinity-norm of a transfer function matrix", Systems & Control
       Letters 14(4), 287-293, 1990.

    Examples
    --------
    An LQR of the paper's truck against ``dG = G Delta 0.1``,
    ``dF = G Delta [0.1, 0, 0, 0]``; the margin is the reciprocal of the peak
    of ``|E (z I - A)^-1 H|`` on the unit circle (here on a fine grid), and
    the same gain is quadratically stable over the 0-300 % payload polytope:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    >>> res = rc.robust_stability(ctrl, unc)
    >>> res.certified, round(res.margin, 4)
    (True, 4.0359)
    >>> A, H, E = ctrl.closed_loop(), unc.H, unc.EF + unc.EG @ ctrl.K
    >>> z = np.exp(1j * np.linspace(0.0, np.pi, 20001))[:, None, None]
    >>> peak = np.abs(E @ np.linalg.solve(z * np.eye(4) - A, H)).max()
    >>> bool(abs(res.margin * peak - 1.0) < 1e-4)
    True
    >>> rc.robust_stability(ctrl, vertices=[truck_plant(300.0)]).certified
    True

    A stack of gains is answered at once; a gain that destabilises the
    nominal loop is flagged, and the others' margins agree with
    python-control's ``linfnorm``:

    >>> import control
    >>> gains = np.stack([ctrl.K, 2.0 * ctrl.K, 50.0 * ctrl.K])
    >>> batch = rc.robust_stability((plant, gains), unc)
    >>> batch.reason.tolist(), batch.certified.tolist()
    (['ok', 'ok', 'unstable'], [True, True, False])
    >>> ref = [1.0 / control.linfnorm(control.ss(plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K, 0, 0.1))[0]
    ...        for K in gains[:2]]
    >>> bool(np.allclose(batch.margin[:2], ref, rtol=1e-8))
    True
    """
    if (uncertainty is None) == (vertices is None):
        raise ValueError("give exactly one of uncertainty (a NormBounded) and vertices (a list of Plant)")
    if vertices is not None:
        plant, K = _loop(controller, batch=True)
        base = _controller_plant(controller)
        # a polytope needs a vertex besides the nominal plant
        plants = check_vertices(base, vertices, reference="the controller's plant", non_empty=True)
        plants = [plant, *(_augmented_plant(v, plant.n - base.n) for v in plants[1:])]
        if K.ndim == 2:
            return _polytope_stability(plants, K)
        return _polytope_batch(plants, K)
    plant, K, unc = _uncertain_loop(controller, uncertainty, batch=True)
    if K.ndim == 2:
        return _norm_bounded_stability(plant, K, unc)
    return _norm_bounded_batch(plant, K, unc)


def _polytope_batch(plants: list[Plant], K: np.ndarray) -> RobustStabilityBatch:
    """The polytope test design by design (a bisection of SDPs each), assembled like the norm-bounded batch."""
    B, n = K.shape[0], plants[0].n
    out = {"certified": np.zeros(B, dtype=bool), "margin": np.full(B, np.nan), "radius": np.zeros(B)}
    P = np.full((B, n, n), np.nan)
    cert = {f"vertex[{i}]": np.full(B, np.nan) for i in range(len(plants))}
    cert = {"P": np.full(B, np.nan), **cert}
    reason = np.full(B, "not finite", dtype=object)
    nominal = np.full(B, np.nan)
    path = np.full(B, "", dtype=object)
    for b in range(B):
        if not np.isfinite(K[b]).all():
            continue
        res = _polytope_stability(plants, K[b])
        out["certified"][b], out["margin"][b], out["radius"][b] = res.certified, res.margin, res.radius
        nominal[b] = res.info["nominal_radius"]
        reason[b] = "ok" if res.P is not None else "unstable"
        if res.P is not None:
            P[b] = res.P
            path[b] = "sdp"
            for key, v in res.certificate.items():
                cert[key][b] = v
    info = {"path": _ro(path.astype(str)), "nominal_radius": frozen(nominal), "sdp_solves": int((path == "sdp").sum())}
    bundle = (_ro(out["certified"]), frozen(out["radius"]), frozen(P),
              MappingProxyType({k: frozen(v) for k, v in cert.items()}), MappingProxyType(info))
    return RobustStabilityBatch(frozen(out["margin"]), _ro(reason.astype(str)), "polytope", lambda: bundle)
