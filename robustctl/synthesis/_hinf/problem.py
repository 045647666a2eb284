"""Stage 1 of the synthesis: the validated problem statement."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ... import _cvx
from ..._validation import check_bool, check_performance, check_positive_scalar, check_positive_vector, check_real
from ...errors import InfeasibleError
from ...systems.plant import Plant, check_plant, check_vertices
from ...systems.regions import Region, as_regions, describe_regions
from ...systems.stability import check_stabilizable, immovable_modes
from ...systems.uncertainty import NormBounded, check_norm_bounded

__all__ = ["Problem", "validate", "check_stabilisable", "check_poles_reachable", "check_uncertainty",
           "vertex_name"]


@dataclass(frozen=True, eq=False)
class Problem:
    """What :func:`robustctl.hinf` was asked, checked: plants, channels and options.

    ``plants`` is ``(plant, *vertices)``; ``u_max`` is ``None`` or one bound
    per input; ``w_energy`` is set exactly when ``u_max`` is; ``regions`` the
    pole regions (their intersection; empty for none); ``uncertainty`` a
    :class:`~robustctl.NormBounded` with ``dF, dG`` not identically zero, or
    ``None``.
    """

    plants: tuple[Plant, ...]
    Bw: np.ndarray
    Cz: np.ndarray
    Dzu: np.ndarray
    Dzw: np.ndarray
    gamma: float | None
    u_max: np.ndarray | None
    w_energy: float | None
    backoff: float
    extended: bool
    solver: str
    regions: tuple[Region, ...] = ()
    uncertainty: NormBounded | None = None

    @property
    def discrete(self) -> bool:
        return self.plants[0].is_discrete

    @property
    def polytopic(self) -> bool:
        return len(self.plants) > 1

    def beyond_plain(self) -> list[str]:
        """The arguments that make this more than the plain problem, in the order of ``hinf``'s signature.

        The plain problem: one plant, free level, standard LMI, no input bound, pole region or uncertainty.
        """
        return [name for name, on in (("vertices", self.polytopic), ("gamma", self.gamma is not None),
                                      ("u_max", self.u_max is not None), ("extended", self.extended),
                                      ("poles", bool(self.regions)), ("uncertainty", self.uncertainty is not None))
                if on]

    def infeasibility(self) -> str:
        """Plain-English statement of what no gain satisfies (for InfeasibleError messages)."""
        if not self.polytopic:
            what = "no stabilising gain satisfies the H-infinity LMI"
        else:
            what = (f"no common {'slack matrix' if self.extended else 'Lyapunov matrix'} and gain satisfy the "
                    f"H-infinity LMI at all {len(self.plants)} vertices"
                    + ("" if self.extended or self.regions or self.uncertainty else " (try extended=True)"))
        if self.uncertainty is not None:
            what += " for every ||Delta|| <= 1 of the norm-bounded uncertainty (S-procedure)"
        if self.regions:
            what += f" with every closed-loop pole in {describe_regions(self.regions)} (the same Lyapunov matrix)"
        if self.u_max is not None:
            what += (f" together with |u_j| <= u_max = {self.u_max.tolist()} for every disturbance of energy "
                     f"{self.w_energy:g} (the input bound may be too tight for this disturbance energy)")
        return what


def validate(plant, *, Bw, Cz, Dzu, Dzw, vertices, gamma, u_max, w_energy, backoff, extended,
             solver, poles=None, uncertainty=None, defer_solver: bool = False) -> Problem:
    """Check every argument of :func:`robustctl.hinf` (errors name the argument) and stabilisability.

    ``defer_solver``: only check that ``solver`` names an SDP solver cvxpy knows (``robustctl._cvx.SDP_SOLVERS``); the
    full check (:func:`robustctl._cvx.check_solver`, which imports cvxpy) is left
    to the caller, for a path that may not need an SDP solver at all.
    """
    plants = check_vertices(check_plant(plant), vertices, non_empty=vertices is not None)
    Bw, Cz, Dzu, Dzw = check_performance(plant.n, plant.m, Bw, Cz, Dzu, Dzw)
    if gamma is not None:
        gamma = check_positive_scalar(gamma, "gamma")
    if u_max is not None:
        u_max = check_positive_vector(u_max, "u_max", plant.m, what="the number of inputs")
        w_energy = 1.0 if w_energy is None else check_positive_scalar(w_energy, "w_energy")
    elif w_energy is not None:
        raise ValueError("w_energy is only used together with u_max; give u_max or drop w_energy")
    backoff = check_real(backoff, "backoff", minimum=0.0)
    if check_bool(extended, "extended") and not plant.is_discrete:
        raise ValueError("extended=True is the discrete-time slack-variable LMI; plant is continuous-time (dt=None)")
    solver = _cvx.check_solver(solver, installed=not defer_solver)
    regions = as_regions(poles)
    uncertainty = check_uncertainty(uncertainty, plant)
    for name, given in (("poles", regions), ("uncertainty", uncertainty)):
        if extended and given:
            raise ValueError(f"{name} is supported with the standard LMI only; drop {name} or use extended=False")
    check_stabilisable(plants)
    check_poles_reachable(plants, regions)
    return Problem(plants=tuple(plants), Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, gamma=gamma, u_max=u_max,
                   w_energy=w_energy, backoff=float(backoff), extended=bool(extended), solver=solver,
                   regions=regions, uncertainty=uncertainty)


def check_uncertainty(uncertainty, plant: Plant) -> NormBounded | None:
    """A NormBounded of the plant's size; ``None`` if absent or if ``H = 0`` or ``[EF EG] = 0`` (no uncertainty)."""
    if uncertainty is None:
        return None
    check_norm_bounded(uncertainty, plant)
    if not np.any(uncertainty.H) or not (np.any(uncertainty.EF) or np.any(uncertainty.EG)):
        return None  # dF = dG = 0 exactly: the nominal design (the S-procedure multiplier would be unbounded)
    return uncertainty


