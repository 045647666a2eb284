"""The Kalman filter against python-control (dlqe, lqe, dare), a hand-written recursion and filterpy."""

from __future__ import annotations

import control
import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

import robustctl as rc
from robustctl.errors import ConvergenceError, NotDetectableError


def spd(rng, k, scale=1.0):
    A = rng.normal(size=(k, k))
    M = scale * (A @ A.T + 0.1 * k * np.eye(k))
    return 0.5 * (M + M.T)


def process_noise(plant, W):
    """``Bw W Bw'`` symmetrised: python-control's dare refuses a Q off symmetry by more than eps (absolute)."""
    Q = plant.Bw @ W @ plant.Bw.T
    return 0.5 * (Q + Q.T)


def random_plant(seed: int, n=4, m=2, p=2, nw=3, unstable=False, D=False):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n))
    F *= (1.15 if unstable else 0.9) / max(abs(np.linalg.eigvals(F)))
    plant = rc.Plant(F, rng.normal(size=(n, m)), dt=0.1, C=rng.normal(size=(p, n)),
                     D=rng.normal(size=(p, m)) if D else None, Bw=rng.normal(size=(n, nw)))
    return plant, spd(rng, nw), spd(rng, p, 0.1), rng


@pytest.mark.parametrize("seed,unstable", [(0, False), (1, True), (2, False), (3, True)])
def test_discrete_gains_against_dlqe(seed, unstable):
    plant, W, V, _ = random_plant(seed, unstable=unstable)
    Lp, P, E = control.dlqe(plant.F, np.eye(4), plant.C, process_noise(plant, W), V)
    est = rc.kalman(plant, W, V)
    assert est.form == "filter"
    assert np.allclose(est.P, P, rtol=1e-9, atol=0)
    assert np.allclose(est.L_predictor, Lp, rtol=1e-9, atol=1e-14)
    Lf = P @ plant.C.T @ np.linalg.inv(plant.C @ P @ plant.C.T + V)
    assert np.allclose(est.L, Lf, rtol=1e-9, atol=1e-14)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(est.closed_loop)), np.sort_complex(E), rtol=1e-9, atol=1e-12)
    predictor = rc.kalman(plant, W, V, form="predictor")
    assert predictor.form == "predictor" and np.allclose(predictor.L, Lp, rtol=1e-9, atol=1e-14)
    assert np.array_equal(predictor.P, est.P)


def test_against_a_hand_written_recursion():
    plant, W, V, _ = random_plant(4)
    F, C, Q = plant.F, plant.C, plant.Bw @ W @ plant.Bw.T
    P = np.eye(4)
    for _ in range(3000):
        P = F @ P @ F.T + Q - F @ P @ C.T @ np.linalg.solve(C @ P @ C.T + V, C @ P @ F.T)
    est = rc.kalman(plant, W, V)
    assert np.allclose(est.P, P, rtol=1e-10, atol=0)
    Pf = P - P @ C.T @ np.linalg.solve(C @ P @ C.T + V, C @ P)
    assert np.allclose(est.P_filtered, Pf, rtol=1e-10, atol=0)


def test_cross_covariance_against_control_dare():
    plant, W, V, rng = random_plant(5)
    N = 0.2 * rng.normal(size=(3, 2))
    V = V + N.T @ np.linalg.solve(W, N)
    S = plant.Bw @ N
    P, _, _ = control.dare(plant.F.T, plant.C.T, process_noise(plant, W), V, S)
    est = rc.kalman(plant, W, V, N=N)
    Re = plant.C @ P @ plant.C.T + V
    assert np.allclose(est.P, P, rtol=1e-9, atol=0)
    assert np.allclose(est.L_predictor, (plant.F @ P @ plant.C.T + S) @ np.linalg.inv(Re), rtol=1e-9)
    assert np.allclose(est.L_filter, P @ plant.C.T @ np.linalg.inv(Re), rtol=1e-9)
    assert np.allclose(est.J, S @ np.linalg.inv(Re), rtol=1e-9)


