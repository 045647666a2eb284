r"""MOMBI-II: many-objective metaheuristic based on the R2 indicator, version II.

Reference
---------
R. Hernandez Gomez and C. A. Coello Coello, "Improved metaheuristic based on
the R2 indicator for many-objective optimization", Proceedings of GECCO 2015,
pp. 679-686, doi:10.1145/2739480.2754776.

What is implemented
-------------------
*Normalisation.* With the ideal point ``z_min`` and the nadir estimate
``z_max`` kept by the survival, objective vectors are scaled as

.. math:: \bar f_i(x) = \frac{f_i(x) - z^{min}_i}{z^{max}_i - z^{min}_i}.

*Achievement scalarising function (ASF).* For a weight vector ``w``

.. math:: \mathrm{ASF}(x \mid w) = \max_{i=1..M} \bar f_i(x) / w_i ,

zero weight components being replaced by ``1e-2`` (``1e-6`` with two
objectives), the values of the first author's own framework (see "Readings").

*R2 ranking.* For every weight vector the population is sorted by ASF value,
ties broken by the Euclidean norm ``||\bar f(x)||_2`` (smaller first); the
rank of ``x`` is its best (smallest, 1-based) position over all weight
vectors. Environmental selection keeps the ``N`` individuals that are first
in the lexicographic order (rank, norm).

*Reference-point update* (the paper's statistical nadir estimation; see
:func:`update_reference_points`). ``z_min`` is the running minimum of every
objective vector the survival has seen. After each selection the nadir
candidate ``c = max_{x in P} f(x)`` of the survivors ``P`` is appended to a
record of the last ``record_size`` candidates (default 5); once the record is
full, with the per-objective (population) variance ``v`` of the record:

1. if ``max_i v_i > alpha`` (default 0.5) the front is still moving:
   ``z_max_i = max_j c_j`` for every ``i``;
2. otherwise, objective by objective,

   a. if ``|z_max_i - z_min_i| < epsilon`` (default 1e-3):
      ``z_max_i = max_j z_max_j`` (marked);
   b. else if ``c_i > z_max_i``: ``z_max_i = c_i + |c_i - z_max_i|`` (marked);
   c. else if ``v_i = 0`` (read as ``v_i < epsilon``, see "Readings") and
      objective ``i`` has not been marked in the last ``record_size``
      updates: ``z_max_i = (z_max_i + max(record_i)) / 2`` (marked).

*Mating selection.* Binary tournament: a feasible or less-violating parent
wins, then the smaller R2 rank, then the smaller norm, then a fair coin.

Readings where the paper is ambiguous (chosen as a careful reader would)
------------------------------------------------------------------------
The full text of the paper was not at hand (in this session either); the
rules above were checked against the first author's own C implementation (the
EMO framework of Hernandez Gomez and Coello Coello, CINVESTAV: ``mombi2.c``,
``utility.c``) and read against jMetal's and PlatEMO's MOMBI-II (read to
resolve doubts, nothing ported). Where those differ:

* Zero weight components. The authors' framework replaces them in every
  scalarising function by ``wzero = (nobj == 2)? 1e-6 : 1e-2`` (``utility.c``,
  ``EMO_Utility_alloc``; the ASF is ``x[i] / y`` with ``y = w[i]? w[i] :
  wzero``). PlatEMO floors the weights at 1e-6 for any number of objectives,
  and so did this module before: with Das-Dennis weights most vectors have a
  zero component (74 of the 84 for 4 objectives), and 1e-6 makes each of them
  rank the points by their smallest objective alone, which crowds the
  population onto the edges of the front (measured:
  :ref:`validation-mombi2`).
* "``v_i = 0``" in rule c. The authors' code tests the variance of the record
  for exact equality with zero, which in floating point holds only when the
  population's worst value in objective ``i`` comes from one and the same
  individual for ``record_size`` generations. On DTLZ2 with 4 objectives that
  almost never happens for some objectives, and the nadir estimate then
  stays at the initial population's maximum. We read the test as
  ``v_i < epsilon``, the paper's own tolerance parameter (PlatEMO instead
  compares only the last two candidates, exactly).

* The update order follows the authors' C implementation (EMO framework):
  rule 1 uses the largest component of the *new* candidate, marks live for
  ``record_size`` updates, nothing is updated before the record is full, and
  the variance divides by the record length. "``v_i = 0``" is tested exactly
  as "all record entries equal", which is the same condition without
  round-off.
* The nadir record is updated at the end of every call of the survival, from
  the survivors (equivalent to the authors' update from the parents at the
  start of the next generation). When MO-LSP calls the survival a second time
  in a generation, that call updates the record as well.
* Ranks used by the mating tournament are recomputed on the survivors with
  the updated reference points (the rank of an individual in the population
  it now belongs to).
* Mating selection: the binary tournament on the R2 rank (the criterion
  MOMBI-II's ranking provides, and the mating selection of the PlatEMO
  implementation the reproduced paper's experiments ran on); the authors'
  C code instead draws the two parents uniformly at random.
* Infeasible individuals are placed after the feasible ones by pymoo's
  :class:`~pymoo.core.survival.Survival` (least violation first); only
  feasible ones enter the ideal/nadir estimation, as in the authors' code.
* Weight vectors: Das-Dennis directions of
  :func:`moo.algorithms.operators.reference_directions` (91 for 3
  objectives, 84 for 4), population 92.

Notes
-----
What the algorithm does on the test problems (measured runs, collapses, comparisons with
other implementations) is in the documentation's Validation pages,
:ref:`validation-mombi2`.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.survival import Survival
from pymoo.operators.selection.tournament import TournamentSelection

from ..validation import check_directions, check_int, check_real
from .base import MOEA, factory_arguments, factory_ref_dirs, float_column, objectives
from .operators import POP_SIZE, OperatorSettings

__all__ = [
    "MOMBI2",
    "R2RankingSurvival",
    "asf_matrix",
    "make_mombi2",
    "r2_ranking",
    "r2_tournament",
    "update_reference_points",
    "zero_weight",
    "ORIGINAL_OPERATORS",
    "ZERO_WEIGHT",
    "ZERO_WEIGHT_2D",
]

#: MOMBI-II's own settings (SBX pc = 0.9, eta_c = 20; polynomial mutation pm = 1/n, eta_m = 20:
#: the MOMBI papers' settings, as in jMetal's MOMBI-II runner; the GECCO text was not at hand).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=0.9, crossover_eta=20.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Hernandez Gomez & Coello Coello (2015), as configured in jMetal")

#: Values substituted for zero weight components in the ASF: 1e-6 with 2 objectives, 1e-2 with more
#: (the authors' EMO framework, ``utility.c``: ``wzero = (nobj == 2)? 1e-6 : 1e-2``).
ZERO_WEIGHT_2D = 1e-6
ZERO_WEIGHT = 1e-2


def zero_weight(n_obj: int) -> float:
    """The ASF's stand-in for a zero weight component.

    :data:`ZERO_WEIGHT_2D` for 2 objectives, else :data:`ZERO_WEIGHT`.
    """
    return ZERO_WEIGHT_2D if n_obj == 2 else ZERO_WEIGHT


#: Smallest range z_max - z_min used in the normalisation (avoids 0/0).
_TINY_RANGE = 1e-12


def asf_matrix(F_norm: np.ndarray, weights: np.ndarray, zero: float | None = None) -> np.ndarray:
    """Achievement scalarising function of every individual for every weight.

    Parameters
    ----------
    F_norm : ndarray, shape (N, M)
        Normalised objective vectors (ideal point at the origin).
    weights : ndarray, shape (K, M)
        Weight vectors; zero components are replaced by ``zero``, by default
        :func:`zero_weight` of the number of objectives.

    Returns
    -------
    ndarray, shape (N, K)
        ``ASF[n, k] = max_i F_norm[n, i] / weights[k, i]``.
    """
    W = np.asarray(weights, dtype=float)
    W = np.where(W > 0, W, zero_weight(W.shape[1]) if zero is None else zero)
    F_norm = np.asarray(F_norm, dtype=float)
    # one (N, K) pass per objective: faster than reducing a (N, K, M) array over its short last axis
    out = F_norm[:, :1] / W[None, :, 0]
    for i in range(1, W.shape[1]):
        np.maximum(out, F_norm[:, i:i + 1] / W[None, :, i], out=out)
    return out


def r2_ranking(F: np.ndarray, weights: np.ndarray, ideal: np.ndarray, nadir: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """R2 ranking of a population (MOMBI-II, Algorithm "R2 ranking").

    Parameters
    ----------
    F : ndarray, shape (N, M)
        Objective vectors.
    weights : ndarray, shape (K, M)
        Weight vectors of the R2 indicator.
    ideal, nadir : ndarray, shape (M,)
        Reference points of the normalisation
        ``(F - ideal) / (nadir - ideal)`` (ranges below ``1e-12`` are
        floored to ``1e-12``).

    Returns
    -------
    rank : ndarray of int, shape (N,)
        ``rank[n] = min_k`` (1-based position of ``n`` when the population is
        sorted by ``ASF(. | w_k)``, ties by the norm, then by index).
    norm : ndarray, shape (N,)
        Euclidean norm of the normalised objective vectors.
    """
    F = np.asarray(F, dtype=float)
    W = check_directions(weights, "weights")
    if F.ndim != 2 or F.shape[1] != W.shape[1]:
        raise ValueError(f"F must have shape (N, {W.shape[1]}) to match weights {W.shape}, got shape {F.shape}")
    ideal = np.asarray(ideal, dtype=float)
    nadir = np.asarray(nadir, dtype=float)
    if ideal.shape != (F.shape[1],) or nadir.shape != (F.shape[1],):
        raise ValueError(f"ideal and nadir must have shape ({F.shape[1]},), got {ideal.shape} and {nadir.shape}")
    n = F.shape[0]
    if n == 0:
        return np.zeros(0, dtype=int), np.zeros(0)
    F_norm = (F - ideal) / np.maximum(nadir - ideal, _TINY_RANGE)
    norm = np.linalg.norm(F_norm, axis=1)
    asf = asf_matrix(F_norm, W)
    # lexicographic sort (ASF, norm, index) of every column at once: order the
    # rows by norm first, then a stable sort on the ASF values.
    by_norm = np.argsort(norm, kind="stable")
    pos = np.argsort(asf[by_norm], axis=0, kind="stable")
    order = by_norm[pos]                          # order[p, k]: individual at position p for weight k
    ranks = np.empty_like(order)
    ranks[order, np.arange(W.shape[0])[None, :]] = np.arange(1, n + 1)[:, None]
    return ranks.min(axis=1), norm


def update_reference_points(nadir: np.ndarray, ideal: np.ndarray, candidate: np.ndarray,
                            record: np.ndarray, marks: np.ndarray, *, alpha: float = 0.5,
                            epsilon: float = 1e-3, record_size: int = 5
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MOMBI-II nadir-point update from statistics of the recent nadir candidates.

    Parameters
    ----------
    nadir : ndarray, shape (M,)
        Current nadir estimate ``z_max``.
    ideal : ndarray, shape (M,)
        Current ideal point ``z_min``.
    candidate : ndarray, shape (M,)
        New nadir candidate (component-wise maximum of the current population).
    record : ndarray, shape (r, M), r <= record_size
        The previous candidates, oldest first.
    marks : ndarray of int, shape (M,)
        Remaining number of updates during which objective ``i`` counts as
        recently marked.
    alpha, epsilon, record_size
        Variance threshold, tolerance and record length of the paper
        (defaults 0.5, 1e-3, 5).

    Returns
    -------
    nadir, record, marks
        Updated copies (the inputs are not modified). See the module
        docstring for the rules.
    """
    nadir = np.array(nadir, dtype=float)
    ideal = np.asarray(ideal, dtype=float)
    candidate = np.asarray(candidate, dtype=float)
    marks = np.array(marks, dtype=int)
    record = np.vstack([np.asarray(record, dtype=float).reshape(-1, nadir.size), candidate])[-record_size:]
    if record.shape[0] < record_size:
        return nadir, record, marks
    variance = record.var(axis=0)
    if variance.max() > alpha:
        nadir[:] = candidate.max()
    else:
        stagnant = variance < epsilon                  # "v_i = 0" read with the tolerance epsilon (module docstring)
        for i in range(nadir.size):                    # loop over objectives (the rules are sequential)
            if abs(nadir[i] - ideal[i]) < epsilon:
                nadir[i] = nadir.max()
                marks[i] = record_size
            elif candidate[i] > nadir[i]:
                nadir[i] = candidate[i] + abs(candidate[i] - nadir[i])
                marks[i] = record_size
            elif stagnant[i] and marks[i] == 0:
                nadir[i] = 0.5 * (nadir[i] + record[:, i].max())
                marks[i] = record_size
    marks = np.maximum(marks - 1, 0)
    return nadir, record, marks


