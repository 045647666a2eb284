"""H2 state feedback by LMI (robustctl.h2) against the Riccati-based optimum and python-control.

References: for one plant the H2-optimal state feedback is the LQR with
Q = Cz'Cz, R = Dzu'Dzu, N = Cz'Dzu, whose cost from x0 = Bw e_i sums to
trace(Bw' P Bw) (scipy's solve_discrete_are / solve_continuous_are), plus
trace(Dzw'Dzw) in discrete time; the gain itself is python-control's
dlqr / lqr (u = -K_pc x); the H2 norm of every closed loop is
python-control's norm(sys, 2).
"""

from __future__ import annotations

import importlib

import control
import numpy as np
import pytest
import scipy.linalg
from test_hinf import MSD_BW, MSD_CZ, MSD_DZU, msd, random_case
from test_regions import closed_form

import robustctl as rc
from robustctl import Disk, HalfPlane, InfeasibleError, Plant


def h2_norm(plant, K, Bw, Cz, Dzu, Dzw=None) -> float:
    D = np.zeros((Cz.shape[0], Bw.shape[1])) if Dzw is None else Dzw
    return float(control.norm(control.ss(plant.F + plant.G @ K, Bw, Cz + Dzu @ K, D,
                                         plant.dt if plant.is_discrete else 0), 2))


def riccati_optimum(plant, Bw, Cz, Dzu, Dzw=None):
    Q, R, N = Cz.T @ Cz, Dzu.T @ Dzu, Cz.T @ Dzu
    if plant.is_discrete:
        P = scipy.linalg.solve_discrete_are(plant.F, plant.G, Q, R, s=N)
        K_pc = control.dlqr(plant.F, plant.G, Q, R, N)[0]
    else:
        P = scipy.linalg.solve_continuous_are(plant.F, plant.G, Q, R, s=N)
        K_pc = control.lqr(plant.F, plant.G, Q, R, N)[0]
    extra = 0.0 if Dzw is None else float(np.sum(Dzw**2))
    return float(np.sqrt(np.trace(Bw.T @ P @ Bw) + extra)), -np.asarray(K_pc)


@pytest.mark.parametrize("discrete", [True, False])
@pytest.mark.parametrize("seed", [0, 1, 2, 5])
def test_optimum_equals_the_riccati_h2_optimum(seed, discrete):
    n, m, q = (4, 2, 2) if seed != 5 else (6, 2, 3)
    plant, Bw, Cz, Dzu, Dzw = random_case(seed, n, m, q, discrete, cross=True)
    Dzw = Dzw if discrete else None
    ref, K_ref = riccati_optimum(plant, Bw, Cz, Dzu, Dzw)
    ctrl = rc.design("h2", plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    assert ctrl.h2_opt == pytest.approx(ref, rel=1e-6)
    assert ctrl.h2_bound == pytest.approx(1.001 * ctrl.h2_opt, rel=1e-12)
    norm = h2_norm(plant, ctrl.K, Bw, Cz, Dzu, Dzw)
    assert ref * (1 - 1e-9) <= norm <= ctrl.h2_bound            # no gain beats the optimum; the guarantee
    assert ctrl.info["h2_norms"][0] == pytest.approx(norm, rel=1e-8)
    at_opt = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw, backoff=0)
    assert np.allclose(at_opt.K, K_ref, rtol=1e-3, atol=1e-3 * np.abs(K_ref).max())   # the LQR gain
    assert h2_norm(plant, at_opt.K, Bw, Cz, Dzu, Dzw) == pytest.approx(ref, rel=1e-6)


def test_polytopic_bound_holds_on_a_mass_grid():
    ctrl = rc.h2(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)])
    for mass in np.linspace(1.0, 4.0, 13):
        assert h2_norm(msd(mass), ctrl.K, MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.h2_bound
    own = max(riccati_optimum(msd(mm), MSD_BW, MSD_CZ, MSD_DZU)[0] for mm in (1.0, 4.0))
    assert ctrl.h2_opt >= own * (1 - 1e-6)
    assert len(ctrl.info["h2_norms"]) == 2


@pytest.mark.parametrize("discrete,regions", [
    (True, Disk(0.0, 0.3)), (True, Disk(0.5, 0.3)), (True, [Disk(0.0, 0.5), HalfPlane(0.1, "right")]),
    (True, Disk(0.9, 0.05)), (False, HalfPlane(-3.0)), (False, [HalfPlane(-1.0), rc.ConicSector(0.0, 0.4)])],
    ids=repr)
def test_poles_lie_in_the_region(discrete, regions):
    plant, Bw, Cz, Dzu, _ = random_case(1 if discrete else 3, 4, 2, 2, discrete)
    free = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    ctrl = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, poles=regions)
    poles = ctrl.closed_loop_poles()
    regions = regions if isinstance(regions, list) else [regions]
    assert all(np.all(closed_form(r, poles)) for r in regions)
    assert not all(np.all(closed_form(r, free.closed_loop_poles())) for r in regions)   # the region binds
    assert ctrl.h2_opt >= free.h2_opt * (1 - 1e-6)
    assert h2_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.h2_bound


