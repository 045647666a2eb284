"""Tests of MOEA/IGD-NS (moo.algorithms.moea_igd_ns).

References used (independent of the code under test):

* hand-worked IGD-NS values, deletions, angle truncations and survivals on
  tiny populations (the arithmetic is written next to each case);
* a plain double loop implementing the IGD-NS definition, evaluated on every
  ``Q \\ {x}`` (checks the vectorised deletion scores and the incremental
  nearest-neighbour bookkeeping of the deletion loop);
* brute-force Pareto dominance for the archive;
* pymoo's NSGA-III at the same budget (DTLZ2) and the closed-form DTLZ1 front.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.problems import get_problem

from moo.algorithms.moea_igd_ns import (
    IGDNSSurvival,
    igd_ns,
    igd_ns_deletion_scores,
    make_moea_igd_ns,
    reduce_by_igd_ns,
    truncate_by_angle,
    update_archive,
)

PROBLEM2 = Problem(n_var=1, n_obj=2)


def _igd_ns_loop(Q, A):
    """The definition: sum over A of the nearest distance + distances of non-contributing solutions."""
    def d(x, y):
        return math.sqrt(sum((a - b) ** 2 for a, b in zip(x, y, strict=True)))
    total, contributing = 0.0, set()
    for y in A:
        dists = [d(x, y) for x in Q]
        j = min(range(len(Q)), key=lambda k: (dists[k], k))
        contributing.add(j)
        total += dists[j]
    for k, x in enumerate(Q):
        if k not in contributing:
            total += min(d(x, y) for y in A)
    return total


# ----------------------------------------------------------------------------- the indicator
def test_igd_ns_by_hand():
    # (0,1) and (1,0) serve the two reference points at distance 0; (0.6, 0.6)
    # serves none, its distance to the archive is sqrt(0.6^2 + 0.4^2) = sqrt(0.52)
    Q = [[0.0, 1.0], [1.0, 0.0], [0.6, 0.6]]
    A = [[0.0, 1.0], [1.0, 0.0]]
    assert igd_ns(Q, A) == pytest.approx(math.sqrt(0.52), rel=1e-14)
    # without the non-contributing solution only the IGD part (0) remains
    assert igd_ns(Q[:2], A) == 0.0


def test_igd_ns_matches_loop():
    rng = np.random.default_rng(1)
    Q, A = rng.random((15, 3)), rng.random((25, 3))
    assert igd_ns(Q, A) == pytest.approx(_igd_ns_loop(Q.tolist(), A.tolist()), rel=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_deletion_scores_match_definition(seed):
    rng = np.random.default_rng(seed)
    n, r, m = rng.integers(3, 20), rng.integers(1, 30), rng.integers(2, 5)
    Q, A = rng.random((n, m)), rng.random((r, m))
    alive = rng.random(n) < 0.7
    alive[:2] = True
    from scipy.spatial.distance import cdist
    scores = igd_ns_deletion_scores(cdist(Q, A), alive)
    idx = np.flatnonzero(alive)
    for x in idx:
        rest = [Q[k].tolist() for k in idx if k != x]
        assert scores[x] == pytest.approx(_igd_ns_loop(rest, A.tolist()), rel=1e-10, abs=1e-12)
    assert np.all(np.isinf(scores[~alive]))


def test_reduce_by_hand():
    # A = (0,1), (.5,.5), (1,0); Q0 = (0,1.05), Q1 = (.52,.52), Q2 = (.5,.55), Q3 = (1.02,0).
    # Q2 serves no point (Q1 is nearer (.5,.5): .0283 < .05): deleting it lowers IGD-NS by .05;
    # deleting Q1 instead: (.5,.5) moves to Q2 (+.05 - .0283) and Q2 stops being
    # non-contributing (-.05): net -.0283 > -.05. So Q2 goes first.
    A = [[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]]
    Q = [[0.0, 1.05], [0.52, 0.52], [0.5, 0.55], [1.02, 0.0]]
    np.testing.assert_array_equal(reduce_by_igd_ns(Q, A, 3), [0, 1, 3])
    # next deletion among Q0, Q1, Q3 (all contributing, nearest distances .05, .0283, .02):
    # Q0 out: (0,1) -> Q1 at .7077, increase .6577; Q1 out: (.5,.5) -> Q3 at .7214, increase .6931;
    # Q3 out: (1,0) -> Q1 at .7077, increase .6877. Smallest increase: delete Q0.
    np.testing.assert_array_equal(reduce_by_igd_ns(Q, A, 2), [1, 3])


@pytest.mark.parametrize("seed", range(3))
def test_reduce_is_greedy_on_definition(seed):
    rng = np.random.default_rng(10 + seed)
    Q, A = rng.random((12, 2)), rng.random((9, 2))
    keep = reduce_by_igd_ns(Q, A, 4)
    # the same greedy deletion, each step by the loop definition
    alive = list(range(len(Q)))
    while len(alive) > 4:
        vals = [_igd_ns_loop([Q[k] for k in alive if k != x], A) for x in alive]
        alive.remove(alive[int(np.argmin(vals))])
    np.testing.assert_array_equal(keep, alive)


# ----------------------------------------------------------------------------- archive
def test_truncate_by_angle_by_hand():
    # extremes (1,0) [0 deg] and (0,1) [90 deg] first; then the largest minimum angle:
    # (.5,.5) at 45 deg (min angle 45) beats (.2,.8) at 76 deg (14) and (.9,.15) at 9.5 deg (9.5);
    # then (.2,.8): min angle to {0, 45, 90} is 14 > 9.5.
    F = np.array([[0.2, 0.8], [1.0, 0.0], [0.5, 0.5], [0.0, 1.0], [0.9, 0.15]])
    np.testing.assert_array_equal(truncate_by_angle(F, 3), [1, 3, 2])
    np.testing.assert_array_equal(truncate_by_angle(F, 4), [1, 3, 2, 0])
    np.testing.assert_array_equal(truncate_by_angle(F, 9), np.arange(5))


def test_truncate_random_when_extremes_exceed_size():
    F = np.eye(4)
    rng = np.random.default_rng(0)
    out = truncate_by_angle(F, 2, random_state=rng)
    assert len(out) == 2 and len(set(out)) == 2
    with pytest.raises(ValueError, match="random_state"):
        truncate_by_angle(F, 2)


def test_update_archive_keeps_nondominated_once():
    F = np.array([[1.0, 2.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0], [0.5, 3.0], [3.0, 3.0]])
    idx = update_archive(F, 10)
    # brute force: non-dominated rows, duplicates once
    nd = [i for i in range(len(F)) if not any(np.all(F[j] <= F[i]) and np.any(F[j] < F[i]) for j in range(len(F)))]
    assert sorted(set(map(tuple, F[idx]))) == sorted(set(map(tuple, F[nd])))
    assert len(idx) == 3


def test_survival_updates_archive_from_what_it_receives():
    surv = IGDNSSurvival(archive_size=4)
    rng = np.random.default_rng(0)
    t = rng.random(6)
    front = np.column_stack([t, 1 - t])          # mutually non-dominated
    pop = Population.new(X=rng.random((6, 1)), F=front + 0.5)
    surv.do(PROBLEM2, pop, n_survive=3)
    assert len(surv.archive) == 4
    # a second call (as MO-LSP does) with better points replaces the archive
    better = Population.new(X=rng.random((6, 1)), F=front)
    out = surv.do(PROBLEM2, Population.merge(pop, better), n_survive=3)
    assert len(out) == 3
    A = surv.archive.get("F")
    assert len(A) == 4 and np.all(np.isin(A[:, 0], front[:, 0]))
    surv.reset()
    assert surv.archive is None


def test_survival_by_hand():
    # front 1 = (0,1), (1,0) (the archive); front 2 = (.1,1.1), (1.1,.1), (1.05,1.05).
    # n_survive 4: front 1 kept; from front 2, (1.05,1.05) serves no archive point and is
    # sqrt(1.05^2 + .05^2) = 1.0512 away from it, the others serve (0,1) and (1,0) at .1414:
    # deleting (1.05,1.05) lowers IGD-NS by 1.0512, deleting (.1,1.1) would raise it
    # ((0,1) would be served at distance 1.0512 instead of .1414). (1.05,1.05) goes.
    F = np.array([[0.1, 1.1], [0.0, 1.0], [1.05, 1.05], [1.0, 0.0], [1.1, 0.1]])
    pop = Population.new(X=np.zeros((5, 1)), F=F)
    surv = IGDNSSurvival(archive_size=10)
    kept = surv.do(PROBLEM2, pop, n_survive=4, return_indices=True)
    assert sorted(kept) == [0, 1, 3, 4]
    np.testing.assert_array_equal(np.sort(surv.archive.get("F"), axis=0), [[0.0, 0.0], [1.0, 1.0]])


def test_survival_feasible_first_and_archive_from_feasible_only():
    # the infeasible (-1,-1) would dominate everything; it must neither survive ahead of
    # the feasible points nor enter the archive
    F = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5], [-1.0, -1.0], [2.0, 2.0]])
    cv = np.array([0, 0, 0, 0.3, 0.1])[:, None]
    pop = Population.new(X=np.zeros((5, 1)), F=F, CV=cv)
    surv = IGDNSSurvival(archive_size=10)
    kept = surv.do(Problem(n_var=1, n_obj=2, n_ieq_constr=1), pop, n_survive=4, return_indices=True)
    assert sorted(kept[:3]) == [0, 1, 2] and kept[3] == 4
    assert len(surv.archive) == 3 and np.all(surv.archive.get("F") >= 0)


def test_survival_any_merged_size():
    rng = np.random.default_rng(5)
    surv = IGDNSSurvival(archive_size=50)
    problem = Problem(n_var=2, n_obj=3)
    for n in (20, 37, 120):
        pop = Population.new(X=rng.random((n, 2)), F=rng.random((n, 3)))
        assert len(surv.do(problem, pop, n_survive=20)) == 20
    assert len(surv.archive) <= 50


def test_archive_on_runs_wrapped_with_molsp():
    # the MO-LSP run itself (budget, determinism) is checked in test_moea_common.py
    from moo.molsp import molsp

    problem = get_problem("dtlz2", n_obj=3)
    res = minimize(problem, molsp(make_moea_igd_ns(n_obj=3), ref_point=np.full(3, 2.0)), ("n_eval", 1500), seed=2)
    A = res.algorithm.survival.archive.get("F")
    # the archive holds mutually non-dominated points only
    assert not np.any([np.any(np.all(a >= A, axis=1) & np.any(a > A, axis=1)) for a in A])


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, exc, word", [
    ({"n_obj": "3"}, TypeError, "n_obj"),
    ({"n_obj": 3, "archive_size": 0}, ValueError, "archive_size"),
    ({"n_obj": 3, "archive_size": 10.0}, TypeError, "archive_size"),
])
def test_bad_parameters(kwargs, exc, word):
    with pytest.raises(exc, match=word):
        make_moea_igd_ns(**kwargs)


def test_bad_shapes():
    with pytest.raises(ValueError, match=r"reference must have 2 columns, got shape \(2, 3\)"):
        igd_ns(np.zeros((3, 2)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="Q must be a 2-D"):
        igd_ns(np.zeros(3), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="finite"):
        reduce_by_igd_ns([[np.nan, 1.0], [0.0, 1.0]], [[0.0, 1.0]], 1)
    with pytest.raises(ValueError, match="alive"):
        igd_ns_deletion_scores(np.zeros((3, 2)), np.array([True, False, False]))