class R2RankingSurvival(Survival):
    """MOMBI-II environmental selection: keep the best ``N`` by (R2 rank, norm).

    State (updated by the survival itself, so it tolerates being called
    several times per generation on populations of any size): ``ideal``,
    ``nadir``, ``record`` and ``marks`` of :func:`update_reference_points`.
    """

    def __init__(self, weights: np.ndarray, *, alpha: float = 0.5, epsilon: float = 1e-3,
                 record_size: int = 5) -> None:
        super().__init__(filter_infeasible=True)
        self.weights = check_directions(weights, "weights")
        self.alpha = check_real(alpha, "alpha", positive=False)
        self.epsilon = check_real(epsilon, "epsilon", positive=False)
        self.record_size = check_int(record_size, "record_size", 1)
        self.reset()

    def reset(self) -> None:
        """Forget the reference points (called when a run is set up)."""
        self.ideal: np.ndarray | None = None
        self.nadir: np.ndarray | None = None
        self.record = np.zeros((0, self.weights.shape[1]))
        self.marks = np.zeros(self.weights.shape[1], dtype=int)

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        if F.shape[1] != self.weights.shape[1]:
            raise ValueError(f"the problem has {F.shape[1]} objectives but the weights have "
                             f"{self.weights.shape[1]} columns")
        if self.ideal is None or self.nadir is None:        # set together (reset() clears both)
            self.ideal = F.min(axis=0)
            self.nadir = F.max(axis=0)
        else:
            self.ideal = np.minimum(self.ideal, F.min(axis=0))
        rank, norm = r2_ranking(F, self.weights, self.ideal, self.nadir)
        keep = np.lexsort((norm, rank))[:n_survive]
        survivors = pop[keep]
        F_s = F[keep]
        self.nadir, self.record, self.marks = update_reference_points(
            self.nadir, self.ideal, F_s.max(axis=0), self.record, self.marks,
            alpha=self.alpha, epsilon=self.epsilon, record_size=self.record_size)
        rank_s, norm_s = r2_ranking(F_s, self.weights, self.ideal, self.nadir)
        survivors.set("rank", rank_s, "r2_norm", norm_s)
        return survivors


