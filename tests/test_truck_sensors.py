"""The truck with sensors (issue 33 item 6): the data-sheet noise levels, the sensor plant, and the loop on an
estimate (PathFollowing.run_estimated) against a step-by-step numpy loop of the estimator's equations,
Estimator.step, the loop on the true state, and the Lyapunov covariance of the estimation error."""

import numpy as np
import pytest
import scipy.linalg
from scipy import signal, stats

import robustctl as rc
from robustctl.models import truck
from robustctl.models.path import ReferencePath
from robustctl.models.pathfollow import DEFAULT_SETUP, PathFollowing

DT = 0.1
SENSORS = truck.TruckSensors()
V = SENSORS.covariance(DT)
G0 = truck.truck_plant(0.0).G
Q, R = truck.lqr_weights()


def _kalman(form="filter", N=None):
    return rc.kalman(truck.sensor_plant(0.0), [[0.01]], V, Bw=G0, form=form, N=N)


def _robust(form="filter"):
    au = truck.algebraic_uncertainty()                          # the appendix's rule on the model
    return rc.robust_kalman(truck.sensor_plant(0.0), [[0.01]], V, Bw=G0, H=au.H, EF=au.EF, EG=au.EG[:, :1],
                            mu=1e4, form=form)


def _gains():
    """Three stabilising steering gains: the LQR, and LQRs of heavier and lighter weights on rho."""
    plant = truck.truck_plant(0.0)
    return np.stack([rc.lqr(plant, Q=Q * np.diag([1, 1, s, 1]), R=R).K for s in (1.0, 4.0, 0.25)])


def _path(T=300):
    """A bend that turns left and right (curvature up to 1/250 m)."""
    return ReferencePath.from_curvature(np.sin(np.linspace(0, 3 * np.pi, T)) / 250.0)


# -- sensors ---------------------------------------------------------------------------------------------------
def test_position_and_heading_sigmas_give_the_data_sheet_medians_by_monte_carlo():
    _, s_rho, s_theta = SENSORS.std(DT)
    rng = np.random.default_rng(0)
    xy = rng.normal(scale=s_rho, size=(200_000, 2))              # a circular normal horizontal error
    assert np.median(np.hypot(xy[:, 0], xy[:, 1])) == pytest.approx(SENSORS.position_cep, rel=0.01)
    heading = rng.normal(scale=s_theta, size=200_000)
    assert np.degrees(np.median(np.abs(heading))) == pytest.approx(SENSORS.heading_error_50, rel=0.01)
    assert stats.rayleigh.median(scale=s_rho) == pytest.approx(0.02)          # 0.01 m + 1 ppm at 10 km (ZED-F9P)
    assert np.degrees(stats.halfnorm.median(scale=s_theta)) == pytest.approx(0.4)    # ZED-F9H, 1 m baseline


def test_gyro_sigma_is_white_noise_of_the_density_averaged_over_a_sample():
    # white rate noise at 2 kHz whose one-sided density (scipy's Welch estimate) is the data sheet's N, averaged
    # over each 0.1 s sample
    N, fs = SENSORS.gyro_noise_density, 2000.0
    fast = np.random.default_rng(1).normal(scale=N * np.sqrt(fs / 2), size=(20_000, int(fs * DT)))
    _, psd = signal.welch(fast[:200].ravel(), fs=fs, nperseg=4096)
    assert np.sqrt(psd.mean()) == pytest.approx(N, rel=0.02)
    assert np.radians(fast.mean(axis=1).std()) == pytest.approx(SENSORS.std(DT)[0], rel=0.02)


def test_sensor_covariance_is_the_diagonal_of_the_squares_and_levels_are_configurable():
    assert np.allclose(V, np.diag(SENSORS.std(DT) ** 2))
    coarse = truck.TruckSensors(position_cep=0.2)
    assert coarse.std(DT)[1] == pytest.approx(10 * SENSORS.std(DT)[1])
    for name, bad in (("position_cep", 0.0), ("heading_error_50", -0.4), ("gyro_noise_density", np.inf)):
        with pytest.raises(ValueError, match=name):
            truck.TruckSensors(**{name: bad})
    with pytest.raises(ValueError, match="dt"):
        SENSORS.covariance(0.0)


