"""robustctl.systems.stability: spectral radius, Schur/Hurwitz stability with one margin, PBH stabilisability,
against eigenvalues computed directly and plants built with a known uncontrollable mode."""

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.systems.stability import STABILITY_MARGIN, check_stabilizable, is_stable, unstabilizable_modes


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


@pytest.mark.parametrize("discrete", [True, False])
def test_a_boundary_mode_of_a_large_plant_is_found_at_a_tolerance_that_scales_with_its_norm(discrete):
    """An uncontrollable mode exactly on the boundary (1, or 0 in continuous time) of a plant with
    ||F|| ~ 1e6 is computed ~1e-10 away from it (eigenvalues are exact to ~eps ||F||): an absolute
    1e-12 would call it stable; UNSTABLE_TOL * max(1, ||[F G]||) does not, in either time domain."""
    from robustctl.systems.stability import UNSTABLE_TOL

    boundary = 1.0 if discrete else 0.0
    rng = np.random.default_rng(1)
    missed = 0
    for _ in range(20):
        T = rng.standard_normal((3, 3)) + 3 * np.eye(3)
        F = T @ np.diag([-1e6, -3e5, boundary]) @ np.linalg.inv(T)
        G = T @ np.array([[1.0], [1.0], [0.0]])                     # the boundary mode is not reached
        lam = np.linalg.eigvals(F)
        found = lam[np.argmin(np.abs(lam - boundary))]
        distance = 1.0 - abs(found) if discrete else -found.real
        missed += distance > UNSTABLE_TOL                          # what the absolute rule would miss
        plant = rc.Plant(F, G, 0.1 if discrete else None)
        np.testing.assert_allclose(plant.unstabilizable_modes, [found])
        with pytest.raises(rc.NotStabilizableError, match=r"plant is not stabilisable: its mode lambda"):
            check_stabilizable(plant)
        reachable = rc.Plant(F, T @ np.ones((3, 1)), plant.dt)     # the same mode, reached by the input
        assert reachable.is_stabilizable
    assert missed >= 3       # the case has teeth (about half the draws fall on the stable side)


def test_immovable_modes_at_chosen_eigenvalues():
    from robustctl.systems.stability import immovable_modes

    F, G = np.diag([0.5, 0.2, -0.7]), np.array([[0.0], [1.0], [0.0]])      # 0.5 and -0.7 are not reached
    np.testing.assert_allclose(np.sort(immovable_modes(F, G, lambda z: np.abs(z) > 0.3).real), [-0.7, 0.5])
    np.testing.assert_allclose(immovable_modes(F, G, lambda z: z.real > 0.3), [0.5])
    assert immovable_modes(F, G, lambda z: np.abs(z) < 0.3).size == 0          # 0.2 is reached
    with pytest.raises(ValueError, match=r"^G must have 3 rows"):
        immovable_modes(F, np.ones((2, 1)), lambda z: z.real > 0)


def test_every_design_raises_not_stabilizable_error_naming_the_vertex():
    bad = rc.Plant(np.diag([1.2, 0.5]), [[0.0], [1.0]], 0.1)
    good = rc.Plant(np.diag([1.2, 0.5]), [[1.0], [1.0]], 0.1)
    kw = dict(Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]])
    for design in (lambda: rc.lqr(bad), lambda: rc.rlqr(bad, [[0.1, 0.1]], [[0.1]], 1e4),
                   lambda: rc.hinf(bad, **kw), lambda: rc.h2(bad, **kw)):
        with pytest.raises(rc.NotStabilizableError, match=r"^plant is not stabilisable: its mode lambda = 1\.2"):
            design()
    for design in (rc.hinf, rc.h2):
        with pytest.raises(rc.NotStabilizableError, match=r"^vertices\[0\] is not stabilisable"):
            design(good, **kw, vertices=[bad])


