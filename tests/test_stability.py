"""Batched Schur stability: closed-form spectral radii, the norm certificate against the eigenvalues."""

import numpy as np
import pytest

import robustctl as rc


def _rotation(r, phi):
    """r times a rotation by phi: eigenvalues r e^(+-i phi), spectral radius r."""
    return r * np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])


def test_spectral_radius_closed_forms():
    A = np.stack([_rotation(r, 0.3) for r in (0.5, 0.999, 1.0, 1.7)])
    np.testing.assert_allclose(rc.spectral_radius(A), [0.5, 0.999, 1.0, 1.7], rtol=1e-14)
    # companion matrix of (z - 0.9)(z + 0.2)(z - 1.1): roots 0.9, -0.2, 1.1
    c = np.poly([0.9, -0.2, 1.1])
    comp = np.vstack([-c[1:], np.eye(3)[:2]])
    assert float(rc.spectral_radius(comp)) == pytest.approx(1.1, rel=1e-12)
    # a Jordan block: ||A^k|| grows before it decays, rho = 0.95
    J = np.array([[0.95, 50.0], [0.0, 0.95]])
    assert float(rc.spectral_radius(J)) == pytest.approx(0.95, rel=1e-12)
    assert rc.spectral_radius(np.ones((2, 3, 4, 4))).shape == (2, 3)


def test_non_finite_matrices_are_unstable():
    A = np.stack([0.5 * np.eye(3), np.full((3, 3), np.nan), np.diag([0.1, np.inf, 0.2])])
    np.testing.assert_array_equal(rc.spectral_radius(A), [0.5, np.inf, np.inf])
    np.testing.assert_array_equal(rc.is_schur_stable(A), [True, False, False])


def test_certificate_agrees_with_eigenvalues_on_hard_stacks():
    rng = np.random.default_rng(4)
    A = rng.standard_normal((3000, 4, 4)) / 2.0
    A[:1000] *= 0.999 / rc.spectral_radius(A[:1000])[:, None, None]      # just inside the circle
    A[1000:2000] *= 1.001 / rc.spectral_radius(A[1000:2000])[:, None, None]   # just outside
    A[2000] = np.array([[0.95, 1e4, 0, 0], [0, 0.95, 0, 0], [0, 0, 0.1, 0], [0, 0, 0, 0.1]])   # transient 1e4
    want = rc.spectral_radius(A) < 1.0
    np.testing.assert_array_equal(rc.is_schur_stable(A), want)
    assert want[:1000].all() and not want[1000:2000].any() and want[2000]
    np.testing.assert_array_equal(rc.is_schur_stable(A, margin=0.01), rc.spectral_radius(A) < 0.99)


def test_bad_arguments():
    with pytest.raises(ValueError, match="A must be a square matrix"):
        rc.spectral_radius(np.ones((2, 3)))
    with pytest.raises(TypeError, match="A must be an array of numbers"):
        rc.is_schur_stable("A")
    with pytest.raises(ValueError, match="margin"):
        rc.is_schur_stable(np.eye(2), margin=1.0)
    with pytest.raises(TypeError, match="margin"):
        rc.is_schur_stable(np.eye(2), margin=True)
