"""Quality indicators of a Pareto-front approximation (paper Section 4.1.3).

All functions take objective vectors as a 2-D array ``F`` of shape
``(n_points, n_obj)`` (minimisation), usually the non-dominated set a run
returned; none of them filters dominated points, pass the set you mean to
assess. ``ref_set`` is a reference set ``P*`` sampling the true front (for the
control-design MOPs, whose front is unknown, the non-dominated union of all
runs, see PAPER_NOTES.md).

=================  =======================  ========  ==========================================
indicator          function                 better    source
=================  =======================  ========  ==========================================
IGD                :func:`igd`              lower     Coello & Reyes Sierra (2004)
IGD+               :func:`igd_plus`         lower     Ishibuchi et al. (2015); moocore
Spacing (SP)       :func:`spacing`          lower     Schott (1995)
Hypervolume (HV)   :func:`hypervolume`      higher    While et al. (2006); moocore
Pure diversity     :func:`pure_diversity`   higher    Wang, Jin & Yao (2017)
Spread             :func:`spread`           lower     Zhou et al. (2006); Wang, Wu & Yuan (2010)
=================  =======================  ========  ==========================================

Scale. Every indicator is computed on the objective vectors divided by a
common power of two (about the largest magnitude in ``F``, ``ref_set`` and
``ref_point``, so the scaled coordinates lie in ``(-2, 2)``; an exact
division) and scaled back: distances are homogeneous of degree 1, the
hypervolume of degree ``m``, Spread of degree 0. So coordinates up to the
float range (fronts spanning ``+-1e308``) give finite, accurate values
(squared distances would overflow above about 1e154 and underflow below
1e-154); an indicator whose value itself exceeds the float range (a
hypervolume, or a spacing or pure diversity of points ``2e308`` apart)
raises ``OverflowError`` instead of returning ``inf`` or NaN.
"""

from __future__ import annotations

from typing import Literal

import moocore
import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.distance import cdist

from .validation import as_matrix, check_positive_scalar

__all__ = ["igd", "igd_plus", "spacing", "hypervolume", "pure_diversity", "spread"]

#: Largest set :func:`pure_diversity` accepts with ``method="exact"`` (2^n subsets).
PD_EXACT_MAX_POINTS = 16
#: Smallest Minkowski exponent :func:`pure_diversity` accepts: the dissimilarity of two vectors differing in
#: all ``m`` objectives by the same amount ``t`` is ``m^(1/p) t``, finite for ``p >= 0.01`` up to 1200 objectives.
PD_MIN_P = 0.01


def _points(F: ArrayLike, name: str, *, n_obj: int | None = None, min_rows: int = 1) -> np.ndarray:
    arr = as_matrix(F, name, cols=n_obj, cols_what="the number of objectives")
    if arr.shape[0] < min_rows:
        raise ValueError(f"{name} must have at least {min_rows} points (rows), got shape {arr.shape}")
    return arr


def _common_scale(*arrays: np.ndarray) -> float:
    """A power of two at most the largest magnitude in ``arrays`` and above half of it (1 when all are zero).

    ``2^(e - 1)`` with ``top = f 2^e``, ``0.5 <= f < 1``: finite even for
    ``top`` near the float maximum (``2^e`` itself would be ``2^1024 = inf``
    there, and ``A / inf = 0`` turned every indicator into NaN).
    """
    top = max(float(np.max(np.abs(a))) for a in arrays)
    return 1.0 if top == 0.0 else float(np.ldexp(1.0, int(np.frexp(top)[1]) - 1))


def _scaled_back(value: float, c: float, name: str) -> float:
    """``c * value``; ``OverflowError`` naming the indicator if that exceeds the float range."""
    with np.errstate(over="ignore"):
        out = float(np.float64(c) * np.float64(value))
    if not np.isfinite(out):
        raise OverflowError(f"the {name} exceeds the float range ({value!r} x {c!r}); rescale the objectives")
    return out


def _distance_to_reference(indicator, F: ArrayLike, ref_set: ArrayLike) -> float:
    """``indicator(F, ref=ref_set)`` (a moocore distance indicator, degree 1) on the scaled sets."""
    A = _points(F, "F")
    R = _points(ref_set, "ref_set", n_obj=A.shape[1])
    c = _common_scale(A, R)
    return c * float(indicator(A / c, ref=R / c))


