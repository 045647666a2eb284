r"""Time-domain goals: errors, peak input, settling time and overshoot, read from one batched run per population.

A :class:`Response` runs every design on every scenario (discrete plants) and
keeps the run (:class:`Run`) for the goals made from it
(:meth:`Response.error`, :meth:`~Response.peak_input`,
:meth:`~Response.settling_time`, :meth:`~Response.overshoot`), so the goals
of one population share one simulation; :class:`StepTracking` is the
response to a step of the reference. From ``x[0] = x0`` (and ``x_c = 0``)
every design runs ``u[k] = sat(K(z) (y[k] - r[k]))``,
``x[k+1] = F x[k] + G u[k]`` for ``T = steps`` samples on every scenario
(``y = x`` and ``K(z) = K`` for a state feedback:
:class:`robustctl.sim.simulator.LinearSimulator`; an output feedback:
:func:`robustctl.sim.simulate_output_feedback`), with the error
``e = y - r`` (``r = 0`` without a reference):

========================  ================================================  ==========
goal                      per design and scenario                           ``over``
========================  ================================================  ==========
``error(measure="mse")``  ``sum_i w_i (1/T) sum_k e_i[k]^2``                 ``"mean"``
``error(measure="ise")``  ``sum_i w_i dt sum_k e_i[k]^2``                    ``"mean"``
``error(measure="iae")``  ``sum_i w_i dt sum_k |e_i[k]|``                    ``"mean"``
``peak_input()``          ``max_k max_j |u_j[k]|``                          ``"max"``
``settling_time()``       ``dt k*``, ``k*`` the first sample from which     ``"mean"``
                          every ``|e_i|`` stays within ``tol max_k |e_i|``
``overshoot()``           ``max_i max_k (y_i[k] - r_i[T-1]) / r_i[T-1]``,   ``"max"``
                          clipped at 0
========================  ================================================  ==========

(sums over the chosen signals ``i``). The protocol every goal follows is in
:mod:`moo.tuning.goals`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal, cast

import numpy as np

import robustctl as rc
from robustctl.sim import OutputFeedbackSimulator
from robustctl.sim.simulator import BACKENDS, DEFAULT_BOUND, LinearSimulator
from robustctl.validation import as_float_array, check_choice, check_int, check_positive_scalar, check_real

from .goals import OVER, Goal, check_scenarios, discrete, reduce, set_fields
from .loops import Controllers, check_controllers, is_output_feedback

__all__ = ["Response", "StepTracking", "Run", "ErrorGoal", "PeakInput", "SettlingTime", "Overshoot", "MEASURES"]

#: Error measures of ``Response.error``.
MEASURES = ("mse", "ise", "iae")


def _indices(value, name: str, what: str) -> tuple[int, ...] | None:
    """``None`` or a non-empty tuple of non-negative ints (``value`` may be one int)."""
    if value is None:
        return None
    items = [value] if isinstance(value, (int, np.integer)) and not isinstance(value, bool) else value
    if not isinstance(items, Sequence | np.ndarray) or isinstance(items, (str, bytes)) or len(items) == 0:
        raise TypeError(f"{name} must be a {what} index or a non-empty list of them, got {value!r}")
    return tuple(check_int(i, f"{name}[{j}]", minimum=0) for j, i in enumerate(items))


def _check_range(idx: tuple[int, ...] | None, size: int, name: str, what: str) -> None:
    if idx is not None and max(idx) >= size:
        raise ValueError(f"{name} must be {what} indices in [0, {size}) for these plants, got {list(idx)}")


def _signals(plants) -> int:
    """The widest measured signal the goals may index: ``max(n, p)`` (state or output feedback)."""
    return max(plants[0].n, plants[0].p)


@dataclass(frozen=True, eq=False)
class Run:
    """What the time-domain goals read of a :class:`Response`'s batched run (B designs, S scenarios, T samples).

    Attributes
    ----------
    errors : (B, S, T, q) ndarray or None
        The controller's input ``e = y - r`` (``x - r`` for a state feedback),
        None when only sums were kept.
    sq_error_sum : (B, S, q) ndarray
        ``sum_k e[k]^2``.
    inputs : (B, S, T, m) ndarray or None
        Applied (saturated) inputs.
    reference : (S, T, q) ndarray
        ``r``.
    diverged : (B, S) bool ndarray
    T : int
    dt : float
    result : robustctl.sim.SimulationResult or robustctl.sim.OutputFeedbackResult
        The simulator's own result (everything it kept).
    """

    errors: np.ndarray | None
    sq_error_sum: np.ndarray
    inputs: np.ndarray | None
    reference: np.ndarray
    diverged: np.ndarray
    T: int
    dt: float
    result: Any = None

    @property
    def states(self) -> np.ndarray:
        """The plant's states ``x`` (B, S, T, n) (a run that kept its trajectories)."""
        return self.result.states

