r"""Numerical kernels of :func:`robustctl.loop_margins` on stacks of loop transfers (private).

Every function works on stacks: ``A`` (K, n, n), ``B`` (K, n, m), ``C``
(K, m, n), ``D`` (K, m, m), one loop per row, with batched ``np.linalg``
calls and no Python loop over the rows.

* :func:`sensitivity`: the realisation of ``S = (I + L)^-1``.
* :func:`classical`: the crossings of a SISO ``S`` (below) and the classical
  gain and phase margins of ``l = 1 / S - 1``.
* :func:`mu_upper`: the D-scaled upper bound of the structured singular
  value for diagonal complex perturbations; :func:`mu_peak` its peak over
  frequency.

Crossings without a frequency grid. With ``S(s) = d + c (sI - A)^-1 b``
(real data), ``l`` is real where ``Im S(jw) = 0`` and ``|l| = 1`` where
``Re S(jw) = 1/2`` (``|1 - S| = |S|``). On the imaginary axis
``S(-jw) = conj S(jw)``, so these are the imaginary-axis zeros of

    Phi(s) = S(s) - S(-s)      (A2, b2, c2, d2) = (diag(A, -A), [b; b], [c,  c], 0)
    Psi(s) = S(s) + S(-s) - 1  (A2, b2, c2, d2) = (diag(A, -A), [b; b], [c, -c], 2d - 1)

(``S(-s) = d - c (sI + A)^-1 b``). The zeros of ``(A2, b2, c2, d2)`` are
the finite generalised eigenvalues ``lambda`` of the pencil
``([[A2, b2], [c2, d2]], diag(I, 0))``; with a real shift ``sigma`` they
are ``lambda = sigma + 1 / mu`` for the eigenvalues ``mu != 0`` of the
leading ``2n x 2n`` block of ``([[A2, b2], [c2, d2]] - sigma diag(I, 0))^-1``
(the infinite ones give ``mu = 0``). Those near the imaginary axis are
polished by Newton's method on ``Im S(jw)`` or ``Re S(jw) - 1/2`` and kept
where it converges to a root. A discrete loop is first mapped to a
continuous one by the bilinear transform ``z = (1 + s) / (1 - s)``
(:func:`robustctl.analysis._hinfnorm._cayley`; values unchanged,
``theta = 2 arctan w``).
"""

from __future__ import annotations

import contextlib

import numpy as np

from . import _hinfnorm

# Candidates: zeros with |Re| <= _NEAR (|lambda| + 1e-3 scale) go to Newton's method (false ones are rejected there).
_NEAR = 1e-3
# Newton steps on a crossing, and the residual (relative to 1 + |S|) at which a crossing is accepted.
_NEWTON = 4
_RESIDUAL = 1e-9
# The shift of the pencil, in units of the row's scale (any number that is not a zero will do).
_SHIFT = 0.6180339887498949
# Golden-section steps of the peak refinement (the bracket shrinks by 0.618 a step), and rounds of its check.
_GOLDEN = 45
_CHECKS = 3
# D-scaling for three loops or more: the powers p of the smoothed bound and the descent steps for each.
_POWERS = (4, 32, 256, 2048)
_DESCENT = 25


def sensitivity(A, B, C, D):
    """``(A_S, B_S, C_S, D_S, posed)``: ``S = (I + L)^-1`` of ``L = (A, B, C, D)``.

    ``A_S = A - B E^-1 C``, ``B_S = B E^-1``, ``C_S = -E^-1 C``,
    ``D_S = E^-1`` with ``E = I + D``; ``posed`` (K,) is False where ``E``
    is singular (an ill-posed loop: those rows get ``E = I``).
    """
    m = D.shape[-1]
    E = np.eye(m) + D
    sv = np.linalg.svd(E, compute_uv=False)
    posed = sv[:, -1] > 1e-12 * np.maximum(sv[:, 0], 1.0)
    Ei = np.linalg.inv(np.where(posed[:, None, None], E, np.eye(m)))
    return A - B @ Ei @ C, B @ Ei, -(Ei @ C), Ei, posed


