"""moo.stats: indicators per run (hand-computed cases), the ANOVA/Tukey wrapper against scipy, tables."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest
from scipy import stats as sps

from moo.stats import (
    INDICATORS,
    Comparison,
    RunIndicators,
    compare,
    pairwise_test,
    reference_sets,
    run_indicators,
    to_csv,
    to_latex,
    to_markdown,
    true_front,
)

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


def test_run_indicators_igd_plus_hand_computed_and_against_pymoo():
    from pymoo.indicators.igd_plus import IGDPlus

    A = [[0.0, 2.0], [2.0, 0.0], [0.5, 1.0]]
    B = [[1.0, 1.0], [0.0, 3.0]]
    recs = [_record(A, 1), _record(B, 2, molsp=True), _record(np.zeros((0, 2)), 3)]
    ra, rb, empty = run_indicators(recs)           # P* = A, as in the test above
    # IGD+ of B: to (0,2) min(|(1,0)|, |(0,1)|) = 1; to (2,0) min(|(0,1)|, |(0,3)|) = 1;
    # to (0.5,1) min(|(0.5,0)|, |(0,2)|) = 0.5 -> 2.5 / 3 (IGD is (1 + sqrt 2 + 0.5) / 3)
    assert ra.igd_plus == 0.0 and rb.igd_plus == pytest.approx(2.5 / 3.0, rel=1e-12)
    assert rb.igd_plus == pytest.approx(IGDPlus(np.array(A))(np.array(B)), rel=1e-12)
    assert math.isnan(empty.igd_plus)
    # a dominated reference point costs nothing: IGD+ 0 where IGD is not
    r1, r2 = run_indicators([_record([[0.0, 0.0]], 1), _record([[1.0, 1.0]], 2)], {("toy", 2): np.array([[1.0, 1.0]])})
    assert (r1.igd_plus, r2.igd_plus) == (0.0, 0.0) and r1.igd == pytest.approx(math.sqrt(2.0))
    rng = np.random.default_rng(3)
    F, R = rng.random((15, 3)), rng.random((40, 3))
    rec = {"problem": "toy", "n_obj": 3, "algorithm": "a", "molsp": False, "seed": 0, "F": F.tolist(),
           "hv_ref_point": [2.0] * 3}
    got = run_indicators([rec], {("toy", 3): R})[0].igd_plus
    assert got == pytest.approx(IGDPlus(R)(F), rel=1e-12)


def test_igd_plus_in_the_tables_and_the_papers_five_alone():
    runs = [_row("alg", False, s, igd_plus=v) for s, v in enumerate([1.0, 2.0, 3.0])] + \
           [_row("alg", True, s, igd_plus=v) for s, v in enumerate([11.0, 12.0, 13.0])]
    table = compare(runs)
    c = {x.indicator: x for x in table}["igd_plus"]
    assert (c.mean_plain, c.mean_molsp, c.better, c.significant) == (2.0, 12.0, "plain", True)   # lower is better
    md = to_markdown(table)
    assert "| MOEA | IGD | SP | HV | PD | Spread | IGD+ |" in md
    assert "(lower IGD, SP, Spread, IGD+; higher HV, PD)" in md
    assert "**2.0000E+00 ± 1.00E+00**^a,*" in next(line for line in md.splitlines() if line.startswith("| alg |"))
    five = [x for x in table if x.indicator != "igd_plus"]
    md5, tex5 = to_markdown(five), to_latex(five)
    assert "| MOEA | IGD | SP | HV | PD | Spread |\n|---|---|---|---|---|---|" in md5 and "IGD+" not in md5
    assert "(lower IGD, SP, Spread; higher HV, PD)" in md5                 # the legend of the paper's five
    assert r"\begin{tabular}{lccccc}" in tex5 and "IGD+" not in tex5
    # the other columns do not depend on IGD+ being there
    assert md5.splitlines()[4] == " | ".join(md.splitlines()[4].split(" | ")[:6]) + " |"


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


# ----------------------------------------------------------------------------- nonparametric statistics

from moo.stats import (  # noqa: E402
    FriedmanResult,
    friedman,
    friedman_test,
    holm,
    nemenyi_cd,
    rank_sum_test,
    ranks_to_csv,
    ranks_to_latex,
    ranks_to_markdown,
)

# Demsar (2006), Table 6: AUC of C4.5, C4.5+m, C4.5+cf, C4.5+m+cf on 14 UCI data sets (as printed).
DEMSAR_AUC = np.array([
    [0.763, 0.768, 0.771, 0.798], [0.599, 0.591, 0.590, 0.569], [0.954, 0.971, 0.968, 0.967],
    [0.628, 0.661, 0.654, 0.657], [0.882, 0.888, 0.886, 0.898], [0.936, 0.931, 0.916, 0.931],
    [0.661, 0.668, 0.609, 0.685], [0.583, 0.583, 0.563, 0.625], [0.775, 0.838, 0.866, 0.875],
    [1.000, 1.000, 1.000, 1.000], [0.940, 0.962, 0.965, 0.962], [0.619, 0.666, 0.614, 0.669],
    [0.972, 0.981, 0.975, 0.975], [0.957, 0.978, 0.946, 0.970]])


def test_friedman_and_nemenyi_against_demsar_2006():
    ranks, chi2, p, cd = friedman_test(DEMSAR_AUC, higher_is_better=True, alpha=0.05)
    # Demsar's mean ranks 3.143, 2.000, 2.893, 1.964 come from the unrounded AUCs: in the printed table
    # C4.5+cf and C4.5+m+cf tie on one data set (0.975), which moves 0.5/14 between them.
    assert ranks[0] == pytest.approx(3.143, abs=5e-4) and ranks[1] == pytest.approx(2.000, abs=5e-4)
    assert ranks[2] == pytest.approx(2.893 + 0.5 / 14, abs=5e-4)
    assert ranks[3] == pytest.approx(1.964 - 0.5 / 14, abs=5e-4)
    # Demsar's chi2_F = 12N/(k(k+1)) [sum R_j^2 - k(k+1)^2/4] (9.28 with his ranks), divided by the usual
    # tie correction 1 - sum(t^3 - t) / (N k (k^2 - 1)) over the groups of tied values in each block
    N, k = DEMSAR_AUC.shape
    assert 12 * N / (k * (k + 1)) * (np.sum(np.array([3.143, 2.000, 2.893, 1.964]) ** 2)
                                     - k * (k + 1) ** 2 / 4) == pytest.approx(9.28, abs=0.01)
    uncorrected = 12 * N / (k * (k + 1)) * (np.sum(ranks ** 2) - k * (k + 1) ** 2 / 4)
    ties = sum(t ** 3 - t for row in DEMSAR_AUC for t in np.unique(row, return_counts=True)[1])
    assert chi2 == pytest.approx(uncorrected / (1 - ties / (N * k * (k * k - 1))), rel=1e-12)
    assert p == pytest.approx(sps.chi2.sf(chi2, k - 1), rel=1e-12)
    # the critical differences of Demsar's Section 3.2.2: q_0.05 = 2.569, CD = 1.25; q_0.10 = 2.291, CD = 1.12
    assert cd == pytest.approx(2.569 * math.sqrt(k * (k + 1) / (6 * N)), rel=2e-4)
    assert round(cd, 2) == 1.25 and round(nemenyi_cd(4, 14, 0.10), 2) == 1.12
    # Demsar's conclusion: at 0.05 no pair differs; at 0.10 C4.5 is worse than C4.5+m and C4.5+m+cf
    names = ("C4.5", "C4.5+m", "C4.5+cf", "C4.5+m+cf")
    for alpha, pairs in ((0.05, set()), (0.10, {("C4.5", "C4.5+m"), ("C4.5", "C4.5+m+cf")})):
        res = FriedmanResult("demsar", "auc", names, tuple(ranks), N, chi2, p, nemenyi_cd(k, N, alpha), alpha)
        assert {(a, b) for i, a in enumerate(names) for b in names[i + 1:] if res.differs(a, b)} == pairs
        P = res.nemenyi_p()
        assert np.array_equal(alpha > P, np.array([[res.differs(a, b) for b in names] for a in names]))
        assert np.allclose(P, P.T) and np.all(np.diag(P) == 1)


def test_nemenyi_q_table_of_demsar():
    """Demsar (2006), Table 5(a): q_0.05 for k = 2..10 (Studentized range / sqrt 2, three decimals)."""
    table = [1.960, 2.343, 2.569, 2.728, 2.850, 2.949, 3.031, 3.102, 3.164]
    for k, q in zip(range(2, 11), table, strict=True):
        assert nemenyi_cd(k, 1, 0.05) / math.sqrt(k * (k + 1) / 6) == pytest.approx(q, abs=1.5e-3)


def test_friedman_two_treatments_is_the_sign_test():
    """With k = 2 and no ties, Friedman's chi2 equals (n_+ - n_-)^2 / n (the sign test's statistic)."""
    rng = np.random.default_rng(3)
    X = rng.normal(size=(15, 2)) + np.array([0.0, 0.4])   # shifted columns
    ranks, chi2, p, _ = friedman_test(X)
    wins = int(np.sum(X[:, 0] < X[:, 1]))
    assert chi2 == pytest.approx((wins - (15 - wins)) ** 2 / 15, rel=1e-12)
    assert ranks.sum() == pytest.approx(3.0) and p == pytest.approx(sps.chi2.sf(chi2, 1), rel=1e-12)
    # three treatments: the same statistic as scipy on the untouched table
    Y = rng.normal(size=(12, 3))
    assert friedman_test(Y)[1] == pytest.approx(sps.friedmanchisquare(*Y.T).statistic, rel=1e-12)
    with pytest.raises(ValueError, match="values must be a"):
        friedman_test(np.ones((1, 3)))
    with pytest.raises(ValueError, match="finite"):
        friedman_test([[1.0, np.nan], [1.0, 2.0]])
    assert friedman_test(np.ones((4, 3)))[1:3] == (0.0, 1.0)


def test_holm_against_the_textbook_example():
    """Holm (1979) step-down on four hypotheses (the example of Wikipedia's 'Holm-Bonferroni method'):
    p = 0.01, 0.04, 0.03, 0.005 at alpha 0.05 rejects H1 and H4 only."""
    adjusted = holm([0.01, 0.04, 0.03, 0.005])
    assert np.allclose(adjusted, [0.03, 0.06, 0.06, 0.02], rtol=1e-12)
    assert list(adjusted < 0.05) == [True, False, False, True]
    # NaNs stay NaN and leave the family: the same as the finite values alone
    assert np.allclose(holm([0.01, np.nan, 0.04])[[0, 2]], holm([0.01, 0.04])) and np.isnan(holm([np.nan])[0])
    with pytest.raises(ValueError, match="p_values"):
        holm([0.5, 1.5])


def test_holm_is_the_step_down_procedure():
    """The adjusted p-values reject exactly what the sequential procedure rejects, at every alpha."""
    rng = np.random.default_rng(8)
    for _ in range(200):
        p = rng.random(rng.integers(1, 12)) ** 3
        adj = holm(p)
        for alpha in (0.01, 0.05, 0.2):
            order, m, rejected = np.argsort(p), len(p), np.zeros(len(p), bool)
            for i, j in enumerate(order):
                if p[j] > alpha / (m - i):
                    break
                rejected[j] = True
            assert np.array_equal(adj <= alpha, rejected)


def test_rank_sum_against_the_scipy_example():
    """scipy.stats.mannwhitneyu's documented example (ages of males and females): U = 17, exact p = 0.1111."""
    males, females = [19, 22, 16, 29, 24], [20, 11, 17, 12]
    assert rank_sum_test(males, females) == pytest.approx(0.1111111111111111, rel=1e-12)
    assert sps.mannwhitneyu(males, females).statistic == 17
    # complete separation of 3 vs 3: exact two-sided p = 2 / C(6, 3) = 0.1
    assert rank_sum_test([1.0, 2.0, 3.0], [11.0, 12.0, 13.0]) == pytest.approx(0.1, rel=1e-12)
    assert rank_sum_test([1.0, 1.0], [1.0, 1.0, 1.0]) == 1.0 and math.isnan(rank_sum_test([1.0], [2.0, 3.0]))


def test_compare_wilcoxon_holm_family_is_the_column():
    rng = np.random.default_rng(5)
    runs = []
    for alg, shift in (("a1", 3.0), ("a2", 0.0), ("a3", 1.0)):
        runs += [_row(alg, False, s, igd=v) for s, v in enumerate(rng.normal(0, 1, 12))]
        runs += [_row(alg, True, s, igd=v) for s, v in enumerate(rng.normal(shift, 1, 12))]
    table = [c for c in compare(runs) if c.indicator == "igd"]
    raw = [sps.mannwhitneyu([r.igd for r in runs if r.algorithm == c.algorithm and not r.molsp],
                            [r.igd for r in runs if r.algorithm == c.algorithm and r.molsp]).pvalue for c in table]
    assert [c.p_wilcoxon for c in table] == pytest.approx(raw, rel=1e-12)
    assert [c.p_wilcoxon_holm for c in table] == pytest.approx(list(holm(raw)), rel=1e-12)
    by = {c.algorithm: c for c in table}
    assert by["a1"].significant_wilcoxon and not by["a2"].significant_wilcoxon
    md = to_markdown(compare(runs))
    assert "^a,w" in md and "^w:" in md and "Holm" in md         # the mark and its legend


def _grid_runs(seeds=10):
    """Three MOEAs x two variants, run i of each sharing seed i; 'good+molsp' best on every run."""
    rng = np.random.default_rng(9)
    quality = {"good": 1.0, "mid": 2.0, "bad": 3.0}
    runs = []
    for s in range(seeds):
        noise = rng.normal(0, 0.1, 6)
        for i, (alg, molsp) in enumerate((a, v) for a in quality for v in (True, False)):
            runs.append(_row(alg, molsp, s, igd=quality[alg] - 0.5 * molsp + noise[i], hv=float(s)))
    return runs


def test_friedman_over_variants_blocks_by_seed():
    runs = _grid_runs()
    results = {r.indicator: r for r in friedman(runs)}
    igd = results["igd"]
    assert igd.variants == ("bad+molsp", "bad", "good+molsp", "good", "mid+molsp", "mid")   # not registered: by name
    assert igd.n_blocks == 10 and igd.rejects
    table = np.array([[r.igd for v in igd.variants for r in runs
                       if r.seed == s and f"{r.algorithm}{'+molsp' if r.molsp else ''}" == v] for s in range(10)])
    ranks, chi2, p, cd = friedman_test(table)
    assert igd.mean_ranks == tuple(ranks) and (igd.statistic, igd.p_value, igd.cd) == (chi2, p, cd)
    assert igd.differs("good+molsp", "bad") and not igd.differs("good+molsp", "good")
    # HV constant within each block: every variant ties, the test does not reject
    assert results["hv"].mean_ranks == (3.5,) * 6 and results["hv"].p_value == 1.0
    # a run missing for one variant drops that seed's block
    assert {r.indicator: r for r in friedman([r for r in runs if not (r.seed == 0 and r.algorithm == "bad")])}[
        "igd"].n_blocks == 9


def test_ranks_tables_marks_and_legend(tmp_path):
    results = friedman(_grid_runs())
    md = ranks_to_markdown(results)
    row = next(line for line in md.splitlines() if line.startswith("| good/MO-LSP |"))
    assert row.split("|")[2].strip().startswith("**1.")                    # best mean rank in bold
    bad = next(line for line in md.splitlines() if line.startswith("| bad |"))
    assert bad.split("|")[2].strip().endswith("^n")                       # Nemenyi: worse than the best
    assert "| Friedman p |" in md and "| CD |" in md and "^n:" in md and "Bold:" in md
    tex = ranks_to_latex(results)
    assert r"\textbf{" in tex and "$^{n}$" in tex and r"\end{tabular}" in tex
    rows = list(csv.DictReader(io.StringIO(ranks_to_csv(results, tmp_path / "r.csv"))))
    assert len(rows) == len(INDICATORS) * 6 and (tmp_path / "r.csv").exists()
    igd_bad = next(r for r in rows if r["indicator"] == "igd" and r["variant"] == "bad")
    assert igd_bad["worse_than_best"] == "True" and float(igd_bad["mean_rank"]) > 5


def test_comparison_legend_explains_every_mark():
    md, tex = to_markdown(_table()), to_latex(_table())
    for mark in ("Bold:", "^a:", "^w:", "^*:"):
        assert mark in md
    assert "$^{a}$:" in tex and "$^{*}$:" in tex and r"\%" in tex
