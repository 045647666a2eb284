"""A plant with one measured output, written outside the library, tuned through the public API and the CLI (issue 35).

The user module (written to ``tmp_path``, imported by a fresh interpreter
through ``PYTHONPATH``) is Franklin, Powell & Emami-Naeini's hovering
helicopter with only its pitch measured, a static output feedback and a PID
tuned on a pitch step. ``python -m moo run --problem helicopter:problem``
must give the run ``moo.tuning.tune`` gives with the same seed, and
``python -m moo select`` the controller ``TuningResult.select`` picks; the
chosen controller is checked against python-control's closed loop.
"""

from __future__ import annotations

import json
import os
import sys
import textwrap
from pathlib import Path

import control
import numpy as np
import pytest
from conftest import main_many

import robustctl as rc

REPO = Path(__file__).resolve().parents[1]

USER_MODULE = '''
"""Hovering helicopter (Franklin, Powell & Emami-Naeini, Feedback Control of Dynamic Systems): states
pitch rate q, pitch theta, horizontal velocity v; input the rotor tilt; only the pitch is measured."""
import numpy as np
import robustctl as rc
from moo import tuning

A = np.array([[-0.4, 0.0, -0.01], [1.0, 0.0, 0.0], [-1.4, 9.8, -0.02]])
B = np.array([[6.3], [0.0], [9.8]])
PLANT = rc.Plant.from_continuous(A, B, 0.05, C=[[0.0, 1.0, 0.0]])
SCENARIOS = [rc.Plant.from_continuous(A, B * s, 0.05) for s in (0.8, 1.0, 1.2)]   # the rotor's gain to 20 %


def _goals():
    step = tuning.StepTracking(200, signal=0, amplitude=0.1, width=1, n=3)
    return [step.error(), step.peak_input()]


def problem():
    prob = tuning.TuningProblem(tuning.StaticOutputFeedbackFamily(PLANT), SCENARIOS, _goals())
    prob.uncertainty = rc.NormBounded.from_plants(PLANT, SCENARIOS)     # select reports the certified margin
    return prob


def pid_problem():
    return tuning.TuningProblem(tuning.PIDFamily(PLANT), SCENARIOS, _goals())
'''

RUN = ["--algorithm", "nsga2", "--molsp", "--seed", "1", "--evals", "300", "--pop-size", "20"]


@pytest.fixture
def helicopter(tmp_path, monkeypatch):
    (tmp_path / "helicopter.py").write_text(textwrap.dedent(USER_MODULE))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]), OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("helicopter", None)
    import helicopter

    return tmp_path, env, helicopter


@pytest.mark.parametrize("factory", ["problem", "pid_problem"])
def test_a_plant_with_one_sensor_tuned_by_the_api_and_the_cli(helicopter, factory):
    from moo import tuning

    tmp, env, module = helicopter
    prob = getattr(module, factory)()
    res = tuning.tune(prob, "nsga2", molsp=True, evals=300, seed=1, pop_size=20)
    assert len(res.F) >= 1 and np.all(prob.penalty > res.F)
    assert isinstance(res.gains, rc.ControllerBatch) and len(res.gains) == len(res.F)
    sel = res.select(n_sims=100, seed=3)
    ctrl = sel.controller
    assert ctrl.is_dynamic and ctrl.order == (0 if factory == "problem" else 2)
    # python-control's closed loop of the chosen controller is stable on every scenario
    for scenario in module.SCENARIOS:
        P = control.ss(scenario.F, scenario.G, module.PLANT.C, 0, 0.05)
        assert np.abs(control.feedback(P, ctrl.controller_statespace(), sign=+1).poles()).max() < 1.0

    run = tmp / f"{factory}.json"
    results = main_many([
        ["run", "--problem", f"helicopter:{factory}", *RUN, "--out", str(run)],
        ["select", str(run), "--problem", f"helicopter:{factory}", "--n-sims", "100", "--seed", "3",
         "--out", str(tmp / "sel.json")],
    ], env, tmp)
    for code, err, _ in results:
        assert code == 0, err
    rec = json.loads(run.read_text())
    np.testing.assert_allclose(np.array(rec["X"]), res.X, rtol=0, atol=0)      # the same run
    assert rec["hv"] == pytest.approx(res.run.hv, rel=1e-12)
    chosen = json.loads((tmp / "sel.json").read_text())
    assert chosen["K"] is None and chosen["index"] == sel.index
    np.testing.assert_allclose(np.array(chosen["controller"]["Dc"]), ctrl.Dc, rtol=1e-12)
    assert "K(z): order" in results[1][2]
    if factory == "problem":
        assert chosen["margin"] == pytest.approx(rc.robust_stability(ctrl, prob.uncertainty).margin, rel=1e-12)
        assert "certified robust margin" in results[1][2]