def r2_tournament(P: np.ndarray, cv: np.ndarray, rank: np.ndarray, norm: np.ndarray,
                  random_state: np.random.Generator) -> np.ndarray:
    """Winners of MOMBI-II's binary tournaments.

    Parameters
    ----------
    P : ndarray of int, shape (n, 2)
        Indices of the two competitors of each tournament.
    cv, rank, norm : ndarray, shape (N,)
        Constraint violation (``<= 0`` feasible), R2 rank and normalised norm
        of every individual (``inf`` rank/norm for unranked ones).
    random_state : numpy Generator
        Source of the fair coin for complete ties.

    Returns
    -------
    ndarray of int, shape (n, 1)
        The winner of each tournament: smaller violation, then smaller rank,
        then smaller norm, then a fair coin.
    """
    P = np.asarray(P, dtype=int)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"P must have shape (n, 2), got shape {P.shape}")
    cv = np.maximum(np.asarray(cv, dtype=float), 0.0)
    rank = np.asarray(rank, dtype=float)
    norm = np.asarray(norm, dtype=float)
    a, b = P[:, 0], P[:, 1]
    coin = random_state.random(len(P)) < 0.5
    a_wins = np.where(cv[a] != cv[b], cv[a] < cv[b],
                      np.where(rank[a] != rank[b], rank[a] < rank[b],
                               np.where(norm[a] != norm[b], norm[a] < norm[b], coin)))
    return np.where(a_wins, a, b)[:, None]


