"""The WFG1-9 entries of the problems registry (moo.problems): sizes, closed-form front bounds, reference points."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.util.ref_dirs import get_reference_directions

from moo.problems import PROBLEMS, make_problem, true_front_bounds

WFG = [f"wfg{i}" for i in range(1, 10)]


@pytest.mark.parametrize("name", WFG)
def test_wfg_registered_with_the_toolkit_sizes(name):
    assert name in PROBLEMS
    for M in (2, 3, 5):
        p = make_problem(name, n_obj=M)
        k = 4 if M == 2 else 2 * (M - 1)
        assert (p.n_obj, p.n_var, p.k, p.l) == (M, k + 20, k, 20)
        np.testing.assert_array_equal(p.xu, 2.0 * np.arange(1, k + 21))      # z_i in [0, 2i]
    assert make_problem(name).n_obj == 3


@pytest.mark.parametrize("M", [2, 3, 4, 5])
@pytest.mark.parametrize("name", [n for n in WFG if n not in ("wfg1", "wfg4", "wfg5")])
def test_wfg_front_bounds_match_pymoos_front(name, M):
    # pymoo's front sample reaches the closed-form corners exactly for these problems (WFG1 is lifted by pymoo's
    # rounding, see moo.problems; WFG4/5's samples of the concave front stop short of the corners)
    W = get_reference_directions("das-dennis", M, n_partitions={2: 99, 3: 12, 4: 6, 5: 4}[M])
    pf = make_problem(name, n_obj=M).pareto_front(W)
    ideal, nadir = true_front_bounds(name, M)
    np.testing.assert_allclose(pf.min(axis=0), ideal, atol=1e-9)
    np.testing.assert_allclose(pf.max(axis=0), nadir, rtol=1e-9)


def test_wfg3_degenerate_front_bounds_by_hand():
    # M = 4: f_1 <= 2 (1/2)^2, f_2 <= 4 (1/2)^2, f_3 <= 6 (1/2), f_4 <= 8
    ideal, nadir = true_front_bounds("wfg3", 4)
    np.testing.assert_array_equal(ideal, np.zeros(4))
    np.testing.assert_allclose(nadir, [0.5, 1.0, 3.0, 8.0])
    np.testing.assert_allclose(true_front_bounds("wfg3", 2)[1], [2.0, 4.0])


@pytest.mark.parametrize("name", WFG)
def test_wfg_reference_points_lie_beyond_the_nadir(name):
    p = make_problem(name, n_obj=3)
    _, nadir = true_front_bounds(name, 3)
    np.testing.assert_allclose(p.hv_ref_point, 1.1 * nadir)
    np.testing.assert_allclose(p.molsp_ref_point, p.hv_ref_point)


def test_wfg_bad_numbers_of_objectives():
    with pytest.raises(ValueError, match="n_obj must be between 2 and 15"):
        make_problem("wfg2", n_obj=1)
    with pytest.raises(TypeError, match="n_obj must be an integer"):
        make_problem("wfg2", n_obj=3.0)
