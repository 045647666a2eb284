"""moo.stats: indicators per run (hand-computed cases), the ANOVA/Tukey wrapper against scipy, tables."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest
from scipy import stats as sps

from moo.stats import (INDICATORS, Comparison, RunIndicators, compare, pairwise_test, reference_sets,
                       run_indicators, to_csv, to_latex, to_markdown, true_front)


# ----------------------------------------------------------------------------- ANOVA / Tukey wrapper

def _t_test_p(a, b):
    """Independent reference: the two-sided pooled-variance t-test, computed by hand."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    na, nb = len(a), len(b)
    sp2 = ((na - 1) * a.var(ddof=1) + (nb - 1) * b.var(ddof=1)) / (na + nb - 2)
    t = (a.mean() - b.mean()) / math.sqrt(sp2 * (1 / na + 1 / nb))
    return t, 2 * sps.t.sf(abs(t), na + nb - 2)


@pytest.mark.parametrize("shift, significant", [(1.0, True), (0.0, False)])
def test_pairwise_test_matches_t_test_and_studentized_range(shift, significant):
    rng = np.random.default_rng(2024)
    a = rng.normal(0.0, 1.0, 40)
    b = rng.normal(shift, 1.0, 35)
    p_anova, p_tukey = pairwise_test(a, b)
    t, p_t = _t_test_p(a, b)
    # with two groups, F = t^2 and Tukey's q = sqrt(2) |t| with k = 2, df = n - 2
    assert p_anova == pytest.approx(p_t, rel=1e-9)
    p_q = sps.studentized_range.sf(math.sqrt(2) * abs(t), 2, len(a) + len(b) - 2)
    assert p_tukey == pytest.approx(p_q, rel=1e-4, abs=1e-9)
    assert p_anova == pytest.approx(sps.ttest_ind(a, b).pvalue, rel=1e-9)
    assert (p_tukey < 0.05) is significant


def test_pairwise_test_detection_rate_under_null_and_alternative():
    rng = np.random.default_rng(11)
    null = [pairwise_test(rng.normal(size=20), rng.normal(size=20))[1] < 0.05 for _ in range(60)]
    alt = [pairwise_test(rng.normal(size=20), rng.normal(1.5, 1, size=20))[1] < 0.05 for _ in range(60)]
    assert np.mean(null) <= 0.15                 # about 5 % false positives (binomial, n = 60)
    assert np.mean(alt) >= 0.9                   # power ~0.999 for a 1.5-sigma shift with n = 20


def test_pairwise_test_degenerate_samples():
    assert pairwise_test([1.0, 1.0, 1.0], [1.0, 1.0]) == (1.0, 1.0)
    assert pairwise_test([1.0, 1.0, 1.0], [2.0, 2.0]) == (0.0, 0.0)
    assert all(math.isnan(p) for p in pairwise_test([1.0], [1.0, 2.0]))
    # NaNs are dropped: the same as the finite values alone
    a, b = [1.0, 2.0, np.nan, 3.0], [2.0, 4.0, 5.0]
    assert pairwise_test(a, b) == pairwise_test([1.0, 2.0, 3.0], b)
    with pytest.raises(ValueError, match="plain must be 1-D"):
        pairwise_test(np.ones((2, 2)), [1.0, 2.0])


def _row(algorithm, molsp, seed, **values):
    base = dict(igd=1.0, sp=1.0, hv=1.0, pd=1.0, spread=1.0)
    base.update(values)
    return RunIndicators(problem="toy", n_obj=2, algorithm=algorithm, molsp=molsp, seed=seed, n_points=5, **base)


