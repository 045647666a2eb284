"""Truck path following (Morais et al. 2022, Section 4.5): the paper's closed-loop runs on the batched simulator.

The true plant is the truck (:mod:`robustctl.models.truck`) at each
scenario's payload overload; the controller knows only the nominal model.
Along a :class:`robustctl.path.ReferencePath`::

    e[k]     = x[k] - x_ref[k]
    alpha[k] = sat_{steer_limit}( M K e[k] + alpha_ff[k] )
    x[k+1]   = F x[k] + G alpha[k] + Gk kappa[k]

with ``F, G, Gk`` the ZOH model of the true vehicle
(:func:`robustctl.models.truck.discretise`), ``kappa`` the path curvature,
``x_ref``, ``alpha_ff`` the nominal model's steady cornering along the path
(:func:`robustctl.models.truck.reference_states`; ``x_ref = [beta_1 v, v, 0,
-beta_1] kappa`` with ``beta_1`` the nominal sideslip per unit curvature) and
``M`` the map from the controller's inputs to the steering angle (``[[1]]``
for a plain gain, ``[[1, 1]]`` for the doubled steering column
``alpha = u1 + u2`` of the applied RLQR designs,
:data:`robustctl.models.truck.DOUBLED_INPUT_MAP`). The steady-state steering
feedforward is the same for every controller; with it, the nominal plant
follows a constant-curvature path with zero error, and errors come from
transients, the initial offset and payload mismatch.

:class:`PathFollowing` discretises the scenarios and builds the reference
once (an optimiser's problem keeps one); :func:`simulate` is the one-call form.
The simulation itself, the divergence rule and the backends are those of
:mod:`robustctl.batchsim`.

References
----------
Morais et al. (2022), Section 4.5.2 (the four objectives f1..f4 and the
payload cases). K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed.,
Princeton 2021, Sec. 8.5 (feedforward plus feedback on the tracking error).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .batchsim import DEFAULT_BOUND, LinearSimulator, SimulationResult
from .models import truck as _truck
from .path import ReferencePath

__all__ = ["PathFollowing", "PathFollowingResult", "simulate", "DEFAULT_INITIAL_ERROR"]

#: Initial path-following error of :func:`simulate`: the truck starts 1 m to the
#: left of the path, parallel to it, at steady speed ([ydot, psidot, rho, theta]).
DEFAULT_INITIAL_ERROR = (0.0, 0.0, 1.0, 0.0)


@dataclass(frozen=True, eq=False, repr=False)
class PathFollowingResult(SimulationResult):
    """A :class:`~robustctl.batchsim.SimulationResult` of the truck, with its path.

    :meth:`mse` reports the paper's ``[f1, f2, f3, f4]`` = MSE of the
    ``[rho, psidot, ydot, theta]`` errors (lateral displacement [m^2], yaw rate
    [(rad/s)^2], lateral velocity [(m/s)^2], orientation [rad^2];
    :attr:`objective_names`), while ``errors`` and :meth:`state_mse` keep
    the model's state order ``[ydot, psidot, rho, theta]``
    (:data:`robustctl.models.truck.STATE_NAMES`). ``mse("zero")`` is the
    *regulation* error (MSE of the states themselves); for the truck it
    differs from the tracking error only in ``ydot``, ``psidot`` and ``theta``
    (``rho_ref = 0``): in a bend the yaw rate must be ``v kappa``, so its
    regulation error measures the path as much as the controller.

    Attributes
    ----------
    path : ReferencePath
    overloads : tuple
        Scenario overloads in percent (floats, or (T,) arrays when time-varying).
    """

    path: ReferencePath | None = None
    overloads: tuple | None = None

    @property
    def steering(self) -> np.ndarray:
        """Applied steering angle, shape (B, S, T)."""
        self._need_trajectories()
        return self.inputs[..., 0]

    def pose(self, method: Literal["path", "integrated"] = "path") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Global position and heading of the vehicle, each of shape (B, S, T).

        ``method="path"`` (default): the path point at ``s = v t`` displaced by
        ``rho`` along the path's left normal, with heading ``path heading + theta``:
        ``X = X_p - rho sin(h_p)``, ``Y = Y_p + rho cos(h_p)``, ``heading = h_p + theta``.
        This is the model's own frame (its ``rho, theta`` are defined relative
        to the path point reached at speed ``v``), so the drawn track is
        exactly the simulated one, with no drift.

        ``method="integrated"``: dead reckoning from the simulated body
        velocities, ``psi' = psidot``, ``X' = v cos(psi) - ydot sin(psi)``,
        ``Y' = v sin(psi) + ydot cos(psi)`` (trapezoidal rule), from the start
        pose of the ``"path"`` method. It differs from ``"path"`` by the
        linearisation of the model (second order in ``theta`` and
        ``kappa rho``), which accumulates along the route.
        """
        self._need_trajectories()
        x = self.states
        rho, theta = x[..., 2], x[..., 3]
        h = self.path.heading[: self.T]
        X0 = self.path.X[0] - rho[..., 0] * np.sin(h[0])
        Y0 = self.path.Y[0] + rho[..., 0] * np.cos(h[0])
        if method == "path":
            return (self.path.X[: self.T] - rho * np.sin(h), self.path.Y[: self.T] + rho * np.cos(h),
                    h + theta)
        if method != "integrated":
            raise ValueError(f"method must be 'path' or 'integrated', got {method!r}")
        dt, v = self.path.dt, self.path.speed

        def integrate(rate, start):
            steps = 0.5 * (rate[..., 1:] + rate[..., :-1]) * dt
            return np.concatenate([start[..., None], start[..., None] + np.cumsum(steps, axis=-1)], axis=-1)

        psi = integrate(x[..., 1], h[0] + theta[..., 0])
        ydot = x[..., 0]
        X = integrate(v * np.cos(psi) - ydot * np.sin(psi), X0)
        Y = integrate(v * np.sin(psi) + ydot * np.cos(psi), Y0)
        return X, Y, psi


