"""moo.indicators against hand-computed cases and independent brute-force computations."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from moo.indicators import hypervolume, igd, igd_plus, pure_diversity, spacing, spread

# ----------------------------------------------------------------------------- references


def igd_loop(A, R):
    """IGD by explicit loops over points (math.dist)."""
    return sum(min(math.dist(r, a) for a in A) for r in R) / len(R)


def igd_plus_loop(A, R):
    """IGD+ by explicit loops: only the objectives in which the point is worse than the reference count."""
    return sum(min(math.sqrt(sum(max(a_j - r_j, 0.0) ** 2 for a_j, r_j in zip(a, r, strict=True))) for a in A)
               for r in R) / len(R)


def hv_inclusion_exclusion(A, r):
    """HV as the measure of a union of boxes, by inclusion-exclusion over all subsets."""
    A = [a for a in A if all(x < y for x, y in zip(a, r, strict=True))]
    total = 0.0
    for k in range(1, len(A) + 1):
        for subset in itertools.combinations(A, k):
            corner = np.max(subset, axis=0)
            total += (-1) ** (k + 1) * float(np.prod(np.maximum(np.asarray(r) - corner, 0.0)))
    return total


def hv_grid(A, r):
    """HV by cutting space at every point coordinate and summing the dominated cells."""
    A = np.asarray(A, dtype=float)
    axes = [np.unique(np.concatenate([A[:, k], [r[k]]])) for k in range(A.shape[1])]
    axes = [ax[ax <= r[k]] for k, ax in enumerate(axes)]
    total = 0.0
    for cell in itertools.product(*[range(len(ax) - 1) for ax in axes]):
        lo = np.array([axes[k][i] for k, i in enumerate(cell)])
        hi = np.array([axes[k][i + 1] for k, i in enumerate(cell)])
        if np.any(np.all(lo >= A, axis=1)):         # the cell lies in a dominated box
            total += float(np.prod(hi - lo))
    return total


def pd_permutations(A, p=0.1):
    """Eq. (pd) unrolled: the best removal order, each point scored by its nearest later point."""
    A = np.asarray(A, dtype=float)
    n = len(A)
    D = [[(np.sum(np.abs(A[i] - A[j]) ** p)) ** (1 / p) for j in range(n)] for i in range(n)]
    best = 0.0
    for order in itertools.permutations(range(n)):
        score = sum(min(D[order[k]][j] for j in order[k + 1:]) for k in range(n - 1))
        best = max(best, score)
    return best


# ----------------------------------------------------------------------------- IGD


def test_igd_hand_case():
    # from (0,0): nearest at distance 1; from (2,2): sqrt(5); mean (1 + sqrt 5) / 2
    assert igd([[0, 1], [1, 0]], [[0, 0], [2, 2]]) == pytest.approx((1 + math.sqrt(5)) / 2, rel=1e-14)


def test_igd_zero_when_set_contains_reference():
    R = [[0, 1], [0.5, 0.5], [1, 0]]
    assert igd([*R, [2, 2]], R) == 0.0


@pytest.mark.parametrize("m", [2, 3, 5])
def test_igd_matches_brute_force(m):
    rng = np.random.default_rng(m)
    A, R = rng.random((17, m)), rng.random((23, m))
    assert igd(A, R) == pytest.approx(igd_loop(A, R), rel=1e-12)


# ----------------------------------------------------------------------------- IGD+


def test_igd_plus_hand_case():
    # reference (0, 0): point (1, 2) is worse by (1, 2) -> sqrt 5, point (3, -1) by (3, 0) -> 3: min sqrt 5;
    # reference (2, 2): (1, 2) weakly dominates it -> 0. Mean sqrt(5) / 2.
    assert igd_plus([[1, 2], [3, -1]], [[0, 0], [2, 2]]) == pytest.approx(math.sqrt(5) / 2, rel=1e-14)


@pytest.mark.parametrize("m", [2, 3, 5])
def test_igd_plus_matches_brute_force_and_never_exceeds_igd(m):
    rng = np.random.default_rng(10 + m)
    A, R = rng.random((17, m)), rng.random((23, m))
    assert igd_plus(A, R) == pytest.approx(igd_plus_loop(A, R), rel=1e-12)
    assert igd_plus(A, R) <= igd(A, R)


# ----------------------------------------------------------------------------- scale (issue 12, item 7)


@pytest.mark.parametrize("c", [1e300, 1e200, 1e-300])
def test_indicators_are_finite_and_homogeneous_over_the_float_range(c):
    # distances are homogeneous of degree 1, Spread of degree 0: scaling the sets by c scales the values by c
    # (squared distances alone would overflow above about 1e154 and underflow below 1e-154)
    rng = np.random.default_rng(4)
    A, R = rng.random((12, 3)), rng.random((20, 3))
    assert igd(c * A, c * R) == pytest.approx(c * igd(A, R), rel=1e-12)
    assert igd_plus(c * A, c * R) == pytest.approx(c * igd_plus(A, R), rel=1e-12)
    assert spacing(c * A) == pytest.approx(c * spacing(A), rel=1e-12)
    assert pure_diversity(c * A) == pytest.approx(c * pure_diversity(A), rel=1e-12)
    assert spread(c * A, c * R) == pytest.approx(spread(A, R), rel=1e-12)


def test_hypervolume_is_homogeneous_of_degree_m_and_refuses_to_overflow():
    rng = np.random.default_rng(5)
    A, r = rng.random((9, 3)), np.full(3, 1.1)
    assert hypervolume(1e100 * A, 1e100 * r) == pytest.approx(1e300 * hypervolume(A, r), rel=1e-12)
    with pytest.raises(OverflowError, match="exceeds the float range"):
        hypervolume(1e200 * A, 1e200 * r)


# ----------------------------------------------------------------------------- HV


def test_hypervolume_hand_case_2d():
    # staircase (1,3), (2,2), (3,1) under (4,4): strips of widths 1, 1, 1 and heights 1, 2, 3
    assert hypervolume([[1, 3], [2, 2], [3, 1]], [4, 4]) == pytest.approx(6.0, rel=1e-15)


def test_hypervolume_hand_case_3d():
    # boxes [0,2]^3 (8) and [1,2]x[1,2]x[-1,2] (3) overlap in [1,2]x[1,2]x[0,2] (2)
    A = [[0, 0, 0], [1, 1, -1]]
    r = [2, 2, 2]
    assert hypervolume(A, r) == pytest.approx(8 + 1 * 1 * 3 - 1 * 1 * 2, rel=1e-15)


def test_hypervolume_ignores_points_beyond_reference():
    assert hypervolume([[0.5, 0.5], [2, 0], [1, -3]], [1, 1]) == pytest.approx(0.25)
    assert hypervolume([[1, 0.5]], [1, 1]) == 0.0      # on the boundary: no volume


@pytest.mark.parametrize("m, n", [(2, 8), (3, 7), (4, 6), (5, 6)])
def test_hypervolume_matches_inclusion_exclusion(m, n):
    rng = np.random.default_rng(10 * m + n)
    A = rng.random((n, m))
    r = np.full(m, 1.1)
    assert hypervolume(A, r) == pytest.approx(hv_inclusion_exclusion(A, r), rel=1e-12)


@pytest.mark.parametrize("m, n", [(2, 9), (3, 6)])
def test_hypervolume_matches_grid(m, n):
    rng = np.random.default_rng(100 + m)
    A = np.round(rng.random((n, m)), 2)          # shared coordinates and dominated points happen
    r = np.full(m, 1.0)
    assert hypervolume(A, r) == pytest.approx(hv_grid(A, r), rel=1e-12)


# ----------------------------------------------------------------------------- spacing


def test_spacing_hand_case():
    # L1 nearest-neighbour distances 2, 2, 4: mean 8/3, sample variance (4+4+16)/9/2 = 4/3
    assert spacing([[0, 0], [1, 1], [3, 3]]) == pytest.approx(math.sqrt(4 / 3), rel=1e-14)


def test_spacing_uses_l1_distance():
    # Euclidean nearest distances would be 1, 1, 1 (spacing 0); L1 ones are 1, 1, 2 (=> nonzero)
    F = [[0, 0], [1, 0], [1.5, math.sqrt(3) / 2]]
    d = [1.0, 1.0, 0.5 + math.sqrt(3) / 2]
    assert spacing(F) == pytest.approx(np.std(d, ddof=1), rel=1e-14)


def test_spacing_zero_for_even_front():
    t = np.linspace(0, 1, 11)
    assert spacing(np.column_stack([t, 1 - t])) == pytest.approx(0.0, abs=1e-14)


def test_spacing_needs_two_points():
    with pytest.raises(ValueError, match="F must have at least 2 points"):
        spacing([[0.0, 1.0]])


# ----------------------------------------------------------------------------- pure diversity


def test_pure_diversity_two_points_is_their_dissimilarity():
    # (|1|^0.1 + |1|^0.1)^(1/0.1) = 2^10
    assert pure_diversity([[0, 0], [1, 1]]) == pytest.approx(1024.0, rel=1e-12)
    assert pure_diversity([[0, 0], [1, 1]], method="exact") == pytest.approx(1024.0, rel=1e-12)
    assert pure_diversity([[0.3, 0.7]]) == 0.0


def test_pure_diversity_hand_cases_on_a_line():
    # along one axis the p=0.1 dissimilarity is |dx|
    line = lambda xs: np.column_stack([xs, np.zeros(len(xs))])  # noqa: E731
    # greedy: withdraw 3 (nearest 1 at 2), then 0 (nearest 1 at 1): 3. Exact: remove 1 first: 1 + 3 = 4
    assert pure_diversity(line([0, 1, 3])) == pytest.approx(3.0, rel=1e-12)
    assert pure_diversity(line([0, 1, 3]), method="exact") == pytest.approx(4.0, rel=1e-12)
    # greedy: 10 (nearest 2 at 8), then 0 (1), then 1 (1; 2's component holds 10): 10.
    # exact: remove 1 (1), then 2 (2), then 10 vs 0 (10): 13
    assert pure_diversity(line([0, 1, 2, 10])) == pytest.approx(10.0, rel=1e-12)
    assert pure_diversity(line([0, 1, 2, 10]), method="exact") == pytest.approx(13.0, rel=1e-12)


def test_pure_diversity_hand_case_minkowski():
    # d((0,0),(1,0)) = d((0,0),(0,1)) = 1, d((1,0),(0,1)) = (1 + 1)^10 = 1024.
    # Best removal order: (0,0) first (1), then the pair (1024): 1025. Greedy: all nearest
    # distances tie at 1, (0,0) goes first and links to (0,1); then (0,1) reaches (1,0) at 1024.
    F = [[1, 0], [0, 0], [0, 1]]
    assert pure_diversity(F) == pytest.approx(1025.0, rel=1e-12)
    assert pure_diversity(F, method="exact") == pytest.approx(1025.0, rel=1e-12)
    assert pure_diversity(F, p=2.0, method="exact") == pytest.approx(1 + math.sqrt(2), rel=1e-12)


def test_pure_diversity_exact_matches_permutation_brute_force():
    rng = np.random.default_rng(7)
    for n in (3, 5, 6):
        A = rng.random((n, 3))
        assert pure_diversity(A, method="exact") == pytest.approx(pd_permutations(A), rel=1e-12)


def test_pure_diversity_invariances():
    rng = np.random.default_rng(3)
    A = rng.random((15, 4))
    base = pure_diversity(A)
    assert pure_diversity(A[rng.permutation(15)]) == pytest.approx(base, rel=1e-12)
    assert pure_diversity(A + 5.0) == pytest.approx(base, rel=1e-12)


def test_pure_diversity_p_inf_is_the_chebyshev_limit():
    # p = inf: d(a, b) = max_j |a_j - b_j| (issue 12: it returned 2.0 for any front). Hand case on the
    # anti-diagonal, Chebyshev distances 0.5 (neighbours) and 1 (ends): the greedy withdraws an end (0.5)
    # and then links the rest (0.5): 1.0; the recursion withdraws the middle point first (0.5 + 1): 1.5.
    P = [[0, 1], [0.5, 0.5], [1, 0]]
    assert pure_diversity(P, p=np.inf) == pytest.approx(1.0, rel=1e-14)
    assert pure_diversity(P, p=np.inf, method="exact") == pytest.approx(1.5, rel=1e-14)
    rng = np.random.default_rng(8)
    A = rng.random((6, 3))
    cheb = np.max(np.abs(A[:, None] - A[None]), axis=2)
    best = max(sum(min(cheb[o[k], j] for j in o[k + 1:]) for k in range(5)) for o in itertools.permutations(range(6)))
    assert pure_diversity(A, p=np.inf, method="exact") == pytest.approx(best, rel=1e-12)
    # and the Minkowski values approach it as p grows (within m^(1/p)), without overflow
    assert pure_diversity(A, p=1e4, method="exact") == pytest.approx(best, rel=1e-3)


def test_pure_diversity_bad_arguments():
    with pytest.raises(ValueError, match="method"):
        pure_diversity([[0, 1], [1, 0]], method="fast")
    with pytest.raises(ValueError, match="p must be"):
        pure_diversity([[0, 1], [1, 0]], p=0)
    with pytest.raises(ValueError, match="p must be"):
        pure_diversity([[0, 1], [1, 0]], p=np.nan)
    with pytest.raises(TypeError, match="p must be a real number"):
        pure_diversity([[0, 1], [1, 0]], p="2")
    with pytest.raises(ValueError, match="at most 16 points"):
        pure_diversity(np.random.default_rng(0).random((17, 2)), method="exact")


# ----------------------------------------------------------------------------- spread


def test_spread_zero_for_even_front_reaching_extremes():
    t = np.linspace(0, 1, 6)
    P = np.column_stack([t, 1 - t])
    assert spread(P, P) == pytest.approx(0.0, abs=1e-14)


def test_spread_hand_case():
    # nearest distances a, a, 3a (a = sqrt(2)/4), mean 5a/3, deviations 2a/3, 2a/3, 4a/3;
    # extremes (1,0) and (0,1) are in P: (0 + 8a/3) / (0 + 3 * 5a/3) = 8/15
    P = [[0, 1], [0.25, 0.75], [1, 0]]
    assert spread(P, [[0, 1], [0.5, 0.5], [1, 0]]) == pytest.approx(8 / 15, rel=1e-14)


def test_spread_hand_case_with_extreme_gaps():
    # P = (0.2,0.8), (0.8,0.2): nearest distances equal (d = 0.6 sqrt 2), deviations 0;
    # extremes (1,0), (0,1) at distance 0.2 sqrt 2 each: 0.4 sqrt2 / (0.4 sqrt2 + 1.2 sqrt2) = 1/4
    P = [[0.2, 0.8], [0.8, 0.2]]
    assert spread(P, [[0, 1], [1, 0]]) == pytest.approx(0.25, rel=1e-14)


def test_spread_extremes_are_reference_maxima_in_3d():
    ref = np.eye(3)                 # extremes: the three corners
    P = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    assert spread(P, ref) == pytest.approx(0.0, abs=1e-14)  # equilateral, extremes reached


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize("func", [igd, igd_plus, spread])
def test_reference_set_columns_must_match(func):
    with pytest.raises(ValueError, match=r"ref_set must have 2 columns.*\(3, 3\)"):
        func([[0, 1], [1, 0]], np.zeros((3, 3)))


def test_hypervolume_reference_point_shape():
    with pytest.raises(ValueError, match=r"ref_point must have 2 columns.*\(1, 3\)"):
        hypervolume([[0, 1], [1, 0]], [1, 1, 1])


@pytest.mark.parametrize("func", [spacing, pure_diversity])
def test_non_finite_objectives_rejected(func):
    with pytest.raises(ValueError, match="F must have finite entries"):
        func([[0, np.nan], [1, 0]])
    with pytest.raises(TypeError, match="F must be an array"):
        func("abc")


# ----------------------------------------------------------------------------- other implementations


def test_against_pymoo_indicators():
    """pymoo's IGD, IGD+, HV and spacing (the last with the population std, 1/n instead of 1/(n-1))."""
    from pymoo.indicators.hv import HV
    from pymoo.indicators.igd import IGD
    from pymoo.indicators.igd_plus import IGDPlus
    from pymoo.indicators.spacing import SpacingIndicator

    rng = np.random.default_rng(11)
    A, R = rng.random((30, 3)), rng.random((50, 3))
    assert igd(A, R) == pytest.approx(IGD(R)(A), rel=1e-12)
    assert igd_plus(A, R) == pytest.approx(IGDPlus(R)(A), rel=1e-12)
    assert hypervolume(A, [1.2, 1.1, 1.0]) == pytest.approx(HV(ref_point=np.array([1.2, 1.1, 1.0]))(A), rel=1e-12)
    n = len(A)
    assert spacing(A) == pytest.approx(SpacingIndicator()(A) * math.sqrt(n / (n - 1)), rel=1e-12)


