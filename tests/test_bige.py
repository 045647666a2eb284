"""Tests of BiGE (moo.algorithms.bige).

Expected values are worked out by hand in the comments, or come from a
per-pair reference written straight from Eqs. 1-5 of Li, Yang & Liu (2015),
independent of the vectorised code under test.
"""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem

from moo.algorithms.base import BinaryTournament
from moo.algorithms.bige import (
    BiGESurvival,
    _bige_tournament,
    bige_estimation,
    niche_radius,
)

# Three mutually non-dominated points already in [0, 1]^2 (min (0,0), max (1,1): normalisation
# is the identity):  p0 = (0, 1), p1 = (0.3, 0.6), p2 = (1, 0).
#   proximity f_pr = sum = [1, 0.9, 1]
#   distances d01 = |(0.3, -0.4)| = 0.5, d12 = sqrt(0.85) = 0.922, d02 = sqrt 2
FRONT = np.array([[0.0, 1.0], [0.3, 0.6], [1.0, 0.0]])
# two points dominated by p2 = (1, 0), mutually non-dominated
SECOND = np.array([[1.0, 1.1], [1.1, 1.0]])


class _Dummy(Problem):
    def __init__(self, n_obj=2):
        super().__init__(n_var=1, n_obj=n_obj, xl=0.0, xu=1.0)


def _pop(F, cv=None):
    F = np.asarray(F, dtype=float)
    pop = Population.new("X", np.zeros((len(F), 1)), "F", F)
    pop.set("CV", np.zeros((len(F), 1)) if cv is None else np.asarray(cv, dtype=float)[:, None])
    return pop


def _reference_estimation(F, r):
    """Eqs. 1-5 pair by pair (no proximity ties allowed)."""
    lo, hi = F.min(0), F.max(0)
    G = (F - lo) / (hi - lo)
    n = len(G)
    fpr = np.array([sum(G[p]) for p in range(n)])
    fcd = np.zeros(n)
    for p in range(n):
        total = 0.0
        for q in range(n):
            if q == p:
                continue
            d = float(np.sqrt(np.sum((G[p] - G[q]) ** 2)))
            if d < r:
                assert fpr[p] != fpr[q]
                w = 0.5 if fpr[p] < fpr[q] else 1.5
                total += (w * (1 - d / r)) ** 2
        fcd[p] = np.sqrt(total)
    return fpr, fcd


# ----------------------------------------------------------------------------- estimation

def test_niche_radius():
    assert niche_radius(8, 3) == pytest.approx(0.5, rel=1e-15)        # 8^(-1/3)
    assert niche_radius(100, 2) == pytest.approx(0.1, rel=1e-15)      # 100^(-1/2)
    assert niche_radius(92, 3) == pytest.approx(92 ** (-1 / 3), rel=1e-15)
    with pytest.raises(ValueError, match="pop_size"):
        niche_radius(0, 3)
    with pytest.raises(TypeError, match="n_obj"):
        niche_radius(10, 2.0)


def test_estimation_hand_example():
    # r = 0.6: only p0, p1 share a niche, 1 - d01/r = 1 - 0.5/0.6 = 1/6.
    # p0 has the worse proximity (1 > 0.9): sh(0,1) = (1.5/6)^2 -> f_cd(p0) = 0.25
    # p1 the better one:                       sh(1,0) = (0.5/6)^2 -> f_cd(p1) = 1/12; p2 alone -> 0
    fpr, fcd = bige_estimation(FRONT, 0.6, np.random.default_rng(0))
    np.testing.assert_allclose(fpr, [1.0, 0.9, 1.0], rtol=1e-14)
    np.testing.assert_allclose(fcd, [0.25, 1 / 12, 0.0], rtol=1e-12, atol=1e-15)


def test_estimation_is_invariant_to_objective_scaling():
    # f1 -> 2 + 2 f1, f2 -> 5 + 5 f2: min-max normalisation maps back to FRONT
    F = FRONT * np.array([2.0, 5.0]) + np.array([2.0, 5.0])
    fpr, fcd = bige_estimation(F, 0.6, np.random.default_rng(0))
    np.testing.assert_allclose(fpr, [1.0, 0.9, 1.0], rtol=1e-14)
    np.testing.assert_allclose(fcd, [0.25, 1 / 12, 0.0], rtol=1e-12, atol=1e-15)


