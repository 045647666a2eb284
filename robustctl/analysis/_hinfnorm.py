r"""Batched H-infinity norm and bounded-real Riccati solutions of stable loops (private).

For stacks of stable realisations ``G_b(s) = C_b (sI - A_b)^-1 B_b``
(continuous time) or ``G_b(z) = C_b (zI - A_b)^-1 B_b`` (discrete time),
``b = 0..B-1``, of one state size, everything below works on the whole
stack at once: eigenvalues of (B, 2n, 2n) arrays, solves on (B, k, n, n)
arrays, no Python loop over the stack.

Norm: level-set iteration (Bruinsma & Steinbuch 1990; Boyd, Balakrishnan &
Kabamba 1989). For ``gamma > sigma_max(D)`` the Hamiltonian (``R = gamma^2
I - D'D``)::

    M(gamma) = [ A + B R^-1 D'C               B R^-1 B'               ]
               [ -C'(I + D R^-1 D')C         -(A + B R^-1 D'C)'       ]

has the eigenvalue ``j w`` iff ``gamma`` is a singular value of ``G(jw)``.
Starting from the largest ``sigma_max`` at ``w = 0``, at the modulus of the
most lightly damped pole (discrete time: ``z = 1``, ``z = -1`` and the
angle of the complex pole nearest the unit circle), each step takes the imaginary
eigenvalues of ``M((1 + 2 tol) g)``, evaluates ``sigma_max`` at the
midpoints of consecutive ones and raises the lower bound ``g`` to the
largest value found; no imaginary eigenvalue means
``g <= ||G||_inf <= (1 + 2 tol) g`` (convergence is quadratic). Designs
that have converged leave the stack.

Discrete time is mapped to continuous time by the bilinear (Cayley)
transform ``z = (1 + s) / (1 - s)``::

    Ac = (A + I)^-1 (A - I),  Bc = sqrt(2) (A + I)^-1 B,
    Cc = sqrt(2) C (A + I)^-1,  Dc = -C (A + I)^-1 B

which maps the unit circle onto the imaginary axis (``w = tan(theta / 2)``)
and keeps the norm and the storage function. Where ``sigma_max(G(-1))``
exceeds ``sigma_max(G(1))`` the loop ``(-A, B, -C)`` (the same norm,
``z -> -z``) is transformed instead, so that ``Dc`` is the smaller of the
two and ``R = gamma^2 I - Dc'Dc`` stays far from singular near the peak.
A feedthrough ``D`` (:func:`hinf_norm` takes one) enters ``M(gamma)`` as
above; in continuous time the level set starts from ``sigma_max(D)`` (the
gain at ``w = inf``) too, and where that exceeds ``sigma_max(G(0))`` it runs
on ``G(1/s)``, realised by ``(A^-1, A^-1 B, -C A^-1, D - C A^-1 B)`` (the
same singular values at ``w`` and ``1 / w``, feedthrough ``G(0)``), for the
same reason as the flip. For the Riccati equation: the stabilising solution of
the continuous bounded-real Riccati equation of ``(Ac, Bc, Cc, Dc)`` is the
stabilising solution ``P`` of the discrete one,
``P = A'PA + C'C + A'PB (gamma^2 I - B'PB)^-1 B'PA``. ``A + I`` is
invertible for a Schur-stable ``A``. The singular values of a discrete
loop are evaluated on its original realisation (at ``z = exp(j theta)``),
those of an inverted continuous one on ``G(1/s)``.

Riccati: the stabilising solution at a level ``gamma > ||G||_inf`` is
``P = X2 X1^-1`` from the ``n`` eigenvectors ``[X1; X2]`` of ``M(gamma)``
with negative real parts (continuous:
``A'P + PA + C'C + PBB'P / gamma^2 = 0``). The caller verifies it.

One loop of larger state size: the structure-preserving doubling algorithm
(SDA; Chu, Fan & Lin 2005) instead, which works on ``n x n`` matrices
only. A discrete equation in the form ``P = Q + A'P(I + GP)^-1 A`` (here
``G = -BB' / gamma^2``, ``Q = C'C``) is solved by::

    W = I + G_k H_k,  A_k+1 = A_k W^-1 A_k,  G_k+1 = G_k + A_k W^-1 G_k A_k',
    H_k+1 = H_k + A_k' H_k W^-1 A_k

from ``(A, G, Q)``; ``H_k`` converges quadratically to the stabilising
solution. A continuous equation is first mapped to a discrete one by the
bilinear transform ``z = (a + s) / (a - s)`` (``a`` the geometric mean of
the smallest and largest pole moduli; the solution is unchanged), whose
feedthrough ``D = C (aI - A)^-1 B`` is absorbed as in ``M(gamma)``.

One loop: :func:`hinf_norm_one` and :func:`riccati_one` do the same on
2-D arrays and call LAPACK directly (for a small loop the bookkeeping of the
stacked versions would cost more than the eigenvalue problems).

References
----------
N. A. Bruinsma, M. Steinbuch, "A fast algorithm to compute the
H-infinity-norm of a transfer function matrix", Systems & Control Letters
14(4), 1990. S. Boyd, V. Balakrishnan, P. Kabamba, "A bisection method for
computing the H-infinity norm of a transfer matrix and related problems",
Mathematics of Control, Signals and Systems 2(3), 1989. K. Zhou, J. C.
Doyle, K. Glover, *Robust and Optimal Control*, Prentice Hall 1996,
Sec. 4.7 and 21. E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, "A structure-preserving
doubling algorithm for continuous-time algebraic Riccati equations", Linear
Algebra and its Applications 396, 2005.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.linalg import lapack

__all__ = ["hinf_norm", "bounded_real_riccati", "sigma_max", "eigvals", "eigvalsh", "solve", "hinf_norm_one",
           "riccati_one", "riccati_doubling", "norm_one", "slicot_ab13dd"]

#: Relative accuracy of the norm: the value ``g`` returned has ``g <= ||G|| <= (1 + 2 TOL) g``.
TOL = 1e-10
# An eigenvalue of M counts as imaginary when |Re| <= _IMAG (|lambda| + 1e-3 rho(M)). Generous on purpose: a
# false one only adds a test frequency (the midpoints of a true interval stay in it), while two nearly equal
# crossings near a sharp peak come out with |Re| up to ~1e-4 |lambda| (1e-6 stopped 4e-3 below the norm).
_IMAG = 1e-3
_MAX_ITER = 60


@functools.lru_cache(maxsize=64)
def eye(n: int) -> np.ndarray:
    """A read-only identity of size ``n`` (cached: small calls are overhead-bound)."""
    out = np.eye(n)
    out.flags.writeable = False
    return out


@functools.cache
def slicot_ab13dd():
    """The wrapper of SLICOT AB13DD in slycot (the norm of python-control's ``linfnorm``), or None without slycot."""
    try:
        from slycot import ab13dd
    except ImportError:
        return None
    return ab13dd


def norm_one(A, B, C, lam, *, discrete: bool, tol: float = TOL,
             method: str = "auto") -> tuple[float, float, int, float, str]:
    """``||C (zI - A)^-1 B||_inf`` of one stable loop: ``(gain, peak, steps, h2, method)``.

    ``method="auto"`` uses SLICOT AB13DD (Bruinsma & Steinbuch with a
    structure-preserving Hamiltonian eigensolver, Fortran) when slycot is
    installed, and :func:`hinf_norm_one` (``"level-set"``) without it or if
    AB13DD fails; ``"level-set"`` forces the latter. ``steps`` and ``h2``
    are those of :func:`hinf_norm_one` (0 for AB13DD: ``h2`` is then not
    computed). The returned ``method`` says which one computed the norm.
    """
    if method == "auto":
        ab13dd = slicot_ab13dd()
        if ab13dd is not None and A.shape[0] > 0:
            n, p, l = A.shape[0], B.shape[1], C.shape[0]
            try:
                gain, peak = ab13dd("D" if discrete else "C", "I", "S", "Z", n, p, l, A, eye(n), B, C,
                                    np.zeros((l, p)), tol)
            except (RuntimeError, ArithmeticError, ValueError):   # slycot's errors: the pure path decides
                gain = np.nan
            if 0.0 <= gain < np.inf and 0.0 <= peak < np.inf:
                if discrete:
                    peak = abs(np.angle(np.exp(1j * peak)))    # theta in [0, pi]
                return float(gain), float(peak), 0, 0.0, "ab13dd"
    g, w, steps, h2 = hinf_norm_one(A, B, C, lam, discrete=discrete, tol=tol)
    return g, w, steps, h2, "level-set"


def eigvals(M):
    """``np.linalg.eigvals`` of a real stack (S, k, k); one matrix goes to LAPACK directly (less overhead)."""
    if M.shape[0] == 1:
        wr, wi, _, _, info = lapack.dgeev(M[0], compute_vl=0, compute_vr=0)
        if info == 0:
            return (wr + 1j * wi)[None]
    return np.linalg.eigvals(M)


def solve(a, b):
    """``np.linalg.solve`` for stacks ``a`` (S, k, k), ``b`` (S, k, r); one system goes to LAPACK directly."""
    if a.shape[0] == 1 and a.ndim == 3:
        gesv = lapack.zgesv if (np.iscomplexobj(a) or np.iscomplexobj(b)) else lapack.dgesv
        _, _, x, info = gesv(a[0], b[0])
        if info == 0:
            return x[None]
    return np.linalg.solve(a, b)


def eigvalsh(M):
    """``np.linalg.eigvalsh`` of a real symmetric stack (S, k, k) (lower triangle); one matrix goes to LAPACK."""
    if M.shape[0] == 1:
        w, _, info = lapack.dsyevd(M[0], compute_v=0, lower=1)
        if info == 0:
            return w[None]
    return np.linalg.eigvalsh(M)


def _stable_subspace(M, n: int):
    """Sorted real parts (S, 2n) and a basis (S, 2n, n) of the invariant subspace of the smallest ``n``.

    For one matrix the basis is real: LAPACK returns a complex pair's
    eigenvector as its real and imaginary parts, which span the pair's
    real invariant subspace (both members of a pair are selected, or the
    caller's gap test fails).
    """
    if M.shape[0] == 1:
        wr, _, _, vr, info = lapack.dgeev(M[0], compute_vl=0, compute_vr=1)
        if info == 0:
            order = np.argsort(wr, kind="stable")
            return wr[order][None], vr[:, order[:n]][None]
    ev, V = np.linalg.eig(M)
    order = np.argsort(ev.real, axis=1)
    return np.take_along_axis(ev.real, order, axis=1), np.take_along_axis(V, order[:, None, :n], axis=2)


def _cayley(A, B, C, flip=None, D=None):
    """``(Ac, Bc, Cc, Dc)`` of the bilinear transform ``z = (1 + s) / (1 - s)`` (stacks).

    Where ``flip`` (S,) is True, of ``z = -(1 + s) / (1 - s)`` instead: the
    transform of ``(-A, B, -C, D)``, which has the same norm and storage
    functions, with ``Dc = G(1)`` instead of ``G(-1)``. ``D`` None means zero.
    """
    if flip is not None and flip.any():
        sgn = np.where(flip, -1.0, 1.0)[:, None, None]
        A, C = sgn * A, sgn * C
    n = A.shape[-1]
    I = np.eye(n)
    Mi = solve(A + I, np.broadcast_to(I, A.shape))
    MiB = Mi @ B
    Dc = -(C @ MiB) if D is None else D - C @ MiB
    return Mi @ (A - I), np.sqrt(2.0) * MiB, np.sqrt(2.0) * (C @ Mi), Dc


def _invert(A, B, C, D, flip):
    """``(A^-1, A^-1 B, -C A^-1, D - C A^-1 B)`` (the realisation of ``G(1/s)``) where ``flip`` (S,) is True."""
    if not flip.any():
        return A, B, C, D
    Ai = solve(A[flip], np.broadcast_to(np.eye(A.shape[-1]), A[flip].shape))
    Bi, Ci = Ai @ B[flip], C[flip] @ Ai
    A, B, C, D = A.copy(), B.copy(), C.copy(), D.copy()
    A[flip], D[flip] = Ai, D[flip] - C[flip] @ Bi
    B[flip], C[flip] = Bi, -Ci
    return A, B, C, D


def _hamiltonian(A, B, C, D, gamma):
    """``M(gamma)`` of the module docstring for stacks (``D`` None means zero)."""
    g2 = (gamma * gamma)[:, None, None]
    if D is None:
        Ah, G, Q = A, (B @ B.mT) / g2, C.mT @ C
    else:
        p = D.shape[-1]
        R = g2 * np.eye(p) - D.mT @ D
        DC = D.mT @ C
        S = solve(R, np.concatenate([DC, B.mT], axis=-1))   # R^-1 [D'C, B']
        n = A.shape[-1]
        RDC, RB = S[..., :n], S[..., n:]
        Ah = A + B @ RDC
        G = B @ RB
        Q = C.mT @ C + DC.mT @ RDC
    top = np.concatenate([Ah, G], axis=-1)
    bottom = np.concatenate([-Q, -Ah.mT], axis=-1)
    return np.concatenate([top, bottom], axis=-2)


def sigma_max(A, B, C, points, D=None):
    """``sigma_max(D + C (sI - A)^-1 B)`` at complex ``points`` (B, k) for stacks (B, n, n), (B, n, p), (B, l, n).

    ``D`` (B, l, p) None means zero.
    """
    n = A.shape[-1]
    M = points[:, :, None, None] * np.eye(n) - A[:, None]
    rhs = np.broadcast_to(B[:, None], (*points.shape, *B.shape[1:])).astype(complex)
    T = C[:, None] @ np.linalg.solve(M, rhs)
    if D is not None:
        T = T + D[:, None]
    return _smax(T)


def _smax(T):
    """Largest singular value of each matrix of a complex stack (..., l, p).

    Closed forms for ``min(l, p) <= 2`` on large stacks (cheaper than the
    stacked SVD there; on a few matrices the SVD's lower overhead wins).
    """
    k = min(T.shape[-2:])
    if k > 2 or T.size < 64 * T.shape[-1] * T.shape[-2]:
        return np.linalg.svd(T, compute_uv=False)[..., 0]
    if k == 1:
        return np.sqrt((T.real ** 2 + T.imag ** 2).sum(axis=(-2, -1)))
    if k == 2:
        # the largest eigenvalue of the 2 x 2 Gram matrix [[a, b], [b*, d]]
        u, v = (T[..., 0], T[..., 1]) if T.shape[-1] == 2 else (T[..., 0, :], T[..., 1, :])
        a = (u.real ** 2 + u.imag ** 2).sum(axis=-1)
        d = (v.real ** 2 + v.imag ** 2).sum(axis=-1)
        b = (u.conj() * v).sum(axis=-1)
        h = 0.5 * (a - d)
        return np.sqrt(0.5 * (a + d) + np.sqrt(h * h + b.real ** 2 + b.imag ** 2))
    return np.linalg.svd(T, compute_uv=False)[..., 0]


def _theta(w, flip):
    """Angles on the unit circle of the frequencies ``w`` (S, k) of the transformed loops."""
    phi = 2.0 * np.arctan(w)
    return phi if flip is None else np.where(flip[:, None], np.pi - phi, phi)


def _start(lam, discrete: bool):
    """First frequencies (S, 2 or 3) from the poles ``lam`` (S, n).

    ``w = 0`` and the modulus of the most lightly damped complex pole
    (continuous, the choice of Bruinsma & Steinbuch); ``theta = 0``, ``pi``
    and the angle of the complex pole nearest the unit circle (discrete).
    """
    zero = np.zeros((lam.shape[0], 1))
    rows = np.arange(lam.shape[0])
    if discrete:
        k = np.argmax(np.where(lam.imag > 0, np.abs(lam), -1.0), axis=1)
        return np.concatenate([zero, zero + np.pi, np.abs(np.angle(lam[rows, k]))[:, None]], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.argmax(np.where(lam.imag > 0, np.abs(lam.imag / lam.real), -1.0), axis=1)
    return np.concatenate([zero, np.where(lam[rows, k].imag > 0, np.abs(lam[rows, k]), 0.0)[:, None]], axis=1)


def hinf_norm(A, B, C, *, discrete: bool, tol: float = TOL, poles=None, D=None):
    """``||G_b||_inf`` of each stable loop of a stack.

    Parameters
    ----------
    A : (S, n, n), B : (S, n, p), C : (S, l, n) ndarrays, every ``A`` stable
    discrete : bool
    tol : float
        Relative accuracy (module docstring).
    poles : (S, n) ndarray, optional
        The eigenvalues of ``A`` if already known.
    D : (S, l, p) ndarray, optional
        The feedthrough (None: zero). In continuous time the level set then
        starts from ``sigma_max(D)`` too (the gain at ``w = inf``, reported
        as the peak frequency ``inf`` where it is the norm).

    Returns
    -------
    gain : (S,) ndarray
    freq : (S,) ndarray
        The peak frequency: ``w`` in rad per time unit (continuous) or
        ``theta`` in ``[0, pi]`` rad per sample (discrete).
    iterations : int
        Level-set steps of the slowest loop.
    """
    S = A.shape[0]
    # equal norms for B and C (G unchanged) keep M(gamma) balanced
    b = np.sqrt((B * B).sum(axis=(1, 2)))
    c = np.sqrt((C * C).sum(axis=(1, 2)))
    live = (b > 0) & (c > 0)
    if not live.all():
        gain = np.zeros(S) if D is None else _smax(D)
        freq = np.zeros(S)
        if live.any():
            g, w, it = hinf_norm(A[live], B[live], C[live], discrete=discrete, tol=tol,
                                 poles=None if poles is None else poles[live], D=None if D is None else D[live])
            gain[live], freq[live] = g, w
            return gain, freq, it
        return gain, freq, 0
    f = np.sqrt(c / b)[:, None, None]
    B, C = B * f, C / f
    rows = np.arange(S)
    w0 = _start(eigvals(A) if poles is None else poles, discrete)
    sig = sigma_max(A, B, C, np.exp(1j * w0) if discrete else 1j * w0, D)
    if D is not None and not discrete:
        w0 = np.concatenate([w0, np.full((S, 1), np.inf)], axis=1)
        sig = np.concatenate([sig, _smax(D)[:, None]], axis=1)
    k = np.argmax(sig, axis=1)
    lb, peak = sig[rows, k], w0[rows, k]
    flip = np.zeros(S, dtype=bool)
    if discrete:
        # Dc of the transform is G(-1), or G(1) where flipped: the smaller keeps R = gamma^2 I - Dc'Dc far from singular
        flip = sig[:, 1] > sig[:, 0]
        Ah, Bh, Ch, Dh = _cayley(A, B, C, flip, D)
    elif D is not None:
        # where sigma_max(G(inf)) > sigma_max(G(0)), the level set runs on G(1/s) (feedthrough G(0)), for that reason
        flip = sig[:, -1] > sig[:, 0]
        Ah, Bh, Ch, Dh = _invert(A, B, C, D, flip)
    else:
        Ah, Bh, Ch, Dh = A, B, C, None
    active = rows
    ham: tuple = (Ah, Bh, Ch, Dh)
    iterations = 0
    while active.size and iterations < _MAX_ITER:
        iterations += 1
        ev = eigvals(_hamiltonian(ham[0], ham[1], ham[2], ham[3], (1.0 + 2.0 * tol) * lb[active]))
        mag = np.abs(ev)
        imag = (np.abs(ev.real) <= _IMAG * (mag + 1e-3 * mag.max(axis=1, keepdims=True))) & (ev.imag >= 0)
        count = imag.sum(axis=1)
        keep = count > 0
        if not keep.any():
            break
        act, hk = active, ham
        if not keep.all():
            imag, ev, count, act = imag[keep], ev[keep], count[keep], active[keep]
            hk = tuple(None if M is None else M[keep] for M in ham)
        wi = np.where(imag, np.abs(ev.imag), np.inf)
        wi = np.sort(wi, axis=1)[:, :int(count.max())]
        wi = np.concatenate([np.zeros((wi.shape[0], 1)), wi], axis=1)
        mid = 0.5 * (wi[:, :-1] + wi[:, 1:])
        valid = np.isfinite(mid)
        mid = np.where(valid, mid, 0.0)
        if discrete:
            mid = _theta(mid, flip[act])
            sv = sigma_max(A[act], B[act], C[act], np.exp(1j * mid), None if D is None else D[act])
        else:   # on the realisation of the Hamiltonian: G(1/s) has the singular values of G(s) at w = 1 / mid
            sv = sigma_max(hk[0], hk[1], hk[2], 1j * mid, hk[3])
            if flip.any():
                with np.errstate(divide="ignore"):
                    mid = np.where(flip[act][:, None], 1.0 / mid, mid)
        sv = np.where(valid, sv, -np.inf)
        j = np.argmax(sv, axis=1)
        r = np.arange(sv.shape[0])
        best = sv[r, j]
        old = lb[act]
        better = best > old
        lb[act[better]] = best[better]
        peak[act[better]] = mid[r, j][better]
        # no progress: the bound is within rounding of the norm
        keep[np.flatnonzero(keep)[best <= old * (1.0 + tol)]] = False
        if not keep.all():
            active = active[keep]
            ham = tuple(None if M is None else M[keep] for M in ham)
    return lb, peak, iterations


def bounded_real_riccati(A, B, C, gamma, *, discrete: bool):
    """Stabilising solutions of the bounded-real Riccati equations at levels ``gamma`` (S,).

    Continuous: ``A'P + PA + C'C + PBB'P / gamma^2 = 0`` with ``A + BB'P / gamma^2`` stable;
    discrete: ``P = A'PA + C'C + A'PB (gamma^2 I - B'PB)^-1 B'PA`` (module docstring).

    Returns
    -------
    P : (S, n, n) ndarray
        Symmetric; rows where ``ok`` is False may hold anything finite or NaN.
    ok : (S,) bool ndarray
        The Hamiltonian had ``n`` eigenvalues left of the imaginary axis and
        ``n`` right of it and ``X1`` was invertible (not a proof: verify ``P``).
    """
    n = A.shape[-1]
    if discrete:
        Ah, Bh, Ch, Dh = _cayley(A, B, C)
    else:
        Ah, Bh, Ch, Dh = A, B, C, None
    re, X = _stable_subspace(_hamiltonian(Ah, Bh, Ch, Dh, gamma), n)
    ok = (re[:, n - 1] < 0.0) & (re[:, n] > 0.0)
    X1, X2 = X[:, :n], X[:, n:]
    with np.errstate(all="ignore"):
        try:
            P = solve(X1.mT, X2.mT).mT
        except np.linalg.LinAlgError:   # one singular X1 spoils the stacked solve: one by one
            P = np.full(X1.shape, np.nan, dtype=X1.dtype)
            for i in range(X1.shape[0]):
                try:
                    P[i] = np.linalg.solve(X1[i].T, X2[i].T).T
                except np.linalg.LinAlgError:
                    ok[i] = False
        if np.iscomplexobj(P):
            Pr = P.real
            ok &= np.isfinite(P).all(axis=(1, 2)) & (np.abs(P.imag).max(axis=(1, 2))
                                                      <= 1e-6 * np.abs(Pr).max(axis=(1, 2)))
        else:
            Pr = P
            ok &= np.isfinite(P).all(axis=(1, 2))
    Pr = 0.5 * (Pr + Pr.mT)
    return Pr, ok


# ---------------------------------------------------------------- one loop (2-D arrays, less overhead)
def _cayley_one(A, B, C, flip: bool = False):
    """:func:`_cayley` of one realisation."""
    if flip:
        A, C = -A, -C
    I = eye(A.shape[0])
    _, _, Mi, info = lapack.dgesv(A + I, I)
    if info != 0:
        Mi = np.linalg.inv(A + I)
    MiB = Mi @ B
    return I - 2.0 * Mi, np.sqrt(2.0) * MiB, np.sqrt(2.0) * (C @ Mi), -(C @ MiB)


def _hamiltonian_one(A, B, C, D, gamma: float):
    """:func:`_hamiltonian` of one realisation."""
    n = A.shape[0]
    M = np.empty((2 * n, 2 * n))
    g2 = gamma * gamma
    if D is None:
        Ah, G, Q = A, (B @ B.T) / g2, C.T @ C
    else:
        R = g2 * eye(D.shape[1]) - D.T @ D
        DC = D.T @ C
        rhs = np.concatenate([DC, B.T], axis=1)
        _, _, S, info = lapack.dgesv(R, rhs)
        if info != 0:
            S = np.linalg.solve(R, rhs)
        Ah = A + B @ S[:, :n]
        G = B @ S[:, n:]
        Q = C.T @ C + DC.T @ S[:, :n]
    M[:n, :n] = Ah
    M[:n, n:] = G
    M[n:, :n] = -Q
    M[n:, n:] = -Ah.T
    return M


def _sigma_one(A, B, C, points):
    """``sigma_max(C (sI - A)^-1 B)`` at the complex ``points`` (k,) for one realisation."""
    M = points[:, None, None] * eye(A.shape[0]) - A
    X = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (points.shape[0], *B.shape)))
    return _smax(C @ X), (X.real ** 2 + X.imag ** 2).sum(axis=(1, 2))


