"""Shapes of the optimal Lyapunov variables, for the frame of :mod:`.output_coordinates`.

* H-infinity (:func:`hinf_shapes`): at a level ``gamma`` a little above the
  optimum (the Riccati bisection of :mod:`.output_riccati` to ``SHAPE_RTOL``),
  ``X ~ gamma^2 X_inf^-1`` and ``Y ~ Y_inf^-1`` (the variables of the
  ``gamma^2`` form). A singular channel is regularised first (``eps I``
  appended to ``D12`` and ``D21``), a discrete plant replaced by its Tustin
  image (same states).
* H2 (:func:`h2_shapes`): the LQG controller of the two Riccati equations
  (weights regularised by ``SHAPE_EPS`` where singular) and the
  controllability Gramian ``Wc`` of its closed loop: ``X ~ Wc_11`` and
  ``Y ~ ((Wc^-1)_11)``, the variables of that controller's own H2 bound.

Both also return the level (norm) they reached, by which ``z`` is scaled so
that the optimum is near 1. ``None`` when a Riccati equation fails: the frame
is then the textbook one.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .coordinates import lifted
from .generalised import Channel, DynamicGain, Generalised, closed_loop
from .output_riccati import bisect_level, is_regular, level_riccati, normalise, tustin

__all__ = ["hinf_shapes", "h2_shapes", "regularised", "SHAPE_RTOL", "SHAPE_EPS", "SHAPE_GAMMA_MAX"]

#: Relative accuracy of the level at which the H-infinity shapes are taken.
SHAPE_RTOL = 1e-2
#: Regularisation of a singular channel (unit-sized) for its shapes.
SHAPE_EPS = 1e-3
#: Largest level tried by the shapes' bisection (unit-sized channels).
SHAPE_GAMMA_MAX = 1e8
#: Floor of the Riccati solutions, relative to their largest eigenvalue, before they are inverted.
RICCATI_FLOOR = 1e-10


def regularised(plant: Generalised, eps: float, k: int = 0) -> Generalised:
    """Channel ``k`` with ``eps I`` appended to ``D12`` (rows of ``z``) and ``D21`` (columns of ``w``)."""
    c = plant.channels[k]
    n, m, p = plant.n, plant.m, plant.p
    nz, nw = c.nz, c.nw
    chan = Channel(np.hstack([c.B1, np.zeros((n, p))]), np.vstack([c.C1, np.zeros((m, n))]),
                   np.block([[c.D11, np.zeros((nz, p))], [np.zeros((m, nw + p))]]),
                   np.vstack([c.D12, eps * np.eye(m)]), np.hstack([c.D21, eps * np.eye(p)]))
    return Generalised(plant.A, plant.B2, plant.C2, (chan,), plant.discrete)


def _inverse(M: np.ndarray) -> np.ndarray | None:
    floored = lifted(M, RICCATI_FLOOR)
    return None if floored is None else np.linalg.inv(floored)


def hinf_shapes(plant: Generalised, k: int = 0):
    """``(X0, Y0, gamma)`` for the H-infinity bound of channel ``k``, or ``None`` (module docstring)."""
    g = Generalised(plant.A, plant.B2, plant.C2, (plant.channels[k],), plant.discrete)
    if g.discrete:
        image = tustin(g, np.zeros((g.p, g.m)))
        if image is None:
            return None
        g = image[0]
    if not is_regular(g.channels[0]):
        g = regularised(g, SHAPE_EPS)
    norm = normalise(g)
    hi, _, _ = bisect_level(norm, rtol=SHAPE_RTOL, gamma_max=SHAPE_GAMMA_MAX)
    sol = level_riccati(norm, hi) if np.isfinite(hi) else None
    if sol is None:
        return None
    Xi, Yi = _inverse(sol[0]), _inverse(sol[1])
    return None if Xi is None or Yi is None else (hi**2 * Xi, Yi, hi)


def h2_shapes(plant: Generalised, k: int = 0):
    """``(X0, Y0, norm)`` for the H2 bound of channel ``k`` from the LQG closed loop, or ``None``."""
    c = plant.channels[k]
    A, B2, C2 = plant.A, plant.B2, plant.C2
    are = scipy.linalg.solve_discrete_are if plant.discrete else scipy.linalg.solve_continuous_are

    def reg(M):
        return M + SHAPE_EPS**2 * max(1.0, float(np.linalg.norm(M, 2))) * np.eye(M.shape[0])

    R, V = reg(c.D12.T @ c.D12), reg(c.D21 @ c.D21.T)
    try:
        with np.errstate(all="ignore"):
            Pc = are(A, B2, c.C1.T @ c.C1, R, s=c.C1.T @ c.D12)
            Pf = are(A.T, C2.T, c.B1 @ c.B1.T, V, s=c.B1 @ c.D21.T)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if plant.discrete:
        Kc = -np.linalg.solve(R + B2.T @ Pc @ B2, B2.T @ Pc @ A + c.D12.T @ c.C1)
        L = -np.linalg.solve(V + C2 @ Pf @ C2.T, C2 @ Pf @ A.T + c.D21 @ c.B1.T).T
    else:
        Kc = -np.linalg.solve(R, B2.T @ Pc + c.D12.T @ c.C1)
        L = -np.linalg.solve(V, C2 @ Pf + c.D21 @ c.B1.T).T
    K = DynamicGain(A + B2 @ Kc + L @ C2, -L, Kc, np.zeros((plant.m, plant.p)))
    Acl, Bcl, Ccl, _ = closed_loop(plant, K, k)
    try:
        if plant.discrete:
            Wc = scipy.linalg.solve_discrete_lyapunov(Acl, Bcl @ Bcl.T)
        else:
            Wc = scipy.linalg.solve_continuous_lyapunov(Acl, -Bcl @ Bcl.T)
        n = plant.n
        floored = lifted(Wc, RICCATI_FLOOR)
        if floored is None:
            return None
        Wc = floored
        Y0 = np.linalg.inv(Wc)[:n, :n]
    except (ValueError, np.linalg.LinAlgError):
        return None
    norm = float(np.sqrt(max(np.trace(Ccl @ Wc @ Ccl.T), 0.0)))
    return Wc[:n, :n], Y0, norm
