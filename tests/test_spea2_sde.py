"""Tests of SPEA2+SDE (moo.algorithms.spea2_sde).

Expected values are worked out by hand in the comments, or come from a
per-pair reference written straight from the definitions (Li, Yang & Liu
2014, Sec. III; Zitzler, Laumanns & Thiele 2001, Sec. 3), independent of the
vectorised code under test.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.indicators.igd import IGD
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.util.ref_dirs import get_reference_directions
from scipy.spatial.distance import cdist

from moo.algorithms.base import BinaryTournament
from moo.algorithms.spea2_sde import (
    SPEA2SDESurvival,
    _sde_tournament,
    make_spea2_sde,
    sde_fitness,
    sde_truncation,
    shifted_distances,
)

# Three mutually non-dominated points (2 objectives) used throughout:
#   p0 = (1, 4), p1 = (2, 2), p2 = (4.5, 1)
# Shifted distance seen from i: move j to max(f(j), f(i)), then Euclidean.
#   sd(0,1): max((2,2),(1,4)) = (2,4) - (1,4) = (1,0)   -> 1
#   sd(0,2): max((4.5,1),(1,4)) = (4.5,4) - (1,4)       -> 3.5
#   sd(1,0): max((1,4),(2,2)) = (2,4) - (2,2) = (0,2)   -> 2
#   sd(1,2): (4.5,2) - (2,2) = (2.5,0)                  -> 2.5
#   sd(2,0): (4.5,4) - (4.5,1) = (0,3)                  -> 3
#   sd(2,1): (4.5,2) - (4.5,1) = (0,1)                  -> 1
THREE = np.array([[1.0, 4.0], [2.0, 2.0], [4.5, 1.0]])
THREE_SD = np.array([[np.inf, 1.0, 3.5], [2.0, np.inf, 2.5], [3.0, 1.0, np.inf]])


class _Dummy(Problem):
    def __init__(self, n_obj=2):
        super().__init__(n_var=1, n_obj=n_obj, xl=0.0, xu=1.0)


def _pop(F, cv=None):
    F = np.asarray(F, dtype=float)
    pop = Population.new("X", np.zeros((len(F), 1)), "F", F)
    pop.set("CV", np.zeros((len(F), 1)) if cv is None else np.asarray(cv, dtype=float)[:, None])
    return pop


def _reference_sd(F):
    """Shifted distance by the case definition (Li et al. 2014, Sec. III).

    f_k(q') = f_k(p) if f_k(q) < f_k(p) else f_k(q).
    """
    n = len(F)
    D = np.full((n, n), np.inf)
    for p, q in itertools.permutations(range(n), 2):
        shifted = np.array([max(F[q, k], F[p, k]) for k in range(F.shape[1])])
        D[p, q] = cdist(F[p][None], shifted[None])[0, 0]
    return D


def _reference_fitness(F, G):
    """SPEA2 fitness by per-individual loops: dominance on F, shifted distances on G."""
    n = len(F)
    dom = lambda a, b: np.all(F[a] <= F[b]) and np.any(F[a] < F[b])  # noqa: E731
    S = [sum(dom(i, j) for j in range(n)) for i in range(n)]
    R = [sum(S[j] for j in range(n) if dom(j, i)) for i in range(n)]
    D = _reference_sd(G)
    k = int(np.floor(np.sqrt(n)))
    dens = [1.0 / (sorted(D[i, j] for j in range(n) if j != i)[k - 1] + 2.0) for i in range(n)]
    return np.array(R, float) + np.array(dens), np.array(R, float), np.array(dens)


def _naive_truncation(D, n_keep):
    """Zitzler's truncation by brute force: re-sort every row after each removal."""
    alive = list(range(len(D)))
    while len(alive) > n_keep:
        rows = [tuple(sorted(D[i, j] for j in alive if j != i)) for i in alive]
        alive.pop(min(range(len(alive)), key=lambda a: (rows[a], a)))
    return np.array(alive)


# ----------------------------------------------------------------------------- shifted distances

def test_shifted_distances_hand_example():
    np.testing.assert_array_equal(shifted_distances(THREE), THREE_SD)


def test_shifted_distance_is_zero_to_a_dominating_point_and_euclidean_when_worse_everywhere():
    # q = (1,1) dominates p = (2,3): q shifted to p itself, sd(p,q) = 0.
    # seen from q, p is worse in every objective: no shift, sd(q,p) = |(1,2)| = sqrt(5).
    D = shifted_distances([[2.0, 3.0], [1.0, 1.0]])
    assert D[0, 1] == 0.0
    assert D[1, 0] == pytest.approx(np.sqrt(5.0), rel=1e-15)


def test_shifted_distances_match_the_definition_on_random_sets():
    rng = np.random.default_rng(3)
    for n, m in [(2, 2), (7, 3), (15, 5)]:
        F = rng.random((n, m))
        np.testing.assert_allclose(shifted_distances(F), _reference_sd(F), rtol=1e-14, atol=0)


def test_shifted_distances_reject_bad_input():
    with pytest.raises(ValueError, match=r"F must be a non-empty 2-D array.*shape \(3,\)"):
        shifted_distances([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="F must have finite entries"):
        shifted_distances([[1.0, np.nan], [0.0, 1.0]])
    with pytest.raises(TypeError, match="F must be"):
        shifted_distances("abc")


# ----------------------------------------------------------------------------- fitness

def test_fitness_hand_example_raw_objectives():
    # F = p0 (1,4), p1 (2,2), p2 (4.5,1), p3 (3,3), p4 (5,5).
    # Dominance: p1 > p3, p4; p3 > p4; p0 > p4; p2 > p4.
    # Strength S = [1, 2, 1, 1, 0]; raw R = [0, 0, 0, S(p1) = 2, 1+2+1+1 = 5].
    # n = 5 -> k = floor(sqrt 5) = 2: second smallest shifted distance seen from each:
    #   p0: to p1 1, p3 (3,4)-(1,4) = 2, p2 3.5, p4 |(4,1)| -> sigma = 2
    #   p1: to p0 2, p2 2.5, p3 |(1,1)| = 1.414, p4 |(3,3)| -> sigma = 2
    #   p2: to p1 1, p3 (4.5,3)-(4.5,1) = 2, p0 3, p4 |(0.5,4)| -> sigma = 2
    #   p3: to p1 0 (p1 dominates p3), p0 (3,4)-(3,3) = 1, p2 (4.5,3)-(3,3) = 1.5, p4 -> sigma = 1
    #   p4: dominated by all -> every sd is 0 -> sigma = 0
    # D = 1/(sigma + 2) = [1/4, 1/4, 1/4, 1/3, 1/2]
    F = np.vstack([THREE, [[3.0, 3.0], [5.0, 5.0]]])
    fit, raw, dens = sde_fitness(F, normalize=False)
    np.testing.assert_array_equal(raw, [0, 0, 0, 2, 5])
    np.testing.assert_allclose(dens, [0.25, 0.25, 0.25, 1 / 3, 0.5], rtol=1e-15)
    np.testing.assert_allclose(fit, [0.25, 0.25, 0.25, 2 + 1 / 3, 5.5], rtol=1e-15)
    # normalised by the ideal (1,1) and the non-dominated nadir (4.5, 4): spans (3.5, 3),
    #   p0 (0,1), p1 (2/7,1/3), p2 (1,0), p3 (4/7,2/3), p4 (8/7,4/3); second smallest sd:
    #   p0: to p1 (2/7,0), to p3 (4/7,0), to p2 (1,0)              -> sigma = 4/7, D = 7/18
    #   p1: to p3 |(2/7,1/3)| = 0.439, to p0 (0,2/3), to p2 (5/7,0) -> sigma = 2/3, D = 3/8
    #   p2: to p1 (0,1/3), to p3 (0,2/3), to p0 (0,1)              -> sigma = 2/3, D = 3/8
    #   p3: to p1 0, to p0 (0,1/3), to p2 (3/7,0)                  -> sigma = 1/3, D = 3/7
    #   p4: all 0                                                  -> D = 1/2
    _, raw_n, dens_n = sde_fitness(F)
    np.testing.assert_array_equal(raw_n, raw)
    np.testing.assert_allclose(dens_n, [7 / 18, 3 / 8, 3 / 8, 3 / 7, 0.5], rtol=1e-14)


def test_fitness_matches_per_individual_reference():
    rng = np.random.default_rng(11)
    for n, m in [(9, 2), (16, 3), (30, 4)]:
        F = rng.random((n, m)) * np.array([1.0, 100.0, 0.01, 5.0])[:m]
        F[n // 2] = F[0] + 0.1                 # make sure some dominance exists
        nondominated = [not any(np.all(g <= f) and np.any(g < f) for g in F) for f in F]
        lo, hi = F.min(0), F[nondominated].max(0)
        for normalize, G in [(False, F), (True, (F - lo) / (hi - lo))]:
            got = sde_fitness(F, normalize=normalize)
            want = _reference_fitness(F, G)
            for g, w in zip(got, want, strict=True):
                np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-15)


def test_fitness_below_one_iff_nondominated():
    rng = np.random.default_rng(5)
    F = rng.random((40, 3))
    fit, raw, _ = sde_fitness(F)
    dominated = np.array([np.any(np.all(f >= F, axis=1) & np.any(f > F, axis=1)) for f in F])
    np.testing.assert_array_equal(fit < 1.0, ~dominated)
    np.testing.assert_array_equal(raw == 0, ~dominated)


def test_fitness_single_individual():
    fit, raw, dens = sde_fitness([[1.0, 2.0]])
    assert fit.tolist() == [0.5] and raw.tolist() == [0.0] and dens.tolist() == [0.5]


# ----------------------------------------------------------------------------- truncation

def test_truncation_hand_example_keeps_the_knee_unlike_euclidean():
    # Sorted shifted rows: p0 (1, 3.5), p1 (2, 2.5), p2 (1, 3): p0 and p2 tie on the
    # nearest distance, p2's second (3) < p0's (3.5) -> p2 removed.
    # Then among {p0, p1}: sd(0,1) = 1 < sd(1,0) = 2 -> p0 removed.
    np.testing.assert_array_equal(sde_truncation(THREE_SD, 2), [0, 1])
    np.testing.assert_array_equal(sde_truncation(THREE_SD, 1), [1])
    # Plain Euclidean SPEA2 truncation removes the middle point instead:
    # d01 = sqrt 5 = 2.236, d12 = sqrt 7.25 = 2.693, d02 = sqrt 21.25 = 4.610:
    # rows p0 (2.236, 4.610), p1 (2.236, 2.693), p2 (2.693, 4.610) -> p1 removed.
    np.testing.assert_array_equal(sde_truncation(cdist(THREE, THREE), 2), [0, 2])


def test_truncation_exact_tie_removes_lowest_index():
    # (1,4), (2,2), (4,1): rows (1,3), (2,2), (1,3) -> exact tie of p0 and p2 -> p0 goes.
    D = shifted_distances([[1.0, 4.0], [2.0, 2.0], [4.0, 1.0]])
    np.testing.assert_array_equal(sde_truncation(D, 2), [1, 2])


def test_truncation_matches_brute_force():
    rng = np.random.default_rng(7)
    for trial in range(60):
        n, m = int(rng.integers(2, 25)), int(rng.integers(2, 5))
        F = rng.random((n, m))
        if trial % 3 == 0:
            F = np.round(F, 1)                  # ties and duplicates
        D = shifted_distances(F)
        n_keep = int(rng.integers(1, n + 1))
        np.testing.assert_array_equal(sde_truncation(D, n_keep), _naive_truncation(D, n_keep))


def test_truncation_rejects_bad_input():
    with pytest.raises(ValueError, match=r"dist must be a square.*shape \(2, 3\)"):
        sde_truncation(np.zeros((2, 3)), 1)
    with pytest.raises(ValueError, match=r"n_keep must be in \[1, 3\].*got 4"):
        sde_truncation(THREE_SD, 4)
    with pytest.raises(ValueError, match="n_keep"):
        sde_truncation(THREE_SD, 0)
    with pytest.raises(TypeError, match="n_keep must be an integer"):
        sde_truncation(THREE_SD, 1.5)
    with pytest.raises(ValueError, match="NaN"):
        sde_truncation(np.array([[0.0, np.nan], [1.0, 0.0]]), 1)


# ----------------------------------------------------------------------------- survival and mating

def test_survival_fills_by_fitness_then_truncates():
    # Same five points as the fitness example, normalised fitness [7/18, 3/8, 3/8, 2 + 3/7, 5.5].
    F = np.vstack([THREE, [[3.0, 3.0], [5.0, 5.0]]])
    surv = SPEA2SDESurvival()
    problem = _Dummy()
    # 4 survivors: the 3 non-dominated + the best dominated one (p3, 2.43 < 5.5), in fitness order
    out = surv.do(problem, _pop(F), n_survive=4, random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(out.get("F"), F[[1, 2, 0, 3]])
    np.testing.assert_allclose(out.get("sde_fitness"), [3 / 8, 3 / 8, 7 / 18, 2 + 3 / 7], rtol=1e-14)
    # 2 survivors: truncation of {p0, p1, p2} in the normalised space (see the fitness example):
    #   sorted rows p0 (2/7, 1), p1 (2/3, 5/7), p2 (1/3, 1) -> p0 goes;
    #   then p1 sees p2 at 5/7, p2 sees p1 at 1/3 -> p2 goes.
    # (Raw objectives, the hand example above, remove p2 first: the scaling matters.)
    out = surv.do(problem, _pop(F), n_survive=2, random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(out.get("F"), F[[1, 2]])
    out = surv.do(problem, _pop(F), n_survive=1, random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(out.get("F"), F[[1]])
    raw = SPEA2SDESurvival(normalize=False).do(problem, _pop(F), n_survive=2, random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(raw.get("F"), F[[0, 1]])


def test_normalisation_falls_back_to_the_whole_range_when_the_front_hardly_spans_an_objective():
    # rows 0, 1 non-dominated with f2 = 2e-300, 1e-300; row 2 = (2, 1) dominated by both (raw fitness 1 + 1).
    # By the front's f2 range (1e-300) alone row 2 would scale to 1e300 and its squared distances overflow
    # (a RuntimeWarning, an error under the test settings). A front range below 1e-10 of the whole set's takes
    # the whole set's (1), so f2 ~ (1e-300, 0, 1) and f1 = (0, 1, 2) / 1. Shifted distances (k = 1): row 0 sees
    # row 1 at 1 and row 2 at sqrt 5 -> density 1/3; row 1 sees row 0 at 1e-300 -> 1/2; row 2 sees row 0 at 0.
    F = np.array([[0.0, 2e-300], [1.0, 1e-300], [2.0, 1.0]])
    fit, raw, density = sde_fitness(F)
    np.testing.assert_array_equal(raw, [0, 0, 2])
    np.testing.assert_allclose(density, [1 / 3, 1 / 2, 1 / 2], rtol=1e-12)
    np.testing.assert_allclose(fit, [1 / 3, 1 / 2, 2.5], rtol=1e-12)


def test_normalised_survival_is_invariant_to_objective_scaling():
    # Scaling objective k by a_k > 0 and shifting it leaves the normalised set unchanged, so the
    # same individuals survive; the raw form is not invariant (it follows the largest objective).
    rng = np.random.default_rng(4)
    F = rng.random((60, 3))
    F[:40] /= np.linalg.norm(F[:40], axis=1, keepdims=True)   # 40 on a sphere, 20 scattered
    G = F * np.array([1.0, 1e3, 1e-2]) + np.array([5.0, -2.0, 0.0])
    problem = _Dummy(3)

    def kept(X, normalize):
        pop = _pop(X)
        pop.set("X", np.arange(60.0)[:, None])
        out = SPEA2SDESurvival(normalize=normalize).do(problem, pop, n_survive=25,
                                                        random_state=np.random.default_rng(0))
        return sorted(out.get("X")[:, 0].astype(int))

    assert kept(F, True) == kept(G, True)
    assert kept(F, False) != kept(G, False)


def test_survival_puts_feasible_first():
    F = np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 1.0], [3.0, 3.0]])
    problem = Problem(n_var=1, n_obj=2, n_ieq_constr=1, xl=0.0, xu=1.0)
    pop = _pop(F, cv=[1.0, 0.0, 0.0, 0.0])
    out = SPEA2SDESurvival().do(problem, pop, n_survive=3, random_state=np.random.default_rng(0))
    # (0,0) dominates everything but is infeasible: the three feasible ones survive
    np.testing.assert_array_equal(out.get("F"), F[[1, 2, 3]])


def test_survival_tolerates_repeated_calls_on_merged_populations():
    rng = np.random.default_rng(2)
    surv = SPEA2SDESurvival()
    problem = _Dummy(3)
    pop = surv.do(problem, _pop(rng.random((92 + 92, 3))), n_survive=92, random_state=rng)
    assert len(pop) == 92
    merged = Population.merge(pop, _pop(rng.random((57, 3))))
    again = surv.do(problem, merged, n_survive=92, random_state=rng)
    assert len(again) == 92
    fit, _, _ = sde_fitness(merged.get("F"))
    # the stored fitness is the one of the merged set, recomputed on the second call
    ids = {id(ind): i for i, ind in enumerate(merged)}
    np.testing.assert_array_equal(again.get("sde_fitness"), fit[[ids[id(ind)] for ind in again]])


def test_tournament_prefers_lower_fitness_cv_first_and_breaks_ties_at_random():
    pop = _pop(np.zeros((4, 2)), cv=[0.0, 0.0, 0.0, 2.0])
    pop.set("sde_fitness", np.array([0.3, 0.7, 0.3, 0.1]))
    P = np.array([[0, 1], [1, 0], [1, 3], [3, 1]])
    S = _sde_tournament(pop, P, random_state=np.random.default_rng(0))
    # lower fitness wins; 3 has the best fitness but violates a constraint
    np.testing.assert_array_equal(S[:, 0], [0, 0, 1, 1])
    ties = np.tile([[0, 2]], (200, 1))
    won = _sde_tournament(pop, ties, random_state=np.random.default_rng(1))[:, 0]
    assert set(won) == {0, 2} and 60 < np.sum(won == 0) < 140


def test_tournament_ranks_an_unranked_population_itself():
    # No stored fitness (a population that never went through the survival): the feasible
    # individuals are ranked on the spot. (0,0) dominates (1,1) -> R = [0, 1] -> 0 wins.
    pop = _pop([[0.0, 0.0], [1.0, 1.0], [-1.0, -1.0]], cv=[0.0, 0.0, 3.0])
    S = _sde_tournament(pop, np.array([[0, 1], [1, 0], [2, 1]]), random_state=np.random.default_rng(0))
    # the infeasible (-1,-1) would dominate both but loses on CV
    np.testing.assert_array_equal(S[:, 0], [0, 0, 1])


def test_mating_selection_is_a_binary_tournament_with_replacement():
    # Fitness 0.1 < 0.2 < 0.3 < 0.4, pairs drawn uniformly with replacement from 4:
    #   P(best chosen)  = P(0 in the pair) = 1 - (3/4)^2 = 7/16
    #   P(worst chosen) = P(pair = (3, 3)) = 1/16   (a permutation-based tournament gives 0)
    pop = _pop(np.zeros((4, 2)))
    pop.set("sde_fitness", np.array([0.1, 0.2, 0.3, 0.4]))
    S = BinaryTournament(_sde_tournament).do(_Dummy(), pop, 8000, 2,
                                             to_pop=False, random_state=np.random.default_rng(0))
    assert S.shape == (8000, 2)
    freq = np.bincount(S.ravel(), minlength=4) / S.size
    np.testing.assert_allclose(freq, [7 / 16, 5 / 16, 3 / 16, 1 / 16], atol=0.015)


# ----------------------------------------------------------------------------- whole runs

def _dtlz2_igd(alg, n_eval, seed, n_obj=3):
    problem = get_problem("dtlz2", n_obj=n_obj)
    res = minimize(problem, alg, ("n_eval", n_eval), seed=seed)
    pf = problem.pareto_front(get_reference_directions("das-dennis", n_obj, n_partitions=30))
    return IGD(pf)(res.F), res


def test_normalize_must_be_a_bool():
    assert make_spea2_sde(n_obj=4, pop_size=40, normalize=False).survival.normalize is False
    with pytest.raises(TypeError, match="normalize"):
        make_spea2_sde(n_obj=3, normalize="yes")


def test_fitness_is_set_on_runs_wrapped_with_molsp():
    # the MO-LSP run itself (budget, determinism) is checked in test_moea_common.py
    from moo.molsp import molsp

    problem = get_problem("dtlz2", n_obj=3)
    res = minimize(problem, molsp(make_spea2_sde(n_obj=3), ref_point=np.full(3, 2.0)), ("n_eval", 1500), seed=2)
    # the fitness stored on the population is set by the last (MO-LSP) survival call
    assert np.all(np.isfinite(res.pop.get("sde_fitness").astype(float)))


