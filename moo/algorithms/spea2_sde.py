"""SPEA2 with shift-based density estimation (SPEA2+SDE).

References
----------
[1] M. Li, S. Yang and X. Liu, "Shift-based density estimation for
   Pareto-based algorithms in many-objective optimization", IEEE Trans.
   Evol. Comput. 18(3), 348-365, 2014.
[2] E. Zitzler, M. Laumanns and L. Thiele, "SPEA2: Improving the strength
   Pareto evolutionary algorithm", TIK-Report 103, ETH Zurich, 2001.

What is implemented
-------------------
SPEA2 [2] with every Euclidean distance replaced by the *shifted* distance of
SDE [1]. With ``f(i)`` the objective vector of individual ``i`` (minimised)
and ``n`` the size of the set being ranked (archive plus offspring):

* strength ``S(i) = |{j : i dominates j}|`` and raw fitness
  ``R(i) = sum_{j dominates i} S(j)`` ([2], Sec. 3.1), so ``R(i) = 0`` exactly
  for the non-dominated individuals;
* shifted distance ([1], Sec. III): to estimate the density around
  ``i`` every other individual ``j`` is moved to ``j' = max(f(j), f(i))``
  (component-wise: an objective in which ``j`` is better than ``i`` is set to
  ``i``'s value), and

  ``sd(i, j) = || max(f(j), f(i)) - f(i) || = sqrt(sum_k max(0, f_k(j) - f_k(i))^2)``.

  ``sd`` is not symmetric. Row ``i`` of the matrix holds the distances *seen
  from* ``i``: an individual that is worse than its neighbours in many
  objectives sees them shifted onto itself and looks crowded;
* density ``D(i) = 1 / (sigma_i^k + 2)`` with ``sigma_i^k`` the ``k``-th
  smallest ``sd(i, j)``, ``j != i``, and ``k = floor(sqrt(n))`` ([2], Sec. 3.1;
  pymoo's SPEA2 uses the ``(k+1)``-th, we follow the report); fitness
  ``F(i) = R(i) + D(i)`` (lower is better; ``D < 1/2`` so ``F < 1`` iff
  non-dominated);
* environmental selection ([2], Sec. 3.2): keep every individual with
  ``F < 1``; if fewer than ``N`` fill with the best remaining ``F``; if more,
  truncate iteratively: remove the individual whose sorted vector of shifted
  distances to the remaining ones is lexicographically smallest (closest
  shifted neighbour, ties by the second closest, ...), recomputing after each
  removal. Exact ties (identical vectors) remove the lowest index;
* mating selection ([2], Step 5): binary tournament *with replacement* on
  the archive, lower ``F`` wins (ties at random); infeasible individuals lose
  to feasible ones and to smaller constraint violations.

Readings where the papers leave a choice
----------------------------------------
* Normalisation. ``sd`` is scale dependent and [1] defines it on the
  objective values; PlatEMO's implementation, on which the Morais et al.
  (2022) experiments ran, uses the raw objectives. The control-design
  problems of this project have objectives of very different magnitudes, so
  by default (``normalize=True``) each objective is scaled, before the
  distances are computed, by the ideal point and the nadir of the
  non-dominated individuals of the set being ranked,
  ``(f - z_min) / (z_nad - z_min)`` (an objective with zero range maps to 0);
  the truncation uses the same distances. The front's range rather than the
  whole set's is used so that a few badly converged individuals do not
  compress the scale of the region that matters. The map is increasing in
  every objective, so dominance, ``S`` and ``R`` are unchanged; only the
  densities depend on it. ``normalize=False`` gives the raw-objective form.
* Population and archive have the same size ``N`` (92 by default), as in [1]
  and in the paper being reproduced.
* Survival is a function of the set it receives (no hidden state), so it can
  be called again on any merged population, as MO-LSP does.

Notes
-----
What the algorithm does on the test problems (measured runs, collapses, comparisons with
other implementations) is in the documentation's Validation pages,
:ref:`validation-spea2-sde`.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.survival import Survival

from ..validation import as_float_array, as_objectives
from .base import MOEA, BinaryTournament, factory_arguments, float_column, objectives
from .operators import POP_SIZE, OperatorSettings

__all__ = [
    "SPEA2SDE",
    "SPEA2SDESurvival",
    "make_spea2_sde",
    "sde_fitness",
    "sde_truncation",
    "shifted_distances",
    "ORIGINAL_OPERATORS",
]

#: SPEA2+SDE's own settings (Li, Yang & Liu 2014, Sec. IV: SBX pc = 1, eta_c = 20; polynomial
#: mutation pm = 1/n, eta_m = 20).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=20.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Li, Yang & Liu (2014), Sec. IV")

_FITNESS = "sde_fitness"


def _normalise(F: np.ndarray, nondominated: np.ndarray) -> np.ndarray:
    """Scale each objective by the ideal point and the nadir of the non-dominated individuals.

    ``(f - z_min) / (z_nad - z_min)`` with ``z_min`` the component-wise minimum
    (always attained by a non-dominated individual) and ``z_nad`` the
    component-wise maximum over the non-dominated ones. A range below
    ``1e-10`` of the whole set's is replaced by the whole set's (on DTLZ4 the
    non-dominated individuals can all have an objective of ``1e-300``, and the
    dominated ones would then scale to ``1e300`` and overflow in the
    distances); a zero range maps to 0. Dominated individuals may get values
    above 1.
    """
    fmin = F.min(axis=0)
    full = F.max(axis=0) - fmin
    span = F[nondominated].max(axis=0) - fmin
    span = np.where(span > 1e-10 * full, span, full)
    span = np.where(span > 0, span, 1.0)
    return (F - fmin) / span


def shifted_distances(F) -> np.ndarray:
    """Matrix of SDE shifted distances, ``D[i, j] = sd(i, j)``.

    Parameters
    ----------
    F : array_like, shape (n, m)
        Objective vectors (minimised), used as given (normalise beforehand if
        the objectives are not commensurable).

    Returns
    -------
    numpy.ndarray, shape (n, n)
        ``D[i, j] = sqrt(sum_k max(0, F[j, k] - F[i, k])**2)`` for ``i != j``
        (Li, Yang & Liu 2014, Sec. III: ``j`` shifted to ``max(F[j], F[i])``),
        ``inf`` on the diagonal. Row ``i`` is the neighbourhood seen from ``i``.
    """
    F = as_objectives(F)
    n, m = F.shape
    D = np.zeros((n, n))
    for k in range(m):                      # a loop over objectives keeps memory at O(n^2)
        col = F[:, k]
        step = col[None, :] - col[:, None]  # step[i, j] = F[j, k] - F[i, k]
        np.maximum(step, 0.0, out=step)
        D += step * step
    np.sqrt(D, out=D)
    np.fill_diagonal(D, np.inf)
    return D


def _domination_matrix(F: np.ndarray) -> np.ndarray:
    """``dom[i, j]`` is True iff ``F[i]`` Pareto-dominates ``F[j]`` (minimisation)."""
    n, m = F.shape
    le = np.ones((n, n), dtype=bool)
    lt = np.zeros((n, n), dtype=bool)
    for k in range(m):                      # a loop over objectives, each step an (n, n) array op
        col = F[:, k]
        le &= col[:, None] <= col[None, :]
        lt |= col[:, None] < col[None, :]
    return le & lt


def _fitness(F: np.ndarray, normalize: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fitness, raw fitness, density and the shifted-distance matrix of the set ``F``."""
    n = F.shape[0]
    dom = _domination_matrix(F)
    strength = dom.sum(axis=1)
    raw = (dom * strength[:, None]).sum(axis=0).astype(np.float64)
    D = shifted_distances(_normalise(F, raw == 0) if normalize else F)
    if n == 1:
        density = np.full(1, 0.5)
    else:
        k = min(max(int(np.sqrt(n)), 1), n - 1)
        sigma = np.partition(D, k - 1, axis=1)[:, k - 1]
        density = 1.0 / (sigma + 2.0)
    return raw + density, raw, density, D


