"""Pieces shared by the pymoo algorithm classes of :mod:`moo.algorithms`.

- :func:`paper_operators`: the paper's default variation operators and
  output, filled in where a constructor argument is ``None``.
- :class:`NormalizationForwarding`: a survival's public view of the
  :class:`~moo.algorithms._normalize.HyperplaneNormalization` it holds.
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
from pymoo.core.selection import Selection
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.util.display.multi import MultiObjectiveOutput

from .._validation import check_choice, check_directions, check_int
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
    from ._normalize import HyperplaneNormalization

__all__ = ["BinaryTournament", "MIN_POP_SIZE", "NormalizationForwarding", "check_ref_dirs_fit", "factory_arguments",
           "factory_ref_dirs", "float_column", "objectives", "paper_operators"]

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
    """Mixin for a survival holding a :class:`~moo.algorithms._normalize.HyperplaneNormalization` in ``self.norm``.

    Exposes its ideal and nadir estimates, its ``normalize`` and its ``reset``.
    """

    norm: HyperplaneNormalization

    @property
    def ideal_point(self) -> np.ndarray:
        return self.norm.ideal_point

    @property
    def nadir_point(self) -> np.ndarray | None:
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
