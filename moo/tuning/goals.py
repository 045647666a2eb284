r"""Tuning goals: objectives and constraints on a population's closed loops over a set of plants.

A goal is any callable ``goal(K, plants) -> (B,)`` float array: ``K`` holds
B designs that stabilise every scenario - the gains (B, m, n) of state
feedbacks ``u = K x``, or an :class:`robustctl.ControllerBatch` of dynamic
output feedbacks ``u = K(z) y`` - and ``plants`` is the scenario tuple
(:class:`robustctl.Plant`, one ``n``, ``m`` and ``dt``; with an output
feedback each carries the output model the controllers read). Smaller is
better; a constraint holds where its value is ``<= 0``. The goals of this
module take either kind of ``K``; they are small frozen classes, each
batched over the B designs and the S scenarios (the closed loops of
:mod:`moo.tuning.loops` in the states ``(x, x_c)``, one compiled
simulation), each reducing the scenarios with ``over="mean"`` or ``"max"``,
and each with

* ``name`` - a label for tables and plots (``name=`` overrides it);
* ``check(plants)`` - the goal's arguments against the plants (index out of
  range, reference of the wrong shape, ``Bw`` with other than ``n`` rows, a
  continuous plant for a goal that samples ...), a ``ValueError`` naming the
  argument; the tuning problem calls it once, and every call repeats it
  (cheap) so a goal is safe on its own;
* ``measure(K, plants)`` - the goal's quantity in its own sense, to which the
  bounds of :func:`at_most` and :func:`at_least` refer. It equals the goal's
  value except for the margins (:class:`RobustMargin`,
  :class:`~moo.tuning.DiskMargin`), quantities to *maximise* that are
  minimised as ``1 / margin``.

Time domain (one simulation per population, shared; :class:`Response`,
:class:`StepTracking`; discrete plants): from ``x[0] = x0`` (and
``x_c = 0``) every design runs ``u[k] = sat(K(z) (y[k] - r[k]))``,
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

(sums over the chosen signals ``i``). Closed loop ``A_cl`` (``F + G K`` for a
state feedback; per scenario, ``over="max"``):

* :class:`SpectralRadius` - ``max |eig(A_cl)|`` (discrete plants);
* :class:`PoleRegion` - ``max_z lambda_max(L + M z + M' conj(z))`` over the
  poles ``z`` and the regions' characteristic matrices (Chilali & Gahinet
  1996): ``<= 0`` with every pole inside; for a :class:`robustctl.Disk` it is
  ``max |z - c| - r``, the distance of the farthest pole beyond the circle;
* :class:`ControllerPoles` - the controller's own poles (``max |eig(A_c)|``
  or a region's violation);
* :class:`H2Norm` - ``||T_zw||_2 = sqrt(trace(C_K P C_K'))`` of
  ``xi+ = A_cl xi + B_a w``, ``z = C_K xi``, ``C_K = [Cz 0] + Dzu K_u``, with the
  controllability Gramian ``P = A_cl P A_cl' + B_a B_a'`` (:func:`gramians`:
  the squared Smith iteration, Smith 1968; continuous plants through the
  Cayley transform);
* :class:`Variance` - the stationary variance of ``z`` under process noise
  and measurement noise (the same Gramians);
* :class:`HinfNorm` - ``||C_K (zI - A_cl)^-1 B_a||_inf``, as ``1 / margin`` of
  :func:`robustctl.robust_stability` with ``NormBounded(Bw, Cz, Dzu)`` (the
  small-gain value: one norm implementation in the project).

Robustness: :class:`RobustMargin` - the certified margin of
:func:`robustctl.robust_stability` against a :class:`robustctl.NormBounded`
uncertainty about a nominal plant, ``1 / ||E (zI - A)^-1 H||_inf`` with
``A = F + G K``, ``E = EF + EG K`` (the augmented loop for a dynamic
controller); ``at_least(RobustMargin(unc), 1.0)`` is "certified for every
``||Delta|| <= 1``". The loop margins (disk, gain and phase margins,
sensitivity peaks) are in :mod:`moo.tuning.margins`.

References
----------
P. Apkarian, D. Noll, "Nonsmooth H-infinity synthesis", IEEE TAC 51(1), 2006,
and MATLAB's ``systune`` / ``TuningGoal`` objects (goals as objects; soft goals
and hard constraints over an array of plants).
M. Chilali, P. Gahinet, "H-infinity design with pole placement constraints: an
LMI approach", IEEE TAC 41(3), 1996.
K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*, Prentice Hall
1996, Ch. 4 (H2 and H-infinity norms, Gramians).
R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math. 16(1), 1968.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, cast

import numpy as np

import robustctl as rc
from robustctl.sim import OutputFeedbackSimulator
from robustctl.sim.simulator import BACKENDS, DEFAULT_BOUND, LinearSimulator
from robustctl.systems.regions import Region, as_regions
from robustctl.validation import (
    as_float_array,
    as_matrix,
    check_choice,
    check_int,
    check_plants,
    check_positive_scalar,
    check_real,
)

from .loops import Controllers, Loops, check_controllers, closed_loops, count, is_output_feedback, with_outputs

__all__ = ["Goal", "Response", "StepTracking", "Run", "ErrorGoal", "PeakInput", "SettlingTime", "Overshoot",
           "SpectralRadius", "PoleRegion", "ControllerPoles", "H2Norm", "HinfNorm", "Variance", "RobustMargin",
           "Bound", "at_most", "at_least", "check_scenarios", "gramians", "OVER", "MEASURES"]

#: Reductions over the scenarios a goal accepts as ``over``.
OVER = ("mean", "max")
#: Error measures of ``Response.error``.
MEASURES = ("mse", "ise", "iae")
# Squared Smith iteration: relative size of the last increment, and the most doublings
# (A^(2^64) of a stable A is zero unless its spectral radius is within ~1e-17 of 1).
_SMITH_RTOL = 1e-16
_SMITH_MAX = 64


# ---------------------------------------------------------------- shared checks
def check_scenarios(plants, name: str = "plants", *, continuous: bool = False) -> list[rc.Plant]:
    """``plants`` as a non-empty list of plants of one ``n``, ``m`` and ``dt``, discrete unless ``continuous``.

    :func:`robustctl.validation.check_plants`, with messages naming ``name[i]``;
    ``continuous=True`` accepts continuous-time plants too (all of one domain).
    """
    return check_plants(plants, name, discrete_for=None if continuous else "tuning")


def _loops(K, plants) -> tuple[Controllers, list[rc.Plant], Loops]:
    """The checked controllers, the plants (either domain) and their closed loops (:mod:`moo.tuning.loops`)."""
    plants = check_scenarios(plants, continuous=True)
    K = check_controllers(K, plants)
    return K, plants, closed_loops(K, plants)


def _with_outputs(plant: rc.Plant, K: Controllers) -> rc.Plant:
    """``plant`` with the output model the controllers read (an output feedback's batch plant's, if it has none)."""
    return with_outputs(plant, K.plant) if is_output_feedback(K) else plant


def _discrete(plants, what: str, hint: str = "") -> list[rc.Plant]:
    """The plants, refused by name if continuous (goals that sample)."""
    plants = check_scenarios(plants, continuous=True)
    if not plants[0].is_discrete:
        raise ValueError(f"{what} needs discrete-time plants; these are continuous{hint}")
    return plants


def _reduce(values: np.ndarray, over: str) -> np.ndarray:
    """(B, S) -> (B,) by the mean or the max over the scenarios."""
    return values.mean(axis=1) if over == "mean" else values.max(axis=1)


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


def _matrix(value, name: str, vector: str) -> np.ndarray:
    """A finite non-empty 2-D float array, read-only (a 1-D array is a ``vector``: "column" or "row")."""
    arr = as_matrix(value, name, vector=vector)
    arr.flags.writeable = False
    return arr


def _robust_margins(plant: rc.Plant, K: Controllers, unc: rc.NormBounded) -> np.ndarray:
    """``robust_stability`` margins of each design on ``plant``, shape (B,).

    ``K``: gains (B, m, n) (``(plant, K)``) or a :class:`robustctl.ControllerBatch`
    (its loops through ``plant``'s outputs, the augmented uncertainty). One
    batched call of :func:`robustctl.robust_stability` (margins only: the
    certificates of a stack are computed on request). Unstable loops get 0,
    a design the analysis cannot answer NaN (the tuning problem penalises it).
    """
    if is_output_feedback(K):
        loop: Any = rc.ControllerBatch(_with_outputs(plant, K), K.Ac, K.Bc, K.Cc, K.Dc)
        return np.array(rc.robust_stability(loop, unc).margin, dtype=float)
    return np.array(rc.robust_stability((plant, np.asarray(K)), unc).margin, dtype=float)


# ---------------------------------------------------------------- base
class Goal:
    """Base of the goals of this module (see the module docstring for the protocol).

    Subclasses define ``name``, ``check(plants)`` and ``measure(K, plants)``;
    calling a goal returns its measure (the value to minimise). A goal need
    not derive from this class: any callable ``f(K, plants) -> (B,)`` is a
    goal for :class:`~moo.tuning.TuningProblem`. Deriving gives a ``check``
    the problem calls once, and a ``measure`` that :func:`at_most` and
    :func:`at_least` bound.

    See Also
    --------
    SpectralRadius, Response, H2Norm, RobustMargin : goals of this module.
    at_most, at_least : constraints from a goal.

    Examples
    --------
    The Frobenius norm of the gain as a goal:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Goal
    >>> class GainNorm(Goal):
    ...     name = "gain norm"
    ...
    ...     def check(self, plants):
    ...         pass
    ...
    ...     def measure(self, K, plants):
    ...         return np.linalg.norm(K, axis=(1, 2))
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> GainNorm()(np.array([[[3.0, 4.0]]]), [plant])
    array([5.])
    """

    name: str

    def check(self, plants) -> None:  # pragma: no cover - every goal defines it
        """``ValueError`` naming the argument that does not fit ``plants``."""
        raise NotImplementedError

    def measure(self, K, plants) -> np.ndarray:  # pragma: no cover
        """The goal's quantity per design, shape (B,)."""
        raise NotImplementedError

    def __call__(self, K, plants) -> np.ndarray:
        """The value to minimise for each design, shape (B,) (the measure)."""
        return self.measure(K, plants)

    def __repr__(self) -> str:
        over = getattr(self, "over", None)
        return f"{type(self).__name__}(name={self.name!r}" + (f", over={over!r})" if over else ")")


def _set(obj, **values) -> None:
    for k, v in values.items():
        object.__setattr__(obj, k, v)


# ---------------------------------------------------------------- time domain
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
        plants = _discrete(plants, "a Response", " (a response is simulated in discrete time)")
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
        _set(self, response=response, states=idx, measure_name=measure, weights=w,
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
        return _reduce(per_state @ w, self.over)


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
        _set(self, response=response, inputs=idx, over=check_choice(over, "over", OVER),
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
        return _reduce(np.abs(u).max(axis=(2, 3)), self.over)


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
        _set(self, response=response, states=idx, tol=tol, over=check_choice(over, "over", OVER),
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
        return _reduce(k_star * res.dt, self.over)


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
        _set(self, response=response, states=_indices(states, "states", "measured signal"),
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
        return _reduce(np.maximum(rel.max(axis=2), 0.0), self.over)


def _signals(plants) -> int:
    """The widest measured signal the goals may index: ``max(n, p)`` (state or output feedback)."""
    return max(plants[0].n, plants[0].p)


# ---------------------------------------------------------------- closed loop
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
        _discrete(plants, "SpectralRadius", " (use PoleRegion(rc.HalfPlane(...)) for a continuous loop)")

    def measure(self, K, plants) -> np.ndarray:
        """The spectral radius of each design, shape (B,)."""
        self.check(plants)
        _, _, loops = _loops(K, plants)
        return _reduce(np.asarray(rc.spectral_radius(loops.A)), self.over)


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
        _set(self, region=regions, over=check_choice(self.over, "over", OVER),
             name=self.name or "pole region")

    def check(self, plants) -> None:
        """Only the plants themselves are checked (either time domain: the regions are in its plane)."""
        check_scenarios(plants, continuous=True)

    def measure(self, K, plants) -> np.ndarray:
        """The largest violation of each design, shape (B,)."""
        _, _, loops = _loops(K, plants)
        return _reduce(_region_violation(np.linalg.eigvals(loops.A), self.region), self.over)


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
        _set(self, region=regions, name=self.name or "controller poles")

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


@dataclass(frozen=True, eq=False, repr=False)
class _Channel(Goal):
    """A performance channel ``x+ = A x + Bw w``, ``z = (Cz + Dzu K) x`` of the closed loop."""

    Bw: Any
    Cz: Any
    Dzu: Any = None
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        Bw, Cz = _matrix(self.Bw, "Bw", "column"), _matrix(self.Cz, "Cz", "row")
        Dzu = None if self.Dzu is None else _matrix(self.Dzu, "Dzu", "row")
        if Dzu is not None and Dzu.shape[0] != Cz.shape[0]:
            raise ValueError(f"Dzu must have {Cz.shape[0]} rows (the rows of Cz), got shape {Dzu.shape}")
        _set(self, Bw=Bw, Cz=Cz, Dzu=Dzu, over=check_choice(self.over, "over", OVER),
             name=self.name or self._default_name)

    _default_name = ""

    def check(self, plants) -> None:
        """``ValueError`` naming ``Bw``, ``Cz`` or ``Dzu`` if its size does not fit ``plants``."""
        plants = check_scenarios(plants, continuous=True)
        n, m = plants[0].n, plants[0].m
        if self.Bw.shape[0] != n:
            raise ValueError(f"Bw must have {n} rows (the number of states of the plants), got shape {self.Bw.shape}")
        if self.Cz.shape[1] != n:
            raise ValueError(f"Cz must have {n} columns (the number of states of the plants), "
                             f"got shape {self.Cz.shape}")
        if self.Dzu is not None and self.Dzu.shape[1] != m:
            raise ValueError(f"Dzu must have {m} columns (the number of inputs of the plants), "
                             f"got shape {self.Dzu.shape}")

    def _channel(self, loops: Loops) -> tuple[np.ndarray, np.ndarray]:
        """``(B_a (N, q), C_K (B, S, l, N))``: ``w`` enters the plant states, ``z = [C_z 0] + D_zu K_u``."""
        N = loops.A.shape[-1]
        Ba = np.zeros((N, self.Bw.shape[1]))
        Ba[:loops.n] = self.Bw
        Ca = np.zeros((self.Cz.shape[0], N))
        Ca[:, :loops.n] = self.Cz
        C = np.broadcast_to(Ca, (*loops.A.shape[:2], *Ca.shape))
        return Ba, (C if self.Dzu is None else C + self.Dzu @ loops.Ku)


@dataclass(frozen=True, eq=False, repr=False)
class H2Norm(_Channel):
    r"""H2 norm of the channel ``w -> z = Cz x + Dzu u`` of the closed loop ``x+ = (F + G K) x + Bw w``.

    With white ``w`` of unit intensity its square is the steady-state
    variance of ``z``. The max (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Disturbance input matrix.
    Cz : (l, n) array_like (1-D: one row)
        Performance output matrix.
    Dzu : (l, m) array_like, optional
        Feedthrough of the input to the performance output (default none).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label for tables and plots (default ``"H2 norm"``).

    Raises
    ------
    ValueError
        ``Bw``, ``Cz`` or ``Dzu`` not finite or of sizes that do not fit each
        other or the plants (the message names the matrix and the shapes).

    See Also
    --------
    HinfNorm : the worst-case gain of the same channel.
    robustctl.h2 : H2-optimal synthesis.

    Notes
    -----
    .. math::

        \|T_{zw}\|_2^2 = \operatorname{trace}(C_K P C_K^T), \qquad
        C_K = C_z + D_{zu} K, \qquad P = A P A^T + B_w B_w^T, \qquad A = F + G K,

    the controllability Gramian :math:`P` computed by the batched squared
    Smith iteration [1]_ (:math:`P \leftarrow P + A_j P A_j^T`,
    :math:`A_j \leftarrow A_j^2`); a loop where it does not settle gets ``inf``.

    References
    ----------
    .. [1] R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math.
       16(1), 198-201, 1968.
    .. [2] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4.

    Examples
    --------
    Against the Gramian of :func:`scipy.linalg.solve_discrete_lyapunov`:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from scipy.linalg import solve_discrete_lyapunov
    >>> from moo.tuning import H2Norm
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> goal = H2Norm(Bw=[[0.0], [1.0]], Cz=[[1.0, 0.0]])
    >>> P = solve_discrete_lyapunov(plant.F + plant.G @ K[0], np.diag([0.0, 1.0]))
    >>> np.allclose(goal(K, [plant]), np.sqrt(P[0, 0]))
    True
    """

    _default_name = "H2 norm"

    def measure(self, K, plants) -> np.ndarray:
        """The H2 norm of each design, shape (B,)."""
        self.check(plants)
        _, _, loops = _loops(K, plants)
        Ba, C = self._channel(loops)
        P, done = gramians(loops.A, Ba @ Ba.T, discrete=loops.discrete)
        value = np.sqrt(np.maximum(np.einsum("bsln,bsnk,bslk->bs", C, P, C), 0.0))
        value[~done | ~np.isfinite(value)] = np.inf
        return _reduce(value, self.over)


def gramians(A: np.ndarray, Q: np.ndarray, *, discrete: bool) -> tuple[np.ndarray, np.ndarray]:
    r"""Controllability Gramians of a stack of stable loops: ``P = A P A' + Q`` (discrete) or ``A P + P A' + Q = 0``.

    ``A`` (..., N, N), ``Q`` (N, N) or (..., N, N) positive semidefinite;
    returns ``P`` and where the iteration settled (a loop that is not stable,
    or too close to the boundary, does not). Discrete: the squared Smith
    iteration [1]_, ``P <- P + A_j P A_j'``, ``A_j <- A_j^2``. Continuous: the
    Cayley transform ``A_d = (cI - A)^{-1} (cI + A)``,
    ``Q_d = 2c (cI - A)^{-1} Q (cI - A)^{-T}`` (same ``P``; ``c`` the mean
    modulus of the diagonal of ``A``), then the same iteration.

    References
    ----------
    .. [1] R. A. Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math.
       16(1), 198-201, 1968.
    """
    A = np.asarray(A, dtype=float)
    Q = np.broadcast_to(Q, A.shape).astype(float)
    if not discrete:
        N = A.shape[-1]
        c = np.maximum(np.abs(np.diagonal(A, axis1=-2, axis2=-1)).mean(axis=-1), 1e-6)[..., None, None]
        M = c * np.eye(N) - A
        with np.errstate(all="ignore"):
            Minv = np.linalg.solve(np.where(np.isfinite(M), M, 0.0), np.broadcast_to(np.eye(N), M.shape))
        A, Q = Minv @ (c * np.eye(N) + A), 2.0 * c * (Minv @ Q @ np.swapaxes(Minv, -1, -2))
    P = Q.copy()
    Aj = A.copy()
    done = np.zeros(A.shape[:-2], dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(_SMITH_MAX):
            inc = Aj @ P @ np.swapaxes(Aj, -1, -2)
            P += inc
            done = np.abs(inc).max(axis=(-2, -1)) <= _SMITH_RTOL * np.abs(P).max(axis=(-2, -1))
            if done.all():
                break
            Aj = Aj @ Aj
    return P, done & np.isfinite(P).all(axis=(-2, -1))


@dataclass(frozen=True, eq=False, repr=False)
class HinfNorm(_Channel):
    r"""H-infinity norm of the channel ``w -> z = Cz x + Dzu u`` of ``x+ = (F + G K) x + Bw w``.

    The worst-case energy gain from ``w`` to ``z``, per scenario; the max
    (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Disturbance input matrix.
    Cz : (l, n) array_like (1-D: one row)
        Performance output matrix.
    Dzu : (l, m) array_like, optional
        Feedthrough of the input to the performance output (default none).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label for tables and plots (default ``"Hinf norm"``).

    Raises
    ------
    ValueError
        ``Bw``, ``Cz`` or ``Dzu`` not finite or of sizes that do not fit each
        other or the plants (the message names the matrix and the shapes).

    See Also
    --------
    H2Norm : the average gain of the same channel.
    RobustMargin : the same computation, read as a robustness margin.
    robustctl.robust_stability : the small-gain analysis it uses.

    Notes
    -----
    .. math::

        \|T_{zw}\|_\infty = \max_{\omega} \sigma_{\max}\big((C_z + D_{zu} K)
        (e^{j\omega} I - F - G K)^{-1} B_w\big)
        = 1 / \text{margin},

    the margin of ``robustctl.robust_stability((plant, K),
    NormBounded(Bw, Cz, Dzu))`` (the small-gain value: one norm
    implementation in the project; 0 where the channel is zero).

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4.

    Examples
    --------
    This loop's gain is largest at ``omega = 0`` (its DC gain, 9); a
    frequency sweep finds the same value:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import HinfNorm
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> norm = HinfNorm(Bw=[[0.0], [1.0]], Cz=[[1.0, 0.0]])(K, [plant])
    >>> A, z = plant.F + plant.G @ K[0], np.exp(1j * np.linspace(0.0, np.pi, 2001))
    >>> sweep = max(abs(np.linalg.solve(zk * np.eye(2) - A, [0.0, 1.0])[0]) for zk in z)
    >>> np.allclose(norm, sweep), np.allclose(norm, 9.0)
    (True, True)
    """

    _default_name = "Hinf norm"

    def measure(self, K, plants) -> np.ndarray:
        """The H-infinity norm of each design, shape (B,)."""
        self.check(plants)
        K, plants, _ = _loops(K, plants)
        Dzu = np.zeros((self.Cz.shape[0], plants[0].m)) if self.Dzu is None else self.Dzu
        unc = rc.NormBounded(self.Bw, self.Cz, Dzu)
        with np.errstate(divide="ignore"):
            norms = np.stack([1.0 / _robust_margins(p, K, unc) for p in plants], axis=1)   # (B, S)
        return _reduce(norms, self.over)


@dataclass(frozen=True, eq=False, repr=False)
class Variance(Goal):
    r"""Stationary variance of an output under process and measurement noise (noise to output, H2).

    MATLAB's ``TuningGoal.Variance``: with white process noise ``w`` of
    covariance ``W`` entering ``x+ = F x + G u + B_w w`` and white measurement
    noise ``v`` of covariance ``V`` added to what the controller measures
    (``y + v``; the state for a state feedback), the value is the sum of the
    stationary variances of ``z = C_z x + D_zu u`` (``trace E[z z']``).
    Continuous plants: ``W`` and ``V`` are intensities and ``z`` must not
    see ``v`` directly. The max (default) or mean over the scenarios.

    Parameters
    ----------
    Bw : (n, q) array_like (1-D: one column)
        Process noise input.
    W : (q, q) array_like, optional
        Process noise covariance (default identity).
    V : (r, r) array_like, optional
        Measurement noise covariance (``r`` the measured signals: the plant's
        ``p``, or ``n`` for a state feedback); default none.
    Cz : (l, n) array_like, optional
        Performance output (default the plant's output ``C``, the state
        without an output model).
    Dzu : (l, m) array_like, optional
        Its input feedthrough (default the plant's ``D`` with the default
        ``Cz``, else zero).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label (default ``"variance"``).

    Raises
    ------
    ValueError
        Matrices not finite, ``W`` or ``V`` not symmetric positive
        semidefinite, sizes that do not fit each other or the plants.

    See Also
    --------
    H2Norm : the unit-intensity case without measurement noise.

    Notes
    -----
    In the loop states :math:`\xi = (x, x_c)`, with :math:`E = (I - D_c D)^{-1}`,

    .. math::

        \xi^+ = A_{cl} \xi + B_a w + B_v v, \quad
        z = C_a \xi + D_v v, \quad
        B_a = \begin{bmatrix} B_w \\ 0 \end{bmatrix}, \quad
        B_v = \begin{bmatrix} G E D_c \\ B_c (I + D E D_c) \end{bmatrix},

    :math:`C_a = [C_z\ 0] + D_{zu} K_u`, :math:`D_v = D_{zu} E D_c`, and

    .. math::

        \operatorname{var} z = \operatorname{trace}\big(C_a P C_a^T + D_v V D_v^T\big), \qquad
        P = A_{cl} P A_{cl}^T + B_a W B_a^T + B_v V B_v^T

    (continuous: :math:`A_{cl} P + P A_{cl}^T + B_a W B_a^T + B_v V B_v^T = 0`),
    by the batched Gramians of :func:`gramians`.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 4 (H2 norm and covariance).

    Examples
    --------
    ``x+ = 0.5 x + w`` (the loop ``x+ = 0.7 x - 0.2 x + w``): the variance
    ``1 / (1 - 0.25)``, python-control's H2 norm squared:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import Variance
    >>> plant = rc.Plant([[0.7]], [[1.0]], 0.1)
    >>> Variance(Bw=[[1.0]])(np.array([[[-0.2]]]), [plant])
    array([1.33333333])
    >>> round(float(control.norm(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1), 2) ** 2), 10)
    1.3333333333
    """

    Bw: Any
    W: Any = None
    V: Any = None
    Cz: Any = None
    Dzu: Any = None
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        Bw = _matrix(self.Bw, "Bw", "column")
        q = Bw.shape[1]
        W = np.eye(q) if self.W is None else _covariance(self.W, "W", q, "the columns of Bw")
        V = None if self.V is None else _covariance(self.V, "V", None, "")
        Cz = None if self.Cz is None else _matrix(self.Cz, "Cz", "row")
        Dzu = None if self.Dzu is None else _matrix(self.Dzu, "Dzu", "row")
        if Cz is not None and Dzu is not None and Dzu.shape[0] != Cz.shape[0]:
            raise ValueError(f"Dzu must have {Cz.shape[0]} rows (the rows of Cz), got shape {Dzu.shape}")
        _set(self, Bw=Bw, W=W, V=V, Cz=Cz, Dzu=Dzu, over=check_choice(self.over, "over", OVER),
             name=self.name or "variance")

    def check(self, plants) -> None:
        """``ValueError`` naming ``Bw``, ``V``, ``Cz`` or ``Dzu`` if its size does not fit ``plants``."""
        plants = check_scenarios(plants, continuous=True)
        n, m = plants[0].n, plants[0].m
        if self.Bw.shape[0] != n:
            raise ValueError(f"Bw must have {n} rows (the number of states of the plants), got shape {self.Bw.shape}")
        if self.Cz is not None and self.Cz.shape[1] != n:
            raise ValueError(f"Cz must have {n} columns (the number of states), got shape {self.Cz.shape}")
        if self.Dzu is not None and self.Dzu.shape[1] != m:
            raise ValueError(f"Dzu must have {m} columns (the number of inputs), got shape {self.Dzu.shape}")
        if self.Cz is None and self.Dzu is not None and self.Dzu.shape[0] != plants[0].p:
            raise ValueError(f"Dzu must have {plants[0].p} rows (the plant's outputs, the default Cz), "
                             f"got shape {self.Dzu.shape}")
        if self.V is not None and self.V.shape[0] not in (n, plants[0].p):
            raise ValueError(f"V must be ({plants[0].p}, {plants[0].p}) (the measured outputs) or ({n}, {n}) (a state "
                             f"feedback's), got shape {self.V.shape}")

    def measure(self, K, plants) -> np.ndarray:
        """The summed stationary variance of ``z`` of each design, shape (B,)."""
        self.check(plants)
        K, plants, loops = _loops(K, plants)
        B, S, N = loops.A.shape[:3]
        n, m = loops.n, plants[0].m
        C0, D0 = plants[0].output_matrices()
        Cz = C0 if self.Cz is None else self.Cz
        Dzu = (D0 if self.Cz is None else np.zeros((Cz.shape[0], m))) if self.Dzu is None else self.Dzu
        Ca = np.zeros((Cz.shape[0], N))
        Ca[:, :n] = Cz
        Ca = Ca + Dzu @ loops.Ku                                                     # (B, S, l, N)
        Ba = np.zeros((N, self.Bw.shape[1]))
        Ba[:n] = self.Bw
        Q = np.broadcast_to(Ba @ self.W @ Ba.T, loops.A.shape).copy()
        extra = np.zeros((B, S))
        if self.V is not None:
            Dc = K.Dc if is_output_feedback(K) else np.asarray(K)
            r = Dc.shape[-1]
            if self.V.shape != (r, r):
                raise ValueError(f"V must be ({r}, {r}) (the signals these controllers measure), got shape "
                                 f"{self.V.shape}")
            Bv = loops.Bv @ Dc[:, None]                                              # (B, S, N, r)
            if is_output_feedback(K) and K.order:
                Bv[..., n:, :] += K.Bc[:, None]
            Q += Bv @ self.V @ np.swapaxes(Bv, -1, -2)
            Dv = Dzu @ loops.E @ Dc[:, None]                                         # (B, S, l, r)
            if not loops.discrete and np.any(Dv):
                raise ValueError("V: the output z sees the measurement noise directly (D_zu E D_c != 0): its "
                                 "variance is infinite for a continuous plant")
            extra = np.einsum("bsli,ij,bslj->bs", Dv, self.V, Dv)
        P, done = gramians(loops.A, Q, discrete=loops.discrete)
        value = np.einsum("bsln,bsnk,bslk->bs", Ca, P, Ca) + extra
        value[~done | ~np.isfinite(value)] = np.inf
        return _reduce(np.maximum(value, 0.0), self.over)


def _covariance(value, name: str, size: int | None, what: str) -> np.ndarray:
    """A finite symmetric positive semidefinite (size, size) matrix, read-only."""
    M = as_matrix(value, name)
    if M.shape[0] != M.shape[1] or (size is not None and M.shape[0] != size):
        want = f"({size}, {size}) ({what})" if size is not None else "square"
        raise ValueError(f"{name} must be {want}, got shape {M.shape}")
    scale = max(1.0, float(np.abs(M).max()))
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * scale) \
            or np.linalg.eigvalsh(0.5 * (M + M.T))[0] < -1e-12 * scale:
        raise ValueError(f"{name} must be symmetric positive semidefinite (a covariance)")
    M = 0.5 * (M + M.T)
    M.flags.writeable = False
    return M


# ---------------------------------------------------------------- robustness
@dataclass(frozen=True, eq=False, repr=False)
class RobustMargin(Goal):
    r"""The certified robust-stability margin against a norm-bounded uncertainty (a quantity to maximise).

    The margin of :func:`robustctl.robust_stability` ``((nominal, K),
    uncertainty)``: the loop is quadratically stable for every
    ``||Delta|| <= margin`` (``inf`` if the uncertainty does not reach the
    loop). :meth:`measure` returns the margin, to which bounds refer
    (``at_least(RobustMargin(unc), 1.0)``: certified); as an objective the
    goal is minimised as ``1 / margin`` (the small-gain norm; 0 for an
    unreachable loop).

    Parameters
    ----------
    uncertainty : robustctl.NormBounded
        E.g. :meth:`robustctl.NormBounded.from_plants` of the scenarios.
    nominal : robustctl.Plant, optional
        The plant the uncertainty is about (default: the first scenario).
    name : str, optional
        Label for tables and plots.

    Raises
    ------
    TypeError
        ``uncertainty`` not a :class:`robustctl.NormBounded`, ``nominal`` not
        a :class:`robustctl.Plant`.
    ValueError
        (When checked against the plants.) An uncertainty or a nominal plant
        whose sizes do not fit the plants.

    See Also
    --------
    robustctl.robust_stability : the analysis it calls (batched over the designs).
    at_least : the constraint form.
    HinfNorm : the norm of a performance channel.

    Notes
    -----
    For :math:`[\delta F\ \delta G] = H \Delta [E_F\ E_G]` about the nominal
    plant, with :math:`A = F + G K`, :math:`E = E_F + E_G K`,

    .. math::

        \text{margin}(K) = \frac{1}{\|E (zI - A)^{-1} H\|_\infty},

    and the small-gain theorem certifies stability for every
    :math:`\|\Delta\| < \text{margin}` [1]_.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 9.

    Examples
    --------
    An uncertain entry ``F[1, 0]`` (``H = e_2``, ``E_F = e_1^T``): the
    margin is the inverse of the ``H -> E`` gain, 9 for this gain:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import RobustMargin
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> goal = RobustMargin(rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]))
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> goal.measure(K, [plant]), goal(K, [plant])
    (array([0.11111111]), array([9.]))
    """

    uncertainty: rc.NormBounded
    nominal: rc.Plant | None = None
    name: str = "1/robust margin"

    def __post_init__(self):
        if not isinstance(self.uncertainty, rc.NormBounded):
            raise TypeError(f"uncertainty must be a robustctl.NormBounded, got {type(self.uncertainty).__name__}")
        if self.nominal is not None and not isinstance(self.nominal, rc.Plant):
            raise TypeError(f"nominal must be a robustctl.Plant or None, got {type(self.nominal).__name__}")

    def _plant(self, plants) -> rc.Plant:
        plants = check_scenarios(plants, continuous=True)
        nominal = plants[0] if self.nominal is None else self.nominal
        try:
            self.uncertainty.check_plant(nominal)
        except ValueError as exc:
            raise ValueError(f"uncertainty does not fit the plants: {exc}") from None
        if (nominal.n, nominal.m, nominal.dt) != (plants[0].n, plants[0].m, plants[0].dt):
            raise ValueError(f"nominal must have n={plants[0].n}, m={plants[0].m}, dt={plants[0].dt} like the "
                             f"plants, got n={nominal.n}, m={nominal.m}, dt={nominal.dt}")
        return nominal

    def check(self, plants) -> None:
        """``ValueError`` if the uncertainty or the nominal plant does not fit ``plants``."""
        self._plant(plants)

    def measure(self, K, plants) -> np.ndarray:
        """The margin of each design, shape (B,) (to maximise)."""
        nominal = self._plant(plants)
        K, plants, _ = _loops(K, plants)
        return _robust_margins(nominal, K, self.uncertainty)

    def __call__(self, K, plants) -> np.ndarray:
        """``1 / margin`` of each design (to minimise)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.measure(K, plants)

    def __repr__(self) -> str:
        return f"RobustMargin({self.uncertainty!r}, name={self.name!r})"


# ---------------------------------------------------------------- constraints
@dataclass(frozen=True, eq=False, repr=False)
class Bound:
    """A constraint from a goal and a bound, ``<= 0`` where it holds (:func:`at_most`, :func:`at_least`).

    The bound refers to the goal's :meth:`~Goal.measure` (for a user callable,
    its value): ``at_most``: ``measure - bound``; ``at_least``: ``bound - measure``.
    Build it with :func:`at_most` or :func:`at_least`.

    Parameters
    ----------
    goal : Goal or callable
        One of this module's goals or any ``f(K, plants) -> (B,)``.
    bound : float
        The bound.
    kind : {"at_most", "at_least"}
        Which side of the bound holds.
    name : str
        Label for tables and plots.

    See Also
    --------
    at_most, at_least

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import SpectralRadius, at_most
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]], [[-3.0, -4.0]]])
    >>> bound = at_most(SpectralRadius(), 0.91)
    >>> bound.name
    'spectral radius <= 0.91'
    >>> np.allclose(bound(K, [plant]), SpectralRadius()(K, [plant]) - 0.91)
    True
    """

    goal: Callable[..., Any]
    bound: float
    kind: str
    name: str = field(default="")

    def check(self, plants) -> None:
        """The goal's own check, if it has one."""
        check = getattr(self.goal, "check", None)
        if callable(check):
            check(plants)

    def __call__(self, K, plants) -> np.ndarray:
        """The constraint value of each design, shape (B,); ``<= 0`` where it holds."""
        measure = self.goal.measure if isinstance(self.goal, Goal) else self.goal
        value = np.asarray(measure(K, plants), dtype=float)
        return value - self.bound if self.kind == "at_most" else self.bound - value

    def __repr__(self) -> str:
        return f"{self.kind}({self.goal!r}, {self.bound:g})"


