r"""MO-LSP, the multiobjective local search procedure (paper Section 3.2, Algorithm 2).

:func:`molsp` adds MO-LSP to any pymoo algorithm built on survival selection
(a :class:`~pymoo.algorithms.base.genetic.GeneticAlgorithm` with a
``survival`` operator: every MOEA of :mod:`moo.algorithms`, and pymoo's NSGA2,
NSGA3, SPEA2, AGEMOEA, SMSEMOA, ...). Each generation, after the host's own
step (mating, evaluation, survival), MO-LSP

1. takes the ``K`` individuals of the first two non-dominated fronts of the
   population (among the individuals with finite objectives, and feasible
   ones when the problem has constraints);
2. picks the leader :math:`\hat d`: the one whose box :math:`[y_j, r]` against
   the fixed reference point ``r`` has the largest volume
   :math:`\Gamma_j = \prod_k (r_k - y_{jk})` (:func:`leader_scores`);
3. builds ``K`` mutants (:func:`build_mutants`), with per-variable draws
   :math:`\kappa \sim U(0, 1)` and :math:`\phi \in \{1, 2\}`:

   .. math::

       m_{1,w} = d_w + d_w\,\kappa\,(-1)^{\phi}, \qquad                 \text{Eq. (bestM1)}

       m_{h+1,w} = z_{h,w} + \Lambda_{h,w}\,\kappa\,(-1)^{\phi}, \quad
       \Lambda_h = d - z_h,\ \Lambda_{h,w} = 0 \to 1,                   \text{Eqs. (delta), (bestM)}

   for the other candidates :math:`z_h`, ``h = 1 .. K - 1``;
4. repairs bounds by Eq. (ch) (:func:`repair_bounds`);
5. evaluates the mutants with the host's evaluator (they count in
   ``algorithm.evaluator.n_eval``), and lets the host's survival pick the next
   population from population + mutants, through exactly::

       algorithm.survival.do(problem, merged_pop, n_survive=algorithm.pop_size,
                             algorithm=algorithm, random_state=algorithm.random_state)

Design
------
``molsp(alg, ref_point=r)`` returns a *copy* of ``alg`` whose class is a
subclass created on the fly, ``MOLSP[<Host>]``, with :class:`MOLSP` as a mixin
placed before the host in the MRO. The mixin overrides only ``_advance`` (run
the host's ``_advance``, then the local search above) and ``_setup`` (check the
reference point against the problem). ``isinstance(wrapped, Host)`` stays true,
and everything else (mating, termination, display, callbacks, ``opt``) is the
host's own. Wrapped algorithms deep-copy and pickle (``__reduce_ex__`` rebuilds
the dynamic class).

Decisions (see PAPER_NOTES.md)
------------------------------
* :math:`\kappa` and :math:`\phi` are drawn **per variable** (independently for
  every entry of every mutant). The paper's Fig. "search" shows the search
  spaces :math:`A_1, A_2, A_3` as regions, not segments, which per-mutant draws
  would give.
* Eq. (ch) as printed gives :math:`f_r(0.25\,ss_w)` for a lower violation,
  i.e. a value in :math:`[0, 0.25\,ss_w]`, correct only when :math:`L_w = 0`;
  we use :math:`U(L_w, L_w + 0.25\,ss_w)` below the lower bound and
  :math:`U(U_w - 0.25\,ss_w, U_w)` above the upper one, :math:`ss_w = U_w - L_w`.
* Leader when no candidate strictly dominates ``r`` (the paper assumes one
  does; early generations often have none): the candidate with the smallest
  Chebyshev excess :math:`\max_k (y_{jk} - r_k)`. Scores are
  :math:`\Gamma_j > 0` inside the box and :math:`-\max_k (y_{jk} - r_k) \le 0`
  outside, so one ``argmax`` covers both; ties go to the lowest index. Since a
  dominated point never scores higher than the point dominating it, the leader
  always belongs to the first front.
* ``max_leaders`` (default ``None``: the paper's behaviour) caps ``K``: the
  leader plus the ``max_leaders - 1`` best other candidates, ordered by front
  and then by score.
* Budget: the mutants are built and evaluated only while the run's evaluation
  budget (a ``("n_eval", N)`` termination, found also inside combined
  criteria) is not spent; when fewer than ``K`` evaluations remain, only the
  first ones are kept (the leader's mutant first, then in the order above).
  So MO-LSP never takes the count past ``N``; the run stops as the host does,
  at the end of the first generation with ``n_eval >= N``, and the overshoot,
  if any, is the host's own (less than one offspring batch). Without an
  evaluation budget all ``K`` mutants are always evaluated.
* Mutants are not checked for duplicates; all randomness comes from
  ``algorithm.random_state`` (the run's Generator).

References
----------
Morais et al. (2022), "Robust path-following control design of heavy vehicles
based on multiobjective evolutionary optimization", Expert Systems with
Applications, Section 3.2 and Algorithm 2; the single-objective LSP of
de Moura Oliveira et al. (2019), cited there as ``de2019soft``.
"""

