"""One optimisation run: problem and MOEA by name or import path, optional MO-LSP, an evaluation budget.

:func:`prepare` checks every argument and builds the problem and the algorithm
once (a bad argument raises ``ValueError``/``TypeError`` naming it, before any
work); :meth:`PreparedRun.run` then runs it. :func:`run` does both. In detail,
:func:`prepare` builds the problem (:func:`moo.problems.make_problem`, or a
user's factory ``package.module:factory``, see :mod:`moo.factories`) and the
algorithm (:func:`moo.algorithms.make_algorithm`, or a user's factory), wraps it with MO-LSP
(:func:`moo.molsp.molsp`, reference point ``problem.molsp_ref_point``) if
asked, runs it with pymoo's ``("n_eval", evals)`` termination and records the
hypervolume of the non-dominated set after every generation (reference point
``problem.hv_ref_point``).

Budget rule: pymoo stops at the end of the first generation whose evaluation
count reaches ``evals``; the last generation may overshoot by less than one
offspring batch (MO-LSP's mutants never add to the overshoot, see
:mod:`moo.molsp`). ``n_evals`` reports the evaluations actually used.

Randomness: the seed goes to pymoo's ``setup``, which makes the run's only
Generator (``algorithm.random_state``); the global numpy state is not touched.
Same arguments, same result.

The record
----------
:meth:`RunResult.to_dict` is the JSON record that ``python -m moo run`` and
``python -m moo experiment`` write (plain JSON types; arrays as nested lists):

=================  ==========================================================
``problem``        problem name (lower case; an import path as given),
                   ``n_obj`` its objectives
``setup``          the problem's set-up (``applied``: ``"ours"`` or
                   ``"authors"``, see :mod:`moo.problems.applied`); null for
                   problems without one
``algorithm``      registry name (or import path); ``molsp`` true for the
                   MO-LSP version
``max_leaders``    MO-LSP's cap on candidates per generation (null: none)
``seed``           the run's seed
``pop_size``       population size used (reference-direction algorithms
                   may enlarge the one asked for)
``budget``         evaluation budget; ``n_evals`` evaluations used (at
                   most one offspring batch more); ``molsp_evals`` of them
                   spent on MO-LSP mutants
``n_gen``          generations, the initial one included
``hv``             hypervolume of the final set at ``hv_ref_point``
``F``, ``X``       objectives and decision vectors of the final
                   non-dominated set (``|F| x n_obj``, ``|F| x n_var``)
``hv_ref_point``   hypervolume reference point; ``molsp_ref_point`` MO-LSP's
                   (null for a plain run)
``hv_history``     ``{"evaluations": [...], "hypervolume": [...]}`` after
                   every generation
``wall_time_s``    seconds spent in the run
``versions``       Python and package versions
``run_index``      (experiment records only) the run's index in the grid
=================  ==========================================================
"""

from __future__ import annotations

import copy
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib.metadata import PackageNotFoundError, version

import moocore
import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.callback import Callback
from pymoo.core.problem import Problem

from moo.algorithms.operators import POP_SIZE
from moo.factories import build_algorithm, build_problem, check_algorithm_name, check_problem_name
from moo.indicators import hypervolume
from moo.molsp import molsp as add_molsp
from moo.validation import check_int

__all__ = ["RunResult", "PreparedRun", "prepare", "prepare_on", "run", "check_budget", "setup_name"]


def _versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for dist in ("robustctl", "numpy", "scipy", "pymoo", "moocore"):
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            out[dist] = "unknown"
    return out


