"""Tests of MOMBI-II (moo.algorithms.mombi2).

References used (independent of the code under test):

* hand-worked R2 ranks, ASF values and reference-point updates on tiny
  populations (the arithmetic is written next to each case);
* a plain triple loop over weights / individuals implementing the R2 ranking
  definition (sort by ASF then norm, rank = best position);
* pymoo's NSGA-III at the same budget (DTLZ2) and the closed-form DTLZ1
  front ``sum f = 0.5``.
"""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.util.ref_dirs import get_reference_directions

from moo.algorithms.mombi2 import (
    MOMBI2,
    R2RankingSurvival,
    asf_matrix,
    make_mombi2,
    r2_ranking,
    r2_tournament,
    update_reference_points,
)

# weights (1,0), (.5,.5), (0,1); zero components act as 1e-6 in the ASF
W2 = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])
# a=(0,1), b=(.5,.5), c=(1,0), d=(.6,.6), e=(1,1): ideal (0,0), nadir (1,1) -> already normalised
PROBLEM2 = Problem(n_var=1, n_obj=2)
F5 = np.array([[0.0, 1.0], [0.5, 0.5], [1.0, 0.0], [0.6, 0.6], [1.0, 1.0]])


# ----------------------------------------------------------------------------- ASF and R2 ranking
def test_asf_by_hand():
    # ASF(x|w) = max_i x_i / w_i, zero weights -> 1e-6
    got = asf_matrix(F5, W2)
    expected = np.array([
        [1e6, 2.0, 1.0],        # a: max(0, 1/1e-6); 2*max(0,1); max(0/1e-6, 1)
        [5e5, 1.0, 5e5],        # b
        [1.0, 2.0, 1e6],        # c
        [6e5, 1.2, 6e5],        # d
        [1e6, 2.0, 1e6],        # e
    ])
    np.testing.assert_allclose(got, expected, rtol=1e-12)


