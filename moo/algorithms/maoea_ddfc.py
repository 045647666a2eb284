"""MaOEA-DDFC: directional diversity and favorable convergence.

Cheng, Yen & Zhang, "A many-objective evolutionary algorithm with enhanced
mating and environmental selections", IEEE Transactions on Evolutionary
Computation 19(4), 592-605, 2015.

What it implements
------------------
Objectives are normalised with the ideal point ``z*`` (best value seen so far)
and the nadir estimate ``z^nad`` from the intercepts of the hyperplane through
the extreme points found among the non-dominated solutions (NSGA-III's
procedure; the project's
:class:`moo.algorithms.normalization.HyperplaneNormalization`)::

    f~_i(x) = (f_i(x) - z*_i) / (z^nad_i - z*_i).

Favorable convergence (FC). The Chebyshev function ``g(x|w) = max_i w_i f~_i(x)``
is smallest, over weights on the simplex, at the *favorable weight*
``w^x_i = (1/f~_i(x)) / sum_j 1/f~_j(x)``, where all the terms ``w_i f~_i`` are
equal. FC is that smallest value::

    FC(x) = g(x | w^x) = 1 / sum_j (1 / f~_j(x)),

and ``FC(x) = 0`` when some ``f~_j(x) = 0`` (all the weight on that objective).
Smaller FC means better convergence along the solution's own direction.

Directional diversity (DD). Normalised vectors are projected onto the unit
simplex, ``p(x) = f~(x) / sum_i f~_i(x)``, so that the Euclidean distance
between projections measures the difference of *directions*. The density of a
candidate's direction relative to the already selected set ``S`` is::

    DD(x) = sum_{k=1..K} 1 / d_k(x, S),

with ``d_k`` the distance to its ``k``-th nearest member of ``S`` in the
projected space (``K = 5``; fewer terms while ``|S| < K``). Smaller DD is a
sparser, more diverse direction.

Mating selection: binary tournament; a parent that Pareto-dominates the other
wins, otherwise the one with the smaller FC (ties: the first drawn).

Environmental selection on the merged population of parents and offspring:

1. Non-dominated sorting; whole fronts enter while they fit.
2. From the front that overflows, solutions are added one at a time: the
   ``L = 3`` remaining candidates with the smallest DD with respect to the
   solutions selected so far form a tournament, and the winner is chosen by
   FC - by roulette wheel with probability proportional to ``1/FC``
   (``candidate_choice="roulette"``, default) or deterministically the
   smallest FC (``"best"``).
3. If the first front alone overflows (nothing selected yet), DD of the first
   pick is measured against the other candidates of that front.

Readings where the paper leaves room
------------------------------------
* How the FC tournament is decided. The paper describes the environmental
  selection as "tournament-like"; PlatEMO (on which the reproduced study ran)
  draws the winner by roulette wheel on ``1/FC``. The roulette is the default;
  ``candidate_choice="best"`` is the greedy reading. FC alone favours
  directions near the boundary of the front (``FC -> 0`` as any
  ``f~_i -> 0``), and the greedy choice follows that bias more strictly
  (measured: :ref:`validation-maoea-ddfc`).
* FC is computed on the same normalised objectives as DD, so that it does not
  depend on the units of the objectives (the paper's control MOPs have
  objectives of very different scales); PlatEMO translates by the ideal point
  only.
* Resolution of FC. The paper compares FC values without saying how close to
  zero they may be told apart. FC is the smallest normalised objective up to a
  factor of at most ``M``, so on a problem such as DTLZ4, whose ``x^100`` puts
  normalised objectives of ``1e-50`` to ``1e-300`` on the boundary of the
  front, a comparison at full precision ranks boundary points by digits that
  carry no information. Here FC values below ``1e-6`` compare as equal, in
  the mating tournament (the first drawn wins, i.e. a random one) as in the
  environmental selection (the roulette weight ``1/max(FC, 1e-6)`` is finite
  for ``FC = 0``; ``"best"`` breaks FC ties by the smaller DD, then by
  population index). PlatEMO's ``CalFC`` floors FC at ``1e-6`` the same way
  (in raw units; ours are normalised). The floor is a trade-off: fewer
  collapsed runs on DTLZ4, a weaker convergence on DTLZ1 at
  8 objectives (measured: :ref:`validation-maoea-ddfc`).
* A solution exactly at the ideal point (``sum f~ = 0``) is projected to the
  simplex centre ``1/M``.
* Coincident projections (distance 0) give ``DD = inf``: a duplicated
  direction is taken last.
* The survival tolerates any population size ``>= n_survive`` and repeated
  calls in a generation (MO-LSP); its only state is the normalisation, which it
  updates itself. It stores ``"FC"`` and ``"rank"`` (Pareto front index) on
  the survivors.

Notes
-----
What the algorithm does on the test problems (measured runs, collapses, comparisons with
other implementations) is in the documentation's Validation pages,
:ref:`validation-maoea-ddfc`.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from scipy.spatial.distance import cdist

from ..validation import as_matrix, check_choice, check_int
from .base import MOEA, NormalizationForwarding, factory_arguments, objectives
from .normalization import HyperplaneNormalization
from .operators import POP_SIZE, OperatorSettings

__all__ = [
    "MaOEADDFC",
    "DDFCSurvival",
    "DDFCMatingSelection",
    "favorable_convergence",
    "directional_projection",
    "select_by_dd_fc",
    "tournament_winners",
    "make_maoea_ddfc",
    "ORIGINAL_OPERATORS",
]

#: MaOEA-DDFC's own settings (Cheng, Yen & Zhang 2015, Sec. V: SBX pc = 1, eta_c = 20;
#: polynomial mutation pm = 1/n, eta_m = 20).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=20.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Cheng, Yen & Zhang (2015), Sec. V")

#: Resolution of FC (normalised units): smaller values compare as equal (see "Readings").
_FC_FLOOR = 1e-6
_CandidateChoice = Literal["roulette", "best"]
_CHOICES: tuple[_CandidateChoice, ...] = get_args(_CandidateChoice)


def favorable_convergence(F: np.ndarray) -> np.ndarray:
    """FC of each row of normalised objectives ``F`` (ideal point at the origin).

    ``FC(x) = min_{w in simplex} max_i w_i F_i(x) = 1 / sum_i (1 / F_i(x))``,
    and 0 if some ``F_i(x) = 0``. Negative entries (a point better than the
    stored ideal) are clipped to 0. Computed as ``m / sum_i (m / F_i)`` with
    ``m = min_i F_i``: every ratio lies in ``(0, 1]``, so tiny or huge values
    neither overflow (``1 / 1e-310`` does) nor lose the result.
    """
    F = np.maximum(as_matrix(F, "F"), 0.0)
    m = F.min(axis=1)
    fc = np.zeros(len(F))
    pos = m > 0
    fc[pos] = m[pos] / np.sum(m[pos, None] / F[pos], axis=1)
    return fc


def directional_projection(F: np.ndarray) -> np.ndarray:
    """Project normalised objective vectors on the unit simplex, ``F / sum(F)``."""
    F = np.maximum(as_matrix(F, "F"), 0.0)
    s = F.sum(axis=1, keepdims=True)
    centre = np.full_like(F, 1.0 / F.shape[1])
    with np.errstate(invalid="ignore", divide="ignore"):
        P = F / s
    return np.where(s > 0, P, centre)


def select_by_dd_fc(
    P_selected: np.ndarray,
    P_candidates: np.ndarray,
    fc: np.ndarray,
    n_select: int,
    *,
    n_neighbors: int = 5,
    n_candidates: int = 3,
    candidate_choice: _CandidateChoice = "roulette",
    random_state: np.random.Generator | None = None,
) -> np.ndarray:
    """Pick ``n_select`` of the candidates one at a time by DD, then FC.

    Parameters
    ----------
    P_selected : (s, M) array
        Projected directions of the solutions already selected (may be empty).
    P_candidates : (c, M) array
        Projected directions of the candidates.
    fc : (c,) array
        FC of the candidates.
    n_select : int
        How many candidates to pick (``<= c``).
    n_neighbors : int
        ``K`` in ``DD = sum_{k<=K} 1/d_k``.
    n_candidates : int
        ``L``, the size of the tournament of the least crowded candidates.
    candidate_choice : {"roulette", "best"}
        Winner by roulette wheel on ``1/FC`` or the smallest FC.
    random_state : numpy Generator
        Needed for ``"roulette"``.

    Returns
    -------
    (n_select,) int array
        Candidate indices in the order they were picked.
    """
    P_c = np.asarray(P_candidates, dtype=float)
    c = len(P_c)
    P_s = np.asarray(P_selected, dtype=float).reshape(-1, P_c.shape[1])
    fc = np.asarray(fc, dtype=float)
    if fc.shape != (c,):
        raise ValueError(f"fc must have shape ({c},) (one per candidate), got shape {fc.shape}")
    fc = np.maximum(fc, _FC_FLOOR)                        # below the resolution FC values tie
    n_select = check_int(n_select, "n_select", 0)
    if n_select > c:
        raise ValueError(f"n_select must be <= the number of candidates ({c}), got {n_select}")
    k = check_int(n_neighbors, "n_neighbors", 1)
    L = check_int(n_candidates, "n_candidates", 1)
    candidate_choice = check_choice(candidate_choice, "candidate_choice", _CHOICES)
    if candidate_choice == "roulette" and random_state is None:
        raise ValueError("random_state is required with candidate_choice='roulette'")

    D_cc = cdist(P_c, P_c)
    taken = np.zeros(c, dtype=bool)
    picked = np.empty(n_select, dtype=np.int64)
    with np.errstate(divide="ignore"):
        # nearest[i]: the (up to K) smallest distances from candidate i to the selected set,
        # sorted; updated incrementally after every pick (one column more until it holds K).
        if len(P_s):
            nearest = np.sort(cdist(P_c, P_s), axis=1)[:, :k]
            dd = (1.0 / nearest).sum(axis=1)
        else:
            # nothing selected yet: the first pick's density is measured among the candidates
            d = D_cc.copy()
            np.fill_diagonal(d, np.inf)
            near = np.sort(d, axis=1)[:, : min(k, c - 1)]
            nearest = np.empty((c, 0))
            dd = (1.0 / near).sum(axis=1) if near.shape[1] else np.zeros(c)
        for step in range(n_select):
            dd[taken] = np.nan                            # NaN sorts after inf: never chosen
            tour = np.argsort(dd, kind="stable")[: min(L, c - step)]   # least crowded, ties by index
            if candidate_choice == "best":
                win = tour[np.argmin(fc[tour])]           # FC ties: smaller DD, then index
            else:
                assert random_state is not None           # checked above for "roulette"
                cum = np.cumsum(1.0 / fc[tour])
                pos = np.searchsorted(cum, random_state.random() * cum[-1], side="right")
                win = tour[min(pos, len(tour) - 1)]
            picked[step] = win
            taken[win] = True
            nearest = np.sort(np.concatenate([nearest, D_cc[:, win, None]], axis=1), axis=1)[:, :k]
            dd = (1.0 / nearest).sum(axis=1)
    return picked


class DDFCSurvival(NormalizationForwarding, Survival):
    """Environmental selection of MaOEA-DDFC (non-dominated fronts, then DD/FC tournaments)."""

    def __init__(self, n_obj: int, *, n_neighbors: int = 5, n_candidates: int = 3,
                 candidate_choice: _CandidateChoice = "roulette"):
        super().__init__(filter_infeasible=True)
        self.n_neighbors = n_neighbors
        self.n_candidates = n_candidates
        self.candidate_choice = candidate_choice
        self.norm = HyperplaneNormalization(n_obj)

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        F = objectives(pop)
        if n_survive is None:
            n_survive = len(pop)
        fronts, rank = NonDominatedSorting().do(F, return_rank=True, n_stop_if_ranked=n_survive)
        self.norm.update(F, nondominated=fronts[0])
        Fn = self.normalize(F)
        fc = favorable_convergence(Fn)
        pop.set("rank", rank, "FC", fc)

        before = np.concatenate(fronts[:-1]) if len(fronts) > 1 else np.empty(0, dtype=int)
        last = np.asarray(fronts[-1])
        if len(before) + len(last) <= n_survive:
            return pop[np.concatenate([before, last])]
        P = directional_projection(Fn)
        chosen = select_by_dd_fc(P[before], P[last], fc[last], n_survive - len(before),
                                 n_neighbors=self.n_neighbors, n_candidates=self.n_candidates,
                                 candidate_choice=self.candidate_choice, random_state=random_state)
        return pop[np.concatenate([before, last[chosen]])]


def tournament_winners(F: np.ndarray, fc: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Winners of the binary tournaments ``a[t]`` vs ``b[t]`` (MaOEA-DDFC mating rule).

    ``a[t]`` wins if it Pareto-dominates ``b[t]``, or if neither dominates and
    ``fc[a[t]] <= fc[b[t]]``; otherwise ``b[t]`` wins. FC values below
    ``1e-6`` compare as equal (so ``a[t]``, the first drawn, wins between two
    such solutions; see the module's "Readings").
    """
    F = np.asarray(F, dtype=float)
    fc = np.maximum(np.asarray(fc, dtype=float), _FC_FLOOR)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    a_better = np.any(F[a] < F[b], axis=1)
    b_better = np.any(F[a] > F[b], axis=1)
    a_dom = a_better & ~b_better
    b_dom = b_better & ~a_better
    return np.where(a_dom | (~b_dom & (fc[a] <= fc[b])), a, b)


