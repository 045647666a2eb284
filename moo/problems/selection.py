"""Monte Carlo design selection: pick one design of a Pareto front (Morais et al. 2022, Secs. 4.4.1, 4.5.1).

A MOEA returns a whole front of RLQR uncertainty models ``z``; the controller
needs one. The paper picks it by simulation: every candidate design (the
front's decision vectors plus a few baselines) is run on the same ``S``
random realisations of the uncertainty, ``Delta ~ U(-1, 1)``; in each
simulation the design with the least cumulative error wins, and the design
that wins most often is the selected ``z*``. The paper ran ``S = 1000`` and
shows the win counts as a histogram (its Figs. "fl-generic", "fl-applied").

This module has three layers:

* :func:`monte_carlo_selection` - the counting rule on a (designs x
  simulations) array of cumulative errors (problem independent);
* the problem-specific samplers that produce that array for all designs and
  scenarios in one batched computation (no Python loop over designs):
  :func:`generic_errors` (the generic MOP of Section 4.4) and
  :func:`applied_errors` (the truck of Section 4.5);
* :func:`build_designs` (front + the paper's extra designs) and
  :func:`select_design` (everything in one call).

Any other :class:`moo.tuning.TuningProblem` goes through the general rule
of :mod:`moo.tuning.selection` (each simulation draws a scenario of the
problem, or a plant from a ``sampler``; the cumulative error is the weighted
sum of the problem's objectives on that plant alone): :func:`build_designs`
gives the front, the family's *nominal* design if it has one (``nominal()``,
e.g. :class:`moo.tuning.RLQRFamily`) and a *random* one, and
:func:`select_design` returns the same :class:`DesignSelection`.

Design sets (the paper's order). Generic: the ``N`` front designs, then the
*nominal* design, then a *random* one (``N + 2`` designs, 94 in the paper).
Applied: the front, *nominal*, *RLQR^A*, *random* (``N + 3``, 95 in the paper).

* *nominal*: the controller designed with no uncertainty, i.e. the LQR with
  the problem's ``Q``, ``R`` on its design plant (:func:`robustctl.lqr`; for the
  truck the doubled steering column ``[G G]`` with ``R = 2 r I``, whose
  summed steering gain is the plain truck's LQR gain).
* *random*: the RLQR of a ``z`` drawn uniformly from the problem's bounds.
* *RLQR^A*: the RLQR with the appendix's printed algebraic uncertainty
  (:func:`robustctl.models.morais2022.algebraic_uncertainty`, ``H = 1``, ``mu = 1e9``),
  with the problem's ``Q``, ``R`` and ``alpha``; its ``z`` is recorded as
  ``[EF (4), EG (2), 81]`` (outside the MOP's bounds: EF, EG are negative).

References
----------
D. C. Morais et al., "Robust path-following control design of heavy vehicles
based on multiobjective evolutionary optimization", Expert Systems with
Applications 192 (2022) 116304, Sections 4.4.1 and 4.5.1.
A. M. Barbosa et al., "Robust path-following control for articulated heavy-duty
vehicles", Control Engineering Practice 85 (2019) (RLQR^A, the doubled column).

Notes
-----
Layering: the paper's samplers live in :mod:`moo.problems` because, like the
problems, they are specific to the paper's MOPs and import ``robustctl`` (the
LQR, the truck model and the batched simulator); the counting rule and the
general selection are in :mod:`moo.tuning.selection` (re-exported here).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import robustctl as rc
from robustctl.models import morais2022, truck
from robustctl.models.morais2022 import get_setup
from robustctl.models.path import ReferencePath, default_route
from robustctl.models.pathfollow import PathFollowing, PathFollowingSetup
from robustctl.sim.simulator import check_gains

from ..tuning import TuningProblem
from ..tuning.selection import SelectionResult, check_weights, default_weights, draw_errors, monte_carlo_selection
from ..validation import as_matrix, check_int
from .applied import AppliedRLQRProblem
from .generic import GenericRLQRProblem

__all__ = [
    "SelectionResult", "DesignSet", "DesignSelection", "monte_carlo_selection", "draw_deltas",
    "overload_from_delta", "generic_errors", "applied_errors", "build_designs", "select_design", "is_paper_problem",
    "MAX_OVERLOAD", "BRYSON_SCALES", "error_scales",
]

#: Largest payload overload of the paper's robustness study [%] (Section 4.5.2: 0 to 300 %).
MAX_OVERLOAD = 300.0
#: Default error scales of :func:`applied_errors`, in the objectives' order
#: (``rho`` [m], ``psidot`` [rad/s], ``ydot`` [m/s], ``theta`` [rad]): Bryson's
#: acceptable errors :data:`robustctl.models.truck.MAX_ERRORS`, from which the
#: designs' state weight ``Q`` is built.
BRYSON_SCALES = tuple(float(truck.MAX_ERRORS[i]) for i in truck.OBJECTIVE_STATES)
#: Scenarios simulated together by :func:`applied_errors` (bounds the memory of the disturbance arrays).
_SCENARIO_CHUNK = 250


# ---------------------------------------------------------------------------
# scenarios and the problem-specific samplers
# ---------------------------------------------------------------------------

def _rng(seed) -> np.random.Generator:
    """``np.random.default_rng(seed)``, with an error that names ``seed``."""
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"seed must be None, a non-negative integer, a SeedSequence or a Generator "
                        f"({exc})") from None


def draw_deltas(n_sims: int, seed=None) -> np.ndarray:
    """``n_sims`` realisations ``Delta ~ U(-1, 1)`` from ``np.random.default_rng(seed)``."""
    n_sims = check_int(n_sims, "n_sims", 1)
    return _rng(seed).uniform(-1.0, 1.0, n_sims)


def _as_deltas(deltas) -> np.ndarray:
    d = as_matrix(deltas, "deltas", rows=1, rows_what="a 1-D array of realisations").ravel()
    if np.any(np.abs(d) > 1.0):
        raise ValueError(f"deltas must lie in [-1, 1] (||Delta|| <= 1), got min {d.min():g}, max {d.max():g}")
    return d


def overload_from_delta(deltas) -> np.ndarray:
    r"""Payload overload [%] of each realisation: ``150 (1 + Delta)``, so ``Delta in [-1, 1] -> [0, 300] %``.

    The truck's uncertainty is its payload, and the model refuses negative
    overloads (less than the nominal payload) by design, so ``Delta`` cannot be
    read as a symmetric deviation around the nominal payload. We map it
    affinely onto the paper's robustness range instead: the MSE table
    (Section 4.5.2) tests 0, 100, 200 and 300 % overload, so ``Delta = -1`` is
    the nominal payload, ``Delta = 0`` 150 % and ``Delta = 1`` 300 % (four times
    the payload). ``Delta ~ U(-1, 1)`` thus gives overloads ``~ U(0, 300)``.
    """
    return MAX_OVERLOAD / 2.0 * (1.0 + _as_deltas(deltas))


def _as_gains(K, n: int, ms: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(D, m, n) float gains (non-finite rows zeroed) and the (D,) mask of finite rows."""
    want = " or ".join(f"(D, {m}, {n})" for m in ms)
    try:
        arr, bad = check_gains(K, n, "flag")
    except ValueError:
        arr = None
    if arr is None or np.ndim(K) != 3 or arr.shape[1] not in ms:
        raise ValueError(f"K must have shape {want} (one gain per design), got shape {np.shape(K)}")
    return arr, ~bad