def _nearest_neighbour(D: np.ndarray) -> np.ndarray:
    """Row-wise minimum of a square distance matrix, the diagonal excluded."""
    D = D.copy()
    np.fill_diagonal(D, np.inf)
    return D.min(axis=1)


def igd(F: ArrayLike, ref_set: ArrayLike) -> float:
    r"""Inverted generational distance, the paper's Eqs. (igd) and (dk).

    Parameters
    ----------
    F : array_like, shape (n, m)
        The approximation ``P``.
    ref_set : array_like, shape (k, m)
        The reference set ``P*``.

    Returns
    -------
    float
        Mean Euclidean distance from each reference point to its nearest point of ``F``.

    Raises
    ------
    TypeError, ValueError
        ``F`` or ``ref_set`` not a finite 2-D array of numbers, empty, or with
        other numbers of columns (the message names the argument and the shapes).

    See Also
    --------
    igd_plus : the Pareto-compliant variant.
    hypervolume : the other indicator of a front without a reference set.

    Notes
    -----
    .. math::

        IGD(P, P^*) = \frac{1}{|P^*|} \sum_{k \in P^*} \min_{i \in P} \lVert k - i \rVert_2 .

    Computed by :func:`moocore.igd`.

    References
    ----------
    .. [1] C. A. Coello Coello and M. Reyes Sierra, "A study of the
       parallelization of a coevolutionary multi-objective evolutionary
       algorithm", MICAI 2004, LNCS 2972, 2004.

    Examples
    --------
    The middle reference point is :math:`\sqrt{0.5}` from both points, the
    others lie on ``F``:

    >>> import numpy as np
    >>> from moo.indicators import igd
    >>> value = igd([[0, 1], [1, 0]], [[0, 1], [0.5, 0.5], [1, 0]])
    >>> value
    0.2357
    >>> bool(np.isclose(value, np.sqrt(0.5) / 3))
    True
    """
    return _distance_to_reference(moocore.igd, F, ref_set)


def igd_plus(F: ArrayLike, ref_set: ArrayLike) -> float:
    r"""IGD+, the Pareto-compliant modification of IGD (minimisation).

    .. math::

        IGD^+(P, P^*) = \frac{1}{|P^*|} \sum_{k \in P^*} \min_{i \in P}
        \Big(\sum_{j=1}^{m} \max(i_j - k_j, 0)^2\Big)^{1/2},

    the distance from each reference point to the part of the nearest point's
    dominated region: only the objectives in which ``i`` is worse than ``k``
    count. Zero when ``F`` weakly dominates every reference point.

    Parameters
    ----------
    F : array_like, shape (n, m)
        The approximation ``P``.
    ref_set : array_like, shape (k, m)
        The reference set ``P*``.

    References
    ----------
    H. Ishibuchi, H. Masuda, Y. Tanigaki and Y. Nojima (2015), "Modified distance
    calculation in generational distance and inverted generational distance",
    EMO 2015, LNCS 9019, 110-125. Computed by :func:`moocore.igd_plus`.

    Examples
    --------
    ``(0.5, 0.5)`` is worse than each reference point in one objective, by 0.5;
    a point that dominates the reference set scores 0:

    >>> from moo.indicators import igd_plus
    >>> igd_plus([[0.5, 0.5]], [[0, 1], [1, 0]])
    0.5
    >>> igd_plus([[0, 0]], [[0, 1], [1, 0]])
    0.0
    """
    return _distance_to_reference(moocore.igd_plus, F, ref_set)


def spacing(F: ArrayLike) -> float:
    r"""Schott's spacing: sample standard deviation of nearest-neighbour L1 distances.

    .. math::

        SP(P) = \sqrt{\frac{1}{|P| - 1} \sum_{i \in P} (\bar d - d_i)^2},
        \qquad d_i = \min_{h \in P, h \ne i} \sum_{j=1}^{m} |f_j(i) - f_j(h)|,

    with :math:`\bar d` the mean of the :math:`d_i`. Zero for evenly spaced points.

    Notes
    -----
    The paper's Eq. (sp) drops the square of :math:`\bar d - d_i` (a typo: the sum
    of deviations from the mean is identically zero) and writes a Euclidean
    :math:`d_i`; we follow Schott's definition, with the L1 (city-block) distance
    between objective vectors, which is also what PlatEMO, where the paper's
    experiments ran, computes.

    Parameters
    ----------
    F : array_like, shape (n, m), n >= 2

    References
    ----------
    J. R. Schott (1995), "Fault tolerant design using single and multicriteria
    genetic algorithm optimization", MSc thesis, MIT.

    Examples
    --------
    Evenly spaced points score 0; nearest-neighbour L1 distances 2, 2 and 4
    give the sample standard deviation :math:`\sqrt{4/3}`:

    >>> from moo.indicators import spacing
    >>> spacing([[0, 2], [1, 1], [2, 0]])
    0.0
    >>> spacing([[0, 3], [1, 2], [3, 0]])
    1.1547
    """
    A = _points(F, "F", min_rows=2)
    c = _common_scale(A)
    d = _nearest_neighbour(cdist(A / c, A / c, metric="cityblock"))
    return _scaled_back(float(np.std(d, ddof=1)), c, "spacing")