def test_compare_means_std_direction_and_significance():
    runs = [_row("alg", False, s, igd=v, hv=v) for s, v in enumerate([1.0, 2.0, 3.0])] + \
           [_row("alg", True, s, igd=v, hv=v) for s, v in enumerate([11.0, 12.0, 13.0])]
    table = {c.indicator: c for c in compare(runs)}
    assert list(table) == list(INDICATORS)
    igd, hv, sp = table["igd"], table["hv"], table["sp"]
    assert (igd.mean_plain, igd.std_plain, igd.mean_molsp, igd.std_molsp) == (2.0, 1.0, 12.0, 1.0)
    assert (igd.n_plain, igd.n_molsp) == (3, 3)
    # IGD: lower is better -> plain; HV: higher is better -> MO-LSP; equal constants -> tie, p = 1
    assert igd.better == "plain" and hv.better == "molsp" and sp.better == "tie"
    assert igd.significant and hv.significant and not sp.significant and sp.p_tukey == 1.0
    _, p_t = _t_test_p([1, 2, 3], [11, 12, 13])
    assert igd.p_anova == pytest.approx(p_t, rel=1e-9)


def test_compare_one_variant_missing_and_bad_alpha():
    runs = [_row("alg", False, s, igd=float(s)) for s in range(3)]
    c = compare(runs)[0]
    assert c.n_molsp == 0 and math.isnan(c.mean_molsp) and math.isnan(c.p_tukey) and not c.significant
    assert c.better == "tie"
    with pytest.raises(ValueError, match="alpha"):
        compare(runs, alpha=1.5)


# ----------------------------------------------------------------------------- indicators per run

def _record(F, seed, algorithm="a", molsp=False, problem="toy", ref=(3.0, 3.0)):
    F = np.asarray(F, float)
    return {"problem": problem, "n_obj": 2, "algorithm": algorithm, "molsp": molsp, "seed": seed,
            "F": F.tolist(), "hv_ref_point": list(ref)}


def test_run_indicators_hand_computed():
    A = [[0.0, 2.0], [2.0, 0.0], [0.5, 1.0]]
    B = [[1.0, 1.0], [0.0, 3.0]]
    recs = [_record(A, 1), _record(B, 2, molsp=True)]
    # P* = non-dominated union = A ((1,1) is dominated by (0.5,1), (0,3) by (0,2))
    ref = reference_sets(recs)[("toy", 2)]
    assert sorted(map(tuple, ref)) == sorted(map(tuple, A))
    ra, rb = run_indicators(recs)
    assert ra.igd == pytest.approx(0.0, abs=1e-15)
    assert rb.igd == pytest.approx((1.0 + math.sqrt(2.0) + 0.5) / 3.0, rel=1e-12)
    # Schott spacing with L1 nearest-neighbour distances 1.5, 2.5, 1.5 -> sample std sqrt(1/3)
    assert ra.sp == pytest.approx(math.sqrt(1.0 / 3.0), rel=1e-12)
    assert rb.sp == pytest.approx(0.0, abs=1e-15)
    # HV at (3, 3): A 3 + 2.5 + 1 = 6.5; B: only (1,1) strictly dominates r -> 4
    assert (ra.hv, rb.hv) == (pytest.approx(6.5, rel=1e-12), pytest.approx(4.0, rel=1e-12))
    # PD of two points = their Minkowski p=0.1 dissimilarity
    assert rb.pd == pytest.approx((1.0 + 2.0 ** 0.1) ** 10, rel=1e-12)
    # Spread: extremes of P* are (2,0) and (0,2), both in A -> d_ext = 0
    d = np.array([math.sqrt(1.25), math.sqrt(3.25), math.sqrt(1.25)])
    assert ra.spread == pytest.approx(np.abs(d - d.mean()).sum() / (3 * d.mean()), rel=1e-12)
    # B: d_ext = |(2,0)-(1,1)| + |(0,2)-(0,3)| = sqrt(2) + 1; both nn distances sqrt(5)
    d_ext = math.sqrt(2.0) + 1.0
    assert rb.spread == pytest.approx(d_ext / (d_ext + 2 * math.sqrt(5.0)), rel=1e-12)
    assert (ra.n_points, rb.n_points, ra.molsp, rb.molsp) == (3, 2, False, True)


