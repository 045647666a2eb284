"""Batched closed-loop simulation of linear plants under saturated state feedback (model free).

For B gains and S scenarios (plants) at once::

    e[k]   = x[k] - x_ref[k]
    u[k]   = sat( M K e[k] + u_ff[k] ),     |u_j| <= u_limit_j
    x[k+1] = F[k] x[k] + G[k] u[k] + w[k]

``K`` (m x n) is the controller's gain (convention ``u = K x``), ``M`` (p x m)
maps its m inputs to the plant's p physical inputs (identity by default);
``F``, ``G``, ``x_ref``, ``u_ff``, ``w`` may differ between scenarios and, for
the plant, between time steps. :class:`LinearSimulator` checks the plant,
reference and options once; its :meth:`~robustctl.sim.simulator.LinearSimulator.run` then checks only
the gains, so an optimiser that simulates a population per generation pays
the argument checks once. :func:`simulate_linear` does both in one call.

Divergence. Diverging runs (an unstable closed loop, or a saturated one that
drifts away) are not integrated to overflow: once any error component exceeds
``bound`` in magnitude the run is frozen and flagged (``diverged``,
``diverged_step``), and from then on *every* component of its error is held at
``+-bound`` (the sign it had at divergence). A run that diverges at step ``k``
therefore has, in every state, a mean squared error of at least
``(T - k) / T * bound**2``: large, finite, larger the earlier it diverged, and
never better than a stable run in any single objective (which holding the last
value would allow) - a safe ranking for an optimiser. A run whose error
becomes NaN (gains so large that ``K e`` or ``F x`` overflows, ``inf - inf``)
is flagged the same way, design by design, whatever the others in the batch
do; its error is frozen at ``+bound``. ``bound=inf`` turns the bound test off
(an overflowed run is still flagged, frozen at ``+inf``: MSE ``inf``).

Backends. ``backend="numba"`` (default) runs the compiled kernel of
:mod:`robustctl.sim._kernel`; ``backend="numpy"`` runs the reference
implementation below (one array recursion over the time steps on (S, n, B)
state arrays), which the tests compare the kernel with. Both do the same
arithmetic in the same order up to the summation order inside the matrix
products, so on runs whose inputs rarely saturate they agree to about 1e-14
(relative); on runs that sit on the saturation limit for most steps a
rounding difference can flip a saturation decision and the two trajectories
drift apart (chaotically; the numpy backend disagrees with itself by as much
when the same design runs in a batch of another size). The compiled kernel
computes each design independently of the others: its result for a design
does not depend on the size or the order of the batch.

References
----------
K. J. Astrom & R. M. Murray, *Feedback Systems*, 2nd ed., Princeton 2021,
Sec. 8.5 (two-degree-of-freedom tracking: feedforward plus feedback on the
error from a reference trajectory).
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import as_batch, as_float_array, check_choice, check_positive_scalar

__all__ = ["SimulationResult", "LinearSimulator", "simulate_linear", "check_gains", "DEFAULT_BOUND", "BACKENDS"]

#: Divergence bound on ``|x - x_ref|`` (any component), in the states' units.
DEFAULT_BOUND = 1e3
#: Names :meth:`robustctl.sim.simulator.LinearSimulator.run` accepts as ``backend``.
BACKENDS = ("numba", "numpy")


@dataclass(frozen=True, eq=False, repr=False)
class SimulationResult:
    """Outcome of a batched closed-loop run: B gains x S scenarios x T samples.

    Built by :meth:`LinearSimulator.run` (and :func:`simulate_linear`).

    Parameters
    ----------
    errors, inputs, sq_error_sum, sq_state_sum : ndarray or None
        The attributes below.
    diverged, diverged_step, saturated_steps, x_ref : ndarray
        The attributes below.
    objectives, T, dt, state_names
        The attributes below.

    Attributes
    ----------
    errors : (B, S, T, n) ndarray or None
        ``x[k] - x_ref[k]`` for k = 0..T-1, states in the plant's order (None
        if trajectories were not kept).
    inputs : (B, S, T, p) ndarray or None
        Applied (saturated) physical inputs.
    sq_error_sum : (B, S, n) ndarray
        ``sum_k (x[k] - x_ref[k])^2``, states in the plant's order.
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
        State indices :meth:`mse` reports, in its order (see :attr:`objective_names`).
    T : int
    dt : float or None
    state_names : tuple of str or None
        Names of the n states, in the plant's order (``x0``, ``x1``, ... when None).

    See Also
    --------
    LinearSimulator : runs the simulation.

    Examples
    --------
    A scalar loop that leaves ``bound = 5`` is frozen there: its error
    holds at ``+-bound`` from the step it left, as the module docstring says.

    >>> import numpy as np
    >>> from robustctl.sim import simulate_linear
    >>> T = 10
    >>> res = simulate_linear([[[-0.5]], [[0.5]]], [[1.2]], [[1.0]], np.zeros((T, 1)), x0=[1.0], bound=5.0,
    ...                       backend="numpy")
    >>> res
    SimulationResult(B=2, S=1, T=10, dt=None, diverged=1/2, trajectories=True)
    >>> res.diverged_step[:, 0].tolist()
    [-1, 4]
    >>> 1.7**4 > 5.0 > 1.7**3            # the second loop, x[k] = 1.7^k, leaves at k = 4
    True
    >>> bool(res.mse()[1, 0, 0] >= (T - 4) / T * 5.0**2)
    True
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
    state_names: tuple[str, ...] | None = None

    @property
    def B(self) -> int:
        """Number of gains (designs)."""
        return self.diverged.shape[0]

    @property
    def S(self) -> int:
        """Number of scenarios."""
        return self.diverged.shape[1]

    @property
    def objective_names(self) -> tuple[str, ...]:
        """Name of the state behind each column of :meth:`mse`."""
        names = self.state_names or tuple(f"x{i}" for i in range(self.sq_error_sum.shape[-1]))
        return tuple(names[i] for i in self.objectives)

    def mse(self, target: Literal["reference", "zero"] = "reference") -> np.ndarray:
        """Mean squared error of each objective, shape (B, S, len(objectives)).

        Column ``j`` is the MSE of state ``objectives[j]`` (named
        ``objective_names[j]``), which is in general *not* column ``j`` of
        ``errors`` (states in the plant's order; :meth:`state_mse` keeps
        that order). Diverged runs get a large finite value (see the module
        docstring).

        Parameters
        ----------
        target : {"reference", "zero"}
            ``"reference"`` (default): MSE of the tracking error ``x - x_ref``.
            ``"zero"``: MSE of the states themselves, the *regulation* error
            of a regulator driving every state to zero.

        Returns
        -------
        (B, S, len(objectives)) ndarray
            ``sum_k e_j[k]^2 / T`` for each objective state ``j``.
        """
        return self.state_mse(target)[..., list(self.objectives)]

    def state_mse(self, target: Literal["reference", "zero"] = "reference") -> np.ndarray:
        """Mean squared error of every state in the plant's order, shape (B, S, n) (see :meth:`mse`).

        Parameters
        ----------
        target : {"reference", "zero"}
            As in :meth:`mse`.

        Returns
        -------
        (B, S, n) ndarray
        """
        check_choice(target, "target", ("reference", "zero"))
        return (self.sq_error_sum if target == "reference" else self.sq_state_sum) / self.T

    @property
    def states(self) -> np.ndarray:
        """``x = errors + x_ref``, shape (B, S, T, n)."""
        self._need_trajectories()
        return self.errors + self.x_ref

    def _need_trajectories(self):
        if self.errors is None:
            raise ValueError("trajectories were not kept (keep_trajectories=False)")

    def __repr__(self) -> str:
        n_div = int(self.diverged.sum())
        return (f"{type(self).__name__}(B={self.B}, S={self.S}, T={self.T}, dt={self.dt}, "
                f"diverged={n_div}/{self.diverged.size}, trajectories={self.errors is not None})")