class Response:
    r"""A closed-loop response shared by the time-domain goals made from it.

    Every design runs the saturated loop of the Notes for ``steps`` samples
    on every scenario, in one batched simulation: gains ``K`` (B, m, n) with
    :class:`robustctl.sim.simulator.LinearSimulator`, an
    :class:`robustctl.ControllerBatch` of output feedbacks with
    :class:`robustctl.sim.OutputFeedbackSimulator`. The goals of
    :meth:`error`, :meth:`peak_input`, :meth:`settling_time` and
    :meth:`overshoot` read that one simulation: it is kept for the last
    ``(K, plants)`` (same plant objects, equal designs), so several goals of
    one population cost one run.

    Parameters
    ----------
    x0 : (n,) or (S, n) array_like
        Initial plant state, shared or one per scenario (a per-scenario ``x0`` or
        ``reference`` ties the goals to lists of S plants: the Monte Carlo
        selection, which evaluates goals on one plant at a time, needs shared
        ones). A controller's own state starts at 0.
    steps : int
        Number of samples ``T`` (``k = 0 .. T-1``; the horizon is ``T dt``).
    reference : (T, q) or (S, T, q) array_like, optional
        Reference ``r`` of what the controller measures: the state (``q = n``)
        for a state feedback, the outputs ``y`` (``q = p``) for an output
        feedback; default zero (regulation).
    u_limit : float or (m,) array_like, optional
        Saturation ``|u_j| <= u_limit_j``; default none.
    backend : {"numba", "numpy"}
        The compiled kernel or the numpy reference (:mod:`robustctl.sim.simulator`).
    bound : float
        Divergence bound on the states (a run beyond it is frozen there; see
        :mod:`robustctl.sim.simulator`), so a saturated loop that drifts away gets
        a large finite error.

    Raises
    ------
    TypeError, ValueError
        ``x0``, ``reference`` or ``u_limit`` not finite or of the wrong shape,
        ``steps`` not a positive integer, an unknown ``backend``; when the
        goals meet the plants (:meth:`check`), sizes that do not fit them or
        continuous-time plants.

    See Also
    --------
    ErrorGoal, PeakInput, SettlingTime, Overshoot : the goals read from a response.
    StepTracking : a response to a step of the reference.

    Notes
    -----
    From :math:`x[0] = x_0` (and :math:`x_c[0] = 0`), on every scenario,

    .. math::

        u[k] = \operatorname{sat}\big(K(z)\, (y[k] - r[k])\big), \qquad
        x[k+1] = F_s x[k] + G_s u[k], \qquad k = 0, \dots, T - 1,

    with ``y = x`` and ``K(z) = K`` for a state feedback, ``y = C x + D u``
    and ``x_c^+ = A_c x_c + B_c (y - r)``, ``u = C_c x_c + D_c (y - r)`` for
    an output feedback; the error is :math:`e = y - r` (:math:`r = 0`
    without a reference).

    Examples
    --------
    On ``x[k+1] = 0.5 x[k]`` from ``x0 = 1`` the mean squared error over
    ``T = 20`` samples is the geometric sum ``(1 - 0.25^T) / (0.75 T)``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Response
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> K = np.array([[[-0.2]]])                        # x[k+1] = 0.5 x[k]
    >>> response = Response(x0=[1.0], steps=20)
    >>> mse = response.error()(K, [plant])
    >>> np.allclose(mse, (1 - 0.25**20) / (0.75 * 20))
    True

    The same loop as a static output feedback of ``y = 2 x`` (``u = -0.1 y``):

    >>> sensor = rc.Plant([[0.7]], [[1.0]], dt=0.1, C=[[2.0]])
    >>> sof = rc.ControllerBatch(sensor, np.zeros((1, 0, 0)), np.zeros((1, 0, 1)), np.zeros((1, 1, 0)), [[[-0.1]]])
    >>> np.allclose(response.error()(sof, [sensor]), 4 * (1 - 0.25**20) / (0.75 * 20))    # y = 2 x
    True
    """

    def __init__(self, x0, steps: int, reference=None, u_limit=None,
                 backend: Literal["numba", "numpy"] = "numba", *, bound: float = DEFAULT_BOUND):
        x = as_float_array(x0, "x0")
        if x.ndim not in (1, 2) or x.size == 0 or not np.all(np.isfinite(x)):
            raise ValueError(f"x0 must be a finite (n,) or (S, n) array, got shape {x.shape}")
        self.x0 = x
        self.steps = check_int(steps, "steps")
        if reference is None:
            self.reference = None
        else:
            r = as_float_array(reference, "reference")
            if r.ndim not in (2, 3) or not np.all(np.isfinite(r)):
                raise ValueError(f"reference must be a finite (T, q) or (S, T, q) array, got shape {r.shape}")
            if r.shape[-2] != self.steps:
                raise ValueError(f"reference must have steps={self.steps} samples along axis {r.ndim - 2}, "
                                 f"got shape {r.shape}")
            self.reference = r
        if u_limit is None:
            self.u_limit = None
        else:
            lim = as_float_array(u_limit, "u_limit")
            if lim.ndim > 1 or lim.size == 0 or not np.all(np.isfinite(lim)) or np.any(lim <= 0):
                raise ValueError(f"u_limit must be a positive number or a (m,) array of them, got {u_limit!r}")
            self.u_limit = lim
        self.backend = cast(Literal["numba", "numpy"], check_choice(backend, "backend", BACKENDS))
        self.bound = check_positive_scalar(bound, "bound", allow_inf=True)
        self._sims: dict[bool, tuple[tuple[rc.Plant, ...], Any]] = {}
        self._last: tuple[tuple[rc.Plant, ...], Any, Run] | None = None
        self._keep = False      # a goal made from this response reads trajectories (not only sums)

    def _register(self, trajectories: bool) -> None:
        """A goal made from this response: keep trajectories in every run if it reads them."""
        self._keep = self._keep or trajectories

    # -- checks and simulation ----------------------------------------------------------
    def check(self, plants) -> None:
        """``ValueError`` naming ``x0``, ``reference`` or ``u_limit`` if it does not fit ``plants``.

        The reference may have ``n`` columns (a state feedback's) or the plants'
        ``p`` (an output feedback's); the controllers decide when they run.
        """
        plants = discrete(plants, "a Response", " (a response is simulated in discrete time)")
        S, n, m, p = len(plants), plants[0].n, plants[0].m, plants[0].p
        if self.x0.shape[-1] != n or (self.x0.ndim == 2 and self.x0.shape[0] != S):
            raise ValueError(f"x0 must have shape ({n},) or ({S}, {n}) (states; scenarios, states) for "
                             f"these plants, got shape {self.x0.shape}")
        r = self.reference
        if r is not None and (r.shape[-1] not in (n, p) or (r.ndim == 3 and r.shape[0] != S)):
            shapes = " or ".join(f"({self.steps}, {q}) or ({S}, {self.steps}, {q})" for q in dict.fromkeys((n, p)))
            raise ValueError(f"reference must have shape {shapes} for these plants (the states, or the outputs an "
                             f"output feedback reads), got shape {r.shape}")
        if self.u_limit is not None and self.u_limit.size not in (1, m):
            raise ValueError(f"u_limit must be a number or have {m} entries (the plants' inputs), "
                             f"got shape {self.u_limit.shape}")

    def _width(self, K: Controllers, plants: list[rc.Plant]) -> int:
        """What the controllers measure: ``n`` (state feedback) or ``p`` (output feedback); the reference must fit."""
        q = plants[0].n if not is_output_feedback(K) else K.plant.p
        if self.reference is not None and self.reference.shape[-1] != q:
            kind = "a state feedback reads the n" if not is_output_feedback(K) else "the controllers read p"
            raise ValueError(f"reference must have {q} columns ({kind}={q} signals), got shape {self.reference.shape}")
        return q

    def simulator(self, plants, output_feedback: bool = False):
        """The simulator of ``plants`` (built once per list of plant objects and kind of controller)."""
        kept = self._sims.get(output_feedback)
        if kept is not None and isinstance(plants, Sequence) and len(kept[0]) == len(plants) \
                and all(a is b for a, b in zip(kept[0], plants, strict=True)):
            return kept[1]                        # the same plant objects: checked when the simulator was built
        key = tuple(check_scenarios(plants))
        self.check(key)
        n = key[0].n
        if output_feedback:
            sim: Any = OutputFeedbackSimulator(key, self.steps, x0=self.x0, reference=self.reference,
                                               u_limit=self.u_limit, bound=self.bound)
        else:
            F, G = np.stack([p.F for p in key]), np.stack([p.G for p in key])
            ref = np.zeros((self.steps, n)) if self.reference is None else self.reference
            sim = LinearSimulator(F, G, ref, x0=self.x0 - ref[..., 0, :], u_limit=self.u_limit, bound=self.bound,
                                  dt=key[0].dt)
        self._sims[output_feedback] = (key, sim)
        return sim

    def simulate(self, K, plants, *, trajectories: bool = True) -> Run:
        """The batched run of the designs ``K`` on ``plants`` (kept for the next call with the same ones).

        ``K``: gains (B, m, n) or a :class:`robustctl.ControllerBatch`.
        ``trajectories=False`` keeps only the squared-error sums of a state
        feedback's run (enough for MSE and ISE) unless a goal made from this
        response reads trajectories (so the goals of one population share one
        run); an output feedback's run always has them.
        """
        trajectories = trajectories or self._keep
        plants = check_scenarios(plants)
        output = is_output_feedback(K)
        if not output:
            K = check_controllers(K, plants)
        q = self._width(K, plants)
        sim = self.simulator(plants, output)
        key = self._sims[output][0]
        last = self._last
        if last is not None and last[0] is key and _same_designs(last[1], K) \
                and (last[2].errors is not None or not trajectories):
            return last[2]
        S, T = len(key), self.steps
        ref = np.zeros((S, T, q)) if self.reference is None else np.broadcast_to(self.reference, (S, T, q))
        if output:
            res = sim.run(K, backend=self.backend)
            errors = res.errors
            run = Run(errors=errors, sq_error_sum=(errors * errors).sum(axis=2), inputs=res.inputs, reference=ref,
                      diverged=res.diverged, T=T, dt=res.dt, result=res)
        else:
            r = sim.run(K, keep_trajectories=trajectories, backend=self.backend)
            run = Run(errors=r.errors, sq_error_sum=r.sq_error_sum, inputs=r.inputs, reference=ref,
                      diverged=r.diverged, T=T, dt=float(key[0].dt or 0.0), result=r)
        self._last = (key, K, run)
        return run

    # -- goals -------------------------------------------------------------------------
    def error(self, states=None, measure: str = "mse", *, weights=None, over: str = "mean",
              name: str | None = None) -> ErrorGoal:
        """The error goal (MSE, ISE or IAE of ``e = y - r`` summed over ``states``); see :class:`ErrorGoal`."""
        return ErrorGoal(self, states, measure, weights=weights, over=over, name=name)

    def peak_input(self, inputs=None, *, over: str = "max", name: str | None = None) -> PeakInput:
        """The largest applied ``|u_j|`` (``inputs``: default all); see :class:`PeakInput`."""
        return PeakInput(self, inputs, over=over, name=name)

    def settling_time(self, states=None, tol: float = 0.02, *, over: str = "mean",
                      name: str | None = None) -> SettlingTime:
        """The settling time of ``states`` into ``tol`` of their peak; see :class:`SettlingTime`."""
        return SettlingTime(self, states, tol, over=over, name=name)

    def overshoot(self, states=None, *, over: str = "max", name: str | None = None) -> Overshoot:
        """The overshoot of ``states`` beyond their final reference; see :class:`Overshoot`."""
        return Overshoot(self, states, over=over, name=name)

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(x0 shape {self.x0.shape}, steps={self.steps}, "
                f"reference={'none' if self.reference is None else self.reference.shape}, "
                f"u_limit={None if self.u_limit is None else self.u_limit.tolist()})")


