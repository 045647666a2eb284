"""Problems by name: the paper's two control-design MOPs and the ZDT/DTLZ/WFG benchmarks.

``make_problem(name, n_obj=None)`` returns a pymoo :class:`~pymoo.core.problem.Problem`
carrying two reference points:

* ``hv_ref_point`` - the hypervolume reference point of the runs' HV history;
* ``molsp_ref_point`` - the fixed reference point ``r`` of MO-LSP's leader choice.

``generic`` and ``applied`` (3 and 4 objectives) come from
:mod:`moo.problems.generic` and :mod:`moo.problems.applied`, imported on first
use; they set their own reference points from the scale of our objectives
(the paper's HV points ``[25, 25, 25]`` and ``[5000, 10000, 5000, 5000]`` are in
its own units, not ours; see those modules).

ZDT1-6 (2 objectives) and DTLZ1-7 (``n_obj`` objectives, default 3) are pymoo's,
with Deb et al.'s numbers of variables: ZDT 30 (ZDT4, ZDT6: 10), DTLZ
``n_obj + k - 1`` with ``k`` = 5 (DTLZ1), 10 (DTLZ2-6), 20 (DTLZ7). For them both
reference points are ``nadir + 0.1 (nadir - ideal)`` of the true Pareto front
(1.1 x the nadir when the ideal point is the origin), from the fronts' closed
forms (:func:`true_front_bounds`). ZDT5 is binary; it is offered as a
real-coded relaxation (:class:`ZDT5Real`: each variable in [0, 1] stands for
the bit ``x >= 0.5``) so that the real-coded operators of the registry apply.

WFG1-9 (``n_obj`` objectives, default 3) are pymoo's, with the WFG toolkit's
usual sizes: ``k = 2 (M - 1)`` position and ``l = 20`` distance variables (``k
= 4`` for 2 objectives), ``z_i`` in ``[0, 2 i]``. Their true fronts span
``f_m`` in ``[0, 2 m]`` (Huband et al. 2006, the scaling constants
``S_m = 2 m``), except the degenerate WFG3, whose front is a line with
``f_1 <= 2 (1/2)^(M-2)``, ``f_m <= 2 m (1/2)^(M-m)`` for ``1 < m < M`` and
``f_M <= 2 M``; the reference points follow from these bounds as for DTLZ.
pymoo's WFG1 lifts every point of its sampled front by about 0.09: its
polynomial bias ``y^0.02`` turns the rounding residue of an optimal distance
variable (``1e-17`` instead of 0) into about 0.47, so its optimum as computed
differs from the closed form; the bounds here are the closed-form ones.

References
----------
E. Zitzler, K. Deb and L. Thiele (2000), "Comparison of multiobjective
evolutionary algorithms: empirical results", Evol. Comput. 8(2), 173-195;
K. Deb, L. Thiele, M. Laumanns and E. Zitzler (2005), "Scalable test problems
for evolutionary multiobjective optimization", in Evolutionary Multiobjective
Optimization, Springer, 105-145;
S. Huband, P. Hingston, L. Barone and L. While (2006), "A review of
multiobjective test problems and a scalable test problem toolkit", IEEE TEVC
10(5), 477-506.
"""

from __future__ import annotations

from importlib import import_module

import numpy as np
from pymoo.core.problem import Problem
from pymoo.problems.many import dtlz, wfg
from pymoo.problems.multi import zdt
from scipy.optimize import minimize_scalar

__all__ = ["PROBLEMS", "make_problem", "true_front_bounds", "ZDT5Real"]

_CONTROL = {"generic": ("moo.problems.generic", "GenericRLQRProblem", 3),
            "applied": ("moo.problems.applied", "AppliedRLQRProblem", 4)}
_ZDT = {f"zdt{i}": getattr(zdt, f"ZDT{i}") for i in range(1, 7)}
_DTLZ = {f"dtlz{i}": getattr(dtlz, f"DTLZ{i}") for i in range(1, 8)}
_DTLZ_K = {"dtlz1": 5, "dtlz7": 20}          # others: 10
_MAX_DTLZ_OBJ = 15
_WFG = {f"wfg{i}": getattr(wfg, f"WFG{i}") for i in range(1, 10)}
_WFG_L = 20