# -- argument checks ----------------------------------------------------------------------
def check_gains(K, n: int, nan_gains: str = "raise") -> tuple[np.ndarray, np.ndarray]:
    """``K`` as (B, m, n) float gains and the (B,) mask of gains with non-finite entries (zeroed).

    Parameters
    ----------
    K : (m, n) or (B, m, n) array_like
        One gain or a stack.
    n : int
        The number of states (columns of each gain).
    nan_gains : {"raise", "flag"}
        ``"raise"`` rejects non-finite gains, ``"flag"`` zeroes and reports them.

    Returns
    -------
    K : (B, m, n) ndarray
        The gains (a copy; flagged ones zeroed).
    bad : (B,) ndarray of bool
        The gains that had a NaN or infinite entry.

    Raises
    ------
    ValueError
        Wrong shape or number of columns; non-finite entries with
        ``nan_gains="raise"``.

    Examples
    --------
    >>> import numpy as np
    >>> from robustctl.sim.simulator import check_gains
    >>> K, bad = check_gains([[[1.0, 2.0]], [[np.nan, 0.0]]], 2, nan_gains="flag")
    >>> K.shape, bad.tolist(), K[1].tolist()
    ((2, 1, 2), [False, True], [[0.0, 0.0]])
    """
    check_choice(nan_gains, "nan_gains", ("raise", "flag"))
    arr = as_float_array(K, "K")
    if arr.ndim not in (2, 3) or 0 in arr.shape:
        raise ValueError(f"K must be an (m, n) gain or a non-empty (B, m, n) stack of gains, got shape {arr.shape}")
    arr = arr[None] if arr.ndim == 2 else arr
    if arr.shape[2] != n:
        raise ValueError(f"K must have {n} columns (the number of states), got shape {np.shape(K)}")
    bad = ~np.isfinite(arr).all(axis=(1, 2))
    if bad.any():
        if nan_gains == "raise":
            raise ValueError("K must have finite entries (found NaN or inf); "
                             "nan_gains='flag' reports such gains as diverged instead")
        arr[bad] = 0.0
    return arr, bad