class DDFCMatingSelection(Selection):
    """Binary tournament: Pareto dominance first, then the smaller FC (ties: first drawn).

    FC is computed from the population's objectives with the normalisation held
    by the algorithm's :class:`DDFCSurvival` (or the population's own range if
    none is available).
    """

    def _do(self, problem, pop, n_select, n_parents, *args, random_state=None, algorithm=None,
            **kwargs):
        F = objectives(pop)
        survival = getattr(algorithm, "survival", None)
        if isinstance(survival, DDFCSurvival) and survival.nadir_point is not None:
            fc = favorable_convergence(survival.normalize(F))
        else:
            lo, hi = F.min(axis=0), F.max(axis=0)
            fc = favorable_convergence((F - lo) / np.where(hi - lo > 1e-12, hi - lo, 1e-12))
        n = n_select * n_parents
        a = random_state.integers(0, len(pop), size=n)
        b = random_state.integers(0, len(pop), size=n)
        return tournament_winners(F, fc, a, b).reshape(n_select, n_parents)


class MaOEADDFC(MOEA):
    """MaOEA-DDFC as a pymoo genetic algorithm (see the module docstring).

    Parameters
    ----------
    n_obj : int
        Number of objectives (for the normalisation).
    pop_size : int
        Population size ``N``.
    n_neighbors : int
        ``K``, neighbours in the directional density DD (5).
    n_candidates : int
        ``L``, least crowded candidates entering each FC tournament (3).
    candidate_choice : {"roulette", "best"}
        How the FC tournament is decided.
    sampling, crossover, mutation, eliminate_duplicates, output
        As for any pymoo genetic algorithm.
    """

    def __init__(self, n_obj: int, *, pop_size: int = POP_SIZE, n_neighbors: int = 5,
                 n_candidates: int = 3, candidate_choice: _CandidateChoice = "roulette", sampling=None,
                 crossover=None, mutation=None, eliminate_duplicates: bool = True, output=None):
        self.n_obj = check_int(n_obj, "n_obj", 2)
        n_neighbors = check_int(n_neighbors, "n_neighbors", 1)
        n_candidates = check_int(n_candidates, "n_candidates", 1)
        candidate_choice = check_choice(candidate_choice, "candidate_choice", _CHOICES)
        survival = DDFCSurvival(self.n_obj, n_neighbors=n_neighbors, n_candidates=n_candidates,
                                candidate_choice=candidate_choice)
        super().__init__(survival, DDFCMatingSelection(), pop_size=pop_size, sampling=sampling, crossover=crossover,
                         mutation=mutation, eliminate_duplicates=eliminate_duplicates, output=output)

    def _setup(self, problem, **kwargs):
        if problem.n_obj != self.n_obj:
            raise ValueError(f"n_obj is {self.n_obj} but the problem has {problem.n_obj} objectives")
        super()._setup(problem, **kwargs)


def make_maoea_ddfc(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                    n_neighbors: int = 5, n_candidates: int = 3,
                    candidate_choice: _CandidateChoice = "roulette") -> MaOEADDFC:
    """MaOEA-DDFC with the paper's settings (``K = 5``, ``L = 3``, SBX and PM as in the paper).

    The shape of every factory (:mod:`moo.algorithms`); ``operators="original"``:
    :data:`ORIGINAL_OPERATORS`.
    """
    n_obj, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    return MaOEADDFC(n_obj, pop_size=pop_size, n_neighbors=n_neighbors, n_candidates=n_candidates,
                     candidate_choice=candidate_choice, **variation)