def _same_designs(a, b) -> bool:
    """The same designs: the same batch object, or equal gain stacks."""
    if is_output_feedback(a) or is_output_feedback(b):
        return a is b
    return a.shape == b.shape and np.array_equal(a, b)


class StepTracking(Response):
    r"""The response to a step of the reference: a :class:`Response` with ``r_j[k] = amplitude`` from ``k = 0``.

    The goals of a step response (:meth:`~Response.error`,
    :meth:`~Response.overshoot`, :meth:`~Response.settling_time`,
    :meth:`~Response.peak_input`) are made from it; the system starts at rest
    (``x0 = 0``, ``x_c = 0``) unless ``x0`` is given.

    Parameters
    ----------
    steps : int
        Number of samples ``T``.
    signal : int
        The measured signal that steps (an output ``y_j``, or a state for a
        state feedback); the others keep ``r = 0``.
    amplitude : float
        The step's size (non-zero).
    width : int
        The number of measured signals ``q`` (the plant's ``p``, or ``n`` for
        a state feedback).
    x0 : (n,) array_like, optional
        Initial plant state (default zero; needs ``n``).
    n : int, optional
        Number of plant states (for the default ``x0``; default ``width``).
    u_limit, backend, bound
        As in :class:`Response`.

    Raises
    ------
    ValueError
        ``signal`` out of range, a zero ``amplitude``, sizes that do not fit.

    See Also
    --------
    Response, Overshoot, SettlingTime

    Examples
    --------
    A unit step of ``y`` of ``x+ = 0.5 x + u`` under the integral controller
    ``K(z) = -0.25 / (z - 1)``; its overshoot is that of python-control's
    step response of the same loop:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import StepTracking
    >>> plant = rc.Plant([[0.5]], [[1.0]], 1.0, C=[[1.0]])
    >>> batch = rc.ControllerBatch(plant, [[[1.0]]], [[[-0.25]]], [[[1.0]]], [[[0.0]]])
    >>> step = StepTracking(60, signal=0, amplitude=1.0, width=1)
    >>> loop = control.feedback(plant.to_statespace() * control.tf([0.25], [1, -1], 1.0))
    >>> _, y = control.step_response(loop, np.arange(60.0))
    >>> bool(np.allclose(step.overshoot()(batch, [plant]), y.max() - 1.0))
    True
    """

    def __init__(self, steps: int, signal: int = 0, amplitude: float = 1.0, *, width: int, x0=None,
                 n: int | None = None, u_limit=None, backend: Literal["numba", "numpy"] = "numba",
                 bound: float = DEFAULT_BOUND):
        T, q = check_int(steps, "steps"), check_int(width, "width")
        j = check_int(signal, "signal", 0)
        if j >= q:
            raise ValueError(f"signal must be in [0, {q}) (width={q} measured signals), got {j}")
        a = check_real(amplitude, "amplitude")
        if a == 0:
            raise ValueError("amplitude must be non-zero (a step)")
        r = np.zeros((T, q))
        r[:, j] = a
        x0 = np.zeros(check_int(n, "n") if n is not None else q) if x0 is None else x0
        super().__init__(x0, T, reference=r, u_limit=u_limit, backend=backend, bound=bound)
        self.signal, self.amplitude = j, a


