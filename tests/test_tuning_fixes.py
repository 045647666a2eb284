"""Regressions of issue 35 item 4: faults found in the tuning API, the CLI and the store, one test each."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys

import numpy as np
import pytest

import robustctl as rc
from moo import tuning
from moo.__main__ import main

PLANT = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
SCENARIOS = [rc.Plant(PLANT.F * s, PLANT.G, dt=0.1) for s in (0.95, 1.0, 1.05)]
RUN = ["run", "--problem", "zdt1", "--algorithm", "nsga2", "--seed", "0", "--evals", "40", "--pop-size", "20"]


def effort(K, plants):
    return np.abs(K).sum(axis=(1, 2))


def peak(K, plants):
    return np.abs(K).max(axis=(1, 2))


# -- the uncertainty's time domain ----------------------------------------------------------
def test_norm_bounded_from_plants_records_the_domain_and_refuses_another():
    unc = rc.NormBounded.from_plants(SCENARIOS[1], SCENARIOS)
    assert unc.domain == 0.1
    continuous = rc.Plant([[-1.0, 1.0], [0.0, -2.0]], [[0.0], [1.0]], dt=None)
    with pytest.raises(ValueError, match=r"uncertainty is for discrete-time plants with dt=0\.1.*continuous"):
        rc.robust_stability((continuous, np.zeros((1, 2))), unc)
    with pytest.raises(ValueError, match=r"uncertainty is for discrete-time plants with dt=0\.1.*dt=0\.2"):
        rc.robust_stability((rc.Plant(PLANT.F, PLANT.G, dt=0.2), np.zeros((2, 1, 2))), unc)
    slower = rc.Plant(PLANT.F, PLANT.G, dt=0.2)
    with pytest.raises(ValueError, match=r"uncertainty does not fit the plants: .*dt=0\.1.*plant has dt=0\.2"):
        tuning.RobustMargin(unc).check([slower])
    fitted_c = rc.NormBounded.from_plants(continuous, [rc.Plant(continuous.F * 1.1, continuous.G, dt=None)])
    assert fitted_c.domain == "continuous"
    with pytest.raises(ValueError, match="uncertainty is for continuous-time plants"):
        rc.robust_stability((PLANT, np.zeros((1, 2))), fitted_c)
    # a hand-built model is unchecked, as before; an explicit domain is checked
    hand = rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    assert hand.domain is None and np.isfinite(rc.robust_stability((continuous, np.zeros((1, 2))), hand).margin)
    with pytest.raises(ValueError, match="domain must be None, 'continuous' or a positive sampling time"):
        rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]], domain=-1.0)
    assert "domain=0.1" in repr(unc)


# -- plants of another sampling time or size ---------------------------------------------------
def test_family_of_another_sampling_time_is_refused_by_name():
    with pytest.raises(ValueError, match=r"family\.plant has dt=0\.2 but the scenarios have dt=0\.1"):
        tuning.TuningProblem(tuning.LQRFamily(rc.Plant(PLANT.F, PLANT.G, dt=0.2)), SCENARIOS, [effort])


def test_sampler_of_another_sampling_time_or_size_is_refused_by_name():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, peak], hv_ref_point=[100, 100])
    K = prob.gains(np.zeros((1, 3))).K
    other_dt = rc.Plant(PLANT.F, PLANT.G, dt=0.2)
    with pytest.raises(ValueError, match=r"sampler returned a plant with dt=0\.2; the scenarios have dt=0\.1"):
        tuning.select(prob, K, n_sims=3, sampler=lambda rng: other_dt)
    bigger = rc.Plant(np.eye(3) * 0.5, np.ones((3, 1)), dt=0.1)
    with pytest.raises(ValueError, match=r"sampler returned a plant with n=3 states and m=1 inputs; the scenarios"):
        tuning.select(prob, K, n_sims=3, sampler=lambda rng: bigger)


# -- weights that underflow --------------------------------------------------------------------
def test_lqr_weights_that_underflow_are_flagged_not_raised():
    fam = tuning.LQRFamily(PLANT)
    g = fam.gains(np.array([[0.0, 0.0, 0.0], [-400.0, -400.0, -400.0], [0.0, 0.0, -400.0]]))
    assert g.ok.tolist() == [True, False, False]
    assert np.all(np.isnan(g.K[1:])) and g.reason[1] != ""
    _, _, ok = tuning.dlqr_gains(PLANT.F, PLANT.G, np.stack([np.eye(2), 1e-400 * np.eye(2)]),
                                 np.stack([np.eye(1), 1e-400 * np.eye(1)]))
    assert ok.tolist() == [True, False]
    prob = tuning.TuningProblem(fam, SCENARIOS, [effort], xl=-400, xu=4, hv_ref_point=[100])
    F = prob.evaluate(np.array([[0.0, 0.0, 0.0], [-400.0, -400.0, -400.0]]))
    assert F[0, 0] < 100 and F[1, 0] == 2 * prob.penalty


# -- selection -----------------------------------------------------------------------------------
def test_select_never_picks_a_design_that_destabilises_a_scenario():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, peak], hv_ref_point=[100, 100])
    good = prob.gains(np.zeros((1, 3))).K[0]
    # a small gain: stable on the first scenario, unstable on the other two, and the cheapest there
    weak = np.array([[-0.76, 0.13]])
    stable, _ = prob.stability(np.stack([good, weak]))
    assert stable[0].all() and stable[1].tolist() == [True, False, False]
    assert effort(weak[None], SCENARIOS)[0] < effort(good[None], SCENARIOS)[0]
    sel = tuning.select(prob, np.stack([weak, good]), n_sims=50, seed=0)
    assert sel.index == 1 and sel.counts[0] == 0
    with pytest.raises(ValueError, match="no candidate stabilises every scenario"):
        tuning.select(prob, weak[None], n_sims=5, seed=0)


def test_select_refuses_all_zero_weights():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, peak], hv_ref_point=[100, 100])
    K = prob.gains(np.zeros((2, 3))).K
    with pytest.raises(ValueError, match="weights must not all be zero"):
        tuning.select(prob, K, n_sims=5, weights=[0, 0])


# -- what goals may do to what they are given ---------------------------------------------------------
def test_goals_get_read_only_copies():
    seen = []

    def popper(K, plants):
        plants.pop()
        return effort(K, plants)

    def zeroer(K, plants):
        K[:] = 0.0
        return effort(K, plants)

    def record(K, plants):
        seen.append((len(plants), float(np.abs(K).sum())))
        return effort(K, plants)

    for bad in (popper, zeroer):
        prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [bad, record], hv_ref_point=[100, 100])
        with pytest.raises((AttributeError, ValueError)):
            prob.evaluate(np.zeros((2, 3)))
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [record, record], hv_ref_point=[100, 100])
    prob.evaluate(np.zeros((2, 3)))
    assert seen[-1][0] == seen[-2][0] == 3 and seen[-1][1] == seen[-2][1] > 0
    assert len(prob.scenarios) == 3


@pytest.mark.parametrize(("value", "what"), [(lambda K: effort(K, None) + 1j, "complex"),
                                             (lambda K: np.array(["1.5"] * len(K)), "str")])
def test_complex_or_string_goal_values_are_refused(value, what):
    def goal(K, plants):
        return value(K)

    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [goal, peak], hv_ref_point=[100, 100])
    with pytest.raises(ValueError, match=rf"goal 'goal' must return real numbers.*got .*{what}"):
        prob.evaluate(np.zeros((2, 3)))


# -- argument checks at the call ---------------------------------------------------------------------------
def test_rlqr_family_refuses_an_unstabilisable_plant():
    unstabilisable = rc.Plant([[1.5, 0.0], [0.0, 0.5]], [[0.0], [1.0]], dt=0.1)
    with pytest.raises(ValueError, match=r"plant must be stabilisable .* for RLQRFamily"):
        tuning.RLQRFamily(unstabilisable)


def test_tune_progress_and_plot_x0_are_checked_by_name():
    prob = tuning.TuningProblem(tuning.LQRFamily(PLANT), SCENARIOS, [effort, peak], hv_ref_point=[100, 100])
    with pytest.raises(TypeError, match="progress must be a bool or a callable"):
        tuning.tune(prob, evals=40, pop_size=20, progress=3)
    res = tuning.tune(prob, evals=40, pop_size=20)
    with pytest.raises(ValueError, match=r"x0 must have 2 entries \(the number of states\), got shape \(3,\)"):
        res.plot(x0=[1.0, 2.0, 3.0])


# -- the CLI's outputs --------------------------------------------------------------------------------------
def test_out_through_a_symbolic_link_keeps_the_link(tmp_path):
    target = tmp_path / "records" / "run.json"
    target.parent.mkdir()
    target.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    assert main([*RUN, "--out", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert json.loads(target.read_text())["problem"] == "zdt1"


def _device(path, minor):
    try:
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
    except (PermissionError, OSError) as exc:
        pytest.skip(f"cannot create a device node here ({exc})")


def test_out_onto_a_device_writes_through_never_replaces_it(tmp_path, capsys):
    full, null = tmp_path / "full", tmp_path / "null"
    _device(full, 7)                               # a copy of /dev/full: every write fails with ENOSPC
    _device(null, 3)                               # a copy of /dev/null
    monkey_tmp = tmp_path / "spare"
    monkey_tmp.mkdir()
    code = main([*RUN, "--out", str(full)])
    err = capsys.readouterr().err
    assert code == 1 and f"cannot write {full} (No space left on device)" in err
    assert stat.S_ISCHR(os.stat(full).st_mode)
    assert main([*RUN, "--out", str(null)]) == 0
    assert stat.S_ISCHR(os.stat(null).st_mode)


def test_out_to_the_standard_output_prints_the_record(tmp_path):
    # /dev/stdout's own structure (a link to /proc/self/fd/1, a pipe here) in a directory of the test's: a regression
    # replaces this link, never the system's /dev/stdout
    stdout = tmp_path / "stdout"
    stdout.symlink_to("/proc/self/fd/1")
    proc = subprocess.run([sys.executable, "-m", "moo", *RUN, "--out", str(stdout)],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["problem"] == "zdt1"
    assert stdout.is_symlink()


def test_settings_mismatch_on_resume_names_the_flag(tmp_path, capsys):
    out = tmp_path / "res"
    base = ["experiment", "--problem", "zdt1", "--algorithms", "nsga2", "--runs", "1", "--pop-size", "20",
            "--out", str(out)]
    assert main([*base, "--evals", "40"]) == 0
    capsys.readouterr()
    assert main([*base, "--evals", "60"]) == 2
    err = capsys.readouterr().err
    assert "--evals 40 (this grid: 60)" in err and "budget" not in err