def _scenarios(overloads, T: int) -> tuple:
    """Normalise ``overloads`` to a tuple of floats / (T,) arrays."""
    if isinstance(overloads, (str, bytes)) or overloads is None:
        raise TypeError(f"overloads must be a number or a sequence of numbers / (T,) arrays, "
                        f"got {type(overloads).__name__}")
    if np.ndim(overloads) == 0:
        return (float(_truck.check_overload(overloads, "overloads")),)
    items = list(overloads)
    if not items:
        raise ValueError("overloads must not be empty")
    out = []
    for i, ov in enumerate(items):
        if np.ndim(ov) == 0:
            out.append(float(_truck.check_overload(ov, f"overloads[{i}]")))
        else:
            a = np.asarray(_truck.check_overload(ov, f"overloads[{i}]"), dtype=float)
            if a.shape != (T,):
                raise ValueError(f"overloads[{i}] is time-varying and must have shape ({T},) "
                                 f"(the path's samples), got {a.shape}")
            out.append(a)
    return tuple(out)


class PathFollowing:
    """The truck along ``path`` at S payload scenarios, ready to simulate gains (checked once).

    Parameters
    ----------
    path : ReferencePath
        Speed and ``dt`` must equal the model's ``params.v`` and ``params.dt``.
    overloads : float, or sequence of S floats / (T,) arrays
        Payload overload of each scenario in percent (>= 0); an array gives a
        time-varying payload (e.g. unloading at a stop), sample by sample.
    params : TruckParameters, optional
    nominal_overload : float
        Overload of the model the reference and feedforward are computed on.
    steer_limit : float or None
        Steering saturation [rad] (0.45 in the paper); None for none.
    feedforward : bool
        Add the nominal steady-state steering ``alpha_ff`` (default True).
    x0 : (4,) or (S, 4) array_like
        Initial error ``x[0] - x_ref[0]`` (default: 1 m left of the path).
    bound : float
        Divergence bound (see :mod:`robustctl.batchsim`).
    input_map : (1, m) array_like, optional
        How the controller's m inputs make the steering angle: ``[[1]]`` (the
        default, for gains of one row) or e.g. ``[[1, 1]]`` for the doubled
        steering column (:data:`robustctl.models.truck.DOUBLED_INPUT_MAP`).
        Gains of several rows need it: without it they are summed, with a
        ``DeprecationWarning`` (the earlier, implicit behaviour).
    """

    def __init__(self, path: ReferencePath, overloads=0.0, *, params: _truck.TruckParameters | None = None,
                 nominal_overload: float = 0.0, steer_limit: float | None = _truck.STEER_LIMIT,
                 feedforward: bool = True, x0=DEFAULT_INITIAL_ERROR, bound: float = DEFAULT_BOUND,
                 input_map=None):
        p = _truck._params(params)
        if not isinstance(path, ReferencePath):
            raise TypeError(f"path must be a robustctl.path.ReferencePath, got {type(path).__name__}")
        if abs(path.speed - p.v) > 1e-9 * p.v or abs(path.dt - p.dt) > 1e-12:
            raise ValueError(f"path speed/dt ({path.speed:g} m/s, {path.dt:g} s) must equal the model's "
                             f"({p.v:g} m/s, {p.dt:g} s)")
        T = path.T
        scen = _scenarios(overloads, T)
        values = np.unique(np.concatenate([np.atleast_1d(s) for s in scen]))   # discretise each once
        Fu, Gu, Gku = _truck.discretise(values, params=p)
        if all(np.ndim(s) == 0 for s in scen):
            idx = np.searchsorted(values, np.array(scen))
            F, G = Fu[idx], Gu[idx]                                             # (S, 4, 4), (S, 4, 1)
            w = Gku[idx][:, None, :] * path.kappa[None, :, None]               # (S, T, 4)
        else:
            idx = np.stack([np.searchsorted(values, np.broadcast_to(s, (T,))) for s in scen])  # (S, T)
            F, G = Fu[idx], Gu[idx]                                             # (S, T, 4, 4) ...
            w = Gku[idx] * path.kappa[None, :, None]
        x_ref, a_ff = _truck.reference_states(path.kappa, nominal_overload, params=p)
        if not isinstance(feedforward, (bool, np.bool_)):
            raise TypeError(f"feedforward must be a bool, got {type(feedforward).__name__}")
        self._given_map = input_map is not None
        self._linear = LinearSimulator(
            F, G, x_ref, u_ff=(a_ff if feedforward else np.zeros_like(a_ff))[:, None], w=w, x0=x0,
            u_limit=steer_limit, input_map=input_map, bound=bound, objectives=_truck.OBJECTIVE_STATES,
            state_names=_truck.STATE_NAMES, dt=p.dt)
        self.path = path
        self.overloads = scen

    @property
    def S(self) -> int:
        return self._linear.S

    @property
    def T(self) -> int:
        return self._linear.T

    def run(self, K, *, keep_trajectories: bool = True, nan_gains: Literal["raise", "flag"] = "raise",
            backend: Literal["numba", "numpy"] = "numba") -> PathFollowingResult:
        """Simulate B gains on every scenario.

        Parameters
        ----------
        K : (m, 4) or (B, m, 4) array_like
            Gains with ``u = K e`` (``m`` = the input map's columns).
        keep_trajectories : bool
            False keeps only the MSE sums (for optimisers).
        nan_gains : {"raise", "flag"}
            ``"flag"``: gains with NaN entries (failed designs, e.g.
            ``RLQRBatch.K`` where ``ok`` is False) are reported as diverged at
            step 0 with MSE ``bound**2`` instead of raising.
        backend : {"numba", "numpy"}
            Compiled kernel (default) or the numpy reference.

        Returns
        -------
        PathFollowingResult
            ``errors`` (B, S, T, 4), ``steering`` (B, S, T), ``mse()`` (B, S, 4)
            in the paper's order f1..f4; ``pose()`` for plotting.
        """
        sim = self._linear
        try:
            shape = np.shape(K) if not isinstance(K, (str, bytes)) else ()
        except ValueError:                          # ragged nested lists: check_gains names K
            shape = ()
        m = shape[-2] if len(shape) in (2, 3) else 1
        if not self._given_map and m > 1:
            warnings.warn(f"K has {m} rows but the truck has one steering input: summing them "
                          f"(alpha = u1 + ... + u{m}) without an input_map is deprecated; pass "
                          f"input_map=[[1] * {m}] (robustctl.models.truck.DOUBLED_INPUT_MAP for two)",
                          DeprecationWarning, stacklevel=3)
            sim = sim.with_input_map(np.ones((1, m)))
        res = sim.run(K, keep_trajectories=keep_trajectories, nan_gains=nan_gains, backend=backend)
        return PathFollowingResult(**vars(res), path=self.path, overloads=self.overloads)

    def __repr__(self) -> str:
        return (f"PathFollowing(path={self.path.name!r}, S={self.S}, T={self.T}, "
                f"input_map={'given' if self._given_map else 'default'})")


