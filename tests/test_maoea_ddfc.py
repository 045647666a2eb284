"""Tests of MaOEA-DDFC (Cheng, Yen & Zhang, IEEE TEVC 19(4), 2015).

FC is checked against an independent linear program (min over the simplex of
the Chebyshev function), the DD/FC selection and the survival on tiny
populations worked out by hand (arithmetic in the comments).
"""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from scipy.optimize import linprog

from moo.algorithms.maoea_ddfc import (
    DDFCSurvival,
    directional_projection,
    favorable_convergence,
    make_maoea_ddfc,
    select_by_dd_fc,
    tournament_winners,
)


# ----------------------------------------------------------------------------- FC
def test_fc_hand_values():
    # 1/(1+1) = .5; 1/(1 + 1/3) = .75; 1/(1/2 + 2 + 1) = 1/3.5; a zero objective gives 0
    F = [[1, 1], [1, 3], [0, 0.4]]
    np.testing.assert_allclose(favorable_convergence(F), [0.5, 0.75, 0.0])
    np.testing.assert_allclose(favorable_convergence([[2, 0.5, 1]]), [1 / 3.5])


def test_fc_of_tiny_and_huge_values_without_warnings():
    # issue 17: 1/1e-310 overflowed (a RuntimeWarning, an error under the test settings). FC is homogeneous of
    # degree 1, so FC(c f) = c FC(f); 1e-310 is subnormal, so compare with a relative tolerance of 1e-6.
    f = np.array([[1.0, 2.0, 4.0]])                      # FC = 1 / (1 + 1/2 + 1/4) = 4/7
    for c in (1e-310, 1e-300, 1e300):
        np.testing.assert_allclose(favorable_convergence(c * f), [c * 4 / 7], rtol=1e-6)
    np.testing.assert_allclose(favorable_convergence([[1e-310, 1.0]]), [1e-310], rtol=1e-6)


def _fc_by_lp(f):
    # min s  s.t.  w_i f_i <= s,  sum w = 1,  w >= 0   (variables [w, s])
    M = len(f)
    c = np.r_[np.zeros(M), 1.0]
    A_ub = np.c_[np.diag(f), -np.ones(M)]
    res = linprog(c, A_ub=A_ub, b_ub=np.zeros(M), A_eq=np.r_[np.ones(M), 0.0][None],
                  b_eq=[1.0], bounds=[(0, None)] * (M + 1), method="highs")
    assert res.status == 0
    return res.fun


def test_fc_is_the_minimum_chebyshev_value_over_weights():
    rng = np.random.default_rng(0)
    F = np.vstack([rng.random((20, 4)) * [1, 10, 0.1, 3], [[0.0, 1, 2, 3]]])
    expected = [_fc_by_lp(f) for f in F]
    np.testing.assert_allclose(favorable_convergence(F), expected, rtol=1e-7, atol=1e-10)


def test_projection_hand_values():
    np.testing.assert_allclose(directional_projection([[2, 2], [1, 3], [0, 0]]),
                               [[0.5, 0.5], [0.25, 0.75], [0.5, 0.5]])


# ----------------------------------------------------------------------------- DD / FC selection
def _line(t):
    """Points (t, 1 - t) on the 2-objective simplex: distances are sqrt(2)|dt|."""
    t = np.asarray(t, dtype=float)
    return np.c_[t, 1 - t]


CAND = [0.1, 0.5, 0.8, 0.55]


def test_dd_pure_diversity_hand_case():
    # Selected t = 0 and 1; K = 1, L = 1 (the least crowded direction wins outright).
    # DD = 1/distance to the nearest selected (units of sqrt(2) dt):
    #   step 1: .1 -> 1/.1, .5 -> 1/.5, .8 -> 1/.2, .55 -> 1/.45   => pick .5 (index 1)
    #   step 2: .55 now 1/.05; .8 -> 1/.2; .1 -> 1/.1              => pick .8 (index 2)
    #   step 3: .1 -> 1/.1 vs .55 -> 1/.05                          => pick .1 (index 0), then .55
    got = select_by_dd_fc(_line([0, 1]), _line(CAND), np.ones(4), 4, n_neighbors=1, n_candidates=1,
                          candidate_choice="best")
    assert got.tolist() == [1, 2, 0, 3]


def test_dd_with_two_neighbours_hand_case():
    # K = 2: DD = 1/d1 + 1/d2 (units of sqrt(2) dt), selected {0, 1}:
    #   .1: 1/.1 + 1/.9 = 11.1; .5: 2 + 2 = 4; .8: 5 + 1.25 = 6.25; .55: 2.22 + 1.82 = 4.04 => .5
    #   then {0, .5, 1}: .1: 10 + 2.5; .8: 5 + 3.33; .55: 20 + 2.22                       => .8
    #   then {0, .5, .8, 1}: .1: 10 + 2.5; .55: 20 + 4                                    => .1
    got = select_by_dd_fc(_line([0, 1]), _line(CAND), np.ones(4), 4, n_neighbors=2, n_candidates=1,
                          candidate_choice="best")
    assert got.tolist() == [1, 2, 0, 3]