def hinf_norm_one(A, B, C, lam, *, discrete: bool, tol: float = TOL) -> tuple[float, float, int, float]:
    """:func:`hinf_norm` of one stable loop ``(A, B, C)`` with poles ``lam``.

    Returns ``(gain, peak frequency, steps, h2)`` with ``h2`` the squared
    Frobenius norm of ``(zI - A)^-1 B`` at the peak.
    """
    b2, c2 = float((B * B).sum()), float((C * C).sum())
    if b2 == 0.0 or c2 == 0.0:
        return 0.0, 0.0, 0, 0.0
    f = (c2 / b2) ** 0.25
    B, C = B * f, C / f
    cplx = lam.imag > 0
    if not cplx.any():
        w0 = np.array([0.0, np.pi]) if discrete else np.zeros(1)
    elif discrete:
        w0 = np.array([0.0, np.pi, abs(np.angle(lam[cplx][np.argmax(np.abs(lam[cplx]))]))])
    else:
        lc = lam[cplx]
        with np.errstate(divide="ignore"):
            w0 = np.array([0.0, abs(lc[np.argmax(np.abs(lc.imag / lc.real))])])
    sig, xn = _sigma_one(A, B, C, np.exp(1j * w0) if discrete else 1j * w0)
    k = int(np.argmax(sig))
    lb, peak, h2 = float(sig[k]), float(w0[k]), float(xn[k])
    flip = bool(discrete and sig[1] > sig[0])
    if discrete:
        Ah, Bh, Ch, Dh = _cayley_one(A, B, C, flip)
    else:
        Ah, Bh, Ch, Dh = A, B, C, None
    iterations = 0
    while iterations < _MAX_ITER:
        iterations += 1
        M = _hamiltonian_one(Ah, Bh, Ch, Dh, (1.0 + 2.0 * tol) * lb)
        wr, wi, _, _, info = lapack.dgeev(M, compute_vl=0, compute_vr=0)
        if info != 0:
            ev = np.linalg.eigvals(M)
            wr, wi = ev.real, ev.imag
        mag = np.hypot(wr, wi)
        imag = (np.abs(wr) <= _IMAG * (mag + 1e-3 * mag.max())) & (wi >= 0)
        if not imag.any():
            break
        w = np.sort(wi[imag])
        mid = 0.5 * (np.concatenate([[0.0], w[:-1]]) + w)
        if discrete:
            phi = 2.0 * np.arctan(mid)
            mid = np.pi - phi if flip else phi
            pts = np.exp(1j * mid)
        else:
            pts = 1j * mid
        sv, xn = _sigma_one(A, B, C, pts)
        j = int(np.argmax(sv))
        best, old = float(sv[j]), lb
        if best > lb:
            lb, peak, h2 = best, float(mid[j]), float(xn[j])
        if best <= old * (1.0 + tol):   # no progress: the bound is within rounding of the norm
            break
    return lb, peak, iterations, h2 / (f * f)