# ----------------------------------------------------------------------------- the float range's edge (issue 23, 11)


def test_spacing_of_fronts_spanning_the_float_range():
    # the common scale was 2^1024 = inf for coordinates near 1.8e308: A / inf = 0 and 0 * inf = NaN
    F = np.array([[-1e308, 1e308], [0.0, 0.0], [1e308, -1e308]])        # every nearest L1 distance 2e308
    assert spacing(F) == 0.0
    G = np.column_stack([[0.0, 2e307, 4e307, 8e307], [1.7e308, 1.5e308, 1.3e308, 0.9e308]])
    d = np.array([4.0, 4.0, 4.0, 8.0])                                   # nearest L1 distances / 1e307, by hand
    assert spacing(G) == pytest.approx(1e307 * np.std(d, ddof=1), rel=1e-12)


def test_pure_diversity_near_the_float_range_and_its_overflow():
    line = lambda xs: np.column_stack([xs, np.zeros(len(xs))])  # noqa: E731
    F = line([1.0e308, 1.5e308, 1.7e308])
    # greedy: withdraw 1.0 (nearest 0.5), then 1.5 or 1.7 (0.2): 0.7e308; exact: remove 1.5 first: 0.2 + 0.7
    assert pure_diversity(F) == pytest.approx(0.7e308, rel=1e-12)
    assert pure_diversity(F, method="exact") == pytest.approx(0.9e308, rel=1e-12)
    assert pure_diversity(F, p=np.inf) == pytest.approx(0.7e308, rel=1e-12)
    # +-1e308 apart in two objectives: (2 (2e308)^0.1)^10 is beyond the float range: said, not inf or NaN
    with pytest.raises(OverflowError, match="pure diversity exceeds the float range"):
        pure_diversity([[-1e308, 1e308], [1e308, -1e308]])
    with pytest.raises(OverflowError, match="spacing exceeds the float range"):
        spacing([[-1.7e308, -1.7e308], [1.7e308, 1.7e308], [1.7e308, 1.6e308]])   # std of [6.7, .1, .1]e308


@pytest.mark.parametrize("p", [1e-300, 1e-3, 0.0099])
def test_pure_diversity_refuses_a_vanishing_exponent(p):
    # p -> 0: (|a|^p + |b|^p)^(1/p) -> 2^(1/p) |.|, inf for p = 1e-300 (returned before)
    with pytest.raises(ValueError, match=r"p must be >= 0.01 \(or inf\)"):
        pure_diversity([[0.0, 0.0], [1.0, 1.0]], p=p)
    assert pure_diversity([[0.0, 0.0], [1.0, 1.0]], p=0.01) == pytest.approx(2.0 ** 100, rel=1e-12)