def test_asf_zero_weights_with_three_objectives_by_hand():
    # with more than two objectives a zero weight component stands for 1e-2 (1e-6 with two):
    # x = (0.2, 0.01, 0.5): w = (1, 0, 0) -> max(0.2, 0.01 / 1e-2, 0.5 / 1e-2) = 50; w = (0.5, 0.5, 0) -> 50;
    # w = (1/3, 1/3, 1/3) -> 1.5
    W = np.array([[1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [1 / 3, 1 / 3, 1 / 3]])
    np.testing.assert_allclose(asf_matrix(np.array([[0.2, 0.01, 0.5]]), W), [[50.0, 50.0, 1.5]], rtol=1e-12)
    np.testing.assert_allclose(asf_matrix(np.array([[0.2, 0.01, 0.5]]), W, zero=1e-6), [[5e5, 5e5, 1.5]],
                               rtol=1e-12)


def test_r2_ranking_by_hand():
    # w1 order: c(1) b(5e5) d(6e5) a(1e6, norm 1) e(1e6, norm 1.41) -> c1 b2 d3 a4 e5
    # w2 order: b(1) d(1.2) a(2, norm 1, index 0) c(2, norm 1, index 2) e(2) -> b1 d2 a3 c4 e5
    # w3 order: a(1) b d c(1e6, norm 1) e(1e6, norm 1.41) -> a1 b2 d3 c4 e5
    # best positions: a 1, b 1, c 1, d 2, e 5
    rank, norm = r2_ranking(F5, W2, np.zeros(2), np.ones(2))
    np.testing.assert_array_equal(rank, [1, 1, 1, 2, 5])
    np.testing.assert_allclose(norm, [1.0, np.sqrt(0.5), 1.0, np.sqrt(0.72), np.sqrt(2.0)])


def test_r2_ranking_normalises_with_ideal_and_nadir():
    # scaling objective 2 by 10 and shifting both is undone by the normalisation
    F = F5 * [1.0, 10.0] + [3.0, -2.0]
    rank, norm = r2_ranking(F, W2, np.array([3.0, -2.0]), np.array([4.0, 8.0]))
    np.testing.assert_array_equal(rank, [1, 1, 1, 2, 5])
    np.testing.assert_allclose(norm[1], np.sqrt(0.5))


def _r2_ranking_loop(F, W, ideal, nadir):
    """The definition, one weight and one individual at a time."""
    Fn = (F - ideal) / (nadir - ideal)
    norms = [float(np.sqrt(sum(v * v for v in row))) for row in Fn]
    rank = [len(F) + 1] * len(F)
    zero = 1e-6 if W.shape[1] == 2 else 1e-2         # the authors' wzero (EMO framework, utility.c)
    for w_row in W:
        w = [wi if wi > 0 else zero for wi in w_row]
        values = [max(row[i] / w[i] for i in range(len(w))) for row in Fn]
        order = sorted(range(len(F)), key=lambda n: (values[n], norms[n], n))
        for pos, n in enumerate(order, start=1):
            rank[n] = min(rank[n], pos)
    return np.array(rank), np.array(norms)


@pytest.mark.parametrize("n_obj", [2, 3, 4])
def test_r2_ranking_matches_loop(n_obj):
    rng = np.random.default_rng(n_obj)
    W = get_reference_directions("das-dennis", n_obj, n_partitions=5)
    F = rng.random((40, n_obj)) * rng.uniform(0.5, 5.0, n_obj)
    F[7] = F[3]                                  # a duplicate: ties resolved by index
    ideal, nadir = F.min(axis=0) - 0.1, F.max(axis=0)
    rank, norm = r2_ranking(F, W, ideal, nadir)
    ref_rank, ref_norm = _r2_ranking_loop(F, W, ideal, nadir)
    np.testing.assert_array_equal(rank, ref_rank)
    np.testing.assert_allclose(norm, ref_norm, rtol=1e-12)


# ----------------------------------------------------------------------------- reference-point update
def test_update_waits_for_a_full_record():
    nadir, record, marks = update_reference_points(
        np.ones(2), np.zeros(2), np.array([5.0, 5.0]), np.array([[1.0, 1.0]]), np.zeros(2, int),
        alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_array_equal(nadir, [1.0, 1.0])          # unchanged
    np.testing.assert_array_equal(record, [[1.0, 1.0], [5.0, 5.0]])
    np.testing.assert_array_equal(marks, [0, 0])


def test_update_large_variance_sets_all_to_largest_candidate():
    # record of objective 1: 1, 1, 3 -> mean 5/3, variance (2*(2/3)^2 + (4/3)^2)/3 = 24/27 > 0.5
    nadir, record, _ = update_reference_points(
        np.ones(2), np.zeros(2), np.array([3.0, 2.0]), np.ones((2, 2)), np.zeros(2, int),
        alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_array_equal(nadir, [3.0, 3.0])
    assert record.shape == (3, 2)
    # just below the threshold nothing of rule 1 happens: alpha = 24/27 + 1e-9
    nadir, _, _ = update_reference_points(
        np.ones(2), np.zeros(2), np.array([3.0, 2.0]), np.ones((2, 2)), np.zeros(2, int),
        alpha=24 / 27 + 1e-9, epsilon=1e-3, record_size=3)
    # objective 1: 3 > 1 -> 3 + |3 - 1| = 5; objective 2: 2 > 1 -> 2 + 1 = 3
    np.testing.assert_allclose(nadir, [5.0, 3.0])


def test_update_epsilon_rule_and_stagnation_rule():
    # record constant (variance 0). Objective 1: range 1 >= eps, candidate 1 not > 1,
    # constant and unmarked -> (1 + max record 1) / 2 = 1 (marked). Objective 2:
    # |5e-4 - 0| < 1e-3 -> max(nadir) = 1 (marked). Marks: 3 then one decrement -> 2.
    rec = np.array([[1.0, 4e-4], [1.0, 4e-4]])
    nadir, _, marks = update_reference_points(
        np.array([1.0, 5e-4]), np.zeros(2), np.array([1.0, 4e-4]), rec, np.zeros(2, int),
        alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_allclose(nadir, [1.0, 1.0])
    np.testing.assert_array_equal(marks, [2, 2])


def test_update_growth_and_halfway_rules():
    # objective 1: candidate 1.2 > nadir 1 -> 1.2 + 0.2 = 1.4;
    # objective 2: record 0.9, 0.9, 0.9 constant, unmarked -> (1 + 0.9) / 2 = 0.95
    rec = np.array([[1.2, 0.9], [1.2, 0.9]])
    cand = np.array([1.2, 0.9])
    nadir, _, marks = update_reference_points(np.ones(2), np.zeros(2), cand, rec, np.zeros(2, int),
                                              alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_allclose(nadir, [1.4, 0.95])
    np.testing.assert_array_equal(marks, [2, 2])
    # objective 2 marked recently: no halfway step, its mark counts down
    nadir, _, marks = update_reference_points(np.ones(2), np.zeros(2), cand, rec, np.array([0, 2]),
                                              alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_allclose(nadir, [1.4, 1.0])
    np.testing.assert_array_equal(marks, [2, 1])
    # objective 2 not constant over the record: no halfway step either
    rec2 = np.array([[1.2, 0.8], [1.2, 0.9]])
    nadir, _, _ = update_reference_points(np.ones(2), np.zeros(2), cand, rec2, np.zeros(2, int),
                                          alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_allclose(nadir, [1.4, 1.0])


def test_update_stagnation_rule_reads_zero_variance_with_tolerance_epsilon():
    # record of objective 2: 0.9, 0.9004, 0.9 -> variance 3.6e-8 < epsilon = 1e-3: stagnant, unmarked
    # -> (1 + 0.9004) / 2; objective 1: 1.2, 1.25, 1.2 -> variance 5.6e-4 < 1e-3 as well, but the candidate
    # 1.2 exceeds the nadir 1, so the growth rule comes first: 1.2 + 0.2
    rec = np.array([[1.2, 0.9], [1.25, 0.9004]])
    nadir, _, _ = update_reference_points(np.ones(2), np.zeros(2), np.array([1.2, 0.9]), rec, np.zeros(2, int),
                                          alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_allclose(nadir, [1.4, 0.9502], rtol=1e-12)
    # 0.85, 0.95, 0.9: a variance of 1.7e-3 > epsilon is not stagnation
    rec = np.array([[1.0, 0.85], [1.0, 0.95]])
    nadir, _, _ = update_reference_points(np.ones(2), np.zeros(2), np.array([1.0, 0.9]), rec, np.zeros(2, int),
                                          alpha=0.5, epsilon=1e-3, record_size=3)
    assert nadir[1] == 1.0


def test_update_does_not_modify_inputs():
    nadir0, rec0, marks0 = np.ones(2), np.ones((2, 2)), np.zeros(2, int)
    update_reference_points(nadir0, np.zeros(2), np.array([3.0, 2.0]), rec0, marks0,
                            alpha=0.5, epsilon=1e-3, record_size=3)
    np.testing.assert_array_equal(nadir0, [1, 1])
    np.testing.assert_array_equal(rec0, np.ones((2, 2)))


# ----------------------------------------------------------------------------- survival and mating
def test_survival_keeps_best_by_rank_then_norm():
    # ranks a1 b1 c1 d2 e5, norms a 1, b .71, c 1, d .85, e 1.41 -> order b, a, c, d, e
    surv = R2RankingSurvival(W2, record_size=5)
    pop = Population.new(X=np.zeros((5, 1)), F=F5)
    kept = surv.do(PROBLEM2, pop, n_survive=3, return_indices=True)
    assert sorted(kept) == [0, 1, 2]
    surv.reset()
    kept = surv.do(PROBLEM2, pop, n_survive=4, return_indices=True)
    assert sorted(kept) == [0, 1, 2, 3]
    np.testing.assert_array_equal(surv.ideal, [0, 0])
    np.testing.assert_array_equal(surv.nadir, [1, 1])
    np.testing.assert_array_equal(surv.record, [[1, 1]])


def test_survival_ideal_is_running_minimum_and_any_size_works():
    rng = np.random.default_rng(3)
    W = get_reference_directions("das-dennis", 3, n_partitions=4)
    surv = R2RankingSurvival(W)
    problem = Problem(n_var=2, n_obj=3)
    pop = Population.new(X=rng.random((30, 2)), F=rng.random((30, 3)) + 1.0)
    s1 = surv.do(problem, pop, n_survive=15)
    assert len(s1) == 15
    ideal1 = surv.ideal.copy()
    big = Population.new(X=rng.random((70, 2)), F=rng.random((70, 3)) + 2.0)   # all worse
    s2 = surv.do(problem, Population.merge(s1, big), n_survive=15)
    assert len(s2) == 15
    np.testing.assert_array_equal(surv.ideal, ideal1)   # nothing better was seen
    assert len(surv.record) == 2
    assert np.all(np.isin(s2.get("F")[:, 0], s1.get("F")[:, 0]))  # the worse newcomers are ranked behind


def test_survival_feasible_first_and_reference_points_from_feasible_only():
    # F5 feasible except e=(1,1) (CV .5) and an extra infeasible point (-5,-5) (CV .1), which
    # would otherwise move the ideal point; 5 survivors: the 4 feasible ones, then the
    # least violating infeasible one
    F = np.vstack([F5, [[-5.0, -5.0]]])
    cv = np.array([0, 0, 0, 0, 0.5, 0.1])[:, None]
    pop = Population.new(X=np.zeros((6, 1)), F=F, CV=cv)
    surv = R2RankingSurvival(W2)
    kept = surv.do(Problem(n_var=1, n_obj=2, n_ieq_constr=1), pop, n_survive=5, return_indices=True)
    assert kept == [1, 0, 2, 3, 5]
    np.testing.assert_array_equal(surv.ideal, [0, 0])
    np.testing.assert_array_equal(surv.nadir, [1, 1])


def test_tournament_rules():
    cv = np.array([0.0, 0.0, 0.0, 1.0, 0.0])
    rank = np.array([1, 2, 2, 1, 1])
    norm = np.array([0.5, 0.5, 0.3, 0.1, 0.5])
    rng = np.random.default_rng(0)
    P = np.array([[0, 1], [1, 2], [3, 0], [1, 0]])
    # rank 1 beats 2; equal rank -> smaller norm; feasible beats infeasible (3 has the best rank/norm)
    np.testing.assert_array_equal(r2_tournament(P, cv, rank, norm, rng)[:, 0], [0, 2, 0, 0])
    # full tie (0 vs 4): both must win sometimes
    winners = r2_tournament(np.tile([0, 4], (200, 1)), cv, rank, norm, rng)[:, 0]
    assert set(winners) == {0, 4}
    with pytest.raises(ValueError, match=r"P must have shape \(n, 2\)"):
        r2_tournament(np.zeros((3, 3)), cv, rank, norm, rng)


def test_tournament_in_population_treats_unranked_as_worst():
    pop = Population.new(X=np.zeros((2, 1)))
    pop[0].set("rank", 7)
    pop[0].set("r2_norm", 1.0)
    out = MOMBI2(W2).mating.selection.func_comp(pop, np.array([[1, 0], [0, 1]]),
                                                random_state=np.random.default_rng(1))
    np.testing.assert_array_equal(out[:, 0], [0, 0])


def test_nadir_record_on_runs_wrapped_with_molsp():
    # the MO-LSP run itself (budget, determinism) is checked in test_moea_common.py
    from moo.molsp import molsp

    problem = get_problem("dtlz2", n_obj=3)
    res = minimize(problem, molsp(make_mombi2(n_obj=3), ref_point=np.full(3, 2.0)), ("n_eval", 1500), seed=2)
    # the survival was called twice per generation: the record holds the last 5 candidates
    assert res.algorithm.survival.record.shape == (5, 3)


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, exc, word", [
    ({"n_obj": 3.0}, TypeError, "n_obj"),
    ({"n_obj": 3, "alpha": -0.1}, ValueError, "alpha"),
    ({"n_obj": 3, "alpha": "x"}, TypeError, "alpha"),
    ({"n_obj": 3, "epsilon": float("nan")}, ValueError, "epsilon"),
    ({"n_obj": 3, "record_size": 0}, ValueError, "record_size"),
    ({"n_obj": 3, "record_size": 2.5}, TypeError, "record_size"),
])
def test_bad_parameters(kwargs, exc, word):
    with pytest.raises(exc, match=word):
        make_mombi2(**kwargs)


def test_bad_shapes():
    with pytest.raises(ValueError, match="weights"):
        r2_ranking(F5, np.ones(3), np.zeros(2), np.ones(2))
    with pytest.raises(ValueError, match=r"F must have shape \(N, 3\).*\(4, 2\)"):
        r2_ranking(F5[:4], np.ones((2, 3)) / 3, np.zeros(3), np.ones(3))
    with pytest.raises(ValueError, match="ideal and nadir"):
        r2_ranking(F5, W2, np.zeros(3), np.ones(2))
    with pytest.raises(ValueError, match="weights"):
        R2RankingSurvival(-W2)
    with pytest.raises(ValueError, match="objectives"):
        minimize(get_problem("dtlz2", n_obj=2), make_mombi2(n_obj=3), ("n_eval", 200), seed=0)