@dataclass(frozen=True, repr=False)
class RunResult:
    """The record of one run (see :func:`run`); :meth:`~RunResult.to_dict` gives its JSON form.

    The fields are the keys of the record, documented in the table of the
    module docstring ("The record"), with ``wall_time`` for ``wall_time_s``.
    ``F``/``X`` are the objectives and decision vectors of the final
    non-dominated set (of the final population together with the algorithm's
    ``opt``, finite and feasible individuals only, duplicates in objective
    space removed); ``hv_history`` is an ``(n_gen, 2)`` array of
    (evaluations used, hypervolume) after each generation, the initial one
    included; ``hv`` its last hypervolume.
    """

    problem: str
    n_obj: int
    algorithm: str
    molsp: bool
    max_leaders: int | None
    seed: int
    pop_size: int
    budget: int
    n_evals: int
    n_gen: int
    molsp_evals: int
    F: np.ndarray
    X: np.ndarray
    hv_ref_point: np.ndarray
    molsp_ref_point: np.ndarray | None
    hv_history: np.ndarray
    wall_time: float
    versions: dict[str, str] = field(default_factory=dict)
    setup: str | None = None

    @property
    def hv(self) -> float:
        """Hypervolume of the final non-dominated set."""
        return float(self.hv_history[-1, 1])

    def to_dict(self) -> dict:
        """Plain Python types only (lists for arrays), ready for ``json.dump``."""
        return {
            "problem": self.problem, "n_obj": self.n_obj, "setup": self.setup, "algorithm": self.algorithm,
            "molsp": self.molsp, "max_leaders": self.max_leaders, "seed": self.seed,
            "pop_size": self.pop_size, "budget": self.budget, "n_evals": self.n_evals,
            "n_gen": self.n_gen, "molsp_evals": self.molsp_evals, "hv": self.hv,
            "hv_ref_point": self.hv_ref_point.tolist(),
            "molsp_ref_point": None if self.molsp_ref_point is None else self.molsp_ref_point.tolist(),
            "F": self.F.tolist(), "X": self.X.tolist(),
            "hv_history": {"evaluations": self.hv_history[:, 0].astype(int).tolist(),
                           "hypervolume": self.hv_history[:, 1].tolist()},
            "wall_time_s": self.wall_time, "versions": dict(self.versions),
        }

    def __repr__(self) -> str:
        tag = "+MO-LSP" if self.molsp else ""
        return (f"RunResult({self.algorithm}{tag} on {self.problem} (M={self.n_obj}), seed={self.seed}, "
                f"n_evals={self.n_evals}/{self.budget}, n_gen={self.n_gen}, |F|={len(self.F)}, "
                f"hv={self.hv:.6g}, {self.wall_time:.2f} s)")


def _stacked(algorithm, key: str) -> np.ndarray:
    """``Population.merge(pop, opt).get(key)`` as float rows, read by attribute and without the merge."""
    parts = [pop for pop in (algorithm.pop, algorithm.opt) if pop is not None and len(pop)]
    return np.concatenate([np.asarray([getattr(ind, key) for ind in pop], dtype=float).reshape(len(pop), -1)
                           for pop in parts])


def _front_rows(algorithm) -> tuple[np.ndarray, np.ndarray]:
    """Objectives of the non-dominated set of population + ``opt``, and their rows in :func:`_stacked`.

    Only individuals with finite objectives (and feasible ones, for constrained
    problems) count; of duplicate objective vectors the first is kept.
    """
    F = _stacked(algorithm, "F")
    keep = np.all(np.isfinite(F), axis=1)
    if algorithm.problem.has_constraints():
        keep &= _stacked(algorithm, "FEAS").astype(bool).ravel()
    rows = np.flatnonzero(keep)
    if rows.size:
        rows = rows[moocore.is_nondominated(F[rows], keep_weakly=False)]
    return F[rows], rows


def _front(algorithm) -> tuple[np.ndarray, np.ndarray]:
    """Objectives and decisions of the non-dominated set of population + ``opt`` (see :func:`_front_rows`)."""
    F, rows = _front_rows(algorithm)
    return F, _stacked(algorithm, "X")[rows]


class _HVHistory(Callback):
    def __init__(self, ref_point: np.ndarray, progress: Callable[[int, int], None] | None, budget: int):
        super().__init__()
        self.ref_point, self.progress, self.budget = ref_point, progress, budget
        self.rows: list[tuple[int, float]] = []

    def notify(self, algorithm):
        n_eval = algorithm.evaluator.n_eval
        F, _ = _front_rows(algorithm)
        hv = hypervolume(F, self.ref_point) if len(F) else 0.0
        self.rows.append((n_eval, hv))
        if self.progress is not None:
            self.progress(n_eval, self.budget)


def check_budget(problem, algorithm: str, *, evals: int, pop_size: int = POP_SIZE):
    """The algorithm ``algorithm`` built for ``problem`` (a pymoo problem).

    Raises ``ValueError`` if ``evals`` is below the population size it uses.
    """
    alg = build_algorithm(algorithm, n_obj=problem.n_obj, pop_size=pop_size)
    if evals < alg.pop_size:
        raise ValueError(f"evals must be at least the population size of {algorithm} ({alg.pop_size}), "
                         f"got {evals}")
    return alg