def solve(M, rhs):
    """``np.linalg.solve`` on stacks, with NaN for the singular systems instead of an error for all."""
    try:
        return np.linalg.solve(M, rhs)
    except np.linalg.LinAlgError:
        rhs = np.broadcast_to(rhs, (*M.shape[:-1], rhs.shape[-1]))
        out = np.full(rhs.shape, np.nan, dtype=np.result_type(M, rhs))
        for i in np.ndindex(M.shape[:-2]):
            with contextlib.suppress(np.linalg.LinAlgError):
                out[i] = np.linalg.solve(M[i], rhs[i])
        return out


def response(A, B, C, D, points):
    """``D + C (pI - A)^-1 B`` at complex ``points`` (K, r): (K, r, l, p); NaN at a pole."""
    n = A.shape[-1]
    if n == 0:
        return np.broadcast_to(D[:, None], (*points.shape, *D.shape[1:])).astype(complex)
    M = points[:, :, None, None] * np.eye(n) - A[:, None]
    X = solve(M, np.broadcast_to(B[:, None], (*points.shape, *B.shape[1:])).astype(complex))
    return D[:, None] + C[:, None] @ X


# ---------------------------------------------------------------- crossings (SISO rows)
def _axis_zeros(A2, b2, c2, d2):
    """``|Im lambda|`` (K, N) of the zeros of ``(A2, b2, c2, d2)`` near the imaginary axis; NaN elsewhere."""
    K, N = A2.shape[:2]
    scale = np.maximum(np.sqrt((A2 * A2).sum(axis=(1, 2)) / N), 1e-300)
    M = np.zeros((K, N + 1, N + 1))
    M[:, :N, :N] = A2
    M[:, :N, N:] = b2
    M[:, N:, :N] = c2
    M[:, N, N] = d2
    X = np.full((K, N + 1, N), np.nan)
    sigma = np.zeros(K)
    todo = np.arange(K)
    for shift in (_SHIFT, -1.37 * _SHIFT, 2.71 * _SHIFT):      # a shift on a zero makes the matrix singular
        sigma[todo] = shift * scale[todo]
        Ms = M[todo]
        Ms[:, np.arange(N), np.arange(N)] -= sigma[todo, None]
        X[todo] = solve(Ms, np.eye(N + 1, N))
        todo = todo[~np.isfinite(X[todo]).all(axis=(1, 2))]
        if not todo.size:
            break
    fine = np.isfinite(X).all(axis=(1, 2))    # a row singular for every shift: Phi = 0 (l = 0), no crossing
    mu = np.zeros((K, N), dtype=complex)
    if fine.any():
        mu[fine] = _hinfnorm.eigvals(X[fine, :N, :])
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = sigma[:, None] + 1.0 / mu
    mag = np.abs(lam)
    near = np.isfinite(lam) & (mag < 1e8 * scale[:, None]) \
        & (np.abs(lam.real) <= _NEAR * (mag + 1e-3 * scale[:, None]))
    return np.where(near, np.abs(lam.imag), np.nan)


def _newton(A, b, c, d, w, real_part: bool):
    """Roots of ``f(w) = Im S(jw)`` (``real_part``: ``Re S(jw) - 1/2``) polished from ``w`` (K, r); NaN if none."""
    n = A.shape[-1]
    valid = np.isfinite(w)
    W = np.where(valid, w, 0.0)
    I = np.eye(n)
    step = np.zeros_like(W)
    for _ in range(_NEWTON):
        M = 1j * W[:, :, None, None] * I - A[:, None]
        X = solve(M, np.broadcast_to(b[:, None], (*W.shape, n, 1)).astype(complex))
        Y = solve(M, X)
        S = (d[:, None] + c[:, None] @ X)[..., 0, 0]
        dS = (-1j * (c[:, None] @ Y))[..., 0, 0]                     # dS/dw
        f, fp = (S.real - 0.5, dS.real) if real_part else (S.imag, dS.imag)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(fp != 0.0, f / fp, np.inf)
        valid &= np.isfinite(step)   # NaN at a pole of S
        W = np.where(valid, np.abs(W - step), 0.0)                   # f is even or odd in w
    S = response(A, b, c, d, 1j * W)[..., 0, 0]
    f = S.real - 0.5 if real_part else S.imag
    ok = valid & (np.abs(f) <= _RESIDUAL * (1.0 + np.abs(S))) & (np.abs(step) <= 1e-6 * (W + 1.0))
    return np.where(ok, W, np.nan)


