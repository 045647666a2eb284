r"""Objective normalisation for reference-direction MOEAs: ideal point, extreme points, intercepts.

Package-internal: the algorithm modules share it; :mod:`moo.algorithms` does
not re-export it.

Many-objective algorithms that compare solutions against reference directions
(NSGA-III, theta-DEA, SPEA/R, ...) first map the objectives to a common scale

.. math::

    \tilde f_i(x) = \frac{f_i(x) - z^*_i}{z^{nad}_i - z^*_i}, \qquad i = 1, \dots, M,

where :math:`z^*` is the ideal point (the smallest value of each objective seen
so far) and :math:`z^{nad}` an estimate of the nadir point. This module offers
the two estimates in use:

* :class:`HyperplaneNormalization` - the procedure of NSGA-III (Deb & Jain
  2014, Sec. IV-C) as refined by theta-DEA (Yuan et al. 2016, Sec. III-C):
  a running ideal point; for each axis :math:`j` an *extreme point*
  :math:`e^j` minimising the achievement scalarising function

  .. math::

      \mathrm{ASF}_j(x) = \max_{i} \frac{|f_i(x) - z^*_i|}{s_i\, w^j_i},
      \qquad w^j_i = 1 \text{ if } i = j \text{ else } \varepsilon = 10^{-6},

  over the non-dominated solutions and the previous extreme points
  (:math:`s = z^{nad} - z^*` from the previous call, so the ASF is scale
  free), scaled terms :math:`|f_i - z^*_i| / s_i` below ``ZERO_TOL`` = 1e-3
  counting as zero (see "Readings" below); the hyperplane through the
  :math:`M` extreme points gives the intercepts :math:`a_j` and
  :math:`z^{nad} = z^* + a`. See :func:`extreme_points` and
  :func:`hyperplane_nadir`.
* :func:`front_bounds` - the simpler ideal/nadir of the current
  non-dominated solutions (min and max of each objective), used by SPEA/R
  (Jiang & Yang 2017, Sec. III-A).

Fallbacks (the usual ones, all documented where applied): when the extreme
points are linearly dependent, an intercept is not finite or not larger than
``min_intercept`` (a negative or degenerate hyperplane), the nadir estimate is
the worst value of each objective over the non-dominated solutions (theta-DEA's
choice); a range :math:`z^{nad}_i - z^*_i` still below ``min_range`` takes the
worst value over the whole population (pymoo's NSGA-III choice), and a range
that is still zero (a constant objective) is set to 1 so that the normalised
objective is a plain translation and never a division by zero.

Readings where the papers leave room
------------------------------------
* Near-zero terms in the ASF. Neither NSGA-III's nor theta-DEA's text says
  what happens when an off-axis term is tiny but not zero, and it matters:
  with the weight ``1e-6`` an off-axis term of ``1e-5`` (a well converged
  point close to the axis) costs 10 in the ASF, while a poorly converged
  point lying *exactly* on the axis (off-axis terms 0, which SBX and
  polynomial mutation produce at the bounds of the variables, e.g. DTLZ2's
  ``x_1 = 0``) costs only its axis term, about 1.03. Such a point, found in
  an early generation, is then never replaced, and the intercept stays 1-3 %
  too large for the rest of the run (measured on theta-DEA:
  :ref:`validation-theta-dea`). The
  theta-DEA authors' code (yyxhdy/ManyEAs, ``ThetaDEA.asfFunction``)
  computes the ASF exactly as printed and has the same flaw. pymoo's
  NSGA-III (``get_extreme_points_c``, read, not copied) sets the terms below
  1e-3 to zero; we do the same on the *scaled* terms (relative to the
  previous range ``s``), so that the rule does not depend on the units of
  the objectives. A near-axis point then competes by its axis term alone.

References
----------
K. Deb and H. Jain, "An evolutionary many-objective optimization algorithm
using reference-point-based nondominated sorting approach, Part I", IEEE TEVC
18(4), 577-601, 2014.

Y. Yuan, H. Xu, B. Wang and X. Yao, "A new dominance relation-based
evolutionary algorithm for many-objective optimization", IEEE TEVC 20(1),
16-37, 2016.

S. Jiang and S. Yang, "A strength Pareto evolutionary algorithm based on
reference direction for multiobjective and many-objective optimization",
IEEE TEVC 21(3), 329-346, 2017.
"""

