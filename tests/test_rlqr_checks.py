"""rlqr refuses a gain that does not stabilise the nominal plant (issue 23 item 9), the mu = inf rank message
gives the numbers of its test (item 11), and rlqr / rlqr_gains agree with and without H (item 12)."""

import numpy as np
import pytest

import robustctl as rc
from robustctl import NotStabilizingError


def _cart_pole(dt=0.02):
    """Cart-pole linearised about the upright pendulum (cart 1 kg, pole 0.1 kg, 0.5 m), x = [p, pdot, th, thdot]."""
    M, m, l, g = 1.0, 0.1, 0.5, 9.81
    A = np.array([[0, 1, 0, 0], [0, 0, -m * g / M, 0], [0, 0, 0, 1], [0, 0, (M + m) * g / (M * l), 0]])
    B = np.array([[0.0], [1 / M], [0.0], [-1 / (M * l)]])
    return rc.Plant.from_continuous(A, B, dt=dt)


CASES = {
    "cart-pole": (_cart_pole(), 0.1 * np.ones((1, 4)), np.array([[0.1]]), 1e8),
    "nearly uncontrollable": (rc.Plant(np.diag([1.2, 0.5]), np.array([[1e-4], [1.0]]), 0.1),
                              np.array([[0.1, 0.1]]), np.array([[0.1]]), 1e4),
}


@pytest.mark.parametrize("case", CASES)
def test_rlqr_refuses_a_gain_that_leaves_the_plant_unstable(case):
    plant, EF, EG, mu = CASES[case]
    assert plant.is_stabilizable
    with pytest.raises(NotStabilizingError, match=r"does not stabilise the nominal plant: rho\(F \+ G K\) = ") as e:
        rc.rlqr(plant, EF, EG, mu)
    assert isinstance(e.value, rc.ConvergenceError)
    c = rc.design("rlqr", plant, EF, EG, mu, check_stability=False)
    rho = max(abs(np.linalg.eigvals(plant.F + plant.G @ c.K)))     # independent of robustctl.systems.stability
    assert rho > 1.0 and c.info["stabilizing"] is False
    b = rc.rlqr_gains(plant, EF, EG, [mu])                         # batched: flagged, no raise
    assert b.ok[0] and not b.stabilizing[0]
    np.testing.assert_allclose(b.K[0], c.K, rtol=1e-9, atol=1e-12)


def test_rlqr_stabilising_design_reports_it():
    plant = _cart_pole()
    c = rc.rlqr(plant, 1e-3 * np.ones((1, 4)), [[1e-3]], 1e8)      # small uncertainty: close to the LQR
    assert c.info["stabilizing"] is True and max(abs(np.linalg.eigvals(c.closed_loop()))) < 1.0
    with pytest.raises(TypeError, match="check_stability"):
        rc.rlqr(plant, 1e-3 * np.ones((1, 4)), [[1e-3]], 1e8, check_stability="no")


def test_mu_inf_rank_message_states_condition_number_and_tolerance():
    plant = rc.Plant(np.diag([0.5, 0.6, 0.7]), np.eye(3)[:, :2], 0.1)
    EG = np.array([[1.0, 0.0], [1.0, 1e-14]])                     # cond(EG) = 2e14 by its SVD
    cond = np.linalg.cond(EG)
    with pytest.raises(rc.RankConditionError) as e:
        rc.rlqr(plant, np.ones((2, 3)), EG, np.inf)
    msg = str(e.value)
    assert "got numerical rank 1" in msg and f"condition number {cond:.3g}" in msg
    assert "1e-12 times the largest" in msg and "got rank 2" not in msg


@pytest.mark.parametrize("with_h", [True, False])
def test_rlqr_and_rlqr_gains_agree_with_and_without_H(generic_plant, with_h):
    """The README's two lines give the same design when given the same arguments; omitted, H is ones((n, l))
    in both (documented), and equals passing that explicitly."""
    EF, EG, mu = np.array([[0.5, 0.2, 0.1]]), np.array([[0.3]]), 1e4
    H = np.array([[0.2], [0.1], [0.0]]) if with_h else None
    single = rc.rlqr(generic_plant, EF, EG, mu, H=H, check_stability=False)
    batch = rc.rlqr_gains(generic_plant, EF[None], EG[None], np.array([mu]), H=H)
    np.testing.assert_allclose(batch.K[0], single.K, rtol=1e-10, atol=1e-13)
    if not with_h:
        ones = rc.rlqr(generic_plant, EF, EG, mu, H=np.ones((3, 1)), check_stability=False)
        np.testing.assert_array_equal(single.K, ones.K)
