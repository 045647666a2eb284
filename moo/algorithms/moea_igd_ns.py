r"""MOEA/IGD-NS: selection by the IGD with non-contributing solutions.

Reference
---------
Y. Tian, X. Zhang, R. Cheng and Y. Jin, "A multi-objective evolutionary
algorithm based on an enhanced inverted generational distance metric",
Proceedings of the IEEE Congress on Evolutionary Computation (CEC 2016),
pp. 5222-5229, doi:10.1109/CEC.2016.7748352.

What is implemented
-------------------
*IGD-NS.* For a solution set ``Q`` and a reference set ``P*`` (the
objective vectors of the external archive), a solution ``x in Q`` is
*non-contributing* when it is the nearest member of ``Q`` of no reference
point; with ``Q*`` the non-contributing solutions and ``d`` the Euclidean
distance,

.. math::

    \mathrm{IGD\text{-}NS}(Q, P^*) = \sum_{y \in P^*} \min_{x \in Q} d(x, y)
        + \sum_{x' \in Q^*} \min_{y \in P^*} d(x', y).

The first term is (unnormalised) IGD; the second pulls the solutions that do
not serve any reference point towards the archive, so they too carry
selection pressure.

*Environmental selection.* The received population is sorted into
non-dominated fronts; whole fronts are accepted while they fit, and the last
front ``F_l`` is reduced one solution at a time: each step removes the
solution ``x`` whose removal leaves the smallest ``IGD-NS(F_l \ {x}, P*)``
(computed for all candidates at once from the nearest and second-nearest
solution of every reference point, see :func:`igd_ns_deletion_scores`).

*External archive.* The archive holds non-dominated solutions of everything
the survival has seen: on every call ``A <- ND(A u pop)``; when it exceeds
``archive_size`` it keeps the solutions with the largest value of each
objective (the extremes) and then adds, one at a time, the solution with the
largest minimum angle to those already kept (:func:`truncate_by_angle`).

*Mating selection.* Uniformly random parents (pymoo's random selection).

Readings where the paper is ambiguous (chosen as a careful reader would)
------------------------------------------------------------------------
The full text of the paper was not at hand when this module was written; the
archive bound, the archive truncation and the last-front evaluation below were
checked against PlatEMO's MOEA/IGD-NS (by the paper's authors' group; read to
resolve doubts, nothing ported).

* The archive and the reference set derived from it are updated inside the
  survival from the population it receives (the MO-LSP contract: the host's
  survival may be called twice per generation on merged populations); since
  that population contains the offspring, this is the paper's
  ``A <- Update(A u O)``.
* The archive bound defaults to ``5 * pop_size`` (the setting of the PlatEMO
  implementation the reproduced paper's experiments ran on).
* Angles for the archive truncation are measured at the ideal point of the
  candidate set, so they do not depend on the origin of the objectives.
* IGD-NS is evaluated on the last front only (the solutions of earlier fronts
  are kept whatever their contribution); distances are in raw objective
  units, as in the paper. Exact ties in the deletion score remove the
  lowest index (deterministic). Objective-space duplicates in the archive
  are kept once.
* Infeasible individuals are placed after the feasible ones by pymoo's
  :class:`~pymoo.core.survival.Survival` (least violation first) and never
  enter the archive.

Notes
-----
What the algorithm does on the test problems (measured runs, collapses, comparisons with
other implementations) is in the documentation's Validation pages,
:ref:`validation-moea-igd-ns`.
"""

from __future__ import annotations

import numpy as np
from moocore import is_nondominated
from pymoo.core.population import Population
from pymoo.core.survival import Survival
from pymoo.operators.selection.rnd import RandomSelection
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from scipy.spatial.distance import cdist

from ..validation import check_int
from .base import MOEA, factory_arguments, objectives
from .operators import POP_SIZE, OperatorSettings

__all__ = [
    "IGDNSSurvival",
    "MOEAIGDNS",
    "igd_ns",
    "igd_ns_deletion_scores",
    "make_moea_igd_ns",
    "reduce_by_igd_ns",
    "truncate_by_angle",
    "update_archive",
    "ORIGINAL_OPERATORS",
]

