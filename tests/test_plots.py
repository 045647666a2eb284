"""moo.plots: the numbers behind the figures (step-function HV, median run, CD cliques) and the files written."""

from __future__ import annotations

import numpy as np
import pytest

from moo.__main__ import main
from moo.experiment import run_experiment
from moo.plots import _cliques, _hv_on_grid, _median_run, cd_diagram, check_formats, plot_results
from moo.stats import FriedmanResult
from moo.store import load_records


def test_hv_history_is_read_as_a_step_function():
    rec = {"hv_history": {"evaluations": [10, 20, 35], "hypervolume": [0.1, 0.5, 0.7]}}
    H = _hv_on_grid([rec], np.array([0.0, 9.9, 10.0, 19.0, 20.0, 34.0, 35.0, 99.0]))
    assert np.isnan(H[0, :2]).all()                            # before the first generation: no value
    assert H[0, 2:].tolist() == [0.1, 0.1, 0.5, 0.5, 0.7, 0.7]


def test_median_run_and_cliques():
    recs = [{"hv": v, "seed": s} for s, v in enumerate([0.3, 0.1, 0.9, 0.5])]
    assert _median_run(recs)["hv"] == 0.3 and _median_run(recs[:3])["hv"] == 0.3 and _median_run([]) is None
    # Demsar's example at alpha 0.10 (CD 1.12): sorted ranks 1.964, 2.000, 2.893, 3.143
    # (C4.5+m+cf, C4.5+m, C4.5+cf) and (C4.5+cf, C4.5): C4.5 differs from the first two, as Demsar finds
    assert _cliques(np.array([1.964, 2.000, 2.893, 3.143]), 1.12) == [(0, 2), (2, 3)]
    assert _cliques(np.array([1.0, 3.0, 5.0]), 1.0) == []
    assert _cliques(np.array([1.0, 1.5, 2.0]), 5.0) == [(0, 2)]


def test_cd_diagram_labels_every_variant_with_its_rank():
    res = FriedmanResult("p", "igd", ("a+molsp", "a", "b"), (1.2, 2.9, 1.9), 10, 8.0, 0.02, 1.05, 0.05)
    fig = cd_diagram(res)
    texts = {t.get_text() for ax in fig.axes for t in ax.texts}
    assert {"a/MO-LSP (1.20)", "a (2.90)", "b (1.90)", "CD = 1.05"} <= texts
    with pytest.raises(ValueError, match="no mean ranks"):
        cd_diagram(FriedmanResult("p", "igd", ("a",), (1.0,), 1, np.nan, np.nan, np.nan, 0.05))


def test_check_formats():
    assert check_formats("png, PDF,png") == ("png", "pdf")
    for bad in ("", "gif", ["png", "bmp"]):
        with pytest.raises(ValueError, match="format must be"):
            check_formats(bad)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("res")
    run_experiment("zdt1", "nsga2,nsga3", runs=3, evals=300, pop_size=20, out=out, progress=False)
    run_experiment("dtlz2", "nsga3", runs=3, evals=300, pop_size=20, out=out, progress=False)
    return out


def test_plot_results_writes_every_figure(results, tmp_path):
    paths = plot_results(load_records(results), tmp_path, formats=("png", "pdf"))
    names = {p.name for p in paths}
    for key in ("zdt1", "dtlz2-m3"):
        cds = (f"cd_{key}_{i}" for i in ("igd", "sp", "hv", "pd", "spread", "igd_plus"))
        for stem in (f"hv_{key}", f"boxplots_{key}", *cds):
            assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert "fronts_zdt1.png" in names                                  # one figure for two objectives
    assert "fronts_dtlz2-m3_nsga3.png" in names                         # a scatter matrix per MOEA
    for p in paths:
        head = p.read_bytes()[:8]
        assert head.startswith(b"\x89PNG") if p.suffix == ".png" else head.startswith(b"%PDF")
        assert p.stat().st_size > 5000


def test_cli_plot(tmp_path, capsys):
    results = tmp_path / "res"
    run_experiment("zdt1", "nsga2", runs=2, evals=100, pop_size=20, out=results, progress=False)
    assert main(["plot", str(results), "--out", str(tmp_path / "fig"), "--format", "png"]) == 0
    printed = capsys.readouterr().out.split()
    assert len(printed) == len(list((tmp_path / "fig").iterdir())) and all(p.endswith(".png") for p in printed)
    for args, message in (([str(tmp_path / "none"), "--out", str(tmp_path / "f")], "does not exist"),
                          ([str(results), "--out", str(tmp_path / "f"), "--format", "gif"], "format must be"),
                          ([str(results), "--out", "/proc/figs"], "--out: cannot create directory")):
        assert main(["plot", *args]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