def generic_errors(K, deltas, *, problem: GenericRLQRProblem | None = None) -> np.ndarray:
    r"""Cumulative regulation errors (D, S) of gains ``K`` on the generic plant, one column per ``Delta``.

    For design ``d`` and realisation ``delta_s`` (held constant over the run, as
    in :class:`~moo.problems.generic.GenericRLQRProblem`) the closed loop is
    ``A_{d,s} = F + H delta_s E_F^true + (G + H delta_s E_G^true) K_d`` and

    .. math::

        E[d, s] = \sum_{j=1}^{3} e_{j}
                = \sum_{i=1}^{n_0} \sum_{k=0}^{N} \big\| A_{d,s}^k x_{0,i} \big\|^2 ,

    the sum over the three states of the problem's regulation errors
    (:meth:`~moo.problems.generic.GenericRLQRProblem.regulation_errors`), with
    the problem's initial states ``x_{0,i}`` (default the unit vectors, so
    ``E`` is the trace of the finite-horizon Gramian) and horizon ``N``. A
    closed loop that is not Schur-stable at ``delta_s`` (infinite regulation
    error), or a non-finite gain, gets ``+inf``.

    Parameters
    ----------
    K : (D, 1, 3) array_like
        Gains ``u = K x``; rows with NaN (failed designs) are allowed.
    deltas : (S,) array_like
        Realisations in ``[-1, 1]`` (see :func:`draw_deltas`).
    problem : GenericRLQRProblem, optional
        Source of the initial states and horizon (default: the default problem).

    Returns
    -------
    (D, S) ndarray
        All designs and realisations in one stacked recursion.
    """
    if problem is None:
        problem = GenericRLQRProblem()
    elif not isinstance(problem, GenericRLQRProblem):
        raise TypeError(f"problem must be a GenericRLQRProblem, got {type(problem).__name__}")
    Kb, ok = _as_gains(K, problem.plant.n, (problem.plant.m,))
    mc = GenericRLQRProblem(deltas=_as_deltas(deltas), initial_states=problem.initial_states,
                            horizon=problem.horizon, backend=problem.backend)
    e, _ = mc.regulation_errors(np.where(ok[:, None, None], Kb, np.nan))
    E = e.sum(axis=2)
    E[~ok] = np.inf
    return E