@dataclass(frozen=True, repr=False)
class PreparedRun:
    """A run whose arguments are checked and whose problem and algorithm are built (see :func:`prepare`)."""

    problem_name: str
    algorithm_name: str
    seed: int
    evals: int
    molsp: bool
    max_leaders: int | None
    problem: Problem
    algorithm: Algorithm
    setup: str | None = None

    def __repr__(self) -> str:
        tag = "+molsp" if self.molsp else ""
        return (f"PreparedRun({self.algorithm_name}{tag} on {self.problem_name} (M={self.problem.n_obj}), "
                f"seed={self.seed}, evals={self.evals})")

    def run(self, progress: Callable[[int, int], None] | None = None) -> RunResult:
        """Run it (on a copy of the algorithm, so a prepared run can be run again: same result).

        ``progress`` is called as ``progress(n_evals, evals)`` after every generation.
        """
        prob, alg = self.problem, copy.deepcopy(self.algorithm)
        hv_ref = np.asarray(prob.hv_ref_point, dtype=float)
        history = _HVHistory(hv_ref, progress, self.evals)
        start = time.perf_counter()
        alg.setup(prob, termination=("n_eval", self.evals), seed=self.seed, callback=history, verbose=False)
        while alg.has_next():
            alg.next()
        wall = time.perf_counter() - start

        F, X = _front(alg)
        molsp_ref = np.asarray(prob.molsp_ref_point, dtype=float) if self.molsp else None
        return RunResult(
            problem=self.problem_name, n_obj=prob.n_obj, algorithm=self.algorithm_name, molsp=self.molsp,
            max_leaders=self.max_leaders, seed=self.seed, pop_size=int(alg.pop_size), budget=self.evals,
            n_evals=int(alg.evaluator.n_eval), n_gen=len(history.rows),
            molsp_evals=int(alg.data.get("molsp_n_eval", 0)), F=F, X=X, hv_ref_point=hv_ref,
            molsp_ref_point=molsp_ref, hv_history=np.array(history.rows, dtype=float).reshape(-1, 2),
            wall_time=wall, versions=_versions(), setup=self.setup)


def setup_name(problem) -> str | None:
    """The name of a built problem's set-up (``problem.setup.name``), None for problems without one."""
    return getattr(getattr(problem, "setup", None), "name", None)


def prepare(problem: str, algorithm: str, *, seed: int, evals: int, n_obj: int | None = None,
            molsp: bool = False, pop_size: int = POP_SIZE, max_leaders: int | None = None,
            setup: str | None = None) -> PreparedRun:
    """Check the arguments of one run and build its problem and algorithm (once).

    Parameters
    ----------
    problem : str
        A name of :data:`moo.problems.PROBLEMS`, or the import path
        ``package.module:factory`` of a user's problem factory
        (:mod:`moo.factories`: called with no argument, or ``n_obj=``).
    algorithm : str
        A name of :data:`moo.algorithms.ALGORITHMS`, or the import path of a
        user's algorithm factory, called as ``factory(n_obj=M, pop_size=P)``.
    seed : int
        Non-negative seed of the run's Generator.
    evals : int
        Evaluation budget; at least the population size.
    n_obj : int, optional
        Number of objectives (DTLZ; fixed for the others).
    molsp : bool
        Wrap the algorithm with MO-LSP (reference point ``problem.molsp_ref_point``).
    pop_size : int
        Population size (the paper's 92, :data:`moo.algorithms.operators.POP_SIZE`,
        by default; reference-direction algorithms may enlarge it, the size
        used is recorded).
    max_leaders : int, optional
        MO-LSP's cap on candidates per generation (default: none, the paper's).
    setup : str, optional
        The problem's set-up (``applied`` only: ``"ours"``, the default, or
        ``"authors"``); recorded as ``setup``.

    Returns
    -------
    PreparedRun

    Raises
    ------
    ValueError, TypeError
        A bad argument (the message names it).
    NotImplementedError
        A registered problem or algorithm whose module is not available.
    """
    problem_key, algorithm_key = check_problem_name(problem), check_algorithm_name(algorithm)
    options = _run_options(seed, evals, pop_size, molsp, max_leaders)
    return _prepared(build_problem(problem_key, n_obj, setup=setup), problem_key, algorithm_key, *options)


def _run_options(seed, evals, pop_size, molsp, max_leaders) -> tuple[int, int, int, bool, int | None]:
    seed = check_int(seed, "seed", 0)
    evals = check_int(evals, "evals", 1)
    pop_size = check_int(pop_size, "pop_size", 4)
    if not isinstance(molsp, (bool, np.bool_)):
        raise TypeError(f"molsp must be a bool, got {type(molsp).__name__}")
    if max_leaders is not None:
        max_leaders = check_int(max_leaders, "max_leaders", 1)
        if not molsp:
            raise ValueError("max_leaders needs molsp=True")
    return seed, evals, pop_size, bool(molsp), max_leaders


