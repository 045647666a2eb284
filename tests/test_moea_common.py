"""Run-level checks that hold for every MOEA of the registry ``moo.algorithms.ALGORITHMS``.

Same seed -> identical run, other seed -> other run; a reused algorithm object
repeats its run (state is reset at setup); the algorithm runs wrapped by MO-LSP
and stays deterministic; the factories reject bad ``n_obj``/``pop_size``.
Algorithm-specific checks (hand-made cases, quality against NSGA-III, DTLZ1
convergence) stay in each algorithm's own test file.
"""

from __future__ import annotations

from importlib import import_module

import numpy as np
import pytest
from pymoo.optimize import minimize
from pymoo.problems import get_problem

from moo.algorithms import ALGORITHMS
from moo.molsp import molsp

NAMES = list(ALGORITHMS)
#: The paper's eight compared MOEAs (NSGA-II/III are pymoo's, whose factories check nothing).
CHECKED_FACTORIES = [name for name in NAMES if name not in ("nsga2", "nsga3")]


def _factory(name: str):
    module, func = ALGORITHMS[name].split(":")
    return getattr(import_module(module), func)


@pytest.mark.parametrize("name", NAMES)
def test_same_seed_same_result_different_seed_differs(name):
    # DTLZ2, 3 objectives (12 variables), 600 evaluations, seeds 4, 4, 5
    problem = get_problem("dtlz2", n_obj=3)
    runs = [minimize(problem, _factory(name)(n_obj=3), ("n_eval", 600), seed=s).pop for s in (4, 4, 5)]
    np.testing.assert_array_equal(runs[0].get("X"), runs[1].get("X"))
    np.testing.assert_array_equal(runs[0].get("F"), runs[1].get("F"))
    F0, F2 = runs[0].get("F"), runs[2].get("F")
    assert F0.shape == F2.shape and not np.array_equal(F0, F2)


@pytest.mark.parametrize("n_obj, pop_size, n_eval", [(3, 92, 400), (2, 20, 300)])
@pytest.mark.parametrize("name", NAMES)
def test_reused_algorithm_starts_fresh(name, n_obj, pop_size, n_eval):
    # any state (normalisation, archive, nadir record) is reset at setup: a reused object repeats its run
    problem = get_problem("dtlz2", n_obj=n_obj)
    alg = _factory(name)(n_obj=n_obj, pop_size=pop_size)
    a = minimize(problem, alg, ("n_eval", n_eval), seed=0, copy_algorithm=False).pop.get("F")
    b = minimize(problem, alg, ("n_eval", n_eval), seed=0, copy_algorithm=False).pop.get("F")
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", NAMES)
def test_runs_wrapped_with_molsp(name):
    problem = get_problem("dtlz2", n_obj=3)
    res = minimize(problem, molsp(_factory(name)(n_obj=3), ref_point=np.full(3, 2.0)), ("n_eval", 1500), seed=2)
    # MO-LSP never passes the budget itself; the host may overshoot by less than one offspring batch
    assert len(res.pop) == 92 and 1500 <= res.algorithm.evaluator.n_eval < 1500 + 92
    assert res.algorithm.data["molsp_n_eval"] > 0
    again = minimize(problem, molsp(_factory(name)(n_obj=3), ref_point=np.full(3, 2.0)), ("n_eval", 1500), seed=2)
    np.testing.assert_array_equal(res.pop.get("F"), again.pop.get("F"))


@pytest.mark.parametrize("kwargs, word", [
    ({"n_obj": 1}, "n_obj"),
    ({"n_obj": 3, "pop_size": 1}, "pop_size"),
    ({"n_obj": 3, "pop_size": 0}, "pop_size"),
])
@pytest.mark.parametrize("name", CHECKED_FACTORIES)
def test_factory_rejects_bad_n_obj_and_pop_size(name, kwargs, word):
    with pytest.raises(ValueError, match=word):
        _factory(name)(**kwargs)