def error_scales(setup: str | PathFollowingSetup = "ours") -> np.ndarray:
    """Default scales of :func:`applied_errors`: ``1 / sqrt(Q_ii)`` of the set-up's state weight.

    In the objectives' order (``rho, psidot, ydot, theta``); ``"ours"`` gives :data:`BRYSON_SCALES`.
    """
    setup = get_setup(setup)
    q = np.asarray(setup.Q_diag, dtype=float)[list(truck.OBJECTIVE_STATES)]
    if np.any(q <= 0):
        raise ValueError(f"scales: the set-up's Q has a zero weight on an objective's state ({setup.Q_diag}); "
                         "give scales")
    return 1.0 / np.sqrt(q)


def _as_scales(scales, setup: PathFollowingSetup) -> np.ndarray:
    if scales is None:                  # E is the quadratic state cost of the set-up's Q
        return error_scales(setup)
    s = as_matrix(scales, "scales", rows=1, cols=4, cols_what="one per objective: rho, psidot, ydot, theta").ravel()
    if np.any(s <= 0):
        raise ValueError(f"scales must be positive, got {s}")
    return s


def applied_errors(K, deltas, *, path: ReferencePath | None = None, scales=None,
                   setup: str | PathFollowingSetup = "ours") -> np.ndarray:
    r"""Cumulative normalised tracking errors (D, S) of truck gains ``K``, one column per ``Delta``.

    Each ``Delta_s`` is a payload overload ``150 (1 + Delta_s)`` % held over the
    run (:func:`overload_from_delta`); every design drives the true truck at
    that payload along ``path`` (:class:`robustctl.models.pathfollow.PathFollowing`
    in the ``setup``'s loop, 0.45 rad steering limit; ``"ours"``: nominal
    steady-cornering reference and feedforward, 1 m initial offset;
    ``"authors"``: the authors' regulation loop), and

    .. math::

        E[d, s] = \sum_{k=0}^{T-1} \sum_{i=1}^{4} \Big(\frac{e_i[k]}{\sigma_i}\Big)^2,

    with ``e`` the tracking errors of the four objectives' states (``rho``,
    ``psidot``, ``ydot``, ``theta``; ``x - x_ref`` as in the MOP's
    objectives) and ``sigma`` the error scales. The default scales are
    ``1 / sqrt(Q_ii)`` of the set-up's state weight, so that ``E`` is the
    quadratic state cost ``sum_k e[k]^T Q e[k]`` of the weight ``Q`` the
    set-up's designs use: the objectives are added in the units the designs
    trade them in. ``"ours"``: Bryson's acceptable errors ``[0.25 m, 0.1
    rad/s, 0.5 m/s, 0.05 rad]`` (:data:`BRYSON_SCALES`,
    :func:`robustctl.models.truck.lqr_weights`); ``"authors"``: ``[1/sqrt(25000)
    m, 1 rad/s, 1 m/s, 0.1 rad]``. ``E = T * sum_i f_i / sigma_i^2``
    with ``f_i`` the MOP's per-scenario MSEs. A gain with non-finite entries
    gets ``+inf``; a run that diverges is frozen by the simulator at its bound
    (a huge finite error, see :mod:`robustctl.sim.simulator`).

    Parameters
    ----------
    K : (D, 2, 4) or (D, 1, 4) array_like
        Gains ``u = K e`` (doubled column, steering ``u1 + u2``, or plain truck).
    deltas : (S,) array_like
        Realisations in ``[-1, 1]``.
    path : ReferencePath, optional
        Default :func:`robustctl.models.path.default_route` (540 s); a shorter one
        (``ReferencePath.truncated``) makes the selection cheaper.
    scales : (4,) array_like, optional
        ``sigma``; e.g. ``np.sqrt(AppliedRLQRProblem().hv_ref_point)`` weights
        the objectives by the problem's hypervolume reference point instead.
    setup : str or PathFollowingSetup
        Loop, initial state and default scales (:data:`robustctl.models.morais2022.SETUPS`).

    Returns
    -------
    (D, S) ndarray
        All designs and scenarios in one batched simulation (scenarios in
        chunks of 250 to bound memory; no loop over designs).
    """
    Kb, ok = _as_gains(K, 4, (1, 2))
    overloads = overload_from_delta(deltas)
    setup = get_setup(setup)
    sigma = _as_scales(scales, setup)
    if path is None:
        path = default_route()
    elif not isinstance(path, ReferencePath):
        raise TypeError(f"path must be a robustctl.models.path.ReferencePath, got {type(path).__name__}")
    steering = np.ones((1, Kb.shape[1]))                   # alpha = u1 (+ u2 on the doubled column)
    E = np.empty((Kb.shape[0], overloads.size))
    for start in range(0, overloads.size, _SCENARIO_CHUNK):
        chunk = overloads[start:start + _SCENARIO_CHUNK]
        res = PathFollowing(path, tuple(chunk.tolist()), setup=setup, input_map=steering).run(
            Kb, keep_trajectories=False)
        E[:, start:start + chunk.size] = (res.sq_error_sum[..., list(res.objectives)] / sigma**2).sum(axis=2)
    E[~ok] = np.inf
    return E