def sde_fitness(F, *, normalize: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SPEA2+SDE fitness ``F(i) = R(i) + D(i)`` of a set of objective vectors.

    Parameters
    ----------
    F : array_like, shape (n, m)
        Objective vectors (minimised) of the whole set being ranked.
    normalize : bool, default True
        Scale each objective by the ideal point and the nadir of the set's
        non-dominated individuals before computing the shifted distances
        (dominance is unaffected).

    Returns
    -------
    fitness, raw, density : numpy.ndarray, shape (n,)
        ``raw[i] = R(i) = sum of S(j) over the j dominating i`` with
        ``S(j)`` the number of individuals ``j`` dominates;
        ``density[i] = 1 / (sigma_i^k + 2)`` with ``sigma_i^k`` the ``k``-th
        smallest shifted distance seen from ``i`` and ``k = floor(sqrt(n))``
        (clipped to ``[1, n - 1]``; ``density = 1/2`` for ``n = 1``);
        ``fitness = raw + density``, lower is better.

    References
    ----------
    Zitzler, Laumanns & Thiele (2001), Sec. 3.1; Li, Yang & Liu (2014), Sec. III.
    """
    F = as_objectives(F)
    if not isinstance(normalize, (bool, np.bool_)):
        raise TypeError(f"normalize must be a bool, got {type(normalize).__name__}")
    return _fitness(F, bool(normalize))[:3]


def sde_truncation(dist, n_keep: int) -> np.ndarray:
    """SPEA2 archive truncation on a (shifted) distance matrix.

    Repeatedly removes the individual ``i`` whose row of distances to the
    remaining individuals, sorted increasingly, is lexicographically smallest
    (Zitzler et al. 2001, Sec. 3.2, the relation ``<=_d``), until ``n_keep``
    remain. Row ``i`` must hold the distances seen from ``i`` (for SDE,
    :func:`shifted_distances`); the diagonal is ignored. Exact ties remove the
    lowest index.

    Parameters
    ----------
    dist : array_like, shape (n, n)
    n_keep : int
        Number of individuals to keep, ``1 <= n_keep <= n``.

    Returns
    -------
    numpy.ndarray
        Sorted indices of the kept individuals.

    Notes
    -----
    Each row is sorted once. A pointer per row marks its nearest remaining
    neighbour; a removal advances only the pointers that pointed at the
    removed individual, so a step costs ``O(n)`` unless the nearest distances
    tie, when the tied rows are compared lexicographically over their
    remaining entries. Total ``O(n^2 log n)`` for the sort plus ``O(r n)``
    for ``r`` removals in the tie-free case.
    """
    D = as_float_array(dist, "dist")
    if D.ndim != 2 or D.shape[0] != D.shape[1] or D.shape[0] < 1:
        raise ValueError(f"dist must be a square (n, n) matrix, got shape {D.shape}")
    n = D.shape[0]
    if isinstance(n_keep, bool) or not isinstance(n_keep, (int, np.integer)):
        raise TypeError(f"n_keep must be an integer, got {type(n_keep).__name__}")
    if not 1 <= n_keep <= n:
        raise ValueError(f"n_keep must be in [1, {n}] (the number of rows of dist), got {n_keep}")
    if n_keep == n:
        return np.arange(n)
    if np.any(np.isnan(D[~np.eye(n, dtype=bool)])):
        raise ValueError("dist must not contain NaN off the diagonal")
    np.fill_diagonal(D, np.inf)
    # sort each row once and drop the diagonal entry (column id == row id)
    order = np.argsort(D, axis=1)
    order = order[order != np.arange(n)[:, None]].reshape(n, n - 1)
    S = np.take_along_axis(D, order, axis=1)
    dead = np.zeros(n, dtype=bool)
    ptr = np.zeros(n, dtype=np.intp)                 # position of each row's nearest living neighbour
    nearest = order[:, 0].copy()                     # id of that neighbour
    cur = S[:, 0].copy()                             # distance to it (inf once the row is removed)
    rows = np.arange(n)
    for _ in range(n - n_keep):
        cand = np.flatnonzero(cur == cur.min())
        if cand.size > 1:
            # compare the tied rows over their remaining entries (lexsort is stable: lowest id wins ties)
            live = ~dead[order[cand]]
            sub = S[cand][live].reshape(cand.size, -1)
            cand = cand[np.lexsort(sub.T[::-1])]
        victim = cand[0]
        dead[victim] = True
        cur[victim] = np.inf
        # advance the pointers of the living rows whose nearest neighbour was the victim
        moved = np.flatnonzero(nearest == victim)
        moved = moved[~dead[moved]]
        hit = moved
        while hit.size:
            ptr[hit] += 1
            hit = hit[ptr[hit] < n - 1]               # a lone survivor has no neighbour left
            hit = hit[dead[order[hit, ptr[hit]]]]
        moved = moved[ptr[moved] < n - 1]
        nearest[moved] = order[moved, ptr[moved]]
        cur[moved] = S[moved, ptr[moved]]
    return rows[~dead]


class SPEA2SDESurvival(Survival):
    """SPEA2 environmental selection (archive update) with SDE distances.

    Parameters
    ----------
    normalize : bool, default True
        Scale the objectives by the ideal point and the non-dominated nadir of
        the set being ranked before the shifted distances are computed (see
        the module docstring).

    Notes
    -----
    Sets the attribute ``"sde_fitness"`` (the SPEA2+SDE fitness computed on
    the whole set it receives, lower is better) on the survivors; the mating
    tournament reads it.
    """

    def __init__(self, normalize: bool = True):
        super().__init__(filter_infeasible=True)
        self.normalize = bool(normalize)

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        n = len(pop)
        if n_survive is None:
            n_survive = n
        fitness, _, _, D = _fitness(F, self.normalize)
        pop.set(_FITNESS, fitness)
        nondom = np.flatnonzero(fitness < 1.0)
        if nondom.size <= n_survive:
            # non-dominated first, then the best remaining fitness (stable: ties by index)
            survivors = np.argsort(fitness, kind="stable")[:n_survive]
        else:
            # truncation among the non-dominated, distances in the same (normalised) space
            kept = sde_truncation(D[np.ix_(nondom, nondom)], n_survive)
            survivors = nondom[kept]
        return pop[survivors]


def _sde_tournament(pop, P, random_state=None, **kwargs):
    """Binary tournament: feasibility / CV first, then lower SPEA2+SDE fitness, ties at random."""
    if P.shape[1] != 2:
        raise ValueError(f"SPEA2+SDE uses a binary tournament, got tournaments of size {P.shape[1]}")
    rng = random_state if random_state is not None else np.random.default_rng()
    n = len(pop)
    cv = pop.get("CV")
    cv = np.zeros(n) if cv is None else np.asarray(cv, dtype=np.float64).reshape(n, -1)[:, 0]
    feasible = cv <= 0
    fit = float_column(pop.get(_FITNESS), np.nan)    # individuals never ranked carry None: NaN
    if np.any(np.isnan(fit[feasible])):
        # feasible individuals not ranked by the survival (e.g. a user-supplied population):
        # rank the feasible ones now, as the survival does
        fit[feasible] = sde_fitness(objectives(pop)[feasible])[0]
    a, b = P[:, 0], P[:, 1]
    coin = rng.random(len(P)) < 0.5
    infeasible = ~(feasible[a] & feasible[b])
    va = np.where(infeasible, cv[a], fit[a])
    vb = np.where(infeasible, cv[b], fit[b])
    winner = np.where(va < vb, a, np.where(vb < va, b, np.where(coin, a, b)))
    return winner[:, None].astype(int)


class SPEA2SDE(MOEA):
    """SPEA2+SDE as a pymoo algorithm (archive = ``pop``, offspring = population).

    Parameters
    ----------
    pop_size : int
        Archive size and number of offspring per generation (``N = N-bar``).
    sampling, crossover, mutation
        pymoo operators (defaults: uniform random sampling, the paper's SBX
        and polynomial mutation).
    normalize : bool, default True
        See :class:`SPEA2SDESurvival`.
    eliminate_duplicates : bool, default True
        pymoo duplicate elimination of offspring.
    """

    def __init__(self, *, pop_size: int = POP_SIZE, sampling=None, crossover=None, mutation=None,
                 normalize: bool = True, eliminate_duplicates: bool = True, output=None):
        super().__init__(SPEA2SDESurvival(normalize=normalize),
                         BinaryTournament(_sde_tournament),   # with replacement (Zitzler et al. 2001, Step 5)
                         pop_size=pop_size, sampling=sampling, crossover=crossover, mutation=mutation,
                         eliminate_duplicates=eliminate_duplicates, output=output)


def make_spea2_sde(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                   normalize: bool = True) -> SPEA2SDE:
    """SPEA2+SDE with the paper's settings (population = archive = 92, SBX, PM).

    The shape of every factory (:mod:`moo.algorithms`).

    Parameters
    ----------
    n_obj : int
        Number of objectives (>= 2); SPEA2+SDE needs no reference directions,
        it is checked only.
    pop_size : int, default 92
        Archive size ``N`` and number of offspring per generation.
    operators : {"paper", "original"} or OperatorSettings
        Variation settings; ``"original"``: :data:`ORIGINAL_OPERATORS`.
    normalize : bool, default True
        Scale objectives by the ranked set's ideal point and non-dominated
        nadir before the shifted distances (``False``: raw objectives, as
        PlatEMO).

    Returns
    -------
    SPEA2SDE
    """
    _, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    if not isinstance(normalize, (bool, np.bool_)):
        raise TypeError(f"normalize must be a bool, got {type(normalize).__name__}")
    return SPEA2SDE(pop_size=pop_size, normalize=bool(normalize), **variation)

