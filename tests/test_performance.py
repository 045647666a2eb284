"""robustctl.lq_output against closed forms and scipy's matrix square root."""

import numpy as np
import pytest
import scipy.linalg

import robustctl as rc


def test_diagonal_weights_give_the_entrywise_square_root_exactly():
    Q, R = np.diag([1.0, 1.0, 25000.0, 100.0]), np.array([[33535.0]])
    Cz, Dzu = rc.lq_output(Q, R)
    assert Cz.shape == (5, 4) and Dzu.shape == (5, 1)
    np.testing.assert_array_equal(Cz, np.vstack([np.sqrt(Q), np.zeros((1, 4))]))
    np.testing.assert_array_equal(Dzu, np.vstack([np.zeros((4, 1)), np.sqrt(R)]))


@pytest.mark.parametrize("seed", range(3))
def test_full_weights_match_scipy_sqrtm_and_the_quadratic_cost(seed):
    rng = np.random.default_rng(seed)
    n, m = 4, 2
    C, D = rng.standard_normal((n, n)), rng.standard_normal((m, m))
    Q, R = C.T @ C + 0.1 * np.eye(n), D.T @ D + 0.5 * np.eye(m)
    Cz, Dzu = rc.lq_output(Q, R)
    np.testing.assert_allclose(Cz[:n], scipy.linalg.sqrtm(Q).real, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(Dzu[n:], scipy.linalg.sqrtm(R).real, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(Cz[n:], 0.0)
    np.testing.assert_array_equal(Dzu[:n], 0.0)
    x, u = rng.standard_normal(n), rng.standard_normal(m)
    z = Cz @ x + Dzu @ u
    assert z @ z == pytest.approx(x @ Q @ x + u @ R @ u, rel=1e-12)


def test_singular_psd_weight():
    """A rank-one Q (no Cholesky factor): Cz'Cz = Q still holds and the root is symmetric PSD."""
    v = np.array([[1.0], [2.0], [-1.0]])
    Q = v @ v.T
    Cz, Dzu = rc.lq_output(Q, 2.0)
    S = Cz[:3]
    np.testing.assert_allclose(S, S.T, atol=1e-15)
    np.testing.assert_allclose(S.T @ S, Q, atol=1e-12)
    np.testing.assert_allclose(S, Q / np.linalg.norm(v), atol=1e-12)          # closed form: v v' / |v|
    assert np.linalg.eigvalsh(S).min() > -1e-12
    np.testing.assert_array_equal(Cz.T @ Dzu, 0.0)
    assert Dzu[3, 0] == pytest.approx(np.sqrt(2.0))


@pytest.mark.parametrize("Q, R, match", [
    (np.diag([1.0, -1.0]), 1.0, "Q must be positive semidefinite"),
    ([[1.0, 2.0], [0.0, 1.0]], 1.0, "Q must be symmetric"),
    (np.ones((2, 3)), 1.0, "Q must be square"),
    (np.eye(2), -1.0, "R must be positive semidefinite"),
    (np.eye(2), [[np.nan]], "R must have finite entries"),
])
def test_bad_weights(Q, R, match):
    with pytest.raises(ValueError, match=match):
        rc.lq_output(Q, R)
