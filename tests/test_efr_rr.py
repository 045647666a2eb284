"""Tests of EFR-RR (Yuan et al., IEEE TEVC 20(2), 2016).

Selection rules are checked on tiny populations worked out by hand (the
arithmetic is in the comments) and against a brute-force loop written here
independently of the vectorised implementation.
"""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.util.ref_dirs import get_reference_directions

from moo.algorithms.efr_rr import EFRRRSurvival, make_efr_rr, maximum_ranking

# Two objectives, three weight vectors: e1, the diagonal, e2.
W3 = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])


def brute_force_ranks(F, W, k, scalarizing="tchebycheff", theta=5.0):
    """Global ranks by explicit loops over solutions and weight vectors."""
    n = len(F)
    near = []
    for x in F:
        d = []
        for w in W:
            u = w / np.sqrt(w @ w)
            d.append(np.sqrt(max(x @ x - (x @ u) ** 2, 0.0)))
        near.append(set(np.argsort(d, kind="stable")[:k].tolist()))
    rg = np.full(n, np.iinfo(np.int64).max)
    for j, w in enumerate(W):
        members = [i for i in range(n) if j in near[i]]
        if scalarizing == "tchebycheff":
            wz = np.where(w > 0, w, 1e-6)
            val = {i: max(F[i] / wz) for i in members}
        else:
            u = w / np.sqrt(w @ w)
            val = {}
            for i in members:
                d1 = F[i] @ u
                val[i] = d1 + theta * np.sqrt(max(F[i] @ F[i] - d1 ** 2, 0.0))
        for pos, i in enumerate(sorted(members, key=lambda i: (val[i], i))):
            rg[i] = min(rg[i], pos + 1)
    return rg


def test_ranking_restriction_hand_case_k1_vs_k2():
    # P1=(.3,.3): d2 = (.3, 0, .3) -> nearest diag, then e1 (tie with e2, lower index)
    # P2=(.35,.25): d2 = (.25, .0707, .35) -> diag, e1
    # P3=(.2,.9): d2 = (.9, .495, .2) -> e2, diag
    F = np.array([[0.3, 0.3], [0.35, 0.25], [0.2, 0.9]])
    # K=1: diag ranks P1 (g=max(.6,.6)=.6) before P2 (g=.7); e2 has only P3.
    assert maximum_ranking(F, W3, n_neighbors=1).tolist() == [1, 2, 1]
    # K=2: e1 now ranks {P1, P2} by max(f1, f2/1e-6): P2 (2.5e5) before P1 (3e5),
    # so P2's best rank becomes 1.
    assert maximum_ranking(F, W3, n_neighbors=2).tolist() == [1, 1, 1]


def test_ranking_hand_case_six_points():
    # Worked by hand (K=2), see test_survival_hand_case for the distances:
    # e1 ranks X1 (g=1), X4 (2.5e5), X3 (3e5);
    # diag ranks X3 (.6), X4 (.7), X6 (1.4), X5 (1.8), X1 (2), X2 (2, later index);
    # e2 ranks X2 (1), X5 (2e5), X6 (6e5).
    F = np.array([[1, 0], [0, 1], [0.3, 0.3], [0.35, 0.25], [0.2, 0.9], [0.6, 0.7]])
    assert maximum_ranking(F, W3, n_neighbors=2).tolist() == [1, 1, 1, 2, 2, 3]


@pytest.mark.parametrize("k", [1, 2, 3, 5])
@pytest.mark.parametrize("scalarizing", ["tchebycheff", "pbi"])
def test_ranking_matches_brute_force(k, scalarizing):
    rng = np.random.default_rng(7)
    W = get_reference_directions("das-dennis", 3, n_partitions=4)
    F = rng.random((40, 3)) ** 2
    got = maximum_ranking(F, W, n_neighbors=k, scalarizing=scalarizing, theta=5.0)
    np.testing.assert_array_equal(got, brute_force_ranks(F, W, k, scalarizing, 5.0))


def test_each_weight_has_a_rank_one_solution_when_someone_is_near_it():
    # A property of max ranking: the number of rank-1 solutions is at least the number of
    # distinct weight vectors that appear among the solutions' K nearest.
    rng = np.random.default_rng(1)
    W = get_reference_directions("das-dennis", 3, n_partitions=6)
    F = rng.random((60, 3))
    rg = maximum_ranking(F, W, n_neighbors=1)
    d = np.stack([np.linalg.norm(F - np.outer(F @ (w / np.linalg.norm(w)), w / np.linalg.norm(w)), axis=1)
                  for w in W], axis=1)
    used = len(np.unique(np.argmin(d, axis=1)))
    assert np.sum(rg == 1) == used


def _pop(F):
    return Population.new(X=np.zeros((len(F), 1)), F=np.asarray(F, dtype=float))


class _Dummy(Problem):
    def __init__(self):
        super().__init__(n_var=1, n_obj=2, xl=0.0, xu=1.0)