def _plant_array(M, name: str, rows: int, cols: int | None, T: int) -> np.ndarray:
    """``M`` of shape (rows, cols), (S, rows, cols) or (S, T, rows, cols) as a contiguous 4-D array."""
    arr = as_float_array(M, name)
    if arr.ndim not in (2, 3, 4):
        raise ValueError(f"{name} must have shape ({rows}, {cols or 'p'}), (S, {rows}, {cols or 'p'}) "
                         f"or (S, T, {rows}, {cols or 'p'}), got shape {arr.shape}")
    lead = (None,) * (arr.ndim - 2)
    arr = as_batch(arr, name, (*lead, rows, cols), ("",) * len(lead) + ("the number of states, from F", ""))
    arr = arr[None, None] if arr.ndim == 2 else (arr[:, None] if arr.ndim == 3 else arr)
    if arr.shape[1] not in (1, T):
        raise ValueError(f"{name} has {arr.shape[1]} time steps, expected 1 or T={T} (from x_ref)")
    return np.ascontiguousarray(arr)


def _signal(value, name: str, width: int, what: str, T: int) -> np.ndarray:
    """A (T, width) or (S, T, width) signal as (1 or S, T, width); None -> zeros (1, 1, width)."""
    if value is None:
        return np.zeros((1, 1, width))
    a = as_float_array(value, name)
    if a.ndim not in (2, 3):
        raise ValueError(f"{name} must have shape (T, {width}) or (S, T, {width}), got shape {a.shape}")
    a = as_batch(a, name, (None,) * (a.ndim - 1) + (width,), ("",) * (a.ndim - 1) + (what,))
    if a.shape[-2] != T:
        raise ValueError(f"{name} must have T={T} samples (from x_ref), got shape {a.shape}")
    return np.ascontiguousarray(a if a.ndim == 3 else a[None])