def crossings(A, b, c, d, *, discrete: bool):
    """Frequencies (K, r) where ``Im S = 0`` and where ``Re S = 1/2`` (NaN-padded; ``theta`` if ``discrete``).

    ``Im S = 0`` always holds at ``w = 0`` (and ``theta = pi``): those are
    included. ``A`` (K, n, n), ``b`` (K, n, 1), ``c`` (K, 1, n), ``d`` (K, 1, 1).
    """
    K, n = A.shape[:2]
    ends = np.array([0.0, np.pi]) if discrete else np.array([0.0])
    ends = np.broadcast_to(ends, (K, ends.size))
    if n == 0:
        return ends.copy(), np.full((K, 1), np.nan)
    flip = None
    if discrete:   # transform the better conditioned of (A, b, c, d) and (-A, b, -c, d): A + I or I - A
        smin = np.linalg.svd(np.stack([A + np.eye(n), np.eye(n) - A]), compute_uv=False)[..., -1]
        flip = smin[1] > smin[0]
        A, b, c, d = _hinfnorm._cayley(A, b, c, flip, d)
    A2 = np.zeros((2 * K, 2 * n, 2 * n))
    A2[:, :n, :n] = np.concatenate([A, A])
    A2[:, n:, n:] = -np.concatenate([A, A])
    b2 = np.concatenate([b, b], axis=1)
    b2 = np.concatenate([b2, b2])
    c2 = np.concatenate([np.concatenate([c, c], axis=2), np.concatenate([c, -c], axis=2)])
    d2 = np.concatenate([np.zeros(K), 2.0 * d[:, 0, 0] - 1.0])
    w = _axis_zeros(A2, b2, c2, d2)
    w_imag = _newton(A, b, c, d, w[:K], real_part=False)
    w_half = _newton(A, b, c, d, w[K:], real_part=True)
    if discrete:
        w_imag, w_half = (_theta(x, flip) for x in (w_imag, w_half))
    return np.concatenate([ends, w_imag], axis=1), w_half


def _theta(w, flip):
    """Angles of the transformed frequencies ``w`` (K, r) (:func:`crossings`)."""
    phi = 2.0 * np.arctan(w)
    return np.where(flip[:, None], np.pi - phi, phi)


def classical(A, b, c, d, *, discrete: bool):
    """Classical margins of the SISO loops ``l = 1 / S - 1`` for ``S = (A, b, c, d)`` (stacks).

    Returns ``(gain_margin, gm_freq, phase_margin, pm_freq)``, (K,) each, as
    :func:`control.stability_margins` picks them: the gain margin
    ``1 / |l|`` at the real-axis crossing with ``l <= 0`` closest to 1 in
    ``|log|``; the phase margin ``angle(l) mod 360 - 180`` (degrees) at the
    unit-gain crossing (``w > 0``) smallest in absolute value; ``inf`` with
    frequency NaN where there is none. Frequencies are ``theta`` (rad per
    sample) if ``discrete``.
    """
    K = A.shape[0]
    w_real, w_half = crossings(A, b, c, d, discrete=discrete)
    rows = np.arange(K)

    def at(w):
        pts = np.exp(1j * np.nan_to_num(w)) if discrete else 1j * np.nan_to_num(w)
        return response(A, b, c, d, pts)[..., 0, 0]

    with np.errstate(divide="ignore", invalid="ignore"):
        S = at(w_real)
        l = 1.0 / S - 1.0
        real = np.isfinite(w_real) & np.isfinite(l) & (l.real <= 0.0)
        gm = np.where(real, 1.0 / np.abs(l), np.nan)
        key = np.where(real & np.isfinite(np.log(gm)), np.abs(np.log(gm)), np.inf)
        k = np.argmin(key, axis=1)
        found = np.isfinite(key[rows, k])
        gain_margin = np.where(found, gm[rows, k], np.inf)
        gm_freq = np.where(found, w_real[rows, k], np.nan)
        S = at(w_half)
        l = 1.0 / S - 1.0
        pm = np.remainder(np.angle(l, deg=True), 360.0) - 180.0
        valid = np.isfinite(w_half) & (w_half > 0.0) & np.isfinite(pm)
        key = np.where(valid, np.abs(pm), np.inf)
    k = np.argmin(key, axis=1)
    found = np.isfinite(key[rows, k])
    phase_margin = np.where(found, pm[rows, k], np.inf)
    pm_freq = np.where(found, w_half[rows, k], np.nan)
    return gain_margin, gm_freq, phase_margin, pm_freq