def test_survival_hand_case():
    # X1=(1,0) and X2=(0,1) are the extreme points, so ideal=(0,0), intercepts=(1,1) and the
    # normalised objectives equal F. Global ranks (test above): [1, 1, 1, 2, 2, 3].
    F = [[1, 0], [0, 1], [0.3, 0.3], [0.35, 0.25], [0.2, 0.9], [0.6, 0.7]]
    for n_survive, expected in [(3, {0, 1, 2}), (5, {0, 1, 2, 3, 4})]:
        s = EFRRRSurvival(W3, n_neighbors=2)
        out = s.do(_Dummy(), _pop(F), n_survive=n_survive, random_state=np.random.default_rng(0))
        got = {int(np.flatnonzero((np.asarray(F) == f).all(axis=1))[0]) for f in out.get("F")}
        assert got == expected
    # n_survive=4: X1, X2, X3 always, plus one of the rank-2 pair {X4, X5} at random.
    seen = set()
    for seed in range(30):
        s = EFRRRSurvival(W3, n_neighbors=2)
        out = s.do(_Dummy(), _pop(F), n_survive=4, random_state=np.random.default_rng(seed))
        rows = {tuple(f) for f in out.get("F").tolist()}
        assert {(1.0, 0.0), (0.0, 1.0), (0.3, 0.3)} <= rows and len(rows) == 4
        seen |= rows - {(1.0, 0.0), (0.0, 1.0), (0.3, 0.3)}
    assert seen == {(0.35, 0.25), (0.2, 0.9)}


def test_survival_is_invariant_to_objective_scaling():
    # Normalisation by ideal point and intercepts makes the choice unit-free.
    F = np.array([[1, 0], [0, 1], [0.3, 0.3], [0.35, 0.25], [0.2, 0.9], [0.6, 0.7]])
    scale = np.array([1e3, 1e-2])
    a = EFRRRSurvival(W3).do(_Dummy(), _pop(F), n_survive=5, random_state=np.random.default_rng(0))
    b = EFRRRSurvival(W3).do(_Dummy(), _pop(F * scale), n_survive=5,
                             random_state=np.random.default_rng(0))
    np.testing.assert_allclose(a.get("F") * scale, b.get("F"))


def test_survival_any_size_and_repeated_calls():
    # MO-LSP contract: merged populations of any size >= n_survive, twice per generation.
    rng = np.random.default_rng(3)
    W = get_reference_directions("das-dennis", 3, n_partitions=4)
    s = EFRRRSurvival(W)
    prob = get_problem("dtlz2", n_obj=3, n_var=5)
    for n in (15, 40, 97, 15):
        pop = _pop(rng.random((n, 3)))
        out = s.do(prob, pop, n_survive=15, random_state=rng)
        assert len(out) == 15
        assert np.all(np.isfinite(s.nadir_point))


@pytest.mark.parametrize("kwargs, exc, word", [
    ({"n_obj": 3, "n_neighbors": 0}, ValueError, "n_neighbors"),
    ({"n_obj": 3, "n_neighbors": 2.5}, TypeError, "n_neighbors"),
    ({"n_obj": 3, "n_neighbors": 1000}, ValueError, "n_neighbors"),
    ({"n_obj": 3, "scalarizing": "ws"}, ValueError, "scalarizing"),
    ({"n_obj": 3, "theta": -1.0}, ValueError, "theta"),
    ({"n_obj": 3, "mating": "roulette"}, ValueError, "mating"),
])
def test_bad_arguments(kwargs, exc, word):
    with pytest.raises(exc, match=word):
        make_efr_rr(**kwargs)


def test_bad_ranking_inputs():
    with pytest.raises(ValueError, match=r"ref_dirs.*3 columns"):
        maximum_ranking(np.zeros((4, 3)), W3)
    with pytest.raises(ValueError, match="ref_dirs"):
        maximum_ranking(np.zeros((4, 2)), -W3)
    with pytest.raises(ValueError, match="F"):
        maximum_ranking(np.full((4, 2), np.nan), W3)


def test_tournament_mating_runs_and_differs_from_random():
    problem = get_problem("dtlz2", n_obj=3, n_var=12)
    a = minimize(problem, make_efr_rr(n_obj=3, mating="tournament"), ("n_eval", 600), seed=2).F
    b = minimize(problem, make_efr_rr(n_obj=3), ("n_eval", 600), seed=2).F
    assert a.shape[1] == 3 and not np.array_equal(a, b)


def test_rank_tournament_frequencies():
    # Two individuals with global ranks 1 and 2: the worse one wins only when drawn twice,
    # probability 1/4; with equal ranks the coin makes each win half of the time.
    from moo.algorithms.efr_rr import RankTournament

    rng = np.random.default_rng(5)
    pop = _pop([[0, 1], [1, 0]])
    pop.set("rank", np.array([1, 2]))
    picks = RankTournament().do(_Dummy(), pop, 4000, 1, to_pop=False, random_state=rng).ravel()
    assert abs(np.mean(picks == 1) - 0.25) < 0.03          # ~4 standard deviations
    pop.set("rank", np.array([3, 3]))
    picks = RankTournament().do(_Dummy(), pop, 4000, 1, to_pop=False, random_state=rng).ravel()
    assert abs(np.mean(picks == 1) - 0.5) < 0.035
