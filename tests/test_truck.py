"""Truck single-track model: hand derivation, textbook steady state, c2d, Appendix A uncertainty."""

import control
import numpy as np
import pytest

from robustctl.models import truck
from robustctl.models.truck import PAPER_PARAMETERS as P

OVERLOADS = [0.0, 100.0, 200.0, 300.0]


def _hand_model(m, J, p=P):
    """Linear single-track model from tyre forces, as a function; Jacobian by unit vectors.

    Front slip angle  a_f = alpha - (ydot + a r)/v,  rear  a_r = -(ydot - b r)/v,
    Fy_f = c1 a_f, Fy_r = c2 a_r;  m (ydot' + v r) = Fy_f + Fy_r;  J r' = a Fy_f - b Fy_r;
    rho' = ydot + v theta;  theta' = r - v kappa.
    """
    def f(x, alpha, kappa):
        ydot, r, _rho, theta = x
        Ff = p.c1 * (alpha - (ydot + p.a * r) / p.v)
        Fr = p.c2 * (-(ydot - p.b * r) / p.v)
        return np.array([(Ff + Fr) / m - p.v * r, (p.a * Ff - p.b * Fr) / J,
                         ydot + p.v * theta, r - p.v * kappa])

    A = np.column_stack([f(e, 0.0, 0.0) for e in np.eye(4)])
    B = f(np.zeros(4), 1.0, 0.0)[:, None]
    E = f(np.zeros(4), 0.0, 1.0)
    return A, B, E


