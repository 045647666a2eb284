"""Compiled (numba) kernel of the batched closed-loop simulation.

One function, :func:`closed_loop`, runs the recursion of
:func:`robustctl.sim.simulator.simulate_linear` for every gain and scenario; the
argument checks, broadcasting rules and the result object live there. The
numpy loop in :mod:`robustctl.sim.simulator` is the reference implementation the
tests compare this kernel with.

Layout. For each scenario the gains are processed in blocks of up to
:data:`MAX_BLOCK` designs; inside a block every work array is ``(n, block)``
with the designs contiguous, and every innermost loop runs over the designs
of the block, so LLVM vectorises it (measured: blocks as wide as the batch
run about twice as fast as blocks of 8 or 16, whose short loops cost more in
set-up than in arithmetic). The loop is bound by loads and stores of the work
arrays rather than by arithmetic, so ``F x`` is summed over chunks of four
columns per pass (the state work arrays carry zero rows up to a multiple of
four; about 20 % faster on the truck than one pass per column; fused
multiply-add measured no faster and is not used). Each design's arithmetic is the same sequence of
IEEE operations whatever its position in the block or the size and order of
the batch (no reduction runs across designs, and without ``fastmath`` LLVM
neither reassociates nor contracts multiply-adds), so a design's result does
not depend on the batch it is simulated in.

Compilation: :func:`robustctl._jit.jit` (cached on disk, GIL released).
"""

from __future__ import annotations

import numpy as np

from .._jit import jit

__all__ = ["closed_loop", "MAX_BLOCK", "cache_enabled"]

#: Most designs per block (bounds the work arrays: 128 designs x 4 states x 8 arrays = 32 kB, L1-sized).
MAX_BLOCK = 128


def cache_enabled() -> bool:
    """Whether the kernel's machine code is cached on disk (False: compiled in every process)."""
    return closed_loop._cache.__class__.__name__ != "NullCache"


@jit
def _row4(F, s, t, i, l, n):
    """``F[s, t, i, l:l + 4]`` as four numbers, zero beyond column ``n``."""
    return (F[s, t, i, l], F[s, t, i, l + 1] if l + 1 < n else 0.0, F[s, t, i, l + 2] if l + 2 < n else 0.0,
            F[s, t, i, l + 3] if l + 3 < n else 0.0)