def _compare_in_population(pop, P, random_state=None, **kwargs) -> np.ndarray:
    """Comparison hook of pymoo's ``TournamentSelection``: read CV, rank and norm from ``pop``."""
    return r2_tournament(P, float_column(pop.get("CV"), 0.0), float_column(pop.get("rank"), np.inf),
                         float_column(pop.get("r2_norm"), np.inf), random_state)


class MOMBI2(MOEA):
    """MOMBI-II (Hernandez Gomez & Coello Coello, GECCO 2015) as a pymoo algorithm.

    Parameters
    ----------
    ref_dirs : ndarray, shape (K, M)
        Weight vectors of the R2 indicator.
    pop_size : int, optional
        Population size (default: the number of weight vectors).
    alpha, epsilon, record_size
        Reference-point update parameters (paper defaults 0.5, 1e-3, 5).
    sampling, crossover, mutation
        pymoo operators (defaults: uniform random sampling and the paper's
        SBX / polynomial mutation of :mod:`moo.algorithms.operators`).
    eliminate_duplicates : bool
        Remove duplicate offspring (default True).
    """

    def __init__(self, ref_dirs: np.ndarray, *, pop_size: int | None = None, alpha: float = 0.5,
                 epsilon: float = 1e-3, record_size: int = 5, sampling=None, crossover=None,
                 mutation=None, eliminate_duplicates: bool = True, output=None) -> None:
        ref_dirs = check_directions(ref_dirs)
        survival = R2RankingSurvival(ref_dirs, alpha=alpha, epsilon=epsilon, record_size=record_size)
        super().__init__(survival, TournamentSelection(func_comp=_compare_in_population), pop_size=pop_size,
                         ref_dirs=ref_dirs, sampling=sampling, crossover=crossover, mutation=mutation,
                         eliminate_duplicates=eliminate_duplicates, output=output)


def make_mombi2(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                alpha: float = 0.5, epsilon: float = 1e-3, record_size: int = 5,
                ref_dirs: np.ndarray | None = None) -> MOMBI2:
    """MOMBI-II with the paper's settings; the shape of every factory (:mod:`moo.algorithms`).

    Parameters
    ----------
    n_obj : int
        Number of objectives.
    pop_size : int
        Population size (92 in the paper).
    operators : {"paper", "original"} or OperatorSettings
        Variation settings; ``"original"``: :data:`ORIGINAL_OPERATORS`.
    alpha : float
        Variance threshold of the nadir record (0.5).
    epsilon : float
        Tolerance below which an objective range counts as collapsed (1e-3).
    record_size : int
        Number of past nadir candidates kept (5).
    ref_dirs : ndarray, optional
        Weight vectors (default :func:`~moo.algorithms.operators.reference_directions`).
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    return MOMBI2(factory_ref_dirs(ref_dirs, n_obj, pop_size), pop_size=pop_size, alpha=alpha,
                  epsilon=epsilon, record_size=record_size, **variation)