@pytest.mark.parametrize("overload", OVERLOADS)
def test_continuous_model_matches_hand_derivation(overload):
    m = P.m + P.payload * (1 + overload / 100)
    J = P.J * m / P.m
    A, B, E = truck.continuous_model(overload)
    Ah, Bh, Eh = _hand_model(m, J)
    np.testing.assert_allclose(A, Ah, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(B, Bh, rtol=1e-12)
    np.testing.assert_allclose(E, Eh, rtol=1e-12)


def test_typos_of_eq1_are_corrected():
    A, _, _ = truck.continuous_model(0.0)
    m, J = P.total_mass(0), P.inertia(0)
    assert A[0, 1] == pytest.approx((P.b * P.c2 - P.a * P.c1 - m * P.v**2) / (m * P.v), rel=1e-14)
    assert A[1, 1] == pytest.approx(-(P.a**2 * P.c1 + P.b**2 * P.c2) / (J * P.v), rel=1e-14)
    # the printed (wrong) entries would differ clearly
    assert abs(A[1, 1] - (-(P.a**2 * P.c1 + P.b**2 * P.c1) / (J * P.v))) > 0.1


def test_mass_and_inertia_scaling():
    assert P.total_mass(0) == pytest.approx(16030 + 12550)
    assert P.total_mass(100) == pytest.approx(16030 + 2 * 12550)
    assert P.total_mass(300) == pytest.approx(16030 + 4 * 12550)
    assert P.inertia(0) / P.total_mass(0) == pytest.approx(P.J / P.m)   # same radius of gyration
    assert P.wheelbase == pytest.approx(4.805)


@pytest.mark.parametrize("overload", OVERLOADS)
def test_eigenvalues_plausible(overload):
    A, _, _ = truck.continuous_model(overload)
    ev = np.linalg.eigvals(A)
    ev = ev[np.argsort(np.abs(ev))]
    np.testing.assert_allclose(ev[:2], 0.0, atol=1e-12)            # rho and theta integrate
    lat = ev[2:]
    assert np.all(lat.real < 0)                                     # stable handling dynamics
    wn = np.abs(lat[0])
    assert 0.3 < wn < 5.0                                           # rad/s, a heavy vehicle's yaw mode
    # the lateral sub-block's eigenvalues are those of the 2x2 handling model
    np.testing.assert_allclose(np.sort_complex(lat), np.sort_complex(np.linalg.eigvals(A[:2, :2])))


@pytest.mark.parametrize("overload", OVERLOADS)
def test_static_steering_gain_matches_understeer_gradient(overload):
    """Textbook steady cornering (Gillespie 1992, Ch. 6): delta = L/R + K_us a_y,
    K_us = m/L (b/c1 - a/c2) [rad/(m/s^2)], sideslip beta = (b - m a v^2/(L c2)) / R."""
    m = P.total_mass(overload)
    L = P.wheelbase
    Kus = m / L * (P.b / P.c1 - P.a / P.c2)
    x, alpha = truck.steady_state_cornering(overload)
    assert Kus > 0                                                  # the truck understeers
    assert alpha == pytest.approx(L + Kus * P.v**2, rel=1e-10)
    beta = P.b - m * P.a * P.v**2 / (L * P.c2)
    assert x[0] / P.v == pytest.approx(beta, rel=1e-10)
    assert x[1] == pytest.approx(P.v)
    assert x[2] == 0.0
    assert x[3] == pytest.approx(-x[0] / P.v)
    # it is an equilibrium of the full continuous model for kappa = 1
    A, B, E = truck.continuous_model(overload)
    np.testing.assert_allclose(A @ x + B[:, 0] * alpha + E, 0.0, atol=1e-9)
    # static yaw-rate gain r/delta = v / (L + K_us v^2) is positive and below the neutral-steer v/L
    assert 0 < P.v / alpha < P.v / L


@pytest.mark.parametrize("overload", OVERLOADS)
def test_discretisation_matches_c2d(overload):
    A, B, E = truck.continuous_model(overload)
    sysd = control.c2d(control.ss(A, np.column_stack([B, E]), np.eye(4), 0), 0.1, method="zoh")
    F, G, Gk = truck.discretise(overload)
    np.testing.assert_allclose(F[0], sysd.A, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(G[0], sysd.B[:, :1], rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(Gk[0], sysd.B[:, 1], rtol=1e-10, atol=1e-13)
    plant = truck.truck_plant(overload)
    np.testing.assert_allclose(plant.F, sysd.A, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(plant.G, sysd.B[:, :1], rtol=1e-10, atol=1e-13)
    assert plant.dt == 0.1


def test_batched_discretisation_equals_single():
    F, G, Gk = truck.discretise([0.0, 150.0, 300.0])
    for i, ov in enumerate([0.0, 150.0, 300.0]):
        F1, G1, Gk1 = truck.discretise(ov)
        np.testing.assert_allclose(F[i], F1[0], rtol=1e-13)
        np.testing.assert_allclose(G[i], G1[0], rtol=1e-13)
        np.testing.assert_allclose(Gk[i], Gk1[0], rtol=1e-13)


def test_doubled_column():
    p1 = truck.truck_plant(0.0)
    p2 = truck.truck_plant(0.0, doubled=True)
    assert (p2.n, p2.m) == (4, 2)
    np.testing.assert_array_equal(p2.G, np.hstack([p1.G, p1.G]))
    np.testing.assert_array_equal(p2.F, p1.F)


def test_algebraic_uncertainty_computed_structure():
    """Appendix A: Gamma = model(unloaded) - model(100 % overload), first row, weights [1 1 1 .1] / [.1 .1]."""
    def c2d_at_mass(m):
        A, B, _ = _hand_model(m, P.J * m / P.m)
        s = control.c2d(control.ss(A, B, np.eye(4), 0), 0.1)
        return s.A, s.B

    F0, G0 = c2d_at_mass(P.m)
    F1, G1 = c2d_at_mass(P.m + 2 * P.payload)
    unc = truck.algebraic_uncertainty()
    assert unc.EF.shape == (1, 4) and unc.EG.shape == (1, 2) and unc.H.shape == (4, 1)
    np.testing.assert_allclose(unc.EF[0], np.array([1, 1, 1, 0.1]) * (F0 - F1)[0], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(unc.EG[0], 0.1 * (G0 - G1)[0, 0] * np.ones(2), rtol=1e-9)
    np.testing.assert_array_equal(unc.H, np.ones((4, 1)))
    # lateral velocity does not depend on rho, theta: those entries vanish
    assert unc.EF[0, 2] == 0.0 and unc.EF[0, 3] == 0.0
    # the first row is the one most affected by the mass (largest Gamma_F row norm)
    gF = F0 - F1
    assert np.argmax(np.linalg.norm(gF, axis=1)) == 0
    assert unc.mu == pytest.approx(1e9) and unc.source == "computed"
    assert truck.algebraic_uncertainty(mu=10.0).mu == 10.0
    with pytest.raises(ValueError, match="mu must be > 0"):
        truck.algebraic_uncertainty(mu=0.0)


@pytest.mark.parametrize("bad", [-1.0, -100.0, np.nan, np.inf])
def test_bad_overload(bad):
    with pytest.raises(ValueError, match="overload"):
        truck.truck_plant(bad)
    with pytest.raises(ValueError, match="overload"):
        P.total_mass(bad)


def test_bad_overload_type_and_params():
    with pytest.raises(TypeError, match="overload"):
        truck.truck_plant("heavy")
    with pytest.raises(TypeError, match="params"):
        truck.truck_plant(0.0, params={"m": 1})
    with pytest.raises(ValueError, match="c1"):
        truck.TruckParameters(c1=-1.0)
    with pytest.raises(ValueError, match="payload"):
        truck.TruckParameters(payload=-5.0)
    assert truck.TruckParameters(payload=0.0).total_mass(300) == pytest.approx(P.m)


def test_lqr_weights_doubled_column_costs_the_same():
    """The doubled-column LQR (R2 = 2 r I) gives the plain LQR's steering: K1 + K2 = K."""
    import robustctl as rc

    Q, R = truck.lqr_weights()
    Q2, R2 = truck.lqr_weights(doubled=True)
    np.testing.assert_array_equal(Q, Q2)
    assert R.shape == (1, 1) and R2.shape == (2, 2)
    K = -control.dlqr(truck.truck_plant(0.0).F, truck.truck_plant(0.0).G, Q, R)[0]
    p2 = truck.truck_plant(0.0, doubled=True)
    K2 = rc.design("lqr", p2, Q=Q2, R=R2).K
    np.testing.assert_allclose(K2.sum(axis=0), K[0], rtol=1e-8)
    np.testing.assert_allclose(K2[0], K2[1], rtol=1e-8)


def test_truck_plant_does_not_import_python_control():
    """The applied MOP's import cost: the ZOH is scipy's expm, python-control stays unloaded."""
    import subprocess
    import sys

    code = ("import sys; from robustctl.models import truck; truck.truck_plant(0.0, doubled=True); "
            "print('control' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("overload", [0.0, 150.0])
def test_open_loop_reference_matches_dlsim(overload):
    """The open-loop reference against scipy.signal.dlsim of the ZOH model with inputs (u_ref, kappa)."""
    import scipy.signal

    rng = np.random.default_rng(3)
    kappa = np.convolve(rng.normal(0, 2e-3, 400), np.ones(25) / 25, mode="same")
    x_ref, u_ref = truck.open_loop_reference(kappa, overload)
    _, a_per_kappa = truck.steady_state_cornering(overload)
    np.testing.assert_allclose(u_ref, a_per_kappa * kappa, rtol=1e-15)
    A, B, E = truck.continuous_model(overload)
    sysd = scipy.signal.cont2discrete((A, np.column_stack([B, E]), np.eye(4), np.zeros((4, 2))), P.dt, "zoh")
    _, y, _ = scipy.signal.dlsim((*sysd[:4], P.dt), np.column_stack([u_ref, kappa]))
    np.testing.assert_allclose(x_ref, y, rtol=1e-9, atol=1e-12 * np.abs(y).max())


def test_open_loop_reference_of_steady_cornering_settles_on_the_steady_state():
    """On a long constant bend the open-loop vehicle's velocities settle at the steady cornering values."""
    kappa = np.full(3000, 1 / 300.0)
    x_ref, _ = truck.open_loop_reference(kappa)
    x_ss, _ = truck.steady_state_cornering(0.0)
    np.testing.assert_allclose(x_ref[-1, :2], x_ss[:2] / 300.0, rtol=1e-9)


def test_curvature_input_does_not_depend_on_the_payload():
    """Gk is the same at every payload, so the curvature cancels from x - x_ref (open_loop_reference)."""
    _, _, Gk = truck.discretise([0.0, 100.0, 300.0])
    np.testing.assert_allclose(Gk[1:], np.broadcast_to(Gk[0], (2, 4)), rtol=1e-12, atol=1e-15)
