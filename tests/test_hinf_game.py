"""Game-Riccati H-infinity (robustctl.synthesis.hinf_game) against independent references.

References: the stationary game Riccati equation of robustctl.synthesis.hinf_riccati
(scipy's DARE with an indefinite weight, its own checks), scipy's DARE for the
LQR limit gamma -> inf, and the saddle point of the stacked finite-horizon
quadratic game (one linear solve, no recursion).
"""

import numpy as np
import pytest
import scipy.linalg

from robustctl import InfeasibleError, NormBounded, Plant, lq_output
from robustctl.errors import ConvergenceError
from robustctl.models import morais2022, truck
from robustctl.synthesis.hinf_game import hinf_game
from robustctl.synthesis.hinf_riccati import hinf_riccati, riccati_level
from robustctl.systems.input_memory import with_input_memory


def _random_case(seed, n=4, m=2, q=2):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n))
    F *= 1.1 / np.max(np.abs(np.linalg.eigvals(F)))          # mildly unstable
    G, Bw = rng.normal(size=(n, m)), rng.normal(size=(n, q))
    C = rng.normal(size=(n, n))
    Q = C.T @ C / n + 0.1 * np.eye(n)
    D = rng.normal(size=(m, m))
    R = D.T @ D + 0.5 * np.eye(m)
    return Plant(F, G, 0.1), Bw, Q, R


def _performance(Q, R):
    return lq_output(Q, R)


@pytest.mark.parametrize("seed", range(4))
def test_stationary_solution_equals_the_game_riccati_equation(seed):
    plant, Bw, Q, R = _random_case(seed)
    Cz, Dzu = _performance(Q, R)
    opt = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-6).gamma
    gamma = 1.5 * opt
    K_ref, P_ref = riccati_level(plant, gamma, Bw=Bw, Cz=Cz, Dzu=Dzu)
    g = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=gamma)
    np.testing.assert_allclose(g.P, P_ref, rtol=1e-8, atol=1e-8 * np.abs(P_ref).max())
    np.testing.assert_allclose(g.K, K_ref, rtol=1e-7, atol=1e-8 * np.abs(K_ref).max())
    assert g.state_feedback and g.horizon is None and g.iterations > 1
    # the full-information gains from the same P
    Ruu = R + plant.G.T @ g.P @ plant.G
    np.testing.assert_allclose(g.K_x, -np.linalg.solve(Ruu, plant.G.T @ g.P @ plant.F), rtol=1e-10)
    np.testing.assert_allclose(g.K_w, -np.linalg.solve(Ruu, plant.G.T @ g.P @ Bw), rtol=1e-10)


def test_truck_at_the_codes_level_equals_the_game_riccati_equation():
    """The authors' gamma = 14350 with their Q, R and H = 1 on our truck (scaled reference, same gain)."""
    plant = truck.truck_plant(0.0)
    Q, R = morais2022.authors_weights()
    H = np.ones((4, 1))
    g = hinf_game(plant, Bw=H, Q=Q, R=R, gamma=14350.0, P_final=np.eye(4))
    s = 1.0 / np.sqrt(R[0, 0])                    # z scaled by hand (no longer needed: test_hinf_scaling)
    Cz, Dzu = _performance(Q, R)
    K_ref, P_ref = riccati_level(plant, 14350.0 * s, Bw=H, Cz=s * Cz, Dzu=s * Dzu)
    np.testing.assert_allclose(g.P, P_ref / s**2, rtol=1e-9)
    np.testing.assert_allclose(g.K, K_ref, rtol=1e-8)
    assert np.max(np.abs(np.linalg.eigvals(plant.F + plant.G @ g.K))) < 1


def test_large_gamma_gives_the_lqr():
    plant, Bw, Q, R = _random_case(7)
    P_lqr = scipy.linalg.solve_discrete_are(plant.F, plant.G, Q, R)
    K_lqr = -np.linalg.solve(R + plant.G.T @ P_lqr @ plant.G, plant.G.T @ P_lqr @ plant.F)
    g = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=1e7)
    np.testing.assert_allclose(g.P, P_lqr, rtol=1e-8)
    np.testing.assert_allclose(g.K, K_lqr, rtol=1e-7)
    np.testing.assert_allclose(g.K_x, K_lqr, rtol=1e-7)


def _stacked_value(plant, Bw, Q, R, gamma, N, P_N, x0):
    """Saddle value of J(u, w) = x_N'P_N x_N + sum x'Qx + u'Ru - gamma^2 w'w over stacked sequences."""
    F, G = plant.F, plant.G
    n, m, q = plant.n, plant.m, Bw.shape[1]
    Phi = np.stack([np.linalg.matrix_power(F, k) for k in range(N + 1)])       # x_k = Phi_k x0 + ...
    Gu = np.zeros((N + 1, n, N * m))
    Gw = np.zeros((N + 1, n, N * q))
    for k in range(1, N + 1):
        for j in range(k):
            Gu[k, :, j * m:(j + 1) * m] = Phi[k - 1 - j] @ G
            Gw[k, :, j * q:(j + 1) * q] = Phi[k - 1 - j] @ Bw
    M = np.concatenate([Gu, Gw], axis=2)                                          # x_k = Phi_k x0 + M_k z
    W = [Q] * N + [P_N]
    H = sum(M[k].T @ W[k] @ M[k] for k in range(N + 1))
    c = sum(M[k].T @ W[k] @ Phi[k] @ x0 for k in range(N + 1))
    H[:N * m, :N * m] += np.kron(np.eye(N), R)
    H[N * m:, N * m:] -= gamma**2 * np.eye(N * q)
    const = sum(x0 @ Phi[k].T @ W[k] @ Phi[k] @ x0 for k in range(N + 1))
    z = -np.linalg.solve(H, c)
    return const + c @ z, H, N * m