# ---------------------------------------------------------------- structured singular value
def mu_upper(M):
    """Upper bound ``min_D sigma_max(D M D^-1)`` over positive diagonal ``D``, and ``log D``, of a stack (..., m, m).

    One loop: ``|M|``. Two: exact (below). Three or more: the Frobenius
    (Osborne) scaling refined by :func:`_descent` on
    ``log sigma_max(e^x M e^-x)``, which is convex in ``x`` (Sezginer &
    Overton 1990). The bound is ``sigma_max(e^x M e^-x)`` at the returned
    ``x``: an upper bound of mu whatever the accuracy of the minimisation.

    For two loops, ``sigma_max(N)^2 = (|N|_F^2 + sqrt(|N|_F^4 - 4 |det M|^2)) / 2``
    for ``N = D M D^-1`` grows with ``|N|_F``, which is smallest at
    ``d_1 / d_2 = sqrt(|m21| / |m12|)``: the bound is
    ``(F + sqrt(F^2 - 4 |det M|^2)) / 2`` with
    ``F = |m11|^2 + |m22|^2 + 2 |m12 m21|``.
    """
    m = M.shape[-1]
    shape = M.shape[:-2]
    if m == 1:
        return np.abs(M[..., 0, 0]), np.zeros((*shape, 1))
    a2 = M.real ** 2 + M.imag ** 2
    if m == 2:
        F = a2[..., 0, 0] + a2[..., 1, 1] + 2.0 * np.sqrt(a2[..., 0, 1] * a2[..., 1, 0])
        det = M[..., 0, 0] * M[..., 1, 1] - M[..., 0, 1] * M[..., 1, 0]
        disc = np.maximum(F * F - 4.0 * (det.real ** 2 + det.imag ** 2), 0.0)
        with np.errstate(divide="ignore"):
            x0 = np.clip(0.25 * (np.log(a2[..., 1, 0]) - np.log(a2[..., 0, 1])), -30.0, 30.0)
        x = np.stack([np.nan_to_num(x0), np.zeros(shape)], axis=-1)
        return np.sqrt(0.5 * (F + np.sqrt(disc))), x
    x = _osborne(a2)
    return _descent(M, x)


def _scaled(M, x):
    return M * np.exp(x[..., :, None] - x[..., None, :])


def _osborne(a2, sweeps: int = 8):
    """``log D`` minimising ``|D M D^-1|_F`` (coordinate minimisation), from ``|M|^2`` (..., m, m)."""
    m = a2.shape[-1]
    off = a2 * (1.0 - np.eye(m)) + 1e-300
    x = np.zeros(a2.shape[:-1])
    for _ in range(sweeps):
        for k in range(m):
            e = np.exp(2.0 * x)
            R = (off[..., k, :] / e).sum(axis=-1)       # row k: |m_kj|^2 e^(-2 x_j)
            Cc = (off[..., :, k] * e).sum(axis=-1)      # column k: |m_ik|^2 e^(2 x_i)
            x[..., k] = 0.25 * np.log(Cc / R)
        x -= x[..., -1:]
    return np.clip(x, -30.0, 30.0)


def _smoothed(M, x, p: int):
    """``(log tr((N*N)^p) / 2p, gradient)`` at ``N = e^x M e^-x`` (``p`` a power of 2; products normalised)."""
    N = _scaled(M, x)
    H, G = N.conj().mT @ N, N @ N.conj().mT
    logt = np.zeros(H.shape[:-2])
    k = 1
    while True:
        t = np.trace(H, axis1=-2, axis2=-1).real
        logt = 2.0 * logt + np.log(t)
        H, G = H / t[..., None, None], G / t[..., None, None]
        if k == p:
            break
        H, G = H @ H, G @ G
        k *= 2
    # d/dx_i tr((N*N)^p) = 2p ((NN*)^p - (N*N)^p)_ii; H and G are those powers over their trace
    grad = np.diagonal(G, axis1=-2, axis2=-1).real - np.diagonal(H, axis1=-2, axis2=-1).real
    return logt / (2.0 * p), grad


