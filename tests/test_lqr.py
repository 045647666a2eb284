"""LQR against python-control (slycot) and the Riccati residual."""

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.lqr import dare
from conftest import random_plant


@pytest.mark.parametrize("seed", range(5))
def test_lqr_equals_minus_dlqr(seed):
    rng = np.random.default_rng(seed)
    n, m = rng.integers(1, 6), rng.integers(1, 4)
    plant = random_plant(rng, n, m, scale=1.5)
    X = rng.standard_normal((n, n))
    Q = X @ X.T + 0.1 * np.eye(n)
    R = np.diag(rng.uniform(0.5, 2.0, m))
    c = rc.design("lqr", plant, Q=Q, R=R)
    K_pc, S_pc, _ = control.dlqr(plant.F, plant.G, Q, R)
    np.testing.assert_allclose(c.K, -K_pc, atol=1e-8, rtol=0)
    np.testing.assert_allclose(c.info["P"], S_pc, rtol=1e-8)
    assert c.info["residual"] < 1e-10
    assert c.is_stabilizing()


def test_dare_scipy_fallback_matches(monkeypatch):
    rng = np.random.default_rng(3)
    plant = random_plant(rng, 4, 2, scale=1.5)
    P_sly, backend = dare(plant.F, plant.G, np.eye(4), np.eye(2))
    assert backend == "slycot"

    def broken(*a, **k):
        raise RuntimeError("slycot unavailable")

    monkeypatch.setattr(control, "dare", broken)
    P_sci, backend = dare(plant.F, plant.G, np.eye(4), np.eye(2))
    assert backend == "scipy"
    np.testing.assert_allclose(P_sci, P_sly, rtol=1e-9)


def test_unstabilisable_plant_raises():
    plant = rc.Plant(np.diag([2.0, 0.5]), np.array([[0.0], [1.0]]), 0.1)  # unstable mode not controllable
    with pytest.raises(rc.ConvergenceError, match="stabilisable"):
        rc.design("lqr", plant)


@pytest.mark.parametrize(
    "kw,err,match",
    [
        ({"Q": np.array([[1.0, 2.0], [0.0, 1.0]])}, ValueError, "Q must be symmetric"),
        ({"Q": -np.eye(2)}, ValueError, "Q must be positive semidefinite"),
        ({"R": np.zeros((1, 1))}, ValueError, "R must be positive definite"),
        ({"R": np.eye(2)}, ValueError, r"R must have 1 rows"),
        ({"Q": np.full((2, 2), np.inf)}, ValueError, "Q must have finite entries"),
    ],
)
def test_lqr_bad_weights(kw, err, match):
    plant = rc.Plant(np.eye(2) * 0.9, np.ones((2, 1)), 0.1)
    with pytest.raises(err, match=match):
        rc.design("lqr", plant, **kw)


def test_lqr_rejects_continuous_plant():
    with pytest.raises(ValueError, match="discrete-time"):
        rc.lqr(rc.Plant(np.eye(2), np.ones((2, 1)), None))