def test_fc_decides_among_the_l_least_crowded():
    # L = 2, K = 1, FC = [.3, .9, .2, .4] for t = [.1, .5, .8, .55]; selected {0, 1}.
    #   step 1: two least crowded: .5 (1/.5) and .55 (1/.45); FC .9 vs .4        => .55 (index 3)
    #   step 2: .1 -> 1/.1, .5 -> 1/.05, .8 -> 1/.2: least crowded .8, .1; FC .2 vs .3 => .8 (index 2)
    #   step 3: .1 (1/.1) and .5 (1/.05); FC .3 vs .9                             => .1, then .5
    fc = np.array([0.3, 0.9, 0.2, 0.4])
    got = select_by_dd_fc(_line([0, 1]), _line(CAND), fc, 4, n_neighbors=1, n_candidates=2,
                          candidate_choice="best")
    assert got.tolist() == [3, 2, 0, 1]


def test_roulette_probabilities_are_inverse_fc():
    # First pick of the previous case by roulette: P(.55) = (1/.4) / (1/.4 + 1/.9) = 0.6923.
    fc = np.array([0.3, 0.9, 0.2, 0.4])
    rng = np.random.default_rng(11)
    first = [select_by_dd_fc(_line([0, 1]), _line(CAND), fc, 1, n_neighbors=1, n_candidates=2,
                             random_state=rng)[0] for _ in range(4000)]
    first = np.asarray(first)
    assert set(first.tolist()) == {1, 3}
    assert abs(np.mean(first == 3) - (2.5 / (2.5 + 1 / 0.9))) < 0.03   # ~4 standard deviations


def test_selection_from_scratch_hand_case():
    # Nothing selected: the first DD is measured among the candidates themselves (K = 1):
    #   t = 0, .1, .2, .9: nearest distances .1, .1, .1, .7                        => .9 first
    #   then against {.9}: 0 -> .9, .1 -> .8, .2 -> .7                               => 0
    #   then {.9, 0}: .1 -> .1, .2 -> .2                                             => .2, then .1
    got = select_by_dd_fc(np.empty((0, 2)), _line([0, 0.1, 0.2, 0.9]), np.ones(4), 4, n_neighbors=1,
                          n_candidates=1, candidate_choice="best")
    assert got.tolist() == [3, 0, 2, 1]


def test_duplicated_direction_is_taken_last():
    got = select_by_dd_fc(_line([0, 1]), _line([0.5, 0.3, 0.3]), np.ones(3), 3, n_neighbors=1,
                          n_candidates=1, candidate_choice="best")
    # .5 first (1/.5); then .3 (index 1, tie with index 2 broken by index); its twin is last
    assert got.tolist() == [0, 1, 2]


def test_select_bad_inputs():
    with pytest.raises(ValueError, match="fc"):
        select_by_dd_fc(_line([0]), _line(CAND), np.ones(3), 2)
    with pytest.raises(ValueError, match="n_select"):
        select_by_dd_fc(_line([0]), _line(CAND), np.ones(4), 5, random_state=np.random.default_rng())
    with pytest.raises(ValueError, match="random_state"):
        select_by_dd_fc(_line([0]), _line(CAND), np.ones(4), 2)
    with pytest.raises(ValueError, match="candidate_choice"):
        select_by_dd_fc(_line([0]), _line(CAND), np.ones(4), 2, candidate_choice="worst")


# ----------------------------------------------------------------------------- mating
def test_tournament_rule_hand_case():
    # 0 = (.1,.1) dominates 1 = (.5,.5); 2 = (.2,.9) and 3 = (.9,.3) are mutually non-dominated
    F = np.array([[0.1, 0.1], [0.5, 0.5], [0.2, 0.9], [0.9, 0.3]])
    fc = np.array([0.9, 0.01, 0.3, 0.2])          # FC must not override dominance
    a = np.array([0, 1, 2, 3, 2, 1])
    b = np.array([1, 0, 3, 2, 2, 3])
    # (0,1) dominance -> 0; (1,0) -> 0; (2,3) FC .3 > .2 -> 3; (3,2) -> 3; (2,2) -> 2;
    # (1,3): non-dominated, FC .01 < .2 -> 1
    assert tournament_winners(F, fc, a, b).tolist() == [0, 0, 3, 3, 2, 1]


def test_tournament_treats_fc_below_its_resolution_as_equal():
    # DTLZ4's x^100 gives boundary points normalised objectives such as 1e-50 or 1e-100, so FC ~ 1e-50 and
    # ~ 1e-100: both are "on the boundary" and the comparison must not decide (it made the point of a rare
    # region lose every tournament). Below 1e-6 the first drawn wins, in both orders; above, the smaller FC.
    F = np.array([[1.0, 1e-100, 0.0], [0.1, 1e-50, 0.9], [0.5, 0.5, 0.5]])   # mutually non-dominated
    fc = np.array([1e-100, 1e-50, 0.3])
    a = np.array([0, 1, 1, 2])
    b = np.array([1, 0, 2, 1])
    assert tournament_winners(F, fc, a, b).tolist() == [0, 1, 1, 1]
    assert tournament_winners(F, np.array([0.0, 2e-6, 0.3]), np.array([1]), np.array([0])).tolist() == [0]


