"""paper_repro/mse_table.py end to end (short horizon, both set-ups), its outputs, and the paper's table as data."""

import csv
import itertools
import subprocess
import sys
from pathlib import Path

import control
import mse_table
import numpy as np
import pytest
from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS, PAPER_MSE, paper_winner
from truck_margins import truck_margins

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.path import default_route
from robustctl.models.pathfollow import simulate
from robustctl.synthesis.hinf_game import hinf_game

ROOT = Path(__file__).resolve().parents[1]


def _read(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """The engineering set-up ("ours")."""
    out = tmp_path_factory.mktemp("mse")
    assert mse_table.main(["--out", str(out), "--duration", "20", "--no-figures", "--setup", "ours",
                           "--no-margins"]) == 0
    return out


@pytest.fixture(scope="module")
def authors_run(tmp_path_factory):
    """The default: the authors' set-up."""
    out = tmp_path_factory.mktemp("mse_authors")
    assert mse_table.main(["--out", str(out), "--duration", "20", "--no-figures"]) == 0
    return out


def test_csv_has_all_64_finite_cells(short_run):
    rows = _read(short_run / "mse_table.csv")
    assert list(rows[0].keys()) == ["objective", "controller", "overload", "mse"]
    main = {(r["objective"], r["controller"], int(r["overload"])): float(r["mse"])
            for r in rows if r["controller"] in CONTROLLERS}
    assert len(main) == 64
    assert {k[0] for k in main} == set(OBJECTIVES)
    assert {k[2] for k in main} == set(OVERLOADS)
    assert all(np.isfinite(v) and v >= 0 for v in main.values())
    extras = {r["controller"] for r in rows} - set(CONTROLLERS)
    assert extras == {"Hinf_polytopic", "Hinf_unbounded", "RLQR_A_computed", "Hinf_robust", "RLQR_A_code_EG"}
    for name in ("mse_table.md", "mse_table.tex", "mse_table.txt", "designs.txt",
                 "mse_table_regulation.csv", "mse_table_regulation.md"):
        assert (short_run / name).stat().st_size > 0
    assert r"\begin{tabular}" in (short_run / "mse_table.tex").read_text()


def test_lqr_row_matches_an_independent_run(short_run):
    """Recompute the LQR cells with python-control's dlqr gain and a direct simulation."""
    Q, R = truck.lqr_weights()
    plant = truck.truck_plant(0.0)
    K = -control.dlqr(plant.F, plant.G, Q, R)[0]
    res = simulate(K, default_route(duration=20.0), [0.0, 100.0, 200.0, 300.0])
    rows = {(r["objective"], int(r["overload"])): float(r["mse"])
            for r in _read(short_run / "mse_table.csv") if r["controller"] == "LQR"}
    for j, obj in enumerate(OBJECTIVES):
        for s, ov in enumerate(OVERLOADS):
            assert rows[obj, ov] == pytest.approx(res.mse()[0, s, j], rel=1e-7)
    # the regulation table is the MSE of the states themselves
    reg = {(r["objective"], int(r["overload"])): float(r["mse"])
           for r in _read(short_run / "mse_table_regulation.csv") if r["controller"] == "LQR"}
    x = res.states[0]
    assert reg["f3", 300] == pytest.approx(np.mean(x[3, :, 0] ** 2), rel=1e-7)


@pytest.mark.parametrize("setup", ["ours", "authors"])
def test_designs_are_stabilising_at_nominal(short_run, setup):
    text = (short_run / "designs.txt").read_text()
    for name in CONTROLLERS:
        assert name + ":" in text
    designs = mse_table.design_controllers(controllers=list(CONTROLLERS), setup=setup)
    F, G, _ = truck.discretise(0.0)
    for d in designs:
        assert np.max(np.abs(np.linalg.eigvals(F[0] + G[0] @ d.K_steer))) < 1, d.name
    mop = next(d for d in designs if d.name == "RLQR_MOP")
    assert mop.K.shape == (2, 4)                    # doubled steering column


def test_paper_values_bold_entries():
    """The paper's bold (best) entries: H-inf wins f1 at 0-200 %, LQR at 300 %, RLQR_MOP the rest."""
    assert [paper_winner("f1", ov) for ov in OVERLOADS] == ["Hinf", "Hinf", "Hinf", "LQR"]
    for obj in ("f2", "f3", "f4"):
        assert {paper_winner(obj, ov) for ov in OVERLOADS} == {"RLQR_MOP"}
    assert PAPER_MSE["f1"]["Hinf"][0] == pytest.approx(8.3135e-4)
    assert all(len(v) == 4 for o in PAPER_MSE.values() for v in o.values())


def test_other_z_and_subset(tmp_path):
    z = [1.0, 50.0, 20.0, 400.0, 40.0, 45.0, 300.0]
    mse = mse_table.run(tmp_path, z=z, duration=10.0, figures=False, controllers=["RLQR_MOP", "LQR"],
                        with_margins=False, log=lambda *a: None)
    assert set(mse["f1"]) == {"RLQR_MOP", "LQR"}
    assert "z = [  1." in (tmp_path / "designs.txt").read_text()


@pytest.mark.parametrize("argv, match", [
    (["--controllers", "LQR", "PID"], "unknown controller"),
    (["--duration", "-5"], "duration"),
    (["--duration", "0.01"], "one sample step"),
    (["--z", "1", "1", "1", "1", "1", "1", "-2"], "log10 mu"),
])
def test_bad_arguments_exit_with_a_message(tmp_path, capsys, argv, match):
    with pytest.raises(SystemExit) as exc:
        mse_table.main(["--out", str(tmp_path), "--no-figures", *argv])
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


def test_unknown_controller_in_api():
    with pytest.raises(ValueError, match="valid: RLQR_MOP"):
        mse_table.design_controllers(controllers=["lqr"])
    with pytest.raises(ValueError, match="uncertainty"):
        mse_table.design_controllers(uncertainty="guess")
    with pytest.raises(ValueError, match="unknown setup"):
        mse_table.design_controllers(setup="theirs")
    with pytest.raises(ValueError, match="valid: RLQR_MOP"):          # no game row in our set-up
        mse_table.design_controllers(controllers=["Hinf_game"], setup="ours")


@pytest.mark.slow
def test_script_with_figures_as_a_subprocess(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "paper_repro" / "mse_table.py"), "--out", str(tmp_path),
                           "--duration", "15"], capture_output=True, text=True, timeout=300, cwd=ROOT, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "Best controller agrees with the paper" in proc.stdout
    assert "Agreement, set-up authors" in proc.stdout and "Agreement, set-up    ours" in proc.stdout
    for ov in OVERLOADS:
        for kind in ("response", "errors"):
            f = tmp_path / f"{kind}_{ov}.png"
            assert f.stat().st_size > 10_000