def _descent(M, x):
    """Minimise ``sigma_max(e^x M e^-x)`` from ``x``: ``(bound, x)``.

    ``log sigma_max`` is convex but not smooth at its minimum (the largest
    singular value is repeated there); its smooth upper approximations
    ``log tr((N*N)^p) / 2p`` (within ``log(m) / 2p``) are minimised in turn
    for growing ``p`` by BFGS with a backtracking (Armijo) line search, each
    row on its own, and the bound is ``sigma_max`` at the best ``x`` met.
    """
    m = M.shape[-1]
    best = np.linalg.svd(_scaled(M, x), compute_uv=False)[..., 0]
    best_x = x
    for p in _POWERS:
        f, g = _smoothed(M, x, p)
        H = np.broadcast_to(np.eye(m), (*f.shape, m, m)).copy()
        for _ in range(_DESCENT):
            d = -(H @ g[..., None])[..., 0]
            slope = (g * d).sum(axis=-1)
            t = np.ones(f.shape)
            done = ~(slope < -1e-15)               # converged (or no descent direction): stay
            if done.all():
                break
            xn, fn, gn = x, f, g
            for _ in range(30):
                xt = x + t[..., None] * d
                ft, gt = _smoothed(M, xt, p)
                ok = ~done & (ft <= f + 1e-4 * t * slope)
                xn = np.where(ok[..., None], xt, xn)
                fn, gn = np.where(ok, ft, fn), np.where(ok[..., None], gt, gn)
                done |= ok
                if done.all():
                    break
                t = np.where(done, t, 0.5 * t)
            sv, yv = xn - x, gn - g
            sy = (sv * yv).sum(axis=-1)
            upd = sy > 1e-300
            rho = np.where(upd, 1.0 / np.where(upd, sy, 1.0), 0.0)[..., None, None]
            V = np.eye(m) - rho * (sv[..., :, None] * yv[..., None, :])
            H = np.where(upd[..., None, None], V @ H @ V.mT + rho * (sv[..., :, None] * sv[..., None, :]), H)
            x, f, g = xn, fn, gn
        s = np.linalg.svd(_scaled(M, x), compute_uv=False)[..., 0]
        up = s < best
        best, best_x = np.where(up, s, best), np.where(up[..., None], x, best_x)
    return best, best_x


def _bilinear(A, B, C, D, ws):
    """``G(ws (z - 1) / (z + 1))`` of continuous stacks: the frequency ``w`` goes to ``theta = 2 arctan(w / ws)``."""
    n = A.shape[-1]
    I = np.eye(n)
    Mi = np.linalg.inv(ws[:, None, None] * I - A)
    r = np.sqrt(2.0 * ws)[:, None, None]
    return (ws[:, None, None] * I + A) @ Mi, r * (Mi @ B), r * (C @ Mi), D + C @ Mi @ B


def _grid(lam, discrete: bool, extra):
    """Sweep angles (K, G) in ``[0, pi]``: uniform, log-spaced over the poles' range, the poles' own and ``extra``."""
    K = lam.shape[0]
    uniform = np.broadcast_to(np.linspace(0.0, np.pi, 65), (K, 65))
    mod = np.abs(np.log(lam)) if discrete else np.abs(lam)
    mod = np.where(mod > 0, mod, np.nan)
    lo, hi = np.nanmin(mod, axis=1, initial=np.inf), np.nanmax(mod, axis=1, initial=-np.inf)
    lo = np.where(np.isfinite(lo), lo, 1.0)
    hi = np.where(np.isfinite(hi), hi, 1.0)
    u = np.linspace(0.0, 1.0, 160)
    logw = np.log(lo / 100.0)[:, None] + u * np.log(1e4 * hi / lo)[:, None]
    if discrete:
        spread = np.minimum(np.exp(logw), np.pi)
        poles = np.abs(np.angle(lam))
        ws = None
    else:
        ws = np.sqrt(lo * hi)
        spread = 2.0 * np.arctan(np.exp(logw) / ws[:, None])
        poles = 2.0 * np.arctan(np.abs(lam.imag) / ws[:, None])
        extra = 2.0 * np.arctan(extra / ws[:, None])
    theta = np.sort(np.concatenate([uniform, spread, poles, np.nan_to_num(extra, nan=0.0)], axis=1), axis=1)
    return theta, ws


