"""Mixed H2/H-infinity *state* feedback ``u = K x``: the state-feedback blocks of both norms with one ``(X, Y)``.

The H-infinity block is :func:`.lmis.hinf_blocks` of the first channel at
its bound (``z`` scaled so that the bound is 1), the H2 blocks are
``h2_blocks`` of ``robustctl.synthesis.h2`` for the second channel; both
channels are in the balanced coordinates of the first
(:func:`.coordinates.normalised`, the second moved there by
:meth:`.coordinates.Coordinates.to`), so that one ``X`` and ``Y = K X``
serve both (Khargonekar & Rotea 1991). ``trace(W)`` is minimised, then a
well-centred point at ``(1 + backoff)`` times the optimal bound gives ``K``;
its closed loop is certified by :mod:`.output_certificate` (the Hamiltonian
test at the bound and the Gramian's H2 norm), the backoff raised by
``BACKOFF_STEPS`` if it is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import _cvx
from ...errors import ConvergenceError, InfeasibleError
from .coordinates import Coordinates, channel_scales, normalised
from .generalised import Channel, DynamicGain, Generalised
from .lmis import hinf_blocks, region_blocks, variables
from .output_certificate import h2_norm, hinf_certificate, poles_inside
from .tolerances import BACKOFF_STEPS, CENTRE_TOL, LEVEL_TOL

__all__ = ["MixedState", "mixed_state"]


@dataclass(frozen=True, eq=False)
class MixedState:
    """The gain, the optimal and guaranteed H2 bounds (caller's units), the backoff used and the solves."""

    K: np.ndarray
    h2_opt: float
    h2_bound: float
    backoff: float
    solves: tuple[dict, ...]
    certificate: dict


def _data(plant, c: Channel, T: np.ndarray | None) -> Coordinates:
    w_scale, z_unit = channel_scales(c.B1, c.C1, c.D12, c.D11)
    data = normalised([plant.F], [plant.G], c.B1, c.C1, c.D12, c.D11, w_scale, z_unit=z_unit)
    return data if T is None else data.to(T)


def _blocks(h: Coordinates, q: Coordinates, V, W, discrete: bool, regions, margin, z_h: float, z_q: float,
            shared_w: bool):
    """The H-infinity, H2 and region blocks; the H2 Gramian block left out when it is implied (``shared_w``)."""
    from ..h2 import h2_blocks

    h2 = h2_blocks(q, V, W, discrete, margin=margin, z_scale=z_q)
    if shared_w:   # a principal submatrix / Schur complement of the H-infinity block (.output_level.Spec)
        h2 = [lmi for lmi in h2 if not lmi.name.startswith("gramian")]
    return (hinf_blocks(h, V, 1.0, discrete=discrete, margin=margin, z_scale=z_h) + h2
            + region_blocks(regions, h, V, margin))


def mixed_state(plant, hinf_channel: Channel, h2_channel: Channel, gamma: float, *, regions=(), backoff: float,
                solver: str) -> MixedState:
    """Minimise the H2 bound of ``h2_channel`` with ``||T||_inf < gamma`` on ``hinf_channel`` (``u = K x``)."""
    import cvxpy as cp

    h = _data(plant, hinf_channel, None)
    q = _data(plant, h2_channel, h.T)
    z_h = 1.0 / (gamma * h.level_scale)            # the H-infinity bound becomes 1
    discrete = plant.is_discrete
    shared = np.array_equal(hinf_channel.B1, h2_channel.B1)
    const = float(np.sum(q.Dzw**2))                # trace(Dzw' Dzw) of the H2 channel (discrete)
    V = variables(h.n, h.m, 1, False)
    W = cp.Variable((q.p, q.p), symmetric=True, name="W")
    what = f"no state feedback meets ||T_zw||_inf < gamma={gamma:.6g}"
    rep = _cvx.solve_sdp(cp.Minimize(cp.trace(W)), _blocks(h, q, V, W, discrete, regions, 0.0, z_h, 1.0, shared),
                         solver=solver, tol=LEVEL_TOL, infeasible_msg=f"{what} (the mixed LMIs are infeasible)")
    best = float(np.sqrt(max(float(np.trace(_cvx.value(W))), 0.0) + const))
    solves = [rep.as_dict()]
    gen = Generalised(plant.F, plant.G, np.eye(plant.n), (hinf_channel, h2_channel), discrete)
    failure: Exception | None = None
    for factor in BACKOFF_STEPS:
        b = backoff * factor
        bound = (1.0 + b) * best
        z_q = 1.0 / float(np.sqrt(bound**2 - const))
        V = variables(h.n, h.m, 1, False)
        W = cp.Variable((q.p, q.p), symmetric=True, name="W")
        t = cp.Variable(name="t")
        try:
            rep = _cvx.solve_sdp(cp.Maximize(t), _blocks(h, q, V, W, discrete, regions, t, z_h, z_q, shared),
                                 [t <= 1.0, cp.trace(W) <= 1.0], solver=solver, tol=CENTRE_TOL,
                                 infeasible_msg=f"{what} with the H2 bound {b:g} above its optimum")
        except (ConvergenceError, InfeasibleError) as exc:
            failure = exc
            continue
        solves.append({**rep.as_dict(), "centring": "margin"})
        K = h.to_original(V.values().gain(), np.eye(h.n))[0]
        gain = DynamicGain(np.zeros((0, 0)), np.zeros((0, plant.n)), np.zeros((plant.m, 0)), K)
        cert = hinf_certificate(gen, gain, gamma, 0)
        norm = h2_norm(gen, gain, 1)
        user_bound = bound / q.level_scale
        if cert is not None and norm <= user_bound and (not regions or poles_inside(gen, gain, regions)):
            return MixedState(K, best / q.level_scale, user_bound, b, tuple(solves),
                              {**cert, "h2_norm_ratio": norm / user_bound})
        failure = ConvergenceError(f"the gain of the centred point at {b:g} above the optimal H2 bound is not "
                                   "certified by its closed loop; increase backoff")
    raise failure or ConvergenceError("no centring attempt")