def _scenario_count(arrays: dict[str, np.ndarray]) -> int:
    """S from the leading axes (each 1 or S)."""
    S = max(a.shape[0] for a in arrays.values())
    for name, a in arrays.items():
        if a.shape[0] not in (1, S):
            raise ValueError(f"{name} has {a.shape[0]} scenarios, expected 1 or {S}")
    return S


def _input_map(input_map, p: int) -> np.ndarray:
    """The (p, m) input map (a 1-D map is one row)."""
    M = as_float_array(input_map, "input_map")
    return as_batch(M if M.ndim == 2 else M[None], "input_map", (p, None),
                    ("the plant's inputs, from G", "the controller's inputs"))


def _limits(u_limit, p: int) -> np.ndarray:
    """(p,) saturation levels, ``inf`` for none (``inf`` entries: those inputs are not limited)."""
    if u_limit is None:
        return np.full(p, np.inf)
    try:
        lim = np.broadcast_to(np.asarray(u_limit, dtype=float), (p,)).copy()
    except (TypeError, ValueError):
        lim = None
    if lim is None or not np.all(lim > 0) or isinstance(u_limit, bool):
        raise ValueError(f"u_limit must be a positive scalar or a ({p},) array (one per plant input; inf: no "
                         f"limit), got {u_limit!r}")
    return lim


