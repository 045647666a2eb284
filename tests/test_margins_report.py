"""robustctl.margins_report: margins against python-control's H-infinity norm and the LMI certificates' residuals."""

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.analysis import MarginsReport, margins_report
from robustctl.models.truck import truck_plant


@pytest.fixture(scope="module")
def report():
    plant = truck_plant(0.0)
    unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    K = rc.lqr(plant).K
    laws = {"LQR": K, "memory": rc.InputMemoryFeedback(K, [[0.3]]), "ctrl": rc.lqr(plant)}
    models = {"payload": [truck_plant(300.0)], "steering": unc}
    return plant, unc, K, margins_report(plant, laws, models)


def _small_gain(A, H, E, dt):
    return 1.0 / control.linfnorm(control.ss(A, H, E, np.zeros((E.shape[0], H.shape[1])), dt))[0]


def test_norm_bounded_margins_are_the_small_gain_values(report):
    plant, unc, K, rep = report
    assert isinstance(rep, MarginsReport) and rep is not None
    assert rep.controllers == ("LQR", "memory", "ctrl") and rep.models == ("payload", "steering")
    A, E = plant.F + plant.G @ K, unc.EF + unc.EG @ K
    assert rep.margin[0, 1] == pytest.approx(_small_gain(A, unc.H, E, plant.dt), rel=1e-4)
    assert rep.margin[2, 1] == rep.margin[0, 1]                        # a Controller is its gain
    # the law with input memory, closed loop built by hand on [x; u_prev] (u_prev known exactly)
    Ku = np.array([[0.3]])
    Aa = np.block([[plant.F + plant.G @ K, plant.G @ Ku], [K, Ku]])
    Ha, Ea = np.vstack([unc.H, [[0.0]]]), np.hstack([unc.EF + unc.EG @ K, unc.EG @ Ku])
    assert rep.margin[1, 1] == pytest.approx(_small_gain(Aa, Ha, Ea, plant.dt), rel=1e-4)


def test_polytope_certificate_holds_at_every_vertex(report):
    """The returned P makes A_i' P A_i - P negative definite at the nominal and the 300 % vertex."""
    plant, _, K, rep = report
    res = rep.results["LQR"]["payload"]
    assert res.certified == bool(rep.certified[0, 0]) and rep.margin[0, 0] >= 1
    for p in (plant, truck_plant(300.0)):
        A = p.F + p.G @ K
        assert np.linalg.eigvalsh(A.T @ res.P @ A - res.P).max() < 0
    assert np.linalg.eigvalsh(res.P).min() > 0


def test_writers(report, tmp_path):
    *_, rep = report
    text = rep.to_csv(tmp_path / "m.csv")
    raw = (tmp_path / "m.csv").read_bytes()
    assert raw.decode() == text and raw.startswith(b"controller,uncertainty,margin,certified\r\n")
    assert len(text.splitlines()) == 1 + 3 * 2
    md = rep.to_markdown().splitlines()
    assert md[0] == "| controller | payload | steering |" and md[1] == "|---|---:|---:|"
    assert md[2].startswith("| LQR | ") and "(certified)" in md[2]
    assert rep.to_text().splitlines()[1].startswith("controller")
    assert "MarginsReport(controllers=3" in repr(rep)


def test_failed_analysis_is_reported_not_raised():
    plant = truck_plant(0.0)
    other_dt = rc.Plant(truck_plant(300.0).F, truck_plant(300.0).G, dt=0.2)
    rep = margins_report(plant, {"LQR": rc.lqr(plant).K}, {"bad": [other_dt]})
    assert rep.results["LQR"]["bad"].startswith("n/a (")
    assert np.isnan(rep.margin[0, 0]) and not rep.certified[0, 0]
    assert rep.to_csv().splitlines()[1] == "LQR,bad,,"


def test_bad_arguments():
    plant = truck_plant(0.0)
    K = rc.lqr(plant).K
    with pytest.raises(TypeError, match="models\\['x'\\] must be a NormBounded"):
        margins_report(plant, {"LQR": K}, {"x": "polytope"})
    with pytest.raises(TypeError, match="controllers must be"):
        margins_report(plant, {}, {"x": [truck_plant(300.0)]})
    with pytest.raises(ValueError, match="controllers\\['LQR'\\]"):
        margins_report(plant, {"LQR": [[np.nan] * 4]}, {"x": [truck_plant(300.0)]})
    with pytest.raises(TypeError, match="plant"):
        margins_report(K, {"LQR": K}, {"x": [truck_plant(300.0)]})