def test_sensor_plant_measures_yaw_rate_displacement_and_heading_and_is_observable():
    plant = truck.sensor_plant(200.0)
    x = np.array([0.3, -0.05, 1.2, 0.02])
    assert np.allclose(plant.C @ x, x[[1, 2, 3]])
    assert [truck.STATE_NAMES[i] for i in truck.SENSOR_OUTPUTS] == list(truck.SENSOR_NAMES)
    ref = truck.truck_plant(200.0)
    assert np.array_equal(plant.F, ref.F) and np.array_equal(plant.G, ref.G) and not plant.D.any()
    assert plant.is_detectable
    assert np.linalg.matrix_rank(np.vstack([plant.C @ np.linalg.matrix_power(plant.F, k) for k in range(4)])) == 4


# -- the loop on an estimate ---------------------------------------------------------------------------------
def reference_loop(K, est, overloads, path, v, *, x0=DEFAULT_SETUP.x0, xhat0=None):
    """The estimator's equations step by step (numpy, every gain, overload and draw at once), engineering set-up.

    Truck: x+ = F_s x + G_s alpha + E_s kappa; sensors y = C x + v; estimator on its own model with the nominal
    curvature input; alpha = sat(K (xhat - x_ref) + alpha_ff). Returns the errors x - x_ref (B, S, N, T, 4) and
    the estimates xhat - x_ref.
    """
    C = est.plant.C
    kappa = path.kappa
    T = kappa.size
    F, G, E = truck.discretise(overloads)
    E0 = truck.discretise(0.0)[2][0]
    x_ref, a_ff = truck.reference_states(kappa, 0.0)
    B, S, N = K.shape[0], len(overloads), v.shape[0]
    x = np.broadcast_to(x_ref[0] + np.asarray(x0), (B, S, N, 4)).copy()
    if xhat0 is None:
        xp = x_ref[0] + (x - x_ref[0] + np.zeros(4)) @ C.T @ np.linalg.pinv(C).T + v[:, 0] @ np.linalg.pinv(C).T
    else:
        xp = np.broadcast_to(x_ref[0] + np.asarray(xhat0), x.shape).copy()
    errors, estimates = np.empty((T, B, S, N, 4)), np.empty((T, B, S, N, 4))
    for k in range(T):
        y = x @ C.T + v[:, k]
        e = y - xp @ C.T
        xf = xp + e @ est.L_filter.T
        xhat = xf if est.form == "filter" else xp
        alpha = np.clip(np.einsum("bj,bsnj->bsn", K[:, 0], xhat - x_ref[k]) + a_ff[k], -truck.STEER_LIMIT,
                        truck.STEER_LIMIT)
        errors[k], estimates[k] = x - x_ref[k], xhat - x_ref[k]
        x = (np.einsum("sij,bsnj->bsni", F, x) + G[None, :, None, :, 0] * alpha[..., None]
             + E[None, :, None] * kappa[k])
        xp = xf @ est.F.T + alpha[..., None] * est.G[:, 0] + e @ est.J.T + E0 * kappa[k]
    return np.moveaxis(errors, 0, 3), np.moveaxis(estimates, 0, 3)


def _as_draws(res, B, S, N):
    """(B, S N, T, 4) -> (B, S, N, T, 4)."""
    return res.reshape(B, S, N, *res.shape[2:])


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("make", [_kalman, lambda: _kalman("predictor"), _robust,
                                  lambda: _robust("predictor"),
                                  lambda: _kalman(N=np.array([[1e-5, 2e-4, 0.0]]))],
                         ids=["kalman", "kalman-predictor", "robust", "robust-predictor", "kalman-cross-N"])
