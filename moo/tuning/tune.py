"""Tune: run a MOEA (with MO-LSP by default) on a :class:`~moo.tuning.TuningProblem` and keep its front.

:func:`tune` goes through the project's runner (:mod:`moo.runner`: the
algorithm registry :func:`moo.algorithms.make_algorithm`, MO-LSP
:func:`moo.molsp.molsp` with the problem's ``molsp_ref_point``, the
hypervolume history at ``hv_ref_point``), so a tuning run is the same run
``python -m moo run`` makes, and :class:`TuningResult` holds its record.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import robustctl as rc

from ..algorithms.operators import POP_SIZE
from ..progress import ProgressBar, check_progress, front_summary
from ..runner import RunResult, prepare_on
from ..validation import as_float_array, check_int
from .problem import TuningProblem
from .selection import Selection, select

__all__ = ["tune", "TuningResult", "select_front", "design_plant"]


def _method(family) -> str:
    name = type(family).__name__
    return {"RLQRFamily": "rlqr", "LQRFamily": "lqr", "StaticOutputFeedbackFamily": "static output feedback",
            "PIDFamily": "pid", "FixedOrderFamily": "fixed order", "LQGFamily": "lqg",
            "RobustLQGFamily": "rlqg"}.get(name, "tuned")


def design_plant(problem: TuningProblem) -> rc.Plant:
    """The family's design plant (``family.plant``), else the first scenario."""
    plant = getattr(problem.family, "plant", None)
    return plant if isinstance(plant, rc.Plant) else problem.scenarios[0]


def select_front(problem: TuningProblem, X, F=None, *, n_sims: int = 1000, seed=None,
                 sampler: Callable[[np.random.Generator], rc.Plant] | None = None, weights=None,
                 progress: Callable[[int, int], None] | None = None) -> Selection:
    """The Monte Carlo selection (:func:`moo.tuning.selection.select`) of one design of a front ``X``.

    What :meth:`TuningResult.select` does, for decision vectors from anywhere
    (e.g. a run record's ``X``, as ``python -m moo select`` reads them): the
    gains are ``problem.gains(X).K``, the controller's plant is the family's
    ``plant`` (else the first scenario) and its method the family's
    (``"rlqr"``, ``"lqr"``, else ``"tuned"``).

    Parameters
    ----------
    problem : TuningProblem
        The problem the front belongs to.
    X : (N, n_var) array_like
        Decision vectors of the front (N >= 1).
    F : (N, n_obj) array_like, optional
        Their objectives (for the default weights; default: evaluated).
    n_sims, seed, sampler, weights, progress
        As in :func:`moo.tuning.selection.select`.

    Returns
    -------
    Selection
        Its ``index`` is a row of ``X``.

    Raises
    ------
    TypeError
        ``problem`` not a :class:`TuningProblem`.
    ValueError
        An empty front, ``X`` of the wrong shape, bad selection arguments.

    See Also
    --------
    moo.tuning.select : the selection itself, on gains.
    TuningResult.select : the same on a tuning run's front.

    Examples
    --------
    Two LQR designs (``Q = I``, ``R = 1`` and ``R = 0.01``):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo import tuning
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> scenarios = [rc.Plant(plant.F, plant.G * s, dt=0.1) for s in (0.8, 1.0, 1.2)]
    >>> response = tuning.Response(x0=[1.0, 0.0], steps=50)
    >>> prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios,
    ...                             [response.error(), response.peak_input()])
    >>> sel = tuning.select_front(prob, [[0.0, 0.0, 0.0], [0.0, 0.0, -2.0]], n_sims=20, seed=0)
    >>> sel.controller.method, int(sel.counts.sum())
    ('lqr', 20)
    >>> R = [1.0, 0.01][sel.index]                  # the chosen row's weight
    >>> np.allclose(sel.K, rc.lqr(plant, Q=np.eye(2), R=[[R]]).K)
    True
    """
    if not isinstance(problem, TuningProblem):
        raise TypeError(f"problem must be a moo.tuning.TuningProblem, got {type(problem).__name__}")
    if len(X) == 0:
        raise ValueError("the front is empty (no design stabilised every scenario): nothing to select")
    X = problem.population(X, "X")
    return select(problem, problem.designs(X)[0], F=F, n_sims=n_sims, seed=seed, sampler=sampler, weights=weights,
                  plant=design_plant(problem), method=_method(problem.family), progress=progress)


