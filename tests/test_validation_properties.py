"""Property-based checks: any malformed input gives ValueError/TypeError naming the argument,
never a NaN, a hang or an exception from deep inside numpy."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robustctl as rc

dims = st.integers(1, 4)
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(n=dims, m=dims, rows_G=dims, cols_F=dims, dt=st.one_of(st.floats(-1.0, 1.0), st.just(np.nan)))
def test_plant_shapes_and_dt(n, m, rows_G, cols_F, dt):
    F, G = np.zeros((n, cols_F)), np.zeros((rows_G, m))
    valid = cols_F == n and rows_G == n and dt > 0
    if valid:
        p = rc.Plant(F, G, dt)
        assert (p.n, p.m) == (n, m)
    else:
        with pytest.raises(ValueError, match=r"^(F|G|dt) "):
            rc.Plant(F, G, dt)


@SETTINGS
@given(l=dims, cols_EF=dims, rows_EG=dims, cols_EG=dims)
def test_rlqr_shape_errors_name_the_argument(l, cols_EF, rows_EG, cols_EG):
    plant = rc.Plant(0.5 * np.eye(3), np.ones((3, 2)), 0.1)
    EF, EG = np.ones((l, cols_EF)), np.ones((rows_EG, cols_EG))
    if cols_EF == 3 and rows_EG == l and cols_EG == 2:
        assert np.isfinite(rc.rlqr(plant, EF, EG, 10.0).K).all()
    else:
        with pytest.raises(ValueError, match=r"^(EF|EG) must have"):
            rc.rlqr(plant, EF, EG, 10.0)


@SETTINGS
@given(mu=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5)),
       alpha=st.floats(-1.0, 2.0, allow_nan=False))
def test_rlqr_scalars(mu, alpha):
    plant = rc.Plant(0.5 * np.eye(2), np.eye(2), 0.1)
    EF, EG = np.array([[0.3, 0.1]]), np.array([[1.0, 0.5]])
    bad_mu = not (mu >= 1e-100)  # NaN, 0, negative, or below the documented floor
    if bad_mu or alpha <= 0:
        with pytest.raises(ValueError, match=r"^(mu|alpha) "):
            rc.rlqr(plant, EF, EG, mu, alpha=alpha)
    else:
        try:
            c = rc.rlqr(plant, EF, EG, mu, alpha=alpha)
        except rc.ConvergenceError:
            return  # a clear, named failure is acceptable; silent NaN is not
        assert np.isfinite(c.K).all()


@SETTINGS
@given(where=st.sampled_from(["F", "G", "EF", "EG", "Q", "R", "H"]),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_non_finite_entries_are_named(where, value):
    data = {"F": 0.5 * np.eye(2), "G": np.eye(2), "EF": np.array([[0.3, 0.1]]),
            "EG": np.array([[1.0, 0.5]]), "Q": np.eye(2), "R": np.eye(2), "H": np.ones((2, 1))}
    data[where] = data[where].copy()
    data[where][0, 0] = value
    with pytest.raises(ValueError, match=rf"^{where} must have finite entries"):
        plant = rc.Plant(data["F"], data["G"], 0.1)
        rc.rlqr(plant, data["EF"], data["EG"], 10.0, Q=data["Q"], R=data["R"], H=data["H"])


@SETTINGS
@given(B=st.integers(1, 5), seed=st.integers(0, 10_000))
def test_batch_never_returns_unflagged_nan(B, seed):
    rng = np.random.default_rng(seed)
    plant = rc.Plant(rng.standard_normal((3, 3)), rng.standard_normal((3, 1)), 0.1)
    EF = rng.uniform(0, 500, (B, 1, 3))
    EG = rng.uniform(0, 500, (B, 1, 1)) * rng.integers(0, 2, (B, 1, 1))
    mu = 10 ** np.sqrt(rng.uniform(0, 500, B))
    mu[rng.random(B) < 0.3] = np.inf
    b = rc.rlqr_gains(plant, EF, EG, mu)
    assert np.isfinite(b.K[b.ok]).all() and np.isfinite(b.P[b.ok]).all()
    assert np.isnan(b.K[~b.ok]).all()
    assert set(b.reason) <= {"ok", "rank", "diverged", "not converged"}