def test_run_estimated_matches_the_step_by_step_loop(make, backend):
    est = make()
    K = _gains()
    overloads = [0.0, 150.0, 300.0]
    path = _path()
    v = np.random.default_rng(2).standard_normal((2, path.T, 3)) @ np.sqrt(V)
    E, Xh = reference_loop(K, est, overloads, path, v)
    res = PathFollowing(path, overloads).run_estimated(K, est, noise=v, backend=backend)
    assert res.draws == 2 and res.form == est.form and res.errors.shape == (3, 6, path.T, 4)
    scale = np.abs(E).max()
    assert np.abs(_as_draws(res.errors, 3, 3, 2) - E).max() <= 1e-10 * scale
    assert np.abs(_as_draws(res.estimates, 3, 3, 2) - Xh).max() <= 1e-10 * scale
    assert np.allclose(res.mse_by_draw(), (E**2).mean(axis=3)[..., list(truck.OBJECTIVE_STATES)], rtol=1e-9)


def test_run_estimated_matches_a_hand_written_loop_with_estimator_step():
    est = _robust()
    K = _gains()[:1]
    path = _path(40)
    F, G, E = (a[0] for a in truck.discretise(200.0))
    E0 = truck.discretise(0.0)[2][0]
    x_ref, a_ff = truck.reference_states(path.kappa, 0.0)
    v = np.random.default_rng(3).standard_normal((path.T, 3)) @ np.sqrt(V)
    xhat0 = np.array([0.1, 0.0, 0.8, 0.01])
    x, xhat = x_ref[0] + np.asarray(DEFAULT_SETUP.x0), x_ref[0] + xhat0
    errors = []
    for k in range(path.T):
        y = est.plant.C @ x + v[k]
        _, x_filtered = est.step(xhat, np.zeros(1), y)             # D = 0: x[k|k] does not need alpha[k]
        alpha = np.clip(K[0] @ (x_filtered - x_ref[k]) + a_ff[k], -truck.STEER_LIMIT, truck.STEER_LIMIT)
        xhat = est.step(xhat, alpha, y)[0] + E0 * path.kappa[k]
        errors.append(x - x_ref[k])
        x = F @ x + G @ alpha + E * path.kappa[k]
    res = PathFollowing(path, 200.0).run_estimated(K, est, noise=v, xhat0=xhat0)
    assert np.allclose(res.errors[0, 0], np.array(errors), rtol=0, atol=1e-12)


@pytest.mark.parametrize("form", ["filter", "predictor"])
def test_noiseless_kalman_started_at_the_true_state_tracks_as_the_full_state_loop(form):
    path = _path(600)
    K = _gains()
    runs = PathFollowing(path, [0.0, 0.0])
    exact = runs.run(K)
    sensed = runs.run_estimated(K, _kalman(form), V=np.zeros((3, 3)), xhat0=DEFAULT_SETUP.x0)
    scale = np.abs(exact.errors).max()
    assert np.abs(sensed.errors - exact.errors).max() <= 1e-12 * scale
    assert np.abs(sensed.estimation_errors).max() <= 1e-12 * scale
    assert np.allclose(sensed.mse(), exact.mse(), rtol=1e-12, atol=0)


def test_estimation_error_covariance_matches_the_lyapunov_solution():
    # nominal truck, no process noise: e_p+ = (F - Lp C) e_p - Lp v and e_f = (I - Lf C) e_p - Lf v
    est = _kalman()
    plant = est.plant
    A = plant.F - est.L_predictor @ plant.C
    P_prior = scipy.linalg.solve_discrete_lyapunov(A, est.L_predictor @ V @ est.L_predictor.T)
    ILC = np.eye(4) - est.L_filter @ plant.C
    P_filt = ILC @ P_prior @ ILC.T + est.L_filter @ V @ est.L_filter.T
    res = PathFollowing(ReferencePath.straight(60.0), 0.0).run_estimated(_gains()[:1], est, draws=2000, rng=4)
    e = res.estimation_errors[0, :, 200:]                       # (draws, steps, 4), after the start
    cov = np.einsum("dki,dkj->ij", e, e) / (e.shape[0] * e.shape[1])
    assert np.allclose(np.diag(cov), np.diag(P_filt), rtol=0.02)
    assert abs(cov[2, 3] / np.sqrt(cov[2, 2] * cov[3, 3]) - P_filt[2, 3] / np.sqrt(P_filt[2, 2] * P_filt[3, 3])) < 0.02


