"""Plant, NormBounded, Controller and design(): construction, checks, python-control agreement."""

import control
import numpy as np
import pytest

import robustctl as rc

A = np.array([[0.0, 1.0], [-2.0, -3.0]])
B = np.array([[0.0], [1.0]])


@pytest.mark.parametrize("method,pc_method", [("zoh", "zoh"), ("tustin", "tustin")])
def test_from_continuous_matches_control_c2d(method, pc_method):
    p = rc.Plant.from_continuous(A, B, dt=0.05, method=method)
    ref = control.c2d(control.ss(A, B, np.eye(2), 0), 0.05, method=pc_method)
    np.testing.assert_allclose(p.F, ref.A, atol=1e-14)
    np.testing.assert_allclose(p.G, ref.B, atol=1e-14)
    assert p.dt == 0.05 and p.n == 2 and p.m == 1


def test_from_continuous_zoh_is_matrix_exponential():
    """Independent closed form: expm([[A, B], [0, 0]] dt) = [[F, G], [0, I]]."""
    from scipy.linalg import expm

    M = np.zeros((3, 3))
    M[:2, :2], M[:2, 2:] = A, B
    E = expm(M * 0.1)
    p = rc.Plant.from_continuous(A, B, dt=0.1)
    np.testing.assert_allclose(p.F, E[:2, :2], atol=1e-14)
    np.testing.assert_allclose(p.G, E[:2, 2:], atol=1e-14)


def test_euler_and_continuous():
    p = rc.Plant.from_continuous(A, B, dt=0.1, method="euler")
    np.testing.assert_allclose(p.F, np.eye(2) + 0.1 * A)
    np.testing.assert_allclose(p.G, 0.1 * B)
    c = rc.Plant.from_continuous(A, B, dt=None)
    assert not c.is_discrete and c.dt is None
    np.testing.assert_array_equal(c.F, A)


def test_from_statespace_roundtrip():
    sysd = control.c2d(control.ss(A, B, np.eye(2), 0), 0.2)
    p = rc.Plant.from_statespace(sysd)
    assert p.dt == 0.2
    np.testing.assert_array_equal(p.F, sysd.A)
    back = p.to_statespace()
    np.testing.assert_array_equal(back.B, sysd.B)
    assert rc.Plant.from_statespace(control.ss(A, B, np.eye(2), 0)).dt is None


def test_plant_is_immutable():
    p = rc.Plant(np.eye(2), np.ones((2, 1)), 0.1)
    with pytest.raises(ValueError, match="read-only"):
        p.F[0, 0] = 5.0


@pytest.mark.parametrize(
    "args,match",
    [
        ((np.eye(2), np.ones((3, 1)), 0.1), r"G must have 2 rows .*got shape \(3, 1\)"),
        ((np.ones((2, 3)), np.ones((2, 1)), 0.1), r"F must be square, got shape \(2, 3\)"),
        ((np.eye(2), np.ones((2, 1)), 0.0), r"dt must be > 0"),
        ((np.eye(2), np.ones((2, 1)), -1), r"dt must be > 0"),
        ((np.eye(2) * np.nan, np.ones((2, 1)), 0.1), r"F must have finite entries"),
        ((np.eye(2), np.ones((2, 1)), np.inf), r"dt must be finite"),
    ],
)
def test_plant_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        rc.Plant(*args)


def test_plant_bad_types_and_methods():
    with pytest.raises(TypeError, match="F must be"):
        rc.Plant("abc", np.ones((2, 1)), 0.1)
    with pytest.raises(ValueError, match="method must be one of"):
        rc.Plant.from_continuous(A, B, dt=0.1, method="foh2")
    with pytest.raises(TypeError, match=r"sys must be a control\.StateSpace"):
        rc.Plant.from_statespace(np.eye(2))