def test_estimation_matches_pairwise_reference():
    rng = np.random.default_rng(8)
    for n, m in [(6, 2), (20, 3), (40, 5)]:
        F = rng.random((n, m)) * (1.0 + 10.0 * np.arange(m))
        r = niche_radius(n, m)
        got = bige_estimation(F, r, np.random.default_rng(0))
        want = _reference_estimation(F, r)
        np.testing.assert_allclose(got[0], want[0], rtol=1e-13)
        np.testing.assert_allclose(got[1], want[1], rtol=1e-12, atol=1e-15)


def test_equal_proximity_splits_the_discriminator_at_random():
    # p0 = p1 = (0, 1): d = 0 < r, equal proximity -> one takes 0.5, the other 1.5:
    # f_cd = 0.5 * (1 - 0) and 1.5 * (1 - 0); p2 = (1, 0) is sqrt 2 away -> 0.
    F = np.array([[0.0, 1.0], [0.0, 1.0], [1.0, 0.0]])
    seen = set()
    for seed in range(20):
        _, fcd = bige_estimation(F, 0.5, np.random.default_rng(seed))
        assert sorted(fcd[:2].tolist()) == [0.5, 1.5] and fcd[2] == 0.0
        seen.add(tuple(fcd[:2]))
    assert seen == {(0.5, 1.5), (1.5, 0.5)}
    a = bige_estimation(F, 0.5, np.random.default_rng(3))
    b = bige_estimation(F, 0.5, np.random.default_rng(3))
    np.testing.assert_array_equal(a[1], b[1])


def test_estimation_constant_objective_and_single_individual():
    # f2 constant -> normalised to 0; proximity is f1's normalised value
    fpr, fcd = bige_estimation([[1.0, 3.0], [2.0, 3.0]], 0.5, np.random.default_rng(0))
    np.testing.assert_array_equal(fpr, [0.0, 1.0])
    np.testing.assert_array_equal(fcd, [0.0, 0.0])
    fpr, fcd = bige_estimation([[1.0, 3.0]], 0.5, np.random.default_rng(0))
    assert fpr.tolist() == [0.0] and fcd.tolist() == [0.0]


def test_estimation_rejects_bad_input():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match=r"F must be a non-empty 2-D array.*shape \(2,\)"):
        bige_estimation([1.0, 2.0], 0.5, rng)
    with pytest.raises(ValueError, match="F must have finite entries"):
        bige_estimation([[1.0, np.inf]], 0.5, rng)
    with pytest.raises(ValueError, match="radius must be finite and > 0"):
        bige_estimation(FRONT, 0.0, rng)
    with pytest.raises(TypeError, match=r"random_state must be a numpy\.random\.Generator"):
        bige_estimation(FRONT, 0.5, 3)


# ----------------------------------------------------------------------------- survival and mating

def test_survival_uses_bigoal_layers_on_the_critical_front():
    # Objective fronts: FRONT (3 points), then SECOND (2 points).
    # n_survive = 2: FRONT is critical; r = niche_radius(2, 2) = 1/sqrt 2 = 0.7071, only d01 < r:
    #   1 - 0.5/0.7071 = 0.2929 -> f_cd = [1.5 * 0.2929, 0.5 * 0.2929, 0] = [0.439, 0.146, 0]
    #   goals p0 (1, 0.439), p1 (0.9, 0.146), p2 (1, 0): p1 dominates p0; p1, p2 non-dominated
    #   -> first bi-goal layer {p1, p2} fills both slots exactly.
    F = np.vstack([FRONT, SECOND])
    out = BiGESurvival().do(_Dummy(), _pop(F), n_survive=2, random_state=np.random.default_rng(0))
    assert sorted(map(tuple, out.get("F"))) == sorted(map(tuple, FRONT[[1, 2]]))


def test_survival_estimates_the_goals_on_the_critical_front_only():
    # Pins the reading of Alg. 3 + Sec. 4 (goals of the critical front, normalised over it).
    # A (3,8), B (7,6), C (9,1), D (5,0), E (8,3): front 1 = {A, D}, critical front {B, C, E};
    # n_survive = 3 -> one slot; r = 3^(-1/2) = 0.577.
    # Over the critical front (min (7,1), span (2,5)): B (0,1), C (1,0), E (0.5,0.4);
    #   f_pr = [1, 1, 0.9]; d_BE = 0.781, d_CE = 0.640, d_BC = 1.414, all >= r -> f_cd = 0;
    #   E (0.9, 0) dominates B and C (1, 0) -> E survives, whatever the seed.
    # (Estimating over all five points instead -- min (3,0), span (6,8) -- would put E within r
    #  of B (0.410) and C (0.300), give C (1.125, 0.240), E (1.208, 0.734), B (1.417, 0.435),
    #  and keep C.)
    F = np.array([[3.0, 8.0], [7.0, 6.0], [9.0, 1.0], [5.0, 0.0], [8.0, 3.0]])
    for seed in range(5):
        out = BiGESurvival().do(_Dummy(), _pop(F), n_survive=3, random_state=np.random.default_rng(seed))
        assert sorted(map(tuple, out.get("F"))) == [(3.0, 8.0), (5.0, 0.0), (8.0, 3.0)]