# ---------------------------------------------------------------------------
# the design set
# ---------------------------------------------------------------------------

@dataclass(frozen=True, eq=False, repr=False)
class DesignSet:
    """Candidate designs of a selection: the front, then the paper's extra designs.

    Attributes
    ----------
    K : (D, m, n) ndarray
        Gains ``u = K x`` (NaN rows where an RLQR design failed).
    z : (D, n_var) ndarray
        Decision vector of each design (NaN row for the nominal LQR).
    labels : tuple of str
        ``"1"`` .. ``"N"`` for the front, then ``"nominal"``, [``"RLQR^A"``,] ``"random"``.
    kinds : tuple of str
        ``"front"``, ``"nominal"``, ``"rlqr_a"`` or ``"random"`` per design.
    ok : (D,) bool ndarray
        The design was computed (finite gain).
    """

    K: np.ndarray
    z: np.ndarray
    labels: tuple[str, ...]
    kinds: tuple[str, ...]
    ok: np.ndarray

    def __len__(self) -> int:
        return self.K.shape[0]

    @property
    def n_front(self) -> int:
        """Number of designs taken from the front (the others are the extra designs)."""
        return self.kinds.count("front")

    def index(self, kind: str) -> int:
        """Index of the (single) extra design of ``kind`` (``"nominal"``, ``"rlqr_a"``, ``"random"``)."""
        if kind == "front" or kind not in self.kinds:
            raise ValueError(f"kind must be one of the extra designs {sorted(set(self.kinds) - {'front'})}, "
                             f"got {kind!r}")
        return self.kinds.index(kind)

    def __repr__(self) -> str:
        extras = [lab for lab, k in zip(self.labels, self.kinds, strict=True) if k != "front"]
        return (f"DesignSet(D={len(self)}, front={self.n_front}, extras={extras}, "
                f"failed={int((~self.ok).sum())})")