# -- the authors' set-up (the default) -------------------------------------------------------------
def test_authors_run_outputs_and_lqr_row(authors_run):
    rows = _read(authors_run / "mse_table.csv")
    assert {r["controller"] for r in rows} - set(CONTROLLERS) == {
        "RLQR_A_code_EG", "RLQR_A_computed", "Hinf_polytopic", "Hinf_robust", "Hinf_game"}
    Q, R = morais2022.authors_weights()
    plant = truck.truck_plant(0.0)
    K = -control.dlqr(plant.F, plant.G, Q, R)[0]
    res = simulate(K, default_route(duration=20.0), [0.0, 100.0, 200.0, 300.0],
                   setup=morais2022.SETUPS["authors"])
    lqr = {(r["objective"], int(r["overload"])): float(r["mse"]) for r in rows if r["controller"] == "LQR"}
    for j, obj in enumerate(OBJECTIVES):
        for s, ov in enumerate(OVERLOADS):
            assert lqr[obj, ov] == pytest.approx(res.mse()[0, s, j], rel=1e-7)
    text = (authors_run / "designs.txt").read_text()
    assert "set-up 'authors'" in text and "25000" in text and "barbosafilipe/robust_lqr" in text
    agreement = (authors_run / "agreement.md").read_text()
    assert "| authors |" in agreement and "| ours |" in agreement
    margins = (authors_run / "margins.md").read_text()
    for name in (*CONTROLLERS, "Hinf_game"):
        assert f"| {name} |" in margins
    assert (authors_run / "margins.csv").stat().st_size > 0


