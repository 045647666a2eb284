r"""SPEA/R: the strength Pareto evolutionary algorithm based on reference directions.

S. Jiang and S. Yang, "A strength Pareto evolutionary algorithm based on
reference direction for multiobjective and many-objective optimization",
IEEE Transactions on Evolutionary Computation 21(3), 329-346, 2017.

SPEA2's strength fitness is computed inside the subregions (niches) that a set
of reference directions cuts the objective space into, a reference-direction
angle replaces SPEA2's k-th nearest neighbour density, and the environmental
selection is "diversity first, convergence second". One generation on the
union ``Q = P u P'`` of parents and offspring:

1. *Normalisation* (Sec. III-A): ``f~ = (f - z_min) / (z_max - z_min)``. The
   paper's reading (``normalization="front"``) takes ``z_min``, ``z_max`` as
   the minimum and maximum of each objective over the non-dominated members
   of ``Q`` (:func:`moo.algorithms.normalization.front_bounds`); the default
   (``"hyperplane"``) takes the shared ideal point and hyperplane nadir of
   :class:`moo.algorithms.normalization.HyperplaneNormalization` (see
   "Readings").
2. *Space partition* (Sec. III-A): ``x`` belongs to the subregion
   ``Omega_j`` of the reference direction with the smallest acute angle
   ``theta(x) = angle(f~(x), w_j)``.
3. *Density* (Sec. III-B): ``D(x) = theta(x) / (theta(x) + theta_bar)``, where
   ``theta_bar`` is the largest, over the directions, of the angle between a
   direction and its nearest neighbouring direction; ``0 <= D < 1``.
4. *Fitness* (Sec. III-B), with ``x > y`` Pareto dominance:

   .. math::

      S(x)  &= |\{y \in Q : x \succ y\}|, &
      R(x)  &= \sum_{y \in Q,\ y \succ x} S(y)            & \text{(global)} \\
      S'(x) &= |\{y \in \Omega(x) : x \succ y\}|, &
      R'(x) &= \sum_{y \in \Omega(x),\ y \succ x} S'(y)  & \text{(local)}

   .. math::

      F(x) = \begin{cases} R'(x) + D(x) & |\Omega(x)| = 1 \\
                             R'(x) + R(x) + D(x) & \text{otherwise,} \end{cases}

   so a solution alone in its subregion is never penalised for being dominated
   by solutions elsewhere (diversity first); ``F(x) < 1`` iff ``x`` is
   non-dominated in its subregion and (alone there or globally
   non-dominated).
5. *Environmental selection* (Sec. III-C, diversity first, convergence
   second): in round ``k = 1, 2, ...`` each non-empty subregion offers its
   best remaining member (smallest ``F``); a round that fits is taken whole,
   and from the round that does not fit the members with the smallest ``F``
   fill the population.
6. *Mating selection* (Sec. III-D): each parent ``x`` mates with the nearest
   (Euclidean distance in the normalised objective space) of ``K`` distinct
   members of ``P`` drawn at random, ``K = 20`` by default - a restricted
   mating that recombines neighbours.

Readings where the paper leaves room (all deliberate). The paper's text was
not at hand, in this session either; the details were compared with
PlatEMO's SPEA/R (read for understanding, not ported), which has the value
``K = 20`` of the mating, the global raw fitness term ``R(x)`` for crowded
subregions, the min/max normalisation of the non-dominated solutions and the
final-generation rule below, all as written here (``k_mating`` is a keyword
argument).

* Normalisation (``normalization="hyperplane"``, the default). The min/max of
  the non-dominated solutions is not robust to dominance-resistant points:
  on DTLZ1 and DTLZ3 a point far from the front but with one objective a
  hair below everyone else's (an SBX/mutation child at a variable bound) is
  non-dominated and stretches ``z_max``. The directions near that axis then
  cut subregions that contain no front point, and "diversity first" keeps
  one straggler in each. With the hyperplane nadir (NSGA-III's and
  theta-DEA's normalisation; a dominance-resistant point loses the
  extreme-point ASF to any converged point near the axis) the stragglers go
  (measured: :ref:`validation-spea-r`).
  ``normalization="front"`` keeps the paper's reading.

* Population ``N = 92`` with the project's 91 (3 objectives) / 84
  (4 objectives) directions.
* The first parent of each mating runs through random permutations of ``P``;
  SBX keeps both children (pymoo's mating), so ``N/2`` pairs per generation
  rather than one child for each of ``N`` pairs; duplicates are eliminated as
  in the project's NSGA-III.
* The mating distances use ``P``'s own min/max normalisation (step 1,
  ``"front"``, on ``P``) so the rule is scale free.
* The paper's special treatment of the final generation (keeping only
  ``F < 1`` solutions) is not applied: the survival cannot know that a
  generation is the last, and pymoo already reports the non-dominated subset
  of the final population as the result.
* A point at ``z_min`` (zero normalised vector) has angle 0 to every
  direction and joins direction 0; ties of ``F`` are broken by position.
* Constraints (not treated in the paper): the survival takes feasible
  solutions first and fills up with the least violating ones (pymoo's
  ``Survival`` split); the mating ignores the violation.
* Individuals with a NaN or infinite objective rank behind all others in
  the survival (:func:`~moo.algorithms.theta_dea.finite_first`) and count
  as infinitely far in the mating; the paper assumes finite objectives.

Notes
-----
What the algorithm does on the test problems (measured runs, collapses, comparisons with
other implementations) is in the documentation's Validation pages,
:ref:`validation-spea-r`.
"""