def _check_problem(problem) -> None:
    if not isinstance(problem, TuningProblem):
        raise TypeError(f"problem must be a moo.tuning.TuningProblem (e.g. a GenericRLQRProblem or an "
                        f"AppliedRLQRProblem), got {type(problem).__name__}")


def is_paper_problem(problem) -> bool:
    """True for the paper's two problems, which keep the paper's design sets and selection rule."""
    return isinstance(problem, (GenericRLQRProblem, AppliedRLQRProblem))


def _design_set(X: np.ndarray, K_front: np.ndarray, extras: list[tuple[str, str, np.ndarray, np.ndarray]],
                z_random: np.ndarray, K_random: np.ndarray) -> DesignSet:
    """``[front (N), *extras, random]``; each extra is ``(label, kind, K (1, m, n), z (1, n_var))``."""
    N = X.shape[0]
    K = np.concatenate([K_front, *(K_e for _, _, K_e, _ in extras), K_random])
    return DesignSet(K=K, z=np.concatenate([X, *(z_e for *_, z_e in extras), z_random[None]]),
                     labels=(*(str(i + 1) for i in range(N)), *(lab for lab, *_ in extras), "random"),
                     kinds=(*["front"] * N, *(kind for _, kind, *_ in extras), "random"),
                     ok=np.all(np.isfinite(K), axis=(1, 2)))


def _general_designs(problem: TuningProblem, X: np.ndarray, seed) -> DesignSet:
    """Front, the family's nominal design (if it has ``nominal()``), random: for any TuningProblem."""
    if problem.feedback == "output":
        raise TypeError("select_design's extra designs are state feedbacks; for an output-feedback problem use "
                        "moo.tuning.select_front (the front alone)")
    z_random = np.asarray(_rng(seed).uniform(problem.xl, problem.xu))
    K_all = np.asarray(problem.designs(np.vstack([X, z_random]))[0])
    N = X.shape[0]
    extras = []
    nominal = getattr(problem.family, "nominal", None)
    if callable(nominal):
        extras.append(("nominal", "nominal", np.asarray(problem.check_gains(nominal())),
                       np.full((1, problem.n_var), np.nan)))
    return _design_set(X, K_all[:N], extras, z_random, K_all[N:])