def hypervolume(F: ArrayLike, ref_point: ArrayLike) -> float:
    r"""Hypervolume dominated by ``F`` and bounded by ``ref_point``, Eq. (hv).

    Points that do not strictly dominate ``r`` contribute nothing. Exact in
    any dimension (:func:`moocore.hypervolume`: dimension sweep in 2-D, HV3D+
    and HV4D+ in 3-D/4-D, inclusion-exclusion or recursion above).

    Parameters
    ----------
    F : array_like, shape (n, m)
        The points (minimised objectives).
    ref_point : array_like, shape (m,)
        The reference point ``r``.

    Returns
    -------
    float
        The hypervolume (0 when no point strictly dominates ``r``).

    Raises
    ------
    TypeError, ValueError
        ``F`` or ``ref_point`` not finite numbers, or of sizes that do not fit
        (the message names the argument and the shapes).
    OverflowError
        A hypervolume beyond the float range (rescale the objectives).

    See Also
    --------
    igd : distance to a reference set.
    moo.run : records the hypervolume after every generation.

    Notes
    -----
    .. math::

        HV(P, r) = \Lambda_m\Big(\bigcup_{i \in P} [f(i), r]\Big),

    the Lebesgue measure of the union of the boxes between each point and ``r``.

    References
    ----------
    .. [1] L. While, P. Hingston, L. Barone and S. Huband, "A faster algorithm
       for calculating hypervolume", IEEE TEVC 10(1), 29-38, 2006.
    .. [2] M. Lopez-Ibanez, moocore: core algorithms for multi-objective
       optimization.

    Examples
    --------
    Two 2 x 1 boxes overlapping in a unit square (inclusion-exclusion:
    ``2 + 2 - 1``):

    >>> from moo.indicators import hypervolume
    >>> hypervolume([[1, 2], [2, 1]], ref_point=[3, 3])
    3.0
    """
    A = _points(F, "F")
    r = as_matrix(ref_point, "ref_point", rows=1, cols=A.shape[1],
                  cols_what="the number of objectives of F").ravel()
    c = _common_scale(A, r)
    with np.errstate(over="ignore"):
        hv = float(moocore.hypervolume(A / c, ref=r / c) * np.float64(c) ** A.shape[1])
    if not np.isfinite(hv):
        raise OverflowError(f"the hypervolume exceeds the float range (the boxes reach about {c:.1e} in each of "
                            f"the {A.shape[1]} objectives); rescale the objectives")
    return hv


def _minkowski_dissimilarity(A: np.ndarray, p: float) -> np.ndarray:
    """``(sum_j |a_j - b_j|^p)^(1/p)``, ``max_j |a_j - b_j|`` for ``p = inf`` (cdist refuses ``p < 1``).

    Computed as ``d_max (sum_j (|a_j - b_j| / d_max)^p)^(1/p)``, which neither
    overflows nor underflows for large or small ``p``.
    """
    diff = np.abs(A[:, None, :] - A[None, :, :])
    top = diff.max(axis=2)
    if np.isinf(p):
        return top
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(top[..., None] > 0, diff / top[..., None], 0.0)
    return top * np.sum(ratio**p, axis=2) ** (1.0 / p)