from __future__ import annotations

import numpy as np
from moocore import is_nondominated
from pymoo.core.crossover import Crossover
from pymoo.core.mutation import Mutation
from pymoo.core.sampling import Sampling
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.util.display.output import Output
from pymoo.util.misc import random_permutations

from ..validation import check_choice, check_directions, check_int
from .base import MOEA, factory_arguments, factory_ref_dirs, objectives
from .normalization import HyperplaneNormalization, front_bounds
from .operators import POP_SIZE, OperatorSettings
from .theta_dea import finite_first, select_by_fronts, theta_nondominated_ranks

__all__ = [
    "SPEAR",
    "SPEARSurvival",
    "NeighbourMatingSelection",
    "dominance_matrix",
    "largest_neighbour_angle",
    "associate_by_angle",
    "spea_r_fitness",
    "make_spea_r",
    "ORIGINAL_OPERATORS",
    "NORMALIZATIONS",
]

#: ``normalization`` options of the survival: the shared hyperplane normalisation, or the paper's
#: minimum and maximum of the non-dominated solutions (see "Readings").
NORMALIZATIONS = ("hyperplane", "front")

#: SPEA/R's own settings (Jiang & Yang 2017, Sec. IV: SBX pc = 1, eta_c = 30; polynomial
#: mutation pm = 1/n, eta_m = 20, the settings of the NSGA-III study it compares with).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=30.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Jiang & Yang (2017), Sec. IV")


def dominance_matrix(F: np.ndarray) -> np.ndarray:
    """Boolean ``(n, n)`` matrix, ``[i, j]`` true iff row ``i`` Pareto-dominates row ``j`` (minimisation)."""
    F = np.asarray(F, dtype=float)
    n = len(F)
    weakly = np.ones((n, n), dtype=bool)
    strictly = np.zeros((n, n), dtype=bool)
    for col in F.T:                      # a loop over the M objectives, each step one (n, n) comparison
        a, b = col[:, None], col[None, :]
        weakly &= a <= b
        strictly |= a < b
    return weakly & strictly


def largest_neighbour_angle(ref_dirs: np.ndarray) -> float:
    """``theta_bar``: max over directions of the angle to the nearest other direction (radians).

    pi/2 for a single direction.
    """
    W = check_directions(ref_dirs)
    if len(W) == 1:
        return float(np.pi / 2)
    U = W / np.linalg.norm(W, axis=1, keepdims=True)
    C = np.clip(U @ U.T, -1.0, 1.0)
    np.fill_diagonal(C, -np.inf)
    return float(np.arccos(C.max(axis=1)).max())