@dataclass(frozen=True, eq=False, repr=False)
class TuningResult:
    """The front of a tuning run (what :func:`tune` returns).

    Parameters
    ----------
    problem : TuningProblem
        The problem tuned.
    X : (N, n_var) ndarray
        Decision vectors of the final non-dominated set.
    F : (N, n_obj) ndarray
        Their objectives.
    run : moo.runner.RunResult
        The run's record (hypervolume history, evaluations, wall time; ``run.to_dict()`` is JSON).

    Attributes
    ----------
    gains : (N, m, n) ndarray
        The front's gains (designed once, on first use).

    See Also
    --------
    tune : makes it.
    select_front : the selection behind :meth:`select`.

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
    >>> res = tuning.tune(prob, evals=400, seed=1, pop_size=20)
    >>> res
    TuningResult(front=..., n_obj=2, evaluations=400, hv=...)
    >>> stable, _ = prob.stability(res.gains)        # every front design stabilises every scenario
    >>> bool(stable.all())
    True
    """

    problem: TuningProblem
    X: np.ndarray
    F: np.ndarray
    run: RunResult

    @functools.cached_property
    def gains(self) -> np.ndarray | rc.ControllerBatch:
        """The front's designs, computed once.

        Gains (N, m, n) (``u = K x``; NaN rows: failed designs), or the
        :class:`robustctl.ControllerBatch` of an output-feedback family.
        """
        K = self.problem.designs(self.X)[0]
        if isinstance(K, np.ndarray):
            K.flags.writeable = False
        return K

    def _plant(self) -> rc.Plant:
        return design_plant(self.problem)

    def controllers(self) -> list[rc.Controller]:
        """One :class:`robustctl.Controller` per front design (its ``info`` holds ``z`` and the objectives).

        A front design whose gain could not be computed (only possible when no
        design of the run was acceptable, so the front holds penalised ones) is left out.
        """
        method, plant = _method(self.problem.family), self._plant()
        K = self.gains
        if isinstance(K, rc.ControllerBatch):
            mats = [(K.Ac[i], K.Bc[i], K.Cc[i], K.Dc[i]) for i in range(len(K))]
            return [rc.Controller.dynamic(*M, method, plant, {"z": x.copy(), "objectives": f.copy()})
                    for M, x, f in zip(mats, self.X, self.F, strict=True) if all(np.isfinite(a).all() for a in M)]
        return [rc.Controller(k, method, plant, {"z": x.copy(), "objectives": f.copy()})
                for k, x, f in zip(K, self.X, self.F, strict=True) if np.all(np.isfinite(k))]

    def select(self, *, n_sims: int = 1000, seed=None, sampler: Callable[[np.random.Generator], rc.Plant] | None = None,
               weights=None) -> Selection:
        """Pick one front design by the Monte Carlo selection (:func:`moo.tuning.selection.select`).

        ``index`` of the returned :class:`~moo.tuning.selection.Selection` is a row of ``X``/``F``.
        """
        return select_front(self.problem, self.X, self.F, n_sims=n_sims, seed=seed, sampler=sampler,
                            weights=weights)

    def plot(self, selection: Selection | None = None, *, x0=None, steps: int = 50):
        """Figure: the front (pairwise objectives) and a design's closed-loop response on every scenario.

        Parameters
        ----------
        selection : Selection, optional
            The design to show (default: ``self.select(n_sims=200, seed=0)``).
        x0 : (n,) array_like, optional
            Initial state of the response (default: all ones).
        steps : int
            Samples of the response.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        if selection is None:
            selection = self.select(n_sims=200, seed=0)
        steps = check_int(steps, "steps", 1)
        n = self.problem.n_states
        x = np.ones(n) if x0 is None else as_float_array(x0, "x0")
        if x.shape != (n,) or not np.all(np.isfinite(x)):
            raise ValueError(f"x0 must have {n} entries (the number of states), got shape {x.shape}")
        fig, (ax_f, ax_r) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
        F = self.F
        j = 1 if F.shape[1] > 1 else 0
        ax_f.scatter(F[:, 0], F[:, j], s=12, label="front")
        ax_f.scatter(F[selection.index, 0], F[selection.index, j], s=60, marker="*", color="C3", label="selected")
        ax_f.set_xlabel(self.problem.objective_names[0])
        ax_f.set_ylabel(self.problem.objective_names[j])
        ax_f.set_title("front")
        ax_f.legend()
        chosen = selection.controller.as_batch() if selection.K is None else selection.K[None]
        A = self.problem.closed_loops(chosen)[0]                    # (S, N, N): states (x, xc)
        traj = np.zeros((A.shape[0], steps + 1, A.shape[-1]))
        traj[:, 0, :n] = x
        for k in range(steps):
            traj[:, k + 1] = np.einsum("sij,sj->si", A, traj[:, k])
        for s in range(A.shape[0]):
            for i in range(n):
                ax_r.plot(traj[s, :, i], color=f"C{i}", alpha=0.6, label=f"x{i + 1}" if s == 0 else None)
        ax_r.set_xlabel("step k")
        ax_r.set_title(f"selected design {selection.index}: response on {A.shape[0]} scenarios")
        ax_r.legend()
        return fig

    @property
    def hv_reference(self) -> str:
        """Where the hypervolume's reference point comes from (the problem's ``hv_ref_source``)."""
        return str(getattr(self.problem, "hv_ref_source", "given"))

    def summary(self, where: str | None = None) -> str:
        """One line: front size, hypervolume and its reference, best value per goal (and ``where`` it was written)."""
        return front_summary(self.F, self.problem.objective_names, self.run.hv, self.hv_reference, where)

    def __repr__(self) -> str:
        return (f"TuningResult(front={len(self.X)}, n_obj={self.F.shape[1]}, evaluations={self.run.n_evals}, "
                f"hv={self.run.hv:.6g} (reference: {self.hv_reference}))")


def tune(problem: TuningProblem, algorithm: str | None = None, *, molsp: bool = True, evals: int = 10000,
         seed: int = 0, pop_size: int | None = None, max_leaders: int | None = None,
         progress: bool | Callable[[int, int], None] = False) -> TuningResult:
    """Tune: one MOEA run on ``problem``, optionally with MO-LSP; the final non-dominated set.

    The run is the one ``python -m moo run`` makes (:mod:`moo.runner`), on a
    :class:`TuningProblem` recorded as ``"tuning"``. Other pymoo problems run
    through :func:`moo.runner.prepare_on` (any problem carrying
    ``hv_ref_point`` and ``molsp_ref_point``) or :func:`moo.run` (a
    registered name or a factory's import path); their front has no gains.

    Parameters
    ----------
    problem : TuningProblem
        The problem to tune.
    algorithm : str, optional
        A name of :data:`moo.algorithms.ALGORITHMS` or
        :data:`moo.algorithms.MORE_ALGORITHMS`; default ``"nsga2"``, or
        ``"ga"`` for a problem with one objective. The names
        (:data:`moo.algorithms.ALGORITHM_NOTES`):

        * ``"nsga2"`` - NSGA-II with the paper's operators (SBX pc 1, eta 20;
          polynomial mutation with 0.5 expected mutated variables, eta 20),
          not pymoo's defaults;
        * ``"pymoo-nsga2"`` - pymoo's own NSGA-II with pymoo's default
          operators (SBX pc 0.9, eta 15; mutation rate 1/n, eta 20);
        * ``"ga"`` - a single-objective genetic algorithm (pymoo's GA with
          the paper's operators), for a problem with one objective;
        * ``"nsga3"``, ``"theta-dea"``, ``"mombi2"``, ``"moea-igd-ns"``,
          ``"efr-rr"``, ``"maoea-ddfc"``, ``"spea-r"``, ``"spea2-sde"``,
          ``"bige"`` - the other MOEAs of the paper's study, each with the
          paper's operators.
    molsp : bool
        Add the MO-LSP local search (reference point ``problem.molsp_ref_point``).
    evals : int
        Evaluation budget (at least the population size).
    seed : int
        Seed of the run (same seed, same result).
    pop_size : int, optional
        Population size (default the paper's 92).
    max_leaders : int, optional
        MO-LSP's cap on leaders per generation.
    progress : bool or callable
        ``True``: a progress bar on stderr and one summary line at the end
        (:meth:`TuningResult.summary`), when stderr is a terminal (silent
        otherwise); a callable: ``progress(n_evals, evals)`` after every
        generation; ``False`` (default): nothing.

    Returns
    -------
    TuningResult
        The front (``X``, ``F``, ``gains``) and the run's record.

    Raises
    ------
    TypeError
        ``problem`` not a :class:`TuningProblem`, ``progress`` neither a bool
        nor a callable, or a run argument of the wrong type (the message names it).
    ValueError
        A bad run argument (the message names it): an unknown algorithm, a
        multiobjective one for a problem of one objective (the message names
        ``"ga"``), a budget below the population size, a negative seed, ...

    See Also
    --------
    TuningProblem : the problem.
    TuningResult.select : pick one design of the front.
    moo.run : a run on a problem by name.

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304.

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
    >>> res = tuning.tune(prob, "nsga2", evals=400, seed=1, pop_size=20)
    >>> res.run.n_evals, res.gains.shape[1:]
    (400, (1, 2))
    >>> sel = res.select(n_sims=50, seed=0)
    >>> bool(np.all(np.abs(np.linalg.eigvals(plant.F + plant.G @ sel.K)) < 1))
    True
    """
    if not isinstance(problem, TuningProblem):
        raise TypeError(f"problem must be a moo.tuning.TuningProblem, got {type(problem).__name__}")
    progress = check_progress(progress)
    if algorithm is None:
        algorithm = "ga" if problem.n_obj == 1 else "nsga2"
    job = prepare_on(problem, "tuning", algorithm, seed=seed, evals=evals, molsp=molsp,
                     pop_size=POP_SIZE if pop_size is None else pop_size, max_leaders=max_leaders)
    if progress is not True:
        record = job.run(progress if callable(progress) else None)
        return TuningResult(problem=problem, X=record.X, F=record.F, run=record)
    with ProgressBar(f"{job.algorithm_name}{'+molsp' if molsp else ''}", unit="evals", total=evals) as bar:
        record = job.run(bar)
    res = TuningResult(problem=problem, X=record.X, F=record.F, run=record)
    if bar.enabled:
        print(res.summary(), file=sys.stderr)
    return res
