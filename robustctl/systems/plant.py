"""Linear time-invariant plants ``x[k+1] = F x[k] + G u[k]`` (or ``x' = F x + G u``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._validation import as_matrix, check_choice, check_positive_scalar, check_square, frozen, frozen_complex
from .stability import unstabilizable_modes

__all__ = ["Plant", "check_plant", "check_vertices"]

_METHODS = ("zoh", "tustin", "euler")


def _singular(M: np.ndarray, scale: float) -> bool:
    """Whether ``M`` is singular up to the rounding of forming it from terms of norm ``scale``.

    Smallest singular value at most ``n eps scale`` (or ``M`` not finite).
    """
    if not np.all(np.isfinite(M)):
        return True
    return bool(np.linalg.svd(M, compute_uv=False)[-1] <= M.shape[0] * np.finfo(float).eps * scale)


@dataclass(frozen=True, eq=False, repr=False)
class Plant:
    """A state-space plant without outputs.

    Discrete time (``dt > 0``): ``x[k+1] = F x[k] + G u[k]``.
    Continuous time (``dt=None``): ``dx/dt = F x + G u`` (``F``, ``G`` are then
    the usual ``A``, ``B``); only the H-infinity synthesis accepts those.

    Parameters
    ----------
    F : (n, n) array_like
    G : (n, m) array_like (a 1-D array is read as one input column)
    dt : float or None
        Sampling time in seconds, or ``None`` for a continuous-time plant.
    """

    F: np.ndarray
    G: np.ndarray
    dt: float | None

    def __init__(self, F, G, dt: float | None):
        F = check_square(as_matrix(F, "F"), "F")
        G = as_matrix(G, "G", rows=F.shape[0], vector="column", rows_what="the number of states, from F")
        dt = None if dt is None else check_positive_scalar(dt, "dt")
        object.__setattr__(self, "F", frozen(F))
        object.__setattr__(self, "G", frozen(G))
        object.__setattr__(self, "dt", dt)

    # -- sizes -------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of states."""
        return self.F.shape[0]

    @property
    def m(self) -> int:
        """Number of inputs."""
        return self.G.shape[1]

    @property
    def is_discrete(self) -> bool:
        """Whether the plant is discrete-time (``dt`` given)."""
        return self.dt is not None

    @cached_property
    def unstabilizable_modes(self) -> np.ndarray:
        """Eigenvalues of ``F`` that are not stable and that ``G`` cannot move (PBH test).

        Empty for a stabilisable plant; see :mod:`robustctl.systems.stability` for the tolerances.
        """
        return frozen_complex(unstabilizable_modes(self.F, self.G, discrete=self.is_discrete))

    @property
    def is_stabilizable(self) -> bool:
        """Some gain ``u = K x`` makes the loop stable (no ``unstabilizable_modes``)."""
        return self.unstabilizable_modes.size == 0

    # -- constructors ------------------------------------------------------
    @classmethod
    def from_continuous(cls, A, B, dt: float | None, method: str = "zoh") -> Plant:
        """Discretise ``dx/dt = A x + B u`` with sampling time ``dt``.

        ``method`` is ``"zoh"`` (exact for piecewise-constant inputs, via
        python-control's ``c2d``), ``"tustin"`` (bilinear; needs ``I - A dt/2``
        invertible, i.e. no eigenvalue of ``A`` at ``2/dt``, up to the
        rounding of forming it: smallest singular value above
        ``n eps (1 + ||A|| dt/2)``) or ``"euler"``
        (forward Euler, ``F = I + A dt``, ``G = B dt``). ``dt=None`` keeps the
        plant in continuous time. ``ValueError`` naming ``A`` if ``A dt`` is
        too large for the discrete plant to be finite.
        """
        A = check_square(as_matrix(A, "A"), "A")
        B = as_matrix(B, "B", rows=A.shape[0], vector="column", rows_what="the number of states, from A")
        if dt is None:
            return cls(A, B, None)
        dt = check_positive_scalar(dt, "dt")
        method = check_choice(method, "method", _METHODS)
        n, m = B.shape
        with np.errstate(all="ignore"):
            if method == "euler":
                F, G = np.eye(n) + A * dt, B * dt
            else:
                half = A * (dt / 2)
                if method == "tustin" and _singular(np.eye(n) - half, 1.0 + float(np.linalg.norm(half, 2))):
                    raise ValueError(f"method='tustin' needs I - A dt/2 invertible, but A has an eigenvalue at "
                                     f"2/dt = {2 / dt:g} (dt={dt:g}); use method='zoh' or another dt")
                import control

                sysd = control.c2d(control.ss(A, B, np.zeros((1, n)), np.zeros((1, m))), dt, method=method)
                F, G = sysd.A, sysd.B
        if not (np.all(np.isfinite(F)) and np.all(np.isfinite(G))):
            raise ValueError(f"A is too large for dt={dt:g}: the discretised plant ({method}) has non-finite "
                             "entries; check the units of A and B or use a smaller dt")
        return cls(F, G, dt)

    @classmethod
    def from_statespace(cls, sys) -> Plant:
        """Build a plant from a python-control ``StateSpace`` (its C and D are ignored)."""
        import control

        if not isinstance(sys, control.StateSpace):
            raise TypeError(f"sys must be a control.StateSpace, got {type(sys).__name__}")
        if sys.dt is True:
            raise ValueError("sys has an unspecified sampling time (dt=True); give a number")
        return cls(sys.A, sys.B, None if not sys.dt else float(sys.dt))

    def to_statespace(self, C=None, D=None):
        """The plant as a python-control ``StateSpace`` (default outputs: the full state)."""
        import control

        C = np.eye(self.n) if C is None else as_matrix(C, "C", cols=self.n, cols_what="the number of states")
        D = np.zeros((C.shape[0], self.m)) if D is None else as_matrix(
            D, "D", rows=C.shape[0], cols=self.m, rows_what="rows of C", cols_what="the number of inputs")
        return control.ss(self.F, self.G, C, D, 0 if self.dt is None else self.dt)

    def __repr__(self) -> str:
        time = "continuous" if self.dt is None else f"dt={self.dt:g}"
        return f"Plant(n={self.n}, m={self.m}, {time})"