#: MOEA/IGD-NS's own settings (Tian et al. 2016, Sec. IV: SBX pc = 1, eta_c = 20; polynomial
#: mutation pm = 1/n, eta_m = 20, PlatEMO's defaults, in which the authors' group ran it).
ORIGINAL_OPERATORS = OperatorSettings(crossover_prob=1.0, crossover_eta=20.0, mutation_rate=1.0, mutation_eta=20.0,
                                      source="Tian et al. (2016), Sec. IV")


def _as_points(value, name: str, n_obj: int | None = None) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim != 2:
        raise ValueError(f"{name} must be a 2-D array (n_points, n_obj), got shape {arr.shape}")
    if n_obj is not None and arr.shape[1] != n_obj:
        raise ValueError(f"{name} must have {n_obj} columns, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must have finite entries (found NaN or inf)")
    return arr


def igd_ns(Q, reference) -> float:
    """IGD-NS of the solution set ``Q`` with respect to ``reference`` (Tian et al. 2016, Eq. 2).

    Parameters
    ----------
    Q : array_like, shape (n, M)
        Objective vectors of the solutions.
    reference : array_like, shape (r, M)
        Reference points ``P*`` (the archive).

    Returns
    -------
    float
        ``sum_y min_x d(x, y) + sum_{x' non-contributing} min_y d(x', y)``.
        A solution is contributing when it is the nearest (first in index
        order on ties) of at least one reference point.
    """
    Q = _as_points(Q, "Q")
    R = _as_points(reference, "reference", Q.shape[1])
    if len(Q) == 0 or len(R) == 0:
        raise ValueError(f"Q and reference must be non-empty, got shapes {Q.shape} and {R.shape}")
    D = cdist(Q, R)
    nearest = D.argmin(axis=0)
    contributing = np.zeros(len(Q), dtype=bool)
    contributing[nearest] = True
    return float(D.min(axis=0).sum() + D.min(axis=1)[~contributing].sum())