def _state_names(idx: tuple[int, ...] | None) -> str:
    return "x" if idx is None else ",".join(f"x{i}" for i in idx)


@dataclass(frozen=True, eq=False, repr=False)
class ErrorGoal(Goal):
    r"""Error of chosen states along a :class:`Response`: MSE, ISE or IAE, summed over the states.

    Made by :meth:`Response.error`. A run that diverges (a saturated loop
    drifting away) is held at the divergence bound, hence a large finite
    error.

    Parameters
    ----------
    response : Response
        The simulation the goal reads.
    states : int or sequence of int, optional
        State indices (default all).
    measure : {"mse", "ise", "iae"}
        The error measure (Notes).
    weights : (len(states),) array_like, optional
        Non-negative weights of the states (e.g. to mix units).
    over : {"mean", "max"}
        Reduction over the scenarios (default the mean).
    name : str, optional
        Label for tables and plots (default e.g. ``"mse(x)"``).

    Raises
    ------
    TypeError, ValueError
        ``response`` not a :class:`Response`, an unknown ``measure`` or
        ``over``, ``weights`` negative or of the wrong length; state indices
        out of range for the plants (when checked).

    See Also
    --------
    Response, PeakInput, SettlingTime

    Notes
    -----
    Per design and scenario, with :math:`e = x - r`, the chosen states
    :math:`i` and weights :math:`w_i` (default 1),

    .. math::

        \text{mse} = \sum_i w_i \frac{1}{T} \sum_{k=0}^{T-1} e_i[k]^2, \qquad
        \text{ise} = \sum_i w_i\, \Delta t \sum_{k=0}^{T-1} e_i[k]^2, \qquad
        \text{iae} = \sum_i w_i\, \Delta t \sum_{k=0}^{T-1} |e_i[k]|,

    then the mean (default) or the max over the scenarios.

    Examples
    --------
    On ``x[k+1] = 0.5 x[k]`` from ``x0 = 1`` (``dt = 0.1``) the integral of
    the absolute error is ``dt (1 - 0.5^T) / 0.5``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Response
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> K = np.array([[[-0.2]]])                        # x[k+1] = 0.5 x[k]
    >>> response = Response(x0=[1.0], steps=20)
    >>> iae = response.error(measure="iae")
    >>> iae
    ErrorGoal(name='iae(x)', over='mean')
    >>> np.allclose(iae(K, [plant]), 0.1 * (1 - 0.5**20) / 0.5)
    True
    """

    response: Response
    states: Any = None
    measure_name: str = "mse"
    weights: Any = None
    over: str = "mean"
    name: str = ""

    def __init__(self, response: Response, states=None, measure: str = "mse", *, weights=None,
                 over: str = "mean", name: str | None = None):
        if not isinstance(response, Response):
            raise TypeError(f"response must be a moo.tuning Response, got {type(response).__name__}")
        idx = _indices(states, "states", "state")
        measure = check_choice(measure, "measure", MEASURES)
        w = None
        if weights is not None:
            w = as_float_array(weights, "weights")
            size = "the chosen states" if idx is None else len(idx)
            if w.ndim != 1 or (idx is not None and w.size != len(idx)) or not np.all(np.isfinite(w)) \
                    or np.any(w < 0):
                raise ValueError(f"weights must be {size} finite non-negative numbers, got {weights!r}")
        response._register(measure == "iae")
        set_fields(self, response=response, states=idx, measure_name=measure, weights=w,
             over=check_choice(over, "over", OVER),
             name=name if name is not None else f"{measure}({_state_names(idx)})")

    def check(self, plants) -> None:
        """``ValueError`` if ``states``, ``weights`` or the response's arguments do not fit ``plants``."""
        self.response.check(plants)
        _check_range(self.states, _signals(plants), "states", "measured signal")

    def measure(self, K, plants) -> np.ndarray:
        """The error of each design, shape (B,)."""
        self.check(plants)
        res = self.response.simulate(K, plants, trajectories=self.measure_name == "iae")
        q = res.sq_error_sum.shape[-1]
        _check_range(self.states, q, "states", "measured signal")
        idx = list(range(q)) if self.states is None else list(self.states)
        if self.weights is not None and self.weights.size != len(idx):
            raise ValueError(f"weights must have {len(idx)} entries (one per measured signal), got {self.weights.size}")
        if self.measure_name == "iae":
            assert res.errors is not None
            per_state = np.abs(res.errors[..., idx]).sum(axis=2) * res.dt
        else:
            per_state = res.sq_error_sum[..., idx] * (1.0 / res.T if self.measure_name == "mse" else res.dt)
        w = np.ones(len(idx)) if self.weights is None else self.weights
        return reduce(per_state @ w, self.over)