#: Every name :func:`~moo.problems.make_problem` accepts.
PROBLEMS: tuple[str, ...] = (*_CONTROL, *_ZDT, *_DTLZ, *_WFG)

#: Relative margin of the ZDT/DTLZ reference points beyond the nadir.
REF_MARGIN = 0.1


class ZDT5Real(zdt.ZDT5):
    r"""ZDT5 on [0, 1]^80 read as bits ``x >= 0.5`` (pymoo's normalised objectives).

    ZDT5 is a binary problem; this real-coded relaxation lets the
    real-coded operators of the registry run on it. Its objectives are
    those of pymoo's ZDT5 at the bits :math:`b_i = [x_i \ge 0.5]`.

    Parameters
    ----------
    m, n, normalize
        As pymoo's ZDT5: ``m`` groups of bits (11), the first of 30 bits and
        the others of ``n`` (5); ``normalize`` the objectives (True).

    See Also
    --------
    make_problem : ``make_problem("zdt5")`` returns it, with reference points.

    References
    ----------
    .. [1] E. Zitzler, K. Deb and L. Thiele, "Comparison of multiobjective
       evolutionary algorithms: empirical results", Evol. Comput. 8(2),
       173-195, 2000.

    Examples
    --------
    >>> import numpy as np
    >>> from pymoo.problems.multi.zdt import ZDT5
    >>> from moo.problems import ZDT5Real
    >>> x = np.random.default_rng(0).random((4, 80))
    >>> np.allclose(ZDT5Real().evaluate(x), ZDT5().evaluate((x >= 0.5).astype(float)))
    True
    """

    def _evaluate(self, x, out, *args, **kwargs):
        super()._evaluate((np.asarray(x) >= 0.5).astype(float), out, *args, **kwargs)


def _dtlz7_hump() -> tuple[float, float]:
    """Argmax and max of h(x) = x/2 (1 + sin 3 pi x) on the last hump of DTLZ7's front."""
    res = minimize_scalar(lambda x: -0.5 * x * (1 + np.sin(3 * np.pi * x)), bounds=(0.7, 1.0),
                          method="bounded", options={"xatol": 1e-12})
    return float(res.x), float(-res.fun)