from __future__ import annotations

import numpy as np

__all__ = ["HyperplaneNormalization", "extreme_points", "hyperplane_nadir", "front_bounds", "safe_range"]

ASF_EPSILON = 1e-6
MIN_INTERCEPT = 1e-6
MIN_RANGE = 1e-10
ZERO_TOL = 1e-3


def _as_objectives(F: np.ndarray, name: str = "F") -> np.ndarray:
    F = np.asarray(F, dtype=float)
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] == 0:
        raise ValueError(f"{name} must be a non-empty 2-D array (n_points, n_obj), got shape {F.shape}")
    if not np.all(np.isfinite(F)):
        raise ValueError(f"{name} must be finite (no NaN or inf objective values)")
    return F


def safe_range(low: np.ndarray, high: np.ndarray, fallback_high: np.ndarray | None = None,
               min_range: float = MIN_RANGE) -> np.ndarray:
    """The range ``high - low`` with the degenerate entries repaired.

    Entries with ``high - low <= min_range`` take ``fallback_high - low`` when
    ``fallback_high`` is given (e.g. the worst of the whole population); those
    still ``<= min_range`` become 1.
    """
    rng = np.asarray(high, dtype=float) - low
    if fallback_high is not None:
        bad = rng <= min_range
        rng[bad] = (np.asarray(fallback_high, dtype=float) - low)[bad]
    rng[rng <= min_range] = 1.0
    return rng


def extreme_points(F: np.ndarray, ideal: np.ndarray, scale: np.ndarray | None = None,
                   epsilon: float = ASF_EPSILON, zero_tol: float = ZERO_TOL) -> np.ndarray:
    """For each axis j, the row of ``F`` minimising ``ASF_j`` (first row on ties).

    ``ASF_j(f) = max_i t_i / w_i`` with ``t_i = |f_i - ideal_i| / scale_i``
    set to 0 when below ``zero_tol``, ``w_j = 1`` and ``w_i = epsilon`` for
    ``i != j`` (Deb & Jain 2014, Eq. 4; Yuan et al. 2016, Sec. III-C; the
    ``zero_tol`` rule is explained in the module docstring). Returns an
    ``(M, M)`` array whose row j is the extreme point of axis j.
    """
    F = _as_objectives(F)
    M = F.shape[1]
    scale = np.ones(M) if scale is None else np.asarray(scale, dtype=float)
    T = np.abs(F - ideal) / scale                              # (n, M)
    T[zero_tol > T] = 0.0
    weights = np.full((M, M), epsilon)
    np.fill_diagonal(weights, 1.0)
    asf = np.max(T[None, :, :] / weights[:, None, :], axis=2)  # (M axes, n)
    return F[np.argmin(asf, axis=1)]


def hyperplane_nadir(extremes: np.ndarray, ideal: np.ndarray,
                     min_intercept: float = MIN_INTERCEPT) -> np.ndarray | None:
    """Nadir estimate ``ideal + a`` from the hyperplane through the extreme points.

    Solves ``(E - ideal) b = 1`` for the plane ``b . (f - ideal) = 1``; the
    intercepts are ``a_j = 1 / b_j``. Returns None when ``E - ideal`` is rank
    deficient, or an intercept is not finite or ``<= min_intercept`` (the
    caller then falls back, see the module docstring).
    """
    E = np.asarray(extremes, dtype=float) - ideal
    M = E.shape[1]
    if E.shape != (M, M) or np.linalg.matrix_rank(E) < M:
        return None
    try:
        b = np.linalg.solve(E, np.ones(M))
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(b)) or not np.allclose(E @ b, 1.0):
        return None
    with np.errstate(divide="ignore"):
        intercepts = 1.0 / b
    if not np.all(np.isfinite(intercepts)) or np.any(intercepts <= min_intercept):
        return None
    return ideal + intercepts


