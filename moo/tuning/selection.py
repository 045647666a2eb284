r"""Monte Carlo design selection over a tuning problem's scenarios (Morais et al. 2022, Secs. 4.4.1, 4.5.1).

A MOEA returns a front of designs; a controller needs one. The paper picks
it by simulation: every candidate is run on the same ``S`` random
realisations of the uncertainty, in each simulation the design with the
least cumulative error wins, and the design that wins most often is chosen.

For any :class:`~moo.tuning.TuningProblem` (:func:`select`):

* **draws** - simulation ``s`` draws one plant ``P_s``: a scenario of the
  problem chosen uniformly at random, or ``sampler(rng)`` if a sampler is
  given (e.g. a random ``Delta`` of a norm-bounded model, or a random
  parameter inside the range the scenarios sample);
* **error** - every design ``d`` runs on ``P_s`` alone: the problem's
  objectives evaluated on the one-plant list ``[P_s]`` give ``f_j(K_d, P_s)``
  and the cumulative error is their weighted sum

  .. math::

      E[d, s] = \sum_j w_j\, f_j(K_d, [P_s]), \qquad
      w_j = 1 / \big(\max_d F_{dj} - \min_d F_{dj}\big) \text{ (default)},

  the default weights dividing each objective by its spread over the front
  (``F`` the front's objectives), so that each objective counts the same over
  the range the front covers (adding a constant to an objective does not change
  a winner). A design unstable on ``P_s``, or whose goal is NaN there, gets
  ``+inf`` (cannot win);
* **count** - :func:`monte_carlo_selection` (ties go to the lowest index).

When the draws come from the scenario set, each goal is called once per
distinct scenario drawn (not once per simulation); with a sampler, once per
simulation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

import robustctl as rc

from ..validation import as_float_array, check_int
from .loops import count, is_output_feedback

__all__ = ["SelectionResult", "monte_carlo_selection", "Selection", "select", "scenario_errors", "draw_errors",
           "check_weights", "default_weights"]


@dataclass(frozen=True, eq=False, repr=False)
class SelectionResult:
    """Outcome of :func:`monte_carlo_selection` on ``D`` designs and ``S`` simulations.

    The fields are attributes of the same names; ``n_designs``,
    ``n_simulations``, ``n_no_winner`` and :meth:`ranking` are derived.

    Parameters
    ----------
    winners : (S,) int ndarray
        Index of the design with the least error in each simulation (ties: the
        lowest index); ``-1`` where no design has a finite error.
    counts : (D,) int ndarray
        Number of simulations each design won; ``counts.sum() == S - n_no_winner``.
    best : int
        The most frequent winner (ties: the lowest index), the selected design.

    See Also
    --------
    monte_carlo_selection : makes it.
    Selection : the result of the whole selection on a tuning problem.

    Examples
    --------
    Design 2 wins simulation 0, design 1 simulations 1 and 2; in simulation 3
    every design is unstable (no winner):

    >>> import numpy as np
    >>> from moo.tuning import monte_carlo_selection
    >>> E = np.array([[1.0, 3.0, 2.0, np.inf],      # design 0 in simulations 0 to 3
    ...               [2.0, 1.0, 1.0, np.inf],      # design 1
    ...               [0.5, 2.0, 3.0, np.inf]])     # design 2
    >>> res = monte_carlo_selection(E)
    >>> res
    SelectionResult(D=3, S=4, best=1, wins=2, no_winner=1)
    >>> bool(res.counts.sum() == res.n_simulations - res.n_no_winner)
    True
    """

    winners: np.ndarray
    counts: np.ndarray
    best: int

    @property
    def n_designs(self) -> int:
        """Number of candidate designs D."""
        return int(self.counts.size)

    @property
    def n_simulations(self) -> int:
        """Number of simulations (realisations) S."""
        return int(self.winners.size)

    @property
    def n_no_winner(self) -> int:
        """Simulations in which every design's error was infinite."""
        return int(np.count_nonzero(self.winners < 0))

    def ranking(self) -> np.ndarray:
        """Design indices by decreasing win count (equal counts: increasing index)."""
        return np.argsort(-self.counts, kind="stable")

    def __repr__(self) -> str:
        return (f"SelectionResult(D={self.n_designs}, S={self.n_simulations}, best={self.best}, "
                f"wins={int(self.counts[self.best])}, no_winner={self.n_no_winner})")


def _as_errors(errors) -> np.ndarray:
    if isinstance(errors, (str, bytes)) or errors is None:
        raise TypeError(f"errors must be a (designs, simulations) array of numbers, got {type(errors).__name__}")
    try:
        arr = np.asarray(errors, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError("errors must be a (designs, simulations) array of real numbers") from None
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"errors must be a non-empty 2-D array (designs, simulations), got shape {arr.shape}")
    if np.any(np.isnan(arr)) or np.any(arr == -np.inf):
        raise ValueError("errors must not contain NaN or -inf (+inf marks a design that cannot win)")
    return arr


