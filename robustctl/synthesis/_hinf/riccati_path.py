"""The ``synthesis="riccati"`` fast path of ``robustctl.synthesis.hinf`` for the plain problem.

One plant, no input bound, pole region or uncertainty (standard LMI, free
level). In the balanced, unit-channel coordinates of :func:`.coordinates.normalised`:

1. the optimal level ``gamma_opt`` by bisection on the game Riccati equation
   (:func:`robustctl.synthesis.hinf_riccati.bisect_level`: the stabilising solution
   exists, and in discrete time ``Dzw'Dzw + Bw'PBw < gamma^2 I``, exactly
   when a static gain reaches the level; Basar & Bernhard 1995);
2. the gain ``K`` of the saddle point at ``(1 + backoff / 2) gamma_opt``
   (well inside the feasible set, so ``K`` is moderate even where the
   optimum needs an unbounded gain);
3. the LMI certificate of ``robustctl.synthesis.hinf`` at ``(1 + backoff)
   gamma_opt``: a strictly feasible ``(X, K X)`` built from the closed loop's
   bounded-real Riccati equation and accepted only on the eigenvalues of
   every LMI block (:func:`.gains.riccati_certified`), the same check as the
   SDP path.

If a step fails (a Riccati solve rejected by its checks, or no strictly
positive certificate) the caller falls back to the SDP.

References
----------
T. Basar and P. Bernhard, *H-infinity Optimal Control and Related Minimax
Design Problems*, 2nd ed., Birkhaeuser 1995, Ch. 3-4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..hinf_riccati import bisect_level, level_gain
from .coordinates import Coordinates
from .gains import Gain, riccati_certified
from .problem import Problem

__all__ = ["RiccatiPath", "riccati_synthesis", "check_plain", "RTOL", "GAMMA_MAX"]

#: Relative width of the final bisection bracket (the level's accuracy, like
#: the SDP's ``LEVEL_TOL``).
RTOL = 1e-9
#: Largest level tried, in the unit-sized channels (see ``hinf_riccati``).
GAMMA_MAX = 1e10


@dataclass(frozen=True, eq=False)
class RiccatiPath:
    """Outcome of the fast path: a certified gain, or ``gain=None`` and the ``reason`` for the fallback."""

    gain: Gain | None
    gamma_opt: float
    gamma_low: float
    iterations: int
    reason: str = ""


def riccati_synthesis(problem: Problem, data: Coordinates, lqr: Coordinates | None) -> RiccatiPath:
    """Steps 1-3 of the module docstring on ``data`` (one plant; levels returned unscaled).

    The certificate is checked in the LQR coordinates ``lqr`` of ``data``
    (:func:`.coordinates.lqr_coordinates`, where ``X ~ I`` as for the SDP;
    shared with the SDP fallback), then in ``data`` itself.

    Raises InfeasibleError when no level up to ``GAMMA_MAX`` is feasible
    (the plant is stabilisable, as validated, so this means a degenerate
    problem; the caller may try the SDP).
    """
    arrays = (data.F[0], data.G[0], data.Bw, data.Cz, data.Dzu, data.Dzw)
    hi, lo, _, _, its = bisect_level(arrays, discrete=problem.discrete, rtol=RTOL, gamma_max=GAMMA_MAX)
    scale = data.level_scale
    backoff = problem.backoff
    sol = level_gain(arrays, hi * (1.0 + 0.5 * backoff), discrete=problem.discrete)
    its += 1
    if sol is None:
        return RiccatiPath(None, hi / scale, lo / scale, its,
                           "the game Riccati equation failed its checks at the gain's level")
    K = sol[0]
    gain = None
    for coords in (c for c in (lqr, data) if c is not None):
        K_c = K @ np.linalg.solve(data.T, coords.T)   # u = K x_data, x_data = T_data^-1 T_coords x_coords
        gain = riccati_certified(problem, coords, K_c, hi / scale * (1.0 + backoff), backoff, "riccati")
        if gain is not None:
            break
    if gain is None:
        return RiccatiPath(None, hi / scale, lo / scale, its,
                           "no strictly positive LMI certificate at the backed-off level")
    return RiccatiPath(gain, hi / scale, lo / scale, its)


def check_plain(problem: Problem) -> None:
    """ValueError naming the argument that ``synthesis="riccati"`` does not support."""
    given = problem.beyond_plain()
    if given:
        raise ValueError(f"synthesis='riccati' is the plain problem only (one plant, free level, no input bound, "
                         f"pole region or uncertainty, standard LMI); drop {', '.join(given)} or use "
                         "synthesis='lmi'")