def test_spectral_abscissa_matches_the_eigenvalues():
    from robustctl.systems.stability import spectral_abscissa

    A = np.random.default_rng(2).standard_normal((5, 3, 3))
    np.testing.assert_allclose(spectral_abscissa(A), np.linalg.eigvals(A).real.max(axis=-1), rtol=1e-12)
    assert isinstance(spectral_abscissa(A[0]), float)
    np.testing.assert_array_equal(spectral_abscissa(np.stack([-np.eye(2), np.full((2, 2), np.nan)])), [-1.0, np.inf])


@pytest.mark.parametrize("discrete", [True, False])
def test_every_stability_decision_uses_the_one_margin(discrete):
    """A loop inside the margin (rho = 1 - 1e-12, or abscissa -1e-12) is unstable for the controller, the
    LMI syntheses' internal check, the robust analysis and the worst-case search alike."""
    from robustctl.synthesis.hinf import check_closed_loop

    edge = 1.0 if discrete else 0.0
    plant = rc.Plant([[edge + 1e-12]], [[1.0]], 1.0 if discrete else None)
    ctrl = rc.Controller([[-2e-12]], "x", plant)                       # F + G K = edge - 1e-12
    assert abs(ctrl.closed_loop()[0, 0] - edge) < 2e-12
    assert not ctrl.is_stabilizing()
    with pytest.raises(rc.ConvergenceError, match="does not stabilise plant"):
        check_closed_loop(ctrl.K, [plant])
    unc = rc.NormBounded([[1.0]], [[0.1]], [[0.0]])
    res = rc.robust_stability(ctrl, unc)
    assert not res.certified and res.margin == 0.0 and res.P is None
    assert not rc.robust_stability(ctrl, vertices=[plant]).certified
    wc = rc.worst_case(ctrl, rc.NormBounded([[0.0]], [[0.0]], [[0.0]]), seed=0, n_starts=0)
    assert wc.destabilizing and wc.radius == pytest.approx(edge - 1e-12, abs=1e-15)
    with pytest.raises(rc.InfeasibleError, match="nominal closed loop F \\+ G K is unstable"):
        rc.guaranteed_cost(ctrl, unc, [[1.0]], [[1.0]])
    stable = rc.Controller([[-1e-6]], "x", plant)                       # 1e-6 inside: stable everywhere
    assert stable.is_stabilizing() and not rc.worst_case(stable, rc.NormBounded([[0.0]], [[0.0]], [[0.0]]),
                                                         n_starts=0).destabilizing
    check_closed_loop(stable.K, [plant])


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


def test_pbh_test_is_invariant_to_badly_scaled_state_units():
    """Stabilisability does not depend on units: the PBH test runs on F balanced (one place, for every design)."""
    rng = np.random.default_rng(7)
    F = rng.normal(size=(4, 4)) * 0.6 + 0.9 * np.eye(4)            # unstable modes, all controllable
    G = rng.normal(size=(4, 1))
    F[3, :3], G[3] = 0.0, 0.0
    F[3, 3] = 1.5                                                   # ... but the last: unstable, uncontrollable
    T = np.diag(10.0 ** np.array([-8.0, -3.0, 4.0, 8.0]))          # states in absurd units
    Ts, Gs = np.linalg.solve(T, F @ T), np.linalg.solve(T, G)
    stuck = rc.Plant(Ts, Gs, 0.1).unstabilizable_modes
    np.testing.assert_allclose(stuck, [1.5], rtol=1e-9)             # the true unstabilisable mode, and only it
    T3 = T[:3, :3]
    ok = rc.Plant(np.linalg.solve(T3, F[:3, :3] @ T3), np.linalg.solve(T3, G[:3]), 0.1)
    assert ok.is_stabilizable                                       # refused before F was balanced
    K = rc.lqr(ok, Q=T3.T @ T3).K                                   # the unit-free LQR, in these units
    assert rc.is_schur_stable(ok.F + ok.G @ K)