def test_norm_bounded_perturb():
    F, G = np.diag([0.5, 0.2]), np.array([[1.0], [0.0]])
    plant = rc.Plant(F, G, 0.1)
    unc = rc.NormBounded([1.0, 2.0], [[0.1, 0.2]], [[0.3]])
    assert (unc.n, unc.m, unc.p, unc.l) == (2, 1, 1, 1)
    pert = unc.perturb(plant, -0.5)
    np.testing.assert_allclose(pert.F, F - 0.5 * np.array([[0.1, 0.2], [0.2, 0.4]]))
    np.testing.assert_allclose(pert.G, G - 0.5 * np.array([[0.3], [0.6]]))
    Fs, Gs = unc.perturbed_matrices(plant, np.array([-1.0, 0.0, 1.0]))
    assert Fs.shape == (3, 2, 2) and Gs.shape == (3, 2, 1)
    np.testing.assert_allclose(Fs[1], F)
    with pytest.raises(ValueError, match="contraction"):
        unc.perturb(plant, 1.5)
    with pytest.raises(ValueError, match="H must have 2 rows"):
        rc.NormBounded(np.ones((3, 1)), [[0.1, 0.2]], [[0.3]])
    with pytest.raises(ValueError, match="EG must have 1 rows"):
        rc.NormBounded([1.0, 2.0], [[0.1, 0.2]], np.ones((2, 1)))
    with pytest.raises(ValueError, match="uncertainty is for n=2"):
        unc.perturb(rc.Plant(np.eye(3), np.ones((3, 1)), 0.1), 0.0)


def test_controller_interface():
    plant = rc.Plant(np.array([[1.1, 0.1], [0.0, 0.9]]), np.array([[1.0], [0.5]]), 0.1)
    K = np.array([[-0.5, -0.1]])
    c = rc.Controller(K, "custom", plant)
    np.testing.assert_allclose(c([1.0, 2.0]), K @ [1.0, 2.0])
    np.testing.assert_allclose(c(np.ones((5, 2))), np.ones((5, 2)) @ K.T)
    np.testing.assert_allclose(c.closed_loop(), plant.F + plant.G @ K)
    assert c.is_stabilizing() == (np.abs(np.linalg.eigvals(plant.F + plant.G @ K)).max() < 1)
    assert not rc.Controller(np.zeros((1, 2)), "zero", plant).is_stabilizing()  # F has eigenvalue 1.1
    other = rc.Plant(np.eye(2) * 0.5, np.zeros((2, 1)), 0.1)
    np.testing.assert_allclose(c.closed_loop(other), other.F)
    assert "method='custom'" in repr(c) and "K=" in repr(c)
    with pytest.raises(ValueError, match="K must have 1 rows"):
        rc.Controller(np.zeros((2, 2)), "x", plant)
    with pytest.raises(ValueError, match="x must have 2 entries"):
        c(np.ones(3))
    with pytest.raises(TypeError):
        c.info["new"] = 1  # read-only mapping


def test_continuous_controller_stability():
    plant = rc.Plant.from_continuous(A, B, dt=None)
    assert rc.Controller(np.zeros((1, 2)), "zero", plant).is_stabilizing()  # A is Hurwitz
    assert not rc.Controller(np.array([[5.0, 5.0]]), "bad", plant).is_stabilizing()


def test_design_dispatch_errors():
    plant = rc.Plant(np.eye(2) * 0.5, np.ones((2, 1)), 0.1)
    with pytest.raises(ValueError, match="unknown design method 'pid'; valid: h2, h2hinf, hinf, lqg, lqr, rlqg, rlqr"):
        rc.design("pid", plant)
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        rc.design("lqr", np.eye(2))
    assert rc.design("LQR", plant).method == "lqr"


def test_closed_loop_statespace_is_python_controls_feedback_with_minus_K():
    rng = np.random.default_rng(2)
    plant = rc.Plant(rng.standard_normal((3, 3)) * 0.6, rng.standard_normal((3, 2)), 0.1)
    c = rc.lqr(plant)
    cl = c.to_statespace()
    ref = control.feedback(plant.to_statespace(), -c.K)    # python-control feeds back with a minus sign
    for ours, theirs in zip((cl.A, cl.B, cl.C, cl.D), (ref.A, ref.B, ref.C, ref.D), strict=True):
        np.testing.assert_allclose(ours, theirs, atol=1e-14)
    assert cl.dt == 0.1
    x0 = rng.standard_normal(3)
    resp = control.initial_response(cl, T=np.arange(20) * 0.1, X0=x0)
    x = x0.copy()
    for k in range(20):                                    # x+ = (F + G K) x, u = K x
        np.testing.assert_allclose(resp.states[:, k], x, atol=1e-12)
        x = plant.F @ x + plant.G @ c(x)
    # around a perturbed plant, and for a continuous loop
    other = rc.Plant(plant.F * 0.9, plant.G, 0.1)
    np.testing.assert_allclose(c.to_statespace(other).A, other.F + other.G @ c.K)
    cont = rc.Controller(np.array([[-1.0, -2.0]]), "x", rc.Plant.from_continuous(A, B, dt=None))
    assert cont.to_statespace().dt == 0


