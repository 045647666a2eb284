r"""LMI pole regions (Chilali & Gahinet 1996): disks, half-planes, conic sectors.

An *LMI region* is ``D = {z in C : L + M z + M' conj(z) < 0}`` with ``L``
symmetric (its *characteristic function*). A matrix ``A`` has every
eigenvalue in ``D`` iff there is ``X > 0`` with

    M_D(A, X) = L (x) X + M (x) (A X) + M' (x) (A X)' < 0     ((x): Kronecker product),

so with ``A = F + G K`` and ``Y = K X`` the condition is linear in
``(X, Y)``: :func:`robustctl.hinf` and :func:`robustctl.h2` take
``poles=Disk(...)`` (or a list of regions: their intersection) and impose it
with the same ``X`` as the performance LMI (the usual, conservative, single
Lyapunov matrix of multi-objective synthesis). Intersections of LMI regions
are LMI regions. Regions are symmetric about the real axis (real plants have
conjugate poles). They apply to the eigenvalues of ``F + G K``: the ``z``
plane for discrete plants (``Disk(0, 0.9)``: spectral radius below 0.9) and
the ``s`` plane for continuous ones (``HalfPlane(-1)``: decay rate above 1,
``ConicSector(0, angle)``: damping ratio above ``cos(angle)``).

Reference: M. Chilali and P. Gahinet, "H-infinity design with pole
placement constraints: an LMI approach", IEEE Trans. Automatic Control
41(3), 358-367, 1996.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._validation import check_positive_scalar, check_real

__all__ = ["Region", "Disk", "HalfPlane", "ConicSector", "as_regions", "describe_regions", "region_lmi"]


class Region:
    """Base class: an LMI region given by its characteristic matrices ``L`` (symmetric) and ``M``."""

    @property
    def L(self) -> np.ndarray:  # pragma: no cover - every region defines it
        """The symmetric characteristic matrix ``L``."""
        raise NotImplementedError

    @property
    def M(self) -> np.ndarray:  # pragma: no cover
        """The characteristic matrix ``M``."""
        raise NotImplementedError

    def real_interval(self) -> tuple[float, float]:  # pragma: no cover
        """The open interval of real points in the region."""
        raise NotImplementedError

    def contains(self, z) -> np.ndarray:
        """Whether each point of ``z`` (complex, any shape) lies in the open region: ``L + M z + M' conj(z) < 0``."""
        z = np.asarray(z, dtype=complex)
        f = self.L + self.M * z[..., None, None] + self.M.T * np.conj(z)[..., None, None]
        return np.linalg.eigvalsh(f).max(axis=-1) < 0


@dataclass(frozen=True)
class Disk(Region):
    """``|z - center| < radius`` (``center`` real).

    Characteristic matrices ``L = [[-r, -c], [-c, -r]]``, ``M = [[0, 1], [0, 0]]``.
    """

    center: float = 0.0
    radius: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "center", check_real(self.center, "center"))
        object.__setattr__(self, "radius", check_positive_scalar(self.radius, "radius"))

    @property
    def L(self) -> np.ndarray:
        """The characteristic matrix ``L`` (class docstring)."""
        return np.array([[-self.radius, -self.center], [-self.center, -self.radius]])

    @property
    def M(self) -> np.ndarray:
        """The characteristic matrix ``M`` (class docstring)."""
        return np.array([[0.0, 1.0], [0.0, 0.0]])

    def real_interval(self) -> tuple[float, float]:
        """The open interval of real points in the region."""
        return self.center - self.radius, self.center + self.radius


@dataclass(frozen=True)
class HalfPlane(Region):
    """``Re z < boundary`` (``side="left"``, e.g. a decay rate) or ``Re z > boundary`` (``side="right"``).

    Characteristic function ``2 Re z - 2 boundary`` (left) or its negative.
    """

    boundary: float = 0.0
    side: str = "left"

    def __post_init__(self):
        object.__setattr__(self, "boundary", check_real(self.boundary, "boundary"))
        if self.side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {self.side!r}")

    @property
    def _sign(self) -> float:
        return 1.0 if self.side == "left" else -1.0

    @property
    def L(self) -> np.ndarray:
        """The characteristic matrix ``L`` (class docstring)."""
        return np.array([[-2.0 * self._sign * self.boundary]])

    @property
    def M(self) -> np.ndarray:
        """The characteristic matrix ``M`` (class docstring)."""
        return np.array([[self._sign]])

    def real_interval(self) -> tuple[float, float]:
        """The open interval of real points in the region."""
        return (-math.inf, self.boundary) if self.side == "left" else (self.boundary, math.inf)


@dataclass(frozen=True)
class ConicSector(Region):
    """The sector ``|Im z| < tan(angle) (apex - Re z)`` opening to the left of ``apex``.

    ``angle`` is the half-angle from the negative real axis, in ``(0, pi/2)``:
    continuous-time poles in ``ConicSector(0, angle)`` have damping ratio
    above ``cos(angle)``. Characteristic matrices (with ``s = sin(angle)``,
    ``c = cos(angle)``) ``L = -2 apex s I``, ``M = [[s, c], [-c, s]]``.
    """

    apex: float = 0.0
    angle: float = math.pi / 4

    def __post_init__(self):
        object.__setattr__(self, "apex", check_real(self.apex, "apex"))
        angle = check_real(self.angle, "angle")
        if not 0.0 < angle < math.pi / 2:
            raise ValueError(f"angle must be in (0, pi/2) radians (the half-angle of the sector), got {angle}")
        object.__setattr__(self, "angle", angle)

    @property
    def L(self) -> np.ndarray:
        """The characteristic matrix ``L`` (class docstring)."""
        return -2.0 * self.apex * math.sin(self.angle) * np.eye(2)

    @property
    def M(self) -> np.ndarray:
        """The characteristic matrix ``M`` (class docstring)."""
        s, c = math.sin(self.angle), math.cos(self.angle)
        return np.array([[s, c], [-c, s]])

    def real_interval(self) -> tuple[float, float]:
        """The open interval of real points in the region."""
        return -math.inf, self.apex


def as_regions(poles) -> tuple[Region, ...]:
    """``poles=`` as a tuple of regions (their intersection): ``None``, one region, or a list of them."""
    if poles is None:
        return ()
    if isinstance(poles, Region):
        return (poles,)
    if isinstance(poles, Sequence) and not isinstance(poles, (str, bytes)) and len(poles) > 0:
        for i, r in enumerate(poles):
            if not isinstance(r, Region):
                raise TypeError(f"poles[{i}] must be a Disk, HalfPlane or ConicSector, got {type(r).__name__}")
        return tuple(poles)
    raise TypeError(f"poles must be a Disk, HalfPlane, ConicSector or a non-empty list of them, "
                    f"got {type(poles).__name__}")


def describe_regions(regions: Sequence[Region]) -> str:
    """``Disk(center=0.0, radius=0.9) and HalfPlane(...)``."""
    return " and ".join(repr(r) for r in regions)


def region_lmi(region: Region, AX, X):
    """``-M_D(A, X)`` (``>= 0`` means the eigenvalues of ``A`` lie in the region), from ``A X`` and ``X``.

    ``AX`` and ``X`` are cvxpy expressions or arrays; the result is a
    symmetric block of size ``k n`` (``k`` the size of ``L``).
    """
    import cvxpy as cp

    L, M = region.L, region.M
    k = L.shape[0]
    rows = [[-(L[i, j] * X + M[i, j] * AX + M[j, i] * AX.T) for j in range(k)] for i in range(k)]
    return cp.bmat(rows)