def test_draws_share_their_noise_across_overloads_and_a_seed_repeats_a_run():
    runs = PathFollowing(_path(), [0.0, 0.0])
    a = runs.run_estimated(_gains(), _kalman(), draws=3, rng=5)
    b = runs.run_estimated(_gains(), _kalman(), draws=3, rng=5)
    assert np.array_equal(a.errors, b.errors)
    assert np.array_equal(a.errors[:, :3], a.errors[:, 3:])     # same overload, same draws: same runs
    assert not np.array_equal(a.errors[:, 0], a.errors[:, 1])   # two draws differ
    assert a.overloads == (0.0,) * 6


def test_time_varying_overload_constant_in_time_equals_the_constant_overload():
    path = _path()
    v = np.random.default_rng(6).standard_normal((1, path.T, 3)) @ np.sqrt(V)
    const = PathFollowing(path, [100.0]).run_estimated(_gains(), _robust(), noise=v)
    varying = PathFollowing(path, [np.full(path.T, 100.0)]).run_estimated(_gains(), _robust(), noise=v)
    assert np.allclose(varying.errors, const.errors, rtol=0, atol=1e-12)


def test_doubled_column_gains_need_the_input_map_and_match_their_steering_sum():
    K2 = np.concatenate([_gains()[:, :, :] * 0.3, _gains() * 0.7], axis=1)        # u1 + u2 = K
    v = np.zeros((1, _path().T, 3))
    with pytest.raises(ValueError, match="input_map"):
        PathFollowing(_path(), 0.0).run_estimated(K2, _kalman(), noise=v)
    doubled = PathFollowing(_path(), 0.0, input_map=truck.DOUBLED_INPUT_MAP).run_estimated(K2, _kalman(), noise=v)
    single = PathFollowing(_path(), 0.0).run_estimated(_gains(), _kalman(), noise=v)
    assert np.allclose(doubled.errors, single.errors, rtol=0, atol=1e-12)


def test_failed_gains_are_flagged_per_design():
    K = _gains()
    K[1, 0, 0] = np.nan
    res = PathFollowing(_path(), 0.0).run_estimated(K, _kalman(), draws=1, rng=0, nan_gains="flag",
                                                    keep_trajectories=False)
    assert res.diverged[:, 0].tolist() == [False, True, False] and res.errors is None and res.estimates is None