# -- the simulator ----------------------------------------------------------------------------
class LinearSimulator:
    r"""Plant, scenarios, reference and options of :func:`simulate_linear`, checked once.

    :meth:`run` then simulates any number of gains on every scenario,
    checking only the gains (an optimiser pays the argument checks once).

    Parameters
    ----------
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
        Symmetric saturation ``|u_j| <= u_limit_j`` (default: none; an ``inf``
        entry leaves that input unlimited).
    input_map : (p, m) array_like, optional
        ``M`` mapping the controller's m inputs to the plant's p inputs
        (default identity, m = p). The doubled steering column of the truck
        (``alpha = u1 + u2``) is ``M = [[1, 1]]``.
    bound : float
        Divergence bound on ``|x - x_ref|`` (see the module docstring); ``inf``: none.
    objectives : sequence of int, optional
        State indices :meth:`SimulationResult.mse` reports (default all, in order).
    state_names : sequence of str, optional
        Names of the states (recorded in the result).
    dt : float, optional
        Sampling time, only recorded in the result.

    Attributes
    ----------
    n, p, m, S, T : int
        States, plant inputs, controller inputs, scenarios, samples.

    Raises
    ------
    ValueError
        Shapes that do not agree (the message names the array and both
        shapes), a scenario count that differs between arrays, non-finite
        entries, a non-positive ``u_limit`` or ``bound``, objectives that are
        not state indices.
    TypeError
        A non-numeric entry.

    See Also
    --------
    simulate_linear : the one-call form.
    robustctl.models.pathfollow.PathFollowing : the truck on a path, built on it.

    Notes
    -----
    For gain ``b`` and scenario ``s`` at step ``k`` (module docstring) [1]_:

    .. math::

        e_k = x_k - x^{ref}_k, \qquad
        u_k = \operatorname{sat}_{u_{lim}}\!\left(M K_b e_k + u^{ff}_k\right), \qquad
        x_{k+1} = F_{s,k}\, x_k + G_{s,k}\, u_k + w_k ,

    with ``x_0 = x^ref_0 + x0``; the result keeps ``sum_k e_k^2`` and
    ``sum_k x_k^2`` per state.

    References
    ----------
    .. [1] K. J. Astrom, R. M. Murray, *Feedback Systems*, 2nd ed., Princeton
       2021, Sec. 8.5.

    Examples
    --------
    One plant, two gains and two scenarios (the plant's pole at 0.9 or 1.05),
    the input saturated at 0.2; the second scenario of the first gain,
    written out step by step, gives the same MSE:

    >>> import numpy as np
    >>> from robustctl.sim import LinearSimulator
    >>> T = 50
    >>> sim = LinearSimulator([[[0.9]], [[1.05]]], [[0.5]], np.zeros((T, 1)), x0=[1.0], u_limit=0.2)
    >>> sim
    LinearSimulator(n=1, p=1, m=1, S=2, T=50, bound=1000, saturation=True)
    >>> res = sim.run([[[-0.6]], [[-1.2]]], backend="numpy")
    >>> res.mse().shape
    (2, 2, 1)
    >>> x, squares = 1.0, []
    >>> for _ in range(T):
    ...     squares.append(x * x)
    ...     x = 1.05 * x + 0.5 * np.clip(-0.6 * x, -0.2, 0.2)
    >>> bool(np.isclose(res.mse()[0, 1, 0], np.mean(squares)))
    True
    """

    def __init__(self, F, G, x_ref, *, u_ff=None, w=None, x0=None, u_limit=None, input_map=None,
                 bound: float = DEFAULT_BOUND, objectives: Sequence[int] | None = None,
                 state_names: Sequence[str] | None = None, dt: float | None = None):
        F_ = as_float_array(F, "F")
        if F_.ndim < 2 or F_.shape[-1] != F_.shape[-2]:
            raise ValueError(f"F must be square in its last two axes (n, n), got shape {F_.shape}")
        n = F_.shape[-1]
        xr = as_float_array(x_ref, "x_ref")
        if xr.ndim not in (2, 3):
            raise ValueError(f"x_ref must have shape (T, {n}) or (S, T, {n}), got shape {xr.shape}")
        xr = as_batch(xr, "x_ref", (None,) * (xr.ndim - 1) + (n,),
                      ("",) * (xr.ndim - 1) + ("the number of states, from F",))
        T = xr.shape[-2]
        if T < 1:
            raise ValueError("x_ref must have at least one sample (T >= 1)")
        self._x_ref = xr
        self._F = _plant_array(F_, "F", n, n, T)
        self._G = _plant_array(G, "G", n, None, T)
        p = self._G.shape[-1]
        self._xr = np.ascontiguousarray(xr if xr.ndim == 3 else xr[None])
        self._uff = _signal(u_ff, "u_ff", p, "the number of plant inputs, from G", T)
        self._w = _signal(w, "w", n, "the number of states, from F", T)
        if x0 is None:
            e0 = np.zeros((1, n))
        else:
            e0 = as_float_array(x0, "x0")
            e0 = as_batch(e0 if e0.ndim == 2 else e0[None], "x0", (None, n), ("scenarios", "the number of states"))
        self._e0 = np.ascontiguousarray(e0)
        self.S = _scenario_count({"F": self._F, "G": self._G, "x_ref": self._xr, "u_ff": self._uff,
                                  "w": self._w, "x0": self._e0})
        self.n, self.p, self.T = n, p, T
        self._M = None if input_map is None else _input_map(input_map, p)
        self.m = p if self._M is None else self._M.shape[1]
        self._lim = _limits(u_limit, p)
        self._has_limit = u_limit is not None
        self._bound = check_positive_scalar(bound, "bound", allow_inf=True)
        obj = tuple(range(n)) if objectives is None else tuple(int(i) for i in objectives)
        if any(i < 0 or i >= n for i in obj):
            raise ValueError(f"objectives must be state indices in [0, {n}), got {obj}")
        self._objectives = obj
        names = None if state_names is None else tuple(str(s) for s in state_names)
        if names is not None and len(names) != n:
            raise ValueError(f"state_names must name the {n} states, got {len(names)} names")
        self._state_names = names
        self._dt = dt

    def with_input_map(self, input_map) -> LinearSimulator:
        """The same simulator with another input map ``M`` (p, m') (no other argument is checked again).

        Parameters
        ----------
        input_map : (p, m') array_like
            Maps the controller's m' inputs to the plant's p inputs.

        Returns
        -------
        LinearSimulator
            A shallow copy with that map.

        Raises
        ------
        ValueError
            A map without ``p`` rows.
        """
        M = _input_map(input_map, self.p)
        other = copy.copy(self)
        other._M, other.m = M, M.shape[1]
        return other

    def run(self, K, *, keep_trajectories: bool = True, nan_gains: Literal["raise", "flag"] = "raise",
            backend: Literal["numba", "numpy"] = "numba") -> SimulationResult:
        """Simulate every gain on every scenario.

        Parameters
        ----------
        K : (m, n) or (B, m, n) array_like
            State-feedback gains, convention ``u = K x`` (before the input map).
        keep_trajectories : bool
            Keep ``errors`` and ``inputs`` (B, S, T, .) arrays; False keeps only the
            sums needed for :meth:`SimulationResult.mse` (less memory, faster).
        nan_gains : {"raise", "flag"}
            A gain with NaN/inf entries (e.g. a failed design of a batch) raises
            ``ValueError`` (default), or with ``"flag"`` is not simulated and is
            reported as diverged at step 0 with every error at ``+bound``
            (MSE ``bound**2``).
        backend : {"numba", "numpy"}
            The compiled kernel (default) or the numpy reference implementation.

        Returns
        -------
        SimulationResult
            B = the number of gains, S scenarios, T samples.

        Raises
        ------
        ValueError
            Gains of the wrong shape (their number of inputs must be the
            input map's columns), non-finite gains with
            ``nan_gains="raise"``, an unknown ``backend``.
        TypeError
            ``keep_trajectories`` not a bool.
        """
        if backend not in BACKENDS:
            raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
        if not isinstance(keep_trajectories, (bool, np.bool_)):
            raise TypeError(f"keep_trajectories must be a bool, got {type(keep_trajectories).__name__}")
        Kb, dead = check_gains(K, self.n, nan_gains)
        if Kb.shape[1] != self.m:
            fix = (f"the plant has {self.p}; give input_map of shape ({self.p}, {Kb.shape[1]})" if self._M is None
                   else f"input_map has {self.m} columns")
            raise ValueError(f"K has {Kb.shape[1]} inputs (shape {np.shape(K)}) but {fix}")
        Keff = Kb if self._M is None else np.einsum("pm,bmn->bpn", self._M, Kb)
        run = _run_numba if backend == "numba" else _run_numpy
        sq, sqx, div, sat, E, U = run(self, Keff, dead, bool(keep_trajectories))
        return SimulationResult(errors=E, inputs=U, sq_error_sum=sq, sq_state_sum=sqx,
                                diverged=div >= 0, diverged_step=div, saturated_steps=sat,
                                x_ref=self._x_ref, objectives=self._objectives, T=self.T, dt=self._dt,
                                state_names=self._state_names)

    def __repr__(self) -> str:
        return (f"LinearSimulator(n={self.n}, p={self.p}, m={self.m}, S={self.S}, T={self.T}, "
                f"bound={self._bound:g}, saturation={self._has_limit})")