@dataclass(frozen=True, eq=False, repr=False)
class PeakInput(Goal):
    r"""The largest applied (saturated) input ``max_k max_j |u_j[k]|`` along a :class:`Response`.

    Made by :meth:`Response.peak_input`; a natural constraint
    (``at_most(response.peak_input(), u_max)``).

    Parameters
    ----------
    response : Response
        The simulation the goal reads.
    inputs : int or sequence of int, optional
        Input indices (default all).
    over : {"mean", "max"}
        Default ``"max"``: the worst scenario (an actuator limit).
    name : str, optional
        Label for tables and plots (default e.g. ``"peak |u|"``).

    Raises
    ------
    TypeError, ValueError
        ``response`` not a :class:`Response`, an unknown ``over``; input
        indices out of range for the plants (when checked).

    See Also
    --------
    Response, ErrorGoal, SettlingTime

    Notes
    -----
    Per design and scenario :math:`\max_{k} \max_{j} |u_j[k]|` over the
    chosen inputs :math:`j`, then the max (default) or mean over the scenarios.

    Examples
    --------
    With ``u[k] = -0.2 x[k]`` and ``x[k] = 0.5^k`` the peak is the first
    input, ``0.2``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Response
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> K = np.array([[[-0.2]]])                        # x[k+1] = 0.5 x[k]
    >>> response = Response(x0=[1.0], steps=20)
    >>> response.peak_input()(K, [plant])
    array([0.2])
    """

    response: Response
    inputs: Any = None
    over: str = "max"
    name: str = ""

    def __init__(self, response: Response, inputs=None, *, over: str = "max", name: str | None = None):
        if not isinstance(response, Response):
            raise TypeError(f"response must be a moo.tuning Response, got {type(response).__name__}")
        idx = _indices(inputs, "inputs", "input")
        label = "u" if idx is None else ",".join(f"u{i}" for i in idx)
        response._register(True)
        set_fields(self, response=response, inputs=idx, over=check_choice(over, "over", OVER),
             name=name if name is not None else f"peak |{label}|")

    def check(self, plants) -> None:
        """``ValueError`` if ``inputs`` or the response's arguments do not fit ``plants``."""
        self.response.check(plants)
        _check_range(self.inputs, plants[0].m, "inputs", "input")

    def measure(self, K, plants) -> np.ndarray:
        """The peak input of each design, shape (B,)."""
        self.check(plants)
        res = self.response.simulate(K, plants, trajectories=True)
        assert res.inputs is not None
        u = res.inputs if self.inputs is None else res.inputs[..., list(self.inputs)]
        return reduce(np.abs(u).max(axis=(2, 3)), self.over)