def _pd_exact(D: np.ndarray) -> float:
    """The recursion of Eq. (pd) by dynamic programming over subsets (bitmasks)."""
    n = D.shape[0]
    full = (1 << n) - 1
    pd = np.zeros(1 << n)
    for mask in range(1, full + 1):
        members = [i for i in range(n) if mask >> i & 1]
        if len(members) < 2:
            continue
        best = -np.inf
        for i in members:
            rest = [j for j in members if j != i]
            best = max(best, pd[mask & ~(1 << i)] + D[i, rest].min())
        pd[mask] = best
    return float(pd[full])


def _pd_greedy(D: np.ndarray) -> float:
    """Graph-based greedy computation (see :func:`pure_diversity`, Notes)."""
    n = D.shape[0]
    component = np.arange(n)          # component label of each point in the link graph
    active = np.ones(n, dtype=bool)
    total = 0.0
    for _ in range(n - 1):
        allowed = component[:, None] != component[None, :]      # links that close no cycle
        dist = np.where(allowed, D, np.inf)
        nearest = dist.argmin(axis=1)
        nn = dist[np.arange(n), nearest]
        nn[~active] = -np.inf
        i = int(np.argmax(nn))
        j = int(nearest[i])
        total += float(nn[i])
        component[component == component[j]] = component[i]
        active[i] = False
    return total


def pure_diversity(F: ArrayLike, *, p: float = 0.1,
                   method: Literal["greedy", "exact"] = "greedy") -> float:
    r"""Pure diversity (PD) of Wang, Jin & Yao (2017), Eqs. (pd) and (ds).

    .. math::

        PD(X) = \max_{s_i \in X}\big(PD(X - s_i) + d(s_i, X - s_i)\big),\quad
        PD(\{s\}) = 0,\qquad
        d(s, X) = \min_{s_i \in X} \lVert s - s_i \rVert_p,

    with the Minkowski dissimilarity :math:`\lVert a - b\rVert_p =
    (\sum_j |a_j - b_j|^p)^{1/p}` (its limit :math:`\max_j |a_j - b_j|` for
    ``p = inf``), ``p = 0.1`` (an L_p "norm" with p < 1, which
    Wang et al. chose because it separates points better in many objectives).
    The paper's Eq. (ds) prints ``max`` in :math:`d(s, X)`; the original
    definition, followed here, is the dissimilarity to the *nearest* individual.

    Parameters
    ----------
    F : array_like, shape (n, m)
    p : float, default 0.1
        Minkowski exponent, ``PD_MIN_P = 0.01 <= p <= inf`` (``inf``: the
        Chebyshev distance, the limit). Smaller ``p`` are refused: as ``p ->
        0`` the dissimilarity of vectors differing in ``k >= 2`` objectives
        grows like ``k^(1/p)`` (``p = 1e-300`` gives ``inf`` for any such
        front, an indicator that no longer ranks anything).
    method : {"greedy", "exact"}
        ``"exact"`` evaluates the recursion exactly by dynamic programming over
        subsets, O(2^n n^2), for n <= 16. ``"greedy"`` (default) is the practical
        graph-based computation: each point starts as its own component; n - 1
        times, among the points not yet withdrawn, the one whose dissimilarity to
        its nearest point *in another component* (withdrawn points included) is
        the largest is withdrawn, that dissimilarity is added to PD, and the two
        components are joined (so no link closes a cycle), O(n^3). This is the
        graph-based computation used in practice for PD; PlatEMO, in which the
        paper's PD values were computed, checks the cycle condition lazily (only
        for the point it is about to withdraw) and breaks ties by row order, so
        its values can differ from ours in rare cases. Ties, common since two
        mutual nearest neighbours share their distance, go here to the
        lexicographically smallest objective vector, so the value does not
        depend on the order of the rows. The greedy value is not always equal
        to the recursion (points 0, 1, 3 on a line: greedy 3, exact 4).

    Returns
    -------
    float
        Larger is more diverse; 0 for a single point.

    Raises
    ------
    ValueError
        ``p`` is below ``PD_MIN_P``, NaN or not positive.
    OverflowError
        The value exceeds the float range (points about ``1e308`` apart).

    References
    ----------
    H. Wang, Y. Jin and X. Yao (2017), "Diversity assessment in many-objective
    optimization", IEEE Trans. Cybernetics 47(6), 1510-1522.

    Examples
    --------
    Points 0, 1 and 3 on a line (any ``p`` gives the plain distance in one
    objective), where the greedy computation and the recursion differ:

    >>> from moo.indicators import pure_diversity
    >>> pure_diversity([[0], [1], [3]])
    3.0
    >>> pure_diversity([[0], [1], [3]], method="exact")
    4.0
    """
    A = _points(F, "F")
    p = check_positive_scalar(p, "p", allow_inf=True)
    if p < PD_MIN_P:
        raise ValueError(f"p must be >= {PD_MIN_P:g} (or inf), got {p:g}: for smaller p the Minkowski "
                         "dissimilarity grows like (number of differing objectives)^(1/p) and overflows")
    if method not in ("greedy", "exact"):
        raise ValueError(f"method must be 'greedy' or 'exact', got {method!r}")
    n = A.shape[0]
    if n == 1:
        return 0.0
    A = A[np.lexsort(A.T[::-1])]          # canonical order: ties broken by the points, not the rows
    c = _common_scale(A)
    D = _minkowski_dissimilarity(A / c, p)
    if method == "exact":
        if n > PD_EXACT_MAX_POINTS:
            raise ValueError(f"method='exact' handles at most {PD_EXACT_MAX_POINTS} points, "
                             f"F has {n}; use method='greedy'")
        return _scaled_back(_pd_exact(D), c, "pure diversity")
    return _scaled_back(_pd_greedy(D), c, "pure diversity")