def monte_carlo_selection(errors) -> SelectionResult:
    r"""Count how often each design has the least cumulative error; select the most frequent winner.

    Parameters
    ----------
    errors : (D, S) array_like
        Cumulative errors of ``D`` designs in ``S`` simulations, lower is
        better; finite or ``+inf`` (a design that cannot win, e.g. unstable
        there).

    Returns
    -------
    SelectionResult
        The winner of each simulation, the win counts and the selected design.

    Raises
    ------
    TypeError
        ``errors`` not an array of real numbers.
    ValueError
        ``errors`` not 2-D or empty, containing NaN or ``-inf``, or no
        simulation has a winner.

    See Also
    --------
    select : the whole selection on a tuning problem (draws, errors, count).

    Notes
    -----
    With :math:`E[d, s]` the cumulative error of design :math:`d` in
    simulation :math:`s`,

    .. math::

        w_s = \min \arg\min_d E[d, s], \qquad
        c_d = \#\{s : w_s = d\}, \qquad
        d^* = \min \arg\max_d c_d,

    i.e. ties within a simulation go to the lowest design index, and so do ties
    between win counts. A simulation in which every design is ``+inf`` has no
    winner (``winners[s] = -1``) and counts for nobody.

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Section 4.4.1: "The control
       design with less cumulative error is assigned as the winner for each
       simulation [...] the selection criterium is to choose [...] the most
       frequent individual".

    Examples
    --------
    Design 2 wins simulation 0, design 1 simulations 1 and 2; in simulation 3
    every design is unstable (no winner):

    >>> import numpy as np
    >>> from moo.tuning import monte_carlo_selection
    >>> E = np.array([[1.0, 3.0, 2.0, np.inf],      # design 0 in simulations 0 to 3
    ...               [2.0, 1.0, 1.0, np.inf],      # design 1
    ...               [0.5, 2.0, 3.0, np.inf]])     # design 2
    >>> res = monte_carlo_selection(E)
    >>> res.winners, res.counts, res.best
    (array([ 2,  1,  1, -1]), array([0, 2, 1]), 1)
    """
    E = _as_errors(errors)
    D = E.shape[0]
    winners = np.argmin(E, axis=0)                       # first minimum: lowest index on ties
    winners[~np.isfinite(E.min(axis=0))] = -1
    counts = np.bincount(winners[winners >= 0], minlength=D)
    if counts.sum() == 0:
        raise ValueError("errors: no design has a finite error in any simulation; nothing to select")
    return SelectionResult(winners=winners, counts=counts, best=int(np.argmax(counts)))


def default_weights(F) -> np.ndarray:
    """``1 / (max_d F[d, j] - min_d F[d, j])`` per objective (1 where the spread is zero or not finite)."""
    F = as_float_array(F, "F")
    if F.ndim != 2 or F.shape[0] < 1:
        raise ValueError(f"F must be a non-empty (designs, objectives) array, got shape {F.shape}")
    spread = np.max(F, axis=0) - np.min(F, axis=0)
    return np.where(np.isfinite(spread) & (spread > 0), 1.0 / np.where(spread > 0, spread, 1.0), 1.0)