def test_unreachable_regions_and_bad_input():
    plant = Plant(np.diag([0.5, 0.2]), [[0.0], [1.0]], 0.1)
    kw = dict(Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]])
    with pytest.raises(InfeasibleError, match=r"mode lambda = 0\.5.*outside the pole region"):
        rc.h2(plant, **kw, poles=Disk(0.0, 0.3))
    with pytest.raises(InfeasibleError, match="no point in common"):
        rc.h2(plant, **kw, poles=Disk(-3.0, 1.0))
    with pytest.raises(InfeasibleError, match="not stabilisable"):
        rc.h2(Plant(np.diag([1.5, 0.2]), [[0.0], [1.0]], 0.1), **kw)
    cont = Plant(-np.eye(2), [[0.0], [1.0]], None)
    with pytest.raises(ValueError, match="Dzw must be zero for a continuous-time plant"):
        rc.h2(cont, **kw, Dzw=np.ones((3, 2)))
    with pytest.raises(ValueError, match="backoff must be"):
        rc.h2(plant, **kw, backoff=-1)
    with pytest.raises(TypeError, match=r"plant must be a robustctl\.Plant"):
        rc.h2(np.eye(2), **kw)
    with pytest.raises(ValueError, match=r"Bw must have 2 rows"):
        rc.h2(plant, **{**kw, "Bw": np.ones((3, 1))})


def test_controller_type_and_dispatch():
    plant, Bw, Cz, Dzu, _ = random_case(0, 3, 1, 1, discrete=True)
    ctrl = rc.design("h2", plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert isinstance(ctrl, rc.H2Controller) and ctrl.method == "h2" and ctrl.is_stabilizing()
    assert "h2_bound=" in repr(ctrl) and ctrl.info["backoff"] == 1e-3
    assert rc.h2 is importlib.import_module("robustctl.synthesis.h2").h2


def test_tiny_backoff_is_raised_or_reported():
    """Near the accuracy of h2_opt the centring fails; the backoff is raised (x10, x100) before giving up."""
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    with pytest.raises((rc.ConvergenceError, InfeasibleError), match=r"\(1 \+ 1e-12\) h2_opt; increase backoff"):
        rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, backoff=1e-14)
    ctrl = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, backoff=1e-8)
    assert ctrl.info["backoff"] in (1e-8, 1e-7, 1e-6) and len(ctrl.info["solves"]) >= 2
    assert ctrl.h2_bound == pytest.approx((1 + ctrl.info["backoff"]) * ctrl.h2_opt, rel=1e-12)
    assert h2_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.h2_bound * (1 + 1e-9)


def test_internal_norm_check(monkeypatch):
    h2_module = importlib.import_module("robustctl.synthesis.h2")
    monkeypatch.setattr(h2_module, "_h2_norm", lambda *a: 1e9)
    plant, Bw, Cz, Dzu, _ = random_case(0, 3, 1, 1, discrete=True)
    with pytest.raises(rc.ConvergenceError, match=r"closed-loop H2 norms .* exceed the guaranteed"):
        rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)


def test_failed_centring_solve_raises_the_backoff(monkeypatch):
    from robustctl import _cvx

    real, calls = _cvx.solve_sdp, []

    def first_centring_fails(objective, *args, **kwargs):
        calls.append(type(objective).__name__)
        if calls == ["Minimize", "Maximize"]:
            raise rc.ConvergenceError("injected")
        return real(objective, *args, **kwargs)

    monkeypatch.setattr(_cvx, "solve_sdp", first_centring_fails)
    plant, Bw, Cz, Dzu, _ = random_case(0, 3, 1, 1, discrete=True)
    ctrl = rc.h2(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert calls == ["Minimize", "Maximize", "Maximize"] and ctrl.info["backoff"] == pytest.approx(1e-2)
    assert h2_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.h2_bound