def spread(F: ArrayLike, ref_set: ArrayLike) -> float:
    r"""Generalised spread, the paper's Eq. (sprd).

    .. math::

        \Delta(P) = \frac{\sum_{i=1}^{m} d(e_i, P) + \sum_{x \in P} |d(x, P) - \bar d|}
                         {\sum_{i=1}^{m} d(e_i, P) + |P|\,\bar d},

    where :math:`e_i` is the point of ``ref_set`` with the largest ``i``-th
    objective (the ``i``-th extreme of the reference front; first one on ties),
    :math:`d(e_i, P)` its Euclidean distance to the nearest point of ``P``,
    :math:`d(x, P)` the Euclidean distance from ``x`` to its nearest *other*
    point of ``P``, and :math:`\bar d = \frac{1}{|P|}\sum_{x\in P} d(x, P)`.

    Notes
    -----
    The paper's Eq. (dm) averages :math:`d(\chi, P)` over :math:`P^*`; that
    contradicts its own numerator (deviations of the points of ``P`` from the
    mean) and the definition it cites, so the mean is taken over ``P`` as in
    Zhou et al. (2006). (PlatEMO, where the paper's values were computed,
    puts :math:`(|P| - m)\,\bar d` in the denominator instead.) Zero for
    evenly spaced points that reach the reference
    extremes; if every point of ``P`` coincides with the extremes and all
    nearest-neighbour distances are zero the ratio is 0/0 and 0.0 is returned.

    Parameters
    ----------
    F : array_like, shape (n, m), n >= 2
    ref_set : array_like, shape (k, m)

    References
    ----------
    A. Zhou, Y. Jin, Q. Zhang, B. Sendhoff and E. Tsang (2006), "Combining
    model-based and genetics-based offspring generation for multi-objective
    optimization using a convergence criterion", IEEE CEC 2006, 892-899;
    Y.-N. Wang, L.-H. Wu and X.-F. Yuan (2010), "Multi-objective self-adaptive
    differential evolution with elitist archive and crowding entropy-based
    diversity measure", Soft Computing 14(3), 193-209.

    Examples
    --------
    Evenly spaced points that reach the extremes of the reference front score
    0; uneven gaps raise it (nearest-neighbour distances 0.14, 0.14 and 1.27):

    >>> from moo.indicators import spread
    >>> front = [[0, 1], [0.5, 0.5], [1, 0]]
    >>> spread(front, front)
    0.0
    >>> spread([[0, 1], [0.1, 0.9], [1, 0]], front)
    0.9697
    """
    A = _points(F, "F", min_rows=2)
    R = _points(ref_set, "ref_set", n_obj=A.shape[1])
    c = _common_scale(A, R)                # Spread is a ratio: scaled distances give the same value
    A, R = A / c, R / c
    extremes = R[np.argmax(R, axis=0)]
    d_ext = cdist(extremes, A).min(axis=1).sum()
    d = _nearest_neighbour(cdist(A, A))
    d_bar = d.mean()
    numerator = d_ext + np.abs(d - d_bar).sum()
    denominator = d_ext + len(A) * d_bar
    if denominator == 0.0:
        return 0.0
    return float(numerator / denominator)