def check_weights(weights, n_obj: int) -> np.ndarray:
    """``weights`` as ``n_obj`` finite non-negative floats (``ValueError`` naming ``weights`` otherwise)."""
    w = as_float_array(weights, "weights").ravel()
    if w.shape != (n_obj,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError(f"weights must be {n_obj} finite non-negative numbers (one per objective), got {w}")
    if not w.any():
        raise ValueError(f"weights must not all be zero (every design would tie), got {w}")
    return w


def draw_errors(problem, K, n_sims: int, rng: np.random.Generator,
                sampler: Callable[[np.random.Generator], rc.Plant] | None, weights,
                progress: Callable[[int, int], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The (designs, simulations) errors of ``K`` on ``n_sims`` drawn plants, and the draws.

    Each simulation draws a scenario of ``problem`` (its index in ``draws``),
    or a plant from ``sampler(rng)`` (``draws`` -1); every used scenario is
    simulated once (:func:`scenario_errors`, which calls ``progress(done, total)``
    after each plant).
    """
    if sampler is None:
        draws = rng.integers(0, len(problem.scenarios), size=n_sims)
        used = np.unique(draws)
        per = scenario_errors(problem, K, [problem.scenarios[i] for i in used], weights, progress)
        return per[:, np.searchsorted(used, draws)], draws
    if not callable(sampler):
        raise TypeError(f"sampler must be callable as sampler(rng) -> robustctl.Plant, got {type(sampler).__name__}")
    plants = []
    ref = problem.scenarios[0]
    for _ in range(n_sims):
        p = sampler(rng)
        if not isinstance(p, rc.Plant):
            raise TypeError(f"sampler must return a robustctl.Plant, got {type(p).__name__}")
        if (p.n, p.m) != (ref.n, ref.m):
            raise ValueError(f"sampler returned a plant with n={p.n} states and m={p.m} inputs; the scenarios "
                             f"have n={ref.n}, m={ref.m}")
        if p.dt != ref.dt:
            raise ValueError(f"sampler returned a plant with dt={p.dt}; the scenarios have dt={ref.dt}")
        plants.append(p)
    return scenario_errors(problem, K, plants, weights, progress), np.full(n_sims, -1)


def scenario_errors(problem, K, plants: Sequence[rc.Plant], weights,
                    progress: Callable[[int, int], None] | None = None) -> np.ndarray:
    """Cumulative errors (D, P): ``sum_j w_j f_j(K_d, [plant_p])`` of every design on every plant alone.

    ``+inf`` where a design has NaN gains, is unstable on that plant or a goal is not finite there.
    ``progress(done, P)`` is called after each plant.
    """
    K = problem.check_gains(K)
    w = check_weights(weights, problem.n_obj)
    E = np.empty((count(K), len(plants)))
    for p, plant in enumerate(plants):
        F, _ = problem.evaluate_gains(K, [plant])
        with np.errstate(invalid="ignore"):
            e = (np.where(w > 0, F, 0.0) * w).sum(axis=1)
        E[:, p] = np.where(np.isfinite(e), e, np.inf)
        if progress is not None:
            progress(p + 1, len(plants))
    return E


@dataclass(frozen=True, eq=False, repr=False)
class Selection:
    """The design chosen by :func:`select`, with the evidence.

    The fields are attributes of the same names; :attr:`result` is the
    counting result as a :class:`SelectionResult`.

    Parameters
    ----------
    index : int
        Row of the chosen design in the candidates.
    K : (m, n) ndarray or None
        Its gain ``u = K x`` (None for an output feedback: see ``controller``).
    controller : robustctl.Controller
        Its controller (a dynamic one for an output-feedback problem).
    counts : (D,) int ndarray
        Simulations won by each candidate.
    winners : (S,) int ndarray
        Winner of each simulation (-1: none).
    errors : (D, S) ndarray
        Cumulative errors.
    draws : (S,) int ndarray
        Scenario drawn by each simulation (-1 where a sampler drew the plant).
    weights : (n_obj,) ndarray
        Weights of the objectives in the cumulative error.

    See Also
    --------
    select : makes it.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo import tuning
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> scenarios = [rc.Plant(plant.F, plant.G * s, dt=0.1) for s in (0.8, 1.0, 1.2)]
    >>> response = tuning.Response(x0=[1.0, 0.0], steps=50)
    >>> prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios,
    ...                             [response.error(), response.peak_input()])
    >>> K = prob.gains([[0.0, 0.0, 0.0], [0.0, 0.0, -2.0]]).K
    >>> sel = tuning.select(prob, K, n_sims=30, seed=0)
    >>> sel.errors.shape, sel.draws.shape
    ((2, 30), (30,))
    >>> bool(np.all(sel.winners == np.argmin(sel.errors, axis=0)))   # the least error wins
    True
    """

    index: int
    K: np.ndarray | None
    controller: rc.Controller
    counts: np.ndarray
    winners: np.ndarray
    errors: np.ndarray
    draws: np.ndarray
    weights: np.ndarray

    @property
    def result(self) -> SelectionResult:
        """The counting result (:class:`SelectionResult`)."""
        return SelectionResult(winners=self.winners, counts=self.counts, best=self.index)

    def __repr__(self) -> str:
        return (f"Selection(index={self.index}, wins={int(self.counts[self.index])}/{self.winners.size}, "
                f"D={self.counts.size})")


def _rng(seed) -> np.random.Generator:
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"seed must be None, a non-negative integer, a SeedSequence or a Generator ({exc})") from None


def select(problem, K, *, F=None, n_sims: int = 1000, seed=None,
           sampler: Callable[[np.random.Generator], rc.Plant] | None = None, weights=None,
           plant: rc.Plant | None = None, method: str = "tuned",
           progress: Callable[[int, int], None] | None = None) -> Selection:
    r"""The paper's Monte Carlo selection, for any tuning problem (module docstring).

    Parameters
    ----------
    problem : TuningProblem
        The problem whose objectives make the cumulative error.
    K : (D, m, n) array_like or robustctl.ControllerBatch
        Candidate gains (e.g. a front's, ``TuningResult.gains``), or the
        candidate controllers of an output-feedback problem.
    F : (D, n_obj) array_like, optional
        Their objectives, for the default weights (:func:`default_weights`);
        default: evaluated on the problem's scenarios.
    n_sims : int
        Number of simulations ``S``.
    seed : int or numpy Generator-compatible seed
        Seed of the draws.
    sampler : callable, optional
        ``sampler(rng) -> robustctl.Plant``: draw the plant of a simulation
        (same size as the scenarios). Default: a random scenario.
    weights : (n_obj,) array_like, optional
        Weights of the objectives in the cumulative error (default: 1 / the front's spread).
    plant : robustctl.Plant, optional
        The plant of the returned :class:`~robustctl.Controller` (default: the first scenario).
    method : str
        The controller's ``method``.
    progress : callable, optional
        ``progress(done, total)`` after each plant simulated (a drawn scenario, or a sampler's plant).

    Returns
    -------
    Selection
        The chosen design, its controller and the evidence (errors, draws, wins).

    Raises
    ------
    TypeError, ValueError
        Gains of the wrong shape, ``n_sims`` not a positive integer, a bad
        seed, weights not ``n_obj`` non-negative numbers or all zero, a
        sampler that is not callable or returns anything but a plant of the
        scenarios' size and sampling time, no candidate that stabilises every
        scenario (a front that is all penalised), no design with a finite
        error in any simulation.

    See Also
    --------
    monte_carlo_selection : the counting step.
    moo.tuning.TuningResult.select : the same on a tuning run's front.

    Notes
    -----
    Only the candidates that stabilise every scenario of the problem take
    part (the others get ``+inf`` everywhere). Simulation :math:`s` draws a
    plant :math:`P_s`; every design :math:`d` gets the cumulative error

    .. math::

        E[d, s] = \sum_j w_j\, f_j(K_d, [P_s]), \qquad
        w_j = 1 / \big(\max_d F_{dj} - \min_d F_{dj}\big) \text{ (default)},

    ``+inf`` where the design is unstable on :math:`P_s` or a goal is not
    finite; :func:`monte_carlo_selection` then picks the most frequent winner.

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Sections 4.4.1, 4.5.1.

    Examples
    --------
    Between two LQR designs (``R = 1`` and ``R = 0.01``), on draws of the
    problem's scenarios:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo import tuning
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> scenarios = [rc.Plant(plant.F, plant.G * s, dt=0.1) for s in (0.8, 1.0, 1.2)]
    >>> response = tuning.Response(x0=[1.0, 0.0], steps=50)
    >>> prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios,
    ...                             [response.error(), response.peak_input()])
    >>> K = prob.gains([[0.0, 0.0, 0.0], [0.0, 0.0, -2.0]]).K
    >>> sel = tuning.select(prob, K, n_sims=30, seed=0)
    >>> sel.controller.method, int(sel.counts.sum())
    ('tuned', 30)
    >>> sel.index == int(np.argmax(np.bincount(np.argmin(sel.errors, axis=0))))
    True
    """
    Kc = problem.check_gains(K)
    n_sims = check_int(n_sims, "n_sims", 1)
    rng = _rng(seed)
    stable, _ = problem.stability(Kc)
    candidates = stable.all(axis=1)
    if not candidates.any():
        raise ValueError("no candidate stabilises every scenario of the problem (the whole front is penalised): "
                         "nothing to select; tune longer, widen the bounds or revise the goals")
    if weights is None:
        if F is None:
            F, _ = problem.evaluate_gains(Kc)
        Ff = as_float_array(F, "F")
        if Ff.shape != (count(Kc), problem.n_obj):
            raise ValueError(f"F must have shape ({count(Kc)}, {problem.n_obj}) (candidates, objectives), "
                             f"got shape {Ff.shape}")
        use = candidates & np.all(np.isfinite(Ff), axis=1)
        weights = default_weights(Ff[use] if use.any() else Ff[candidates])
    w = check_weights(weights, problem.n_obj)
    E, draws = draw_errors(problem, Kc, n_sims, rng, sampler, w, progress)
    E[~candidates] = np.inf                     # a design unstable on a scenario never wins
    res = monte_carlo_selection(E)
    info = {"selection_wins": int(res.counts[res.best]), "n_sims": n_sims}
    owner = problem.scenarios[0] if plant is None else plant
    if is_output_feedback(Kc):
        one = Kc[res.best]
        Kbest = None
        ctrl = rc.Controller.dynamic(one.Ac, one.Bc, one.Cc, one.Dc, method, owner, info)
    else:
        Kbest = Kc[res.best].copy()
        ctrl = rc.Controller(Kbest, method, owner, info)
    return Selection(index=res.best, K=Kbest, controller=ctrl, counts=res.counts, winners=res.winners,
                     errors=E, draws=draws, weights=w)