from __future__ import annotations

import copy
from functools import cache
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from pymoo.core.algorithm import Algorithm
from pymoo.core.population import Population
from pymoo.core.termination import MultipleCriteria
from pymoo.termination.max_eval import MaximumFunctionCallTermination
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from .algorithms.base import objectives
from .validation import as_matrix

if TYPE_CHECKING:
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.problem import Problem
    from pymoo.core.survival import Survival
    from pymoo.core.termination import Termination
    from pymoo.util.archive import Archive

__all__ = ["MOLSP", "molsp", "candidates", "leader_scores", "mutation_steps", "build_mutants",
           "repair_bounds", "propose"]

#: Share of the range where an out-of-bounds entry is redrawn, Eq. (ch).
REPAIR_SHARE = 0.25


# ---------------------------------------------------------------------------------------------
# The mechanics, as pure functions of arrays
# ---------------------------------------------------------------------------------------------

def leader_scores(F: ArrayLike, ref_point: ArrayLike) -> np.ndarray:
    r"""Leader score of each objective vector (larger is better).

    ``prod(r - y_j)`` (the volume of the box :math:`[y_j, r]`, the paper's
    :math:`\Gamma_m`) when ``y_j`` strictly dominates ``r``, else
    ``-max_k (y_jk - r_k) <= 0`` (minus the Chebyshev excess over ``r``).
    """
    F = as_matrix(F, "F")
    r = as_matrix(ref_point, "ref_point", rows=1, cols=F.shape[1],
                  cols_what="the number of objectives of F").ravel()
    gap = r - F
    inside = np.all(gap > 0, axis=1)
    return np.where(inside, np.prod(np.where(inside[:, None], gap, 1.0), axis=1), gap.min(axis=1))


def _check_max_leaders(max_leaders) -> None:
    if max_leaders is not None and (isinstance(max_leaders, bool) or not isinstance(max_leaders, (int, np.integer))
                                    or max_leaders < 1):
        raise ValueError(f"max_leaders must be None or an integer >= 1, got {max_leaders!r}")


def candidates(F: ArrayLike, ref_point: ArrayLike, max_leaders: int | None = None) -> np.ndarray:
    """Indices of the MO-LSP candidates, leader first.

    The individuals of the first two non-dominated fronts of ``F`` (pymoo's
    :class:`NonDominatedSorting`), the leader (largest :func:`leader_scores`)
    first, then the others ordered by front and by score (descending, stable),
    truncated to ``max_leaders`` if given.
    """
    F = as_matrix(F, "F")
    _check_max_leaders(max_leaders)
    score = leader_scores(F, ref_point)
    fronts = NonDominatedSorting().do(F, n_stop_if_ranked=len(F))
    idx = np.concatenate([np.asarray(f, dtype=int) for f in fronts[:2]])
    front_no = np.concatenate([np.full(len(f), k) for k, f in enumerate(fronts[:2])])
    order = np.lexsort((idx, -score[idx], front_no))   # front, then score desc, then index
    idx = idx[order]
    leader = idx[np.argmax(score[idx])]                 # first of the maxima: lowest front, lowest index
    idx = np.concatenate([[leader], idx[idx != leader]])
    return idx if max_leaders is None else idx[:max_leaders]