def true_front_bounds(name: str, n_obj: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Ideal and nadir points of the true Pareto front of a ZDT/DTLZ/WFG problem (closed forms).

    Parameters
    ----------
    name : str
        ``zdt1`` ... ``zdt6``, ``dtlz1`` ... ``dtlz7``, ``wfg1`` ... ``wfg9``
        (case-insensitive).
    n_obj : int, optional
        Number of objectives (DTLZ and WFG; default 3).

    Returns
    -------
    ideal, nadir : (n_obj,) ndarray
        The smallest and largest value of each objective on the true front.

    Raises
    ------
    ValueError
        A name that is not a ZDT, DTLZ or WFG problem.

    See Also
    --------
    make_problem : sets the reference points from these bounds.

    Notes
    -----
    ZDT1/2/4/5: [0, 0], [1, 1] (ZDT5 normalised as in pymoo); ZDT3: f1 in
    [0, 0.8518], f2 in [-0.7734, 1]; ZDT6: f1 in [0.2808, 1] (the minimum of
    ``1 - exp(-4 x) sin^6(6 pi x)``), f2 = 1 - f1^2 in [0, 0.9212]. DTLZ1: 0 and 0.5;
    DTLZ2-4: 0 and 1; DTLZ5/6 (a curve): nadir
    ``[c^(M-2), c^(M-2), c^(M-3), ..., c, 1]``, ``c = 1/sqrt(2)``; DTLZ7: f_i
    (i < M) in [0, x*], f_M in [2 (M - (M-1) h(x*)), 2M], with x* ~ 0.8594 the
    maximiser of

    .. math::

        h(x) = \tfrac{x}{2} \big(1 + \sin 3 \pi x\big)

    on the front's last segment. WFG: 0 and ``2 m`` (WFG3: the line's ends,
    see the module docstring).

    References
    ----------
    .. [1] K. Deb, L. Thiele, M. Laumanns and E. Zitzler, "Scalable test
       problems for evolutionary multiobjective optimization", in Evolutionary
       Multiobjective Optimization, Springer, 105-145, 2005.
    .. [2] S. Huband, P. Hingston, L. Barone and L. While, "A review of
       multiobjective test problems and a scalable test problem toolkit",
       IEEE TEVC 10(5), 477-506, 2006.

    Examples
    --------
    The bounds of DTLZ2's front are those of pymoo's sampled front:

    >>> import numpy as np
    >>> from moo.problems import make_problem, true_front_bounds
    >>> ideal, nadir = true_front_bounds("dtlz2", 3)
    >>> front = make_problem("dtlz2", 3).pareto_front()
    >>> np.allclose(front.min(axis=0), ideal), np.allclose(front.max(axis=0), nadir)
    (True, True)
    """
    key = name.lower()
    if key in _WFG:
        M = 3 if n_obj is None else n_obj
        nadir = 2.0 * np.arange(1, M + 1)
        if key == "wfg3" and M > 2:
            nadir[:-1] *= 0.5 ** (M - np.maximum(np.arange(1, M), 2))
        return np.zeros(M), nadir
    if key in _ZDT:
        if key == "zdt3":
            # f2 = 1 - sqrt(f1) - f1 sin(10 pi f1) on the front's last segment [0.8233, 0.8518]
            f1 = minimize_scalar(lambda x: 1 - np.sqrt(x) - x * np.sin(10 * np.pi * x), bounds=(0.8, 0.86),
                                 method="bounded", options={"xatol": 1e-12}).x
            f2_min = 1 - np.sqrt(f1) - f1 * np.sin(10 * np.pi * f1)
            return np.array([0.0, f2_min]), np.array([f1, 1.0])
        if key == "zdt6":
            # f1 = 1 - exp(-4 x) sin^6(6 pi x) is smallest near x = 1/12
            f1_min = minimize_scalar(lambda x: 1 - np.exp(-4 * x) * np.sin(6 * np.pi * x) ** 6,
                                     bounds=(0.0, 1.0 / 6.0), method="bounded", options={"xatol": 1e-12}).fun
            return np.array([f1_min, 0.0]), np.array([1.0, 1.0 - f1_min**2])
        return np.zeros(2), np.ones(2)
    if key in _DTLZ:
        M = 3 if n_obj is None else n_obj
        if key == "dtlz1":
            return np.zeros(M), np.full(M, 0.5)
        if key in ("dtlz2", "dtlz3", "dtlz4"):
            return np.zeros(M), np.ones(M)
        if key in ("dtlz5", "dtlz6"):
            c = 1.0 / np.sqrt(2.0)
            nadir = np.array([c ** (M - 2)] + [c ** (M - m) for m in range(2, M)] + [1.0])
            return np.zeros(M), nadir
        x_star, h_star = _dtlz7_hump()
        ideal = np.zeros(M)
        ideal[-1] = 2.0 * (M - (M - 1) * h_star)
        nadir = np.full(M, x_star)
        nadir[-1] = 2.0 * M
        return ideal, nadir
    raise ValueError(f"true_front_bounds knows ZDT, DTLZ and WFG problems only, got {name!r}")


def make_problem(name: str, n_obj: int | None = None, *, setup: str | None = None) -> Problem:
    r"""A problem by name, with ``hv_ref_point`` and ``molsp_ref_point`` attributes.

    Parameters
    ----------
    name : str
        One of :data:`PROBLEMS` (case-insensitive): ``generic``, ``applied``,
        ``zdt1`` ... ``zdt6``, ``dtlz1`` ... ``dtlz7``, ``wfg1`` ... ``wfg9``.
    n_obj : int, optional
        Number of objectives. DTLZ and WFG: 2 to 15, default 3. The others have
        a fixed number (generic 3, applied 4, ZDT 2); giving another one is an
        error.
    setup : str, optional
        ``applied`` only: ``"ours"`` (default) or ``"authors"``
        (:class:`~moo.problems.applied.AppliedRLQRProblem`).

    Returns
    -------
    pymoo.core.problem.Problem
        The problem, with the two reference points (module docstring).

    Raises
    ------
    TypeError
        ``name`` not a string, ``n_obj`` not an integer.
    ValueError
        Unknown name or an ``n_obj`` the problem does not have, a ``setup``
        for a problem other than ``applied``.
    NotImplementedError
        ``generic``/``applied`` when their module is not available.

    See Also
    --------
    true_front_bounds : the benchmarks' ideal and nadir points.
    moo.run : one run on a problem by name.

    Notes
    -----
    For the benchmarks both reference points are

    .. math::

        r = z^{nad} + 0.1\, (z^{nad} - z^*)

    from the true front's ideal :math:`z^*` and nadir :math:`z^{nad}`
    (:func:`true_front_bounds`).

    Examples
    --------
    >>> import numpy as np
    >>> from moo.problems import make_problem, true_front_bounds
    >>> problem = make_problem("dtlz2", n_obj=3)
    >>> problem.n_var, problem.n_obj
    (12, 3)
    >>> ideal, nadir = true_front_bounds("dtlz2", 3)
    >>> np.allclose(problem.hv_ref_point, nadir + 0.1 * (nadir - ideal))
    True
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a string, got {type(name).__name__}")
    key = name.lower()
    if key not in PROBLEMS:
        raise ValueError(f"unknown problem {name!r}; valid: {', '.join(PROBLEMS)}")
    if n_obj is not None and (isinstance(n_obj, bool) or not isinstance(n_obj, (int, np.integer))):
        raise TypeError(f"n_obj must be an integer or None, got {type(n_obj).__name__}")

    if setup is not None and key != "applied":
        raise ValueError(f"setup applies to the 'applied' problem only, got setup={setup!r} for {key!r}")
    if key in _CONTROL:
        module, cls, m = _CONTROL[key]
        if n_obj is not None and n_obj != m:
            raise ValueError(f"problem {key!r} has {m} objectives, got n_obj={n_obj}")
        try:
            problem_cls = getattr(import_module(module), cls)
        except (ImportError, AttributeError) as exc:
            raise NotImplementedError(f"problem {key!r} is not available: {exc}") from exc
        problem = problem_cls() if setup is None else problem_cls(setup=setup)
        for attr in ("hv_ref_point", "molsp_ref_point"):
            if getattr(problem, attr, None) is None:
                raise NotImplementedError(f"{cls} lacks the {attr} attribute")
        return problem

    if key in _ZDT:
        if n_obj is not None and n_obj != 2:
            raise ValueError(f"problem {key!r} has 2 objectives, got n_obj={n_obj}")
        problem = ZDT5Real() if key == "zdt5" else _ZDT[key]()
        ideal, nadir = true_front_bounds(key)
    else:
        M = 3 if n_obj is None else int(n_obj)
        if not 2 <= M <= _MAX_DTLZ_OBJ:
            raise ValueError(f"n_obj must be between 2 and {_MAX_DTLZ_OBJ} for {key}, got {M}")
        if key in _WFG:
            k = 4 if M == 2 else 2 * (M - 1)
            problem = _WFG[key](n_var=k + _WFG_L, n_obj=M, k=k, l=_WFG_L)
        else:
            problem = _DTLZ[key](n_var=M + _DTLZ_K.get(key, 10) - 1, n_obj=M)
        ideal, nadir = true_front_bounds(key, M)
    ref = nadir + REF_MARGIN * (nadir - ideal)
    problem.hv_ref_point = ref
    problem.molsp_ref_point = ref.copy()
    return problem
