"""Issue 35 item 3: honest defaults and feedback (reference points, progress, one objective, algorithm names)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import robustctl as rc
from moo import tuning
from moo.algorithms import make_algorithm

PLANT = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
SCENARIOS = [rc.Plant(PLANT.F * s, PLANT.G, dt=0.1) for s in (0.95, 1.0, 1.05)]


def effort(K, plants):
    return np.abs(K).sum(axis=(1, 2))


def radius(K, plants):
    return np.max([np.abs(np.linalg.eigvals(p.F + p.G @ K)).max(axis=1) for p in plants], axis=0)


def test_the_hypervolume_of_a_result_is_measured_from_sampled_designs():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    res = tuning.tune(prob, evals=200, seed=1, pop_size=20)
    hv, _ = prob.sample_reference_points(500, seed=0)
    np.testing.assert_array_equal(res.run.hv_ref_point, hv)
    assert res.hv_reference == "sampled designs" and "(reference: sampled designs)" in repr(res)
    # on the penalty scale (the old default) every front's hypervolume is ~1e12 and differences vanish
    assert res.run.hv < 1e3 and np.all(hv < 1e3)


def test_the_penalty_is_the_reference_only_when_no_sampled_design_is_acceptable():
    def huge(K, plants):
        return np.full(len(K), 2e6)                 # above the penalty: clipped, never acceptable

    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [huge, effort], reference_samples=20)
    np.testing.assert_array_equal(prob.hv_ref_point, [1e6, 1e6])
    assert prob.hv_ref_source == "penalty: none of 20 sampled designs was acceptable"


def test_tune_shows_a_bar_and_one_summary_line_on_a_terminal_only(monkeypatch, capsys):
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    res = tuning.tune(prob, evals=100, seed=0, pop_size=20, progress=True)
    assert capsys.readouterr().err == ""                       # not a terminal under pytest: quiet
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    again = tuning.tune(prob, evals=100, seed=0, pop_size=20, progress=True)
    err = capsys.readouterr().err
    np.testing.assert_array_equal(again.F, res.F)              # the bar changes nothing
    assert "evals/s" in err and "/100 [" in err
    assert err.rsplit("\r", 1)[-1] == res.summary() + "\n"
    assert res.summary().startswith(f"front: {len(res.F)} designs, hypervolume {res.run.hv:.6g} "
                                    "(reference: sampled designs); best effort ")
    calls = []
    tuning.tune(prob, evals=100, seed=0, pop_size=20, progress=lambda done, total: calls.append((done, total)))
    assert calls[0] == (20, 100) and calls[-1][0] >= 100 and all(t == 100 for _, t in calls)


def test_a_single_objective_problem_runs_with_a_genetic_algorithm():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [radius])
    res = tuning.tune(prob, evals=300, seed=2, pop_size=20)
    assert res.run.algorithm == "ga" and res.run.molsp and res.F.shape == (1, 1)
    # the best design of a random sample of 300 is not better than the tuned one
    Z = np.random.default_rng(0).uniform(prob.xl, prob.xu, (300, prob.n_var))
    assert res.F[0, 0] <= prob.evaluate(Z).min() + 1e-12
    with pytest.raises(ValueError, match=r"n_obj must be >= 2 for the MOEA .nsga3.*runs with algorithm .ga."):
        tuning.tune(prob, "nsga3", evals=300, pop_size=20)


def test_nsga2_is_the_papers_operators_and_pymoo_nsga2_is_pymoos():
    ours, theirs = make_algorithm("nsga2", n_obj=2, pop_size=20), make_algorithm("pymoo-nsga2", n_obj=2, pop_size=20)
    assert (ours.mating.crossover.eta.value, ours.mating.crossover.prob.value) == (20.0, 1.0)
    assert (theirs.mating.crossover.eta.value, theirs.mating.crossover.prob.value) == (15, 0.9)
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, radius])
    res = tuning.tune(prob, "pymoo-nsga2", evals=100, seed=0, pop_size=20, molsp=False)
    assert res.run.algorithm == "pymoo-nsga2" and len(res.F) >= 1
    with pytest.raises(TypeError, match="progress must be a bool or a callable"):
        tuning.tune(prob, evals=100, pop_size=20, progress="yes")
