"""margins_report's loop margins: each controller's loop rebuilt by hand with python-control (a gain, a law with
input memory on the plant augmented by the previous input, an output feedback), and the writers."""

from __future__ import annotations

import csv
import io

import control
import numpy as np
import pytest
from scipy.optimize import brentq

import robustctl as rc
from robustctl.models.truck import truck_plant


@pytest.fixture(scope="module")
def setup():
    plant = truck_plant(0.0)
    K = rc.lqr(plant).K
    Ku = np.array([[0.3]])
    C = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    oplant = rc.Plant(plant.F, plant.G, plant.dt, C=C)
    Lk = control.dlqr(plant.F.T, C.T, np.eye(4), np.eye(2))[0].T       # an observer: xh+ = F xh + G u + Lk (y - C xh)
    observer = rc.Controller.dynamic(plant.F + plant.G @ K - Lk @ C, Lk, K, np.zeros((1, 2)), "observer", oplant)
    laws = {"LQR": K, "memory": rc.InputMemoryFeedback(K, Ku), "observer": observer, "unstable": -K}
    unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    return plant, K, Ku, observer, rc.margins_report(oplant, laws, {"steering": unc})


def grid_phase_margin(L) -> float:
    """The phase margin from python-control's frequency response alone: every sign change of |L| - 1 on a
    200001-point grid up to the Nyquist frequency, refined by brentq, the one smallest in absolute value.
    (control.stability_margins is off here: for the law with input memory it reports 39.33 degrees at a frequency
    where |L| = 0.998 and the phase gives 39.10.)"""
    def gain(w):
        return np.abs(L(np.exp(1j * w * L.dt))) - 1.0

    w = np.linspace(1e-6, np.pi / L.dt, 200001)
    g = gain(w)
    roots = [brentq(gain, w[i], w[i + 1], xtol=1e-15) for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
    pms = [np.remainder(np.angle(L(np.exp(1j * r * L.dt)), deg=True), 360.0) - 180.0 for r in roots]
    return min(pms, key=abs)


def test_loops_match_loops_built_by_hand(setup):
    plant, K, Ku, observer, rep = setup
    dt = plant.dt
    # u = K x: L = -K (zI - F)^-1 G; with input memory the state is [x; u_prev]: Fa = [[F, 0], [0, 0]], Ga = [G; I]
    Fa = np.block([[plant.F, np.zeros((4, 1))], [np.zeros((1, 5))]])
    Ga = np.vstack([plant.G, np.eye(1)])
    P = control.ss(plant.F, plant.G, observer.plant.C, 0, dt)
    by_hand = {"LQR": control.ss(plant.F, plant.G, -K, 0, dt),
               "memory": control.ss(Fa, Ga, -np.hstack([K, Ku]), 0, dt),
               "observer": -(observer.controller_statespace() * P)}
    for name, L in by_hand.items():
        lm = rep.loops[name]
        assert lm.reason == "ok" and lm.at == "input"
        assert lm.phase_margin == pytest.approx(grid_phase_margin(L), rel=1e-9), name
        assert float(control.disk_margins(L, np.array([lm.alpha_freq]))[0]) == pytest.approx(lm.alpha, rel=1e-8)
    assert rep.loops["unstable"].reason == "unstable" and rep.loops["unstable"].alpha == 0.0


def test_writers(setup, tmp_path):
    *_, rep = setup
    text = rep.to_text()
    assert "Certified robust-stability margins" in text and "Loop margins at the plant input" in text
    md = rep.loops_to_markdown().splitlines()
    assert md[0].startswith("| controller | disk margin | disk gains |") and len(md) == 2 + 4
    written = rep.loops_to_csv(tmp_path / "loops.csv")
    assert (tmp_path / "loops.csv").read_bytes().decode() == written
    rows = {r["controller"]: r for r in csv.DictReader(io.StringIO(written))}
    lm = rep.loops["LQR"]
    assert float(rows["LQR"]["disk_margin"]) == pytest.approx(lm.alpha, rel=1e-5)
    assert float(rows["LQR"]["disk_gain_max"]) == pytest.approx(lm.gain_range[1], rel=1e-5)
    assert float(rows["LQR"]["phase_margin_deg"]) == pytest.approx(lm.phase_margin, rel=1e-5)
    assert float(rows["unstable"]["disk_margin"]) == 0.0
    # the robust-stability table is unchanged by the loop margins
    assert rep.to_markdown().splitlines()[0] == "| controller | steering |"
