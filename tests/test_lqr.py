"""LQR against python-control (slycot) and the Riccati residual."""

import control
import numpy as np
import pytest
import scipy.linalg
from conftest import random_plant

import robustctl as rc
from robustctl.synthesis.lqr import dare


@pytest.mark.parametrize("seed", range(5))
def test_lqr_equals_minus_dlqr(seed):
    rng = np.random.default_rng(seed)
    n, m = rng.integers(1, 6), rng.integers(1, 4)
    plant = random_plant(rng, n, m, scale=1.5)
    X = rng.standard_normal((n, n))
    Q = X @ X.T + 0.1 * np.eye(n)
    R = np.diag(rng.uniform(0.5, 2.0, m))
    c = rc.design("lqr", plant, Q=Q, R=R)
    K_pc, S_pc, _ = control.dlqr(plant.F, plant.G, Q, R)
    np.testing.assert_allclose(c.K, -K_pc, atol=1e-8, rtol=0)
    np.testing.assert_allclose(c.info["P"], S_pc, rtol=1e-8)
    assert c.info["residual"] < 1e-10
    assert c.is_stabilizing()


def test_dare_scipy_fallback_matches(monkeypatch):
    pytest.importorskip("slycot")  # the optional robustctl[slycot] extra (make test installs it)
    rng = np.random.default_rng(3)
    plant = random_plant(rng, 4, 2, scale=1.5)
    P_sly, backend = dare(plant.F, plant.G, np.eye(4), np.eye(2))
    assert backend == "slycot"

    def broken(*a, **k):
        raise RuntimeError("slycot unavailable")

    monkeypatch.setattr(control, "dare", broken)
    P_sci, backend = dare(plant.F, plant.G, np.eye(4), np.eye(2))
    assert backend == "scipy"
    np.testing.assert_allclose(P_sci, P_sly, rtol=1e-9)


def test_unstabilisable_plant_raises():
    plant = rc.Plant(np.diag([2.0, 0.5]), np.array([[0.0], [1.0]]), 0.1)  # unstable mode not controllable
    with pytest.raises(rc.ConvergenceError, match="stabilisable"):
        rc.design("lqr", plant)


@pytest.mark.parametrize(
    "kw,err,match",
    [
        ({"Q": np.array([[1.0, 2.0], [0.0, 1.0]])}, ValueError, "Q must be symmetric"),
        ({"Q": -np.eye(2)}, ValueError, "Q must be positive semidefinite"),
        ({"R": np.zeros((1, 1))}, ValueError, "R must be positive definite"),
        ({"R": np.eye(2)}, ValueError, r"R must have 1 rows"),
        ({"Q": np.full((2, 2), np.inf)}, ValueError, "Q must have finite entries"),
    ],
)
def test_lqr_bad_weights(kw, err, match):
    plant = rc.Plant(np.eye(2) * 0.9, np.ones((2, 1)), 0.1)
    with pytest.raises(err, match=match):
        rc.design("lqr", plant, **kw)


def test_continuous_lqr_against_python_control():
    A, B = np.array([[0.0, 1.0], [2.0, -0.5]]), np.array([[0.0], [1.0]])
    Q, R = np.diag([3.0, 0.2]), np.array([[0.5]])
    ctrl = rc.lqr(rc.Plant(A, B, None), Q=Q, R=R)
    K_pc, P_pc, _ = control.lqr(A, B, Q, R)
    np.testing.assert_allclose(ctrl.K, -K_pc, rtol=1e-10)
    np.testing.assert_allclose(ctrl.info["P"], P_pc, rtol=1e-10)
    assert ctrl.is_stabilizing() and ctrl.info["residual"] < 1e-12
    with pytest.raises(rc.ConvergenceError, match="continuous Riccati equation"):   # an undamped mode not weighted
        rc.lqr(rc.Plant([[0.0, 1.0], [-1.0, 0.0]], [[0.0], [1.0]], None), Q=np.zeros((2, 2)))


_WITHOUT_SLYCOT = r'''
import importlib.abc, json, sys

class _Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == "slycot" or name.startswith("slycot."):
            raise ImportError("slycot hidden for this test")

sys.meta_path.insert(0, _Hide())
for mod in [m for m in sys.modules if m == "slycot" or m.startswith("slycot.")]:
    del sys.modules[mod]
import numpy as np
import robustctl as rc
from robustctl.synthesis.hinf_riccati import hinf_riccati

try:
    import slycot  # noqa: F401
    hidden = False
except ImportError:
    hidden = True
case = json.loads(sys.argv[1])
plant = rc.Plant(case["F"], case["G"], 0.1)
lqr = rc.lqr(plant, Q=np.eye(plant.n), R=np.eye(plant.m))
Bw, Cz, Dzu = (np.array(case[k]) for k in ("Bw", "Cz", "Dzu"))
h = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
ref = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
A, C = plant.F + plant.G @ h.K, Cz + Dzu @ h.K
peak = max(np.linalg.svd(C @ np.linalg.solve(np.exp(1j * w) * np.eye(plant.n) - A, Bw), compute_uv=False)[0]
           for w in np.linspace(0, np.pi, 4001))
print(json.dumps({"hidden": hidden, "backend": lqr.info["backend"], "K": lqr.K.tolist(),
                  "residual": lqr.info["residual"], "gamma": h.gamma, "gamma_opt": h.gamma_opt,
                  "gamma_riccati": float(ref.gamma), "peak": float(peak)}))
'''