def simulate(K, path: ReferencePath, overloads=0.0, *, params: _truck.TruckParameters | None = None,
             nominal_overload: float = 0.0, steer_limit: float | None = _truck.STEER_LIMIT,
             feedforward: bool = True, x0=DEFAULT_INITIAL_ERROR, bound: float = DEFAULT_BOUND,
             keep_trajectories: bool = True, nan_gains: Literal["raise", "flag"] = "raise",
             input_map=None, backend: Literal["numba", "numpy"] = "numba") -> PathFollowingResult:
    """Truck path following: B gains x S payload scenarios over ``path``, in one call.

    ``PathFollowing(path, overloads, ...).run(K, ...)``; see :class:`PathFollowing`
    (scenarios, input map) and :meth:`PathFollowing.run` (gains, result).
    A gain of several rows needs ``input_map`` (e.g. ``[[1, 1]]`` for the
    doubled steering column); without it the rows are summed with a
    ``DeprecationWarning``.

    Returns
    -------
    PathFollowingResult
        ``errors`` (B, S, T, 4), ``steering`` (B, S, T), ``mse()`` (B, S, 4)
        in the paper's order f1..f4 = MSE of rho, psidot, ydot, theta;
        ``pose()`` for plotting.
    """
    sim = PathFollowing(path, overloads, params=params, nominal_overload=nominal_overload,
                        steer_limit=steer_limit, feedforward=feedforward, x0=x0, bound=bound,
                        input_map=input_map)
    return sim.run(K, keep_trajectories=keep_trajectories, nan_gains=nan_gains, backend=backend)
