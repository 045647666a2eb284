"""Stage 1 of the synthesis: the validated problem statement."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .. import _cvx
from .._validation import check_performance, check_positive_scalar
from ..errors import InfeasibleError
from ..plant import Plant
from ..regions import Region, as_regions, describe_regions
from ..uncertainty import NormBounded
from . import _tolerances as tol

__all__ = ["Problem", "validate", "check_vertices", "check_stabilisable", "check_poles_reachable",
           "check_uncertainty", "check_backoff", "immovable_mode"]


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
             solver, poles=None, uncertainty=None) -> Problem:
    """Check every argument of :func:`robustctl.hinf` (errors name the argument) and stabilisability."""
    if not isinstance(plant, Plant):
        raise TypeError(f"plant must be a robustctl.Plant, got {type(plant).__name__}")
    plants = check_vertices(plant, vertices)
    Bw, Cz, Dzu, Dzw = check_performance(plant.n, plant.m, Bw, Cz, Dzu, Dzw)
    if gamma is not None:
        gamma = check_positive_scalar(gamma, "gamma")
    if u_max is not None:
        u_max = _check_u_max(u_max, plant.m)
        w_energy = 1.0 if w_energy is None else check_positive_scalar(w_energy, "w_energy")
    elif w_energy is not None:
        raise ValueError("w_energy is only used together with u_max; give u_max or drop w_energy")
    backoff = check_backoff(backoff)
    if not isinstance(extended, (bool, np.bool_)):
        raise TypeError(f"extended must be a bool, got {type(extended).__name__}")
    if extended and not plant.is_discrete:
        raise ValueError("extended=True is the discrete-time slack-variable LMI; plant is continuous-time (dt=None)")
    solver = _cvx.check_solver(solver)
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
    if not isinstance(uncertainty, NormBounded):
        raise TypeError(f"uncertainty must be a robustctl.NormBounded, got {type(uncertainty).__name__}")
    uncertainty.check_plant(plant)
    if not np.any(uncertainty.H) or not (np.any(uncertainty.EF) or np.any(uncertainty.EG)):
        return None  # dF = dG = 0 exactly: the nominal design (the S-procedure multiplier would be unbounded)
    return uncertainty


def check_backoff(backoff) -> float:
    """A finite real ``>= 0``."""
    if isinstance(backoff, bool) or not isinstance(backoff, numbers.Real) or not np.isfinite(backoff) \
            or backoff < 0:
        raise ValueError(f"backoff must be a finite number >= 0, got {backoff!r}")
    return float(backoff)


def check_vertices(plant: Plant, vertices) -> list[Plant]:
    """``[plant] + vertices`` after checking that every vertex is a Plant of the same size and dt."""
    plants = [plant]
    if vertices is None:
        return plants
    if isinstance(vertices, Plant) or not isinstance(vertices, Sequence):
        raise TypeError("vertices must be a list of robustctl.Plant")
    for i, v in enumerate(vertices):
        if not isinstance(v, Plant):
            raise TypeError(f"vertices[{i}] must be a robustctl.Plant, got {type(v).__name__}")
        if (v.n, v.m) != (plant.n, plant.m):
            raise ValueError(f"vertices[{i}] must have n={plant.n} states and m={plant.m} inputs like plant, "
                             f"got n={v.n}, m={v.m}")
        if v.dt != plant.dt:
            raise ValueError(f"vertices[{i}] must have the sampling time of plant (dt={plant.dt}), got dt={v.dt}")
        plants.append(v)
    return plants


def _check_u_max(u_max, m: int) -> np.ndarray:
    if isinstance(u_max, (str, bytes)):
        raise TypeError(f"u_max must be a positive number or {m} positive numbers, got {type(u_max).__name__}")
    try:
        arr = np.array(u_max, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"u_max must be a positive number or {m} positive numbers") from None
    if arr.ndim == 0:
        arr = np.full(m, float(arr))
    if arr.shape != (m,):
        raise ValueError(f"u_max must be a scalar or have {m} {'entry' if m == 1 else 'entries'} "
                         f"(the number of inputs), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("u_max must be finite (use u_max=None for no input bound)")
    if np.any(arr <= 0):
        raise ValueError(f"u_max must be > 0 for every input, got {arr.tolist()}")
    return arr


def immovable_mode(plant: Plant, concerned) -> complex | None:
    """The first eigenvalue ``lambda`` of ``F`` with ``concerned(lambda)`` that the input cannot move (PBH).

    PBH rank test: ``[F - lambda I, G]`` has a smallest singular value of at
    most ``PBH_RANK * max(1, ||[F G]||)``.
    """
    F, G = plant.F, plant.G
    scale = max(1.0, np.linalg.norm(np.hstack([F, G]), 2))
    for lam in np.linalg.eigvals(F):
        if concerned(lam) and \
                np.linalg.svd(np.hstack([F - lam * np.eye(plant.n), G]), compute_uv=False)[-1] <= tol.PBH_RANK * scale:
            return complex(lam)
    return None


def _where(i: int) -> str:
    return "plant" if i == 0 else f"vertices[{i - 1}]"


def check_stabilisable(plants: Sequence[Plant]) -> None:
    """PBH test at every unstable eigenvalue of every vertex; plain-English InfeasibleError if it fails."""
    for i, p in enumerate(plants):
        scale = max(1.0, np.linalg.norm(np.hstack([p.F, p.G]), 2))
        if p.is_discrete:
            lam = immovable_mode(p, lambda z: abs(z) >= 1.0 - tol.UNSTABLE_MODE)
        else:
            lam = immovable_mode(p, lambda s: s.real >= -tol.UNSTABLE_MODE * scale)
        if lam is not None:
            kind = "|lambda| >= 1" if p.is_discrete else "Re(lambda) >= 0"
            raise InfeasibleError(
                f"{_where(i)} is not stabilisable: its mode lambda = {lam:.6g} ({kind}) cannot be moved "
                "by the input G (PBH rank test), so no gain u = K x makes the loop stable and no finite "
                "gamma exists")


def check_poles_reachable(plants: Sequence[Plant], regions: Sequence[Region]) -> None:
    """InfeasibleError with the reason if no gain can place the poles of a vertex in the regions.

    Exact for one plant: the regions and the stability region must meet on
    the real axis (an open convex set symmetric about it then contains a
    real interval, where the movable poles can be placed), and every mode
    outside the regions must be movable by the input (PBH rank test).
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
        lam = immovable_mode(p, lambda z: not all(r.contains(z) for r in regions))
        if lam is not None:
            raise InfeasibleError(
                f"{_where(i)}'s mode lambda = {lam:.6g} lies outside the pole region {describe_regions(regions)} "
                "and cannot be moved by the input G (PBH rank test), so no gain places every closed-loop pole "
                "there")
