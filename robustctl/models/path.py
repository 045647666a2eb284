"""Reference paths for path following at constant speed.

A path is a planar curve given by its signed curvature ``kappa(s)`` along the
arc length ``s`` (positive = turning left / counter-clockwise) and a start
pose. Driven at constant speed ``v`` and sampled every ``dt``, it becomes the
curvature signal ``kappa[k]`` that enters the path-following model as a known
disturbance (``theta' = psidot - v kappa``, see :mod:`robustctl.models.truck`),
plus the path's global pose ``(X, Y, heading)`` at ``s_k = v k dt`` used to
draw the vehicle in global coordinates.

Geometry: ``heading(s) = heading_0 + int_0^s kappa``, ``X(s) = X_0 + int cos(heading)``,
``Y(s) = Y_0 + int sin(heading)``, integrated on a grid 16 times finer than
``v dt`` (composite trapezoid). ``kappa[k]`` is the *mean* curvature over
``[s_k, s_{k+1}]``, so a zero-order-hold model turns the path heading by
exactly the right amount each sample.

Build a path from road elements (:class:`Straight`, :class:`Curve` with
clothoid transitions, :class:`LaneChange`), from any curvature profile, or
from waypoints; :func:`default_route` is the route used by the paper
reproduction.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .._validation import as_batch, check_positive_scalar, frozen

__all__ = ["ReferencePath", "Straight", "Curve", "LaneChange", "default_route", "DEFAULT_SPEED"]

#: The paper's forward speed, 60 km/h [m/s].
DEFAULT_SPEED = 16.6667
_FINE = 16  # integration sub-steps per sample


# -- road elements ------------------------------------------------------------
@dataclass(frozen=True)
class Straight:
    """A straight of ``length`` metres (a road element of :meth:`ReferencePath.from_segments`).

    Parameters
    ----------
    length : float
        Length [m], positive.

    Raises
    ------
    ValueError, TypeError
        A length that is not a positive number.

    See Also
    --------
    Curve, LaneChange : the other road elements.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.path import Straight
    >>> Straight(100.0).curvature(np.array([0.0, 50.0])).tolist()
    [0.0, 0.0]
    """

    length: float

    def __post_init__(self):
        check_positive_scalar(self.length, "Straight.length")

    def curvature(self, s: np.ndarray) -> np.ndarray:
        """Curvature [1/m] at arc lengths ``s`` [m] from the element's start: zero.

        Parameters
        ----------
        s : ndarray
            Arc lengths from the element's start [m].

        Returns
        -------
        ndarray
            Zeros of the shape of ``s``.
        """
        return np.zeros_like(s)


@dataclass(frozen=True)
class Curve:
    r"""A circular arc of ``radius`` [m] turning by ``angle`` [deg] (positive = left).

    The curvature ramps linearly from 0 to ``±1/radius`` over ``transition``
    metres (a clothoid, as in road design [1]_), stays constant, and ramps back over
    another ``transition`` metres. The heading turns by exactly ``angle``; the
    element's length is ``|angle| radius + transition`` (needs
    ``|angle| radius >= transition``).

    Parameters
    ----------
    radius : float
        Radius of the arc [m], positive.
    angle : float
        Heading change [deg], non-zero; positive turns left.
    transition : float
        Length of each clothoid ramp [m], ``>= 0``.

    Raises
    ------
    ValueError
        A non-positive radius, a zero or non-finite angle, a negative
        transition or one longer than the turn.

    See Also
    --------
    Straight, LaneChange : the other road elements.

    Notes
    -----
    With ``k = sign(angle) / radius``, ``L`` the length and ``L_t`` the
    transition, the curvature at ``s`` is

    .. math::

        \kappa(s) = k\, \min\left(1, \frac{\min(s, L - s)}{L_t}\right),
        \qquad \int_0^L \kappa(s)\, ds = k\,(L - L_t) = \text{angle} .

    References
    ----------
    .. [1] American Association of State Highway and Transportation
       Officials, *A Policy on Geometric Design of Highways and Streets*,
       7th ed., AASHTO 2018 (transition curves).

    Examples
    --------
    The curvature integrates to the heading change:

    >>> import numpy as np
    >>> from robustctl.models.path import Curve
    >>> bend = Curve(radius=400.0, angle=90.0, transition=80.0)
    >>> round(float(bend.length), 3)
    708.319
    >>> s = np.linspace(0.0, bend.length, 100001)
    >>> bool(np.isclose(np.trapezoid(bend.curvature(s), s), np.radians(90.0), rtol=1e-8))
    True
    """

    radius: float
    angle: float
    transition: float = 60.0

    def __post_init__(self):
        check_positive_scalar(self.radius, "Curve.radius")
        if not np.isfinite(self.angle) or self.angle == 0:
            raise ValueError(f"Curve.angle must be finite and non-zero (degrees), got {self.angle}")
        if not np.isfinite(self.transition) or self.transition < 0:
            raise ValueError(f"Curve.transition must be >= 0 metres, got {self.transition}")
        if abs(np.radians(self.angle)) * self.radius < self.transition:
            raise ValueError(f"Curve.transition ({self.transition} m) is longer than the turn "
                             f"|angle| radius = {abs(np.radians(self.angle)) * self.radius:.1f} m")

    @property
    def length(self) -> float:
        """Arc length [m]: ``|angle| radius + transition``."""
        return abs(np.radians(self.angle)) * self.radius + self.transition

    def curvature(self, s: np.ndarray) -> np.ndarray:
        """Curvature [1/m] at arc lengths ``s`` [m] from the element's start (the arc between two clothoid ramps).

        Parameters
        ----------
        s : ndarray
            Arc lengths from the element's start [m].

        Returns
        -------
        ndarray
            The curvature, of the shape of ``s``.
        """
        k = np.sign(self.angle) / self.radius
        L, Lt = self.length, self.transition
        if Lt == 0:
            return np.full_like(s, k)
        return k * np.clip(np.minimum(s, L - s) / Lt, 0.0, 1.0)


@dataclass(frozen=True)
class LaneChange:
    r"""A lane change by ``offset`` metres (positive = to the left) over ``length`` metres.

    Parameters
    ----------
    offset : float
        Lateral offset [m], non-zero; positive to the left.
    length : float
        Length along the road [m], positive.

    Raises
    ------
    ValueError
        A zero or non-finite offset, a length that is not positive.

    See Also
    --------
    Straight, Curve : the other road elements.

    Notes
    -----
    The lateral offset is the cycloid-like profile (zero heading and
    curvature at both ends)

    .. math::

        y(s) = \text{offset}\left(\frac{s}{L} - \frac{\sin(2\pi s/L)}{2\pi}\right),
        \qquad \kappa(s) \approx y''(s) = \text{offset}\,\frac{2\pi}{L^2}\sin\frac{2\pi s}{L},

    in the small-angle form, so the achieved offset equals ``offset`` to
    within ``(2 offset/L)^2``.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.path import LaneChange, ReferencePath, Straight
    >>> path = ReferencePath.from_segments([Straight(50.0), LaneChange(3.5, 150.0), Straight(50.0)])
    >>> bool(abs(path.Y[-1] - 3.5) < (2 * 3.5 / 150.0) ** 2 * 3.5)     # one lane to the left
    True
    >>> bool(abs(path.heading[-1]) < 1e-8)                            # and parallel to the road again
    True
    """

    offset: float
    length: float = 150.0

    def __post_init__(self):
        check_positive_scalar(self.length, "LaneChange.length")
        if not np.isfinite(self.offset) or self.offset == 0:
            raise ValueError(f"LaneChange.offset must be finite and non-zero, got {self.offset}")

    def curvature(self, s: np.ndarray) -> np.ndarray:
        """Curvature [1/m] at arc lengths ``s`` [m] from its start: ``offset (2 pi / L^2) sin(2 pi s / L)``.

        Parameters
        ----------
        s : ndarray
            Arc lengths from the element's start [m].

        Returns
        -------
        ndarray
            The curvature, of the shape of ``s``.
        """
        L = self.length
        return self.offset * 2 * np.pi / L**2 * np.sin(2 * np.pi * s / L)


Segment = Straight | Curve | LaneChange


# -- the path -------------------------------------------------------------------
@dataclass(frozen=True, eq=False, repr=False)
class ReferencePath:
    r"""A path driven at constant ``speed`` and sampled every ``dt`` seconds.

    Build one with :meth:`from_segments`, :meth:`from_curvature`,
    :meth:`from_waypoints` or :meth:`straight`; the constructor takes the
    sampled arrays as they are.

    Parameters
    ----------
    kappa, X, Y, heading, speed, dt, name
        The attributes below.

    Attributes
    ----------
    kappa : (T,) ndarray
        Mean curvature over each sample interval [1/m].
    X, Y, heading : (T,) ndarray
        Pose of the path point at ``s_k = speed k dt`` [m, m, rad].
    speed : float
        [m/s].
    dt : float
        [s].
    name : str
        Shown by ``repr``.

    See Also
    --------
    default_route : the route of the paper reproduction.
    robustctl.models.pathfollow.PathFollowing : the truck along a path.

    Notes
    -----
    The pose integrates the curvature along the arc length (module
    docstring),

    .. math::

        \psi(s) = \psi_0 + \int_0^s \kappa, \qquad
        X(s) = X_0 + \int_0^s \cos\psi, \qquad Y(s) = Y_0 + \int_0^s \sin\psi,

    and ``kappa[k]`` is the mean curvature over ``[s_k, s_{k+1}]``, so that
    ``v dt sum_k kappa[k]`` is the heading change.

    Examples
    --------
    A straight, a 90-degree left bend of radius 400 m, a straight:

    >>> import numpy as np
    >>> from robustctl.models.path import Curve, ReferencePath, Straight
    >>> path = ReferencePath.from_segments([Straight(100.0), Curve(400.0, 90.0, 80.0), Straight(100.0)])
    >>> path
    ReferencePath('', T=544, duration=54.4 s, length=907 m, speed=16.6667 m/s, dt=0.1 s, min radius=400 m)
    >>> bool(np.isclose(path.heading[-1], np.pi / 2))
    True
    >>> bool(np.isclose(path.speed * path.dt * path.kappa.sum(), np.pi / 2))
    True
    """

    kappa: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    heading: np.ndarray
    speed: float
    dt: float
    name: str = ""

    # -- sizes --------------------------------------------------------------
    @property
    def T(self) -> int:
        """Number of samples."""
        return self.kappa.shape[0]

    @property
    def t(self) -> np.ndarray:
        """Sample times ``k dt`` [s], shape (T,)."""
        return np.arange(self.T) * self.dt

    @property
    def s(self) -> np.ndarray:
        """Arc length at each sample [m], shape (T,)."""
        return self.t * self.speed

    @property
    def duration(self) -> float:
        """Length of the run ``T dt`` [s]."""
        return self.T * self.dt

    # -- constructors -------------------------------------------------------
    @classmethod
    def from_curvature(cls, kappa: Callable[[np.ndarray], np.ndarray] | Sequence[float] | np.ndarray,
                       *, duration: float | None = None, speed: float = DEFAULT_SPEED,
                       dt: float = 0.1, start: tuple[float, float, float] = (0.0, 0.0, 0.0),
                       name: str = "") -> ReferencePath:
        """Path from a curvature profile.

        Parameters
        ----------
        kappa : callable or (T,) array_like
            Either a vectorised function of arc length ``s`` [m] returning the
            curvature [1/m] (then ``duration`` is required), or the curvature at
            each sample (held constant over the sample; ``duration`` then
            defaults to ``T dt``).
        duration : float, optional
            Length of the run [s]; at least one sample (``>= dt``).
        speed, dt : float
            Constant forward speed [m/s] and sampling time [s].
        start : (X0, Y0, heading0)
            Start pose [m, m, rad].
        name : str
            Shown by ``repr``.

        Returns
        -------
        ReferencePath
            ``T = duration / dt`` samples (rounded down).

        Raises
        ------
        ValueError
            A duration shorter than one sample or missing for a function,
            a function that does not return finite values of the shape of
            its argument, too few curvature samples.

        Examples
        --------
        A circle of radius 400 m: after ``s`` metres the path is at
        ``(R sin(s/R), R (1 - cos(s/R)))``:

        >>> import numpy as np
        >>> from robustctl.models.path import ReferencePath
        >>> path = ReferencePath.from_curvature(lambda s: np.full_like(s, 1 / 400.0), duration=10.0)
        >>> theta = path.heading[-1]
        >>> bool(np.isclose(theta, path.s[-1] / 400.0))
        True
        >>> bool(np.allclose([path.X[-1], path.Y[-1]], [400 * np.sin(theta), 400 * (1 - np.cos(theta))], rtol=1e-7))
        True
        """
        speed = check_positive_scalar(speed, "speed")
        dt = check_positive_scalar(dt, "dt")
        pose0 = as_batch(start, "start", (3,), ("X0, Y0, heading0",))
        if callable(kappa):
            if duration is None:
                raise ValueError("duration is required when kappa is a function of arc length")
            T = _n_samples(duration, dt)
            ds = speed * dt / _FINE
            s = np.arange(T * _FINE + 1) * ds
            k_fine = np.asarray(kappa(s), dtype=float)
            if k_fine.shape != s.shape:
                raise ValueError(f"kappa(s) must return an array of the shape of s {s.shape}, "
                                 f"got {k_fine.shape}")
            if not np.all(np.isfinite(k_fine)):
                raise ValueError("kappa(s) must be finite")
            h_fine = pose0[2] + np.concatenate([[0.0], np.cumsum(0.5 * (k_fine[1:] + k_fine[:-1]) * ds)])
        else:
            k = as_batch(kappa, "kappa", (None,))
            if k.size == 0:
                raise ValueError("kappa must have at least one sample (a path shorter than one step)")
            T = k.size if duration is None else _n_samples(duration, dt)
            if k.size < T:
                raise ValueError(f"duration {duration} s needs {T} curvature samples, kappa has {k.size}")
            k = k[:T]
            ds = speed * dt / _FINE
            k_fine = np.repeat(k, _FINE)
            h_fine = pose0[2] + np.concatenate([[0.0], np.cumsum(k_fine * ds)])
        c, sn = np.cos(h_fine), np.sin(h_fine)
        X = pose0[0] + np.concatenate([[0.0], np.cumsum(0.5 * (c[1:] + c[:-1]) * ds)])
        Y = pose0[1] + np.concatenate([[0.0], np.cumsum(0.5 * (sn[1:] + sn[:-1]) * ds)])
        idx = np.arange(T + 1) * _FINE
        kappa_mean = np.diff(h_fine[idx]) / (speed * dt)
        return cls(frozen(kappa_mean), frozen(X[idx[:-1]]), frozen(Y[idx[:-1]]),
                   frozen(h_fine[idx[:-1]]), speed, dt, name)

    @classmethod
    def from_segments(cls, segments: Sequence[Segment], *, duration: float | None = None,
                      speed: float = DEFAULT_SPEED, dt: float = 0.1,
                      start: tuple[float, float, float] = (0.0, 0.0, 0.0),
                      name: str = "") -> ReferencePath:
        """Path from a sequence of road elements (:class:`Straight`, :class:`Curve`, :class:`LaneChange`).

        Parameters
        ----------
        segments : sequence of Straight, Curve or LaneChange
            The road, in driving order.
        duration : float, optional
            Length of the run [s]; default: the time to drive all elements
            (rounded down to whole samples). A longer duration continues
            straight after the last one.
        speed, dt : float
            Constant forward speed [m/s] and sampling time [s].
        start : (X0, Y0, heading0)
            Start pose [m, m, rad].
        name : str
            Shown by ``repr``.

        Returns
        -------
        ReferencePath

        Raises
        ------
        TypeError
            An element of another type.
        ValueError
            No element; see :meth:`from_curvature`.

        Examples
        --------
        >>> from robustctl.models.path import ReferencePath, Straight
        >>> path = ReferencePath.from_segments([Straight(166.667)])
        >>> path.T, float(path.kappa.max())
        (100, 0.0)
        """
        segments = list(segments)
        if not segments:
            raise ValueError("segments must not be empty")
        for i, seg in enumerate(segments):
            if not isinstance(seg, (Straight, Curve, LaneChange)):
                raise TypeError(f"segments[{i}] must be a Straight, Curve or LaneChange, "
                                f"got {type(seg).__name__}")
        lengths = np.array([seg.length for seg in segments])
        ends = np.cumsum(lengths)
        starts = ends - lengths
        speed_ = check_positive_scalar(speed, "speed")
        if duration is None:
            duration = ends[-1] / speed_

        def kappa(s):
            out = np.zeros_like(s)
            for seg, a, b in zip(segments, starts, ends, strict=True):
                inside = (s >= a) & (s < b)
                out[inside] = seg.curvature(s[inside] - a)
            return out

        return cls.from_curvature(kappa, duration=duration, speed=speed, dt=dt, start=start, name=name)

    @classmethod
    def from_waypoints(cls, X, Y, *, speed: float = DEFAULT_SPEED, dt: float = 0.1,
                       duration: float | None = None, name: str = "") -> ReferencePath:
        """Path through waypoints, by a cubic spline in the chord-length parameter.

        The curvature ``(x' y'' - y' x'') / (x'^2 + y'^2)^(3/2)`` of an
        interpolating cubic spline (scipy ``CubicSpline``, not-a-knot ends)
        is resampled along its arc length and integrated again from the first
        waypoint and the spline's initial tangent. Waypoints should be spaced
        at least a few metres apart and describe a smooth road; the spline
        passes through them, so noisy waypoints give noisy curvature.

        Parameters
        ----------
        X, Y : (N,) array_like
            Waypoints [m], N >= 4, distinct consecutive points.
        speed, dt : float
            Constant forward speed [m/s] and sampling time [s].
        duration : float, optional
            Length of the run [s]; default: the length of the spline.
        name : str
            Shown by ``repr``.

        Returns
        -------
        ReferencePath
            Starting at the first waypoint, along the spline's tangent.

        Raises
        ------
        ValueError
            Fewer than 4 waypoints, repeated consecutive points, ``X`` and
            ``Y`` of different lengths.

        Examples
        --------
        Ten points of a quarter circle of radius 400 m give a curvature
        close to 1/400:

        >>> import numpy as np
        >>> from robustctl.models.path import ReferencePath
        >>> angle = np.linspace(0.0, np.pi / 2, 10)
        >>> path = ReferencePath.from_waypoints(400 * np.cos(angle), 400 * np.sin(angle))
        >>> bool(abs(np.median(path.kappa) * 400.0 - 1.0) < 1e-2)
        True
        """
        from scipy.interpolate import CubicSpline

        X = as_batch(X, "X", (None,))
        Y = as_batch(Y, "Y", (X.size,), ("the number of waypoints, from X",))
        if X.size < 4:
            raise ValueError(f"from_waypoints needs at least 4 waypoints, got {X.size}")
        chord = np.hypot(np.diff(X), np.diff(Y))
        if np.any(chord <= 0):
            raise ValueError("consecutive waypoints must be distinct")
        u = np.concatenate([[0.0], np.cumsum(chord)])
        sx, sy = CubicSpline(u, X), CubicSpline(u, Y)
        uf = np.linspace(0.0, u[-1], max(2000, 20 * X.size))
        dx, dy = sx(uf, 1), sy(uf, 1)
        ddx, ddy = sx(uf, 2), sy(uf, 2)
        speed_u = np.hypot(dx, dy)
        k_u = (dx * ddy - dy * ddx) / speed_u**3
        s_u = np.concatenate([[0.0], np.cumsum(0.5 * (speed_u[1:] + speed_u[:-1]) * np.diff(uf))])
        speed_ = check_positive_scalar(speed, "speed")
        if duration is None:
            duration = s_u[-1] / speed_
        start = (float(X[0]), float(Y[0]), float(np.arctan2(dy[0], dx[0])))
        return cls.from_curvature(lambda s: np.interp(s, s_u, k_u, right=0.0), duration=duration,
                                  speed=speed, dt=dt, start=start, name=name)

    @classmethod
    def straight(cls, duration: float, *, speed: float = DEFAULT_SPEED, dt: float = 0.1) -> ReferencePath:
        """A straight along the X axis lasting ``duration`` seconds.

        Parameters
        ----------
        duration : float
            Length of the run [s].
        speed, dt : float
            Constant forward speed [m/s] and sampling time [s].

        Returns
        -------
        ReferencePath

        Examples
        --------
        >>> import numpy as np
        >>> from robustctl.models.path import ReferencePath
        >>> path = ReferencePath.straight(10.0)
        >>> path.T, bool(np.allclose(path.X, path.s) and not path.Y.any())
        (100, True)
        """
        return cls.from_curvature(np.zeros_like, duration=duration, speed=speed, dt=dt,
                                  name="straight")

    def truncated(self, duration: float) -> ReferencePath:
        """The first ``duration`` seconds of the path (at least one sample).

        Parameters
        ----------
        duration : float
            Length kept [s]; longer than the path keeps all of it.

        Returns
        -------
        ReferencePath

        Raises
        ------
        ValueError
            A duration shorter than one sample.
        """
        T = _n_samples(duration, self.dt)
        T = min(T, self.T)
        return ReferencePath(self.kappa[:T], self.X[:T], self.Y[:T], self.heading[:T],
                             self.speed, self.dt, self.name)

    def __repr__(self) -> str:
        R = np.inf if not np.any(self.kappa) else 1.0 / np.max(np.abs(self.kappa))
        return (f"ReferencePath({self.name!r}, T={self.T}, duration={self.duration:g} s, "
                f"length={self.T * self.dt * self.speed:.0f} m, speed={self.speed:g} m/s, "
                f"dt={self.dt:g} s, min radius={R:.0f} m)")


def _n_samples(duration, dt: float) -> int:
    if isinstance(duration, bool) or not isinstance(duration, (int, float, np.integer, np.floating)):
        raise TypeError(f"duration must be a number of seconds, got {type(duration).__name__}")
    if not np.isfinite(duration) or duration < dt * (1 - 1e-9):
        raise ValueError(f"duration must be at least one sample step (dt = {dt:g} s), got {duration} s; "
                         "a path shorter than one step cannot be simulated")
    return int(np.floor(duration / dt + 1e-9))


#: The road of the default route: a 9.0 km drive (about 540 s at 60 km/h).
DEFAULT_ROUTE = (
    Straight(250.0),                  # start (the vehicle may start off the lane centre)
    LaneChange(3.5, 150.0),           # overtaking: one 3.5 m lane to the left ...
    Straight(300.0),
    LaneChange(-3.5, 150.0),          # ... and back
    Straight(300.0),
    Curve(400.0, 90.0, 80.0),         # left bend, R = 400 m
    Straight(500.0),
    Curve(250.0, -60.0, 60.0),        # right bend, R = 250 m
    Straight(400.0),
    Curve(300.0, 45.0, 60.0),         # S-bend
    Curve(300.0, -45.0, 60.0),
    Straight(600.0),
    LaneChange(3.5, 120.0),           # a quicker lane change
    Straight(200.0),
    LaneChange(-3.5, 120.0),
    Straight(300.0),
    Curve(200.0, -120.0, 80.0),       # tight right-hand hairpin-like bend, R = 200 m
    Straight(700.0),
    Curve(500.0, 30.0, 60.0),         # gentle left, R = 500 m
    Straight(400.0),
    LaneChange(-3.5, 150.0),          # move right (e.g. to an exit lane)
    Straight(300.0),
    Curve(350.0, 75.0, 70.0),         # left bend, R = 350 m
    Straight(1100.0),
)


def default_route(*, speed: float = DEFAULT_SPEED, dt: float = 0.1,
                  duration: float | None = None) -> ReferencePath:
    """The reference path of the paper reproduction (the paper does not publish its path).

    A 9.0 km road for a heavy truck at 60 km/h (about 540 s, over the paper's
    "more than 400 s"): straights, five lane changes of 3.5 m (one lane) over
    120-150 m, and bends of radius 200-500 m (lateral acceleration at most
    ``v^2/R = 1.4 m/s^2``, comfortable for a truck) entered through clothoid
    transitions of 60-80 m, as road design prescribes at this speed. The
    elements are in ``DEFAULT_ROUTE``; build your own with
    :meth:`ReferencePath.from_segments`, :meth:`~ReferencePath.from_curvature`
    or :meth:`~ReferencePath.from_waypoints`.

    Parameters
    ----------
    speed, dt : float
        Constant forward speed [m/s] and sampling time [s].
    duration : float, optional
        Length of the run [s]; default: the whole route.

    Returns
    -------
    ReferencePath

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.models.path import default_route
    >>> route = default_route()
    >>> route
    ReferencePath('default route', T=5406, duration=540.6 s, length=9010 m, ...)
    >>> v2_over_R = route.speed**2 * np.abs(route.kappa).max()        # lateral acceleration at 60 km/h
    >>> bool(v2_over_R < 1.4)
    True
    """
    return ReferencePath.from_segments(DEFAULT_ROUTE, speed=speed, dt=dt, duration=duration,
                                       name="default route")