def _cayley_hamiltonian_one(A, B, C, gamma: float):
    """``M(gamma)`` of the Cayley transform of one discrete loop (:func:`_cayley_one`, :func:`_hamiltonian_one`).

    With ``Mi = (A + I)^-1``, ``X = Mi B``, ``Y = C Mi``, ``Z = C X`` and
    ``R = gamma^2 I - Z'Z``, ``[T1, T2] = R^-1 [Z'Y, X']``, the blocks are
    ``I - 2 (Mi + X T1)``, ``2 X T2`` and ``2 Y'(Y + Z T1)`` (fewer small
    products than the two steps). None if ``A + I`` or ``R`` is singular.
    """
    n = A.shape[0]
    I = eye(n)
    _, _, Mi, info = lapack.dgesv(A + I, I)
    if info != 0:
        return None
    X = Mi @ B
    Y = C @ Mi
    Z = C @ X
    _, _, T, info = lapack.dgesv((gamma * gamma) * eye(B.shape[1]) - Z.T @ Z, np.concatenate([Z.T @ Y, X.T], axis=1))
    if info != 0:
        return None
    T1 = T[:, :n]
    Ah = I - 2.0 * (Mi + X @ T1)
    M = np.empty((2 * n, 2 * n))
    M[:n, :n] = Ah
    M[:n, n:] = 2.0 * (X @ T[:, n:])
    M[n:, :n] = -2.0 * (Y.T @ (Y + Z @ T1))
    M[n:, n:] = -Ah.T
    return M


