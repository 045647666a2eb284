"""Closed-loop simulation of state feedback with input saturation, batched.

Two layers:

* :func:`simulate_linear` - any discrete-time linear plant
  ``x[k+1] = F[k] x[k] + G[k] u[k] + w[k]`` under the saturated tracking law
  ``u[k] = sat(M K (x[k] - x_ref[k]) + u_ff[k])``, for B gains and S plants
  (scenarios) at once: the time loop runs over T steps on (S, n, B) state
  arrays, so a whole population costs one array recursion.
* :func:`simulate` - the truck path-following run of the paper
  (:mod:`robustctl.models.truck`, :mod:`robustctl.path`): true plant at a given
  payload overload, controller designed on the nominal model, steering limit
  0.45 rad, curvature of the path as a known disturbance, reference states and
  steady-state steering feedforward from the nominal model.

Diverging runs (an unstable closed loop, or a saturated one that drifts away)
are not integrated to overflow: once any error component exceeds ``bound`` in
magnitude the run is frozen and flagged (``diverged``, ``diverged_step``), and
from then on *every* component of its error is held at ``±bound`` (the sign it
had at divergence). A run that diverges at step ``k`` therefore has, in every
objective, an MSE of at least ``(T - k) / T * bound**2``: large, finite, larger
the earlier it diverged, and never better than a stable run in any single
objective (which holding the last value would allow, e.g. a small yaw-rate
error while ``rho`` blows up) - a safe ranking for an optimiser.

References
----------
K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed., Princeton 2021,
Sec. 8.5 (two-degree-of-freedom tracking: feedforward plus feedback on the
error from a reference trajectory). Morais et al. (2022), Section 4.5.2
(the four objectives f1..f4 and the payload cases).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ._validation import as_batch, check_positive_scalar
from .models import truck as _truck
from .path import ReferencePath

__all__ = ["SimulationResult", "simulate", "simulate_linear", "DEFAULT_INITIAL_ERROR", "DEFAULT_BOUND"]

#: Initial path-following error of :func:`simulate`: the truck starts 1 m to the
#: left of the path, parallel to it, at steady speed ([ydot, psidot, rho, theta]).
DEFAULT_INITIAL_ERROR = (0.0, 0.0, 1.0, 0.0)
#: Divergence bound on ``|x - x_ref|`` (any component), in the states' units.
DEFAULT_BOUND = 1e3


@dataclass(frozen=True, eq=False, repr=False)
class SimulationResult:
    """Outcome of a batched closed-loop run: B gains x S scenarios x T samples.

    Attributes
    ----------
    errors : (B, S, T, n) ndarray or None
        ``x[k] - x_ref[k]`` for k = 0..T-1 (None if trajectories were not kept).
    inputs : (B, S, T, p) ndarray or None
        Applied (saturated) physical inputs.
    sq_error_sum : (B, S, n) ndarray
        ``sum_k (x[k] - x_ref[k])^2``.
    sq_state_sum : (B, S, n) ndarray
        ``sum_k x[k]^2`` (for regulation errors, see :meth:`mse`).
    diverged : (B, S) ndarray of bool
        Run left the ``bound`` (then frozen; see the module docstring).
    diverged_step : (B, S) ndarray of int
        First step beyond the bound, -1 if none.
    saturated_steps : (B, S) ndarray of int
        Steps at which an input was at its limit (after divergence the frozen
        run's input keeps being counted).
    x_ref : (T, n) or (S, T, n) ndarray
    objectives : tuple of int
        State indices :meth:`mse` reports, in order.
    T : int
    dt : float or None
    path : ReferencePath or None
        Set by :func:`simulate` (needed by :meth:`pose`).
    overloads : tuple or None
        Scenario overloads of :func:`simulate` (floats, or arrays when time-varying).
    """

    errors: np.ndarray | None
    inputs: np.ndarray | None
    sq_error_sum: np.ndarray
    sq_state_sum: np.ndarray
    diverged: np.ndarray
    diverged_step: np.ndarray
    saturated_steps: np.ndarray
    x_ref: np.ndarray
    objectives: tuple[int, ...]
    T: int
    dt: float | None = None
    path: ReferencePath | None = None
    overloads: tuple | None = None

    @property
    def B(self) -> int:
        return self.diverged.shape[0]

    @property
    def S(self) -> int:
        return self.diverged.shape[1]

    def mse(self, target: str = "reference") -> np.ndarray:
        """Mean squared error of each objective state, shape (B, S, len(objectives)).

        For :func:`simulate` this is the paper's ``[f1, f2, f3, f4]`` =
        MSE of ``[rho, psidot, ydot, theta]`` errors (lateral displacement [m^2],
        yaw rate [(rad/s)^2], lateral velocity [(m/s)^2], orientation [rad^2]).
        Diverged runs get a large finite value (see the module docstring).

        Parameters
        ----------
        target : {"reference", "zero"}
            ``"reference"`` (default): MSE of the tracking error ``x - x_ref``.
            ``"zero"``: MSE of the states themselves, the *regulation* error
            of a regulator driving every state to zero. For the truck the two
            differ only in ``ydot``, ``psidot`` and ``theta`` (``rho_ref = 0``):
            in a bend the yaw rate must be ``v kappa``, so its regulation error
            measures the path as much as the controller.
        """
        if target == "reference":
            sums = self.sq_error_sum
        elif target == "zero":
            sums = self.sq_state_sum
        else:
            raise ValueError(f"target must be 'reference' or 'zero', got {target!r}")
        return sums[..., list(self.objectives)] / self.T

    @property
    def steering(self) -> np.ndarray:
        """Applied steering (first physical input), shape (B, S, T)."""
        self._need_trajectories()
        return self.inputs[..., 0]

    @property
    def states(self) -> np.ndarray:
        """``x = errors + x_ref``, shape (B, S, T, n)."""
        self._need_trajectories()
        return self.errors + self.x_ref

    def pose(self, method: str = "path") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
        if self.path is None:
            raise ValueError("pose() needs the path; it is set by robustctl.simulate.simulate")
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

    def _need_trajectories(self):
        if self.errors is None:
            raise ValueError("trajectories were not kept (keep_trajectories=False)")

    def __repr__(self) -> str:
        n_div = int(self.diverged.sum())
        return (f"SimulationResult(B={self.B}, S={self.S}, T={self.T}, dt={self.dt}, "
                f"diverged={n_div}/{self.diverged.size}, trajectories={self.errors is not None})")


# -- generic layer -----------------------------------------------------------------------
def _as_gains(K, name: str = "K", nan_gains: str = "raise") -> tuple[np.ndarray, np.ndarray]:
    """(B, m, n) gains and a (B,) mask of gains with non-finite entries (zeroed)."""
    if isinstance(K, (str, bytes)):
        raise TypeError(f"{name} must be an array of numbers, got {type(K).__name__}")
    try:
        arr = np.array(K, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of real numbers") from None
    if arr.ndim not in (2, 3):
        raise ValueError(f"{name} must be an (m, n) gain or a (B, m, n) stack of gains, got shape {arr.shape}")
    arr = arr[None] if arr.ndim == 2 else arr
    if nan_gains not in ("raise", "flag"):
        raise ValueError(f"nan_gains must be 'raise' or 'flag', got {nan_gains!r}")
    bad = ~np.isfinite(arr).all(axis=(1, 2))
    if nan_gains == "raise":
        return as_batch(arr, name, (None, None, None)), bad
    arr[bad] = 0.0
    return arr, bad


def _time_matrices(M, name: str, rows: int, cols: int | None):
    """Return M as (S, T, rows, cols) (a broadcast view when constant in time)."""
    arr = np.asarray(M, dtype=float)
    if arr.ndim == 2:
        arr = arr[None]
    if arr.ndim == 3:
        arr = as_batch(arr, name, (None, rows, cols))
        return arr[:, None]
    if arr.ndim == 4:
        return as_batch(arr, name, (None, None, rows, cols))
    raise ValueError(f"{name} must have shape ({rows}, {cols or 'p'}), (S, {rows}, {cols or 'p'}) "
                     f"or (S, T, {rows}, {cols or 'p'}), got shape {arr.shape}")


def simulate_linear(K, F, G, x_ref, *, u_ff=None, w=None, x0=None, u_limit=None, input_map=None,
                    bound: float = DEFAULT_BOUND, keep_trajectories: bool = True,
                    objectives: Sequence[int] | None = None, dt: float | None = None,
                    nan_gains: str = "raise") -> SimulationResult:
    """Simulate ``x[k+1] = F x[k] + G u[k] + w[k]``, ``u[k] = sat(M K (x[k] - x_ref[k]) + u_ff[k])``.

    All B gains are run on all S plants (scenarios) in one array recursion.

    Parameters
    ----------
    K : (m, n) or (B, m, n) array_like
        State-feedback gains, convention ``u = K x``.
    F : (n, n), (S, n, n) or (S, T, n, n) array_like
        Plant matrices per scenario, constant or per time step (time-varying plant).
    G : (n, p), (S, n, p) or (S, T, n, p) array_like
        Physical input matrices.
    x_ref : (T, n) or (S, T, n) array_like
        Reference states; fixes the horizon T.
    u_ff : (T, p) or (S, T, p) array_like, optional
        Feedforward input (default zero).
    w : (T, n) or (S, T, n) array_like, optional
        Known additive disturbance (default zero).
    x0 : (n,) or (S, n) array_like, optional
        Initial *error* ``x[0] - x_ref[0]`` (default zero).
    u_limit : float or (p,) array_like, optional
        Symmetric saturation ``|u_j| <= u_limit_j`` (default: none).
    input_map : (p, m) array_like, optional
        ``M`` mapping the controller's m inputs to the plant's p inputs
        (default identity, which needs m == p). The doubled steering column is
        ``M = [[1, 1]]``.
    bound : float
        Divergence bound on ``|x - x_ref|`` (see the module docstring).
    keep_trajectories : bool
        Keep ``errors`` and ``inputs`` (B, S, T, .) arrays; False keeps only the
        sums needed for :meth:`SimulationResult.mse` (less memory, a bit faster).
    objectives : sequence of int, optional
        State indices :meth:`SimulationResult.mse` reports (default all, in order).
    dt : float, optional
        Sampling time, only recorded in the result.
    nan_gains : {"raise", "flag"}
        A gain with NaN/inf entries (e.g. a failed design of a batch) raises
        ``ValueError`` (default), or with ``"flag"`` is not simulated and is
        reported as diverged at step 0 with every error at ``bound`` (MSE =
        ``bound**2``).

    Returns
    -------
    SimulationResult
    """
    Kb, bad_gain = _as_gains(K, nan_gains=nan_gains)
    B, m, n = Kb.shape
    x_ref = np.asarray(x_ref, dtype=float)
    if x_ref.ndim == 2:
        x_ref = as_batch(x_ref, "x_ref", (None, n), ("", "the number of states, from K"))
        T = x_ref.shape[0]
    elif x_ref.ndim == 3:
        x_ref = as_batch(x_ref, "x_ref", (None, None, n), ("", "", "the number of states, from K"))
        T = x_ref.shape[1]
    else:
        raise ValueError(f"x_ref must have shape (T, {n}) or (S, T, {n}), got shape {x_ref.shape}")
    if T < 1:
        raise ValueError("x_ref must have at least one sample (T >= 1)")
    Fa = _time_matrices(F, "F", n, n)
    Ga = _time_matrices(G, "G", n, None)
    p = Ga.shape[-1]
    S = max(Fa.shape[0], Ga.shape[0], x_ref.shape[0] if x_ref.ndim == 3 else 1)
    for name, arr in (("F", Fa), ("G", Ga)):
        if arr.shape[0] not in (1, S):
            raise ValueError(f"{name} has {arr.shape[0]} scenarios, expected 1 or {S}")
        if arr.shape[1] not in (1, T):
            raise ValueError(f"{name} has {arr.shape[1]} time steps, expected 1 or T={T} (from x_ref)")
    Fa = np.broadcast_to(Fa, (S, T, n, n))
    Ga = np.broadcast_to(Ga, (S, T, n, p))
    xr = np.broadcast_to(x_ref if x_ref.ndim == 3 else x_ref[None], (S, T, n))

    def per_step(val, name, width, what):
        if val is None:
            return np.zeros((S, T, width))
        a = np.asarray(val, dtype=float)
        shape = (None, width) if a.ndim == 2 else (None, None, width)
        a = as_batch(a, name, shape, ("",) * (len(shape) - 1) + (what,))
        if a.ndim == 3 and a.shape[0] not in (1, S):
            raise ValueError(f"{name} has {a.shape[0]} scenarios, expected 1 or {S}")
        if a.shape[-2] != T:
            raise ValueError(f"{name} must have T={T} samples (from x_ref), got shape {a.shape}")
        return np.broadcast_to(a if a.ndim == 3 else a[None], (S, T, width))

    uff = per_step(u_ff, "u_ff", p, "the number of plant inputs, from G")
    wa = per_step(w, "w", n, "the number of states")

    if input_map is None:
        if m != p:
            raise ValueError(f"K has {m} inputs (shape {Kb.shape[1:]}) but the plant has {p}; "
                             f"give input_map of shape ({p}, {m})")
        Keff = Kb
    else:
        M = as_batch(np.atleast_2d(np.asarray(input_map, dtype=float)), "input_map", (p, m),
                     ("the plant's inputs, from G", "the controller's inputs, from K"))
        Keff = np.einsum("pm,bmn->bpn", M, Kb)
    lim = None
    if u_limit is not None:
        try:
            lim = np.broadcast_to(np.asarray(u_limit, dtype=float), (p,)).copy()
        except (TypeError, ValueError):
            lim = None
        if lim is None or not np.all(lim > 0) or not np.all(np.isfinite(lim)):
            raise ValueError(f"u_limit must be a positive scalar or a ({p},) array (one per plant input), "
                             f"got {u_limit!r}")
    bound = check_positive_scalar(bound, "bound")
    if x0 is None:
        e0 = np.zeros((S, n))
    else:
        e0 = np.asarray(x0, dtype=float)
        e0 = as_batch(e0 if e0.ndim == 2 else np.broadcast_to(e0, (S,) + e0.shape), "x0", (S, n),
                      ("scenarios", "the number of states"))
    objectives = tuple(range(n)) if objectives is None else tuple(int(i) for i in objectives)
    if any(i < 0 or i >= n for i in objectives):
        raise ValueError(f"objectives must be state indices in [0, {n}), got {objectives}")

    # State layout (S, n, B): one batched matmul per step. A frozen (diverged)
    # run keeps x = x_ref + e_frozen, so its error stays e_frozen (|e| <= bound)
    # and the cheap global bound check below stays false for it.
    x = (xr[:, 0] + e0)[:, :, None] * np.ones((1, 1, B))
    KT = np.ascontiguousarray(np.transpose(Keff, (1, 2, 0)))    # (p, n, B)
    sq = np.zeros((S, n, B))
    sqx = np.zeros((S, n, B))
    alive = np.ones((S, B), dtype=bool)
    div_step = np.full((S, B), -1, dtype=np.int64)
    sat_steps = np.zeros((S, B), dtype=np.int64)
    E_all = np.empty((T, S, n, B)) if keep_trajectories else None
    U_all = np.empty((T, S, p, B)) if keep_trajectories else None
    e_frozen = np.zeros((S, n, B))
    any_dead = bool(bad_gain.any())
    if any_dead:
        alive[:, bad_gain] = False
        div_step[:, bad_gain] = 0
        e_frozen[:, :, bad_gain] = bound
        x = np.where(alive[:, None, :], x, xr[:, 0, :, None] + e_frozen)
    alive3 = alive[:, None, :]                                   # view: follows alive
    if lim is not None:
        lo, hi = -lim[None, :, None], lim[None, :, None]
    for k in range(T):
        e = x - xr[:, k, :, None]
        if np.abs(e).max() > bound:                              # rare: someone diverges now
            newly = (np.abs(e).max(axis=1) > bound) & alive
            div_step[newly] = k
            alive &= ~newly
            any_dead = True
            e_frozen = np.where(newly[:, None, :], np.where(e < 0, -bound, bound), e_frozen)
            e = np.where(alive3, e, e_frozen)
            x = np.where(alive3, x, xr[:, k, :, None] + e_frozen)
        # u[s, p, b] = sum_n Keff[b, p, n] e[s, n, b]
        u = np.einsum("pnb,snb->spb", KT, e) + uff[:, k, :, None]
        if lim is not None:
            sat = (u <= lo) | (u >= hi)
            sat_steps += sat[:, 0] if p == 1 else sat.any(axis=1)
            u = np.minimum(np.maximum(u, lo), hi)
        sq += e * e
        sqx += x * x
        if keep_trajectories:
            E_all[k] = e
            U_all[k] = u
        if k + 1 < T:
            x = Fa[:, k] @ x + Ga[:, k] @ u + wa[:, k, :, None]
            if any_dead:
                x = np.where(alive3, x, xr[:, k + 1, :, None] + e_frozen)
    errors = inputs = None
    if keep_trajectories:
        errors = np.transpose(E_all, (3, 1, 0, 2))    # (B, S, T, n)
        inputs = np.transpose(U_all, (3, 1, 0, 2))
    return SimulationResult(
        errors=errors, inputs=inputs, sq_error_sum=np.transpose(sq, (2, 0, 1)),
        sq_state_sum=np.transpose(sqx, (2, 0, 1)),
        diverged=(div_step >= 0).T, diverged_step=div_step.T, saturated_steps=sat_steps.T,
        x_ref=np.asarray(x_ref), objectives=objectives, T=T, dt=dt)


# -- the truck path-following run ------------------------------------------------------------
def _scenarios(overloads, T: int):
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


def simulate(K, path: ReferencePath, overloads=0.0, *, params: _truck.TruckParameters | None = None,
             nominal_overload: float = 0.0, steer_limit: float | None = _truck.STEER_LIMIT,
             feedforward: bool = True, x0=DEFAULT_INITIAL_ERROR, bound: float = DEFAULT_BOUND,
             keep_trajectories: bool = True, nan_gains: str = "raise") -> SimulationResult:
    """Truck path following: B gains x S payload scenarios over ``path``.

    The true plant is the truck at each scenario's overload; the controller
    knows only the nominal model (``nominal_overload``, 0 % by default)::

        e[k]     = x[k] - x_ref[k]
        alpha[k] = sat_{steer_limit}( sum_j (K e[k])_j + alpha_ff[k] )
        x[k+1]   = F x[k] + G alpha[k] + Gk kappa[k]

    with ``F, G, Gk`` the ZOH model of the true vehicle (:func:`robustctl.models.truck.discretise`),
    ``kappa`` the path curvature, and ``x_ref``, ``alpha_ff`` the nominal
    model's steady cornering along the path (:func:`robustctl.models.truck.reference_states`;
    ``x_ref = [beta_1 v, v, 0, -beta_1] kappa`` with ``beta_1`` the nominal
    sideslip per unit curvature). The steady-state
    steering feedforward is the same for every controller; with it, the
    nominal plant follows a constant-curvature path with zero error, and
    errors come from transients, the initial offset and payload mismatch.

    Parameters
    ----------
    K : (m, n) or (B, m, n) array_like
        Gains with ``u = K e``; the steering is the sum of the m inputs, so
        m = 1 is the plain truck and m = 2 the doubled steering column
        (``alpha = u1 + u2``) of the applied RLQR designs.
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
        Divergence bound (see the module docstring).
    keep_trajectories : bool
        False keeps only the MSE sums (for optimisers).
    nan_gains : {"raise", "flag"}
        ``"flag"``: gains with NaN entries (failed designs, e.g.
        ``RLQRBatch.K`` where ``ok`` is False) are reported as diverged at
        step 0 with MSE ``bound**2`` instead of raising.

    Returns
    -------
    SimulationResult
        ``errors`` (B, S, T, 4), ``steering`` (B, S, T), ``mse()`` (B, S, 4)
        in the paper's order f1..f4 = MSE of rho, psidot, ydot, theta;
        ``pose()`` for plotting.
    """
    p = _truck._params(params)
    if not isinstance(path, ReferencePath):
        raise TypeError(f"path must be a robustctl.path.ReferencePath, got {type(path).__name__}")
    if abs(path.speed - p.v) > 1e-9 * p.v or abs(path.dt - p.dt) > 1e-12:
        raise ValueError(f"path speed/dt ({path.speed:g} m/s, {path.dt:g} s) must equal the model's "
                         f"({p.v:g} m/s, {p.dt:g} s)")
    Kb, _ = _as_gains(K, nan_gains=nan_gains)
    if Kb.shape[2] != 4:
        raise ValueError(f"K must have 4 columns (the truck's states), got shape {np.shape(K)}")
    T = path.T
    scen = _scenarios(overloads, T)
    # discretise each distinct overload once
    values = np.unique(np.concatenate([np.atleast_1d(s) for s in scen]))
    Fu, Gu, Gku = _truck.discretise(values, params=p)
    if all(np.ndim(s) == 0 for s in scen):
        idx = np.searchsorted(values, np.array(scen))
        F, G, Gk = Fu[idx], Gu[idx], Gku[idx]                          # (S, 4, 4) ...
        w = Gk[:, None, :] * path.kappa[None, :, None]                 # (S, T, 4)
    else:
        idx = np.stack([np.searchsorted(values, np.broadcast_to(s, (T,))) for s in scen])  # (S, T)
        F, G = Fu[idx], Gu[idx]                                        # (S, T, 4, 4) ...
        w = Gku[idx] * path.kappa[None, :, None]
    x_ref, a_ff = _truck.reference_states(path.kappa, nominal_overload, params=p)
    if not feedforward:
        a_ff = np.zeros_like(a_ff)
    K_in = np.asarray(K, dtype=float)
    res = simulate_linear(K_in if K_in.ndim == 3 else K_in[None], F, G, x_ref, u_ff=a_ff[:, None], w=w, x0=x0, u_limit=steer_limit,
                          input_map=np.ones((1, Kb.shape[1])), bound=bound,
                          keep_trajectories=keep_trajectories, objectives=_truck.OBJECTIVE_STATES,
                          dt=p.dt, nan_gains=nan_gains)
    return SimulationResult(res.errors, res.inputs, res.sq_error_sum, res.sq_state_sum, res.diverged,
                            res.diverged_step, res.saturated_steps, res.x_ref, res.objectives, res.T,
                            res.dt, path, scen)