def build_designs(problem: TuningProblem, X_front, *, seed=None) -> DesignSet:
    """The candidate designs: the front's decision vectors plus the paper's extra designs.

    Generic: ``[front (N), nominal, random]``; applied: ``[front (N), nominal,
    RLQR^A, random]`` (the paper's order, see the module docstring); any
    other :class:`~moo.tuning.TuningProblem`: ``[front (N), nominal (if its
    family has ``nominal()``), random]``. The front
    and random designs are computed in one batched RLQR call
    (:meth:`~moo.problems.generic.GenericRLQRProblem.gains`), with the problem's ``Q``, ``R``, ``alpha`` and
    ``max_iter``; a design that fails keeps NaN gains (``ok`` False) and can
    never win.

    Parameters
    ----------
    problem : TuningProblem
    X_front : (N, n_var) array_like
        Decision vectors of the front (N >= 1), e.g. ``moo.runner.run(...).X``.
    seed : int or numpy Generator-compatible seed
        Seed of the random design, drawn from ``U(problem.xl, problem.xu)``.
    """
    _check_problem(problem)
    X = as_matrix(X_front, "X_front", cols=problem.n_var, cols_what="the problem's number of variables")
    if not is_paper_problem(problem):
        return _general_designs(problem, X, seed)
    if np.any(X[:, -1] < 0):
        raise ValueError(f"X_front's last variable, (log10 mu)^2, must be >= 0, got {X[:, -1].min():g}")
    z_random = np.asarray(_rng(seed).uniform(problem.xl, problem.xu))      # (n_var,): pymoo's bounds are arrays
    K_rlqr, ok, _ = problem.designs(np.vstack([X, z_random]))
    K_rlqr = np.where(ok[:, None, None], np.asarray(K_rlqr), np.nan)
    K_nom = rc.lqr(problem.plant, Q=problem.Q, R=problem.R).K
    assert K_nom is not None                                 # lqr designs a state feedback
    N = X.shape[0]
    extras = [("nominal", "nominal", K_nom[None], np.full((1, problem.n_var), np.nan))]
    if isinstance(problem, AppliedRLQRProblem):
        u = morais2022.algebraic_uncertainty("printed")
        a = rc.rlqr_gains(problem.plant, u.EF, u.EG, np.array([u.mu]), Q=problem.Q, R=problem.R, H=u.H,
                          alpha=problem.alpha, max_iter=problem.max_iter)
        extras.append(("RLQR^A", "rlqr_a", np.where(a.ok[:, None, None], a.K, np.nan),
                       np.concatenate([u.EF.ravel(), u.EG.ravel(), [np.log10(u.mu) ** 2]])[None]))
    return _design_set(X, K_rlqr[:N], extras, z_random, K_rlqr[N:])


# ---------------------------------------------------------------------------
# everything in one call
# ---------------------------------------------------------------------------

@dataclass(frozen=True, eq=False, repr=False)
class DesignSelection:
    """Outcome of :func:`select_design`.

    Attributes
    ----------
    designs : DesignSet
    deltas : (S,) ndarray
        The realisations ``Delta_s`` (the paper's problems), or the index of
        the scenario each simulation drew (any other problem; -1 where a
        ``sampler`` drew the plant).
    errors : (D, S) ndarray
        Cumulative errors (see :func:`generic_errors`, :func:`applied_errors`,
        :func:`moo.tuning.selection.scenario_errors`).
    result : SelectionResult
    """

    designs: DesignSet
    deltas: np.ndarray
    errors: np.ndarray
    result: SelectionResult

    @property
    def best(self) -> int:
        """Index of the selected design (the result's ``best``)."""
        return self.result.best

    @property
    def label(self) -> str:
        """Label of the selected design (``"49"``, ``"nominal"``, ...)."""
        return self.designs.labels[self.best]

    @property
    def z(self) -> np.ndarray:
        """Decision vector ``z*`` of the selected design (NaN for the nominal LQR)."""
        return self.designs.z[self.best].copy()

    def __repr__(self) -> str:
        return (f"DesignSelection(D={len(self.designs)}, S={self.deltas.size}, winner={self.label!r}, "
                f"wins={int(self.result.counts[self.best])})")