@jit
def closed_loop(KT, F, G, xr, uff, w, e0, lim, bound, dead, keep, sq, sqx, div_step, sat_steps, E, U):
    """Run ``x[k+1] = F x[k] + G u[k] + w[k]``, ``u[k] = sat(K (x[k] - xr[k]) + uff[k])`` for all gains.

    Parameters
    ----------
    KT : (p, n, B) float64 ndarray
        Effective gains (input map applied), design ``b`` at ``[:, :, b]``.
    F, G : (1 or S, 1 or T, n, n), (1 or S, 1 or T, n, p) ndarray
        Plant per scenario and time step (a leading size 1 broadcasts).
    xr, uff, w : (1 or S, T, n), (1 or S, 1 or T, p), (1 or S, 1 or T, n) ndarray
        Reference, feedforward, disturbance.
    e0 : (1 or S, n) ndarray
        Initial errors.
    lim : (p,) ndarray
        Saturation levels (``inf``: none).
    bound : float
        Divergence bound: a run diverges when ``not |e_i| <= bound`` for some
        state, so a NaN error (an overflowed run: ``inf - inf``) diverges
        too, even with ``bound = inf`` (no bound test).
    dead : (B,) bool ndarray
        Gains flagged as not computable (frozen at ``+bound`` from step 0).
    keep : bool
        Write the trajectories ``E`` and ``U``.
    sq, sqx : (B, S, n) ndarray
        Output: sums of ``e^2`` and ``x^2``.
    div_step, sat_steps : (B, S) int64 ndarray
        Output: first step beyond the bound (-1: none), steps at a limit.
    E, U : (B, S, T, n), (B, S, T, p) ndarray
        Output trajectories when ``keep`` (else any 4-D arrays, unused).

    Notes
    -----
    Every array is C-contiguous; the outputs are written in place.
    """
    p, n, B = KT.shape
    S = sq.shape[1]
    T = xr.shape[1]
    W = min(B, MAX_BLOCK)
    NW = n * W
    NP = (n + 3) // 4 * 4 * W                   # x, xn padded to whole chunks of 4 rows, pad rows zero
    x, xn = np.zeros(NP), np.zeros(NP)
    e, ef, acc, accx = np.empty(NW), np.empty(NW), np.empty(NW), np.empty(NW)
    u, kb = np.empty(p * W), np.empty(p * NW)
    alive = np.empty(W, dtype=np.bool_)
    div = np.empty(W, dtype=np.int64)
    nsat = np.empty(W, dtype=np.int64)
    satnow = np.empty(W, dtype=np.bool_)
    for s in range(S):
        sF = s if F.shape[0] > 1 else 0
        sG = s if G.shape[0] > 1 else 0
        sX = s if xr.shape[0] > 1 else 0
        sU = s if uff.shape[0] > 1 else 0
        sW = s if w.shape[0] > 1 else 0
        s0 = s if e0.shape[0] > 1 else 0
        for b0 in range(0, B, W):
            nb = min(W, B - b0)
            for q in range(p):
                for i in range(n):
                    o = (q * n + i) * W
                    for j in range(nb):
                        kb[o + j] = KT[q, i, b0 + j]
            any_dead = False
            for j in range(nb):
                alive[j] = not dead[b0 + j]
                any_dead |= dead[b0 + j]
                div[j] = -1 if alive[j] else 0
                nsat[j] = 0
            for i in range(n):
                o = i * W
                for j in range(nb):
                    ef[o + j] = bound
                    acc[o + j] = 0.0
                    accx[o + j] = 0.0
                    x[o + j] = xr[sX, 0, i] + (e0[s0, i] if alive[j] else bound)
            for k in range(T):
                nout = 0                                  # frozen runs: e = ef exactly, |ef| = bound
                for i in range(n):
                    r = xr[sX, k, i]
                    o = i * W
                    if any_dead:
                        for j in range(nb):
                            v = x[o + j] - r if alive[j] else ef[o + j]
                            e[o + j] = v
                            nout += not abs(v) <= bound       # NaN counts: overflow is divergence
                    else:
                        for j in range(nb):
                            v = x[o + j] - r
                            e[o + j] = v
                            nout += not abs(v) <= bound       # NaN counts: overflow is divergence
                if nout > 0:                          # rare: a run leaves the bound now
                    for j in range(nb):
                        if not alive[j]:
                            continue
                        out = False
                        for i in range(n):
                            out |= not abs(e[i * W + j]) <= bound
                        if out:
                            alive[j] = False
                            any_dead = True
                            div[j] = k
                            for i in range(n):
                                t = i * W + j
                                ef[t] = -bound if e[t] < 0 else bound
                                e[t] = ef[t]
                                x[t] = xr[sX, k, i] + ef[t]
                tU = k if uff.shape[1] > 1 else 0
                for j in range(nb):
                    satnow[j] = False
                for q in range(p):
                    o = q * W
                    for j in range(nb):
                        u[o + j] = 0.0
                    for i in range(n):
                        ok = (q * n + i) * W
                        oe = i * W
                        for j in range(nb):
                            u[o + j] += kb[ok + j] * e[oe + j]
                    c = uff[sU, tU, q]
                    hi = lim[q]
                    for j in range(nb):
                        v = u[o + j] + c
                        satnow[j] |= (v <= -hi) | (v >= hi)
                        u[o + j] = min(max(v, -hi), hi)
                for j in range(nb):
                    nsat[j] += satnow[j]
                for i in range(n):
                    o = i * W
                    for j in range(nb):
                        acc[o + j] += e[o + j] * e[o + j]
                        accx[o + j] += x[o + j] * x[o + j]
                if keep:
                    for j in range(nb):
                        for i in range(n):
                            E[b0 + j, s, k, i] = e[i * W + j]
                        for q in range(p):
                            U[b0 + j, s, k, q] = u[q * W + j]
                if k + 1 < T:
                    tF = k if F.shape[1] > 1 else 0
                    tG = k if G.shape[1] > 1 else 0
                    tW = k if w.shape[1] > 1 else 0
                    for i in range(n):           # F x, four columns per pass (x has >= 3 zero pad rows)
                        o = i * W
                        a0, a1, a2, a3 = _row4(F, sF, tF, i, 0, n)
                        for j in range(nb):
                            xn[o + j] = (a0 * x[j] + a1 * x[W + j] + a2 * x[2 * W + j]) + a3 * x[3 * W + j]
                        for l in range(4, n, 4):
                            a0, a1, a2, a3 = _row4(F, sF, tF, i, l, n)
                            ol = l * W
                            for j in range(nb):
                                xn[o + j] += ((a0 * x[ol + j] + a1 * x[ol + W + j] + a2 * x[ol + 2 * W + j])
                                              + a3 * x[ol + 3 * W + j])
                        c = w[sW, tW, i]
                        if p > 1:
                            for j in range(nb):
                                gu = 0.0
                                for q in range(p):
                                    gu += G[sG, tG, i, q] * u[q * W + j]
                                xn[o + j] = (xn[o + j] + gu) + c
                        elif any_dead:                   # frozen runs: x = x_ref + ef
                            g = G[sG, tG, i, 0]
                            r = xr[sX, k + 1, i]
                            for j in range(nb):
                                xn[o + j] = (xn[o + j] + g * u[j]) + c if alive[j] else r + ef[o + j]
                        else:
                            g = G[sG, tG, i, 0]
                            for j in range(nb):
                                xn[o + j] = (xn[o + j] + g * u[j]) + c
                        if p > 1 and any_dead:
                            r = xr[sX, k + 1, i]
                            for j in range(nb):
                                xn[o + j] = xn[o + j] if alive[j] else r + ef[o + j]
                    x, xn = xn, x
            for j in range(nb):
                div_step[b0 + j, s] = div[j]
                sat_steps[b0 + j, s] = nsat[j]
                for i in range(n):
                    sq[b0 + j, s, i] = acc[i * W + j]
                    sqx[b0 + j, s, i] = accx[i * W + j]