def riccati_one(A, B, C, gamma: float, *, discrete: bool):
    """:func:`bounded_real_riccati` of one realisation: ``P`` or None."""
    n = A.shape[0]
    M = _cayley_hamiltonian_one(A, B, C, gamma) if discrete else _hamiltonian_one(A, B, C, None, gamma)
    if M is None:
        return None
    wr, _, _, vr, info = lapack.dgeev(M, compute_vl=0, compute_vr=1)
    if info != 0:
        return None
    order = np.argsort(wr, kind="stable")
    if not (wr[order[n - 1]] < 0.0 < wr[order[n]]):
        return None
    X = vr[:, order[:n]]
    _, _, Pt, info = lapack.dgesv(X[:n].T, X[n:].T)
    if info != 0 or not np.isfinite(Pt).all():
        return None
    return 0.5 * (Pt + Pt.T)


#: Doubling steps before :func:`riccati_doubling` gives up.
_SDA_MAX_ITER = 60
#: Relative change of ``H_k`` (largest entry) at which the doubling has converged.
_SDA_TOL = 1e-13


def _doubling(A, G, H):
    """The SDA of the module docstring from ``(A, G, H)``: the stabilising solution, or None."""
    n = A.shape[0]
    I = eye(n)
    for _ in range(_SDA_MAX_ITER):
        _, _, Y, info = lapack.dgesv(I + G @ H, np.concatenate([A, G @ A.T], axis=1))
        if info != 0:
            return None
        Y1 = Y[:, :n]
        Hn = H + A.T @ (H @ Y1)
        G = G + A @ Y[:, n:]
        A = A @ Y1
        change = np.abs(Hn - H).max()
        H = Hn
        if not change <= 1e300:   # NaN or overflow: no stabilising solution at this level
            return None
        if change <= _SDA_TOL * np.abs(H).max():
            return 0.5 * (H + H.T)
    return None