def mutation_steps(d: ArrayLike, Z: ArrayLike) -> np.ndarray:
    r"""``Lambda_h = d - z_h`` with zero entries replaced by 1, Eqs. (delta), (delta_cond).

    Parameters
    ----------
    d : array_like, shape (n,)
        The leader's decision vector.
    Z : array_like, shape (K - 1, n)
        The other candidates' decision vectors.
    """
    d = as_matrix(d, "d", rows=1).ravel()
    Z = as_matrix(Z, "Z", cols=d.size, cols_what="the number of variables of d", allow_empty=True)
    lam = d[None, :] - Z
    lam[lam == 0.0] = 1.0
    return lam


def build_mutants(d: ArrayLike, Z: ArrayLike, kappa: ArrayLike, phi: ArrayLike) -> np.ndarray:
    r"""The mutants of Eqs. (bestM1) and (bestM) for given draws.

    Row 0 is :math:`m_1 = d + d\,\kappa_0\,(-1)^{\phi_0}`; row ``h`` (``h >= 1``) is
    :math:`z_h + \Lambda_h\,\kappa_h\,(-1)^{\phi_h}` with :math:`\Lambda_h` from
    :func:`mutation_steps`. All products are entry-wise. As Eq. (bestM1) scales
    the leader's step with ``d`` itself, zero entries of ``d`` stay zero in
    :math:`m_1` (the paper's rule, kept as printed).

    Parameters
    ----------
    d : array_like, shape (n,)
    Z : array_like, shape (K - 1, n)
    kappa : array_like, shape (K, n)
        Values in [0, 1].
    phi : array_like of int, shape (K, n)
        Values in {1, 2}.

    Returns
    -------
    ndarray, shape (K, n)
        The mutants before bound repair.
    """
    d = as_matrix(d, "d", rows=1).ravel()
    lam = mutation_steps(d, Z)
    Z = np.asarray(Z, dtype=float).reshape(-1, d.size)
    K = lam.shape[0] + 1
    kappa = as_matrix(kappa, "kappa", rows=K, cols=d.size, rows_what="one per mutant",
                      cols_what="the number of variables")
    phi_arr = np.asarray(phi)
    if phi_arr.shape != (K, d.size) or not np.all((phi_arr == 1) | (phi_arr == 2)):
        raise ValueError(f"phi must be an array of shape {(K, d.size)} with entries in {{1, 2}}, "
                         f"got shape {phi_arr.shape}")
    sign = np.where(phi_arr == 1, -1.0, 1.0)                 # (-1)^phi
    base = np.vstack([d[None, :], Z])
    step = np.vstack([d[None, :], lam])
    return base + step * kappa * sign


def repair_bounds(M: ArrayLike, xl: ArrayLike, xu: ArrayLike, rng: np.random.Generator) -> np.ndarray:
    r"""Eq. (ch): redraw out-of-bounds entries in the nearest 25 % of the range.

    An entry below ``xl_w`` becomes ``U(xl_w, xl_w + 0.25 (xu_w - xl_w))``; one
    above ``xu_w`` becomes ``U(xu_w - 0.25 (xu_w - xl_w), xu_w)``. One uniform
    number is drawn for every entry of ``M`` (whether used or not), so the
    stream of draws does not depend on which entries violate. Infinite bounds
    are never violated.
    """
    M = as_matrix(M, "M", allow_empty=True)
    n = M.shape[1]
    xl = np.broadcast_to(np.asarray(xl, dtype=float), (n,))
    xu = np.broadcast_to(np.asarray(xu, dtype=float), (n,))
    if np.any(xu < xl):
        raise ValueError("xu must be >= xl entry-wise")
    u = rng.random(M.shape)
    span = np.where(np.isfinite(xu - xl), xu - xl, 0.0) * REPAIR_SHARE
    return np.where(xl > M, xl + u * span, np.where(xu < M, xu - u * span, M))