@dataclass(frozen=True, eq=False, repr=False)
class SettlingTime(Goal):
    r"""Settling time of chosen states along a :class:`Response`.

    Made by :meth:`Response.settling_time`. For each state ``i`` the band is
    ``tol`` times the state's peak error ``max_k |e_i[k]|`` on that run; the
    settling time is ``dt k*``, ``k*`` the first sample from which every
    chosen ``|e_i[k]|`` stays within its band (0 if it never leaves it; the
    horizon ``T dt`` if it is still outside at the last sample, and for a
    diverged run). Then the mean (default) or the max over the scenarios.

    Parameters
    ----------
    response : Response
        The simulation the goal reads.
    states : int or sequence of int, optional
        State indices (default all).
    tol : float
        Relative band, in (0, 1).
    over : {"mean", "max"}
        Reduction over the scenarios (default the mean).
    name : str, optional
        Label for tables and plots (default e.g. ``"settling time(x)"``).

    Raises
    ------
    TypeError, ValueError
        ``response`` not a :class:`Response`, ``tol`` outside (0, 1), an
        unknown ``over``; state indices out of range for the plants (when
        checked).

    See Also
    --------
    Response, ErrorGoal, PeakInput

    Notes
    -----
    .. math::

        k^* = \min\big\{k : |e_i[j]| \le \text{tol} \max_{l} |e_i[l]|
        \ \text{for all chosen } i \text{ and all } j \ge k\big\}, \qquad
        t_s = k^*\, \Delta t.

    Examples
    --------
    ``|e[k]| = 0.5^k`` first stays within 2 % of its peak 1 at ``k = 6``
    (``0.5^5 = 0.031``, ``0.5^6 = 0.016``), so with ``dt = 0.1``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Response
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> K = np.array([[[-0.2]]])                        # x[k+1] = 0.5 x[k]
    >>> response = Response(x0=[1.0], steps=20)
    >>> response.settling_time(tol=0.02)(K, [plant])
    array([0.6])
    """

    response: Response
    states: Any = None
    tol: float = 0.02
    over: str = "mean"
    name: str = ""

    def __init__(self, response: Response, states=None, tol: float = 0.02, *, over: str = "mean",
                 name: str | None = None):
        if not isinstance(response, Response):
            raise TypeError(f"response must be a moo.tuning Response, got {type(response).__name__}")
        idx = _indices(states, "states", "state")
        tol = check_positive_scalar(tol, "tol")
        if tol >= 1:
            raise ValueError(f"tol must be in (0, 1) (a fraction of the peak error), got {tol}")
        response._register(True)
        set_fields(self, response=response, states=idx, tol=tol, over=check_choice(over, "over", OVER),
             name=name if name is not None else f"settling time({_state_names(idx)})")

    def check(self, plants) -> None:
        """``ValueError`` if ``states`` or the response's arguments do not fit ``plants``."""
        self.response.check(plants)
        _check_range(self.states, _signals(plants), "states", "measured signal")

    def measure(self, K, plants) -> np.ndarray:
        """The settling time of each design in seconds, shape (B,)."""
        self.check(plants)
        res = self.response.simulate(K, plants, trajectories=True)
        assert res.errors is not None
        _check_range(self.states, res.errors.shape[-1], "states", "measured signal")
        e = np.abs(res.errors if self.states is None else res.errors[..., list(self.states)])   # (B, S, T, q)
        outside = (e > self.tol * e.max(axis=2, keepdims=True)).any(axis=3)                     # (B, S, T)
        T = outside.shape[2]
        last = T - 1 - np.argmax(outside[..., ::-1], axis=2)                                    # last sample outside
        k_star = np.where(outside.any(axis=2), last + 1, 0)
        k_star = np.where(res.diverged, T, k_star)
        return reduce(k_star * res.dt, self.over)