def test_authors_designs_use_the_codes_values():
    d = {x.name: x for x in mse_table.design_controllers(setup="authors")}
    Q, R = morais2022.authors_weights()
    plant = truck.truck_plant(0.0)
    np.testing.assert_allclose(d["LQR"].K, -control.dlqr(plant.F, plant.G, Q, R)[0], rtol=1e-8)
    g = hinf_game(plant, Bw=np.ones((4, 1)), Q=Q, R=R, gamma=14350.0, P_final=np.eye(4))
    np.testing.assert_array_equal(d["Hinf_game"].K, g.K_e)
    np.testing.assert_array_equal(d["Hinf_game"].K_input, g.K_u)
    assert "EG = [-0.0667 -0.0067]" in d["RLQR_A_code_EG"].note
    # the authors' H-infinity: Bw = H, the authors' Q and R, no bound; independent reference: the
    # game-Riccati bisection (hinf_riccati) on the same (scaled) channels gives the same optimal gain
    from robustctl.synthesis.hinf_riccati import hinf_riccati
    s = 1 / np.sqrt(R[0, 0])
    Cz, Dzu = rc.lq_output(Q, R)
    ref = hinf_riccati(plant, Bw=np.ones((4, 1)), Cz=s * Cz, Dzu=s * Dzu, rtol=1e-6)
    np.testing.assert_allclose(d["Hinf"].K, ref.K, rtol=2e-3)
    assert "no input bound" in d["Hinf"].note


def test_agreement_measures_on_known_tables():
    paper = {o: {c: np.array(PAPER_MSE[o][c]) for c in CONTROLLERS} for o in OBJECTIVES}
    a = mse_table.agreement(paper)
    assert (a.winners, a.pairs_agree, a.pairs) == (16, 96, 96)
    assert a.ratio_median == a.ratio_min == a.ratio_max == 1.0
    reversed_ = {o: {c: 1.0 / v for c, v in paper[o].items()} for o in OBJECTIVES}
    b = mse_table.agreement(reversed_)
    assert b.pairs_agree == 0 and b.winners == 0
    doubled = {o: {c: 2 * v if c == "LQR" else v for c, v in paper[o].items()} for o in OBJECTIVES}
    c = mse_table.agreement(doubled)
    assert c.ratio_max == 2.0 and c.ratio_median == 1.0
    # LQR doubled changes the order of exactly the pairs where LQR was below another controller by < 2x
    flips = sum(PAPER_MSE[o]["LQR"][i] < PAPER_MSE[o][k][i] < 2 * PAPER_MSE[o]["LQR"][i]
                for o in OBJECTIVES for i in range(4) for k in CONTROLLERS if k != "LQR")
    assert c.pairs_agree == 96 - flips