def check_plant(value, name: str = "plant", *, discrete_for: str | None = None) -> Plant:
    """``value`` if it is a :class:`~robustctl.Plant`, else ``TypeError`` naming ``name``.

    With ``discrete_for`` (a design's name), a continuous-time plant is refused
    with a ``ValueError`` that says so.
    """
    if not isinstance(value, Plant):
        raise TypeError(f"{name} must be a robustctl.Plant, got {type(value).__name__}")
    if discrete_for is not None and not value.is_discrete:
        raise ValueError(f"{name} must be discrete-time (dt > 0) for {discrete_for}; discretise it first")
    return value


def check_plants(plants, name: str = "plants", *, like: Plant | None = None, reference: str | None = None,
                 non_empty: bool = True, discrete_for: str | None = None) -> list[Plant]:
    """``plants`` as a list of :class:`~robustctl.Plant` of one size and sampling time.

    Every plant must have the ``n``, ``m`` and ``dt`` of ``like`` (default
    ``plants[0]``), which ``reference`` names in the messages (default
    ``"<name>[0]"``); with ``discrete_for`` each must be discrete-time. The
    one check of a plant set: polytope vertices, the scenarios of a tuning
    problem, the plants of :meth:`NormBounded.from_plants
    <robustctl.NormBounded.from_plants>`. ``TypeError`` for anything but a
    list (or tuple) of plants (an empty one too, with ``non_empty``),
    ``ValueError`` naming ``<name>[i]`` for a size or sampling time that differs.
    """
    what = f"a {'non-empty ' if non_empty else ''}list of robustctl.Plant"
    if isinstance(plants, Plant) or not isinstance(plants, Sequence) or isinstance(plants, (str, bytes)):
        raise TypeError(f"{name} must be {what}, got {type(plants).__name__}")
    if non_empty and len(plants) == 0:
        raise TypeError(f"{name} must be {what}, got an empty {type(plants).__name__}")
    out = [check_plant(p, f"{name}[{i}]", discrete_for=discrete_for) for i, p in enumerate(plants)]
    ref = like if like is not None else (out[0] if out else None)
    reference = reference or f"{name}[0]"
    for i, p in enumerate(out):
        assert ref is not None
        if (p.n, p.m) != (ref.n, ref.m):
            raise ValueError(f"{name}[{i}] must have n={ref.n} states and m={ref.m} inputs like {reference}, "
                             f"got n={p.n}, m={p.m}")
        if p.dt != ref.dt:
            raise ValueError(f"{name}[{i}] must have the sampling time of {reference} (dt={ref.dt}), got dt={p.dt}")
    return out


def check_vertices(plant: Plant, vertices, *, reference: str = "plant", non_empty: bool = False) -> list[Plant]:
    """``[plant, *vertices]``, each vertex checked to be a :class:`~robustctl.Plant` of ``plant``'s size and ``dt``.

    The vertices of a polytope ``conv{plant, *vertices}`` (e.g. the ``vertices``
    of :func:`robustctl.hinf` and :func:`robustctl.robust_stability`).
    ``vertices=None`` (and, unless ``non_empty``, an empty list) is the plant
    alone. ``reference`` names ``plant`` in the messages (:func:`check_plants`).
    """
    if vertices is None and not non_empty:
        return [plant]
    return [plant, *check_plants(vertices, "vertices", like=plant, reference=reference, non_empty=non_empty)]