def test_run_indicators_small_and_empty_sets():
    recs = [_record([[1.0, 1.0]], 1), _record(np.zeros((0, 2)), 2), _record([[0.0, 2.0], [2.0, 0.0]], 3)]
    one, empty, two = run_indicators(recs)
    assert math.isnan(one.sp) and math.isnan(one.spread) and one.pd == 0.0 and one.hv == pytest.approx(4.0)
    assert empty.hv == 0.0 and all(math.isnan(getattr(empty, k)) for k in ("igd", "sp", "pd", "spread"))
    c = {x.indicator: x for x in compare([one, empty, two])}
    assert c["sp"].n_plain == 1 and c["hv"].n_plain == 3     # NaNs are left out and counted


def test_true_front_closed_forms():
    F = true_front("zdt1")
    assert np.allclose(F[:, 1], 1 - np.sqrt(F[:, 0])) and F[:, 0].min() == 0 and F[:, 0].max() == 1
    F = true_front("zdt3")
    assert np.allclose(F[:, 1], 1 - np.sqrt(F[:, 0]) - F[:, 0] * np.sin(10 * np.pi * F[:, 0]))
    assert F[:, 0].max() < 0.86                  # the dominated tail of the curve is removed
    assert np.allclose(true_front("dtlz1", 3).sum(axis=1), 0.5)
    assert np.allclose(np.linalg.norm(true_front("dtlz2", 4), axis=1), 1.0)
    F5 = true_front("dtlz5", 3)
    assert np.allclose(np.linalg.norm(F5, axis=1), 1.0) and np.allclose(F5[:, 0], F5[:, 1])  # a curve
    F7 = true_front("dtlz7", 3)
    h = 3 - np.sum(F7[:, :2] / 2 * (1 + np.sin(3 * np.pi * F7[:, :2])), axis=1)
    assert np.allclose(F7[:, 2], 2 * h)          # g = 1 on the front: f3 = (1 + g) h
    with pytest.raises(ValueError, match="ZDT and DTLZ"):
        true_front("generic")


def test_reference_set_of_zdt_is_true_front_not_union():
    recs = [_record([[5.0, 5.0], [6.0, 4.0]], 1, problem="zdt1")]
    assert np.array_equal(reference_sets(recs)[("zdt1", 2)], true_front("zdt1"))


# ----------------------------------------------------------------------------- output

def _table():
    runs = [_row("alg", False, s, igd=v) for s, v in enumerate([1.0, 2.0, 3.0])] + \
           [_row("alg", True, s, igd=v) for s, v in enumerate([11.0, 12.0, 13.0])]
    return compare(runs)


def test_to_csv_roundtrip(tmp_path):
    table = _table()
    text = to_csv(table, tmp_path / "t.csv")
    assert (tmp_path / "t.csv").read_text() == text
    rows = list(csv.DictReader(io.StringIO(text)))
    assert [r["indicator"] for r in rows] == list(INDICATORS)
    assert float(rows[0]["mean_molsp"]) == 12.0 and rows[0]["better"] == "plain"
    assert rows[0]["significant"] == "True"


def test_markdown_and_latex_marks():
    md = to_markdown(_table())
    plain_row = next(line for line in md.splitlines() if line.startswith("| alg |"))
    molsp_row = next(line for line in md.splitlines() if line.startswith("| alg/MO-LSP |"))
    # IGD: plain better (bold), significantly (a), best over the table (*)
    assert "**2.0000E+00 ± 1.00E+00**^a,*" in plain_row
    assert "12.0000E+00" not in molsp_row and "1.2000E+01 ± 1.00E+00 |" in molsp_row
    tex = to_latex(_table())
    assert r"\textbf{2.0000E+00 $\pm$ 1.00E+00}$^{a,*}$" in tex and r"\end{tabular}" in tex


def test_comparison_is_frozen():
    c = _table()[0]
    assert isinstance(c, Comparison)
    with pytest.raises(AttributeError):
        c.better = "molsp"
