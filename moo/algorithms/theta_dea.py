r"""theta-DEA: the theta-dominance based evolutionary algorithm.

Y. Yuan, H. Xu, B. Wang and X. Yao, "A new dominance relation-based
evolutionary algorithm for many-objective optimization", IEEE Transactions on
Evolutionary Computation 20(1), 16-37, 2016.

One generation (the paper's Algorithm 1):

1. Offspring ``Q`` from parents chosen at random from ``P`` (SBX + polynomial
   mutation); ``R = P u Q``.
2. ``S``: the Pareto fronts ``F_1, F_2, ...`` of ``R`` in order until
   ``|S| >= N`` (the last one whole).
3. *Normalize* ``S`` (Sec. III-C): running ideal point ``z*``, extreme points
   by the achievement scalarising function, nadir ``z_nad`` from the
   hyperplane intercepts (falling back to the worst of ``F_1``), then
   ``f~ = (f - z*) / (z_nad - z*)``; see :mod:`moo.algorithms.normalization`.
4. *Clustering* (Sec. III-D): each ``x`` in ``S`` joins the cluster ``C_j`` of
   the reference direction ``w_j`` with the smallest perpendicular distance

   .. math::

      d_{j,1}(x) = \frac{\tilde f(x)^T w_j}{\lVert w_j \rVert}, \qquad
      d_{j,2}(x) = \Big\lVert \tilde f(x) - d_{j,1}(x)
                   \frac{w_j}{\lVert w_j \rVert} \Big\rVert .

5. theta-dominance (Sec. III-E, Def. 1): ``x`` theta-dominates ``y`` iff both
   are in the same cluster ``C_j`` and ``F_j(x) < F_j(y)`` with the
   PBI-like function

   .. math::

      F_j(x) = d_{j,1}(x) + \theta_j\, d_{j,2}(x), \qquad
      \theta_j = \begin{cases} 10^6 & w_j \text{ an objective axis} \\
                                 \theta & \text{otherwise.} \end{cases}

   Since theta-dominance only relates members of one cluster, which it orders
   totally, the theta-non-dominated fronts are: front ``k`` holds the
   ``k``-th best member (by ``F_j``) of every cluster.
6. ``P`` is filled front by front; from the front that does not fit, the
   remaining places are filled at random.

Readings where the paper leaves room (all deliberate). The authors' own Java
code (Yuan Yuan, github.com/yyxhdy/ManyEAs, ``ThetaDEA.java``,
``ThetaDEA_main.java``; read, not ported) was compared with this module:

* Normalisation: the authors' ``updateExtremePoints`` / ``asfFunction``
  compute the ASF exactly as printed; the shared normalisation reads terms
  below 1e-3 of the scale as zero, which keeps a poorly converged point lying
  exactly on an axis from staying the extreme point for the whole run
  (``moo.algorithms.normalization``, "Readings"; measured:
  :ref:`validation-theta-dea`).
* Operators: ``operators="original"`` gives the authors' settings
  (``ThetaDEA_main.java``: SBX probability 1.0, distribution index 30;
  polynomial mutation probability ``1 / n``, index 20).
* Population ``N = 92`` with the project's 91 (3 objectives) / 84
  (4 objectives) directions (the paper uses ``N`` = number of directions);
  clustering does not depend on that equality.
* The paper's mating is uniform random selection and one SBX child per pair
  (the authors' ``doCrossover``: each member ``i`` mates with a random
  ``r != i`` and keeps the first child); here pairs are drawn uniformly at
  random (feasible-first binary tournament on constraint violation when the
  problem has constraints, a no-op otherwise) and SBX keeps both children
  (pymoo's mating); duplicates are eliminated as in the project's NSGA-III,
  for a like-for-like comparison.
* Constraints (not treated in the paper): the survival takes feasible
  solutions first and fills up with the least violating ones (pymoo's
  ``Survival`` split), and the random mating becomes a binary tournament on
  the violation.
* Ties in ``F_j`` are broken by position in ``S`` (deterministic).
* Individuals with a NaN or infinite objective rank behind all others
  (:func:`finite_first`); the paper assumes finite objectives.
* Degenerate normalisation ranges are repaired as documented in
  :mod:`moo.algorithms.normalization` (the paper has no such case).
"""

from __future__ import annotations

import numpy as np
from pymoo.core.crossover import Crossover
from pymoo.core.mutation import Mutation
from pymoo.core.population import Population
from pymoo.core.sampling import Sampling
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.util.display.output import Output
from pymoo.util.misc import random_permutations
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from ..validation import check_directions, check_real
from .base import MOEA, NormalizationForwarding, factory_arguments, factory_ref_dirs, objectives
from .normalization import HyperplaneNormalization
from .operators import POP_SIZE, OperatorSettings

__all__ = [
    "ThetaDEA",
    "ThetaSurvival",
    "RandomFeasibleSelection",
    "theta_clustering",
    "theta_nondominated_ranks",
    "select_by_fronts",
    "finite_first",
    "make_theta_dea",
    "ORIGINAL_OPERATORS",
]