def front_bounds(F: np.ndarray, nondominated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ideal point and range from the non-dominated rows of ``F`` (SPEA/R's normalisation).

    ``z_min = min F[nd]`` and ``range = max F[nd] - z_min``, the degenerate
    entries of the range repaired by :func:`safe_range` with the worst of the
    whole ``F`` as fallback.
    """
    F = _as_objectives(F)
    nd = F[np.asarray(nondominated)]
    if len(nd) == 0:
        raise ValueError("nondominated must select at least one row of F")
    z_min = nd.min(axis=0)
    return z_min, safe_range(z_min, nd.max(axis=0), F.max(axis=0))


class HyperplaneNormalization:
    """Running ideal point and hyperplane (intercept) nadir estimate.

    State kept between calls (the survival of an algorithm owns one
    instance): the ideal point (minimum of everything passed to
    :meth:`update`), the ``M`` extreme points and the last nadir estimate.

    Parameters
    ----------
    n_obj : int
        Number of objectives ``M``.
    epsilon : float
        Off-axis ASF weight (1e-6 in both papers).
    min_intercept : float
        Intercepts not larger than this reject the hyperplane.

    Notes
    -----
    One :meth:`update` (Yuan et al. 2016, procedure *Normalize*):

    1. ``z* <- min(z*, min F)``.
    2. Candidates: previous extreme points and the non-dominated rows of
       ``F``; for each axis the candidate minimising ``ASF_j`` with the scale
       ``s = z_nad - z*`` of the previous estimate (on the first call the
       worst of ``F``), previous extremes winning ties.
    3. ``z_nad`` from :func:`hyperplane_nadir`; on failure the worst of the
       non-dominated rows.
    4. Degenerate ranges repaired by :func:`safe_range` with the worst of
       ``F`` as fallback.

    Unlike pymoo's ``HyperplaneNormalization`` the nadir is not clipped to the
    worst point ever seen (the papers do not), and the ASF terms are rounded
    to zero relative to the scale, not in absolute units.
    """

    def __init__(self, n_obj: int, *, epsilon: float = ASF_EPSILON, min_intercept: float = MIN_INTERCEPT):
        if not isinstance(n_obj, (int, np.integer)) or n_obj < 1:
            raise ValueError(f"n_obj must be a positive integer, got {n_obj!r}")
        if not (0 < epsilon < 1):
            raise ValueError(f"epsilon must lie in (0, 1), got {epsilon!r}")
        self.n_obj = int(n_obj)
        self.epsilon = float(epsilon)
        self.min_intercept = float(min_intercept)
        self.reset()

    def reset(self) -> None:
        """Forget the ideal point, extreme points and nadir estimate."""
        self.ideal_point = np.full(self.n_obj, np.inf)
        self.nadir_point: np.ndarray | None = None
        self.extreme_points: np.ndarray | None = None
        self.hyperplane_ok = False

    def update(self, F: np.ndarray, nondominated: np.ndarray | None = None) -> None:
        """Update the ideal point, extreme points and nadir estimate with ``F``.

        ``nondominated`` indexes the non-dominated rows of ``F`` (all rows if
        None).
        """
        F = _as_objectives(F)
        if F.shape[1] != self.n_obj:
            raise ValueError(f"F must have {self.n_obj} columns (n_obj), got shape {F.shape}")
        nd = F if nondominated is None else F[np.asarray(nondominated)]
        if len(nd) == 0:
            raise ValueError("nondominated must select at least one row of F")
        self.ideal_point = np.minimum(self.ideal_point, F.min(axis=0))
        ideal = self.ideal_point
        worst = F.max(axis=0)
        if self.nadir_point is None:
            scale = safe_range(ideal, worst)
        else:
            scale = safe_range(ideal, self.nadir_point, worst)
        candidates = nd if self.extreme_points is None else np.vstack([self.extreme_points, nd])
        self.extreme_points = extreme_points(candidates, ideal, scale, self.epsilon)
        nadir = hyperplane_nadir(self.extreme_points, ideal, self.min_intercept)
        self.hyperplane_ok = nadir is not None
        if nadir is None:
            nadir = nd.max(axis=0)
        self.nadir_point = ideal + safe_range(ideal, nadir, worst)

    def normalize(self, F: np.ndarray) -> np.ndarray:
        """``(F - z*) / (z_nad - z*)`` with the current estimates."""
        if self.nadir_point is None:
            raise RuntimeError("HyperplaneNormalization.normalize called before update")
        F = np.asarray(F, dtype=float)
        return (F - self.ideal_point) / (self.nadir_point - self.ideal_point)