def test_from_continuous_errors_name_A():
    with pytest.raises(ValueError, match=r"tustin.*I - A dt/2 invertible.*eigenvalue at 2/dt = 20"):
        rc.Plant.from_continuous(np.diag([20.0, -1.0]), [[1.0], [1.0]], dt=0.1, method="tustin")
    with pytest.raises(ValueError, match=r"^A is too large for dt=0.1"):
        rc.Plant.from_continuous(1e300 * np.eye(2), [[1.0], [1.0]], dt=0.1)
    with pytest.raises(ValueError, match=r"^B must be a rectangular array"):
        rc.Plant.from_continuous(A, [[1.0, 2.0], [3.0]], dt=0.1)
    with pytest.raises(ValueError, match=r"^A must be a rectangular array"):
        rc.Plant.from_continuous([[1.0, 2.0], [3.0]], B, dt=0.1)


def test_controller_rejects_non_numeric_and_non_finite_states():
    plant = rc.Plant(np.eye(2) * 0.5, np.ones((2, 1)), 0.1)
    c = rc.Controller(np.array([[-0.1, -0.2]]), "x", plant)
    with pytest.raises(TypeError, match=r"^x must be an array of numbers"):
        c("x")
    with pytest.raises(ValueError, match=r"^x must have finite entries"):
        c([np.nan, 1.0])
    with pytest.raises(TypeError, match=r"^x must contain real numbers, got booleans"):
        c([True, False])
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        rc.Controller(np.zeros((1, 2)), "x", np.eye(2))


def test_perturb_rejects_booleans_strings_and_non_plants():
    plant = rc.Plant(np.eye(2) * 0.5, np.ones((2, 1)), 0.1)
    unc = rc.NormBounded([1.0, 2.0], [[0.1, 0.2]], [[0.3]])
    for bad, err, match in ((True, TypeError, "^Delta must be an array of numbers"),
                            ("x", TypeError, "^Delta must be an array of numbers"),
                            (1j, TypeError, "^Delta must contain real numbers, got complex")):
        with pytest.raises(err, match=match):
            unc.perturb(plant, bad)
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        unc.perturb(np.eye(2), 0.5)
    with pytest.raises(ValueError, match=r"^H must be a rectangular array"):
        rc.NormBounded([[1.0], [2.0, 3.0]], [[0.1, 0.2]], [[0.3]])


def test_one_vertex_check_serves_hinf_h2_and_the_analysis():
    from robustctl.validation import check_vertices

    plant = rc.Plant(0.5 * np.eye(2), np.ones((2, 1)), 0.1)
    other = rc.Plant(0.4 * np.eye(2), np.ones((2, 1)), 0.1)
    assert check_vertices(plant, None) == [plant] and check_vertices(plant, []) == [plant]
    assert check_vertices(plant, (other,)) == [plant, other]
    for bad, err, match in (("ab", TypeError, "^vertices must be a list of robustctl.Plant"),
                            (plant, TypeError, "^vertices must be a list"),
                            ([other, 1.0], TypeError, r"^vertices\[1\] must be a robustctl.Plant, got float"),
                            ([rc.Plant(np.eye(3), np.ones((3, 1)), 0.1)], ValueError,
                             r"^vertices\[0\] must have n=2 states and m=1 inputs like plant, got n=3, m=1"),
                            ([rc.Plant(np.eye(2), np.ones((2, 1)), None)], ValueError,
                             r"^vertices\[0\] must have the sampling time of plant \(dt=0.1\), got dt=None")):
        with pytest.raises(err, match=match):
            check_vertices(plant, bad)
    for empty in (None, []):
        with pytest.raises(TypeError, match=r"^vertices must be a non-empty list"):
            check_vertices(plant, empty, non_empty=True)
    with pytest.raises(ValueError, match="like the controller's plant"):
        rc.robust_stability((plant, np.zeros((1, 2))), vertices=[rc.Plant(np.eye(3), np.ones((3, 1)), 0.1)])