def propose(X: ArrayLike, F: ArrayLike, xl: ArrayLike, xu: ArrayLike, ref_point: ArrayLike,
            rng: np.random.Generator, max_leaders: int | None = None) -> np.ndarray:
    """One MO-LSP proposal: candidates, leader, mutants, bound repair (steps 1-4).

    Draws, in this order, ``kappa = rng.random((K, n))``,
    ``phi = rng.integers(1, 3, (K, n))`` and the repair numbers of
    :func:`repair_bounds`. Returns the ``(K, n)`` mutants, leader's first.
    """
    X = as_matrix(X, "X")
    F = as_matrix(F, "F", rows=X.shape[0], rows_what="one per row of X")
    idx = candidates(F, ref_point, max_leaders)
    d, Z = X[idx[0]], X[idx[1:]]
    K, n = len(idx), X.shape[1]
    kappa = rng.random((K, n))
    phi = rng.integers(1, 3, size=(K, n))
    return repair_bounds(build_mutants(d, Z, kappa, phi), xl, xu, rng)


# ---------------------------------------------------------------------------------------------
# The wrapper
# ---------------------------------------------------------------------------------------------

def _eval_budget(termination) -> float | None:
    """The smallest ``n_max_evals`` of a max-evaluation criterion in ``termination``, if any."""
    if isinstance(termination, MaximumFunctionCallTermination):
        n = termination.n_max_evals
        return None if n is None or not np.isfinite(n) else float(n)
    if isinstance(termination, MultipleCriteria):
        found = [b for b in (_eval_budget(t) for t in termination.criteria) if b is not None]
        return min(found) if found else None
    return None


if TYPE_CHECKING:
    class _SurvivalHost:
        """What :class:`MOLSP` uses of its host, a pymoo survival-based algorithm (type checking only).

        The attributes of a set-up :class:`pymoo.core.algorithm.Algorithm` /
        :class:`~pymoo.algorithms.base.genetic.GeneticAlgorithm` and the two
        hooks MO-LSP extends. At run time :class:`MOLSP` derives from ``object``
        and finds all of them on the host, the other base of ``MOLSP[<Host>]``.
        """

        problem: Problem
        pop: Population
        pop_size: int
        survival: Survival
        evaluator: Evaluator
        termination: Termination
        random_state: np.random.Generator
        n_iter: int
        data: dict[str, Any]
        archive: Archive | None

        def _setup(self, problem: Problem, **kwargs: Any) -> None: ...

        def _advance(self, infills: Population | None = None, **kwargs: Any) -> bool | None: ...
else:
    _SurvivalHost = object


class MOLSP(_SurvivalHost):
    """Mixin that runs MO-LSP after every generation of its host algorithm.

    Not instantiated directly: use :func:`molsp`. ``isinstance(alg, MOLSP)``
    tells whether an algorithm is wrapped. Attributes set by :func:`molsp`:
    ``molsp_ref_point`` (ndarray) and ``molsp_max_leaders`` (int or None).
    After each generation ``alg.data["molsp"]`` holds the counts of that
    generation (``n_candidates``, ``n_mutants``, ``n_survived``) and
    ``alg.data["molsp_n_eval"]`` the mutant evaluations so far.
    """

    molsp_ref_point: np.ndarray
    molsp_max_leaders: int | None
    _molsp_host: ClassVar[type]      # set by _wrapped_class

    def _setup(self, problem: Problem, **kwargs: Any) -> None:
        super()._setup(problem, **kwargs)
        if self.molsp_ref_point.size != problem.n_obj:
            raise ValueError(f"ref_point must have {problem.n_obj} entries (the number of objectives), "
                             f"got {self.molsp_ref_point.size}")
        self.data["molsp_n_eval"] = 0

    def _advance(self, infills: Population | None = None, **kwargs: Any) -> bool | None:
        value = super()._advance(infills=infills, **kwargs)
        if value is None or value:
            self._molsp_step()
        return value

    def _molsp_step(self) -> None:
        pop, problem = self.pop, self.problem
        stats = {"n_candidates": 0, "n_mutants": 0, "n_survived": 0}
        self.data["molsp"] = stats
        keep = np.all(np.isfinite(objectives(pop)), axis=1)
        if problem.has_constraints():
            keep &= np.asarray(pop.get("FEAS"), dtype=bool).ravel()
        pool = pop[np.flatnonzero(keep)]
        if len(pool) == 0:
            return
        budget = _eval_budget(self.termination)
        remaining = None if budget is None else int(max(budget - self.evaluator.n_eval, 0))
        if remaining == 0:
            return
        xl, xu = problem.bounds()
        n_var = problem.n_var
        xl = np.full(n_var, -np.inf) if xl is None else xl
        xu = np.full(n_var, np.inf) if xu is None else xu
        X = np.asarray(pool.get("X"), dtype=float)
        mutants_X = propose(X, objectives(pool), xl, xu, self.molsp_ref_point, self.random_state,
                            self.molsp_max_leaders)
        stats["n_candidates"] = len(mutants_X)
        if remaining is not None:
            mutants_X = mutants_X[:remaining]
        mutants = Population.new(X=mutants_X)
        mutants.set("n_gen", self.n_iter)
        mutants.set("n_iter", self.n_iter)
        self.evaluator.eval(problem, mutants, algorithm=self)
        self.data["molsp_n_eval"] += len(mutants)
        merged = Population.merge(pop, mutants)
        self.pop = self.survival.do(problem, merged, n_survive=self.pop_size, algorithm=self,
                                    random_state=self.random_state)
        stats["n_mutants"] = len(mutants)
        mutant_ids = {id(ind) for ind in mutants}
        stats["n_survived"] = sum(id(ind) in mutant_ids for ind in self.pop)
        if self.archive is not None:
            self.archive = self.archive.add(mutants)

    def __reduce_ex__(self, protocol: Any) -> tuple[Any, ...]:
        return _restore, (type(self)._molsp_host,), self.__dict__.copy()