def _goal_name(goal) -> str:
    return str(getattr(goal, "name", None) or getattr(goal, "__name__", None) or type(goal).__name__)


def _bound(goal, bound, kind: str, op: str, name: str | None) -> Bound:
    if not callable(goal):
        raise TypeError(f"goal must be a goal or a callable f(K, plants) -> (B,), got {type(goal).__name__}")
    b = check_real(bound, "bound")
    label = _goal_name(goal)
    if isinstance(goal, RobustMargin):
        label = "robust margin"
    return Bound(goal, b, kind, name if name is not None else f"{label} {op} {b:g}")


def at_most(goal, bound: float, *, name: str | None = None) -> Bound:
    """The constraint ``goal <= bound`` (value ``measure - bound``, ``<= 0`` where it holds).

    Parameters
    ----------
    goal : Goal or callable
        One of this module's goals (its :meth:`~Goal.measure`) or any
        callable ``f(K, plants) -> (B,)``.
    bound : float
        The largest value allowed.
    name : str, optional
        Label (default e.g. ``"spectral radius <= 0.95"``).

    Returns
    -------
    Bound
        The constraint, a goal for :class:`~moo.tuning.TuningProblem`'s ``constraints``.

    Raises
    ------
    TypeError
        ``goal`` not callable, ``bound`` not a real number.

    See Also
    --------
    at_least : the other side.

    Examples
    --------
    The closed loop ``x[k+1] = 0.5 x[k]`` meets ``rho <= 0.95`` (value ``0.5 - 0.95``):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import SpectralRadius, at_most
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> constraint = at_most(SpectralRadius(), 0.95)
    >>> constraint
    at_most(SpectralRadius(name='spectral radius', over='max'), 0.95)
    >>> constraint(np.array([[[-0.2]]]), [plant])
    array([-0.45])
    """
    return _bound(goal, bound, "at_most", "<=", name)