def test_printed_rlqr_a_is_forced_to_a_unit_eigenvalue_as_mu_grows():
    """Equal EG entries and mu -> inf: K1 + K2 -> -EF/EG, no rho feedback, an eigenvalue at exactly 1."""
    u = morais2022.algebraic_uncertainty("printed")
    assert u.EG[0, 0] == u.EG[0, 1] and u.EF[0, 2] == 0.0
    p = truck.truck_plant(0.0)
    K_lim = -u.EF / u.EG[0, 0]
    A = p.F + p.G @ K_lim
    np.testing.assert_array_equal(A[:, 2], [0.0, 0.0, 1.0, 0.0])       # the rho column stays a unit vector
    ev = np.linalg.eigvals(A)
    assert np.min(np.abs(ev - 1.0)) < 1e-12
    Q, R2 = truck.lqr_weights(doubled=True)
    dist = []
    for mu in (1e9, 1e12, 1e15, 1e18):
        K = rc.design("rlqr", truck.truck_plant(0.0, doubled=True), u.EF, u.EG, mu, Q=Q, R=R2,
                      H=np.ones((4, 1)), check_stability=False).K.sum(axis=0, keepdims=True)
        dist.append((np.abs(K - K_lim).max(), np.min(np.abs(np.linalg.eigvals(p.F + p.G @ K) - 1.0))))
    assert all(b[0] < a[0] and b[1] < a[1] for a, b in itertools.pairwise(dist))
    assert dist[-1][0] < 1e-3 and dist[-1][1] < 1e-5
    lim = mse_table.rlqr_a_limit(mse_table.TABLE_SETUPS["authors"])
    assert abs(lim["eig_nearest_1_limit"] - 1.0) < 1e-12
    # with the authors' R = 67070 I2, mu = 1e9 is far from the limit: real rho feedback, no unit eigenvalue
    assert lim["K_printed_mu"][0, 2] < -0.1 and abs(lim["eig_nearest_1_printed_mu"] - 1.0) > 0.05


def test_one_choice_at_a_time_switches_only_that_choice():
    ours, authors = mse_table.TABLE_SETUPS["ours"], mse_table.TABLE_SETUPS["authors"]
    fields = {"weights": {"Q_diag", "r"}, "loop": {"reference", "feedforward"}, "x0": {"x0"}}
    for choice, switch in mse_table.CHOICES.items():
        new = switch(ours, authors)
        changed_loop = {f for f in ("Q_diag", "r", "reference", "feedforward", "x0")
                        if getattr(new.loop, f) != getattr(ours.loop, f)}
        changed = {f for f in ("hinf", "rlqr_a_eg", "course") if getattr(new, f) != getattr(ours, f)}
        if choice in fields:
            assert changed_loop == fields[choice] and not changed
        else:
            assert not changed_loop and len(changed) == 1


def test_margins_of_a_design_match_the_analysis_engine():
    d = next(x for x in mse_table.design_controllers(setup="authors") if x.name == "LQR")
    m = truck_margins({d.name: d.law}).results[d.name]
    plant = truck.truck_plant(0.0)
    ref = rc.robust_stability((plant, d.K_steer), vertices=[truck.truck_plant(k) for k in (100.0, 200.0, 300.0)])
    assert m["polytope 0-300 %"].margin == pytest.approx(ref.margin, rel=1e-6)
    # the norm-bounded margin is the small-gain value 1 / ||E (zI - A)^-1 H||_inf (python-control's linfnorm)
    u = morais2022.algebraic_uncertainty("printed")
    A, E = plant.F + plant.G @ d.K_steer, u.EF + u.EG[:, :1] @ d.K_steer
    gain = control.linfnorm(control.ss(A, u.H, E, np.zeros((1, 1)), plant.dt))[0]
    assert m["appendix (printed)"].margin == pytest.approx(1.0 / gain, rel=1e-4)


def test_compare_setups_short(tmp_path):
    rows = mse_table.compare_setups(duration=5.0, log=lambda *a: None)
    assert [r[1] for r in rows[:7]] == ["(as is)", *mse_table.CHOICES]
    assert rows[-1][1] == "H-infinity = the code's game law"
    assert all(0 <= a.winners <= 16 and a.pairs == 96 for _, _, a in rows)
    mse_table.write_comparison(tmp_path, rows)
    assert "| ours | (as is) |" in (tmp_path / "setup_comparison.md").read_text()
