"""The robust filter's public functions: zero uncertainty is the Kalman filter, the mu -> inf limit,
the block (KKT) implementation, batches, the finite horizon, and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robustctl as rc
from robustctl.errors import NotDetectableError
from robustctl.estimation._model import robust_model
from robustctl.estimation._recursion import block_step


def spd(rng, k, scale=1.0):
    A = rng.normal(size=(k, k))
    M = scale * (A @ A.T + 0.1 * k * np.eye(k))
    return 0.5 * (M + M.T)


@pytest.fixture
def setup():
    rng = np.random.default_rng(33)
    n, m, p = 4, 2, 2
    F = rng.normal(size=(n, n))
    F *= 1.05 / max(abs(np.linalg.eigvals(F)))
    plant = rc.Plant(F, rng.normal(size=(n, m)), dt=0.1, C=rng.normal(size=(p, n)), D=rng.normal(size=(p, m)),
                     Bw=rng.normal(size=(n, 3)))
    unc = dict(H=0.3 * rng.normal(size=(n, 1)), EF=rng.normal(size=(1, n)), EG=rng.normal(size=(1, m)),
               EBw=0.1 * rng.normal(size=(1, 3)))
    return plant, spd(rng, 3), spd(rng, p, 0.1), unc, rng


def test_zero_uncertainty_is_the_kalman_filter(setup):
    """H = 0 (EF given) and EF = 0 (H given) at mu = inf: the Kalman filter, steady state and each step."""
    plant, W, V, unc, rng = setup
    kalman = rc.kalman(plant, W, V)
    T = 30
    u, y, x0, P0 = rng.normal(size=(T, 2)), rng.normal(size=(T, 2)), rng.normal(size=4), spd(rng, 4)
    ref = kalman.run(u, y, x0=x0, P0=P0)
    for kw in (dict(unc, H=np.zeros((4, 1))), dict(H=unc["H"], EF=np.zeros((1, 4)))):
        robust = rc.robust_kalman(plant, W, V, **kw, mu=np.inf)
        for name in ("L_filter", "L_predictor", "P", "P_filtered", "F", "G"):
            a, b = getattr(robust, name), getattr(kalman, name)
            assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
        run = robust.run(u, y, x0=x0, P0=P0)
        for name in ("x_prior", "x_filtered", "P_prior", "P_filtered", "L"):
            a, b = getattr(run, name), getattr(ref, name)
            assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name


def test_large_finite_mu_without_uncertainty_is_within_1_over_mu(setup):
    plant, W, V, unc, _ = setup
    kalman = rc.kalman(plant, W, V)
    robust = rc.robust_kalman(plant, W, V, **dict(unc, H=np.zeros((4, 1))), mu=1e12)
    assert np.abs(robust.P - kalman.P).max() < 1e-10 * np.abs(kalman.P).max()


def test_mu_to_inf_is_the_limit(setup):
    plant, W, V, unc, _ = setup
    limit = rc.robust_kalman(plant, W, V, **unc, mu=np.inf)
    gaps = [np.abs(rc.robust_kalman(plant, W, V, **unc, mu=mu).L - limit.L).max() for mu in (1e3, 1e6, 1e9)]
    assert gaps[1] < 1e-2 * gaps[0] and gaps[2] < 1e-2 * gaps[1]
    assert gaps[2] < 1e-7 * np.abs(limit.L).max()
    assert limit.info["mu"] == np.inf and limit.info["lambda"] == np.inf


@pytest.mark.parametrize("mu", [0.5, 50.0, np.inf])
def test_block_implementation_equals_the_closed_form(setup, mu):
    plant, W, V, unc, _ = setup
    HC, EC = np.array([[0.2], [0.1]]), np.array([[0.3, 0.0, -0.2, 0.1]])
    closed = rc.robust_kalman(plant, W, V, **unc, HC=HC, EC=EC, mu=mu)
    block = rc.robust_kalman(plant, W, V, **unc, HC=HC, EC=EC, mu=mu, implementation="block", tol=1e-14)
    for name in ("L_filter", "L_predictor", "P", "P_filtered", "F", "G"):
        a, b = getattr(block, name), getattr(closed, name)
        assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max(), name


def test_finite_horizon_against_the_block_system(setup):
    """run() from (x0, P0): each filtered estimate and covariance is one block (KKT) solve from the last."""
    plant, W, V, unc, rng = setup
    est = rc.robust_kalman(plant, W, V, **unc, mu=7.0)
    T = 8
    u, y, x0, P0 = rng.normal(size=(T, 2)), rng.normal(size=(T, 2)), rng.normal(size=4), spd(rng, 4)
    run = est.run(u, y, x0=x0, P0=P0)
    d = est._model
    x, Pf = run.x_filtered[0], run.P_filtered[0]
    for k in range(1, T):
        x, Pf = block_step(x, Pf, u[k - 1], u[k], y[k], d)
        assert np.allclose(run.x_filtered[k], x, rtol=1e-10, atol=1e-12)
        assert np.allclose(run.P_filtered[k], Pf, rtol=1e-10, atol=1e-14)


def test_batch_equals_single_designs(setup):
    plant, W, V, unc, rng = setup
    B = 6
    EF = rng.normal(size=(B, 1, 4))
    mu = np.array([0.3, 3.0, 1e4, 1e12, 1e22, np.inf])
    for form in ("filter", "predictor"):
        batch = rc.robust_kalman_gains(plant, W, V, H=unc["H"], EF=EF, EG=unc["EG"], mu=mu, form=form)
        assert batch.ok.all(), batch.reason
        for i in range(B):
            one = rc.robust_kalman(plant, W, V, H=unc["H"], EF=EF[i], EG=unc["EG"], mu=mu[i], form=form)
            assert np.allclose(batch.L[i], one.L, rtol=1e-9, atol=1e-12)
            assert np.allclose(batch.P[i], one.P, rtol=1e-9, atol=0)
            assert np.allclose(batch.F[i], one.F, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("mu", [5.0, np.inf])
def test_dependent_rows_are_one_row(setup, mu):
    """H Delta [EF; EF], ||Delta|| <= 1, is H delta (sqrt 2 EF): the same filter (no rank condition at mu = inf)."""
    plant, W, V, unc, _ = setup
    two = rc.robust_kalman(plant, W, V, H=unc["H"], EF=np.vstack([unc["EF"], unc["EF"]]),
                           EG=np.vstack([unc["EG"], unc["EG"]]), mu=mu)
    one = rc.robust_kalman(plant, W, V, H=unc["H"], EF=np.sqrt(2) * unc["EF"], EG=np.sqrt(2) * unc["EG"], mu=mu)
    for name in ("L", "P", "F", "G"):
        assert np.allclose(getattr(two, name), getattr(one, name), rtol=1e-9, atol=1e-12), name


def test_bad_input_is_named(setup):
    plant, W, V, unc, _ = setup
    with pytest.raises(TypeError, match="mu is required"):
        rc.robust_kalman(plant, W, V, **unc, mu=None)
    with pytest.raises(ValueError, match="EF must have 4 columns"):
        rc.robust_kalman(plant, W, V, H=unc["H"], EF=np.ones((1, 3)), mu=1.0)
    with pytest.raises(ValueError, match="EG must have 1 rows"):
        rc.robust_kalman(plant, W, V, H=unc["H"], EF=unc["EF"], EG=np.ones((2, 2)), mu=1.0)
    with pytest.raises(TypeError, match="HC and EC together"):
        rc.robust_kalman(plant, W, V, **unc, HC=np.ones((2, 1)), mu=1.0)
    with pytest.raises(ValueError, match="no output matrix C"):
        rc.robust_kalman(rc.Plant(plant.F, plant.G, 0.1), W, V, **unc, mu=1.0)
    with pytest.raises(ValueError, match="discrete-time"):
        rc.robust_kalman(rc.Plant(plant.F, plant.G, None, C=plant.C), W, V, **unc, mu=1.0)
    with pytest.raises(ValueError, match="mu must be > 0"):
        rc.robust_kalman(plant, W, V, **unc, mu=-1.0)
    with pytest.raises(TypeError, match="mu must be a scalar"):
        rc.robust_kalman(plant, W, V, **unc, mu=[1.0, 2.0])
    with pytest.raises(ValueError, match="implementation must be one of"):
        rc.robust_kalman(plant, W, V, **unc, mu=1.0, implementation="fast")
    with pytest.raises(ValueError, match="batch sizes differ"):
        rc.robust_kalman_gains(plant, W, V, H=unc["H"], EF=np.ones((3, 1, 4)), mu=[1.0, 2.0])
    undetectable = rc.Plant(np.diag([1.2, 0.5]), [[1.0], [1.0]], dt=0.1, C=[[0.0, 1.0]])
    with pytest.raises(NotDetectableError):
        rc.robust_kalman(undetectable, np.eye(2), [[1.0]], H=[[1.0], [0.0]], EF=[[1.0, 0.0]], mu=1.0)
    flagged = rc.robust_kalman_gains(undetectable, np.eye(2), [[1.0]], H=[[1.0], [0.0]], EF=[[1.0, 0.0]], mu=[1.0])
    assert flagged.reason.tolist() == ["undetectable"]


def test_model_keeps_lambda_free_without_uncertainty():
    """H = 0 and HC = 0: no pseudo-measurement rows, Phi = I/mu (the lambda -> 0 limit)."""
    d = robust_model(np.eye(2), np.ones((2, 1)), np.ones((1, 2)), np.zeros((1, 1)), np.eye(2), np.eye(2),
                     np.eye(1), H=np.zeros((2, 1)), EF=np.ones((1, 1, 2)), EG=np.ones((1, 1, 1)),
                     EBw=np.zeros((1, 1, 2)), HC=np.zeros((1, 0)), EC=np.zeros((0, 2)), mu=np.array([4.0]), alpha=0.1)
    assert d.EF.shape[1] == 0 and not d.uncertain
    assert np.allclose(d.Q[0], np.eye(2) + np.eye(2) / 4.0) and np.allclose(d.R[0], 1.25)
