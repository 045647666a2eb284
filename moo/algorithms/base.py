"""The base of the MOEAs of :mod:`moo.algorithms` and the pieces their modules share.

Package-internal: the algorithm modules import it; :mod:`moo.algorithms` does
not re-export it (only :data:`MIN_POP_SIZE`).

- :class:`MOEA`: a pymoo ``GeneticAlgorithm`` wired as every MOEA of the
  package (a survival and a mating selection injected, the paper's operators
  by default, the initial population ranked by the survival, reference
  directions checked and the survival's state reset when a run is set up).
- :func:`paper_operators`: the paper's default variation operators and
  output, filled in where a constructor argument is ``None``.
- :class:`NormalizationForwarding`: a survival's public view of the
  :class:`~moo.algorithms.normalization.HyperplaneNormalization` it holds.
- :class:`BinaryTournament`: binary tournament *with replacement*, decided by
  a comparison function.
- :func:`check_ref_dirs_fit`: reference directions must match the problem's
  number of objectives.
- :func:`float_column`: a per-individual attribute read from a population,
  with the entries never set filled in; :func:`objectives`: the objective
  vectors of a population, read by attribute.
- :func:`factory_arguments`, :func:`factory_ref_dirs`: the checks every
  registry factory makes (the shape documented in :mod:`moo.algorithms`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.core.crossover import Crossover
from pymoo.core.mutation import Mutation
from pymoo.core.sampling import Sampling
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.util.display.multi import MultiObjectiveOutput
from pymoo.util.display.output import Output

from ..validation import check_choice, check_directions, check_int
from .operators import (
    OPERATOR_CHOICES,
    PAPER_OPERATORS,
    OperatorSettings,
    paper_crossover,
    paper_mutation,
    reference_directions,
    variation_operators,
)

if TYPE_CHECKING:
    from .normalization import HyperplaneNormalization

__all__ = ["MOEA", "BinaryTournament", "MIN_POP_SIZE", "NormalizationForwarding", "check_ref_dirs_fit",
           "factory_arguments", "factory_ref_dirs", "float_column", "objectives", "paper_operators"]

#: Smallest population a registry factory accepts.
MIN_POP_SIZE = 4


def factory_arguments(n_obj, pop_size, operators, original: OperatorSettings) -> tuple[int, int, dict]:
    """Check the arguments every registry factory takes.

    Returns ``n_obj`` and ``pop_size`` as ints and the ``crossover`` /
    ``mutation`` keyword arguments of the chosen ``operators``: ``"paper"``
    (:data:`~moo.algorithms.operators.PAPER_OPERATORS`), ``"original"``
    (``original``, the algorithm's own paper) or an
    :class:`~moo.algorithms.operators.OperatorSettings`. ``TypeError`` for
    a value of the wrong kind, ``ValueError`` for one out of range.
    """
    n_obj = check_int(n_obj, "n_obj", 2)
    pop_size = check_int(pop_size, "pop_size", MIN_POP_SIZE)
    if not isinstance(operators, OperatorSettings):
        operators = PAPER_OPERATORS if check_choice(operators, "operators", OPERATOR_CHOICES) == "paper" else original
    return n_obj, pop_size, variation_operators(operators)


def factory_ref_dirs(ref_dirs, n_obj: int, pop_size: int) -> np.ndarray:
    """``ref_dirs`` checked against ``n_obj``, or the project's default directions when None."""
    if ref_dirs is None:
        return reference_directions(n_obj, pop_size)
    W = check_directions(ref_dirs)
    if W.shape[1] != n_obj:
        raise ValueError(f"ref_dirs must have {n_obj} columns (n_obj), got shape {W.shape}")
    return W


def paper_operators(sampling=None, crossover=None, mutation=None, output=None) -> dict:
    """Keyword arguments ``sampling``, ``crossover``, ``mutation``, ``output`` of a pymoo algorithm.

    Each one given is kept; each ``None`` becomes the paper's default: uniform
    random sampling in the box, :func:`~moo.algorithms.operators.paper_crossover`
    (SBX, pc = 1, eta 20), :func:`~moo.algorithms.operators.paper_mutation`
    (polynomial, 0.5 expected mutations, eta 20) and pymoo's
    ``MultiObjectiveOutput``.
    """
    return {
        "sampling": sampling if sampling is not None else FloatRandomSampling(),
        "crossover": crossover if crossover is not None else paper_crossover(),
        "mutation": mutation if mutation is not None else paper_mutation(),
        "output": output if output is not None else MultiObjectiveOutput(),
    }


def check_ref_dirs_fit(ref_dirs, problem) -> None:
    """Raise ``ValueError`` unless ``ref_dirs`` has one column per objective of ``problem``."""
    if ref_dirs.shape[1] != problem.n_obj:
        raise ValueError(f"ref_dirs has {ref_dirs.shape[1]} columns but the problem has {problem.n_obj} objectives")


def float_column(values, fill: float) -> np.ndarray:
    """``values`` (``pop.get(name)``, one per individual) as float64 ``(n,)``, ``None`` entries as ``fill``.

    pymoo stores an attribute never set on an individual as ``None`` (an object
    array); a 2-D attribute such as ``CV`` gives its first column.
    """
    arr = np.asarray(values)
    if arr.dtype == object:
        arr = np.where(np.equal(arr, np.array(None)), fill, arr)
    return arr.astype(float).reshape(len(arr), -1)[:, 0]


def objectives(pop) -> np.ndarray:
    """``pop.get("F")`` as float64, read as ``Individual.F`` (the same array, several times faster).

    ``Population.get`` looks each attribute up through ``Individual.get``; on the
    small problems of the paper that lookup was a tenth of a survival's time.
    """
    return np.array([ind.F for ind in pop], dtype=float)


class NormalizationForwarding:
    """Mixin for a survival holding a :class:`~moo.algorithms.normalization.HyperplaneNormalization` in ``self.norm``.

    Exposes its ideal and nadir estimates, its ``normalize`` and its ``reset``.
    """

    norm: HyperplaneNormalization

    @property
    def ideal_point(self) -> np.ndarray:
        """The ideal point ``z*`` estimated so far."""
        return self.norm.ideal_point

    @property
    def nadir_point(self) -> np.ndarray | None:
        """The nadir estimate ``z^nad`` (None before the first update)."""
        return self.norm.nadir_point

    def normalize(self, F: np.ndarray) -> np.ndarray:
        """``(F - z*) / (z^nad - z*)`` with the current estimates (update first)."""
        return self.norm.normalize(F)

    def reset(self) -> None:
        """Forget the normalisation state (a new run starts)."""
        self.norm.reset()


class BinaryTournament(Selection):
    """Binary tournament *with replacement*: ``n_select * n_parents`` pairs drawn uniformly.

    Parameters
    ----------
    compare : callable
        ``compare(pop, P, random_state=rng) -> (n, 1) int array``: the winner of
        each pair ``P[t] = (a, b)`` of population indices. It sees all pairs
        of a call at once (so estimates over the population are made once).
    """

    def __init__(self, compare: Callable[..., np.ndarray]) -> None:
        super().__init__()
        self.compare = compare

    def _do(self, problem, pop, n_select, n_parents, *args, random_state=None, **kwargs):
        rng = random_state if random_state is not None else np.random.default_rng()
        P = rng.integers(0, len(pop), size=(n_select * n_parents, 2))
        return self.compare(pop, P, random_state=rng).reshape(n_select, n_parents)


class MOEA(GeneticAlgorithm):
    """A pymoo ``GeneticAlgorithm`` wired as every MOEA of :mod:`moo.algorithms`.

    An algorithm of the package is its survival (environmental selection) and
    its mating selection; this base wires them into pymoo's genetic algorithm
    the same way for all (pymoo's ``NSGA2`` over ``GeneticAlgorithm`` is the
    model):

    * ``sampling``, ``crossover``, ``mutation`` and ``output`` left ``None``
      become the paper's (:func:`paper_operators`);
    * the initial population goes through the survival before the first
      mating (``advance_after_initial_infill``), so the first mating sees
      ranked individuals;
    * when a run is set up, ``ref_dirs`` (if given) must have one column per
      objective of the problem, and the survival's ``reset()`` (if it has
      one) forgets the state of a previous run.

    Parameters
    ----------
    survival : pymoo Survival
        The environmental selection.
    selection : pymoo Selection
        The mating selection.
    pop_size : int, optional
        Population size (at least 2); default ``len(ref_dirs)``.
    ref_dirs : ndarray, shape (K, M), optional
        The algorithm's reference directions (or weight vectors), kept as
        ``self.ref_dirs`` and checked against the problem at set-up.
    sampling, crossover, mutation : pymoo operators, optional
        Default: uniform random sampling in the box and the paper's SBX and
        polynomial mutation (:func:`paper_operators`).
    eliminate_duplicates : bool
        Remove duplicate offspring (pymoo's mechanism); default True.
    n_offsprings : int, optional
        Offspring per generation (default ``pop_size``).
    output : pymoo Output, optional
        Progress display (default pymoo's multi-objective output).

    Raises
    ------
    TypeError, ValueError
        ``pop_size`` not an integer >= 2, or neither it nor ``ref_dirs``
        given; at set-up, ``ref_dirs`` whose columns are not the problem's
        objectives.

    See Also
    --------
    moo.algorithms.make_algorithm : the registry's factories, which build the subclasses.

    Examples
    --------
    A MOEA from pymoo's rank-and-crowding survival and a random mating,
    run on ZDT1:

    >>> from pymoo.algorithms.moo.nsga2 import RankAndCrowding
    >>> from pymoo.operators.selection.rnd import RandomSelection
    >>> from pymoo.optimize import minimize
    >>> from moo.problems import make_problem
    >>> alg = MOEA(RankAndCrowding(), RandomSelection(), pop_size=20)
    >>> type(alg.mating.crossover).__name__, type(alg.mating.mutation).__name__   # the paper's operators
    ('SBX', 'PaperPM')
    >>> res = minimize(make_problem("zdt1"), alg, ("n_gen", 5), seed=1)
    >>> res.F.shape[1], alg.advance_after_initial_infill
    (2, True)
    """

    def __init__(self, survival: Survival, selection: Selection, *, pop_size: int | None = None,
                 ref_dirs: np.ndarray | None = None, sampling: Sampling | None = None,
                 crossover: Crossover | None = None, mutation: Mutation | None = None,
                 eliminate_duplicates: bool = True, n_offsprings: int | None = None, output: Output | None = None):
        if pop_size is None:
            if ref_dirs is None:
                raise TypeError("pop_size is required when there are no ref_dirs")
            pop_size = len(ref_dirs)
        self.ref_dirs = ref_dirs
        super().__init__(
            pop_size=check_int(pop_size, "pop_size", 2),
            selection=selection,
            survival=survival,
            eliminate_duplicates=eliminate_duplicates,
            n_offsprings=n_offsprings,
            advance_after_initial_infill=True,
            **paper_operators(sampling, crossover, mutation, output),
        )

    def _setup(self, problem, **kwargs) -> None:
        if self.ref_dirs is not None:
            check_ref_dirs_fit(self.ref_dirs, problem)
        reset = getattr(self.survival, "reset", None)
        if callable(reset):
            reset()
