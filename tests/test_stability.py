"""robustctl.stability: spectral radius, Schur/Hurwitz stability with one margin, PBH stabilisability,
against eigenvalues computed directly and plants built with a known uncontrollable mode."""

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.stability import STABILITY_MARGIN, is_stable, unstabilizable_modes


def _rho(A):
    return np.abs(np.linalg.eigvals(A)).max(axis=-1)


@pytest.mark.parametrize("B", [1, 5, 300])  # small batches use eigenvalues, large ones the squaring certificate
def test_schur_stability_matches_the_eigenvalues(B):
    rng = np.random.default_rng(B)
    A = rng.standard_normal((B, 4, 4)) * rng.uniform(0.05, 0.6, (B, 1, 1))
    A[: B // 3] *= 5.0                                   # some clearly unstable
    if B > 2:
        T = rng.standard_normal((4, 4)) + 4 * np.eye(4)
        A[1] = T @ np.diag([1 - 1e-6, 0.5, -0.3, 0.1]) @ np.linalg.inv(T)  # stable, barely, non-normal
        A[2] = T @ np.diag([1 - 1e-12, 0.5, -0.3, 0.1]) @ np.linalg.inv(T)  # inside the margin: unstable
    np.testing.assert_allclose(rc.spectral_radius(A), _rho(A), rtol=1e-12)
    np.testing.assert_array_equal(rc.is_schur_stable(A), _rho(A) < 1 - STABILITY_MARGIN)
    if B > 2:
        assert rc.is_schur_stable(A[1]) and not rc.is_schur_stable(A[2])


def test_stability_of_non_finite_and_shapes():
    A = np.stack([0.5 * np.eye(2), np.full((2, 2), np.nan), np.diag([np.inf, 0.1])])
    np.testing.assert_array_equal(rc.spectral_radius(A), [0.5, np.inf, np.inf])
    np.testing.assert_array_equal(rc.is_schur_stable(A), [True, False, False])
    assert rc.is_schur_stable(np.zeros((3, 2, 2))).shape == (3,)
    assert isinstance(rc.spectral_radius(np.eye(2)), float)
    with pytest.raises(ValueError, match=r"A must be a square matrix or a stack"):
        rc.spectral_radius(np.ones((2, 3)))
    with pytest.raises(TypeError, match="A must contain real numbers, got booleans"):
        rc.is_schur_stable(np.eye(2, dtype=bool))


def test_hurwitz_stability_matches_python_control():
    rng = np.random.default_rng(0)
    for _ in range(20):
        A = rng.standard_normal((3, 3))
        poles = control.ss(A, np.zeros((3, 1)), np.zeros((1, 3)), 0).poles()
        assert is_stable(A, discrete=False) == (poles.real.max() < -STABILITY_MARGIN)
        Ad = 0.5 * A
        assert is_stable(Ad, discrete=True) == (np.abs(np.linalg.eigvals(Ad)).max() < 1 - STABILITY_MARGIN)


def test_pbh_against_the_controllability_staircase():
    """Uncontrollable modes: eigenvalues of F on the complement of the controllable subspace (Kalman)."""
    rng = np.random.default_rng(5)
    for trial in range(30):
        n, r = 4, int(rng.integers(1, 4))       # controllable subspace of dimension r
        T = np.linalg.qr(rng.standard_normal((n, n)))[0]
        F = np.zeros((n, n))
        F[:r, :r] = rng.standard_normal((r, r))
        F[:r, r:] = rng.standard_normal((r, n - r))
        F[r:, r:] = rng.standard_normal((n - r, n - r)) * 0.9
        G = np.vstack([rng.standard_normal((r, 1)), np.zeros((n - r, 1))])
        F, G = T @ F @ T.T, T @ G
        C = control.ctrb(F, G)
        assert np.linalg.matrix_rank(C, tol=1e-9) == r
        U = np.linalg.svd(C)[0]
        F_bar = (U.T @ F @ U)[r:, r:]                  # the uncontrollable block
        expected = np.linalg.eigvals(F_bar)
        expected = np.sort_complex(expected[np.abs(expected) >= 1 - 1e-12])
        got = np.sort_complex(unstabilizable_modes(F, G))
        np.testing.assert_allclose(got, expected, atol=1e-8, err_msg=str(trial))
        assert rc.Plant(F, G, 0.1).is_stabilizable == (expected.size == 0)


def test_continuous_stabilisability():
    plant = rc.Plant(np.diag([0.3, -1.0]), [[0.0], [1.0]], None)  # Re = 0.3 >= 0, uncontrollable
    np.testing.assert_allclose(plant.unstabilizable_modes, [0.3])
    assert rc.Plant(np.diag([-0.3, 1.0]), [[0.0], [1.0]], None).is_stabilizable


def _rotation(r, phi):
    """r times a rotation by phi: eigenvalues r e^(+-i phi), spectral radius r."""
    return r * np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])


def test_spectral_radius_closed_forms():
    A = np.stack([_rotation(r, 0.3) for r in (0.5, 0.999, 1.0, 1.7)])
    np.testing.assert_allclose(rc.spectral_radius(A), [0.5, 0.999, 1.0, 1.7], rtol=1e-14)
    # companion matrix of (z - 0.9)(z + 0.2)(z - 1.1): roots 0.9, -0.2, 1.1
    c = np.poly([0.9, -0.2, 1.1])
    comp = np.vstack([-c[1:], np.eye(3)[:2]])
    assert rc.spectral_radius(comp) == pytest.approx(1.1, rel=1e-12)
    assert rc.spectral_radius(np.ones((2, 3, 4, 4))).shape == (2, 3)


def test_certificate_agrees_with_eigenvalues_on_hard_stacks():
    """Radii just inside and just outside the circle, and a stable loop with a 1e4 transient."""
    rng = np.random.default_rng(4)
    A = rng.standard_normal((3000, 4, 4)) / 2.0
    A[:1000] *= 0.999 / rc.spectral_radius(A[:1000])[:, None, None]
    A[1000:2000] *= 1.001 / rc.spectral_radius(A[1000:2000])[:, None, None]
    A[2000] = np.array([[0.95, 1e4, 0, 0], [0, 0.95, 0, 0], [0, 0, 0.1, 0], [0, 0, 0, 0.1]])
    want = _rho(A) < 1.0 - STABILITY_MARGIN
    np.testing.assert_array_equal(rc.is_schur_stable(A), want)
    assert want[:1000].all() and not want[1000:2000].any() and want[2000]
    np.testing.assert_array_equal(rc.is_schur_stable(A, margin=0.01), _rho(A) < 0.99)