def vertex_name(i: int) -> str:
    """How messages name ``plants[i]``: ``"plant"``, then ``"vertices[0]"``, ..."""
    return "plant" if i == 0 else f"vertices[{i - 1}]"


def check_stabilisable(plants: Sequence[Plant]) -> None:
    """:func:`~robustctl.systems.stability.check_stabilizable` at every vertex (``NotStabilizableError``)."""
    for i, p in enumerate(plants):
        check_stabilizable(p, vertex_name(i))


def check_poles_reachable(plants: Sequence[Plant], regions: Sequence[Region]) -> None:
    """InfeasibleError with the reason if no gain can place the poles of a vertex in the regions.

    Exact for one plant: the regions and the stability region must meet on
    the real axis (an open convex set symmetric about it then contains a
    real interval, where the movable poles can be placed), and every mode
    outside the regions must be movable by the input (PBH rank test,
    :func:`robustctl.systems.stability.immovable_modes`).
    """
    if not regions:
        return
    discrete = plants[0].is_discrete
    lo, hi = (-1.0, 1.0) if discrete else (-np.inf, 0.0)
    for r in regions:
        a, b = r.real_interval()
        lo, hi = max(lo, a), min(hi, b)
    if not lo < hi:
        stable = "|z| < 1" if discrete else "Re z < 0"
        raise InfeasibleError(f"the pole regions {describe_regions(regions)} have no point in common with each "
                              f"other and with the stability region {stable} (none on the real axis), so no gain "
                              "places every closed-loop pole there")
    for i, p in enumerate(plants):
        stuck = immovable_modes(p.F, p.G, lambda z: ~np.all([r.contains(z) for r in regions], axis=0))
        if stuck.size:
            raise InfeasibleError(
                f"{vertex_name(i)}'s mode lambda = {complex(stuck[0]):.6g} lies outside the pole region "
                f"{describe_regions(regions)} and cannot be moved by the input G (PBH rank test), so no gain "
                "places every closed-loop pole there")