#: theta-DEA's own settings (Yuan et al. 2016, Sec. V; the authors' ``ThetaDEA_main.java``:
#: SBX pc = 1, eta_c = 30; polynomial mutation pm = 1/n, eta_m = 20).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=30.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Yuan et al. (2016), Sec. V; authors' code yyxhdy/ManyEAs")

AXIS_THETA = 1.0e6


def theta_clustering(Fn: np.ndarray, ref_dirs: np.ndarray,
                     theta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cluster normalised objectives on reference directions and compute ``F_j``.

    Parameters
    ----------
    Fn : ndarray, shape (n, M)
        Normalised objectives (``f~`` above, relative to the ideal point).
    ref_dirs : ndarray, shape (K, M)
        Reference directions (need not be unit length).
    theta : float
        Penalty of the non-axis directions; axis directions use ``1e6``.

    Returns
    -------
    cluster : ndarray of int, shape (n,)
        ``argmin_j d_{j,2}`` (lowest index on ties).
    d1, d2 : ndarray, shape (n,)
        Distances along and perpendicular to the own direction.
    fitness : ndarray, shape (n,)
        ``F_j(x) = d1 + theta_j d2``.
    """
    Fn = np.asarray(Fn, dtype=float)
    W = check_directions(ref_dirs)
    U = W / np.linalg.norm(W, axis=1, keepdims=True)                     # (K, M)
    D1 = Fn @ U.T                                                         # (n, K)
    D2 = np.linalg.norm(Fn[:, None, :] - D1[:, :, None] * U[None, :, :], axis=2)
    cluster = np.argmin(D2, axis=1)
    rows = np.arange(len(Fn))
    d1 = np.abs(D1[rows, cluster])
    d2 = D2[rows, cluster]
    is_axis = np.count_nonzero(W, axis=1) == 1
    thetas = np.where(is_axis, AXIS_THETA, float(theta))
    return cluster, d1, d2, d1 + thetas[cluster] * d2


def theta_nondominated_ranks(cluster: np.ndarray, fitness: np.ndarray) -> np.ndarray:
    """theta-non-dominated front of each solution (0-based).

    Front ``k`` holds the ``k``-th best solution of each cluster by
    ``fitness`` (ties: earlier position first).
    """
    cluster = np.asarray(cluster)
    order = np.lexsort((np.arange(len(cluster)), fitness, cluster))      # by cluster, fitness, index
    sorted_cluster = cluster[order]
    starts = np.r_[0, np.flatnonzero(np.diff(sorted_cluster)) + 1]
    first_of_group = np.repeat(starts, np.diff(np.r_[starts, len(order)]))
    ranks = np.empty(len(cluster), dtype=int)
    ranks[order] = np.arange(len(order)) - first_of_group
    return ranks


def select_by_fronts(ranks: np.ndarray, n_survive: int, last_front_key: np.ndarray) -> np.ndarray:
    """Indices of ``n_survive`` solutions taken front by front.

    The whole fronts that fit are taken; from the first front that does not
    fit, the ones with the smallest ``last_front_key`` (a random key gives a
    random choice).
    """
    ranks = np.asarray(ranks)
    n_survive = min(int(n_survive), len(ranks))
    counts = np.bincount(ranks)
    cum = np.cumsum(counts)
    last = int(np.searchsorted(cum, n_survive))                          # first front with cum >= n_survive
    full = np.flatnonzero(ranks < last)
    need = n_survive - len(full)
    cand = np.flatnonzero(ranks == last)
    chosen = cand[np.argsort(np.asarray(last_front_key)[cand], kind="stable")[:need]]
    return np.sort(np.concatenate([full, chosen]))


def finite_first(survive, problem, pop, n_survive: int, random_state):
    """Apply ``survive`` to the rows of ``pop`` with finite objectives; non-finite rows fill up last.

    Individuals with a NaN or infinite objective cannot be normalised or
    placed on a reference direction; they are ranked behind every finite one
    (in population order) and only survive when the finite ones are too few.
    """
    finite = np.all(np.isfinite(objectives(pop)), axis=1)
    good, bad = np.flatnonzero(finite), np.flatnonzero(~finite)
    if len(good) == 0:
        return pop[bad[:n_survive]]
    survivors = survive(problem, pop[good], n_survive=min(n_survive, len(good)), random_state=random_state)
    rest = n_survive - len(survivors)
    return Population.merge(survivors, pop[bad[:rest]]) if rest > 0 else survivors


class RandomFeasibleSelection(Selection):
    """Uniform random parents; on constrained problems a binary tournament on the violation.

    For each parent slot two individuals ``a, b`` are drawn (successive
    entries of random permutations, as pymoo's random selection); the one with
    the smaller constraint violation wins, and the choice between ``a`` and
    ``b`` is random when the violations are equal (always so for
    unconstrained problems, which makes it plain uniform random selection).
    """

    def _do(self, problem, pop, n_select, n_parents, random_state=None, **kwargs):
        n = n_select * n_parents
        P = random_permutations(int(np.ceil(2 * n / len(pop))) + 1, len(pop), random_state=random_state)
        a, b = P[:n], P[n:2 * n]
        if len(b) < n:  # tiny populations: fill the second contestant at random
            b = random_state.integers(0, len(pop), size=n)
        cv = pop.get("CV")
        cv = np.zeros(len(pop)) if cv is None else np.asarray(cv, dtype=float).reshape(len(pop), -1)[:, 0]
        cv = np.nan_to_num(cv, nan=0.0)
        coin = random_state.random(n) < 0.5
        winner = np.where(cv[a] < cv[b], a, np.where(cv[b] < cv[a], b, np.where(coin, a, b)))
        return winner.reshape(n_select, n_parents)


class ThetaSurvival(NormalizationForwarding, Survival):
    """theta-DEA environmental selection (steps 2-6 of the module docstring).

    Keeps its own :class:`~moo.algorithms.normalization.HyperplaneNormalization`
    (ideal point, extreme points, nadir; exposed as ``ideal_point``,
    ``nadir_point``, ``normalize`` and ``reset``) across calls, so it may be called
    any number of times per generation on populations of any size.
    Individuals with non-finite objectives are ranked last (:func:`finite_first`).
    After a call the survivors carry ``rank`` (Pareto front), ``theta_rank``,
    ``cluster`` and ``theta_fitness``.
    """

    def __init__(self, ref_dirs: np.ndarray, theta: float = 5.0):
        super().__init__(filter_infeasible=True)
        self.ref_dirs = check_directions(ref_dirs)
        self.theta = check_real(theta, "theta", positive=False)
        self.norm = HyperplaneNormalization(self.ref_dirs.shape[1])

    def _do(self, problem, pop, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        if F.shape[1] != self.ref_dirs.shape[1]:
            raise ValueError(f"the population has {F.shape[1]} objectives but ref_dirs has "
                             f"{self.ref_dirs.shape[1]} columns")
        if not np.all(np.isfinite(F)):
            return finite_first(self._do, problem, pop, n_survive, random_state)
        fronts = NonDominatedSorting().do(F, n_stop_if_ranked=n_survive)
        S = np.concatenate(fronts)
        pareto_rank = np.concatenate([np.full(len(f), i) for i, f in enumerate(fronts)])
        F = F[S]
        self.norm.update(F, nondominated=np.arange(len(fronts[0])))
        cluster, _, _, fitness = theta_clustering(self.norm.normalize(F), self.ref_dirs, self.theta)
        ranks = theta_nondominated_ranks(cluster, fitness)
        keep = select_by_fronts(ranks, n_survive, random_state.random(len(S)))
        survivors = pop[S[keep]]
        survivors.set("rank", pareto_rank[keep], "theta_rank", ranks[keep],
                      "cluster", cluster[keep], "theta_fitness", fitness[keep])
        return survivors


class ThetaDEA(MOEA):
    """theta-DEA as a pymoo algorithm (see the module docstring).

    Parameters
    ----------
    ref_dirs : ndarray, shape (K, M)
        Reference directions (the paper's reference points).
    theta : float
        Penalty parameter theta of the non-axis directions (paper: 5).
    pop_size : int
        Population size; defaults to ``K``.
    sampling, crossover, mutation :
        pymoo operators (defaults: uniform sampling and the paper's SBX / PM).
    eliminate_duplicates : bool
        Remove duplicate offspring (pymoo's mechanism).
    n_offsprings : int, optional
        Offspring per generation (default ``pop_size``).
    output : pymoo Output, optional
        Progress display (default pymoo's multi-objective output).
    """

    def __init__(self, ref_dirs: np.ndarray, *, theta: float = 5.0, pop_size: int | None = None,
                 sampling: Sampling | None = None, crossover: Crossover | None = None,
                 mutation: Mutation | None = None, eliminate_duplicates: bool = True,
                 n_offsprings: int | None = None, output: Output | None = None):
        ref_dirs = check_directions(ref_dirs)
        self.theta = check_real(theta, "theta", positive=False)
        super().__init__(ThetaSurvival(ref_dirs, theta=self.theta), RandomFeasibleSelection(), pop_size=pop_size,
                         ref_dirs=ref_dirs, sampling=sampling, crossover=crossover, mutation=mutation,
                         eliminate_duplicates=eliminate_duplicates, n_offsprings=n_offsprings, output=output)


def make_theta_dea(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                   theta: float = 5.0, ref_dirs: np.ndarray | None = None) -> ThetaDEA:
    """theta-DEA with the paper's settings (theta = 5); the shape of every factory (:mod:`moo.algorithms`).

    Directions: ``ref_dirs``, by default
    :func:`~moo.algorithms.operators.reference_directions` (91 for 3
    objectives, 84 for 4); population ``pop_size`` (92);
    ``operators="original"``: :data:`ORIGINAL_OPERATORS`.
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    theta = check_real(theta, "theta", positive=False)
    return ThetaDEA(factory_ref_dirs(ref_dirs, n_obj, pop_size), theta=theta, pop_size=pop_size, **variation)