def simulate_linear(K, F, G, x_ref, *, u_ff=None, w=None, x0=None, u_limit=None, input_map=None,
                    bound: float = DEFAULT_BOUND, keep_trajectories: bool = True,
                    objectives: Sequence[int] | None = None, dt: float | None = None,
                    nan_gains: Literal["raise", "flag"] = "raise",
                    backend: Literal["numba", "numpy"] = "numba") -> SimulationResult:
    r"""Simulate ``x[k+1] = F x[k] + G u[k] + w[k]``, ``u[k] = sat(M K (x[k] - x_ref[k]) + u_ff[k])``.

    All B gains run on all S plants (scenarios) at once. One call of
    ``LinearSimulator(F, G, x_ref, ...).run(K, ...)``; see the module
    docstring for divergence and backends.

    Parameters
    ----------
    K : (m, n) or (B, m, n) array_like
        State-feedback gains, ``u = K x`` (before the input map).
    F : (n, n), (S, n, n) or (S, T, n, n) array_like
        Plant matrices per scenario, constant or per time step.
    G : (n, p), (S, n, p) or (S, T, n, p) array_like
        Physical input matrices.
    x_ref : (T, n) or (S, T, n) array_like
        Reference states; fixes the horizon T.
    u_ff : (T, p) or (S, T, p) array_like, optional
        Feedforward input (default zero).
    w : (T, n) or (S, T, n) array_like, optional
        Known additive disturbance (default zero).
    x0 : (n,) or (S, n) array_like, optional
        Initial error ``x[0] - x_ref[0]`` (default zero).
    u_limit : float or (p,) array_like, optional
        Symmetric saturation ``|u_j| <= u_limit_j`` (default: none).
    input_map : (p, m) array_like, optional
        Maps the controller's m inputs to the plant's p inputs (default identity).
    bound : float
        Divergence bound on ``|x - x_ref|``; ``inf``: none.
    keep_trajectories : bool
        Keep ``errors`` and ``inputs``; False keeps only the MSE sums.
    objectives : sequence of int, optional
        State indices :meth:`SimulationResult.mse` reports.
    dt : float, optional
        Sampling time, only recorded.
    nan_gains : {"raise", "flag"}
        Raise on non-finite gains, or flag them as diverged at step 0.
    backend : {"numba", "numpy"}
        The compiled kernel (default) or the numpy reference.

    Returns
    -------
    SimulationResult
        The runs of every gain on every scenario.

    Raises
    ------
    ValueError
        As :class:`LinearSimulator` and :meth:`LinearSimulator.run`.
    TypeError
        A non-numeric argument.

    See Also
    --------
    LinearSimulator : the same, with the checks done once for many runs.

    Notes
    -----
    Without saturation and disturbance the error of a regulator is
    ``e_k = (F + G K)^k e_0``, so its MSE is

    .. math::

        \frac{1}{T} \sum_{k=0}^{T-1} e_k^2 ,

    a geometric sum for a scalar loop.

    Examples
    --------
    A scalar loop with the pole ``a + b k = 0.6`` has the MSE
    ``(1 - 0.6^(2T)) / (1 - 0.6^2) / T`` from ``e_0 = 1``:

    >>> import numpy as np
    >>> from robustctl.sim import simulate_linear
    >>> a, b, k, T = 0.9, 0.5, -0.6, 50
    >>> res = simulate_linear([[k]], [[a]], [[b]], np.zeros((T, 1)), x0=[1.0], backend="numpy")
    >>> res.mse().shape
    (1, 1, 1)
    >>> pole = a + b * k
    >>> bool(np.isclose(res.mse()[0, 0, 0], (1 - pole ** (2 * T)) / (1 - pole**2) / T))
    True
    """
    sim = LinearSimulator(F, G, x_ref, u_ff=u_ff, w=w, x0=x0, u_limit=u_limit, input_map=input_map,
                          bound=bound, objectives=objectives, dt=dt)
    return sim.run(K, keep_trajectories=keep_trajectories, nan_gains=nan_gains, backend=backend)