def _two_nearest(DT: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Row-wise nearest and second-nearest columns of ``DT`` and their values (ties: lower index first).

    Two ``argmin`` passes (much faster than ``argpartition`` on short rows);
    ``DT`` is modified during the call and restored.
    """
    rows = np.arange(DT.shape[0])
    i1 = DT.argmin(axis=1)
    v1 = DT[rows, i1]
    DT[rows, i1] = np.inf
    i2 = DT.argmin(axis=1)
    v2 = DT[rows, i2]
    DT[rows, i1] = v1
    return i1, i2, v1, v2


def _relative_scores(n1, n2, d1, d2, con, alive) -> tuple[np.ndarray, float]:
    """Deletion scores minus the current IGD-NS value (and that value); ``inf`` for dead candidates."""
    n = len(alive)
    contributing = np.bincount(n1, minlength=n) > 0
    noncontrib = alive & ~contributing
    delta = np.bincount(n1, weights=d2 - d1, minlength=n)
    # S(x) = {n2(y) : n1(y) = x} minus the contributing set, each member counted once
    promoted = noncontrib[n2]
    if promoted.any():
        pairs = np.unique(n1[promoted] * n + n2[promoted])
        delta -= np.bincount(pairs // n, weights=con[pairs % n], minlength=n)
    total = float(d1.sum() + con[noncontrib].sum())
    return np.where(contributing, delta, np.where(noncontrib, -con, np.inf)), total


def igd_ns_deletion_scores(D: np.ndarray, alive: np.ndarray) -> np.ndarray:
    r"""``IGD-NS(Q \ {x}, P*)`` for every alive ``x`` at once.

    Parameters
    ----------
    D : ndarray, shape (n, r)
        Distances between the ``n`` candidate solutions and the ``r``
        reference points.
    alive : ndarray of bool, shape (n,)
        The candidates currently in ``Q`` (at least two).

    Returns
    -------
    ndarray, shape (n,)
        The score of each alive candidate (``inf`` for the others).

    Notes
    -----
    With ``n1(y), n2(y)`` the nearest and second-nearest alive solutions of
    reference point ``y`` (distances ``d1, d2``), ``C`` the contributing set
    ``{n1(y)}`` and ``c(x) = min_y d(x, y)``, the current value is
    ``I = sum_y d1(y) + sum_{x not in C} c(x)``. Removing a non-contributing
    ``x`` gives ``I - c(x)``; removing a contributing ``x`` moves each
    reference point it served to ``n2(y)`` and makes those ``n2(y)`` that were
    non-contributing contributing:
    ``I + sum_{y: n1(y)=x} (d2(y) - d1(y)) - sum_{z in S(x)} c(z)`` with
    ``S(x) = {n2(y) : n1(y) = x} \ C``.
    """
    D = np.asarray(D, dtype=float)
    alive = np.asarray(alive, dtype=bool)
    if D.ndim != 2 or alive.shape != (D.shape[0],):
        raise ValueError(f"D must be 2-D and alive must have shape ({D.shape[0] if D.ndim else '?'},), "
                         f"got D {D.shape} and alive {alive.shape}")
    if alive.sum() < 2:
        raise ValueError(f"at least two candidates must be alive, got {int(alive.sum())}")
    n1, n2, d1, d2 = _two_nearest(np.where(alive[None, :], D.T, np.inf))
    relative, total = _relative_scores(n1, n2, d1, d2, D.min(axis=1), alive)
    return total + relative


def reduce_by_igd_ns(F, reference, n_keep: int) -> np.ndarray:
    """Indices of the ``n_keep`` solutions kept by deleting, one at a time, the worst for IGD-NS.

    Each step removes the candidate whose removal gives the smallest
    ``IGD-NS`` of the remaining set with respect to ``reference`` (the scores
    of :func:`igd_ns_deletion_scores`; only the reference points whose
    nearest or second-nearest solution was deleted are re-examined).
    Returns the kept indices in increasing order.
    """
    F = _as_points(F, "F")
    R = _as_points(reference, "reference", F.shape[1])
    n_keep = check_int(n_keep, "n_keep", 0)
    n = len(F)
    if n_keep >= n:
        return np.arange(n)
    if n_keep == 0:
        return np.zeros(0, dtype=int)
    if len(R) == 0:
        raise ValueError("reference must contain at least one point")
    DT = cdist(R, F)                          # (r, n): one row per reference point
    con = DT.min(axis=0)
    alive = np.ones(n, dtype=bool)
    n1, n2, d1, d2 = _two_nearest(DT)
    for step in range(n - n_keep):            # one vectorised scoring per deletion
        x = int(np.argmin(_relative_scores(n1, n2, d1, d2, con, alive)[0]))
        alive[x] = False
        if step == n - n_keep - 1:
            break
        DT[:, x] = np.inf
        stale = np.flatnonzero((n1 == x) | (n2 == x))
        if stale.size:
            n1[stale], n2[stale], d1[stale], d2[stale] = _two_nearest(DT[stale])
    return np.flatnonzero(alive)


def truncate_by_angle(F, max_size: int, random_state=None) -> np.ndarray:
    """Indices of at most ``max_size`` rows of ``F`` spread by angle.

    The rows holding the largest value of each objective are kept first (a
    random subset of them if they alone exceed ``max_size``); the others are
    added one at a time, each time the row whose largest cosine similarity to
    the rows already kept is smallest (largest minimum angle). Vectors are
    taken from the ideal point ``min(F)``. Returns indices in selection order.
    """
    F = _as_points(F, "F")
    max_size = check_int(max_size, "max_size", 1)
    n = len(F)
    if n <= max_size:
        return np.arange(n)
    extremes = np.unique(F.argmax(axis=0))
    if len(extremes) >= max_size:
        if random_state is None:
            raise ValueError("random_state is needed when the extremes alone exceed max_size")
        return np.sort(random_state.choice(extremes, size=max_size, replace=False))
    V = F - F.min(axis=0)
    V = V / np.maximum(np.linalg.norm(V, axis=1, keepdims=True), 1e-300)
    # score = largest cosine similarity to the kept rows, +inf for the kept rows themselves
    # (row by row: a full n x n product costs more than the rows actually needed)
    score = np.max(V @ V[extremes].T, axis=1)
    score[extremes] = np.inf
    order = list(extremes)
    for _ in range(max_size - len(extremes)):
        k = int(np.argmin(score))
        order.append(k)
        np.maximum(score, V @ V[k], out=score)
        score[k] = np.inf
    return np.asarray(order, dtype=int)


def update_archive(F, max_size: int, random_state=None) -> np.ndarray:
    """Indices of the new archive among the candidate rows ``F``.

    Keeps the non-dominated rows (one copy of duplicates) and, if there are
    more than ``max_size``, truncates them with :func:`truncate_by_angle`.
    """
    F = _as_points(F, "F")
    nd = np.flatnonzero(is_nondominated(F, keep_weakly=False))
    return nd[truncate_by_angle(F[nd], max_size, random_state=random_state)]


class IGDNSSurvival(Survival):
    """MOEA/IGD-NS environmental selection with its external archive.

    Attributes
    ----------
    archive : pymoo Population or None
        The external archive of non-dominated solutions (updated on every
        call from the population received).
    """

    def __init__(self, archive_size: int) -> None:
        super().__init__(filter_infeasible=True)
        self.archive_size = check_int(archive_size, "archive_size", 1)
        self.archive: Population | None = None

    def reset(self) -> None:
        """Empty the archive (called when a run is set up)."""
        self.archive = None

    def _update_archive(self, pop, random_state) -> Population:
        """Merge ``pop`` into the archive and update it by :func:`update_archive`; returns the new archive."""
        merged = pop if self.archive is None else Population.merge(self.archive, pop)
        keep = update_archive(objectives(merged), self.archive_size, random_state=random_state)
        self.archive = merged[keep]
        return self.archive

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        archive = self._update_archive(pop, random_state)
        F = objectives(pop)
        fronts = NonDominatedSorting().do(F, n_stop_if_ranked=n_survive)
        selected: list[np.ndarray] = []
        n_sel = 0
        for front in fronts:
            if n_sel + len(front) <= n_survive:
                selected.append(front)
                n_sel += len(front)
            else:
                kept = reduce_by_igd_ns(F[front], objectives(archive), n_survive - n_sel)
                selected.append(front[kept])
                n_sel += len(kept)
            if n_sel >= n_survive:
                break
        return pop[np.concatenate(selected)]


class MOEAIGDNS(MOEA):
    """MOEA/IGD-NS (Tian, Zhang, Cheng & Jin, CEC 2016) as a pymoo algorithm.

    Parameters
    ----------
    pop_size : int
        Population size.
    archive_size : int, optional
        Bound of the external archive (default ``5 * pop_size``).
    sampling, crossover, mutation
        pymoo operators (defaults: uniform random sampling and the paper's
        SBX / polynomial mutation of :mod:`moo.algorithms.operators`).
    eliminate_duplicates : bool
        Remove duplicate offspring (default True).
    """

    def __init__(self, *, pop_size: int = POP_SIZE, archive_size: int | None = None, sampling=None,
                 crossover=None, mutation=None, eliminate_duplicates: bool = True, output=None) -> None:
        pop_size = check_int(pop_size, "pop_size", 2)
        survival = IGDNSSurvival(5 * pop_size if archive_size is None else archive_size)
        super().__init__(survival, RandomSelection(), pop_size=pop_size, sampling=sampling, crossover=crossover,
                         mutation=mutation, eliminate_duplicates=eliminate_duplicates, output=output)


def make_moea_igd_ns(*, n_obj: int, pop_size: int = POP_SIZE, operators: str | OperatorSettings = "paper",
                     archive_size: int | None = None) -> MOEAIGDNS:
    """MOEA/IGD-NS with the paper's settings; the shape of every factory (:mod:`moo.algorithms`).

    Parameters
    ----------
    n_obj : int
        Number of objectives (the algorithm needs no reference directions;
        checked for consistency with the registry's signature).
    pop_size : int
        Population size (92 in the paper).
    operators : {"paper", "original"} or OperatorSettings
        Variation settings; ``"original"``: :data:`ORIGINAL_OPERATORS`.
    archive_size : int, optional
        Bound of the external archive (default ``5 * pop_size``).
    """
    _, pop_size, variation = factory_arguments(n_obj, pop_size, operators, ORIGINAL_OPERATORS)
    return MOEAIGDNS(pop_size=pop_size, archive_size=archive_size, **variation)