def riccati_doubling(A, B, C, gamma: float, lam, *, discrete: bool):
    """:func:`riccati_one` by the doubling algorithm (module docstring): ``P`` or None.

    ``lam`` are the eigenvalues of ``A`` (the continuous case picks its
    bilinear transform from them).
    """
    n = A.shape[0]
    g2 = gamma * gamma
    if discrete:
        return _doubling(A, -(B @ B.T) / g2, C.T @ C)
    mod = np.abs(lam)
    a = float(np.sqrt(mod.min() * mod.max())) if mod.size and mod.min() > 0 else 1.0
    I = eye(n)
    _, _, Mi, info = lapack.dgesv(a * I - A, I)
    if info != 0:
        return None
    MiB = Mi @ B
    r = np.sqrt(2.0 * a)
    Ad, Bd, Cd, Dd = Mi @ (a * I + A), r * MiB, r * (C @ Mi), C @ MiB
    DC = Dd.T @ Cd
    _, _, S, info = lapack.dgesv(g2 * eye(B.shape[1]) - Dd.T @ Dd, np.concatenate([DC, Bd.T], axis=1))
    if info != 0:
        return None
    return _doubling(Ad + Bd @ S[:, :n], -(Bd @ S[:, n:]), Cd.T @ Cd + DC.T @ S[:, :n])
