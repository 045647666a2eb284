"""Truck path following (Morais et al. 2022, Section 4.5): the paper's closed-loop runs on the batched simulator.

The true plant is the truck (:mod:`robustctl.models.truck`) at each
scenario's payload overload; the controller knows only the nominal model.
Along a :class:`robustctl.models.path.ReferencePath`::

    e[k]     = x[k] - x_ref[k]
    alpha[k] = sat_{steer_limit}( M K e[k] + alpha_ff[k] )
    x[k+1]   = F x[k] + G alpha[k] + Gk kappa[k]

with ``F, G, Gk`` the ZOH model of the true vehicle
(:func:`robustctl.models.truck.discretise`), ``kappa`` the path curvature and
``M`` the map from the controller's inputs to the steering angle (``[[1]]``
for a plain gain, ``[[1, 1]]`` for the doubled steering column
``alpha = u1 + u2`` of the applied RLQR designs,
:data:`robustctl.models.truck.DOUBLED_INPUT_MAP`).

Set-ups
-------
A :class:`PathFollowingSetup` fixes the reference, the loop and the
initial state, together with the design weights ``Q``, ``R`` that the
controllers of a study share. The default, :data:`DEFAULT_SETUP` (the
engineering set-up): ``x_ref`` and ``alpha_ff`` are the nominal model's
steady cornering along the path
(:func:`robustctl.models.truck.reference_states`; ``x_ref = [beta_1 v, v, 0,
-beta_1] kappa``), with the steady-state steering as feedforward: the
nominal plant follows a constant-curvature path with zero error, and errors
come from transients, the initial offset and the payload mismatch; every
state is a *tracking* error. Bryson's weights
(:func:`robustctl.models.truck.lqr_weights`) and a 1 m initial offset.
The other reference, ``"open_loop"``, follows the nominal truck driven open
loop by the path's steady-cornering steering
(:func:`robustctl.models.truck.open_loop_reference`) and regulates the
lateral velocity and the yaw rate to zero. The set-ups of the paper and of
its authors' code are in :mod:`robustctl.models.morais2022`.

:class:`PathFollowing` discretises the scenarios and builds the reference
once (an optimiser's problem keeps one); :func:`simulate` is the one-call form.
:meth:`PathFollowing.run_estimated` closes the loop on an estimate of the
state instead: a Kalman or robust filter (:mod:`robustctl.estimation`) of the
nominal model fed with noisy measurements ``y = C x + v`` (the truck's
sensors: :func:`robustctl.models.truck.sensor_plant`) and the applied
steering angle.
The simulation itself, the divergence rule and the backends are those of
:mod:`robustctl.sim.simulator`. A law that also feeds back the previous steering
angle (``K_input``, e.g. :mod:`robustctl.synthesis.hinf_game`'s delayed
full-information law) runs on the plant augmented by that angle as a state.

References
----------
Morais et al. (2022), Section 4.5.2 (the four objectives f1..f4 and the
payload cases). K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed.,
Princeton 2021, Sec. 8.5 (feedforward plus feedback on the tracking error).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from typing import Any, Literal

import numpy as np

from .._validation import (
    as_batch,
    as_float_array,
    as_matrix,
    as_rng,
    check_bool,
    check_choice,
    check_int,
    check_positive_scalar,
    check_spd,
)
from ..estimation.estimator import Estimator
from ..sim.simulator import DEFAULT_BOUND, LinearSimulator, SimulationResult, check_gains
from ..systems.input_memory import InputMemoryFeedback
from . import truck as _truck
from .path import ReferencePath

__all__ = ["PathFollowing", "PathFollowingResult", "EstimatedPathFollowingResult", "PathFollowingSetup",
           "DEFAULT_SETUP", "simulate", "DEFAULT_INITIAL_ERROR"]

#: Initial path-following error of the default set-up: the truck starts 1 m to the
#: left of the path, parallel to it, at steady speed ([ydot, psidot, rho, theta]).
DEFAULT_INITIAL_ERROR = (0.0, 0.0, 1.0, 0.0)


@dataclass(frozen=True)
class PathFollowingSetup:
    """How a path-following study is posed: reference, loop, initial state and design weights.

    Parameters
    ----------
    name, reference, feedforward, x0, Q_diag, r, source
        The attributes below.

    Attributes
    ----------
    name : str
    reference : {"steady", "open_loop"}
        ``"steady"``: ``x_ref`` is the nominal model's steady cornering along
        the path, every state tracked
        (:func:`robustctl.models.truck.reference_states`). ``"open_loop"``:
        ``x_ref = [0, 0, rho_ol, theta_ol]`` from the nominal truck driven open
        loop by the path's steady-cornering steering
        (:func:`robustctl.models.truck.open_loop_reference`); the lateral
        velocity and the yaw rate are regulated to zero.
    feedforward : bool
        Add the steady-cornering steering ``alpha_per_kappa kappa`` (the
        reference's steering command) to the feedback.
    x0 : tuple of 4 floats
        Initial error ``x[0] - x_ref[0]`` (``x_ref[0] = 0`` at the start of a
        straight).
    Q_diag : tuple of 4 floats
        State weight ``Q = diag(Q_diag)`` of every design of the study.
    r : float
        Steering weight on the plain truck; the doubled steering column uses
        ``R = 2 r I2`` (the cheapest split of a steering angle costs the same,
        see :func:`robustctl.models.truck.lqr_weights`).
    source : str
        Where the choices come from.

    Raises
    ------
    ValueError, TypeError
        An unknown ``reference``, a non-bool ``feedforward``, ``x0`` or
        ``Q_diag`` not four finite numbers, a negative weight, ``r <= 0``.

    See Also
    --------
    robustctl.models.morais2022.get_setup : the set-ups of the paper's reproduction.

    Examples
    --------
    The default set-up uses Bryson's weights of the truck:

    >>> import numpy as np
    >>> from robustctl.models.pathfollow import DEFAULT_SETUP
    >>> from robustctl.models.truck import lqr_weights
    >>> DEFAULT_SETUP.name, DEFAULT_SETUP.reference, DEFAULT_SETUP.x0
    ('engineering', 'steady', (0.0, 0.0, 1.0, 0.0))
    >>> Q, R = DEFAULT_SETUP.weights(doubled=True)
    >>> Q_ref, R_ref = lqr_weights(doubled=True)
    >>> bool(np.allclose(Q, Q_ref) and np.allclose(R, R_ref))
    True
    """

    name: str
    reference: Literal["steady", "open_loop"]
    feedforward: bool
    x0: tuple[float, float, float, float]
    Q_diag: tuple[float, float, float, float]
    r: float
    source: str = ""

    def __post_init__(self):
        check_choice(self.reference, "reference", ("steady", "open_loop"))
        check_bool(self.feedforward, "feedforward")
        as_batch(self.x0, "x0", (4,))
        if np.any(as_batch(self.Q_diag, "Q_diag", (4,)) < 0):
            raise ValueError(f"Q_diag must be >= 0, got {self.Q_diag}")
        check_positive_scalar(self.r, "r")

    def weights(self, *, doubled: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``Q`` (4, 4) and ``R``: ``[[r]]``, or ``2 r I2`` on the doubled steering column.

        Parameters
        ----------
        doubled : bool
            Weights for the doubled steering column (two inputs).

        Returns
        -------
        Q : (4, 4) ndarray
            ``diag(Q_diag)``.
        R : (1, 1) or (2, 2) ndarray
            ``[[r]]``, or ``2 r I2``.
        """
        Q = np.diag(np.asarray(self.Q_diag, dtype=float))
        return Q, (2.0 * self.r * np.eye(2) if doubled else np.array([[float(self.r)]]))


_Q_DEFAULT, _R_DEFAULT = _truck.lqr_weights()
#: The default set-up (module docstring): steady-cornering tracking with feedforward,
#: Bryson's weights, a 1 m initial offset.
DEFAULT_SETUP = PathFollowingSetup(
    "engineering", "steady", True, DEFAULT_INITIAL_ERROR, tuple(np.diag(_Q_DEFAULT).tolist()),
    float(_R_DEFAULT[0, 0]),
    "steady-cornering tracking with feedforward, Bryson's weights (robustctl.models.truck.lqr_weights), "
    "1 m initial offset")


def _check_setup(setup) -> PathFollowingSetup:
    if not isinstance(setup, PathFollowingSetup):
        raise TypeError(f"setup must be a PathFollowingSetup (the paper's set-ups by name: "
                        f"robustctl.models.morais2022.get_setup), got {type(setup).__name__}")
    return setup


@dataclass(frozen=True, eq=False, repr=False)
class PathFollowingResult(SimulationResult):
    """A :class:`~robustctl.sim.simulator.SimulationResult` of the truck, with its path.

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

    Parameters
    ----------
    path : ReferencePath, optional
        The path the runs followed.
    overloads : tuple, optional
        The scenarios' overloads.
    **fields
        The fields of :class:`~robustctl.sim.simulator.SimulationResult`.

    Attributes
    ----------
    path : ReferencePath
        The path the runs followed.
    overloads : tuple
        Scenario overloads in percent (floats, or (T,) arrays when time-varying).

    See Also
    --------
    PathFollowing.run : produces it.

    Examples
    --------
    On a straight along the X axis the vehicle's global ``Y`` is its
    lateral displacement ``rho``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models import truck
    >>> from robustctl.models.path import ReferencePath
    >>> from robustctl.models.pathfollow import simulate
    >>> K = rc.lqr(truck.truck_plant(0.0), Q=truck.lqr_weights()[0], R=truck.lqr_weights()[1]).K
    >>> res = simulate(K, ReferencePath.straight(20.0), [0.0, 100.0], backend="numpy")
    >>> res.objective_names
    ('rho', 'psidot', 'ydot', 'theta')
    >>> X, Y, heading = res.pose()
    >>> bool(np.allclose(Y, res.states[..., 2]) and np.allclose(heading, res.states[..., 3]))
    True
    """

    path: ReferencePath | None = None
    overloads: tuple | None = None

    def _path(self) -> ReferencePath:
        if self.path is None:
            raise ValueError("this result has no path (path=None): the poses need the reference path")
        return self.path

    def reference_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Global position ``(X, Y)`` of the reference, each (T,) or (S, T).

        The path displaced by ``rho_ref`` along its left normal (the path itself for the ``"steady"`` reference).

        Returns
        -------
        X, Y : ndarray
            (T,), or (S, T) for a reference per scenario.

        Raises
        ------
        ValueError
            The result has no path.
        """
        path = self._path()
        h = path.heading[: self.T]
        rho = self.x_ref[..., 2]
        return path.X[: self.T] - rho * np.sin(h), path.Y[: self.T] + rho * np.cos(h)

    @property
    def steering(self) -> np.ndarray:
        """Applied steering angle, shape (B, S, T)."""
        self._need_trajectories()
        assert self.inputs is not None                 # kept with the errors
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

        Parameters
        ----------
        method : {"path", "integrated"}
            The model's frame, or dead reckoning.

        Returns
        -------
        X, Y, heading : (B, S, T) ndarray
            Global position [m] and heading [rad].

        Raises
        ------
        ValueError
            Trajectories not kept, no path, an unknown ``method``.
        """
        check_choice(method, "method", ("path", "integrated"))
        self._need_trajectories()
        x = self.states
        rho, theta = x[..., 2], x[..., 3]
        path = self._path()
        h = path.heading[: self.T]
        X0 = path.X[0] - rho[..., 0] * np.sin(h[0])
        Y0 = path.Y[0] + rho[..., 0] * np.cos(h[0])
        if method == "path":
            return (path.X[: self.T] - rho * np.sin(h), path.Y[: self.T] + rho * np.cos(h),
                    h + theta)
        dt, v = path.dt, path.speed

        def integrate(rate, start):
            steps = 0.5 * (rate[..., 1:] + rate[..., :-1]) * dt
            return np.concatenate([start[..., None], start[..., None] + np.cumsum(steps, axis=-1)], axis=-1)

        psi = integrate(x[..., 1], h[0] + theta[..., 0])
        ydot = x[..., 0]
        X = integrate(v * np.cos(psi) - ydot * np.sin(psi), X0)
        Y = integrate(v * np.sin(psi) + ydot * np.cos(psi), Y0)
        return X, Y, psi


@dataclass(frozen=True, eq=False, repr=False)
class EstimatedPathFollowingResult(PathFollowingResult):
    """A :class:`PathFollowingResult` of the loop on an estimate (:meth:`PathFollowing.run_estimated`).

    The scenario axis holds every payload scenario once per draw of the
    measurement noise, the draw fastest: scenario ``s * draws + d`` is the
    ``s``-th overload with the ``d``-th noise sequence (the same sequences
    at every overload). ``errors`` and :meth:`mse` are those of the true
    state, ``x - x_ref``; ``estimates`` is the estimate the controller fed
    back, ``xhat - x_ref``.

    Parameters
    ----------
    estimates : ndarray, optional
        The attribute below.
    draws : int
        Noise sequences per payload scenario.
    form : str
        The estimator's form.
    **fields
        The fields of :class:`PathFollowingResult`.

    Attributes
    ----------
    estimates : (B, S * draws, T, 4) ndarray or None
        ``xhat[k] - x_ref[k]`` (None if trajectories were not kept).
    draws : int
    form : {"filter", "predictor"}
        ``xhat[k] = x[k|k]`` (``"filter"``) or ``x[k|k-1]`` (``"predictor"``).

    See Also
    --------
    PathFollowing.run_estimated : produces it.

    Examples
    --------
    Two noise draws at two overloads make four scenarios; :meth:`mse_by_draw`
    splits them again:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models import truck
    >>> from robustctl.models.path import ReferencePath
    >>> from robustctl.models.pathfollow import PathFollowing
    >>> sensors = truck.TruckSensors()
    >>> est = rc.kalman(truck.sensor_plant(0.0), [[0.01]], sensors.covariance(0.1), Bw=truck.truck_plant(0.0).G)
    >>> Q, R = truck.lqr_weights()
    >>> K = rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K
    >>> res = PathFollowing(ReferencePath.straight(10.0), [0.0, 100.0]).run_estimated(K, est, draws=2, rng=0,
    ...                                                                                 backend="numpy")
    >>> res.overloads, res.mse().shape, res.mse_by_draw().shape
    ((0.0, 0.0, 100.0, 100.0), (1, 4, 4), (1, 2, 2, 4))
    >>> bool(np.allclose(res.estimation_errors, res.estimates - res.errors))
    True
    """

    estimates: np.ndarray | None = None
    draws: int = 1
    form: str = "filter"

    def mse_by_draw(self, target: Literal["reference", "zero"] = "reference") -> np.ndarray:
        """:meth:`mse` with the scenarios split into payloads and draws, shape (B, S, draws, 4).

        Parameters
        ----------
        target : {"reference", "zero"}
            As in :meth:`mse`.

        Returns
        -------
        (B, S, draws, 4) ndarray
        """
        m = self.mse(target)
        return m.reshape(m.shape[0], -1, self.draws, m.shape[-1])

    @property
    def estimation_errors(self) -> np.ndarray:
        """``xhat - x``, shape (B, S * draws, T, 4)."""
        self._need_trajectories()
        assert self.estimates is not None                 # kept with the errors
        return self.estimates - self.errors


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
    out: list[float | np.ndarray] = []
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


def _measurement_noise(noise, V, draws, rng, est: Estimator, T: int, p: int) -> np.ndarray:
    """The noise samples (N, T, p): ``noise`` as given, or ``draws`` white normal sequences of covariance ``V``."""
    if noise is not None:
        if V is not None or rng is not None or not (isinstance(draws, int) and draws == 1):
            raise ValueError("give either noise (the samples) or V, draws and rng (drawn here), not both")
        v = as_float_array(noise, "noise")
        v = v[None] if v.ndim == 2 else v
        if v.ndim != 3 or v.shape[1:] != (T, p) or v.shape[0] == 0:
            raise ValueError(f"noise must have shape ({T}, {p}) or (draws, {T}, {p}) (the path's samples, the "
                             f"estimator's outputs), got shape {np.shape(noise)}")
        if not np.all(np.isfinite(v)):
            raise ValueError("noise must have finite entries (found NaN or inf)")
        return v
    if V is None:
        V = est.info.get("V")
        if V is None:
            raise ValueError("V: the estimator records no measurement covariance; give V (or noise)")
    V = check_spd(as_matrix(V, "V", rows=p, cols=p, rows_what="the estimator's outputs",
                            cols_what="the estimator's outputs"), "V", semidefinite=True)
    draws = check_int(draws, "draws")
    lam, U = np.linalg.eigh(V)
    root = (U * np.sqrt(np.clip(lam, 0.0, None))) @ U.T              # the symmetric square root of V
    return as_rng(rng, "rng").standard_normal((draws, T, p)) @ root


def _estimator_loop(est: Estimator, F, G, w, w_nominal, v, e0, eh0):
    """The truck and the estimator as one linear loop in ``(x, xhat)`` (:meth:`PathFollowing.run_estimated`).

    ``F`` (S, [T,] 4, 4), ``G`` (S, [T,] 4, 1) and ``w`` (S, T, 4) are the true trucks and their curvature
    input, ``w_nominal`` (T, 4) the estimator's, ``v`` (N, T, p) the noise, ``e0`` (S, 4) the initial errors and
    ``eh0`` (S, N, 4) the priors ``x[0|-1] - x_ref[0]``. Returns ``F_a`` (S N, [T,] 8, 8), ``G_a``, ``w_a``
    (S N, T, 8) and the initial errors (S N, 8) of the scenarios ``s N + d``, with ``xhat = x[k|k]`` (filter) or
    ``x[k|k-1]`` (predictor) as the second state.
    """
    C = est.plant.output_matrices()[0]
    p, N = C.shape[0], v.shape[0]
    I4 = np.eye(4)
    if est.form == "filter":
        Lf = est.L_filter
        ICL = np.eye(p) - C @ Lf
        if np.linalg.svd(ICL, compute_uv=False)[-1] <= 1e-12:
            raise ValueError("estimator: I - C L_filter is singular, so the innovation is not a function of the "
                             "filtered estimate; use form='predictor'")
        Je = est.J @ np.linalg.inv(ICL)                       # J e_k = Je (C x_k + v_k - C x[k|k])
        Psi = I4 - Lf @ C
        A21, A22, B2 = Psi @ Je @ C + Lf @ C @ F, Psi @ (est.F - Je @ C), Psi @ est.G + Lf @ C @ G
        v_next = np.concatenate([v[:, 1:], np.zeros_like(v[:, :1])], axis=1)   # the last one is never used
        w2 = (w_nominal @ Psi.T + (w @ (Lf @ C).T)[:, None] + (v @ (Psi @ Je).T + v_next @ Lf.T)[None])
        eh0 = eh0 + ((e0 @ C.T)[:, None] + v[None, :, 0] - eh0 @ C.T) @ Lf.T
    else:
        Lp = est.L_predictor
        A21, A22, B2 = np.broadcast_to(Lp @ C, F.shape), est.F - Lp @ C, np.broadcast_to(est.G, G.shape)
        w2 = np.broadcast_to(w_nominal + (v @ Lp.T)[None], (w.shape[0], N, *w.shape[1:]))
    Fa = np.zeros((*F.shape[:-2], 8, 8))
    Fa[..., :4, :4], Fa[..., 4:, :4], Fa[..., 4:, 4:] = F, A21, A22
    Ga = np.concatenate([G, np.broadcast_to(B2, G.shape)], axis=-2)
    wa = np.concatenate([np.broadcast_to(w[:, None], w2.shape), w2], axis=-1)
    xa0 = np.concatenate([np.broadcast_to(e0[:, None], eh0.shape), eh0], axis=-1)
    S = F.shape[0]
    return (np.repeat(Fa, N, axis=0), np.repeat(Ga, N, axis=0), wa.reshape(S * N, *wa.shape[2:]),
            xa0.reshape(S * N, 8))


class PathFollowing:
    r"""The truck along ``path`` at S payload scenarios, ready to simulate gains (checked once).

    Parameters
    ----------
    path : ReferencePath
        Speed and ``dt`` must equal the model's ``params.v`` and ``params.dt``.
    overloads : float, or sequence of S floats / (T,) arrays
        Payload overload of each scenario in percent (>= 0); an array gives a
        time-varying payload (e.g. unloading at a stop), sample by sample.
    setup : PathFollowingSetup
        Reference, loop and initial state (module docstring; default :data:`DEFAULT_SETUP`).
    params : TruckParameters, optional
    nominal_overload : float
        Overload of the model the reference and feedforward are computed on.
    steer_limit : float or None
        Steering saturation [rad] (0.45 in the paper); None for none.
    feedforward : bool, optional
        Add the reference's steering command (default: the set-up's).
    x0 : (4,) or (S, 4) array_like, optional
        Initial error ``x[0] - x_ref[0]`` (default: the set-up's).
    bound : float
        Divergence bound (see :mod:`robustctl.sim.simulator`).
    input_map : (1, m) array_like, optional
        How the controller's m inputs make the steering angle: ``[[1]]`` (the
        default, for gains of one row) or e.g. ``[[1, 1]]`` for the doubled
        steering column (:data:`robustctl.models.truck.DOUBLED_INPUT_MAP`).
        Gains of several rows need it: without it they are summed, with a
        ``DeprecationWarning`` (the earlier, implicit behaviour).

    Attributes
    ----------
    path : ReferencePath
        The path.
    overloads : tuple
        The scenarios' overloads (floats, or (T,) arrays).
    setup : PathFollowingSetup
        The set-up.

    Raises
    ------
    TypeError
        ``path`` not a ReferencePath, ``setup`` not a PathFollowingSetup,
        non-numeric overloads.
    ValueError
        A path whose speed or ``dt`` differs from the model's, negative
        overloads, a time-varying overload of another length than the path.

    See Also
    --------
    simulate : the one-call form.
    robustctl.sim.LinearSimulator : the simulator underneath.

    Notes
    -----
    Each scenario ``s`` is the ZOH model of the truck at its overload
    (:func:`robustctl.models.truck.discretise`) in the loop (module docstring) [1]_

    .. math::

        e_k = x_k - x^{ref}_k, \qquad
        \alpha_k = \operatorname{sat}_{0.45}\left(M K e_k + \alpha^{ff}_k\right), \qquad
        x_{k+1} = F_s x_k + G_s \alpha_k + G_{\kappa,s} \kappa_k .

    References
    ----------
    .. [1] G. A. Prudencio de Morais et al., "Robust path-following control
       design of heavy vehicles based on multiobjective evolutionary
       optimization", Expert Systems with Applications 192, 116304, 2022,
       Section 4.5.

    Examples
    --------
    An LQR of the nominal truck on a straight, started 1 m off the path,
    at the nominal payload and at 100 % overload; without saturation the
    error is ``(F_s + G_s K)^k e_0``, written out here:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models import truck
    >>> from robustctl.models.path import ReferencePath
    >>> from robustctl.models.pathfollow import PathFollowing
    >>> Q, R = truck.lqr_weights()
    >>> K = rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K
    >>> runs = PathFollowing(ReferencePath.straight(20.0), [0.0, 100.0])
    >>> runs
    PathFollowing(path='straight', setup='engineering', S=2, T=200, input_map=default)
    >>> res = runs.run(K, backend="numpy")
    >>> bool(np.abs(res.steering).max() < truck.STEER_LIMIT)          # never saturated
    True
    >>> plant = truck.truck_plant(100.0)
    >>> e, squares = np.array([0.0, 0.0, 1.0, 0.0]), np.zeros(4)
    >>> for _ in range(runs.T):
    ...     squares += e * e
    ...     e = (plant.F + plant.G @ K) @ e
    >>> bool(np.allclose(res.state_mse()[0, 1], squares / runs.T))
    True
    """

    def __init__(self, path: ReferencePath, overloads=0.0, *, setup: PathFollowingSetup = DEFAULT_SETUP,
                 params: _truck.TruckParameters | None = None, nominal_overload: float = 0.0,
                 steer_limit: float | None = _truck.STEER_LIMIT, feedforward: bool | None = None, x0=None,
                 bound: float = DEFAULT_BOUND, input_map=None):
        p = _truck._params(params)
        self.setup = _check_setup(setup)
        if not isinstance(path, ReferencePath):
            raise TypeError(f"path must be a robustctl.models.path.ReferencePath, got {type(path).__name__}")
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
        if self.setup.reference == "steady":
            x_ref, a_ff = _truck.reference_states(path.kappa, nominal_overload, params=p)
        else:
            x_ref, a_ff = _truck.open_loop_reference(path.kappa, nominal_overload, params=p)
            x_ref[:, :2] = 0.0                        # lateral velocity and yaw rate regulated to zero
        feedforward = self.setup.feedforward if feedforward is None else check_bool(feedforward, "feedforward")
        u_ff = a_ff if feedforward else np.zeros_like(a_ff)
        x0 = self.setup.x0 if x0 is None else x0
        self._given_map = input_map is not None
        self._linear = LinearSimulator(
            F, G, x_ref, u_ff=u_ff[:, None], w=w, x0=x0, u_limit=steer_limit, input_map=input_map, bound=bound,
            objectives=_truck.OBJECTIVE_STATES, state_names=_truck.STATE_NAMES, dt=p.dt)
        self._memory: LinearSimulator | None = None    # the plant augmented by the previous steering angle
        self._loop = dict(F=F, G=G, x_ref=x_ref, u_ff=u_ff, w=w, x0=np.asarray(x0, dtype=float),
                          steer_limit=steer_limit, bound=bound, dt=p.dt, input_map=input_map,
                          w_nominal=_truck.discretise(nominal_overload, params=p)[2][0] * path.kappa[:, None])
        self.path = path
        self.overloads = scen

    @property
    def S(self) -> int:
        """Number of payload scenarios."""
        return self._linear.S

    @property
    def T(self) -> int:
        """Number of samples along the path."""
        return self._linear.T

    def _memory_simulator(self) -> LinearSimulator:
        """``[x; alpha_prev]``: ``F_a = [[F, 0], [0, 0]]``, ``G_a = [G; 1]`` (built on first use)."""
        if self._memory is None:
            a = self._loop
            F, G = a["F"], a["G"]
            Fa = np.zeros((*F.shape[:-2], 5, 5))
            Fa[..., :4, :4] = F
            Ga = np.concatenate([G, np.ones((*G.shape[:-2], 1, 1))], axis=-2)

            def pad(v):                              # the memory state's entry: zero reference, disturbance, start
                return np.concatenate([v, np.zeros((*v.shape[:-1], 1))], axis=-1)

            self._memory = LinearSimulator(
                Fa, Ga, pad(a["x_ref"]), u_ff=a["u_ff"][:, None], w=pad(a["w"]), x0=pad(a["x0"]),
                u_limit=a["steer_limit"], bound=a["bound"], objectives=_truck.OBJECTIVE_STATES,
                state_names=(*_truck.STATE_NAMES, "alpha_prev"), dt=a["dt"])
        return self._memory

    def run(self, K, *, K_input=None, keep_trajectories: bool = True, nan_gains: Literal["raise", "flag"] = "raise",
            backend: Literal["numba", "numpy"] = "numba") -> PathFollowingResult:
        """Simulate B gains on every scenario.

        Parameters
        ----------
        K : (m, 4) or (B, m, 4) array_like
            Gains with ``u = K e`` (``m`` = the input map's columns).
        K_input : (m, 1) or (B, m, 1) array_like, optional
            Gain on the previous applied (saturated) steering angle, for laws
            with input memory: ``u[k] = K e[k] + K_input alpha[k-1]``,
            ``alpha[-1] = 0`` (one-row gains, no input map).
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

        Raises
        ------
        ValueError
            Gains of the wrong shape or with non-finite entries (unless
            ``nan_gains="flag"``), ``K_input`` with an input map.

        Warns
        -----
        DeprecationWarning
            Gains of several rows without an ``input_map`` (summed).
        """
        if K_input is not None:
            return self._run_with_memory(K, K_input, keep_trajectories, nan_gains, backend)
        sim = self._linear
        shape: tuple[int, ...]
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

    def run_laws(self, laws: Sequence[InputMemoryFeedback], *, keep_trajectories: bool = True,
                 backend: Literal["numba", "numpy"] = "numba") -> PathFollowingResult:
        """Simulate a list of one-row laws, static and with input memory mixed, in their order.

        The static laws (``K_input`` None) run as one batch of :meth:`run`,
        those with input memory as a second one (``run(K, K_input=...)``); the
        result's batch axis follows ``laws``.

        Parameters
        ----------
        laws : sequence of InputMemoryFeedback
            Laws ``u[k] = K e[k] (+ K_input alpha[k-1])`` with one-row ``K``
            (1, 4) on the steering angle.
        keep_trajectories : bool
            False keeps only the MSE sums.
        backend : {"numba", "numpy"}
            Compiled kernel (default) or the numpy reference.

        Returns
        -------
        PathFollowingResult
            As :meth:`run`, B = ``len(laws)``.

        Raises
        ------
        TypeError
            ``laws`` empty or not all :class:`~robustctl.InputMemoryFeedback`.
        """
        laws = list(laws)
        if not laws or not all(isinstance(law, InputMemoryFeedback) for law in laws):
            raise TypeError("laws must be a non-empty sequence of robustctl.InputMemoryFeedback")
        static = [b for b, law in enumerate(laws) if law.K_input is None]
        memory = [b for b, law in enumerate(laws) if law.K_input is not None]
        parts = []
        if static:
            parts.append(self.run(np.stack([laws[b].K for b in static]), keep_trajectories=keep_trajectories,
                                  backend=backend))
        if memory:
            parts.append(self.run(np.stack([laws[b].K for b in memory]),
                                  K_input=np.stack([Ku for b in memory if (Ku := laws[b].K_input) is not None]),
                                  keep_trajectories=keep_trajectories, backend=backend))
        if len(parts) == 1:
            return parts[0]
        order = np.argsort(static + memory)                                  # back to the laws' order
        stacked: dict[str, Any] = {}
        for f in dataclass_fields(parts[0]):
            a, b = getattr(parts[0], f.name), getattr(parts[1], f.name)
            batched = f.name in ("errors", "inputs", "sq_error_sum", "sq_state_sum", "diverged", "diverged_step",
                                 "saturated_steps")
            stacked[f.name] = np.concatenate([a, b])[order] if batched and a is not None else a
        return PathFollowingResult(**stacked)

    def run_estimated(self, K, estimator: Estimator, *, noise=None, V=None, draws: int = 1, rng=None,
                      xhat0=None, keep_trajectories: bool = True, nan_gains: Literal["raise", "flag"] = "raise",
                      backend: Literal["numba", "numpy"] = "numba") -> EstimatedPathFollowingResult:
        r"""Simulate B gains fed back on an estimate of the state from noisy measurements, on every scenario.

        The controller sees ``y = C x + v`` (the estimator's ``C``, e.g. the
        sensors of :func:`robustctl.models.truck.sensor_plant`), not the state:
        ``u = sat(M K (xhat - x_ref) + u_ff)``, with ``xhat`` the estimate that
        ``estimator`` makes from ``y`` and the applied (saturated) steering
        angle. The estimator runs on its own (nominal) model at every
        scenario: the true truck is the scenario's, the estimator is not told.

        Parameters
        ----------
        K : (m, 4) or (B, m, 4) array_like
            Gains with ``u = K e`` (``m`` > 1 needs the simulator's ``input_map``).
        estimator : Estimator
            A discrete-time estimator of the truck with one steering input
            (``n = 4``, ``m = 1``) and the path's ``dt``, from
            :func:`robustctl.kalman` or :func:`robustctl.robust_kalman`; its
            ``form`` says which estimate is fed back: ``x[k|k]``
            (``"filter"``) or ``x[k|k-1]`` (``"predictor"``).
        noise : (T, p) or (draws, T, p) array_like, optional
            Measurement noise samples ``v[0] .. v[T-1]`` (any sequence: a
            colored or biased error too). Default: drawn here, white normal of
            covariance ``V``.
        V : (p, p) array_like, optional
            Covariance of the drawn noise (symmetric positive semidefinite;
            zero: noiseless sensors). Default the estimator's design ``V``.
        draws : int
            Noise sequences drawn, each run at every scenario (the same
            sequences at every overload).
        rng : None, int or Generator
            Seed of the draws (:func:`numpy.random.default_rng`).
        xhat0 : (4,) array_like, optional
            The estimator's prior ``x[0|-1] - x_ref[0]``. Default: from the
            first measurement, ``pinv(C) (y[0] - C x_ref[0])`` (the measured
            states as measured, the others at the reference).
        keep_trajectories : bool
            False keeps only the MSE sums.
        nan_gains : {"raise", "flag"}
            As :meth:`run`.
        backend : {"numba", "numpy"}
            The compiled kernel (default) or the numpy reference of
            :class:`~robustctl.sim.LinearSimulator`.

        Returns
        -------
        EstimatedPathFollowingResult
            Scenarios ``s * draws + d`` (the ``s``-th overload with the
            ``d``-th noise sequence): ``errors`` (B, S * draws, T, 4) of the
            true state, ``estimates`` of the estimate, ``mse()`` and
            ``mse_by_draw()`` (B, S, draws, 4).

        Raises
        ------
        TypeError
            ``estimator`` is not an :class:`~robustctl.estimation.estimator.Estimator`.
        ValueError
            An estimator of another plant size, sampling time or of
            continuous time; gains of the wrong shape or of several rows
            without an input map; ``noise`` of the wrong shape or with
            non-finite entries, or given with ``V``, ``draws`` or ``rng``;
            ``V`` not symmetric positive semidefinite; ``xhat0`` not 4
            numbers.

        See Also
        --------
        run : the loop on the true state.
        robustctl.observer_controller : the same loop as a dynamic controller.

        Notes
        -----
        With ``e = y - C xhat_{k|k-1} - D u`` the innovation, ``L_f``, ``F_e``,
        ``G_e``, ``J`` the estimator's (:class:`~robustctl.estimation.estimator.Estimator`)
        and ``E_0 kappa_k`` the curvature input of the nominal model, the loop
        is [1]_

        .. math::

            x_{k|k} = x_{k|k-1} + L_f e_k, \qquad
            x_{k+1|k} = F_e x_{k|k} + G_e \alpha_k + J e_k + E_0 \kappa_k, \qquad
            \alpha_k = \operatorname{sat}(M K (\hat x_k - x^{ref}_k) + \alpha^{ff}_k),

        with ``xhat_k = x_{k|k}`` (filter) or ``x_{k|k-1}`` (predictor), and
        the truck's ``x_{k+1} = F_s x_k + G_s alpha_k + E_s kappa_k``. It is
        simulated as one linear loop in ``(x, xhat)`` on
        :class:`~robustctl.sim.LinearSimulator` (filter form: ``e_k =
        (I - C L_f)^{-1} (C x_k + v_k - C x_{k|k})``); the divergence bound
        applies to both parts.

        References
        ----------
        .. [1] G. F. Franklin, J. D. Powell, M. L. Workman, *Digital Control
           of Dynamic Systems*, 3rd ed., Addison-Wesley 1998, Sec. 8.6.

        Examples
        --------
        With noiseless sensors and the estimator started at the true state,
        a Kalman filter of the nominal model tracks the nominal truck
        exactly as the loop on the true state does:

        >>> import numpy as np
        >>> import robustctl as rc
        >>> from robustctl.models import truck
        >>> from robustctl.models.path import ReferencePath
        >>> from robustctl.models.pathfollow import PathFollowing
        >>> est = rc.kalman(truck.sensor_plant(0.0), [[0.01]], truck.TruckSensors().covariance(0.1),
        ...                 Bw=truck.truck_plant(0.0).G)
        >>> Q, R = truck.lqr_weights()
        >>> K = rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K
        >>> runs = PathFollowing(ReferencePath.from_curvature(np.full(200, 1 / 300.0)), 0.0)
        >>> sensed = runs.run_estimated(K, est, V=np.zeros((3, 3)), xhat0=runs.setup.x0, backend="numpy")
        >>> exact = runs.run(K, backend="numpy")
        >>> bool(np.allclose(sensed.errors, exact.errors, rtol=0, atol=1e-12))
        True
        """
        a = self._loop
        est = self._check_estimator(estimator)
        C = est.plant.output_matrices()[0]
        v = _measurement_noise(noise, V, draws, rng, est, self.T, C.shape[0])
        Kb, bad = check_gains(K, 4, nan_gains)
        if Kb.shape[1] > 1 and a["input_map"] is None:
            raise ValueError(f"K has {Kb.shape[1]} rows but the truck has one steering input: give the "
                             f"PathFollowing an input_map (e.g. robustctl.models.truck.DOUBLED_INPUT_MAP)")
        e0 = np.broadcast_to(a["x0"], (self.S, 4))
        if xhat0 is None:                                     # the measured states as measured, the others at 0
            eh0 = (e0 @ C.T)[:, None] + v[None, :, 0]
            eh0 = eh0 @ np.linalg.pinv(C).T
        else:
            eh0 = np.broadcast_to(as_batch(as_float_array(xhat0, "xhat0"), "xhat0", (4,)), (self.S, v.shape[0], 4))
        Fa, Ga, wa, xa0 = _estimator_loop(est, a["F"], a["G"], a["w"], a["w_nominal"], v, e0, eh0)
        sim = LinearSimulator(
            Fa, Ga, np.concatenate([a["x_ref"], a["x_ref"]], axis=-1), u_ff=a["u_ff"][:, None], w=wa, x0=xa0,
            u_limit=a["steer_limit"], input_map=a["input_map"], bound=a["bound"],
            objectives=_truck.OBJECTIVE_STATES, dt=a["dt"])
        Ka = np.concatenate([np.zeros_like(Kb), Kb], axis=2)     # u = K (xhat - x_ref)
        Ka[bad] = np.nan                                          # flagged by the simulator
        res = sim.run(Ka, keep_trajectories=keep_trajectories, nan_gains=nan_gains, backend=backend)
        fields = vars(res).copy()
        both = fields["errors"]
        for name in ("errors", "sq_error_sum", "sq_state_sum", "x_ref"):
            if fields[name] is not None:
                fields[name] = fields[name][..., :4]
        fields["state_names"] = _truck.STATE_NAMES
        N = v.shape[0]
        return EstimatedPathFollowingResult(
            **fields, path=self.path, overloads=tuple(ov for ov in self.overloads for _ in range(N)),
            estimates=None if both is None else both[..., 4:], draws=N, form=est.form)

    def _check_estimator(self, estimator) -> Estimator:
        if not isinstance(estimator, Estimator):
            raise TypeError(f"estimator must be a robustctl Estimator (robustctl.kalman, robustctl.robust_kalman), "
                            f"got {type(estimator).__name__}")
        plant, dt = estimator.plant, self._loop["dt"]
        if not plant.is_discrete or abs(plant.dt - dt) > 1e-12 * dt:
            raise ValueError(f"estimator must be a discrete-time estimator at the path's dt = {dt:g} s, got "
                             f"{'a continuous-time one' if not plant.is_discrete else f'dt = {plant.dt:g} s'}")
        if (plant.n, plant.m) != (4, 1):
            raise ValueError(f"estimator must be designed on the truck with one steering input (n = 4, m = 1, e.g. "
                             f"robustctl.models.truck.sensor_plant), got n = {plant.n}, m = {plant.m}")
        return estimator

    def _run_with_memory(self, K, K_input, keep, nan_gains, backend) -> PathFollowingResult:
        if self._given_map:
            raise ValueError("K_input needs one-row gains on the steering angle (no input_map)")
        Kb, bad = check_gains(K, 4, nan_gains)
        Ku = as_float_array(K_input, "K_input")
        Ku = Ku[None] if Ku.ndim == 2 else Ku
        if Kb.shape[1] != 1 or Ku.ndim != 3 or Ku.shape[1:] != (1, 1) or Ku.shape[0] not in (1, Kb.shape[0]):
            raise ValueError(f"K_input must have shape (1, 1) or (B, 1, 1) for K of shape (B, 1, 4), "
                             f"got K {np.shape(K)} and K_input {np.shape(K_input)}")
        bad_u = ~np.isfinite(Ku).all(axis=(1, 2))
        if bad_u.any() and nan_gains == "raise":
            raise ValueError("K_input must have finite entries (found NaN or inf); "
                             "nan_gains='flag' reports such gains as diverged instead")
        Ka = np.concatenate([Kb, np.broadcast_to(Ku, (Kb.shape[0], 1, 1))], axis=2)
        Ka[bad | bad_u] = np.nan                    # flagged by the simulator (nan_gains="flag" here)
        res = self._memory_simulator().run(Ka, keep_trajectories=keep, nan_gains=nan_gains, backend=backend)
        fields = vars(res).copy()
        for name in ("errors", "sq_error_sum", "sq_state_sum", "x_ref"):
            if fields[name] is not None:
                fields[name] = fields[name][..., :4]
        fields["state_names"] = _truck.STATE_NAMES
        return PathFollowingResult(**fields, path=self.path, overloads=self.overloads)

    def __repr__(self) -> str:
        return (f"PathFollowing(path={self.path.name!r}, setup={self.setup.name!r}, S={self.S}, T={self.T}, "
                f"input_map={'given' if self._given_map else 'default'})")


def simulate(K, path: ReferencePath, overloads=0.0, *, setup: PathFollowingSetup = DEFAULT_SETUP,
             params: _truck.TruckParameters | None = None, nominal_overload: float = 0.0,
             steer_limit: float | None = _truck.STEER_LIMIT, feedforward: bool | None = None, x0=None,
             bound: float = DEFAULT_BOUND, keep_trajectories: bool = True,
             nan_gains: Literal["raise", "flag"] = "raise", input_map=None, K_input=None,
             backend: Literal["numba", "numpy"] = "numba") -> PathFollowingResult:
    """Truck path following: B gains x S payload scenarios over ``path``, in one call.

    ``PathFollowing(path, overloads, ...).run(K, ...)``; see :class:`PathFollowing`
    (scenarios, set-up, input map) and :meth:`PathFollowing.run` (gains,
    ``K_input``, result). A gain of several rows needs ``input_map`` (e.g.
    ``[[1, 1]]`` for the doubled steering column); without it the rows are
    summed with a ``DeprecationWarning``.

    Parameters
    ----------
    K : (m, 4) or (B, m, 4) array_like
        Gains, ``u = K e``.
    path : ReferencePath
        The path (speed and ``dt`` of the model).
    overloads : float, or sequence of S floats / (T,) arrays
        Payload overload of each scenario in percent.
    setup : PathFollowingSetup
        Reference, loop and initial state (default :data:`DEFAULT_SETUP`).
    params : TruckParameters, optional
        Defaults to the paper's parameters.
    nominal_overload : float
        Overload of the model the reference is computed on.
    steer_limit : float or None
        Steering saturation [rad]; None for none.
    feedforward : bool, optional
        Add the reference's steering command (default: the set-up's).
    x0 : (4,) or (S, 4) array_like, optional
        Initial error (default: the set-up's).
    bound : float
        Divergence bound.
    keep_trajectories : bool
        False keeps only the MSE sums.
    nan_gains : {"raise", "flag"}
        Raise on non-finite gains, or flag them as diverged.
    input_map : (1, m) array_like, optional
        How the controller's inputs make the steering angle.
    K_input : (m, 1) or (B, m, 1) array_like, optional
        Gain on the previous steering angle (laws with input memory).
    backend : {"numba", "numpy"}
        Compiled kernel (default) or the numpy reference.

    Returns
    -------
    PathFollowingResult
        ``errors`` (B, S, T, 4), ``steering`` (B, S, T), ``mse()`` (B, S, 4)
        in the paper's order f1..f4 = MSE of rho, psidot, ydot, theta;
        ``pose()`` for plotting.

    Raises
    ------
    ValueError, TypeError
        As :class:`PathFollowing` and :meth:`PathFollowing.run`.

    See Also
    --------
    PathFollowing : the same with the scenarios built once.

    Examples
    --------
    On a path of constant curvature the nominal truck, started on its
    steady-cornering reference, follows it with no error (the feedforward
    is the steady-state steering):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models import truck
    >>> from robustctl.models.path import ReferencePath
    >>> from robustctl.models.pathfollow import simulate
    >>> Q, R = truck.lqr_weights()
    >>> K = rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K
    >>> circle = ReferencePath.from_curvature(np.full(100, 1 / 300.0))
    >>> res = simulate(K, circle, 0.0, x0=np.zeros(4), backend="numpy")
    >>> res.mse().shape
    (1, 1, 4)
    >>> bool(np.abs(res.errors).max() < 1e-12)
    True
    """
    sim = PathFollowing(path, overloads, setup=setup, params=params, nominal_overload=nominal_overload,
                        steer_limit=steer_limit, feedforward=feedforward, x0=x0, bound=bound,
                        input_map=input_map)
    return sim.run(K, K_input=K_input, keep_trajectories=keep_trajectories, nan_gains=nan_gains, backend=backend)