def select_design(problem: TuningProblem, X_front, *, n_sims: int = 1000, seed=None,
                  path: ReferencePath | None = None, scales=None, sampler=None, weights=None) -> DesignSelection:
    """The paper's Monte Carlo selection of ``z*`` from a front, in one call.

    Builds the design set (:func:`build_designs`), draws ``n_sims`` realisations
    ``Delta ~ U(-1, 1)`` (:func:`draw_deltas`), computes the cumulative errors
    (:func:`generic_errors` or :func:`applied_errors`) and counts the winners
    (:func:`monte_carlo_selection`). Any other :class:`~moo.tuning.TuningProblem`:
    each simulation draws one of its scenarios (or ``sampler(rng)``) and the
    errors are :func:`moo.tuning.selection.scenario_errors` with ``weights``
    (default: 1 / the spread of the front's objectives, see :mod:`moo.tuning.selection`).

    Parameters
    ----------
    problem : TuningProblem
        The problem the front was computed on (the paper's: its ``Q``, ``R``, ``alpha`` design
        the gains; the generic one also gives initial states and horizon).
    X_front : (N, n_var) array_like
    n_sims : int
        ``S`` (the paper: 1000).
    seed : int or numpy Generator-compatible seed
        ``np.random.default_rng(seed)`` is split (``Generator.spawn``) into two
        independent streams: the random design and the realisations.
    path : ReferencePath, optional
        Applied problem only: the simulated path (default ``problem.path``).
    scales : (4,) array_like, optional
        Applied problem only: see :func:`applied_errors` (the loop and the
        default scales are those of ``problem.setup``).
    sampler : callable, optional
        Problems other than the paper's: ``sampler(rng) -> robustctl.Plant``, the plant of a simulation.
    weights : (n_obj,) array_like, optional
        Problems other than the paper's: weights of the objectives in the cumulative error.
    """
    _check_problem(problem)
    n_sims = check_int(n_sims, "n_sims", 1)
    if not is_paper_problem(problem):
        if path is not None or scales is not None:
            raise ValueError("path and scales apply to the applied problem only; give None")
        return _general_selection(problem, X_front, n_sims, seed, sampler, weights)
    if sampler is not None or weights is not None:
        raise ValueError("sampler and weights apply to problems other than the paper's two; give None")
    generic = isinstance(problem, GenericRLQRProblem)
    if generic and (path is not None or scales is not None):
        raise ValueError("path and scales apply to the applied problem only; give None for the generic one")
    design_rng, delta_rng = _rng(seed).spawn(2)
    designs = build_designs(problem, X_front, seed=design_rng)
    deltas = draw_deltas(n_sims, delta_rng)
    if generic:
        errors = generic_errors(designs.K, deltas, problem=problem)
    else:
        errors = applied_errors(designs.K, deltas, path=problem.path if path is None else path, scales=scales,
                                setup=problem.setup)
    return DesignSelection(designs=designs, deltas=deltas, errors=errors, result=monte_carlo_selection(errors))


def _general_selection(problem: TuningProblem, X_front, n_sims: int, seed, sampler, weights) -> DesignSelection:
    """:func:`select_design` for a TuningProblem other than the paper's (see :mod:`moo.tuning.selection`)."""
    design_rng, draw_rng = _rng(seed).spawn(2)
    designs = build_designs(problem, X_front, seed=design_rng)
    if weights is None:
        F, _ = problem.evaluate_gains(designs.K[:designs.n_front])
        fin = np.all(np.isfinite(F), axis=1)
        weights = default_weights(F[fin] if fin.any() else np.ones((1, problem.n_obj)))
    errors, draws = draw_errors(problem, designs.K, n_sims, draw_rng, sampler, check_weights(weights, problem.n_obj))
    return DesignSelection(designs=designs, deltas=draws, errors=errors, result=monte_carlo_selection(errors))
