"""Variation operators of moo.algorithms.operators against their closed-form distributions."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.problem import Problem
from scipy import stats

from moo.algorithms.operators import (
    PAPER_OPERATORS,
    ClippedSBX,
    OperatorSettings,
    PaperPM,
    paper_crossover,
    variation_operators,
)


class _Box(Problem):
    def __init__(self, n_var=4, xl=0.0, xu=1.0):
        super().__init__(n_var=n_var, n_obj=1, xl=xl, xu=xu)


def _children(p1, p2, n, eta=20.0, seed=0, xl=0.0, xu=1.0):
    X = np.empty((2, n, np.size(p1)))
    X[0], X[1] = p1, p2
    return ClippedSBX(eta=eta)._do(_Box(np.size(p1), xl, xu), X, random_state=np.random.default_rng(seed))


def test_clipped_sbx_spread_follows_the_sbx_distribution():
    # parents 0.4 / 0.6 in a wide box (no clipping): crossed variables have |c1 - c2| = beta |p1 - p2| with
    # P(beta <= b) = b^(eta+1) / 2 for b <= 1 and 1 - b^-(eta+1) / 2 above (Deb & Agrawal 1995); the children
    # keep the parents' mean, and half of the variables are copied unchanged
    eta = 20.0
    Q = _children(np.full(1, 0.4), np.full(1, 0.6), 40000, eta=eta, xl=-10.0, xu=10.0)
    c1, c2 = Q[0, :, 0], Q[1, :, 0]
    np.testing.assert_allclose(c1 + c2, 1.0, atol=1e-14)
    copied = (c1 == 0.4) & (c2 == 0.6)
    assert abs(copied.mean() - 0.5) < 0.01                      # 40000 draws: sd 0.0025
    beta = np.abs(c1 - c2)[~copied] / 0.2

    def cdf(b):
        return np.where(b <= 1, 0.5 * b ** (eta + 1), 1 - 0.5 * b ** -(eta + 1))

    assert stats.kstest(beta, cdf).pvalue > 1e-3
    # the sign is random: c1 lies above the mean as often as below among crossed variables
    assert abs(np.mean(c1[~copied] > 0.5) - 0.5) < 0.02


def test_clipped_sbx_clips_to_the_bounds():
    # parents 0.5 / 0.99: mean 0.745, half-difference 0.245; the upper child passes 1 when
    # beta > 0.255 / 0.245, probability 0.5 (0.255 / 0.245)^-21 per crossed variable, and lands exactly on 1.
    # Over all child values: crossed (1/2) x beyond x one child of two (1/2)
    Q = _children(np.full(3, 0.5), np.full(3, 0.99), 100000)
    assert Q.min() >= 0.0 and Q.max() <= 1.0
    expected = 0.5 * 0.5 * (0.255 / 0.245) ** -21 * 0.5
    assert np.mean(Q == 1.0) == pytest.approx(expected, rel=0.05)     # 600000 values: sd about 0.6 %


def test_paper_crossover_forms_and_errors():
    assert isinstance(paper_crossover(form="clipped"), ClippedSBX)
    assert type(paper_crossover()).__name__ == "SBX"
    with pytest.raises(ValueError, match="form must be"):
        paper_crossover(form="other")


def test_variation_operators_carry_the_settings():
    ops = variation_operators(OperatorSettings(0.9, 15.0, 2.0, 25.0, "test", crossover_form="clipped"))
    assert isinstance(ops["crossover"], ClippedSBX)
    assert ops["crossover"].prob.value == 0.9 and ops["crossover"].eta.value == 15.0
    assert isinstance(ops["mutation"], PaperPM)
    assert ops["mutation"].expected_mutations == 2.0 and ops["mutation"].eta.value == 25.0


def test_paper_operators_mutate_half_a_variable_per_offspring_on_average():
    # the reproduced paper's PlatEMO proM = 0.5: over 10000 offspring of 8 variables, 0.5 mutated per offspring
    ops = variation_operators(PAPER_OPERATORS)
    X = np.full((10000, 8), 0.5)
    Y = ops["mutation"]._do(_Box(8), X.copy(), random_state=np.random.default_rng(0))
    per_offspring = np.mean(np.sum(Y != X, axis=1))
    assert per_offspring == pytest.approx(0.5, abs=0.03)        # sd of the mean about 0.007


def test_paper_pm_mutates_expected_number_of_variables():
    # 0.5 expected mutations over 10 variables: each variable mutates with probability 0.05
    pm = PaperPM(expected_mutations=0.5)
    np.testing.assert_allclose(pm.get_prob_var(_Box(10), size=3), [0.05] * 3)
    np.testing.assert_allclose(PaperPM(expected_mutations=20).get_prob_var(_Box(10), size=1), [1.0])
    with pytest.raises(ValueError, match="expected_mutations"):
        PaperPM(expected_mutations=0)