def _golden(value, theta, f, t, rows):
    """Golden-section search of ``value`` between the grid points ``theta`` next to ``t`` (per row), from ``(f, t)``."""
    lo = np.where(theta < t[:, None], theta, 0.0).max(axis=1)
    hi = np.where(theta > t[:, None], theta, np.pi).min(axis=1)
    g = 0.5 * (np.sqrt(5.0) - 1.0)
    a, b = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fb = value(a[:, None], rows)[0][:, 0], value(b[:, None], rows)[0][:, 0]
    for _ in range(_GOLDEN):
        left = fa >= fb          # the maximum is in [lo, b]
        hi = np.where(left, b, hi)
        lo = np.where(left, lo, a)
        new = np.where(left, hi - g * (hi - lo), lo + g * (hi - lo))
        fn = value(new[:, None], rows)[0][:, 0]
        a, b, fa, fb = (np.where(left, new, b), np.where(left, a, new),
                        np.where(left, fn, fb), np.where(left, fa, fn))
    for tt, ff in ((a, fa), (b, fb)):
        up = ff > f
        f, t = np.where(up, ff, f), np.where(up, tt, t)
    return f, t


def mu_peak(A, B, C, D, *, discrete: bool, lam, extra):
    """Peak over frequency of :func:`mu_upper` of ``D + C (sI - A)^-1 B`` (stable stacks, square).

    A sweep (:func:`_grid`; ``extra`` (K, e) frequencies to include, e.g.
    the loop-at-a-time peaks) refined by golden-section search between the
    neighbours of its largest value. The peak is then checked with the
    scaling ``D*`` found there: ``||D* M D*^-1||_inf`` (level sets) bounds
    the bound at every frequency; where it exceeds the peak, the bound is
    evaluated at its peak frequency and refined there if larger (a peak the
    sweep stepped over), for up to ``_CHECKS`` rounds.

    Returns ``(peak, freq)``, (K,) each: ``freq`` is ``w`` (``inf``
    allowed) or ``theta`` if ``discrete``. Where the constant scaling
    confirms the peak (to ``1e-9``), no frequency has a larger bound; where
    it does not, the scaling varies with frequency and no larger bound was
    found at the frequency it points to. Continuous loops are swept on the
    unit circle after the bilinear map :func:`_bilinear` (``w = ws tan(theta
    / 2)``, ``ws`` the geometric mean of the smallest and largest pole
    moduli), which includes ``w = inf``.
    """
    K = A.shape[0]
    theta, ws = _grid(lam, discrete, extra)
    if not discrete:
        A, B, C, D = _bilinear(A, B, C, D, ws)

    def value(t, rows=slice(None)):
        return mu_upper(response(A[rows], B[rows], C[rows], D[rows], np.exp(1j * t)))

    mu = value(theta)[0]
    rows = np.arange(K)
    k = np.argmax(mu, axis=1)
    best, at = _golden(value, theta, mu[rows, k], theta[rows, k], rows)
    todo = rows
    for _ in range(_CHECKS):
        e = np.exp(value(at[todo, None], todo)[1][:, 0])
        norm, where, _ = _hinfnorm.hinf_norm(A[todo], B[todo] / e[:, None, :], e[:, :, None] * C[todo],
                                             discrete=True, D=e[:, :, None] * D[todo] / e[:, None, :])
        ok = norm <= best[todo] * (1.0 + 1e-9)
        todo, where = todo[~ok], where[~ok]
        if not todo.size:
            break
        f, t = _golden(value, theta[todo], value(where[:, None], todo)[0][:, 0], where, todo)
        up = f > best[todo]
        best[todo[up]], at[todo[up]] = f[up], t[up]
        todo = todo[up]          # no larger bound found: the constant scaling is only conservative there
        if not todo.size:
            break
    if discrete:
        return best, at
    with np.errstate(over="ignore"):
        return best, np.where(at >= np.pi, np.inf, ws * np.tan(0.5 * at))