def test_survival_fills_the_last_layer_at_random():
    # n_survive = 4: FRONT fits, SECOND is critical with one slot. Normalised over SECOND it is
    # (0, 1), (1, 0): equal proximity, distance sqrt 2 > r = 0.5 -> both f_cd = 0, one layer of 2
    # -> one of them drawn at random.
    F = np.vstack([FRONT, SECOND])
    picked = set()
    for seed in range(12):
        out = BiGESurvival().do(_Dummy(), _pop(F), n_survive=4, random_state=np.random.default_rng(seed))
        got = out.get("F")
        assert len(got) == 4
        np.testing.assert_array_equal(got[:3], FRONT)
        picked.add(tuple(got[3]))
    assert picked == set(map(tuple, SECOND))
    out = BiGESurvival().do(_Dummy(), _pop(F), n_survive=5, random_state=np.random.default_rng(0))
    assert len(out) == 5


def test_survival_tolerates_repeated_calls_on_merged_populations():
    rng = np.random.default_rng(2)
    surv = BiGESurvival()
    problem = _Dummy(3)
    pop = surv.do(problem, _pop(rng.random((184, 3))), n_survive=92, random_state=rng)
    assert len(pop) == 92
    again = surv.do(problem, Population.merge(pop, _pop(rng.random((130, 3)))), n_survive=92, random_state=rng)
    assert len(again) == 92


def test_tournament_bigoal_dominance_cv_first_else_random():
    # Goals of FRONT as the current population (N = 3, r = 3^(-1/2) = 0.577, 1 - 0.5/0.577 = 0.134):
    #   p0 (1, 0.201), p1 (0.9, 0.067), p2 (1, 0)
    # (0,1): p1 dominates -> 1;  (0,2): p2 dominates (same f_pr, lower f_cd) -> 2;  (1,2): random.
    pop = _pop(FRONT)
    S = _bige_tournament(pop, np.array([[0, 1], [1, 0], [0, 2], [2, 0]]), random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(S[:, 0], [1, 1, 2, 2])
    won = _bige_tournament(pop, np.tile([[1, 2]], (200, 1)), random_state=np.random.default_rng(1))[:, 0]
    assert set(won) == {1, 2} and 60 < np.sum(won == 1) < 140
    # a constraint violation decides first: p1 is best in the goals but infeasible
    pop = _pop(FRONT, cv=[0.0, 1.0, 0.5])
    S = _bige_tournament(pop, np.array([[0, 1], [1, 2]]), random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(S[:, 0], [0, 2])


def test_tournament_estimates_goals_on_feasible_individuals_only():
    # FRONT plus two infeasible points (10, -5). N = 5 -> r = 5^(-1/2) = 0.447 < every distance in
    # FRONT -> f_cd = 0; feasible-only normalisation keeps FRONT as is: goals (1,0), (0.9,0), (1,0),
    # so p1 beats p2. Normalising with the infeasible points too would give f_pr = [1, 0.967, 0.933]
    # and p2 would win instead.
    pop = _pop(np.vstack([FRONT, [[10.0, -5.0], [10.0, -5.0]]]), cv=[0, 0, 0, 1.0, 2.0])
    S = _bige_tournament(pop, np.array([[1, 2], [2, 1], [0, 1], [3, 4], [4, 0]]),
                         random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(S[:, 0], [1, 1, 1, 3, 0])


def test_mating_selection_is_a_binary_tournament_with_replacement():
    # Goals as above: p0 is dominated by p1 and p2, which are mutually non-dominated.
    # Pairs uniform with replacement from 3: p0 wins only (0, 0): 1/9;
    # p1 wins (1,1), (0,1), (1,0) and half of (1,2), (2,1): (1 + 2 + 1)/9 = 4/9; p2 likewise 4/9.
    S = BinaryTournament(_bige_tournament).do(_Dummy(), _pop(FRONT), 9000, 2,
                                              to_pop=False, random_state=np.random.default_rng(0))
    assert S.shape == (9000, 2)
    freq = np.bincount(S.ravel(), minlength=3) / S.size
    np.testing.assert_allclose(freq, [1 / 9, 4 / 9, 4 / 9], atol=0.015)


# ----------------------------------------------------------------------------- whole runs