@pytest.mark.parametrize("seed", range(3))
def test_finite_horizon_value_equals_the_stacked_saddle_point(seed):
    plant, Bw, Q, R = _random_case(seed, n=3, m=1, q=2)
    Cz, Dzu = _performance(Q, R)
    gamma = 2.0 * hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-6).gamma
    N, P_N = 7, np.eye(3)
    g = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=gamma, horizon=N, P_final=P_N)
    assert g.P.shape == (N + 1, 3, 3) and g.K.shape == (N, 1, 3) and g.K_u.shape == (N, 1, 1)
    np.testing.assert_array_equal(g.P[-1], P_N)
    x0 = np.random.default_rng(seed).normal(size=3)
    value, H, nu = _stacked_value(plant, Bw, Q, R, gamma, N, P_N, x0)
    # a saddle point: convex in u, concave in w after u's reply
    assert np.linalg.eigvalsh(H[:nu, :nu]).min() > 0
    S = H[nu:, nu:] - H[nu:, :nu] @ np.linalg.solve(H[:nu, :nu], H[:nu, nu:])
    assert np.linalg.eigvalsh(S).max() < 0
    assert x0 @ g.P[0] @ x0 == pytest.approx(value, rel=1e-9)


def test_long_horizon_from_the_stationary_solution_keeps_it():
    plant, Bw, Q, R = _random_case(2)
    st = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=50.0)
    fh = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=50.0, horizon=20, P_final=st.P)
    np.testing.assert_allclose(fh.P, np.broadcast_to(st.P, fh.P.shape), rtol=1e-9)
    np.testing.assert_allclose(fh.K_e, np.broadcast_to(st.K_e, fh.K_e.shape), rtol=1e-9)


def test_delayed_law_applies_the_full_information_input_one_step_late():
    """u_k = K_e x_k + K_u u_{k-1} equals the full-information input of step k - 1 along any trajectory."""
    plant, Bw, Q, R = _random_case(4)
    g = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=50.0)
    rng = np.random.default_rng(0)
    x = rng.normal(size=4)
    for _ in range(10):
        w = rng.normal(size=2)
        u_fi = g.K_x @ x + g.K_w @ w
        u = rng.normal(size=2)                          # any input: the identity holds for every trajectory
        x_next = plant.F @ x + plant.G @ u + Bw @ w
        np.testing.assert_allclose(g.K_e @ x_next + g.K_u @ u, u_fi, rtol=1e-10, atol=1e-12)
        x = x_next


def test_with_input_memory_closed_loop_equals_the_recursion():
    plant, Bw, Q, R = _random_case(5, m=1)
    g = hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=50.0)
    aug = with_input_memory(plant)
    A = aug.F + aug.G @ np.hstack([g.K_e, g.K_u])
    x, u = np.arange(1.0, 5.0), np.zeros(1)
    z = np.concatenate([x, u])
    for _ in range(6):
        u = g.K_e @ x + g.K_u @ u
        x = plant.F @ x + plant.G @ u
        z = A @ z
    np.testing.assert_allclose(z, np.concatenate([x, u]), rtol=1e-10)
    unc = NormBounded(np.ones((4, 1)), [[0.1, 0.0, 0.2, 0.0]], [[0.05]])
    aug2, unc2 = with_input_memory(plant, unc)
    np.testing.assert_array_equal(aug2.F, aug.F)
    assert unc2.H.shape == (5, 1) and unc2.EF.shape == (1, 5)
    np.testing.assert_array_equal(unc2.EF[:, :4], unc.EF)
    np.testing.assert_array_equal(unc2.EG, unc.EG)


def test_gamma_below_the_level_is_infeasible():
    plant, Bw, Q, R = _random_case(1)
    Cz, Dzu = _performance(Q, R)
    opt = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, rtol=1e-6).gamma
    with pytest.raises(InfeasibleError, match="below the achievable level"):
        hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=0.3 * opt)
    with pytest.raises(ConvergenceError, match="did not settle"):
        hinf_game(plant, Bw=Bw, Q=Q, R=R, gamma=2 * opt, max_iter=3)


@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(Bw=np.ones((3, 1))), ValueError, "Bw must have 4 rows"),
    (dict(Q=-np.eye(4)), ValueError, "Q must be positive semidefinite"),
    (dict(R=np.zeros((2, 2))), ValueError, "R must be positive definite"),
    (dict(R=np.eye(3)), ValueError, "R must have 2 rows"),
    (dict(gamma=0.0), ValueError, "gamma must be > 0"),
    (dict(gamma="5"), TypeError, "gamma must be"),
    (dict(horizon=0), ValueError, "horizon must be a positive integer"),
    (dict(horizon=2.0), TypeError, "horizon must be"),
    (dict(P_final=-np.eye(4)), ValueError, "P_final must be positive semidefinite"),
])
def test_bad_arguments(kwargs, exc, words):
    plant, Bw, Q, R = _random_case(0)
    args = dict(Bw=Bw, Q=Q, R=R, gamma=100.0) | kwargs
    with pytest.raises(exc, match=words):
        hinf_game(plant, **args)


def test_bad_plant():
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        hinf_game(np.eye(2), Bw=np.ones(2), Q=np.eye(2), R=np.eye(1), gamma=1.0)
    with pytest.raises(ValueError, match="must be discrete-time"):
        hinf_game(Plant(np.eye(2), np.ones((2, 1)), None), Bw=np.ones(2), Q=np.eye(2), R=np.eye(1), gamma=1.0)
    with pytest.raises(TypeError, match="uncertainty must be"):
        with_input_memory(Plant(np.eye(2), np.ones((2, 1)), 0.1), "H")
