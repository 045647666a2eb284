"""A published example: Sayed (2001), the uncertain parameter of F[0, 1].

``F(delta) = [[0.9802, 0.0196 + 0.099 delta], [0, 0.9802]]``, ``|delta| <= 1``,
``Bw = I``, ``C = [1, -1]``, ``W = [[1.9608, 0.0195], [0.0195, 1.9605]]``,
``V = 1`` (A. H. Sayed, "A framework for state-space estimation with
uncertain models", IEEE TAC 46(7), 2001; also Ishihara, Terra & Cerri 2015),
with ``H = [0.0198; 0]``, ``EF = [0, 5]``. The steady error variance
``tr cov(x[k] - x[k|k])`` of each filter on the true plant ``F(delta)``,
by the Lyapunov equation of plant and filter together and by Monte Carlo.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import robustctl as rc

F0 = np.array([[0.9802, 0.0196], [0.0, 0.9802]])
W = np.array([[1.9608, 0.0195], [0.0195, 1.9605]])
V = np.array([[1.0]])
C = np.array([[1.0, -1.0]])
H, EF = np.array([[0.0198], [0.0]]), np.array([[0.0, 5.0]])
DELTAS = np.linspace(-1.0, 1.0, 41)


def true_F(delta: float) -> np.ndarray:
    return F0 + np.array([[0.0, 0.099 * delta], [0.0, 0.0]])


def error_variance(est: rc.Estimator, delta: float) -> float:
    """``tr cov(x - x[k|k])`` in steady state, from the Lyapunov equation of (x, x[k|k-1])."""
    n = 2
    Lf, Lp, Fe = est.L_filter, est.L_predictor, est.F
    A = np.block([[true_F(delta), np.zeros((n, n))], [Lp @ C, Fe - Lp @ C]])
    B = np.block([[np.eye(n), np.zeros((n, 1))], [np.zeros((n, n)), Lp]])
    assert max(abs(np.linalg.eigvals(A))) < 1
    S = scipy.linalg.solve_discrete_lyapunov(A, B @ scipy.linalg.block_diag(W, V) @ B.T)
    M = np.hstack([np.eye(n) - Lf @ C, -(np.eye(n) - Lf @ C)])      # x - x[k|k] = M (x, x[k|k-1]) - Lf v
    return float(np.trace(M @ S @ M.T + Lf @ V @ Lf.T))


@pytest.fixture(scope="module")
def filters():
    plant = rc.Plant(F0, np.zeros((2, 1)), dt=1.0, C=C)
    return rc.kalman(plant, W, V), rc.robust_kalman(plant, W, V, H=H, EF=EF, mu=np.inf)


def test_worst_case_variance_by_the_lyapunov_equation(filters):
    kalman, robust = filters
    vk = np.array([error_variance(kalman, d) for d in DELTAS])
    vr = np.array([error_variance(robust, d) for d in DELTAS])
    assert vr.max() < 0.5 * vk.max()          # about 112 against 433
    assert vk[20] < vr[20]                    # the nominal plant: the Kalman filter is optimal there
    # the Kalman filter's nominal variance is the trace of its filtered covariance
    assert error_variance(kalman, 0.0) == pytest.approx(np.trace(kalman.P_filtered), rel=1e-9)


def monte_carlo(est: rc.Estimator, delta: float, rng, trajectories=400, steps=2000, burn=300) -> float:
    x = rng.multivariate_normal(np.zeros(2), np.eye(2), trajectories)
    xs, ys = np.empty((trajectories, steps, 2)), np.empty((trajectories, steps, 1))
    Fd, Lw = true_F(delta), np.linalg.cholesky(W)
    for k in range(steps):
        xs[:, k] = x
        ys[:, k] = x @ C.T + rng.normal(size=(trajectories, 1))
        x = x @ Fd.T + rng.normal(size=(trajectories, 2)) @ Lw.T
    run = est.run(np.zeros((trajectories, steps, 1)), ys)
    err = xs[:, burn:] - run.x_filtered[:, burn:]
    return float(np.mean(np.sum(err**2, axis=2)))


def test_worst_case_variance_by_monte_carlo(filters):
    kalman, robust = filters
    rng = np.random.default_rng(2001)
    worst_k = DELTAS[np.argmax([error_variance(kalman, d) for d in DELTAS])]
    worst_r = DELTAS[np.argmax([error_variance(robust, d) for d in DELTAS])]
    mc_k = monte_carlo(kalman, worst_k, rng)
    mc_r = monte_carlo(robust, worst_r, rng)
    assert mc_k == pytest.approx(error_variance(kalman, worst_k), rel=0.06)
    assert mc_r == pytest.approx(error_variance(robust, worst_r), rel=0.06)
    assert mc_r < 0.5 * mc_k