def prepare_on(problem, problem_name: str, algorithm: str, *, seed: int, evals: int, molsp: bool = False,
               pop_size: int = POP_SIZE, max_leaders: int | None = None) -> PreparedRun:
    """:func:`prepare` for a problem already built (a pymoo problem with ``hv_ref_point``/``molsp_ref_point``).

    ``problem_name`` is what the record calls it (``moo.tuning.tune`` runs a
    :class:`~moo.tuning.TuningProblem` as ``"tuning"``); the other arguments
    are those of :func:`prepare`, checked the same way.
    """
    return _prepared(problem, problem_name, check_algorithm_name(algorithm),
                     *_run_options(seed, evals, pop_size, molsp, max_leaders))


def _prepared(problem, problem_name: str, algorithm_key: str, seed: int, evals: int, pop_size: int, molsp: bool,
              max_leaders: int | None) -> PreparedRun:
    """The run of checked options: the algorithm built for ``problem`` (MO-LSP around it if asked)."""
    alg = check_budget(problem, algorithm_key, evals=evals, pop_size=pop_size)
    if molsp:
        alg = add_molsp(alg, ref_point=np.asarray(problem.molsp_ref_point, dtype=float), max_leaders=max_leaders)
    return PreparedRun(problem_name=problem_name, algorithm_name=algorithm_key, seed=seed, evals=evals,
                       molsp=molsp, max_leaders=max_leaders, problem=problem, algorithm=alg,
                       setup=setup_name(problem))


def run(problem: str, algorithm: str, *, seed: int, evals: int, n_obj: int | None = None,
        molsp: bool = False, pop_size: int = POP_SIZE, max_leaders: int | None = None,
        progress: Callable[[int, int], None] | None = None, setup: str | None = None) -> RunResult:
    """Run one MOEA (optionally with MO-LSP) on one problem to an evaluation budget.

    :func:`prepare` checks the arguments and builds the problem and the
    algorithm; :meth:`PreparedRun.run` runs it. This is the run
    ``python -m moo run`` makes.

    Parameters
    ----------
    problem : str
        A name of :data:`moo.problems.PROBLEMS`, or the import path
        ``package.module:factory`` of a user's problem factory
        (:mod:`moo.factories`: called with no argument, or ``n_obj=``).
    algorithm : str
        A name of :data:`moo.algorithms.ALGORITHMS`, or the import path of a
        user's algorithm factory, called as ``factory(n_obj=M, pop_size=P)``.
    seed : int
        Non-negative seed of the run's Generator (same arguments, same result).
    evals : int
        Evaluation budget; at least the population size.
    n_obj : int, optional
        Number of objectives (DTLZ, WFG; fixed for the others).
    molsp : bool
        Wrap the algorithm with MO-LSP (reference point ``problem.molsp_ref_point``).
    pop_size : int
        Population size (the paper's 92 by default; reference-direction
        algorithms may enlarge it, the size used is recorded).
    max_leaders : int, optional
        MO-LSP's cap on candidates per generation (default: none, the paper's).
    progress : callable, optional
        Called as ``progress(n_evals, evals)`` after every generation.
    setup : str, optional
        The problem's set-up (``applied`` only: ``"ours"``, the default, or
        ``"authors"``).

    Returns
    -------
    RunResult
        The run's record; :meth:`RunResult.to_dict` is its JSON form (the
        table of its keys is in the module docstring).

    Raises
    ------
    ValueError, TypeError
        A bad argument (the message names it), raised before any work.
    NotImplementedError
        A registered problem or algorithm whose module is not available.

    See Also
    --------
    prepare : check and build once, run several times.
    moo.run_experiment : a resumable grid of runs.
    moo.tune : a run on a :class:`~moo.tuning.TuningProblem`.

    Notes
    -----
    pymoo stops at the end of the first generation whose evaluation count
    reaches ``evals``; ``n_evals`` reports the evaluations used. The
    hypervolume of the non-dominated set is recorded after every generation
    (reference point ``problem.hv_ref_point``).

    Examples
    --------
    >>> import numpy as np
    >>> import moo
    >>> res = moo.run("dtlz2", "nsga2", n_obj=2, seed=0, evals=500, pop_size=20)
    >>> res.n_evals, res.F.shape[1]
    (500, 2)
    >>> bool(np.isclose(res.hv, moo.hypervolume(res.F, res.hv_ref_point)))
    True
    """
    return prepare(problem, algorithm, seed=seed, evals=evals, n_obj=n_obj, molsp=molsp, pop_size=pop_size,
                   max_leaders=max_leaders, setup=setup).run(progress)
