"""Path-following set-ups (the default, the paper's "authors") and laws with input memory, against independent loops."""

import dataclasses

import numpy as np
import pytest
import scipy.signal

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.path import Curve, LaneChange, ReferencePath, Straight, default_route
from robustctl.models.pathfollow import (
    DEFAULT_INITIAL_ERROR,
    DEFAULT_SETUP,
    PathFollowing,
    PathFollowingSetup,
    simulate,
)

AUTHORS = morais2022.SETUPS["authors"]

OVERLOADS = (0.0, 200.0)


@pytest.fixture(scope="module")
def path():
    return ReferencePath.from_segments([Straight(100.0), LaneChange(3.5, 120.0), Curve(250.0, 40.0, 50.0),
                                        Straight(150.0)], name="short")


def _reference(path, overload=0.0):
    """Open-loop nominal response to the steady-cornering steering, by scipy's dlsim (independent)."""
    A, B, E = truck.continuous_model(overload)
    _, a_per_kappa = truck.steady_state_cornering(overload)
    u_ref = a_per_kappa * path.kappa
    sysd = scipy.signal.cont2discrete((A, np.column_stack([B, E]), np.eye(4), np.zeros((4, 2))), path.dt, "zoh")
    _, x_ol, _ = scipy.signal.dlsim((*sysd[:4], path.dt), np.column_stack([u_ref, path.kappa]))
    return x_ol, u_ref


def _loop(path, overload, K, x_target, u_ff, x0, K_input=0.0, limit=truck.STEER_LIMIT):
    """x[k+1] = F x + G sat(K (x - x_target) + K_input alpha[k-1] + u_ff) + Gk kappa, one step at a time."""
    F, G, Gk = (a[0] for a in truck.discretise(overload))
    x = x_target[0] + np.asarray(x0, float)
    prev, errs = 0.0, []
    for k in range(path.T):
        e = x - x_target[k]
        errs.append(e)
        alpha = float(np.clip(K @ e + K_input * prev + u_ff[k], -limit, limit))
        x = F @ x + G[:, 0] * alpha + Gk * path.kappa[k]
        prev = alpha
    return np.array(errs)


@pytest.fixture(scope="module")
def K_authors():
    Q, R = AUTHORS.weights()
    return rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K


