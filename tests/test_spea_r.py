"""Tests of SPEA/R (moo.algorithms.spea_r).

Expected values are worked out by hand in the comments (angles from atan2,
strengths by counting), or by brute force independent of the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from moocore import is_nondominated
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.util.ref_dirs import get_reference_directions

from moo.algorithms.normalization import HyperplaneNormalization, front_bounds
from moo.algorithms.spea_r import (
    NeighbourMatingSelection,
    SPEARSurvival,
    associate_by_angle,
    dominance_matrix,
    largest_neighbour_angle,
    make_spea_r,
    spea_r_fitness,
)

DIRS3 = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])                  # at 0, 45, 90 degrees
DIRS5 = np.array([[1.0, 0.0], [0.75, 0.25], [0.5, 0.5], [0.25, 0.75], [0.0, 1.0]])  # 0, 18.43, 45, 71.57, 90


def _pop(F):
    return Population.new("F", np.asarray(F, dtype=float))


class _Dummy(Problem):
    def __init__(self, n_obj=2):
        super().__init__(n_var=1, n_obj=n_obj, xl=0.0, xu=1.0)


def _density(angle, theta_bar):
    return angle / (angle + theta_bar)


def test_dominance_matrix_by_hand():
    F = np.array([[1.0, 1.0], [2.0, 2.0], [1.0, 2.0], [0.5, 3.0], [1.0, 1.0]])
    D = dominance_matrix(F)
    expected = np.zeros((5, 5), bool)
    expected[0, [1, 2]] = True          # (1,1) dominates (2,2) and (1,2), not its duplicate
    expected[4, [1, 2]] = True
    expected[2, 1] = True               # (1,2) dominates (2,2)
    np.testing.assert_array_equal(D, expected)


def test_largest_neighbour_angle():
    assert largest_neighbour_angle(DIRS3) == pytest.approx(np.pi / 4)
    # 5 directions: gaps 18.43, 26.57, 26.57, 18.43 degrees; nearest-neighbour angles 18.43, 18.43, 26.57, 18.43,
    # 18.43 -> the largest is 45 - atan(1/3) = atan(1/2)
    assert largest_neighbour_angle(DIRS5) == pytest.approx(math.atan(0.5))
    assert largest_neighbour_angle(np.array([[1.0, 1.0]])) == pytest.approx(np.pi / 2)


def test_largest_neighbour_angle_brute_force_3d():
    W = get_reference_directions("das-dennis", 3, n_partitions=12)
    best = 0.0
    for i, u in enumerate(W):
        nearest = min(math.acos(min(1.0, float(u @ v) / math.hypot(*u) / math.hypot(*v)))
                      for j, v in enumerate(W) if j != i)
        best = max(best, nearest)
    assert largest_neighbour_angle(W) == pytest.approx(best, rel=1e-9)


def test_associate_by_angle_by_hand():
    Fn = np.array([[0.1, 0.9], [0.6, 0.7], [0.0, 0.0], [2.0, 0.1]])
    niche, angle = associate_by_angle(Fn, DIRS3)
    np.testing.assert_array_equal(niche, [2, 1, 0, 0])
    np.testing.assert_allclose(angle, [math.atan2(0.1, 0.9), math.atan2(0.7, 0.6) - np.pi / 4, 0.0,
                                       math.atan2(0.1, 2.0)], atol=1e-12)


def test_fitness_local_and_global_strength_by_hand():
    # b (0.5, 0.5), c (0.6, 0.7), d (0.9, 0.2), a (0.55, 2.0); directions at 0, 45, 90 degrees.
    # Dominance: b > c, b > a (only). Global strengths S: b 2, others 0 -> R: c 2, a 2.
    # Niches: b, c -> diagonal (angles 0 and atan2(.7,.6) - 45deg); d -> f1 axis (atan(.2/.9));
    #         a -> f2 axis (atan(.55/2)), alone.
    # Local: S'(b) = 1 in the diagonal niche -> R'(c) = 1.
    # F: b = 0; c = R' + R + D = 1 + 2 + D(c); d = D(d); a alone -> R'(a) + D(a) = D(a) (its R = 2 is ignored).
    F = np.array([[0.5, 0.5], [0.6, 0.7], [0.9, 0.2], [0.55, 2.0]])
    niche, angle = associate_by_angle(F, DIRS3)
    np.testing.assert_array_equal(niche, [1, 1, 0, 2])
    tb = np.pi / 4
    fit = spea_r_fitness(F, niche, angle, tb)
    expected = [0.0,
                3.0 + _density(math.atan2(0.7, 0.6) - np.pi / 4, tb),
                _density(math.atan2(0.2, 0.9), tb),
                _density(math.atan2(0.55, 2.0), tb)]
    np.testing.assert_allclose(fit, expected, atol=1e-12)
    assert fit[3] < 1.0 < fit[1]


# Hand population for the environmental selection, 5 directions (theta_bar = atan(1/2)):
#   p1 (0, 1), p2 (1, 0), p3 (0.5, 0.5), s (0.45, 0.56): non-dominated -> z_min (0, 0), z_max (1, 1), so the
#     normalised objectives equal the raw ones.
#   q (0.5, 1.0): dominated by p3 and s; at 63.4 degrees -> niche 3 (71.57), alone there: F = D(q) < 1.
#   r (0.7, 0.6): dominated by p3 and s; at 40.6 degrees -> niche 2 with p3 and s.
#     Local S'(p3) = S'(s) = 1 -> R'(r) = 2; global S(p3) = S(s) = 2 (q and r) -> R(r) = 4; F(r) = 6 + D(r).
#   Niches: p2 -> 0, {p3, s, r} -> 2, q -> 3, p1 -> 4. F = 0 for p1, p2, p3 (angle 0); F(s) = D(6.2 deg).
# Round 1: p2, p3, q, p1; round 2: s (F(s) < F(r)); round 3: r.
HAND = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5], [0.5, 1.0], [0.7, 0.6], [0.45, 0.56]])
P1, P2, P3, Q, R, S = range(6)


@pytest.mark.parametrize("n_survive, expected", [
    (3, {P1, P2, P3}),            # round 1 does not fit: smallest F (0, 0, 0 < D(q))
    (4, {P1, P2, P3, Q}),         # diversity first: the dominated q beats the non-dominated s
    (5, {P1, P2, P3, Q, S}),      # round 2: s before r
    (6, set(range(6))),
])
def test_environmental_selection_hand_population(n_survive, expected):
    surv = SPEARSurvival(DIRS5)
    out = surv.do(_Dummy(), _pop(HAND), n_survive=n_survive, random_state=np.random.default_rng(0))
    got = {int(np.flatnonzero(np.all(f == HAND, axis=1))[0]) for f in out.get("F")}
    assert got == expected
    if n_survive == 6:
        fit = dict(zip(map(tuple, out.get("F")), out.get("fitness"), strict=True))
        tb = math.atan(0.5)
        assert fit[tuple(HAND[Q])] == pytest.approx(_density(math.atan2(0.75, 0.25) - math.atan2(1.0, 0.5), tb))
        assert fit[tuple(HAND[R])] == pytest.approx(6.0 + _density(np.pi / 4 - math.atan2(0.6, 0.7), tb))
        assert fit[tuple(HAND[S])] == pytest.approx(_density(math.atan2(0.56, 0.45) - np.pi / 4, tb))


def test_selection_is_invariant_to_objective_scaling():
    rng = np.random.default_rng(4)
    F = rng.random((50, 3))
    dirs = get_reference_directions("das-dennis", 3, n_partitions=5)
    scale, shift = np.array([100.0, 1.0, 0.01]), np.array([-3.0, 0.0, 7.0])
    a = SPEARSurvival(dirs).do(_Dummy(3), _pop(F), n_survive=20, random_state=np.random.default_rng(0))
    b = SPEARSurvival(dirs).do(_Dummy(3), _pop(F * scale + shift), n_survive=20, random_state=np.random.default_rng(0))
    np.testing.assert_allclose(a.get("F") * scale + shift, b.get("F"))


def test_mating_with_all_candidates_picks_nearest_neighbour():
    # non-dominated points on f1 + f2 = 1 spanning (0,1)-(1,0): normalised = raw. Nearest others:
    # 0 -> 1, 1 -> 0, 2 -> 3, 3 -> 2, 4 -> 3.
    F = np.array([[0.0, 1.0], [0.1, 0.9], [0.5, 0.5], [0.55, 0.45], [1.0, 0.0]])
    P = NeighbourMatingSelection(k=4).do(_Dummy(), _pop(F), 10, 2, to_pop=False,
                                         random_state=np.random.default_rng(0))
    nearest = np.array([1, 0, 3, 2, 3])
    np.testing.assert_array_equal(P[:, 1], nearest[P[:, 0]])
    np.testing.assert_array_equal(np.sort(P[:5, 0]), np.arange(5))      # first parents: a permutation


def test_mating_with_one_candidate_is_uniform_over_others():
    F = np.array([[0.0, 1.0], [0.1, 0.9], [0.5, 0.5], [0.55, 0.45], [1.0, 0.0]])
    P = NeighbourMatingSelection(k=1).do(_Dummy(), _pop(F), 5000, 2, to_pop=False,
                                         random_state=np.random.default_rng(1))
    assert np.all(P[:, 0] != P[:, 1])
    for i in range(5):
        freq = np.bincount(P[P[:, 0] == i, 1], minlength=5) / np.sum(P[:, 0] == i)
        assert freq[i] == 0
        np.testing.assert_allclose(np.delete(freq, i), 0.25, atol=0.05)


def test_non_finite_objectives_rank_last_and_mate_far():
    F = np.vstack([HAND[:3], [[np.inf, 0.0]], HAND[3:], [[np.nan, np.nan]]])
    surv = SPEARSurvival(DIRS5)
    out = surv.do(_Dummy(), _pop(F), n_survive=4, random_state=np.random.default_rng(0))
    np.testing.assert_array_equal(np.sort(out.get("F"), axis=0), np.sort(HAND[[P1, P2, P3, Q]], axis=0))
    out = surv.do(_Dummy(), _pop(F), n_survive=7, random_state=np.random.default_rng(0))
    assert len(out) == 7 and np.sum(~np.all(np.isfinite(out.get("F")), axis=1)) == 1
    # mating with every candidate visible: a finite parent never picks a non-finite mate
    P = NeighbourMatingSelection(k=7).do(_Dummy(), _pop(F), 40, 2, to_pop=False,
                                         random_state=np.random.default_rng(0))
    bad = {3, 7}
    assert all(m not in bad for f, m in P if f not in bad)


def test_survival_tolerates_repeated_calls_on_any_size():
    rng = np.random.default_rng(5)
    surv = SPEARSurvival(get_reference_directions("das-dennis", 3, n_partitions=5))
    for n in (21, 64, 30, 250):
        out = surv.do(_Dummy(3), _pop(rng.random((n, 3))), n_survive=21, random_state=rng)
        assert len(out) == 21 and np.all(np.isfinite(out.get("fitness")))
    # a degenerate population: all identical -> no division by zero, any 3 survive
    out = surv.do(_Dummy(3), _pop(np.ones((6, 3))), n_survive=3, random_state=rng)
    assert len(out) == 3


# ---------------------------------------------------------------------------------------------
# runs
# ---------------------------------------------------------------------------------------------

def _run(alg, problem, n_eval, seed):
    return minimize(problem, alg, ("n_eval", n_eval), seed=seed)


def test_factory_arguments():
    assert make_spea_r(n_obj=4, k_mating=5).mating.selection.k == 5
    with pytest.raises(ValueError, match="k_mating"):
        make_spea_r(n_obj=3, k_mating=0)
    with pytest.raises(ValueError, match="n_obj"):
        make_spea_r(n_obj=1)
    with pytest.raises(ValueError, match="3 columns but the problem has 2"):
        _run(make_spea_r(n_obj=3), get_problem("zdt1"), 200, 0)


def test_runs_wrapped_in_molsp():
    from moo.molsp import molsp
    p = get_problem("dtlz2", n_obj=3)
    res = _run(molsp(make_spea_r(n_obj=3), ref_point=[1.5, 1.5, 1.5]), p, 1500, 3)
    assert res.algorithm.evaluator.n_eval <= 1500 + 92
    assert np.all(np.isfinite(res.F)) and len(res.F) > 10
    assert np.median(np.linalg.norm(res.F, axis=1)) < 1.5


# ---------------------------------------------------------------------------------------------
# property test against a brute-force reference (plain Python loops, no code under test)
# ---------------------------------------------------------------------------------------------

def _brute_spea_r_survivors(F, n_survive, W, Fn=None):
    """The paper's selection by loops; angles from ``Fn`` when given, else the front's min/max normalisation."""
    n, M = F.shape
    dom = [[all(x <= y for x, y in zip(F[i], F[j], strict=True)) and any(x < y for x, y in zip(F[i], F[j], strict=True))
            for j in range(n)] for i in range(n)]
    nd = [i for i in range(n) if not any(dom[j][i] for j in range(n))]
    lo = [min(F[i, m] for i in nd) for m in range(M)]
    hi = [max(F[i, m] for i in nd) for m in range(M)]
    rng = [hi[m] - lo[m] if hi[m] - lo[m] > 1e-10 else max(F[:, m]) - lo[m] for m in range(M)]
    rng = [r if r > 1e-10 else 1.0 for r in rng]
    norm = lambda v: math.sqrt(sum(x * x for x in v))  # noqa: E731
    cosang = lambda u, v: sum(a * b for a, b in zip(u, v, strict=True)) / (norm(u) * norm(v))  # noqa: E731
    theta_bar = max(min(math.acos(min(1.0, cosang(W[i], W[j]))) for j in range(len(W)) if j != i)
                    for i in range(len(W)))
    niche, angle = [], []
    for i in range(n):
        fn = [(F[i, m] - lo[m]) / rng[m] for m in range(M)] if Fn is None else list(Fn[i])
        if norm(fn) == 0:
            niche.append(0)
            angle.append(0.0)
            continue
        cos = [cosang(fn, w) for w in W]
        j = max(range(len(W)), key=lambda k: cos[k])
        niche.append(j)
        angle.append(math.acos(min(1.0, cos[j])))
    S = [sum(dom[i]) for i in range(n)]
    Sl = [sum(1 for j in range(n) if dom[i][j] and niche[j] == niche[i]) for i in range(n)]
    fit = []
    for i in range(n):
        R = sum(S[j] for j in range(n) if dom[j][i])
        Rl = sum(Sl[j] for j in range(n) if dom[j][i] and niche[j] == niche[i])
        alone = sum(1 for j in range(n) if niche[j] == niche[i]) == 1
        fit.append(Rl + angle[i] / (angle[i] + theta_bar) + (0 if alone else R))
    chosen, left = [], set(range(n))
    while len(chosen) < n_survive:                       # the paper's rounds, literally
        H = [min((i for i in left if niche[i] == j), key=lambda i: fit[i]) for j in sorted({niche[i] for i in left})]
        left -= set(H)
        if len(chosen) + len(H) <= n_survive:
            chosen += H
        else:
            chosen += sorted(H, key=lambda i: fit[i])[:n_survive - len(chosen)]
    return set(chosen)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), M=st.sampled_from([2, 3, 4]), extra=st.integers(0, 30))
def test_survival_matches_brute_force_reference(seed, M, extra):
    rng = np.random.default_rng(seed)
    W = get_reference_directions("das-dennis", M, n_partitions={2: 7, 3: 4, 4: 3}[M])
    n_survive = len(W)
    F = rng.random((n_survive + extra + 1, M)) ** rng.uniform(0.5, 3.0)
    F[:, 0] *= 10.0
    got = set(SPEARSurvival(W, normalization="front").do(_Dummy(M), _pop(F), n_survive=n_survive,
                                                          random_state=rng, return_indices=True))
    assert got == _brute_spea_r_survivors(F, n_survive, W)
    # the default, hyperplane normalisation: the same rules on the objectives a fresh HyperplaneNormalization maps
    # (its own checks are in test_theta_dea.py)
    nd = np.flatnonzero(is_nondominated(F))
    norm = HyperplaneNormalization(M)
    norm.update(F, nondominated=nd)
    got = set(SPEARSurvival(W).do(_Dummy(M), _pop(F), n_survive=n_survive, random_state=rng, return_indices=True))
    assert got == _brute_spea_r_survivors(F, n_survive, W, Fn=norm.normalize(F))


def test_hyperplane_normalisation_ignores_a_dominance_resistant_point():
    # DTLZ1-like plane sum f = 0.5 (a Das-Dennis grid on it, lifted by 1e-6) plus one dominance-resistant point
    # (1.0, 1e-9, 1e-9): non-dominated (its f2 = 1e-9 is the smallest), so the min/max of the non-dominated set
    # ("front", the paper's reading) stretches f1's range to 1.0 and the directions near the f1 axis then see
    # only such stragglers; the hyperplane through the extreme points keeps the true 0.5
    W = get_reference_directions("das-dennis", 3, n_partitions=6)
    F = np.vstack([0.5 * W + 1e-6, [[1.0, 1e-9, 1e-9]]])
    nd = is_nondominated(F)
    assert nd.all()
    z_min, span = front_bounds(F, nd)
    np.testing.assert_allclose(z_min + span, [1.0, 0.5, 0.5], atol=2e-6)
    surv = SPEARSurvival(get_reference_directions("das-dennis", 3, n_partitions=4))
    surv.do(_Dummy(3), _pop(F), n_survive=15, random_state=np.random.default_rng(0))
    np.testing.assert_allclose(surv.norm.nadir_point, [0.5, 0.5, 0.5], atol=1e-5)
