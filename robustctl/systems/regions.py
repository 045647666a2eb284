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
    """Base class: an LMI region given by its characteristic matrices ``L`` (symmetric) and ``M``.

    A subclass defines ``L``, ``M`` and :meth:`real_interval`; :meth:`contains`
    and :func:`region_lmi` follow from them (module docstring).

    See Also
    --------
    Disk, HalfPlane, ConicSector : the regions.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.regions import Region
    >>> isinstance(rc.Disk(0.0, 0.9), Region), bool(rc.Disk(0.0, 0.9).contains(0.5))
    (True, True)
    """

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
        """Whether each point of ``z`` lies in the open region: ``L + M z + M' conj(z) < 0``.

        Parameters
        ----------
        z : complex array_like
            Points of the complex plane, any shape.

        Returns
        -------
        ndarray of bool
            The shape of ``z``: True where the characteristic matrix is
            negative definite.
        """
        z = np.asarray(z, dtype=complex)
        f = self.L + self.M * z[..., None, None] + self.M.T * np.conj(z)[..., None, None]
        return np.linalg.eigvalsh(f).max(axis=-1) < 0


@dataclass(frozen=True)
class Disk(Region):
    r"""The open disk ``|z - center| < radius`` (``center`` real), an LMI region.

    For a discrete plant, ``poles=Disk(0, r)`` asks for a spectral radius of
    ``F + G K`` below ``r`` (a decay rate); ``Disk(c, r)`` with ``c > 0``
    also bounds the damping of the poles.

    Parameters
    ----------
    center : float
        Centre on the real axis.
    radius : float
        Radius, positive.

    Attributes
    ----------
    center, radius : float
        As given.
    L, M : ndarray
        The characteristic matrices (Notes).

    Raises
    ------
    ValueError
        A non-finite centre, or a radius that is not positive.
    TypeError
        A non-numeric argument.

    See Also
    --------
    HalfPlane, ConicSector : the other regions.
    robustctl.hinf : takes ``poles=`` regions.

    Notes
    -----
    With ``c`` the centre and ``r`` the radius, the characteristic function
    of Chilali and Gahinet [1]_ is

    .. math::

        f_D(z) = L + M z + M^T \bar z =
        \begin{bmatrix} -r & z - c \\ \bar z - c & -r \end{bmatrix} < 0
        \iff |z - c| < r ,

    (a Schur complement), i.e. ``L = [[-r, -c], [-c, -r]]`` and
    ``M = [[0, 1], [0, 0]]``.

    References
    ----------
    .. [1] M. Chilali, P. Gahinet, "H-infinity design with pole placement
       constraints: an LMI approach", IEEE Trans. Automatic Control 41(3),
       358-367, 1996.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> disk = rc.Disk(center=0.5, radius=0.3)
    >>> z = np.array([0.6, 0.5 + 0.29j, 0.9, 0.1j])
    >>> disk.contains(z)
    array([ True,  True, False, False])
    >>> bool(np.array_equal(disk.contains(z), abs(z - 0.5) < 0.3))
    True
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
    r"""The half-plane ``Re z < boundary`` (``side="left"``) or ``Re z > boundary`` (``side="right"``).

    For a continuous plant, ``poles=HalfPlane(-a)`` asks for every pole of
    ``F + G K`` to decay at least as fast as ``exp(-a t)``.

    Parameters
    ----------
    boundary : float
        The vertical line ``Re z = boundary``.
    side : {"left", "right"}
        Which side of it the region is.

    Attributes
    ----------
    boundary : float
    side : str
    L, M : ndarray
        The characteristic matrices (1 x 1, Notes).

    Raises
    ------
    ValueError
        A non-finite boundary or another ``side``.
    TypeError
        A non-numeric boundary.

    See Also
    --------
    Disk, ConicSector : the other regions.

    Notes
    -----
    The characteristic function [1]_ of the left half-plane is

    .. math::

        f_D(z) = -2 b + z + \bar z = 2 (\operatorname{Re} z - b) < 0 ,

    ``L = -2 b``, ``M = 1`` (the right half-plane: both negated).

    References
    ----------
    .. [1] M. Chilali, P. Gahinet, "H-infinity design with pole placement
       constraints: an LMI approach", IEEE Trans. Automatic Control 41(3),
       358-367, 1996.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> region = rc.HalfPlane(-1.0)                 # decay rate above 1
    >>> z = np.array([-2.0 + 3.0j, -0.5, -0.999])
    >>> region.contains(z)
    array([ True, False, False])
    >>> bool(np.array_equal(region.contains(z), z.real < -1.0))
    True
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
    r"""The sector ``|Im z| < tan(angle) (apex - Re z)`` opening to the left of ``apex``.

    ``angle`` is the half-angle from the negative real axis, in ``(0, pi/2)``:
    continuous-time poles in ``ConicSector(0, angle)`` have damping ratio
    above ``cos(angle)``.

    Parameters
    ----------
    apex : float
        The sector's apex on the real axis.
    angle : float
        Half-angle from the negative real axis [rad], in ``(0, pi/2)``.

    Attributes
    ----------
    apex, angle : float
    L, M : ndarray
        The characteristic matrices (2 x 2, Notes).

    Raises
    ------
    ValueError
        An angle outside ``(0, pi/2)``, a non-finite apex.
    TypeError
        A non-numeric argument.

    See Also
    --------
    Disk, HalfPlane : the other regions.

    Notes
    -----
    With ``s = sin(angle)``, ``c = cos(angle)`` and ``a`` the apex, the
    characteristic function [1]_ is

    .. math::

        f_D(z) = \begin{bmatrix} s\,(z + \bar z - 2a) & c\,(z - \bar z) \\
                                 c\,(\bar z - z) & s\,(z + \bar z - 2a) \end{bmatrix} < 0 ,

    i.e. ``L = -2 a s I`` and ``M = [[s, c], [-c, s]]``.

    References
    ----------
    .. [1] M. Chilali, P. Gahinet, "H-infinity design with pole placement
       constraints: an LMI approach", IEEE Trans. Automatic Control 41(3),
       358-367, 1996.

    Examples
    --------
    Poles of damping ratio 0.7 lie in the sector of damping above 0.5, poles
    of damping 0.3 do not (python-control's ``damp`` reads the damping back):

    >>> import math
    >>> import numpy as np
    >>> import control
    >>> import robustctl as rc
    >>> sector = rc.ConicSector(0.0, math.acos(0.5))
    >>> poles = [control.tf([1.0], [1.0, 2 * zeta * 2.0, 4.0]).poles()[0] for zeta in (0.7, 0.3)]
    >>> sector.contains(poles)
    array([ True, False])
    >>> [round(float(control.damp(control.tf([1.0], np.poly([p, np.conj(p)]).real), doprint=False)[1][0]), 6)
    ...  for p in poles]
    [0.7, 0.3]
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
    """``poles=`` as a tuple of regions (their intersection): ``None``, one region, or a list of them.

    Parameters
    ----------
    poles : None, Region or sequence of Region
        The ``poles=`` argument of a synthesis.

    Returns
    -------
    tuple of Region
        Empty for None.

    Raises
    ------
    TypeError
        Anything else, or an empty sequence (naming the bad entry).

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.regions import as_regions
    >>> as_regions(None), as_regions(rc.Disk(0.0, 0.9))
    ((), (Disk(center=0.0, radius=0.9),))
    """
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
    """``Disk(center=0.0, radius=0.9) and HalfPlane(...)``: the regions for messages.

    Parameters
    ----------
    regions : sequence of Region
        The regions (their intersection).

    Returns
    -------
    str

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.regions import describe_regions
    >>> describe_regions([rc.Disk(0.0, 0.9), rc.HalfPlane(0.2, "right")])
    "Disk(center=0.0, radius=0.9) and HalfPlane(boundary=0.2, side='right')"
    """
    return " and ".join(repr(r) for r in regions)


def region_lmi(region: Region, AX, X):
    r"""``-M_D(A, X)`` (``>= 0`` means the eigenvalues of ``A`` lie in the region), from ``A X`` and ``X``.

    Parameters
    ----------
    region : Region
        The region, with ``L`` of size ``k``.
    AX : (n, n) cvxpy expression or ndarray
        ``A X`` (in a synthesis ``F X + G Y``).
    X : (n, n) cvxpy expression or ndarray
        The Lyapunov matrix, symmetric positive definite.

    Returns
    -------
    cvxpy expression
        The symmetric block ``-M_D(A, X)`` of size ``k n``.

    Notes
    -----
    With the Kronecker product [1]_,

    .. math::

        M_D(A, X) = L \otimes X + M \otimes (A X) + M^T \otimes (A X)^T ,

    and ``A`` has its eigenvalues in the region iff ``M_D(A, X) < 0`` for
    some ``X > 0``.

    References
    ----------
    .. [1] M. Chilali, P. Gahinet, "H-infinity design with pole placement
       constraints: an LMI approach", IEEE Trans. Automatic Control 41(3),
       358-367, 1996.

    Examples
    --------
    ``A`` with eigenvalues 0.5 and -0.3 and ``X = I`` satisfy the disk of
    radius 0.9: the block is ``[[0.9 I, -A], [-A', 0.9 I]]``, positive
    definite because ``||A|| < 0.9``.

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.systems.regions import region_lmi
    >>> A = np.diag([0.5, -0.3])
    >>> block = region_lmi(rc.Disk(0.0, 0.9), A, np.eye(2))
    >>> bool(np.allclose(block.value, [[0.9, 0, -0.5, 0], [0, 0.9, 0, 0.3], [-0.5, 0, 0.9, 0], [0, 0.3, 0, 0.9]]))
    True
    >>> round(float(np.linalg.eigvalsh(block.value)[0]), 6)
    0.4
    """
    import cvxpy as cp

    L, M = region.L, region.M
    k = L.shape[0]
    rows = [[-(L[i, j] * X + M[i, j] * AX + M[j, i] * AX.T) for j in range(k)] for i in range(k)]
    return cp.bmat(rows)
