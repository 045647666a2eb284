"""The paper's data and set-ups (robustctl.models.morais2022): printed values, the authors' code, the set-ups."""

import subprocess
import sys

import control
import numpy as np
import pytest

from robustctl.models import morais2022, truck
from robustctl.models.pathfollow import DEFAULT_INITIAL_ERROR, DEFAULT_SETUP


def test_the_general_library_does_not_import_the_paper_module():
    """DESIGN.md: the vehicle model, paths, simulator and designs name none of the paper's data."""
    code = ("import sys, robustctl, robustctl.models.pathfollow, robustctl.models.path, robustctl.models, "
            "robustctl.models.truck, robustctl.sim.simulator; print('robustctl.models.morais2022' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_algebraic_uncertainty_printed():
    unc = morais2022.algebraic_uncertainty()
    assert unc.source == "printed"
    np.testing.assert_array_equal(unc.EF[0], [6.85718e-4, -8.62010e-4, 0.0, -6.6666e-3])
    np.testing.assert_array_equal(unc.EG[0], [-6.66666e-3, -6.66666e-3])
    np.testing.assert_array_equal(unc.H, np.ones((4, 1)))
    assert np.log10(unc.mu) ** 2 == pytest.approx(81.0)
    assert "printed" in repr(unc)
    assert not unc.EF.flags.writeable
    with pytest.raises(ValueError, match="source"):
        morais2022.algebraic_uncertainty("guessed")


def test_algebraic_uncertainty_computed_is_the_models():
    """``"computed"``: the appendix's rule on the model (truck.algebraic_uncertainty) at the printed mu."""
    unc, model = morais2022.algebraic_uncertainty("computed"), truck.algebraic_uncertainty()
    assert unc.source == "computed" and unc.mu == pytest.approx(1e9)
    for name in ("H", "EF", "EG"):
        np.testing.assert_array_equal(getattr(unc, name), getattr(model, name))


def test_uncertainty_from_z():
    EF, EG, mu = morais2022.uncertainty_from_z(morais2022.RLQR_MOP_Z)
    assert EF.shape == (1, 1, 4) and EG.shape == (1, 1, 2) and mu.shape == (1,)
    np.testing.assert_array_equal(EF[0, 0], [4.45032, 57.84300, 21.90069, 455.67736])
    np.testing.assert_array_equal(EG[0, 0], [48.05012, 44.98551])
    assert np.log10(mu[0]) == pytest.approx(np.sqrt(280.28421))
    Z = np.tile(morais2022.RLQR_MOP_Z, (5, 1))
    assert morais2022.uncertainty_from_z(Z)[0].shape == (5, 1, 4)
    with pytest.raises(ValueError, match="z"):
        morais2022.uncertainty_from_z(np.ones(6))
    with pytest.raises(ValueError, match="log10 mu"):
        morais2022.uncertainty_from_z([1, 1, 1, 1, 1, 1, -1])
    with pytest.raises(TypeError, match="z must be"):
        morais2022.uncertainty_from_z("1234567")


# -- the authors' set-up (Barbosa et al. 2019's published code) ---------------------------------------
def test_authors_weights_and_constants():
    """The values of barbosafilipe/robust_lqr's parameters.m / model.m, mapped to the 4 states."""
    Q, R = morais2022.authors_weights()
    np.testing.assert_array_equal(Q, np.diag([1.0, 1.0, 25000.0, 100.0]))
    np.testing.assert_array_equal(R, [[33535.0]])
    _, R2 = morais2022.authors_weights(doubled=True)
    np.testing.assert_array_equal(R2, 67070.0 * np.eye(2))
    assert morais2022.AUTHORS_X0 == (0.0, 0.0, 0.3, -0.1)
    np.testing.assert_allclose(morais2022.CODE_EG, [-1 / 15, -1 / 150], rtol=1e-14)


def test_authors_doubled_weight_gives_the_single_column_lqr():
    """R = 67070 I2 on [G G] and R = 33535 on G give the same steering gain (python-control's dlqr)."""
    Q, R1 = morais2022.authors_weights()
    _, R2 = morais2022.authors_weights(doubled=True)
    p1, p2 = truck.truck_plant(0.0), truck.truck_plant(0.0, doubled=True)
    K1 = -control.dlqr(p1.F, p1.G, Q, R1)[0]
    K2 = -control.dlqr(p2.F, p2.G, Q, R2)[0]
    # the doubled column's Riccati equation is worse conditioned (G2 has rank 1): a few 1e-9 across BLAS kernels
    np.testing.assert_allclose(K2.sum(axis=0, keepdims=True), K1, rtol=1e-7)


# -- the set-ups --------------------------------------------------------------------------------------
def test_setups_hold_the_documented_values():
    ours, authors = morais2022.get_setup("ours"), morais2022.get_setup("authors")
    assert (ours.name, authors.name) == ("ours", "authors")
    for a, b in zip(ours.weights(doubled=True), DEFAULT_SETUP.weights(doubled=True), strict=True):
        np.testing.assert_array_equal(a, b)                     # "ours" is the simulator's default set-up
    assert (ours.reference, ours.feedforward, ours.x0) == ("steady", True, DEFAULT_INITIAL_ERROR)
    for a, b in zip(authors.weights(doubled=True), morais2022.authors_weights(doubled=True), strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(authors.weights()[1], morais2022.authors_weights()[1])
    assert (authors.reference, authors.feedforward, authors.x0) == ("open_loop", False, morais2022.AUTHORS_X0)
    assert morais2022.get_setup(authors) is authors


@pytest.mark.parametrize("setup, exc, words", [
    ("theirs", ValueError, "unknown setup 'theirs'; valid: ours, authors"), (3, TypeError, "setup must be a name"),
])
def test_bad_setup(setup, exc, words):
    with pytest.raises(exc, match=words):
        morais2022.get_setup(setup)


def test_code_manoeuvre_is_the_codes_steering_command():
    """Its steady-cornering steering is 0.01 sin(0.4 pi (t - 10)) on [10, 15) s, the negative on [20, 25) s."""
    path = morais2022.code_manoeuvre()
    assert path.T == 300 and path.duration == pytest.approx(30.0)
    _, u_ref = truck.open_loop_reference(path.kappa)
    t = path.t
    want = np.zeros(path.T)
    for start, sign in ((10.0, 1.0), (20.0, -1.0)):
        on = (t >= start - 1e-9) & (t < start + 5.0 - 1e-9)
        # kappa is the mean over each sample: the mean of the sine over [t, t + dt]
        a, b = 0.4 * np.pi * (t[on] - start), 0.4 * np.pi * (t[on] + path.dt - start)
        want[on] = sign * 0.01 * (np.cos(a) - np.cos(b)) / (b - a)
    np.testing.assert_allclose(u_ref, want, atol=1e-7)        # the path's trapezoidal heading on its 16x finer grid
    np.testing.assert_allclose(path.heading[-1], 0.0, atol=1e-9)


def test_code_manoeuvre_rejects_bad_params():
    with pytest.raises(TypeError, match="params must be a TruckParameters"):
        morais2022.code_manoeuvre(params={"v": 10.0})
