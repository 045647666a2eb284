"""paper_repro/mse_table.py end to end (short horizon), its outputs, and the paper's table as data."""

import csv
import subprocess
import sys
from pathlib import Path

import control
import numpy as np
import pytest

from paper_repro import mse_table
from paper_repro.paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS, PAPER_MSE, paper_winner
from robustctl.models import truck
from robustctl.path import default_route
from robustctl.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]


def _read(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("mse")
    assert mse_table.main(["--out", str(out), "--duration", "20", "--no-figures"]) == 0
    return out


def test_csv_has_all_64_finite_cells(short_run):
    rows = _read(short_run / "mse_table.csv")
    assert list(rows[0].keys()) == ["objective", "controller", "overload", "mse"]
    main = {(r["objective"], r["controller"], int(r["overload"])): float(r["mse"])
            for r in rows if r["controller"] in CONTROLLERS}
    assert len(main) == 64
    assert set(k[0] for k in main) == set(OBJECTIVES)
    assert set(k[2] for k in main) == set(OVERLOADS)
    assert all(np.isfinite(v) and v >= 0 for v in main.values())
    extras = {r["controller"] for r in rows} - set(CONTROLLERS)
    assert extras == {"Hinf_polytopic", "Hinf_unbounded", "RLQR_A_computed"}
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


def test_designs_are_stabilising_at_nominal(short_run):
    text = (short_run / "designs.txt").read_text()
    for name in CONTROLLERS:
        assert name + ":" in text
    designs = mse_table.design_controllers(controllers=list(CONTROLLERS))
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
                        log=lambda *a: None)
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
        mse_table.main(["--out", str(tmp_path), "--no-figures"] + argv)
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


def test_unknown_controller_in_api():
    with pytest.raises(ValueError, match="valid: RLQR_MOP"):
        mse_table.design_controllers(controllers=["lqr"])
    with pytest.raises(ValueError, match="uncertainty"):
        mse_table.design_controllers(uncertainty="guess")


@pytest.mark.slow
def test_script_with_figures_as_a_subprocess(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "paper_repro" / "mse_table.py"), "--out", str(tmp_path),
                           "--duration", "15"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert "Best controller agrees with the paper" in proc.stdout
    for ov in OVERLOADS:
        for kind in ("response", "errors"):
            f = tmp_path / f"{kind}_{ov}.png"
            assert f.stat().st_size > 10_000