def test_bad_arguments_are_named():
    runs = PathFollowing(_path(), 0.0)
    K, est = _gains(), _kalman()
    T = runs.T
    with pytest.raises(TypeError, match="estimator must be a robustctl Estimator"):
        runs.run_estimated(K, "kalman")
    doubled = rc.kalman(rc.Plant(truck.truck_plant(0.0, doubled=True).F, truck.truck_plant(0.0, doubled=True).G,
                                 DT, C=truck.sensor_plant(0.0).C), [[0.01]], V, Bw=G0)
    with pytest.raises(ValueError, match="one steering input"):
        runs.run_estimated(K, doubled)
    slow = rc.kalman(rc.Plant.from_continuous(*truck.continuous_model(0.0)[:2], 0.2, C=truck.sensor_plant(0.0).C),
                     [[0.01]], V, Bw=np.eye(4)[:, :1])
    with pytest.raises(ValueError, match=r"dt = 0\.1"):
        runs.run_estimated(K, slow)
    with pytest.raises(ValueError, match=r"noise must have shape \(300, 3\)"):
        runs.run_estimated(K, est, noise=np.zeros((T, 2)))
    with pytest.raises(ValueError, match="finite"):
        runs.run_estimated(K, est, noise=np.full((T, 3), np.nan))
    with pytest.raises(ValueError, match="not both"):
        runs.run_estimated(K, est, noise=np.zeros((T, 3)), rng=0)
    with pytest.raises(ValueError, match="V must have 3 rows"):
        runs.run_estimated(K, est, V=np.eye(2))
    with pytest.raises(ValueError, match="V"):
        runs.run_estimated(K, est, V=-np.eye(3))
    with pytest.raises(ValueError, match="draws"):
        runs.run_estimated(K, est, draws=0)
    with pytest.raises(ValueError, match="xhat0"):
        runs.run_estimated(K, est, xhat0=[0.0, 1.0])
    with pytest.raises(ValueError, match="4 columns"):
        runs.run_estimated(np.ones((1, 3)), est)


# -- the paper's table with sensors (paper_repro/mse_table_sensors.py) ----------------------------------------
def test_script_writes_the_table_beside_the_full_state_one(tmp_path):
    import csv

    import mse_table
    import mse_table_sensors
    from mse_designs import get_table_setup
    from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS

    assert mse_table_sensors.main(["--out", str(tmp_path), "--duration", "20", "--draws", "2",
                                   "--no-figures"]) == 0
    rows = list(csv.DictReader((tmp_path / "mse_sensors.csv").open()))
    assert len(rows) == len(mse_table_sensors.ESTIMATORS) * len(CONTROLLERS) * len(OBJECTIVES) * len(OVERLOADS)
    full = mse_table.table_for(get_table_setup("authors"), duration=20)
    for r in rows:
        assert np.isfinite(float(r["mse"])) and float(r["mse"]) >= 0
        if r["estimator"] == "full_state":                   # mse_table.py's numbers, to the digits written
            assert float(r["mse"]) == pytest.approx(full[r["objective"]][r["controller"]][
                OVERLOADS.index(int(r["overload"]))], rel=1e-10)
        else:
            assert r["draws"] == "2"
    mu = list(csv.DictReader((tmp_path / "mse_sensors_mu.csv").open()))
    chosen = [r for r in mu if r["chosen"] == "True"]
    assert len(mu) == 10 and len(chosen) == 1
    assert float(chosen[0]["worst_spectral_radius"]) == min(float(r["worst_spectral_radius"]) for r in mu)
    assert "robust_paper_mu" in (tmp_path / "mse_sensors.md").read_text()
    radius = {(r["estimator"], r["controller"], int(r["overload"])): float(r["spectral_radius"])
              for r in csv.DictReader((tmp_path / "mse_sensors_radius.csv").open())}
    K = rc.lqr(truck.truck_plant(0.0), Q=np.diag([1.0, 1.0, 25000.0, 100.0]), R=[[33535.0]]).K   # the LQR row
    p300 = truck.truck_plant(300.0)
    assert radius["full_state", "LQR", 300] == pytest.approx(np.abs(np.linalg.eigvals(p300.F + p300.G @ K)).max(),
                                                             rel=1e-6)


def test_docs_render_the_committed_result_files():
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("papertables", root / "docs" / "_ext" / "papertables.py")
    papertables = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(papertables)
    results = root / "paper_repro" / "results"
    tables = papertables.sensor_tables(results / "mse_sensors.csv")
    assert list(tables) == ["f1", "f2", "f3", "f4"]
    assert all(text.count("   * - ") == 1 + 16 for text in tables.values())     # header + 4 controllers x 4
    assert papertables.mu_table(results / "mse_sensors_mu.csv").count("yes") == 1
    assert papertables.radius_table(results / "mse_sensors_radius.csv").count("   * - ") == 1 + 16