# ----------------------------------------------------------------------------- survival
class _Dummy(Problem):
    def __init__(self):
        super().__init__(n_var=1, n_obj=2, xl=0.0, xu=1.0)


def _pop(F):
    return Population.new(X=np.zeros((len(F), 1)), F=np.asarray(F, dtype=float))


# Front 1: A=(0,1), B=(1,0), G=(.5,.5) (A, B are the extreme points: the normalised objectives
# equal F). Front 2: C=(.3,1.05) (dominated by A), D=(1.1,.3) (by B), E=(.6,.6), H=(.55,.62) (by G).
SURV_F = [[0, 1], [1, 0], [0.5, 0.5], [0.3, 1.05], [1.1, 0.3], [0.6, 0.6], [0.55, 0.62]]


def test_survival_hand_case():
    # Directions t = f1/(f1+f2): A 0, B 1, G .5, C .2222, D .7857, E .5, H .4701.
    # K = 1, L = 1: distance to the nearest of {0, .5, 1}: C .2222, D .2143, E 0, H .0299
    #   => C (least crowded) then D (.2143 vs H .0299, E 0).
    s = DDFCSurvival(2, n_neighbors=1, n_candidates=1, candidate_choice="best")
    out = s.do(_Dummy(), _pop(SURV_F), n_survive=5, random_state=np.random.default_rng(0))
    assert out.get("F").tolist() == [SURV_F[i] for i in (0, 1, 2, 3, 4)]
    np.testing.assert_array_equal(s.ideal_point, [0, 0])
    np.testing.assert_allclose(s.nadir_point, [1, 1])
    np.testing.assert_array_equal(out.get("rank"), [0, 0, 0, 1, 1])
    np.testing.assert_allclose(out.get("FC"), [0, 0, 0.25, 1 / (1 / 0.3 + 1 / 1.05), 1 / (1 / 1.1 + 1 / 0.3)])


def test_survival_whole_fronts_and_defaults():
    # With the default K = 5, L = 3 and roulette, front 1 always survives whole, and a
    # population that fits is returned unchanged.
    for seed in range(10):
        s = DDFCSurvival(2)
        out = s.do(_Dummy(), _pop(SURV_F), n_survive=4, random_state=np.random.default_rng(seed))
        rows = out.get("F").tolist()
        assert rows[:3] == SURV_F[:3] and len(rows) == 4
    out = DDFCSurvival(2).do(_Dummy(), _pop(SURV_F), n_survive=7, random_state=np.random.default_rng(0))
    assert sorted(out.get("F").tolist()) == sorted(SURV_F)


def test_survival_is_invariant_to_objective_scaling():
    scale = np.array([1e3, 1e-2])
    kw = dict(n_neighbors=2, n_candidates=2, candidate_choice="best")
    a = DDFCSurvival(2, **kw).do(_Dummy(), _pop(SURV_F), n_survive=5, random_state=np.random.default_rng(0))
    b = DDFCSurvival(2, **kw).do(_Dummy(), _pop(np.asarray(SURV_F) * scale), n_survive=5,
                                 random_state=np.random.default_rng(0))
    np.testing.assert_allclose(a.get("F") * scale, b.get("F"))


def test_survival_any_size_and_repeated_calls():
    rng = np.random.default_rng(3)
    s = DDFCSurvival(3)
    prob = get_problem("dtlz2", n_obj=3, n_var=5)
    for n in (15, 40, 97, 15):
        out = s.do(prob, _pop(rng.random((n, 3))), n_survive=15, random_state=rng)
        assert len(out) == 15 and np.all(np.isfinite(out.get("FC")))


# ----------------------------------------------------------------------------- runs
def _run(seed, n_eval=600, **kw):
    problem = get_problem("dtlz2", n_obj=3, n_var=12)
    res = minimize(problem, make_maoea_ddfc(n_obj=3, **kw), ("n_eval", n_eval), seed=seed)
    return res.algorithm.pop.get("F")


def test_determinism_with_best_candidate_choice():
    # the default settings are checked for every algorithm in test_moea_common.py
    np.testing.assert_array_equal(_run(4, candidate_choice="best"), _run(4, candidate_choice="best"))


@pytest.mark.parametrize("kwargs, exc, word", [
    ({"n_obj": 3, "n_neighbors": 0}, ValueError, "n_neighbors"),
    ({"n_obj": 3, "n_candidates": 1.5}, TypeError, "n_candidates"),
    ({"n_obj": 3, "candidate_choice": "tournament"}, ValueError, "candidate_choice"),
])
def test_bad_arguments(kwargs, exc, word):
    with pytest.raises(exc, match=word):
        make_maoea_ddfc(**kwargs)