def test_continuous_against_lqe():
    plant, W, V, _ = random_plant(6)
    cplant = rc.Plant(plant.F - np.eye(4), plant.G, None, C=plant.C, Bw=plant.Bw)
    L, P, E = control.lqe(cplant.F, np.eye(4), cplant.C, process_noise(cplant, W), V)
    est = rc.kalman(cplant, W, V)
    assert np.allclose(est.P, P, rtol=1e-9) and np.allclose(est.L, L, rtol=1e-9)
    E_ours = np.sort_complex(np.linalg.eigvals(est.closed_loop))
    assert np.allclose(E_ours, np.sort_complex(E), rtol=1e-6)  # python-control's E is complex64
    with pytest.raises(ValueError, match="discrete-time"):
        est.run(np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="one form"):
        rc.kalman(cplant, W, V, form="predictor")


def test_default_noise_input_is_the_plant_s_then_the_identity():
    plant, W, V, _ = random_plant(7)
    assert np.allclose(rc.kalman(plant, W, V).P, rc.kalman(plant, W, V, Bw=plant.Bw).P)
    bare = rc.Plant(plant.F, plant.G, 0.1, C=plant.C)
    est = rc.kalman(bare, 0.1 * np.eye(4), V)
    assert np.allclose(est.P, control.dlqe(plant.F, np.eye(4), plant.C, 0.1 * np.eye(4), V)[1], rtol=1e-9)
    assert np.array_equal(est.info["Bw"], np.eye(4))


def filterpy_run(plant, W, V, u, y, x0, P0):
    kf = KalmanFilter(dim_x=plant.n, dim_z=plant.p, dim_u=plant.m)
    kf.F, kf.B, kf.H = plant.F, plant.G, plant.C
    kf.Q, kf.R = plant.Bw @ W @ plant.Bw.T, V
    kf.x, kf.P = x0.copy(), P0.copy()
    prior, post, P_prior, P_post = [], [], [], []
    for k in range(len(u)):
        prior.append(kf.x.copy())
        P_prior.append(kf.P.copy())
        kf.update(y[k] - plant.D @ u[k])
        post.append(kf.x.copy())
        P_post.append(kf.P.copy())
        kf.predict(u=u[k])
    return np.array(prior), np.array(post), np.array(P_prior), np.array(P_post), kf.x


def test_time_varying_filter_against_filterpy():
    plant, W, V, rng = random_plant(8, unstable=True, D=True)
    T = 60
    u, y = rng.normal(size=(T, 2)), rng.normal(size=(T, 2))
    x0, P0 = rng.normal(size=4), spd(rng, 4, 5.0)
    est = rc.kalman(plant, W, V)
    run = est.run(u, y, x0=x0, P0=P0)
    prior, post, P_prior, P_post, x_next = filterpy_run(plant, W, V, u, y, x0, P0)
    assert np.allclose(run.x_prior, prior, rtol=1e-10, atol=1e-10)
    assert np.allclose(run.x_filtered, post, rtol=1e-10, atol=1e-10)
    assert np.allclose(run.x, post, rtol=1e-10, atol=1e-10)
    assert np.allclose(run.P_prior, P_prior, rtol=1e-10, atol=1e-12)
    assert np.allclose(run.P_filtered, P_post, rtol=1e-10, atol=1e-12)
    assert np.allclose(run.x_next, x_next, rtol=1e-10, atol=1e-10)
    # the gains converge to the steady state's
    assert np.allclose(run.L[-1], est.L, rtol=1e-6)


def test_run_from_the_steady_state_is_step_and_batches_trajectories():
    plant, W, V, rng = random_plant(9, D=True)
    for form in ("filter", "predictor"):
        est = rc.kalman(plant, W, V, form=form)
        u, y = rng.normal(size=(3, 20, 2)), rng.normal(size=(3, 20, 2))
        x0 = rng.normal(size=(3, 4))
        run = est.run(u, y, x0=x0)
        x = x0
        for k in range(20):
            x_next, x_est = est.step(x, u[:, k], y[:, k])
            assert np.allclose(run.x[:, k], x_est, rtol=1e-10, atol=1e-12)
            x = x_next
        assert np.allclose(run.x_next, x, rtol=1e-10, atol=1e-12)
        one = est.run(u[1], y[1], x0=x0[1])
        assert np.allclose(one.x_filtered, run.x_filtered[1]) and one.x_filtered.shape == (20, 4)


