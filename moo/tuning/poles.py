r"""Eigenvalue goals: the closed loop's spectral radius and poles in a region, and the controller's own poles.

The closed loop ``A_cl`` (``F + G K`` for a state feedback; the loops of
:mod:`moo.tuning.loops` for an output feedback), per scenario, reduced with
``over="max"`` by default:

* :class:`SpectralRadius` - ``max |eig(A_cl)|`` (discrete plants);
* :class:`PoleRegion` - ``max_z lambda_max(L + M z + M' conj(z))`` over the
  poles ``z`` and the regions' characteristic matrices (Chilali & Gahinet
  1996): ``<= 0`` with every pole inside; for a :class:`robustctl.Disk` it is
  ``max |z - c| - r``, the distance of the farthest pole beyond the circle;
* :class:`ControllerPoles` - the controller's own poles (``max |eig(A_c)|``
  or a region's violation).

The protocol every goal follows is in :mod:`moo.tuning.goals`.

References
----------
M. Chilali, P. Gahinet, "H-infinity design with pole placement constraints: an
LMI approach", IEEE TAC 41(3), 1996.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import robustctl as rc
from robustctl.systems.regions import Region, as_regions
from robustctl.validation import check_choice

from .goals import OVER, Goal, check_scenarios, checked_loops, discrete, reduce, set_fields
from .loops import check_controllers, count, is_output_feedback

__all__ = ["SpectralRadius", "PoleRegion", "ControllerPoles"]


@dataclass(frozen=True, eq=False, repr=False)
class SpectralRadius(Goal):
    r"""Spectral radius ``max |eig(F + G K)|`` of the closed loop, the max (default) or mean over the scenarios.

    Parameters
    ----------
    over : {"mean", "max"}
        Reduction over the scenarios (default the max: the worst scenario).
    name : str
        Label for tables and plots.

    Raises
    ------
    ValueError
        An unknown ``over``.

    See Also
    --------
    robustctl.spectral_radius : the batched eigenvalue computation it uses.
    PoleRegion : a pole constraint in a region of the plane.

    Notes
    -----
    .. math::

        \rho(K) = \max_{s} \max_{i} |\lambda_i(F_s + G_s K)| .

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import SpectralRadius
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]], [[-3.0, -4.0]]])
    >>> rho = SpectralRadius()(K, [plant])
    >>> np.allclose(rho, [np.abs(np.linalg.eigvals(plant.F + plant.G @ k)).max() for k in K])
    True
    """

    over: str = "max"
    name: str = "spectral radius"

    def __post_init__(self):
        check_choice(self.over, "over", OVER)

    def check(self, plants) -> None:
        """The plants must be discrete-time (a continuous loop has a spectral abscissa: use :class:`PoleRegion`)."""
        discrete(plants, "SpectralRadius", " (use PoleRegion(rc.HalfPlane(...)) for a continuous loop)")

    def measure(self, K, plants) -> np.ndarray:
        """The spectral radius of each design, shape (B,)."""
        self.check(plants)
        _, _, loops = checked_loops(K, plants)
        return reduce(np.asarray(rc.spectral_radius(loops.A)), self.over)


@dataclass(frozen=True, eq=False, repr=False)
class PoleRegion(Goal):
    r"""Largest violation of a pole region: ``<= 0`` with every closed-loop pole inside.

    Parameters
    ----------
    region : Region or sequence of Region
        :class:`robustctl.Disk`, :class:`robustctl.HalfPlane`,
        :class:`robustctl.ConicSector`, or a list (their intersection), in the
        ``z`` plane of the discrete plants.
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label for tables and plots (default ``"pole region"``).

    Raises
    ------
    TypeError, ValueError
        ``region`` not a region or a non-empty list of them; an unknown ``over``.

    See Also
    --------
    SpectralRadius : the special case of the disk ``Disk(0, 1)``, plus 1.
    robustctl.Disk, robustctl.HalfPlane, robustctl.ConicSector : the regions.

    Notes
    -----
    With a region's characteristic matrices :math:`L = L^T`, :math:`M`
    (negative definite inside the region [1]_), over the poles :math:`z` of
    :math:`F_s + G_s K` and the regions,

    .. math::

        v(K) = \max_{z} \max_{\text{regions}} \lambda_{\max}\big(L + M z + M^T \bar z\big),

    which for ``Disk(c, r)`` is :math:`\max |z - c| - r` and for a
    half-plane ``Re z < b`` is :math:`2 (\max \operatorname{Re} z - b)`.

    References
    ----------
    .. [1] M. Chilali, P. Gahinet, "H-infinity design with pole placement
       constraints: an LMI approach", IEEE TAC 41(3), 358-367, 1996.

    Examples
    --------
    The pole 0.5 is 0.1 inside the disk of radius 0.6 about the origin:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import PoleRegion
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> K = np.array([[[-0.2]]])                        # x[k+1] = 0.5 x[k]
    >>> PoleRegion(rc.Disk(0.0, 0.6))(K, [plant])
    array([-0.1])
    """

    region: Any
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        try:
            regions = as_regions(self.region)
        except TypeError:
            regions = ()
        if not regions:
            raise TypeError(f"region must be a robustctl Disk, HalfPlane, ConicSector or a non-empty list of "
                            f"them, got {type(self.region).__name__}")
        set_fields(self, region=regions, over=check_choice(self.over, "over", OVER),
             name=self.name or "pole region")

    def check(self, plants) -> None:
        """Only the plants themselves are checked (either time domain: the regions are in its plane)."""
        check_scenarios(plants, continuous=True)

    def measure(self, K, plants) -> np.ndarray:
        """The largest violation of each design, shape (B,)."""
        _, _, loops = checked_loops(K, plants)
        return reduce(_region_violation(np.linalg.eigvals(loops.A), self.region), self.over)


def _region_violation(z: np.ndarray, regions) -> np.ndarray:
    """``max_z max_regions lambda_max(L + M z + M' conj z)`` over the last axis of the poles ``z`` (-inf: no pole)."""
    worst = np.full(z.shape[:-1], -np.inf)
    if z.shape[-1] == 0:
        return worst
    for reg in regions:
        assert isinstance(reg, Region)
        L, M = reg.L, reg.M
        f = L + M * z[..., None, None] + M.T * np.conj(z)[..., None, None]   # Hermitian (..., n, k, k)
        worst = np.maximum(worst, np.linalg.eigvalsh(f)[..., -1].max(axis=-1))
    return worst


@dataclass(frozen=True, eq=False, repr=False)
class ControllerPoles(Goal):
    r"""Where the controller's own poles are: ``max |eig(A_c)|``, or the violation of a pole region.

    MATLAB's ``TuningGoal.ControllerPoles``: keeps a tuned dynamic
    controller stable, slow enough or damped enough (e.g.
    ``at_most(ControllerPoles(), 0.98)``). Without ``region`` the value is
    the spectral radius of ``A_c`` (discrete) or its spectral abscissa
    ``max Re eig(A_c)`` (continuous); with one, the violation as in
    :class:`PoleRegion` (``<= 0`` inside). A controller without states (a
    static feedback) has no poles: 0 without a region, ``-1`` with one. The
    same controller on every scenario: no reduction.

    Parameters
    ----------
    region : Region or sequence of Region, optional
        :class:`robustctl.Disk`, :class:`robustctl.HalfPlane`,
        :class:`robustctl.ConicSector` or a list (their intersection).
    name : str, optional
        Label (default ``"controller poles"``).

    Raises
    ------
    TypeError
        ``region`` not a region or a non-empty list of them.

    See Also
    --------
    PoleRegion : the closed loop's poles.

    Notes
    -----
    .. math::

        v(K) = \max_i |\lambda_i(A_c)| \quad\text{(discrete)}, \qquad
        \max_i \operatorname{Re} \lambda_i(A_c) \quad\text{(continuous)}.

    References
    ----------
    .. [1] P. Gahinet, P. Apkarian, "Structured H-infinity synthesis in
       MATLAB", IFAC World Congress 2011 (tuning goals on the controller's
       poles).

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import ControllerPoles
    >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1, C=[[1.0]])
    >>> K = rc.ControllerBatch(plant, [[[0.9, 0.2], [0.0, -0.3]]], np.ones((1, 2, 1)), np.ones((1, 1, 2)), [[[0.0]]])
    >>> ControllerPoles()(K, [plant])
    array([0.9])
    >>> ControllerPoles(rc.Disk(0.0, 0.8))(K, [plant]).round(6)     # 0.1 beyond the disc
    array([0.1])
    """

    region: Any = None
    name: str = ""

    def __post_init__(self):
        regions = None
        if self.region is not None:
            try:
                regions = as_regions(self.region)
            except TypeError:
                regions = ()
            if not regions:
                raise TypeError(f"region must be a robustctl Disk, HalfPlane, ConicSector or a non-empty list of "
                                f"them, got {type(self.region).__name__}")
        set_fields(self, region=regions, name=self.name or "controller poles")

    def check(self, plants) -> None:
        """Only the plants themselves are checked."""
        check_scenarios(plants, continuous=True)

    def measure(self, K, plants) -> np.ndarray:
        """The controller pole measure of each design, shape (B,)."""
        plants = check_scenarios(plants, continuous=True)
        K = check_controllers(K, plants)
        if not is_output_feedback(K) or K.order == 0:
            return np.full(count(K), 0.0 if self.region is None else -1.0)
        lam = np.linalg.eigvals(K.Ac)                                              # (B, nc)
        if self.region is not None:
            return _region_violation(lam, self.region)
        return np.abs(lam).max(axis=1) if plants[0].is_discrete else lam.real.max(axis=1)