def test_lqr_and_hinf_work_with_slycot_hidden():
    """slycot is an optional extra (GPL-2.0): with it hidden, lqr falls back to scipy's DARE and hinf to no
    balancing; the results match slycot's LQR (this process) and the game-Riccati bisection (scipy)."""
    import json
    import subprocess
    import sys

    rng = np.random.default_rng(8)
    plant = random_plant(rng, 3, 1, scale=1.3)
    case = {"F": plant.F.tolist(), "G": plant.G.tolist(), "Bw": rng.standard_normal((3, 1)).tolist(),
            "Cz": np.vstack([np.eye(3), np.zeros((1, 3))]).tolist(), "Dzu": [[0.0], [0.0], [0.0], [1.0]]}
    run = subprocess.run([sys.executable, "-c", _WITHOUT_SLYCOT, json.dumps(case)], capture_output=True,
                         text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["hidden"] and out["backend"] == "scipy" and out["residual"] < 1e-10
    K_pc = -control.dlqr(plant.F, plant.G, np.eye(3), np.eye(1))[0]    # slycot in this process
    np.testing.assert_allclose(out["K"], K_pc, atol=1e-8)
    assert abs(out["gamma_opt"] - out["gamma_riccati"]) <= 1e-5 * out["gamma_riccati"]
    assert out["gamma_opt"] * (1 - 1e-3) <= out["peak"] <= out["gamma"] * (1 + 1e-9)


@pytest.mark.parametrize("F,G,Q", [
    (np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]]), np.diag([0.0, 1.0])),  # position left out
    (np.array([[1.0]]), np.array([[1.0]]), np.zeros((1, 1))),                                # Q = 0
    (np.array([[0.0, 1.0], [-1.0, 0.0]]), np.array([[0.0], [1.0]]), np.zeros((2, 2))),        # lambda = +-1j
])
def test_lqr_unweighted_mode_on_unit_circle_raises(F, G, Q):
    """(Q^1/2, F) with an unobservable mode on the unit circle: no stabilising DARE solution exists
    (Lancaster & Rodman, Thm 13.1.3); both backends return P with rho(F + G K) = 1, which is refused."""
    plant = rc.Plant(F, G, 0.1)
    with pytest.raises(rc.ConvergenceError, match=r"not detectable on the unit circle: the mode lambda = "):
        rc.lqr(plant, Q=Q)


def test_lqr_unweighted_unstable_mode_is_fine():
    """Only the unit circle matters: an unweighted mode at |lambda| = 2 is still stabilised (mirrored)."""
    F, G, Q = np.diag([2.0, 0.5]), np.array([[1.0], [1.0]]), np.diag([0.0, 1.0])
    c = rc.lqr(rc.Plant(F, G, 0.1), Q=Q)
    np.testing.assert_allclose(c.K, -control.dlqr(F, G, Q, np.eye(1))[0], atol=1e-10)
    assert c.is_stabilizing()


@pytest.mark.parametrize("seed", [1, 3, 4])
def test_lqr_input_scaled_1e8_matches_dlqr(seed):
    """G x 1e8: both backends' P miss 1e-8 relative to max(1, ||P||) (the old test); relative to the
    equation's terms, after a Newton refinement, they pass and the gain equals control.dlqr's."""
    plant = random_plant(np.random.default_rng(seed), 4, 2, scale=1.5)
    G = plant.G * 1e8
    c = rc.lqr(rc.Plant(plant.F, G, 0.1))
    K_pc = -control.dlqr(plant.F, G, np.eye(4), np.eye(2))[0]
    np.testing.assert_allclose(c.K, K_pc, rtol=1e-6, atol=1e-6 * np.abs(K_pc).max())
    assert c.info["residual"] < 1e-8 and c.is_stabilizing()


@pytest.mark.parametrize("spread", [4, 8])
def test_lqr_state_units_1e_spread(spread):
    """States in units 1e-spread..1e+spread (x_s = T x): the same problem, so K_s = K T^-1, checked against
    scipy.linalg.solve_discrete_are; slycot warns (spread 4: SlycotResultWarning, raised by python-control)
    or fails (8), and the PBH test on the unbalanced F refused the plant."""
    plant = random_plant(np.random.default_rng(0), 4, 1, scale=1.5)
    t = np.logspace(-spread, spread, 4)
    F, G, Q = plant.F * t[:, None] / t[None, :], plant.G * t[:, None], np.diag(t ** -2.0)
    c = rc.lqr(rc.Plant(F, G, 0.1), Q=Q)
    P = scipy.linalg.solve_discrete_are(F, G, Q, np.eye(1))
    K_ref = -np.linalg.solve(np.eye(1) + G.T @ P @ G, G.T @ P @ F)
    np.testing.assert_allclose(c.K, K_ref, rtol=1e-6)
    K0 = -control.dlqr(plant.F, plant.G, np.eye(4), np.eye(1))[0]                  # unscaled problem
    np.testing.assert_allclose(c.K, K0 / t[None, :], rtol=1e-6)
    assert c.info["backend"] == "scipy" and c.info["residual"] < 1e-8


def test_dare_slycot_warning_falls_back(monkeypatch):
    """A backend that raises a warning class (python-control turns SlycotResultWarning into an exception) hands
    over to scipy instead of escaping."""
    plant = random_plant(np.random.default_rng(2), 3, 1)

    class ResultWarning(UserWarning):
        pass

    def warns(*a, **k):
        raise ResultWarning("solution may be inaccurate")

    monkeypatch.setattr(control, "dare", warns)
    P, backend = dare(plant.F, plant.G)
    assert backend == "scipy"
    np.testing.assert_allclose(P, scipy.linalg.solve_discrete_are(plant.F, plant.G, np.eye(3), np.eye(1)),
                               rtol=1e-10)