def test_batch_equals_single_designs():
    plant, W, V, _ = random_plant(10)
    Ws = np.stack([W * s for s in (0.1, 1.0, 10.0)])
    Vs = np.stack([V * s for s in (1.0, 0.5, 2.0)])
    for form in ("filter", "predictor"):
        batch = rc.kalman_gains(plant, Ws, Vs, form=form)
        assert batch.ok.all() and batch.stable.all() and len(batch) == 3
        for i in range(3):
            one = rc.kalman(plant, Ws[i], Vs[i], form=form)
            assert np.allclose(batch.L[i], one.L, rtol=1e-10) and np.allclose(batch.P[i], one.P, rtol=1e-10)
    shared = rc.kalman_gains(plant, W, Vs)
    assert np.allclose(shared.L[2], rc.kalman(plant, W, Vs[2]).L, rtol=1e-10)


def test_bad_input_is_named():
    plant, W, V, _ = random_plant(11)
    with pytest.raises(ValueError, match="no output matrix C"):
        rc.kalman(rc.Plant(plant.F, plant.G, 0.1), W, V)
    with pytest.raises(ValueError, match=r"C must have 4 columns"):
        rc.Plant(plant.F, plant.G, 0.1, C=np.ones((2, 3)))
    with pytest.raises(ValueError, match="W must have 3 rows"):
        rc.kalman(plant, np.eye(2), V)
    with pytest.raises(ValueError, match="W must be symmetric"):
        rc.kalman(plant, W + np.triu(np.ones((3, 3)), 1), V)
    with pytest.raises(ValueError, match="W must be positive semidefinite"):
        rc.kalman(plant, -W, V)
    with pytest.raises(ValueError, match="V must be positive definite"):
        rc.kalman(plant, W, np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"N .* too large"):
        rc.kalman(plant, W, V, N=100 * np.ones((3, 2)))
    with pytest.raises(ValueError, match="form must be one of"):
        rc.kalman(plant, W, V, form="smoother")
    with pytest.raises(ValueError, match=r"W\[1\] must be symmetric"):
        rc.kalman_gains(plant, np.stack([W, W + np.triu(np.ones((3, 3)), 1)]), V)
    with pytest.raises(ValueError, match="batch sizes differ"):
        rc.kalman_gains(plant, np.stack([W, W]), np.stack([V, V, V]))
    est = rc.kalman(plant, W, V)
    with pytest.raises(ValueError, match="y must have shape"):
        est.run(np.zeros((5, 2)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="xhat must have shape"):
        est.step(np.zeros(3), np.zeros(2), np.zeros(2))


def test_undetectable_plant():
    F = np.diag([1.2, 0.5])
    plant = rc.Plant(F, [[1.0], [1.0]], dt=0.1, C=[[0.0, 1.0]])
    with pytest.raises(NotDetectableError, match="not detectable"):
        rc.kalman(plant, np.eye(2), [[1.0]])
    batch = rc.kalman_gains(plant, np.eye(2), [[1.0]])
    assert not batch.ok.any() and set(batch.reason) == {"undetectable"} and np.isnan(batch.L).all()


def test_a_filter_that_does_not_converge_says_so():
    """An integrator the process noise does not reach has no stabilising steady state."""
    plant = rc.Plant(np.diag([1.0, 0.5]), [[1.0], [0.0]], dt=0.1, C=[[1.0, 1.0]], Bw=[[0.0], [1.0]])
    with pytest.raises(ConvergenceError, match="unit circle"):
        rc.kalman(plant, [[1.0]], [[1.0]])
    batch = rc.kalman_gains(plant, [[1.0]], [[1.0]])
    assert not batch.ok[0] and batch.reason[0] in ("not converged", "diverged")