@cache
def _wrapped_class(host: type) -> type:
    return type(f"MOLSP[{host.__name__}]", (MOLSP, host), {"__module__": __name__, "_molsp_host": host})


def _restore(host: type):
    return object.__new__(_wrapped_class(host))


def molsp(algorithm: Algorithm, *, ref_point: ArrayLike, max_leaders: int | None = None) -> Algorithm:
    """A copy of ``algorithm`` that runs MO-LSP after each of its generations.

    Parameters
    ----------
    algorithm : pymoo Algorithm
        Not yet set up (``minimize``/``setup`` not called), with a ``survival``
        operator and a ``pop_size``: every :class:`~pymoo.algorithms.base.genetic.GeneticAlgorithm`-based MOEA.
        It is deep-copied; the argument is left untouched.
    ref_point : array_like, shape (n_obj,)
        The fixed reference point ``r`` of the leader choice (checked against the
        problem's number of objectives at setup).
    max_leaders : int, optional
        Cap on the number of candidates ``K`` (and so of mutants per
        generation). ``None`` (default) is the paper's behaviour, ``K`` up to
        the population size.

    Returns
    -------
    Algorithm
        An instance of ``MOLSP[<type(algorithm).__name__>]``, a subclass of both
        :class:`MOLSP` and ``type(algorithm)``.

    Examples
    --------
    >>> from pymoo.algorithms.moo.nsga2 import NSGA2
    >>> from pymoo.optimize import minimize
    >>> from pymoo.problems import get_problem
    >>> alg = molsp(NSGA2(pop_size=20), ref_point=[1.1, 1.1])
    >>> res = minimize(get_problem("zdt1"), alg, ("n_eval", 400), seed=1)
    >>> res.algorithm.evaluator.n_eval <= 400 + 20
    True
    """
    if not isinstance(algorithm, Algorithm):
        raise TypeError(f"algorithm must be a pymoo Algorithm, got {type(algorithm).__name__}")
    if isinstance(algorithm, MOLSP):
        raise ValueError("algorithm already runs MO-LSP")
    if getattr(algorithm, "survival", None) is None or getattr(algorithm, "pop_size", None) is None:
        raise TypeError(f"algorithm must have a survival operator and a pop_size (a survival-based "
                        f"MOEA), {type(algorithm).__name__} has not")
    if algorithm.problem is not None or algorithm.is_initialized:
        raise ValueError("algorithm must not be set up yet: wrap it before minimize()/setup()")
    r = as_matrix(ref_point, "ref_point", rows=1).ravel()
    _check_max_leaders(max_leaders)
    host: type = type(algorithm)
    wrapped = copy.deepcopy(algorithm)
    wrapped.__class__ = _wrapped_class(host)
    wrapped.molsp_ref_point = r
    wrapped.molsp_max_leaders = None if max_leaders is None else int(max_leaders)
    return wrapped