# -- backends: (sim, Keff (B, p, n), dead (B,), keep) -> (sq, sqx, div_step, sat_steps, E, U) --------
def _run_numba(sim: LinearSimulator, Keff: np.ndarray, dead: np.ndarray, keep: bool):
    from ._kernel import closed_loop

    B, S, T, n, p = Keff.shape[0], sim.S, sim.T, sim.n, sim.p
    sq = np.empty((B, S, n))
    sqx = np.empty((B, S, n))
    div = np.empty((B, S), dtype=np.int64)
    sat = np.empty((B, S), dtype=np.int64)
    E = np.empty((B, S, T, n) if keep else (0, 0, 0, 0))
    U = np.empty((B, S, T, p) if keep else (0, 0, 0, 0))
    closed_loop(np.ascontiguousarray(np.transpose(Keff, (1, 2, 0))), sim._F, sim._G, sim._xr, sim._uff,
                sim._w, sim._e0, sim._lim, sim._bound, np.ascontiguousarray(dead), keep, sq, sqx, div, sat, E, U)
    if not sim._has_limit:
        sat[:] = 0
    return sq, sqx, div, sat, (E if keep else None), (U if keep else None)


@np.errstate(over="ignore", invalid="ignore")
def _run_numpy(sim: LinearSimulator, Keff: np.ndarray, dead: np.ndarray, keep: bool):
    """The reference implementation: one array recursion over T steps on (S, n, B) states.

    Overflow is not warned about (as in the kernel): a run that overflows is flagged as diverged.
    """
    B, S, T, n, p = Keff.shape[0], sim.S, sim.T, sim.n, sim.p
    bound = sim._bound
    Fa = np.broadcast_to(sim._F, (S, *sim._F.shape[1:]))
    Ga = np.broadcast_to(sim._G, (S, *sim._G.shape[1:]))
    xr = np.broadcast_to(sim._xr, (S, T, n))
    uff = np.broadcast_to(sim._uff, (S, *sim._uff.shape[1:]))
    wa = np.broadcast_to(sim._w, (S, *sim._w.shape[1:]))
    e0 = np.broadcast_to(sim._e0, (S, n))
    lo, hi = -sim._lim[None, :, None], sim._lim[None, :, None]
    # State layout (S, n, B): one batched matmul per step. A frozen (diverged) run
    # keeps x = x_ref + e_frozen and its error is set to e_frozen exactly.
    alive = np.ones((S, B), dtype=bool)
    alive[:, dead] = False
    div_step = np.where(alive, -1, 0).astype(np.int64)
    e_frozen = np.full((S, n, B), bound)
    x = xr[:, 0, :, None] + np.where(alive[:, None, :], e0[:, :, None], e_frozen)
    KT = np.ascontiguousarray(np.transpose(Keff, (1, 2, 0)))    # (p, n, B)
    sq = np.zeros((S, n, B))
    sqx = np.zeros((S, n, B))
    sat_steps = np.zeros((S, B), dtype=np.int64)
    T_keep = T if keep else 0                                    # the trajectories, only if asked for
    E_all, U_all = np.empty((T_keep, S, n, B)), np.empty((T_keep, S, p, B))
    any_dead = bool(dead.any())
    alive3 = alive[:, None, :]                                   # view: follows alive
    for k in range(T):
        e = x - xr[:, k, :, None]
        if any_dead:
            e = np.where(alive3, e, e_frozen)
        # rare: someone diverges now. "not <=" so that NaN (an overflowed run, inf - inf) counts as divergence:
        # a NaN max must not switch the test off for the whole batch
        if not np.abs(e).max() <= bound:
            newly = (~(np.abs(e) <= bound)).any(axis=1) & alive
            div_step[newly] = k
            alive &= ~newly
            any_dead = True
            e_frozen = np.where(newly[:, None, :], np.where(e < 0, -bound, bound), e_frozen)
            e = np.where(alive3, e, e_frozen)
            x = np.where(alive3, x, xr[:, k, :, None] + e_frozen)
        # u[s, p, b] = sum_n Keff[b, p, n] e[s, n, b]
        u = np.einsum("pnb,snb->spb", KT, e) + uff[:, k if uff.shape[1] > 1 else 0, :, None]
        if sim._has_limit:
            sat_steps += ((u <= lo) | (u >= hi)).any(axis=1)
            u = np.minimum(np.maximum(u, lo), hi)
        sq += e * e
        sqx += x * x
        if keep:
            E_all[k] = e
            U_all[k] = u
        if k + 1 < T:
            kF, kG, kW = (k if a.shape[1] > 1 else 0 for a in (Fa, Ga, wa))
            x = Fa[:, kF] @ x + Ga[:, kG] @ u + wa[:, kW, :, None]
            if any_dead:
                x = np.where(alive3, x, xr[:, k + 1, :, None] + e_frozen)
    E = np.transpose(E_all, (3, 1, 0, 2)) if keep else None    # (B, S, T, n)
    U = np.transpose(U_all, (3, 1, 0, 2)) if keep else None
    return (np.transpose(sq, (2, 0, 1)), np.transpose(sqx, (2, 0, 1)), div_step.T.copy(),
            sat_steps.T.copy(), E, U)

