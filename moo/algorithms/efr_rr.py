"""EFR-RR: ensemble fitness ranking with ranking restriction.

Yuan, Xu, Wang, Zhang & Yao, "Balancing convergence and diversity in
decomposition-based many-objective optimizers", IEEE Transactions on
Evolutionary Computation 20(2), 180-198, 2016 (Section IV), building on the
ensemble fitness ranking (EFR) of Yuan, Xu & Wang, GECCO 2014, pp. 669-676.

What it implements
------------------
Each generation the parents ``P`` (size ``N``) and their offspring are merged
into ``S`` and ``N`` survivors are chosen from ``S`` as follows.

1. Normalisation. With the ideal point ``z*`` (best value seen so far in each
   objective) and the nadir estimate ``z^nad`` from the intercepts of the
   hyperplane through the ``M`` extreme points (NSGA-III's procedure as the
   same authors use it in theta-DEA; the project's
   :class:`moo.algorithms.normalization.HyperplaneNormalization`, extreme points
   kept across generations, with its fall-backs when the hyperplane is
   degenerate)::

       f~_i(x) = (f_i(x) - z*_i) / (z^nad_i - z*_i).

2. Ranking restriction. For every solution ``x`` and weight vector ``w_j``
   the perpendicular distance from ``f~(x)`` to the line through ``w_j``::

       d_2(x, w_j) = || f~(x) - (w_j^T f~(x) / ||w_j||^2) w_j ||,

   and ``x`` takes part only in the rankings of the ``K`` weight vectors with
   the smallest ``d_2(x, .)`` (``K = 2`` is the paper's recommended value).

3. Fitness functions. The ``j``-th ranker sorts the solutions associated with
   ``w_j`` by the normalised, modified Tchebycheff function (the paper's
   choice; its minimiser lies on the ray of ``w_j``)::

       g^tch(x | w_j) = max_i f~_i(x) / w_ji        (w_ji = 0 read as 1e-6),

   or, with ``scalarizing="pbi"``, by the penalty-based boundary intersection
   ``g^pbi = d_1 + theta d_2`` with ``d_1 = w_j^T f~(x) / ||w_j||``.
   ``R_j(x)`` is the 1-based position of ``x`` in the ascending sort among
   the solutions associated with ``w_j``.

4. Maximum ranking (the ensemble). The global rank is the best of a
   solution's restricted ranks, ``R_g(x) = min_{j in B(x)} R_j(x)``, where
   ``B(x)`` is the set of its ``K`` nearest weight vectors.

5. Selection by levels. Solutions enter in increasing ``R_g``; the level that
   overflows ``N`` is sampled uniformly at random (the run's Generator).

Mating selection is uniformly random, as in the EFR framework (EFR and EFR-RR
put all the selection pressure in the environmental selection). A binary
tournament on ``R_g`` (smaller wins, ties random) is offered as
``mating="tournament"``.

Readings where the paper leaves room
------------------------------------
* Normalisation uses the whole merged population to find the extreme points
  (EFR-RR does not sort by Pareto dominance at all).
* A zero weight component is replaced by ``1e-6`` in ``g^tch``, the usual
  convention of the modified Tchebycheff function; PlatEMO (whose
  ``UniformPoint`` clamps every weight to ``1e-6``, the platform of the
  reproduced study) and EvoMO read it the same way. Such a weight multiplies
  an objective that is not exactly 0 by ``1e6``, so on the boundary
  directions the ranker orders points by their off-face objectives. A point
  lies exactly on a face of a DTLZ front only when its position variables
  sit exactly on their bounds, which pymoo's bound-aware SBX never produces
  and a clipped SBX often does (measured: :ref:`validation-efr-rr`).
* The population (92 in the paper's experiments) need not equal the number of
  weight vectors (91 for 3 objectives, 84 for 4); the rankings are defined for
  any population size, so no change is needed.
* Equal fitness values within one ranker are ordered by population index
  (deterministic); this only matters for exact duplicates.
* The survival tolerates any population size ``>= n_survive`` and being called
  more than once per generation (MO-LSP contract); its only state is the
  normalisation (ideal point, extreme points), which it updates itself.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.operators.selection.rnd import RandomSelection

from ..validation import as_matrix, check_choice, check_int, check_real
from .base import MOEA, NormalizationForwarding, factory_arguments, factory_ref_dirs, objectives
from .normalization import HyperplaneNormalization
from .operators import POP_SIZE, OperatorSettings

__all__ = ["EFRRR", "EFRRRSurvival", "maximum_ranking", "make_efr_rr", "ORIGINAL_OPERATORS"]

#: EFR-RR's own settings (Yuan et al. 2016, TEVC 20(2), Sec. V, the same as the authors' theta-DEA:
#: SBX pc = 1, eta_c = 30; polynomial mutation pm = 1/n, eta_m = 20).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=30.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Yuan, Xu, Wang, Zhang & Yao (2016), Sec. V")

_ZERO_WEIGHT = 1e-6
_Scalarizing = Literal["tchebycheff", "pbi"]
_Mating = Literal["random", "tournament"]
_SCALARIZINGS: tuple[_Scalarizing, ...] = get_args(_Scalarizing)
_MATINGS: tuple[_Mating, ...] = get_args(_Mating)


def perpendicular_distances(F: np.ndarray, W: np.ndarray) -> np.ndarray:
    """``D[i, j]``: distance from the point ``F[i]`` to the line through ``0`` and ``W[j]``."""
    unit = W / np.linalg.norm(W, axis=1, keepdims=True)
    proj = F @ unit.T                                   # (n, nw) scalar projections d_1
    sq = np.sum(F * F, axis=1, keepdims=True) - proj * proj
    return np.sqrt(np.maximum(sq, 0.0))


def maximum_ranking(
    F: np.ndarray,
    ref_dirs: np.ndarray,
    *,
    n_neighbors: int = 2,
    scalarizing: _Scalarizing = "tchebycheff",
    theta: float = 5.0,
) -> np.ndarray:
    """Global ranks ``R_g`` of EFR-RR (maximum ranking with ranking restriction).

    Parameters
    ----------
    F : (n, M) array
        Normalised objective vectors (ideal point at the origin).
    ref_dirs : (nw, M) array
        Weight vectors (non-negative, not all zero).
    n_neighbors : int
        ``K``: each solution is ranked only by the fitness functions of its
        ``K`` nearest weight vectors (perpendicular distance).
    scalarizing : {"tchebycheff", "pbi"}
        ``g(x|w) = max_i F_i / w_i`` (zero weights read as 1e-6) or
        ``d_1 + theta d_2``.
    theta : float
        PBI penalty (used only with ``scalarizing="pbi"``).

    Returns
    -------
    (n,) int array
        ``R_g(x) = min_{j in B(x)} R_j(x)`` where ``R_j(x)`` is the 1-based rank
        of ``x`` by ``g(.|w_j)`` among the solutions that have ``w_j`` among
        their ``K`` nearest weight vectors. Smaller is better.

    References
    ----------
    Yuan et al., IEEE TEVC 20(2), 2016, Section IV.
    """
    F = as_matrix(F, "F")
    W = as_matrix(ref_dirs, "ref_dirs", cols=F.shape[1], cols_what="the number of objectives of F")
    if np.any(W < 0) or np.any(W.sum(axis=1) <= 0):
        raise ValueError("ref_dirs must be non-negative with a positive sum in every row")
    n, nw = F.shape[0], W.shape[0]
    k = check_int(n_neighbors, "n_neighbors", 1)
    if k > nw:
        raise ValueError(f"n_neighbors must be <= the number of weight vectors ({nw}), got {k}")
    scalarizing = check_choice(scalarizing, "scalarizing", _SCALARIZINGS)

    d2 = perpendicular_distances(F, W)
    nearest = np.argsort(d2, axis=1, kind="stable")[:, :k]          # B(x), (n, K)
    member = np.zeros((n, nw), dtype=bool)
    member[np.arange(n)[:, None], nearest] = True

    if scalarizing == "tchebycheff":
        Wz = np.where(W > 0, W, _ZERO_WEIGHT)
        g = np.max(F[:, None, :] / Wz[None, :, :], axis=2)          # (n, nw)
    else:
        theta = check_real(theta, "theta", positive=True)
        d1 = F @ (W / np.linalg.norm(W, axis=1, keepdims=True)).T
        g = d1 + theta * d2
    g = np.where(member, g, np.inf)                                  # restriction

    order = np.argsort(g, axis=0, kind="stable")                     # per ranker
    ranks = np.empty((n, nw), dtype=np.int64)
    ranks[order, np.arange(nw)[None, :]] = np.arange(1, n + 1)[:, None]
    ranks = np.where(member, ranks, np.iinfo(np.int64).max)
    return ranks.min(axis=1)


class EFRRRSurvival(NormalizationForwarding, Survival):
    """Environmental selection of EFR-RR: normalise, rank, select by levels of ``R_g``.

    Sets the attribute ``"rank"`` (the global rank ``R_g`` within the population
    it was given) on the survivors.
    """

    def __init__(self, ref_dirs: np.ndarray, *, n_neighbors: int = 2,
                 scalarizing: _Scalarizing = "tchebycheff", theta: float = 5.0):
        super().__init__(filter_infeasible=True)
        self.ref_dirs = np.asarray(ref_dirs, dtype=float)
        self.n_neighbors = n_neighbors
        self.scalarizing = scalarizing
        self.theta = theta
        self.norm = HyperplaneNormalization(self.ref_dirs.shape[1])

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        self.norm.update(F)
        rank = maximum_ranking(self.normalize(F), self.ref_dirs, n_neighbors=self.n_neighbors,
                               scalarizing=self.scalarizing, theta=self.theta)
        pop.set("rank", rank)
        if n_survive is None or n_survive >= len(pop):
            return pop

        levels, counts = np.unique(rank, return_counts=True)
        last = levels[np.searchsorted(np.cumsum(counts), n_survive)]
        sure = np.flatnonzero(rank < last)
        tied = np.flatnonzero(rank == last)
        picked = tied[random_state.permutation(len(tied))[: n_survive - len(sure)]]
        return pop[np.concatenate([sure, np.sort(picked)])]


class RankTournament(Selection):
    """Binary tournament on the attribute ``"rank"`` (smaller wins, ties at random)."""

    def _do(self, problem, pop, n_select, n_parents, *args, random_state=None, **kwargs):
        n = n_select * n_parents
        pairs = random_state.integers(0, len(pop), size=(n, 2))
        rank = pop.get("rank")
        if rank is None or np.any([r is None for r in rank]):
            winner = pairs[:, 0]
        else:
            rank = np.asarray(rank, dtype=float)
            ra, rb = rank[pairs[:, 0]], rank[pairs[:, 1]]
            coin = random_state.random(n) < 0.5
            first = (ra < rb) | ((ra == rb) & coin)
            winner = np.where(first, pairs[:, 0], pairs[:, 1])
        return winner.reshape(n_select, n_parents)


class EFRRR(MOEA):
    """EFR-RR as a pymoo genetic algorithm (see the module docstring).

    Parameters
    ----------
    ref_dirs : (nw, M) array
        Weight vectors.
    pop_size : int
        Population size ``N``.
    n_neighbors : int
        ``K``, number of nearest weight vectors a solution is ranked by (2).
    scalarizing : {"tchebycheff", "pbi"}
        Fitness function of each ranker.
    theta : float
        PBI penalty (only for ``scalarizing="pbi"``).
    mating : {"random", "tournament"}
        Uniform random parents (the paper) or a binary tournament on ``R_g``.
    sampling, crossover, mutation, eliminate_duplicates, output
        As for any pymoo genetic algorithm.
    """

    def __init__(self, ref_dirs: np.ndarray, *, pop_size: int = POP_SIZE, n_neighbors: int = 2,
                 scalarizing: _Scalarizing = "tchebycheff", theta: float = 5.0, mating: _Mating = "random",
                 sampling=None, crossover=None, mutation=None, eliminate_duplicates: bool = True,
                 output=None):
        ref_dirs = as_matrix(ref_dirs, "ref_dirs")
        if ref_dirs.shape[1] < 2:
            raise ValueError(f"ref_dirs must have >= 2 columns (objectives), got shape {ref_dirs.shape}")
        if np.any(ref_dirs < 0) or np.any(ref_dirs.sum(axis=1) <= 0):
            raise ValueError("ref_dirs must be non-negative with a positive sum in every row")
        n_neighbors = check_int(n_neighbors, "n_neighbors", 1)
        if n_neighbors > len(ref_dirs):
            raise ValueError(f"n_neighbors must be <= the number of weight vectors "
                             f"({len(ref_dirs)}), got {n_neighbors}")
        scalarizing = check_choice(scalarizing, "scalarizing", _SCALARIZINGS)
        theta = check_real(theta, "theta", positive=True)
        mating = check_choice(mating, "mating", _MATINGS)
        self.n_neighbors = n_neighbors
        survival = EFRRRSurvival(ref_dirs, n_neighbors=n_neighbors, scalarizing=scalarizing, theta=theta)
        super().__init__(survival, RandomSelection() if mating == "random" else RankTournament(), pop_size=pop_size,
                         ref_dirs=ref_dirs, sampling=sampling, crossover=crossover, mutation=mutation,
                         eliminate_duplicates=eliminate_duplicates, output=output)


def make_efr_rr(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                n_neighbors: int = 2, scalarizing: _Scalarizing = "tchebycheff",
                theta: float = 5.0, mating: _Mating = "random",
                ref_dirs: np.ndarray | None = None) -> EFRRR:
    """EFR-RR with the paper's settings; the shape of every factory (:mod:`moo.algorithms`).

    Weight vectors ``ref_dirs``, by default
    :func:`moo.algorithms.operators.reference_directions` (91 for 3
    objectives, 84 for 4), SBX and polynomial mutation as configured in the
    paper (``operators="original"``: :data:`ORIGINAL_OPERATORS`), ``K = 2``
    nearest weight vectors, normalised modified Tchebycheff fitness, random
    mating.
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    return EFRRR(factory_ref_dirs(ref_dirs, n_obj, pop_size), pop_size=pop_size, n_neighbors=n_neighbors,
                 scalarizing=scalarizing, theta=theta, mating=mating, **variation)
