"""Plants with measured outputs and a disturbance input (issue 33, item 1), against python-control and scipy."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg

import robustctl as rc

A = np.array([[0.0, 1.0, 0.0], [-2.0, -0.3, 1.0], [0.0, 0.0, -5.0]])
B = np.array([[0.0], [0.0], [5.0]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
BW = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def test_no_output_model_keeps_todays_meaning():
    plant = rc.Plant(A, B, 0.1)
    assert not plant.has_outputs and plant.C is None and plant.D is None and plant.Bw is None
    assert plant.p == plant.n == 3
    Cm, Dm = plant.output_matrices()
    np.testing.assert_array_equal(Cm, np.eye(3))
    np.testing.assert_array_equal(Dm, np.zeros((3, 1)))
    assert repr(plant) == "Plant(n=3, m=1, dt=0.1)"


def test_outputs_shapes_defaults_and_read_only():
    plant = rc.Plant(A, B, None, C=C, Bw=BW)
    assert plant.has_outputs and plant.p == 2 and plant.D.shape == (2, 1) and not plant.D.any()
    assert repr(plant) == "Plant(n=3, m=1, p=2, continuous)"
    for M in (plant.C, plant.D, plant.Bw):
        with pytest.raises(ValueError, match="read-only"):
            M[0, 0] = 1.0
    one = rc.Plant(A, B, 0.1, C=[1.0, 0.0, 0.0], Bw=[0.0, 1.0, 0.0])     # 1-D: one output row, one column
    assert one.C.shape == (1, 3) and one.Bw.shape == (3, 1)


@pytest.mark.parametrize("kwargs, match", [
    (dict(C=np.ones((2, 2))), r"^C must have 3 columns \(the number of states, from F\), got shape \(2, 2\)"),
    (dict(C=C, D=np.ones((2, 2))), r"^D must have 1 columns \(the number of inputs, columns of G\), got shape"),
    (dict(C=C, D=np.ones((3, 1))), r"^D must have 2 rows \(the number of outputs, rows of C\), got shape \(3, 1\)"),
    (dict(D=np.ones((2, 1))), r"^D needs C"),
    (dict(Bw=np.ones((2, 1))), r"^Bw must have 3 rows \(the number of states, from F\), got shape \(2, 1\)"),
    (dict(C=[[np.nan, 0.0, 0.0]]), r"^C must have finite entries"),
])
def test_bad_outputs_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        rc.Plant(A, B, 0.1, **kwargs)


def test_zoh_discretises_bw_with_the_plant_as_python_control():
    plant = rc.Plant.from_continuous(A, B, 0.05, C=C, Bw=BW)
    ref = control.c2d(control.ss(A, np.hstack([B, BW]), C, np.zeros((2, 3))), 0.05, method="zoh")
    np.testing.assert_allclose(plant.F, ref.A, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(plant.G, ref.B[:, :1], rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(plant.Bw, ref.B[:, 1:], rtol=1e-13, atol=1e-15)
    np.testing.assert_array_equal(plant.C, C)
    # the integral of e^{As} ds [B Bw], by quadrature
    integral = scipy.integrate.quad_vec(lambda s: scipy.linalg.expm(A * s), 0.0, 0.05, epsabs=1e-14)[0]
    np.testing.assert_allclose(plant.Bw, integral @ BW, rtol=1e-9, atol=1e-14)


def test_tustin_changes_c_and_d_as_python_control():
    plant = rc.Plant.from_continuous(A, B, 0.05, "tustin", C=C)
    ref = control.c2d(control.ss(A, B, C, np.zeros((2, 1))), 0.05, method="tustin")
    for ours, theirs in ((plant.F, ref.A), (plant.G, ref.B), (plant.C, ref.C), (plant.D, ref.D)):
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-15)
    assert np.abs(plant.D).max() > 1e-4          # the Tustin image has a feedthrough
    with pytest.raises(ValueError, match=r"^method='tustin' with both C and Bw"):
        rc.Plant.from_continuous(A, B, 0.05, "tustin", C=C, Bw=BW)


def test_euler_and_continuous_keep_the_outputs():
    plant = rc.Plant.from_continuous(A, B, 0.01, "euler", C=C, Bw=BW)
    np.testing.assert_allclose(plant.Bw, 0.01 * BW)
    np.testing.assert_array_equal(plant.C, C)
    cont = rc.Plant.from_continuous(A, B, None, C=C, D=[[1.0], [0.0]], Bw=BW)
    np.testing.assert_array_equal(cont.D, [[1.0], [0.0]])
    assert cont.dt is None


def test_statespace_round_trip_carries_c_and_d():
    D = np.array([[0.5], [0.0]])
    sys = control.ss(A, B, C, D, 0.1)
    plant = rc.Plant.from_statespace(sys)
    np.testing.assert_array_equal(plant.C, C)
    np.testing.assert_array_equal(plant.D, D)
    back = plant.to_statespace()
    for x, y in ((back.A, sys.A), (back.B, sys.B), (back.C, sys.C), (back.D, sys.D)):
        np.testing.assert_array_equal(x, y)
    assert back.dt == 0.1
    state = rc.Plant.from_statespace(control.ss(A, B, np.eye(3), np.zeros((3, 1))))
    assert not state.has_outputs                                   # C = I, D = 0: the state is measured
    assert rc.Plant.from_statespace(control.ss(A, B, np.eye(3), np.ones((3, 1)))).has_outputs


def test_detectability_by_pbh_against_the_observability_staircase():
    # the mode 1.2 of the second state is not seen by C = [1 0]
    F = np.array([[0.5, 0.0], [0.0, 1.2]])
    blind = rc.Plant(F, [[1.0], [1.0]], 0.1, C=[[1.0, 0.0]])
    np.testing.assert_allclose(blind.undetectable_modes, [1.2])
    assert not blind.is_detectable
    with pytest.raises(rc.NotDetectableError, match=r"^plant is not detectable: its mode lambda = \(?1\.2"):
        rc.systems.stability.check_detectable(blind)
    seen = rc.Plant(F, [[1.0], [1.0]], 0.1, C=[[1.0, 1e-3]])
    assert seen.is_detectable
    # a stable hidden mode is fine (detectable, not observable)
    assert rc.Plant(np.diag([1.5, 0.3]), [[1.0], [0.0]], 0.1, C=[[1.0, 0.0]]).is_detectable
    # python-control's observability matrix agrees on the rank
    assert np.linalg.matrix_rank(control.obsv(F, [[1.0, 0.0]])) == 1


def test_perturbed_plants_keep_outputs_and_disturbance():
    plant = rc.Plant(A, B, None, C=C, Bw=BW)
    unc = rc.NormBounded(np.ones((3, 1)), [[0.1, 0.0, 0.0]], [[0.0]])
    other = unc.perturb(plant, 1.0)
    np.testing.assert_allclose(other.F, A + np.ones((3, 1)) @ [[0.1, 0.0, 0.0]])
    np.testing.assert_array_equal(other.C, plant.C)
    np.testing.assert_array_equal(other.Bw, plant.Bw)


def test_noise_covariance_against_quadrature():
    W = np.array([[2.0, 0.3], [0.3, 1.0]])
    Wd = rc.noise_covariance(A, BW, W, 0.2)
    integrand = lambda s: scipy.linalg.expm(A * s) @ BW @ W @ BW.T @ scipy.linalg.expm(A.T * s)  # noqa: E731
    ref = scipy.integrate.quad_vec(integrand, 0.0, 0.2, epsabs=1e-14)[0]
    np.testing.assert_allclose(Wd, ref, rtol=1e-9, atol=1e-14)
    np.testing.assert_array_equal(Wd, Wd.T)
    with pytest.raises(ValueError, match=r"^W must have 2 rows \(columns of Bw\)"):
        rc.noise_covariance(A, BW, np.eye(3), 0.2)
    with pytest.raises(ValueError, match=r"^W must be"):
        rc.noise_covariance(A, BW, -np.eye(2), 0.2)