def associate_by_angle(Fn: np.ndarray, ref_dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Subregion (direction of smallest angle, lowest index on ties) and that angle, for each row."""
    Fn = np.asarray(Fn, dtype=float)
    W = check_directions(ref_dirs)
    U = W / np.linalg.norm(W, axis=1, keepdims=True)
    norms = np.linalg.norm(Fn, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        C = (Fn @ U.T) / norms[:, None]
    C[norms == 0] = 1.0
    niche = np.argmax(C, axis=1)
    # the angle itself from atan2(perpendicular, parallel): accurate also near 0, where arccos is not
    u = U[niche]
    along = np.sum(Fn * u, axis=1)
    perp = np.linalg.norm(Fn - along[:, None] * u, axis=1)
    return niche, np.arctan2(perp, along)


def spea_r_fitness(F: np.ndarray, niche: np.ndarray, angle: np.ndarray, theta_bar: float,
                   dom: np.ndarray | None = None) -> np.ndarray:
    """SPEA/R fitness ``F(x)`` (step 4 of the module docstring); smaller is better.

    Parameters
    ----------
    F : ndarray, shape (n, M)
        Objectives (dominance is scale invariant, raw or normalised alike).
    niche : ndarray of int, shape (n,)
        Subregion of each solution.
    angle : ndarray, shape (n,)
        Angle to the own reference direction (radians).
    theta_bar : float
        Largest neighbouring-direction angle, > 0.
    dom : ndarray of bool, shape (n, n), optional
        Precomputed :func:`dominance_matrix` of ``F``.
    """
    if dom is None:
        dom = dominance_matrix(F)
    niche = np.asarray(niche)
    angle = np.asarray(angle, dtype=float)
    strength = dom.sum(axis=1)
    raw = dom.T.astype(float) @ strength                   # R(x) = sum of S(y) over y dominating x
    local = dom & (niche[:, None] == niche[None, :])
    raw_local = local.T.astype(float) @ local.sum(axis=1)  # R'(x)
    density = angle / (angle + theta_bar)
    crowded = np.bincount(niche)[niche] > 1
    return raw_local + density + np.where(crowded, raw, 0.0)


class SPEARSurvival(Survival):
    """SPEA/R environmental selection (steps 1-5 of the module docstring).

    With ``normalization="front"`` stateless: a function of the population it
    is given; with ``"hyperplane"`` (default) its only state is the
    normalisation (ideal point, extreme points), which it updates itself. So
    it may be called any number of times per generation on populations of any
    size. Individuals with non-finite objectives are ranked last. The
    survivors carry ``niche``, ``angle``, ``fitness`` and ``round`` (the
    selection round, 0-based).
    """

    def __init__(self, ref_dirs: np.ndarray, normalization: str = "hyperplane"):
        super().__init__(filter_infeasible=True)
        self.ref_dirs = check_directions(ref_dirs)
        self.theta_bar = largest_neighbour_angle(self.ref_dirs)
        self.normalization = check_choice(normalization, "normalization", NORMALIZATIONS)
        self.norm = HyperplaneNormalization(self.ref_dirs.shape[1])

    def reset(self) -> None:
        """Forget the normalisation state (a new run starts)."""
        self.norm.reset()

    def _normalized(self, F: np.ndarray, nondominated: np.ndarray) -> np.ndarray:
        if self.normalization == "front":
            z_min, rng = front_bounds(F, nondominated)
            return (F - z_min) / rng
        self.norm.update(F, nondominated=np.flatnonzero(nondominated))
        return self.norm.normalize(F)

    def _do(self, problem, pop, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        if F.shape[1] != self.ref_dirs.shape[1]:
            raise ValueError(f"the population has {F.shape[1]} objectives but ref_dirs has "
                             f"{self.ref_dirs.shape[1]} columns")
        if not np.all(np.isfinite(F)):
            return finite_first(self._do, problem, pop, n_survive, random_state)
        dom = dominance_matrix(F)
        niche, angle = associate_by_angle(self._normalized(F, ~np.any(dom, axis=0)), self.ref_dirs)
        fitness = spea_r_fitness(F, niche, angle, self.theta_bar, dom=dom)
        rounds = theta_nondominated_ranks(niche, fitness)
        keep = select_by_fronts(rounds, n_survive, fitness)
        survivors = pop[keep]
        survivors.set("niche", niche[keep], "angle", angle[keep], "fitness", fitness[keep], "round", rounds[keep])
        return survivors


class NeighbourMatingSelection(Selection):
    """SPEA/R mating: each first parent mates with the nearest of ``k`` random others.

    First parents run through random permutations of the population; for
    each, ``min(k, n - 1)`` distinct other members are drawn uniformly and the
    one nearest in the normalised objective space (``front_bounds`` of the
    population) is the second parent. Only two-parent mating is defined.
    """

    def __init__(self, k: int = 20):
        super().__init__()
        self.k = check_int(k, "k", 1)

    def _do(self, problem, pop, n_select, n_parents, random_state=None, **kwargs):
        if n_parents != 2:
            raise ValueError(f"NeighbourMatingSelection needs n_parents == 2, got {n_parents}")
        n = len(pop)
        first = random_permutations(int(np.ceil(n_select / n)), n, random_state=random_state)[:n_select]
        if n == 1:
            return np.stack([first, first], axis=1)
        F = objectives(pop)
        finite = np.all(np.isfinite(F), axis=1)
        Fn = np.full_like(F, np.inf)                                 # non-finite rows: infinitely far
        if finite.any():
            z_min, rng = front_bounds(F[finite], is_nondominated(F[finite]))
            Fn[finite] = (F[finite] - z_min) / rng
        k = min(self.k, n - 1)
        keys = random_state.random((n_select, n))
        keys[np.arange(n_select), first] = np.inf                    # never the parent itself
        cand = np.argpartition(keys, k - 1, axis=1)[:, :k]           # k distinct random others
        with np.errstate(invalid="ignore"):
            dist = np.linalg.norm(Fn[cand] - Fn[first][:, None, :], axis=2)
        dist[np.isnan(dist)] = np.inf                                # inf - inf: no preference
        mate = cand[np.arange(n_select), np.argmin(dist, axis=1)]
        return np.stack([first, mate], axis=1)


class SPEAR(MOEA):
    """SPEA/R as a pymoo algorithm (see the module docstring).

    Parameters
    ----------
    ref_dirs : ndarray, shape (K, M)
        Reference directions.
    pop_size : int
        Population size; defaults to ``K``.
    k_mating : int
        Number of random candidates of the restricted mating (default 20).
    sampling, crossover, mutation :
        pymoo operators (defaults: uniform sampling and the paper's SBX / PM).
    eliminate_duplicates : bool
        Remove duplicate offspring (pymoo's mechanism).
    n_offsprings : int, optional
        Offspring per generation (default ``pop_size``).
    output : pymoo Output, optional
        Progress display (default pymoo's multi-objective output).
    """

    def __init__(self, ref_dirs: np.ndarray, *, pop_size: int | None = None, k_mating: int = 20,
                 normalization: str = "hyperplane", sampling: Sampling | None = None,
                 crossover: Crossover | None = None, mutation: Mutation | None = None,
                 eliminate_duplicates: bool = True, n_offsprings: int | None = None,
                 output: Output | None = None):
        ref_dirs = check_directions(ref_dirs)
        selection = NeighbourMatingSelection(check_int(k_mating, "k_mating", 1))
        super().__init__(SPEARSurvival(ref_dirs, normalization=normalization), selection, pop_size=pop_size,
                         ref_dirs=ref_dirs, sampling=sampling, crossover=crossover, mutation=mutation,
                         eliminate_duplicates=eliminate_duplicates, n_offsprings=n_offsprings, output=output)


def make_spea_r(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                k_mating: int = 20, normalization: str = "hyperplane",
                ref_dirs: np.ndarray | None = None) -> SPEAR:
    """SPEA/R with the project's directions; the shape of every factory (:mod:`moo.algorithms`).

    Directions: ``ref_dirs``, by default
    :func:`~moo.algorithms.operators.reference_directions` (91 for 3
    objectives, 84 for 4); population ``pop_size`` (92); ``k_mating``
    random candidates in the restricted mating selection;
    ``operators="original"``: :data:`ORIGINAL_OPERATORS`.
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    k_mating = check_int(k_mating, "k_mating", 1)
    return SPEAR(factory_ref_dirs(ref_dirs, n_obj, pop_size), pop_size=pop_size, k_mating=k_mating,
                 normalization=normalization, **variation)