def at_least(goal, bound: float, *, name: str | None = None) -> Bound:
    """The constraint ``goal >= bound`` (value ``bound - measure``, ``<= 0`` where it holds).

    ``at_least(RobustMargin(unc), 1.0)`` holds for the designs certified
    robustly stable for every ``||Delta|| <= 1``.

    Parameters
    ----------
    goal : Goal or callable
        One of this module's goals (its :meth:`~Goal.measure`) or any
        callable ``f(K, plants) -> (B,)``.
    bound : float
        The smallest value allowed.
    name : str, optional
        Label (default e.g. ``"robust margin >= 1"``).

    Returns
    -------
    Bound
        The constraint, a goal for :class:`~moo.tuning.TuningProblem`'s ``constraints``.

    Raises
    ------
    TypeError
        ``goal`` not callable, ``bound`` not a real number.

    See Also
    --------
    at_most : the other side.

    Examples
    --------
    Of two gains, only the second is certified for ``||Delta|| <= 0.2``
    (margins 1/9 and 3/8):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import RobustMargin, at_least
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> unc = rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    >>> constraint = at_least(RobustMargin(unc), 0.2)
    >>> constraint.name
    'robust margin >= 0.2'
    >>> K = np.array([[[-1.0, -2.0]], [[-3.0, -4.0]]])
    >>> constraint(K, [plant]) <= 0
    array([False,  True])
    """
    return _bound(goal, bound, "at_least", ">=", name)