@dataclass(frozen=True, eq=False, repr=False)
class Overshoot(Goal):
    r"""Overshoot of chosen signals beyond their final reference, relative to it, along a :class:`Response`.

    Made by :meth:`Response.overshoot` (e.g. of a :class:`StepTracking`).
    For each chosen signal ``i`` with the final reference ``r_i = r_i[T-1]``
    (non-zero), ``max_k (y_i[k] - r_i) / r_i`` clipped at 0: ``0.1`` is 10 %
    overshoot (the same on the negative side for a negative reference). A
    diverged run is held at the divergence bound (a large, finite
    overshoot). The max over the signals, then over the scenarios (default)
    or their mean.

    Parameters
    ----------
    response : Response
        The simulation the goal reads (it needs a reference).
    states : int or sequence of int, optional
        Measured signals (default: every signal with a non-zero final reference).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label (default ``"overshoot"``).

    Raises
    ------
    TypeError, ValueError
        ``response`` not a :class:`Response` or without a reference; a chosen
        signal whose final reference is zero (when checked).

    See Also
    --------
    StepTracking, SettlingTime

    Notes
    -----
    .. math::

        \text{overshoot} = \max_i \max\Big(0,\ \max_k \frac{y_i[k] - r_i[T-1]}{r_i[T-1]}\Big).

    Examples
    --------
    ``y[k] = 1 - (-0.5)^k`` on a unit step overshoots by 50 % at ``k = 1``:
    the static output feedback ``u = -1.5 (y - 1)`` of ``x+ = x + u``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import StepTracking
    >>> plant = rc.Plant([[1.0]], [[1.0]], 0.1, C=[[1.0]])
    >>> K = rc.ControllerBatch(plant, np.zeros((1, 0, 0)), np.zeros((1, 0, 1)), np.zeros((1, 1, 0)), [[[-1.5]]])
    >>> StepTracking(20, width=1).overshoot()(K, [plant])
    array([0.5])
    """

    response: Response
    states: Any = None
    over: str = "max"
    name: str = ""

    def __init__(self, response: Response, states=None, *, over: str = "max", name: str | None = None):
        if not isinstance(response, Response):
            raise TypeError(f"response must be a moo.tuning Response, got {type(response).__name__}")
        if response.reference is None:
            raise ValueError("response must have a reference (an overshoot is measured beyond it)")
        response._register(True)
        set_fields(self, response=response, states=_indices(states, "states", "measured signal"),
             over=check_choice(over, "over", OVER), name=name if name is not None else "overshoot")

    def check(self, plants) -> None:
        """``ValueError`` if ``states`` or the response's arguments do not fit ``plants``."""
        self.response.check(plants)
        _check_range(self.states, _signals(plants), "states", "measured signal")

    def measure(self, K, plants) -> np.ndarray:
        """The relative overshoot of each design, shape (B,)."""
        self.check(plants)
        res = self.response.simulate(K, plants, trajectories=True)
        assert res.errors is not None
        final = res.reference[:, -1, :]                                                 # (S, q)
        idx = np.flatnonzero(np.any(final != 0, axis=0)) if self.states is None else np.array(self.states)
        _check_range(tuple(int(i) for i in idx) or None, final.shape[-1], "states", "measured signal")
        if idx.size == 0 or np.any(final[:, idx] == 0):
            raise ValueError("states: an overshoot needs a non-zero final reference of every chosen signal")
        y = res.errors[..., idx] + res.reference[None, :, :, idx]                       # (B, S, T, q')
        rel = ((y - final[None, :, None, idx]) / final[None, :, None, idx]).max(axis=2)  # (B, S, q')
        return reduce(np.maximum(rel.max(axis=2), 0.0), self.over)