def test_authors_loop_equals_an_independent_loop(path, K_authors):
    """No feedforward, x_ref = [0, 0, rho_ol, theta_ol], x0 = [0, 0, 0.3, -0.1] (the authors' code)."""
    x_ol, _ = _reference(path)
    target = x_ol.copy()
    target[:, :2] = 0.0
    res = PathFollowing(path, OVERLOADS, setup=AUTHORS).run(K_authors)
    for s, ov in enumerate(OVERLOADS):
        e = _loop(path, ov, K_authors[0], target, np.zeros(path.T), morais2022.AUTHORS_X0)
        np.testing.assert_allclose(res.errors[0, s], e, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(res.mse()[0, s], (e**2).mean(axis=0)[list(truck.OBJECTIVE_STATES)], rtol=1e-9)
    assert res.saturated_steps.max() > 0            # the 0.3 m / -0.1 rad start saturates the steering


def test_the_default_setup_tracks_steady_cornering_with_feedforward(path):
    Q, R = DEFAULT_SETUP.weights()
    K = rc.lqr(truck.truck_plant(0.0), Q=Q, R=R).K
    a = PathFollowing(path, OVERLOADS).run(K)
    b = PathFollowing(path, OVERLOADS, setup=morais2022.SETUPS["ours"], feedforward=True,
                      x0=DEFAULT_INITIAL_ERROR).run(K)
    x_ref, a_ff = truck.reference_states(path.kappa)
    e = _loop(path, 200.0, K[0], x_ref, a_ff, DEFAULT_INITIAL_ERROR)
    np.testing.assert_array_equal(a.errors, b.errors)
    np.testing.assert_allclose(a.errors[0, 1], e, rtol=1e-9, atol=1e-12)


def test_open_loop_reference_with_its_command_as_feedforward_is_followed_exactly(path):
    """The open-loop reference is a nominal trajectory: zero gain plus its command follows it exactly."""
    x_ol, _ = _reference(path)
    res = simulate(np.zeros((1, 4)), path, 0.0, setup=AUTHORS, feedforward=True, x0=np.zeros(4))
    e = res.errors[0, 0]
    np.testing.assert_allclose(e[:, 2:], 0.0, atol=1e-12)               # rho, theta on the reference
    np.testing.assert_allclose(e[:, :2], x_ol[:, :2], rtol=1e-9, atol=1e-14)   # velocities regulated to zero


def test_input_memory_equals_an_independent_loop(path, K_authors):
    K_u = np.array([[0.4]])
    res = PathFollowing(path, OVERLOADS, setup=AUTHORS).run(K_authors, K_input=K_u)
    x_ol, _ = _reference(path)
    target = x_ol.copy()
    target[:, :2] = 0.0
    for s, ov in enumerate(OVERLOADS):
        e = _loop(path, ov, K_authors[0], target, np.zeros(path.T), morais2022.AUTHORS_X0, K_input=0.4)
        np.testing.assert_allclose(res.errors[0, s], e, rtol=1e-9, atol=1e-12)
    assert res.errors.shape[-1] == 4 and res.sq_error_sum.shape[-1] == 4
    np.testing.assert_allclose(res.steering[0, :, 1:], np.clip(
        np.einsum("sti,i->st", res.errors[0, :, 1:], K_authors[0]) + 0.4 * res.steering[0, :, :-1], -0.45, 0.45),
        rtol=1e-9, atol=1e-12)
    zero = PathFollowing(path, OVERLOADS, setup=AUTHORS).run(K_authors, K_input=np.zeros((1, 1)), backend="numpy")
    np.testing.assert_allclose(zero.errors, PathFollowing(path, OVERLOADS, setup=AUTHORS).run(K_authors).errors,
                               rtol=1e-9, atol=1e-12)


def test_input_memory_bad_arguments(path, K_authors):
    pf = PathFollowing(path, OVERLOADS, setup=AUTHORS)
    with pytest.raises(ValueError, match="K_input must have shape"):
        pf.run(K_authors, K_input=np.zeros((2, 1)))
    with pytest.raises(ValueError, match="K_input must have finite"):
        pf.run(K_authors, K_input=[[np.nan]])
    with pytest.raises(TypeError, match="K_input must"):
        pf.run(K_authors, K_input="0.1")
    flagged = pf.run(np.stack([K_authors, K_authors]), K_input=np.array([[[0.1]], [[np.nan]]]), nan_gains="flag")
    assert flagged.diverged[1].all() and not flagged.diverged[0].any()
    with pytest.raises(ValueError, match="no input_map"):
        PathFollowing(path, 0.0, input_map=truck.DOUBLED_INPUT_MAP).run(np.zeros((2, 4)), K_input=np.zeros((2, 1)))


def test_reference_pose(path, K_authors):
    res = PathFollowing(path, 0.0, setup=AUTHORS).run(K_authors)
    X, Y = res.reference_pose()
    x_ol, _ = _reference(path)
    np.testing.assert_allclose(X, path.X - x_ol[:, 2] * np.sin(path.heading), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(Y, path.Y + x_ol[:, 2] * np.cos(path.heading), rtol=1e-9, atol=1e-9)
    ours = PathFollowing(path, 0.0).run(K_authors)
    np.testing.assert_allclose(ours.reference_pose()[0], path.X, atol=1e-12)


def test_poses_without_a_path_name_it(path, K_authors):
    res = dataclasses.replace(PathFollowing(path, 0.0).run(K_authors), path=None)
    for pose in (res.reference_pose, res.pose):
        with pytest.raises(ValueError, match=r"no path \(path=None\)"):
            pose()


def test_open_loop_reference_drifts_on_the_default_route():
    """The documented drift of the open-loop reference over the 9 km route (about 22 m)."""
    x_ol, _ = truck.open_loop_reference(default_route().kappa)
    assert 15.0 < np.abs(x_ol[:, 2]).max() < 30.0


def test_the_default_setup_holds_the_documented_values():
    Q, R = truck.lqr_weights(doubled=True)
    np.testing.assert_array_equal(DEFAULT_SETUP.weights(doubled=True)[0], Q)
    np.testing.assert_array_equal(DEFAULT_SETUP.weights(doubled=True)[1], R)
    assert (DEFAULT_SETUP.reference, DEFAULT_SETUP.feedforward, DEFAULT_SETUP.x0) == ("steady", True,
                                                                                      DEFAULT_INITIAL_ERROR)


@pytest.mark.parametrize("setup", ["authors", 3])
def test_bad_setup(path, setup):
    with pytest.raises(TypeError, match=r"setup must be a PathFollowingSetup .*morais2022\.get_setup"):
        PathFollowing(path, 0.0, setup=setup)


@pytest.mark.parametrize("field, value, words", [
    ("reference", "closed", "reference must be one of"), ("feedforward", 1, "feedforward must be a bool"),
    ("x0", (0.0, 1.0), "x0 must have size 4"), ("x0", (0.0, 0.0, np.nan, 0.0), "x0 must have finite"),
    ("Q_diag", (1.0, 1.0, -1.0, 1.0), "Q_diag must be >= 0"), ("r", 0.0, "r must be > 0"),
    ("r", "1", "r must be"),
])
def test_bad_setup_fields(field, value, words):
    kwargs = dict(name="x", reference="steady", feedforward=True, x0=(0.0,) * 4, Q_diag=(1.0,) * 4, r=1.0)
    kwargs[field] = value
    with pytest.raises((ValueError, TypeError), match=words):
        PathFollowingSetup(**kwargs)
